"""Wire-frame distance texture: checkerboard colouring and line-edge fallback, the texture's
outlines against the element edges (precision and recall on jittered quad grids, brute-force
point-to-segment reference), signs across edges, triangles, and refused input."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.algo.fepatch.surface import WIRE_PAIRS
from workbench.algo.fepatch.wiretex import RING, checkerboard, decode_wire, on_outline, wire_texture


def texel_grid(nx, ny, cell, jitter=0.0, offset=(0.0, 0.0), seed=0):
    """(nodes (N, 2), elements (M, 4)) of an nx × ny grid of counter-clockwise quads with
    ``cell`` texels per side, nodes jittered by up to ``jitter`` texels."""
    return quad_grid(nx, ny, cell=cell, origin=offset, jitter=jitter, seed=seed, dim=2)


def texel_centres(w, h):
    jj, ii = np.meshgrid(np.arange(w), np.arange(h))
    return np.c_[jj.ravel() + 0.5, ii.ravel() + 0.5]


def edges_of(corners):
    """(start, end) of every non-degenerate element edge, (K, 2) each."""
    a = corners.reshape(-1, 2)
    b = np.roll(corners, -1, axis=1).reshape(-1, 2)
    keep = np.linalg.norm(b - a, axis=1) > 1e-9
    return a[keep], b[keep]


def distance_to_segments(points, a, b):
    """Brute force: each point's distance to the nearest segment a→b."""
    ab = b - a
    t = np.einsum("pkj,kj->pk", points[:, None] - a[None], ab) / (ab * ab).sum(axis=1)
    q = a[None] + np.clip(t, 0, 1)[..., None] * ab[None]
    return np.linalg.norm(points[:, None] - q, axis=2).min(axis=1)


def edge_probes(a, b, n=7):
    """Points along the middle 60 % of each segment."""
    t = np.linspace(0.2, 0.8, n)[None, :, None]
    return (a[:, None] + t * (b - a)[:, None]).reshape(-1, 2)


def atlas_for(corners, margin=3):
    return (int(np.ceil(corners[..., 0].max())) + margin,
            int(np.ceil(corners[..., 1].max())) + margin)


# ---------------------------------------------------------------- checkerboard

def test_grid_colours_alternate_across_every_shared_edge():
    _, e = texel_grid(7, 5, 3.0)
    colour, line_edges = checkerboard(e)
    assert colour.dtype == np.int8 and set(np.unique(colour)) == {0, 1}
    assert line_edges.shape == (0, 2)
    c = colour.reshape(5, 7)
    assert (c[:, 1:] != c[:, :-1]).all() and (c[1:] != c[:-1]).all()


def test_three_quads_around_a_node_leave_exactly_one_line_edge():
    # node 0 in the middle; the quads share the edges 0-1, 0-3 and 0-5 pairwise: an odd cycle
    e = np.array([[0, 1, 2, 3], [0, 3, 4, 5], [0, 5, 6, 1]])
    colour, line_edges = checkerboard(e)
    users = {(0, 1): (0, 2), (0, 3): (0, 1), (0, 5): (1, 2)}
    same = [edge for edge, (p, q) in users.items() if colour[p] == colour[q]]
    assert len(same) == 1
    assert line_edges.tolist() == [list(same[0])]


@pytest.mark.parametrize("closed, k, expected", [(False, 6, 0), (True, 6, 0), (True, 5, 1),
                                                 (True, 7, 1)])
def test_triangle_fans(closed, k, expected):
    ring = np.arange(1, k + 1)
    nxt = np.roll(ring, -1) if closed else ring[1:]
    ring = ring if closed else ring[:-1]
    e = np.stack([np.zeros_like(ring), ring, nxt, nxt], axis=1)
    colour, line_edges = checkerboard(e)
    assert len(line_edges) == expected
    for a, b in line_edges:  # a spoke from the centre whose two triangles share a colour
        assert a == 0
        users = np.flatnonzero((e == b).any(axis=1))
        assert len(users) == 2 and colour[users[0]] == colour[users[1]]


def element_edge_users(e):
    users = {}
    for m, el in enumerate(e):
        for k in range(4):
            a, b = int(el[k]), int(el[(k + 1) % 4])
            if a != b:
                users.setdefault((min(a, b), max(a, b)), []).append(m)
    return users


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), n=st.integers(4, 60))
def test_every_shared_edge_is_shown_by_two_colours_or_drawn_as_a_line(seed, n):
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(seed)
    tri = Delaunay(rng.uniform(0, 1, (n, 2))).simplices
    e = np.c_[tri, tri[:, 2]]
    colour, line_edges = checkerboard(e)
    drawn = {tuple(x) for x in line_edges.tolist()}
    assert len(drawn) == len(line_edges)
    for edge, users in element_edge_users(e).items():
        if len(users) == 2:
            assert (colour[users[0]] == colour[users[1]]) == (edge in drawn)
        else:
            assert edge not in drawn


