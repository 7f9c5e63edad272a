"""fe2003 preprocessing (workbench.algo.fepatch.pipeline) on small generated shells: exact area
of a flat plate, crack-free simplified surfaces, the distance bound that follows from the
construction, unpinched subpatches, the atlas and the wire texture, and the fallback of
subpatches that cannot be retriangulated."""

from __future__ import annotations

import math

import numpy as np
import pytest
from meshes import quad_grid

from workbench.algo.fepatch.atlas import plane_frames
from workbench.algo.fepatch.lines import simplify_polyline
from workbench.algo.fepatch.pipeline import (
    PARAMETER_SETS,
    STAGES,
    FEPatchParams,
    border_network,
    build_model,
    parse_params,
    simplified_triangles,
    unpinched,
)
from workbench.algo.fepatch.wireid import on_outline
from workbench.algo.hausdorff import hausdorff
from workbench.scene.derived import triangulate
from workbench.scene.generators import stamped_panel


# --------------------------------------------------------------------------- shapes
def grid(nx: int, ny: int, h: float = 1.0, drop=()) -> tuple[np.ndarray, np.ndarray]:
    """Quads of an nx × ny grid of cells of size h in the (s, t) plane, cells ``drop`` left out;
    (elements (M, 4), st (N, 2)) with unused nodes removed. Wound counter-clockwise in (s, t)."""
    st, e = quad_grid(nx, ny, cell=h, ij=True, dim=2)
    dropped = set(drop)
    e = e[[(i, j) not in dropped for i in range(nx) for j in range(ny)]]
    used = np.unique(e)
    remap = np.full(len(st), -1)
    remap[used] = np.arange(len(used))
    return remap[e], st[used]


HOLE = [(i, j) for i in (2, 3) for j in (4, 5, 6)]


def bent_plate(bump: float = 15.0, nx: int = 30, ny: int = 12, h: float = 10.0,
               drop=HOLE) -> tuple[np.ndarray, np.ndarray]:
    """A strip of nx × ny quads (h model units) bent along grid lines: flat, a 30° crease, flat,
    a gentle 40° arc (4° per element, below the 12° G1 angle) carrying a dome of height
    ``bump``, a −25° crease, flat; with a hole in the first flat part."""
    e, st = grid(nx, ny, h, drop)
    cell = np.arange(nx)
    theta = np.radians(30.0) * (cell >= 8) + np.radians(4.0) * np.clip(cell - 13, 0, 10) \
        - np.radians(25.0) * (cell >= 26)
    px = np.r_[0.0, np.cumsum(np.cos(theta))] * h
    pz = np.r_[0.0, np.cumsum(np.sin(theta))] * h
    k = np.rint(st[:, 0] / h).astype(int)
    heading = 0.5 * (np.r_[theta[0], theta][k] + np.r_[theta, theta[-1]][k])
    s = st[:, 0] / h
    dome = np.where((s >= 14) & (s <= 24), np.sin(np.pi * (s - 14) / 10), 0.0) \
        * np.sin(np.pi * st[:, 1] / (ny * h)) * bump
    c = np.c_[px[k] - dome * np.sin(heading), st[:, 1], pz[k] + dome * np.cos(heading)]
    return e, c


def panel(seed: int) -> tuple[np.ndarray, np.ndarray]:
    m = stamped_panel(18, 12, 300.0, 200.0, flange_depth=20.0, seed=seed)
    return np.asarray(m.elements, np.int64), np.asarray(m.nodes, np.float64)


def rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


# --------------------------------------------------------------------------- checks
def node_ids(surface, coords) -> np.ndarray:
    """(V,) the node of each surface vertex: vertices are duplicated per subpatch, their
    positions are copies of node coordinates, so welding by identical position recovers it."""
    assert len(np.unique(coords, axis=0)) == len(coords), "shapes need distinct node positions"
    index = {tuple(p): i for i, p in enumerate(coords.tolist())}
    return np.array([index[tuple(p)] for p in surface.positions.tolist()], np.int64)


