"""Clusters kept for a block of work: :func:`kept_clusters`.

Within the block, :func:`~workbench.distributed.cluster.sweep_cluster` calls that start a local
cluster share one cluster per set of arguments: the first call starts it, later ones reuse it,
its workers already warm (their kernels compiled or loaded from the disk cache, their GL
contexts made), and it is closed when the block ends, also on an error. An experiment's
untimed tiny run and its timed run share their cluster this way
(:func:`~workbench.experiment.registry.run_experiment`), so that the timed run neither starts a
second cluster nor times its workers' first calls. Connections to an existing scheduler are not
kept. This module imports nothing of Dask: entering the block costs nothing where no cluster
is started.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Kept:
    """The clusters of one :func:`kept_clusters` block, by their arguments, and the stack
    that closes them when the block ends."""

    stack: ExitStack
    clusters: dict[tuple, Any] = field(default_factory=dict)


_BLOCKS: list[Kept] = []


@contextmanager
def kept_clusters() -> Iterator[Kept]:
    """A block within which local clusters are started once per set of arguments and kept
    until it ends (see the module notes); yields its :class:`Kept`."""
    with ExitStack() as stack:
        block = Kept(stack)
        _BLOCKS.append(block)
        try:
            yield block
        finally:
            _BLOCKS.remove(block)


def innermost_kept() -> Kept | None:
    """The innermost open :func:`kept_clusters` block, or None outside any."""
    return _BLOCKS[-1] if _BLOCKS else None
