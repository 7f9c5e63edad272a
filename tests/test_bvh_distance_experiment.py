"""The table_bvh_distance experiment end to end in its quick form: what its tables show."""

import pytest

from workbench.experiment.registry import discover, run_experiment
from workbench.experiment.tables import read_table


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    discover()
    root = tmp_path_factory.mktemp("figures")
    return run_experiment("table_bvh_distance", figures_root=root, quick=True)


def test_every_hierarchy_is_exact_and_counts_its_tests(result):
    rows, _ = result
    ours = [r for r in rows if not str(r["model"]).startswith("paper")]
    assert {(r["kind"], r["elements_per_leaf"]) for r in ours} == {
        ("aabb", "1"), ("aabb", "<= 10"), ("obb", "1"), ("obb", "<= 10")}
    for r in ours:
        assert r["point_bv_tests"] > 0 and r["n_bvs"] > 0 and r["queries_per_s"] > 0
        if r["elements_per_leaf"] == "1":
            assert r["plane_skips"] == 0  # one element per leaf: nothing to skip
    checked = [r for r in ours if r.get("checked_nodes")]
    assert len(checked) == 3
    for r in checked:
        assert r["max_rel_error"] <= 1e-12 and r["same_nodes_within"] is True
    assert [r for r in ours if r.get("max_change_translated_1e6_mm") is not None][0][
        "max_change_translated_1e6_mm"] <= 1e-9
    assert sum(str(r["model"]).startswith("paper") for r in rows) == 4


def test_references_are_compared_with_the_exact_distances(result):
    _, out_dir = result
    refs = read_table(out_dir / "references.csv")
    libigl = [r for r in refs if r["tool"] == "libigl"]
    assert libigl and all(r["max_abs_error_mm"] <= 1e-9 and r["nodes_flagged"] == 0
                          for r in libigl)
    assert any(r["tool"].startswith("open3d") for r in refs)
    assert all(r["constraints"] for r in refs)


def test_force_tubes_and_flanges(result):
    _, out_dir = result
    tubes = read_table(out_dir / "forcetube.csv")
    assert tubes[0]["max_rel_error_vs_closed_form"] <= 1e-9
    car = [r for r in tubes if str(r["case"]).startswith("car rails: planes")]
    if car:  # the car deck is there
        assert car[0]["equal_forces"] is True
    flange = read_table(out_dir / "flange.csv")
    assert {r["view"] for r in flange} == {"fig9_distance", "fig9_flanges"}
    by = {r["view"]: r for r in flange}
    assert 0 < by["fig9_flanges"]["covered_px"] < by["fig9_distance"]["covered_px"]
    for name in ("fig9_distance.png", "fig9_flanges.png", "connectivity.png"):
        assert (out_dir / name).stat().st_size > 0
