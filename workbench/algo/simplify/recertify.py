"""Re-certification of the original triangles a collapse u → v touches.

The faces around u change or go; every original triangle one of them supports is certified
again (:func:`~workbench.algo.simplify.certify._certify`) against its remaining support plus
the new fan around v, each against the faces of its own part and its own tolerance. A vertex
sliding along the common boundary of two parts thereby re-certifies the triangles of both.
The collapse is refused (``hausdorff``) unless all pass, or (``support``) when one needs more
than ``_MAX_SUPPORT`` faces.
"""

from __future__ import annotations

import numba
import numpy as np

from .certify import _REC, _certify, _set_record
from .rules import _ACCEPTED, _HAUSDORFF, _SUPPORT
from .state import _MAX_SUPPORT


@numba.njit(cache=True)
def _recertified(u, v, nfu, nfv, cur, surface, originals, supports, s):
    """Whether the collapse u → v keeps every original triangle within tolerance:
    (``_ACCEPTED``, ``_HAUSDORFF`` or ``_SUPPORT``, n_aff, new_sup (n_aff, S), new_n (n_aff,)),
    the new supports of the original triangles ``s.aff[:n_aff]`` where accepted. The faces
    around u and v are ``s.fu[:nfu]`` and ``s.fv[:nfv]``; ``cur`` numbers this attempt."""
    fan, n_fan = _new_fan(u, v, nfu, nfv, surface, s)
    n_aff = _affected(nfu, cur, supports, s)
    reason, new_sup, new_n = _recertify(u, fan, n_fan, n_aff, surface, originals, supports, s)
    return reason, n_aff, new_sup, new_n


@numba.njit(cache=True)
def _new_fan(u, v, nfu, nfv, surface, s):
    """The faces around v after the collapse u → v into ``s.fw`` and their records
    (``_REC``): (records (n_fan, _REC), n_fan)."""
    V, F = surface.V, surface.F
    fu, fv, fw, tri = s.fu, s.fv, s.fw, s.tri
    # unchanged faces of v, changed faces of u (of every part; an original triangle is
    # certified against the faces of its own part only)
    n_fan = 0
    for j in range(nfv):
        g = fv[j]
        if F[g, 0] == u or F[g, 1] == u or F[g, 2] == u:
            continue
        fw[n_fan] = g
        n_fan += 1
    for i in range(nfu):
        f = fu[i]
        if F[f, 0] == v or F[f, 1] == v or F[f, 2] == v:
            continue
        fw[n_fan] = f
        n_fan += 1
    fan = np.empty((n_fan, _REC))
    for j in range(n_fan):
        g = fw[j]
        for k in range(3):
            x = F[g, k]
            if x == u:
                x = v
            for c in range(3):
                tri[k, c] = V[x, c]
        _set_record(fan, j, tri[0], tri[1], tri[2])
    return fan, n_fan


@numba.njit(cache=True)
def _affected(nfu, cur, supports, s):
    """The original triangles supported by the faces ``s.fu[:nfu]`` around u, each once, into
    ``s.aff``; returns their count. Unlinks stale entries from the faces' lists on the way;
    ``s.stamp`` marks the triangles listed in attempt ``cur``."""
    sup, sup_n, s_head, e_tri, e_next = (supports.sup, supports.sup_n, supports.s_head,
                                         supports.e_tri, supports.e_next)
    fu, aff, stamp = s.fu, s.aff, s.stamp
    n_aff = 0
    for i in range(nfu):
        f = fu[i]
        prev = -1
        e = s_head[f]
        while e >= 0:
            ne = e_next[e]
            t = e_tri[e]
            valid = False
            for j in range(sup_n[t]):
                if sup[t, j] == f:
                    valid = True
            if not valid:
                if prev < 0:
                    s_head[f] = ne
                else:
                    e_next[prev] = ne
            else:
                prev = e
                if stamp[t] != cur:
                    stamp[t] = cur
                    aff[n_aff] = t
                    n_aff += 1
            e = ne
    return n_aff


