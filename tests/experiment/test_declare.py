"""An experiment's declaration (:mod:`workbench.experiment.declare`): tables checked against it
before they are written, legends under the Markdown tables, claims that read only declared
columns, and the report reading the claims from it."""

import pytest

from workbench.experiment import EXPERIMENTS, experiment, run_experiment
from workbench.experiment.declare import (
    Claim,
    Column,
    Declaration,
    DeclarationError,
    Table,
    interval_columns,
)
from workbench.experiment.report import ClaimRow, declared_claims, declared_headlines
from workbench.output.tables import read_table

MAIN = Table("table", Column("scene", "", "the scene"), Column("wall_ms", "ms", "wall time"),
             Column("note", "", "a note", optional=True))
STEPS = Table("steps", Column("step", "", "the step"),
              Column("{scene} ms", "ms", "the step's time on {scene}"))


def declared(claims=()) -> Declaration:
    return Declaration("paper 2000", (MAIN, STEPS), claims)


# ---------------------------------------------------------------- checking rows
def test_declared_rows_pass_and_optional_columns_may_be_absent():
    MAIN.check([{"scene": "a", "wall_ms": 1.0}, {"scene": "b", "wall_ms": 2.0, "note": "x"}],
               "exp")
    MAIN.check([{"scene": "a", "wall_ms": 1.0}], "exp")
    MAIN.check([], "exp")  # an empty table has no columns to check
    # the harness's device column and the store-only raw samples need no declaration
    MAIN.check([{"scene": "a", "wall_ms": 1.0, "egl_device": "egl0:software",
                 "wall_samples_ms": [1.0, 1.1]}], "exp")


def test_the_columns_written_are_checked_where_a_table_picks_them():
    rows = [{"scene": "a", "wall_ms": 1.0, "other": 2}]
    MAIN.check(rows, "exp", columns=["scene", "wall_ms"])  # "other" is not written
    with pytest.raises(DeclarationError, match="column 'other' is not declared"):
        MAIN.check(rows, "exp", columns=["scene", "wall_ms", "other"])
    with pytest.raises(DeclarationError, match="declared column 'wall_ms' is missing"):
        MAIN.check(rows, "exp", columns=["scene"])


def test_an_undeclared_column_names_experiment_table_and_column():
    with pytest.raises(DeclarationError, match=r"experiment 'exp', table 'table': column "
                                               r"'bogus' is not declared"):
        MAIN.check([{"scene": "a", "wall_ms": 1.0, "bogus": 3}], "exp")


def test_a_missing_declared_column_names_it():
    with pytest.raises(DeclarationError, match=r"table 'table': declared column 'wall_ms' is "
                                               r"missing"):
        MAIN.check([{"scene": "a"}], "exp")


def test_an_undeclared_table_is_refused():
    with pytest.raises(DeclarationError, match=r"experiment 'exp': table 'other' is not "
                                               r"declared \(declared: table, steps\)"):
        declared().check("exp", "other", [{"scene": "a"}])


def test_a_placeholder_column_matches_any_text_and_fills_its_legend():
    STEPS.check([{"step": "s", "benchmark 8x4x4 ms": 1.0, "large 8x8x8 ms": 2.0}], "exp")
    with pytest.raises(DeclarationError, match="'benchmark ms2' is not declared"):
        STEPS.check([{"step": "s", "benchmark ms2": 1.0}], "exp")
    assert STEPS.legend(["step", "large ms"]) == [("step", "", "the step"),
                                                  ("large ms", "ms", "the step's time on large")]
    assert STEPS.declared_names(["step", "a ms", "b ms", "egl_device"]) == ["step", "{scene} ms"]


def test_declarations_refuse_what_contradicts_them():
    with pytest.raises(DeclarationError, match="more than once"):
        Table("t", Column("a", "", "a"), Column("a", "", "again"))
    with pytest.raises(DeclarationError, match="no legend"):
        Column("a", "ms", "")
    with pytest.raises(DeclarationError, match="tables declared twice"):
        Declaration("p", (MAIN, MAIN))
    with pytest.raises(DeclarationError, match="reads column 'gpu_ms' that table 'table' does "
                                               "not declare"):
        declared([Claim("q", {"table": ("scene", "gpu_ms")}, lambda tables: [])])
    with pytest.raises(DeclarationError, match="table 'nothing' is not declared"):
        declared([Claim("q", {"nothing": ("scene",)}, lambda tables: [])])
    with pytest.raises(DeclarationError, match="reads column 'gpu_ms'"):  # a headline too
        Declaration("p", (MAIN,), headline=Claim("h", {"table": ("gpu_ms",)}, lambda t: []))


