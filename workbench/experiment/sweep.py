"""Sweeps: a TOML grid of scenes × paths × options, run on Dask, cached point by point.

A config::

    name = "bands_vertex_pixel"     # default: the file's stem
    repeats = 7                     # timed draws per point (>= 5; --quick lowers it to 5)
    reference = "pixel_color"       # optional: the path whose image gives the diff_* columns
    timed = true                    # false: every point draws once, untimed (error-only)
    metric = "diff_mean_abs"        # optional: the error plotted in pareto.png

    [grid]
    scene = ["semicylinders:16", "semicylinders:32"]
    path = ["vertex_color", "pixel_color"]
    bands = [0, 4, 10]
    field = "distance"              # a scalar is a one-element list
    size = "400x400"

Grid keys: ``scene`` (a built-in scene name or a mesh file), ``path`` (registry names),
``size`` ("WxH" pixels, default 400x300), ``samples`` (MSAA), ``view`` ([azimuth, elevation]
in degrees, default [30, 25]), ``rasterizer`` ("gl", default, or "software": the es2008
rasterizer on the CPU draws the mesh path, orthographic), ``simplifier``, ``tolerance`` and
``quadrisection`` (see below),
and any option of the grid's paths (the fields of their style class: ``bands``, ``field``,
``wireframe``, ``strips``, ``clip_planes``, ``fepatch``, ``edge_overdraw`` …). The sweep runs the Cartesian
product in the order the keys are written, the last key varying fastest. A key that no path of
the grid takes is refused before anything runs.

**Options only some paths take** go to those paths only, and only those appear in their rows;
the other paths' points are the same for every value of such a key and are run once (the first
of the equal points keeps its place in the grid).

**Values that are sequences** (``view``, ``value_range``, ``hide_range``, ``base_color``,
``wire_color``: a list of numbers; ``clip_planes``: a list of planes, each [a, b, c, d]) are one
value when written as such; a list of them sweeps them.

**Simplification**: ``simplifier`` names "ours"
(:func:`workbench.algo.simplify.hausdorff_decimate`), a reference simplifier of
:mod:`workbench.experiment.simplifiers` ("pymeshlab quadric", "open3d quadric",
"meshoptimizer simplify", "libigl qslim", "libigl decimate") or "none";
``tolerance`` is in % of each part's bounding-sphere diameter (default 0.5), and the reference
simplifiers aim at the triangle count ours reaches at that tolerance.

**Quadrisection** (st2005 §4.2): ``quadrisection`` splits a spacetime scene's polygons down to
that fraction of their mean area before they are drawn (``polygons`` records how many); the
reference image is drawn from the unsplit scene. Such a point simplifies
the scene, measures the certified one-sided Hausdorff distance original → simplified and draws
the simplified mesh (see :func:`workbench.experiment.sweep_points.simplified_scene`).

**Error**: with ``reference``, every point's image is compared with the reference path's image
of the same (unsimplified) scene and options (``diff_max_abs``, ``diff_mean_abs`` in 1/255,
``diff_share_differing``, ``diff_psnr``, ``diff_ssim``); ``metric`` picks the one plotted
(default ``hausdorff_pct`` when the grid simplifies, else ``diff_mean_abs``).

**Timing**: timed draws hold the host's draw lock (one at a time per machine); untimed work runs
in parallel. ``timed = false`` (or ``workbench sweep --untimed``) makes every point error-only:
drawn once, no lock, ``wall_ms`` empty, and pareto.png plots ``point_ms`` (the whole point's
wall time on its worker) instead; the local workers then draw with one llvmpipe thread each
(they fill the cores by themselves).

**Cache**: every point's row is stored as ``DIR/points/<key>.json``, ``key`` = :func:`point_key`,
written whole (temporary file, then rename); a rerun or a resume after a kill computes only the
missing points. A point that raises is stored with ``error`` and the sweep goes on; a point
whose task could not run at all (its worker died) is reported with ``error`` but not stored, so
the next run tries it again.

Results: ``DIR/table.csv``, ``DIR/table.md`` (grid order) and ``DIR/pareto.png``.

Run: ``workbench sweep CONFIG.toml [--out DIR] [--workers N] [--scheduler ADDRESS] [--quick]
[--untimed]`` (or ``python -m workbench.experiment.sweep CONFIG.toml …``); the default DIR is
``figures/sweeps/<name>``. Exit status 1 when a point failed, 2 for bad input.
"""

