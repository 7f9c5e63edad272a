"""The texture-memory rules of fe2003's atlas: element widths against a brute-force reference,
every element's outline decodable at the chosen scale (or drawn as lines when the scale leaves
it too narrow), the quantile scale rule using no more texels than the smallest-element rule,
and the coarser normal map sharing the wire map's texture coordinates."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import grid_quads

from workbench.algo.fepatch import wireid, wiretex
from workbench.algo.fepatch.atlas import build_atlas
from workbench.algo.fepatch.pipeline import PAPER_TEXTURE_RULE, build_model
from workbench.algo.fepatch.surface import TexturedSurface
from workbench.algo.fepatch.wireid import on_outline
from workbench.algo.fepatch.wiretex import element_widths
from workbench.scene.derived import triangulate


def graded_plate(seed: int, nx: int, ny: int, grade: float, skew: float, bump: float):
    """(elements (M, 4), coords (N, 3)): an nx × ny quad grid whose column and row widths grow
    geometrically by ``grade`` (element sizes vary within a subpatch), sheared by ``skew`` and
    jittered, with a gentle bump of height ``bump``."""
    rng = np.random.default_rng(seed)
    xs = np.r_[0.0, np.cumsum(grade ** np.arange(nx))] * 4.0
    ys = np.r_[0.0, np.cumsum(grade ** np.arange(ny)[::-1])] * 4.0
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    x, y = X.ravel() + skew * Y.ravel(), Y.ravel()
    step = 0.15 * min(np.diff(xs).min(), np.diff(ys).min())
    x = x + rng.uniform(-step, step, x.shape)
    y = y + rng.uniform(-step, step, y.shape)
    z = bump * np.sin(np.pi * x / x.max()) * np.sin(np.pi * y / y.max())
    return grid_quads(nx, ny, ij=True), np.c_[x, y, z]


def corner_vertices(e, coords, surface) -> np.ndarray:
    """(M, 4) vertex of every element corner on the original surface."""
    tri = triangulate(e, coords)
    vertex = {}
    for t, k in enumerate(tri.element_of.tolist()):
        for corner, v in zip(tri.corners[t].tolist(), surface.triangles[t].tolist()):
            vertex[(k, int(corner))] = v
    return np.array([[vertex[(k, c)] for c in range(4)] for k in range(len(e))])


def corner_uv(e, coords, surface) -> np.ndarray:
    """(M, 4, 2) atlas positions of every element's corners on the original surface."""
    return surface.uv[corner_vertices(e, coords, surface)]


def element_base(e, coords, surface) -> np.ndarray | int:
    """(M,) the corner-table row of each element's subpatch (0 for the distance texture)."""
    if surface.element_base is None:
        return 0
    return surface.element_base[corner_vertices(e, coords, surface)[:, 0]]


def segment_distance(points, a, b):
    ab = b - a
    length2 = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(np.einsum("pkj,kj->pk", points[:, None] - a[None], ab) / length2, 0, 1)
    q = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None] - q, axis=2).min(axis=1)


# ------------------------------------------------------------------------- element widths
def brute_width(corners: np.ndarray) -> float:
    """Smallest over the edges of the farthest corner from the edge's line, by loops."""
    best = np.inf
    edges = 0
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        d = b - a
        length = float(np.hypot(*d))
        if length <= 1e-9:
            continue
        edges += 1
        far = max(abs(d[0] * (p[1] - a[1]) - d[1] * (p[0] - a[0])) / length for p in corners)
        best = min(best, far)
    return best if edges >= 2 else 0.0


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 10**6), triangle=st.booleans(), scale=st.floats(0.5, 20.0))
def test_element_widths_match_a_brute_force_reference(seed, triangle, scale):
    rng = np.random.default_rng(seed)
    corners = rng.uniform(0, scale, (20, 4, 2))
    if triangle:
        corners[:, 3] = corners[:, 2]
    got = element_widths(corners)
    want = np.array([brute_width(c) for c in corners])
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12)


def test_element_widths_of_known_shapes():
    square = np.array([[[0, 0], [3, 0], [3, 3], [0, 3]]], float)
    rhombus = np.array([[[0, 0], [4, 0], [6, 2], [2, 2]]], float)  # heights 2 and 4·sin 45°
    triangle = np.array([[[0, 0], [4, 0], [0, 3], [0, 3]]], float)  # heights 3, 4, 2.4
    segment = np.array([[[0, 0], [4, 0], [4, 0], [4, 0]]], float)
    assert element_widths(square)[0] == pytest.approx(3.0)
    assert element_widths(rhombus)[0] == pytest.approx(2.0)
    assert element_widths(triangle)[0] == pytest.approx(2.4)
    assert element_widths(segment)[0] == 0.0
    with pytest.raises(ValueError):
        element_widths(np.zeros((2, 3, 2)))


