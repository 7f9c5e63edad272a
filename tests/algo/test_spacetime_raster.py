"""Pixel-centre location in slice polygons, and the float64 shading model of st2005."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import random_tiling

from workbench.algo.spacetime.raster import PixelGrid, locate_pixels
from workbench.algo.spacetime.shading import LIGHT, log_scale, phong, ramp_color, shade


def _brute(corners, xs, ys):
    """Reference: every polygon tested against every pixel centre (inside or on an edge)."""
    X, Y = np.meshgrid(xs, ys)
    out = np.full(X.shape, -1)
    for p, poly in enumerate(corners):
        inside = np.ones(X.shape, bool)
        for k in range(4):
            a, b = poly[k], poly[(k + 1) % 4]
            inside &= (b[0] - a[0]) * (Y - a[1]) - (b[1] - a[1]) * (X - a[0]) >= 0
        out[inside] = p
    return out


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 6), seed=st.integers(0, 10_000), width=st.integers(5, 60),
       far=st.booleans())
def test_locate_matches_brute_force_and_covers_the_domain(n, seed, width, far):
    offset = np.array([3.0e5, -7.0e5]) if far else np.zeros(2)
    corners = random_tiling(n, 0.3, seed) + offset
    grid = PixelGrid.fit(offset, offset + n, width, margin=0.1)
    loc = locate_pixels(corners, grid)
    xs, ys = grid.centres()
    assert np.array_equal(loc, _brute(corners, xs, ys))
    X, Y = np.meshgrid(xs, ys)
    # a pixel centre computed to lie on the square's edge may miss it by a rounding (-5.6e-17):
    # it is neither inside nor outside
    tol = 1e-12 * (n + np.abs(offset).max())
    lo, hi = offset - tol, offset + n + tol
    inside = (X > lo[0] + 2 * tol) & (X < hi[0] - 2 * tol) & (Y > lo[1] + 2 * tol) & \
        (Y < hi[1] - 2 * tol)
    outside = (X < lo[0]) | (X > hi[0]) | (Y < lo[1]) | (Y > hi[1])
    assert (loc[inside] >= 0).all()  # the polygons tile the square: no hole
    assert (loc[outside] == -1).all()


def test_pixel_grid_fit_and_refusals():
    g = PixelGrid.fit((0, 0), (2, 1), 200, margin=0.0)
    assert (g.width, g.height) == (200, 100) and g.dx == pytest.approx(0.01)
    xs, ys = g.centres()
    assert xs[0] == pytest.approx(0.005) and ys[0] == pytest.approx(0.995)
    with pytest.raises(ValueError):
        PixelGrid(0, 0, 0.0, 1, 4, 4)
    with pytest.raises(ValueError):
        PixelGrid.fit((0, 0), (0, 1), 10)
    with pytest.raises(ValueError):
        locate_pixels(np.zeros((3, 3, 2)), g)


def test_log_scale_and_ramp():
    U = np.array([0.0, 9.0, 99.0, 1e6, -1.0])
    s = log_scale(U, 99.0)
    assert s == pytest.approx([0.0, 0.5, 1.0, 1.0, 0.0])
    table = np.array([[0, 0, 0, 255], [255, 0, 0, 255], [255, 255, 255, 255]], np.uint8)
    assert ramp_color([0.0, 0.25, 0.5, 1.0], table) == pytest.approx(
        np.array([[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [1, 1, 1]]))
    with pytest.raises(ValueError):
        log_scale(U, 0.0)


def test_phong_lights_facing_surfaces_more_and_stays_in_range():
    color = np.full((3, 3), 0.8)
    facing = LIGHT[None, :]
    away = np.array([[-LIGHT[0], -LIGHT[1], 0.0]]) / np.hypot(LIGHT[0], LIGHT[1])
    up = np.array([[0.0, 0.0, 1.0]])
    lit = phong(color[:3], np.concatenate([facing, up, away]))
    assert lit[0, 0] > lit[1, 0] > lit[2, 0]
    assert lit[2] == pytest.approx(0.8 * 0.3)  # ambient only: the light grazes it
    assert (lit >= 0).all() and (lit <= 1).all()
    flat = shade(np.array([9.0]), np.zeros((1, 2)), U_max=99.0,
                 table=np.array([[0, 0, 0, 255], [255, 255, 255, 255]], np.uint8), height_scale=1.0)
    assert np.isfinite(flat).all()


def test_degenerate_polygons_cover_nothing():
    grid = PixelGrid.fit((0, 0), (4, 4), 40, margin=0.0)
    point = np.full((1, 4, 2), 2.0)
    segment = np.array([[[1.0, 1.0], [3.0, 3.0], [3.0, 3.0], [1.0, 1.0]]])
    square = np.array([[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]])
    loc = locate_pixels(np.concatenate([square, point, segment]), grid)
    assert (loc == 0).all()  # the slice through a vertex or a flat front leaves no trace


def test_edge_distance_to_the_polygon_boundary():
    from workbench.algo.spacetime.exact import edge_distance
    square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    triangle = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [0.0, 2.0]]
    corners = np.array([square, triangle]) + 1e6
    d = edge_distance(corners, np.array([0, 0, 1, 1]), np.array([0.5, 0.1, 0.5, 1.0]) + 1e6,
                      np.array([0.5, 0.7, 0.5, 1.0]) + 1e6)
    assert d == pytest.approx([0.5, 0.1, 0.5, 0.0], abs=1e-9)
