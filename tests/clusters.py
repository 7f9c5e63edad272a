"""A Dask scheduler and workers started as processes of their own (the command-line tools of
distributed), as on a real cluster, for the tests that must not run on a LocalCluster."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from contextlib import contextmanager


@contextmanager
def scheduler_and_workers(folder, workers: int = 2):
    """Start ``python -m distributed.cli.dask_scheduler`` on 127.0.0.1 (its address file in
    ``folder``) and one ``dask_worker`` process with ``workers`` single-threaded workers; yield
    the scheduler's address once the workers may connect; stop both on the way out."""
    scheduler_file = folder / "scheduler.json"
    started = []
    try:
        started.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
             "--port", "0", "--no-dashboard", "--scheduler-file", str(scheduler_file)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + 60
        while not scheduler_file.exists():
            assert time.monotonic() < deadline and started[0].poll() is None
            time.sleep(0.1)
        time.sleep(0.2)  # the file is complete once its JSON parses
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        started.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--host",
             "127.0.0.1", "--nworkers", str(workers), "--nthreads", "1", "--no-dashboard"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield address
    finally:
        for proc in reversed(started):
            proc.terminate()
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
