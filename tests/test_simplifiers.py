"""Reference simplifiers and distance tools behind one shape: outputs, failures, known values."""

import numpy as np
import pytest
import trimesh

from workbench.experiment.simplifiers import (SIMPLIFIERS, igl_hausdorff, open3d_distances,
                                              pymeshlab_hausdorff, simplify_with)


@pytest.fixture(scope="module")
def sphere():
    m = trimesh.creation.icosphere(subdivisions=3)  # 1280 triangles, closed and manifold
    return np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64)


@pytest.mark.parametrize("method", sorted(SIMPLIFIERS))
def test_simplifiers_reach_about_the_target_on_a_sphere(sphere, method):
    v, f = sphere
    out = simplify_with(method, v, f, 320)
    assert out.failure is None, out.failure
    assert 0 < len(out.triangles) <= 1.1 * 320
    assert out.triangles.max() < len(out.vertices) and out.seconds > 0
    # the vertices stay near the unit sphere
    radius = np.linalg.norm(out.vertices[np.unique(out.triangles)], axis=1)
    assert np.abs(radius - 1).max() < 0.1
    if out.shares_vertices:
        assert out.vertices is v or np.array_equal(out.vertices, v)


def test_a_failing_tool_is_reported_not_raised():
    # three triangles on one edge: libigl's manifold decimators give nothing back
    v = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1]], np.float64)
    f = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    out = simplify_with("libigl qslim", v, f, 1)
    assert out.failure is not None and len(out.triangles) == 0
    with pytest.raises(ValueError, match="known"):
        simplify_with("vertex clustering", v, f, 1)


def test_distance_tools_on_a_lifted_copy():
    # a unit square and its copy lifted by 0.25: every tool's distance is 0.25
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float64)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    lifted = v + [0, 0, 0.25]
    assert pymeshlab_hausdorff(v, f, lifted, f, 2000)["max"] == pytest.approx(0.25, abs=1e-6)
    assert igl_hausdorff(v, f, lifted, f)["value"] == pytest.approx(0.25, abs=1e-9)
    d = open3d_distances(v, lifted, f)
    assert d["max"] == pytest.approx(0.25, abs=1e-6) and len(d["distances"]) == 4
