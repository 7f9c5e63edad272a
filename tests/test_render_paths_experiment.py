"""The render_paths experiment end to end in its quick form: tables, figures and what they must show."""

import pytest

from workbench.data import CAR_DECK, shared_file
from workbench.experiment.registry import discover, run_experiment
from workbench.experiment.tables import read_table


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    if shared_file(CAR_DECK) is None:
        pytest.skip("shared car deck not found (set WORKBENCH_DATA)")
    discover()
    root = tmp_path_factory.mktemp("figures")
    rows, out_dir = run_experiment("render_paths", figures_root=root, quick=True)
    return rows, out_dir


def test_every_path_is_measured_on_both_scenes(result):
    rows, _ = result
    scenes = {r["scene"] for r in rows}
    assert len(scenes) == 2
    for scene in scenes:
        paths = {r["path"] for r in rows if r["scene"] == scene}
        assert {"position", "flat", "gouraud", "gouraud + wire", "pixel smooth", "vertex smooth",
                "pixel bands", "vertex bands", "pixel bands + clip", "pixel bands, 4x MSAA",
                "pyrender (EGL)"} <= paths
    for r in rows:
        assert r["renderer"] and r["wall_ms"] > 0 and r["triangles"] > 0


def test_per_vertex_colour_is_compared_with_per_pixel(result):
    rows, _ = result
    for r in (r for r in rows if r["path"].startswith("vertex")):
        assert r["reference"].startswith("pixel")
        assert 0 < r["share_differing"] < 1 and r["ssim"] > 0.9


def test_pyrender_draws_a_like_for_like_image(result):
    rows, _ = result
    for r in (r for r in rows if r["path"] == "pyrender (EGL)"):
        assert r["reference"] == "gouraud, 4x MSAA" and r["ssim"] >= 0.9


def test_time_steps_upload_coordinates_not_topology(result):
    rows, _ = result
    car = [r for r in rows if r["scene"] == "car" and r["path"] == "pixel bands"][0]
    # per step: float32 positions and normals of every drawn vertex, plus the field values
    assert car["bytes_per_step"] == car["vertices"] * (12 + 12 + 4)
    assert car["bytes_per_step"] < car["bytes_uploaded"]


def test_tables_and_figures_are_written(result):
    rows, out_dir = result
    assert len(read_table(out_dir / "table.csv")) == len(rows)
    assert (out_dir / "table.md").read_text().count("\n| ") >= len(rows)
    assert len(read_table(out_dir / "targets.csv")) == 2
    for name in ("car_bands_wire.png", "car_vertex_vs_pixel.png", "semicylinders_bands_wire.png"):
        assert (out_dir / name).stat().st_size > 1000


def test_without_the_shared_data_the_car_is_skipped_with_a_message(tmp_path, monkeypatch):
    import workbench.experiments.render_paths as render_paths

    discover()
    monkeypatch.setattr(render_paths, "shared_file", lambda relative: None)
    messages = []
    rows, out_dir = run_experiment("render_paths", figures_root=tmp_path, quick=True,
                                   progress=messages.append)
    assert {r["scene"] for r in rows} == {"semicylinders n=64"}
    assert any("car skipped" in m for m in messages)
    assert len(read_table(out_dir / "targets.csv")) == 1
