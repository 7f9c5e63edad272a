"""Quad stripping by bandification (crash2000, section 3.1) and the triangle-strip baseline.

`quad_strips` is checked three ways: against a slow pure-Python reference that follows the
specification line by line (dicts and lists, one quad at a time), against invariants that hold
for any correct stripping whatever the band choice, and on small hand-checked meshes (a row, a
grid, the L shape of the paper's Fig. 3, a ring, non-manifold and mis-wound edges).
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.algo.strips import quad_strips, tri_strips
from workbench.scene.derived import triangulate

RESTART = 0xFFFFFFFF
PROPERTY = settings(max_examples=60, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

QUAD, TRI, DEGENERATE = "quad", "triangle", "degenerate"


# --------------------------------------------------------------------------- reference
def kind_of(e) -> str:
    """Element kind from its four node indices (quad / triangle / degenerate)."""
    a, b, c, d = e
    adjacent = (a == b) + (b == c) + (c == d) + (d == a)
    opposite = a == c or b == d
    if opposite:
        return DEGENERATE
    return {0: QUAD, 1: TRI}.get(adjacent, DEGENERATE)


def as_rows(elements) -> list[tuple[int, int, int, int]]:
    rows = [tuple(int(x) for x in row)
            for row in np.asarray(elements).reshape(-1, np.shape(elements)[-1])]
    return [r + (r[2],) if len(r) == 3 else r for r in rows]


def edge_users(rows, kinds) -> dict[frozenset, list[int]]:
    """Undirected edge -> non-degenerate elements using it (zero-length edges skipped)."""
    users: dict[frozenset, list[int]] = {}
    for idx, e in enumerate(rows):
        if kinds[idx] == DEGENERATE:
            continue
        for j in range(4):
            u, v = e[j], e[(j + 1) % 4]
            if u != v:
                users.setdefault(frozenset((u, v)), []).append(idx)
    return users


def reference_strips(elements, cutoff: int = 1) -> dict:
    """Bandification exactly as specified, one quad at a time."""
    rows = as_rows(elements)
    kinds = [kind_of(e) for e in rows]
    users = edge_users(rows, kinds)
    quads = [i for i, k in enumerate(kinds) if k == QUAD]

    def neighbour(q, j):
        """(r, k): the quad across q's local edge j and r's local edge back, or None."""
        u, v = rows[q][j], rows[q][(j + 1) % 4]
        using = users[frozenset((u, v))]
        if len(using) != 2:
            return None
        r = using[0] if using[1] == q else using[1]
        if r == q or kinds[r] != QUAD:
            return None
        for k in range(4):
            if rows[r][k] == v and rows[r][(k + 1) % 4] == u:
                return r, k
        return None

    def band(i, d, active):
        """[(quad, entry edge)] of the band through i in direction d."""
        members = {i}

        def walk(edge):
            out = []
            current = i
            while True:
                found = neighbour(current, edge)
                if found is None:
                    break
                r, k = found
                if not active[r] or r in members:
                    break
                members.add(r)
                out.append((r, k))
                current, edge = r, (k + 2) % 4
            return out

        backward = walk(d)
        forward = walk((d + 2) % 4)
        # a backward quad is entered from the quad found after it: its edge opposite k
        result = [(r, (k + 2) % 4) for r, k in reversed(backward)]
        result.append((i, d))
        result += [(r, k) for r, k in forward]
        return result

    def max_band(i, active):
        b0, b1 = band(i, 0, active), band(i, 1, active)
        return b0 if len(b0) >= len(b1) else b1

    active = {q: True for q in quads}
    strips = []
    passes = 0
    while True:
        available = {q: True for q in quads if active[q]}
        found = []
        for i in quads:
            if not (active[i] and available.get(i, False)):
                continue
            b = max_band(i, active)
            if len(b) >= cutoff:
                for q, _ in b:
                    available[q] = False
                found.append(b)
            else:
                active[i] = False
        if not found:
            break
        # passes that found (and so accepted) a band; the final empty one is not counted
        passes += 1
        found.sort(key=len, reverse=True)  # stable: ties keep discovery order
        for b in found:
            if all(active[q] for q, _ in b):
                for q, _ in b:
                    active[q] = False
                strips.append(b)
            else:
                break

    vertex_lists, quad_lists = [], []
    for b in strips:
        q0, e0 = b[0]
        c = rows[q0]
        vs = [c[e0], c[(e0 + 1) % 4]]
        for q, entry in b:
            c = rows[q]
            vs += [c[(entry + 3) % 4], c[(entry + 2) % 4]]
        vertex_lists.append(vs)
        quad_lists.append([q for q, _ in b])
    in_strips = {q for ql in quad_lists for q in ql}
    return {
        "vertices": vertex_lists,
        "quads": quad_lists,
        "leftover": [q for q in quads if q not in in_strips],
        "triangles": [i for i, k in enumerate(kinds) if k == TRI],
        "degenerate": [i for i, k in enumerate(kinds) if k == DEGENERATE],
        "passes": passes,
    }


# --------------------------------------------------------------------------- checks and unstripping
def strips_of(result) -> tuple[list[list[int]], list[list[int]]]:
    """(vertex sequences, quad lists) of a QuadStrips, as Python lists."""
    vs = [result.vertices[result.vertex_starts[s]:result.vertex_starts[s + 1]].tolist()
          for s in range(result.n_strips)]
    qs = [result.quads[result.quad_starts[s]:result.quad_starts[s + 1]].tolist()
          for s in range(result.n_strips)]
    return vs, qs


def is_rotation(seq, target) -> bool:
    seq, target = list(seq), list(target)
    return len(seq) == len(target) and any(seq == target[i:] + target[:i]
                                           for i in range(len(target)))


def canonical(tri) -> tuple:
    """The rotation of a triangle starting at its smallest vertex (winding kept)."""
    t = [int(x) for x in tri]
    i = t.index(min(t))
    return tuple(t[i:] + t[:i])


def unstrip(indices, restart, drop_degenerate=False) -> list[tuple[int, int, int]]:
    """Triangles GL draws from a GL_TRIANGLE_STRIP index buffer with primitive restart."""
    tris = []
    strip: list[int] = []

    def flush():
        for t in range(len(strip) - 2):
            a, b, c = strip[t], strip[t + 1], strip[t + 2]
            if t % 2:
                a, b = b, a
            if drop_degenerate and len({a, b, c}) < 3:
                continue
            tris.append((a, b, c))

    for idx in (int(x) for x in indices):
        if idx == restart:
            flush()
            strip = []
        else:
            strip.append(idx)
    flush()
    return tris


def ears(quad) -> list[tuple]:
    """The four triangles (P[i], P[i+1], P[i+2]) of a quad polygon, in its winding."""
    return [(quad[i], quad[(i + 1) % 4], quad[(i + 2) % 4]) for i in range(4)]


def covers_quad(t1, t2, quad) -> bool:
    """Two triangles sharing a diagonal whose union is the quad, both wound as the quad."""
    e = [canonical(t) for t in ears(quad)]
    c1, c2 = canonical(t1), canonical(t2)
    return c1 in e and c2 in e and e.index(c2) == (e.index(c1) + 2) % 4


def check_invariants(elements, result, cutoff: int) -> None:
    """Everything a correct stripping satisfies, whichever bands it picks."""
    rows = as_rows(elements)
    kinds = [kind_of(e) for e in rows]
    users = edge_users(rows, kinds)
    m = len(rows)

    # fields: shapes and dtypes
    assert result.elements.dtype == np.int32 and result.elements.shape == (m, 4)
    assert result.elements.tolist() == [list(r) for r in rows]
    assert result.vertices.dtype == np.int32 and result.vertices.ndim == 1
    assert result.quads.dtype == np.int32 and result.quads.ndim == 1
    assert result.vertex_starts.dtype == np.int64 and result.quad_starts.dtype == np.int64
    for name in ("leftover", "triangles", "degenerate"):
        assert getattr(result, name).dtype == np.int32, name
    s = result.n_strips
    assert result.vertex_starts.shape == (s + 1,) and result.quad_starts.shape == (s + 1,)
    assert result.vertex_starts[0] == 0 and result.vertex_starts[-1] == len(result.vertices)
    assert result.quad_starts[0] == 0 and result.quad_starts[-1] == len(result.quads)
    assert result.cutoff == cutoff

    vs, qs = strips_of(result)
    for k in range(s):
        assert result.strip(k).tolist() == vs[k]

    # element kinds listed exactly; every quad once in strips or leftover
    assert result.triangles.tolist() == [i for i in range(m) if kinds[i] == TRI]
    assert result.degenerate.tolist() == [i for i in range(m) if kinds[i] == DEGENERATE]
    assert result.leftover.tolist() == sorted(result.leftover.tolist())
    placed = [q for ql in qs for q in ql] + result.leftover.tolist()
    assert sorted(placed) == [i for i in range(m) if kinds[i] == QUAD]

    for verts, quads in zip(vs, qs):
        assert len(quads) >= cutoff
        assert len(verts) == 2 * (len(quads) + 1)
        for k, q in enumerate(quads):
            polygon = (verts[2 * k], verts[2 * k + 1], verts[2 * k + 3], verts[2 * k + 2])
            assert is_rotation(polygon, rows[q]), (q, polygon, rows[q])
            if k + 1 < len(quads):
                # the shared edge joins per the rule: two users, both quads, opposite winding
                u, v = verts[2 * k + 2], verts[2 * k + 3]
                using = users[frozenset((u, v))]
                assert sorted(using) == sorted((q, quads[k + 1]))
                nxt = (verts[2 * k + 2], verts[2 * k + 3], verts[2 * k + 5], verts[2 * k + 4])
                assert is_rotation(nxt, rows[quads[k + 1]])

    # counts
    n_quads_in_strips = sum(len(q) for q in qs)
    n_tris = len(result.triangles)
    assert result.vertex_count == len(result.vertices) + 4 * len(result.leftover) + 3 * n_tris
    expected_mean = 2 * n_quads_in_strips / s if s else 0.0
    assert result.mean_triangles_per_strip == pytest.approx(expected_mean)

    # triangle list: exactly as specified, and each quad covered by its two ears
    tl = result.triangle_list()
    assert tl.dtype == np.int32 and tl.shape == (
        2 * (n_quads_in_strips + len(result.leftover)) + n_tris, 3)
    expected = []
    for verts in vs:
        for k in range((len(verts) - 2) // 2):
            v = verts[2 * k:2 * k + 4]
            expected += [(v[0], v[1], v[2]), (v[2], v[1], v[3])]
    for q in result.leftover.tolist():
        a, b, c, d = rows[q]
        expected += [(a, b, d), (d, b, c)]
    if n_tris:
        tri_of = triangulate(np.array(rows, np.int64)[result.triangles],
                             np.zeros((max(max(r) for r in rows) + 1, 3))).triangles
        expected += [tuple(t) for t in tri_of.tolist()]
    assert [tuple(t) for t in tl.tolist()] == expected
    pos = 0
    for q in [q for ql in qs for q in ql] + result.leftover.tolist():
        assert covers_quad(tl[pos], tl[pos + 1], rows[q]), (q, tl[pos:pos + 2], rows[q])
        pos += 2
    for t in result.triangles.tolist():
        assert set(tl[pos].tolist()) == set(rows[t]) and len(set(tl[pos].tolist())) == 3
        pos += 1

    # restart index buffer draws exactly the triangle list
    ri = result.restart_indices()
    assert ri.dtype == np.uint32 and ri.ndim == 1
    pieces = s + len(result.leftover) + n_tris
    assert int((ri == RESTART).sum()) == max(pieces - 1, 0)
    if len(ri):
        assert ri[0] != RESTART and ri[-1] != RESTART
        assert not ((ri[1:] == RESTART) & (ri[:-1] == RESTART)).any()
    assert int((ri != RESTART).sum()) == (len(result.vertices) + 4 * len(result.leftover)
                                          + 3 * n_tris)
    drawn = unstrip(ri, RESTART)
    assert len(drawn) == len(tl)
    for got, want in zip(drawn, tl.tolist()):
        assert is_rotation(got, want), (got, want)


# --------------------------------------------------------------------------- mesh strategies
def grid(nx: int, ny: int, first: int = 0, wrap: bool = False) -> list[list[int]]:
    """nx x ny quads, counter-clockwise in xy, row-major; wrap closes the rows into a ring."""
    cols = nx if wrap else nx + 1

    def v(i, j):
        return first + (i % nx if wrap else i) + j * cols

    return [[v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]
            for j in range(ny) for i in range(nx)]


@st.composite
def structured_meshes(draw, max_side: int = 10) -> np.ndarray:
    """Grids and rings with holes, rotations, flips, glued, triangle, isolated, degenerate,
    duplicated elements, node renumbering and element shuffling."""
    elements: list[list[int]] = []
    n_nodes = 0
    for _ in range(draw(st.integers(1, 2))):
        nx, ny = draw(st.integers(1, max_side)), draw(st.integers(1, max_side))
        wrap = nx >= 3 and draw(st.booleans())
        elements += grid(nx, ny, n_nodes, wrap)
        n_nodes += (nx if wrap else nx + 1) * (ny + 1)

    def fresh(k):
        nonlocal n_nodes
        n_nodes += k
        return list(range(n_nodes - k, n_nodes))

    m = len(elements)
    holes = draw(st.sets(st.integers(0, m - 1), max_size=m // 3))
    elements = [e for i, e in enumerate(elements) if i not in holes] or elements[:1]
    m = len(elements)
    # mixed-in triangles: drop one corner, store the repeated node at one of four positions
    for i, (drop, at) in draw(st.dictionaries(st.integers(0, m - 1),
                                              st.tuples(st.integers(0, 3), st.integers(0, 3)),
                                              max_size=4)).items():
        p, q, r = [elements[i][(drop + 1 + k) % 4] for k in range(3)]
        elements[i] = [[p, p, q, r], [p, q, q, r], [p, q, r, r], [p, q, r, p]][at]
    for i, rot in draw(st.dictionaries(st.integers(0, m - 1), st.integers(1, 3),
                                       max_size=m)).items():
        elements[i] = elements[i][rot:] + elements[i][:rot]
    for i in draw(st.sets(st.integers(0, m - 1), max_size=m // 4)):
        elements[i] = elements[i][::-1]
    # elements glued onto existing edges (non-manifold edges), quads or triangles
    for i, j, flip, tri in draw(st.lists(st.tuples(st.integers(0, m - 1), st.integers(0, 3),
                                                   st.booleans(), st.booleans()), max_size=4)):
        u, v = elements[i][j], elements[i][(j + 1) % 4]
        if u == v:
            continue
        if flip:
            u, v = v, u
        x, y = fresh(2)
        elements.append([v, u, x, x] if tri else [v, u, x, y])
    # duplicates, possibly rotated or reversed
    for i, rot, rev in draw(st.lists(st.tuples(st.integers(0, m - 1), st.integers(0, 3),
                                               st.booleans()), max_size=3)):
        e = elements[i][rot:] + elements[i][:rot]
        elements.append(e[::-1] if rev else e)
    # degenerate elements on existing nodes
    for i, pattern in draw(st.lists(st.tuples(st.integers(0, m - 1), st.integers(0, 5)),
                                    max_size=4)):
        a, b, c, d = elements[i]
        elements.append([[a, b, a, d], [a, b, c, b], [a, b, a, b], [a, a, a, a],
                         [a, a, b, b], [a, b, b, a]][pattern])
    # isolated elements
    for kind in draw(st.lists(st.sampled_from([QUAD, TRI]), max_size=3)):
        p = fresh(4)
        elements.append(p if kind == QUAD else [p[0], p[1], p[2], p[2]])

    arr = np.array(elements, np.int64)
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    if draw(st.booleans()):
        arr = rng.permutation(3 * n_nodes)[:n_nodes][arr]
    if draw(st.booleans()):
        arr = arr[rng.permutation(len(arr))]
    return arr


@st.composite
def soups(draw) -> np.ndarray:
    """Random elements over a handful of nodes: many shared, non-manifold and degenerate ones."""
    n = draw(st.integers(4, 9))
    node = st.integers(0, n - 1)
    rows = draw(st.lists(st.tuples(node, node, node, node), min_size=1, max_size=25))
    return np.array(rows, np.int64)


meshes = st.one_of(structured_meshes(), soups())


# --------------------------------------------------------------------------- property tests
@PROPERTY
@given(elements=meshes, cutoff=st.integers(1, 4))
def test_matches_reference(elements, cutoff):
    result = quad_strips(elements, cutoff=cutoff)
    ref = reference_strips(elements, cutoff)
    vs, qs = strips_of(result)
    assert qs == ref["quads"]
    assert vs == ref["vertices"]
    assert result.leftover.tolist() == ref["leftover"]
    assert result.triangles.tolist() == ref["triangles"]
    assert result.degenerate.tolist() == ref["degenerate"]
    assert result.passes == ref["passes"]


@PROPERTY
@given(elements=meshes, cutoff=st.integers(1, 4))
def test_invariants(elements, cutoff):
    check_invariants(elements, quad_strips(elements, cutoff=cutoff), cutoff)


@PROPERTY
@given(elements=meshes)
def test_custom_restart_value(elements):
    result = quad_strips(elements)
    restart = int(elements.max()) + 1
    ri = result.restart_indices(restart=restart)
    default = result.restart_indices()
    assert ri.dtype == np.uint32
    assert ((ri == restart) == (default == RESTART)).all()
    assert unstrip(ri, restart) == unstrip(default, RESTART)


@PROPERTY
@given(elements=soups())
def test_triangle_input_is_padded(elements):
    tris = elements[:, :3]
    padded = np.concatenate([tris, tris[:, 2:]], axis=1)
    a, b = quad_strips(tris), quad_strips(padded)
    assert a.elements.tolist() == padded.tolist()
    assert strips_of(a) == strips_of(b)
    assert a.triangles.tolist() == b.triangles.tolist()
    assert a.degenerate.tolist() == b.degenerate.tolist()
    check_invariants(tris, a, 1)


# --------------------------------------------------------------------------- hand-checked meshes
@pytest.mark.parametrize("n", [1, 2, 3, 7])
def test_row_is_one_strip(n):
    result = quad_strips(np.array(grid(n, 1)))
    assert result.n_strips == 1
    assert len(result.strip(0)) == 2 * n + 2
    assert result.vertex_count == 2 * n + 2
    assert result.leftover.size == 0
    assert result.mean_triangles_per_strip == 2 * n
    if n == 3:
        # bottom nodes 0..3, top 4..7; the backward walk runs right, so the band starts there
        assert result.strip(0).tolist() == [3, 7, 2, 6, 1, 5, 0, 4]
        assert result.quads.tolist() == [2, 1, 0]


def test_row_shorter_than_cutoff_is_left_over():
    result = quad_strips(np.array(grid(3, 1)), cutoff=4)
    assert result.n_strips == 0 and result.leftover.tolist() == [0, 1, 2]
    assert result.vertex_count == 12 and result.mean_triangles_per_strip == 0.0
    assert result.restart_indices().tolist() == [0, 1, 4, 5, RESTART, 1, 2, 5, 6, RESTART,
                                                 2, 3, 6, 7]


@pytest.mark.parametrize("m, n", [(2, 1), (5, 3), (4, 4), (9, 2)])
def test_grid_strips_run_along_the_longer_side(m, n):
    result = quad_strips(np.array(grid(m, n)))
    assert result.n_strips == n and result.leftover.size == 0
    _, qs = strips_of(result)
    assert all(len(q) == m for q in qs)
    assert result.vertex_count == n * (2 * m + 2)
    if m > n:
        assert all(len({q // m for q in ql}) == 1 for ql in qs)  # each strip is one row


@settings(max_examples=30, deadline=None)
@given(mn=st.tuples(st.integers(2, 9), st.integers(1, 8)).filter(lambda t: t[0] > t[1]),
       transpose=st.booleans(), seed=st.integers(0, 2**32 - 1))
def test_grid_longer_side_wins_for_any_order_and_rotation(mn, transpose, seed):
    m, n = mn
    rng = np.random.default_rng(seed)
    e = np.array(grid(n, m) if transpose else grid(m, n))
    e = np.array([np.roll(row, r) for row, r in zip(e, rng.integers(0, 4, len(e)))])
    e = e[rng.permutation(len(e))]
    result = quad_strips(e)
    assert result.n_strips == n and result.leftover.size == 0
    _, qs = strips_of(result)
    assert all(len(q) == m for q in qs)


def test_l_shape_gives_two_strips_not_a_swap():
    # Fig. 3: three quads in a row and two above the last one
    full = grid(3, 3)
    e = np.array([full[0], full[1], full[2], full[5], full[8]])
    result = quad_strips(e)
    _, qs = strips_of(result)
    assert qs == [[2, 1, 0], [3, 4]]
    assert result.vertex_count == 8 + 6
    check_invariants(e, result, 1)


def test_ring_closes_on_itself():
    n = 6
    ring = np.array(grid(n, 1, wrap=True))
    result = quad_strips(ring)
    assert result.n_strips == 1 and len(result.quads) == n
    verts = result.strip(0).tolist()
    assert len(verts) == 2 * n + 2 and verts[:2] == verts[-2:]
    tall = quad_strips(np.array(grid(5, 2, wrap=True)))
    assert tall.n_strips == 2 and sorted(np.diff(tall.quad_starts).tolist()) == [5, 5]


def test_opposite_winding_does_not_join():
    joined = quad_strips(np.array([[0, 1, 2, 3], [1, 0, 4, 5]]))
    assert joined.n_strips == 1 and len(joined.quads) == 2
    flipped = quad_strips(np.array([[0, 1, 2, 3], [0, 1, 4, 5]]))
    assert flipped.n_strips == 2 and len(flipped.quads) == 2
    assert quad_strips(np.array([[0, 1, 2, 3], [0, 1, 4, 5]]), cutoff=2).leftover.tolist() == [0, 1]


def test_edge_of_three_quads_joins_none():
    e = np.array([[0, 1, 2, 3], [1, 0, 4, 5], [1, 0, 6, 7]])
    result = quad_strips(e)
    assert result.n_strips == 3 and np.diff(result.quad_starts).tolist() == [1, 1, 1]
    assert quad_strips(e, cutoff=2).leftover.tolist() == [0, 1, 2]


def test_triangle_on_edge_blocks_but_degenerate_is_ignored():
    pair = [[0, 1, 2, 3], [1, 0, 4, 5]]
    with_degenerate = quad_strips(np.array(pair + [[0, 1, 0, 1]]))
    assert with_degenerate.n_strips == 1 and with_degenerate.degenerate.tolist() == [2]
    with_triangle = quad_strips(np.array(pair + [[1, 0, 8, 8]]))
    assert with_triangle.n_strips == 2 and with_triangle.triangles.tolist() == [2]


def test_empty_mesh():
    result = quad_strips(np.zeros((0, 4), np.int32))
    assert result.n_strips == 0 and result.vertex_count == 0
    assert result.triangle_list().shape == (0, 3) and result.restart_indices().shape == (0,)


@pytest.mark.parametrize("bad", [
    np.zeros((3, 5), np.int32), np.zeros(4, np.int32), np.zeros((2, 4), np.float64),
    np.array([[0, 1, 2, -1]]), np.zeros((2, 2), np.int32),
])
def test_bad_elements_refused(bad):
    with pytest.raises(ValueError):
        quad_strips(bad)


@pytest.mark.parametrize("cutoff", [0, -1])
def test_bad_cutoff_refused(cutoff):
    with pytest.raises(ValueError):
        quad_strips(np.array(grid(2, 2)), cutoff=cutoff)


def test_car_deck(car):
    elements = car.elements
    result = quad_strips(elements, cutoff=1)
    check_invariants(elements, result, 1)
    ref = reference_strips(elements, 1)
    assert strips_of(result) == (ref["vertices"], ref["quads"])
    assert result.passes == ref["passes"]
    # fewer vertices than drawing each element on its own (4 per quad, 3 per triangle)
    assert result.vertex_count < (4 * (len(result.quads) + len(result.leftover))
                                  + 3 * len(result.triangles))


# --------------------------------------------------------------------------- tri_strips
def tri_soup(elements) -> np.ndarray:
    coords = np.random.default_rng(0).random((int(elements.max()) + 1, 3))
    return triangulate(elements, coords).triangles


def check_tri_strips(triangles, result, restart=RESTART) -> None:
    idx = result.indices
    assert idx.dtype == np.uint32 and idx.ndim == 1
    assert result.restart == restart
    assert result.n_triangles == len(triangles)
    markers = int((idx == restart).sum())
    assert result.n_vertices == len(idx) - markers
    assert result.n_strips == (markers + 1 if len(idx) else 0)
    if len(idx):
        assert idx[0] != restart and idx[-1] != restart
    if result.n_strips:
        assert result.mean_triangles_per_strip == pytest.approx(
            (result.n_vertices - 2 * result.n_strips) / result.n_strips)
    drawn = unstrip(idx, restart, drop_degenerate=True)
    tl = result.triangle_list()
    assert [tuple(t) for t in np.asarray(tl).tolist()] == drawn
    assert Counter(canonical(t) for t in drawn) == Counter(canonical(t) for t in triangles.tolist())


@PROPERTY
@given(elements=structured_meshes())
def test_tri_strips_draw_the_input(elements):
    triangles = tri_soup(elements)
    check_tri_strips(triangles, tri_strips(triangles))
    check_tri_strips(triangles, tri_strips(triangles, vertex_count=int(elements.max()) + 1))


@pytest.mark.parametrize("restart", [RESTART, 0xFFFF])
def test_tri_strips_on_a_grid_save_vertices(restart):
    e = np.array(grid(8, 6))
    triangles = tri_soup(e)
    result = tri_strips(triangles, restart=restart)
    check_tri_strips(triangles, result, restart)
    assert result.n_vertices < 3 * len(triangles)


@pytest.mark.parametrize("bad", [
    np.zeros((2, 4), np.int32), np.arange(3), np.array([[0.0, 1.0, 2.0]]),
    np.array([[0, 1, -2]]), np.array([[0, 1, 2], [3, 3, 4]]), np.array([[5, 6, 5]]),
])
def test_tri_strips_bad_input_refused(bad):
    with pytest.raises(ValueError):
        tri_strips(bad)


def test_a_restart_value_that_is_a_vertex_index_is_refused():
    e = np.array(grid(3, 2))
    with pytest.raises(ValueError, match="must exceed every vertex index"):
        quad_strips(e).restart_indices(restart=int(e.max()))
    with pytest.raises(ValueError, match="must exceed every vertex index"):
        tri_strips(tri_soup(e), restart=2)
