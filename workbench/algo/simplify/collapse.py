"""The greedy loop of certified half-edge collapses, in phases.

Each pass fills the queue with every half-edge out of a vertex that may move
(:func:`_queue_all`); then, until the queue runs dry, the cheapest valid half-edge u → v is
popped and tried: the topology and shape rules
(:func:`~workbench.algo.simplify.rules._check_rules`), then the re-certification of the
original triangles around u (:func:`~workbench.algo.simplify.recertify._recertified`). A
collapse that passes both is applied (:func:`_move_faces`, :func:`_replace_supports`,
:func:`_merge_quadrics`, :func:`_slide_line`); one that fails leaves the mesh as it was and is
counted by reason. After a collapse the half-edges out of v, out of its neighbours that saw a
rejection since they were last queued, and the new ones towards v are queued
(:func:`_requeue`). When the queue runs dry every remaining half-edge is tried once more
(``passes``), since re-certified supports elsewhere can make earlier rejections feasible.

Everything runs inside one compiled call: the phases are compiled functions that call each
other natively.
"""

from __future__ import annotations

import numba
import numpy as np

from .heap import _cost, _heap_pop, _heap_push, _new_heap
from .recertify import _recertified
from .rules import _ACCEPTED, _FIXED, _check_rules
from .state import Supports, _corner_links, _initial_supports, _lines_of, _new_marks, _new_scratch
from .topology import _edge_key, _gather, _neighbours


@numba.njit(cache=True)
def _decimate(surface, originals, quadrics, constraints, cos_max, max_passes):
    """Greedy certified half-edge collapses; changes ``surface.F``, ``surface.alive``,
    ``constraints.cdeg``, ``quadrics.Q`` and ``quadrics.area`` in place (the groups of
    :mod:`~workbench.algo.simplify.state`). ``cos_max`` is the cosine of the largest turn of a
    face's normal, ``max_passes`` how often the queue is filled at most.

    Returns (support (K, S), support counts (K,), collapses, rejections (8,), passes).
    """
    n_vert = surface.V.shape[0]
    m = surface.F.shape[0]
    k_orig = originals.corners.shape[0]
    links = _corner_links(surface.F, surface.alive, n_vert)
    supports, n_e = _initial_supports(originals.face, m)
    lines = _lines_of(constraints)
    marks = _new_marks(n_vert)
    max_depth = originals.depth.max() if k_orig > 0 else 0
    s = _new_scratch(n_vert, m, k_orig, max_depth)
    dead, version, retry = marks.dead, marks.version, marks.retry
    rejected = np.zeros(8, np.int64)
    collapses = 0
    cur = 0
    heap = _new_heap()
    hn = 0
    passes = 0
    while passes < max_passes:
        passes += 1
        heap, hn = _queue_all(surface, lines, quadrics, links, marks, s, heap, hn)
        pass_collapses = 0
        while hn > 0:
            u, v, st, hn = _heap_pop(heap, hn)
            if dead[u] or dead[v] or st != version[u]:
                continue
            # try u → v: the rules, then the certificates, then apply it (or leave all as is)
            outcome, nfu, nnu, nfv, nnv = _check_rules(u, v, surface, lines, links, cos_max, s)
            if outcome == _ACCEPTED:
                cur += 1
                outcome, n_aff, new_sup, new_n = _recertified(u, v, nfu, nfv, cur, surface,
                                                              originals, supports, s)
                if outcome == _ACCEPTED:
                    _move_faces(u, v, nfu, surface, links, s.fu)
                    supports, n_e = _replace_supports(n_aff, new_sup, new_n, supports, n_e,
                                                      s.aff)
                    _merge_quadrics(u, v, quadrics)
                    _slide_line(u, v, nnu, lines, s.nbu, n_vert)
                    dead[u] = True
                    collapses += 1
                    pass_collapses += 1
                    _mark_near(nnu, nnv, collapses, marks, s)
                    heap, hn = _requeue(v, collapses, surface, lines, quadrics, links, marks, s,
                                        heap, hn)
                    continue
            if outcome >= 0:
                # refused: a collapse next to u queues u again (retry), unless u is fixed
                rejected[outcome] += 1
                if outcome != _FIXED:
                    retry[u] = True
        if pass_collapses == 0:
            break
    return supports.sup, supports.sup_n, collapses, rejected, passes


# --------------------------------------------------------------------------- apply a collapse
@numba.njit(cache=True)
def _move_faces(u, v, nfu, surface, links, fu):
    """Remove the faces ``fu[:nfu]`` of u on uv, move u to v in the others, and hand u's
    corner slots to v."""
    F, alive = surface.F, surface.alive
    head, tail, nxt = links.head, links.tail, links.nxt
    for i in range(nfu):
        f = fu[i]
        if F[f, 0] == v or F[f, 1] == v or F[f, 2] == v:
            alive[f] = False
        else:
            for k in range(3):
                if F[f, k] == u:
                    F[f, k] = v
    if head[u] >= 0:
        if head[v] < 0:
            head[v] = head[u]
        else:
            nxt[tail[v]] = head[u]
        tail[v] = tail[u]
        head[u] = -1
        tail[u] = -1


