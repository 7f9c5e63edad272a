"""Normal-map baking: coverage without cracks, constant and linearly varying normal fields at
texel centres, triangle elements, the encoded map against the quantisation bound, and the
dilation ring."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid
from scipy.ndimage import binary_dilation

from workbench.algo.fepatch.bake import bake_normals, normal_map
from workbench.algo.fepatch.normalmap import decode_normals, dropped_axis, restore_error_bound


def texel_grid(nx, ny, cell, jitter=0.0, offset=(0.0, 0.0), seed=0):
    """(nodes (N, 2), elements (M, 4)) of an nx × ny grid with ``cell`` texels per side; inner
    nodes jittered by up to ``jitter`` texels, the border kept straight."""
    return quad_grid(nx, ny, cell=cell, origin=offset, jitter=jitter, seed=seed,
                     jitter_border=False, dim=2)


def unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def centres(w, h):
    jj, ii = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    return jj, ii


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), cell=st.floats(1.5, 7.0), jitter=st.floats(0.0, 0.3),
       ox=st.floats(1.0, 2.0), oy=st.floats(1.0, 2.0))
def test_constant_normal_covers_the_grid_without_cracks(seed, cell, jitter, ox, oy):
    nx, ny = 4, 3
    nodes, e = texel_grid(nx, ny, cell, jitter * cell, (ox, oy), seed)
    n = unit([0.3, -0.5, 0.8])
    w, h = int(nx * cell + ox) + 3, int(ny * cell + oy) + 3
    normals, owner = bake_normals(nodes[e], np.broadcast_to(n, (len(e), 4, 3)), (w, h))
    x, y = centres(w, h)
    inside = (x >= ox) & (x <= ox + nx * cell) & (y >= oy) & (y <= oy + ny * cell)
    assert ((owner >= 0) == inside).all()
    assert np.abs(normals[inside] - n).max() < 1e-12
    assert (normals[~inside] == 0).all()


def test_a_normal_field_varying_along_u_is_reproduced_at_texel_centres():
    # per element, the corner normals depend on u only: the bake must give the normalised linear
    # blend between the element's left and right normals at every texel centre
    nx, ny, cell, ox, oy = 5, 3, 4.3, 1.37, 0.81
    nodes, e = texel_grid(nx, ny, cell, offset=(ox, oy))
    theta = (nodes[:, 0] - ox) / (nx * cell) * 1.2 - 0.6
    node_normal = np.c_[np.sin(theta), np.zeros_like(theta), np.cos(theta)]
    w, h = int(nx * cell + ox) + 2, int(ny * cell + oy) + 2
    normals, owner = bake_normals(nodes[e], node_normal[e], (w, h))
    x, _ = centres(w, h)
    covered = owner >= 0
    col = np.clip(np.floor((x - ox) / cell), 0, nx - 1).astype(int)
    t = (x - ox) / cell - col
    left, right = node_normal[col], node_normal[col + 1]
    expected = unit((1 - t)[..., None] * left + t[..., None] * right)
    assert covered.sum() > 0.9 * (nx * cell) * (ny * cell)
    assert np.abs(normals[covered] - expected[covered]).max() < 1e-9
    # the texel's element is the one whose cell contains the centre
    m = owner[covered]
    assert np.array_equal(m % nx, col[covered])


def test_a_triangle_element_covers_exactly_its_texel_centres():
    p = np.array([[1.3, 1.1], [9.7, 2.4], [4.2, 8.9]])
    corners = np.r_[p, p[2:]][None]
    n = np.array([[0, 0, 1.0], [0, 1.0, 0], [1.0, 0, 0], [1.0, 0, 0]])[None]
    normals, owner = bake_normals(corners, n, (12, 11))
    x, y = centres(12, 11)
    q = np.stack([x, y], axis=-1)

    def cross(a, b, c):
        return (b[0] - a[0]) * (c[..., 1] - a[1]) - (b[1] - a[1]) * (c[..., 0] - a[0])

    s = [cross(p[k], p[(k + 1) % 3], q) for k in range(3)]
    inside = ((s[0] >= 0) & (s[1] >= 0) & (s[2] >= 0)) | ((s[0] <= 0) & (s[1] <= 0) & (s[2] <= 0))
    assert ((owner == 0) == inside).all() and inside.sum() > 20
    # barycentric blend at a centre: weights from the sub-triangle areas
    i, j = 5, 4
    area = [abs(cross(p[(k + 1) % 3], p[(k + 2) % 3], q[i, j])) for k in range(3)]
    assert np.allclose(normals[i, j], unit(np.dot(area, n[0, :3])), atol=1e-12)


def test_the_encoded_map_decodes_within_the_quantisation_bound():
    rng = np.random.default_rng(7)
    nodes, e = texel_grid(6, 5, 5.0, 1.0, (2.0, 2.0), seed=3)
    # a wavy surface: node normals vary smoothly, every element drops its mean's largest axis
    node_normal = unit(np.c_[0.6 * np.sin(nodes[:, 0] / 6), 0.5 * np.cos(nodes[:, 1] / 5),
                             np.ones(len(nodes))] + rng.normal(0, 0.05, (len(nodes), 3)))
    axis = dropped_axis(node_normal[e].mean(axis=1))
    size = (36, 32)
    texels = normal_map(nodes[e], node_normal[e], axis, size)
    assert texels.shape == (32, 36, 2) and texels.dtype == np.uint8
    normals, owner = bake_normals(nodes[e], node_normal[e], size)
    covered = owner >= 0
    texel_axis = axis[owner[covered]]
    back = decode_normals(texels[covered], texel_axis)
    exact = normals[covered]
    dropped = np.abs(exact[np.arange(len(exact)), texel_axis])
    cos = np.abs((back * exact).sum(axis=1))
    assert np.arccos(np.clip(cos, -1, 1)).max() <= restore_error_bound(dropped.min())


@pytest.mark.parametrize("passes", [0, 1, 2, 3])
def test_dilation_covers_the_ring_around_the_mask(passes):
    nodes, e = texel_grid(3, 2, 4.0, offset=(5.3, 6.2))
    n = unit([0.2, 0.1, -0.9])
    texels = normal_map(nodes[e], np.broadcast_to(n, (len(e), 4, 3)), np.full(len(e), 2),
                        (26, 22), dilate=passes)
    _, owner = bake_normals(nodes[e], np.broadcast_to(n, (len(e), 4, 3)), (26, 22))
    mask = owner >= 0
    ring = binary_dilation(mask, np.ones((3, 3), bool), iterations=passes) if passes else mask
    value = texels[mask][0]
    assert not np.array_equal(value, [128, 128])
    assert (texels[ring] == value).all()  # a constant field stays constant in the ring
    assert (texels[~ring] == 128).all()


def test_bake_refuses_bad_input():
    c = np.zeros((1, 4, 2))
    n = np.zeros((1, 4, 3))
    with pytest.raises(ValueError):
        bake_normals(c, np.zeros((1, 3, 3)), (4, 4))
    with pytest.raises(ValueError):
        bake_normals(np.full((1, 4, 2), np.inf), n, (4, 4))
    with pytest.raises(ValueError):
        bake_normals(c, n, (4, -1))
    with pytest.raises(ValueError):
        normal_map(c, n, np.array([3]), (4, 4))
    with pytest.raises(ValueError):
        normal_map(c, n, np.array([0]), (4, 4), dilate=-1)
