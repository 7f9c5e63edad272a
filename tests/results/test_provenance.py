"""Provenance of a run: the machine fingerprint, the code state and the run record, checked
against independent sources (git itself, /proc, the installed packages)."""

import json
import os
import subprocess
from importlib import metadata
from pathlib import Path

import pytest

from workbench.results.provenance import (
    LIBRARIES,
    MACHINE_FIELDS,
    check_run_id,
    code_state,
    library_versions,
    machine_fingerprint,
    new_run_id,
    run_record,
)

ROOT = Path(__file__).resolve().parents[2]
RENDERER = {"renderer": "TestGPU 9000", "gl_vendor": "Test", "gl_version": "4.6 Test 1.0",
            "driver": "Test 1.0", "egl_device": "/dev/dri/renderD128"}


def git(*args: str, cwd: Path = ROOT) -> str:
    return subprocess.run(["git", "-C", str(cwd), *args], capture_output=True, text=True,
                          check=True).stdout.strip()


def test_commit_and_dirty_state_are_gits_own():
    state = code_state()
    assert state["version"] == metadata.version("workbench")
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    assert state["commit"] == git("rev-parse", "HEAD")
    dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
    assert state["dirty"] is dirty


def test_a_change_to_a_tracked_file_makes_the_tree_dirty(tmp_path):
    repo = tmp_path / "repo"
    repo.mkdir()
    env = {**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t",
           "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t"}
    for args in (["init", "-q"], ["add", "f"], ["commit", "-q", "-m", "one"]):
        if args[0] == "add":
            (repo / "f").write_text("one\n")
        subprocess.run(["git", "-C", str(repo), *args], check=True, env=env)
    clean = code_state(repo)
    assert clean["commit"] == git("rev-parse", "HEAD", cwd=repo) and clean["dirty"] is False
    (repo / "f").write_text("two\n")
    assert code_state(repo)["dirty"] is True
    (repo / "untracked").write_text("x")  # untracked files do not change what was measured
    subprocess.run(["git", "-C", str(repo), "checkout", "-q", "f"], check=True)
    assert code_state(repo)["dirty"] is False


def test_outside_a_checkout_commit_and_dirty_are_unknown(tmp_path):
    state = code_state(tmp_path)
    assert state["commit"] is None and state["dirty"] is None


def test_fingerprint_names_the_machine_and_hashes_it():
    machine = machine_fingerprint(renderer=RENDERER)
    assert set(machine) == {"machine_id", *MACHINE_FIELDS}
    assert machine["logical_cores"] == os.cpu_count()
    assert machine["renderer"] == "TestGPU 9000" and machine["driver"] == "Test 1.0"
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        assert machine["cpu"] in cpuinfo.read_text()
    meminfo = Path("/proc/meminfo")
    if meminfo.exists():
        kib = int(meminfo.read_text().split("MemTotal:")[1].split()[0])
        assert abs(machine["memory_gib"] - kib / 2**20) < 0.2
    # the same fields give the same id; another renderer another
    assert machine_fingerprint(renderer=RENDERER)["machine_id"] == machine["machine_id"]
    other = machine_fingerprint(renderer={**RENDERER, "egl_device": "/dev/dri/renderD129"})
    assert other["machine_id"] != machine["machine_id"]


@pytest.mark.gl
def test_fingerprint_of_the_real_context_names_its_renderer(ctx):
    machine = machine_fingerprint(ctx)
    assert machine["renderer"] == ctx.info["GL_RENDERER"]
    assert machine["gl_version"] == ctx.info["GL_VERSION"]


def test_run_record_carries_code_libraries_and_load():
    machine = machine_fingerprint(renderer=RENDERER)
    run = run_record(machine, "run render_paths --quick", size="quick", note="x")
    assert run["machine_id"] == machine["machine_id"] and run["size"] == "quick"
    assert run["command"] == "run render_paths --quick" and run["note"] == "x"
    assert run["commit"] == code_state()["commit"]
    libraries = json.loads(run["libraries"])
    assert set(libraries) == set(LIBRARIES)
    assert libraries["numpy"] == metadata.version("numpy")
    assert run["load_1m"] == pytest.approx(os.getloadavg()[0], abs=2.0)
    assert library_versions(("no-such-package-xyz",)) == {"no-such-package-xyz": None}


def test_run_ids_sort_by_time_are_unique_and_checked():
    ids = {new_run_id() for _ in range(200)}
    assert len(ids) == 200
    assert all(check_run_id(i) == i for i in ids)
    for bad in ("", "a/b", "../x", "..", ".hidden", "a b", 3):
        with pytest.raises(ValueError, match="run id"):
            check_run_id(bad)
