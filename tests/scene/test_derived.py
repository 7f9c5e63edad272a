"""Derived mesh data against brute-force pure-Python references and hand-built cases."""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from meshes import folded, quad_grid

from workbench.scene import FEMesh
from workbench.scene.crease import GouraudSplit, gouraud_split
from workbench.scene.derived import (
    Triangulation,
    element_normals,
    node_normals,
    triangulate,
    unique_edges,
)

PROPERTY = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
ZERO_REL = 1e-12  # the same "cross product is noise" threshold the module documents
COS_TOL = 1e-12


# --------------------------------------------------------------------------- strategies
@st.composite
def meshes(draw, max_nodes: int = 9, max_elements: int = 12):
    """Small random meshes: quads, triangles, collapsed quads and arbitrary (often degenerate)
    node quadruples over few nodes, so shared, non-manifold and flipped edges are frequent."""
    n = draw(st.integers(3, max_nodes))
    m = draw(st.integers(1, max_elements))
    node = st.integers(0, n - 1)
    rows = []
    for _ in range(m):
        kind = draw(st.sampled_from(["quad", "quad", "tri", "tri", "collapsed", "raw"]))
        if kind == "quad" and n >= 4:
            rows.append(draw(st.lists(node, min_size=4, max_size=4, unique=True)))
        elif kind in ("quad", "tri"):
            t = draw(st.lists(node, min_size=3, max_size=3, unique=True))
            rows.append(t + [t[2]])
        elif kind == "collapsed":
            t = draw(st.lists(node, min_size=3, max_size=3, unique=True))
            k = draw(st.integers(0, 3))
            q = t + [t[2]]
            rows.append(q[k:] + q[:k])  # the repeated pair at any cyclic position
        else:
            rows.append(draw(st.lists(node, min_size=4, max_size=4)))
    coordinate = st.one_of(st.integers(-3, 3).map(float), st.sampled_from([0.0, 1.0]),
                           st.floats(-10, 10, allow_nan=False, allow_subnormal=False))
    coords = draw(hnp.arrays(np.float64, (n, 3), elements=coordinate))
    return np.array(rows, dtype=np.int32), coords


def random_coords(seed: int, n: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-10, 10, (n, 3))


# --------------------------------------------------------------------------- references
def ref_kind(e) -> tuple[int, list[int]]:
    """(3 or 4, kept corners) or (0, []) for a degenerate element, by collapsing cyclic repeats."""
    e = [int(x) for x in e]
    polygon = [e[i] for i in range(4) if e[i] != e[i - 1]]
    if len(polygon) < 3 or len(set(polygon)) != len(polygon):
        return 0, []
    first = [i for i in range(4) if e[i] not in e[:i]]
    return len(polygon), first


def sub(p, q):
    return [p[0] - q[0], p[1] - q[1], p[2] - q[2]]


def cross(u, v):
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def ref_vector_area(e, coords):
    """Half of cross(c - a, d - b) as a list, or None when it is no direction."""
    x = [list(map(float, coords[int(i)])) for i in e]
    d1, d2 = sub(x[2], x[0]), sub(x[3], x[1])
    n = cross(d1, d2)
    if not math.sqrt(dot(n, n)) > ZERO_REL * math.sqrt(dot(d1, d1) * dot(d2, d2)):
        return None
    return [0.5 * c for c in n]


def ref_unit(v):
    if v is None:
        return [0.0, 0.0, 0.0]
    big = max(abs(c) for c in v)  # scaled first: tiny components' squares underflow
    v = [c / big for c in v]
    length = math.sqrt(dot(v, v))
    return [c / length for c in v]


def ref_triangulation(elements, coords):
    tris, elem, corners = [], [], []
    for i, e in enumerate(elements):
        kind, first = ref_kind(e)
        if kind == 4:
            x = [list(map(float, coords[int(k)])) for k in e]
            ac, bd = sub(x[2], x[0]), sub(x[3], x[1])
            split = [[0, 1, 2], [0, 2, 3]] if dot(ac, ac) <= dot(bd, bd) else [[0, 1, 3], [1, 2, 3]]
        elif kind == 3:
            split = [first]
        else:
            split = []
        for s in split:
            tris.append([int(e[k]) for k in s])
            elem.append(i)
            corners.append(s)
    return tris, elem, corners


