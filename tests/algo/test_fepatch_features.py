"""Feature edges, feature-divided patches and planar subpatches (fe2003 §3.1-3.2)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import folded, quad_grid
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from workbench.algo.fepatch.features import (
    CLOSING,
    G0,
    G1,
    SMOOTH,
    FeatureEdges,
    element_adjacency,
    feature_edges,
    patches,
    planar_subpatches,
)
from workbench.scene.derived import element_normals, unique_edges
from workbench.scene.generators import semicylinders


# ----------------------------------------------------------------------------- shapes
def grid(nx: int, ny: int, surface, triangles: bool = False):
    """Nodes surface(u, v) on an (nx+1) x (ny+1) parameter grid u, v in [0, 1]; quads (or each
    quad split into two triangles). Node (i, j) has index j * (nx + 1) + i."""
    uv, elements = quad_grid(nx, ny, span=((0, 1), (0, 1)), triangles=triangles, dim=2)
    nodes = np.stack(surface(*uv.T), axis=1).astype(np.float64)
    if triangles:
        elements = elements[:, [0, 1, 2, 2]]
    return nodes, elements.astype(np.int32)


def grid_index(nx: int, ny: int):
    """(i, j) parameter indices of each grid node."""
    k = np.arange((nx + 1) * (ny + 1))
    return k % (nx + 1), k // (nx + 1)


def edge_set(edges) -> set[tuple[int, int]]:
    return {(int(a), int(b)) for a, b in np.sort(np.asarray(edges).reshape(-1, 2), axis=1)}


def outline(edges, i, j, nx, ny) -> set[tuple[int, int]]:
    """Edges whose two nodes lie on one side of the parameter rectangle."""
    a, b = edges[:, 0], edges[:, 1]
    on = ((i[a] == i[b]) & np.isin(i[a], [0, nx])) | ((j[a] == j[b]) & np.isin(j[a], [0, ny]))
    return edge_set(edges[on])


def fold(angle_deg: float, at: float = 0.5):
    """A plate in z = 0 for u <= at that turns up by ``angle_deg`` beyond u = at."""
    def surface(u, v):
        return tuple(folded(np.c_[u, v, np.zeros_like(u)], at, angle_deg).T)
    return surface


def box(k: int):
    """Closed surface of the unit cube, k x k quads per face, nodes merged, winding as it comes."""
    nodes, elements = [], []
    for axis in range(3):
        for side in (0.0, 1.0):
            def surface(u, v, axis=axis, side=side):
                xyz = [None, None, None]
                xyz[axis] = np.full_like(u, side)
                xyz[(axis + 1) % 3], xyz[(axis + 2) % 3] = u, v
                return tuple(xyz)
            n, q = grid(k, k, surface)
            elements.append(q + sum(len(x) for x in nodes))
            nodes.append(n)
    nodes = np.concatenate(nodes)
    elements = np.concatenate(elements)
    key = np.round(nodes * k).astype(np.int64)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    return uniq / k, inverse.ravel()[elements].astype(np.int32)


def crease(fade: str):
    """A V-shaped crease along u = 0.5 whose depth fades smoothly with v: 'end' keeps it from
    v = 0 and fades it out towards v = 1; 'middle' keeps it only around v = 0.5."""
    def amplitude(v):
        if fade == "end":
            x = np.clip((v - 0.2) / 0.6, 0, 1)
            return 1 - x * x * (3 - 2 * x)
        x = np.clip(np.abs(v - 0.5) / 0.35, 0, 1)
        return 1 - x * x * (3 - 2 * x)

    def surface(u, v):
        return u, v, 0.2 * np.abs(u - 0.5) * amplitude(v)
    return surface


def brute_angle(elements, coords, alpha):
    """Kinds without closing: per unique edge, loop over elements (reference implementation)."""
    normals = element_normals(elements, coords)
    sides: dict[tuple[int, int], list[tuple[int, bool]]] = {}
    for m, el in enumerate(elements):
        for k in range(4):
            a, b = int(el[k]), int(el[(k + 1) % 4])
            if a != b:
                sides.setdefault((min(a, b), max(a, b)), []).append((m, a < b))
    out = {}
    for key, s in sides.items():
        if len(s) == 1:
            out[key] = G0
        elif len(s) >= 3:
            out[key] = G1
        else:
            (f, df), (g, dg) = s
            cos = float(normals[f] @ normals[g]) * (1 if df != dg else -1)
            zero = not normals[f].any() or not normals[g].any()
            out[key] = (G1 if not zero and np.degrees(np.arccos(np.clip(cos, -1, 1))) > alpha
                        else SMOOTH)
    return out


def components(elements, labels, value):
    """Number of edge-connected components among the elements carrying ``value``."""
    idx = np.flatnonzero(labels == value)
    indptr, indices = element_adjacency(elements[idx])
    graph = coo_matrix((np.ones(len(indices)),
                        (np.repeat(np.arange(len(idx)), np.diff(indptr)), indices)),
                       shape=(len(idx), len(idx)))
    return connected_components(graph, directed=False)[0]


def plane_deviation(coords, nodes):
    """Largest distance of the points from their least-squares plane, fitted from scratch."""
    p = coords[np.unique(nodes)]
    if len(p) <= 3:
        return 0.0
    q = p - p.mean(axis=0)
    normal = np.linalg.svd(q, full_matrices=False)[2][-1]
    return float(np.max(np.abs(q @ normal)))


def feature_degree(fe: FeatureEdges, n_nodes: int) -> np.ndarray:
    return np.bincount(fe.of_kind(G0, G1, CLOSING).ravel(), minlength=n_nodes)


# ----------------------------------------------------------------------------- feature edges
@pytest.mark.parametrize("triangles", [False, True])
def test_flat_grid_has_only_its_outline(triangles):
    nx, ny = 6, 4
    nodes, el = grid(nx, ny, lambda u, v: (3 * u, 2 * v, 0 * u), triangles)
    fe = feature_edges(el, nodes)
    i, j = grid_index(nx, ny)
    assert np.array_equal(fe.edges, unique_edges(el))
    assert edge_set(fe.of_kind(G0)) == outline(fe.edges, i, j, nx, ny)
    assert len(fe.of_kind(G0)) == 2 * (nx + ny)
    assert fe.counts()["G1"] == 0 and fe.counts()["closing"] == 0
    assert np.nanmax(fe.angle_deg) < 1e-6


@pytest.mark.parametrize("triangles", [False, True])
def test_folded_plate_marks_exactly_the_fold(triangles):
    nx, ny = 8, 5
    nodes, el = grid(nx, ny, fold(90.0), triangles)
    fe = feature_edges(el, nodes)
    i, j = grid_index(nx, ny)
    a, b = fe.edges[:, 0], fe.edges[:, 1]
    fold_line = edge_set(fe.edges[(i[a] == nx // 2) & (i[b] == nx // 2)])
    assert edge_set(fe.of_kind(G1)) == fold_line
    assert len(fold_line) == ny
    assert edge_set(fe.of_kind(G0)) == outline(fe.edges, i, j, nx, ny)
    assert fe.counts()["closing"] == 0
    np.testing.assert_allclose(fe.angle_deg[fe.kind == G1], 90.0)

    labels = patches(el, fe)
    assert labels.max() + 1 == 2
    side = (i[el[:, :3]].mean(axis=1) > nx // 2).astype(int)
    assert np.array_equal(labels, side) or np.array_equal(labels, 1 - side)
    # a plain edge array gives the same patches
    assert np.array_equal(patches(el, fe.of_kind(G0, G1, CLOSING)[:, ::-1]), labels)


def test_flipped_elements_do_not_make_creases():
    nodes, el = grid(6, 6, lambda u, v: (u, v, 0.1 * u * u))
    flipped = el.copy()
    flipped[::3] = flipped[::3, ::-1]
    assert feature_edges(flipped, nodes).counts() == feature_edges(el, nodes).counts()
    assert feature_edges(flipped, nodes).counts()["G1"] == 0


def test_box_edges_are_g1_and_nothing_is_g0():
    k = 3
    nodes, el = box(k)
    fe = feature_edges(el, nodes)
    p, q = nodes[fe.edges[:, 0]], nodes[fe.edges[:, 1]]
    on_cube_edge = ((p == q) & ((p == 0) | (p == 1))).sum(axis=1) == 2
    assert edge_set(fe.of_kind(G1)) == edge_set(fe.edges[on_cube_edge])
    assert len(fe.of_kind(G1)) == 12 * k
    assert fe.counts()["G0"] == 0 and fe.counts()["closing"] == 0
    assert patches(el, fe).max() + 1 == 6


def test_shallow_fold_below_threshold_is_not_a_feature():
    nx, ny = 8, 5
    nodes, el = grid(nx, ny, fold(8.0))
    fe = feature_edges(el, nodes, alpha_g1_deg=12.0)
    i, j = grid_index(nx, ny)
    assert fe.counts()["G1"] == 0 and fe.counts()["closing"] == 0
    assert edge_set(fe.of_kind(G0)) == outline(fe.edges, i, j, nx, ny)
    assert patches(el, fe).max() == 0
    # the same fold is G1 under a lower threshold
    assert len(feature_edges(el, nodes, 5.0).of_kind(G1)) == ny


def test_non_manifold_edge_is_g1():
    nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], float)
    el = np.array([[0, 1, 2, 2], [1, 0, 3, 3], [0, 1, 4, 4]], np.int32)
    fe = feature_edges(el, nodes, close_lines=False)
    assert edge_set(fe.of_kind(G1)) == {(0, 1)}
    assert fe.n_adjacent[fe.kind == G1].tolist() == [3]


@pytest.mark.parametrize("fade", ["end", "middle"])
def test_dangling_crease_is_closed_to_the_boundary(fade):
    n = 24
    nodes, el = grid(n, n, crease(fade))
    open_fe = feature_edges(el, nodes, close_lines=False)
    degree = feature_degree(open_fe, len(nodes))
    dangling = np.flatnonzero(degree == 1)
    assert len(dangling) == (1 if fade == "end" else 2)         # the shape does what it should

    fe = feature_edges(el, nodes)
    assert np.array_equal(fe.kind[fe.kind != CLOSING], open_fe.kind[fe.kind != CLOSING])
    assert edge_set(fe.of_kind(G1)) == edge_set(open_fe.of_kind(G1))
    assert not np.any(feature_degree(fe, len(nodes)) == 1)
    closing = fe.of_kind(CLOSING)
    assert 0 < len(closing) <= (n if fade == "end" else 2 * n)
    # the crease with its closing edges is one simple path between two boundary nodes
    line = fe.of_kind(G1, CLOSING)
    deg = np.bincount(line.ravel(), minlength=len(nodes))
    ends = np.flatnonzero(deg == 1)
    boundary = np.unique(fe.of_kind(G0))
    assert len(ends) == 2 and np.isin(ends, boundary).all()
    assert deg.max() <= 2
    graph = coo_matrix((np.ones(len(line)), (line[:, 0], line[:, 1])), shape=(len(nodes),) * 2)
    _, comp = connected_components(graph, directed=False)
    assert comp[ends[0]] == comp[ends[1]] == comp[dangling[0]]
    # closing leaves no open G1 lines and cuts the plate into two patches
    assert patches(el, fe).max() + 1 == 2
    assert patches(el, open_fe).max() + 1 == 1


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(2.0, 40.0), st.booleans())
def test_kinds_match_a_brute_force_reference(seed, alpha, triangles):
    rng = np.random.default_rng(seed)
    nodes, el = grid(5, 4, lambda u, v: (u, v, 0 * u), triangles)
    nodes[:, 2] = rng.normal(0.0, 0.08, len(nodes))
    flip = rng.random(len(el)) < 0.3
    el[flip] = np.where(el[flip, 3:4] == el[flip, 2:3], el[flip][:, [2, 1, 0, 0]],
                        el[flip][:, ::-1])
    fe = feature_edges(el, nodes, alpha, close_lines=False)
    ref = brute_angle(el, nodes, alpha)
    assert {(int(a), int(b)): int(k) for (a, b), k in zip(fe.edges, fe.kind)} == ref
    # closing only adds edges and leaves no dangling end
    closed = feature_edges(el, nodes, alpha)
    assert np.array_equal(closed.kind[closed.kind != CLOSING], fe.kind[closed.kind != CLOSING])
    assert not np.any(feature_degree(closed, len(nodes)) == 1)
    # patches: two elements share a label exactly when a path of smooth edges joins them
    labels = patches(el, closed)
    for (a, b), k in zip(closed.edges, closed.kind):
        on = np.flatnonzero((el == a).any(axis=1) & (el == b).any(axis=1))
        if k == SMOOTH:
            assert len(set(labels[on].tolist())) == 1


def test_bad_input_is_refused():
    nodes, el = grid(2, 2, lambda u, v: (u, v, 0 * u))
    with pytest.raises(ValueError, match="alpha"):
        feature_edges(el, nodes, 200.0)
    with pytest.raises(ValueError):
        feature_edges(el, nodes[:3])
    with pytest.raises(ValueError, match="not element edges"):
        patches(el, np.array([[0, 8]]))
    with pytest.raises(ValueError, match="d must be"):
        planar_subpatches(el, nodes, np.zeros(len(el), int), -1.0)
    with pytest.raises(ValueError, match="patch_labels"):
        planar_subpatches(el, nodes, np.zeros(len(el) + 1, int), 0.1)


# ----------------------------------------------------------------------------- subpatches
def check_subpatches(el, nodes, patch, sub, d):
    assert sub.shape == (len(el),) and sub.min() == 0
    assert np.array_equal(np.unique(sub), np.arange(sub.max() + 1))
    for s in range(sub.max() + 1):
        members = np.flatnonzero(sub == s)
        assert len(np.unique(patch[members])) == 1, "a subpatch crosses patches"
        assert components(el, sub, s) == 1, f"subpatch {s} is not connected"
        if len(members) > 1:
            assert plane_deviation(nodes, el[members]) <= d * (1 + 1e-9) + 1e-12


@pytest.mark.parametrize("triangles", [False, True])
def test_flat_plate_is_one_subpatch(triangles):
    nodes, el = grid(7, 5, lambda u, v: (400 + 3 * u, 2 * v, 5 + u + v), triangles)
    sub = planar_subpatches(el, nodes, np.zeros(len(el), int), 1e-9)
    assert np.all(sub == 0)


def test_cylinder_splits_into_planar_strips():
    mesh = semicylinders(sheets=1, n=12, radius=100.0)
    zeros = np.zeros(mesh.n_elements, int)
    tiny = planar_subpatches(mesh.elements, mesh.nodes, zeros, 1e-6)
    # each column of quads along the axis is planar, two neighbouring columns are not
    assert tiny.max() + 1 == 12
    check_subpatches(mesh.elements, mesh.nodes, zeros, tiny, 1e-6)
    coarse = planar_subpatches(mesh.elements, mesh.nodes, zeros, 3.0)
    assert 1 < coarse.max() + 1 < 12
    check_subpatches(mesh.elements, mesh.nodes, zeros, coarse, 3.0)
    assert planar_subpatches(mesh.elements, mesh.nodes, zeros, 1000.0).max() == 0


def test_subpatches_respect_patches_on_a_folded_plate():
    nodes, el = grid(8, 5, fold(90.0))
    patch = patches(el, feature_edges(el, nodes))
    sub = planar_subpatches(el, nodes, patch, 1e-6)
    assert sub.max() + 1 == 2
    check_subpatches(el, nodes, patch, sub, 1e-6)
    # without the patch cut, a d larger than the plate spans the fold
    one = planar_subpatches(el, nodes, np.zeros(len(el), int), 10.0)
    assert one.max() == 0


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(1e-3, 0.2), st.booleans())
def test_subpatch_properties_on_random_bumpy_plates(seed, d, triangles):
    rng = np.random.default_rng(seed)
    nodes, el = grid(6, 5, lambda u, v: (u, v, 0 * u), triangles)
    nodes[:, 2] = (0.2 * np.sin(3 * nodes[:, 0] + rng.uniform(0, 6))
                   + rng.normal(0, 0.01, len(nodes)))
    patch = patches(el, feature_edges(el, nodes, 20.0))
    sub = planar_subpatches(el, nodes, patch, d)
    check_subpatches(el, nodes, patch, sub, d)


def test_car_deck(car):
    fe = feature_edges(car.elements, car.nodes)
    counts = fe.counts()
    assert counts["G0"] > 0 and counts["G1"] > 0
    assert not np.any(feature_degree(fe, car.n_nodes) == 1)
    patch = patches(car.elements, fe)
    assert 1 < patch.max() + 1 < car.n_elements
    diag = float(np.linalg.norm(np.subtract(*car.bounds())))
    d = 1e-3 * diag
    sub = planar_subpatches(car.elements, car.nodes, patch, d)
    assert sub.max() + 1 >= patch.max() + 1
    check_subpatches(car.elements, car.nodes, patch, sub, d)
