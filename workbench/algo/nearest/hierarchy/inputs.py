"""Checks and small conversions of the inputs of the element hierarchy and of the part
distances built on it: the time step, the element selection, finite coordinates, the local
origin and the squared form of a cut-off.

Coordinates and lengths are in the mesh's units (millimetres for crash decks).
"""

from __future__ import annotations

import numpy as np


def local_origin(coordinates: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """(3,) float64 centre of the axis-aligned bounding box of ``coordinates[nodes]``: the origin
    every query here subtracts before it computes, so that results keep their digits far from
    the global origin. Two computations on the same nodes with the same origin see bitwise the
    same local coordinates."""
    pts = coordinates[nodes]
    return 0.5 * (pts.min(axis=0) + pts.max(axis=0))


def squared_bound(cutoff: float) -> float:
    """The largest float64 b with sqrt(b) <= ``cutoff`` (inf for inf): a squared distance d2 is
    within the cut-off exactly when d2 <= b, so a search may compare squared distances."""
    if cutoff == np.inf:
        return np.inf
    b = float(cutoff) * float(cutoff)
    while b > 0 and np.sqrt(b) > cutoff:
        b = float(np.nextafter(b, 0.0))
    while np.sqrt(np.nextafter(b, np.inf)) <= cutoff:
        b = float(np.nextafter(b, np.inf))
    return b


def distinct(values) -> np.ndarray:
    """Sorted distinct values of an integer array (by sorting, quick for integer ids)."""
    v = np.sort(np.asarray(values).ravel())
    return v[np.r_[True, v[1:] != v[:-1]]] if len(v) else v


def used_nodes(elements, n_nodes: int) -> np.ndarray:
    """Sorted int64 indices of the nodes that ``elements`` (any shape of node indices) use."""
    mask = np.zeros(n_nodes, bool)
    mask[np.asarray(elements).ravel()] = True
    return np.flatnonzero(mask)


def check_finite(coords: np.ndarray, used: np.ndarray) -> None:
    """ValueError naming the first few of ``used`` nodes whose coordinates are NaN or inf."""
    ok = np.isfinite(coords[used]).all(axis=1)
    if not ok.all():
        raise ValueError(f"non-finite coordinates at used nodes {used[~ok][:5].tolist()}")


def check_elements(elements, m: int) -> np.ndarray:
    """``elements`` as a non-empty int64 selection of distinct element indices in [0, m) (all m
    elements when None). Refused with ValueError: not 1-D integers, out of range, repeated,
    empty."""
    if elements is None:
        sel = np.arange(m, dtype=np.int64)
    else:
        sel = np.asarray(elements)
        if sel.ndim != 1 or (sel.size and not np.issubdtype(sel.dtype, np.integer)):
            raise ValueError(f"elements must be a 1-D array of element indices, got "
                             f"{sel.dtype} {sel.shape}")
        sel = sel.astype(np.int64)
        if sel.size and (sel.min() < 0 or sel.max() >= m):
            raise ValueError(f"elements must lie in [0, {m}), got {sel.min()}..{sel.max()}")
        if len(distinct(sel)) != len(sel):
            raise ValueError("elements must not repeat an element")
    if len(sel) == 0:
        raise ValueError("an element hierarchy needs at least one element; got none")
    return sel
