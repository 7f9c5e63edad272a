"""The batched nearest-triangle tree against every point tried on every triangle, to the last bit
of the float64 squared distance: random triangle soups (slivers, degenerate and repeated
triangles, points on the triangles, far outside and repeated), random sets of excluded parts,
group sizes, a candidate list that outgrows its first buffer, thread counts; refusals."""

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.nearest.batch import BatchedTriangleTree
from workbench.algo.nearest.triangle import closest_point_on_triangle


@numba.njit(cache=True)
def _brute(points, point_set, set_ptr, set_parts, corners, tri_part, bound):
    """Squared distance and triangle of the nearest allowed triangle at most ``bound`` away
    (squared), trying every triangle in order; (inf, -1) where none is."""
    n = len(points)
    d2 = np.full(n, np.inf)
    tri = np.full(n, -1, np.int64)
    tmp = np.empty(3)
    for i in range(n):
        s = point_set[i]
        if s < 0:
            continue
        best = np.inf
        for t in range(len(corners)):
            excluded = False
            for k in range(set_ptr[s], set_ptr[s + 1]):
                if set_parts[k] == tri_part[t]:
                    excluded = True
            if excluded:
                continue
            d = closest_point_on_triangle(points[i], corners[t, 0], corners[t, 1],
                                          corners[t, 2], tmp)
            if d < best:
                best, tri[i] = d, t
        if best <= bound:
            d2[i] = best
        else:
            tri[i] = -1
    return d2, tri


def squared_bound(cutoff):
    b = cutoff * cutoff
    while np.sqrt(b) > cutoff:
        b = np.nextafter(b, 0.0)
    while np.sqrt(np.nextafter(b, np.inf)) <= cutoff:
        b = np.nextafter(b, np.inf)
    return b


