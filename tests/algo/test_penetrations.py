"""Initial penetrations with shell thickness (crash2000 §4.1) on keyword decks whose answer is
known: two sheets that penetrate by exactly 1 mm, two that do not, and a tilted sheet whose
penetrating nodes are found with exact rational arithmetic; unknown thickness, include decks,
far-away models, self-contact and a brute-force cross-check.

Tolerance of the depths: a distance from the point-triangle kernel is within 64 u R of the
exact one (u = 2^-53, R the largest distance from the node to the triangle's corners,
:mod:`workbench.algo.nearest.triangle`); R < 100 mm on these decks, so 64 u R < 1e-12 mm, and
the depth, (t_n + t_e)/2 - d with thicknesses exact in binary, carries one more rounding:
``TOL = 1e-11`` mm. Far from the origin (1e5 mm) a coordinate read from 6-decimal text is
rounded to the float64 grid there (half an ulp of 1e5, 7.3e-12 mm, per coordinate); the node
and the corners each move by at most sqrt(3) of that, so a distance moves by at most 2.6e-11
mm: ``FAR_TOL = TOL + 3e-11`` mm. The node sets are the same (no node is within 0.05 mm of
the criterion).
"""

import warnings
from fractions import Fraction

import numpy as np
import pytest
from penetration_decks import deck_text, parallel_sheets, tilted_sheets, write

from workbench.algo.nearest.penetrations import PenetrationWarning, penetrations
from workbench.algo.nearest.triangle import points_triangles_distance
from workbench.scene.mesh import FEMesh
from workbench.scene.readers import ParseWarning, load

TOL = 1e-11
FAR_TOL = TOL + 3e-11


# --------------------------------------------------------------------------- helpers
def read(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PenetrationWarning)
        return load(path)


def by_node(r):
    """{node id: (part, other part, depth)} of a result (one row a node here)."""
    ids = r.node_ids[r.node]
    assert len(set(ids.tolist())) == len(ids)
    return {int(i): (int(p), int(o), float(d))
            for i, p, o, d in zip(ids, r.part, r.other_part, r.depth)}


def node_coordinates(mesh, node_id):
    return mesh.nodes[np.flatnonzero(mesh.node_ids == node_id)[0]]


# --------------------------------------------------------------------------- (a), (b)
def test_a_5mm_and_a_3mm_sheet_3mm_apart_penetrate_by_1mm_over_the_overlap(tmp_path):
    mesh = read(write(tmp_path, "a.k", deck_text(parallel_sheets(3.0), [5.0, 3.0])))
    r = penetrations(mesh)
    # (5 + 3)/2 - 3 = 1 for every node over the other sheet (the edge of the overlap
    # included: its nearest point is the other sheet's edge, 3 mm straight away); the next
    # node out is sqrt(3^2 + 5^2) = 5.83 > 4 mm from the other sheet
    expected = {}
    for nodes, part, other in ((parallel_sheets(3.0)[0][0], 1, 2),
                               (parallel_sheets(3.0)[1][0], 2, 1)):
        expected.update({n: (part, other) for n, x, _, _ in nodes if 20.0 <= x <= 50.0})
    got = by_node(r)
    assert {n: v[:2] for n, v in got.items()} == expected
    assert np.allclose(r.depth, 1.0, rtol=0, atol=TOL)
    assert np.allclose(r.distance, 3.0, rtol=0, atol=TOL)
    assert set(r.node_thickness.tolist()) == {5.0, 3.0}
    # the element reached holds the node's projection onto the other sheet
    for node, element in zip(r.node, r.element):
        corners = mesh.nodes[mesh.elements[element]]
        p = mesh.nodes[node]
        assert corners[:, 0].min() <= p[0] <= corners[:, 0].max()
        assert corners[:, 1].min() <= p[1] <= corners[:, 1].max()
    assert r.nodes_checked == mesh.n_nodes and len(r.unchecked_nodes) == 0
    assert [(p["part"], p["other_part"], p["nodes"]) for p in r.pairs()] == [(1, 2, 21),
                                                                            (2, 1, 21)]


