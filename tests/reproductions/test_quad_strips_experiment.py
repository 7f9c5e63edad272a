"""The table_quad_strips experiment end to end: what its tables must show.

Every test on ``result`` runs at the tiny size (seconds) and, marked slow, on the quick run
(minutes); the tiny run must write every table and column the quick run writes.
"""

import pytest
from declared import assert_declared_tables

from workbench.output.tables import read_table

# per size: the paper sizes stripped, the car meshes named, the refinement k of the largest
# car mesh, and the panels drawn
PAPER_SIZES = {"tiny": [2215], "quick": [2215, 26284, 51473, 104749, 255641]}
CAR_MESHES = {"tiny": {"car", "car 2x2", "car part 1"},
              "quick": {"car", "car 2x2", "car 4x4", "car 8x8", "car part 1"}}
LARGEST_CAR = {"tiny": 2, "quick": 8}
DRAWN_PANELS = {"tiny": "panels_2215_wire.png", "quick": "panels_51473_wire.png"}


@pytest.fixture(scope="module", params=["tiny", pytest.param("quick", marks=pytest.mark.slow)])
def result(request, experiment_run):
    return request.param, *experiment_run("table_quad_strips", request.param)


def test_paper_sizes_are_stripped_better_than_triangle_strips(result):
    size, rows, _ = result
    sizes = [r for r in rows if r["kind"] == "paper size"]
    assert [r["quads"] for r in sizes] == pytest.approx(PAPER_SIZES[size], rel=0.01)
    for r in rows:
        assert r["verts_4n"] == 4 * r["elements"]
        assert r["quad_verts"] < r["tri_verts"], r["scene"]
        # every quad in a strip costs 2 vertices plus 2 per strip; a triangle 3
        assert r["quad_verts"] == (2 * r["quads"] + 2 * r["quad_strips"] + 2 * r["quad_leftover"]
                                   + 3 * r["triangle_elements"])
    for r in sizes:
        assert r["quad_verts_pct"] <= 56.0


def test_the_car_suite_is_in_the_table(result, car_deck):
    size, rows, _ = result
    names = {r["scene"] for r in rows}
    assert CAR_MESHES[size] <= names
    by = {r["scene"]: r for r in rows}
    k = LARGEST_CAR[size]
    assert by[f"car {k}x{k}"]["quads"] == k * k * by["car"]["quads"]


def test_stripped_drawings_equal_the_unstripped_one(result):
    _, _, out_dir = result
    draws = read_table(out_dir / "draw.csv")
    quad = [r for r in draws if r["case"] == "quad strips"]
    assert quad and all(r["differing_px"] == 0 for r in quad)
    tri = [r for r in draws if r["case"] == "meshopt triangle strips"]
    assert tri and all(r["max_diff_255"] <= 1 for r in tri)
    for r in quad:
        assert r["vertices_sent"] < 0.4 * 3 * r["triangles"]
    wire = [r for r in draws if r["case"] == "quad_wire (single pass)"]
    assert wire and all(r["wire_recall_1px"] >= 0.95 and r["wire_precision_1px"] >= 0.95
                        for r in wire)


def test_tables_and_figures_are_written(result):
    size, rows, out_dir = result
    assert len(read_table(out_dir / "table.csv")) == len(rows)
    assert len(read_table(out_dir / "paper.csv")) == len(PAPER_SIZES[size])
    sweep = read_table(out_dir / "cutoff.csv")
    assert {r["cutoff"] for r in sweep} >= {1, 2, 4, 8}
    for name in ("cutoff.png", DRAWN_PANELS[size]):
        assert (out_dir / name).stat().st_size > 1000


# the kinds of row a run writes (its tables and columns are declared by the experiment)
KINDS = {"paper size", "car", "car part", "car refined", "d3plot"}
DRAW_CASES = {"list, shorter diagonal", "list, strip diagonal", "meshopt triangle strips",
              "quad strips", "list + line-overdraw wire", "quad_wire (single pass)"}


def test_every_table_with_every_declared_column_and_kind_of_row(result, car_deck, d3plot_file):
    _, _, out_dir = result
    assert_declared_tables("table_quad_strips", out_dir)
    assert {r["kind"] for r in read_table(out_dir / "table.csv")} == KINDS
    draws = read_table(out_dir / "draw.csv")
    assert {r["case"] for r in draws} == DRAW_CASES
    assert len({r["scene"] for r in draws}) == 2
