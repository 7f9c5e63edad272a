"""The results store: round trips, views, heterogeneous files, concurrent and killed writers."""

from __future__ import annotations

import math
import os
import random
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from workbench.results.store import _HOST, RESULTS_ENV, ResultsStore, results_root

ROOT = Path(__file__).resolve().parents[2]


def _spawn(code: str, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), *map(str, args)],
                            cwd=ROOT)


def _types(store: ResultsStore, view: str = "rows") -> dict[str, str]:
    described = store.query(f"DESCRIBE {view}").to_pydict()
    return dict(zip(described["column_name"], described["column_type"]))


def _hidden(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob(".*") if p.is_file())


def test_round_trip_keeps_values_and_types(tmp_path):
    store = ResultsStore(tmp_path / "results")
    assert not store.root.exists()  # nothing is created before a write
    rows = [
        {"i": 1, "f": 1.5, "nan": float("nan"), "none": None, "ok": True, "s": "x",
         "samples": [1.0, 2.0, 3.5], "np_f": np.float32(0.5), "np_i": np.int64(7),
         "mix": 1, "ints": 3},
        {"i": 2, "f": 2, "nan": math.inf, "none": None, "ok": np.bool_(False), "s": "y",
         "samples": (4, 5.5), "np_f": np.float64(-1.25), "np_i": np.int32(-3),
         "mix": "two", "ints": 2.5},
        {"i": 3, "f": None, "s": None, "samples": np.array([6.0])},
    ]
    path = store.append_rows("run-1", rows, experiment="render_paths", table="table")
    assert path.parent == store.root / "rows" / "run_id=run-1" and path.suffix == ".parquet"
    assert store.append_rows("run-1", []) is None

    types = _types(store)
    assert types == {
        "run_id": "VARCHAR", "row_index": "BIGINT", "experiment": "VARCHAR", "table": "VARCHAR",
        "i": "BIGINT", "f": "DOUBLE", "nan": "DOUBLE", "none": "VARCHAR", "ok": "BOOLEAN",
        "s": "VARCHAR", "samples": "DOUBLE[]", "np_f": "DOUBLE", "np_i": "BIGINT",
        "mix": "VARCHAR", "ints": "DOUBLE"}
    got = store.query("SELECT * FROM rows ORDER BY row_index").to_pylist()
    assert [r["row_index"] for r in got] == [0, 1, 2]
    assert {r["run_id"] for r in got} == {"run-1"}
    assert {(r["experiment"], r["table"]) for r in got} == {("render_paths", "table")}
    assert [r["i"] for r in got] == [1, 2, 3]
    assert [r["f"] for r in got] == [1.5, 2.0, None]
    assert math.isnan(got[0]["nan"]) and got[1]["nan"] == math.inf and got[2]["nan"] is None
    assert [r["none"] for r in got] == [None, None, None]
    assert [r["ok"] for r in got] == [True, False, None]
    assert [r["s"] for r in got] == ["x", "y", None]
    assert [r["samples"] for r in got] == [[1.0, 2.0, 3.5], [4.0, 5.5], [6.0]]
    assert [r["np_f"] for r in got] == [0.5, -1.25, None]
    assert [r["np_i"] for r in got] == [7, -3, None]
    assert [r["mix"] for r in got] == ["1", "two", None]
    assert [r["ints"] for r in got] == [3.0, 2.5, None]
    median = store.query("SELECT median(list_avg(samples)) AS m FROM rows WHERE NOT isnan(nan)")
    assert median.column("m").to_pylist() == [4.75]