from __future__ import annotations

import hashlib
import inspect
import itertools
import json
import math
import os
import re
import sys
import time
import tomllib
import uuid
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from .sweep_points import (NO_SIMPLIFIER, OURS, Point, failure_row, run_point,
                           simplifier_names)
from .tables import atomic_write_text, table_columns, write_table

__all__ = ["SweepConfig", "SweepResult", "Point", "load_config", "grid_points", "point_key",
           "point_sources", "scene_digest", "glsl_folder", "run_sweep", "stable_row",
           "pareto_front", "save_pareto", "add_sweep_parser", "cmd_sweep"]

TOP_KEYS = ("name", "repeats", "reference", "timed", "metric", "grid")
SWEEP_KEYS = ("scene", "path", "size", "samples", "view", "rasterizer")
RASTERIZERS = ("gl", "software")
SIMPLIFY_KEYS = ("simplifier", "tolerance", "quadrisection")  # preprocessing of the scene
# how deeply nested one value of a sequence-valued key is (a list of numbers: 1)
VALUE_DEPTH = {"view": 1, "value_range": 1, "hide_range": 1, "base_color": 1, "wire_color": 1,
               "clip_planes": 2}
IMAGE_METRICS = ("diff_mean_abs", "diff_max_abs", "diff_share_differing")
HAUSDORFF_METRICS = ("hausdorff_pct", "hausdorff", "hausdorff_upper")
DEFAULT_SIZE = (400, 300)
DEFAULT_VIEW = (30.0, 25.0)
DEFAULT_REPEATS = 7
QUICK_REPEATS = 5
DEFAULT_TOLERANCE_PCT = 0.5
PACKAGE = Path(__file__).resolve().parents[1]
_SHADER_NAME = re.compile(r'"([\w.-]+\.glsl)"')
_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


# ------------------------------------------------------------------------------- config
@dataclass(frozen=True)
class SweepConfig:
    """A validated sweep config: ``name``, ``grid`` (key → list of values, in file order),
    ``repeats``, ``reference`` (path name or None), ``timed``, ``metric`` (the error column
    plotted, or None when the sweep has none) and ``source`` (the file)."""

    name: str
    grid: dict
    repeats: int = DEFAULT_REPEATS
    reference: str | None = None
    timed: bool = True
    metric: str | None = None
    source: Path | None = None


def _nesting(value) -> int:
    """0 for a scalar, 1 + the deepest item's nesting for a list."""
    if not isinstance(value, list):
        return 0
    return 1 + max((_nesting(v) for v in value), default=0)


def _as_tuples(value):
    return tuple(_as_tuples(v) for v in value) if isinstance(value, list) else value


def _grid_values(key: str, raw) -> list:
    """The values one grid entry sweeps: a scalar (or one sequence value) is a one-element list."""
    depth = VALUE_DEPTH.get(key, 0)
    values = list(raw) if _nesting(raw) > depth else [raw]
    return [_as_tuples(v) for v in values]


def parse_size(text) -> tuple[int, int]:
    """(W, H) from "WxH" (positive integers); ValueError otherwise."""
    try:
        w, h = (int(v) for v in str(text).lower().split("x"))
    except ValueError:
        raise ValueError(f"size must be 'WxH', got {text!r}") from None
    if w <= 0 or h <= 0:
        raise ValueError(f"size must be positive, got {text!r}")
    return w, h