def element_edges(e: np.ndarray) -> np.ndarray:
    """Directed edges of elements or triangles (M, k) in winding order, repeated corners
    dropped."""
    e = np.asarray(e)
    a, b = e.ravel(), np.roll(e, -1, axis=1).ravel()
    return np.c_[a, b][a != b]


def undirected_counts(edges: np.ndarray) -> dict:
    key, count = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    return {tuple(k): int(n) for k, n in zip(key.tolist(), count)}


def outer_boundary(e: np.ndarray) -> dict:
    """{node: set of its neighbours along the outer boundary} (edges used by one element)."""
    adj: dict = {}
    for (a, b), n in undirected_counts(element_edges(e)).items():
        if n == 1:
            adj.setdefault(a, set()).add(b)
            adj.setdefault(b, set()).add(a)
    assert all(len(v) == 2 for v in adj.values()), "shapes must have no pinched boundary node"
    return adj


def assert_no_crack(tri_nodes: np.ndarray, elements: np.ndarray, oriented: bool = True) -> list:
    """The triangles (node ids, welded) close up like the elements: every edge is used by two
    triangles, except the edges along the outer boundary, which are used once and form the
    original boundary chain with some nodes skipped -- an edge used once anywhere else is a
    crack or a T-junction. ``oriented``: every edge used twice is traversed both ways.
    Returns the outer boundary chains [a, ..., b] that the once-used edges (a, b) replace."""
    edges = element_edges(tri_nodes)
    counts = undirected_counts(edges)
    bad = {k: n for k, n in counts.items() if n > 2}
    assert not bad, f"edges used by three or more triangles: {list(bad.items())[:5]}"
    once = [k for k, n in counts.items() if n == 1]
    adj = outer_boundary(elements)
    kept = {v for k in once for v in k}
    off = [k for k in once if k[0] not in adj or k[1] not in adj]
    assert not off, f"{len(off)} cracks: edges used once off the outer boundary, e.g. {off[:5]}"
    walked = 0
    chains = []
    for a, b in once:
        reached = []
        for first in adj[a]:
            chain = [a, first]
            while chain[-1] not in kept:
                chain.append(next(iter(adj[chain[-1]] - {chain[-2]})))
            reached.append(chain)
        hit = sorted((c for c in reached if c[-1] == b), key=len)
        assert hit, f"edge {(a, b)} used once is not a chord of the outer boundary chain"
        walked += len(hit[0]) - 1
        chains.append(hit[0])
    n_boundary = sum(len(v) for v in adj.values()) // 2
    assert walked == n_boundary, f"the once-used edges cover {walked} of {n_boundary} " \
                                 "outer boundary edges"
    if oriented:
        directed = {tuple(k) for k in edges.tolist()}
        assert len(directed) == len(edges), "a directed edge is used twice (flipped triangle)"
        twice = [k for k, n in counts.items() if n == 2]
        assert all(k in directed and k[::-1] in directed for k in twice)
    return chains


def triangle_normals(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])


def border_passes_twice(elements, labels) -> list:
    """Subpatches whose border (edges used once by the subpatch's elements) passes a node twice:
    [(label, node)]."""
    e = np.asarray(elements)
    lab = np.asarray(labels)
    out = []
    for s in np.unique(lab):
        counts = undirected_counts(element_edges(e[lab == s]))
        ends = np.array([k for k, n in counts.items() if n == 1]).ravel()
        nodes, deg = np.unique(ends, return_counts=True)
        out += [(int(s), int(v)) for v in nodes[deg > 2]]
    return out


# --------------------------------------------------------------------------- built once
@pytest.fixture(scope="module")
def bent():
    e, c = bent_plate()
    return e, c, build_model(e, c, "A")


