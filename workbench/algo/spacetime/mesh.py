"""Simplicial spacetime meshes for st2005 (§3.2): space meshes, red-green refinement and tent
pitching.

A spacetime mesh covers space × [t_start, t_end] with simplices: triangles in (x, t) for a 1-D
space domain (a bar), tetrahedra in (x, y, t) for a 2-D one. It is built the way the paper's
*Tent Pitcher* builds it, in spirit (Üngör & Sheffer): an advancing front τ(v) over the vertices
of a space mesh; a vertex that is a local minimum of the front is lifted forward in time as far
as a causality limit allows, and every space simplex around it sweeps one spacetime simplex (a
"tent" pole). `front_refined` adds what the paper's Fig. 2 shows: the space mesh is refined near
a moving wave front band by band in time, so the spacetime mesh is **non-conforming** on the
band boundaries (faces below and above a boundary need not match).

Coordinates are in the caller's length unit, times in the caller's time unit, wave speeds in
length per time. Everything is float64 numpy; nothing here knows of OpenGL.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = [
    "SpacetimeMesh",
    "rect_triangulation",
    "interval_mesh",
    "refine",
    "tent_pitch",
    "front_refined",
    "spacetime_volume",
    "space_measure",
]


# --------------------------------------------------------------------------- the mesh
@dataclass(frozen=True, eq=False)
class SpacetimeMesh:
    """A simplicial decomposition of space × time, not necessarily conforming.

    points: (P, D+1) float64, the D spatial coordinates then the time t (last column).
    simplices: (M, D+2) int32 indices into `points`: triangles for D = 1, tetrahedra for D = 2.
    Every simplex must have non-zero spacetime volume (the paper's only assumption, §4.1);
    a degenerate one, an index out of range or a D other than 1 or 2 is refused (ValueError).
    Both arrays are stored read-only so the cached per-simplex time bounds stay valid.
    """

    points: np.ndarray
    simplices: np.ndarray

    def __post_init__(self):
        pts = np.array(self.points, dtype=np.float64, order="C")
        sim = np.array(self.simplices, order="C")
        if pts.ndim != 2 or pts.shape[1] not in (2, 3):
            raise ValueError(f"points must be (P, D+1) with D = 1 or 2, got shape {pts.shape}")
        if not np.all(np.isfinite(pts)):
            raise ValueError("points contain NaN or infinity")
        if sim.ndim != 2 or sim.shape[1] != pts.shape[1] + 1:
            raise ValueError(f"simplices must be (M, {pts.shape[1] + 1}) for points of shape "
                             f"{pts.shape}, got {sim.shape}")
        if sim.size and not np.issubdtype(sim.dtype, np.integer):
            raise ValueError(f"simplices must be integer indices, got {sim.dtype}")
        sim = sim.astype(np.int32)
        if sim.size and (sim.min() < 0 or sim.max() >= len(pts)):
            raise ValueError("simplex index out of range of points")
        pts.setflags(write=False)
        sim.setflags(write=False)
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "simplices", sim)
        if sim.size and np.any(_signed_measure(pts, sim) == 0.0):
            raise ValueError("a simplex has zero spacetime volume")

    @property
    def dim(self) -> int:
        """D, the number of spatial dimensions (1 or 2)."""
        return self.points.shape[1] - 1

    @property
    def n_simplices(self) -> int:
        return len(self.simplices)

    @cached_property
    def tmin(self) -> np.ndarray:
        """(M,) the earliest time among each simplex's vertices."""
        out = self.points[:, -1][self.simplices].min(axis=1)
        out.setflags(write=False)
        return out

    @cached_property
    def tmax(self) -> np.ndarray:
        """(M,) the latest time among each simplex's vertices."""
        out = self.points[:, -1][self.simplices].max(axis=1)
        out.setflags(write=False)
        return out

    @cached_property
    def shared_facets(self) -> np.ndarray:
        """(M, D+2) bool: whether the facet opposite vertex i of simplex m (its other D+1
        vertices) is a facet of another simplex too. A facet no other simplex has lies on the
        boundary of the spacetime domain (the spatial boundary, the first and last fronts) or
        on a non-conforming interface."""
        sim = self.simplices.astype(np.int64)
        M, k = sim.shape
        facets = np.sort(np.stack([np.delete(sim, i, axis=1) for i in range(k)], axis=1), axis=2)
        flat = facets.reshape(-1, k - 1)
        n = max(len(self.points), 1)
        if float(n) ** (k - 1) < 2.0 ** 62:  # one int64 key per facet sorts fastest
            key = flat[:, 0]
            for j in range(1, k - 1):
                key = key * n + flat[:, j]
            _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
        else:
            _, inverse, counts = np.unique(flat, axis=0, return_inverse=True, return_counts=True)
        out = (counts[inverse.ravel()] > 1).reshape(M, k)
        out.setflags(write=False)
        return out


def _signed_measure(points: np.ndarray, simplices: np.ndarray) -> np.ndarray:
    """Signed volume of d-simplices in d dimensions: det of the edge vectors / d!."""
    p = points[simplices]
    edges = p[:, 1:] - p[:, :1]
    d = points.shape[1]
    if d == 1:
        return edges[:, 0, 0]
    if d == 2:
        return 0.5 * (edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0])
    a, b, c = edges[:, 0], edges[:, 1], edges[:, 2]
    return np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0


