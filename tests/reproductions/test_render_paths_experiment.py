"""The render_paths experiment end to end: tables, figures and what they must show.

Every test on ``result`` runs at the tiny size (seconds) and, marked slow, on the quick run
(minutes); the tiny run must write every table and column the quick run writes. What holds only
at the quick sizes is tested on the quick run alone.
"""

import pytest
from declared import assert_declared_tables

import workbench.data
from workbench.experiment.registry import discover, run_experiment
from workbench.output.tables import read_table

SEMICYLINDERS = {"tiny": "semicylinders n=4", "quick": "semicylinders n=64"}


@pytest.fixture(scope="module")
def runs(car_deck, experiment_run):
    """size → (size, rows, out_dir), each size run once per session."""
    return lambda size: (size, *experiment_run("render_paths", size))


@pytest.fixture(scope="module", params=["tiny", pytest.param("quick", marks=pytest.mark.slow)])
def result(request, runs):
    return runs(request.param)


@pytest.fixture
def quick(runs):
    return runs("quick")


def test_every_path_is_measured_on_both_scenes(result):
    _, rows, _ = result
    scenes = {r["scene"] for r in rows}
    assert len(scenes) == 2
    for scene in scenes:
        cases = {r["case"] for r in rows if r["scene"] == scene}
        assert {"position", "flat", "gouraud", "gouraud + wire", "pixel smooth", "vertex smooth",
                "pixel bands", "vertex bands", "pixel bands + clip", "pixel bands, 4x MSAA",
                "pyrender (EGL)", "pyvista/VTK (EGL)"} <= cases
    for r in rows:
        assert r["renderer"] and r["wall_ms"] > 0 and r["triangles"] > 0


def test_per_vertex_colour_is_compared_with_per_pixel(result):
    _, rows, _ = result
    for r in (r for r in rows if r["case"].startswith("vertex")):
        assert r["reference"].startswith("pixel")
        assert 0 < r["share_differing"] < 1


@pytest.mark.slow
def test_per_vertex_colour_is_close_to_per_pixel(quick):
    _, rows, _ = quick
    for r in (r for r in rows if r["case"].startswith("vertex")):
        assert r["reference"].startswith("pixel")
        assert 0 < r["share_differing"] < 1 and r["ssim"] > 0.9


def test_pyrender_draws_a_like_for_like_image(result):
    _, rows, _ = result
    for r in (r for r in rows if r["case"] == "pyrender (EGL)"):
        assert r["reference"] == "gouraud, 4x MSAA" and r["ssim"] >= 0.9


def test_pyvista_draws_a_like_for_like_image(result):
    _, rows, _ = result
    vtk_rows = [r for r in rows if r["case"] == "pyvista/VTK (EGL)"]
    assert len(vtk_rows) == 2
    for r in vtk_rows:
        gouraud = next(g for g in rows if g["scene"] == r["scene"]
                       and g["case"] == "gouraud, 4x MSAA")
        assert r["path"] == "pyvista" and r["samples"] == 4
        assert r["reference"] == "gouraud, 4x MSAA" and r["ssim"] >= 0.9
        assert (r["triangles"], r["vertices"]) == (gouraud["triangles"], gouraud["vertices"])
        assert r["wall_over_ours"] == pytest.approx(
            r["wall_ms"] / (gouraud["wall_ms"] + gouraud["readback_ms"]))
        assert r["peer_version"].startswith("VTK 9") and "two-sided" in r["lighting"]


def test_time_steps_upload_coordinates_not_topology(result):
    _, rows, _ = result
    car = next(r for r in rows if r["scene"] == "car" and r["case"] == "pixel bands")
    # per step: float32 positions and normals of every drawn vertex, plus the field values
    assert car["bytes_per_step"] == car["vertices"] * (12 + 12 + 4)
    assert car["bytes_per_step"] < car["bytes_uploaded"]


def test_tables_and_figures_are_written(result):
    _, rows, out_dir = result
    assert len(read_table(out_dir / "table.csv")) == len(rows)
    assert (out_dir / "table.md").read_text().count("\n| ") >= len(rows)
    assert len(read_table(out_dir / "targets.csv")) == 2
    for name in ("car_bands_wire.png", "car_vertex_vs_pixel.png", "semicylinders_bands_wire.png",
                 "car_pyvista.png", "semicylinders_pyvista.png"):
        assert (out_dir / name).stat().st_size > 1000


CASES = {"position", "flat", "gouraud", "gouraud + wire", "pixel smooth", "vertex smooth",
         "pixel bands", "vertex bands", "pixel bands + wire", "pixel transfer (hide low 30 %)",
         "pixel bands + clip", "element flat", "pixel bands, deformation x3",
         "gouraud, 4x MSAA", "pixel bands, 4x MSAA", "pyrender (EGL)", "pyvista/VTK (EGL)"}


def test_every_table_with_every_declared_column_and_kind_of_row(result):
    _, rows, out_dir = result
    assert_declared_tables("render_paths", out_dir)
    assert {r["case"] for r in rows} == CASES


@pytest.mark.parametrize("size", ["tiny", pytest.param("quick", marks=pytest.mark.slow)])
def test_without_the_shared_data_the_car_is_skipped_with_a_message(size, tmp_path, monkeypatch):
    discover()
    monkeypatch.setattr(workbench.data, "shared_data_dir", lambda: None)
    messages = []
    rows, out_dir = run_experiment("render_paths", figures_root=tmp_path, size=size,
                                   progress=messages.append)
    assert {r["scene"] for r in rows} == {SEMICYLINDERS[size]}
    assert any("car skipped" in m for m in messages)
    assert len(read_table(out_dir / "targets.csv")) == 1
