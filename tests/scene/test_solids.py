"""Boundary faces of LS-DYNA solid meshes (workbench.scene.solids): exact sharing, outward
winding."""

from collections import Counter
from itertools import permutations, product

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.scene.mesh import FEMesh
from workbench.scene.solids import boundary_surface, solid_faces, solid_kinds


@pytest.fixture(autouse=True, scope="module", params=["numpy", "compiled"])
def kernels(request):
    """Every test runs on both paths: the numpy steps of small models and the compiled kernels
    of large ones (forced for every size)."""
    from workbench.scene import solids

    saved = solids.COMPILED_FROM
    solids.COMPILED_FROM = 10**12 if request.param == "numpy" else 0
    yield request.param
    solids.COMPILED_FROM = saved


# LS-DYNA hex corner i as (x, y, z) bits.
CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
# Kuhn (Freudenthal) split of a cube into 6 tets: a conforming tet mesh on a grid.
KUHN = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]


def grid(n, m, k, h=(1.0, 1.0, 1.0)):
    x, y, z = np.meshgrid(*(np.arange(d + 1) * s for d, s in zip((n, m, k), h)), indexing="ij")
    nodes = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    idx = np.arange(len(nodes)).reshape(n + 1, m + 1, k + 1)
    corners = np.stack([idx[dx:dx + n, dy:dy + m, dz:dz + k].ravel() for dx, dy, dz in CORNERS], 1)
    return nodes, corners  # corners: (cells, 8) in LS-DYNA hex order


def hexes(corners):
    return corners.copy()


def tets(corners):
    t = corners[:, KUHN].reshape(-1, 4)
    return np.concatenate([t, np.repeat(t[:, 3:], 4, axis=1)], axis=1)


def wedges(corners):
    """Two prisms per cell (xy triangles (00,10,11) and (00,11,01), extruded along z)."""
    rows = []
    for a, b, c in ((0, 1, 2), (0, 2, 3)):  # bottom triangle corners; +4 is the one above
        A, B, C = (corners[:, i] for i in (a, b, c))
        A2, B2, C2 = (corners[:, i + 4] for i in (a, b, c))
        rows.append(np.stack([A, B, B2, A2, C, C, C2, C2], 1))
    return np.stack(rows, 1).reshape(-1, 8)


MAKE = {"hex": hexes, "tet": tets, "wedge": wedges}
PER_CELL = {"hex": 1, "tet": 6, "wedge": 2}


def ref_faces(row):
    """Faces of one LS-DYNA solid as sorted node tuples, pure Python, from its pattern."""
    r = [int(v) for v in row]
    if len(set(r)) == 8:
        table = [(0, 1, 2, 3), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (4, 5, 6, 7)]
    elif len(set(r)) == 6:
        table = [(0, 1, 2, 3), (0, 1, 4), (1, 2, 6, 4), (2, 3, 6), (3, 0, 4, 6)]
    else:
        table = [(0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3)]
    return [tuple(sorted(r[i] for i in f)) for f in table]


def ref_boundary(solids):
    count = Counter(f for row in solids for f in ref_faces(row))
    return {(f, e) for e, row in enumerate(solids) for f in ref_faces(row) if count[f] == 1}


def key(face):
    return tuple(sorted({int(v) for v in face}))


def as_set(elements, element_of):
    return {(key(f), int(e)) for f, e in zip(elements, element_of)}


def oriented(face):
    """A face as its cycle of distinct nodes, rotated to start at the smallest: orientation kept."""
    f = [int(v) for v in face]
    if f[3] == f[2]:
        f = f[:3]
    i = f.index(min(f))
    return tuple(f[i:] + f[:i])


def normals_centres(nodes, faces):
    p = nodes[faces]
    normal = 0.5 * np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])  # vector area, tri too
    tri = faces[:, 3] == faces[:, 2]
    centre = np.where(tri[:, None], p[:, :3].mean(1), p.mean(1))
    return normal, centre


def assert_outward(nodes, solids, faces, element):
    """Every face points away from its (convex) solid's centroid."""
    normal, centre = normals_centres(nodes, faces)
    cent = np.array([nodes[np.unique(s)].mean(0) for s in solids])[element]
    assert (np.einsum("ij,ij->i", normal, centre - cent) > 0).all()


