"""The table_fe_texture_wireframe experiment end to end: what its tables show, at the tiny size
(every table, row kind and column, on small stamped panels) and at the quick size (the car
meshes too; marked slow)."""

import pytest
from declared import assert_declared_tables

from workbench.algo.fepatch.pipeline import PARAMETER_SETS
from workbench.output.tables import read_table


@pytest.fixture(scope="module")
def tiny(experiment_run):
    return experiment_run("table_fe_texture_wireframe", "tiny")


@pytest.fixture(scope="module")
def quick(experiment_run):
    return experiment_run("table_fe_texture_wireframe", "quick")


@pytest.fixture(params=["tiny", pytest.param("quick", marks=pytest.mark.slow)])
def result(request):
    """The tiny run, and the quick run (slow): the assertions below hold at either size."""
    return request.getfixturevalue(request.param)


def test_tiny_writes_every_table_with_its_declared_columns(tiny):
    _, out_dir = tiny
    assert_declared_tables("table_fe_texture_wireframe", out_dir)
    rows = read_table(out_dir / "table.csv")
    assert {r["case"] for r in rows} >= {"original, shaded", "original + line overdraw",
                                         "original + wire texture"}
    assert (out_dir / "sweep.png").stat().st_size > 1000


def test_every_table_and_figure_is_written(result):
    _, out_dir = result
    for name in ("table", "table3", "params", "preprocessing", "closeup"):
        assert (out_dir / f"{name}.csv").is_file() and (out_dir / f"{name}.md").is_file()
    assert (out_dir / "crops.png").stat().st_size > 1000
    assert (out_dir / "closeup.png").stat().st_size > 1000
    params = read_table(out_dir / "params.csv")
    assert [(r["set"], r["alpha_g1_deg"], r["d_mm"], r["l_outer_mm"], r["l_inner_mm"])
            for r in params] == [("A", 12, 1, 0.5, 8), ("B", 18, 3, 2.5, 15)]


def test_simplified_paths_draw_fewer_triangles_and_report_their_errors(result):
    rows, _ = result
    scenes = {r["scene"] for r in rows}
    assert "stamped panels" in scenes
    for scene in scenes:
        by = {r["case"]: r for r in rows if r["scene"] == scene}
        assert by["original + line overdraw"]["speed_vs_overdraw"] == 1.0
        assert by["original + line overdraw"]["line_edges"] > 0
        original = by["original, shaded"]["triangles"]
        for name, params in PARAMETER_SETS.items():
            for label in (f"simplified {name} + normal map",
                          f"simplified {name} + normal map + wire texture"):
                r = by[label]
                assert r["triangles"] < original
                assert r["d_mm"] == params.d
                assert 0 < r["hausdorff_lower_mm"] <= r["hausdorff_mm"]
                assert r["within_d"] == (r["hausdorff_mm"] <= params.d)
                assert 0 < r["ssim"] <= 1
                assert r["rgba_texels_per_element"] > 1
            wire = by[f"simplified {name} + normal map + wire texture"]
            # the outlines come through: most overdraw wire pixels are found within a pixel
            assert 0.8 < wire["wire_recall_1px"] <= 1 and 0.8 < wire["wire_precision_1px"] <= 1
            assert wire["wire_iou_1px"] <= min(wire["wire_recall_1px"],
                                               wire["wire_precision_1px"]) + 1e-12


def test_preprocessing_times_every_stage(result):
    _, out_dir = result
    pre = read_table(out_dir / "preprocessing.csv")
    assert {r["set"] for r in pre} == {"A", "B"}
    for r in pre:
        stages = [r["features, subpatches, lines s"], r["retriangulation s"], r["textures s"]]
        assert all(s > 0 for s in stages)
        assert r["total s"] == pytest.approx(sum(stages))
        assert r["simplified_triangles"] < r["original_triangles"]
        assert r["line_nodes_kept"] <= r["line_nodes"]


def test_before_and_after_rows_show_the_bound_and_the_texture_memory(result):
    rows, out_dir = result
    for scene in {r["scene"] for r in rows}:
        by = {r["case"]: r for r in rows if r["scene"] == scene}
        new = by["simplified A + normal map + wire texture"]
        paper = by["simplified A [paper] + normal map + wire texture"]
        bound_only = by["simplified A [certified d, paper texture] + normal map + wire texture"]
        distance = by["simplified A [distance texture] + normal map + wire texture"]
        assert (new["rules"], paper["rules"]) == ("new", "paper")
        # the certified distance: within d with the new construction, whatever the paper's did
        for r in (new, bound_only):
            assert r["within_d"] and r["hausdorff_mm"] <= r["d_mm"]
        # the texture rule and the encoding change the memory, not the surface
        assert bound_only["triangles"] == distance["triangles"] == new["triangles"]
        assert new["rgba_texels_per_element"] < distance["rgba_texels_per_element"] \
            < bound_only["rgba_texels_per_element"]
    pre = read_table(out_dir / "preprocessing.csv")
    assert {r["rules"] for r in pre} == {"new", "paper", "certified d, paper texture",
                                         "distance texture"}
    assert {r["wire_encoding"] for r in pre if r["rules"] == "new"} == {"corners"}
    assert {r["wire_encoding"] for r in pre if r["rules"] != "new"} == {"distance"}
    for r in pre:
        if r["rules"] != "paper":
            assert r["certified_bound_mm"] <= PARAMETER_SETS[r["set"]].d
    sweep = read_table(out_dir / "sweep.csv")
    configs = {r["case"]: r for r in sweep}
    assert configs["A, paper rules"]["fit_share"] == 1 and not configs["A, paper rules"]["certify"]
    assert configs["A"]["within_d"] and configs["A"]["hausdorff_mm"] <= configs["A"]["d_mm"]


def test_closeup_compares_every_wire_frame_of_set_a_magnified(result):
    _, out_dir = result
    rows = read_table(out_dir / "closeup.csv")
    scenes = {r["scene"] for r in rows}
    assert "stamped panels" in scenes
    for scene in scenes:
        by = {r["rules"]: r for r in rows if r["scene"] == scene}
        assert set(by) == {"new", "paper", "certified d, paper texture", "distance texture"}
        for r in by.values():
            assert 0 < r["wire_recall_1px"] <= 1 and 0 < r["wire_precision_1px"] <= 1
            assert r["wire_pixels"] > 0 and r["overdraw_wire_pixels"] > 0
        # element corners draw the lines where they are, magnified too
        assert by["new"]["wire_iou_1px"] >= 0.95
