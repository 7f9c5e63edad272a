"""EGL devices: listing them, choosing one (``--device``, ``WORKBENCH_EGL_DEVICE``), pinning Dask
workers one device each, the device identity in rows, ``workbench doctor``, and Dask's log
lines kept at WARNING unless ``--verbose``."""

from __future__ import annotations

import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.cli import main
from workbench.distributed.cluster import device_assignment
from workbench.gl.context import probed_devices
from workbench.gl.devices import DEVICE_ENV, current_device, device_index, egl_devices

pytestmark = pytest.mark.gl


def test_the_devices_are_listed_with_distinct_identities_and_a_context_on_each():
    devices = probed_devices()
    assert devices, "EGL lists no device"
    assert [d.index for d in devices] == list(range(len(devices)))
    assert len({d.identity for d in devices}) == len(devices)
    assert all(d.renderer for d in devices)  # a context was made on every device
    assert all(d.identity.startswith(f"egl{d.index}:") for d in devices)


def test_what_a_gpu_driver_says_of_its_devices_is_read():
    """CUDA ids and UUIDs where the driver offers them (NVIDIA's EGL): none on Mesa alone, so
    on a machine without such a GPU this checks only that nothing is invented."""
    devices = egl_devices()
    for d in devices:
        if "EGL_NV_device_cuda" in d.extensions:
            assert isinstance(d.cuda_device, int) and d.cuda_device >= 0
        else:
            assert d.cuda_device is None
        if "EGL_EXT_device_persistent_id" in d.extensions:
            assert d.uuid is not None and len(d.uuid) == 32 and int(d.uuid, 16) >= 0
            assert d.identity == f"egl{d.index}:{d.uuid}"
        else:
            assert d.uuid is None
    cuda = [d.cuda_device for d in devices if d.cuda_device is not None]
    assert len(set(cuda)) == len(cuda)
    uuids = [d.uuid for d in devices if d.uuid is not None]
    assert len(set(uuids)) == len(uuids)


def test_a_context_is_made_on_the_device_asked_for():
    from workbench.gl import create_context, renderer
    from workbench.gl.context import egl, keeping_current

    last = len(egl_devices()) - 1
    with keeping_current() as restore:
        other = create_context(device=last)
        restore.display = egl().eglGetCurrentDisplay()
        try:
            assert current_device().index == last
            assert renderer(other) == probed_devices()[last].renderer
        finally:
            other.release()


def test_device_index_comes_from_the_argument_then_the_environment(monkeypatch):
    monkeypatch.delenv(DEVICE_ENV, raising=False)
    assert device_index() == 0
    assert device_index("0") == 0
    monkeypatch.setenv(DEVICE_ENV, "0")
    assert device_index() == 0
    count = len(egl_devices())
    monkeypatch.setenv(DEVICE_ENV, str(count))
    with pytest.raises(ValueError, match=f"{DEVICE_ENV} {count}: this machine has {count} EGL"):
        device_index()
    assert device_index(0) == 0  # the argument wins over the environment


@pytest.mark.parametrize("value, message", [
    ("x", "expected an EGL device index"), ("1.5", "expected an EGL device index"),
    ("-1", "0 or more"), ("99", "this machine has"),
])
def test_bad_device_indices_are_refused_in_one_line(value, message):
    with pytest.raises(ValueError, match=message) as info:
        device_index(value)
    assert "\n" not in str(info.value)


def test_glcontext_device_variable_that_disagrees_is_refused(monkeypatch):
    from workbench.gl import create_context

    monkeypatch.setenv("GLCONTEXT_DEVICE_INDEX", "5")
    with pytest.raises(ValueError, match="GLCONTEXT_DEVICE_INDEX=5 overrides"):
        create_context(device=0)


