"""Per-node distance to other parts (crash2000 §4.1) and part connectivity: both hierarchies and
leaf sizes against brute force on random multi-part meshes and on the car deck, own parts of
shared nodes, far-from-origin models, Table 2 counters, thread-count independence, refusals."""

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid
from test_hierarchy import mesh_options, random_mesh

from workbench.algo.nearest.hierarchy import local_origin
from workbench.algo.nearest.parts import (
    batched_part_distances,
    brute_force_part_distances,
    connectivity,
    node_parts,
    own_part_sets,
    part_distances,
)
from workbench.algo.nearest.triangle import points_triangles_distance
from workbench.scene.mesh import FEMesh

CONFIGS = [(kind, leaf) for kind in ("aabb", "obb") for leaf in (1, 10)]


def distance_to_part(mesh, node, part, step=0):
    """Exact distance from a node to the triangles of one part (brute force)."""
    tr = mesh.triangulation
    tri = tr.triangles[mesh.parts[tr.element_of] == part]
    coords = mesh.coordinates(step)
    return points_triangles_distance(coords[node:node + 1], coords[tri]).min()


def assert_matches(mesh, r, expected, cutoff, step=0):
    """Distances equal the brute force (relative 1e-12) and the part named is the reference's
    or, on a tie, another part at the same distance."""
    bd, bp = expected
    np.testing.assert_allclose(r.distance, bd, rtol=1e-12, atol=0)
    assert ((r.other_part >= 0) == np.isfinite(r.distance)).all()
    for i in np.flatnonzero(r.other_part != bp):
        assert distance_to_part(mesh, i, r.other_part[i], step) == pytest.approx(bd[i], rel=1e-12)
    assert r.element_tests + r.plane_skips == r.leaf_elements


# --------------------------------------------------------------------------- random meshes
@settings(max_examples=40, deadline=None)
@given(mesh_options, st.sampled_from([0.2, 1.0, 5.0]))
def test_every_hierarchy_matches_brute_force(options, cutoff):
    mesh = random_mesh(**options)
    expected = brute_force_part_distances(mesh, cutoff)
    for kind, leaf in CONFIGS + [("aabb", 3)]:
        r = part_distances(mesh, cutoff, kind=kind, leaf_size=leaf)
        assert_matches(mesh, r, expected, cutoff)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10**6), st.sampled_from(["aabb", "obb"]))
def test_touching_coplanar_shared_and_degenerate_all_at_once(seed, kind):
    mesh = random_mesh(seed, 4, touching=True, coplanar=True, shared=True, degenerate=True,
                       single=True, unused=True)
    expected = brute_force_part_distances(mesh, 1.0)
    for leaf in (1, 10):
        r = part_distances(mesh, 1.0, kind=kind, leaf_size=leaf)
        assert_matches(mesh, r, expected, 1.0)
    # the flat copy overlaps its original in one plane, touching parts share a point: nodes at
    # distance 0 up to rounding
    assert (expected[0] <= 1e-12).sum() >= 2


def test_unused_nodes_and_nodes_of_degenerate_elements():
    mesh = random_mesh(4, 2, degenerate=True, unused=True)
    r = part_distances(mesh, 100.0)
    unused = np.setdiff1d(np.arange(mesh.n_nodes), mesh.elements.ravel())
    assert len(unused) == 2
    assert np.isinf(r.distance[unused]).all() and (r.other_part[unused] == -1).all()
    assert r.nodes_queried == mesh.n_nodes - 2
    # with a cut-off of 100 every used node sees the other part, unless a (degenerate)
    # element of the other part uses it too: then it has no other part
    ptr, _ = node_parts(mesh)
    used = np.unique(mesh.elements)
    both = (ptr[used + 1] - ptr[used]) == 2
    assert both.any() and (~both).any()
    assert np.isfinite(r.distance[used[~both]]).all()
    assert np.isinf(r.distance[used[both]]).all()


