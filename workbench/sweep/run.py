"""Running a sweep (:func:`run_sweep`): the keys of its points, the cached rows, the missing
points computed on a Dask cluster, and the result table and figure."""

from __future__ import annotations

import json
import re
import sys
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..output.tables import table_columns, write_table
from ..output.targets import output_folder, output_target
from .cache import cached_row, json_default, store_row
from .config import SweepConfig, grid_points, load_config
from .pareto import save_pareto
from .points import Point, failure_row, run_point
from .sources import point_key

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..results.recording import Recorder

# what every worker imports once its context exists, so that the first point's time is not
# spent importing
WORKER_IMPORTS = ("workbench.sweep.points",)


@dataclass
class SweepResult:
    """What :func:`run_sweep` did: ``rows`` (grid order, as in the table), ``computed``,
    ``cached`` and ``failed`` point counts, the run's ``run_id``, ``renderer``, ``workers``,
    ``out_dir``, ``skip_ms`` (per cached point: ms to compute its key and read its row) and
    ``compute_s`` (wall seconds from submitting the missing points to storing the last) and
    ``devices`` (the EGL device identity each worker drew on, by worker address)."""

    name: str
    rows: list[dict]
    computed: int
    cached: int
    failed: int
    run_id: str
    renderer: str
    workers: int
    out_dir: Path
    skip_ms: list[float] = field(default_factory=list)
    compute_s: float = 0.0
    devices: dict[str, str | None] = field(default_factory=dict)

    @property
    def summary(self) -> str:
        """``sweep NAME: P points, C computed, H from cache, F failed``."""
        return (f"sweep {self.name}: {len(self.rows)} points, {self.computed} computed, "
                f"{self.cached} from cache, {self.failed} failed")


def _progress(total: int, initial: int, name: str, enabled: bool):
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc=f"sweep {name}", unit="point",
                file=sys.stderr, disable=not enabled, dynamic_ncols=True)


def run_sweep(config: SweepConfig | str | Path, out_dir, *, workers: int | None = None,
              scheduler: str | None = None, quick: bool = False, progress: bool = True,
              timed: bool | None = None, recorder: Recorder | None = None,
              devices: Sequence[int] | None = None,
              verbose: bool | None = None) -> SweepResult:
    """Run ``config`` (a :class:`SweepConfig` or a config file) on a Dask cluster (a new
    LocalCluster of ``workers`` processes, default one per CPU, or the one at ``scheduler``),
    computing only points not cached in ``out_dir/points``; write ``table.csv``, ``table.md``
    and ``pareto.png`` in ``out_dir``.

    ``quick``: smaller built-in scenes, at most 5 repeats. ``timed`` (default the config's):
    False draws every point once, untimed. ``progress``: a tqdm bar on stderr. A failing point
    is stored with its ``error`` and counted in ``failed``; the sweep goes on. With a
    ``recorder`` the points computed now (not those from the cache, recorded by their own run)
    are appended to its results store as table ``points`` of experiment ``sweep:<name>``,
    also when the sweep is interrupted, and the rows carry the recorder's run id. An
    ``out_dir`` or ``out_dir/points`` that is a symbolic link (wherever it points) or not a
    folder is refused (ValueError) before any point is computed, as is a ``table.csv``,
    ``table.md`` or ``pareto.png`` there that exists and is not a regular file. ``devices``
    lists the EGL devices the workers are pinned to (default each host's round-robin);
    ``verbose`` shows Dask's INFO log lines (default: as :func:`sweep_cluster`
    decides).
    """
    from ..distributed.cluster import sweep_cluster

    if not isinstance(config, SweepConfig):
        config = load_config(config)
    points = grid_points(config, quick=quick, timed=timed)
    out = output_folder(out_dir)
    for name in ("table.csv", "table.md", "pareto.png"):  # refused now, not after the points
        output_target(out / name)
    points_dir = output_folder(output_folder(out, create=True) / "points", create=True)
    run_id = recorder.run_id if recorder is not None else uuid.uuid4().hex[:12]
    rows: dict[int, dict] = {}
    skip_ms, computed = [], 0
    untimed = not any(p.timed for p in points)
    with sweep_cluster(workers, scheduler, raster_threads=1 if untimed else None,
                       imports=WORKER_IMPORTS, devices=devices, verbose=verbose) as cluster:
        keys = {}
        for point in points:
            start = time.perf_counter()
            key = keys[point.index] = point_key(point, cluster.renderer)
            row = cached_row(points_dir, key)
            if row is not None:
                rows[point.index] = row
                skip_ms.append((time.perf_counter() - start) * 1e3)
        missing = [p for p in points if p.index not in rows]
        bar = _progress(len(points), len(rows), config.name, progress)
        start = time.perf_counter()
        try:
            computed = _compute(cluster, missing, keys, points_dir, run_id, rows, bar)
        finally:
            bar.close()
            if recorder is not None:
                recorder.append([rows[p.index] for p in missing if p.index in rows],
                                experiment=f"sweep:{config.name}", table="points",
                                experiment_size="quick" if quick else "full")
        compute_s = time.perf_counter() - start
        renderer, count, devices = cluster.renderer, cluster.workers, cluster.devices
    ordered = [rows[p.index] for p in points]
    write_results(config, ordered, out, renderer, timed=points[0].timed if points else True)
    failed = sum(1 for r in ordered if r.get("error"))
    return SweepResult(config.name, ordered, computed, len(points) - computed, failed, run_id,
                       renderer, count, out, skip_ms, compute_s, devices)