# --------------------------------------------------------------------------- 1. flat plate
def test_flat_plate_with_hole_is_a_handful_of_triangles_of_the_same_area():
    e, st = grid(12, 10, drop=[(i, j) for i in (4, 5, 6) for j in (4, 5)])
    rot = rotation(3)
    c = np.c_[st, np.zeros(len(st))] @ rot.T + [5.0, -3.0, 2.0]
    m = build_model(e, c, "A")
    assert len(m.fallback) == 0 and m.n_subpatches == 1
    s = m.simplified
    # a rectangle with a rectangular hole keeps its 4 + 4 corners: V + 2·holes − 2 = 8 triangles
    assert len(s.triangles) == 8
    area = 0.5 * np.linalg.norm(triangle_normals(s.positions, s.triangles), axis=1)
    assert np.all(area > 0)
    assert abs(area.sum() - len(e)) <= 1e-9 * len(e)  # unit cells
    o = m.original
    assert abs(0.5 * np.linalg.norm(triangle_normals(o.positions, o.triangles), axis=1).sum()
               - len(e)) <= 1e-9 * len(e)
    # wound like the elements: every normal along the element normals (+z of the grid, rotated)
    up = rot[:, 2]
    assert np.all(triangle_normals(s.positions, s.triangles) @ up > 0)
    assert np.all(triangle_normals(c, triangulate(e, c).triangles) @ up > 0)
    assert_no_crack(node_ids(s, c)[s.triangles], e)


def test_flat_plate_wound_clockwise_keeps_its_winding():
    e, st = grid(8, 6, drop=[(3, 2), (4, 2)])
    e = e[:, ::-1].copy()
    c = np.c_[st, np.zeros(len(st))]
    m = build_model(e, c, "A")
    s = m.simplified
    assert len(m.fallback) == 0
    assert np.all(triangle_normals(s.positions, s.triangles)[:, 2] < 0)
    area = 0.5 * np.abs(triangle_normals(s.positions, s.triangles)[:, 2]).sum()
    assert abs(area - len(e)) <= 1e-9 * len(e)
    assert_no_crack(node_ids(s, c)[s.triangles], e)


# --------------------------------------------------------------------------- 2. no cracks
def test_bent_plate_simplifies_into_several_subpatches_without_cracks(bent):
    e, c, m = bent
    assert m.n_patches >= 4 and m.n_subpatches >= 8 and m.n_lines >= 8
    assert m.features["G1"] > 0 and m.features["G0"] > 0
    assert m.line_nodes_kept < m.line_nodes  # lines were simplified
    assert len(m.fallback) == 0
    s = m.simplified
    assert_no_crack(node_ids(s, c)[s.triangles], e)


@pytest.mark.parametrize("spec", ["B", "8,0.5,1,1", "12,0.3,0.5,2"])
def test_bent_plate_without_cracks_for_other_parameters(spec):
    e, c = bent_plate(bump=25.0)
    m = build_model(e, c, spec)
    s = m.simplified
    assert_no_crack(node_ids(s, c)[s.triangles], e)


@pytest.mark.parametrize("seed", [0, 4])
def test_stamped_panel_without_cracks(seed):
    e, c = panel(seed)
    m = build_model(e, c, "A")
    s = m.simplified
    assert_no_crack(node_ids(s, c)[s.triangles], e, oriented=False)
    # the generator winds consistently, so the simplification does too
    assert_no_crack(node_ids(s, c)[s.triangles], e, oriented=True)


def test_crack_check_sees_a_crack(bent):
    """The check above can fail: one triangle less opens a hole, and one simplified subpatch
    replaced by its original elements leaves T-junctions against its simplified neighbours."""
    e, c, m = bent
    s = m.simplified
    tri = node_ids(s, c)[s.triangles]
    with pytest.raises(AssertionError):
        assert_no_crack(tri[1:], e)
    label = int(np.bincount(m.subpatch).argmax())
    orig = triangulate(e, c)
    tri_of = node_ids(s, c)[s.triangles]
    keep = ~np.isin(tri_of, np.unique(e[m.subpatch == label])).all(axis=1)
    mixed = np.r_[tri_of[keep], orig.triangles[m.subpatch[orig.element_of] == label]]
    with pytest.raises(AssertionError):
        assert_no_crack(mixed, e)


