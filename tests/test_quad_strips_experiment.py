"""The table_quad_strips experiment end to end in its quick form: what its tables must show."""

import pytest

from workbench.data import CAR_DECK, shared_file
from workbench.experiment.registry import discover, run_experiment
from workbench.experiment.tables import read_table


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    discover()
    root = tmp_path_factory.mktemp("figures")
    rows, out_dir = run_experiment("table_quad_strips", figures_root=root, quick=True)
    return rows, out_dir


def test_paper_sizes_are_stripped_better_than_triangle_strips(result):
    rows, _ = result
    sizes = [r for r in rows if r["kind"] == "paper size"]
    assert [r["quads"] for r in sizes] == pytest.approx([2215, 26284, 51473, 104749, 255641],
                                                        rel=0.01)
    for r in rows:
        assert r["verts_4n"] == 4 * r["elements"]
        assert r["quad_verts"] < r["tri_verts"], r["mesh"]
        # every quad in a strip costs 2 vertices plus 2 per strip; a triangle 3
        assert r["quad_verts"] == (2 * r["quads"] + 2 * r["quad_strips"] + 2 * r["quad_leftover"]
                                   + 3 * r["triangle_elements"])
    for r in sizes:
        assert r["quad_verts_pct"] <= 56.0


def test_the_car_suite_is_in_the_table(result):
    if shared_file(CAR_DECK) is None:
        pytest.skip("shared car deck not found (set WORKBENCH_DATA)")
    rows, _ = result
    names = {r["mesh"] for r in rows}
    assert {"car", "car 2x2", "car 4x4", "car 8x8", "car part 1"} <= names
    by = {r["mesh"]: r for r in rows}
    assert by["car 8x8"]["quads"] == 64 * by["car"]["quads"]


def test_stripped_drawings_equal_the_unstripped_one(result):
    _, out_dir = result
    draws = read_table(out_dir / "draw.csv")
    quad = [r for r in draws if r["path"] == "quad strips"]
    assert quad and all(r["pixels_differing"] == 0 for r in quad)
    tri = [r for r in draws if r["path"] == "meshopt triangle strips"]
    assert tri and all(r["max_diff_255"] <= 1 for r in tri)
    for r in quad:
        assert r["vertices_sent"] < 0.4 * 3 * r["triangles"]
    wire = [r for r in draws if r["path"] == "quad_wire (single pass)"]
    assert wire and all(r["wire_recall_1px"] >= 0.95 and r["wire_precision_1px"] >= 0.95
                        for r in wire)


def test_tables_and_figures_are_written(result):
    rows, out_dir = result
    assert len(read_table(out_dir / "table.csv")) == len(rows)
    assert len(read_table(out_dir / "paper.csv")) == 5
    sweep = read_table(out_dir / "cutoff.csv")
    assert {r["cutoff"] for r in sweep} >= {1, 2, 4, 8}
    for name in ("cutoff.png", "panels_51473_wire.png"):
        assert (out_dir / name).stat().st_size > 1000