class UnionFind:
    def __init__(self):
        self.parent = {}

    def find(self, x):
        self.parent.setdefault(x, x)
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def union(self, a, b):
        self.parent[self.find(a)] = self.find(b)


def ref_gouraud(elements, coords_list, crease_deg):
    """Per-node union-find over (element, node) corners, then per-group orientation by search.

    Returns (vertex_node, elements in vertex space, vertex of each (element, node), signs)."""
    m = len(elements)
    kinds = [ref_kind(e) for e in elements]
    normals = [[ref_unit(ref_vector_area(e, c)) for e in elements] for c in coords_list]
    limit = math.cos(math.radians(crease_deg)) - COS_TOL
    along = defaultdict(list)  # undirected edge -> [(element, u, v)] in element order
    for i, e in enumerate(elements):
        kind, first = kinds[i]
        if not kind:
            continue
        ring = [int(e[k]) for k in first]
        for k in range(len(ring)):
            u, v = ring[k], ring[(k + 1) % len(ring)]
            along[(min(u, v), max(u, v))].append((i, u, v))
    uf = UnionFind()
    links = []  # ((f, node), (g, node), agree)
    for (lo, hi), uses in along.items():
        for (f, fu, fv), (g, gu, gv) in zip(uses, uses[1:]):
            agree = (fu, fv) != (gu, gv)
            smooth = True
            for n in normals:
                if not any(n[f]) or not any(n[g]):
                    smooth = False
                    break
                c = dot(n[f], n[g]) * (1 if agree else -1)
                smooth &= c >= limit
            if smooth:
                for x in (lo, hi):
                    uf.union((f, x), (g, x))
                    links.append(((f, x), (g, x), agree))
    corners = [(i, int(x)) for i, e in enumerate(elements) for x in dict.fromkeys(e.tolist())]
    first_good = {}
    for i, x in corners:
        if kinds[i][0] and x not in first_good:
            first_good[x] = (i, x)
    lonely = {}
    for i, x in corners:
        if not kinds[i][0]:
            uf.union((i, x), first_good.get(x) or lonely.setdefault(x, (i, x)))
    groups = defaultdict(list)
    for c in corners:
        groups[uf.find(c)].append(c)
    ordered = sorted(groups.values(), key=lambda g: (g[0][1], min(i for i, _ in g)))
    vertex_of = {c: v for v, g in enumerate(ordered) for c in g}
    vertex_node = [g[0][1] for g in ordered]
    split = [[vertex_of[(i, int(x))] for x in e] for i, e in enumerate(elements)]

    # orientation: each smooth patch (elements joined by smooth links) takes the winding of its
    # area majority; a patch with contradicting links is oriented per vertex group instead
    area0 = [math.sqrt(dot(w, w)) if w else 0.0
             for w in (ref_vector_area(e, coords_list[0]) for e in elements)]

    def orient(start, neighbours, weight):
        local, stack, consistent = {start: 1}, [start], True
        while stack:
            a = stack.pop()
            for b, agree in neighbours(a):
                want = local[a] if agree else -local[a]
                if b not in local:
                    local[b] = want
                    stack.append(b)
                elif local[b] != want:
                    consistent = False
        if consistent:
            vote = sum(local[k] * weight(k) for k in local)
            count = sum(local.values())
            if vote < 0 or (vote == 0 and count < 0):
                local = {k: -s for k, s in local.items()}
        return local, consistent

    element_links = defaultdict(list)
    corner_links = defaultdict(list)
    for (f, x), (g, _), agree in links:
        element_links[f].append((g, agree))
        element_links[g].append((f, agree))
        corner_links[(f, x)].append(((g, x), agree))
        corner_links[(g, x)].append(((f, x), agree))
    element_sign, orientable = {}, {}
    for i in range(m):
        if kinds[i][0] and i not in element_sign:
            local, ok = orient(i, lambda k: element_links[k], lambda k: area0[k])
            for k, s in local.items():
                element_sign[k], orientable[k] = s, ok
    sign = {}
    for g in ordered:
        g = [c for c in g if kinds[c[0]][0]]
        if not g:
            continue
        if orientable[g[0][0]]:
            sign.update({c: element_sign[c[0]] for c in g})
            continue
        local, ok = orient(g[0], lambda c: corner_links[c], lambda c: area0[c[0]])
        sign.update(local if ok else {c: 1 for c in g})
    return vertex_node, split, vertex_of, sign


