"""Neighbourhood kernels of the decimation: the faces around a vertex, its neighbours, whether
its faces form one fan, the link condition within one part, undirected edge keys.

Faces around a vertex are found through per-vertex singly linked lists of corner slots
(``3 f + k``, see :class:`~workbench.algo.simplify.state.Links`); the slots of dead faces are
unlinked lazily, when the list is next walked.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def _edge_key(a, b, n):
    lo, hi = (a, b) if a < b else (b, a)
    return np.int64(lo) * n + hi


@numba.njit(cache=True)
def _gather(x, head, tail, nxt, alive, out):
    """Alive faces around vertex x into out; unlinks the corner slots of dead faces."""
    n = 0
    prev = -1
    s = head[x]
    while s >= 0:
        ns = nxt[s]
        f = s // 3
        if alive[f]:
            out[n] = f
            n += 1
            prev = s
        else:
            if prev < 0:
                head[x] = ns
            else:
                nxt[prev] = ns
            if ns < 0:
                tail[x] = prev
        s = ns
    return n


@numba.njit(cache=True)
def _neighbours(x, faces, nf, F, fpart, part, nb, cnt, pos):
    """Distinct neighbours of x over faces[:nf] (of ``part`` only when part >= 0) into nb, and
    the number of those faces on each edge (x, nb[j]) into cnt; returns their count.
    ``pos`` (N,) is -1 everywhere on entry and on return."""
    n = 0
    for i in range(nf):
        f = faces[i]
        if part >= 0 and fpart[f] != part:
            continue
        for k in range(3):
            w = F[f, k]
            if w == x:
                continue
            if pos[w] < 0:
                pos[w] = n
                nb[n] = w
                cnt[n] = 1
                n += 1
            else:
                cnt[pos[w]] += 1
    for j in range(n):
        pos[nb[j]] = -1
    return n


@numba.njit(cache=True)
def _one_fan(u, faces, nf, F, seen, queue):
    """True when the faces around u are connected through edges at u (a single fan)."""
    for i in range(nf):
        seen[i] = False
    seen[0] = True
    queue[0] = 0
    head, top = 0, 1
    while head < top:
        a = faces[queue[head]]
        head += 1
        for j in range(nf):
            if seen[j]:
                continue
            b = faces[j]
            shared = False
            for k in range(3):
                w = F[a, k]
                if w != u and (F[b, 0] == w or F[b, 1] == w or F[b, 2] == w):
                    shared = True
            if shared:
                seen[j] = True
                queue[top] = j
                top += 1
    return top == nf


@numba.njit(cache=True)
def _part_link_ok(u, v, fu, nfu, fv, nfv, F, fpart, part, scratch):
    """Link condition of the edge uv within the faces of ``part`` only: the neighbours u and v
    share in that part are the vertices opposite uv in that part's faces. ``fu[:nfu]`` and
    ``fv[:nfv]`` are the faces around u and v; ``scratch`` a
    :class:`~workbench.algo.simplify.state.Scratch` (its ``pos`` is -1 everywhere on entry and
    on return)."""
    nb_u, cnt_u, nb_v, cnt_v = scratch.nbp, scratch.cntp, scratch.nbq, scratch.cntq
    pos = scratch.pos
    n_u = _neighbours(u, fu, nfu, F, fpart, part, nb_u, cnt_u, pos)
    n_v = _neighbours(v, fv, nfv, F, fpart, part, nb_v, cnt_v, pos)
    for i in range(n_v):
        pos[nb_v[i]] = 0
    ok = True
    for j in range(n_u):
        w = nb_u[j]
        if w == v or pos[w] != 0:
            continue
        opposite = False
        for i in range(nfu):
            f = fu[i]
            if fpart[f] == part and (F[f, 0] == v or F[f, 1] == v or F[f, 2] == v) and \
                    (F[f, 0] == w or F[f, 1] == w or F[f, 2] == w):
                opposite = True
        if not opposite:
            ok = False
    for i in range(n_v):
        pos[nb_v[i]] = -1
    return ok


@numba.njit(cache=True, inline="always")
def _cross(a, b, c, out):
    e0, e1, e2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    f0, f1, f2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    out[0] = e1 * f2 - e2 * f1
    out[1] = e2 * f0 - e0 * f2
    out[2] = e0 * f1 - e1 * f0
