"""The element hierarchy (AABB and OBB, one or several elements per leaf): structure, boxes that
enclose their elements, OBB frames of planar parts, nearest-element and plane queries against
brute force, refusals."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.algo.nearest.hierarchy import ElementHierarchy, squared_bound
from workbench.algo.nearest.triangle import points_triangles_distance
from workbench.scene.mesh import FEMesh

KINDS = ("aabb", "obb")


# --------------------------------------------------------------------------- random meshes
def _frame(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q


def random_mesh(seed: int, n_parts: int = 3, *, touching=False, coplanar=False, shared=False,
                degenerate=False, single=False, unused=False, bumps=0.1, size=2.0) -> FEMesh:
    """Random curved grid patches, one part each, quads with some split into stored triangles.

    ``touching``: a part moved so that one of its nodes sits exactly on a node of the previous
    part (distinct node indices, distance 0); ``coplanar``: a part that is a flat copy of the
    previous flat part, shifted within its plane (overlapping, coplanar); ``shared``: an
    element of one part using nodes of another (nodes of two parts); ``degenerate``: elements
    with repeated nodes (no triangle), collinear and coincident nodes (zero area);
    ``single``: a part of one element; ``unused``: nodes no element uses.
    """
    rng = np.random.default_rng(seed)
    nodes, elements, parts = [], [], []

    def add_nodes(pts):
        start = sum(len(n) for n in nodes)
        nodes.append(np.asarray(pts, float).reshape(-1, 3))
        return start + np.arange(len(nodes[-1]))

    def patch(part, flat=False, template=None):
        nx, ny = rng.integers(1, 4, size=2)
        if template is None:
            f = _frame(rng)
            o = rng.uniform(-size, size, 3)
            h = rng.uniform(0.3, 1.0, 2)
        else:
            f, o, h, nx, ny = template
            o = o + f[0] * rng.uniform(-0.5, 0.5) * h[0] + f[1] * rng.uniform(-0.5, 0.5) * h[1]
        i, j = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="ij")
        pts = (o + i.ravel()[:, None] * h[0] * f[0] + j.ravel()[:, None] * h[1] * f[1])
        if not flat:
            pts = pts + bumps * rng.normal(size=(len(pts), 1)) * f[2]
        ids = add_nodes(pts).reshape(nx + 1, ny + 1)
        for a in range(nx):
            for b in range(ny):
                q = [ids[a, b], ids[a + 1, b], ids[a + 1, b + 1], ids[a, b + 1]]
                if rng.random() < 0.3:
                    elements.append([q[0], q[1], q[2], q[2]])
                    elements.append([q[0], q[2], q[3], q[3]])
                    parts.extend([part, part])
                else:
                    elements.append(q)
                    parts.append(part)
        return (f, o, h, nx, ny), ids

    templates = []
    for p in range(n_parts):
        flat = coplanar and p == 0
        tpl = templates[-1][0] if (coplanar and p == 1) else None
        t, ids = patch(10 + p, flat=flat or tpl is not None, template=tpl)
        templates.append((t, ids))
        if touching and p >= 1 and not (coplanar and p == 1):
            # move this part so that its first node sits on a node of the previous part
            prev_ids = templates[-2][1].ravel()
            target = np.concatenate(nodes)[prev_ids[rng.integers(len(prev_ids))]]
            allpts = np.concatenate(nodes)
            shift = target - allpts[ids.ravel()[0]]
            nodes[-1] = nodes[-1] + shift
            nodes[-1][0] = target  # exactly, whatever the rounding of the shift
    allpts = np.concatenate(nodes)
    if shared and n_parts >= 2:
        a_ids = templates[0][1].ravel()
        new = add_nodes(allpts[a_ids[:2]] + rng.normal(size=(2, 3)) * 0.3)
        elements.append([a_ids[0], a_ids[1], new[0], new[1]])
        parts.append(11)  # nodes a_ids[0], a_ids[1] now belong to parts 10 and 11
    if single:
        pts = rng.uniform(-size, size, (1, 3)) + rng.normal(size=(3, 3)) * 0.5
        ids = add_nodes(pts)
        elements.append([ids[0], ids[1], ids[2], ids[2]])
        parts.append(99)
    if degenerate:
        allpts = np.concatenate(nodes)
        k = len(allpts)
        i0, i1 = rng.integers(k, size=2)
        elements.append([i0, i0, i1, i1])  # a segment: no triangle
        parts.append(10 + int(rng.integers(n_parts)))
        elements.append([i1, i1, i1, i1])  # a point: no triangle
        parts.append(10 + int(rng.integers(n_parts)))
        start = rng.uniform(-size, size, 3)
        d = rng.normal(size=3)
        line = add_nodes(start + np.outer([0.0, 0.3, 0.7, 1.0], d))  # collinear quad
        elements.append(list(line))
        parts.append(10 + int(rng.integers(n_parts)))
        same = add_nodes(np.repeat(rng.uniform(-size, size, (1, 3)), 3, axis=0))  # coincident
        elements.append([same[0], same[1], same[2], same[2]])
        parts.append(10 + int(rng.integers(n_parts)))
    if unused:
        add_nodes(rng.uniform(-size, size, (2, 3)))
    return FEMesh(nodes=np.concatenate(nodes), elements=np.array(elements, np.int64),
                  parts=np.array(parts, np.int32))


mesh_options = st.fixed_dictionaries({
    "seed": st.integers(0, 10**6), "n_parts": st.integers(1, 4), "touching": st.booleans(),
    "coplanar": st.booleans(), "shared": st.booleans(), "degenerate": st.booleans(),
    "single": st.booleans(), "unused": st.booleans()})


def element_triangles(mesh, e):
    tr = mesh.triangulation
    return mesh.nodes[tr.triangles[tr.element_of == e]]


# --------------------------------------------------------------------------- structure
def nodes_per_tree(n, leaf):
    return 1 if n <= leaf else 1 + nodes_per_tree(n // 2, leaf) + nodes_per_tree(n - n // 2, leaf)


@settings(max_examples=30, deadline=None)
@given(mesh_options, st.sampled_from(KINDS), st.sampled_from([1, 2, 10]))
def test_structure_partitions_the_elements_and_boxes_enclose_them(options, kind, leaf):
    mesh = random_mesh(**options)
    h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf)
    assert sorted(h.element_order.tolist()) == list(range(mesh.n_elements))
    # part trees: median splits, leaves of at most leaf_size elements of one part
    for part in h.part_ids:
        n = int((mesh.parts == part).sum())
        assert len(h.part_nodes(part)) == nodes_per_tree(n, leaf)
    assert h.n_bvs == sum(nodes_per_tree(int((mesh.parts == p).sum()), leaf) for p in h.part_ids)
    assert h.n_top_bvs == h.n_parts - 1
    leaf_nodes = np.flatnonzero(h.left < 0)
    assert (h.end[leaf_nodes] - h.start[leaf_nodes] <= leaf).all()
    assert (h.node_part[leaf_nodes] >= 0).all()
    for i in np.flatnonzero(h.left >= 0):
        a, b = h.left[i], h.right[i]
        assert h.start[a] == h.start[i] and h.end[a] == h.start[b] and h.end[b] == h.end[i]
        if h.node_part[i] >= 0:  # median split within a part
            assert abs((h.end[a] - h.start[a]) - (h.end[b] - h.start[b])) <= 1
    for q, root in enumerate(h.part_roots):
        members = h.element_order[h.start[root]:h.end[root]]
        assert (mesh.parts[members] == h.part_ids[q]).all()
    # every box encloses its elements' nodes
    centres, axes, half = h.boxes()
    assert np.allclose(np.einsum("nij,nkj->nik", axes, axes), np.eye(3), atol=1e-12)
    for i in range(h.n_nodes):
        members = h.element_order[h.start[i]:h.end[i]]
        pts = mesh.nodes[mesh.elements[members].ravel()]
        t = (pts - centres[i]) @ axes[i].T
        assert (np.abs(t) <= half[i] + 1e-12).all()


def test_more_elements_per_leaf_means_fewer_bvs_and_kinds_agree_on_the_count():
    mesh = random_mesh(5, 4)
    counts = {}
    for kind in KINDS:
        for leaf in (1, 2, 10):
            counts[kind, leaf] = ElementHierarchy(mesh, kind=kind, leaf_size=leaf).n_bvs
    for leaf in (1, 2, 10):
        assert counts["aabb", leaf] == counts["obb", leaf]
    assert counts["aabb", 1] == 2 * mesh.n_elements - len(np.unique(mesh.parts))
    assert counts["aabb", 1] > counts["aabb", 2] > counts["aabb", 10]


@pytest.mark.parametrize("leaf", [1, 10])
def test_obb_frames_of_a_planar_part_lie_in_its_plane(leaf):
    rng = np.random.default_rng(3)
    f = _frame(rng)
    normal = f[2]
    n = 12
    uv, quads = quad_grid(n, n, cell=(1.0, 0.7), jitter=0.2, seed=rng, ij=True, dim=2)
    pts = np.array([1e3, -2e3, 5e2]) + uv @ f[:2]
    # a degenerate element (two nodes) and a zero-area collinear one in the same plane
    elements = np.concatenate([quads, [[0, 0, 1, 1], [0, 1, 2, 2]]])
    mesh = FEMesh(nodes=pts, elements=elements)
    h = ElementHierarchy(mesh, kind="obb", leaf_size=leaf)
    centres, axes, half = h.boxes()
    size = np.ptp(pts, axis=0).max()
    for k in range(h.n_nodes):
        along = np.abs(axes[k] @ normal)
        a = int(np.argmax(along))
        assert along[a] > 1 - 1e-9, (k, along)
        assert half[k, a] <= 1e-9 * size
        others = np.delete(along, a)
        assert (others < 1e-9).all()
        assert abs((centres[k] - pts[0]) @ normal) <= 1e-9 * size
    # the root's in-plane axes are those of the part's shape: the major axis along the longer
    # side (12 × 1.0 against 12 × 0.7)
    assert abs(axes[h.root, 0] @ f[0]) > 0.99


def test_obb_of_a_tilted_plate_is_tighter_than_its_aabb():
    rng = np.random.default_rng(8)
    f = _frame(rng)
    n = 10
    plane, quads = quad_grid(n, n, ij=True, dim=2)
    pts = plane @ f[:2] * 1.0
    mesh = FEMesh(nodes=pts, elements=quads)
    vol = {}
    for kind in KINDS:
        h = ElementHierarchy(mesh, kind=kind)
        _, _, half = h.boxes()
        vol[kind] = np.prod(2 * half[h.root])
    assert vol["obb"] < 1e-6 * vol["aabb"]


# --------------------------------------------------------------------------- nearest
def brute_nearest(mesh, points, cutoff, exclude_parts):
    tr = mesh.triangulation
    if tr.n_triangles == 0:
        return np.full(len(points), np.inf)
    d = points_triangles_distance(points, mesh.nodes[tr.triangles])
    tri_part = mesh.parts[tr.element_of]
    for i, ex in enumerate(exclude_parts):
        d[i, np.isin(tri_part, ex)] = np.inf
    best = d.min(axis=1)
    return np.where(best <= cutoff, best, np.inf)


@settings(max_examples=30, deadline=None)
@given(mesh_options, st.sampled_from(KINDS), st.sampled_from([1, 3, 10]),
       st.sampled_from([0.3, 1.0, np.inf]), st.booleans())
def test_nearest_with_excluded_parts_matches_brute_force(options, kind, leaf, cutoff, plane):
    mesh = random_mesh(**options)
    rng = np.random.default_rng(options["seed"] + 1)
    points = np.concatenate([rng.uniform(-3, 3, (20, 3)), mesh.nodes[:10]])
    ids = np.unique(mesh.parts)
    exclude = [ids[rng.random(len(ids)) < 0.4] for _ in points]
    ptr = np.concatenate([[0], np.cumsum([len(e) for e in exclude])])
    flat = np.concatenate(exclude + [np.zeros(0, np.int64)]).astype(np.int64)
    # the hierarchy's origin is the brute force's origin (0): bitwise the same local coordinates
    h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf, origin=np.zeros(3))
    r = h.nearest(points, cutoff, exclude=(ptr, flat), plane_test=plane)
    expected = brute_nearest(mesh, points, cutoff, exclude)
    np.testing.assert_allclose(r.distance, expected, rtol=1e-12, atol=0)
    found = np.isfinite(r.distance)
    assert ((r.element >= 0) == found).all() and ((r.part >= 0) == found).all()
    for i in np.flatnonzero(found):  # the element named is at that distance, not excluded
        e = r.element[i]
        assert mesh.parts[e] == r.part[i] and r.part[i] not in exclude[i]
        d = points_triangles_distance(points[i:i + 1], element_triangles(mesh, e)).min()
        assert d == r.distance[i]
    assert r.element_tests + r.plane_skips == r.leaf_elements
    if not plane:
        assert r.plane_skips == 0


@settings(max_examples=20, deadline=None)
@given(mesh_options, st.sampled_from(KINDS), st.sampled_from([1, 10]))
def test_nearest_per_part_matches_brute_force(options, kind, leaf):
    mesh = random_mesh(**options)
    rng = np.random.default_rng(options["seed"] + 2)
    points = rng.uniform(-3, 3, (15, 3))
    h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf, origin=np.zeros(3))
    point, part, dist = h.nearest_per_part(points, 1.5)
    got = {(int(i), int(p)): d for i, p, d in zip(point, part, dist)}
    tr = mesh.triangulation
    d = points_triangles_distance(points, mesh.nodes[tr.triangles])
    tri_part = mesh.parts[tr.element_of]
    expected = {}
    for p in np.unique(tri_part):
        best = d[:, tri_part == p].min(axis=1)
        for i in np.flatnonzero(best <= 1.5):
            expected[int(i), int(p)] = best[i]
    assert got.keys() == expected.keys()
    for key, value in expected.items():
        assert got[key] == pytest.approx(value, rel=1e-12, abs=0)


def test_cutoff_is_inclusive():
    # two parallel unit squares exactly 1 apart
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    mesh = FEMesh(nodes=np.concatenate([pts, pts + [0, 0, 1]]),
                  elements=[[0, 1, 2, 3], [4, 5, 6, 7]], parts=[1, 2])
    for kind in KINDS:
        h = ElementHierarchy(mesh, kind=kind)
        ptr = np.arange(9)  # every point excludes its own part
        own = np.repeat([1, 2], 4)
        r = h.nearest(mesh.nodes, 1.0, exclude=(ptr, own))
        assert (r.distance == 1.0).all()
        r = h.nearest(mesh.nodes, float(np.nextafter(1.0, 0.0)), exclude=(ptr, own))
        assert np.isinf(r.distance).all() and (r.part == -1).all()
    assert np.sqrt(squared_bound(1.5)) <= 1.5 < np.sqrt(np.nextafter(squared_bound(1.5), 9))


def test_active_mask_and_only_degenerate_elements():
    mesh = random_mesh(2, 2)
    h = ElementHierarchy(mesh)
    pts = mesh.nodes.copy()
    pts[0] = np.nan
    active = np.ones(len(pts), bool)
    active[0] = False
    r = h.nearest(pts, 10.0, active=active)
    assert np.isinf(r.distance[0]) and r.element[0] == -1 and np.isfinite(r.distance[1:]).all()
    with pytest.raises(ValueError, match="non-finite"):
        h.nearest(pts, 10.0)
    # elements without triangles are enclosed (for plane cuts) but never nearest
    seg = FEMesh(nodes=[[0, 0, 0], [1, 0, 0]], elements=[[0, 0, 1, 1]])
    hs = ElementHierarchy(seg)
    assert np.isinf(hs.nearest([[0.5, 0, 0]], 5.0).distance).all()
    assert hs.cut_by_plane([0.5, 0, 0], [1, 0, 0]).tolist() == [0]


# --------------------------------------------------------------------------- plane cuts
def brute_cut(mesh, point, normal):
    d = mesh.nodes - np.asarray(point, float)
    n = np.asarray(normal, float)
    s = d[:, 0] * n[0] + d[:, 1] * n[1] + d[:, 2] * n[2]
    se = s[mesh.elements]
    return np.flatnonzero(~((se > 0).all(axis=1) | (se < 0).all(axis=1)))


@settings(max_examples=40, deadline=None)
@given(mesh_options, st.sampled_from(KINDS), st.sampled_from([1, 4, 10]), st.integers(0, 10**6),
       st.booleans(), st.sampled_from([0.0, 1e6]))
def test_cut_by_plane_matches_signed_distance_test(options, kind, leaf, seed, through_node, shift):
    mesh = random_mesh(**options)
    if shift:
        mesh = mesh.translated([shift, -shift, 0.5 * shift])
    rng = np.random.default_rng(seed)
    h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf)
    for _ in range(5):
        if through_node:  # a plane through a node, axis-aligned: s is exactly 0 there
            point = mesh.nodes[rng.integers(mesh.n_nodes)]
            normal = np.eye(3)[rng.integers(3)] * rng.choice([-2.0, 0.5])
        else:
            point = mesh.nodes.mean(axis=0) + rng.normal(size=3)
            normal = rng.normal(size=3)
        got = h.cut_by_plane(point, normal)
        assert got.dtype == np.int64
        np.testing.assert_array_equal(got, brute_cut(mesh, point, normal))


def test_cut_by_plane_visits_only_boxes_the_plane_meets():
    # a long strip of 200 quads along x: a plane x = const cuts one or two elements; the cut
    # is found in far fewer steps than there are elements
    n = 200
    x = np.arange(n + 1, dtype=float)
    pts = np.concatenate([np.stack([x, np.zeros_like(x), np.zeros_like(x)], 1),
                          np.stack([x, np.ones_like(x), np.zeros_like(x)], 1)])
    quads = np.stack([np.arange(n), np.arange(1, n + 1), np.arange(n + 2, 2 * n + 2),
                      np.arange(n + 1, 2 * n + 1)], 1)
    mesh = FEMesh(nodes=pts, elements=quads)
    for kind in KINDS:
        h = ElementHierarchy(mesh, kind=kind)
        assert h.cut_by_plane([10.5, 0, 0], [1, 0, 0]).tolist() == [10]
        assert h.cut_by_plane([10.0, 0, 0], [1, 0, 0]).tolist() == [9, 10]
        assert h.cut_by_plane([-1.0, 0, 0], [1, 0, 0]).tolist() == []
        assert h.cut_by_plane([0, 0.5, 0], [0, 1, 0]).tolist() == list(range(n))


# --------------------------------------------------------------------------- refusals
def test_refusals():
    mesh = random_mesh(1, 2)
    with pytest.raises(ValueError, match="kind"):
        ElementHierarchy(mesh, kind="sphere")
    for bad in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="leaf_size"):
            ElementHierarchy(mesh, leaf_size=bad)
    with pytest.raises(ValueError, match="step"):
        ElementHierarchy(mesh, step=1)
    with pytest.raises(ValueError, match="at least one element"):
        ElementHierarchy(mesh, elements=np.zeros(0, np.int64))
    with pytest.raises(ValueError, match="repeat"):
        ElementHierarchy(mesh, elements=[0, 0])
    with pytest.raises(ValueError, match="elements must lie"):
        ElementHierarchy(mesh, elements=[mesh.n_elements])
    with pytest.raises(ValueError, match="origin"):
        ElementHierarchy(mesh, origin=[0, np.nan, 0])
    steps = np.stack([mesh.nodes, mesh.nodes])
    steps[1, mesh.elements[0, 0]] = np.inf
    moving = FEMesh(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts, steps=steps)
    ElementHierarchy(moving, step=0)
    with pytest.raises(ValueError, match="non-finite"):
        ElementHierarchy(moving, step=1)
    h = ElementHierarchy(mesh)
    with pytest.raises(ValueError, match="normal"):
        h.cut_by_plane([0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="normal"):
        h.cut_by_plane([0, 0, 0], [0, np.nan, 1])
    with pytest.raises(ValueError, match="point"):
        h.cut_by_plane([0, np.inf, 0], [0, 0, 1])
    with pytest.raises(ValueError, match="cutoff"):
        h.nearest(mesh.nodes, 0.0)
    with pytest.raises(ValueError, match="cutoff"):
        h.nearest(mesh.nodes, np.nan)
    with pytest.raises(ValueError, match="points"):
        h.nearest(mesh.nodes[:, :2], 1.0)
    with pytest.raises(ValueError, match="exclude"):
        h.nearest(mesh.nodes, 1.0, exclude=(np.zeros(3, np.int64), np.zeros(0, np.int64)))
