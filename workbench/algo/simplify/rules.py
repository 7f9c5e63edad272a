"""The topology and shape rules a half-edge collapse u → v must keep, and the reasons it may be
refused.

Topology and shape rules (a collapse that breaks one is rejected and counted by reason):

* ``topology`` -- the edge has more than two faces, u is a non-manifold vertex (its faces do not
  form one fan), the link condition fails (u and v share a neighbour that is not opposite the
  edge), or an interior edge joins two boundary vertices;
* ``fixed`` -- u never moves: it is used by faces of three or more parts (or of two parts
  anywhere but inside their common boundary, see :mod:`~workbench.algo.simplify.constraints`),
  by a zero-area input face, touches a non-manifold edge, or is a corner (on 1 or >= 3
  feature/boundary edges, or where its feature/boundary polyline turns by more than
  ``feature_deg``). Such vertices are not queued at all; the count is of vertices that became
  corners on the way;
* ``feature`` -- u lies on two feature/boundary edges and uv is not one of them (u may only
  slide along its feature line);
* ``normal`` -- a changed face would turn by more than ``max_normal_deg`` from its normal
  before the collapse or from the normal of the input face it descends from;
* ``degenerate`` -- a changed face would get (close to) zero area;
* ``duplicate`` -- a changed face would repeat an existing face;
* ``hausdorff`` -- an original triangle could not be re-certified within tol;
* ``support`` -- a re-certification needs more than 12 support faces.

The last two are decided by the re-certification (:mod:`~workbench.algo.simplify.collapse`).
A vertex inside the common boundary of two parts slides along it in both parts at once, so such
a collapse must also keep the link condition within each part on its own.
"""

from __future__ import annotations

import numba
import numpy as np

from .topology import _cross, _edge_key, _gather, _neighbours, _one_fan, _part_link_ok

REJECT_REASONS = ("fixed", "feature", "topology", "normal", "degenerate", "duplicate",
                  "hausdorff", "support")
_FIXED, _FEATURE, _TOPOLOGY, _NORMAL, _DEGENERATE, _DUPLICATE, _HAUSDORFF, _SUPPORT = range(8)
# outcomes of an attempt other than a rejection reason (those are >= 0)
_ACCEPTED = -1    # no rule is broken
_SKIPPED = -2     # not a collapse any more (u has no faces, uv is no edge); not counted

# a face whose |cross product| is below this share of its longest edge squared has zero area
_AREA_REL = 1e-6


@numba.njit(cache=True)
def _check_rules(u, v, surface, lines, links, cos_max, s):
    """The outcome of the rules for the collapse u → v: ``_ACCEPTED``, ``_SKIPPED`` or the
    reason of the first rule it breaks, with nfu, nnu, nfv, nnv: the faces ``s.fu[:nfu]`` and
    neighbours ``s.nbu[:nnu]`` of u, and those of v (``s.fv``, ``s.nbv``; 0 unless the rules
    got as far as gathering them). ``surface``, ``lines``, ``links`` and the scratch ``s`` are
    those of :mod:`~workbench.algo.simplify.state`; ``cos_max`` is the cosine of the largest
    turn of a face's normal."""
    F, fpart, cdeg = surface.F, surface.fpart, lines.cdeg
    fu = s.fu
    if lines.fixed[u] or not (cdeg[u] == 0 or cdeg[u] == 2):
        return _FIXED, 0, 0, 0, 0
    nfu = _gather(u, links.head, links.tail, links.nxt, surface.alive, fu)
    if nfu == 0:
        return _SKIPPED, nfu, 0, 0, 0
    nnu = _neighbours(u, fu, nfu, F, fpart, -1, s.nbu, s.cntu, s.pos)
    n_uv = 0
    opp0 = -1
    opp1 = -1
    for i in range(nfu):
        f = fu[i]
        if F[f, 0] == v or F[f, 1] == v or F[f, 2] == v:
            n_uv += 1
            w = F[f, 0] + F[f, 1] + F[f, 2] - u - v
            if opp0 < 0:
                opp0 = w
            else:
                opp1 = w
    if n_uv == 0:
        return _SKIPPED, nfu, nnu, 0, 0
    if cdeg[u] == 2 and _edge_key(u, v, surface.V.shape[0]) not in lines.constrained:
        return _FEATURE, nfu, nnu, 0, 0
    ok, nfv, nnv = _topology_ok(u, v, nfu, nnu, n_uv, opp0, opp1, surface, links, s)
    if not ok:
        return _TOPOLOGY, nfu, nnu, nfv, nnv
    return _shape_reason(u, v, nfu, nfv, surface, cos_max, s), nfu, nnu, nfv, nnv


