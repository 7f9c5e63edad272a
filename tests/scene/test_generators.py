"""Scene generators: the es2008 semicylinders, stamped sheet-metal parts, k×k refinement, crash
steps."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from workbench.scene import FEMesh, MeshError
from workbench.scene.generators import (
    crash_sequence,
    refine,
    semicylinders,
    stamped_panel,
    stamped_panels,
)

PAPER_SIZES = (2215, 26284, 51473, 104749, 255641)  # crash2000 Table 1, #quads


# --------------------------------------------------------------------------- brute-force references
def element_edges(elements: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed edges (start, end) of every element, three for triangles, four for quads."""
    edges = []
    for e in elements.tolist():
        ring = e[:3] if e[3] == e[2] else e
        edges += [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
    edges = np.array(edges, np.int64)
    return edges[:, 0], edges[:, 1]


def edge_use(elements: np.ndarray) -> dict[tuple[int, int], int]:
    a, b = element_edges(elements)
    keys, counts = np.unique(np.stack([np.minimum(a, b), np.maximum(a, b)], 1), axis=0,
                             return_counts=True)
    return {tuple(k): int(c) for k, c in zip(keys.tolist(), counts)}


def normals(elements: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    p = nodes[elements]
    n = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    tri = elements[:, 3] == elements[:, 2]
    n[tri] = np.cross(p[tri, 1] - p[tri, 0], p[tri, 2] - p[tri, 0])
    return n


def areas(elements: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Exact areas of planar quads and of triangles."""
    return 0.5 * np.linalg.norm(normals(elements, nodes), axis=1)


def bilinear(corners: np.ndarray, s, t) -> np.ndarray:
    p0, p1, p2, p3 = corners
    return (1 - s) * (1 - t) * p0 + s * (1 - t) * p1 + s * t * p2 + (1 - s) * t * p3


def boundary_loops(mesh: FEMesh) -> dict[int, int]:
    """Number of boundary loops (connected sets of edges used once) in each part."""
    loops = {}
    for part in np.unique(mesh.parts):
        sub = mesh.part(int(part))
        once = np.array([k for k, c in edge_use(sub.elements).items() if c == 1])
        graph = coo_matrix((np.ones(len(once)), (once[:, 0], once[:, 1])), shape=(sub.n_nodes,) * 2)
        n, labels = connected_components(graph, directed=False)
        loops[int(part)] = len(np.unique(labels[np.unique(once)]))
    return loops


def jittered_grid(nx: int, ny: int, jitter: float = 0.0, z_jitter: float = 0.0,
                  seed: int = 0) -> FEMesh:
    """An nx × ny grid of 10 mm quads, nodes moved by up to ``jitter`` and ``z_jitter`` cells,
    elements in random parts 0..2."""
    rng = np.random.default_rng(seed)
    nodes, elements = quad_grid(nx, ny, cell=10.0)
    nodes[:, :2] += rng.uniform(-jitter, jitter, (len(nodes), 2)) * 10.0
    nodes[:, 2] += rng.uniform(-z_jitter, z_jitter, len(nodes)) * 10.0
    return FEMesh(nodes=nodes, elements=elements, parts=rng.integers(0, 3, len(elements)))


# --------------------------------------------------------------------------- semicylinders
def test_semicylinders_counts_at_default_size():
    m = semicylinders()
    assert m.n_elements == m.n_quads == 8 * 250 * 250
    assert 2 * m.n_quads == 1_000_000          # triangles of the es2008 benchmark
    assert m.n_nodes == 8 * 251 * 251
    assert np.array_equal(np.bincount(m.parts), np.full(8, 250 * 250))


@pytest.mark.parametrize("sheets,n", [(1, 1), (3, 4), (8, 6)])
def test_semicylinders_small_counts(sheets, n):
    m = semicylinders(sheets=sheets, n=n)
    assert m.n_quads == sheets * n * n and m.n_elements == sheets * n * n
    assert m.n_nodes == sheets * (n + 1) ** 2
    assert len(m.used_nodes()) == m.n_nodes
    assert sorted(np.unique(m.parts)) == list(range(sheets))
    # each sheet conforming: interior edges used twice, 4n boundary edges
    for k in range(sheets):
        uses = np.array(list(edge_use(m.part(k).elements).values()))
        assert set(uses) <= {1, 2} and (uses == 1).sum() == 4 * n


def test_semicylinders_sheets_are_depth_ordered_and_do_not_intersect():
    radius, spacing = 50.0, 4.0
    m = semicylinders(sheets=5, n=12, radius=radius, spacing=spacing)
    rng = np.random.default_rng(1)
    xs = rng.uniform(-radius, radius, 500)
    depth = []
    for k in range(5):
        p = m.part(k).nodes
        # every quad is planar and spans a straight x–z segment: the sheet is a height field z(x)
        row = p[np.isclose(p[:, 1], p[:, 1].min())]
        row = row[np.argsort(row[:, 0])]
        assert np.all(np.diff(row[:, 0]) > 0)
        depth.append(np.interp(xs, row[:, 0], row[:, 2]))
        lo, hi = m.part(k).bounds()
        assert np.allclose([lo[0], hi[0], hi[1] - lo[1]], [-radius, radius, 2 * radius])
    depth = np.array(depth)
    gaps = depth[:-1] - depth[1:]
    assert np.all(gaps > 0.999 * spacing - 1e-9)    # sheet k+1 strictly behind sheet k everywhere
    # front-facing: counter-clockwise seen from +z
    assert np.all(normals(m.elements, m.nodes)[:, 2] > -1e-9)
    assert normals(m.elements, m.nodes)[:, 2].sum() > 0


def test_semicylinders_field_is_distance_to_each_sheet_centre():
    n = 10
    m = semicylinders(sheets=3, n=n, radius=20.0, spacing=3.0)
    d = m.node_field("distance")
    for k in range(3):
        used = np.unique(m.elements[m.parts == k])
        p = m.nodes[used]
        # the sheet's centre: the middle node of its grid (apex of the arc, half height)
        centre = m.nodes[k * (n + 1) ** 2 + (n // 2) * (n + 1) + n // 2]
        assert np.isclose(centre[0], 0.0) and np.isclose(centre[1], 0.0)
        assert np.isclose(centre[2], p[:, 2].max())
        assert np.allclose(d[used], np.linalg.norm(p - centre, axis=1))
    assert d.min() == 0.0 and d.max() > 20.0


def test_semicylinders_refuses_bad_sizes():
    with pytest.raises(ValueError):
        semicylinders(n=0)
    with pytest.raises(ValueError):
        semicylinders(sheets=2, radius=-1.0)


# --------------------------------------------------------------------------- stamped panels
@pytest.fixture(scope="module")
def paper_models():
    return {target: stamped_panels(target) for target in PAPER_SIZES}


def test_stamped_panels_hit_the_paper_quad_counts(paper_models):
    for target, m in paper_models.items():
        assert abs(m.n_quads - target) <= 0.01 * target, (target, m.n_quads)
        share = m.is_triangle.mean()
        assert 0.01 <= share <= 0.06, (target, share)
        assert len(np.unique(m.parts)) >= 2


@pytest.mark.parametrize("target,seed", [(3000, 1), (12000, 2), (40000, 3)])
def test_stamped_panels_other_targets_and_seeds(target, seed):
    m = stamped_panels(target, seed=seed)
    assert abs(m.n_quads - target) <= 0.01 * target
    assert 0.01 <= m.is_triangle.mean() <= 0.06


@pytest.mark.parametrize("target,seed", [(2215, 1), (8000, 5)])
def test_stamped_panels_have_holes_creases_and_a_clean_conforming_surface(target, seed):
    m = stamped_panels(target, seed=seed)
    uses = edge_use(m.elements)
    assert set(uses.values()) <= {1, 2}                      # manifold edges
    # every part has its outer boundary plus at least one hole (inner boundary loop)
    assert all(n >= 2 for n in boundary_loops(m).values())
    # boundary loops never touch: every boundary node has exactly two boundary edges
    once = np.array([k for k, c in uses.items() if c == 1])
    assert np.all(np.bincount(once.ravel())[np.unique(once)] == 2)
    # consistent winding: an interior edge is walked once in each direction
    a, b = element_edges(m.elements)
    directed = np.unique(np.stack([a, b], 1), axis=0)
    assert len(directed) == len(a)
    # creases: elements across an interior edge with normals more than 60° apart (flange bends)
    n = normals(m.elements, m.nodes)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    elem_of_edge = np.repeat(np.arange(m.n_elements), np.where(m.is_triangle, 3, 4))
    key = np.minimum(a, b) * m.n_nodes + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    k, e = key[order], elem_of_edge[order]
    pair = k[1:] == k[:-1]
    cos = np.sum(n[e[1:][pair]] * n[e[:-1][pair]], axis=1)
    sharp = int((cos < np.cos(np.radians(60))).sum())
    assert sharp >= 4 * len(np.unique(m.parts)) * 5  # four bend lines per part, many edges each
    assert np.all(areas(m.elements, m.nodes) > 0)


def test_stamped_panels_parts_face_each_other_across_the_flange_gap():
    m = stamped_panels(6000, parts=4, seed=2, gap=1.5)
    owner = np.empty(m.n_nodes, int)
    for c in range(4):
        owner[m.elements[:, c]] = m.parts
    close = np.zeros(m.n_nodes, bool)
    for part in range(4):
        mine = owner == part
        dist, _ = cKDTree(m.nodes[~mine]).query(m.nodes[mine])
        assert dist.min() >= 1.5 - 1e-9                      # parts never touch or cross
        close[mine] = dist <= 2.0
    assert 0.01 < close.mean() < 0.3                         # crash2000 "potential flanges"
    for part in range(4):
        lo, hi = m.part(part).bounds()
        assert np.all((hi - lo)[:2] > 200) and np.all((hi - lo)[:2] < 900)   # car-part sizes, mm


def test_stamped_panels_fields_and_determinism():
    a = stamped_panels(5000, seed=7)
    b = stamped_panels(5000, seed=7)
    c = stamped_panels(5000, seed=8)
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.elements, b.elements)
    assert np.array_equal(a.node_fields["thickness"], b.node_fields["thickness"])
    assert a.n_nodes != c.n_nodes or not np.array_equal(a.nodes, c.nodes)
    t = a.node_field("thickness")
    assert np.all(t > 0.5) and np.all(t <= 2.0)
    s = a.element_field("thickness_strain")
    assert s.shape == (a.n_elements,) and np.all(s >= -1e-12) and s.max() > 0.01
    # smooth: neighbouring nodes differ by a small part of the nominal thickness
    i, j = np.array(list(edge_use(a.elements).keys())).T
    assert np.max(np.abs(t[i] - t[j])) < 0.1 * t.max()
    assert a.units == "mm"


def test_stamped_panel_single_part():
    m = stamped_panel(48, 32, length=500.0, width=320.0, seed=3)
    assert np.all(m.parts == 0)
    assert len(m.used_nodes()) == m.n_nodes
    assert 0.01 <= m.is_triangle.mean() <= 0.06
    assert boundary_loops(m)[0] >= 2
    lo, hi = m.bounds()
    assert np.allclose(hi[:2] - lo[:2], [500.0, 320.0])   # flanges bend down: footprint = top face
    assert np.isclose(lo[2], -25.0)                        # 25 mm flanges hang from the z = 0 edges
    flat = stamped_panel(20, 20, flanges=(), beads=0, holes=0, triangle_share=0.0, seed=1)
    assert flat.n_quads == flat.n_elements == 400 and flat.n_nodes == 21 * 21
    with pytest.raises(ValueError):
        stamped_panel(3, 3)                                   # too coarse for the flanges
    with pytest.raises(ValueError):
        stamped_panel(20, 20, flanges=("z+",))


def test_stamped_panels_refuses_bad_input():
    with pytest.raises(ValueError):
        stamped_panels(0)
    with pytest.raises(ValueError):
        stamped_panels(1000, parts=10)
    with pytest.raises(ValueError):
        stamped_panels(5000, triangle_share=0.7)


# --------------------------------------------------------------------------- refine
@settings(max_examples=40, deadline=None)
@given(nx=st.integers(1, 4), ny=st.integers(1, 4), k=st.integers(1, 4), seed=st.integers(0, 10**6))
def test_refine_quad_grid_properties(nx, ny, k, seed):
    m = jittered_grid(nx, ny, jitter=0.2, z_jitter=0.3, seed=seed)
    rng = np.random.default_rng(seed)
    coeff = rng.normal(size=3)
    m.node_fields["lin"] = m.nodes @ coeff + 2.0
    m.element_fields["e"] = rng.normal(size=m.n_elements)
    r = refine(m, k)
    assert r.n_nodes == (k * nx + 1) * (k * ny + 1)
    assert r.n_elements == r.n_quads == m.n_elements * k * k
    assert np.array_equal(r.nodes[: m.n_nodes], m.nodes)
    # no duplicate coordinates: shared edge nodes are shared
    assert len(np.unique(r.nodes.round(9), axis=0)) == r.n_nodes
    # conforming: interior edges used twice, the boundary split k times
    uses = np.array(list(edge_use(r.elements).values()))
    assert set(uses) <= {1, 2} and (uses == 1).sum() == k * 2 * (nx + ny)
    # children lie on the parent's bilinear patch, child j*k+i at (i/k, j/k)
    for parent in range(m.n_elements):
        corners = m.nodes[m.elements[parent]]
        for j in range(k):
            for i in range(k):
                child = r.elements[parent * k * k + j * k + i]
                want = [bilinear(corners, s / k, t / k)
                        for s, t in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1))]
                assert np.allclose(r.nodes[child], want, atol=1e-9)
    # fields: linear functions reproduced exactly, element fields and parts copied to children
    assert np.allclose(r.node_field("lin"), r.nodes @ coeff + 2.0, atol=1e-9)
    assert np.array_equal(r.element_field("e"), np.repeat(m.element_field("e"), k * k))
    assert np.array_equal(r.parts, np.repeat(m.parts, k * k))


@settings(max_examples=30, deadline=None)
@given(nx=st.integers(1, 4), ny=st.integers(1, 4), k=st.integers(1, 4), seed=st.integers(0, 10**6))
def test_refine_preserves_planar_area_and_winding(nx, ny, k, seed):
    m = jittered_grid(nx, ny, jitter=0.25, seed=seed)     # planar, convex quads
    r = refine(m, k)
    parent_area = areas(m.elements, m.nodes)
    child_area = areas(r.elements, r.nodes).reshape(-1, k * k).sum(axis=1)
    assert np.allclose(child_area, parent_area, rtol=1e-12, atol=1e-9)
    nz = normals(r.elements, r.nodes)[:, 2]
    assert np.all(nz > 0)  # every child keeps the counter-clockwise winding


@settings(max_examples=30, deadline=None)
@given(nx=st.integers(1, 4), ny=st.integers(1, 3), k=st.integers(1, 4), seed=st.integers(0, 10**6))
def test_refine_mixed_mesh_against_brute_force(nx, ny, k, seed):
    """Quads and triangles (split quads, some rotated to other triangle storage): refined node set
    equals the deduplicated per-element parameter points; triangles become k² triangles."""
    rng = np.random.default_rng(seed)
    base = jittered_grid(nx, ny, jitter=0.2, z_jitter=0.2, seed=seed)
    elements = []
    for q in base.elements.tolist():
        if rng.random() < 0.5:
            elements.append(q)
        else:
            elements += [[q[0], q[1], q[2], q[2]], [q[0], q[2], q[3], q[3]]]
    elements = np.array(elements)
    m = FEMesh(nodes=base.nodes, elements=elements)
    coeff = rng.normal(size=3)
    m.node_fields["lin"] = m.nodes @ coeff - 1.0
    r = refine(m, k)

    points = []
    for e in m.elements:
        p = m.nodes[e]
        if e[3] == e[2]:
            points += [p[0] + i / k * (p[1] - p[0]) + j / k * (p[2] - p[0])
                       for j in range(k + 1) for i in range(k + 1 - j)]
        else:
            points += [bilinear(p, i / k, j / k) for j in range(k + 1) for i in range(k + 1)]
    brute = np.unique(np.round(np.array(points), 9), axis=0)
    assert r.n_nodes == len(brute)
    assert np.array_equal(np.unique(r.nodes.round(9), axis=0), brute)
    assert r.n_elements == m.n_elements * k * k
    assert np.array_equal(r.is_triangle, np.repeat(m.is_triangle, k * k))
    assert np.allclose(r.node_field("lin"), r.nodes @ coeff - 1.0, atol=1e-9)
    assert set(edge_use(r.elements).values()) <= {1, 2}
    n_parent = normals(m.elements, m.nodes)
    n_child = normals(r.elements, r.nodes)
    assert np.all(np.sum(n_child * np.repeat(n_parent, k * k, axis=0), axis=1) > 0)


def test_refine_triangles_in_other_storage_and_k1_equality():
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    rotated = FEMesh(nodes=nodes, elements=np.array([[0, 0, 1, 2], [0, 2, 3, 3]]))
    r = refine(rotated, 3)
    assert r.is_triangle.all() and r.n_elements == 18
    assert np.isclose(areas(r.elements, r.nodes).sum(), 1.0)
    m = stamped_panel(20, 16, seed=5)
    m.node_ids = np.arange(m.n_nodes) + 100
    same = refine(m, 1)
    assert np.array_equal(same.nodes, m.nodes) and np.array_equal(same.elements, m.elements)
    assert np.array_equal(same.parts, m.parts)
    assert np.array_equal(same.node_fields["thickness"], m.node_fields["thickness"])
    assert np.array_equal(same.node_ids, m.node_ids)
    with pytest.raises(ValueError):
        refine(m, 0)
    with pytest.raises(MeshError):
        refine(FEMesh(nodes=nodes, elements=np.array([[0, 1, 0, 2]])), 2)


def test_refine_time_steps_and_conformity_of_a_stamped_part():
    m = crash_sequence(stamped_panel(24, 16, seed=2), steps=3)
    r = refine(m, 2)
    assert r.steps.shape == (3, r.n_nodes, 3)
    for t in range(3):
        at_t = refine(FEMesh(nodes=m.steps[t], elements=m.elements), 2)
        assert np.allclose(r.steps[t], at_t.nodes)
    assert r.node_fields["displacement"].shape == (3, r.n_nodes)
    assert r.element_fields["plastic_strain"].shape == (3, r.n_elements)
    assert np.array_equal(r.times, m.times)
    assert boundary_loops(r) == boundary_loops(m)           # holes stay holes, nothing cracks
    assert set(edge_use(r.elements).values()) <= {1, 2}


# --------------------------------------------------------------------------- crash sequence
@pytest.fixture(scope="module")
def crashed():
    m = stamped_panels(4000, seed=1)
    return m, crash_sequence(m, steps=8, crush=0.3, axis="x")


def test_crash_sequence_step0_topology_and_shapes(crashed):
    m, c = crashed
    assert c.steps.shape == (8, m.n_nodes, 3)
    assert np.array_equal(c.steps[0], m.nodes) and np.array_equal(c.nodes, m.nodes)
    assert np.array_equal(c.elements, m.elements) and np.array_equal(c.parts, m.parts)
    assert c.times.shape == (8,) and c.times[0] == 0.0 and np.all(np.diff(c.times) > 0)
    assert c.node_fields["displacement"].shape == (8, m.n_nodes)
    assert c.element_fields["plastic_strain"].shape == (8, m.n_elements)
    assert np.array_equal(c.node_fields["thickness"], m.node_fields["thickness"])


def test_crash_sequence_erodes_at_the_failure_strain_and_keeps_the_failure_value(crashed):
    """An element is deleted from the first state its strain (of the crash without erosion)
    reaches the failure strain on, for good, and keeps that state's value; the others are the
    crash without erosion, unchanged. Checked element by element with a plain loop."""
    m, c = crashed
    strain = c.element_fields["plastic_strain"]
    failure = float(np.quantile(strain[-1], 0.9))
    e = crash_sequence(m, steps=8, crush=0.3, axis="x", failure_strain=failure)
    alive, got = e.element_fields["alive"], e.element_fields["plastic_strain"]
    assert np.array_equal(e.steps, c.steps) and alive.shape == strain.shape
    for k in range(m.n_elements):
        hits = [t for t in range(8) if strain[t, k] >= failure]
        if not hits:
            assert alive[:, k].all() and np.array_equal(got[:, k], strain[:, k])
            continue
        first = hits[0]
        assert alive[:first, k].all() and not alive[first:, k].any()
        assert np.array_equal(got[:first + 1, k], strain[:first + 1, k])
        assert (got[first:, k] == strain[first, k]).all()
    assert 0 < (alive[-1] == 0).sum() < m.n_elements
    assert e.erodes and e.field_range("plastic_strain")[1] < failure
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="failure_strain must be a positive"):
            crash_sequence(m, steps=3, failure_strain=bad)


def test_crash_sequence_displacement_grows_and_is_largest_at_the_front(crashed):
    m, c = crashed
    d = c.node_fields["displacement"]
    assert np.allclose(d, np.linalg.norm(c.steps - m.nodes, axis=2))
    assert np.all(d[0] == 0)
    assert np.all(np.diff(d, axis=0) >= -1e-9)               # monotone per node
    assert np.all(np.diff(d.max(axis=1)) > 0)
    x = m.nodes[:, 0]
    extent = np.ptp(x)
    front = np.argmax(x)
    assert np.isclose(m.nodes[front, 0] - c.steps[-1, front, 0], 0.3 * extent)
    far = x < x.max() - 2.5 * 0.3 * extent
    assert far.any() and np.all(d[:, far] == 0)              # behind the crush zone nothing moves
    near = x > x.max() - 0.1 * extent
    assert d[-1, near].mean() > d[-1, ~near].mean()
    eps = c.element_fields["plastic_strain"]
    assert np.all(eps[0] == 0) and np.all(np.diff(eps, axis=0) >= 0) and eps[-1].max() > 0.01


def test_crash_sequence_axis_and_refusals():
    m = semicylinders(sheets=2, n=8)
    c = crash_sequence(m, steps=3, crush=0.2, axis="-z")
    back = np.argmin(m.nodes[:, 2])
    assert np.isclose(c.steps[-1, back, 2] - m.nodes[back, 2], 0.2 * np.ptp(m.nodes[:, 2]))
    default = crash_sequence(m, steps=2, crush=0.1)  # car body coordinates: front at min x
    left = np.argmin(m.nodes[:, 0])
    assert np.isclose(default.steps[-1, left, 0] - m.nodes[left, 0], 0.1 * np.ptp(m.nodes[:, 0]))
    with pytest.raises(MeshError):
        crash_sequence(c)
    with pytest.raises(ValueError):
        crash_sequence(m, crush=1.5)
    with pytest.raises(ValueError):
        crash_sequence(m, axis="w")
    with pytest.raises(ValueError):
        crash_sequence(m, steps=1)


def test_crash_sequence_keeps_still_parts_in_place():
    # two sheets; with sheet 0 held still only sheet 1 is crushed, measured from its own front
    m = semicylinders(sheets=2, n=8)
    c = crash_sequence(m, steps=3, crush=0.2, axis="-z", still_parts=(0,))
    d = c.node_fields["displacement"]
    still = np.unique(m.elements[m.parts == 0])
    assert np.all(d[:, still] == 0)
    moving = np.unique(m.elements[m.parts == 1])
    z = m.nodes[moving, 2]
    front = moving[np.argmin(z)]
    assert np.isclose(c.steps[-1, front, 2] - m.nodes[front, 2], 0.2 * np.ptp(z))
    with pytest.raises(MeshError):
        crash_sequence(m, still_parts=(0, 1))


def test_box_in_box_hides_its_inner_part_in_a_closed_box():
    from workbench.scene.generators import box_in_box

    mesh = box_in_box(1.0, 0.2, n=4, inner_n=2)
    assert sorted(np.unique(mesh.parts).tolist()) == [1, 2, 3, 4, 5, 6, 7]
    assert (mesh.parts != 7).sum() == 6 * 16 and (mesh.parts == 7).sum() == 6 * 4
    inner = mesh.nodes[np.unique(mesh.elements[mesh.parts == 7])]
    outer = mesh.nodes[np.unique(mesh.elements[mesh.parts != 7])]
    assert np.abs(inner).max() == pytest.approx(0.2) and np.abs(outer).max(axis=1).min() == 1.0
    with pytest.raises(ValueError, match="below box_half"):
        box_in_box(1.0, 1.0)


def test_the_builtin_crash_is_the_car_crushed_over_eight_states(car):
    from workbench.scene.builtin import load_scene

    crash = load_scene("crash")
    assert crash.n_steps == 8 and len(load_scene("crash:3").times) == 3
    np.testing.assert_array_equal(crash.coordinates(0), car.coordinates())
    np.testing.assert_array_equal(crash.elements, car.elements)
    moved = np.linalg.norm(crash.coordinates(7) - car.coordinates(), axis=1)
    rigid = {p for p, title in car.part_names.items() if "rigid" in title.lower()}
    assert rigid and moved.max() > 0
    still = np.isin(crash.parts, list(rigid))
    only_rigid = np.setdiff1d(np.unique(crash.elements[still]),
                              np.unique(crash.elements[~still]))
    assert np.all(moved[only_rigid] == 0)  # the rigid barrier holds still
    assert set(crash.node_fields) == {"displacement"} and "plastic_strain" in crash.element_fields