def ref_split_normals(elements, vertex_of, sign, n_vertices, coords):
    total = [[0.0] * 3 for _ in range(n_vertices)]
    magnitude = [0.0] * n_vertices
    for c, s in sign.items():
        w = ref_vector_area(elements[c[0]], coords) or [0.0] * 3
        v = vertex_of[c]
        total[v] = [t + s * x for t, x in zip(total[v], w)]
        magnitude[v] += math.sqrt(dot(w, w))
    return np.array(total), np.array(magnitude)


# --------------------------------------------------------------------------- grids
def grid(nx: int, ny: int, flip=None):
    """Nodes and int32 quads of an nx x ny grid of unit cells in the z = 0 plane, node (i, j) at
    i * (ny + 1) + j; ``flip`` reverses some windings."""
    nodes, quads = quad_grid(nx, ny, ij=True)
    if flip is not None:
        quads[flip] = quads[flip][:, ::-1]
    return nodes, quads.astype(np.int32)


def rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


# --------------------------------------------------------------------------- triangulation
@PROPERTY
@given(meshes())
def test_triangulation_matches_reference(mesh):
    elements, coords = mesh
    t = triangulate(elements, coords)
    tris, elem, corners = ref_triangulation(elements, coords)
    assert (t.triangles.dtype == np.int32 and t.element_of.dtype == np.int32
            and t.corners.dtype == np.int8)
    assert t.triangles.tolist() == tris
    assert t.element_of.tolist() == elem
    assert t.corners.tolist() == corners
    assert np.array_equal(elements[t.element_of[:, None], t.corners], t.triangles)


@st.composite
def planar_elements(draw):
    """A planar convex quad or triangle in a random plane, far from the origin sometimes."""
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    k = draw(st.sampled_from([3, 4]))
    angles = np.sort(rng.uniform(0, 2 * np.pi, k))
    if np.min(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) < 0.2:
        angles = np.linspace(0, 2 * np.pi, k, endpoint=False) + rng.uniform(0, 1)
    radius = rng.uniform(0.5, 3.0)
    stretch = rng.uniform(0.3, 3.0)
    flat = np.stack([radius * stretch * np.cos(angles), radius * np.sin(angles)], axis=1)
    basis = rotation(seed)
    origin = rng.uniform(-1, 1, 3) * draw(st.sampled_from([1.0, 1e3]))
    pts = origin + flat @ basis[:2]
    element = [0, 1, 2, 3] if k == 4 else [0, 1, 2, 2]
    area = 0.5 * abs(np.sum(flat[:, 0] * np.roll(flat[:, 1], -1)
                            - np.roll(flat[:, 0], -1) * flat[:, 1]))
    return np.array([element], np.int32), pts, area, basis[2]


@PROPERTY
@given(planar_elements())
def test_triangulation_covers_planar_elements_with_their_winding(case):
    elements, pts, area, plane_normal = case
    t = triangulate(elements, pts)
    assert len(t.triangles) == (2 if elements[0, 3] != elements[0, 2] else 1)
    p = pts[t.triangles]
    tri_cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n = element_normals(elements, pts)[0]
    assert np.sum(0.5 * tri_cross @ n) == pytest.approx(area, rel=1e-9)
    assert (tri_cross @ n > 0).all()  # every triangle keeps the element's winding
    assert abs(n @ plane_normal) == pytest.approx(1.0, abs=1e-12)
    if len(t.triangles) == 2:
        a, b, c, d = pts[elements[0]]
        shorter_ac = np.linalg.norm(a - c) <= np.linalg.norm(b - d)
        diagonal = set(t.triangles[0]) & set(t.triangles[1])
        assert diagonal == ({0, 2} if shorter_ac else {1, 3})