def outline_reach(corners: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(points (K, 2), radius (K,)): every corner of the convex elements ``corners`` (M, 4, 2,
    texels; a triangle repeats one) and how far from it the distance texture's outline can
    reach, ``reach / sin(φ/2)`` for a corner of angle θ, φ = min(θ, π − θ).

    Derivation. At a texel centre the sampler returns the stored byte b of each channel,
    ``b = round(127.5 + 127.5·v/WIRE_RANGE)`` of one element's exact signed distance v (the
    element the centre lies deepest inside, else per channel the smallest among the elements
    whose ring reaches it; then the element that gives the channel passing the test passes it
    alone): off by half a byte, plus float32 storage and byte arithmetic (a few roundings at
    magnitudes under 256, each under 2⁻¹⁷ of a byte, together under 2⁻¹⁴), so the decoded value
    is within ``WIRE_RANGE·(0.5 + 2⁻¹⁴)/127.5`` texels of v. The shader's test, one channel
    within h of zero and the other ≥ −h, thus says for that element: one line k with
    |d_k| ≤ h' and every line with d ≥ −h', h' = ``reach`` = h + that. Beside edge k such a
    centre lies within h' of it. Beyond a corner O of edge k (edge k along +x from O, inside
    above, the adjacent edge at angle θ), the region |y| ≤ h', x·sin θ − y·cos θ ≥ −h', x ≤ 0
    has its corners at (0, ±h'), (−h'·cot(θ/2), −h') and (−h'·tan(θ/2), h'): within
    h'/min(sin(θ/2), cos(θ/2)) = h'/sin(φ/2) of O."""
    points, radius = [], []
    for c in corners:
        q = c[np.linalg.norm(np.roll(c, -1, axis=0) - c, axis=1) > 1e-9]
        u, v = np.roll(q, 1, axis=0) - q, np.roll(q, -1, axis=0) - q
        turn = v[:, 0] * np.roll(v, -1, axis=0)[:, 1] - v[:, 1] * np.roll(v, -1, axis=0)[:, 0]
        assert (turn > 0).all() or (turn < 0).all(), "the derivation needs convex elements"
        cos = np.einsum("ij,ij->i", u, v) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1)
        theta = np.arccos(np.clip(cos, -1.0, 1.0))
        points.append(q)
        radius.append(reach / np.sin(np.minimum(theta, np.pi - theta) / 2))
    return np.concatenate(points), np.concatenate(radius)


# ------------------------------------------------------------------------- the scale rule
ENCODINGS = {"corners": (wireid.MIN_WIDTH, 1.2, 2.2), "distance": (wiretex.MIN_WIDTH, 2.0, 3.0)}


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), grade=st.floats(1.0, 1.25), skew=st.floats(-0.6, 0.6),
       bump=st.floats(0.0, 3.0), share=st.floats(0.0, 1.0), quantile=st.floats(0.0, 0.4),
       encoding=st.sampled_from(sorted(ENCODINGS)))
def test_every_outline_is_decodable_within_a_texel_or_drawn_as_lines(seed, grade, skew, bump,
                                                                     share, quantile, encoding):
    min_width, low, high = ENCODINGS[encoding]
    e, c = graded_plate(seed, 8, 6, grade, skew, bump)
    m = build_model(e, c, "12,0.5,0.3,2", wire_encoding=encoding,
                    texels_per_edge=low + share * (high - low), scale_quantile=quantile)
    o = m.original
    corners = corner_uv(e, c, o)
    base = element_base(e, c, o)
    width = element_widths(corners)
    narrow = width < min_width
    assert m.narrow_elements == int(narrow.sum())
    # node of every vertex: the corners the element triangulation names
    tri = triangulate(e, c)
    nodes = np.zeros(len(o.positions), np.int64)
    nodes[o.triangles.ravel()] = tri.triangles.ravel()
    lines = {tuple(sorted(p)) for p in nodes[o.line_edges].tolist()}
    users: dict = {}
    for k in range(len(e)):
        for j in range(4):
            a, b = int(e[k, j]), int(e[k, (j + 1) % 4])
            if a != b:
                users.setdefault(tuple(sorted((a, b))), []).append((k, j, a))
    t = np.linspace(0.2, 0.8, 7)[:, None]
    probes, probe_base = [], []
    for key, sides in users.items():
        if any(narrow[k] for k, _, _ in sides):
            # too narrow for the texture at this scale: its edges are drawn as lines
            assert key in lines
        if key in lines:
            continue
        for k, j, a in sides:
            ua, ub = corners[k, j], corners[k, (j + 1) % 4]
            along = t if a == key[0] else 1.0 - t  # the same points of the edge on every side
            probes.append(ua + along * (ub - ua))
            probe_base += [np.broadcast_to(base, len(e))[k]] * len(t)
    # recall: along the middle of every edge the texture must show, the outline of one of the
    # edge's elements passes (in its own chart): at every probe inside a subpatch; on subpatch
    # borders, where the two elements lie in different charts and each outlines itself alone,
    # at most probes of every edge (the texture misses a few there under the paper's rule too)
    edge_ids = np.repeat(np.array([i for i, (key, sides) in enumerate(users.items())
                                   if key not in lines for _ in sides], np.int64), len(t))
    position = np.tile(np.arange(len(t)), len(probes))
    hit = on_outline(o, np.concatenate(probes), 0.5, np.array(probe_base)) if probes else \
        np.zeros(0, bool)
    shown = np.zeros((len(users), len(t)), bool)
    np.logical_or.at(shown, (edge_ids, position), hit)
    needed = np.array([key not in lines for key in users])
    inside = np.array([len({int(m.subpatch[k]) for k, _, _ in sides}) == 1
                       for sides in users.values()])
    assert shown[needed & inside].all()
    # on a border, an edge shows over most of its length (a miss runs in from a corner where
    # the charts meet: 3 of 7 probes at worst seen), and the misses stay rare overall
    assert (shown[needed & ~inside].sum(axis=1) > len(t) // 2).all()
    assert shown[needed].mean() >= 0.97 if needed.any() else True
    a = corners.reshape(-1, 2)
    b = np.roll(corners, -1, axis=1).reshape(-1, 2)
    keep = np.linalg.norm(b - a, axis=1) > 1e-9
    if encoding == "distance":
        # precision: every texel centre the texture outlines lies within h' of an edge, or
        # within h'/sin(φ/2) of a corner of angle φ (outline_reach gives the derivation)
        h, w = o.wire_map.shape[:2]
        jj, ii = np.meshgrid(np.arange(w), np.arange(h))
        centres = np.c_[jj.ravel() + 0.5, ii.ravel() + 0.5]
        half = 0.5
        hit = centres[on_outline(o, centres, half)]
        reach = half + wiretex.WIRE_RANGE * (0.5 + 2.0 ** -14) / 127.5
        corner, radius = outline_reach(corners, reach)
        far = hit[segment_distance(hit, a[keep], b[keep]) > reach]
        beyond = np.linalg.norm(far[:, None] - corner[None], axis=2) - radius[None]
        # 1e-9: float64 rounding of these distances (under 1e-12 in atlases < 10⁴ texels)
        assert len(hit) and (beyond.min(axis=1, initial=np.inf) <= 1e-9).all()
        return
    # element ids and corners: along the middle of every edge the decoded distance is within a
    # quarter texel of zero, and anywhere in an element it is never below the true distance to
    # the nearest edge (no line that is not there), up to the corners' quantisation
    if not probes:
        return
    probes = np.concatenate(probes)
    decoded = wireid.outline_distance(o.element_map, o.corner_table, o.corner_frac, probes,
                                      np.array(probe_base), o.no_element)
    assert decoded.max() <= 0.25, f"{decoded.max():.3f} texels off an edge"
    rng = np.random.default_rng(seed)
    k = rng.integers(0, len(e), 400)
    w3 = rng.dirichlet(np.ones(3), 400)
    points = (w3[:, :, None] * corners[k][:, [0, 1, 2]]).sum(axis=1)
    got = wireid.outline_distance(o.element_map, o.corner_table, o.corner_frac, points,
                                  np.broadcast_to(base, len(e))[k], o.no_element)
    true = segment_distance(points, a[keep], b[keep])
    assert (got >= true - 1.0 / o.corner_frac).all()


def test_quantile_rule_spends_no_more_texels_than_the_smallest_element_rule():
    e, c = graded_plate(3, 12, 10, 1.2, 0.3, 1.0)
    labels = np.repeat(np.arange(4), len(e) // 4 + 1)[:len(e)]
    area = {}
    for q in (0.0, 0.1, 0.3):
        atlas = build_atlas(c, e, labels, texels_per_edge=2.5, per_subpatch=True, quantile=q)
        area[q] = sum(w * h for w, h in atlas.extents.values())
    assert area[0.3] <= area[0.1] <= area[0.0]
    assert area[0.3] < area[0.0]
    # turning the axes keeps the unturned rectangle among the candidates: never larger
    for turns in (2, 5):
        turned = build_atlas(c, e, labels, texels_per_edge=2.5, per_subpatch=True, turns=turns)
        plain = build_atlas(c, e, labels, texels_per_edge=2.5, per_subpatch=True)
        for label in plain.extents:
            w, h = turned.extents[label]
            assert w * h <= np.prod(plain.extents[label])
        # the turned chart is the plane projection turned and scaled per axis: distances in
        # texels of the turned axes, divided by the scales, are the plane distances
        _, uv = turned.uv[0]
        _, uv0 = plain.uv[0]
        su, sv = turned.scales[0]
        p0, p1 = (uv - uv.min(axis=0)) / [su, sv], (uv0 - uv0.min(axis=0)) / plain.scales[0]
        d_turned = np.linalg.norm(p0[:, None] - p0[None], axis=2)
        d_plain = np.linalg.norm(p1[:, None] - p1[None], axis=2)
        assert np.allclose(d_turned, d_plain, atol=1e-9 * d_plain.max())
    with pytest.raises(ValueError):
        build_atlas(c, e, labels, turns=0)
    with pytest.raises(ValueError):
        build_atlas(c, e, labels, quantile=1.0)
    with pytest.raises(ValueError):
        build_atlas(c, e, labels, multiple=0)


def test_new_rule_needs_fewer_texels_per_element_than_the_paper_rule():
    # unsheared, so the width rule and the paper's extent rule ask for the same scale; a
    # sheared plate makes the width rule the stricter (the extent rule's narrow elements then
    # lose parts of their outline)
    e, c = graded_plate(5, 14, 10, 1.15, 0.0, 2.0)
    new = build_model(e, c, "A")
    paper = build_model(e, c, "A", **PAPER_TEXTURE_RULE)
    assert new.rgba_texels_per_element < paper.rgba_texels_per_element
    assert paper.narrow_elements == 0


# ------------------------------------------------------------------------- coarser normal map
@pytest.mark.parametrize("reduction", [1, 2, 3])
def test_normal_map_is_coarser_by_an_integer_and_shares_the_coordinates(reduction):
    e, c = graded_plate(1, 8, 6, 1.1, 0.1, 2.0)
    m = build_model(e, c, "A", normal_reduction=reduction, texels_per_edge=3.0)
    s = m.simplified
    ww, wh = s.size
    nh, nw = s.normal_map.shape[:2]
    assert s.element_map.shape == (wh, ww) and (ww, wh) == tuple(m.atlas_size)
    assert (nw * reduction, nh * reduction) == (ww, wh)
    # the map is read at uv / (W, H): at each vertex it gives the vertex normal
    st = s.uv / np.array([ww, wh])
    x = np.clip(st[:, 0] * nw - 0.5, 0, nw - 1)
    y = np.clip(st[:, 1] * nh - 0.5, 0, nh - 1)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, nw - 1), np.minimum(y0 + 1, nh - 1)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    t = s.normal_map.astype(float)
    v = ((1 - fx) * (1 - fy) * t[y0, x0] + fx * (1 - fy) * t[y0, x1]
         + (1 - fx) * fy * t[y1, x0] + fx * fy * t[y1, x1]) / 127.5 - 1.0
    kept = np.array([[1, 2], [0, 2], [0, 1]])[s.normal_axis]
    want = np.take_along_axis(s.normals, kept, axis=1)
    want *= np.where(np.take_along_axis(s.normals, s.normal_axis[:, None].astype(int), 1) < 0,
                     -1.0, 1.0)
    assert np.abs(v - want).max() < 0.1  # a gently bent plate: normals vary slowly


def test_surface_refuses_a_normal_map_that_does_not_divide_the_wire_map():
    tri = np.array([[0, 1, 2]])
    pos = np.eye(3)
    base = {"positions": pos, "triangles": tri, "uv": np.zeros((3, 2)),
            "normal_axis": np.zeros(3, int)}
    TexturedSurface(**base, normal_map=np.zeros((4, 6, 2), np.uint8),
                    wire_map=np.zeros((8, 12, 4), np.uint8))
    for shape in ((3, 6), (4, 5), (8, 6)):
        with pytest.raises(ValueError, match="normal_map"):
            TexturedSurface(**base, normal_map=np.zeros((*shape, 2), np.uint8),
                            wire_map=np.zeros((8, 12, 4), np.uint8))