def test_a_node_of_two_parts_measures_the_third_parts_only():
    # parts 1 and 2 share the seam x = 1; part 3 is a plate 0.5 above the seam
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],  # part 1
                      [2, 0, 0], [2, 1, 0],  # part 2 (shares nodes 1, 2)
                      [0.5, 0, 0.5], [1.5, 0, 0.5], [1.5, 1, 0.5], [0.5, 1, 0.5]], float)
    elements = [[0, 1, 2, 3], [1, 4, 5, 2], [6, 7, 8, 9]]
    mesh = FEMesh(nodes=nodes, elements=elements, parts=[1, 2, 3])
    ptr, own = node_parts(mesh)
    assert own[ptr[1]:ptr[2]].tolist() == [1, 2]
    for kind, leaf in CONFIGS:
        r = part_distances(mesh, 2.0, kind=kind, leaf_size=leaf)
        assert r.distance[1] == 0.5 and r.other_part[1] == 3  # not 0 to part 2
        assert r.distance[0] == pytest.approx(np.hypot(0.5, 0.5)) and r.other_part[0] == 3
        assert r.distance[4] == pytest.approx(np.hypot(0.5, 0.5)) and r.other_part[4] == 3
    two = FEMesh(nodes=nodes[:6], elements=elements[:2], parts=[1, 2])
    r = part_distances(two, 2.0)
    assert np.isinf(r.distance[[1, 2]]).all()  # a seam node has no third part
    assert r.distance[0] == 1.0 and r.other_part[0] == 2


@pytest.mark.parametrize("kind,leaf", CONFIGS)
def test_far_from_the_origin_keeps_its_digits(kind, leaf):
    mesh = random_mesh(11, 4, touching=True, coplanar=True, shared=True)
    near = part_distances(mesh, 1.0, kind=kind, leaf_size=leaf)
    far_mesh = mesh.translated([1e6, -1e6, 1e6])
    far = part_distances(far_mesh, 1.0, kind=kind, leaf_size=leaf)
    finite = np.isfinite(near.distance)
    assert finite.sum() > 10
    assert (np.isfinite(far.distance) == finite).all()
    assert np.abs(far.distance[finite] - near.distance[finite]).max() <= 1e-9
    assert_matches(far_mesh, far, brute_force_part_distances(far_mesh, 1.0), 1.0)


def test_time_steps():
    mesh = random_mesh(21, 3)
    rng = np.random.default_rng(0)
    steps = np.stack([mesh.nodes, mesh.nodes + rng.normal(size=mesh.nodes.shape) * 0.3])
    moving = FEMesh(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts, steps=steps)
    r0 = part_distances(moving, 2.0, step=0)
    r1 = part_distances(moving, 2.0, step=1, kind="obb", leaf_size=10)
    assert_matches(moving, r1, brute_force_part_distances(moving, 2.0, step=1), 2.0, step=1)
    np.testing.assert_array_equal(r0.distance, part_distances(mesh, 2.0).distance)
    assert not np.array_equal(r0.distance, r1.distance)