def test_triangulate_degenerate_and_collapsed_elements():
    nodes = random_coords(1, 5)
    elements = np.array([
        [0, 1, 2, 3],  # quad: two triangles
        [0, 0, 0, 0],  # one node: nothing
        [0, 1, 1, 0],  # two nodes: nothing
        [0, 1, 0, 2],  # repeated at opposite corners: folds back, nothing
        [4, 4, 2, 3],  # a == b: triangle (4, 2, 3)
        [1, 2, 3, 1],  # d == a: triangle (1, 2, 3)
        [2, 3, 4, 4],  # stored triangle
    ], np.int32)
    t = triangulate(elements, nodes)
    assert t.element_of.tolist() == [0, 0, 4, 5, 6]
    assert t.triangles[2:].tolist() == [[4, 2, 3], [1, 2, 3], [2, 3, 4]]
    assert t.corners[2:].tolist() == [[0, 2, 3], [0, 1, 2], [0, 1, 2]]
    normals = element_normals(elements, nodes)
    assert not normals[1:4].any()
    assert np.allclose(np.linalg.norm(normals[[0, 4, 5, 6]], axis=1), 1.0)


# --------------------------------------------------------------------------- edges
@PROPERTY
@given(meshes())
def test_unique_edges_match_brute_force_set(mesh):
    elements, _ = mesh
    expected = sorted({(min(int(e[k]), int(e[(k + 1) % 4])), max(int(e[k]), int(e[(k + 1) % 4])))
                       for e in elements for k in range(4) if e[k] != e[(k + 1) % 4]})
    got = unique_edges(elements)
    assert got.dtype == np.int32 and got.shape == (len(expected), 2)
    assert [tuple(r) for r in got.tolist()] == expected


def test_unique_edges_of_a_quad_leave_out_diagonals():
    got = unique_edges(np.array([[0, 1, 2, 3], [3, 2, 4, 4]]))
    assert got.tolist() == [[0, 1], [0, 3], [1, 2], [2, 3], [2, 4], [3, 4]]


# --------------------------------------------------------------------------- normals
@PROPERTY
@given(meshes())
def test_element_normals_are_unit_or_zero_and_match_reference(mesh):
    elements, coords = mesh
    n = element_normals(elements, coords)
    assert n.shape == (len(elements), 3) and np.isfinite(n).all()
    length = np.linalg.norm(n, axis=1)
    assert np.all((np.abs(length - 1) < 1e-12) | (length == 0))
    for i, e in enumerate(elements):
        ref = ref_unit(ref_vector_area(e, coords))
        assert np.allclose(n[i], ref, atol=1e-12)
        if ref_kind(e)[0] == 0:
            assert not n[i].any()
        if ref_kind(e)[0] == 3 and any(ref):
            a, b, c = (coords[e[k]] for k in ref_kind(e)[1])
            tri = np.cross(b - a, c - a)
            if np.linalg.norm(tri) > 1e-6 * np.linalg.norm(b - a) * np.linalg.norm(c - a):
                unit = tri / np.abs(tri).max()  # scaled first, as ref_unit
                assert np.allclose(n[i], unit / np.linalg.norm(unit), atol=1e-9)


@PROPERTY
@given(planar_elements())
def test_element_normals_are_orthogonal_to_planar_edges(case):
    elements, pts, _, _ = case
    n = element_normals(elements, pts)[0]
    for k in range(4):
        edge = pts[elements[0, (k + 1) % 4]] - pts[elements[0, k]]
        if edge.any():
            assert abs(n @ edge) <= 1e-9 * np.linalg.norm(edge)


@PROPERTY
@given(meshes())
def test_node_normals_match_area_weighted_reference(mesh):
    elements, coords = mesh
    got = node_normals(elements, coords)
    assert got.shape == coords.shape and np.isfinite(got).all()
    used = set(elements.ravel().tolist())
    for node in range(len(coords)):
        total, magnitude = np.zeros(3), 0.0
        for e in elements:
            if node in e.tolist():
                w = np.array(ref_vector_area(e, coords) or [0.0] * 3)
                total += w
                magnitude += np.linalg.norm(w)
        length = np.linalg.norm(total)
        if node not in used or length == 0:
            assert not got[node].any()
        elif length > 1e-6 * magnitude:  # away from cancellation, where rounding decides
            assert np.allclose(got[node], total / length, atol=1e-9)