def _check_scene(spec) -> str:
    from ..scene.builtin import parse_scene_spec, scene_names

    if not isinstance(spec, str):
        raise ValueError(f"scene must be a name or a file, got {spec!r}")
    if Path(spec).exists() or parse_scene_spec(spec) is not None:
        return spec
    raise ValueError(f"scene {spec!r} is neither a built-in scene ({', '.join(scene_names())}, "
                     f"with ':N' for the sized ones) nor an existing file")


def _check_sweep_values(key: str, values: list) -> list:
    """The values of a sweep-level or simplification key, checked and normalised."""
    from ..paths import PATHS

    out = []
    for v in values:
        if key == "scene":
            v = _check_scene(v)
        elif key == "path":
            if v not in PATHS:
                raise ValueError(f"unknown path {v!r}; known paths: {', '.join(sorted(PATHS))}")
        elif key == "size":
            v = parse_size(v)
        elif key == "samples":
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"samples must be a non-negative integer, got {v!r}")
        elif key == "view":
            if len(v) != 2 or not all(isinstance(a, (int, float)) for a in v):
                raise ValueError(f"view must be [azimuth, elevation] in degrees, got {v!r}")
            v = (float(v[0]), float(v[1]))
        elif key == "rasterizer":
            if v not in RASTERIZERS:
                raise ValueError(f"rasterizer must be one of {', '.join(RASTERIZERS)}, got {v!r}")
        elif key == "simplifier":
            if v not in simplifier_names():
                raise ValueError(f"unknown simplifier {v!r}; known: "
                                 f"{', '.join(repr(s) for s in simplifier_names())}")
        elif key == "quadrisection":
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0:
                raise ValueError(f"quadrisection must be a positive fraction of the mean "
                                 f"polygon area, got {v!r}")
            v = float(v)
        elif key == "tolerance":
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v < 100:
                raise ValueError(f"tolerance must be a percentage in (0, 100), got {v!r}")
            v = float(v)
        out.append(v)
    return out


def _check_top(source: str, data: dict) -> dict:
    for key in data:
        if key not in TOP_KEYS:
            raise ValueError(f"{source}: unknown key {key!r} (known: {', '.join(TOP_KEYS)})")
    grid = data.get("grid")
    if not isinstance(grid, dict) or not grid:
        raise ValueError(f"{source}: a [grid] table with at least 'scene' and 'path' is needed")
    for key in ("scene", "path"):
        if key not in grid:
            raise ValueError(f"{source}: [grid] needs the key {key!r}")
    return grid


def load_config(path) -> SweepConfig:
    """The sweep config in TOML file ``path``, validated (see the module notes).

    Refused with ValueError naming the file and the key: TOML errors, unknown top-level keys,
    a grid without ``scene`` or ``path``, an empty list, an unknown path, scene or simplifier,
    a grid key that none of the grid's paths takes, option values a path's style refuses,
    ``repeats`` < 5, a ``metric`` the sweep cannot give; OSError for a missing file.
    """
    from ..paths import path_options
    from .timing import MIN_REPEATS

    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FileNotFoundError(f"sweep config {path} not found") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML: {exc}") from None
    raw_grid = _check_top(str(path), data)
    grid = {}
    for key, raw in raw_grid.items():
        values = _grid_values(key, raw)
        if not values:
            raise ValueError(f"{path}: grid key {key!r} has an empty list")
        if key in SWEEP_KEYS or key in SIMPLIFY_KEYS:
            try:
                values = _check_sweep_values(key, values)
            except ValueError as exc:
                raise ValueError(f"{path}: grid key {key!r}: {exc}") from None
        grid[key] = values
    known = set(SWEEP_KEYS) | set(SIMPLIFY_KEYS)
    for name in grid["path"]:
        known |= path_options(name)
    for key in grid:
        if key not in known:
            raise ValueError(f"{path}: grid key {key!r} is an option of none of the paths "
                             f"{', '.join(grid['path'])} (and no sweep key)")
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not re.fullmatch(r"[\w.+-]+", name):
        raise ValueError(f"{path}: name must be letters, digits, '.', '+', '-' or '_', "
                         f"got {name!r}")
    repeats = data.get("repeats", DEFAULT_REPEATS)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < MIN_REPEATS:
        raise ValueError(f"{path}: repeats must be an integer >= {MIN_REPEATS}, got {repeats!r}")
    reference = data.get("reference")
    if reference is not None:
        try:
            _check_sweep_values("path", [reference])
        except ValueError as exc:
            raise ValueError(f"{path}: reference: {exc}") from None
    timed = data.get("timed", True)
    if not isinstance(timed, bool):
        raise ValueError(f"{path}: timed must be true or false, got {timed!r}")
    metric = _metric(str(path), data.get("metric"), reference, "simplifier" in grid
                     or "tolerance" in grid)
    config = SweepConfig(name=name, grid=grid, repeats=repeats, reference=reference, timed=timed,
                         metric=metric, source=path)
    try:
        grid_points(config)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{path}: {exc}") from None
    return config