def test_two_0_8mm_sheets_1_5mm_apart_do_not_penetrate(tmp_path):
    mesh = read(write(tmp_path, "b.k", deck_text(parallel_sheets(1.5), [0.8, 0.8])))
    r = penetrations(mesh)
    assert len(r) == 0 and r.nodes_checked == mesh.n_nodes
    # within a margin of 0.8 mm they show their clearance: (0.8 + 0.8)/2 - 1.5 = -0.7
    near = penetrations(mesh, margin=0.8)
    assert len(near) == 42 and np.allclose(near.depth, -0.7, rtol=0, atol=TOL)


# --------------------------------------------------------------------------- (c) tilted
def segment_distance_sq(p, a, b) -> Fraction:
    """Exact squared distance from point p to segment ab (2-D, Fractions)."""
    ab = (b[0] - a[0], b[1] - a[1])
    ap = (p[0] - a[0], p[1] - a[1])
    t = (ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] ** 2 + ab[1] ** 2)
    t = min(max(t, Fraction(0)), Fraction(1))
    q = (a[0] + t * ab[0], a[1] + t * ab[1])
    return (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2


def expected_tilted():
    """{node id: (part, other, depth as float)} by exact arithmetic on the deck's text: the
    problem is 2-D (both sheets span y 0..10, every node lies within), each sheet a polyline in
    (x, z); a node penetrates where its squared distance to the other polyline is < 2^2."""
    sheets = tilted_sheets()
    polylines = []
    for nodes, _ in sheets:
        row = sorted({(Fraction(x).limit_denominator(), Fraction(z)) for _, x, y, z in nodes})
        polylines.append(row)
    out = {}
    for k, (nodes, _) in enumerate(sheets):
        other = polylines[1 - k]
        for n, x, _, z in nodes:
            p = (Fraction(x).limit_denominator(), Fraction(z))
            d2 = min(segment_distance_sq(p, a, b) for a, b in zip(other, other[1:]))
            if d2 < 4:
                out[n] = (k + 1, 2 - k, 2.0 - float(d2) ** 0.5)
    return out


def check_tilted(r, tol=TOL):
    expected = expected_tilted()
    got = by_node(r)
    assert set(got) == set(expected)
    for n, (part, other, depth) in expected.items():
        assert got[n][:2] == (part, other)
        assert abs(got[n][2] - depth) <= tol, (n, got[n], depth)


def test_a_tilted_sheet_penetrates_on_a_known_subset(tmp_path):
    mesh = read(write(tmp_path, "c.k", deck_text(tilted_sheets(), [2.0, 2.0])))
    r = penetrations(mesh)
    check_tilted(r)
    expected = expected_tilted()
    # the subset is a strict one on both sheets (5 of 9 columns each), and the tilted sheet's
    # depth falls linearly
    assert sum(1 for v in expected.values() if v[0] == 1) == 15
    assert sum(1 for v in expected.values() if v[0] == 2) == 15
    rising = sorted((node_coordinates(mesh, n)[0], d) for n, (p, _, d) in by_node(r).items()
                    if p == 2)
    x, d = np.array(rising).T
    assert np.allclose(d, 2.0 - (0.7 + x / 16), rtol=0, atol=TOL)


def test_far_from_the_origin_the_answer_is_the_same(tmp_path):
    offset = (1e5, -1e5, 1e5)
    near = read(write(tmp_path, "c.k", deck_text(tilted_sheets(), [2.0, 2.0])))
    far = read(write(tmp_path, "far.k", deck_text(tilted_sheets(), [2.0, 2.0], offset)))
    check_tilted(penetrations(far), FAR_TOL)
    a, b = penetrations(near), penetrations(far)
    assert np.array_equal(a.node, b.node) and np.array_equal(a.element, b.element)
    assert np.allclose(a.depth, b.depth, rtol=0, atol=FAR_TOL)
    far_a = read(write(tmp_path, "fara.k", deck_text(parallel_sheets(3.0), [5.0, 3.0], offset)))
    ra = penetrations(far_a)
    assert len(ra) == 42 and np.allclose(ra.depth, 1.0, rtol=0, atol=FAR_TOL)


# --------------------------------------------------------------------------- the criterion
def test_a_farther_thicker_element_reaches_deeper_than_the_nearest():
    """Part 1 (1 mm thick) under two elements of part 2: a thin one (1.2 mm) at z = 1 over
    x -5..0 and a thick one (3 mm) at z = 1.5 over x 0..5. A node at x = -1 is 1 mm under the
    thin one (depth (1 + 1.2)/2 - 1 = 0.1) and sqrt(1 + 1.5^2) = 1.803 mm from the thick one
    (depth 2 - 1.803 = 0.197): the row names the farther, thick one. A node at x = 1 reaches
    only the thick one (0.5)."""
    nodes = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0],      # part 1 at z = 0
                      [-5, -5, 1.0], [0, -5, 1.0], [0, 5, 1.0], [-5, 5, 1.0],  # thin, z = 1
                      [0, -5, 1.5], [5, -5, 1.5], [5, 5, 1.5], [0, 5, 1.5]],   # thick, z = 1.5
                     float)
    elements = np.array([[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]])
    mesh = FEMesh(nodes, elements, parts=np.array([1, 2, 2]),
                  element_fields={"thickness": np.array([1.0, 1.2, 3.0])})
    r = penetrations(mesh)
    low = {int(n): (int(e), float(d)) for n, e, d in zip(r.node, r.element, r.depth) if n < 4}
    assert set(low) == {0, 1, 2, 3}
    assert low[0] == (2, pytest.approx(2 - np.sqrt(1 + 1.5 ** 2), abs=TOL))
    assert low[1] == (2, pytest.approx(0.5, abs=TOL))
    # with the thin element alone, the nodes at x = -1 penetrate it by 0.1
    thin = FEMesh(nodes[:8], elements[:2], parts=np.array([1, 2]),
                  element_fields={"thickness": np.array([1.0, 1.2])})
    r = penetrations(thin)
    low = {int(n): float(d) for n, d in zip(r.node, r.depth) if n < 4}
    assert low == {0: pytest.approx(0.1, abs=TOL), 3: pytest.approx(0.1, abs=TOL)}