def test_degenerate_elements_get_colour_0_and_no_adjacency():
    e = np.array([[0, 1, 2, 3], [1, 1, 2, 2], [1, 4, 5, 2]])
    colour, line_edges = checkerboard(e)
    assert colour[1] == 0 and colour[0] != colour[2] and len(line_edges) == 0


def test_checkerboard_refuses_bad_input():
    with pytest.raises(ValueError):
        checkerboard(np.zeros((3, 3), int))
    with pytest.raises(ValueError):
        checkerboard(np.array([[0, 1, 2, -1]]))
    with pytest.raises(ValueError):
        checkerboard(np.zeros((2, 4)))


# ---------------------------------------------------------------- texture

@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10**6), cell=st.floats(2.5, 8.0), jitter=st.floats(0.0, 0.2),
       nx=st.integers(1, 5), ny=st.integers(1, 5),
       ox=st.floats(2.0, 3.0), oy=st.floats(2.0, 3.0))
@example(seed=249, cell=4.8125, jitter=0.171875, nx=1, ny=1, ox=2.25, oy=2.0)  # a 56° corner
def test_outline_matches_the_element_edges_on_jittered_grids(seed, cell, jitter, nx, ny, ox, oy):
    nodes, e = texel_grid(nx, ny, cell, jitter * cell, (ox, oy), seed)
    colour, line_edges = checkerboard(e)
    assert len(line_edges) == 0
    corners = nodes[e]
    w, h = atlas_for(corners)
    tex = wire_texture(corners, colour, (w, h))
    a, b = edges_of(corners)
    centres = texel_centres(w, h)
    hit = on_outline(tex, centres, 0.5)
    # precision: every texel centre on the outline is within a texel of an element edge, or,
    # where an edge's line runs on past an acute corner inside the written ring, within RING
    # of that corner
    assert hit.any()
    far = centres[hit][distance_to_segments(centres[hit], a, b) > 1.0]
    if len(far):
        to_corner = np.linalg.norm(far[:, None, :] - a[None, :, :], axis=2).min(axis=1)
        assert (to_corner <= RING).all()
    # recall: every element edge is covered along its middle 60 %
    assert on_outline(tex, edge_probes(a, b), 0.5).all()


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10**6), cell=st.floats(7.0, 10.0), jitter=st.floats(0.0, 0.1))
def test_own_pair_is_positive_just_inside_each_edge_and_negative_just_outside(seed, cell, jitter):
    nodes, e = texel_grid(3, 3, cell, jitter * cell, (2.3, 2.6), seed)
    colour, _ = checkerboard(e)
    corners = nodes[e]
    tex = wire_texture(corners, colour, atlas_for(corners))
    for m, c in enumerate(corners):
        for k in range(4):
            a, b = c[k], c[(k + 1) % 4]
            d = b - a
            length = np.linalg.norm(d)
            inward = np.array([-d[1], d[0]]) / length  # counter-clockwise quads
            # away from the corners: within about 2 texels of a node, the field of the diagonal
            # neighbour, which writes the same pair, can take over outside the element
            t = np.linspace(2.5, length - 2.5, 5)[:, None] / length
            on = a + t * d
            inside = decode_wire(tex, on + 0.4 * inward)[:, colour[m], k % 2]
            outside = decode_wire(tex, on - 0.4 * inward)[:, colour[m], k % 2]
            assert (inside > 0).all() and (outside < 0).all(), (m, k)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10**6), size=st.floats(4.0, 12.0))
