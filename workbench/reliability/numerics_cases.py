"""Seeded adversarial inputs of the numerical stress suite's geometric checks
(:mod:`workbench.reliability.numerics`): point–triangle queries, multi-part shell models,
pairs of surfaces whose Hausdorff distance is known exactly, and meshes to decimate.

Every generator takes a :class:`numpy.random.Generator` (the suite's
:func:`~workbench.reliability.numerics.case_rng`) and is deterministic in it. Lengths are model
units; ε (a corner's distance from an edge or another corner, as a share of the triangle's
size) is drawn log-uniformly from 1e-15 to 1e-2; far offsets are integers (dyadic) of 1e3 to
1e7. Where an exact answer must survive a construction — a child triangle lying exactly in its
parent's plane, a surface moved by an offset — the coordinates are dyadic (integers times powers
of two) with few enough bits that every sum is exact, and the generator verifies it with exact
arithmetic (:func:`exact_sum`, :func:`~workbench.reliability.exact.exact_point_triangle_sq`),
retrying with coarser values where a sum would round.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .exact import exact_point_triangle_sq

EPS_RANGE = (1e-15, 1e-2)
OFFSET_RANGE = (1e3, 1e7)
DISTANCE_KINDS = ("sliver", "needle", "collinear", "repeated", "fan", "far sliver",
                  "far needle", "random")
QUERIES_PER_CASE = 8
FAN_TRIANGLES = 1000


# --------------------------------------------------------------------------- helpers
def case_rng(seed: int, key: str, index: int) -> np.random.Generator:
    """The random generator of case ``index`` of generator ``key`` under ``seed``:
    ``numpy.random.default_rng([seed, crc32(key), index])``."""
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, zlib.crc32(key.encode()), int(index)])


def log_uniform(rng, lo: float, hi: float) -> float:
    """A number drawn log-uniformly from [lo, hi] (both > 0)."""
    return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))


def rotation(rng) -> np.ndarray:
    """A random (3, 3) rotation (Haar-distributed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def unit(rng) -> np.ndarray:
    """A random unit vector."""
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def dyadic_offset(rng, lo: float = OFFSET_RANGE[0], hi: float = OFFSET_RANGE[1]) -> np.ndarray:
    """(3,) an offset whose components are integers of magnitude log-uniform in [lo, hi], of
    random sign: exact in float64 and dyadic."""
    return np.array([float(np.rint(log_uniform(rng, lo, hi))) * rng.choice((-1.0, 1.0))
                     for _ in range(3)])


def fit_to_offset(points: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """``points`` rounded to the multiples of the power of two at which ``points + offset`` is
    exact in float64 (so that the moved points are the same geometry, exactly)."""
    top = float(np.abs(points).max() + np.abs(offset).max())
    bits = 51 - math.frexp(top)[1]
    return np.ldexp(np.rint(np.ldexp(points, bits)), -bits)


def exact_sum(points: np.ndarray, offset: np.ndarray) -> bool:
    """Whether ``points + offset`` is exact in float64 for every coordinate."""
    moved = points + offset
    return bool(((moved - offset) == points).all() and ((moved - points) == offset).all())


# --------------------------------------------------------------------------- a. queries
def _standard_queries(rng, tri, size, eps, normal, thin, edge) -> np.ndarray:
    """(8, 3) query points for triangle ``tri`` (3, 3) of size ``size``: on its plane, just
    off it, near its thin corner ``thin``, along the edge ``edge`` (two corner indices) at the
    scale of ``eps``, well off the plane, far, near a corner, exactly a corner or an edge's
    midpoint."""
    def bary():
        w = rng.uniform(-0.25, 1.25, 3)
        return (w / w.sum()) @ tri if abs(w.sum()) > 0.1 else tri.mean(axis=0)

    i, j = edge
    sign = rng.choice((-1.0, 1.0))
    pts = [bary(),
           bary() + normal * size * sign * 10.0 ** rng.uniform(-16, -1),
           tri[thin] + size * 10.0 ** rng.uniform(-16, 0) * unit(rng),
           tri[i] + rng.uniform(-0.2, 1.2) * (tri[j] - tri[i])
           + eps * size * 10.0 ** rng.uniform(-2, 2) * unit(rng),
           bary() + normal * size * rng.uniform(0.1, 2.0),
           tri.mean(axis=0) + size * 10.0 ** rng.uniform(0, 3) * unit(rng),
           tri[rng.integers(3)] + size * 10.0 ** rng.uniform(-16, -3) * unit(rng),
           tri[rng.integers(3)] if rng.random() < 0.5 else 0.5 * (tri[i] + tri[j])]
    return np.array(pts)


def _thin_triangle(rng, kind: str):
    """(tri (3, 3) in a local frame, size, eps, thin corner, nearby edge) of a sliver (a
    corner eps·size from the opposite edge) or a needle (a corner eps·size from another)."""
    size = 2.0 ** rng.uniform(-4, 4)
    eps = log_uniform(rng, *EPS_RANGE)
    a, b = np.zeros(3), np.array([size, 0.0, 0.0])
    if kind == "sliver":
        c = np.array([rng.uniform(-0.3, 1.3) * size, eps * size, 0.0])
        return np.array([a, b, c]), size, eps, 2, (0, 1)
    c = b + eps * size * unit(rng)
    return np.array([a, b, c]), size, eps, 2, (1, 2)


def distance_case(kind: str, rng) -> tuple[str, np.ndarray]:
    """(label, (8, 4, 3) queries): each row a point p and a triangle a, b, c, for generator
    ``kind`` (one of :data:`DISTANCE_KINDS`)."""
    if kind not in DISTANCE_KINDS:
        raise ValueError(f"distance generator must be one of {DISTANCE_KINDS}, got {kind!r}")
    if kind in ("sliver", "needle", "far sliver", "far needle"):
        local, size, eps, thin, edge = _thin_triangle(rng, kind.split()[-1])
        q = rotation(rng)
        tri = local @ q.T + (0.0 if kind.startswith("far") else rng.normal(size=3) * size)
        points = _standard_queries(rng, tri, size, eps, q[:, 2], thin, edge)
        label = f"eps {eps:.1e}"
        if kind.startswith("far"):
            offset = dyadic_offset(rng)
            both = fit_to_offset(np.concatenate([tri, points]), offset)
            if not exact_sum(both, offset):  # pragma: no cover - fit_to_offset makes it exact
                raise AssertionError("offset not exact")
            tri, points = both[:3] + offset, both[3:] + offset
            label += f", offset {np.abs(offset).max():.0e}"
        return label, np.array([[p, *tri] for p in points])
    if kind == "collinear":
        scale = 2.0 ** -int(rng.integers(0, 20))
        base = rng.integers(-64, 64, 3).astype(float)
        d = rng.integers(-8, 9, 3).astype(float)
        d[rng.integers(3)] = float(rng.integers(1, 9))
        k = float(rng.integers(-4, 13))
        tri = np.array([base, base + 8 * d, base + k * d]) * scale
        perm = rng.permutation(3)
        normal = np.cross(d, unit(rng))
        normal /= np.linalg.norm(normal)
        size = float(np.linalg.norm(8 * d) * scale)
        points = _standard_queries(rng, tri, size, 1e-3, normal, 2, (0, 1))
        return f"k {k:g}", np.array([[p, *tri[perm]] for p in points])
    if kind == "repeated":
        size = 2.0 ** rng.uniform(-4, 4)
        a, b = rng.normal(size=3) * size, rng.normal(size=3) * size
        mode = int(rng.integers(4))
        tri = [np.array([a, b, a]), np.array([a, b, b]), np.array([a, a, b]),
               np.array([a, a, a])][mode][rng.permutation(3)]
        points = _standard_queries(rng, tri, size, 1e-3, unit(rng), 0, (0, 1))
        return ["c = a", "c = b", "b = a", "a = b = c"][mode], np.array([[p, *tri]
                                                                          for p in points])
    if kind == "fan":
        return _fan_case(rng)
    size = 2.0 ** rng.uniform(-4, 4)
    tri = rng.normal(size=(3, 3)) * size
    normal = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    normal /= np.linalg.norm(normal)
    return "well shaped", np.array([[p, *tri] for p in _standard_queries(
        rng, tri, size, 1e-3, normal, 2, (0, 1))])


def fan_ring(rng, count: int = FAN_TRIANGLES) -> np.ndarray:
    """(count,) increasing angles in [0, 2π) of the outer corners of a closed fan of ``count``
    thin triangles, jittered by up to a third of a step."""
    step = 2.0 * math.pi / count
    return np.arange(count) * step + rng.uniform(-step / 3, step / 3, count)


def _fan_case(rng) -> tuple[str, np.ndarray]:
    """8 queries near the apex of a closed fan of 1 000 thin triangles in a random plane, each
    against another triangle of the fan."""
    size = 2.0 ** rng.uniform(-4, 4)
    q = rotation(rng)
    apex = rng.normal(size=3) * size
    theta = fan_ring(rng)
    ring = apex + size * (np.cos(theta)[:, None] * q[:, 0] + np.sin(theta)[:, None] * q[:, 1])
    rows = []
    for k in range(QUERIES_PER_CASE):
        i = int(rng.integers(FAN_TRIANGLES))
        tri = np.array([apex, ring[i], ring[(i + 1) % FAN_TRIANGLES]])
        r = size * 10.0 ** rng.uniform(-16, -1)
        p = [apex + r * unit(rng), apex + rng.uniform(-0.1, 1.1) * (tri[1] - apex)
             + r * q[:, 2], apex + r * (q[:, 2] * rng.choice((-1, 1)) + 1e-3 * unit(rng)),
             apex + r * (np.cos(theta[i] + math.pi) * q[:, 0]
                         + np.sin(theta[i] + math.pi) * q[:, 1])][k % 4]
        rows.append([p, *tri])
    return "1000 triangles", np.array(rows)


# --------------------------------------------------------------------------- meshes
def grid(nx: int, ny: int, cell: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(nodes (N, 3) at z = 0, quads (M, 4)) of an nx × ny grid of square cells, counter-
    clockwise seen from +z, node (i, j) at index j·(nx + 1) + i."""
    i, j = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1))
    nodes = np.c_[i.ravel() * cell, j.ravel() * cell, np.zeros(i.size)].astype(np.float64)
    a = (np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)[None, :]).ravel()
    return nodes, np.stack([a, a + 1, a + nx + 2, a + nx + 1], axis=1)


def split_quads(rng, quads: np.ndarray) -> np.ndarray:
    """(2M, 3) triangles of the quads, each cut along a random diagonal, wound as the quad."""
    flip = rng.random(len(quads)) < 0.5
    one = np.where(flip[:, None], quads[:, [0, 1, 2]], quads[:, [0, 1, 3]])
    two = np.where(flip[:, None], quads[:, [0, 2, 3]], quads[:, [1, 2, 3]])
    return np.concatenate([one, two])


def refine_with_slivers(rng, vertices, triangles, share: float = 0.5, max_k: int = 40,
                        min_k: int = 7):
    """(vertices, triangles, smallest ε reached): ``share`` of the triangles split into children
    that lie exactly in the parent's plane and cover it exactly once: at an interior point
    2^-k of the way from an edge (three children, one a sliver) or at a point 2^-k along an edge
    (two children, one a needle), k from ``min_k`` to ``max_k``. A point whose float64 value is
    not the exact point is retried with a smaller k (and dropped below ``min_k``)."""
    v = [np.asarray(x, np.float64) for x in vertices]
    out, smallest = [], 1.0
    for t in np.asarray(triangles):
        if rng.random() >= share:
            out.append(t)
            continue
        a, b, c = (v[int(x)] for x in t)
        k = int(rng.integers(min_k, max_k + 1))
        interior = rng.random() < 0.6
        s = Fraction(int(rng.integers(1, 256)), 256)
        while k >= min_k:
            w = Fraction(1, 2 ** k)
            if interior:  # p = a + s(b − a) + w(c − a)
                exact = [Fraction(a[i]) + s * (Fraction(b[i]) - Fraction(a[i]))
                         + w * (Fraction(c[i]) - Fraction(a[i])) for i in range(3)]
            else:  # p = a + w(b − a)
                exact = [Fraction(a[i]) + w * (Fraction(b[i]) - Fraction(a[i])) for i in range(3)]
            p = np.array([float(x) for x in exact])
            if all(Fraction(p[i]) == exact[i] for i in range(3)) and \
                    exact_point_triangle_sq(p, a, b, c) == 0:
                break
            k -= 4
        if k < min_k:
            out.append(t)
            continue
        v.append(p)
        n = len(v) - 1
        if interior:
            out += [[t[0], t[1], n], [t[1], t[2], n], [t[2], t[0], n]]
        else:
            out += [[t[0], n, t[2]], [n, t[1], t[2]]]
        smallest = min(smallest, 2.0 ** -k)
    return np.array(v), np.array(out, np.int64), smallest


def dyadic_surface(rng, flat: bool, cell_bits: int = 0):
    """(vertices, triangles) of a grid of 2–5 × 2–5 square cells of side 2^cell_bits, each
    cut along a random diagonal; heights integer multiples of the cell (0 where ``flat``)."""
    nx, ny = (int(x) for x in rng.integers(2, 6, 2))
    nodes, quads = grid(nx, ny, 2.0 ** cell_bits)
    if not flat:
        nodes[:, 2] = rng.integers(-2, 3, len(nodes)) * 2.0 ** cell_bits
    return nodes, split_quads(rng, quads)


def permute_axes(rng, *vertex_arrays):
    """The arrays with the same random permutation and sign flips of the axes (exact)."""
    perm, signs = rng.permutation(3), rng.choice((-1.0, 1.0), 3)
    return [np.ascontiguousarray(v[:, perm] * signs) for v in vertex_arrays]


# --------------------------------------------------------------------------- c. pairs
HAUSDORFF_KINDS = ("refinement", "moved vertex", "parallel sheets", "sliver sheets",
                   "far offset")


@dataclass
class SurfacePair:
    """Surfaces A (``va``, ``fa``) and B (``vb``, ``fb``) with the exact one-sided Hausdorff
    distances as intervals of squares: ``forward`` (A → B) and ``backward`` (B → A), each
    (lo², hi²) Fractions (equal where the value is known exactly); ``label`` what was drawn."""

    va: np.ndarray
    fa: np.ndarray
    vb: np.ndarray
    fb: np.ndarray
    forward: tuple[Fraction, Fraction]
    backward: tuple[Fraction, Fraction]
    label: str


def surface_pair(kind: str, rng, max_k: int = 40) -> SurfacePair:
    """A :class:`SurfacePair` of generator ``kind`` (one of :data:`HAUSDORFF_KINDS`): a surface
    against a refinement of itself with sliver and needle children (exact 0 both ways); a flat
    sheet against itself with one interior vertex moved by d along the normal (B → A exactly d,
    the apex; A → B between the exact distance of the vertex's old place and d, since B is a
    graph over A no higher than d); two parallel sheets d apart, triangulated differently
    (exact d both ways); the same with sliver refinements; and one of these moved by an integer
    offset of 1e3–1e6 (exact sums, checked)."""
    if kind not in HAUSDORFF_KINDS:
        raise ValueError(f"Hausdorff generator must be one of {HAUSDORFF_KINDS}, got {kind!r}")
    if kind == "far offset":
        offset = dyadic_offset(rng, 1e3, 1e6)
        for k in (20, 14, 8):
            inner = HAUSDORFF_KINDS[int(rng.integers(4))]
            pair = surface_pair(inner, rng, max_k=k)
            if exact_sum(pair.va, offset) and exact_sum(pair.vb, offset):
                pair.va, pair.vb = pair.va + offset, pair.vb + offset
                pair.label = f"{inner}, {pair.label}, offset {np.abs(offset).max():.0e}"
                return pair
        raise AssertionError("no exact offset found")  # pragma: no cover
    zero = (Fraction(0), Fraction(0))
    if kind == "refinement":
        va, fa = dyadic_surface(rng, flat=False, cell_bits=int(rng.integers(-3, 4)))
        vb, fb, eps = refine_with_slivers(rng, va, fa, 0.7, max_k)
        va, vb = permute_axes(rng, va, vb)
        return SurfacePair(va, fa, vb, fb, zero, zero, f"eps {eps:.1e}")
    cell_bits = int(rng.integers(-3, 4))
    cell = 2.0 ** cell_bits
    d = cell * 2.0 ** -int(rng.integers(-1, min(max_k, 40) + 1))
    d_sq = Fraction(d) ** 2
    if kind == "moved vertex":
        nx, ny = (int(x) for x in rng.integers(3, 6, 2))
        va, quads = grid(nx, ny, cell)
        fa = split_quads(rng, quads)
        i, j = int(rng.integers(1, nx)), int(rng.integers(1, ny))
        apex = j * (nx + 1) + i
        vb = va.copy()
        vb[apex, 2] = d
        near = exact_point_sq(va[apex], vb[fa])
        va, vb = permute_axes(rng, va, vb)
        return SurfacePair(va, fa, vb, fa, (near, d_sq), (d_sq, d_sq), f"d {d:.1e}")
    nx, ny = (int(x) for x in rng.integers(2, 6, 2))
    va, quads = grid(nx, ny, cell)
    fa = split_quads(rng, quads)
    mx, my = (int(x) for x in rng.choice((1, 2, 4), 2))
    vb, quads_b = grid(mx, my, 1.0)
    vb[:, 0] *= nx * cell / mx  # the same rectangle in other cells (a power of two: exact)
    vb[:, 1] *= ny * cell / my
    fb = split_quads(rng, quads_b)
    eps = 1.0
    if kind == "sliver sheets":
        va, fa, e1 = refine_with_slivers(rng, va, fa, 0.7, max_k)
        vb, fb, e2 = refine_with_slivers(rng, vb, fb, 0.7, max_k)
        eps = min(e1, e2)
    vb[:, 2] = d
    va, vb = permute_axes(rng, va, vb)
    label = f"d {d:.1e}" + (f", eps {eps:.1e}" if kind == "sliver sheets" else "")
    return SurfacePair(va, fa, vb, fb, (d_sq, d_sq), (d_sq, d_sq), label)


def exact_point_sq(point, corners) -> Fraction:
    """The exact squared distance from ``point`` (three floats or Fractions) to the union of
    the triangles ``corners`` (T, 3, 3), pruned by their bounding boxes: a box's distance is a
    lower bound of the triangle's, so a triangle whose box lies farther than the nearest exact
    distance found (with a relative 1e-9 and an absolute 1e-12 of the coordinates to spare for
    the rounding of the float boxes) is not evaluated."""
    pf = np.array([float(x) for x in point])
    corners = np.asarray(corners, np.float64)
    lo, hi = corners.min(axis=1), corners.max(axis=1)
    gap = np.sqrt((np.maximum(np.maximum(lo - pf, pf - hi), 0.0) ** 2).sum(axis=1))
    slack = 1e-12 * float(max(np.abs(corners).max(), np.abs(pf).max()))
    order = np.argsort(gap, kind="stable")
    best = exact_point_triangle_sq(point, *corners[order[0]])
    reach = math.sqrt(float(best)) * (1 + 1e-9) + slack
    for f in order[1:]:
        if gap[f] > reach:
            break
        s = exact_point_triangle_sq(point, *corners[f])
        if s < best:
            best = s
            reach = math.sqrt(float(best)) * (1 + 1e-9) + slack
    return best


# --------------------------------------------------------------------------- b. part models
PART_KINDS = ("near-coincident", "touching", "slivers", "collapsed", "far offset")


def part_mesh(kind: str, rng):
    """(FEMesh, cutoff, label): a shell model of two or three parts for generator ``kind`` (one
    of :data:`PART_KINDS`): a grid sheet and a rotated sheet ε·L above it (ε from 1e-15 to
    1e-2); a sheet touched along a line by a perpendicular sheet and at a node by a third part
    sharing it; both sheets refined with sliver and needle triangles; collapsed quads (a
    repeated node), zero-area triangles (a node on the middle of an edge) and duplicate nodes;
    and one of these moved by an integer offset of 1e3–1e7. ``cutoff`` (model units) is drawn
    so that some nodes lie beyond it."""
    from ..scene.mesh import FEMesh

    if kind not in PART_KINDS:
        raise ValueError(f"part generator must be one of {PART_KINDS}, got {kind!r}")
    if kind == "far offset":
        inner = PART_KINDS[int(rng.integers(4))]
        mesh, cutoff, label = part_mesh(inner, rng)
        offset = dyadic_offset(rng)
        nodes = fit_to_offset(mesh.nodes, offset) + offset
        return (FEMesh(nodes=nodes, elements=mesh.elements, parts=mesh.parts), cutoff,
                f"{inner}, {label}, offset {np.abs(offset).max():.0e}")
    n = int(rng.integers(3, 6))
    length = float(n)
    eps = log_uniform(rng, *EPS_RANGE)
    nodes, quads = grid(n, n)
    elements, parts = [quads], [np.full(len(quads), 1)]
    node_sets = [nodes]

    def add(new_nodes, new_elements, part):
        base = sum(len(x) for x in node_sets)
        node_sets.append(np.asarray(new_nodes, np.float64))
        elements.append(np.asarray(new_elements) + base)
        parts.append(np.full(len(new_elements), part))

    if kind in ("near-coincident", "collapsed"):
        m = n - 1
        other, q2 = grid(m, m)
        angle = rng.uniform(0, 2 * math.pi)
        rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        other[:, :2] = (other[:, :2] - m / 2) @ rot.T + n / 2
        other[:, 2] = eps * length
        add(other, q2, 2)
    if kind == "touching":
        x = float(rng.integers(1, n))
        wall = np.array([[x, 0.5, 0.0], [x, n - 0.5, 0.0], [x, n - 0.5, 1.0], [x, 0.5, 1.0]])
        add(wall, [[0, 1, 2, 3]], 2)
        corner = int(rng.integers(len(nodes)))  # a third part sharing one node of the first
        base = sum(len(s) for s in node_sets)
        node_sets.append(np.array([nodes[corner] + [0.0, 0.0, 1.0],
                                   nodes[corner] + [0.5, 0.25, 1.0]]))
        elements.append(np.array([[corner, base, base + 1, base + 1]]))
        parts.append(np.array([3]))
    if kind == "slivers":
        v1, t1 = nodes, split_quads(rng, quads)
        v1, t1, e1 = refine_with_slivers(rng, v1, t1, 0.6, 45)
        node_sets[0], elements[0] = v1, np.c_[t1, t1[:, 2]]
        parts[0] = np.full(len(t1), 1)
        v2, t2, e2 = refine_with_slivers(rng, *grid(n - 1, n - 1)[:1],
                                         split_quads(rng, grid(n - 1, n - 1)[1]), 0.6, 45)
        v2 = v2 + [0.5, 0.5, eps * length]
        add(v2, np.c_[t2, t2[:, 2]], 2)
        eps = min(eps, e1, e2)
    if kind == "collapsed":
        q = elements[0].copy()
        pick = rng.choice(len(q), size=max(1, len(q) // 4), replace=False)
        q[pick[::2], 2] = q[pick[::2], 1]  # a repeated node: a triangle or less
        q[pick[1::2], 3] = q[pick[1::2], 1]  # a node at opposite corners: no triangle
        elements[0] = q
        a, b = nodes[0], nodes[1]
        add([a, b, 0.5 * (a + b)], [[0, 1, 2, 2]], 1)  # zero area, on the sheet's edge
        add([nodes[n + 2], nodes[n + 3], nodes[2 * n + 3]], [[0, 1, 2, 2]], 2)  # duplicates
    mesh = FEMesh(nodes=np.concatenate(node_sets),
                  elements=np.concatenate([np.asarray(e, np.int64) for e in elements]),
                  parts=np.concatenate(parts))
    cutoff = length * rng.uniform(0.05, 0.6)
    return mesh, cutoff, f"eps {eps:.1e}, cutoff {cutoff:.2g}"


# --------------------------------------------------------------------------- d. decimation
SIMPLIFY_KINDS = ("noisy sheet", "slivers", "far offset")


def simplify_mesh(kind: str, rng):
    """(vertices, triangles, tol, label) to decimate with a relative ``tol``, for generator
    ``kind`` (one of :data:`SIMPLIFY_KINDS`): a 6–9 cell square grid with dyadic height noise
    of 2^-8 to 2^-3 of a cell; a dyadic surface (folded or flat) refined with sliver and needle
    children; a noisy sheet moved by an integer offset of 1e3–1e7 (exact)."""
    if kind not in SIMPLIFY_KINDS:
        raise ValueError(f"simplifier generator must be one of {SIMPLIFY_KINDS}, got {kind!r}")
    tol = float(rng.uniform(0.004, 0.03))
    if kind == "slivers":
        v, t = dyadic_surface(rng, flat=rng.random() < 0.5)
        v, t, eps = refine_with_slivers(rng, v, t, 0.7, 45)
        return v, t, tol, f"eps {eps:.1e}, tol {tol:.3f}"
    n = int(rng.integers(6, 10))
    v, quads = grid(n, n)
    amp = 2.0 ** rng.uniform(-8, -3)
    v[:, 2] = np.ldexp(np.rint(np.ldexp(rng.normal(size=len(v)) * amp, 30)), -30)
    t = split_quads(rng, quads)
    label = f"noise {amp:.1e}, tol {tol:.3f}"
    if kind == "far offset":
        offset = dyadic_offset(rng)
        v = fit_to_offset(v, offset) + offset
        label += f", offset {np.abs(offset).max():.0e}"
    return v, t, tol, label
