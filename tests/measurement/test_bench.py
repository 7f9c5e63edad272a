"""``workbench bench``: benchmark modules on the harness, their rows in the results store, and
``results compare`` flagging a benchmark made slower (an injected 3x fault) but not an
unchanged re-run."""

import re
import sys
import textwrap
from pathlib import Path

import pytest

from workbench.cli import main
from workbench.measurement.bench import (
    BENCHMARKS,
    Bench,
    Case,
    benchmark,
    discover,
    get_benchmark,
    run_benchmark,
)
from workbench.results.compare import compare_runs
from workbench.results.store import ResultsStore

ROOT = Path(__file__).resolve().parents[2]

PROBE = '''
import os
import time

from workbench.measurement.bench import Case, benchmark, needs_module


@benchmark("probe", "a nap of known length", cases=[Case("nap", {"ms": 60}, {"ms": 30})])
def probe(bench, ms):
    slowdown = float(os.environ.get("PROBE_SLOWDOWN", "1"))  # the injected fault
    bench.time("sleep", lambda: time.sleep(ms * slowdown / 1e3), requested_ms=ms)
    bench.record("count", naps=1)


@benchmark("absent", "needs a module that is not there",
           requires=[needs_module("no_such_module_for_bench")])
def absent(bench):
    raise AssertionError("a benchmark whose requirement is unmet must not run")
'''


@pytest.fixture
def folder(tmp_path):
    d = tmp_path / "benchmarks"
    d.mkdir()
    (d / "probe.py").write_text(textwrap.dedent(PROBE))
    return d


def bench_run(capsys, folder, store, *extra) -> str:
    """Run ``workbench bench probe --quick`` into ``store``; the run id it stored under."""
    assert main(["bench", "probe", "--quick", "--dir", str(folder), "--store", str(store),
                 "--out", str(store.parent / "table"), *extra]) == 0
    out = capsys.readouterr().out
    return re.search(r"under run (\S+) ", out).group(1)


def test_quick_bench_stores_rows_with_provenance(capsys, folder, tmp_path):
    store_root = tmp_path / "store"
    run = bench_run(capsys, folder, store_root)
    store = ResultsStore(store_root)
    rows = store.query("SELECT * FROM rows WHERE function = 'sleep'").to_pylist()
    assert len(rows) == 1
    row = rows[0]
    assert (row["run_id"], row["experiment"], row["table"], row["experiment_size"],
            row["case"]) == (run, "bench:probe", "nap", "quick", "nap")
    assert len(row["wall_samples_ms"]) == row["repeats"] == 5
    assert row["wall_ms_lo"] <= row["wall_ms"] <= row["wall_ms_hi"]
    assert row["wall_ms"] >= 30.0 and row["requested_ms"] == 30  # the quick size, timed
    (record,) = store.query(f"SELECT * FROM runs WHERE run_id = '{run}'").to_pylist()
    assert record["command"] == "bench probe --quick" and record["size"] == "quick"
    assert record["machine_id"] and "commit" in record and record["libraries"]
    assert store.query("SELECT count(*) FROM rows WHERE function = 'count'").to_pylist()
    table = (tmp_path / "table" / "bench.md").read_text()
    assert "sleep" in table and run in table


def test_compare_flags_a_slowed_benchmark_not_a_rerun(capsys, folder, tmp_path, monkeypatch):
    store_root = tmp_path / "store"
    # 30 ms naps, 9 of each: jitter of a few ms cannot move a median by 2x
    first = bench_run(capsys, folder, store_root, "--repeat", "9")
    again = bench_run(capsys, folder, store_root, "--repeat", "9")
    monkeypatch.setenv("PROBE_SLOWDOWN", "3")
    slowed = bench_run(capsys, folder, store_root, "--repeat", "9")
    store = ResultsStore(store_root)
    # a deliberately wide band (flag only beyond 2x) so that a noisy machine cannot flake
    same = compare_runs(store, first, again, threshold=1.0)
    (line,) = [x for x in same if x["quantity"] == "wall_ms"]
    assert not line["flagged"] and line["drift"] == 1.0  # one time in its case: no drift
    slow = [x for x in compare_runs(store, first, slowed, threshold=1.0)
            if x["quantity"] == "wall_ms"]
    assert slow[0]["flagged"] and slow[0]["relative_lo"] > 2.0
    assert main(["results", "compare", first, again, "--results", str(store_root),
                 "--threshold", "1"]) == 0
    assert main(["results", "compare", first, slowed, "--results", str(store_root),
                 "--threshold", "1"]) == 1
    assert "function=sleep" in capsys.readouterr().out


def test_list_names_every_benchmark_module(capsys):
    assert main(["bench", "--list"]) == 0
    listed = {line.split(":")[0] for line in capsys.readouterr().out.splitlines()}
    modules = {p.stem for p in (ROOT / "benchmarks").glob("*.py") if not p.name.startswith("_")}
    assert len(modules) >= 14 and modules <= listed, modules - listed


