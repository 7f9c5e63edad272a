"""Per-subpatch certificates of fe2003's distance bound ``d``.

The simplified surface must stay within ``d`` of the original: the one-sided Hausdorff distance
original → simplified is at most ``d``. That distance is the largest, over the subpatches, of
the distance from a subpatch's original elements to the simplified surface, and the simplified
surface contains the subpatch's own new triangles and its neighbours'. So measuring each
subpatch's original triangles against the new triangles of the subpatch and of every subpatch
that shares a node with it, with the exact metric :func:`workbench.algo.hausdorff.hausdorff`,
gives an upper bound per subpatch whose largest value bounds the whole surface: the global
distance is certified once every subpatch's bound is at most ``d``.
"""

from __future__ import annotations

import hashlib

import numpy as np
from scipy.sparse import coo_matrix

from ..hausdorff import hausdorff

__all__ = ["array_digest", "subpatch_distance_bounds", "subpatch_neighbours"]


def subpatch_neighbours(elements, labels) -> dict[int, np.ndarray]:
    """{label: sorted labels of the other subpatches that share a node with it}.

    ``elements`` (M, 4) node indices, ``labels`` (M,) non-negative subpatch labels."""
    e = np.asarray(elements, np.int64)
    lab = np.asarray(labels, np.int64)
    n_nodes = int(e.max()) + 1 if e.size else 0
    n_labels = int(lab.max()) + 1 if lab.size else 0
    incidence = coo_matrix((np.ones(e.size, np.int32), (e.ravel(), np.repeat(lab, 4))),
                           shape=(n_nodes, n_labels)).tocsc()
    incidence.data[:] = 1
    touch = (incidence.T @ incidence).tocsr()
    out = {}
    for s in np.unique(lab):
        row = touch.indices[touch.indptr[s]:touch.indptr[s + 1]]
        out[int(s)] = np.sort(row[row != s])
    return out


def subpatch_distance_bounds(coords, original, original_label, simplified: dict, check,
                             neighbours: dict, tol: float,
                             cache: dict | None = None) -> dict[int, float]:
    """{label: certified upper bound (model units) on the distance from the subpatch's original
    triangles to the simplified surface}, for every label in ``check``.

    ``coords`` (N, 3) float64 model units; ``original`` (T, 3) node triangles of the original
    elements and ``original_label`` (T,) their subpatch; ``simplified`` {label: (K, 3) node
    triangles}, the whole simplified surface; ``neighbours`` as :func:`subpatch_neighbours`;
    ``tol`` the width of the Hausdorff bracket (model units, > 0). A subpatch whose simplified
    triangles are its original ones gets 0.

    Each subpatch is measured against its own and its neighbours' new triangles, a part of
    the simplified surface, so its bound is never below its true distance to the surface.
    ``cache``, a dict kept between calls on the same ``coords`` and ``tol``, holds the bounds by
    a digest of their exact triangle sets, so that a subpatch whose triangles and neighbours'
    triangles did not change is not measured again. Refuses a non-positive ``tol``.
    """
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be a positive distance, got {tol!r}")
    c = np.asarray(coords, np.float64)
    orig = np.asarray(original, np.int64)
    lab = np.asarray(original_label, np.int64)
    order = np.argsort(lab, kind="stable")
    start = np.searchsorted(lab[order], np.arange(int(lab.max()) + 2))

    def own_original(s: int) -> np.ndarray:
        return orig[order[start[s]:start[s + 1]]] if s + 1 < len(start) else orig[:0]

    def nearby(s: int) -> np.ndarray:
        """The simplified triangles of subpatch ``s`` and of its neighbours."""
        near = (s, *(int(t) for t in neighbours.get(s, ())))
        parts = [simplified[t] for t in near if t in simplified]
        return np.concatenate(parts) if parts else np.zeros((0, 3), np.int64)

    out: dict[int, float] = {}
    for s in (int(s) for s in check):
        a = own_original(s)
        own = simplified.get(s)
        if len(a) == 0 or (own is not None and len(own) == len(a) and np.array_equal(own, a)):
            out[s] = 0.0
            continue
        b = nearby(s)
        if cache is None:
            out[s] = _bound(c, a, b, tol)
            continue
        key = _digest(a, b)
        if key not in cache:
            cache[key] = _bound(c, a, b, tol)
        out[s] = cache[key]
    return out


def array_digest(*arrays) -> bytes:
    """A 16-byte digest of ``arrays``' types, shapes and contents: the key of a memo of
    repeated work."""
    h = hashlib.blake2b(digest_size=16)
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return h.digest()


def _digest(a: np.ndarray, b: np.ndarray) -> bytes:
    """A digest of the triangle sets ``a`` (in order) and ``b`` (in any order)."""
    return array_digest(np.asarray(a, np.int64), _sorted_rows(b))


def _sorted_rows(t: np.ndarray) -> np.ndarray:
    """Triangles in a canonical order (rows sorted lexicographically), int64."""
    t = np.ascontiguousarray(t, np.int64)
    return t[np.lexsort(t.T[::-1])] if len(t) else t


def _bound(c: np.ndarray, a: np.ndarray, b: np.ndarray, tol: float) -> float:
    """Certified upper bound on the one-sided distance from triangles ``a`` to ``b``."""
    if len(b) == 0:
        return np.inf
    nodes, inverse = np.unique(np.concatenate([a.ravel(), b.ravel()]), return_inverse=True)
    local = c[nodes]
    ia = inverse[:a.size].reshape(a.shape)
    ib = inverse[a.size:].reshape(b.shape)
    return float(hausdorff(local, ia, local, ib, one_sided=True, tol=tol,
                           estimates=False).upper)