def test_deleted_elements_are_no_target_and_their_nodes_not_measured():
    """Erosion: at a state that deletes elements, every search gives what it gives on the
    same model with those elements removed (FEMesh.subset, mapped back by node id), and a node
    that only deleted elements use is not measured; at the state before, nothing changes."""
    rng = np.random.default_rng(3)
    mesh = random_mesh(17, 3)
    steps = np.stack([mesh.nodes, mesh.nodes + rng.normal(size=mesh.nodes.shape) * 0.05])
    alive = np.ones((2, mesh.n_elements))
    alive[1, rng.permutation(mesh.n_elements)[:mesh.n_elements // 3]] = 0
    eroded = FEMesh(mesh.nodes, mesh.elements, mesh.parts, steps,
                    element_fields={"alive": alive}, node_ids=np.arange(mesh.n_nodes))
    kept = FEMesh(mesh.nodes, mesh.elements, mesh.parts, steps,
                  node_ids=np.arange(mesh.n_nodes)).subset(alive[1] != 0)
    only_deleted = ~eroded.live_nodes(1) & eroded.live_nodes(0)
    assert only_deleted.any()
    for search in (lambda m, s: part_distances(m, 2.0, step=s).distance,
                   lambda m, s: part_distances(m, 2.0, step=s, kind="obb", leaf_size=4).distance,
                   lambda m, s: batched_part_distances(m, 2.0, step=s).distance,
                   lambda m, s: brute_force_part_distances(m, 2.0, step=s)[0]):
        got = search(eroded, 1)
        np.testing.assert_array_equal(got[kept.node_ids], search(kept, 1))
        assert np.isinf(got[only_deleted]).all()
        whole = FEMesh(mesh.nodes, mesh.elements, mesh.parts, steps)
        np.testing.assert_array_equal(search(eroded, 0), search(whole, 0))
        assert not np.array_equal(got, search(whole, 1))  # the fault: deleted ones measured


# --------------------------------------------------------------------------- batched
def assert_batched_exact(mesh, r, expected, step=0):
    """The batched search's distances equal the brute force's to the last bit; the part named
    is the brute force's or, on a tie, another part at exactly that distance."""
    bd, bp = expected
    np.testing.assert_array_equal(r.distance, bd)
    assert ((r.other_part >= 0) == np.isfinite(r.distance)).all()
    assert ((r.other_element >= 0) == np.isfinite(r.distance)).all()
    np.testing.assert_array_equal(mesh.parts[r.other_element[r.other_element >= 0]],
                                  r.other_part[r.other_part >= 0])
    tr = mesh.triangulation
    coords = mesh.coordinates(step)
    local = coords - local_origin(coords, np.unique(mesh.elements))  # as the brute force
    for i in np.flatnonzero(r.other_part != bp):
        tri = tr.triangles[mesh.parts[tr.element_of] == r.other_part[i]]
        assert points_triangles_distance(local[i:i + 1], local[tri]).min() == bd[i]


@settings(max_examples=60, deadline=None)
@given(mesh_options, st.sampled_from([0.05, 0.2, 1.0, 5.0]), st.sampled_from([1, 4, 16]))
def test_batched_equals_brute_force_to_the_last_bit(options, cutoff, leaf):
    mesh = random_mesh(**options)
    r = batched_part_distances(mesh, cutoff, leaf_size=leaf)
    assert_batched_exact(mesh, r, brute_force_part_distances(mesh, cutoff))
    assert r.kind == "batched" and r.nodes_queried == len(np.unique(mesh.elements))
    # the crash2000 hierarchy computes the same float64 distances
    np.testing.assert_array_equal(r.distance, part_distances(mesh, cutoff).distance)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10**6))
def test_batched_touching_coplanar_shared_degenerate_far(seed):
    mesh = random_mesh(seed, 4, touching=True, coplanar=True, shared=True, degenerate=True,
                       single=True, unused=True)
    for m in (mesh, mesh.translated([1e6, -1e6, 1e6])):
        assert_batched_exact(m, batched_part_distances(m, 1.0), brute_force_part_distances(m, 1.0))


def test_batched_refined_steps_and_threads():
    from workbench.scene.generators import refine

    mesh = refine(random_mesh(3, 4, touching=True, coplanar=True, shared=True), 4)
    rng = np.random.default_rng(1)
    steps = np.stack([mesh.nodes, mesh.nodes + rng.normal(size=mesh.nodes.shape) * 0.05])
    moving = FEMesh(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts, steps=steps)
    r = batched_part_distances(moving, 0.3, step=1)
    assert_batched_exact(moving, r, brute_force_part_distances(moving, 0.3, step=1), step=1)
    assert np.isfinite(r.distance).sum() > 100
    assert r.bv_tests > 0 and r.element_tests > 0 and r.n_bvs > 0 and r.query_s > 0
    if numba.config.NUMBA_NUM_THREADS < 2:
        return
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = batched_part_distances(moving, 0.3, step=1)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one.distance, r.distance)
    np.testing.assert_array_equal(one.other_element, r.other_element)
    assert (one.bv_tests, one.element_tests) == (r.bv_tests, r.element_tests)


