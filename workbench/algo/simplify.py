"""Decimation bounded by a certified one-sided Hausdorff distance (crash2000, section 3.2).

:func:`hausdorff_decimate` removes triangles by half-edge collapses (a vertex u moves onto a
neighbour v) for as long as every point of the ORIGINAL surface stays within a tolerance of the
simplified one. Vertex coordinates never change and no vertex is created: the result is a new
index array into the caller's vertex array, which the original and the simplified mesh share
(the paper's shared coordinate set).

How the distance is certified rather than sampled: every original triangle T keeps a small
*support* S(T) of current faces such that the subdivision bound of
:func:`workbench.algo.distance.triangle_bounds` certifies ``max_{p ∈ T} d(p, S(T)) <= tol``
(the distance to a triangle is convex, so its maximum over a piece of T is at a corner; pieces
are split four ways at edge midpoints where one face does not cover them). S(T) only holds
faces of the current mesh, so every point of T is within tol of the simplified surface. A
collapse u → v changes or removes the faces around u; every original triangle supported by one
of them is re-certified against its remaining support plus the new faces around v, and the
collapse is undone unless all pass. The new support is the set of faces that certified at least
one leaf piece, so supports stay small. A piece that straddles the edge between two faces is
covered only once it is about tol wide, so the subdivision depth is chosen per original
triangle from its longest edge over its tolerance (:func:`certification_depths`): a fixed
shallow depth refuses even exact collapses on a flat plate of large elements.

Collapse order: a priority queue of half-edges by a quadric error (the mean squared distance of
v from the planes of the original triangles around u and around the vertices already collapsed
into it, plus a small share of the squared edge length, which orders flat regions by edge
length), with lazy invalidation by per-vertex version stamps. After a collapse the half-edges
out of v, out of its neighbours that saw a rejection since they were last queued, and the new
ones towards v are queued; when the queue runs dry every remaining half-edge is tried once more
(``passes``), since re-certified supports elsewhere can make earlier rejections feasible.

Topology and shape rules (a collapse that breaks one is rejected and counted by reason):

* ``topology`` -- the edge has more than two faces, u is a non-manifold vertex (its faces do not
  form one fan), the link condition fails (u and v share a neighbour that is not opposite the
  edge), or an interior edge joins two boundary vertices;
* ``fixed`` -- u never moves: it is used by faces of three or more parts (or of two parts
  anywhere but inside their common boundary, see below), by a zero-area input face, touches a
  non-manifold edge, or is a corner (on 1 or >= 3 feature/boundary edges, or where its
  feature/boundary polyline turns by more than ``feature_deg``). Such vertices are not queued
  at all; the count is of vertices that became corners on the way;
* ``feature`` -- u lies on two feature/boundary edges and uv is not one of them (u may only
  slide along its feature line);
* ``normal`` -- a changed face would turn by more than ``max_normal_deg`` from its normal
  before the collapse or from the normal of the input face it descends from;
* ``degenerate`` -- a changed face would get (close to) zero area;
* ``duplicate`` -- a changed face would repeat an existing face;
* ``hausdorff`` -- an original triangle could not be re-certified within tol;
* ``support`` -- a re-certification needs more than 12 support faces.

The common boundary of two parts (edges with one face of each part) is a feature polyline of
both. A vertex inside it -- used by exactly those two parts, on exactly two constrained edges
which are both common edges, on no open edge -- slides along it in both parts at once: the
half-edge collapse u → v along the common boundary is applied to the faces of both parts
together, so the shared vertex buffer stays shared and no crack opens. Such a collapse must
also keep the link condition within each part on its own, and re-certifies the original
triangles of both parts, each against the faces of its own part and its own part's tolerance.
Where three or more parts meet, where the common boundary ends or turns by more than
``feature_deg``, or where a part's own boundary or feature lines meet it, the vertex is a
corner and stays.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numba
import numpy as np
from numba import types
from numba.typed import Dict

from .distance import closest_point_on_triangle, triangle_bounds

__all__ = ["Decimation", "certification_depths", "hausdorff_decimate"]

REJECT_REASONS = ("fixed", "feature", "topology", "normal", "degenerate", "duplicate",
                  "hausdorff", "support")
_FIXED, _FEATURE, _TOPOLOGY, _NORMAL, _DEGENERATE, _DUPLICATE, _HAUSDORFF, _SUPPORT = range(8)

# a face whose |cross product| is below this share of its longest edge squared has zero area
_AREA_REL = 1e-6
# most faces one original triangle may be certified by
_MAX_SUPPORT = 12
# weight of the squared edge length in the collapse cost (orders flat regions)
_LENGTH_WEIGHT = 1e-3
# bounds of the automatic certification depth (see certification_depths)
MIN_DEPTH = 5
MAX_AUTO_DEPTH = 10


@dataclass
class Decimation:
    """Result of :func:`hausdorff_decimate`.

    ``triangles`` index the caller's vertex array (no vertex is moved or added); ``parts`` is
    the part label of each output triangle. ``part_labels`` (P,) are the input's part labels,
    sorted, and ``tol_abs`` (P,) each one's tolerance in model units (:meth:`tol_for` looks one
    up by label). ``bounds`` has one entry per input triangle: a certified upper bound of the
    largest distance from a point of that triangle to the simplified surface (model units; NaN
    for input triangles with a repeated vertex index, which were dropped); ``certified_max`` is
    their maximum, an upper bound of the one-sided Hausdorff distance original → simplified.
    These bounds are certificates that the tolerance holds, measured against the few faces
    that certify each triangle; they can be far above the true distance (flat parts often sit
    within micrometres of the result yet report a bound near tol). For the distance itself use
    an exact metric such as :mod:`workbench.algo.hausdorff`.
    ``collapses`` counts half-edge collapses done, ``rejected`` the collapses refused, by
    reason (see the module notes), ``seconds`` the wall time of the call, ``passes`` how often
    the queue was filled.
    ``bytes_saved`` is the size of the vertex array a separate simplified mesh would store
    (referenced vertices × 3 × 8 bytes for float64; multiply by the number of time steps for a
    time-dependent result), which sharing the original buffer saves.
    """

    triangles: np.ndarray
    parts: np.ndarray
    part_labels: np.ndarray
    tol_abs: np.ndarray
    collapses: int
    rejected: dict[str, int]
    seconds: float
    bounds: np.ndarray
    certified_max: float
    bytes_saved: int
    input_triangles: int
    passes: int
    dropped: int = 0
    notes: list[str] = field(default_factory=list)

    def tol_for(self, label: int) -> float:
        """The tolerance (model units) of the part labelled ``label``; KeyError if none."""
        hit = np.flatnonzero(self.part_labels == label)
        if len(hit) == 0:
            raise KeyError(f"no part {label}")
        return float(self.tol_abs[hit[0]])

    @property
    def ratio(self) -> float:
        """Output triangles per input triangle."""
        return len(self.triangles) / max(self.input_triangles, 1)


# --------------------------------------------------------------------------- small kernels
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
def _part_link_ok(u, v, fu, nfu, fv, nfv, F, fpart, part, nb_u, cnt_u, nb_v, cnt_v, pos):
    """Link condition of the edge uv within the faces of ``part`` only: the neighbours u and v
    share in that part are the vertices opposite uv in that part's faces. ``pos`` (N,) is -1
    everywhere on entry and on return."""
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


# a candidate face record: corners a, b, c (0:9), bounding-sphere centre (9:12) and radius
# (12), unit normal (13:16) and plane offset (16); a degenerate face has a zero plane
_REC = 17


@numba.njit(cache=True)
def _set_record(rec, j, a, b, c):
    """Fill candidate record j from the corner rows a, b, c."""
    for k in range(3):
        rec[j, k], rec[j, 3 + k], rec[j, 6 + k] = a[k], b[k], c[k]
        rec[j, 9 + k] = (a[k] + b[k] + c[k]) / 3.0
    r2 = 0.0
    for corner in (a, b, c):
        d = 0.0
        for k in range(3):
            d += (corner[k] - rec[j, 9 + k]) ** 2
        r2 = max(r2, d)
    rec[j, 12] = np.sqrt(r2)
    n0 = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1])
    n1 = (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2])
    n2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    length = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    if length > 0.0:
        n0, n1, n2 = n0 / length, n1 / length, n2 / length
    else:
        n0 = n1 = n2 = 0.0
    rec[j, 13], rec[j, 14], rec[j, 15] = n0, n1, n2
    rec[j, 16] = -(n0 * a[0] + n1 * a[1] + n2 * a[2])


@numba.njit(cache=True, inline="always")
def _covers(piece, rec, f, tol, p, a, b, c, tmp):
    """True when the three corners of ``piece`` are within tol of candidate face f.

    The sphere and plane tests only reject (a point farther than tol from the face's bounding
    sphere or plane is farther than tol from the face); acceptance always comes from the
    exact distance of :func:`closest_point_on_triangle`.
    """
    reach = rec[f, 12] + tol
    for i in range(3):
        x, y, z = piece[i, 0], piece[i, 1], piece[i, 2]
        dx, dy, dz = x - rec[f, 9], y - rec[f, 10], z - rec[f, 11]
        if dx * dx + dy * dy + dz * dz > reach * reach:
            return False
        if abs(rec[f, 13] * x + rec[f, 14] * y + rec[f, 15] * z + rec[f, 16]) > tol:
            return False
    for k in range(3):
        a[k], b[k], c[k] = rec[f, k], rec[f, 3 + k], rec[f, 6 + k]
    for i in range(3):
        p[0], p[1], p[2] = piece[i, 0], piece[i, 1], piece[i, 2]
        if np.sqrt(closest_point_on_triangle(p, a, b, c, tmp)) > tol:
            return False
    return True


@numba.njit(cache=True)
def _certify(t, cand, n_cand, tol, max_depth, used, stack, depth, piece, corners):
    """True when every point of triangle t is within tol of the union of the candidate faces
    (records ``cand[:n_cand]``, see ``_REC``); ``corners`` is (5, 3) scratch.

    Walks the same quadtree of pieces as :func:`triangle_bounds` (same midpoints, same order):
    a piece whose three corners are within tol of one face is covered by it (distance to a
    triangle is convex), that face is flagged in ``used`` and the piece is a leaf; otherwise it
    is split, and at ``max_depth`` the certification fails. Faces already flagged are tried
    first, so supports stay small.
    """
    q, qa, qb, qc, tmp = corners[0], corners[1], corners[2], corners[3], corners[4]
    stack[0] = t
    depth[0] = 0
    top = 1
    while top > 0:
        top -= 1
        level = depth[top]
        for i in range(3):
            for c in range(3):
                piece[i, c] = stack[top, i, c]
        covered = False
        for f in range(n_cand):
            if used[f] and _covers(piece, cand, f, tol, q, qa, qb, qc, tmp):
                covered = True
                break
        if not covered:
            for f in range(n_cand):
                if not used[f] and _covers(piece, cand, f, tol, q, qa, qb, qc, tmp):
                    used[f] = True
                    covered = True
                    break
        if covered:
            continue
        if level >= max_depth:
            return False
        for k in range(4):
            for c in range(3):
                m01 = 0.5 * (piece[0, c] + piece[1, c])
                m12 = 0.5 * (piece[1, c] + piece[2, c])
                m20 = 0.5 * (piece[2, c] + piece[0, c])
                if k == 0:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = piece[0, c], m01, m20
                elif k == 1:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = m01, piece[1, c], m12
                elif k == 2:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = m20, m12, piece[2, c]
                else:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = m12, m20, m01
            depth[top] = level + 1
            top += 1
    return True


# --------------------------------------------------------------------------- priority queue
@numba.njit(cache=True)
def _heap_push(hk, hu, hv, hs, n, key, u, v, stamp):
    """Push onto the binary min-heap held in (hk, hu, hv, hs)[:n]; returns the arrays (grown
    when full) and the new size."""
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
    i = n
    while i > 0:
        parent = (i - 1) >> 1
        if hk[parent] <= key:
            break
        hk[i], hu[i], hv[i], hs[i] = hk[parent], hu[parent], hv[parent], hs[parent]
        i = parent
    hk[i], hu[i], hv[i], hs[i] = key, u, v, stamp
    return hk, hu, hv, hs, n + 1


@numba.njit(cache=True)
def _heap_pop(hk, hu, hv, hs, n):
    """Remove the smallest entry; returns it (u, v, stamp) and the new size."""
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


# --------------------------------------------------------------------------- the decimator
@numba.njit(cache=True)
def _decimate(V, F, fpart, alive, n_origin, orig, orig_tol, orig_face, fixed, ckeys, cdeg, Q,
              area, cos_max, orig_depth, max_passes):
    """Greedy certified half-edge collapses; changes F, alive, cdeg, Q and area in place.

    Returns (support (K, S), support counts (K,), collapses, rejections (8,), passes).
    """
    n_vert = V.shape[0]
    m = F.shape[0]
    k_orig = orig.shape[0]
    S = _MAX_SUPPORT

    # vertex -> corner slots (3 f + k) as singly linked lists
    head = np.full(n_vert, -1, np.int64)
    tail = np.full(n_vert, -1, np.int64)
    nxt = np.full(3 * m, -1, np.int64)
    for f in range(m):
        if not alive[f]:
            continue
        for k in range(3):
            s = 3 * f + k
            x = F[f, k]
            if head[x] < 0:
                head[x] = s
            else:
                nxt[tail[x]] = s
            tail[x] = s

    # supports, and per face the original triangles it (may) support, deleted lazily
    sup = np.full((k_orig, S), -1, np.int32)
    sup_n = np.zeros(k_orig, np.int32)
    e_tri = np.empty(2 * k_orig + 16, np.int32)
    e_next = np.empty(2 * k_orig + 16, np.int64)
    n_e = 0
    s_head = np.full(m, -1, np.int64)
    for t in range(k_orig):
        f = orig_face[t]
        sup[t, 0] = f
        sup_n[t] = 1
        e_tri[n_e] = t
        e_next[n_e] = s_head[f]
        s_head[f] = n_e
        n_e += 1

    constrained = Dict.empty(key_type=types.int64, value_type=types.int8)
    for i in range(len(ckeys)):
        constrained[ckeys[i]] = np.int8(1)

    dead = np.zeros(n_vert, np.bool_)
    pos = np.full(n_vert, -1, np.int64)
    version = np.zeros(n_vert, np.int32)
    retry = np.zeros(n_vert, np.bool_)
    near_u = np.full(n_vert, -1, np.int64)
    near_v = np.full(n_vert, -1, np.int64)
    stamp = np.zeros(k_orig, np.int64)
    cur = 0

    fu = np.empty(m, np.int64)
    fv = np.empty(m, np.int64)
    fw = np.empty(m, np.int64)
    nbu = np.empty(2 * m + 2, np.int64)
    cntu = np.empty(2 * m + 2, np.int64)
    nbv = np.empty(2 * m + 2, np.int64)
    cntv = np.empty(2 * m + 2, np.int64)
    nbp = np.empty(2 * m + 2, np.int64)
    cntp = np.empty(2 * m + 2, np.int64)
    nbq = np.empty(2 * m + 2, np.int64)
    cntq = np.empty(2 * m + 2, np.int64)
    seen = np.empty(m, np.bool_)
    queue = np.empty(m, np.int64)
    aff = np.empty(k_orig, np.int64)
    max_depth = orig_depth.max() if k_orig > 0 else 0
    stack = np.empty((4 * max_depth + 4, 3, 3))
    depth = np.empty(4 * max_depth + 4, np.int64)
    piece = np.empty((3, 3))
    corners = np.empty((5, 3))
    tc = np.empty(3)
    nrm = np.empty(3)
    old = np.empty(3)
    tri = np.empty((3, 3))
    rejected = np.zeros(8, np.int64)
    collapses = 0

    hk = np.empty(16)
    hu = np.empty(16, np.int32)
    hv = np.empty(16, np.int32)
    hs = np.empty(16, np.int32)
    hn = 0

    passes = 0
    while passes < max_passes:
        passes += 1
        # every half-edge x -> y out of a vertex that may move
        for x in range(n_vert):
            if dead[x] or fixed[x] or not (cdeg[x] == 0 or cdeg[x] == 2):
                continue
            nfx = _gather(x, head, tail, nxt, alive, fu)
            nnx = _neighbours(x, fu, nfx, F, fpart, -1, nbu, cntu, pos)
            for j in range(nnx):
                y = nbu[j]
                if cdeg[x] == 2 and _edge_key(x, y, n_vert) not in constrained:
                    continue
                hk, hu, hv, hs, hn = _heap_push(hk, hu, hv, hs, hn, _cost(Q, area, V, x, y),
                                                x, y, version[x])
        pass_collapses = 0
        while hn > 0:
            u, v, st, hn = _heap_pop(hk, hu, hv, hs, hn)
            if dead[u] or dead[v] or st != version[u]:
                continue
            if fixed[u] or not (cdeg[u] == 0 or cdeg[u] == 2):
                rejected[_FIXED] += 1
                continue
            nfu = _gather(u, head, tail, nxt, alive, fu)
            if nfu == 0:
                continue
            part = fpart[fu[0]]
            nnu = _neighbours(u, fu, nfu, F, fpart, -1, nbu, cntu, pos)
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
                continue  # no longer an edge
            if cdeg[u] == 2 and _edge_key(u, v, n_vert) not in constrained:
                rejected[_FEATURE] += 1
                retry[u] = True
                continue
            # --- topology
            ok = True
            u_boundary = False
            for j in range(nnu):
                if cntu[j] > 2:
                    ok = False
                if cntu[j] == 1:
                    u_boundary = True
            if ok:
                ok = _one_fan(u, fu, nfu, F, seen, queue)
            nfv = 0
            nnv = 0
            if ok:
                nfv = _gather(v, head, tail, nxt, alive, fv)
                nnv = _neighbours(v, fv, nfv, F, fpart, -1, nbv, cntv, pos)
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
                # u lies on the common boundary of two parts and slides along it in both: uv
                # must be that boundary (one face of each part on it), u's faces only of the
                # two parts, and the link condition must hold within each part on its own
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
                    ok = _part_link_ok(u, v, fu, nfu, fv, nfv, F, fpart, part, nbp, cntp, nbq,
                                       cntq, pos)
                if ok:
                    ok = _part_link_ok(u, v, fu, nfu, fv, nfv, F, fpart, other_part, nbp, cntp,
                                       nbq, cntq, pos)
            if ok and n_uv == 2 and u_boundary:
                # an interior edge between two boundary vertices would pinch the surface
                mixed = False
                for i in range(nfv):
                    if fpart[fv[i]] != part:
                        mixed = True
                if mixed:
                    nnw = _neighbours(v, fv, nfv, F, fpart, part, nbu[nnu:], cntu[nnu:], pos)
                    for i in range(nnw):
                        if cntu[nnu + i] == 1:
                            ok = False
                else:
                    for i in range(nnv):
                        if cntv[i] == 1:
                            ok = False
            if not ok:
                rejected[_TOPOLOGY] += 1
                retry[u] = True
                continue
            # --- shape of the changed faces
            reason = -1
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
            if reason >= 0:
                rejected[reason] += 1
                retry[u] = True
                continue

            # --- the new fan around v: unchanged faces of v, changed faces of u (of every part;
            # an original triangle is certified against the faces of its own part only)
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

            # --- original triangles supported by the faces around u
            cur += 1
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

            # --- re-certify each against its remaining support plus the new fan
            new_sup = np.empty((n_aff, S), np.int32)
            new_n = np.zeros(n_aff, np.int32)
            cand = np.empty((S + n_fan, _REC))
            cand_id = np.empty(S + n_fan, np.int64)
            used = np.empty(S + n_fan, np.bool_)
            for i in range(n_aff):
                t = aff[i]
                tol = orig_tol[t]
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
                t_part = fpart[orig_face[t]]
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
                for j in range(nc):
                    used[j] = False
                if nc == 0 or not _certify(orig[t], cand, nc, tol, orig_depth[t], used, stack,
                                           depth, piece, corners):
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
            if reason >= 0:
                rejected[reason] += 1
                retry[u] = True
                continue

            # --- commit
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
            for c in range(10):
                Q[v, c] += Q[u, c]
            area[v] += area[u]
            if cdeg[u] == 2:
                # u slid along its feature line: the line now runs v - b
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
            dead[u] = True
            collapses += 1
            pass_collapses += 1

            # --- requeue: every half-edge out of v (its quadric changed), out of neighbours
            # with a rejection since their last requeue (their surroundings changed), and the
            # new half-edges towards v
            for j in range(nnu):
                near_u[nbu[j]] = collapses
            for j in range(nnv):
                near_v[nbv[j]] = collapses
            nfv = _gather(v, head, tail, nxt, alive, fv)
            nnv = _neighbours(v, fv, nfv, F, fpart, -1, nbv, cntv, pos)
            for j in range(-1, nnv):
                a = v if j < 0 else nbv[j]
                if fixed[a] or not (cdeg[a] == 0 or cdeg[a] == 2):
                    continue
                if a == v or retry[a]:
                    version[a] += 1
                    retry[a] = False
                    nfa = _gather(a, head, tail, nxt, alive, fu)
                    nna = _neighbours(a, fu, nfa, F, fpart, -1, nbu, cntu, pos)
                    for i in range(nna):
                        b = nbu[i]
                        if cdeg[a] == 2 and _edge_key(a, b, n_vert) not in constrained:
                            continue
                        hk, hu, hv, hs, hn = _heap_push(hk, hu, hv, hs, hn,
                                                        _cost(Q, area, V, a, b), a, b, version[a])
                elif near_u[a] == collapses and near_v[a] != collapses:
                    if cdeg[a] == 2 and _edge_key(a, v, n_vert) not in constrained:
                        continue
                    hk, hu, hv, hs, hn = _heap_push(hk, hu, hv, hs, hn, _cost(Q, area, V, a, v),
                                                    a, v, version[a])
        if pass_collapses == 0:
            break
    return sup, sup_n, collapses, rejected, passes


@numba.njit(cache=True)
def _final_bounds(V, F, orig, orig_tol, sup, sup_n, orig_depth):
    """Per original triangle, the upper bound of :func:`triangle_bounds` against its support
    (split while above tol). The certificate: each is <= tol by construction."""
    k_orig = orig.shape[0]
    out = np.empty(k_orig)
    for t in range(k_orig):
        n = sup_n[t]
        if n == 0:
            out[t] = np.inf
            continue
        faces = np.empty((n, 3, 3))
        for j in range(n):
            g = sup[t, j]
            for k in range(3):
                for c in range(3):
                    faces[j, k, c] = V[F[g, k], c]
        out[t] = triangle_bounds(orig[t], faces, orig_tol[t], orig_depth[t])[1]
    return out


# --------------------------------------------------------------------------- preparation
def _check_inputs(vertices, triangles, tol, parts, feature_deg, max_normal_deg, max_depth,
                  passes, feature_min_length=None):
    v = np.asarray(vertices)
    if v.ndim != 2 or v.shape[1] != 3 or v.dtype.kind not in "fiu":
        raise ValueError(f"vertices must be a numeric (N, 3) array, got {v.dtype} {v.shape}")
    v = np.ascontiguousarray(v, np.float64)
    if not np.isfinite(v).all():
        raise ValueError("vertices must be finite")
    t = np.asarray(triangles)
    if t.ndim != 2 or t.shape[1] != 3 or (t.size and t.dtype.kind not in "iu"):
        raise ValueError(f"triangles must be (K, 3) integer vertex indices, got {t.dtype} "
                         f"{t.shape}")
    if len(t) == 0:
        raise ValueError("no triangles to decimate")
    if t.min() < 0 or t.max() >= len(v):
        bad = np.flatnonzero(((t < 0) | (t >= len(v))).any(axis=1))
        raise ValueError(f"{len(bad)} triangles index missing vertices, first {bad[:5].tolist()}")
    t = np.ascontiguousarray(t, np.int32)
    tol = float(tol)
    if not np.isfinite(tol) or tol <= 0:
        raise ValueError(f"tol must be a positive finite number, got {tol!r}")
    if parts is None:
        p = np.zeros(len(t), np.int32)
    else:
        p = np.asarray(parts)
        if p.shape != (len(t),) or (p.size and p.dtype.kind not in "iu"):
            raise ValueError(f"parts must be ({len(t)},) integer labels, got {p.dtype} {p.shape}")
        p = np.ascontiguousarray(p, np.int32)
    if not 0.0 <= float(feature_deg) <= 180.0:
        raise ValueError(f"feature_deg must be within [0, 180] degrees, got {feature_deg}")
    if not 0.0 < float(max_normal_deg) <= 180.0:
        raise ValueError(f"max_normal_deg must be within (0, 180] degrees, got {max_normal_deg}")
    if max_depth is not None and (int(max_depth) != max_depth or not 0 <= max_depth <= 12):
        raise ValueError(f"max_depth must be an integer within [0, 12], got {max_depth}")
    if int(passes) != passes or passes < 1:
        raise ValueError(f"passes must be a positive integer, got {passes}")
    if feature_min_length is not None and not (np.isfinite(feature_min_length)
                                               and feature_min_length >= 0):
        raise ValueError(f"feature_min_length must be None or a finite number >= 0, got "
                         f"{feature_min_length!r}")
    return v, t, tol, p


def _unit_normals(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit normals (zero where degenerate), areas and a degenerate mask of (K, 3, 3) corners."""
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(cross, axis=1)
    edges = corners[:, [1, 2, 0]] - corners
    longest = (edges ** 2).sum(axis=2).max(axis=1)
    degenerate = ~(length > _AREA_REL * longest)
    unit = np.where(degenerate[:, None], 0.0, cross / np.where(degenerate, 1.0, length)[:, None])
    return unit, 0.5 * length, degenerate