def test_a_triangle_outlines_its_three_edges(seed, size):
    rng = np.random.default_rng(seed)
    while True:
        p = rng.uniform(0, size, (3, 2)) + 2.0
        ab, ac = p[1] - p[0], p[2] - p[0]
        area = abs(ab[0] * ac[1] - ab[1] * ac[0]) / 2
        sides = np.linalg.norm(p - np.roll(p, 1, axis=0), axis=1)
        if area / sides.max() >= 1.5:  # at least 3 texels thick
            break
    corners = np.r_[p, p[2:]][None]
    w, h = atlas_for(corners)
    tex = wire_texture(corners, np.array([1]), (w, h))
    a, b = edges_of(corners)
    assert len(a) == 3
    centres = texel_centres(w, h)
    hit = on_outline(tex, centres, 0.5)
    # the shader's test (both lines within h) reaches h / sin(angle / 2) beyond a corner; half a
    # texel more for the bilinear lookup
    angle = np.array([np.arccos(np.dot(p[(k + 1) % 3] - p[k], p[k - 1] - p[k])
                                / np.linalg.norm(p[(k + 1) % 3] - p[k])
                                / np.linalg.norm(p[k - 1] - p[k])) for k in range(3)])
    tip = np.linalg.norm(centres[hit][:, None] - p[None], axis=2) <= 0.5 / np.sin(angle / 2) + 0.5
    near = distance_to_segments(centres[hit], a, b) <= 1.0
    assert (near | tip.any(axis=1)).all()
    assert on_outline(tex, edge_probes(a, b), 0.5).all()
    # edges ab and ca in the first channel of pair 1, bc in the second
    inside = decode_wire(tex, edge_probes(a, b, 5))[:, 1]
    assert np.abs(inside[:5, 0]).max() < 0.3 and np.abs(inside[10:, 0]).max() < 0.3
    assert np.abs(inside[5:10, 1]).max() < 0.3


def test_unwritten_texels_are_outside_and_far_interior_is_clamped():
    nodes, e = texel_grid(1, 1, 12.0, offset=(4.0, 4.0))
    tex = wire_texture(nodes[e], np.array([0]), (24, 24))
    g, b = WIRE_PAIRS[0]
    r, a = WIRE_PAIRS[1]
    assert (tex[..., [r, a]] == 0).all()  # nobody writes pair 1
    assert (tex[0, 0, [g, b]] == 0).all()  # far outside
    assert (tex[10, 10, [g, b]] == 255).all()  # 6 texels deep: clamped to +wire_range
    # a texel centre 0.5 texel inside edge 0 (y = 4): distance 0.5 -> byte round(127.5 + 31.875)
    assert tex[4, 10, g] == 159 and tex[4, 10, b] == 255


def test_same_colour_neighbours_have_no_zero_crossing_on_their_shared_edge():
    # why line_edges exist: across the common edge of two quads of one colour the pair stays
    # positive (each side keeps its own element's distance), so no isoline marks the edge
    nodes, e = texel_grid(2, 1, 6.0, offset=(3.2, 3.4))
    corners = nodes[e]
    shared = edge_probes(corners[0, 1][None], corners[0, 2][None])
    across = np.array([0.4, 0.0])
    same = wire_texture(corners, np.array([0, 0]), (20, 14))
    for probe in (shared - across, shared, shared + across):
        assert (decode_wire(same, probe)[:, 0, 1] > 0).all()
    diff = wire_texture(corners, np.array([0, 1]), (20, 14))
    assert (decode_wire(diff, shared + across)[:, 0, 1] < 0).all()
    assert (decode_wire(diff, shared - across)[:, 1, 1] < 0).all()
    assert on_outline(diff, shared, 0.5).all()


def test_degenerate_elements_write_nothing():
    c = np.array([[[2, 2], [5, 5], [5, 5], [2, 2]], [[3, 3], [3, 3], [3, 3], [3, 3]]], float)
    assert (wire_texture(c, np.array([0, 1]), (10, 10)) == 0).all()


def test_wire_texture_refuses_bad_input():
    good = np.zeros((1, 4, 2))
    with pytest.raises(ValueError):
        wire_texture(np.zeros((1, 3, 2)), np.array([0]), (4, 4))
    with pytest.raises(ValueError):
        wire_texture(np.full((1, 4, 2), np.nan), np.array([0]), (4, 4))
    with pytest.raises(ValueError):
        wire_texture(good, np.array([2]), (4, 4))
    with pytest.raises(ValueError):
        wire_texture(good, np.array([0, 1]), (4, 4))
    with pytest.raises(ValueError):
        wire_texture(good, np.array([0]), (0, 4))
    with pytest.raises(ValueError):
        wire_texture(good, np.array([0]), (4, 4), wire_range=0.0)
    with pytest.raises(ValueError):
        decode_wire(np.zeros((4, 4, 3), np.uint8), np.zeros((1, 2)))
    with pytest.raises(ValueError):
        on_outline(np.zeros((4, 4, 4), np.uint8), np.zeros((1, 2)), 0.0)