def area(nodes, faces):
    return np.linalg.norm(normals_centres(nodes, faces)[0], axis=1).sum()


def enclosed_volume(nodes, faces):
    normal, centre = normals_centres(nodes, faces)
    return np.einsum("ij,ij->", normal, centre) / 3


@pytest.mark.parametrize("n,m,k", [(1, 1, 1), (2, 3, 4), (5, 1, 2)])
def test_hex_block_boundary_is_outer_quads_outward(n, m, k):
    nodes, corners = grid(n, m, k, h=(1.0, 2.0, 0.5))
    solids = hexes(corners)
    elements, parts, element_of = boundary_surface(solids, nodes)
    assert len(elements) == 2 * (n * m + m * k + n * k)
    assert (elements[:, 3] != elements[:, 2]).all()
    assert elements.dtype == np.int32 and parts.dtype == np.int32 and element_of.dtype == np.int64
    normal, centre = normals_centres(nodes, elements)
    box_centre = nodes.mean(0)
    assert (np.einsum("ij,ij->i", normal, centre - box_centre) > 0).all()
    # every boundary face lies on the box surface, and they tile it
    lo, hi = nodes.min(0), nodes.max(0)
    on = np.isclose(centre, lo) | np.isclose(centre, hi)
    assert on.sum(axis=1).min() == 1
    ext = hi - lo
    assert np.isclose(area(nodes, elements),
                      2 * (ext[0] * ext[1] + ext[1] * ext[2] + ext[0] * ext[2]))
    assert as_set(elements, element_of) == ref_boundary(solids)
    FEMesh(nodes, elements, parts)  # drawable as is


@pytest.mark.parametrize("n,m,k", [(1, 1, 1), (3, 2, 2)])
def test_tet_block_boundary_is_outer_triangles(n, m, k):
    nodes, corners = grid(n, m, k, h=(1.5, 1.0, 2.0))
    solids = tets(corners)
    assert (solid_kinds(solids) == 4).all()
    elements, _, element_of = boundary_surface(solids, nodes)
    assert (elements[:, 3] == elements[:, 2]).all()
    assert len(elements) == 2 * 2 * (n * m + m * k + n * k)
    ext = nodes.max(0) - nodes.min(0)
    assert np.isclose(area(nodes, elements),
                      2 * (ext[0] * ext[1] + ext[1] * ext[2] + ext[0] * ext[2]))
    assert np.isclose(enclosed_volume(nodes, elements), ext.prod())
    normal, centre = normals_centres(nodes, elements)
    assert (np.einsum("ij,ij->i", normal, centre - nodes.mean(0)) > 0).all()
    assert_outward(nodes, solids, elements, element_of)
    assert as_set(elements, element_of) == ref_boundary(solids)


def test_wedge_block_boundary():
    n, m, k = 2, 3, 2
    nodes, corners = grid(n, m, k)
    solids = wedges(corners)
    assert (solid_kinds(solids) == 6).all()
    elements, _, element_of = boundary_surface(solids, nodes)
    tri = elements[:, 3] == elements[:, 2]
    assert tri.sum() == 2 * 2 * n * m  # top and bottom: two triangles per cell
    assert (~tri).sum() == 2 * (m * k + n * k)  # the sides: one quad per cell face
    assert np.isclose(area(nodes, elements), 2 * (n * m + m * k + n * k))
    assert np.isclose(enclosed_volume(nodes, elements), n * m * k)
    assert_outward(nodes, solids, elements, element_of)
    assert as_set(elements, element_of) == ref_boundary(solids)


def test_mixed_mesh():
    """Hexes and wedges in a 2x2x1 block, tets on top of a wedge's triangles."""
    nodes, corners = grid(2, 2, 1)
    cells = corners.reshape(2, 2, 8)
    solids = [hexes(cells[0, 0][None]), hexes(cells[1, 1][None]),
              wedges(cells[1, 0][None]), wedges(cells[0, 1][None])]
    w = wedges(cells[1, 0][None])[0]  # [A B B2 A2 C C C2 C2] of the cell's first prism
    top = [w[3], w[2], w[6]]  # A2 B2 C2: its top triangle, the tet's base
    apex = len(nodes)
    nodes = np.vstack([nodes, nodes[top].mean(0) + [0, 0, 1.0]])
    solids.append(np.array([[top[0], top[1], top[2], apex] + [apex] * 4]))
    solids = np.concatenate(solids)
    assert sorted(solid_kinds(solids).tolist()) == [4, 6, 6, 6, 6, 8, 8]
    elements, _, element_of = boundary_surface(solids, nodes)
    assert as_set(elements, element_of) == ref_boundary(solids)
    assert_outward(nodes, solids, elements, element_of)
    box = 4.0  # the 2x2x1 box; the tet adds its volume and replaces one triangle by three
    tet_vol = abs(np.linalg.det(nodes[[top[1], top[2], apex]] - nodes[top[0]])) / 6
    assert np.isclose(enclosed_volume(nodes, elements), box + tet_vol)


