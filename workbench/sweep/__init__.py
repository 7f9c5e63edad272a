"""Sweeps: a TOML grid of scenes × paths × options, run on Dask, cached point by point.

A config::

    name = "bands_vertex_pixel"     # default: the file's stem
    repeats = 7                     # timed draws per point (>= 5; --quick lowers it to 5)
    reference = "pixel_color"       # optional: the path whose image gives the
                                    # image-difference columns
    timed = true                    # false: every point draws once, untimed (error-only)
    metric = "mean_diff_255"        # optional: the error plotted in pareto.png

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
``wireframe``, ``strips``, ``clip_planes``, ``fepatch``, ``edge_overdraw`` …). The sweep runs
the Cartesian product in the order the keys are written, the last key varying fastest. A key
that no path of the grid takes is refused before anything runs.

**Options only some paths take** go to those paths only, and only those appear in their rows;
the other paths' points are the same for every value of such a key and are run once (the first
of the equal points keeps its place in the grid).

**Values that are sequences** (``view``, ``value_range``, ``hide_range``, ``base_color``,
``wire_color``: a list of numbers; ``clip_planes``: a list of planes, each [a, b, c, d]) are one
value when written as such; a list of them sweeps them.

**Simplification**: ``simplifier`` names "ours"
(:func:`workbench.algo.simplify.hausdorff_decimate`), a reference simplifier of
:mod:`workbench.references.simplifiers` ("pymeshlab quadric", "open3d quadric",
"meshoptimizer simplify", "libigl qslim", "libigl decimate") or "none";
``tolerance`` is in % of each part's bounding-sphere diameter (default 0.5), and the reference
simplifiers aim at the triangle count ours reaches at that tolerance.

**Quadrisection** (st2005 §4.2): ``quadrisection`` splits a spacetime scene's polygons down to
that fraction of their mean area before they are drawn (``polygons`` records how many); the
reference image is drawn from the unsplit scene. Such a point simplifies
the scene, measures the certified one-sided Hausdorff distance original → simplified and draws
the simplified mesh (see :func:`workbench.sweep.points.simplified_scene`).

**Error**: with ``reference``, every point's image is compared with the reference path's image
of the same (unsimplified) scene and options (``max_diff_255``, ``mean_diff_255`` in 1/255,
``share_differing``, ``psnr_db``, ``ssim``); ``metric`` picks the one plotted
(default ``hausdorff_pct_diag`` when the grid simplifies, else ``mean_diff_255``).

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
[--untimed]`` (or ``python -m workbench.cli.sweep CONFIG.toml …``); the default DIR is
``figures/sweeps/<name>``. Exit status 1 when a point failed, 2 for bad input.
"""

from .cache import cached_row, store_row
from .config import SweepConfig, grid_points, load_config, parse_size
from .pareto import pareto_front, save_pareto
from .points import (
                     NO_SIMPLIFIER,
                     OURS,
                     Point,
                     failure_row,
                     measured_columns,
                     run_point,
                     simplified_scene,
                     simplifier_names,
)
from .run import SweepResult, run_sweep, stable_row, write_results
from .sources import glsl_folder, point_key, point_sources, scene_digest

__all__ = ["NO_SIMPLIFIER", "OURS", "Point", "SweepConfig", "SweepResult", "cached_row",
           "failure_row", "glsl_folder", "grid_points", "load_config", "measured_columns",
           "pareto_front", "parse_size", "point_key", "point_sources", "run_point", "run_sweep",
           "save_pareto", "scene_digest", "simplified_scene", "simplifier_names", "stable_row",
           "store_row", "write_results"]
