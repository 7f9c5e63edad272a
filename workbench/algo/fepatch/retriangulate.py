"""Retriangulation of simplified subpatches (stage 2 of :mod:`.pipeline`): each subpatch's
border loops, with the removed line nodes left out, projected on its plane and triangulated by
hole bridging and ear clipping; a subpatch whose loops are not simple polygons in its plane
keeps its original elements, and its border lines are restored in every neighbour, so that no
crack opens between them."""

from __future__ import annotations

import numpy as np

from ...scene.derived import triangulate
from .borders import BorderNetwork
from .certify import array_digest
from .polygon import polygon_area, triangulate_polygon


def _loops(directed: np.ndarray) -> list[np.ndarray] | None:
    """Closed node loops of one subpatch's directed border edges; None where a node has two
    outgoing edges or an edge leads nowhere (pinched or inconsistently wound borders)."""
    a, b = directed[:, 0], directed[:, 1]
    if len(np.unique(a)) != len(a):
        return None
    succ = dict(zip(a.tolist(), b.tolist()))
    seen = set()
    loops = []
    for start in a.tolist():
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        node = succ[start]
        while node != start:
            if node in seen or node not in succ:
                return None
            loop.append(node)
            seen.add(node)
            node = succ[node]
        loops.append(np.array(loop))
    return loops


def _triangulate_subpatch(loops, removed, coords, frame) -> np.ndarray | None:
    """(K, 3) node triangles of one subpatch's simplified loops in its plane, wound like the
    elements; None when the loops do not form a simple polygon with holes."""
    kept = [loop[~removed[loop]] for loop in loops]
    if any(len(k) < 3 for k in kept):
        return None
    nodes = np.concatenate(kept)
    origin, axes = frame
    pts = (coords[nodes] - origin) @ axes[:2].T
    local, start = [], 0
    for k in kept:
        local.append(np.arange(start, start + len(k)))
        start += len(k)
    areas = [polygon_area(pts, loop) for loop in local]
    outer = int(np.argmax(np.abs(areas)))
    holes = [loop for i, loop in enumerate(local) if i != outer]
    # a hole runs against the outer loop when the elements are wound consistently
    if any(np.sign(areas[i]) == np.sign(areas[outer]) for i in range(len(local)) if i != outer):
        return None
    try:
        tri = triangulate_polygon(pts, local[outer], holes)
    except ValueError:
        return None
    if areas[outer] < 0:  # elements wound clockwise in this frame
        tri = tri[:, ::-1]
    return nodes[tri]


def _memo_triangulation(loops, removed, coords, frame, memo):
    """:func:`_triangulate_subpatch`, looked up in ``memo`` (a dict, or None) first."""
    if memo is None:
        return _triangulate_subpatch(loops, removed, coords, frame)
    kept = [loop[~removed[loop]] for loop in loops]
    key = array_digest(np.array([len(k) for k in kept]), *kept, frame[0], frame[1])
    if key not in memo:
        memo[key] = _triangulate_subpatch(loops, removed, coords, frame)
    return memo[key]


def simplified_triangles(elements, coords, labels, network: BorderNetwork,
                         removed: np.ndarray, frames, triangulation=None,
                         keep=(), memo=None) -> tuple[dict, np.ndarray, np.ndarray]:
    """({label: (K, 3) node triangles}, fallback labels, final ``removed``): every subpatch
    retriangulated from its simplified border loops; those that fail keep their original
    element triangles and restore their border nodes, which re-triangulates the neighbours.
    ``triangulation``: the elements' :func:`triangulate`, computed when not given; ``keep``:
    labels that keep their original elements from the start (their border nodes restored);
    ``memo``: a dict kept between calls on the same coordinates, so that a subpatch with the
    same simplified loops and plane is not triangulated again.
    """
    e = np.asarray(elements, np.int64)
    lab = np.asarray(labels, np.int64)
    removed = removed.copy()
    d = network.directed
    order = np.argsort(d[:, 2], kind="stable")
    d = d[order]
    bounds = np.searchsorted(d[:, 2], np.arange(lab.max() + 2))
    loops = {}
    for s in range(lab.max() + 1):
        if bounds[s] == bounds[s + 1]:
            continue
        loops[s] = None if s in set(network.bad.tolist()) else _loops(d[bounds[s]:bounds[s + 1]])
    result: dict = {}
    failed = {int(s) for s in keep if int(s) in loops}  # kept as original elements
    restored: set[int] = set()  # border lines restored after a failure with simplified ones
    for s in failed:
        nodes = np.unique(d[bounds[s]:bounds[s + 1], :2])
        removed[nodes] = False
    todo = set(loops) - failed
    while todo:
        new_fail = []
        for s in sorted(todo):
            tri = None if loops[s] is None else _memo_triangulation(loops[s], removed, coords,
                                                                  frames[s], memo)
            if tri is None:
                new_fail.append(s)
            else:
                result[s] = tri
        todo = set()
        restore = []
        for s in new_fail:
            result.pop(s, None)
            if s in restored or loops[s] is None:
                failed.add(s)
            else:
                restored.add(s)
                todo.add(s)
            nodes = np.unique(d[bounds[s]:bounds[s + 1], :2])
            restore.append(nodes[removed[nodes]])
        restore = np.concatenate(restore) if restore else np.zeros(0, np.int64)
        if len(restore):
            removed[restore] = False
            mark = np.zeros(len(removed), bool)
            mark[restore] = True
            touched = np.unique(d[mark[d[:, 0]] | mark[d[:, 1]], 2])
            todo |= {int(s) for s in touched if s not in failed}
    fallback = np.array(sorted(failed), np.int64)
    if len(fallback):
        tri = triangulation if triangulation is not None else triangulate(e, coords)
        of = lab[tri.element_of]
        for s in fallback:
            result[int(s)] = tri.triangles[of == s].astype(np.int64)
    return result, fallback, removed