def hex_symmetries():
    """The 48 re-numberings of one hex (24 rotations, 24 inverted): new row j = old corner
    sigma(j)."""
    out = []
    for perm in permutations(range(3)):
        for flips in product((0, 1), repeat=3):
            sigma = []
            for c in CORNERS:
                b = tuple(c[perm[a]] ^ flips[a] for a in range(3))
                sigma.append(CORNERS.index(b))
            out.append(sigma)
    return np.array(out)


def wedge_symmetries():
    """The 12 re-numberings of one LS-DYNA wedge ([A B B2 A2 C C C2 C2] as (vertex, level))."""
    pattern = [(0, 0), (1, 0), (1, 1), (0, 1), (2, 0), (2, 0), (2, 1), (2, 1)]
    out = []
    for perm in permutations(range(3)):
        for flip in (0, 1):
            out.append([pattern.index((perm[t], lev ^ flip)) for t, lev in pattern])
    return np.array(out)


def tet_symmetries():
    return np.array([[p[0], p[1], p[2]] + [p[3]] * 5 for p in permutations(range(4))])


SYM = {"hex": hex_symmetries(), "wedge": wedge_symmetries(), "tet": tet_symmetries()}


@pytest.mark.parametrize("kind", ["hex", "wedge", "tet"])
def test_renumbering_and_inversion_give_same_boundary(kind):
    nodes, corners = grid(2, 2, 2)
    solids = MAKE[kind](corners)
    base = boundary_surface(solids, nodes)
    base_set = {(oriented(f), int(e)) for f, e in zip(base[0], base[2])}
    sym = SYM[kind]
    assert len({tuple(s) for s in sym}) == len(sym)
    rng = np.random.default_rng(1)
    for choice in (np.zeros(len(solids), int), rng.integers(0, len(sym), len(solids)),
                   np.full(len(solids), len(sym) - 1)):
        renumbered = np.take_along_axis(solids, sym[choice], axis=1)
        assert (solid_kinds(renumbered) == solid_kinds(solids)).all()
        got = boundary_surface(renumbered, nodes)
        assert {(oriented(f), int(e)) for f, e in zip(got[0], got[2])} == base_set
    # each single symmetry (half of them invert the element) on every solid at once
    for sigma in sym:
        got = boundary_surface(solids[:, sigma], nodes)
        assert {(oriented(f), int(e)) for f, e in zip(got[0], got[2])} == base_set


def test_inverted_elements_counted():
    """Half the hex symmetries reverse the volume sign: the faces are flipped for exactly those."""
    nodes, corners = grid(1, 1, 1)
    flipped = 0
    for sigma in hex_symmetries():
        sf = solid_faces(corners[:, sigma], nodes)
        assert_outward(nodes, corners[:, sigma], sf.faces, sf.element)
        p = nodes[corners[0, sigma]]
        flipped += np.dot(np.cross(p[1] - p[0], p[3] - p[0]), p[4] - p[0]) < 0
    assert flipped == 24


