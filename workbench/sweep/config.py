"""A sweep's config: the TOML file read and checked (:func:`load_config`, :class:`SweepConfig`)
and the grid's points in order (:func:`grid_points`). The keys a config may hold are described
in :mod:`workbench.sweep`."""

from __future__ import annotations

import itertools
import json
import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .points import NO_SIMPLIFIER, OURS, Point, simplifier_names

TOP_KEYS = ("name", "repeats", "reference", "timed", "metric", "grid")
SWEEP_KEYS = ("scene", "path", "size", "samples", "view", "rasterizer")
RASTERIZERS = ("gl", "software")
SIMPLIFY_KEYS = ("simplifier", "tolerance", "quadrisection")  # preprocessing of the scene
# how deeply nested one value of a sequence-valued key is (a list of numbers: 1)
VALUE_DEPTH = {"view": 1, "value_range": 1, "hide_range": 1, "base_color": 1, "wire_color": 1,
               "clip_planes": 2}
IMAGE_METRICS = ("mean_diff_255", "max_diff_255", "share_differing")
HAUSDORFF_METRICS = ("hausdorff_pct_diag", "hausdorff_lower_mm", "hausdorff_mm")
DEFAULT_SIZE = (400, 300)
DEFAULT_VIEW = (30.0, 25.0)
DEFAULT_REPEATS = 7
QUICK_REPEATS = 5
DEFAULT_TOLERANCE_PCT = 0.5


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


def _check_view(value) -> tuple[float, float]:
    """(azimuth, elevation) in degrees from a two-number list; ValueError for anything else:
    another length, a non-number (true/false included), NaN or an infinity (a camera turned by
    NaN degrees draws nothing)."""
    if (not isinstance(value, (tuple, list)) or len(value) != 2
            or not all(isinstance(a, (int, float)) and not isinstance(a, bool) for a in value)):
        raise ValueError(f"view must be [azimuth, elevation] in degrees, got {value!r}")
    if not all(math.isfinite(a) for a in value):
        raise ValueError(f"view angles must be finite numbers of degrees, got "
                         f"[{value[0]!r}, {value[1]!r}]")
    return float(value[0]), float(value[1])


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
            v = _check_view(v)
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
    a ``view`` that is not two finite angles (NaN and infinities included),
    a grid key that none of the grid's paths takes, option values a path's style refuses,
    ``repeats`` < 5, a ``metric`` the sweep cannot give; OSError for a missing file.
    """
    from ..measurement.timing import MIN_REPEATS
    from ..paths import path_options

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
        return "hausdorff_pct_diag" if simplifies else ("mean_diff_255" if reference else None)
    if metric in IMAGE_METRICS and reference is None:
        raise ValueError(f"{source}: metric {metric!r} needs a reference path")
    if metric in HAUSDORFF_METRICS and not simplifies:
        raise ValueError(f"{source}: metric {metric!r} needs a simplifier or tolerance in [grid]")
    if metric not in IMAGE_METRICS + HAUSDORFF_METRICS:
        raise ValueError(f"{source}: unknown metric {metric!r}; known: "
                         f"{', '.join(IMAGE_METRICS + HAUSDORFF_METRICS)}")
    return metric


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
