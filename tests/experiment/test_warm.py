"""Kernels warmed before anything is timed: a quick or full run starts with the experiment's
tiny run (untimed, thrown away), so the first timed call of a compiled kernel is not its
compilation; the tiny run leaves nothing in the figures folder or the results store."""

from __future__ import annotations

import subprocess
import sys

import numba
import numpy as np
import pytest

from workbench.experiment import EXPERIMENTS, experiment, run_experiment
from workbench.experiment.registry import warm_all
from workbench.experiment.warm import warm_experiment


def _kernel():
    """A compiled kernel of its own (not cached on disk), fresh for each test."""

    @numba.njit(cache=False)
    def total(values):
        s = 0.0
        for v in values:
            s += v
        return s

    return total


@pytest.fixture
def timed_kernel_experiment():
    """An experiment that times one call of a fresh kernel, recording how many signatures the
    kernel had compiled when the timed call began (0: the call timed the compiler)."""
    kernel = _kernel()
    seen = []

    @experiment("dummy-warm", "a kernel's first call timed")
    def run(exp):
        size = exp.pick(1000, 100, 10)
        seen.append((exp.size, len(kernel.signatures)))
        kernel(np.ones(size))  # the call an experiment would time
        return [{"size": exp.size}]

    yield seen
    EXPERIMENTS.pop("dummy-warm", None)


def test_a_quick_run_times_a_compiled_kernel(tmp_path, timed_kernel_experiment):
    seen = timed_kernel_experiment
    messages = []
    rows, out_dir = run_experiment("dummy-warm", tmp_path / "figures", quick=True,
                                   progress=messages.append)
    assert seen == [("tiny", 0), ("quick", 1)]  # the tiny run compiled it, the quick run timed it
    assert rows == [{"size": "quick"}]
    assert any("warmed by the tiny run" in m for m in messages)
    # the warm-up left nothing beside the experiment's own folder
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == ["dummy-warm"]


def test_without_warming_the_first_timed_call_compiles(tmp_path, timed_kernel_experiment):
    """The fault the warm-up exists to catch: without it the timed call is the first."""
    seen = timed_kernel_experiment
    run_experiment("dummy-warm", tmp_path, quick=True, warm=False)
    assert seen == [("quick", 0)]


def test_a_tiny_run_is_not_warmed_again(tmp_path, timed_kernel_experiment):
    seen = timed_kernel_experiment
    run_experiment("dummy-warm", tmp_path, size="tiny")
    assert seen == [("tiny", 0)]


def test_warm_experiment_runs_the_tiny_size_and_keeps_nothing(timed_kernel_experiment, tmp_path):
    seen = timed_kernel_experiment
    took = warm_experiment(EXPERIMENTS["dummy-warm"])
    assert seen == [("tiny", 0)] and took >= 0.0
    with pytest.raises(ValueError, match="jobs"):
        warm_all(["dummy-warm"], jobs=0)


def test_the_warm_command_refuses_an_unknown_experiment_in_one_line():
    done = subprocess.run([sys.executable, "-m", "workbench.cli", "warm", "no-such-one"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "unknown experiment 'no-such-one'" in lines[0]