# --------------------------------------------------------------------------- 3. error bound
# Bound. A point p of the original surface in subpatch s is a convex combination of s's nodes;
# the simplified subpatch is s's border loops (original nodes, some line nodes left out)
# triangulated in s's plane, so every simplified point is a convex combination of s's nodes
# too. Heights over the plane therefore lie in [h_min(s), h_max(s)] on both surfaces (a spread
# w(s) <= 2d when every node is within d of the least-squares plane: a curved subpatch has
# its middle on one side of the plane and its border on the other, and the simplified surface
# spans the border only, so d alone, or d + l, is not a bound). In the plane, p's projection
# lies inside the original polygon; where it is outside the simplified one it lies in the
# hull of a removed run of line nodes, all within l of their chord (eq. 1: l <= max(l_inner,
# l_outer); projecting shortens distances), hence within l of the simplified polygon. So
#     one-sided distance(original -> simplified) <= sqrt(l_max² + max_s w(s)²).
# Fallback subpatches are their original elements (distance 0).
def _bound(e, c, m) -> tuple[float, float]:
    frames = plane_frames(c, e, m.subpatch)
    spread = 0.0
    for label, (origin, axes) in frames.items():
        mine = m.subpatch == label
        height = (c[np.unique(e[mine])] - origin) @ axes[2]
        if mine.sum() > 1:  # a single warped element may exceed d: its seed is always accepted
            assert np.abs(height).max() <= m.params.d * (1 + 1e-9) + 1e-12
        spread = max(spread, float(height.max() - height.min()))
    return math.hypot(max(m.params.l_inner, m.params.l_outer), spread), spread


@pytest.mark.parametrize("shape,spec", [
    ("bent15", "A"), ("bent15", "8,0.5,1,1"), ("bent25", "12,2,0.5,1"),
    ("bent25", "20,0.2,0.3,0.6"), ("panel1", "12,0.3,0.5,2"), ("panel7", "8,0.5,1,1"),
])
def test_original_surface_within_the_construction_bound(shape, spec):
    e, c = bent_plate(bump=float(shape[4:])) if shape.startswith("bent") else panel(
        int(shape[5:]))
    m = build_model(e, c, spec)
    bound, spread = _bound(e, c, m)
    o, s = m.original, m.simplified
    r = hausdorff(o.positions, o.triangles, s.positions, s.triangles, one_sided=True, tol=1e-3)
    assert r.upper <= bound, f"{shape} {spec}: distance {r.upper:.4f} above {bound:.4f} " \
                             f"(height spread {spread:.4f})"
    # outer boundary lines have one subpatch beside them, so eq. 1 gives them l_outer: every
    # left-out boundary node lies within l_outer of the chord that replaces it
    chains = assert_no_crack(node_ids(s, c)[s.triangles], e, oriented=False)
    worst = 0.0
    for chain in chains:
        a, b = c[chain[0]], c[chain[-1]]
        p = c[chain[1:-1]]
        if len(p):
            t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
            worst = max(worst, float(np.linalg.norm(p - a - t[:, None] * (b - a), axis=1).max()))
    assert worst <= m.params.l_outer * (1 + 1e-9)
    assert any(len(chain) > 2 for chain in chains)  # the boundary was simplified
    # and the simplified surface stays on the original: its vertices are original nodes
    assert np.isin(node_ids(s, c), np.unique(e)).all()


# --------------------------------------------------------------------------- 4. stages, params
def test_simplification_reduces_triangles_and_times_every_stage(bent):
    e, _, m = bent
    assert len(m.original.triangles) == 2 * len(e)
    assert len(m.simplified.triangles) * 4 <= len(m.original.triangles)
    assert set(m.seconds) == set(STAGES) and len(STAGES) == 3
    assert all(np.isfinite(v) and v >= 0 for v in m.seconds.values())
    assert m.n_elements == len(e) and m.subpatch.shape == (len(e),)
    assert m.rgba_texels_per_element > 0


