"""The fig_pixel_exact experiment (st2005) end to end in its quick form: what its tables show."""

import pytest

from workbench.experiment.registry import discover, run_experiment
from workbench.experiment.tables import read_table


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    discover()
    root = tmp_path_factory.mktemp("figures")
    rows, out_dir = run_experiment("fig_pixel_exact", figures_root=root, quick=True)
    return rows, out_dir


def test_every_table_and_figure_is_written(result):
    _, out_dir = result
    for name in ("table", "slicing", "sweep", "stability"):
        assert (out_dir / f"{name}.csv").is_file() and (out_dir / f"{name}.md").is_file()
    for name in ("fig3_bar", "fig5_slice", "fig5_crop", "fig5_colorbar", "fig4_cracks",
                 "fig8_height", "sweep"):
        assert (out_dir / f"{name}.png").stat().st_size > 10_000


def test_per_pixel_is_exact_off_element_boundaries_and_per_vertex_is_not(result):
    rows, _ = result
    sizes = sorted({r["target_polygons"] for r in rows})
    assert sizes == [1_000, 10_000, 100_000]
    for size in sizes:
        by = {(r["path"], r["edge_overdraw"], r["element_store"]): r
              for r in rows if r["target_polygons"] == size}
        assert len(by) == 2 * 5
        assert 0.5 * size < by[("per_pixel", "none", "buffer")]["polygons"] < 2 * size
        pixel, vertex = by[("per_pixel", "none", "buffer")], by[("per_vertex", "none", "buffer")]
        assert pixel["share_over_1"] <= 0.001  # the 99.9 % target
        # off element edges: within 1/255 up to float32 arithmetic
        assert pixel["err_max_off_edges"] < 1.1
        assert pixel["share_over_1_off_edges"] <= pixel["share_over_1"]
        assert pixel["uncovered"] == 0
        assert vertex["share_over_1"] > 10 * pixel["share_over_1"]
        assert vertex["err_mean"] > pixel["err_mean"]
        # lines and skirts behind the fill leave every polygon pixel as it was
        for mode in ("behind", "skirts"):
            assert by[("per_pixel", mode, "buffer")]["err_max"] == pixel["err_max"]
        # the paper's texture rectangle holds the same numbers
        assert by[("per_pixel", "none", "texture")]["err_max"] == pixel["err_max"]
        assert by[("per_pixel", "over", "buffer")]["crack_pixels"] <= pixel["crack_pixels"]
        # skirts close every crack, however coarse the slice and wide the jumps
        if size <= 10_000:
            assert pixel["crack_pixels"] > 50
        assert by[("per_pixel", "skirts", "buffer")]["crack_pixels"] == 0
        assert by[("per_vertex", "skirts", "buffer")]["crack_pixels"] == 0


def test_slicing_sweep_and_stability_rows(result):
    _, out_dir = result
    (slicing,) = read_table(out_dir / "slicing.csv")
    assert slicing["tets"] > 50_000 and slicing["last_slice_area_error"] < 1e-9
    assert slicing["incremental_ms_median"] > 0
    sweep = read_table(out_dir / "sweep.csv")
    quad = [r for r in sweep if r["sweep"] == "quadrisection" and r["path"] == "per_vertex"]
    assert quad[-1]["polygons"] > 4 * quad[0]["polygons"]
    assert quad[-1]["err_mean"] < quad[0]["err_mean"]  # finer polygons, better per-vertex colour
    res = [r for r in sweep if r["sweep"] == "resolution" and r["path"] == "per_pixel"]
    assert res[-1]["fit_U_err_max"] < res[0]["fit_U_err_max"]  # the fit converges
    stability = {r["case"]: r for r in read_table(out_dir / "stability.csv")}
    near = stability["at the origin"]
    far = stability["10^4 element sizes away, relative upload"]
    glob = stability["10^4 element sizes away, global float32"]
    assert far["err_max_off_edges"] == pytest.approx(near["err_max_off_edges"], abs=1e-6)
    assert glob["err_max_off_edges"] > 1.5 > 1.1 > far["err_max_off_edges"]
    assert glob["f32_global_U_err_rel"] > 100 * glob["f32_local_U_err_rel"]
    for row in stability.values():
        assert row["nan_pixels"] == 0
    flat = stability["slice through the flat front between bands"]
    assert flat["zero_area_polygons"] > 0 and flat["nan_corners"] == 0 and flat["area_error"] < 1e-9
    assert flat["err_max_off_edges"] < 1.1