def test_a_node_of_two_parts_is_checked_with_each_against_the_third():
    """A seam node of parts 1 (4 mm) and 2 (1 mm) 1.5 mm under part 3 (1 mm): with part 1's
    thickness it penetrates part 3 ((4 + 1)/2 - 1.5 = 1), with part 2's it does not ((1 +
    1)/2 = 1 < 1.5); never against its own parts."""
    nodes = np.array([[-10, 0, 0], [0, 0, 0], [0, 10, 0], [-10, 10, 0], [10, 0, 0],
                      [10, 10, 0], [-2, -2, 1.5], [2, -2, 1.5], [2, 2, 1.5], [-2, 2, 1.5]],
                     float)
    elements = np.array([[0, 1, 2, 3], [1, 4, 5, 2], [6, 7, 8, 9]])
    mesh = FEMesh(nodes, elements, parts=np.array([1, 2, 3]),
                  element_fields={"thickness": np.array([4.0, 1.0, 1.0])})
    r = penetrations(mesh)
    rows = {(int(n), int(p), int(o)) for n, p, o in zip(r.node, r.part, r.other_part)}
    assert (1, 1, 3) in rows and (1, 2, 3) not in rows
    assert not any(p == o for _, p, o in rows)
    seam = [d for n, p, o, d in zip(r.node, r.part, r.other_part, r.depth) if n == 1]
    assert seam == [pytest.approx(1.0, abs=TOL)]