def test_collinear_nodes_give_a_zero_normal_not_rounding_noise():
    a = np.array([0.1, 0.2, 0.3])
    nodes = np.stack([a, 3 * a, 4.9 * a, a + [0.0, 0.0, 1.0]])
    assert np.cross(nodes[1] - nodes[0], nodes[2] - nodes[0]).any()  # noise, not a direction
    elements = np.array([[0, 1, 2, 2], [0, 1, 3, 3]], np.int32)
    n = element_normals(elements, nodes)
    assert not n[0].any()
    assert np.linalg.norm(n[1]) == pytest.approx(1.0)
    assert np.allclose(node_normals(elements, nodes)[2], 0.0)
    # a zero-normal element is smooth with nothing, even when any angle would count as smooth
    split = gouraud_split(elements, [nodes], 180.0, triangulate(elements, nodes))
    assert split.added == 2 and not split.normals(nodes)[split.elements[0]].any()


def test_node_normals_zero_for_unreferenced_nodes_and_unit_elsewhere():
    nodes, quads = grid(3, 2)
    nodes = np.vstack([nodes, [[5.0, 5.0, 5.0]]])
    n = node_normals(quads, folded(nodes, 1.0, 40.0))
    assert not n[-1].any()
    assert np.allclose(np.linalg.norm(n[:-1], axis=1), 1.0)


# --------------------------------------------------------------------------- Gouraud split
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(meshes(), st.sampled_from([0.0, 10.0, 30.0, 60.0, 90.0, 120.0, 180.0]),
       st.integers(0, 2**32 - 1), st.booleans())
def test_gouraud_split_matches_union_find_reference(mesh, crease, seed, two_sets):
    elements, coords = mesh
    rng = np.random.default_rng(seed)
    sets = [coords] + ([coords + rng.normal(0, 2, coords.shape)] if two_sets else [])
    t = triangulate(elements, coords)
    split = gouraud_split(elements, sets, crease, t)
    vertex_node, expected, vertex_of, sign = ref_gouraud(elements, sets, crease)
    assert split.vertex_node.tolist() == vertex_node
    # a node's vertices are contiguous, in node order
    assert np.all(np.diff(split.vertex_node) >= 0)
    assert split.elements.tolist() == expected
    assert split.added == len(vertex_node) - len(np.unique(elements))
    assert split.n_vertices == len(vertex_node)
    assert np.array_equal(split.vertex_node[split.elements], elements)
    assert np.array_equal(split.vertex_node[split.triangles], t.triangles)
    assert np.array_equal(split.triangles, split.elements[t.element_of[:, None], t.corners])

    later = coords + rng.normal(0, 1, coords.shape)
    got = split.normals(later)
    assert got.shape == (split.n_vertices, 3) and np.isfinite(got).all()
    total, magnitude = ref_split_normals(elements, vertex_of, sign, split.n_vertices, later)
    length = np.linalg.norm(total, axis=1)
    for v in range(split.n_vertices):
        if length[v] > 1e-6 * magnitude[v]:
            assert np.allclose(got[v], total[v] / length[v], atol=1e-9), v
        elif length[v] == 0:
            assert not got[v].any()


@given(st.integers(1, 6), st.integers(1, 5), st.integers(0, 2**32 - 1),
       st.sampled_from([0.0, 5.0, 30.0]))
@settings(max_examples=40, deadline=None)
def test_flat_grid_adds_no_vertices_even_with_flipped_windings(nx, ny, seed, crease):
    rng = np.random.default_rng(seed)
    nodes, quads = grid(nx, ny, flip=rng.random(nx * ny) < 0.3)
    moved = nodes @ rotation(seed).T + rng.uniform(-1e3, 1e3, 3)
    split = gouraud_split(quads, [moved], crease, triangulate(quads, moved))
    assert split.added == 0
    assert np.array_equal(split.vertex_node, np.arange(len(nodes)))
    n = split.normals(moved)
    assert np.allclose(np.abs(n @ rotation(seed)[:, 2]), 1.0)  # flipped elements do not cancel
    assert np.allclose(n, n[0])  # one orientation for the whole sheet