def _metric(source: str, metric, reference, simplifies: bool) -> str | None:
    """The error column plotted: the configured one if the sweep gives it, else the default."""
    if metric is None:
        return "hausdorff_pct" if simplifies else ("diff_mean_abs" if reference else None)
    if metric in IMAGE_METRICS and reference is None:
        raise ValueError(f"{source}: metric {metric!r} needs a reference path")
    if metric in HAUSDORFF_METRICS and not simplifies:
        raise ValueError(f"{source}: metric {metric!r} needs a simplifier or tolerance in [grid]")
    if metric not in IMAGE_METRICS + HAUSDORFF_METRICS:
        raise ValueError(f"{source}: unknown metric {metric!r}; known: "
                         f"{', '.join(IMAGE_METRICS + HAUSDORFF_METRICS)}")
    return metric


# ------------------------------------------------------------------------------- grid
def grid_points(config: SweepConfig, *, quick: bool = False,
                timed: bool | None = None) -> list[Point]:
    """The sweep's points in grid order (the Cartesian product in the order the grid's keys
    are written, the last varying fastest), equal points kept once at the first place.

    ``quick`` loads the smaller built-in scenes and caps ``repeats`` at 5; ``timed`` overrides
    the config's. Refused with ValueError: option values a path's style (or the reference
    path's) refuses, naming the point.
    """
    from ..paths import path_class, path_options

    keys = list(config.grid)
    timed = config.timed if timed is None else timed
    repeats = min(config.repeats, QUICK_REPEATS) if quick else config.repeats
    points, seen = [], set()
    option_keys = [k for k in keys if k not in SWEEP_KEYS and k not in SIMPLIFY_KEYS]
    for combination in itertools.product(*(config.grid[k] for k in keys)):
        values = dict(zip(keys, combination))
        path = values["path"]
        takes = path_options(path)
        options = {k: values[k] for k in option_keys if k in takes}
        reference_options = {}
        if config.reference is not None:
            ref_takes = path_options(config.reference)
            reference_options = {k: values[k] for k in option_keys if k in ref_takes}
        simplifier, tolerance = values.get("simplifier"), values.get("tolerance")
        if simplifier is not None or tolerance is not None:
            simplifier = simplifier or OURS
            tolerance = None if simplifier == NO_SIMPLIFIER else (
                DEFAULT_TOLERANCE_PCT if tolerance is None else tolerance)
        point = Point(index=len(points), scene=values["scene"], path=path, options=options,
                      size=values.get("size", DEFAULT_SIZE), samples=values.get("samples", 0),
                      view=values.get("view", DEFAULT_VIEW), simplifier=simplifier,
                      tolerance=tolerance, quadrisection=values.get("quadrisection"),
                      reference=config.reference,
                      reference_options=reference_options, repeats=repeats, timed=timed,
                      quick=quick, rasterizer=values.get("rasterizer", "gl"))
        identity = json.dumps(point.params(), sort_keys=True)
        if identity in seen:
            continue
        seen.add(identity)
        for name, opts in ((path, options), (config.reference, reference_options)):
            if name is None:
                continue
            try:
                path_class(name).style_class(**opts)
            except (ValueError, TypeError) as exc:
                raise ValueError(f"point {point.index} ({point.scene}, {name} "
                                 f"{json.dumps(opts)}): {exc}") from None
        points.append(point)
    return points


