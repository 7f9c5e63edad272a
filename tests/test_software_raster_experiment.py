"""The table_software_raster experiment end to end in its quick form: what its tables show."""

import pytest

from workbench.algo.softraster import STEPS
from workbench.experiment.registry import discover, run_experiment
from workbench.experiment.tables import read_table


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    discover()
    root = tmp_path_factory.mktemp("figures")
    return run_experiment("table_software_raster", figures_root=root, quick=True)


def test_software_rows_match_egl_and_name_their_renderer(result):
    rows, _ = result
    soft = [r for r in rows if str(r.get("renderer", "")).startswith("software rasterizer")]
    assert len(soft) >= 10
    for r in soft:
        assert r["wall_ms"] > 0 and r["fragments"] > 0 and r["Mtri_per_s"] > 0
        if "GL rule" in r["config"]:  # llvmpipe's pixel rule: the same image, nearly
            assert r["differing_pct_vs_egl"] <= 0.5, r["config"]
        if "span table" in r["config"]:
            assert r["differing_px_vs_half_space_0_bits"] == 0  # the table changes no pixel
            assert r["table_fit_pct"] > 90
    egl = [r for r in rows if str(r.get("renderer", "")).startswith("llvmpipe")]
    assert egl and all(r.get("speed_vs_llvmpipe_floor") is None for r in egl)
    assert any(r["config"] == "es2008 (paper)" for r in rows)


def test_steps_table_has_every_step_and_the_paper_beside(result):
    _, out_dir = result
    steps = read_table(out_dir / "steps.csv")
    assert [r["step"] for r in steps] == [name for name, _ in STEPS] + ["total"]
    for r in steps[:-1]:  # times, not compared here: they are the experiment's to report
        assert r["small_off_ms"] >= 0 and r["small_on_ms"] >= 0
    assert steps[-1]["paper 1M on s"] == pytest.approx(0.82, abs=0.01)


def test_span_tables_have_the_papers_sizes(result):
    _, out_dir = result
    tables = read_table(out_dir / "span_table.csv")
    assert [r["S"] for r in tables] == [10, 15, 20]
    for r in tables:
        assert r["MB"] == pytest.approx(r["paper_MB"], rel=0.01)


def test_composites_equal_the_one_process_image(result):
    _, out_dir = result
    rows = read_table(out_dir / "composite.csv")
    assert {r["domains"] for r in rows} == {1, 2, 4, 8}
    assert {r["method"] for r in rows} == {"tree", "swap"}
    assert all(r["equal_to_one_process"] is True and r["differing_px"] == 0 for r in rows)
    assert all(r["bytes_moved_MB"] > 0 for r in rows if r["domains"] > 1)
    for name in ("images.png", "steps.png", "table.md", "steps.md", "composite.md"):
        assert (out_dir / name).stat().st_size > 0