@given(st.integers(2, 6), st.integers(1, 5), st.data())
@settings(max_examples=40, deadline=None)
def test_grid_folded_at_90_degrees_splits_the_fold_line(nx, ny, data):
    fold = data.draw(st.integers(1, nx - 1))
    seed = data.draw(st.integers(0, 2**32 - 1))
    flip = np.random.default_rng(seed).random(nx * ny) < 0.3
    nodes, quads = grid(nx, ny, flip=flip)
    bent = folded(nodes, fold, 90.0) @ rotation(seed).T
    t = triangulate(quads, bent)
    on_fold = np.flatnonzero(nodes[:, 0] == fold)
    split = gouraud_split(quads, [bent], 30.0, t)
    # every node of the fold line, the two on the border included, gets one vertex per side
    assert split.added == len(on_fold) == ny + 1
    assert np.array_equal(np.unique(split.vertex_node[np.diff(split.vertex_node, prepend=-1) == 0]),
                          on_fold)
    assert gouraud_split(quads, [bent], 95.0, t).added == 0


def test_fold_normals_follow_each_face():
    nodes, quads = grid(4, 3)
    bent = folded(nodes, 2.0, 90.0)
    split = gouraud_split(quads, [nodes, bent], 30.0, triangulate(quads, bent))
    normals = split.normals(bent)
    faces = element_normals(quads, bent)
    on_fold = np.isin(split.vertex_node, np.flatnonzero(nodes[:, 0] == 2.0))
    assert on_fold.sum() == 8
    for v in np.flatnonzero(on_fold):
        users = np.flatnonzero((split.elements == v).any(axis=1))
        assert np.allclose(faces[users], faces[users[0]])  # one side of the fold per vertex
        assert np.allclose(normals[v], faces[users[0]], atol=1e-12)
    assert ({tuple(np.round(normals[v], 12)) for v in np.flatnonzero(on_fold)}
            == {(0, 0, 1), (-1, 0, 0)})


def test_crease_in_the_last_step_only_is_still_split():
    nodes, quads = grid(4, 2)
    bent = folded(nodes, 2.0, 60.0)
    t = triangulate(quads, nodes)
    assert gouraud_split(quads, [nodes, nodes], 30.0, t).added == 0
    assert gouraud_split(quads, [nodes, bent], 30.0, t).added == 3
    assert gouraud_split(quads, [bent, nodes], 30.0, t).added == 3
    assert gouraud_split(quads, [nodes, bent], 70.0, t).added == 0


def test_fold_back_beyond_90_degrees_is_a_crease_but_a_flipped_element_is_not():
    nodes, quads = grid(4, 2)
    hem = folded(nodes, 2.0, 150.0)  # consistently wound: normals 150 degrees apart
    t = triangulate(quads, nodes)
    assert gouraud_split(quads, [hem], 40.0, t).added == 3
    _, flipped = grid(4, 2, flip=np.arange(8) == 5)  # right half, but wound the other way
    assert gouraud_split(flipped, [folded(nodes, 2.0, 20.0)], 30.0,
                         t := triangulate(flipped, nodes)).added == 0
    assert gouraud_split(flipped, [hem], 40.0, t).added == 3


def test_non_manifold_edge_links_consecutive_elements():
    nodes = np.array([[0, 0, 0], [0, 1, 0], [-1, 0, 0], [-1, 1, 0], [1, 0, 0], [1, 1, 0],
                      [0, 0, 1], [0, 1, 1]], float)
    left, right, fin = [2, 0, 1, 3], [0, 4, 5, 1], [0, 1, 7, 6]
    # along the shared edge (0, 1): left-right smooth, right-fin a crease -> the fin alone
    elements = np.array([left, right, fin], np.int32)
    split = gouraud_split(elements, [nodes], 30.0, triangulate(elements, nodes))
    assert split.added == 2
    assert split.elements[0, 1] == split.elements[1, 0] != split.elements[2, 0]
    # left-fin and fin-right are both creases, so left and right are never linked
    elements = np.array([left, fin, right], np.int32)
    assert gouraud_split(elements, [nodes], 30.0, triangulate(elements, nodes)).added == 4


