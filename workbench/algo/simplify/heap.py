"""The priority queue of half-edges and the quadric cost that orders it.

Collapse order: a priority queue of half-edges by a quadric error (the mean squared distance of
v from the planes of the original triangles around u and around the vertices already collapsed
into it, plus a small share of the squared edge length, which orders flat regions by edge
length), with lazy invalidation by per-vertex version stamps: an entry carries the version of
u when it was pushed and is dropped when popped under a newer one.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

# weight of the squared edge length in the collapse cost (orders flat regions)
_LENGTH_WEIGHT = 1e-3


class Heap(NamedTuple):
    """A binary min-heap of half-edges u → v by ``cost``, held in its first n entries (the size
    travels beside it); ``stamp`` is the version of u when the entry was pushed."""

    cost: np.ndarray     # (C,) float64
    u: np.ndarray        # (C,) int32
    v: np.ndarray        # (C,) int32
    stamp: np.ndarray    # (C,) int32


@numba.njit(cache=True)
def _new_heap():
    """An empty heap with room for 16 entries."""
    return Heap(np.empty(16), np.empty(16, np.int32), np.empty(16, np.int32),
                np.empty(16, np.int32))


@numba.njit(cache=True)
def _heap_push(heap, n, key, u, v, stamp):
    """Push onto ``heap`` holding n entries; returns the heap (grown when full) and the new
    size."""
    hk, hu, hv, hs = heap.cost, heap.u, heap.v, heap.stamp
    if n == len(hk):
        cap = 2 * len(hk) + 16
        nk = np.empty(cap)
        nu = np.empty(cap, np.int32)
        nv = np.empty(cap, np.int32)
        ns = np.empty(cap, np.int32)
        nk[:n] = hk[:n]
        nu[:n] = hu[:n]
        nv[:n] = hv[:n]
        ns[:n] = hs[:n]
        hk, hu, hv, hs = nk, nu, nv, ns
        heap = Heap(hk, hu, hv, hs)
    i = n
    while i > 0:
        parent = (i - 1) >> 1
        if hk[parent] <= key:
            break
        hk[i], hu[i], hv[i], hs[i] = hk[parent], hu[parent], hv[parent], hs[parent]
        i = parent
    hk[i], hu[i], hv[i], hs[i] = key, u, v, stamp
    return heap, n + 1


@numba.njit(cache=True)
def _heap_pop(heap, n):
    """Remove the smallest of the n entries; returns it (u, v, stamp) and the new size."""
    hk, hu, hv, hs = heap.cost, heap.u, heap.v, heap.stamp
    u, v, s = hu[0], hv[0], hs[0]
    n -= 1
    key, lu, lv, ls = hk[n], hu[n], hv[n], hs[n]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= n:
            break
        if c + 1 < n and hk[c + 1] < hk[c]:
            c += 1
        if key <= hk[c]:
            break
        hk[i], hu[i], hv[i], hs[i] = hk[c], hu[c], hv[c], hs[c]
        i = c
    if n > 0:
        hk[i], hu[i], hv[i], hs[i] = key, lu, lv, ls
    return u, v, s, n


@numba.njit(cache=True, inline="always")
def _cost(Q, area, V, a, b):
    """Mean squared distance of b from a's accumulated planes plus a share of |ab|²."""
    x, y, z = V[b, 0], V[b, 1], V[b, 2]
    q = Q[a]
    e = (q[0] * x * x + q[1] * y * y + q[2] * z * z + 2.0 * (q[3] * x * y + q[4] * x * z
         + q[5] * y * z) + 2.0 * (q[6] * x + q[7] * y + q[8] * z) + q[9])
    dx, dy, dz = x - V[a, 0], y - V[a, 1], z - V[a, 2]
    return max(e, 0.0) / max(area[a], 1e-300) + _LENGTH_WEIGHT * (dx * dx + dy * dy + dz * dz)
