"""Compiled kernels warmed before anything is timed: an experiment run once at its tiny size.

The workbench's hot loops are numba kernels compiled on first call (and cached on disk, beside
their modules, for the next process). A table that timed a first call would time the compiler:
a fresh clone's first decimation of the car took 47 s where a compiled one takes 0.5 s. So
before an experiment runs at its quick or full size, :func:`warm_experiment` runs the same
experiment at its tiny size (:mod:`workbench.experiment.context`: the smallest cases that still
give every table, row kind and column) into a temporary folder, untimed and unrecorded, and
throws the result away. Every kernel the experiment calls is then compiled — or loaded from the
disk cache — and every lazily imported library loaded, in the process that goes on to time it.

What this does not cover, said plainly: a kernel that only a larger size reaches (the thread
pool of the batched queries starts at 1 024 queries, say) and a type signature that only a
larger case produces still compile inside the real run. They are few; the timed functions that
meet them warm themselves up (``warmup`` calls of :mod:`workbench.measurement.timing`), and the
single-shot stage times of a pipeline are the ones to read with that in mind.

:func:`~workbench.experiment.registry.warm_all` runs every registered experiment's tiny size in
``jobs`` processes at once (spawned, each with its own GL context): ``install.sh`` calls it
(``workbench warm``) so that the numba cache is filled once, at install, and the first
``reproduce`` on a fresh clone compiles only what the tiny runs do not reach. Warm-up runs
never write into the figures folder or the results store.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable

from .context import ExperimentContext


def warm_experiment(experiment, progress: Callable[[str], None] | None = None) -> float:
    """Run ``experiment`` (a registered :class:`~workbench.experiment.registry.Experiment`)
    at its tiny size into a temporary folder that is then removed; its rows are thrown away
    and nothing is recorded. Returns the wall seconds it took. An error of the tiny run
    propagates: an experiment that cannot run small would fail at its real size too."""
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix=f"workbench-warm-{experiment.name}-") as tmp:
        context = ExperimentContext(experiment.name, tmp, "tiny", progress,
                                    declared=getattr(experiment, "declared", None))
        try:
            experiment.function(context)
        finally:
            context.close()
    return time.perf_counter() - start