def random_case(seed, n_tri, n_points, n_parts, n_sets):
    """A triangle soup with parts, query points near and on it (and some far, some repeated),
    and random sets of excluded parts (set 0 excludes nothing, the last excludes every part)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-5, 5, (n_tri, 1, 3))
    corners = centres + rng.normal(scale=rng.choice([0.05, 0.5, 3.0]), size=(n_tri, 3, 3))
    kind = rng.integers(0, 10, n_tri)
    corners[kind == 0, 2] = corners[kind == 0, 0]  # a repeated corner
    corners[kind == 1, 2] = 0.5 * (corners[kind == 1, 0] + corners[kind == 1, 1])  # collinear
    corners[kind == 2, 1] = corners[kind == 2, 2] = corners[kind == 2, 0]  # a point
    if n_tri > 3:
        corners[3] = corners[1]  # the same triangle twice
    tri_part = rng.integers(0, n_parts, n_tri)
    # points: on triangles (barycentric), near them, far away, and a few repeated
    t = rng.integers(0, n_tri, n_points)
    w = rng.dirichlet([1, 1, 1], n_points)
    points = np.einsum("pk,pka->pa", w, corners[t])
    points += rng.normal(size=points.shape) * rng.choice([0.0, 0.01, 0.3, 2.0], (n_points, 1))
    points[rng.random(n_points) < 0.05] *= 30.0
    points[rng.random(n_points) < 0.1] = points[0]
    sets = [[]] + [sorted(rng.choice(n_parts, rng.integers(1, n_parts + 1), replace=False))
                   for _ in range(max(0, n_sets - 2))] + [list(range(n_parts))]
    set_ptr = np.concatenate([[0], np.cumsum([len(x) for x in sets])]).astype(np.int64)
    set_parts = np.array([p for x in sets for p in x], np.int64)
    point_set = rng.integers(-1, len(sets), n_points)
    return corners, tri_part, points, point_set, set_ptr, set_parts


def check(tree, corners, tri_part, points, point_set, set_ptr, set_parts, cutoff, group=48):
    d2, tri, counts = tree.nearest(points, point_set, set_ptr, set_parts, cutoff, group=group)
    bd2, btri = _brute(points, point_set, set_ptr, set_parts, corners, tri_part,
                       squared_bound(cutoff))
    np.testing.assert_array_equal(d2, bd2)  # to the last bit
    np.testing.assert_array_equal(tri >= 0, btri >= 0)
    found = np.flatnonzero(tri >= 0)
    tmp = np.empty(3)
    for i in found:  # a tie may name another triangle: at the same distance, and allowed
        t = tri[i]
        assert closest_point_on_triangle(points[i], *corners[t], tmp) == d2[i]
        s = point_set[i]
        assert tri_part[t] not in set_parts[set_ptr[s]:set_ptr[s + 1]]
    assert counts["groups"] >= 1 if (point_set >= 0).any() else counts["groups"] == 0
    return d2, tri


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 120), st.integers(1, 300),
       st.integers(1, 5), st.integers(1, 6), st.sampled_from([1, 3, 48]),
       st.sampled_from([1, 2, 16]), st.sampled_from([0.01, 0.5, 2.0, 100.0]))
def test_equals_brute_force_to_the_last_bit(seed, n_tri, n_points, n_parts, n_sets, group,
                                            leaf, cutoff):
    corners, tri_part, points, point_set, set_ptr, set_parts = random_case(
        seed, n_tri, n_points, n_parts, n_sets)
    tree = BatchedTriangleTree(corners, tri_part, leaf_size=leaf)
    check(tree, corners, tri_part, points, point_set, set_ptr, set_parts, cutoff, group)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(1e3, 1e7))
def test_far_from_the_origin_and_slivers(seed, offset):
    """Coordinates far from the origin and long slivers (split into several references):
    still bit for bit."""
    corners, tri_part, points, point_set, set_ptr, set_parts = random_case(seed, 60, 200, 3, 4)
    # the tree splits a triangle whose box diagonal exceeds split_factor (4) times the median
    # diagonal. At least 50 of the 60 diagonals are at most m, the largest of the other 50, so
    # the median is at most m; a sliver of length L > 4·m (and > 0 where m = 0) is split. With
    # L = max(40, 5·m) the margin L − 4·m >= 8 dwarfs the rounding of diagonals at 1e7 (1e-8).
    others = np.linalg.norm(corners[10:].max(axis=1) - corners[10:].min(axis=1), axis=1)
    length = max(40.0, 5.0 * others.max())
    corners[:10, 1] = corners[:10, 0] + np.array([1.0, 0.0125, 0.0]) * length
    corners = corners + offset
    points = points + offset
    tree = BatchedTriangleTree(corners, tri_part, leaf_size=2)
    assert len(tree.ref_tri) > 60  # the slivers are entered as several references
    check(tree, corners, tri_part, points, point_set, set_ptr, set_parts, 1.5)


def test_points_exactly_on_shared_edges_and_at_the_cutoff():
    # two parts meeting at an edge, a third 1.0 above: points on the edge, on the faces and
    # exactly 1.0 from part 2 (the cut-off) are found, those a hair beyond are not
    corners = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                        [[1, 0, 0], [1, 1, 0], [0, 1, 0]],
                        [[0, 0, 1], [1, 0, 1], [0, 1, 1]]], float)
    tri_part = np.array([0, 1, 2])
    points = np.array([[0.5, 0.5, 0], [0.2, 0.2, 0], [0.8, 0.8, 0], [0.2, 0.2, 0.0],
                       [0.2, 0.2, -1e-12]])
    set_ptr = np.array([0, 1, 2, 4])
    set_parts = np.array([0, 1, 0, 1])
    point_set = np.array([0, 0, 1, 2, 2])
    tree = BatchedTriangleTree(corners, tri_part, leaf_size=1)
    d2, tri = check(tree, corners, tri_part, points, point_set, set_ptr, set_parts, 1.0)
    assert d2[0] == 0.0 and tri[0] == 1  # on the shared edge: part 1 at distance 0
    assert d2[3] == 1.0 and tri[3] == 2  # exactly at the cut-off
    assert d2[4] == np.inf and tri[4] == -1  # a hair beyond it


def test_a_candidate_list_longer_than_its_first_buffer():
    # 2000 tiny triangles of one part in a small ball, and a cut-off that takes every leaf
    # in: the group's candidates outgrow the first buffer and the group is searched again
    rng = np.random.default_rng(5)
    corners = rng.uniform(-1, 1, (2000, 1, 3)) + rng.normal(scale=0.01, size=(2000, 3, 3))
    tri_part = np.ones(2000, np.int64)
    points = rng.uniform(-1, 1, (100, 3))
    tree = BatchedTriangleTree(corners, tri_part, leaf_size=1)
    set_ptr, set_parts = np.array([0, 1]), np.array([0])
    d2, tri = check(tree, corners, tri_part, points, np.zeros(100, np.int64), set_ptr,
                    set_parts, 10.0, group=100)
    assert (tri >= 0).all()


def test_results_do_not_depend_on_threads_or_group_size():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has a single thread here")
    corners, tri_part, points, point_set, set_ptr, set_parts = random_case(7, 3000, 20000, 4, 6)
    tree = BatchedTriangleTree(corners, tri_part)
    before = numba.get_num_threads()
    results = []
    try:
        for threads, group in ((1, 48), (2, 48), (2, 5)):
            numba.set_num_threads(threads)
            results.append(tree.nearest(points, point_set, set_ptr, set_parts, 0.3,
                                        group=group))
    finally:
        numba.set_num_threads(before)
    for d2, _, _ in results[1:]:
        np.testing.assert_array_equal(d2, results[0][0])
    # same groups, any thread count: the same triangles and counters as well
    np.testing.assert_array_equal(results[0][1], results[1][1])
    assert results[0][2] == results[1][2]


def test_tree_shape():
    corners, tri_part, *_ = random_case(1, 500, 1, 3, 2)
    tree = BatchedTriangleTree(corners, tri_part, leaf_size=4)
    assert tree.n_triangles == 500 and tree.n_boxes == tree.n_nodes * 4 - np.sum(
        ~np.isfinite(tree.box[:, 0, :]))
    # every reference is in exactly one leaf, every leaf under exactly one slot
    leaves = -tree.child[tree.child < 0] - 1
    assert len(np.unique(leaves)) == len(leaves)
    covered = np.concatenate([np.arange(tree.leaf_first[f], tree.leaf_first[f]
                                        + tree.leaf_count[f]) for f in leaves])
    np.testing.assert_array_equal(np.sort(covered), np.arange(len(tree.ref_tri)))
    # a slot's part is its leaf's, when the leaf has one part
    for w, k in zip(*np.nonzero(tree.child < 0)):
        f = -tree.child[w, k] - 1
        parts = np.unique(tri_part[tree.ref_tri[tree.leaf_first[f]:tree.leaf_first[f]
                                                + tree.leaf_count[f]]])
        assert tree.part[w, k] == (parts[0] if len(parts) == 1 else -1)
    # one triangle: the root holds one leaf
    one = BatchedTriangleTree(corners[:1], tri_part[:1])
    assert one.n_nodes == 1 and one.n_boxes == 1
    d2, tri, _ = one.nearest(np.zeros((1, 3)), np.array([0]), np.array([0, 0]),
                             np.zeros(0, np.int64), 1e3)
    assert tri[0] == 0


def test_refusals():
    corners, tri_part, points, point_set, set_ptr, set_parts = random_case(2, 20, 10, 2, 3)
    for bad in (corners[:, :2], corners.reshape(-1, 3), corners[:0]):
        with pytest.raises(ValueError, match="corners"):
            BatchedTriangleTree(bad, tri_part[:len(bad)])
    nan = corners.copy()
    nan[3, 1, 2] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        BatchedTriangleTree(nan, tri_part)
    for bad in (tri_part[:-1], tri_part - 5, tri_part.astype(float)):
        with pytest.raises(ValueError, match="triangle_part"):
            BatchedTriangleTree(corners, bad)
    with pytest.raises(ValueError, match="leaf_size"):
        BatchedTriangleTree(corners, tri_part, leaf_size=0)
    tree = BatchedTriangleTree(corners, tri_part)
    ok = (points, point_set, set_ptr, set_parts)
    for cutoff in (0.0, -1.0, np.nan, np.inf, "x", None):
        with pytest.raises(ValueError, match="cutoff"):
            tree.nearest(*ok, cutoff)
    for group in (0, 2.5, True):
        with pytest.raises(ValueError, match="group"):
            tree.nearest(*ok, 1.0, group=group)
    with pytest.raises(ValueError, match="points"):
        tree.nearest(points[:, :2], point_set, set_ptr, set_parts, 1.0)
    with pytest.raises(ValueError, match="point_set"):
        tree.nearest(points, point_set[:-1], set_ptr, set_parts, 1.0)
    for bad_set in (len(set_ptr) - 1, -2):
        s = point_set.copy()
        s[4] = bad_set
        with pytest.raises(ValueError, match="point_set: set indices"):
            tree.nearest(points, s, set_ptr, set_parts, 1.0)
    with pytest.raises(ValueError, match="set_ptr"):
        tree.nearest(points, point_set, set_ptr[::-1], set_parts, 1.0)
    # no points, or none to search: nothing found, nothing tested
    for p, s in ((np.zeros((0, 3)), np.zeros(0, np.int64)), (points, np.full(10, -1))):
        d2, tri, counts = tree.nearest(p, s, set_ptr, set_parts, 1.0)
        assert np.isinf(d2).all() and (tri == -1).all() and counts["groups"] == 0
    # non-finite coordinates matter only where a point is searched
    p = points.copy()
    p[2] = np.nan
    s = point_set.copy()
    s[2] = -1
    d2, tri, _ = tree.nearest(p, s, set_ptr, set_parts, 1.0)
    assert d2[2] == np.inf and tri[2] == -1
    s[2] = 0
    with pytest.raises(ValueError, match="non-finite coordinates at point 2"):
        tree.nearest(p, s, set_ptr, set_parts, 1.0)