def test_parse_params_table_1_and_custom():
    a = parse_params("A")
    assert (a.alpha_g1_deg, a.d, a.l_outer, a.l_inner) == (12.0, 1.0, 0.5, 8.0)
    b = parse_params(" b ")
    assert (b.alpha_g1_deg, b.d, b.l_outer, b.l_inner) == (18.0, 3.0, 2.5, 15.0)
    assert a is PARAMETER_SETS["A"] and parse_params(a) is a
    p = parse_params("10, 0.5, 0.25, 4")
    assert (p.alpha_g1_deg, p.d, p.l_outer, p.l_inner) == (10.0, 0.5, 0.25, 4.0)
    assert p.label == "10,0.5,0.25,4"


@pytest.mark.parametrize("spec", ["C", "", "1,2,3", "1,2,3,4,5", "a,b,c,d", "0,1,1,1",
                                  "180,1,1,1", "12,-1,1,1", "12,1,nan,1", "12,1,1,inf"])
def test_parse_params_refuses_bad_specs(spec):
    with pytest.raises(ValueError):
        parse_params(spec)


def test_build_model_refuses_bad_input():
    e, st = grid(2, 2)
    c = np.c_[st, np.zeros(len(st))]
    with pytest.raises(ValueError):
        build_model(e[:0], c)
    bad = c.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError):
        build_model(e, bad)
    with pytest.raises(ValueError):
        build_model(e, c, "Z")
    with pytest.raises(ValueError):
        FEPatchParams(12.0, -1.0, 1.0, 1.0)


# --------------------------------------------------------------------------- 5. unpinched
def test_unpinched_splits_a_subpatch_touching_itself():
    # 4 × 4 cells; subpatch 0 is a ring of cells whose two ends, (1,1) and (2,2), touch only at
    # the grid node (2,2); cells (1,2) and (2,1) are subpatches of their own, the rest is 1
    e, st = grid(4, 4)
    cells = [(i, j) for i in range(4) for j in range(4)]
    ring = {(1, 1), (0, 1), (0, 2), (0, 3), (1, 3), (2, 3), (2, 2)}
    labels = np.array([0 if ij in ring else 2 if ij == (1, 2) else 3 if ij == (2, 1) else 1
                       for ij in cells])
    pinch_node = 2 * 5 + 2
    assert border_passes_twice(e, labels) == [(0, pinch_node)]
    out = unpinched(e, labels, len(st))
    assert out.shape == labels.shape and out.dtype == np.int64
    assert set(out.tolist()) == set(range(out.max() + 1))
    assert border_passes_twice(e, out) == []
    # a refinement of the input, split only at the pinch
    for s in np.unique(out):
        assert len(np.unique(labels[out == s])) == 1
    away = np.array([ij in ring and ij not in {(1, 1), (2, 2)} for ij in cells])
    assert len(np.unique(out[away])) == 1
    assert out[cells.index((1, 1))] != out[cells.index((2, 2))]
    for ij in [(1, 2), (2, 1)]:
        assert (out == out[cells.index(ij)]).sum() == 1
    assert len(np.unique(out[labels == 1])) == 1
    # a mesh without pinches is left as it is (up to renumbering)
    clean = np.array([0 if i < 2 else 1 for i, _ in cells])
    assert np.array_equal(unpinched(e, clean, len(st)), clean)


@pytest.mark.parametrize("shape", ["bent", "panel0", "panel4"])
def test_model_subpatches_are_unpinched(shape, bent):
    e, c, m = bent if shape == "bent" else (*panel(int(shape[5:])), None)
    if m is None:
        m = build_model(e, c, "A")
    assert border_passes_twice(e, m.subpatch) == []


# --------------------------------------------------------------------------- 6. textures
def test_uv_inside_the_atlas_and_outer_boundary_drawn_as_lines(bent):
    e, c, m = bent
    for surf in (m.original, m.simplified):
        w, h = surf.size
        assert (w, h) == tuple(m.atlas_size)
        assert np.all(surf.uv >= 0) and np.all(surf.uv[:, 0] <= w) and np.all(surf.uv[:, 1] <= h)
    o = m.original
    nodes = node_ids(o, c)
    lines = {tuple(sorted(p)) for p in nodes[o.line_edges].tolist()}
    outer = {k for k, n in undirected_counts(element_edges(e)).items() if n == 1}
    assert outer <= lines
    s = m.simplified
    assert {tuple(sorted(p)) for p in node_ids(s, c)[s.line_edges].tolist()} == lines


