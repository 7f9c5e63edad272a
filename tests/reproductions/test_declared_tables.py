"""Every experiment of :mod:`workbench.reproductions` declares its tables once
(:mod:`workbench.experiment.declare`): its tiny run (the shape tests' size, writing every table
and column its quick run writes) writes exactly the declared tables and columns with their
legends, and a column the declaration does not hold makes the write fail."""

import dataclasses
import re

import pytest
from declared import assert_declared_tables, declaration

from workbench.experiment.declare import DeclarationError
from workbench.experiment.registry import EXPERIMENTS, discover, run_experiment
from workbench.measurement.timing import TIMING_COLUMNS
from workbench.output.tables import STORE_ONLY_SUFFIX, read_table
from workbench.reproductions._declared.common import timing

discover()
NAMES = sorted(name for name, exp in EXPERIMENTS.items()
               if exp.function.__module__.startswith("workbench.reproductions."))


def test_every_reproduction_is_declared_with_tables_and_claims():
    assert len(NAMES) == 8
    for name in NAMES:
        declared = declaration(name)
        assert declared.paper and declared.claims, name
        assert "table" in {t.name for t in declared.tables}, name
        for table in declared.tables:
            for column in table.columns:
                assert column.legend.strip() and column.unit is not None, (name, column)


def test_the_shared_timing_columns_are_the_timing_rows():
    assert [c.name for c in timing()] == [c for c in TIMING_COLUMNS
                                          if not c.endswith(STORE_ONLY_SUFFIX)]


@pytest.mark.parametrize("name", NAMES)
def test_the_tiny_run_writes_exactly_the_declared_tables(name, experiment_run, car_deck,
                                                         d3plot_file):
    _, out_dir = experiment_run(name, "tiny")
    assert_declared_tables(name, out_dir)
    declared = declaration(name)
    for table in declared.tables:
        rows = read_table(out_dir / f"{table.name}.csv")
        declared.check(name, table.name, rows)
        injected = [{**rows[0], "undeclared_probe": 1}, *rows[1:]]
        with pytest.raises(DeclarationError, match=re.escape(
                f"experiment '{name}', table '{table.name}': column 'undeclared_probe'")):
            declared.check(name, table.name, injected)
        required = next((c.name for c in table.columns if not c.optional
                         and c.name in rows[0]), None)
        if required is not None:
            dropped = [{k: v for k, v in r.items() if k != required} for r in rows]
            with pytest.raises(DeclarationError, match=re.escape(
                    f"declared column '{required}' is missing")):
                declared.check(name, table.name, dropped)


def test_a_column_injected_into_a_real_run_fails_its_write(tmp_path, monkeypatch):
    """render_paths at the tiny size, one row given a column nobody declared: the run fails
    naming it, and nothing is swapped into place."""
    exp = EXPERIMENTS["render_paths"]

    def injected(context):
        rows = exp.function(context)
        rows[0]["undeclared_probe"] = 1.0
        return rows

    monkeypatch.setitem(EXPERIMENTS, "render_paths", dataclasses.replace(exp, function=injected))
    with pytest.raises(DeclarationError, match="experiment 'render_paths', table 'table': column "
                                               "'undeclared_probe' is not declared"):
        run_experiment("render_paths", figures_root=tmp_path, size="tiny")
    assert not (tmp_path / "render_paths").exists()