def test_solid_faces_fields_and_all_faces():
    nodes, corners = grid(2, 1, 1)
    solids = np.concatenate([hexes(corners[:1]), wedges(corners[1:2]), tets(corners[1:2])[:1]])
    # the tet shares nodes with the wedges but fills the same space: only node sets matter here
    sf = solid_faces(solids, nodes)
    assert sf.faces.dtype == np.int32 and sf.element.dtype == np.int64
    assert sf.local.dtype == np.int8 and sf.boundary.dtype == bool
    assert np.bincount(sf.element).tolist() == [6, 5, 5, 4]
    assert sf.local.tolist() == [0, 1, 2, 3, 4, 5] + [0, 1, 2, 3, 4] * 2 + [0, 1, 2, 3]
    # local numbering: hex face 0 is n1 n4 n3 n2, face 5 is n5..n8
    assert (key(sf.faces[0]) == key(solids[0, :4])
            and oriented(sf.faces[0]) == oriented(solids[0, [0, 3, 2, 1]]))
    assert key(sf.faces[5]) == key(solids[0, 4:])
    # penta face 1 is the triangle n1 n2 n5
    assert key(sf.faces[7]) == key(solids[1, [0, 1, 4]]) and sf.faces[7, 3] == sf.faces[7, 2]
    parts = np.array([3, 5, 5, 7])
    elements, fparts, element_of = boundary_surface(solids, nodes, parts, all_faces=True)
    assert len(elements) == 6 + 5 + 5 + 4
    assert (fparts == parts[element_of]).all() and fparts.dtype == np.int32
    assert (elements == sf.faces).all()
    b_el, b_parts, b_of = boundary_surface(solids, nodes, parts)
    assert (b_el == sf.faces[sf.boundary]).all() and (b_parts == parts[b_of]).all()


def test_all_faces_counts_per_kind():
    nodes, corners = grid(3, 2, 2)
    for kind, per in (("hex", 6), ("tet", 4), ("wedge", 5)):
        solids = MAKE[kind](corners)
        elements, _, element_of = boundary_surface(solids, nodes, all_faces=True)
        assert len(elements) == per * len(solids)
        assert (np.bincount(element_of) == per).all()
        assert_outward(nodes, solids, elements, element_of)


def test_empty_and_non_manifold():
    nodes, corners = grid(1, 1, 1)
    e, p, o = boundary_surface(np.zeros((0, 8), np.int64), nodes)
    assert e.shape == (0, 4) and p.shape == (0,) and o.shape == (0,)
    # the same hex three times: every face is used thrice, none is boundary
    sf = solid_faces(np.repeat(corners, 3, axis=0), nodes)
    assert not sf.boundary.any()
    # a triangle and a quad sharing three nodes are different faces: a tet below the hex whose
    # base is three of the four nodes of the hex's bottom face (the 3 smallest ids among them)
    bottom = sorted(corners[0, :4].tolist())
    apex = len(nodes)
    nodes = np.vstack([nodes, [0.5, 0.5, -1.0]])
    tet = np.array([bottom[:3] + [apex] * 5])
    solids = np.concatenate([corners, tet])
    sf = solid_faces(solids, nodes)
    assert sf.boundary.all()
    assert as_set(sf.faces[sf.boundary], sf.element[sf.boundary]) == ref_boundary(solids)
    solids = np.concatenate([corners, wedges(corners)[:1]])
    sf = solid_faces(solids, nodes)
    assert as_set(sf.faces[sf.boundary], sf.element[sf.boundary]) == ref_boundary(solids)