@numba.njit(cache=True)
def _replace_supports(n_aff, new_sup, new_n, supports, n_e, aff):
    """Give each original triangle ``aff[i]`` (i < n_aff) its new support ``new_sup[i,
    :new_n[i]]``, listing it with the faces it did not know; returns the supports (new entry
    arrays when they grew) and the number of entries used."""
    sup, sup_n, s_head = supports.sup, supports.sup_n, supports.s_head
    e_tri, e_next = supports.e_tri, supports.e_next
    S = sup.shape[1]
    for i in range(n_aff):
        t = aff[i]
        for j in range(new_n[i]):
            g = new_sup[i, j]
            known = False
            for q in range(sup_n[t]):
                if sup[t, q] == g:
                    known = True
            if not known:
                if n_e == len(e_tri):
                    grown_t = np.empty(2 * n_e, np.int32)
                    grown_n = np.empty(2 * n_e, np.int64)
                    grown_t[:n_e] = e_tri[:n_e]
                    grown_n[:n_e] = e_next[:n_e]
                    e_tri, e_next = grown_t, grown_n
                e_tri[n_e] = t
                e_next[n_e] = s_head[g]
                s_head[g] = n_e
                n_e += 1
        for j in range(new_n[i]):
            sup[t, j] = new_sup[i, j]
        for j in range(new_n[i], S):
            sup[t, j] = -1
        sup_n[t] = new_n[i]
    return Supports(sup, sup_n, s_head, e_tri, e_next), n_e


@numba.njit(cache=True)
def _merge_quadrics(u, v, quadrics):
    """v inherits the quadric and area of u."""
    Q, area = quadrics.Q, quadrics.area
    for c in range(10):
        Q[v, c] += Q[u, c]
    area[v] += area[u]


@numba.njit(cache=True)
def _slide_line(u, v, nnu, lines, nbu, n_vert):
    """Where u slid along its feature line (u on two constrained edges, neighbours
    ``nbu[:nnu]``), the line now runs v - b; u leaves the line."""
    cdeg, constrained = lines.cdeg, lines.constrained
    if cdeg[u] == 2:
        other = -1
        for j in range(nnu):
            w = nbu[j]
            if w != v and _edge_key(u, w, n_vert) in constrained:
                other = w
        constrained.pop(_edge_key(u, v, n_vert))
        if other >= 0:
            constrained.pop(_edge_key(u, other, n_vert))
            key = _edge_key(v, other, n_vert)
            if key in constrained:
                cdeg[v] -= 1
                cdeg[other] -= 1
            else:
                constrained[key] = np.int8(1)
        else:
            cdeg[v] -= 1
        cdeg[u] = 0


# --------------------------------------------------------------------------- queue
@numba.njit(cache=True)
def _queue_all(surface, lines, quadrics, links, marks, s, heap, hn):
    """Push every half-edge out of a vertex that may move; returns the heap and its size."""
    dead, fixed, cdeg = marks.dead, lines.fixed, lines.cdeg
    for x in range(surface.V.shape[0]):
        if dead[x] or fixed[x] or not (cdeg[x] == 0 or cdeg[x] == 2):
            continue
        heap, hn = _queue_out_of(x, surface, lines, quadrics, links, marks.version, s, heap, hn)
    return heap, hn


@numba.njit(cache=True)
def _queue_out_of(x, surface, lines, quadrics, links, version, s, heap, hn):
    """Push the half-edges x → y x may collapse along (along its feature line when on one),
    stamped with x's version; returns the heap and its size. Uses ``s.fu``, ``s.nbu``."""
    V, F, fpart = surface.V, surface.F, surface.fpart
    cdeg, constrained = lines.cdeg, lines.constrained
    fu, nbu = s.fu, s.nbu
    nfx = _gather(x, links.head, links.tail, links.nxt, surface.alive, fu)
    nnx = _neighbours(x, fu, nfx, F, fpart, -1, nbu, s.cntu, s.pos)
    for j in range(nnx):
        y = nbu[j]
        if cdeg[x] == 2 and _edge_key(x, y, V.shape[0]) not in constrained:
            continue
        heap, hn = _heap_push(heap, hn, _cost(quadrics.Q, quadrics.area, V, x, y), x, y,
                              version[x])
    return heap, hn


@numba.njit(cache=True)
def _mark_near(nnu, nnv, collapses, marks, s):
    """Stamp the neighbours of u (``s.nbu[:nnu]``) and of v (``s.nbv[:nnv]``) before the
    collapse numbered ``collapses``."""
    for j in range(nnu):
        marks.near_u[s.nbu[j]] = collapses
    for j in range(nnv):
        marks.near_v[s.nbv[j]] = collapses


@numba.njit(cache=True)
def _requeue(v, collapses, surface, lines, quadrics, links, marks, s, heap, hn):
    """After the collapse numbered ``collapses`` into v: push every half-edge out of v (its
    quadric changed), out of neighbours with a rejection since their last requeue (their
    surroundings changed), and the new half-edges towards v (from former neighbours of u
    only); returns the heap and its size."""
    fixed, cdeg, constrained = lines.fixed, lines.cdeg, lines.constrained
    version, retry, near_u, near_v = marks.version, marks.retry, marks.near_u, marks.near_v
    V, nbv = surface.V, s.nbv
    nfv = _gather(v, links.head, links.tail, links.nxt, surface.alive, s.fv)
    nnv = _neighbours(v, s.fv, nfv, surface.F, surface.fpart, -1, nbv, s.cntv, s.pos)
    for j in range(-1, nnv):
        a = v if j < 0 else nbv[j]
        if fixed[a] or not (cdeg[a] == 0 or cdeg[a] == 2):
            continue
        if a == v or retry[a]:
            version[a] += 1
            retry[a] = False
            heap, hn = _queue_out_of(a, surface, lines, quadrics, links, version, s, heap, hn)
        elif near_u[a] == collapses and near_v[a] != collapses:
            if cdeg[a] == 2 and _edge_key(a, v, V.shape[0]) not in constrained:
                continue
            heap, hn = _heap_push(heap, hn, _cost(quadrics.Q, quadrics.area, V, a, v), a, v,
                                  version[a])
    return heap, hn
