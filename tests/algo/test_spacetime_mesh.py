"""Spacetime meshes for st2005 (§3.2): space meshes, red-green refinement, tent pitching and
front-refined bands.

The spacetime volume of a tent-pitched mesh equals |domain| × duration while every simplex is
positive: with the conformity checks (every interior face shared by two simplices) that proves
the simplices tile space × time with no gap and no overlap. Causality is checked edge by edge
against the bound the construction guarantees; the band boundaries of a front-refined mesh
are checked to be non-conforming (faces without a partner) while the volume stays exact.
"""

from __future__ import annotations

from collections import Counter
from itertools import combinations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.algo.spacetime.mesh import (
    SpacetimeMesh,
    front_refined,
    interval_mesh,
    rect_triangulation,
    refine,
    space_measure,
    spacetime_volume,
    tent_pitch,
)

PROPERTY = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def ring_front(x, t):
    """Distance to a circle around (0.5, 0.5) growing at unit speed from radius 0.1."""
    return np.abs(np.linalg.norm(x - 0.5, axis=1) - (0.1 + t))


def bar_front(x, t):
    """Distance to a point moving right at unit speed from x = 0.2."""
    return np.abs(x[:, 0] - (0.2 + t))


def face_counts(mesh: SpacetimeMesh) -> Counter:
    k = mesh.simplices.shape[1]
    faces = np.concatenate([np.sort(mesh.simplices[:, list(c)], axis=1)
                            for c in combinations(range(k), k - 1)])
    return Counter(map(tuple, faces.tolist()))


def on_rect_boundary(p, size=(1.0, 1.0), tol=1e-12):
    return ((np.abs(p[..., 0]) < tol) | (np.abs(p[..., 0] - size[0]) < tol)
            | (np.abs(p[..., 1]) < tol) | (np.abs(p[..., 1] - size[1]) < tol))


def max_slope(mesh: SpacetimeMesh) -> float:
    """Largest |Δt| / |Δx| over the simplex edges that are not purely in time."""
    p = mesh.points[mesh.simplices]
    worst = 0.0
    for i, j in combinations(range(mesh.simplices.shape[1]), 2):
        d = p[:, j] - p[:, i]
        dx = np.linalg.norm(d[:, :-1], axis=1)
        spatial = dx > 0
        if spatial.any():
            worst = max(worst, float(np.max(np.abs(d[spatial, -1]) / dx[spatial])))
    return worst


# --------------------------------------------------------------------------- space meshes
@PROPERTY
@given(nx=st.integers(1, 7), ny=st.integers(1, 7), jitter=st.floats(0.0, 0.349),
       seed=st.integers(0, 99))
def test_rect_triangulation_covers_the_rectangle(nx, ny, jitter, seed):
    p, t = rect_triangulation(nx, ny, size=(2.0, 0.5), origin=(-1.0, 3.0), jitter=jitter, seed=seed)
    assert p.shape == ((nx + 1) * (ny + 1), 2) and t.shape == (2 * nx * ny, 3)
    assert t.dtype == np.int32
    area = space_measure(p, t)
    assert np.all(area > 0)  # CCW, none flipped by the jitter
    assert np.isclose(area.sum(), 1.0, rtol=1e-12)
    assert p[:, 0].min() == -1.0 and p[:, 0].max() == 1.0
    assert p[:, 1].min() == 3.0 and p[:, 1].max() == 3.5


def test_rect_triangulation_alternates_diagonals():
    p, t = rect_triangulation(2, 1)
    # cell 0 has the diagonal 0-4, cell 1 the diagonal 2-4 (nodes 0..2 bottom row, 3..5 top)
    edges = {tuple(sorted(e)) for tri in t.tolist() for e in combinations(tri, 2)}
    assert (0, 4) in edges and (2, 4) in edges and (1, 3) not in edges and (1, 5) not in edges


def test_interval_mesh():
    p, s = interval_mesh(5, length=2.0, origin=1.0, jitter=0.4, seed=3)
    assert p.shape == (6, 1) and s.shape == (5, 2)
    assert p[0, 0] == 1.0 and p[-1, 0] == 3.0
    assert np.all(np.diff(p[:, 0]) > 0)
    assert np.isclose(space_measure(p, s).sum(), 2.0)


