"""The experiment registry behind ``workbench reproduce``.

An experiment script in the package ``workbench.reproductions`` (one module per paper table
or figure) registers a function with :func:`experiment`, with the
:class:`~workbench.experiment.declare.Declaration` of its tables and claims; the function
``run(exp)`` receives an :class:`~workbench.experiment.context.ExperimentContext` (size,
output folder, progress, GL context, measurement defaults, the shared-data guard), writes its
figures and further tables into the context's folder and returns its rows.
:func:`run_experiment` then writes ``table.csv``/``table.md`` from those rows. Every table a
declared experiment writes is checked against its declaration first, and its Markdown carries
the declared legend.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import re
import shutil
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import TYPE_CHECKING

from ..measurement.timing import empty_gpu_note
from ..output.swap import clean_dead_swaps, staging_folder, swap_in
from ..output.tables import write_table
from ..output.targets import output_folder
from .context import SIZES, ExperimentContext
from .declare import Declaration
from .warm import warm_experiment

if TYPE_CHECKING:
    from ..results.recording import Recorder

Progress = Callable[[str], None]
RunFunction = Callable[[ExperimentContext], list]

EXPERIMENTS_PACKAGE = "workbench.reproductions"
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


@dataclass(frozen=True)
class Experiment:
    """A registered experiment: its name (also its figures folder), a one-line description,
    the function ``run(exp: ExperimentContext) -> list[dict]`` and the declaration of its
    tables and claims (None: its tables are written unchecked, without legends)."""

    name: str
    description: str
    function: RunFunction
    declared: Declaration | None = None


EXPERIMENTS: dict[str, Experiment] = {}
_discovered = False


def experiment(name: str, description: str,
               declared: Declaration | None = None) -> Callable[[RunFunction], RunFunction]:
    """Decorator registering ``run`` under ``name`` (letters, digits, ``_ . -``; it names the
    folder ``figures/<name>/``) with ``declared``, the declaration of its tables and claims
    (every experiment of ``workbench.reproductions`` has one). Refuses a name already taken by
    a different function, and a ``declared`` that is not a
    :class:`~workbench.experiment.declare.Declaration`; a module imported again replaces its
    own entry. Returns the function unchanged."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise ValueError(f"experiment name must be letters, digits, '_', '.' or '-' (not leading), "
                         f"got {name!r}")
    if declared is not None and not isinstance(declared, Declaration):
        raise TypeError(f"experiment {name!r}: declared must be a Declaration, "
                        f"got {type(declared).__name__}")

    def register(function: RunFunction) -> RunFunction:
        if not callable(function):
            raise TypeError(f"experiment {name!r} must decorate a function")
        old = EXPERIMENTS.get(name)
        if old is not None and (old.function.__module__, old.function.__qualname__) != (
                function.__module__, function.__qualname__):
            raise ValueError(f"experiment {name!r} is already registered by "
                             f"{old.function.__module__}.{old.function.__qualname__}")
        EXPERIMENTS[name] = Experiment(name, str(description), function, declared)
        return function

    return register


def discover(package: str = EXPERIMENTS_PACKAGE) -> dict[str, Experiment]:
    """Import every module of ``package`` (they register on import) and return the registry.

    Modules whose name starts with ``_`` are skipped. An import error propagates, naming the
    module, so a broken script is not silently missing from the list.
    """
    global _discovered
    pkg = importlib.import_module(package)
    for module in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda m: m.name):
        if module.name.startswith("_"):
            continue
        full = f"{package}.{module.name}"
        try:
            importlib.import_module(full)
        except Exception as exc:
            raise ImportError(f"experiment module {full} failed to import: {exc}") from exc
    _discovered = True
    return EXPERIMENTS


def get_experiment(name: str) -> Experiment:
    """The registered experiment ``name``; KeyError listing the known names otherwise."""
    try:
        return EXPERIMENTS[name]
    except KeyError:
        known = ", ".join(sorted(EXPERIMENTS)) or "none"
        hint = "" if _discovered else " (call discover() first to register the experiment scripts)"
        raise KeyError(f"unknown experiment {name!r}; known: {known}{hint}") from None