def test_append_rows_refuses_bad_input(tmp_path):
    store = ResultsStore(tmp_path)
    for bad in ["", "a/b", "../x", ".hidden", "a b", 3]:
        with pytest.raises(ValueError, match="run_id"):
            store.append_rows(bad, [{"x": 1}])
    with pytest.raises(TypeError, match="dicts"):
        store.append_rows("r", [{"x": 1}, ("x", 1)])
    with pytest.raises(ValueError, match="run_id"):
        store.append_rows("r", [{"run_id": "other"}])
    with pytest.raises(ValueError, match="experiment"):
        store.append_rows("r", [{"experiment": "a"}], experiment="b")
    with pytest.raises(ValueError, match="row_index"):
        store.append_rows("r", [{"row_index": 0}])
    assert not (tmp_path / "rows").exists()
    store.append_rows("r", [{"run_id": "r", "experiment": "b"}], experiment="b")
    assert store.query("SELECT run_id, experiment FROM rows").to_pylist() == [
        {"run_id": "r", "experiment": "b"}]


def test_views_exist_on_an_empty_store(tmp_path):
    store = ResultsStore(tmp_path / "nothing")
    assert store.query("SELECT * FROM rows").num_rows == 0
    assert _types(store, "rows") == {"run_id": "VARCHAR", "row_index": "BIGINT"}
    assert _types(store, "runs") == {"run_id": "VARCHAR", "machine_id": "VARCHAR",
                                     "cpu": "VARCHAR", "renderer": "VARCHAR"}
    assert _types(store, "machines") == {"machine_id": "VARCHAR"}
    assert store.run_ids() == [] and store.clean() == []
    assert not store.root.exists()


def test_runs_view_joins_machines(tmp_path):
    store = ResultsStore(tmp_path)
    store.record_run({"run_id": "r0", "machine_id": "M"})
    assert store.query("SELECT cpu, renderer FROM runs").to_pylist() == [
        {"cpu": None, "renderer": None}]  # no machines recorded yet: the columns are there
    store.record_machine({"machine_id": "M", "cpu": "Ryzen 7", "renderer": "llvmpipe",
                          "cores": np.int64(8)})
    store.record_machine({"machine_id": "N", "cpu": "Xeon", "renderer": "NVIDIA H200"})
    store.record_run({"run_id": "r1", "machine_id": "N", "started": "2024-05-01"})
    got = store.query("SELECT run_id, machine_id, cpu, renderer FROM runs ORDER BY run_id")
    assert got.to_pylist() == [
        {"run_id": "r0", "machine_id": "M", "cpu": "Ryzen 7", "renderer": "llvmpipe"},
        {"run_id": "r1", "machine_id": "N", "cpu": "Xeon", "renderer": "NVIDIA H200"}]
    store.append_rows("r1", [{"wall_ms": 2.0}, {"wall_ms": 4.0}])
    joined = store.query("SELECT u.cpu, avg(r.wall_ms) AS ms FROM rows r "
                         "JOIN runs u USING (run_id) GROUP BY u.cpu")
    assert joined.to_pylist() == [{"cpu": "Xeon", "ms": 3.0}]
    assert store.query("SELECT cores FROM machines WHERE machine_id = 'M'").to_pylist() == [
        {"cores": 8}]


def test_files_that_disagree_on_types_query_fine(tmp_path):
    store = ResultsStore(tmp_path)
    store.append_rows("a", [{"n": 1, "s": "fast", "v": None, "l": [1.0, 2.0], "b": True,
                             "z": None, "k": [0.5]}])
    store.append_rows("a", [{"n": 2.5, "s": 2.5, "v": "x", "b": None, "z": None}])
    store.append_rows("b", [{"n": float("nan"), "s": None, "v": None, "b": False,
                             "k": 0.25}])
    types = _types(store)
    assert types["n"] == "DOUBLE" and types["s"] == "VARCHAR" and types["v"] == "VARCHAR"
    assert types["l"] == "DOUBLE[]" and types["b"] == "BOOLEAN" and types["z"] == "VARCHAR"
    assert types["k"] == "VARCHAR"  # a list in one file, a number in another: text
    every = store.query("SELECT * FROM rows").to_pylist()
    assert len(every) == 3
    assert sorted(str(r["k"]) for r in every) == ["0.25", "None", "[0.5]"]

    def where(condition):
        return store.query(f"SELECT count(*) AS n FROM rows WHERE {condition}")["n"][0].as_py()

    assert where("n BETWEEN 2 AND 3") == 1 and where("isnan(n)") == 1  # NaN sorts above all
    assert where("s = '2.5'") == 1 and where("s = 'fast'") == 1
    assert where("v = 'x'") == 1 and where("v IS NULL") == 2
    assert where("l[2] = 2.0") == 1 and where("l IS NULL") == 2
    assert where("b") == 1 and where("NOT b") == 1
    assert where("z IS NULL") == 3 and where("k = '0.25'") == 1
    groups = store.query("SELECT run_id, count(*) AS n FROM rows GROUP BY run_id ORDER BY 1")
    assert groups.to_pylist() == [{"run_id": "a", "n": 2}, {"run_id": "b", "n": 1}]