@settings(max_examples=30, deadline=None)
@given(mesh_options)
def test_own_part_sets_are_node_parts(options):
    mesh = random_mesh(**options)
    node_set, set_ptr, set_parts = own_part_sets(mesh)
    ptr, own = node_parts(mesh)
    ids = np.unique(mesh.parts)
    for i in range(mesh.n_nodes):
        expected = own[ptr[i]:ptr[i + 1]]
        if len(expected) == 0:
            assert node_set[i] == -1
            continue
        s = node_set[i]
        np.testing.assert_array_equal(ids[set_parts[set_ptr[s]:set_ptr[s + 1]]], expected)
    # sets are distinct, the single parts first
    sets = [tuple(set_parts[set_ptr[s]:set_ptr[s + 1]]) for s in range(len(set_ptr) - 1)]
    assert len(set(sets)) == len(sets)
    assert sets[:len(ids)] == [(p,) for p in range(len(ids))]


def test_batched_refusals():
    mesh = random_mesh(1, 2)
    for bad in (0.0, -1.0, np.nan, np.inf, "x", None):
        with pytest.raises(ValueError, match="finite number > 0"):
            batched_part_distances(mesh, bad)
    for bad in (0, -2, 2.5):
        with pytest.raises(ValueError, match="leaf_size"):
            batched_part_distances(mesh, 1.0, leaf_size=bad)
    with pytest.raises(ValueError, match="step"):
        batched_part_distances(mesh, 1.0, step=3)
    steps = np.stack([mesh.nodes, mesh.nodes])
    steps[1, mesh.elements[-1, 2]] = np.nan
    moving = FEMesh(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts, steps=steps)
    batched_part_distances(moving, 1.0, step=0)
    with pytest.raises(ValueError, match="non-finite"):
        batched_part_distances(moving, 1.0, step=1)


# --------------------------------------------------------------------------- counters
def test_counters_of_table_2():
    mesh = random_mesh(7, 4, touching=True)
    n_parts = len(np.unique(mesh.parts))
    runs = {(k, leaf): part_distances(mesh, 1.0, kind=k, leaf_size=leaf) for k, leaf in CONFIGS}
    for (kind, leaf), r in runs.items():
        assert r.kind == kind and r.leaf_size == leaf and r.cutoff == 1.0
        assert r.element_tests + r.plane_skips == r.leaf_elements > 0
        assert r.bv_tests > 0 and r.build_s > 0 and r.query_s > 0
        assert r.n_top_bvs == n_parts - 1
        np.testing.assert_array_equal(r.distance, runs["aabb", 1].distance)
    assert runs["aabb", 1].n_bvs == runs["obb", 1].n_bvs == 2 * mesh.n_elements - n_parts
    assert runs["aabb", 10].n_bvs == runs["obb", 10].n_bvs < runs["aabb", 1].n_bvs
    # without the point-to-plane test every element reached is measured, with the same result
    for kind, leaf in CONFIGS:
        r = part_distances(mesh, 1.0, kind=kind, leaf_size=leaf, plane_test=False)
        assert r.plane_skips == 0 and r.element_tests == r.leaf_elements
        assert r.element_tests >= runs[kind, leaf].element_tests
        np.testing.assert_array_equal(r.distance, runs[kind, leaf].distance)
        assert r.bv_tests == runs[kind, leaf].bv_tests


def test_plane_test_skips_elements_in_big_leaves():
    # a flat plate under a corrugated one: the elements of a leaf lie in different planes, and
    # those farther by their plane than the nearest element so far are skipped
    n = 24
    p, q = quad_grid(n, n, cell=0.25, ij=True)
    wave = p + [0.0, 0.0, 1.0]
    wave[:, 2] += 0.4 * np.sin(4.0 * p[:, 0]) * np.cos(3.0 * p[:, 1])
    mesh = FEMesh(nodes=np.concatenate([p, wave]), elements=np.concatenate([q, q + len(p)]),
                  parts=np.repeat([1, 2], len(q)))
    r = part_distances(mesh, 1.5, kind="aabb", leaf_size=10)
    off = part_distances(mesh, 1.5, kind="aabb", leaf_size=10, plane_test=False)
    np.testing.assert_array_equal(r.distance, off.distance)
    assert r.plane_skips > 0.1 * r.leaf_elements
    # skipped elements never beat the best so far: the search itself is unchanged
    assert (r.bv_tests, r.leaf_elements) == (off.bv_tests, off.leaf_elements)
    assert r.element_tests == off.element_tests - r.plane_skips