def test_bowtie_vertex_gets_one_vertex_per_fan_and_degenerates_share():
    nodes = random_coords(3, 6)
    elements = np.array([[0, 1, 2, 2], [0, 3, 4, 4], [0, 5, 5, 0], [5, 5, 5, 5]], np.int32)
    split = gouraud_split(elements, [nodes], 180.0, triangulate(elements, nodes))
    assert split.added == 1  # node 0: two triangles meeting at a point
    assert split.elements[2, 0] == split.elements[0, 0]  # degenerate corner joins the first fan
    assert split.elements[2, 1] == split.elements[3, 0]  # node 5: only degenerate elements
    assert not split.normals(nodes)[split.elements[3, 0]].any()


def test_mesh_properties_use_the_derived_functions():
    nodes, quads = grid(3, 3)
    steps = np.stack([nodes, folded(nodes, 1.0, 90.0)])
    mesh = FEMesh(nodes=nodes, elements=quads, steps=steps)
    assert isinstance(mesh.triangulation, Triangulation)
    assert mesh.triangles.shape == (18, 3)
    assert len(mesh.edges) == 24
    g = mesh.gouraud(30.0)
    assert isinstance(g, GouraudSplit) and g.added == 4
    assert mesh.gouraud(30.0) is g
    assert np.allclose(np.linalg.norm(mesh.vertex_normals(1), axis=1), 1.0)
    assert mesh.face_normals(0)[:, 2].tolist() == [1.0] * 9


def test_triangle_arrays_are_padded_and_stable_order_falls_back_for_wide_keys():
    from workbench.scene import crease

    nodes = random_coords(5, 4)
    tris = np.array([[0, 1, 2], [2, 1, 3]])
    padded = np.array([[0, 1, 2, 2], [2, 1, 3, 3]])
    assert np.array_equal(triangulate(tris, nodes).triangles, tris)
    assert np.array_equal(unique_edges(tris), unique_edges(padded))
    assert np.array_equal(element_normals(tris, nodes), element_normals(padded, nodes))
    keys = np.random.default_rng(0).integers(0, 50, 200) * 2**56  # too wide to pack
    assert np.array_equal(crease._stable_order(keys), np.argsort(keys, kind="stable"))
    narrow = keys >> 56
    assert np.array_equal(crease._stable_order(narrow), np.argsort(narrow, kind="stable"))


# --------------------------------------------------------------------------- refusals
def test_bad_input_is_refused_with_a_reason():
    nodes, quads = grid(2, 1)
    t = triangulate(quads, nodes)
    with pytest.raises(ValueError, match="elements must be"):
        unique_edges(np.zeros((3, 5), int))
    with pytest.raises(ValueError, match="integer"):
        triangulate(quads.astype(float), nodes)
    with pytest.raises(ValueError, match="negative"):
        element_normals(-quads, nodes)
    with pytest.raises(ValueError, match="reference node"):
        node_normals(quads, nodes[:3])
    bad = nodes.copy()
    bad[4, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite.*\\[4\\]"):
        element_normals(quads, bad)
    with pytest.raises(ValueError, match="crease_deg"):
        gouraud_split(quads, [nodes], 200.0, t)
    with pytest.raises(ValueError, match="at least one"):
        gouraud_split(quads, [], 30.0, t)
    with pytest.raises(ValueError, match="does not belong"):
        gouraud_split(quads[::-1].copy(), [nodes], 30.0, t)
    with pytest.raises(ValueError, match="normals|coords"):
        gouraud_split(quads, [nodes], 30.0, t).normals(nodes[:2])


def test_mesh_steps_and_coordinates_are_checked_in_one_place():
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    steps = np.stack([nodes, nodes + 1.0, nodes])
    steps[2, 3] = np.nan
    mesh = FEMesh(nodes, np.array([[0, 1, 2, 3]]), steps=steps, name="plate")
    assert [mesh.step_index(s) for s in (0, np.int64(1), 2)] == [0, 1, 2]
    for bad in (True, 1.0, 1.5, "1", None, math.nan):
        with pytest.raises(ValueError, match="reference_step must be an integer step"):
            mesh.step_index(bad, "reference_step")
    for bad in (-1, 3):
        with pytest.raises(ValueError, match=f"step {bad} out of range: plate has steps 0..2"):
            mesh.step_index(bad)
    assert np.array_equal(mesh.finite_coordinates(1), nodes + 1.0)
    with pytest.raises(ValueError, match=r"non-finite coordinates at step 2, nodes \[3\] \(1 in"):
        mesh.finite_coordinates(2)