# --------------------------------------------------------------------------- refusals
def test_unknown_thickness_is_named_in_a_warning_not_dropped_silently(tmp_path):
    mesh = read(write(tmp_path, "a.k", deck_text(parallel_sheets(3.0), [5.0, 3.0])))
    t = mesh.element_fields["thickness"].copy()
    t[mesh.parts == 2] = np.nan  # part 2 unknown
    t[0] = np.nan  # and the first element of part 1
    mesh.element_fields["thickness"] = t
    with pytest.warns(PenetrationWarning) as caught:
        r = penetrations(mesh)
    (message,) = [str(w.message) for w in caught]
    # 20 elements of part 2 (ids 21..40) and element 1; part 2's 33 nodes and node 1 (a
    # corner of element 1 only)
    assert "21 elements (ids 1, 21, 22," in message and "of parts 1, 2" in message
    assert "34 nodes (ids 1, 1001, 1002," in message and "not checked" in message
    assert r.nodes_checked == 66 - 34 and len(r.unknown_elements) == 21
    assert r.unchecked_nodes.tolist() == [0, *range(33, 66)]
    assert len(r) == 0  # part 2 is neither checked nor measured against: nothing to find


def test_an_include_deck_without_its_thickness_parameter_is_refused_naming_it(tmp_path):
    text = deck_text(parallel_sheets(3.0), ["&tsheet", 3.0])
    with pytest.warns(ParseWarning, match="tsheet"):
        mesh = load(write(tmp_path, "include.k", text))
    with pytest.raises(ValueError, match=r"parameter 'tsheet'.*master deck"):
        penetrations(mesh)


def test_a_mesh_without_thickness_or_with_a_bad_one_is_refused():
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    mesh = FEMesh(nodes, np.array([[0, 1, 2, 3]]))
    with pytest.raises(ValueError, match="no element field 'thickness'"):
        penetrations(mesh)
    mesh.element_fields["thickness"] = np.array([-1.0])
    with pytest.raises(ValueError, match="finite and >= 0"):
        penetrations(mesh)
    mesh.element_fields["thickness"] = np.array([1.0])
    with pytest.raises(ValueError, match="margin"):
        penetrations(mesh, margin=-1.0)


# --------------------------------------------------------------------------- self-contact
def fold(gap: float, size: float, n: int):
    """One part folded into a U: a leg at z = 0 and a leg at z = ``gap`` over x 0..n*size,
    joined by a vertical strip at x = n*size; y 0..2*size."""
    xs = np.arange(n + 1) * size
    ys = np.array([0.0, size, 2 * size])
    path = [(x, 0.0) for x in xs] + [(xs[-1], gap)] + [(x, gap) for x in xs[::-1][1:]]
    nodes = np.array([[x, y, z] for y in ys for x, z in path])
    m = len(path)
    elements = [[j * m + i, j * m + i + 1, (j + 1) * m + i + 1, (j + 1) * m + i]
                for j in range(2) for i in range(m - 1)]
    return FEMesh(nodes, np.array(elements), element_fields={
        "thickness": np.full(len(elements), 2.0)}), m


def test_self_contact_finds_a_fold_and_leaves_the_sheet_and_its_bend_alone():
    mesh, m = fold(1.5, 5.0, 8)  # legs 1.5 apart, 2 mm thick: 0.5 mm deep
    assert len(penetrations(mesh)) == 0  # one part: nothing without self-contact
    r = penetrations(mesh, self_contact=True)
    x = mesh.nodes[r.node, 0]
    # every node of both legs but those of the bend (x = 40): its neighbourhood reaches the
    # other leg through the vertical strip
    assert set(np.round(x).tolist()) == set(np.arange(0, 40, 5.0).tolist())
    assert len(r) == 2 * 8 * 3
    assert np.allclose(r.depth, 0.5, rtol=0, atol=TOL) and (r.part == r.other_part).all()