def run_experiment(name: str, figures_root: str | os.PathLike[str] = Path("figures"),
                   quick: bool = False, progress: Progress | None = None,
                   size: str | None = None,
                   recorder: Recorder | None = None,
                   warm: bool = True) -> tuple[list[dict], Path]:
    """Run experiment ``name`` into ``figures_root/<name>/`` and write its table there.

    ``size`` is "full", "quick" or "tiny" (see :mod:`workbench.experiment.context`); by
    default "quick" with ``quick`` and "full" without.

    The experiment writes into a fresh staging folder beside the output folder
    (``.<name>.<random>.<pid>.partial``); its ``table.csv`` and ``table.md`` (titled with the
    name and description) go there too, and only then does the staging folder replace the
    output folder, so a run's outputs change as a set: a run that fails or is killed leaves the
    previous outputs whole. With a ``recorder`` every table's rows are then appended to its
    results store (columns ``experiment``, ``table`` and ``experiment_size`` added), once the
    folder is in place, and the folder holds ``provenance.json`` naming the run and the
    SHA-256 of each of its files
    (:meth:`~workbench.results.recording.Recorder.write_provenance`). With ``warm`` (the
    default) a quick or full run is preceded by the experiment's tiny run, untimed and thrown away
    (:func:`~workbench.experiment.warm.warm_experiment`), so that no table times the
    compilation of a kernel; a Dask cluster the experiment starts is started once and kept
    for both runs (:func:`~workbench.distributed.kept.kept_clusters`), its workers warm. What
    killed runs left behind (staging folders, a previous output folder set aside, temporary
    files) is cleaned up first. Returns ``(rows, out_dir)``.
    Unknown names raise KeyError listing the known ones; rows that are not dicts raise TypeError.
    An output folder that is a symbolic link (wherever it points) or not a folder is refused
    (ValueError) before the experiment runs, and again just before the swap. A declared
    experiment's table whose columns differ from its declaration is refused
    (:class:`~workbench.experiment.declare.DeclarationError`) before it is written.
    """
    exp = get_experiment(name)
    size = size if size is not None else ("quick" if quick else "full")
    if size not in SIZES:
        raise ValueError(f"experiment size must be one of {SIZES}, got {size!r}")
    root = Path(figures_root)
    root.mkdir(parents=True, exist_ok=True)
    out_dir = root / exp.name
    clean_dead_runs(root, exp.name)
    output_folder(out_dir)
    from ..distributed.kept import kept_clusters

    with kept_clusters():  # the tiny run's cluster, its workers warm, serves the timed run
        if warm and size != "tiny":
            took = warm_experiment(exp)
            if progress is not None:
                progress(f"kernels warmed by the tiny run ({took:.1f} s, not timed)")
        staging = staging_folder(out_dir)
        context = ExperimentContext(exp.name, staging, size, progress, declared=exp.declared)
        try:
            try:
                rows = exp.function(context)
            finally:
                context.close()
        except BaseException:
            shutil.rmtree(staging, ignore_errors=True)
            raise
    try:
        if rows is None:
            raise TypeError(f"experiment {name!r} returned None instead of a list of rows")
        rows = list(rows)
        bad = [type(r).__name__ for r in rows if not isinstance(r, dict)]
        if bad:
            raise TypeError(f"experiment {name!r} returned rows that are not dicts: {bad[:3]}")
        rows = context.with_device(rows)
        write_table(rows, staging, "table", title=f"{exp.name}: {exp.description}",
                    notes=empty_gpu_note(rows, context.gl_renderer),
                    legend=context.legend("table", rows))
        if recorder is not None:  # the folder names its run: figures link to it
            recorder.write_provenance(staging, exp.name, size)
        swap_in(staging, out_dir)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if recorder is not None:
        for table, table_rows in [("table", rows), *context.tables]:
            recorder.append(table_rows, experiment=exp.name, table=table, experiment_size=size)
    return rows, out_dir


def clean_dead_runs(root: Path, name: str) -> list[Path]:
    """Remove what runs of experiment ``name`` that died left in ``root``: their staging
    folders and a previous output folder set aside (put back when the output folder is
    missing: :func:`~workbench.output.swap.clean_dead_swaps`), and temporary files in the
    output folder. Folders of runs still alive are left alone. Returns what was removed or
    restored."""
    out_dir = root / name
    done = clean_dead_swaps(out_dir)
    if out_dir.is_dir() and not out_dir.is_symlink():  # never remove files through a link
        for tmp in out_dir.glob(".*.tmp"):
            tmp.unlink(missing_ok=True)
            done.append(tmp)
    return done


def _warm_by_name(name: str) -> tuple[str, float]:
    """Worker side of :func:`warm_all`: discover the experiments, warm ``name``."""
    return name, warm_experiment(discover()[name])


def warm_all(names: Sequence[str], jobs: int = 2,
             progress: Callable[[str], None] | None = None) -> dict[str, float]:
    """Warm every experiment of ``names`` (see
    :func:`~workbench.experiment.warm.warm_experiment`) in ``jobs`` spawned
    processes at once; returns the wall seconds of each, by name. Refuses ``jobs`` < 1
    (ValueError). The first failure propagates after the running warm-ups end."""
    if int(jobs) != jobs or jobs < 1:
        raise ValueError(f"jobs must be a whole number >= 1, got {jobs!r}")
    seconds: dict[str, float] = {}
    if jobs == 1:
        found = discover()
        for name in names:
            seconds[name] = warm_experiment(found[name])
            if progress:
                progress(f"{name}: {seconds[name]:.1f} s")
        return seconds
    with ProcessPoolExecutor(max_workers=int(jobs), mp_context=get_context("spawn")) as pool:
        futures = [pool.submit(_warm_by_name, name) for name in names]
        for future in as_completed(futures):
            name, took = future.result()
            seconds[name] = took
            if progress:
                progress(f"{name}: {took:.1f} s")
    return seconds
