"""Sweeps on real Dask clusters (local worker processes, and a scheduler and workers started as
separate processes): the table, the per-point cache, resume after SIGKILL, failing points and
refused configs. Scenes are tiny (semicylinders:4 at 64 × 48 pixels)."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import workbench.scene.readers as scene_readers
from workbench.output.tables import read_table
from workbench.results.store import ResultsStore
from workbench.sweep import (
    Point,
    glsl_folder,
    grid_points,
    load_config,
    point_key,
    point_sources,
    run_sweep,
    simplified_scene,
    stable_row,
)

SWEEP = [sys.executable, "-m", "workbench.cli.sweep"]
# 4 scenes x 2 paths x 2 band counts: enough points that a kill lands mid-run
SMALL = """
    name = "small"
    repeats = 5
    reference = "pixel_color"

    [grid]
    scene = ["semicylinders:4", "semicylinders:5", "semicylinders:6", "semicylinders:7"]
    path = ["vertex_color", "pixel_color"]
    bands = [0, 4]
    field = "distance"
    size = "64x48"
"""


def write_config(folder: Path, text: str, name: str = "sweep.toml") -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


def stable_table(out: Path) -> list[dict]:
    return [stable_row(r) for r in read_table(out / "table.csv")]


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The SMALL config run once on a 2-process LocalCluster: (config path, out dir, result)."""
    folder = tmp_path_factory.mktemp("small")
    config_path = write_config(folder, SMALL)
    out = folder / "out"
    result = run_sweep(load_config(config_path), out, workers=2, progress=False)
    return config_path, out, result