@pytest.mark.parametrize("args", [dict(nx=0, ny=3), dict(nx=2, ny=2, jitter=0.35),
                                  dict(nx=2, ny=2, size=(0.0, 1.0))])
def test_rect_triangulation_refuses(args):
    with pytest.raises(ValueError):
        rect_triangulation(**args)


# --------------------------------------------------------------------------- refinement
def check_conforming(p, t, size=(1.0, 1.0)):
    """Every edge used by one or two triangles; the one-use edges lie on the rectangle."""
    assert np.all(space_measure(p, t) > 0)
    assert len(np.unique(p, axis=0)) == len(p)  # no duplicate nodes
    edges = Counter(tuple(sorted(e)) for tri in t.tolist() for e in combinations(tri, 2))
    assert max(edges.values()) <= 2
    lone = np.array([e for e, c in edges.items() if c == 1])
    assert np.all(on_rect_boundary(p[lone], size))


@PROPERTY
@given(nx=st.integers(1, 5), ny=st.integers(1, 5), jitter=st.floats(0.0, 0.3),
       data=st.data(), rounds=st.integers(1, 3))
def test_refine_is_conforming_and_keeps_area(nx, ny, jitter, data, rounds):
    p, t = rect_triangulation(nx, ny, jitter=jitter)
    for _ in range(rounds):
        mask = np.array(data.draw(st.lists(st.booleans(), min_size=len(t), max_size=len(t))))
        n_before = len(t)
        p2, t2 = refine(p, t, mask)
        assert np.array_equal(p2[:len(p)], p)  # old nodes keep their indices
        assert len(t2) >= n_before + 3 * mask.sum()
        assert np.isclose(space_measure(p2, t2).sum(), 1.0, rtol=1e-12)
        check_conforming(p2, t2)
        p, t = p2, t2


def test_refine_red_and_green():
    p, t = rect_triangulation(2, 2)
    mask = np.zeros(len(t), dtype=bool)
    mask[0] = True
    p2, t2 = refine(p, t, mask)
    area = space_measure(p2, t2)
    # the marked triangle becomes 4 quarters; its 3 edges split neighbours green (or red)
    assert np.sum(np.isclose(area, space_measure(p, t)[0] / 4)) >= 4
    check_conforming(p2, t2)
    assert np.array_equal(refine(p, t, np.zeros(len(t), bool))[1], t)


def test_refine_segments():
    p, s = interval_mesh(4)
    p2, s2 = refine(p, s, np.array([True, False, True, False]))
    assert len(s2) == 6 and np.isclose(space_measure(p2, s2).sum(), 1.0)
    assert np.all(space_measure(p2, s2) > 0)
    with pytest.raises(ValueError):
        refine(p, s, np.array([True]))


# --------------------------------------------------------------------------- tent pitching
@PROPERTY
@given(nx=st.integers(1, 5), ny=st.integers(1, 5), jitter=st.floats(0.0, 0.3),
       t0=st.floats(-2.0, 2.0), dur=st.floats(0.05, 0.6), c=st.floats(0.5, 3.0),
       safety=st.floats(0.2, 1.0), seed=st.integers(0, 20))
def test_tent_pitch_2d_tiles_spacetime(nx, ny, jitter, t0, dur, c, safety, seed):
    p, t = rect_triangulation(nx, ny, jitter=jitter, seed=seed)
    m = tent_pitch(p, t, t0, t0 + dur, c, safety=safety, rng_seed=seed)
    assert m.dim == 2 and m.simplices.shape[1] == 4 and m.simplices.dtype == np.int32
    vol = spacetime_volume(m)
    assert np.all(vol > 0)
    assert np.isclose(vol.sum(), 1.0 * dur, rtol=1e-9)
    assert max_slope(m) <= safety / c * (1 + 1e-9)
    assert m.points[:, -1].min() == t0 and m.points[:, -1].max() == t0 + dur
    # conforming: every face shared by two tetrahedra except on the spacetime boundary
    for face, count in face_counts(m).items():
        assert count in (1, 2)
        if count == 1:
            q = m.points[list(face)]
            assert (np.all(q[:, -1] == t0) or np.all(q[:, -1] == t0 + dur)
                    or np.all(on_rect_boundary(q)))
    assert np.array_equal(m.tmin, m.points[m.simplices, -1].min(axis=1))
    assert np.array_equal(m.tmax, m.points[m.simplices, -1].max(axis=1))