def test_record_run_refuses_a_duplicate_and_machines_are_written_once(tmp_path):
    store = ResultsStore(tmp_path)
    store.record_machine({"machine_id": "M", "cpu": "first"})
    first = tmp_path / "machines" / "M.parquet"
    stamp = first.stat().st_mtime_ns, first.stat().st_ino
    store.record_machine({"machine_id": "M", "cpu": "second"})
    assert (first.stat().st_mtime_ns, first.stat().st_ino) == stamp
    assert sorted(os.listdir(tmp_path / "machines")) == ["M.parquet"]
    assert store.query("SELECT cpu FROM machines").to_pylist() == [{"cpu": "first"}]

    store.record_run({"run_id": "r", "machine_id": "M", "note": "first"})
    with pytest.raises(ValueError, match="recorded already"):
        store.record_run({"run_id": "r", "machine_id": "M", "note": "second"})
    assert store.query("SELECT note FROM runs").to_pylist() == [{"note": "first"}]
    with pytest.raises(ValueError, match="machine_id"):
        store.record_run({"run_id": "s"})
    with pytest.raises(ValueError, match="machine_id"):
        store.record_machine({"cpu": "no id"})
    assert _hidden(tmp_path) == []


def test_run_ids_oldest_first(tmp_path):
    store = ResultsStore(tmp_path)
    store.record_run({"run_id": "late", "machine_id": "M", "started": "2024-02-01T00:00"})
    store.record_run({"run_id": "undated", "machine_id": "M"})
    store.record_run({"run_id": "early", "machine_id": "M", "started": "2024-01-01T00:00"})
    assert store.run_ids() == ["early", "late", "undated"]
    other = ResultsStore(tmp_path / "other")
    for i, run_id in enumerate(["b", "c", "a"]):
        other.record_run({"run_id": run_id, "machine_id": "M"})
        os.utime(other.root / "runs" / f"{run_id}.parquet", (1e9 + i, 1e9 + i))
    assert other.run_ids() == ["b", "c", "a"]


def test_results_root(tmp_path, monkeypatch):
    monkeypatch.delenv(RESULTS_ENV, raising=False)
    assert results_root() == Path("figures") / "results"
    assert results_root(figures=tmp_path) == tmp_path / "results"
    monkeypatch.setenv(RESULTS_ENV, "")
    assert results_root(figures=tmp_path) == tmp_path / "results"
    monkeypatch.setenv(RESULTS_ENV, str(tmp_path / "env"))
    assert results_root(figures=tmp_path) == tmp_path / "env"
    assert results_root(tmp_path / "explicit", figures=tmp_path) == tmp_path / "explicit"
    assert not any(tmp_path.iterdir())


WRITER = """
    import sys, time
    from pathlib import Path
    from workbench.results.store import ResultsStore
    root, writer = Path(sys.argv[1]), sys.argv[2]
    store = ResultsStore(root)
    (root.parent / f"ready-{writer}").touch()
    while not (root.parent / "go").exists():
        time.sleep(0.01)
    for batch in range(50):
        rows = [{"writer": writer, "batch": batch, "i": i} for i in range(10)]
        store.append_rows("shared", rows)
        store.append_rows(f"own-{writer}", rows)
"""