def test_interval_columns_are_the_four_of_an_interleaved_ratio():
    names = [c.name for c in interval_columns("a_over_b", "a's time over b's")]
    assert names == ["a_over_b", "a_over_b_lo", "a_over_b_hi", "a_over_b_pairs"]


# ---------------------------------------------------------------- the harness
@pytest.fixture
def registered():
    """Register ``dummy-declared`` with the rows ``rows[0]`` (main) and ``rows[1]`` (steps)."""
    rows = [[{"scene": "a", "wall_ms": 1.5}], [{"step": "s", "small ms": 2.0}]]

    @experiment("dummy-declared", "a declared experiment", declared=declared())
    def run(exp):
        exp.table(rows[1], "steps", "The steps")
        return rows[0]

    yield rows
    EXPERIMENTS.pop("dummy-declared", None)


def test_tables_are_written_with_their_legends(registered, tmp_path):
    rows, out_dir = run_experiment("dummy-declared", figures_root=tmp_path, size="tiny")
    text = (out_dir / "table.md").read_text()
    assert text.index("| scene") < text.index("Columns:")
    assert "- `scene`: the scene\n" in text and "- `wall_ms` (ms): wall time\n" in text
    assert "`note`" not in text  # declared, optional, not written
    assert "- `small ms` (ms): the step's time on small" in (out_dir / "steps.md").read_text()


@pytest.mark.parametrize("table", [0, 1])
def test_an_undeclared_column_fails_the_run_and_keeps_the_last_outputs(registered, tmp_path,
                                                                        table):
    run_experiment("dummy-declared", figures_root=tmp_path, size="tiny")
    registered[table][0]["injected"] = 1
    name = ("table", "steps")[table]
    with pytest.raises(DeclarationError, match=f"experiment 'dummy-declared', table '{name}': "
                                               f"column 'injected' is not declared"):
        run_experiment("dummy-declared", figures_root=tmp_path, size="tiny")
    assert "injected" not in read_table(tmp_path / "dummy-declared" / f"{name}.csv")[0]


def test_the_registry_refuses_a_declaration_of_the_wrong_kind():
    with pytest.raises(TypeError, match="declared must be a Declaration"):
        experiment("dummy-wrong", "", declared={"table": []})


# ---------------------------------------------------------------- claims
def test_a_claim_row_holds_only_the_columns_the_claim_reads():
    row = ClaimRow({"scene": "a", "wall_ms": 1.0, "other": 2}, ("scene", "wall_ms", "ms_lo"),
                   "q")
    assert dict(row) == {"scene": "a", "wall_ms": 1.0}
    assert row.get("ms_lo") is None  # declared, not stored in this run
    with pytest.raises(KeyError, match="reads column 'other' without declaring it"):
        row["other"]
    with pytest.raises(KeyError, match="reads column 'other' without declaring it"):
        row.get("other")
    with pytest.raises(KeyError):
        row["ms_lo"]


def test_every_reproduction_declares_its_paper_and_claims():
    claims = declared_claims()
    assert set(claims) == {"render_paths", "table_software_raster", "table_bvh_distance",
                           "simplify_tradeoff", "table_quad_strips",
                           "table_fe_texture_wireframe", "fig_pixel_exact", "fig_exploded"}
    assert [paper for paper, _ in claims.values()] == sorted(p for p, _ in claims.values())
    for name, (_, found) in claims.items():
        declaration = EXPERIMENTS[name].declared
        for claim in found:
            for table, columns in claim.reads.items():
                assert set(columns) <= {c for c in columns if declaration.table(table).column(c)}
    # each declares one headline for the README's table, reading declared columns only
    assert set(declared_headlines()) == set(claims)