@PROPERTY
@given(n=st.integers(1, 12), jitter=st.floats(0.0, 0.45), dur=st.floats(0.1, 3.0),
       c=st.floats(0.3, 3.0), seed=st.integers(0, 20))
def test_tent_pitch_1d_tiles_spacetime(n, jitter, dur, c, seed):
    p, s = interval_mesh(n, length=2.0, jitter=jitter, seed=seed)
    m = tent_pitch(p, s, 0.0, dur, c, rng_seed=seed)
    assert m.dim == 1 and m.simplices.shape[1] == 3
    vol = spacetime_volume(m)
    assert np.all(vol > 0)
    assert np.isclose(vol.sum(), 2.0 * dur, rtol=1e-9)
    assert max_slope(m) <= 0.5 / c * (1 + 1e-9)


def test_causality_bound_is_reached_and_can_fail():
    p, t = rect_triangulation(4, 4, jitter=0.2)
    m = tent_pitch(p, t, 0.0, 1.0, 2.0, safety=0.5)
    slope = max_slope(m)
    assert 0.5 * 0.25 < slope <= 0.25 * (1 + 1e-9)  # the bound is used, not far undershot
    assert max_slope(tent_pitch(p, t, 0.0, 1.0, 1.0, safety=0.5)) > 0.25  # slower wave: steeper


def test_lifts_vary_locally():
    p, t = rect_triangulation(6, 6, jitter=0.2)
    m = tent_pitch(p, t, 0.0, 1.0, 1.0)
    times = np.unique(m.points[:, -1])
    assert len(times) > 5 * len(p)  # not a global time step


def test_tent_pitch_refuses_bad_input():
    p, t = rect_triangulation(2, 2)
    for args in [(p, t, 1.0, 1.0, 1.0), (p, t, 1.0, 0.5, 1.0), (p, t, 0.0, 1.0, 0.0),
                 (p, t, 0.0, 1.0, -1.0), (p, t[:0], 0.0, 1.0, 1.0), (p[:0], t[:0], 0.0, 1.0, 1.0),
                 (p, t, 0.0, np.nan, 1.0)]:
        with pytest.raises(ValueError):
            tent_pitch(*args)
    flat = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(ValueError, match="degenerate"):
        tent_pitch(flat, np.array([[0, 1, 2]]), 0.0, 1.0, 1.0)


def test_spacetime_mesh_refuses_degenerate():
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    assert np.isclose(spacetime_volume(SpacetimeMesh(pts, np.array([[0, 1, 2, 3]]))).sum(), 1 / 6)
    with pytest.raises(ValueError, match="zero"):
        SpacetimeMesh(pts, np.array([[0, 1, 2, 2]]))
    with pytest.raises(ValueError):
        SpacetimeMesh(pts, np.array([[0, 1, 2, 4]]))
    with pytest.raises(ValueError):
        SpacetimeMesh(pts, np.array([[0, 1, 2]]))


# --------------------------------------------------------------------------- refined bands
def band_boundary_faces(m: SpacetimeMesh, tk: float) -> Counter:
    """Faces with all three vertices at t = tk, counted over the tetrahedra using them."""
    return Counter({f: c for f, c in face_counts(m).items()
                    if np.all(m.points[list(f), -1] == tk)})


def test_front_refined_is_non_conforming_on_band_boundaries():
    p, t = rect_triangulation(6, 6, jitter=0.2)
    m = front_refined(p, t, 0.4, 1.0, front_distance=ring_front, bands=4, width=0.05, levels=2)
    vol = spacetime_volume(m)
    assert np.all(vol > 0) and np.isclose(vol.sum(), 0.4, rtol=1e-9)
    for tk in np.linspace(0.0, 0.4, 5)[1:-1]:  # the band boundaries
        faces = band_boundary_faces(m, tk)
        lone = sum(1 for c in faces.values() if c == 1)
        assert all(c <= 2 for c in faces.values())
        assert lone > 0
    # the refinement follows the ring: the mesh is finer than without it
    plain = front_refined(p, t, 0.4, 1.0, bands=4)
    assert m.n_simplices > plain.n_simplices
    assert max_slope(m) <= 0.5 * (1 + 1e-9)


