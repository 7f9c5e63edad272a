"""fe2003's distance bound d, certified: on random displaced plates the one-sided Hausdorff
distance original → simplified (exact, independent of the construction) stays within d; the
paper's construction alone (subpatch nodes within d of the plane, new surface through the
border) does not; per-subpatch bounds are never below the exact distance."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.algo.fepatch.certify import subpatch_distance_bounds, subpatch_neighbours
from workbench.algo.fepatch.features import feature_edges, patches
from workbench.algo.fepatch.pipeline import (
    FEPatchParams,
    build_model,
    certified_triangles,
)
from workbench.algo.hausdorff import hausdorff
from workbench.scene.derived import triangulate


def smooth_field(rng, size: float, amplitude: float):
    """A few long sinusoids: curved regions that planar subpatches approximate."""
    k = rng.uniform(0.5, 2.0, (3, 2)) * 2 * np.pi / size
    phase = rng.uniform(0, 2 * np.pi, 3)
    amp = amplitude * rng.uniform(0.2, 1.0, 3)
    return lambda x, y: sum(a * np.sin(kx * x + ky * y + p)
                            for a, (kx, ky), p in zip(amp, k, phase))


def bumpy_field(rng, size: float, amplitude: float):
    """A few Gaussian bumps of random width on a flat plate."""
    centre = rng.uniform(0, size, (4, 2))
    width = rng.uniform(0.1, 0.4, 4) * size
    amp = amplitude * rng.uniform(-1.0, 1.0, 4)
    return lambda x, y: sum(a * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * w * w))
                            for a, (cx, cy), w in zip(amp, centre, width))


def distance(m, tol: float):
    o, s = m.original, m.simplified
    return hausdorff(o.positions, o.triangles, s.positions, s.triangles, one_sided=True, tol=tol)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), bumpy=st.booleans(), n=st.integers(6, 14),
       h=st.floats(2.0, 12.0), amplitude=st.floats(0.5, 20.0), d=st.floats(0.05, 3.0),
       l_inner=st.floats(0.0, 10.0), l_outer=st.floats(0.0, 3.0))
def test_certified_distance_of_random_displaced_plates_is_within_d(seed, bumpy, n, h, amplitude,
                                                                   d, l_inner, l_outer):
    rng = np.random.default_rng(seed)
    size = n * h
    field = (bumpy_field if bumpy else smooth_field)(rng, size, amplitude)
    c, e = quad_grid(n, n + int(rng.integers(0, 4)), cell=h, z=field, ij=True)
    m = build_model(e, c, FEPatchParams(12.0, d, l_outer, l_inner))
    assert m.distance_bound <= d
    # independent of the construction: the exact metric on the whole surfaces, a bracket of
    # width 1 % of d (the construction keeps 1 % of d in reserve for it)
    r = distance(m, 0.01 * d)
    assert r.upper <= d, f"certified distance {r.upper:.4f} above d = {d:.4f}"
    # the simplified surface still simplifies: never more triangles than the original
    assert len(m.simplified.triangles) <= len(m.original.triangles)


def test_the_paper_construction_alone_exceeds_d_on_a_bowl():
    # a bowl: a subpatch holds its nodes within d of the plane on both sides, and the new
    # surface through its border nodes is up to 2d from its middle
    c, e = quad_grid(20, 20, cell=5.0, ij=True,
                     z=lambda x, y: 0.004 * ((x - 50.0) ** 2 + (y - 50.0) ** 2))
    params = FEPatchParams(12.0, 1.0, 0.5, 8.0)
    paper = build_model(e, c, params, fit_share=1.0, certify=False)
    assert distance(paper, 0.01).lower > params.d
    certified = build_model(e, c, params)
    assert distance(certified, 0.01).upper <= params.d
    assert len(certified.simplified.triangles) < len(certified.original.triangles) / 4


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_subpatch_bounds_are_never_below_the_exact_distance(seed):
    rng = np.random.default_rng(seed)
    c, e = quad_grid(12, 10, cell=6.0, z=bumpy_field(rng, 72.0, 8.0), ij=True)
    params = FEPatchParams(12.0, 0.8, 0.5, 6.0)
    tri = triangulate(e, c)
    patch = patches(e, feature_edges(e, c, params.alpha_g1_deg))
    surface = certified_triangles(e, c, patch, params, tri, certify=False)
    labels = surface.labels
    neighbours = subpatch_neighbours(e, labels)
    bounds = subpatch_distance_bounds(c, tri.triangles, labels[tri.element_of],
                                      surface.triangles, sorted(surface.triangles), neighbours,
                                      1e-3)
    simplified = np.concatenate(list(surface.triangles.values()))
    of = labels[tri.element_of]
    for s, bound in bounds.items():
        exact = hausdorff(c, tri.triangles[of == s], c, simplified, one_sided=True, tol=1e-3)
        assert bound >= exact.lower - 1e-12
    # and their largest is a bound on the whole surface
    whole = hausdorff(c, tri.triangles, c, simplified, one_sided=True, tol=1e-3)
    assert max(bounds.values()) >= whole.lower - 1e-12
    # a cache gives the same bounds, and the same again from the cache
    cache: dict = {}
    args = (c, tri.triangles, of, surface.triangles, sorted(surface.triangles), neighbours, 1e-3)
    assert subpatch_distance_bounds(*args, cache) == bounds
    assert subpatch_distance_bounds(*args, cache) == bounds and len(cache) > 0


def test_neighbours_share_a_node():
    e = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
    assert {k: v.tolist() for k, v in subpatch_neighbours(e, [0, 1, 2, 2]).items()} == \
        {0: [1, 2], 1: [0, 2], 2: [0, 1]}
    assert {k: v.tolist() for k, v in subpatch_neighbours(e, [0, 1, 1, 2]).items()} == \
        {0: [1, 2], 1: [0, 2], 2: [0, 1]}
    far = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
    assert {k: v.tolist() for k, v in subpatch_neighbours(far, [0, 1]).items()} == \
        {0: [], 1: []}


def test_refuses_bad_tolerances():
    c, e = quad_grid(4, 4, z=lambda x, y: 0 * x, ij=True)
    tri = triangulate(e, c)
    with pytest.raises(ValueError, match="tol"):
        subpatch_distance_bounds(c, tri.triangles, np.zeros(len(tri.triangles), int), {}, [0],
                                 {}, 0.0)
    patch = np.zeros(len(e), np.int64)
    for kwargs in ({"fit_share": 0.0}, {"fit_share": 1.5}, {"tol_share": 1.0}):
        with pytest.raises(ValueError):
            certified_triangles(e, c, patch, FEPatchParams(12.0, 1.0, 0.5, 8.0), tri, **kwargs)