def test_results_do_not_depend_on_the_thread_count():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has a single thread here")
    mesh = random_mesh(3, 4, touching=True, coplanar=True)
    from workbench.scene.generators import refine

    mesh = refine(mesh, 4)  # a few thousand nodes: many parallel chunks
    before = numba.get_num_threads()
    try:
        results = []
        for threads in (1, 2):
            numba.set_num_threads(threads)
            results.append([part_distances(mesh, 0.5, kind=k, leaf_size=leaf)
                            for k, leaf in CONFIGS])
    finally:
        numba.set_num_threads(before)
    for a, b in zip(*results):
        np.testing.assert_array_equal(a.distance, b.distance)
        np.testing.assert_array_equal(a.other_part, b.other_part)
        assert (a.bv_tests, a.element_tests, a.plane_skips) == \
            (b.bv_tests, b.element_tests, b.plane_skips)


# --------------------------------------------------------------------------- the car
@pytest.fixture(scope="module")
def car_distances(car_deck):
    """The car deck and its brute-force part distances within 1.5 mm."""
    from workbench.scene.builtin import fresh_scene

    mesh = fresh_scene("car")
    return mesh, brute_force_part_distances(mesh, 1.5)


@pytest.mark.parametrize("kind,leaf", CONFIGS)
def test_car_every_node_equals_brute_force(car_distances, kind, leaf):
    mesh, expected = car_distances
    r = part_distances(mesh, 1.5, kind=kind, leaf_size=leaf)
    assert_matches(mesh, r, expected, 1.5)
    assert np.isfinite(r.distance).sum() > 100  # flanges and seams of the deck
    assert r.nodes_queried == mesh.n_nodes
    if leaf == 10:  # crash2000: the plane test avoids most exact distances in big leaves
        assert r.plane_skips > 0.5 * r.leaf_elements


def test_car_batched_equals_brute_force(car_distances):
    mesh, expected = car_distances
    r = batched_part_distances(mesh, 1.5)
    assert_batched_exact(mesh, r, expected)
    assert np.isfinite(r.distance).sum() > 100


def test_car_far_from_the_origin(car_distances):
    mesh, _ = car_distances
    near = part_distances(mesh, 1.5)
    far = part_distances(mesh.translated([1e6, 1e6, -1e6]), 1.5, kind="obb")
    finite = np.isfinite(near.distance)
    assert (np.isfinite(far.distance) == finite).all()
    assert np.abs(far.distance[finite] - near.distance[finite]).max() <= 1e-9


# --------------------------------------------------------------------------- connectivity
def brute_connectivity(mesh, distance):
    parts = np.unique(mesh.parts)
    tr = mesh.triangulation
    # relative to the same origin as the hierarchy: bitwise the same local coordinates
    local = mesh.nodes - local_origin(mesh.nodes, np.unique(mesh.elements))
    d = points_triangles_distance(local, local[tr.triangles])
    tri_part = mesh.parts[tr.element_of]
    ptr, own = node_parts(mesh)
    best = np.full((len(parts), len(parts)), np.inf)
    count = np.zeros((len(parts), len(parts)), np.int64)
    for i in range(mesh.n_nodes):
        mine = own[ptr[i]:ptr[i + 1]]
        for b, pb in enumerate(parts):
            if pb in mine or not (tri_part == pb).any():
                continue
            dmin = d[i, tri_part == pb].min()
            if dmin <= distance:
                for pa in mine:
                    a = np.searchsorted(parts, pa)
                    best[a, b] = min(best[a, b], dmin)
                    count[a, b] += 1
    return parts, np.minimum(best, best.T), count + count.T


