"""Benchmarks on the measurement harness: modules that declare cases and timed functions.

A benchmark module (one file in the checkout's ``benchmarks/`` folder, found by
:func:`discover`) registers a function with :func:`benchmark`, naming its :class:`Case` s: each
case has parameters at full size and, for ``--quick``, a size that runs in seconds. The
harness calls ``function(bench, **parameters)`` once per case with a :class:`Bench`; the
function prepares its inputs (untimed) and times its work through the bench:

* :meth:`Bench.time` — one function, by :func:`~workbench.measurement.timing.time_call`
  (warm-up calls first, numba compilation included and untimed; an optional untimed
  ``setup`` before every call);
* :meth:`Bench.time_reported` — work that measures itself (a tool's own query clock, a
  subprocess timing its import): each call returns its seconds, or a mapping of named
  seconds (one row each);
* :meth:`Bench.interleave` — two or more functions compared A B A B … in one warm state
  (:func:`~workbench.measurement.interleave.time_interleaved`), with the per-pair ratios'
  medians and 95 % intervals (``over_<denominator>``, ``_lo``, ``_hi``, ``_pairs``) on the
  numerator's row;
* :meth:`Bench.record` — a row of values that are not times (counts, bytes, check results).

Every timed row carries ``case``, ``function``, the case's parameters, the function's own
columns and the timing columns of :data:`~workbench.measurement.timing.TIMING_COLUMNS`
(milliseconds, with the raw samples), so that the results store pairs and compares it like an
experiment's row. A benchmark needing what the machine lacks declares it (``requires``: the
helpers :func:`needs_module`, :func:`needs_shared_file`, :func:`needs_gl`,
:func:`needs_gpu`, :func:`needs_memory_gib`) and is skipped with the reason; a case can skip
itself (:meth:`Bench.require`, :func:`skip`). A run may set any parameter the function takes
for every case (``overrides``, ``workbench bench NAME --set KEY=VALUE``: a benchmark's options,
such as ``distance_fcpw_bench``'s ``hierarchy``); the rows carry the values. Recording the
rows is the caller's part (``workbench bench``, :mod:`workbench.cli.bench`).
"""

from __future__ import annotations

import importlib.util
import inspect
import os
import re
import sys
import time
import types
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

from .interleave import Clock, time_interleaved
from .stats import StoppingRule, paired_ratio_interval
from .timing import MIN_REPEATS, Timing, check_counts, time_call

SIZES = ("full", "quick")
DEFAULT_REPEAT = {"full": 7, "quick": MIN_REPEATS}
BENCHMARKS_ENV = "WORKBENCH_BENCHMARKS"
MODULE_PREFIX = "workbench_benchmarks"
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
Progress = Callable[[str], None]
Requirement = Callable[[], "str | None"]