def _group_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Equal rows of an (R, C) int64 array: a group id per row and each group's first row."""
    order = np.lexsort(rows.T[::-1])
    ordered = rows[order]
    new = np.ones(len(rows), bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    group = np.empty(len(rows), np.int64)
    group[order] = np.cumsum(new) - 1
    return group, order[new]     # lexsort is stable: the first of a group is its smallest row


def _edges_of(F: np.ndarray, n_vert: int):
    """Per face corner k, the edge to the next corner: its two vertices a, b, the face, the
    undirected key ``min * n_vert + max`` and whether it runs from the lower vertex."""
    a = F.ravel().astype(np.int64)
    b = F[:, [1, 2, 0]].ravel().astype(np.int64)
    face = np.repeat(np.arange(len(F)), 3)
    key = np.minimum(a, b) * n_vert + np.maximum(a, b)
    return a, b, face, key, a < b


def _long_chains(a: np.ndarray, b: np.ndarray, V: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """(E,) bool: whether each edge (a, b) lies on a connected set of these edges (joined at
    shared vertices) whose summed length is at least its ``reach``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nodes, inverse = np.unique(np.r_[a, b], return_inverse=True)
    ia, ib = inverse[:len(a)], inverse[len(a):]
    graph = coo_matrix((np.ones(len(a)), (ia, ib)), shape=(len(nodes), len(nodes)))
    _, label = connected_components(graph, directed=False)
    length = np.linalg.norm(V[a] - V[b], axis=1)
    total = np.bincount(label[ia], weights=length)
    return total[label[ia]] >= reach


def certification_depths(corners: np.ndarray, tol: np.ndarray, max_depth=None) -> np.ndarray:
    """(K,) int64 subdivision depth of the certification of each original triangle.

    ``corners`` (K, 3, 3), ``tol`` (K,) in the same units. A piece of a triangle that straddles
    the edge between two simplified faces is certified only once it is narrow enough for one
    face to reach all of its corners, about ``tol`` across: the depth that takes the longest
    edge L of the triangle down to that, ``ceil(log2(L / tol)) + 1``, at least
    ``MIN_DEPTH`` and at most ``MAX_AUTO_DEPTH``. An integer ``max_depth`` fixes every depth
    to it instead.
    """
    if max_depth is not None:
        return np.full(len(corners), int(max_depth), np.int64)
    edges = corners[:, [1, 2, 0]] - corners
    longest = np.sqrt((edges ** 2).sum(axis=2).max(axis=1))
    ratio = np.maximum(longest / tol, 1.0)
    return np.clip(np.ceil(np.log2(ratio)) + 1, MIN_DEPTH, MAX_AUTO_DEPTH).astype(np.int64)


def _sliding_shared(key, common, union_boundary, cdeg, parts_at) -> np.ndarray:
    """(N,) True for the vertices that may slide along the common boundary of two parts:
    used by exactly two parts, on exactly two constrained edges which are both common-boundary
    edges (one face of each part), and on no edge with a single face over all parts. Every
    other vertex used by several parts is a corner of the part structure."""
    n_vert = len(cdeg)
    common_deg = _key_degree(np.unique(key[common]), n_vert)
    open_deg = _key_degree(np.unique(key[union_boundary]), n_vert)
    return (parts_at == 2) & (cdeg == 2) & (common_deg == 2) & (open_deg == 0)


def _key_degree(keys: np.ndarray, n_vert: int) -> np.ndarray:
    """(N,) int32 how many of the undirected edges ``keys`` (``min * n_vert + max``, each once)
    each vertex is on."""
    return (np.bincount(keys // n_vert, minlength=n_vert)
            + np.bincount(keys % n_vert, minlength=n_vert)).astype(np.int32)


def hausdorff_decimate(vertices, triangles, tol: float = 0.005, *, relative: bool = True,
                       parts=None, feature_deg: float = 30.0, keep_boundary: bool = True,
                       max_normal_deg: float = 60.0, max_depth: int | None = None,
                       passes: int = 2, slide_shared: bool = True,
                       feature_min_length: float | None = 10.0) -> Decimation:
    """Decimate a triangle mesh by half-edge collapses within a certified one-sided Hausdorff
    distance from the original surface (crash2000, section 3.2).

    ``vertices`` (N, 3) float64 model units, ``triangles`` (K, 3) integer indices; the result
    indexes the SAME vertex array (vertices are never moved or created). ``tol`` is, with
    ``relative=True`` (default), a fraction of each part's bounding-sphere diameter -- the sphere
    around the part's axis-aligned bounding box (centre = box centre, diameter = box diagonal,
    as :meth:`FEMesh.bounding_sphere`), which is at most √3 times the smallest enclosing sphere;
    0.005 is the paper's 0.5 %. With ``relative=False`` it is a length in model units.

    ``parts`` (K,) labels decimate each part on its own, against its own tolerance: a part's
    original triangles are certified against that part's faces only. With ``slide_shared``
    (default) a vertex inside the common boundary of two parts slides along it in both parts at
    once (the module notes say which vertices are corners); without it, and always where three
    or more parts meet, vertices used by more than one part never move. Either way every part
    stays drawable on its own and shares the vertices along its borders with its neighbours.
    Feature edges (the angle between the orientation-corrected normals of their two faces above
    ``feature_deg`` degrees, on a connected set of such edges at least ``feature_min_length``
    times its part's tolerance long in all: a shorter crease is detail the tolerance lets go,
    like the noise of a scanned surface; None keeps every crease), the common boundaries of
    parts and, with ``keep_boundary``, boundary edges are kept as polylines: a vertex on two
    of them only slides along them, a vertex on one or on three or more, or where its polyline
    turns by more than ``feature_deg``, never moves. ``max_normal_deg`` bounds how far a changed
    face may turn per collapse and from the face it descends from; ``max_depth`` is the
    subdivision depth of the certification (deeper certifies closer to tol, slower): None
    (default) picks it per input triangle from its longest edge and its tolerance
    (:func:`certification_depths`, 5 to 10), an integer fixes it;
    ``passes`` is how often the queue is refilled with every remaining half-edge.

    Guarantee: every point of every input triangle is within its part's tolerance of the
    simplified surface, certified by the convexity bound of
    :func:`~workbench.algo.distance.triangle_bounds` (recomputed with that function for the
    returned ``bounds``), not by sampling. Computation runs in float64 relative to the centre
    of the mesh's bounding box, so far-away models keep their digits.

    Non-manifold input (edges with three or more faces, bow-tie vertices) and duplicate faces
    are accepted: what cannot be collapsed safely is left as it is, duplicate faces are kept
    once (the others are certified against it), zero-area triangles keep their vertices in
    place, triangles with a repeated vertex index are dropped (they have no area; their
    ``bounds`` are NaN). Refused with ValueError: arrays of
    the wrong shape or type, indices out of range, non-finite coordinates, no triangles, a
    non-positive tol, angles out of range, max_depth outside [0, 12], passes < 1, a negative
    feature_min_length.
    """
    start = time.perf_counter()
    v_in, t_in, tol, p_in = _check_inputs(vertices, triangles, tol, parts, feature_deg,
                                          max_normal_deg, max_depth, passes, feature_min_length)
    n_vert = len(v_in)
    k_in = len(t_in)
    notes: list[str] = []

    repeated = (t_in[:, 0] == t_in[:, 1]) | (t_in[:, 1] == t_in[:, 2]) | (t_in[:, 2] == t_in[:, 0])
    keep = np.flatnonzero(~repeated)
    if repeated.any():
        notes.append(f"{int(repeated.sum())} triangles with a repeated vertex index dropped")
    if len(keep) == 0:
        raise ValueError("every triangle repeats a vertex index: nothing to decimate")
    t_orig = t_in[keep]
    p_orig = p_in[keep]

    # per part tolerance from its bounding box diagonal
    labels, part_index = np.unique(p_orig, return_inverse=True)
    part_index = part_index.ravel()
    corner_part = np.repeat(part_index, 3)
    lo = np.full((len(labels), 3), np.inf)
    hi = np.full((len(labels), 3), -np.inf)
    np.minimum.at(lo, corner_part, v_in[t_orig.ravel()])
    np.maximum.at(hi, corner_part, v_in[t_orig.ravel()])
    diagonal = np.linalg.norm(hi - lo, axis=1)
    tol_of_label = tol * diagonal if relative else np.full(len(labels), tol)

    used_all = np.unique(t_orig)
    centre = 0.5 * (v_in[used_all].min(axis=0) + v_in[used_all].max(axis=0))
    V = np.ascontiguousarray(v_in - centre)

    # duplicate faces (same vertex set within a part) are kept once
    sorted_t = np.sort(t_orig, axis=1).astype(np.int64)
    fkey = np.stack([p_orig.astype(np.int64), sorted_t[:, 0], sorted_t[:, 1], sorted_t[:, 2]], 1)
    group, first = _group_rows(fkey)
    order = np.argsort(first)          # faces in the order of their first occurrence
    rank = np.empty(len(first), np.int64)
    rank[order] = np.arange(len(first))
    orig_face = rank[group]
    first = first[order]
    F = np.ascontiguousarray(t_orig[first], np.int32)
    fpart = np.ascontiguousarray(p_orig[first], np.int32)
    m = len(F)

    orig = np.ascontiguousarray(V[t_orig])
    n_origin, face_area, degenerate = _unit_normals(V[F])

    # vertices that never move
    fixed = np.zeros(n_vert, bool)
    _, fpart_index = np.unique(fpart, return_inverse=True)
    vp = np.unique(F.ravel().astype(np.int64) * len(labels) + np.repeat(fpart_index.ravel(), 3))
    parts_at = np.bincount(vp // len(labels), minlength=n_vert)
    fixed[F[degenerate].ravel()] = True

    a, b, face, key, forward = _edges_of(F, n_vert)
    edge_part = np.repeat(fpart, 3).astype(np.int64)
    # count faces per edge over all parts (non-manifold) and per (part, edge)
    _, ui, uc = np.unique(key, return_inverse=True, return_counts=True)
    ui = ui.ravel()
    nonmanifold = uc[ui] > 2
    fixed[a[nonmanifold]] = True
    fixed[b[nonmanifold]] = True
    pi, _ = _group_rows(np.stack([edge_part, key], 1))
    per_part = np.bincount(pi)[pi]
    constrained = np.zeros(len(key), bool)
    if keep_boundary:
        constrained |= per_part == 1
    # feature edges: edges with exactly two faces of one part, normals oriented by the winding
    two = np.flatnonzero((per_part == 2) & ~nonmanifold)
    if len(two):
        order = two[np.lexsort((key[two], edge_part[two]))]
        g1, g2 = order[0::2], order[1::2]
        n1, n2 = n_origin[face[g1]], n_origin[face[g2]]
        cos = np.einsum("ij,ij->i", n1, n2)
        cos = np.where(forward[g1] != forward[g2], cos, -cos)
        crease = cos < np.cos(np.radians(float(feature_deg))) - 1e-12
        if feature_min_length is not None and crease.any():
            edges = g1[crease]
            reach = float(feature_min_length) * tol_of_label[fpart_index[face[edges]]]
            crease[np.flatnonzero(crease)[~_long_chains(a[edges], b[edges], V, reach)]] = False
        constrained[g1[crease]] = True
        constrained[g2[crease]] = True
    # the common boundary of two parts (edges with one face of each) is always a polyline
    common = (uc[ui] == 2) & (per_part == 1)
    constrained |= common
    ckeys = np.unique(key[constrained])
    cdeg = _key_degree(ckeys, n_vert)
    lo_v, hi_v = ckeys // n_vert, ckeys % n_vert
    # a vertex where its two feature/boundary edges turn by more than feature_deg is a corner
    ends = np.concatenate([lo_v, hi_v])
    others = np.concatenate([hi_v, lo_v])
    on_line = cdeg[ends] == 2
    ends, others = ends[on_line], others[on_line]
    order = np.argsort(ends, kind="stable")
    ends, others = ends[order], others[order]
    if len(ends):
        mid = ends[0::2]
        d1 = V[others[0::2]] - V[mid]
        d2 = V[others[1::2]] - V[mid]
        # the turn is 180° minus the angle between the two edges seen from the vertex;
        # coincident vertices (zero-length edges) count as a corner
        lengths = np.linalg.norm(d1, axis=1) * np.linalg.norm(d2, axis=1)
        cos_turn = -np.einsum("ij,ij->i", d1, d2) / np.where(lengths > 0, lengths, 1.0)
        cos_turn[lengths == 0] = -1.0
        fixed[mid[cos_turn < np.cos(np.radians(float(feature_deg))) - 1e-12]] = True
    fixed[(parts_at > 1) & ~(_sliding_shared(key, common, uc[ui] == 1, cdeg, parts_at)
                             & bool(slide_shared))] = True

    # plane quadrics of the original faces, area weighted, accumulated per vertex
    d = -np.einsum("ij,ij->i", n_origin, V[F[:, 0]])
    nx, ny, nz = n_origin[:, 0], n_origin[:, 1], n_origin[:, 2]
    q = np.stack([nx * nx, ny * ny, nz * nz, nx * ny, nx * nz, ny * nz, nx * d, ny * d, nz * d,
                  d * d], 1) * face_area[:, None]
    Q = np.zeros((n_vert, 10))
    area = np.zeros(n_vert)
    for k in range(3):
        np.add.at(Q, F[:, k], q)
        np.add.at(area, F[:, k], face_area)

    alive = np.ones(m, np.bool_)
    orig_tol = tol_of_label[part_index]
    orig_depth = certification_depths(orig, orig_tol, max_depth)
    cos_max = float(np.cos(np.radians(float(max_normal_deg))))
    sup, sup_n, collapses, rejected, n_passes = _decimate(
        V, F, fpart, alive, n_origin, orig, orig_tol, orig_face, fixed, ckeys, cdeg, Q, area,
        cos_max, orig_depth, int(passes))
    kept_bounds = _final_bounds(V, F, orig, orig_tol, sup, sup_n, orig_depth)

    bounds = np.full(k_in, np.nan)
    bounds[keep] = kept_bounds
    out_faces = np.flatnonzero(alive)
    out = np.ascontiguousarray(F[out_faces], np.int32)
    n_used = len(np.unique(out))
    return Decimation(
        triangles=out,
        parts=np.ascontiguousarray(fpart[out_faces]),
        part_labels=labels.astype(np.int32),
        tol_abs=tol_of_label,
        collapses=int(collapses),
        rejected={name: int(c) for name, c in zip(REJECT_REASONS, rejected)},
        seconds=time.perf_counter() - start,
        bounds=bounds,
        certified_max=float(np.nanmax(bounds)),
        bytes_saved=int(n_used * 3 * v_in.itemsize),
        input_triangles=k_in,
        passes=int(n_passes),
        dropped=int(repeated.sum()),
        notes=notes,
    )
