"""How far a decimation made at one state holds at every other state of a time-dependent result.

crash2000 decimates once, with vertices unchanged, so that the simplified topology shares the
coordinates of every time step. :func:`hausdorff_decimate` certifies its bound for the
coordinates it saw; :func:`bounds_over_states` measures, at each state ``k`` and for each part
``p``, the certified one-sided Hausdorff distance from the original triangles of part ``p`` to
the simplified triangles of part ``p``, both placed at state ``k``'s coordinates
(:func:`workbench.algo.hausdorff.hausdorff`, a bracket whose upper end holds the exact value),
and its ratio to the part's tolerance. A ratio above 1 is a state at which the simplified
animation leaves the tolerance the decimation promised.

Distances are in model units; ratios are dimensionless. ``steps`` is (T, N, 3) float64 (the
vertex array the triangles index, at every state). Refused with ValueError: steps of another
shape, triangles or a decimation that do not index them, a part of the original with no
triangle left in the decimation while it had some (it cannot be measured), a bracket width
``tol`` that is not a positive fraction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..hausdorff import hausdorff
from .decimate import Decimation


@dataclass(frozen=True)
class StateBounds:
    """The certified one-sided distances of a decimation over the states of a result:
    ``upper`` and ``lower`` (T, P) the bracket ends (model units) at each state and part,
    ``part_labels`` (P,) and ``tol_abs`` (P,) as in the decimation, ``ratio`` (T, P) = upper /
    tol_abs (above 1: the tolerance is exceeded at that state), ``states`` (T,) the state
    indices measured."""

    states: np.ndarray
    part_labels: np.ndarray
    tol_abs: np.ndarray
    upper: np.ndarray
    lower: np.ndarray

    @property
    def ratio(self) -> np.ndarray:
        return self.upper / self.tol_abs[None, :]

    def worst(self) -> tuple[int, int, float]:
        """(state, part label, ratio) of the largest ratio over every state and part."""
        k, p = np.unravel_index(int(np.argmax(self.ratio)), self.ratio.shape)
        return int(self.states[k]), int(self.part_labels[p]), float(self.ratio[k, p])

    def worst_per_state(self) -> list[tuple[int, int, float]]:
        """(state, part label, ratio) of the largest ratio at each state, in state order."""
        ratio = self.ratio
        p = np.argmax(ratio, axis=1)
        return [(int(s), int(self.part_labels[q]), float(ratio[k, q]))
                for k, (s, q) in enumerate(zip(self.states, p))]


def bounds_over_states(steps, triangles, parts, decimation: Decimation, *,
                       states=None, tol: float = 0.01, alive=None) -> StateBounds:
    """:class:`StateBounds` of ``decimation`` (made from ``triangles`` (K, 3) with part labels
    ``parts`` (K,)) at each of ``states`` (default every state of ``steps``), each part's
    bracket narrowed to ``tol`` × its tolerance (default 1 %: the ratio's upper end is within
    0.01 of the exact ratio where the bracket reaches its width). ``alive`` (T, K) bool,
    optional, says which of ``triangles`` are drawn at each state (eroded elements are not): a
    simplified triangle is drawn where the triangle it descends from is (its ``source``)."""
    return distances_over_states(steps, triangles, parts, decimation.triangles,
                                 decimation.parts, decimation.part_labels, decimation.tol_abs,
                                 states=states, tol=tol, alive=alive,
                                 simplified_alive=None if alive is None else
                                 np.asarray(alive)[:, decimation.source])


def distances_over_states(steps, triangles, parts, simplified, simplified_parts, part_labels,
                          tol_abs, *, simplified_steps=None, states=None,
                          tol: float = 0.01, alive=None, simplified_alive=None) -> StateBounds:
    """:class:`StateBounds` of any simplified surface: ``simplified`` (K', 3) triangles with
    part labels ``simplified_parts`` (K',), indexing ``simplified_steps`` (T, N', 3) -- by
    default ``steps`` itself, the vertices kept in place --, measured against the original
    ``triangles`` (K, 3) with ``parts`` (K,) at each of ``states``, per part of
    ``part_labels`` (P,) against its tolerance ``tol_abs`` (P,, model units). A simplifier that
    moves vertices has coordinates of its own only at the state it saw: the caller says how its
    vertices follow the others (``simplified_steps``). ``alive`` (T, K) and
    ``simplified_alive`` (T, K') bool, optional (both or neither), say which triangles are drawn
    at each state: only the drawn original triangles are measured, against the drawn simplified
    ones; a part with drawn original triangles and no drawn simplified one is infinitely far
    (upper and lower ``inf``), a part with none drawn is 0."""
    steps = np.asarray(steps, dtype=np.float64)
    if steps.ndim != 3 or steps.shape[2] != 3:
        raise ValueError(f"steps must be (T, N, 3), got {steps.shape}")
    moved = steps if simplified_steps is None else np.asarray(simplified_steps, np.float64)
    if moved.ndim != 3 or moved.shape[0] != steps.shape[0] or moved.shape[2] != 3:
        raise ValueError(f"simplified_steps must be ({steps.shape[0]}, N', 3), got "
                         f"{moved.shape}")
    triangles = np.asarray(triangles, dtype=np.int64)
    simplified = np.asarray(simplified, dtype=np.int64)
    parts = np.asarray(parts)
    simplified_parts = np.asarray(simplified_parts)
    for name, tri, n in (("triangles", triangles, steps.shape[1]),
                         ("the simplified triangles", simplified, moved.shape[1])):
        if tri.ndim != 2 or tri.shape[1] != 3 or (tri.size and (tri.min() < 0 or
                                                                 tri.max() >= n)):
            raise ValueError(f"{name} must be (K, 3) indices of the {n} vertices of their steps")
    if parts.shape != (len(triangles),):
        raise ValueError(f"parts must be ({len(triangles)},), got {parts.shape}")
    if simplified_parts.shape != (len(simplified),):
        raise ValueError(f"simplified_parts must be ({len(simplified)},), got "
                         f"{simplified_parts.shape}")
    if not (np.isfinite(tol) and 0 < tol < 1):
        raise ValueError(f"tol must be a fraction in (0, 1), got {tol!r}")
    if (alive is None) != (simplified_alive is None):
        raise ValueError("alive and simplified_alive go together")
    if alive is not None:
        alive = np.asarray(alive, bool)
        simplified_alive = np.asarray(simplified_alive, bool)
        if alive.shape != (len(steps), len(triangles)) or \
                simplified_alive.shape != (len(steps), len(simplified)):
            raise ValueError(f"alive must be ({len(steps)}, {len(triangles)}) and "
                             f"simplified_alive ({len(steps)}, {len(simplified)}), got "
                             f"{alive.shape} and {simplified_alive.shape}")
    states = np.arange(len(steps)) if states is None else np.asarray(states, np.int64)
    labels = np.asarray(part_labels)
    tol_abs = np.asarray(tol_abs, np.float64)
    upper = np.zeros((len(states), len(labels)))
    lower = np.zeros_like(upper)
    for p, label in enumerate(labels):
        in_part, kept_in_part = parts == label, simplified_parts == label
        if in_part.any() and not kept_in_part.any():
            raise ValueError(f"part {label}: the simplification left no triangle to measure")
        for k, state in enumerate(states):
            mine, kept = in_part, kept_in_part
            if alive is not None:
                mine, kept = mine & alive[state], kept & simplified_alive[state]
            if not mine.any():
                continue
            if not kept.any():
                upper[k, p] = lower[k, p] = np.inf
                continue
            r = hausdorff(steps[state], triangles[mine], moved[state], simplified[kept],
                          tol=tol * tol_abs[p], estimates=False)
            upper[k, p], lower[k, p] = r.upper, r.lower
    return StateBounds(states, labels, tol_abs, upper, lower)