@pytest.mark.parametrize("argv", [
    ["info", "--device", "9"],
    ["render", "semicylinders:2", "-o", "{out}", "--size", "40x30", "--device", "9"],
    ["run", "render_paths", "--device", "9", "--figures", "{dir}"],
    ["doctor", "--device", "nine"],
])
def test_a_device_out_of_range_is_one_line_and_exit_2(argv, tmp_path, capsys):
    argv = [a.format(out=tmp_path / "x.png", dir=tmp_path) for a in argv]
    status = main(argv)
    err = capsys.readouterr().err.strip()
    if argv[0] == "doctor":  # doctor reports the failure as a failed check, exit 1
        assert status == 1
        return
    assert status == 2
    assert err.count("\n") == 0 and err.startswith("workbench: error: --device 9: this machine")
    assert not (tmp_path / "x.png").exists()


def test_info_lists_every_device_with_its_identity(capsys):
    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert "EGL devices (" in out
    for device in probed_devices():
        line = next(ln for ln in out.splitlines() if ln.strip().startswith(f"{device.index} "))
        assert device.identity in line and device.renderer in line


# ---------------------------------------------------------------------- pinning workers

def test_round_robin_over_each_hosts_devices():
    counts = {f"tcp://a:{p}": 2 for p in (1, 2, 3)} | {"tcp://b:1": 1, "tcp://b:2": 1}
    hosts = {address: address.split(":")[1][2:] for address in counts}
    assert device_assignment(counts, hosts) == {
        "tcp://a:1": 0, "tcp://a:2": 1, "tcp://a:3": 0, "tcp://b:1": 0, "tcp://b:2": 0}
    assert device_assignment(counts, hosts, [0]) == dict.fromkeys(counts, 0)
    with pytest.raises(ValueError, match="--worker-devices 1: host b has 1 EGL device"):
        device_assignment(counts, hosts, [0, 1])
    assert device_assignment({"tcp://c:1": 0}, {"tcp://c:1": "c"}) == {}  # no EGL there


@given(st.dictionaries(st.integers(0, 50), st.tuples(st.sampled_from("abc"),
                                                     st.integers(0, 4)), min_size=1))
def test_pinned_workers_spread_evenly_over_their_hosts_devices(workers):
    counts, hosts = {}, {}
    for port, (host, _) in workers.items():
        address = f"tcp://{host}:{port:03d}"
        # one device count per host, as every worker of a host sees the same devices
        counts[address] = max(n for h, n in workers.values() if h == host)
        hosts[address] = host
    assigned = device_assignment(counts, hosts)
    for host in set(hosts.values()):
        mine = [a for a in counts if hosts[a] == host]
        if counts[mine[0]] == 0:
            assert not any(a in assigned for a in mine)
            continue
        used = [assigned[a] for a in mine]
        assert all(0 <= d < counts[mine[0]] for d in used)
        per_device = [used.count(d) for d in range(counts[mine[0]])]
        assert max(per_device) - min(per_device) <= 1


@pytest.mark.slow
def test_two_local_workers_each_report_their_pinned_device():
    from workbench.distributed.cluster import sweep_cluster

    expected = [d.identity for d in egl_devices()]
    with sweep_cluster(2) as cluster:
        assert len(cluster.devices) == 2
        pinned = [cluster.devices[a] for a in sorted(cluster.devices)]
        assert pinned == [expected[i % len(expected)] for i in range(2)]
        env = cluster.client.run(lambda: __import__("os").environ.get(DEVICE_ENV))
        assert sorted(env.values()) == sorted(str(i % len(expected)) for i in range(2))


