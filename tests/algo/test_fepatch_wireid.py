"""The element-id wire frame: the element map against a brute-force rasteriser, the corner
table's quantisation, and the decoded outline against brute-force distances on random meshes
(exact along every edge once elements are MIN_WIDTH texels wide, never a line that is not
there)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.algo.fepatch.surface import CORNER_ROW, TexturedSurface
from workbench.algo.fepatch.wireid import (
    MIN_WIDTH,
    NO_ELEMENT,
    corner_table,
    element_map,
    on_outline,
    outline_distance,
)
from workbench.algo.fepatch.wiretex import element_widths


def atlas_quads(seed: int, nx: int, ny: int, jitter: float, shear: float, aspect: float,
                angle: float, width: float) -> tuple[np.ndarray, tuple[int, int]]:
    """((M, 4, 2) corners in texels, atlas size): a jittered, stretched, sheared and turned quad
    grid scaled so that its narrowest element is ``width`` texels wide, 3 texels from the atlas
    edges."""
    rng = np.random.default_rng(seed)
    p, quads = quad_grid(nx, ny, jitter=jitter, seed=rng, dim=2)
    p[:, 0] = p[:, 0] * aspect + shear * p[:, 1]
    c, s = np.cos(angle), np.sin(angle)
    p = p @ np.array([[c, -s], [s, c]])
    corners = p[quads]
    corners = corners * (width / element_widths(corners).min())
    corners = corners - corners.reshape(-1, 2).min(axis=0) + 3.0 + rng.uniform(0, 1, 2)
    size = tuple(int(v) for v in np.ceil(corners.reshape(-1, 2).max(axis=0) + 3.0))
    return corners, size


def inside(points, corners) -> np.ndarray:
    """(P, M) bool: point in element, by its triangles (0, 1, 2) and (0, 2, 3), edges included."""
    out = np.zeros((len(points), len(corners)), bool)
    for t in (0, 1):
        a, b, c = corners[:, 0], corners[:, 1 + t], corners[:, 2 + t]
        area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        p = points[:, None, :]

        def cross(u, v, p=p):
            return (v[None, :, 0] - u[None, :, 0]) * (p[..., 1] - u[None, :, 1]) \
                - (v[None, :, 1] - u[None, :, 1]) * (p[..., 0] - u[None, :, 0])
        la, lb, lc = cross(b, c) / area, cross(c, a) / area, cross(a, b) / area
        ok = np.abs(area) > 1e-12
        out |= ok[None] & (la >= -1e-9) & (lb >= -1e-9) & (lc >= -1e-9)
    return out


def edge_distances(points, corners) -> np.ndarray:
    """(P, M) distance from every point to the nearest edge of every element, by brute force."""
    a = corners[None, :, :, :]
    b = np.roll(corners, -1, axis=1)[None]
    p = points[:, None, None, :]
    ab = b - a
    den = np.maximum((ab * ab).sum(-1), 1e-300)
    t = np.clip(((p - a) * ab).sum(-1) / den, 0, 1)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1).min(axis=2)


def texel_centres(size) -> np.ndarray:
    jj, ii = np.meshgrid(np.arange(size[0]), np.arange(size[1]))
    return np.c_[jj.ravel() + 0.5, ii.ravel() + 0.5]


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10**6), jitter=st.floats(0.0, 0.3), shear=st.floats(-1.0, 1.0),
       aspect=st.floats(1.0, 4.0), angle=st.floats(0.0, 3.2), width=st.floats(1.0, 3.0),
       border=st.integers(0, 2))
def test_element_map_is_the_element_under_each_texel_or_the_nearest(seed, jitter, shear, aspect,
                                                                   angle, width, border):
    corners, size = atlas_quads(seed, 4, 3, jitter, shear, aspect, angle, width)
    owner = element_map(corners, size, border=border).ravel()
    centres = texel_centres(size)
    holds = inside(centres, corners)
    dist = edge_distances(centres, corners)
    covered = holds.any(axis=1)
    # under an element: an element that holds the centre (the last one, where two share an edge)
    assert (owner[covered] != NO_ELEMENT).all()
    assert holds[covered, owner[covered]].all()
    last = len(corners) - 1 - np.argmax(holds[:, ::-1], axis=1)
    assert np.array_equal(owner[covered], last[covered])
    # outside every element: the nearest one within the border, none beyond
    out = ~covered
    nearest = dist[out].min(axis=1)
    taken = owner[out]
    assert np.array_equal(taken != NO_ELEMENT, nearest <= border)
    near = taken != NO_ELEMENT
    got = dist[out][near, taken[near]]
    assert np.allclose(got, nearest[near], atol=1e-9)


def test_corner_table_quantises_within_half_a_step():
    corners, size = atlas_quads(1, 5, 4, 0.2, 0.3, 2.0, 0.4, 1.5)
    table, frac = corner_table(corners, size)
    assert table.dtype == np.uint16 and table.shape == corners.shape
    assert frac & (frac - 1) == 0 and max(size) * frac <= 65535 < max(size) * frac * 2 or \
        frac == 256
    assert np.abs(table / frac - corners).max() <= 0.5 / frac + 1e-12
    big, big_frac = corner_table(np.full((1, 4, 2), 5000.5), (9000, 10))
    assert big_frac == 4 and big[0, 0, 0] == 20002
    with pytest.raises(ValueError, match="16-bit"):
        corner_table(corners, (70000, 10))
    with pytest.raises(ValueError):
        corner_table(corners[:, :3], size)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), jitter=st.floats(0.0, 0.3), shear=st.floats(-1.0, 1.0),
       aspect=st.floats(1.0, 4.0), angle=st.floats(0.0, 3.2),
       width=st.floats(MIN_WIDTH, 3.0 * MIN_WIDTH))
def test_decoded_outline_is_exact_along_edges_and_never_invents_lines(seed, jitter, shear,
                                                                     aspect, angle, width):
    corners, size = atlas_quads(seed, 5, 4, jitter, shear, aspect, angle, width)
    owner = element_map(corners, size, border=1)
    table, frac = corner_table(corners, size)
    q = table / frac
    # along every edge, nodes included, the decoded distance is within a fifth of a texel
    t = np.linspace(0.0, 1.0, 21)[:, None, None]
    a, b = corners, np.roll(corners, -1, axis=1)
    on_edges = (a[None] + t[..., None] * (b - a)[None]).reshape(-1, 2)
    d = outline_distance(owner, table, frac, on_edges)
    assert d.max() <= 0.2, f"{d.max():.3f} texels off an edge"
    # away from edges it is the brute-force distance to the edges of the four texels' elements
    # (so never below the distance to the nearest edge of the mesh)
    rng = np.random.default_rng(seed)
    points = rng.uniform(0.0, 1.0, (300, 2)) * np.array(size)
    got = outline_distance(owner, table, frac, points)
    x0 = np.clip(np.floor(points - 0.5).astype(int), 0, np.array(size) - 1)
    x1 = np.minimum(np.floor(points - 0.5).astype(int) + 1, np.array(size) - 1)
    x1 = np.maximum(x1, 0)
    every = edge_distances(points, q)
    want = np.full(len(points), np.inf)
    for cols, rows in ((x0[:, 0], x0[:, 1]), (x1[:, 0], x0[:, 1]), (x0[:, 0], x1[:, 1]),
                       (x1[:, 0], x1[:, 1])):
        m = owner[rows, cols]
        ok = m != NO_ELEMENT
        want[ok] = np.minimum(want[ok], every[ok, m[ok]])
    assert np.allclose(got, want, atol=1e-9)
    assert (got >= every.min(axis=1) - 1e-9).all()


def test_on_outline_reads_a_surface_and_refuses_one_without_a_wire_frame():
    corners, size = atlas_quads(2, 3, 3, 0.1, 0.0, 1.0, 0.0, 2.0)
    owner = element_map(corners, size, border=1)
    table, frac = corner_table(corners, size)
    uv = corners.reshape(-1, 2)
    base = {"positions": np.c_[uv, np.zeros(len(uv))], "triangles": np.zeros((0, 3), int),
            "uv": uv, "normal_axis": np.zeros(len(uv), int)}
    surface = TexturedSurface(**base, element_map=np.where(owner < 0, 65535, owner)
                              .astype(np.uint16), corner_table=table, corner_frac=frac,
                              element_base=np.zeros(len(uv), np.int32))
    mid = (corners[:, 0] + corners[:, 1]) / 2
    centre = corners.mean(axis=1)
    assert on_outline(surface, mid, 0.05).all()
    assert not on_outline(surface, centre, 0.05).any()
    assert surface.size == size and surface.no_element == 65535
    assert surface.texture_bytes == owner.size * 2 + CORNER_ROW * 16
    with pytest.raises(ValueError, match="no wire frame"):
        on_outline(TexturedSurface(**base), mid, 0.5)
    with pytest.raises(ValueError, match="positive"):
        on_outline(surface, mid, 0.0)


def test_surface_refuses_an_incomplete_or_doubled_wire_frame():
    corners, size = atlas_quads(3, 2, 2, 0.0, 0.0, 1.0, 0.0, 2.0)
    table, frac = corner_table(corners, size)
    uv = corners.reshape(-1, 2)
    base = {"positions": np.c_[uv, np.zeros(len(uv))], "triangles": np.zeros((0, 3), int),
            "uv": uv, "normal_axis": np.zeros(len(uv), int)}
    emap = np.zeros(size[::-1], np.uint16)
    full = {"element_map": emap, "corner_table": table, "corner_frac": frac,
            "element_base": np.zeros(len(uv), np.int32)}
    TexturedSurface(**base, **full)
    with pytest.raises(ValueError, match="together"):
        TexturedSurface(**base, element_map=emap, corner_table=table)
    with pytest.raises(ValueError, match="not both"):
        TexturedSurface(**base, **full, wire_map=np.zeros((*size[::-1], 4), np.uint8))
    with pytest.raises(ValueError, match="uint16 or uint32"):
        TexturedSurface(**base, **{**full, "element_map": emap.astype(np.int32)})
    with pytest.raises(ValueError, match="element_base outside"):
        TexturedSurface(**base, **{**full, "element_base": np.full(len(uv), 99, np.int32)})
    with pytest.raises(ValueError, match="corner_frac"):
        TexturedSurface(**base, **{**full, "corner_frac": 0})
