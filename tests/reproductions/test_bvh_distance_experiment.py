"""The table_bvh_distance experiment end to end: the shape of its tables at the tiny size, and
what its tables show in its quick form (slow)."""

import pytest
from declared import assert_declared_tables

from workbench.algo.nearest.triangle import DISTANCE_ERROR, UNIT_ROUNDOFF
from workbench.output.tables import read_table

NAME = "table_bvh_distance"
FIGURES = ("fig9_distance.png", "fig9_flanges.png", "connectivity.png")


@pytest.fixture(scope="module")
def tiny(experiment_run):
    return experiment_run(NAME, "tiny")


@pytest.fixture(scope="module")
def result(experiment_run):
    return experiment_run(NAME, "quick")


def check_hierarchies(rows, models: int) -> None:
    """Every hierarchy of each of ``models`` models is exact and counts its tests; the paper's
    rows are beside."""
    ours = [r for r in rows if not str(r["scene"]).startswith("paper")]
    assert {(r["kind"], r["elements_per_leaf"]) for r in ours} == {
        ("aabb", "1"), ("aabb", "<= 10"), ("obb", "1"), ("obb", "<= 10")}
    for r in ours:
        assert r["point_bv_tests"] > 0 and r["n_bvs"] > 0 and r["queries_per_s"] > 0
        if r["elements_per_leaf"] == "1":
            assert r["plane_skips"] == 0  # one element per leaf: nothing to skip
    checked = [r for r in ours if r.get("checked_nodes")]
    assert len(checked) == models
    for r in checked:
        # against exact rational arithmetic: within the kernel's documented error, 64 u of the
        # distance plus the nearest triangle's size, both far below 10^4 mm on these models
        assert r["max_abs_error_mm"] <= DISTANCE_ERROR * UNIT_ROUNDOFF * 1e4
        assert r["same_nodes_within"] is True
    assert [r for r in ours if r.get("max_change_translated_1e6_mm") is not None][0][
        "max_change_translated_1e6_mm"] <= 1e-9
    assert sum(str(r["scene"]).startswith("paper") for r in rows) == 4


def check_references(out_dir) -> None:
    refs = read_table(out_dir / "references.csv")
    libigl = [r for r in refs if r["tool"] == "libigl"]
    assert libigl and all(r["max_abs_error_mm"] <= 1e-9 and r["nodes_flagged"] == 0
                          for r in libigl)
    assert any(r["tool"].startswith("open3d") for r in refs)
    assert all(r["constraints"] for r in refs)
    # our two exact paths agree to the last bit; the faster sets the speed ratios
    batched = [r for r in refs if r["tool"] == "ours (batched 4-wide tree)"]
    assert batched and all(r["max_abs_error_mm"] == 0 and r["nodes_flagged"] == 0
                           for r in batched)
    for scene in {r["scene"] for r in refs}:
        ours = [r for r in refs if r["scene"] == scene and r["tool"].startswith("ours")]
        assert len(ours) == 2 and max(r["speed_vs_ours"] for r in ours) == 1.0
    # fcpw: float32, its errors counted against the exact distances
    fcpw = [r for r in refs if r["tool"] == "fcpw"]
    assert fcpw and all("float32" in r["constraints"] and r["nodes_off"] >= 0
                        and r["max_abs_error_mm"] < 1e-3 for r in fcpw)


def check_force_tubes_and_flanges(out_dir) -> None:
    tubes = read_table(out_dir / "forcetube.csv")
    assert tubes[0]["max_rel_error_vs_closed_form"] <= 1e-9
    car = [r for r in tubes if str(r["case"]).startswith("car rails: planes")]
    if car:  # the car deck is there
        assert car[0]["equal_forces"] is True
    flange = read_table(out_dir / "flange.csv")
    assert {r["view"] for r in flange} == {"fig9_distance", "fig9_flanges"}
    by = {r["view"]: r for r in flange}
    assert 0 < by["fig9_flanges"]["covered_px"] < by["fig9_distance"]["covered_px"]
    for name in FIGURES:
        assert (out_dir / name).stat().st_size > 0


# ------------------------------------------------------------------------------- tiny size
def test_tiny_run_writes_every_table_with_its_declared_columns(tiny, car_deck):
    _, out_dir = tiny
    assert_declared_tables(NAME, out_dir)
    assert (out_dir / "force_tubes.png").stat().st_size > 0


def test_tiny_hierarchies_are_exact_and_count_their_tests(tiny):
    rows, _ = tiny
    check_hierarchies(rows, models=2)  # the base model and its 2 x 2 refinement


def test_tiny_references_are_compared_with_the_exact_distances(tiny):
    check_references(tiny[1])


def test_tiny_force_tubes_and_flanges(tiny):
    check_force_tubes_and_flanges(tiny[1])


# ------------------------------------------------------------------------------ quick size
@pytest.mark.slow
def test_every_hierarchy_is_exact_and_counts_its_tests(result):
    rows, _ = result
    check_hierarchies(rows, models=3)  # the base model and its 2 x 2 and 4 x 4 refinements


@pytest.mark.slow
def test_references_are_compared_with_the_exact_distances(result):
    check_references(result[1])


@pytest.mark.slow
def test_force_tubes_and_flanges(result):
    check_force_tubes_and_flanges(result[1])