@numba.njit(cache=True)
def _topology_ok(u, v, nfu, nnu, n_uv, opp0, opp1, surface, links, s):
    """Whether the collapse u → v keeps the topology rules, with nfv, nnv: the faces and
    neighbours of v gathered into ``s.fv``, ``s.nbv`` (0 when u's own fan failed first).
    n_uv faces are on uv, opposite it lie opp0 and opp1 (-1 for none)."""
    F, fpart = surface.F, surface.fpart
    fu, fv, nbu, cntu, nbv, pos = s.fu, s.fv, s.nbu, s.cntu, s.nbv, s.pos
    part = fpart[fu[0]]
    ok = True
    u_boundary = False
    for j in range(nnu):
        if cntu[j] > 2:
            ok = False
        if cntu[j] == 1:
            u_boundary = True
    if ok:
        ok = _one_fan(u, fu, nfu, F, s.seen, s.queue)
    nfv = 0
    nnv = 0
    if ok:
        nfv = _gather(v, links.head, links.tail, links.nxt, surface.alive, fv)
        nnv = _neighbours(v, fv, nfv, F, fpart, -1, nbv, s.cntv, pos)
        # link condition: common neighbours of u and v are opposite the edge
        for i in range(nnv):
            pos[nbv[i]] = 0
        for j in range(nnu):
            w = nbu[j]
            if w != v and pos[w] == 0 and w != opp0 and w != opp1:
                ok = False
        for i in range(nnv):
            pos[nbv[i]] = -1
    other_part = np.int32(-1)
    for i in range(nfu):
        if fpart[fu[i]] != part:
            other_part = fpart[fu[i]]
    if ok and other_part >= 0:
        ok = _slides_in_both(u, v, part, other_part, nfu, nfv, F, fpart, s)
    if ok and n_uv == 2 and u_boundary:
        ok = not _pinches(v, part, nnu, nfv, nnv, F, fpart, s)
    return ok, nfv, nnv


@numba.njit(cache=True)
def _slides_in_both(u, v, part, other_part, nfu, nfv, F, fpart, s):
    """Whether u, on faces of ``part`` and ``other_part``, may slide to v in both parts.

    u lies on the common boundary of two parts and slides along it in both: uv must be that
    boundary (one face of each part on it), u's faces only of the two parts, and the link
    condition must hold within each part on its own.
    """
    fu = s.fu
    ok = True
    n_part = 0
    n_other = 0
    for i in range(nfu):
        f = fu[i]
        if fpart[f] != part and fpart[f] != other_part:
            ok = False
        if F[f, 0] == v or F[f, 1] == v or F[f, 2] == v:
            if fpart[f] == part:
                n_part += 1
            else:
                n_other += 1
    if n_part != 1 or n_other != 1:
        ok = False
    if ok:
        ok = _part_link_ok(u, v, fu, nfu, s.fv, nfv, F, fpart, part, s)
    if ok:
        ok = _part_link_ok(u, v, fu, nfu, s.fv, nfv, F, fpart, other_part, s)
    return ok


@numba.njit(cache=True)
def _pinches(v, part, nnu, nfv, nnv, F, fpart, s):
    """Whether v is a boundary vertex (of ``part``'s faces where v has faces of other parts
    too), so that an interior edge from the boundary vertex u to it would pinch the surface.
    Lists v's neighbours in ``part`` after u's (``s.nbu[nnu:]``)."""
    fv = s.fv
    pinch = False
    mixed = False
    for i in range(nfv):
        if fpart[fv[i]] != part:
            mixed = True
    if mixed:
        nnw = _neighbours(v, fv, nfv, F, fpart, part, s.nbu[nnu:], s.cntu[nnu:], s.pos)
        for i in range(nnw):
            if s.cntu[nnu + i] == 1:
                pinch = True
    else:
        for i in range(nnv):
            if s.cntv[i] == 1:
                pinch = True
    return pinch


@numba.njit(cache=True)
def _shape_reason(u, v, nfu, nfv, surface, cos_max, s):
    """The shape rule the faces ``s.fu[:nfu]`` of u would break when u moves to v
    (``_NORMAL``, ``_DEGENERATE`` or ``_DUPLICATE`` of a face around v, ``s.fv[:nfv]``), or
    ``_ACCEPTED``."""
    V, F, n_origin = surface.V, surface.F, surface.n_origin
    fu, fv, tri, nrm, old = s.fu, s.fv, s.tri, s.nrm, s.old
    reason = _ACCEPTED
    for i in range(nfu):
        f = fu[i]
        if F[f, 0] == v or F[f, 1] == v or F[f, 2] == v:
            continue
        for k in range(3):
            x = v if F[f, k] == u else F[f, k]
            tri[k, 0], tri[k, 1], tri[k, 2] = V[x, 0], V[x, 1], V[x, 2]
        _cross(tri[0], tri[1], tri[2], nrm)
        _cross(V[F[f, 0]], V[F[f, 1]], V[F[f, 2]], old)
        longest = 0.0
        for k in range(3):
            d = 0.0
            for c in range(3):
                d += (tri[(k + 1) % 3, c] - tri[k, c]) ** 2
            longest = max(longest, d)
        length = np.sqrt(nrm[0] ** 2 + nrm[1] ** 2 + nrm[2] ** 2)
        if not length > _AREA_REL * longest:
            reason = _DEGENERATE
            break
        old_length = np.sqrt(old[0] ** 2 + old[1] ** 2 + old[2] ** 2)
        c_old = ((nrm[0] * old[0] + nrm[1] * old[1] + nrm[2] * old[2])
                 / (length * old_length))
        c_origin = (nrm[0] * n_origin[f, 0] + nrm[1] * n_origin[f, 1]
                    + nrm[2] * n_origin[f, 2]) / length
        if c_old < cos_max or c_origin < cos_max:
            reason = _NORMAL
            break
        # the changed face (v, a, b) must not repeat a face around v
        a = -1
        b = -1
        for k in range(3):
            if F[f, k] != u:
                if a < 0:
                    a = F[f, k]
                else:
                    b = F[f, k]
        for j in range(nfv):
            g = fv[j]
            if (F[g, 0] == a or F[g, 1] == a or F[g, 2] == a) and \
                    (F[g, 0] == b or F[g, 1] == b or F[g, 2] == b):
                reason = _DUPLICATE
                break
        if reason >= 0:
            break
    return reason