def test_wire_texture_outlines_every_interior_edge(bent):
    e, c, m = bent
    o = m.original
    nodes = node_ids(o, c)
    tri = triangulate(e, c)
    # (element, node) -> vertex of the original surface, from the element's own triangles
    vertex = {}
    for t, k in enumerate(tri.element_of.tolist()):
        for v in o.triangles[t].tolist():
            vertex[(k, int(nodes[v]))] = v
    lines = {tuple(sorted(p)) for p in nodes[o.line_edges].tolist()}
    sides: dict = {}
    for k, quad in enumerate(e.tolist()):
        for a, b in zip(quad, quad[1:] + quad[:1]):
            sides.setdefault(tuple(sorted((a, b))), set()).add(int(m.subpatch[k]))
    t = np.linspace(0.2, 0.8, 7)[:, None]
    probes, inside, base = [], [], []
    for k, quad in enumerate(e.tolist()):
        for a, b in zip(quad, quad[1:] + quad[:1]):
            if a == b or tuple(sorted((a, b))) in lines:
                continue
            ua, ub = o.uv[vertex[(k, a)]], o.uv[vertex[(k, b)]]
            probes.append(ua + t * (ub - ua))
            inside += [len(sides[tuple(sorted((a, b)))]) == 1] * len(t)
            base += [o.element_base[vertex[(k, a)]]] * len(t)
    probes, inside = np.concatenate(probes), np.array(inside)
    assert len(probes) > 7 * len(e) and 0 < inside.sum() < len(inside)
    hit = on_outline(o, probes, 0.5, np.array(base))
    assert hit.mean() >= 0.99, f"{hit.mean():.4f} of {len(probes)} probes on an outline"
    # inside a subpatch both elements of an edge share the chart: every probe is outlined
    # (the few misses are on subpatch borders, where the neighbour lies in another chart)
    assert hit[inside].all()
    # and element interiors are not outlined everywhere: the centres are mostly clear
    centre = np.array([o.uv[[vertex[(k, n)] for n in quad]].mean(axis=0)
                       for k, quad in enumerate(e.tolist())])
    centre_base = [o.element_base[vertex[(k, quad[0])]] for k, quad in enumerate(e.tolist())]
    assert on_outline(o, centre, 0.5, np.array(centre_base)).mean() < 0.05


# --------------------------------------------------------------------------- 7. fallback
def spiral_ramp(turns: float = 1.2, per_turn: int = 48, width: int = 4, wall: float = 3.0):
    """A flat ramp winding 1.2 times around the z axis (4 elements wide, radius growing by 2
    and height by 0.4 per turn) with a wall bent down by 90° along its outer edge. The ramp is
    one planar subpatch (within d = 1) whose projection overlaps itself: its border is no
    simple polygon in its plane, so it cannot be retriangulated."""
    th = np.linspace(0.0, 2 * np.pi * turns, int(per_turn * turns) + 1)
    grow, pitch = 2.0 * th / (2 * np.pi), 0.4 * th / (2 * np.pi)
    rings = [np.c_[(8 + k + grow) * np.cos(th), (8 + k + grow) * np.sin(th), pitch]
             for k in range(width + 1)]
    rings.append(rings[-1] - [0.0, 0.0, wall])
    c = np.concatenate(rings)
    n = len(th)
    k, i = np.meshgrid(np.arange(len(rings) - 1), np.arange(n - 1), indexing="ij")
    k, i = k.ravel(), i.ravel()
    e = np.c_[k * n + i, (k + 1) * n + i, (k + 1) * n + i + 1, k * n + i + 1]
    return e, c, k < width