@pytest.mark.parametrize("k", [5, 40])
def test_tet_star_around_lowest_node(k):
    """Many faces with the same smallest node (the kernel's large-bucket path): a bipyramid of
    2k tets around node 0 on the axis between two apexes, plus a stray tet sharing node 0 only."""
    ang = 2 * np.pi * np.arange(k) / k
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros(k)], 1)
    nodes = np.vstack([[0, 0, 0], ring, [0, 0, 1], [0, 0, -1], [5, 5, 5], [6, 5, 5], [5, 6, 5]])
    r = 1 + np.arange(k)
    r2 = 1 + (np.arange(k) + 1) % k
    top, bot = k + 1, k + 2
    tets_ = [[0, a, b, top] for a, b in zip(r, r2)] + [[0, b, a, bot] for a, b in zip(r, r2)]
    tets_.append([0, k + 3, k + 4, k + 5])
    solids = np.array([t + [t[3]] * 4 for t in tets_])
    sf = solid_faces(solids, nodes)
    b = sf.boundary
    assert as_set(sf.faces[b], sf.element[b]) == ref_boundary(solids)
    assert b.sum() == 2 * k + 4
    assert_outward(nodes, solids, sf.faces, sf.element)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    dims=st.tuples(*(st.integers(1, 4),) * 3),
    kind=st.sampled_from(["hex", "tet", "wedge", "mixed"]),
    seed=st.integers(0, 2**32 - 1),
    keep=st.floats(0.2, 1.0),
)
def test_random_blocks_match_brute_force(dims, kind, seed, keep):
    rng = np.random.default_rng(seed)
    nodes, corners = grid(*dims)
    if kind == "mixed":  # per cell hex or 2 wedges (conforming: wedges split along z only)
        is_hex = rng.random(len(corners)) < 0.5
        solids = np.concatenate([hexes(corners[is_hex]), wedges(corners[~is_hex])])
        kinds = np.array(["hex"] * int(is_hex.sum()) + ["wedge"] * 2 * int((~is_hex).sum()))
    else:
        solids = MAKE[kind](corners)
        kinds = np.array([kind] * len(solids))
    mask = rng.random(len(solids)) < keep
    if not mask.any():
        mask[rng.integers(len(mask))] = True
    solids, kinds = solids[mask], kinds[mask]
    for name, sym in SYM.items():  # random renumbering of each solid (inverting half the time)
        sel = kinds == name
        solids[sel] = np.take_along_axis(solids[sel], sym[rng.integers(0, len(sym), sel.sum())], 1)
    relabel = rng.permutation(len(nodes))  # random node ids: node i becomes relabel[i]
    new_nodes = np.empty_like(nodes)
    new_nodes[relabel] = nodes
    solids = relabel[solids]
    elements, _, element_of = boundary_surface(solids, new_nodes)
    assert as_set(elements, element_of) == ref_boundary(solids.tolist())
    assert len(as_set(elements, element_of)) == len(elements)
    assert_outward(new_nodes, solids, elements, element_of)
    # a closed outward surface encloses the solids' volume (unit cells: hex 1, wedge 1/2, tet 1/6)
    volume = sum({"hex": 1.0, "wedge": 0.5, "tet": 1 / 6}[k] for k in kinds)
    assert np.isclose(enclosed_volume(new_nodes, elements), volume)


@pytest.mark.parametrize("solids,nodes,match", [
    (np.zeros((2, 7), int), np.zeros((8, 3)), r"\(S, 8\)"),
    (np.zeros(8, int), np.zeros((8, 3)), r"\(S, 8\)"),
    (np.zeros((1, 8)), np.zeros((8, 3)), "integer"),
    (np.arange(8)[None], np.zeros((8, 2)), r"\(N, 3\)"),
    (np.arange(8)[None] - 1, np.zeros((8, 3)), "outside 0..7"),
    (np.arange(8)[None] + 1, np.zeros((8, 3)), "outside 0..7"),
    (np.array([[0, 1, 2, 3, 4, 4, 4, 4]]), np.zeros((8, 3)), "none of the LS-DYNA"),  # pyramid
    (np.array([[0, 0, 2, 3, 4, 5, 6, 7]]), np.zeros((8, 3)), "none of the LS-DYNA"),
    (np.array([[0, 1, 2, 2, 3, 3, 3, 3]]), np.zeros((8, 3)), "none of the LS-DYNA"),
    (np.array([[0, 1, 2, 3, 4, 5, 6, 6]]), np.zeros((8, 3)), "none of the LS-DYNA"),
    (np.array([[0, 1, 2, 3, 4, 4, 4, 4], [0, 1, 2, 3, 4, 5, 6, 7]]), np.zeros((8, 3)), r"\[\(0, "),
    (np.array([[0, 1, 2, 3, 4, 4, 0, 0]]), np.zeros((8, 3)), "none of the LS-DYNA"),
    (np.array([[0, 1, 2, 0, 0, 0, 0, 0]]), np.zeros((8, 3)), "none of the LS-DYNA"),
    (np.arange(8)[None], np.full((8, 3), np.nan), "non-finite"),
])
def test_refusals(solids, nodes, match):
    with pytest.raises(ValueError, match=match):
        solid_faces(solids, nodes)
    with pytest.raises(ValueError, match=match):
        boundary_surface(solids, nodes)


def test_refuses_bad_parts():
    nodes, corners = grid(1, 1, 2)
    with pytest.raises(ValueError, match="parts"):
        boundary_surface(corners, nodes, parts=np.zeros(3, int))
    with pytest.raises(ValueError, match="parts"):
        boundary_surface(corners, nodes, parts=np.zeros(2))