@pytest.mark.slow
def test_an_explicit_device_list_out_of_range_is_refused(tmp_path):
    out = tmp_path / "x.png"
    done = subprocess.run(
        [sys.executable, "-m", "workbench.cli", "render", "semicylinders:2", "-o", str(out),
         "--size", "40x30", "--domains", "2", "--workers", "1", "--worker-devices", "0,7"],
        capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == ("workbench: error: --worker-devices 7: host 127.0.0.1 has "
                                   f"{len(egl_devices())} EGL device")
    assert not out.exists()


# ---------------------------------------------------------------------- Dask's log lines

@pytest.mark.slow
@pytest.mark.parametrize("verbose", [False, True])
def test_dask_info_lines_only_with_verbose(tmp_path, verbose):
    out = tmp_path / "x.png"
    done = subprocess.run(
        [sys.executable, "-m", "workbench.cli", "render", "semicylinders:2", "-o", str(out),
         "--size", "40x30", "--domains", "2", "--workers", "2"] + ["--verbose"] * verbose,
        capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    info = [line for line in done.stderr.splitlines() if " - INFO - " in line]
    assert bool(info) == verbose, done.stderr
    devices = [line for line in done.stderr.splitlines() if line.startswith("worker tcp://")]
    assert len(devices) == 2 and all("EGL device egl" in line for line in devices)
    assert out.is_file()


# ---------------------------------------------------------------------- doctor

def test_doctor_passes_every_check_here(capsys):
    status = main(["doctor"])
    out = capsys.readouterr().out
    assert status == 0, out
    names = ("EGL", "devices", "OpenGL", "shared data", "numba cache", "Dask")
    for name in names:
        assert any(ln.startswith("ok") and f" {name} " in ln for ln in out.splitlines()), name
    assert out.strip().endswith("6 of 6 checks passed")


@pytest.mark.parametrize("fault, failed", [
    ("device", "devices"), ("data", "shared data"), ("numba", "numba cache"),
    ("scheduler", "Dask"),
])
def test_doctor_names_the_fix_of_each_injected_fault(fault, failed, tmp_path, monkeypatch,
                                                     capsys):
    argv = ["doctor"]
    if fault == "device":
        monkeypatch.setenv(DEVICE_ENV, "42")
    elif fault == "data":
        monkeypatch.setenv("WORKBENCH_DATA", str(tmp_path))
    elif fault == "numba":
        blocker = tmp_path / "file"
        blocker.write_text("")
        monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocker / "cache"))
    else:
        argv += ["--scheduler", "tcp://127.0.0.1:9"]  # nothing listens on the discard port
    status = main(argv)
    out = capsys.readouterr().out
    assert status == 1
    lines = out.splitlines()
    fail = next(i for i, ln in enumerate(lines) if ln.startswith("FAIL") and f" {failed} " in ln)
    assert lines[fail + 1].strip().startswith("fix: ")
    assert failed in lines[-1].split("failed: ")[1].split(", ")


def test_doctor_names_the_fix_when_libegl_is_missing(monkeypatch):
    import ctypes

    from workbench.cli.doctor import check_egl

    real = ctypes.CDLL

    def missing(name, *args, **kwargs):
        if name == "libEGL.so.1":
            raise OSError("libEGL.so.1: cannot open shared object file")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(ctypes, "CDLL", missing)
    check = check_egl()
    assert not check.ok and "apt-get install libegl1" in check.fix


# ---------------------------------------------------------------------- rows

def test_rows_drawn_on_the_gl_context_record_its_device(tmp_path, monkeypatch):
    from workbench.experiment.registry import EXPERIMENTS, experiment, run_experiment
    from workbench.gl.context import keeping_current
    from workbench.output.tables import read_table

    last = len(egl_devices()) - 1
    monkeypatch.setenv(DEVICE_ENV, str(last))

    @experiment("dummy-device-rows", "one GL row, one software row, one more table")
    def run(exp):
        exp.table([{"renderer": exp.renderer, "case": "t"}], "more", "more")
        return [{"renderer": exp.renderer, "case": "gl"},
                {"renderer": "software (es2008)", "case": "sw"}]

    try:
        with keeping_current():
            rows, out_dir = run_experiment("dummy-device-rows", tmp_path, size="tiny")
    finally:
        del EXPERIMENTS["dummy-device-rows"]
    identity = egl_devices()[last].identity
    table = {r["case"]: r for r in read_table(out_dir / "table.csv")}
    assert table["gl"]["egl_device"] == identity
    assert table["sw"]["egl_device"] is None  # not drawn on the GL device
    assert read_table(out_dir / "more.csv")[0]["egl_device"] == identity
