"""Re-certification of the original triangles a collapse u → v touches.

The faces around u change or go; every original triangle one of them supports is certified
again (:func:`~workbench.algo.simplify.certify._certify`) against its remaining support plus
the new fan around v, each against the faces of its own part and its own tolerance. A vertex
sliding along the common boundary of two parts thereby re-certifies the triangles of both.
The collapse is refused (``hausdorff``) unless all pass, or (``support``) when one needs more
than ``_MAX_SUPPORT`` faces.

With several certified states (``Surface.Vs``), each original triangle is certified at every
state at which it is live, against the same candidate faces placed at that state; its new
support is the union of the faces that certified a piece at any state, so one support certifies
it at all of them. The state that failed last is tried first: most refused collapses are
refused there, before the other states cost anything. A state at which every vertex the
certificate reads has bit for bit the coordinates of a state already checked is not checked
again: the same computation on the same numbers gives the same answer (all states are centred
on one origin, so a vertex that does not move keeps its coordinates exactly).
"""

from __future__ import annotations

import numba
import numpy as np

from .certify import _REC, _certify, _set_record
from .rules import _ACCEPTED, _HAUSDORFF, _SUPPORT
from .state import _MAX_SUPPORT


@numba.njit(cache=True)
def _recertified(u, v, nfu, nfv, cur, surface, originals, supports, s):
    """Whether the collapse u → v keeps every original triangle within tolerance at every
    certified state: (``_ACCEPTED``, ``_HAUSDORFF`` or ``_SUPPORT``, n_aff, new_sup (n_aff, S),
    new_n (n_aff,)), the new supports of the original triangles ``s.aff[:n_aff]`` where
    accepted. The faces around u and v are ``s.fu[:nfu]`` and ``s.fv[:nfv]``; ``cur`` numbers
    this attempt."""
    fan, n_fan = _new_fan(u, v, nfu, nfv, surface, s)
    n_aff = _affected(nfu, cur, supports, s)
    reason, new_sup, new_n = _recertify(u, v, fan, n_fan, n_aff, surface, originals, supports,
                                       s)
    return reason, n_aff, new_sup, new_n


@numba.njit(cache=True)
def _new_fan(u, v, nfu, nfv, surface, s):
    """The faces around v after the collapse u → v into ``s.fw`` and their records
    (``_REC``) at every certified state: (records (S, n_fan, _REC), n_fan)."""
    Vs, F = surface.Vs, surface.F
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
    n_states = Vs.shape[0]
    fan = np.empty((n_states, n_fan, _REC))
    for st in range(n_states):
        for j in range(n_fan):
            g = fw[j]
            for k in range(3):
                x = F[g, k]
                if x == u:
                    x = v
                for c in range(3):
                    tri[k, c] = Vs[st, x, c]
            _set_record(fan[st], j, tri[0], tri[1], tri[2])
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
def _recertify(u, v, fan, n_fan, n_aff, surface, originals, supports, s):
    """Certify each of ``s.aff[:n_aff]`` at every state at which it is live against its
    remaining support plus the new fan (faces ``s.fw[:n_fan]``, records ``fan`` per state):
    (``_ACCEPTED``, ``_HAUSDORFF`` or ``_SUPPORT``, new_sup (n_aff, S), new_n (n_aff,)),
    filled up to the first failure."""
    S = _MAX_SUPPORT
    aff = s.aff
    n_states = surface.Vs.shape[0]
    new_sup = np.empty((n_aff, S), np.int32)
    new_n = np.zeros(n_aff, np.int32)
    cand = np.empty((S + n_fan, _REC))
    cand_id = np.empty(S + n_fan, np.int64)
    cand_fan = np.empty(S + n_fan, np.int64)
    used = np.empty(S + n_fan, np.bool_)
    slot = np.empty(S + n_fan, np.int64)
    used_here = np.empty(S + n_fan, np.bool_)
    involved = np.empty(3 + 3 * (S + n_fan), np.int64)
    checked = np.empty(n_states, np.int64)
    reason = _ACCEPTED
    for i in range(n_aff):
        t = aff[i]
        nc = _candidates(t, u, n_fan, surface, originals, supports, s, cand_id, cand_fan)
        for j in range(nc):
            used[j] = False
        n_inv = 0
        if n_states > 1:
            n_inv = _involved(t, u, v, nc, cand_id, surface, originals, involved)
        n_checked = 0
        first = s.hint[0]
        for step in range(n_states):
            # the state that failed last first, then the others in order
            st = first if step == 0 else (step - 1 if step <= first else step)
            if not originals.live[st, t]:
                continue
            if _same_as_checked(st, checked, n_checked, involved, n_inv, surface.Vs):
                continue
            checked[n_checked] = st
            n_checked += 1
            corners = _corners_at(t, st, surface, originals, s.at_state)
            n_reach = _reaching(corners, st, fan, nc, cand_id, cand_fan, surface,
                                originals.tol[t], cand, slot)
            for j in range(n_reach):
                used_here[j] = used[slot[j]]
            if n_reach == 0 or not _certify(corners, cand, n_reach, originals.tol[t],
                                            originals.depth[t], used_here, s.stack, s.depth,
                                            s.piece, s.corners):
                reason = _HAUSDORFF
                s.hint[0] = st
                break
            for j in range(n_reach):
                used[slot[j]] = used_here[j]
        if reason >= 0:
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
def _involved(t, u, v, nc, cand_id, surface, originals, out):
    """The vertices a certificate of original triangle t against the candidates
    ``cand_id[:nc]`` after the collapse u → v reads (u read as v), into ``out``; returns
    their count (with repeats)."""
    F = surface.F
    n = 0
    for k in range(3):
        out[n] = originals.index[t, k]
        n += 1
    for j in range(nc):
        g = cand_id[j]
        for k in range(3):
            x = F[g, k]
            out[n] = v if x == u else x
            n += 1
    return n


