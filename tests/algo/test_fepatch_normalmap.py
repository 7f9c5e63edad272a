"""Two-component normal maps: round trip within the quantisation bound in all three restore
cases, interpolated texels decode to unit normals, and border dilation."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.fepatch.normalmap import (
    decode_normals,
    dilate_texels,
    dropped_axis,
    encode_normals,
    restore_error_bound,
)


def unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def angle(a, b):
    return np.arccos(np.clip(np.abs((a * b).sum(axis=-1)), -1, 1))


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 10**6), axis=st.integers(0, 2))
def test_round_trip_within_the_bound_when_the_largest_component_is_dropped(seed, axis):
    rng = np.random.default_rng(seed)
    n = unit(rng.normal(size=(500, 3)))
    n = n[dropped_axis(n) == axis]
    if not len(n):
        return
    back = decode_normals(encode_normals(n, axis), axis)
    assert np.allclose(np.linalg.norm(back, axis=1), 1.0)
    # two-sided: the normal or its inverse, within the worst-case angle
    assert angle(n, back).max() <= restore_error_bound(1 / np.sqrt(3))
    # the restored component is never negative
    assert (back[:, axis] >= 0).all()


def test_the_bound_is_not_loose_by_much():
    rng = np.random.default_rng(1)
    n = unit(rng.normal(size=(20000, 3)))
    axis = dropped_axis(n)
    worst = angle(n, decode_normals(encode_normals(n, axis), axis)).max()
    bound = restore_error_bound(1 / np.sqrt(3))
    assert worst <= bound and worst >= 0.3 * bound


def test_inverted_normals_encode_alike():
    n = unit([[0.2, -0.3, 0.9], [0.9, 0.1, -0.2], [-0.1, 0.95, 0.1]])
    axis = dropped_axis(n)
    assert (encode_normals(n, axis) == encode_normals(-n, axis)).all()


def test_a_fixed_axis_per_subpatch_still_decodes_nearby_normals():
    # a subpatch facing +z: normals within 20 degrees of its plane normal, z dropped for all
    rng = np.random.default_rng(2)
    tilt = np.radians(20) * np.sqrt(rng.uniform(size=300))
    phi = rng.uniform(0, 2 * np.pi, size=300)
    n = np.c_[np.sin(tilt) * np.cos(phi), np.sin(tilt) * np.sin(phi), np.cos(tilt)]
    back = decode_normals(encode_normals(n, 2), 2)
    assert angle(n, back).max() <= restore_error_bound(np.cos(np.radians(20)))


def test_bilinear_interpolation_of_texels_decodes_to_unit_normals():
    n = unit([[0.3, 0.1, 0.95], [-0.2, 0.25, 0.9]])
    t = encode_normals(n, 2).astype(np.float64)
    mid = decode_normals(0.5 * (t[0] + t[1]), 2)
    assert np.linalg.norm(mid) == pytest.approx(1.0)
    # between the two normals
    assert angle(mid, n[0:1]) < angle(n[0:1], n[1:2]) and angle(mid, n[1:2]) < angle(n[0:1], n[1:2])


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="unit"):
        encode_normals([[1.0, 1.0, 0.0]], 2)
    with pytest.raises(ValueError, match="axis"):
        encode_normals([[0.0, 0.0, 1.0]], 3)
    with pytest.raises(ValueError, match="finite"):
        encode_normals([[np.nan, 0.0, 1.0]], 2)


def test_dilation_grows_rings_from_the_mask_and_keeps_the_inside():
    texels = np.zeros((8, 8, 2), np.uint8)
    mask = np.zeros((8, 8), bool)
    mask[3:5, 3:5] = True
    texels[3:5, 3:5] = [[10, 20], [30, 40]]
    out, grown = dilate_texels(texels, mask, passes=2)
    assert (out[3:5, 3:5] == texels[3:5, 3:5]).all()
    assert grown[1:7, 1:7].all() and grown.sum() == 36
    # a ring texel is the mean of its filled neighbours: the corner (2, 2) touches only (3, 3)
    assert (out[2, 2] == texels[3, 3]).all()
    # (2, 3) touches (3, 3) and (3, 4)
    assert (out[2, 3] == np.rint((texels[3, 3].astype(float) + texels[3, 4]) / 2)).all()
    # a constant region stays constant as it grows
    flat, _ = dilate_texels(np.full((6, 6), 77.0), np.eye(6, dtype=bool), passes=3)
    assert (flat == 77.0).all()
