"""Feature-line simplification: eq. 1 bounds, every original node within the bound of the
result, fixed nodes kept, planes respected."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.fepatch.lines import _segment_distances, line_tolerance, simplify_polyline


def deviation(points, kept, closed=False):
    """Largest distance of an original node from the simplified polyline (brute force)."""
    loop = list(kept) + ([kept[0]] if closed else [])
    worst = 0.0
    for q in points:
        d = min(_segment_distances(q[None], points[a], points[b])[0]
                for a, b in zip(loop[:-1], loop[1:]))
        worst = max(worst, d)
    return worst


def test_equation_one_interpolates_between_the_bounds():
    z, x = np.array([0, 0, 1.0]), np.array([1.0, 0, 0])
    assert line_tolerance(z, z, 8.0, 0.5) == pytest.approx(8.0)
    assert line_tolerance(z, x, 8.0, 0.5) == pytest.approx(0.5)
    tilted = np.array([0, np.sin(np.radians(60)), np.cos(np.radians(60))])
    assert line_tolerance(z, tilted, 8.0, 0.5) == pytest.approx(8.0 * 0.25 + 0.5 * 0.75)


def test_a_straight_line_keeps_its_end_points():
    p = np.c_[np.linspace(0, 10, 11), np.zeros(11), np.zeros(11)]
    assert simplify_polyline(p, 1e-9).tolist() == [0, 10]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), tol=st.floats(0.001, 0.5), closed=st.booleans())
def test_every_original_node_stays_within_the_bound(seed, tol, closed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 40))
    t = np.sort(rng.uniform(0, 2 * np.pi * (0.9 if closed else 0.6), n))
    p = np.c_[np.cos(t), np.sin(t), 0.1 * rng.normal(size=n)]
    fixed = rng.uniform(size=n) < 0.1
    kept = simplify_polyline(p, tol, fixed=fixed, closed=closed)
    assert deviation(p, kept, closed) <= tol + 1e-12
    assert set(np.flatnonzero(fixed)) <= set(kept)
    if closed:
        assert len(kept) >= 3
    else:
        assert kept[0] == 0 and kept[-1] == n - 1
    # a larger bound never keeps more nodes
    assert len(simplify_polyline(p, 2 * tol, fixed=fixed, closed=closed)) <= len(kept)


def test_a_node_off_the_planes_never_ends_a_chord():
    # one node 0.2 above the plane z = 0, d = 0.05: it may be removed, but no chord may end on
    # it, so its neighbours stay until it is gone; the end points remain
    p = np.c_[np.linspace(0, 10, 21), np.zeros(21), np.zeros(21)]
    p[10, 2] = 0.2
    kept = simplify_polyline(p, 1.0, planes=[((0, 0, 1.0), 0.0)], d=0.05)
    assert kept.tolist() == [0, 20]
    # below the node's height it must stay, and so must its neighbours (they would end a chord
    # on it); the rest of the straight line goes
    kept = simplify_polyline(p, 0.1, planes=[((0, 0, 1.0), 0.0)], d=0.05)
    assert kept.tolist() == [0, 9, 10, 11, 20]
    assert simplify_polyline(p, 0.1).tolist() == [0, 9, 10, 11, 20]


def test_bad_input_is_refused():
    with pytest.raises(ValueError):
        simplify_polyline(np.zeros((1, 3)), 1.0)
    with pytest.raises(ValueError):
        simplify_polyline(np.zeros((3, 3)), -1.0)