def test_self_overlapping_subpatch_falls_back_and_neighbours_close_up_to_it():
    e, c, on_ramp = spiral_ramp()
    m = build_model(e, c, "A")
    ramp = np.unique(m.subpatch[on_ramp])
    assert len(ramp) == 1 and m.fallback.tolist() == ramp.tolist()
    s = m.simplified
    tri = node_ids(s, c)[s.triangles]
    assert_no_crack(tri, e)
    # the ramp is its original elements, winding included; the wall is still simplified
    orig = triangulate(e, c)
    mine = orig.triangles[on_ramp[orig.element_of]]
    assert {tuple(t) for t in mine.tolist()} <= {tuple(t) for t in tri.tolist()}
    assert len(tri) - len(mine) < 2 * (~on_ramp).sum()
    # the ramp's border nodes are all kept, also on the lines it shares with the wall
    used = np.unique(tri)
    assert np.isin(np.unique(e[on_ramp]), used).all()


def test_inconsistently_wound_border_element_is_split_off_and_keeps_its_winding():
    e, c = bent_plate(bump=15.0)
    cells = [(i, j) for i in range(30) for j in range(12) if (i, j) not in set(HOLE)]
    k = cells.index((5, 0))
    e = e.copy()
    e[k] = e[k, ::-1]
    m = build_model(e, c, "A")
    assert border_passes_twice(e, m.subpatch) == []
    s = m.simplified
    tri = node_ids(s, c)[s.triangles]
    assert_no_crack(tri, e, oriented=False)
    normal = triangle_normals(c, triangulate(e[k:k + 1], c).triangles).sum(axis=0)
    own = np.isin(tri, e[k]).all(axis=1)  # its subpatch, maybe with a line node left out
    assert own.sum() >= 1
    assert np.all(triangle_normals(c, tri[own]) @ normal > 0)


def _line_simplified(e, c, labels, tol):
    network = border_network(e, labels, len(c))
    removed = np.zeros(len(c), bool)
    for nodes, closed, _ in network.lines:
        if len(nodes) >= (4 if closed else 3):
            keep = simplify_polyline(c[nodes], tol, closed=closed, fixed=network.fixed[nodes])
            gone = np.ones(len(nodes), bool)
            gone[keep] = False
            removed[nodes[gone]] = True
    return network, removed


@pytest.mark.parametrize("case", ["pinched", "flipped"])
def test_unretriangulable_subpatch_falls_back_and_neighbours_restore_their_lines(case):
    """Labels given to the retriangulation as they are (build_model unpinches them first): the
    pinched ring of the unpinched test, or subpatch 0 with one element wound the other way."""
    e, st = grid(4, 4)
    c = np.c_[st, 0.05 * st[:, 0] ** 2]  # gently curved, so lines are not all straight
    cells = [(i, j) for i in range(4) for j in range(4)]
    ring = {(1, 1), (0, 1), (0, 2), (0, 3), (1, 3), (2, 3), (2, 2)}
    labels = np.array([0 if ij in ring else 2 if ij == (1, 2) else 3 if ij == (2, 1) else 1
                       for ij in cells])
    if case == "flipped":
        e = e.copy()
        k = cells.index((0, 2))
        e[k] = e[k, ::-1]
        labels = np.where(labels == 0, 2, labels)
        labels[cells.index((0, 2))] = 0
        labels[[cells.index(ij) for ij in [(0, 1), (0, 3)]]] = 0
    network, removed = _line_simplified(e, c, labels, 0.5)
    assert removed.any()
    frames = plane_frames(c, e, labels)
    tris, fallback, final = simplified_triangles(e, c, labels, network, removed, frames)
    assert fallback.tolist() == [0]
    assert set(tris) == set(np.unique(labels).tolist())
    orig = triangulate(e, c)
    assert np.array_equal(np.sort(tris[0], axis=0),
                          np.sort(orig.triangles[labels[orig.element_of] == 0], axis=0))
    # every border node of the fallback subpatch is back, and the neighbours close up to it
    assert not final[np.unique(e[labels == 0])].any()
    assert_no_crack(np.concatenate([tris[s] for s in sorted(tris)]), e, oriented=case == "pinched")