# ------------------------------------------------------------------------------- keys
_DIGESTS: dict[tuple, str] = {}


def _file_digest(path: Path) -> str:
    """sha256 of a file's bytes, cached by path, size and modification time."""
    stat = path.stat()
    memo = (str(path), stat.st_size, stat.st_mtime_ns)
    digest = _DIGESTS.get(memo)
    if digest is None:
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        _DIGESTS[memo] = digest
    return digest


def glsl_folder() -> Path:
    """The folder of the workbench's shaders (the top-level glsl/, shipped as workbench.glsl)."""
    return Path(str(resources.files("workbench.glsl")))


def _shader_files(module_files: list[Path], glsl: Path) -> list[Path]:
    """The shaders named in the modules' source (as "name.glsl" literals) and, transitively,
    those they #include."""
    names = set()
    for module in module_files:
        names |= set(_SHADER_NAME.findall(module.read_text(encoding="utf-8")))
    todo, found = sorted(names), {}
    while todo:
        name = todo.pop()
        if name in found or not (glsl / name).is_file():
            continue
        found[name] = glsl / name
        todo += _INCLUDE.findall(found[name].read_text(encoding="utf-8"))
    return [found[n] for n in sorted(found)]


def point_sources(point: Point, glsl_dir=None) -> dict[str, str]:
    """The source files whose text decides ``point``'s row, name → sha256 of the text: the
    modules of its path and of the reference path, ``paths/base.py``, ``paths/colormap.py``,
    ``experiment/measure.py``, ``experiment/sweep_points.py``, ``experiment/compare.py`` with
    a reference, the decimation, Hausdorff and simplifier modules with a simplifier, the
    modules that make the scene and derive from it (:func:`_scene_modules`), and the
    shaders those path modules name, with their includes, from ``glsl_dir`` (default the
    workbench's glsl folder)."""
    from ..paths import path_class

    glsl = Path(glsl_dir) if glsl_dir is not None else glsl_folder()
    paths = [point.path] + ([point.reference] if point.reference else [])
    modules = {Path(inspect.getsourcefile(path_class(name))).resolve() for name in paths}
    base = PACKAGE / "paths" / "base.py"
    shaders = _shader_files(sorted(modules | {base}), glsl)
    modules |= {base, *(PACKAGE / "paths" / name for name in (
                    "colormap.py", "mesh.py", "drawdata.py", "style.py", "backends.py")),
                PACKAGE / "experiment" / "measure.py", PACKAGE / "experiment" / "sweep_points.py"}
    if point.reference:
        modules.add(PACKAGE / "experiment" / "compare.py")
    if point.simplifier:
        modules |= {*(PACKAGE / "algo" / "simplify").glob("*.py"),
                    *(PACKAGE / "algo" / "hausdorff").glob("*.py"),
                    PACKAGE / "experiment" / "simplifiers.py"}
    if point.rasterizer == "software":
        modules |= {PACKAGE / "paths" / "software.py",
                    *(PACKAGE / "algo" / "softraster").glob("*.py")}
    modules |= _scene_modules(point.scene)
    sources = {f"workbench/{m.relative_to(PACKAGE).as_posix()}": _file_digest(m)
               for m in sorted(modules)}
    sources.update({f"glsl/{s.name}": _file_digest(s) for s in shaders})
    return sources


def _scene_modules(spec: str) -> set[Path]:
    """The modules that make scene ``spec`` and what the paths derive from it: the spacetime
    builders, the generators or the readers, with the derived-data modules."""
    scene = PACKAGE / "scene"
    modules = {scene / "mesh.py", scene / "derived.py", scene / "needs.py"}
    name = spec.split(":")[0]
    if name == "spacetime" and not Path(spec).is_file():
        return modules | set((PACKAGE / "algo" / "spacetime").glob("*.py"))
    if name in ("semicylinders", "panels") and not Path(spec).is_file():
        return modules | {*(scene / "generators").glob("*.py")}
    return modules | {*(scene / "readers").glob("*.py"), scene / "solids.py"}