@numba.njit(cache=True)
def _same_as_checked(st, checked, n_checked, involved, n_inv, Vs):
    """Whether every vertex of ``involved[:n_inv]`` has, at state st, bit for bit the
    coordinates it has at one of the states ``checked[:n_checked]``: the certificate there
    is then the same computation on the same numbers, and holds at st."""
    for r in range(n_checked):
        other = checked[r]
        same = True
        for j in range(n_inv):
            x = involved[j]
            if Vs[st, x, 0] != Vs[other, x, 0] or Vs[st, x, 1] != Vs[other, x, 1] or \
                    Vs[st, x, 2] != Vs[other, x, 2]:
                same = False
                break
        if same:
            return True
    return False


@numba.njit(cache=True, inline="always")
def _corners_at(t, st, surface, originals, out):
    """The corners of original triangle t at certified state st (state 0: as stored)."""
    if st == 0:
        return originals.corners[t]
    for k in range(3):
        x = originals.index[t, k]
        for c in range(3):
            out[k, c] = surface.Vs[st, x, c]
    return out


@numba.njit(cache=True)
def _candidates(t, u, n_fan, surface, originals, supports, s, cand_id, cand_fan):
    """The faces original triangle t is certified against after the collapse of u, at every
    state: face indices into ``cand_id`` and, for faces of the new fan, their place in it
    (``s.fw``) into ``cand_fan`` (-1 for a support face kept as it is); returns their count.
    Its support faces away from u as they are, then the faces of the new fan of t's part."""
    F, fpart = surface.F, surface.fpart
    sup, sup_n = supports.sup, supports.sup_n
    fw = s.fw
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
        cand_id[nc] = g
        cand_fan[nc] = -1
        nc += 1
    t_part = fpart[originals.face[t]]
    for q in range(n_fan):
        if fpart[fw[q]] != t_part:
            continue
        cand_id[nc] = fw[q]
        cand_fan[nc] = q
        nc += 1
    return nc


@numba.njit(cache=True)
def _reaching(corners, st, fan, nc, cand_id, cand_fan, surface, tol, cand, slot):
    """The records at state st of the candidates that may reach the triangle ``corners`` into
    ``cand``, and the candidate each one is into ``slot``; returns their count. A support face
    always counts; a fan face only where its bounding sphere comes within tol of the
    triangle's."""
    Vs, F = surface.Vs, surface.F
    tc0 = (corners[0, 0] + corners[1, 0] + corners[2, 0]) / 3.0
    tc1 = (corners[0, 1] + corners[1, 1] + corners[2, 1]) / 3.0
    tc2 = (corners[0, 2] + corners[1, 2] + corners[2, 2]) / 3.0
    t_rad = 0.0
    for k in range(3):
        t_rad = max(t_rad, (corners[k, 0] - tc0) ** 2 + (corners[k, 1] - tc1) ** 2
                    + (corners[k, 2] - tc2) ** 2)
    t_rad = np.sqrt(t_rad)
    n = 0
    for j in range(nc):
        q = cand_fan[j]
        if q < 0:
            g = cand_id[j]
            _set_record(cand, n, Vs[st, F[g, 0]], Vs[st, F[g, 1]], Vs[st, F[g, 2]])
        else:
            reach = t_rad + fan[st, q, 12] + tol
            if (fan[st, q, 9] - tc0) ** 2 + (fan[st, q, 10] - tc1) ** 2 + \
                    (fan[st, q, 11] - tc2) ** 2 > reach * reach:
                continue
            cand[n] = fan[st, q]
        slot[n] = j
        n += 1
    return n