class Skipped(Exception):
    """Raised by a benchmark (or a case) that cannot run here; ``reason`` says why."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def skip(reason: str) -> NoReturn:
    """Skip the running case with ``reason`` (raises :class:`Skipped`)."""
    raise Skipped(reason)


@dataclass(frozen=True)
class Case:
    """One case of a benchmark: its ``name`` (text, part of every row's key), its parameters
    at full size (``full``) and at ``--quick`` size (``quick``; the full ones where None)."""

    name: str
    full: Mapping[str, Any] = field(default_factory=dict)
    quick: Mapping[str, Any] | None = None

    def parameters(self, size: str) -> dict[str, Any]:
        """The keyword arguments of the case at ``size`` ("full" or "quick")."""
        return dict(self.full if size == "full" or self.quick is None else self.quick)


@dataclass(frozen=True)
class Benchmark:
    """A registered benchmark: name, one-line description, ``function(bench, **parameters)``,
    its cases and its requirements (callables answering None, or why it cannot run)."""

    name: str
    description: str
    function: Callable[..., Any]
    cases: tuple[Case, ...]
    requires: tuple[Requirement, ...] = ()

    def missing(self) -> str | None:
        """Why this benchmark cannot run on this machine (the first unmet requirement), or
        None."""
        for requirement in self.requires:
            reason = requirement()
            if reason:
                return reason
        return None


BENCHMARKS: dict[str, Benchmark] = {}


def benchmark(name: str, description: str, cases: Sequence[Case] = (Case("default"),),
              requires: Sequence[Requirement] = ()) -> Callable:
    """Decorator registering ``function(bench, **parameters)`` as benchmark ``name`` (letters,
    digits, ``_ . -``) with ``cases`` (distinct names, at least one) and ``requires``.
    Refuses a bad or duplicate name and a name already registered by another function; a
    module loaded again replaces its own entry. Returns the function unchanged."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise ValueError(f"benchmark name must be letters, digits, '_', '.' or '-' (not "
                         f"leading), got {name!r}")
    cases = tuple(cases)
    names = [c.name for c in cases]
    if not cases or len(set(names)) != len(names) or not all(isinstance(c, Case)
                                                            for c in cases):
        raise ValueError(f"benchmark {name!r} needs one or more Case with distinct names")

    def register(function: Callable) -> Callable:
        old = BENCHMARKS.get(name)
        if old is not None and old.function.__module__ != function.__module__:
            raise ValueError(f"benchmark {name!r} is already registered by "
                             f"{old.function.__module__}")
        BENCHMARKS[name] = Benchmark(name, str(description), function, cases, tuple(requires))
        return function

    return register


def benchmarks_folder(explicit: str | os.PathLike[str] | None = None) -> Path:
    """Where the benchmark modules are: ``explicit``, else ``$WORKBENCH_BENCHMARKS``, else
    the ``benchmarks`` folder of the checkout this package lies in."""
    if explicit is not None:
        return Path(explicit)
    env = os.environ.get(BENCHMARKS_ENV, "")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "benchmarks"


def discover(folder: str | os.PathLike[str] | None = None) -> dict[str, Benchmark]:
    """Load every ``*.py`` module of ``folder`` (see :func:`benchmarks_folder`; names starting
    with ``_`` skipped) so that it registers its benchmarks, and return the registry. Refuses
    a missing folder (FileNotFoundError); a module that fails to import raises ImportError
    naming it."""
    folder = benchmarks_folder(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"benchmark folder {folder} does not exist")
    # the modules' package, so that their functions pickle by name (process pools)
    package = sys.modules.get(MODULE_PREFIX) or types.ModuleType(MODULE_PREFIX)
    package.__path__ = [str(folder)]
    sys.modules[MODULE_PREFIX] = package
    for path in sorted(folder.glob("*.py")):
        if path.name.startswith("_"):
            continue
        module_name = f"{MODULE_PREFIX}.{path.stem}"
        spec = importlib.util.spec_from_file_location(module_name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module
        try:
            spec.loader.exec_module(module)
        except Exception as exc:
            sys.modules.pop(module_name, None)
            raise ImportError(f"benchmark module {path} failed to import: {exc}") from exc
    return BENCHMARKS


def get_benchmark(name: str) -> Benchmark:
    """The registered benchmark ``name``; KeyError listing the known names otherwise."""
    try:
        return BENCHMARKS[name]
    except KeyError:
        known = ", ".join(sorted(BENCHMARKS)) or "none"
        raise KeyError(f"unknown benchmark {name!r}; known: {known}") from None


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_").lower()


class Bench:
    """What a benchmark function times through: ``size`` ("full"/"quick"), ``repeat``
    (timed repetitions, at least 5), ``case`` and ``parameters``; the rows it made are in
    ``rows``. ``progress`` receives one line per timed function."""

    def __init__(self, case: Case, size: str, repeat: int,
                 progress: Progress | None = None,
                 overrides: Mapping[str, Any] | None = None) -> None:
        check_counts(0, repeat)
        self.case, self.size, self.repeat = case, size, int(repeat)
        self.parameters = {**case.parameters(size), **(overrides or {})}
        self.rows: list[dict[str, Any]] = []
        self._progress = progress

    @property
    def quick(self) -> bool:
        """True at the ``--quick`` size."""
        return self.size == "quick"

    def require(self, *reasons: str | None) -> None:
        """Skip the case with the first of ``reasons`` that is not None or empty (the answers
        of requirement helpers such as :func:`needs_memory_gib`)."""
        for reason in reasons:
            if reason:
                skip(reason)

    def _row(self, function: str, columns: Mapping[str, Any]) -> dict[str, Any]:
        return {"case": self.case.name, "function": str(function), **self.parameters,
                **columns}

    def _add(self, function: str, timing: Timing, columns: Mapping[str, Any]) -> Timing:
        self.rows.append({**self._row(function, columns), **timing.as_row()})
        if self._progress is not None:
            labels = "".join(f", {k}={v}" for k, v in columns.items() if isinstance(v, str))
            self._progress(f"  {self.case.name} / {function}{labels}: {timing.wall_ms:.4g} ms "
                           f"[{timing.wall_ms_lo:.4g}, {timing.wall_ms_hi:.4g}], "
                           f"{timing.repeats} runs")
        return timing

    def time(self, function: str, run: Callable[[], Any], setup: Callable[[], Any] | None = None,
             warmup: int = 1, repeat: int | None = None, **columns: Any) -> Timing:
        """Time ``run()`` (wall ms): ``warmup`` untimed calls, then ``repeat`` (default the
        bench's) timed ones, each after an untimed ``setup()`` where given; one row named
        ``function`` with ``columns``. Returns the
        :class:`~workbench.measurement.timing.Timing` (its ``result`` is the last call's value)."""
        repeat = self.repeat if repeat is None else repeat
        return self._add(function, time_call(run, warmup=warmup, repeat=repeat, setup=setup),
                         columns)

    def time_reported(self, function: str, run: Callable[[], Any], warmup: int = 1,
                      repeat: int | None = None, **columns: Any) -> dict[str, Timing]:
        """Time work that measures itself: each call of ``run()`` returns its seconds, or a
        mapping of names to seconds (one row each, named ``"<function> <name>"``);
        ``warmup`` calls first, untimed. Returns the timings by row name."""
        repeat = self.repeat if repeat is None else repeat
        check_counts(warmup, repeat)
        samples: dict[str, list[float]] = {}
        for i in range(warmup + repeat):
            value = run()
            parts = value if isinstance(value, Mapping) else {None: value}
            if i >= warmup:
                for key, seconds in parts.items():
                    name = function if key is None else f"{function} {key}"
                    samples.setdefault(name, []).append(float(seconds) * 1e3)
        return {name: self._add(name, Timing.from_samples(ms), columns)
                for name, ms in samples.items()}

    def interleave(self, clocks: Mapping[str, Callable[[], Any] | Clock],
                   ratios: Sequence[tuple[str, str]] = (), warmup: int = 1,
                   repeat: int | None = None, reported: bool = False,
                   columns_of: Mapping[str, Mapping[str, Any]] | None = None,
                   **columns: Any) -> dict[str, Timing]:
        """Time ``clocks`` (name → callable, or a
        :class:`~workbench.measurement.interleave.Clock` with an untimed setup) interleaved, one
        call of each per round, ``warmup`` untimed rounds then ``repeat`` timed ones. With
        ``reported`` each call returns its own seconds, which are the samples. One row per clock
        (``columns`` and its ``columns_of[name]`` added); each (numerator, denominator) of
        ``ratios`` puts the median per-round ratio with its 95 % interval on the numerator's row
        (``over_<denominator>``, ``_lo``, ``_hi``, ``_pairs``). Refuses ratios naming unknown clocks
        and fewer than two clocks."""
        if len(clocks) < 2:
            raise ValueError(f"interleave needs two or more clocks, got {list(clocks)}")
        repeat = self.repeat if repeat is None else repeat
        check_counts(warmup, repeat)
        said: dict[str, list[float]] = {name: [] for name in clocks}

        def clock_of(name: str, clock: Callable[[], Any] | Clock) -> Clock:
            clock = clock if isinstance(clock, Clock) else Clock(clock)
            if not reported:
                return clock
            return Clock(lambda: said[name].append(float(clock.run()) * 1e3), clock.setup)

        timed = {name: clock_of(name, clock) for name, clock in clocks.items()}
        # min = max = repeat: exactly ``repeat`` timed rounds (the first pair's count stops)
        names = list(clocks)
        times = time_interleaved(timed, list(ratios) or [(names[0], names[1])],
                                 StoppingRule(0.02, repeat, repeat), warmup)
        if reported:
            times = {name: values[warmup:] for name, values in said.items()}
        extra: dict[str, dict[str, Any]] = {name: {} for name in clocks}
        for a, b in ratios:
            i = paired_ratio_interval(times[a], times[b])
            key = f"over_{_safe(b)}"
            extra[a].update({key: i.estimate, f"{key}_lo": i.lo, f"{key}_hi": i.hi,
                             f"{key}_pairs": i.n})
        return {name: self._add(name, Timing.from_samples(times[name]),
                                {**columns, **(columns_of or {}).get(name, {}), **extra[name]})
                for name in clocks}

    def record(self, function: str, **values: Any) -> dict[str, Any]:
        """A row of values that are not timed (counts, bytes, check results) named
        ``function``; returns it."""
        row = self._row(function, values)
        self.rows.append(row)
        return row


@dataclass
class BenchResult:
    """What one benchmark gave: its rows, and per skipped case (or ``"*"`` for the whole
    benchmark) the reason."""

    name: str
    size: str
    rows: list[dict[str, Any]]
    skipped: dict[str, str]


def parameter_names(name: str) -> list[str]:
    """The keyword parameters the benchmark ``name``'s function takes (besides ``bench``):
    what its cases set and ``overrides`` may set."""
    signature = inspect.signature(get_benchmark(name).function)
    return [p.name for p in list(signature.parameters.values())[1:]
            if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def check_overrides(name: str, overrides: Mapping[str, Any]) -> None:
    """Refuse (ValueError naming the benchmark and the parameters it takes) an override of a
    parameter the benchmark ``name``'s function does not take."""
    known = parameter_names(name)
    unknown = [key for key in overrides if key not in known]
    if unknown:
        raise ValueError(f"benchmark {name!r} takes no parameter {unknown[0]!r} (it takes: "
                         f"{', '.join(known) or 'none'})")


def run_benchmark(name: str, size: str = "full", repeat: int | None = None,
                  progress: Progress | None = None,
                  overrides: Mapping[str, Any] | None = None) -> BenchResult:
    """Run every case of the registered benchmark ``name`` at ``size`` ("full" or "quick")
    with ``repeat`` timed repetitions (default 7 full, 5 quick; at least 5), each case's
    parameters updated by ``overrides`` (parameter → value; the rows carry them). A benchmark
    whose requirements are unmet runs nothing and is reported skipped (``skipped["*"]``); a
    case that raises :class:`Skipped` is skipped with its reason. ``progress`` receives a line
    per case and per timed function. Unknown names raise KeyError; a bad size or count, or an
    override of a parameter the benchmark does not take, ValueError."""
    bench = get_benchmark(name)
    check_overrides(name, overrides or {})
    if size not in SIZES:
        raise ValueError(f"benchmark size must be one of {SIZES}, got {size!r}")
    repeat = DEFAULT_REPEAT[size] if repeat is None else repeat
    check_counts(0, repeat)
    say = progress or (lambda line: None)
    missing = bench.missing()
    if missing:
        say(f"{name}: skipped: {missing}")
        return BenchResult(name, size, [], {"*": missing})
    rows: list[dict[str, Any]] = []
    skipped: dict[str, str] = {}
    for case in bench.cases:
        start = time.perf_counter()
        run = Bench(case, size, repeat, progress, overrides)
        try:
            bench.function(run, **run.parameters)
        except Skipped as exc:
            skipped[case.name] = exc.reason
            say(f"{name} [{case.name}]: skipped: {exc.reason}")
            continue
        rows.extend(run.rows)
        say(f"{name} [{case.name}]: {len(run.rows)} rows in {time.perf_counter() - start:.1f} s")
    return BenchResult(name, size, rows, skipped)


# ---- requirements: each answers None where met, else the reason -------------------------

def needs_module(*names: str) -> Requirement:
    """Requirement: every module of ``names`` imports."""
    def check() -> str | None:
        for module in names:
            if importlib.util.find_spec(module) is None:
                return f"needs the Python module {module}, which is not installed"
        return None
    return check


def needs_shared_file(relative: str | os.PathLike[str]) -> Requirement:
    """Requirement: the shared data file ``relative`` (:func:`workbench.data.shared_file`)."""
    def check() -> str | None:
        from .. import data

        if data.shared_file(relative) is None:
            return f"needs the shared data file {relative} (set WORKBENCH_DATA)"
        return None
    return check


_GL: dict[str, str | None] = {}


def _renderer() -> str | None:
    """The renderer of a GL context made once for the question, or None without one."""
    if "renderer" not in _GL:
        from ..gl.context import GLUnavailable, create_context, describe

        try:
            ctx = create_context()
            _GL["renderer"] = str(describe(ctx).get("renderer"))
            ctx.release()
        except GLUnavailable:
            _GL["renderer"] = None
    return _GL["renderer"]


def needs_gl() -> str | None:
    """Requirement: a headless OpenGL context can be made."""
    return None if _renderer() is not None else "needs an OpenGL context (none can be made)"


def needs_gpu() -> str | None:
    """Requirement: an OpenGL renderer that is a GPU, not a software renderer."""
    from ..gl.context import is_software_renderer

    renderer = _renderer()
    if renderer is None or is_software_renderer(renderer):
        return f"needs a GPU renderer (here: {renderer or 'no OpenGL'})"
    return None


def needs_memory_gib(gib: float) -> str | None:
    """``gib`` GiB of memory or more on this machine: None, else the reason (for
    :meth:`Bench.require`)."""
    try:
        have = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    except (ValueError, OSError, AttributeError):
        return f"needs {gib:g} GiB of memory (unknown here)"
    return None if have >= gib else f"needs {gib:g} GiB of memory (this machine has {have:.0f})"


def seconds_of(run: Callable[[], Any]) -> float:
    """Wall seconds of one call of ``run()`` (a clock for :meth:`Bench.interleave` with
    ``reported`` where the other clocks report their own seconds)."""
    start = time.perf_counter()
    run()
    return time.perf_counter() - start