def _compute(cluster, points: list[Point], keys: dict, points_dir: Path, run_id: str,
             rows: dict, bar) -> int:
    """Submit ``points`` (grid order), store each row as it arrives; returns how many."""
    from distributed import as_completed

    if not points:
        return 0
    client = cluster.client
    futures = {client.submit(run_point, p, cluster.workers, run_id,
                             key=f"workbench-point-{keys[p.index]}", pure=False): p
               for p in points}
    for future in as_completed(futures):
        point = futures[future]
        try:
            result = future.result()
        except Exception as exc:
            # the task itself could not run (a worker died, …): reported, not stored, so
            # that the next run tries again
            rows[point.index] = json.loads(json.dumps(
                failure_row(point, exc, workers=cluster.workers, run_id=run_id),
                default=json_default))
        else:
            rows[point.index] = store_row(points_dir, keys[point.index], point, result)
        future.release()
        bar.update(1)
    return len(points)


_UNSTABLE = re.compile(r"(_ms|_s)(_min|_max|_lo|_hi)?$")


def stable_row(row: dict) -> dict:
    """``row`` without what differs between equal runs: times (columns ending in ``_ms`` or
    ``_s``, with their ``_min``/``_max`` and their interval's ``_lo``/``_hi``) and
    ``run_id``."""
    return {k: v for k, v in row.items() if k != "run_id" and not _UNSTABLE.search(k)}


def _columns(rows: list[dict]) -> list[str]:
    columns = table_columns(rows)
    return [c for c in columns if c != "error"] + (["error"] if "error" in columns else [])


def write_results(config: SweepConfig, rows: list[dict], out: Path, renderer: str, *,
                  timed: bool = True) -> None:
    """``table.csv``, ``table.md`` and ``pareto.png`` of ``rows`` in ``out`` (refused, as a
    ValueError, where ``out`` is a symbolic link or not a folder)."""
    title = f"Sweep {config.name} ({renderer})"
    out = output_folder(out)
    write_table(rows, out, "table", columns=_columns(rows), title=title)
    save_pareto(out / "pareto.png", rows, time_column="wall_ms" if timed else "point_ms",
                metric=config.metric, title=f"sweep {config.name} on {renderer}",
                reference=config.reference)