def test_self_contact_never_reports_a_fine_flat_or_curved_sheet():
    """Elements of 0.5 mm under a 3 mm thickness: elements two and three rings away are within
    (3 + 3)/2 mm of a node, all of them its own neighbourhood."""
    u, v = np.meshgrid(np.arange(41) * 0.5, np.arange(11) * 0.5)
    flat = np.stack([u.ravel(), v.ravel(), np.zeros(u.size)], axis=1)
    angle = u.ravel() / 20.0  # a cylinder of radius 20 mm, 1 rad of it
    curved = np.stack([20 * np.sin(angle), v.ravel(), 20 * (1 - np.cos(angle))], axis=1)
    quads = np.array([[j * 41 + i, j * 41 + i + 1, (j + 1) * 41 + i + 1, (j + 1) * 41 + i]
                      for j in range(10) for i in range(40)])
    for nodes in (flat, curved):
        mesh = FEMesh(nodes, quads, element_fields={"thickness": np.full(len(quads), 3.0)})
        assert len(penetrations(mesh, self_contact=True)) == 0


# --------------------------------------------------------------------------- cross-check
def brute_force(mesh):
    """{(node, part, other part): largest depth} of every (node, part) pair against every
    triangle of the parts the node does not belong to: numpy, all pairs."""
    t = mesh.element_fields["thickness"]
    tri = mesh.triangulation
    corners = mesh.nodes[tri.triangles]
    d = points_triangles_distance(mesh.nodes, corners)  # (N, T)
    tri_part = mesh.parts[tri.element_of]
    tri_t = t[tri.element_of]
    node_parts = {}
    for e, p in enumerate(mesh.parts):
        for v in set(mesh.elements[e].tolist()):
            node_parts.setdefault(v, {}).setdefault(int(p), []).append(t[e])
    out = {}
    for v, parts in node_parts.items():
        for p, ts in parts.items():
            other = ~np.isin(tri_part, list(parts))
            depth = (max(ts) + tri_t[other]) / 2 - d[v, other]
            for q in np.unique(tri_part[other][depth > 0]):
                out[v, p, int(q)] = float(depth[tri_part[other] == q].max())
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_matches_every_pair_by_brute_force(seed):
    """Three wavy sheets with a random thickness per element, close enough to penetrate here
    and there, and a seam between two of them."""
    rng = np.random.default_rng(seed)
    u, v = np.meshgrid(np.linspace(0, 30, 13), np.linspace(0, 20, 9))
    blocks = []
    for k in range(3):
        z = 1.2 * k + 0.6 * np.sin(u / 4 + k) * np.cos(v / 5) + rng.uniform(-0.1, 0.1, u.shape)
        blocks.append(np.stack([u.ravel() + 3 * k, v.ravel(), z.ravel()], axis=1))
    quads = np.array([[j * 13 + i, j * 13 + i + 1, (j + 1) * 13 + i + 1, (j + 1) * 13 + i]
                      for j in range(8) for i in range(12)])
    nodes = np.concatenate(blocks)
    elements = np.concatenate([quads + k * len(blocks[0]) for k in range(3)])
    elements[elements == 2 * len(blocks[0]) + 5] = 5  # a node shared by parts 1 and 3
    parts = np.repeat([1, 2, 3], len(quads))
    t = rng.uniform(0.5, 3.0, len(elements))
    mesh = FEMesh(nodes, elements, parts=parts, element_fields={"thickness": t})
    r = penetrations(mesh)
    got = {(int(n), int(p), int(o)): float(d)
           for n, p, o, d in zip(r.node, r.part, r.other_part, r.depth)}
    expected = brute_force(mesh)
    assert len(expected) > 50
    assert set(got) == set(expected)
    assert max(abs(got[k] - expected[k]) for k in got) <= TOL
    r_obb = penetrations(mesh, kind="obb", leaf_size=4)
    assert np.array_equal(r_obb.node, r.node) and np.allclose(r_obb.depth, r.depth, atol=TOL)