@settings(max_examples=25, deadline=None)
@given(mesh_options, st.sampled_from(["aabb", "obb"]), st.sampled_from([1, 10]),
       st.sampled_from([0.3, 1.0]))
def test_connectivity_matches_brute_force_pair_minimum(options, kind, leaf, distance):
    mesh = random_mesh(**options)
    c = connectivity(mesh, distance, kind=kind, leaf_size=leaf)
    parts, best, count = brute_connectivity(mesh, distance)
    np.testing.assert_array_equal(c.parts, parts)
    np.testing.assert_allclose(c.min_distance, best, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(c.nodes_within, count)
    rows = c.rows()
    assert len(rows) == int(np.triu(count > 0, 1).sum())
    for row in rows:
        a, b = np.searchsorted(parts, [row["part_a"], row["part_b"]])
        assert row["part_a"] < row["part_b"] and row["min_distance"] == best[a, b] <= distance


def test_connectivity_sees_a_second_neighbour():
    # plates at z = 0 (A), 0.5 (B), -0.8 (C), -1.0 (D): every node's nearest other part is
    # B, A, D, C; A and C are still 0.8 apart and must be listed
    sq = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    z = [0.0, 0.5, -0.8, -1.0]
    mesh = FEMesh(nodes=np.concatenate([sq + [0, 0, h] for h in z]),
                  elements=np.arange(16).reshape(4, 4), parts=[1, 2, 3, 4])
    nearest = part_distances(mesh, 1.0)
    assert set(zip(np.repeat([1, 2, 3, 4], 4), nearest.other_part)) == {(1, 2), (2, 1), (3, 4),
                                                                       (4, 3)}
    for kind in ("aabb", "obb"):
        c = connectivity(mesh, 1.0, kind=kind)
        rows = {(r["part_a"], r["part_b"]): (r["min_distance"], r["nodes_within"])
                for r in c.rows()}
        assert rows == {(1, 2): (0.5, 8), (1, 3): (pytest.approx(0.8), 8), (1, 4): (1.0, 8),
                        (3, 4): (pytest.approx(0.2), 8)}


# --------------------------------------------------------------------------- refusals
def test_refusals():
    mesh = random_mesh(1, 2)
    for f in (part_distances, connectivity, brute_force_part_distances):
        for bad in (0.0, -1.0, np.nan, np.inf, "x", None):
            with pytest.raises(ValueError, match="finite number > 0"):
                f(mesh, bad)
    for f in (part_distances, connectivity):
        with pytest.raises(ValueError, match="kind"):
            f(mesh, 1.0, kind="sphere")
        for bad in (0, -2, 2.5):
            with pytest.raises(ValueError, match="leaf_size"):
                f(mesh, 1.0, leaf_size=bad)
        with pytest.raises(ValueError, match="step"):
            f(mesh, 1.0, step=3)
    # NaN or inf at a used node of the measured step; at an unused node it does not matter
    steps = np.stack([mesh.nodes, mesh.nodes])
    steps[1, mesh.elements[-1, 2]] = np.nan
    extra = np.concatenate([mesh.nodes, [[0.0, 0.0, 0.0]]])
    steps_unused = np.stack([extra, extra])
    steps_unused[1, -1] = np.inf
    moving = FEMesh(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts, steps=steps)
    loose = FEMesh(nodes=extra, elements=mesh.elements, parts=mesh.parts, steps=steps_unused)
    for f in (part_distances, connectivity, brute_force_part_distances):
        f(moving, 1.0, step=0)
        f(loose, 1.0, step=1)
        with pytest.raises(ValueError, match="non-finite"):
            f(moving, 1.0, step=1)
    empty = random_mesh(1, 1)
    empty.elements = np.zeros((0, 4), np.int32)
    empty.parts = np.zeros(0, np.int32)
    for f in (part_distances, connectivity, brute_force_part_distances):
        with pytest.raises(ValueError, match="no elements"):
            f(empty, 1.0)


# --------------------------------------------------------------------------- accuracy
def sliver_sheets(rng, eps, offset):
    """Four parts, moved by ``offset``: a fan of thin triangles (pairs of rim corners eps apart,
    as degenerate quads), a sheet just below it, needles (a corner eps from another) and small
    triangles with a corner on a needle's face (where the old region walk overstated the
    distance by up to a quarter of the needle's size)."""
    n = 12
    angles = np.sort(rng.uniform(0, 2 * np.pi, n))
    rim = np.stack([np.cos(angles), np.sin(angles), np.zeros(n)], axis=1)
    rim[1::2] = rim[0::2] + eps * rng.normal(size=(n // 2, 3))  # pairs of close rim nodes
    nodes = [np.vstack([[0.0, 0.0, 0.0], rim])]
    elements = [[0, 1 + i, 1 + (i + 1) % n, 1 + (i + 1) % n] for i in range(n)]
    parts = [1] * n
    sheet = np.array([[-1.2, -1.2, -0.3], [1.2, -1.2, -0.3], [1.2, 1.2, -0.25],
                      [-1.2, 1.2, -0.3]]) + eps * rng.normal(size=(4, 3))
    nodes.append(sheet)
    elements.append([n + 1, n + 2, n + 3, n + 4])
    parts.append(2)
    at = n + 5
    for _ in range(4):
        a, b = rng.normal(size=3) * 0.8, rng.normal(size=3) * 0.8
        c = b + eps * rng.normal(size=3)
        q = b + rng.uniform(0.05, 0.95) * (a - b) + rng.uniform(0, 1) * (c - b)
        nodes += [np.array([a, b, c]), np.array([q, q + [0, 0, 0.5], q + [0.5, 0, 0.5]])]
        elements += [[at, at + 1, at + 2, at + 2], [at + 3, at + 4, at + 5, at + 5]]
        parts += [3, 4]
        at += 6
    return FEMesh(nodes=np.vstack(nodes) + offset, elements=np.array(elements, np.int64),
                  parts=np.array(parts))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), log_eps=st.floats(-14, -3),
       log_offset=st.floats(0, 6), far=st.booleans())
def test_distances_are_within_the_kernel_bound_of_exact_arithmetic(seed, log_eps, log_offset,
                                                                   far):
    """Every path's distances against exact rational arithmetic (no shared code), on slivers
    and far from the origin: within the kernel's documented error, DISTANCE_ERROR · u times the
    distance plus the nearest triangle's size (the mesh's diagonal bounds both here)."""
    from workbench.algo.nearest.triangle import DISTANCE_ERROR, UNIT_ROUNDOFF
    from workbench.reliability.exact import nearest_distance

    rng = np.random.default_rng(seed)
    offset = rng.normal(size=3) * 10.0 ** log_offset if far else np.zeros(3)
    mesh = sliver_sheets(rng, 10.0 ** log_eps, offset)
    used = np.unique(mesh.elements)
    local = mesh.nodes - local_origin(mesh.nodes, used)
    tr = mesh.triangulation
    tri_part = mesh.parts[tr.element_of]
    ptr, own = node_parts(mesh)
    exact = np.full(mesh.n_nodes, np.inf)
    for i in used:
        others = ~np.isin(tri_part, own[ptr[i]:ptr[i + 1]])
        if others.any():
            exact[i] = nearest_distance(local[i], local[tr.triangles[others]])
    exact[exact > 2.0] = np.inf
    diagonal = float(np.linalg.norm(np.ptp(local[used], axis=0)))
    bound = DISTANCE_ERROR * UNIT_ROUNDOFF * 2 * diagonal
    for r in (part_distances(mesh, 2.0), batched_part_distances(mesh, 2.0),
              brute_force_part_distances(mesh, 2.0)):
        distance = r[0] if isinstance(r, tuple) else r.distance
        finite = np.isfinite(exact)
        # within the cut-off to rounding on the same nodes
        assert (np.isfinite(distance[finite]) | (exact[finite] > 2.0 - bound)).all()
        both = finite & np.isfinite(distance)
        assert np.abs(distance[both] - exact[both]).max(initial=0.0) <= bound
