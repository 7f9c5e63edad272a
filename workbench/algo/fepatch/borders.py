"""Subpatch borders as a line network, and its simplification (stage 1 of
:mod:`.pipeline`).

An element edge is a border edge of subpatch s when s's elements use it once; the border edges
form lines between fixed nodes (nodes where the line's neighbourhood changes). Each line is
simplified within eq. 1's bound (:func:`~.lines.line_tolerance`). Pinches -- a subpatch whose
border passes a node twice -- are removed first (:func:`unpinched`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .certify import array_digest
from .lines import line_tolerance, simplify_polyline


@dataclass
class BorderNetwork:
    """Subpatch borders: directed border edges per subpatch and the undirected line network.

    ``directed`` (B, 3) rows (a, b, subpatch) in element winding; ``bad`` labels of subpatches
    with an edge used three or more times inside them; ``lines`` list of (node array, closed,
    subpatch labels); ``fixed`` (N,) bool.
    """

    directed: np.ndarray
    bad: np.ndarray
    lines: list
    fixed: np.ndarray


def _border_edges(elements, labels, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """((B, 3) directed border edges (a, b, subpatch) in element winding, labels of subpatches
    with an edge used three or more times inside them)."""
    e = np.asarray(elements, np.int64)
    lab = np.asarray(labels, np.int64)
    a = e.ravel()
    b = e[:, [1, 2, 3, 0]].ravel()
    s = np.repeat(lab, 4)
    ok = a != b
    a, b, s = a[ok], b[ok], s[ok]
    key = np.minimum(a, b) * n_nodes + np.maximum(a, b)
    order = np.lexsort((key, s))
    ks, kk = s[order], key[order]
    start = np.r_[True, (ks[1:] != ks[:-1]) | (kk[1:] != kk[:-1])]
    group = np.cumsum(start) - 1
    per = np.bincount(group)[group]
    border = order[per == 1]
    return np.c_[a[border], b[border], s[border]], np.unique(ks[per >= 3])


def unpinched(elements, labels, n_nodes: int, rounds: int = 8) -> np.ndarray:
    """``labels`` with pinches removed: where a subpatch's border passes a node twice (the
    subpatch touches itself there), its elements at that node become subpatches of their own,
    for a few rounds. Returns (M,) int64 labels 0..S-1."""
    lab = np.asarray(labels, np.int64).copy()
    e = np.asarray(elements, np.int64)
    for _ in range(rounds):
        directed, _ = _border_edges(e, lab, n_nodes)
        key = directed[:, 2] * n_nodes + directed[:, 0]
        u, count = np.unique(key, return_counts=True)
        pinch = u[count > 1]
        if not len(pinch):
            break
        corner_key = lab[:, None] * n_nodes + e
        hit = np.isin(corner_key, pinch).any(axis=1)
        idx = np.flatnonzero(hit)
        lab[idx] = lab.max() + 1 + np.arange(len(idx))
    _, lab = np.unique(lab, return_inverse=True)
    return lab.astype(np.int64)


def border_network(elements, labels, n_nodes: int) -> BorderNetwork:
    """The borders of the subpatches ``labels`` ((M,) per element) of ``elements`` (M, 4): an
    element edge is a border edge of subpatch s when s's elements use it once. Lines run between
    fixed nodes: nodes with other than two border edges, or whose two border edges separate
    other subpatches; closed lines without a fixed node are reported with ``closed`` True."""
    directed, bad = _border_edges(elements, labels, n_nodes)
    a, b, s = directed[:, 0], directed[:, 1], directed[:, 2]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * n_nodes + hi
    # undirected line network: unique border edges with their subpatch signature
    ukey, inverse, ucount = np.unique(key, return_inverse=True, return_counts=True)
    bs = s
    smin = np.full(len(ukey), np.iinfo(np.int64).max)
    smax = np.full(len(ukey), -1)
    np.minimum.at(smin, inverse, bs)
    np.maximum.at(smax, inverse, bs)
    ulo, uhi = ukey // n_nodes, ukey % n_nodes
    sig = np.c_[ucount, smin, smax]
    degree = np.bincount(np.r_[ulo, uhi], minlength=n_nodes)
    fixed = degree != 2
    fixed &= degree > 0
    # degree-2 nodes whose two edges carry different signatures are fixed too
    ends = np.r_[ulo, uhi]
    eid = np.r_[np.arange(len(ukey)), np.arange(len(ukey))]
    o = np.argsort(ends, kind="stable")
    ends_s, eid_s = ends[o], eid[o]
    first = np.searchsorted(ends_s, np.arange(n_nodes))
    two = np.flatnonzero(degree == 2)
    e1, e2 = eid_s[first[two]], eid_s[first[two] + 1]
    fixed[two[(sig[e1] != sig[e2]).any(axis=1)]] = True
    # walk the lines
    visited = np.zeros(len(ukey), bool)
    lines = []

    def other(edge: int, node: int) -> int:
        return int(uhi[edge] if ulo[edge] == node else ulo[edge])

    def walk(node: int, edge: int) -> list[int]:
        nodes = [node]
        while True:
            visited[edge] = True
            node = other(edge, node)
            nodes.append(node)
            if fixed[node]:
                return nodes
            f = first[node]
            nxt = eid_s[f] if eid_s[f] != edge else eid_s[f + 1]
            if visited[nxt]:
                return nodes  # closed line back at its start
            edge = int(nxt)

    for node in np.flatnonzero(fixed):
        f = first[node]
        for k in range(degree[node]):
            edge = int(eid_s[f + k])
            if not visited[edge]:
                nodes = walk(int(node), edge)
                lines.append((np.array(nodes), False, _labels_of(sig[edge])))
    for edge in np.flatnonzero(~visited):
        if visited[edge]:
            continue
        nodes = walk(int(ulo[edge]), int(edge))
        if nodes[-1] == nodes[0]:
            nodes = nodes[:-1]
        lines.append((np.array(nodes), True, _labels_of(sig[edge])))
    return BorderNetwork(directed=directed, bad=bad, lines=lines, fixed=fixed)


def _labels_of(sig) -> tuple[int, ...]:
    count, lo, hi = (int(v) for v in sig)
    if count == 1:
        return (lo,)
    if count == 2:
        return (lo, hi)
    return (lo, hi) + (-1,) * (count - 2)  # non-manifold: more than two subpatches


def _simplify_lines(network: BorderNetwork, coords, frames, params, memo=None) -> np.ndarray:
    """(N,) bool: nodes removed from the line network. ``memo``: a dict kept between calls on
    the same coordinates and parameters; a line with the same nodes, fixed nodes, bound and
    planes is not simplified again.

    Two lines between the same two fixed nodes would both become the same chord and close
    nothing: each of them keeps at least its node farthest from the chord. A line that returns
    to its start node is simplified as a closed line around it.
    """
    removed = np.zeros(len(coords), bool)
    pairs: dict = {}
    for nodes, closed, _ in network.lines:
        if not closed:
            key = (min(nodes[0], nodes[-1]), max(nodes[0], nodes[-1]))
            pairs[key] = pairs.get(key, 0) + 1
    for nodes, closed, labels in network.lines:
        fixed = None
        if not closed and nodes[0] == nodes[-1]:
            nodes, closed = nodes[:-1], True
            fixed = np.zeros(len(nodes), bool)
            fixed[0] = True
        if len(labels) > 2 or len(nodes) < (4 if closed else 3):
            continue
        normals = [frames[s][1][2] for s in labels]
        if len(labels) == 1:
            tol = params.l_outer
        else:
            tol = line_tolerance(normals[0], normals[1], params.l_inner, params.l_outer)
        points = coords[nodes]
        if not closed and pairs[(min(nodes[0], nodes[-1]), max(nodes[0], nodes[-1]))] > 1:
            chord = points[-1] - points[0]
            off = points - points[0]
            length = np.linalg.norm(chord)
            dist = np.linalg.norm(off if length == 0 else np.cross(off, chord / length), axis=1)
            fixed = np.zeros(len(nodes), bool)
            fixed[int(np.argmax(dist[1:-1])) + 1] = True
        planes = [(n, -float(n @ frames[s][0])) for n, s in zip(normals, labels)]
        key = None
        if memo is not None:
            key = array_digest(nodes, np.asarray(fixed if fixed is not None else [], bool),
                               np.array([tol, float(closed),
                                         *(v for n, o in planes for v in (*n, o))]))
        if key is not None and key in memo:
            keep = memo[key]
        else:
            keep = simplify_polyline(points, tol, fixed=fixed, planes=planes, d=params.d,
                                     closed=closed)
            if key is not None:
                memo[key] = keep
        gone = np.ones(len(nodes), bool)
        gone[keep] = False
        removed[nodes[gone]] = True
    return removed