@numba.njit(cache=True)
def _recertify(u, fan, n_fan, n_aff, surface, originals, supports, s):
    """Certify each of ``s.aff[:n_aff]`` against its remaining support plus the new fan (faces
    ``s.fw[:n_fan]``, records ``fan``): (``_ACCEPTED``, ``_HAUSDORFF`` or ``_SUPPORT``,
    new_sup (n_aff, S), new_n (n_aff,)), filled up to the first failure."""
    S = _MAX_SUPPORT
    aff = s.aff
    new_sup = np.empty((n_aff, S), np.int32)
    new_n = np.zeros(n_aff, np.int32)
    cand = np.empty((S + n_fan, _REC))
    cand_id = np.empty(S + n_fan, np.int64)
    used = np.empty(S + n_fan, np.bool_)
    reason = _ACCEPTED
    for i in range(n_aff):
        t = aff[i]
        nc = _candidates(t, u, fan, n_fan, surface, originals, supports, s, cand, cand_id)
        for j in range(nc):
            used[j] = False
        if nc == 0 or not _certify(originals.corners[t], cand, nc, originals.tol[t],
                                   originals.depth[t], used, s.stack, s.depth, s.piece,
                                   s.corners):
            reason = _HAUSDORFF
            break
        cnt = 0
        for j in range(nc):
            if used[j]:
                if cnt == S:
                    reason = _SUPPORT
                    break
                new_sup[i, cnt] = cand_id[j]
                cnt += 1
        if reason >= 0:
            break
        new_n[i] = cnt
    return reason, new_sup, new_n


@numba.njit(cache=True)
def _candidates(t, u, fan, n_fan, surface, originals, supports, s, cand, cand_id):
    """The faces original triangle t is certified against after the collapse of u, as records
    into ``cand`` and face indices into ``cand_id``; returns their count. Its support faces
    away from u as they are, then the faces of the new fan (``s.fw[:n_fan]``, records
    ``fan``) of t's part whose bounding sphere comes within tol of t's."""
    V, F, fpart = surface.V, surface.F, surface.fpart
    orig, tol = originals.corners, originals.tol[t]
    sup, sup_n = supports.sup, supports.sup_n
    fw, tc = s.fw, s.tc
    # T's bounding sphere, to skip fan faces that cannot reach it
    for c in range(3):
        tc[c] = (orig[t, 0, c] + orig[t, 1, c] + orig[t, 2, c]) / 3.0
    t_rad = 0.0
    for k in range(3):
        t_rad = max(t_rad, (orig[t, k, 0] - tc[0]) ** 2 + (orig[t, k, 1] - tc[1]) ** 2
                    + (orig[t, k, 2] - tc[2]) ** 2)
    t_rad = np.sqrt(t_rad)
    nc = 0
    for j in range(sup_n[t]):
        g = sup[t, j]
        if F[g, 0] == u or F[g, 1] == u or F[g, 2] == u:
            continue  # changed or removed: the fan holds its new shape
        in_fan = False
        for q in range(n_fan):
            if fw[q] == g:
                in_fan = True
        if in_fan:
            continue
        _set_record(cand, nc, V[F[g, 0]], V[F[g, 1]], V[F[g, 2]])
        cand_id[nc] = g
        nc += 1
    t_part = fpart[originals.face[t]]
    for q in range(n_fan):
        if fpart[fw[q]] != t_part:
            continue
        reach = t_rad + fan[q, 12] + tol
        if (fan[q, 9] - tc[0]) ** 2 + (fan[q, 10] - tc[1]) ** 2 + \
                (fan[q, 11] - tc[2]) ** 2 > reach * reach:
            continue
        cand[nc] = fan[q]
        cand_id[nc] = fw[q]
        nc += 1
    return nc