def scene_digest(spec: str) -> str | None:
    """sha256 of the scene's file: the mesh file, or the shared data file of ``car`` and
    ``d3plot``; None for a generated scene."""
    from ..data import CAR_DECK, D3PLOT, shared_file

    if Path(spec).is_file():
        return _file_digest(Path(spec).resolve())
    data = {"car": CAR_DECK, "d3plot": D3PLOT}.get(spec)
    found = shared_file(data) if data is not None else None
    return None if found is None else _file_digest(found)


def point_key(point: Point, renderer: str, *, glsl_dir=None) -> str:
    """The content key of ``point`` drawn on ``renderer``: sha256 (hex) over the workbench
    version, :func:`point_sources`, the scene spec and :func:`scene_digest`, the point's
    parameters (quick flag and repeats included) and the renderer string."""
    from .. import __version__

    payload = dict(version=__version__, sources=point_sources(point, glsl_dir),
                   scene=point.scene, scene_file=scene_digest(point.scene),
                   params=point.params(), renderer=renderer)
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


# ------------------------------------------------------------------------------- cache
def _json_default(value):
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"cannot store {type(value).__name__} in a sweep row")


def cached_row(points_dir: Path, key: str) -> dict | None:
    """The stored row of point ``key``, None when absent or unreadable."""
    try:
        with open(points_dir / f"{key}.json", encoding="utf-8") as handle:
            row = json.load(handle).get("row")
    except (FileNotFoundError, ValueError, AttributeError):
        return None
    return row if isinstance(row, dict) else None


def store_row(points_dir: Path, key: str, point: Point, row: dict) -> dict:
    """Write point ``key``'s row (and parameters) whole; returns the row as stored (plain JSON
    values, so computed and cached rows read the same)."""
    text = json.dumps(dict(key=key, params=point.params(), row=row), default=_json_default,
                      indent=1)
    atomic_write_text(points_dir / f"{key}.json", text)
    return json.loads(text)["row"]


# ------------------------------------------------------------------------------- run
@dataclass
class SweepResult:
    """What :func:`run_sweep` did: ``rows`` (grid order, as in the table), ``computed``,
    ``cached`` and ``failed`` point counts, the run's ``run_id``, ``renderer``, ``workers``,
    ``out_dir``, ``skip_ms`` (per cached point: ms to compute its key and read its row) and
    ``compute_s`` (wall seconds from submitting the missing points to storing the last)."""

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
              timed: bool | None = None) -> SweepResult:
    """Run ``config`` (a :class:`SweepConfig` or a config file) on a Dask cluster (a new
    LocalCluster of ``workers`` processes, default one per CPU, or the one at ``scheduler``),
    computing only points not cached in ``out_dir/points``; write ``table.csv``, ``table.md``
    and ``pareto.png`` in ``out_dir``.

    ``quick``: smaller built-in scenes, at most 5 repeats. ``timed`` (default the config's):
    False draws every point once, untimed. ``progress``: a tqdm bar on stderr. A failing point
    is stored with its ``error`` and counted in ``failed``; the sweep goes on.
    """
    from .cluster import sweep_cluster

    if not isinstance(config, SweepConfig):
        config = load_config(config)
    points = grid_points(config, quick=quick, timed=timed)
    out = Path(out_dir)
    points_dir = out / "points"
    points_dir.mkdir(parents=True, exist_ok=True)
    run_id = uuid.uuid4().hex[:12]
    rows: dict[int, dict] = {}
    skip_ms, computed = [], 0
    untimed = not any(p.timed for p in points)
    with sweep_cluster(workers, scheduler, raster_threads=1 if untimed else None) as cluster:
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
        compute_s = time.perf_counter() - start
        renderer, count = cluster.renderer, cluster.workers
    ordered = [rows[p.index] for p in points]
    write_results(config, ordered, out, renderer, timed=points[0].timed if points else True)
    failed = sum(1 for r in ordered if r.get("error"))
    return SweepResult(config.name, ordered, computed, len(points) - computed, failed, run_id,
                       renderer, count, out, skip_ms, compute_s)


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
                default=_json_default))
        else:
            rows[point.index] = store_row(points_dir, keys[point.index], point, result)
        future.release()
        bar.update(1)
    return len(points)