def test_bad_names_and_options_exit_2_with_one_line(capsys, folder, tmp_path):
    assert main(["bench", "probe", "nosuch", "--dir", str(folder),
                 "--store", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown benchmark 'nosuch'" in err[0] and "probe" in err[0]
    assert not (tmp_path / "s").exists()  # refused before anything is recorded
    for bad in (["--repeat", "2"], ["--repeat", "x"]):
        with pytest.raises(SystemExit) as exc:
            main(["bench", "probe", "--dir", str(folder), *bad])
        assert exc.value.code == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert main(["bench", "--dir", str(tmp_path / "missing")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_set_overrides_a_parameter_of_every_case_and_refuses_one_not_taken(capsys, folder,
                                                                         tmp_path):
    store_root = tmp_path / "store"
    run = bench_run(capsys, folder, store_root, "--set", "ms=45")
    store = ResultsStore(store_root)
    (row,) = store.query("SELECT * FROM rows WHERE function = 'sleep'").to_pylist()
    assert row["requested_ms"] == 45 and row["wall_ms"] >= 45.0  # the set value was slept
    (record,) = store.query(f"SELECT * FROM runs WHERE run_id = '{run}'").to_pylist()
    assert record["command"] == "bench probe --set ms=45 --quick"
    for bad, says in ((["probe", "--set", "nosuch=1"], "takes no parameter 'nosuch' (it "
                                                       "takes: ms)"),
                      (["--set", "ms=1"], "--set needs the benchmarks it applies to named")):
        assert main(["bench", *bad, "--dir", str(folder), "--store", str(tmp_path / "s")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and says in err[0], err
    assert not (tmp_path / "s").exists()
    with pytest.raises(SystemExit) as exc:
        main(["bench", "probe", "--dir", str(folder), "--set", "no equals sign"])
    assert exc.value.code == 2


def test_unmet_requirements_skip_with_the_reason(folder):
    discover(folder)
    result = run_benchmark("absent", "quick")
    assert result.rows == [] and "no_such_module_for_bench" in result.skipped["*"]


def test_interleaved_functions_carry_their_ratio():
    case = Case("c", {"n": 3})
    bench = Bench(case, "full", 5)
    timings = bench.interleave({"a": lambda: sum(range(2000)), "b": lambda: None},
                               ratios=[("a", "b")], kind="x")
    assert set(timings) == {"a", "b"} and all(t.repeats == 5 for t in timings.values())
    row_a, row_b = bench.rows
    assert (row_a["function"], row_a["case"], row_a["n"], row_a["kind"]) == ("a", "c", 3, "x")
    assert row_a["over_b_lo"] <= row_a["over_b"] <= row_a["over_b_hi"]
    assert row_a["over_b_pairs"] == 5 and "over_a" not in row_b
    reported = bench.time_reported("tool", lambda: {"build": 0.002, "query": 0.001})
    assert set(reported) == {"tool build", "tool query"}
    assert reported["tool query"].wall_ms == pytest.approx(1.0)
    with pytest.raises(ValueError, match="two or more"):
        bench.interleave({"a": lambda: None})
    with pytest.raises(ValueError, match="Case"):
        benchmark("dup", "x", cases=[Case("a"), Case("a")])
    assert "dup" not in BENCHMARKS


def test_a_converted_benchmark_runs_at_its_quick_size():
    discover()
    result = run_benchmark("solid_faces_bench", "quick")
    assert [r["case"] for r in result.rows] == ["hex", "tet", "tet-shuffled"]
    hexes = result.rows[0]
    assert (hexes["solids"], hexes["faces"]) == (20**3, 6 * 20**2)  # the quick size
    assert all(r["repeats"] == 5 and r["solids_per_s"] > 0 for r in result.rows)


def test_the_eroding_d3plot_benchmark_reads_back_the_deletions_it_wrote():
    # the d3plot written with lasso-python and read by the workbench's reader deletes, state by
    # state, exactly the elements the crash it was written from deletes
    discover()
    eroding_d3plot = sys.modules[get_benchmark("eroding_d3plot").function.__module__]
    result = run_benchmark("eroding_d3plot", "quick", overrides={"k": 1, "states": 6})
    crash = eroding_d3plot.eroding_crash(1, 6)
    scene = next(r for r in result.rows if r["function"] == "scene")
    assert scene["deleted"] == " ".join(str(crash.n_deleted(s)) for s in range(6))
    assert crash.n_deleted(5) > 0 and scene["shells"] == crash.n_elements
    timed = {(r["path"], r["function"]) for r in result.rows if "wall_ms" in r}
    assert timed == {(p, f"{w} {t}") for p in ("flat", "element_color")
                     for w in ("eroding", "plain") for t in ("upload", "draw")}
