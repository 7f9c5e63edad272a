"""The fig_pixel_exact experiment (st2005) end to end: the shape of its tables and figures at
the tiny size, and what its tables show in its quick form (slow)."""

import pytest
from declared import assert_declared_tables

from workbench.output.tables import read_table

NAME = "fig_pixel_exact"
FIGURES = ("fig3_bar", "fig5_slice", "fig5_crop", "fig5_colorbar", "fig4_cracks", "fig8_height",
           "sweep")


@pytest.fixture(scope="module")
def tiny(experiment_run):
    return experiment_run(NAME, "tiny")


@pytest.fixture(scope="module")
def result(experiment_run):
    return experiment_run(NAME, "quick")


def check_tables_and_figures(out_dir, min_png_bytes: int) -> None:
    assert_declared_tables(NAME, out_dir)
    for name in FIGURES:
        assert (out_dir / f"{name}.png").stat().st_size > min_png_bytes


def check_slice_sizes(rows, sizes: list[int]) -> None:
    """Per pixel is exact off element boundaries and per vertex is not; lines and skirts behind
    the fill leave the polygons' pixels as they were; skirts close every crack."""
    assert sorted({r["target_polygons"] for r in rows}) == sizes
    for size in sizes:
        by = {(r["path"], r["edge_overdraw"], r["element_store"]): r
              for r in rows if r["target_polygons"] == size}
        assert len(by) == 2 * 5
        assert 0.5 * size < by[("per_pixel", "none", "buffer")]["polygons"] < 2 * size
        pixel, vertex = by[("per_pixel", "none", "buffer")], by[("per_vertex", "none", "buffer")]
        assert pixel["share_over_1"] <= 0.001  # the 99.9 % target
        # off element edges: within 1/255 up to float32 arithmetic
        assert pixel["max_diff_255_off_edges"] < 1.1
        assert pixel["share_over_1_off_edges"] <= pixel["share_over_1"]
        assert pixel["uncovered"] == 0
        assert vertex["share_over_1"] > 10 * pixel["share_over_1"]
        assert vertex["mean_diff_255"] > pixel["mean_diff_255"]
        # lines and skirts behind the fill leave every polygon pixel as it was
        for mode in ("behind", "skirts"):
            assert by[("per_pixel", mode, "buffer")]["max_diff_255"] == pixel["max_diff_255"]
        # the paper's texture rectangle holds the same numbers
        assert by[("per_pixel", "none", "texture")]["max_diff_255"] == pixel["max_diff_255"]
        assert by[("per_pixel", "over", "buffer")]["crack_pixels"] <= pixel["crack_pixels"]
        # skirts close every crack, however coarse the slice and wide the jumps
        if size <= 10_000:
            assert pixel["crack_pixels"] > 50
        assert by[("per_pixel", "skirts", "buffer")]["crack_pixels"] == 0
        assert by[("per_vertex", "skirts", "buffer")]["crack_pixels"] == 0


def check_slicing_and_stability(out_dir) -> None:
    """What holds at any size: exact slice areas, no NaN, the relative upload far from the
    origin as good as at it, global float32 coordinates worse."""
    (slicing,) = read_table(out_dir / "slicing.csv")
    assert slicing["last_slice_area_error"] < 1e-9
    assert slicing["incremental_ms_median"] > 0
    stability = {r["case"]: r for r in read_table(out_dir / "stability.csv")}
    near = stability["at the origin"]
    far = stability["10^4 element sizes away, relative upload"]
    glob = stability["10^4 element sizes away, global float32"]
    assert far["max_diff_255_off_edges"] == pytest.approx(near["max_diff_255_off_edges"],
                                                          abs=1e-6)
    assert glob["max_diff_255_off_edges"] > 1.5 > 1.1 > far["max_diff_255_off_edges"]
    assert glob["f32_global_U_err_rel"] > 100 * glob["f32_local_U_err_rel"]
    for row in stability.values():
        assert row["nan_pixels"] == 0
    flat = stability["slice through the flat front between bands"]
    assert flat["zero_area_polygons"] > 0 and flat["nan_corners"] == 0 and flat["area_error"] < 1e-9
    assert flat["max_diff_255_off_edges"] < 1.1


# ------------------------------------------------------------------------------- tiny size
def test_tiny_run_writes_every_table_with_its_declared_columns(tiny):
    _, out_dir = tiny
    check_tables_and_figures(out_dir, min_png_bytes=10_000)
    sweep = read_table(out_dir / "sweep.csv")
    assert {(r["sweep"], r["path"]) for r in sweep} == {
        (s, p) for s in ("quadrisection", "resolution") for p in ("per_vertex", "per_pixel")}


def test_tiny_per_pixel_is_exact_off_element_boundaries_and_per_vertex_is_not(tiny):
    rows, _ = tiny
    check_slice_sizes(rows, [1_000])


def test_tiny_slicing_and_stability_rows(tiny):
    check_slicing_and_stability(tiny[1])


def test_tiny_interleaved_ratio_carries_its_interval(tiny):
    (row,) = read_table(tiny[1] / "interleaved.csv")
    name = "per_pixel_over_per_vertex"
    assert row[f"{name}_lo"] <= row[name] <= row[f"{name}_hi"] and row[f"{name}_pairs"] >= 5
    assert row["per_pixel_ms"] > 0 and row["per_vertex_ms"] > 0 and row["target_polygons"] == 1000


# ------------------------------------------------------------------------------ quick size
@pytest.mark.slow
def test_every_table_and_figure_is_written(result):
    _, out_dir = result
    check_tables_and_figures(out_dir, min_png_bytes=10_000)


@pytest.mark.slow
def test_per_pixel_is_exact_off_element_boundaries_and_per_vertex_is_not(result):
    rows, _ = result
    check_slice_sizes(rows, [1_000, 10_000, 100_000])


@pytest.mark.slow
def test_slicing_sweep_and_stability_rows(result):
    _, out_dir = result
    check_slicing_and_stability(out_dir)
    (slicing,) = read_table(out_dir / "slicing.csv")
    assert slicing["tets"] > 50_000
    sweep = read_table(out_dir / "sweep.csv")
    quad = [r for r in sweep if r["sweep"] == "quadrisection" and r["path"] == "per_vertex"]
    assert quad[-1]["polygons"] > 4 * quad[0]["polygons"]
    # finer polygons, better per-vertex colour
    assert quad[-1]["mean_diff_255"] < quad[0]["mean_diff_255"]
    res = [r for r in sweep if r["sweep"] == "resolution" and r["path"] == "per_pixel"]
    assert res[-1]["fit_U_err_max"] < res[0]["fit_U_err_max"]  # the fit converges