# ------------------------------------------------------------------------------- results
_UNSTABLE = re.compile(r"(_ms|_s)(_min|_max)?$")


def stable_row(row: dict) -> dict:
    """``row`` without what differs between equal runs: times (columns ending in ``_ms`` or
    ``_s``, with their ``_min``/``_max``) and ``run_id``."""
    return {k: v for k, v in row.items() if k != "run_id" and not _UNSTABLE.search(k)}


def _columns(rows: list[dict]) -> list[str]:
    columns = table_columns(rows)
    return [c for c in columns if c != "error"] + (["error"] if "error" in columns else [])


def write_results(config: SweepConfig, rows: list[dict], out: Path, renderer: str, *,
                  timed: bool = True) -> None:
    """``table.csv``, ``table.md`` and ``pareto.png`` of ``rows`` in ``out``."""
    title = f"Sweep {config.name} ({renderer})"
    write_table(rows, out, "table", columns=_columns(rows), title=title)
    save_pareto(out / "pareto.png", rows, time_column="wall_ms" if timed else "point_ms",
                metric=config.metric, title=f"sweep {config.name} on {renderer}",
                reference=config.reference)


def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the non-dominated (time, error) pairs, both minimised, by increasing time:
    a pair is kept when no other is at most as slow and at most as wrong, and better in one."""
    order = sorted(range(len(points)), key=lambda i: points[i])
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def _axis_label(column: str, reference: str | None) -> str:
    against = f" against {reference}" if reference else ""
    return {
        "wall_ms": "wall time per draw (ms, median)",
        "point_ms": "wall time of the whole untimed point (ms)",
        "diff_mean_abs": f"mean absolute difference{against} (1/255)",
        "diff_max_abs": f"largest absolute difference{against} (1/255)",
        "diff_share_differing": f"share of pixels differing{against} (0–1)",
        "hausdorff_pct": "Hausdorff original → simplified (% of diagonal)",
        "hausdorff": "Hausdorff original → simplified (model units)",
        "hausdorff_upper": "Hausdorff original → simplified (model units)",
    }.get(column, column)


def _number(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def save_pareto(path: Path, rows: list[dict], *, time_column: str, metric: str | None,
                title: str, reference: str | None = None) -> Path:
    """Time against error, one colour per path (and one marker per simplifier), the Pareto
    frontier as a step line through the non-dominated points; the time axis is logarithmic
    when it spans more than 10×. Written atomically; a sweep without an error column or
    without plottable points gets a figure saying so."""
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .tables import atomic_write_bytes

    fig = Figure(figsize=(8, 5.5), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    data = [(r, _number(r.get(time_column)), _number(r.get(metric)) if metric else None)
            for r in rows if not r.get("error")]
    data = [(r, x, y) for r, x, y in data if x is not None and x > 0 and y is not None]
    if not data:
        why = "no error column (set reference or sweep a simplifier)" if metric is None \
            else "no point with a time and an error"
        ax.text(0.5, 0.5, why, ha="center", va="center", transform=ax.transAxes)
    else:
        paths = dict.fromkeys(r["path"] for r, _, _ in data)
        colours = {p: f"C{i % 10}" for i, p in enumerate(paths)}
        simplifiers = dict.fromkeys(r.get("simplifier") for r, _, _ in data)
        markers = {s: "osD^v<>ph*"[i % 10] for i, s in enumerate(simplifiers)}
        for (path_name, simplifier), group in itertools.groupby(
                sorted(data, key=lambda d: (d[0]["path"], str(d[0].get("simplifier")))),
                key=lambda d: (d[0]["path"], d[0].get("simplifier"))):
            group = list(group)
            label = path_name if simplifier is None else f"{path_name}, {simplifier}"
            ax.scatter([x for _, x, _ in group], [y for _, _, y in group], s=28,
                       color=colours[path_name], marker=markers[simplifier], label=label,
                       zorder=3)
        front = pareto_front([(x, y) for _, x, y in data])
        fx = [data[i][1] for i in front]
        fy = [data[i][2] for i in front]
        ax.step(fx, fy, where="post", color="black", linewidth=1, zorder=2,
                label="Pareto frontier")
        ax.scatter(fx, fy, s=110, facecolors="none", edgecolors="black", linewidths=1,
                   zorder=4)
        xs = [x for _, x, _ in data]
        if max(xs) > 10 * min(xs):
            ax.set_xscale("log")
        positive = [y for _, _, y in data if y > 0]
        if positive and max(positive) > 100 * min(positive):
            # errors over decades; exact points (error 0) stay visible on a linear stretch
            if len(positive) == len(data):
                ax.set_yscale("log")
            else:
                ax.set_yscale("symlog", linthresh=min(positive))
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    ax.set_xlabel(_axis_label(time_column, None) + (" [log]" if ax.get_xscale() == "log" else ""))
    scale = {"log": " [log]", "symlog": " [symlog]"}
    ax.set_ylabel((_axis_label(metric, reference) if metric else "error")
                  + scale.get(ax.get_yscale(), ""))
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    return atomic_write_bytes(path, buffer.getvalue())


# ------------------------------------------------------------------------------- CLI
def cmd_sweep(args) -> int:
    """``workbench sweep``: run the config, print the summary; 1 when a point failed."""
    config = load_config(args.config)
    out = Path(args.out) if args.out else Path("figures") / "sweeps" / config.name
    try:
        result = run_sweep(config, out, workers=args.workers, scheduler=args.scheduler,
                           quick=args.quick, timed=False if args.untimed else None)
    except KeyboardInterrupt:
        print(f"sweep {config.name}: interrupted; finished points are kept in {out / 'points'}",
              file=sys.stderr)
        return 130
    print(f"{out / 'table.md'}, {out / 'pareto.png'}")
    print(result.summary)
    return 1 if result.failed else 0


def add_sweep_parser(subparsers):
    """Add the ``sweep`` subcommand to an argparse ``subparsers``; returns its parser."""
    p = subparsers.add_parser(
        "sweep", help="run a TOML grid of scenes x paths x options on Dask, cached per point",
        description="Run the Cartesian product of a sweep config's [grid] on a Dask cluster "
                    "(a local one by default), caching each point under DIR/points; write "
                    "DIR/table.csv, DIR/table.md and DIR/pareto.png. Exit status 1 when a "
                    "point failed, 2 for bad input.")
    p.add_argument("config", help="sweep config (TOML)")
    p.add_argument("--out", metavar="DIR", help="output folder (default figures/sweeps/<name>)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the local cluster (default: one per CPU)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the existing Dask cluster at ADDRESS (tcp://host:port)")
    p.add_argument("--quick", action="store_true",
                   help="smaller built-in scenes and at most 5 timed repeats")
    p.add_argument("--untimed", action="store_true",
                   help="draw every point once without timing (error-only, fully parallel)")
    p.set_defaults(func=cmd_sweep)
    return p


def main(argv: list[str] | None = None) -> int:
    """``python -m workbench.experiment.sweep CONFIG …``: the sweep subcommand on its own."""
    import argparse

    parser = argparse.ArgumentParser(prog="workbench")
    add_sweep_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["sweep", *(sys.argv[1:] if argv is None else argv)])
    from ..gl import GLUnavailable

    try:
        return args.func(args)
    except (OSError, ValueError, KeyError, GLUnavailable) as exc:
        if os.environ.get("WORKBENCH_DEBUG"):
            raise
        message = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        print(f"workbench: error: {message}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