def test_two_concurrent_writers_lose_nothing(tmp_path):
    root = tmp_path / "results"
    writers = [_spawn(WRITER, root, w) for w in ("w0", "w1")]
    try:
        deadline = time.monotonic() + 60
        while not all((tmp_path / f"ready-{w}").exists() for w in ("w0", "w1")):
            assert time.monotonic() < deadline and all(p.poll() is None for p in writers)
            time.sleep(0.02)
        (tmp_path / "go").touch()
        assert [p.wait(timeout=60) for p in writers] == [0, 0]
    finally:
        for p in writers:
            if p.poll() is None:
                p.kill()
                p.wait()
    got = ResultsStore(root).query(
        "SELECT run_id, writer, batch, count(*) AS n, count(DISTINCT i) AS d FROM rows "
        "GROUP BY ALL").to_pylist()
    assert len(got) == 2 * 2 * 50
    assert {(r["n"], r["d"]) for r in got} == {(10, 10)}
    assert {r["run_id"] for r in got} == {"shared", "own-w0", "own-w1"}
    for w in ("w0", "w1"):
        assert {r["batch"] for r in got if r["writer"] == w and r["run_id"] == "shared"} == \
            set(range(50))
    assert len(list(root.rglob("*.parquet"))) == 200 and _hidden(root) == []


VICTIM = """
    import sys
    from workbench.results.store import ResultsStore
    store = ResultsStore(sys.argv[1])
    rows = [{"i": i, "x": i * 0.5, "label": f"row {i}"} for i in range(200_000)]
    batch = 0
    while True:
        store.append_rows("victim", rows, batch=batch)
        batch += 1
"""


def test_sigkill_mid_write_leaves_whole_batches(tmp_path):
    root = tmp_path / "results"
    folder = root / "rows" / "run_id=victim"
    child = _spawn(VICTIM, root)
    try:
        deadline = time.monotonic() + 60
        while not list(folder.glob("*.parquet")):
            assert time.monotonic() < deadline and child.poll() is None
            time.sleep(0.01)
        time.sleep(random.uniform(0.0, 0.3))
        known = set(os.listdir(folder))  # then strike as the next file appears: mid-write
        deadline = time.monotonic() + 3
        while set(os.listdir(folder)) <= known and time.monotonic() < deadline:
            time.sleep(0.001)
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
    assert child.returncode == -signal.SIGKILL

    store = ResultsStore(root)
    batches = store.query("SELECT batch, count(*) AS n, count(DISTINCT i) AS d FROM rows "
                          "GROUP BY batch ORDER BY batch").to_pylist()
    assert len(batches) >= 1
    assert [b["batch"] for b in batches] == list(range(len(batches)))
    assert {(b["n"], b["d"]) for b in batches} == {(200_000, 200_000)}

    left = _hidden(root)  # the write the kill interrupted, if it had begun
    assert all(f".{child.pid}@" in p.name for p in left)
    dead = folder / f".{'0' * 32}.parquet.{child.pid}@{_HOST}.0badc0de.tmp"
    dead.write_bytes(b"PAR1 half a file")
    alive = folder / f".{'1' * 32}.parquet.{os.getpid()}@{_HOST}.0123abcd.tmp"
    alive.write_bytes(b"PAR1 being written")
    elsewhere = folder / f".{'2' * 32}.parquet.{child.pid}@another-host.00000001.tmp"
    elsewhere.write_bytes(b"PAR1 on another machine")
    stale = folder / f".{'3' * 32}.parquet.{os.getpid()}@{_HOST}.00000002.tmp"
    stale.write_bytes(b"PAR1 stuck")
    os.utime(stale, (time.time() - 7200, time.time() - 7200))

    assert store.query("SELECT count(*) AS n FROM rows")["n"][0].as_py() == \
        200_000 * len(batches)  # temporary files are never read
    assert sorted(store.clean()) == sorted([*left, dead, stale])
    assert _hidden(root) == sorted([alive, elsewhere])
    assert store.clean() == []
