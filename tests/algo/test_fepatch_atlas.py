"""Texture atlas: plane projections are isometric on planar subpatches, the Nyquist rule holds,
packed rectangles stay inside the atlas and never overlap."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.algo.fepatch.atlas import build_atlas, plane_frames, quantile_of


def plates(n_plates, seed):
    """Flat quad grids of random size, orientation and cell size, one subpatch each."""
    rng = np.random.default_rng(seed)
    coords, elements, labels = [], [], []
    base = 0
    for k in range(n_plates):
        nx, ny = rng.integers(1, 6, size=2)
        cell = rng.uniform(0.5, 3.0)
        p, quads = quad_grid(nx, ny, cell=cell)
        p[:, 1] *= rng.uniform(0.5, 2)
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        coords.append(p @ q.T + rng.normal(size=3) * 50)
        elements.append(quads + base)
        labels.append(np.full(nx * ny, k))
        base += (nx + 1) * (ny + 1)
    return np.concatenate(coords), np.concatenate(elements), np.concatenate(labels)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 12), seed=st.integers(0, 10**6))
def test_atlas_rectangles_are_inside_and_disjoint(n, seed):
    coords, elements, labels = plates(n, seed)
    atlas = build_atlas(coords, elements, labels)
    w, h = atlas.size
    boxes = []
    for label, (x0, y0) in atlas.offsets.items():
        bw, bh = atlas.extents[label]
        assert 0 <= x0 and x0 + bw <= w and 0 <= y0 and y0 + bh <= h
        boxes.append((x0, y0, x0 + bw, y0 + bh))
        nodes, uv = atlas.uv[label]
        # node texel coordinates stay inside their rectangle, away from the border texels
        assert (uv >= [x0 + atlas.border - 1e-9, y0 + atlas.border - 1e-9]).all()
        assert (uv <= [x0 + bw - atlas.border + 1e-9, y0 + bh - atlas.border + 1e-9]).all()
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            a, b = boxes[i], boxes[j]
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]
    assert 0 < atlas.fill <= 1


@settings(max_examples=30, deadline=None)
@given(n=st.integers(1, 6), seed=st.integers(0, 10**6))
def test_planar_projection_is_isometric_and_the_smallest_edge_gets_two_texels(n, seed):
    coords, elements, labels = plates(n, seed)
    atlas = build_atlas(coords, elements, labels, texels_per_edge=2.0)
    shortest = np.inf
    for label in np.unique(labels):
        nodes, uv = atlas.uv[label]
        where = {node: i for i, node in enumerate(nodes)}
        for quad in elements[labels == label]:
            for a, b in zip(quad, np.roll(quad, -1)):
                d3 = np.linalg.norm(coords[a] - coords[b])
                d2 = np.linalg.norm(uv[where[a]] - uv[where[b]])
                assert d2 == pytest.approx(d3 * atlas.scale, rel=1e-9)
                shortest = min(shortest, d2)
    assert shortest == pytest.approx(2.0, rel=1e-9)


def test_frames_are_orthonormal_and_span_the_plane():
    coords, elements, labels = plates(3, 7)
    for label, (origin, axes) in plane_frames(coords, elements, labels).items():
        assert np.allclose(axes @ axes.T, np.eye(3))
        p = coords[np.unique(elements[labels == label])] - origin
        assert np.abs(p @ axes[2]).max() < 1e-9  # flat: no offset along the normal


def test_texels_per_element_of_a_uniform_grid():
    # one 10 x 10 grid of unit cells at 2 texels per edge: 21 + 2 x 2 border texels a side
    coords, elements, labels = plates(1, 0)
    coords, elements = quad_grid(10, 10)
    atlas = build_atlas(coords, elements, np.zeros(100, int), width=25)
    assert atlas.extents[0] == (25, 25) and atlas.size == (25, 25)
    assert atlas.texels_per_element == pytest.approx(6.25)
    with pytest.raises(ValueError, match="labels"):
        build_atlas(coords, elements, np.zeros(99, int))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(min_value=1e-300, max_value=1e300), min_size=1, max_size=40),
       st.sampled_from([0.0, 0.02, 0.1, 0.3, 0.5, 0.75, 1.0]) | st.floats(0.0, 1.0))
def test_quantile_of_is_numpys_quantile_to_the_last_bit(values, q):
    """The atlas's quantile is numpy's (an independent implementation), bit for bit, on any
    positive finite values: duplicates, 600 decades of magnitude, one value."""
    v = np.array(values)
    assert quantile_of(v, q) == float(np.quantile(v, q))