def spacetime_volume(mesh: SpacetimeMesh) -> np.ndarray:
    """(M,) unsigned spacetime volumes (areas in (x, t) for D = 1), in length^D × time."""
    return np.abs(_signed_measure(mesh.points, mesh.simplices))


def space_measure(points: np.ndarray, simplices: np.ndarray) -> np.ndarray:
    """(K,) signed lengths (D = 1) or areas (D = 2) of space simplices; CCW triangles are > 0."""
    points = np.asarray(points, dtype=np.float64)
    return _signed_measure(points, np.asarray(simplices))


# --------------------------------------------------------------------------- space meshes
def rect_triangulation(nx: int, ny: int, size=(1.0, 1.0), origin=(0.0, 0.0),
                       jitter: float = 0.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A structured triangulation of the rectangle origin + [0, size_x] × [0, size_y].

    nx × ny cells, each split into two counter-clockwise triangles along a diagonal whose
    direction alternates in a checkerboard (no directional bias). Interior nodes move by a
    random offset of at most `jitter` cell sizes (uniform in a disc, scaled per axis); boundary
    nodes move along their side only and the corners stay, so the domain is unchanged.
    `jitter` must lie in [0, 0.35): below that bound no triangle can flip.
    Returns points (N, 2) float64 with N = (nx+1)(ny+1) and triangles (2·nx·ny, 3) int32.
    """
    nx, ny = int(nx), int(ny)
    if nx < 1 or ny < 1:
        raise ValueError(f"need nx, ny >= 1, got {nx}, {ny}")
    sx, sy = (float(v) for v in size)
    if not (sx > 0 and sy > 0):
        raise ValueError(f"size must be positive, got {size}")
    if not 0.0 <= jitter < 0.35:
        raise ValueError(f"jitter must lie in [0, 0.35), got {jitter}")
    dx, dy = sx / nx, sy / ny
    i, j = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="xy")
    i, j = i.ravel(), j.ravel()
    offset = np.zeros((len(i), 2))
    if jitter > 0:
        rng = np.random.default_rng(seed)
        ang = rng.uniform(0.0, 2 * np.pi, len(i))
        rad = jitter * np.sqrt(rng.uniform(0.0, 1.0, len(i)))
        offset = np.c_[rad * np.cos(ang), rad * np.sin(ang)]
        offset[(i == 0) | (i == nx), 0] = 0.0
        offset[(j == 0) | (j == ny), 1] = 0.0
    points = np.c_[origin[0] + (i + offset[:, 0]) * dx, origin[1] + (j + offset[:, 1]) * dy]
    # exact boundary coordinates (no rounding drift from i*dx)
    points[i == nx, 0] = origin[0] + sx
    points[j == ny, 1] = origin[1] + sy

    ci, cj = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    ci, cj = ci.ravel(), cj.ravel()
    n00 = ci + cj * (nx + 1)
    n10, n01, n11 = n00 + 1, n00 + nx + 1, n00 + nx + 2
    even = (ci + cj) % 2 == 0
    t1 = np.where(even[:, None], np.c_[n00, n10, n11], np.c_[n00, n10, n01])
    t2 = np.where(even[:, None], np.c_[n00, n11, n01], np.c_[n10, n11, n01])
    triangles = np.concatenate([t1, t2]).astype(np.int32)
    if np.any(space_measure(points, triangles) <= 0):  # guarded by the jitter bound
        raise AssertionError("jittered triangulation has a flipped triangle")
    return points, triangles


def interval_mesh(n: int, length: float = 1.0, origin: float = 0.0, jitter: float = 0.0,
                  seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The interval [origin, origin + length] in n segments; interior nodes move by at most
    `jitter` (in [0, 0.5)) segment lengths. Returns points (n+1, 1) float64, segments (n, 2)
    int32 oriented left to right."""
    n = int(n)
    if n < 1:
        raise ValueError(f"need n >= 1, got {n}")
    if not length > 0:
        raise ValueError(f"length must be positive, got {length}")
    if not 0.0 <= jitter < 0.5:
        raise ValueError(f"jitter must lie in [0, 0.5), got {jitter}")
    h = length / n
    x = np.arange(n + 1, dtype=np.float64)
    if jitter > 0:
        x[1:-1] += np.random.default_rng(seed).uniform(-jitter, jitter, n - 1)
    points = (origin + x * h)[:, None]
    points[-1, 0] = origin + length
    segments = np.c_[np.arange(n), np.arange(1, n + 1)].astype(np.int32)
    return points, segments


# --------------------------------------------------------------------------- refinement
def _unique_edges(simplices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges (E, 2) with lo < hi, and for each triangle its 3 edge ids (K, 3):
    edge k of triangle (a, b, c) is (a, b), (b, c), (c, a) for k = 0, 1, 2."""
    tri = simplices
    pairs = np.stack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]], axis=1).reshape(-1, 2)
    pairs = np.sort(pairs, axis=1).astype(np.int64)
    n = int(tri.max()) + 1 if tri.size else 1
    key = pairs[:, 0] * n + pairs[:, 1]
    ukey, inv = np.unique(key, return_inverse=True)
    edges = np.c_[ukey // n, ukey % n]
    return edges, inv.reshape(-1, 3)


def refine(points, simplices, mask) -> tuple[np.ndarray, np.ndarray]:
    """Conforming refinement of the space simplices selected by the boolean `mask`.

    Triangles (D = 2): red refinement (quadrisection through the edge midpoints) of the marked
    triangles, then closure: a triangle with two or more split edges becomes red too (repeated
    until stable), one with exactly one split edge is bisected (green) from the opposite
    vertex. Midpoints are shared between neighbours, so the result is conforming and covers
    exactly the same area. Segments (D = 1): marked segments are split at their midpoints.
    Existing points keep their indices (new midpoints are appended); orientation is kept.
    Returns (points, simplices int32). Refuses a mask of the wrong length.
    """
    points = np.asarray(points, dtype=np.float64)
    simplices = np.asarray(simplices)
    mask = np.asarray(mask, dtype=bool)
    if mask.shape != (len(simplices),):
        raise ValueError(f"mask must have shape ({len(simplices)},), got {mask.shape}")
    if (simplices.ndim != 2 or simplices.shape[1] not in (2, 3)
            or points.shape[1] != simplices.shape[1] - 1):
        raise ValueError("refine takes segments (K, 2) over (N, 1) points or triangles (K, 3) "
                         f"over (N, 2) points; got {simplices.shape} over {points.shape}")
    if simplices.shape[1] == 2:
        seg = simplices[mask]
        mid = len(points) + np.arange(len(seg))
        new_pts = 0.5 * (points[seg[:, 0]] + points[seg[:, 1]])
        out = np.concatenate([simplices[~mask], np.c_[seg[:, 0], mid], np.c_[mid, seg[:, 1]]])
        return np.concatenate([points, new_pts]), out.astype(np.int32)

    edges, tri_edges = _unique_edges(simplices)
    split = np.zeros(len(edges), dtype=bool)
    split[tri_edges[mask].ravel()] = True
    while True:
        count = split[tri_edges].sum(axis=1)
        grow = count == 2
        if not grow.any():
            break
        split[tri_edges[grow].ravel()] = True
    mid_of = np.full(len(edges), -1, dtype=np.int64)
    mid_of[split] = len(points) + np.arange(int(split.sum()))
    new_pts = 0.5 * (points[edges[split, 0]] + points[edges[split, 1]])

    count = split[tri_edges].sum(axis=1)
    keep = simplices[count == 0]
    red = count == 3
    a, b, c = simplices[red].T
    mab, mbc, mca = mid_of[tri_edges[red]].T
    reds = np.concatenate([np.c_[a, mab, mca], np.c_[mab, b, mbc], np.c_[mca, mbc, c],
                           np.c_[mab, mbc, mca]])
    green = count == 1
    tg, eg = simplices[green], tri_edges[green]
    k = np.argmax(split[eg], axis=1)  # which edge: (v_k, v_{k+1})
    rows = np.arange(len(tg))
    p, q, r = tg[rows, k], tg[rows, (k + 1) % 3], tg[rows, (k + 2) % 3]
    m = mid_of[eg[rows, k]]
    greens = np.concatenate([np.c_[r, p, m], np.c_[r, m, q]])
    out = np.concatenate([keep, reds, greens]).astype(np.int32)
    return np.concatenate([points, new_pts]), out


# --------------------------------------------------------------------------- tent pitching
def _validate_space(space_points, space_simplices) -> tuple[np.ndarray, np.ndarray]:
    pts = np.asarray(space_points, dtype=np.float64)
    sim = np.asarray(space_simplices)
    if pts.ndim != 2 or pts.shape[1] not in (1, 2) or len(pts) == 0:
        raise ValueError("space points must be a non-empty (N, D) array with D = 1 or 2, got "
                         f"{pts.shape}")
    if sim.ndim != 2 or sim.shape[1] != pts.shape[1] + 1 or len(sim) == 0:
        raise ValueError(f"space simplices must be a non-empty (K, {pts.shape[1] + 1}) array, "
                         f"got {sim.shape}")
    if not np.issubdtype(sim.dtype, np.integer):
        raise ValueError("space simplices must be integer indices")
    if sim.min() < 0 or sim.max() >= len(pts):
        raise ValueError("space simplex index out of range")
    if not np.all(np.isfinite(pts)):
        raise ValueError("space points contain NaN or infinity")
    vol = space_measure(pts, sim)
    if np.any(vol == 0):
        raise ValueError("a space simplex is degenerate (zero length or area)")
    sim = sim.astype(np.int64)
    flip = vol < 0  # orient CCW / left to right so every spacetime simplex is positive
    if flip.any():
        sim = sim.copy()
        sim[flip, 0], sim[flip, 1] = sim[flip, 1].copy(), sim[flip, 0].copy()
    return pts, sim


def tent_pitch(space_points, space_simplices, t_start: float, t_end: float, wave_speed: float,
               *, safety: float = 0.5, rng_seed: int = 0) -> SpacetimeMesh:
    """Mesh space × [t_start, t_end] by tent pitching over a space mesh (D = 1 or 2).

    The front τ starts flat at t_start. Each round lifts every vertex v that is a local minimum
    of τ among its mesh neighbours (ties broken by a seeded random rank, so the lifted set is
    independent: no two lifted vertices share an edge) and is below t_end, to

        ``τ_new(v) = min(t_end, min_u τ(u) + f_v · safety · |x_v − x_u| / wave_speed)``,

    u over its neighbours, f_v a seeded random factor in [0.8, 1]. Each space simplex s around
    v sweeps the spacetime simplex (s at the front, v at τ_old) + (v at τ_new); v at τ_new is a
    new spacetime point. Rounds end when the front is flat at t_end.

    Guarantee (the causality bound): every spacetime edge that is not purely in time has
    slope ``|Δt| / |Δx| ≤ safety / wave_speed``, since every front edge keeps that bound.
    Spacetime simplices are positively oriented (space simplices are oriented first), so their
    volumes are positive and sum to ``|domain| × (t_end − t_start)``.
    Size (measured on jittered grids): about 2.8·K·c·(t_end − t_start)/(safety·h) tetrahedra
    for K triangles with cell size h, 1.5·K·c·(t_end − t_start)/(safety·h) triangles for K
    segments of length h; e.g. a 100 × 100 grid of the unit square over t ∈ [0, 0.1] with
    c = 1 gives 1.08 M tetrahedra.
    Unreferenced space points are ignored. Refuses t_end <= t_start, wave_speed <= 0,
    safety <= 0, empty or degenerate space meshes (ValueError).
    """
    pts, sim = _validate_space(space_points, space_simplices)
    t_start, t_end = float(t_start), float(t_end)
    if not (np.isfinite(t_start) and np.isfinite(t_end)) or not t_end > t_start:
        raise ValueError(f"need t_end > t_start, got [{t_start}, {t_end}]")
    if not (np.isfinite(wave_speed) and wave_speed > 0):
        raise ValueError(f"wave_speed must be positive, got {wave_speed}")
    if not (np.isfinite(safety) and safety > 0):
        raise ValueError(f"safety must be positive, got {safety}")
    # compact to the referenced vertices
    used, sim = np.unique(sim, return_inverse=True)
    sim = sim.reshape(-1, pts.shape[1] + 1)
    pts = pts[used]
    n, k = len(pts), sim.shape[1]
    rng = np.random.default_rng(rng_seed)
    rank = rng.permutation(n)  # tie-break among equal front times

    # directed edges sorted by source (CSR) and vertex -> simplex incidence
    pairs = np.concatenate([sim[:, [i, j]] for i in range(k) for j in range(k) if i != j])
    key = np.unique(pairs[:, 0] * n + pairs[:, 1])
    src, dst = key // n, key % n
    edge_len = np.linalg.norm(pts[src] - pts[dst], axis=1)
    step = safety * edge_len / wave_speed  # causality limit per directed edge
    nb_start = np.searchsorted(src, np.arange(n))
    nb_start_hi = np.searchsorted(src, np.arange(n), side="right")
    und = src < dst
    ua, ub = src[und], dst[und]
    inc_v = sim.ravel()
    inc_order = np.argsort(inc_v, kind="stable")
    inc_simplex = (inc_order // k)
    inc_start = np.searchsorted(inc_v[inc_order], np.arange(n + 1))

    tau = np.full(n, t_start)
    current = np.arange(n, dtype=np.int64)  # spacetime point of each vertex at its front time
    out_points = [np.c_[pts, tau]]
    out_simplices = []
    n_points = n
    max_rounds = 10_000_000
    for _ in range(max_rounds):
        below = tau < t_end
        if not below.any():
            break
        # local minima by (tau, rank) among neighbours
        a_first = (tau[ua] < tau[ub]) | ((tau[ua] == tau[ub]) & (rank[ua] < rank[ub]))
        is_min = below.copy()
        is_min[ub[a_first]] = False
        is_min[ua[~a_first]] = False
        lift = np.flatnonzero(is_min)
        # tau_new = min over neighbours u of tau_u + f * step_u (reduceat over CSR ranges)
        counts = nb_start_hi[lift] - nb_start[lift]
        first = np.r_[0, np.cumsum(counts)[:-1]]
        idx = np.repeat(nb_start[lift] - first, counts) + np.arange(counts.sum())
        f = rng.uniform(0.8, 1.0, len(lift))
        reach = tau[dst[idx]] + np.repeat(f, counts) * step[idx]
        new_tau = np.minimum(t_end, np.minimum.reduceat(reach, first))
        if np.any(new_tau <= tau[lift]):
            raise ValueError("a lift is below the float resolution of the times; "
                             "shift t_start towards 0 or use a coarser space mesh")
        new_ids = n_points + np.arange(len(lift))
        n_points += len(lift)
        out_points.append(np.c_[pts[lift], new_tau])
        # one spacetime simplex per space simplex in the star of each lifted vertex
        s_counts = inc_start[lift + 1] - inc_start[lift]
        s_first = np.r_[0, np.cumsum(s_counts)[:-1]]
        s_idx = np.repeat(inc_start[lift] - s_first, s_counts) + np.arange(s_counts.sum())
        stars = inc_simplex[s_idx]
        out_simplices.append(np.c_[current[sim[stars]], np.repeat(new_ids, s_counts)])
        tau[lift] = new_tau
        current[lift] = new_ids
    else:  # pragma: no cover - each round lifts the global minimum by a positive amount
        raise RuntimeError("tent pitching did not reach t_end")
    points = np.concatenate(out_points)
    simplices = np.concatenate(out_simplices) if out_simplices else np.zeros((0, k + 1), np.int32)
    return SpacetimeMesh(points, simplices.astype(np.int32))


# --------------------------------------------------------------------------- refined bands
def _element_size(points: np.ndarray, simplices: np.ndarray) -> np.ndarray:
    """(K,) the longest edge of each space simplex."""
    p = points[simplices]
    k = simplices.shape[1]
    return np.max([np.linalg.norm(p[:, i] - p[:, j], axis=1)
                   for i in range(k) for j in range(i + 1, k)], axis=0)


def front_refined(space_points, space_simplices, t_end: float, wave_speed: float, *,
                  front_distance: Callable[[np.ndarray, float], np.ndarray] | None = None,
                  bands: int = 4, width: float = 0.1, levels: int = 1, t_start: float = 0.0,
                  safety: float = 0.5, rng_seed: int = 0) -> SpacetimeMesh:
    """Tent-pitched spacetime mesh refined along a moving wave front, band by band (Fig. 2).

    [t_start, t_end] is split into `bands` equal bands, at np.linspace(t_start, t_end, bands + 1).
    In each band the *base* space mesh is refined `levels` times (`refine`): a simplex is marked
    when `front_distance(c, t)` at its centroid c is below `width` plus its own size (longest edge)
    for any of 5 times spread over the band; `front_distance(points (N, D), t) -> (N,)` is the
    distance to the wave front in length units. Each band is then tent-pitched from its flat start
    front to its flat end front; the next band starts on that end front, its points merged with the
    previous band's end points where the spatial positions coincide exactly. Where the refined
    region moves between bands, the simplices below and above a band boundary do not share faces:
    the mesh is non-conforming there, as in the paper. With `front_distance=None` no refinement is
    done and the mesh is conforming. D = 1 (segments) is refined by splitting at midpoints. Refuses
    bands < 1, levels < 0, width < 0 and the bad inputs of `tent_pitch` (ValueError).
    """
    pts0, sim0 = _validate_space(space_points, space_simplices)
    bands, levels = int(bands), int(levels)
    if bands < 1:
        raise ValueError(f"need bands >= 1, got {bands}")
    if levels < 0:
        raise ValueError(f"need levels >= 0, got {levels}")
    if not (np.isfinite(width) and width >= 0):
        raise ValueError(f"width must be >= 0, got {width}")
    t_start, t_end = float(t_start), float(t_end)
    if not (np.isfinite(t_start) and np.isfinite(t_end)) or not t_end > t_start:
        raise ValueError(f"need t_end > t_start, got [{t_start}, {t_end}]")
    edges_t = np.linspace(t_start, t_end, bands + 1)
    edges_t[-1] = t_end
    all_points: list[np.ndarray] = []
    all_simplices: list[np.ndarray] = []
    offset = 0
    prev_top: np.ndarray | None = None  # (n, D+1 + 1): spatial coords, global index
    for b in range(bands):
        t0, t1 = edges_t[b], edges_t[b + 1]
        pts, sim = pts0, sim0
        if front_distance is not None:
            for _ in range(levels):
                centroid = pts[sim].mean(axis=1)
                reach = width + _element_size(pts, sim)
                mark = np.zeros(len(sim), dtype=bool)
                for t in np.linspace(t0, t1, 5):
                    d = np.asarray(front_distance(centroid, float(t)), dtype=np.float64)
                    if d.shape != (len(sim),):
                        raise ValueError(f"front_distance must return shape ({len(sim)},), "
                                         f"got {d.shape}")
                    mark |= d < reach
                if not mark.any():
                    break
                pts, sim = refine(pts, sim, mark)
        band = tent_pitch(pts, sim, t0, t1, wave_speed, safety=safety, rng_seed=rng_seed + b)
        bp, bs = band.points, band.simplices.astype(np.int64)
        gid = offset + np.arange(len(bp))
        at_start = bp[:, -1] == t0
        if prev_top is not None:
            # merge the band's start points with the previous band's end points (same x)
            start_idx = np.flatnonzero(at_start)
            cat = np.concatenate([prev_top[:, :-1], bp[start_idx, :-1]])
            _, first_of, inv = np.unique(cat, axis=0, return_index=True, return_inverse=True)
            inv = inv.ravel()
            owner = first_of[inv[len(prev_top):]]
            matched = owner < len(prev_top)
            gid[start_idx[matched]] = prev_top[owner[matched], -1].astype(np.int64)
        keep = np.ones(len(bp), dtype=bool)
        if prev_top is not None:
            keep[np.flatnonzero(at_start)[matched]] = False
        # renumber the kept points compactly after the merged ones
        new_gid = offset + np.cumsum(keep) - 1
        gid[keep] = new_gid[keep]
        all_points.append(bp[keep])
        all_simplices.append(gid[bs])
        offset += int(keep.sum())
        at_end = bp[:, -1] == t1
        prev_top = np.c_[bp[at_end, :-1], gid[at_end]]
    points = np.concatenate(all_points)
    simplices = np.concatenate(all_simplices)
    return SpacetimeMesh(points, simplices.astype(np.int32))
