"""The table_software_raster experiment end to end: the shape of its tables at the tiny size,
and what its tables show in its quick form (slow)."""

import pytest
from declared import assert_declared_tables, header

from workbench.algo.softraster import STEPS
from workbench.output.tables import read_table

NAME = "table_software_raster"


@pytest.fixture(scope="module")
def tiny(experiment_run):
    return experiment_run(NAME, "tiny")


@pytest.fixture(scope="module")
def result(experiment_run):
    return experiment_run(NAME, "quick")


def check_software_rows(rows, differing_pct_gl_rule: float | None) -> None:
    """The software rows name their renderer and reference and, with llvmpipe's pixel rule,
    differ from the EGL image in at most ``differing_pct_gl_rule`` % of the pixels (None: not
    checked); the span table changes no pixel against the half-space generator on the same
    rule."""
    soft = [r for r in rows if str(r.get("renderer", "")).startswith("software rasterizer")]
    assert len(soft) >= 10
    for r in soft:
        assert r["wall_ms"] > 0 and r["fragments"] > 0 and r["mtri_per_s"] > 0
        assert r["reference"] == ("EGL flat" if r["path"] == "flat" else "EGL bands")
        if "GL rule" in r["case"] and differing_pct_gl_rule is not None:
            # llvmpipe's pixel rule: the same image, nearly
            assert r["differing_pct"] <= differing_pct_gl_rule, r["case"]
        if "span table" in r["case"]:
            assert r["differing_px_vs_half_space_0_bits"] == 0  # the table changes no pixel
            assert r["table_fit_pct"] > 90
    egl = [r for r in rows if str(r.get("renderer", "")).startswith("llvmpipe")]
    assert egl and all(r.get("speed_vs_llvmpipe_floor") is None for r in egl)
    assert any(r["case"] == "es2008 (paper)" for r in rows)


def check_steps(out_dir) -> None:
    steps = read_table(out_dir / "steps.csv")
    assert [r["step"] for r in steps] == [name for name, _ in STEPS] + ["total"]
    for r in steps[:-1]:  # times, not compared here: they are the experiment's to report
        assert r["small_off_ms"] >= 0 and r["small_on_ms"] >= 0
    assert steps[-1]["paper 1M on s"] == pytest.approx(0.82, abs=0.01)


def check_span_tables(out_dir) -> None:
    tables = read_table(out_dir / "span_table.csv")
    assert [r["S"] for r in tables] == [10, 15, 20]
    for r in tables:
        assert r["MB"] == pytest.approx(r["paper_MB"], rel=0.01)


def check_composites(out_dir, domains: set) -> None:
    rows = read_table(out_dir / "composite.csv")
    assert {r["domains"] for r in rows} == domains
    assert {r["method"] for r in rows} == {"tree", "swap", "active-swap", "local"}
    assert all(r["equal_to_one_process"] is True and r["differing_px"] == 0 for r in rows)
    assert all(r["bytes_moved_MB"] > 0 for r in rows if r["domains"] > 1)
    for name in ("images.png", "steps.png", "table.md", "steps.md", "composite.md"):
        assert (out_dir / name).stat().st_size > 0


# ------------------------------------------------------------------------------- tiny size
def test_tiny_run_writes_every_table_with_its_declared_columns(tiny):
    _, out_dir = tiny
    assert_declared_tables(NAME, out_dir)
    # in the steps table each scene ("benchmark 8xNxN", "large 8xNxN") has its columns
    steps = header(out_dir / "steps.csv")
    for scene in ("benchmark", "large"):
        assert sum(c.startswith(f"{scene} 8x") for c in steps) == 2, steps


def test_tiny_software_rows_name_their_renderer_and_reference(tiny):
    rows, _ = tiny
    # on images this small the few pixels on band edges weigh too much for the share
    check_software_rows(rows, differing_pct_gl_rule=None)


def test_tiny_steps_table_has_every_step_and_the_paper_beside(tiny):
    check_steps(tiny[1])


def test_tiny_span_tables_have_the_papers_sizes(tiny):
    check_span_tables(tiny[1])


def test_tiny_composites_equal_the_one_process_image(tiny):
    check_composites(tiny[1], domains={1, 2})


# ------------------------------------------------------------------------------ quick size
@pytest.mark.slow
def test_software_rows_match_egl_and_name_their_renderer(result):
    rows, _ = result
    check_software_rows(rows, differing_pct_gl_rule=0.5)


@pytest.mark.slow
def test_steps_table_has_every_step_and_the_paper_beside(result):
    check_steps(result[1])


@pytest.mark.slow
def test_span_tables_have_the_papers_sizes(result):
    check_span_tables(result[1])


@pytest.mark.slow
def test_composites_equal_the_one_process_image(result):
    check_composites(result[1], domains={1, 2, 4, 8})