@pytest.mark.slow
def test_sweep_on_local_cluster(small):
    _, out, result = small
    assert (result.computed, result.cached, result.failed) == (16, 0, 0)
    rows = read_table(out / "table.csv")
    assert [r["point"] for r in rows] == list(range(16))
    assert [(r["scene"], r["path"], r["bands"]) for r in rows[:4]] == [
        ("semicylinders:4", "vertex_color", 0), ("semicylinders:4", "vertex_color", 4),
        ("semicylinders:4", "pixel_color", 0), ("semicylinders:4", "pixel_color", 4)]
    for row in rows:
        assert row["workers"] == 2 and row["host"] and not row.get("error")
        assert row["wall_ms"] > 0 and row["repeats"] == 5 and row["renderer"] == result.renderer
        if row["path"] == "pixel_color":
            assert row["mean_diff_255"] == 0 and row["max_diff_255"] == 0
    banded = [r for r in rows if r["path"] == "vertex_color" and r["bands"] == 4]
    assert all(r["mean_diff_255"] > 0 and r["share_differing"] > 0 for r in banded)
    assert (out / "table.md").read_text().startswith("# Sweep small")
    assert (out / "pareto.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(list((out / "points").glob("*.json"))) == 16


@pytest.mark.slow
def test_rerun_comes_from_cache(small):
    config_path, out, first = small
    before = {p.name: p.stat().st_mtime_ns for p in (out / "points").glob("*.json")}
    again = run_sweep(load_config(config_path), out, workers=2, progress=False)
    assert (again.computed, again.cached, again.failed) == (0, 16, 0)
    assert {p.name: p.stat().st_mtime_ns for p in (out / "points").glob("*.json")} == before
    assert [stable_row(r) for r in again.rows] == [stable_row(r) for r in first.rows]
    assert {r["run_id"] for r in again.rows} == {first.run_id}
    assert again.summary == "sweep small: 16 points, 0 computed, 16 from cache, 0 failed"


@pytest.mark.slow
def test_resume_after_sigkill(small, tmp_path):
    config_path, clean_out, _ = small
    out = tmp_path / "killed"
    points = out / "points"
    proc = subprocess.Popen([*SWEEP, str(config_path), "--out", str(out), "--workers", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while not list(points.glob("*.json")) and proc.poll() is None:
            assert time.monotonic() < deadline, "no point finished within 2 minutes"
            time.sleep(0.005)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    finished = {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in points.glob("*.json")}
    assert 1 <= len(finished) < 16 and not (out / "table.csv").exists()
    resumed = subprocess.run([*SWEEP, str(config_path), "--out", str(out), "--workers", "2"],
                             capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert resumed.stdout.splitlines()[-1] == (
        f"sweep small: 16 points, {16 - len(finished)} computed, {len(finished)} from cache, "
        f"0 failed")
    for name, stamp in finished.items():
        path = points / name
        assert (path.stat().st_ino, path.stat().st_mtime_ns) == stamp, f"{name} was recomputed"
    assert stable_table(out) == stable_table(clean_out)


def test_point_key_follows_the_shaders_a_path_loads(tmp_path):
    config = load_config(write_config(tmp_path, """
        [grid]
        scene = "semicylinders:4"
        path = ["vertex_color", "gouraud"]
        field = "distance"
    """))
    vertex, gouraud = grid_points(config)
    glsl = tmp_path / "glsl"
    shutil.copytree(glsl_folder(), glsl)
    keys = {p.path: point_key(p, "llvmpipe") for p in (vertex, gouraud)}
    assert all(point_key(p, "llvmpipe", glsl_dir=glsl) == keys[p.path] for p in (vertex, gouraud))
    assert point_key(vertex, "llvmpipe") == keys["vertex_color"]  # deterministic
    assert point_key(vertex, "another renderer") != keys["vertex_color"]
    assert "glsl/vertex_color.vert.glsl" in point_sources(vertex)
    assert "glsl/vertex_color.vert.glsl" not in point_sources(gouraud)
    assert "workbench/paths/base.py" in point_sources(gouraud)
    # the code that makes the scene is part of the key: the generator, not the readers
    assert "workbench/scene/generators/cylinders.py" in point_sources(gouraud)
    assert "workbench/scene/generators/__init__.py" in point_sources(gouraud)
    readers = {f"workbench/scene/readers/{p.name}"
               for p in Path(scene_readers.__file__).parent.glob("*.py")}
    assert {"workbench/scene/readers/keyword.py", "workbench/scene/readers/cards.py"} <= readers
    assert not readers & set(point_sources(gouraud))
    deck = Point(index=0, scene=str(tmp_path / "plate.k"), path="gouraud", options={})
    assert readers | {"workbench/scene/solids.py"} <= set(point_sources(deck))

    shader = glsl / "vertex_color.vert.glsl"
    shader.write_text(shader.read_text() + "\n// changed\n")
    assert point_key(vertex, "llvmpipe", glsl_dir=glsl) != keys["vertex_color"]
    assert point_key(gouraud, "llvmpipe", glsl_dir=glsl) == keys["gouraud"]
    included = glsl / "headlight.glsl"  # #included by the lit shaders of both paths
    included.write_text(included.read_text() + "\n// changed\n")
    assert point_key(gouraud, "llvmpipe", glsl_dir=glsl) != keys["gouraud"]

    quick = grid_points(config, quick=True)[0]
    assert point_key(quick, "llvmpipe") != keys["vertex_color"]


@pytest.mark.slow
def test_failing_point_is_recorded_and_exit_status_is_1(tmp_path, session_results_store):
    config_path = write_config(tmp_path, """
        name = "failing"
        repeats = 5
        [grid]
        scene = ["semicylinders:4", "spacetime:radial:4"]
        path = "pixel_color"
        field = ["distance", "no_such_field"]
        size = "64x48"
    """)
    out = tmp_path / "out"
    done = subprocess.run([*SWEEP, str(config_path), "--out", str(out), "--workers", "2"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 1, done.stderr
    assert done.stdout.splitlines()[-1] == ("sweep failing: 4 points, 4 computed, "
                                            "0 from cache, 3 failed")
    rows = read_table(out / "table.csv")
    assert rows[0]["error"] is None and rows[0]["wall_ms"] > 0
    assert rows[1]["error"].startswith("KeyError: ") and "no_such_field" in rows[1]["error"]
    assert rows[2]["error"] == ("ValueError: path 'pixel_color' draws mesh scenes; "
                                "'spacetime:radial:4' is a spacetime scene")
    assert all("\n" not in r["error"] for r in rows[1:])
    stored = [json.loads(p.read_text())["row"] for p in (out / "points").glob("*.json")]
    assert sum(1 for r in stored if r.get("error")) == 3  # failures are cached too
    # the computed points went to the results store too, under the sweep's run
    store = ResultsStore(session_results_store)
    recorded = store.query("SELECT run_id, error, wall_ms FROM rows "
                           "WHERE experiment = 'sweep:failing'").to_pylist()
    assert len(recorded) == 4 and sum(1 for r in recorded if r["error"]) == 3
    assert {r["run_id"] for r in recorded} == {r["run_id"] for r in rows}


def test_unknown_grid_key_is_refused_before_anything_runs(tmp_path):
    config_path = write_config(tmp_path, """
        [grid]
        scene = "semicylinders:4"
        path = ["gouraud", "spacetime_pixel"]
        bandz = [1, 2]
    """)
    out = tmp_path / "out"
    done = subprocess.run([*SWEEP, str(config_path), "--out", str(out)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "'bandz'" in done.stderr
    assert done.stderr.startswith(f"workbench: error: {config_path}: ")
    assert not out.exists()


def test_options_go_only_to_the_paths_that_take_them(tmp_path):
    config = load_config(write_config(tmp_path, """
        [grid]
        scene = "semicylinders:4"
        path = ["gouraud", "spacetime_pixel"]
        bands = [0, 4]
        edge_overdraw = ["none", "skirts"]
        clip_planes = [[], [[0, 0, 1, 0]]]
        view = [0, 90]
    """))
    points = grid_points(config)
    assert [(p.path, p.options) for p in points] == [
        ("gouraud", {"bands": 0, "clip_planes": ()}),
        ("gouraud", {"bands": 0, "clip_planes": ((0, 0, 1, 0),)}),
        ("gouraud", {"bands": 4, "clip_planes": ()}),
        ("gouraud", {"bands": 4, "clip_planes": ((0, 0, 1, 0),)}),
        ("spacetime_pixel", {"edge_overdraw": "none"}),
        ("spacetime_pixel", {"edge_overdraw": "skirts"}),
    ]
    assert all(p.view == (0.0, 90.0) for p in points)


@pytest.mark.parametrize("text, message", [
    ('[grid]\nscene = "semicylinders:4"\npath = "no_such_path"', "unknown path 'no_such_path'"),
    ('[grid]\nscene = "no_such_scene"\npath = "gouraud"', "scene 'no_such_scene'"),
    ('[grid]\nscene = "semicylinders:4"\npath = "gouraud"\nbands = -1', "bands"),
    ('[grid]\nscene = "semicylinders:4"\npath = "gouraud"\nsize = "64by48"', "'size'"),
    ('repeats = 3\n[grid]\nscene = "semicylinders:4"\npath = "gouraud"', "repeats"),
    ('colour = 1\n[grid]\nscene = "semicylinders:4"\npath = "gouraud"', "'colour'"),
    ('[grid]\nscene = "semicylinders:4"\npath = "gouraud"\nsimplifier = "magic"', "'magic'"),
])
def test_bad_configs_are_refused_naming_file_and_key(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ValueError) as info:
        load_config(path)
    assert str(info.value).startswith(f"{path}: ") and message in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.slow
def test_on_a_scheduler_and_workers_started_apart(tmp_path):
    config_path = write_config(tmp_path, """
        name = "remote"
        repeats = 5
        reference = "pixel_color"
        [grid]
        scene = "semicylinders:4"
        path = ["vertex_color", "pixel_color"]
        bands = [0, 4]
        field = "distance"
        size = "64x48"
    """)
    from clusters import scheduler_and_workers
    from distributed import Client

    with scheduler_and_workers(tmp_path) as address:
        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=60)
        out = tmp_path / "out"
        result = run_sweep(load_config(config_path), out, scheduler=address, progress=False)
    assert (result.computed, result.failed, result.workers) == (4, 0, 2)
    rows = read_table(out / "table.csv")
    assert all(r["workers"] == 2 and r["host"] and r["wall_ms"] > 0 for r in rows)
    # each worker pinned to one EGL device of its host, round-robin, and every row says which
    from workbench.gl.devices import egl_devices

    identities = [d.identity for d in egl_devices()]
    pinned = [result.devices[a] for a in sorted(result.devices)]
    assert pinned == [identities[i % len(identities)] for i in range(2)]
    assert {r["egl_device"] for r in rows} <= set(pinned)
    assert [r["mean_diff_255"] > 0 for r in rows] == [True, True, False, False]


def test_simplification_point_on_the_semicylinders():
    from workbench.scene.builtin import load_scene

    mesh = load_scene("semicylinders:6")
    point = Point(index=0, scene="semicylinders:6", path="gouraud", simplifier="ours",
                  tolerance=2.0)
    simplified, columns = simplified_scene(mesh, point)
    assert columns["triangles_before"] == 8 * 6 * 6 * 2
    assert 0 < columns["triangles_after"] == len(simplified.elements) < columns["triangles_before"]
    assert 0 <= columns["hausdorff_lower_mm"] <= columns["hausdorff_mm"]
    assert columns["hausdorff_pct_diag"] < 2.0  # within the tolerance of the largest part
    none, same = simplified_scene(mesh, Point(index=0, scene="semicylinders:6", path="gouraud",
                                              simplifier="none"))
    assert none is mesh and same["hausdorff_lower_mm"] == 0


def test_car_decimation_config_is_valid_and_simplifies_the_car(car):
    root = Path(__file__).resolve().parents[2]
    config = load_config(root / "sweeps" / "car_decimation.toml")
    points = grid_points(config, quick=True)
    assert config.metric == "hausdorff_pct_diag" and {p.scene for p in points} == {"car"}
    assert sum(p.simplifier == "none" for p in points) == 1  # tolerance means nothing there
    ours = next(p for p in points if p.simplifier == "ours")
    simplified, columns = simplified_scene(car, ours)
    assert len(simplified.elements) == columns["triangles_after"]
    assert columns["triangles_after"] < columns["triangles_before"] == len(car.triangles)
    assert 0 < columns["hausdorff_lower_mm"] <= columns["hausdorff_mm"]


@pytest.mark.slow
def test_quadrisection_sweep_brings_per_vertex_closer_to_per_pixel(tmp_path):
    """st2005 §4.2 on a spacetime scene: splitting the polygons lowers the per-vertex error
    against the per-pixel image of the unsplit slice; a mesh scene refuses the key."""
    config = write_config(tmp_path, """
        name = "quadrisection"
        timed = false
        reference = "spacetime_pixel"

        [grid]
        scene = "spacetime:radial:5"
        path = "spacetime_vertex"
        quadrisection = [4.0, 0.25, 0.0625]
        height_scale = 800.0
        size = "96x96"
    """)
    result = run_sweep(load_config(config), tmp_path / "out", workers=1, progress=False)
    assert result.failed == 0
    rows = sorted(result.rows, key=lambda r: -r["quadrisection"])
    polygons = [r["polygons"] for r in rows]
    errors = [r["mean_diff_255"] for r in rows]
    assert polygons[0] < polygons[1] < polygons[2]
    assert errors[2] < 0.75 * errors[0]
    mesh_config = write_config(tmp_path, """
        [grid]
        scene = "semicylinders:4"
        path = "gouraud"
        quadrisection = 0.5
        size = "32x32"
    """, name="mesh.toml")
    result = run_sweep(load_config(mesh_config), tmp_path / "mesh", workers=1, progress=False)
    assert result.failed == 1 and "spacetime" in result.rows[0]["error"]


def test_a_point_drawn_by_the_software_rasterizer(ctx):
    """``rasterizer = "software"`` draws the path on the CPU; its key and sources differ from
    the GL point's, its image is compared with the GL reference path."""
    from workbench.sweep import measured_columns, point_sources

    options = dict(field="distance", bands=6)
    common = dict(index=0, scene="semicylinders:8", path="pixel_color", options=options,
                  reference="pixel_color", reference_options=options, timed=False)
    soft, gl = Point(**common, rasterizer="software"), Point(**common)
    assert point_key(soft, "r") != point_key(gl, "r")
    assert "workbench/algo/softraster/pipeline.py" in point_sources(soft)
    assert "workbench/algo/softraster/pipeline.py" not in point_sources(gl)
    row = measured_columns(soft, ctx)
    assert row["renderer"].startswith("software rasterizer")
    assert row["share_differing"] <= 0.005
    assert soft.columns()["rasterizer"] == "software" and gl.columns()["rasterizer"] == "gl"


def test_es2008_views_config_is_valid():
    root = Path(__file__).resolve().parents[2]
    config = load_config(root / "sweeps" / "es2008_views.toml")
    points = grid_points(config, quick=True)
    assert {p.rasterizer for p in points} == {"software", "gl"}
    assert len({p.view for p in points}) == 8 and len(points) == 16
    # every grid key is a column: no two points' rows look alike
    rows = [p.columns() for p in points]
    assert all({"rasterizer", "view", "samples"} <= set(r) for r in rows)
    assert len({tuple((k, v) for k, v in r.items() if k != "point") for r in rows}) == 16
    assert rows[0]["view"] == "[0.0,0.0]" and {r["rasterizer"] for r in rows} == {"software", "gl"}