@pytest.mark.parametrize("build", ["tent 2-D", "front refined 2-D", "tent 1-D"])
def test_shared_facets_match_a_brute_force_count(build):
    if build == "tent 1-D":
        p, s = interval_mesh(7, jitter=0.2, seed=3)
        m = tent_pitch(p, s, 0.0, 0.5, 1.0)
    else:
        p, s = rect_triangulation(5, 4, jitter=0.2, seed=3)
        m = (tent_pitch(p, s, 0.0, 0.3, 1.0) if build == "tent 2-D" else
             front_refined(p, s, 0.4, 1.0, front_distance=ring_front, bands=4, width=0.05,
                           levels=2))
    counts = face_counts(m)
    k = m.simplices.shape[1]
    expected = np.array([[counts[tuple(np.sort(np.delete(row, i)))] > 1 for i in range(k)]
                         for row in m.simplices])
    assert np.array_equal(m.shared_facets, expected)
    assert 0 < (~expected).sum() < expected.size  # both kinds occur


def test_shared_facets_of_a_mesh_with_too_many_points_for_one_key():
    p, s = rect_triangulation(3, 3, jitter=0.2, seed=1)
    m = tent_pitch(p, s, 0.0, 0.3, 1.0)
    # 2 M unreferenced points: facet keys would overflow int64, the row-wise path takes over
    far = np.c_[np.full((2_000_000, 2), 5.0), np.linspace(0.0, 1.0, 2_000_000)]
    big = SpacetimeMesh(np.concatenate([m.points, far]), m.simplices)
    assert float(len(big.points)) ** 3 > 2.0 ** 62
    assert np.array_equal(big.shared_facets, m.shared_facets)


def test_front_refined_without_front_is_conforming():
    p, t = rect_triangulation(4, 3, jitter=0.1)
    m = front_refined(p, t, 0.3, 1.0, bands=3)
    assert np.isclose(spacetime_volume(m).sum(), 0.3, rtol=1e-9)
    for tk in np.linspace(0.0, 0.3, 4)[1:-1]:
        faces = band_boundary_faces(m, tk)
        assert len(faces) == len(t) and set(faces.values()) == {2}
    assert len(np.unique(m.points, axis=0)) == len(m.points)  # band points merged


@PROPERTY
@given(bands=st.integers(1, 4), levels=st.integers(0, 2), width=st.floats(0.0, 0.2),
       seed=st.integers(0, 10))
def test_front_refined_volume_is_exact(bands, levels, width, seed):
    p, t = rect_triangulation(4, 4, jitter=0.2, seed=seed)
    m = front_refined(p, t, 1.25, 1.5, front_distance=lambda x, tt: ring_front(x, tt - 1.0),
                      bands=bands, width=width, levels=levels, t_start=1.0, rng_seed=seed)
    vol = spacetime_volume(m)
    assert np.all(vol > 0) and np.isclose(vol.sum(), 0.25, rtol=1e-9)
    assert m.points[:, -1].min() == 1.0 and m.points[:, -1].max() == 1.25


@PROPERTY
@given(bands=st.integers(1, 4), levels=st.integers(0, 3), n=st.integers(2, 8))
def test_front_refined_1d(bands, levels, n):
    p, s = interval_mesh(n, length=1.0, jitter=0.2)
    m = front_refined(p, s, 0.6, 1.0, front_distance=bar_front, bands=bands, levels=levels,
                      width=0.05)
    vol = spacetime_volume(m)
    assert np.all(vol > 0) and np.isclose(vol.sum(), 0.6, rtol=1e-9)
    assert max_slope(m) <= 0.5 * (1 + 1e-9)


def test_front_refined_refuses_bad_input():
    p, t = rect_triangulation(2, 2)
    for kw in [dict(bands=0), dict(levels=-1), dict(width=-0.1), dict(t_start=1.0)]:
        with pytest.raises(ValueError):
            front_refined(p, t, 1.0, 1.0, **kw)
    with pytest.raises(ValueError, match="shape"):
        front_refined(p, t, 1.0, 1.0, front_distance=lambda x, t: np.zeros(3))
