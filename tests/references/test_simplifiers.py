"""Reference simplifiers and distance tools behind one shape: outputs, failures, known values."""

import numpy as np
import pytest
import trimesh
from meshes import quad_grid

from workbench.references.simplifiers import (
    PART_SIMPLIFIERS,
    SIMPLIFIERS,
    Simplified,
    igl_hausdorff,
    open3d_distances,
    part_border_vertices,
    pymeshlab_hausdorff,
    simplify_per_part,
    simplify_with,
)


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


# --------------------------------------------------------------------------- per part
@pytest.fixture(scope="module")
def two_parts():
    """A curved 16×16 grid split into two parts along x = 0.5 (they share 17 vertices)."""
    n = 16
    v, f = quad_grid(n, n, span=((0, 1), (0, 1)), triangles=True,
                     z=lambda x, y: 0.2 * np.sin(3 * x) * np.cos(2 * y))
    column = np.tile(np.arange(n), 2 * n)  # of each triangle's square
    parts = (column >= n // 2).astype(np.int32)
    return v, f, parts


def rows_present(v, ids, out):
    """Which of the vertices ``ids`` of v the output uses at exactly their coordinates."""
    used = out.vertices[np.unique(out.triangles)]
    return np.array([(used == v[i]).all(axis=1).any() for i in ids])


@pytest.mark.parametrize("method", sorted(PART_SIMPLIFIERS))
def test_per_part_runs_keep_their_claims(two_parts, method):
    v, f, parts = two_parts
    out = simplify_per_part(method, v, f, parts, {0: 40, 1: 40})
    assert out.scope == "per part" and out.borders in ("locked", "free", "weighted")
    assert out.failure is None, out.failure
    assert out.parts is not None and len(out.parts) == len(out.triangles)
    assert set(np.unique(out.parts).tolist()) == {0, 1}
    assert out.triangles.max() < len(out.vertices)
    border = part_border_vertices(f, parts)
    # the 64 outer-boundary vertices plus the 15 inner ones of the shared line
    assert len(border) == 4 * 16 + 15
    present = rows_present(v, border, out)
    if out.borders == "locked":
        # every border vertex of every part is still there, in both parts where shared
        assert present.all()
        shared = np.intersect1d(f[parts == 0], f[parts == 1])
        for p in (0, 1):
            assert rows_present(v, shared, Simplified(
                method, out.vertices, out.triangles[out.parts == p], 0.0, False)).all()
    if out.shares_vertices:
        assert out.vertices_kept == "kept" and np.array_equal(out.vertices, v)
        assert np.isin(out.triangles, f).all()
    if out.borders == "locked":
        # locked borders cost triangles: neither part can drop to 40
        assert (out.parts == 0).sum() > 40 and (out.parts == 1).sum() > 40


def test_pymeshlab_vertices_kept_is_an_index_array(two_parts):
    v, f, parts = two_parts
    out = simplify_per_part("pymeshlab quadric, vertices kept", v, f, parts, {0: 100, 1: 100})
    assert out.shares_vertices and out.vertices_kept == "kept"
    assert np.isin(out.triangles, f).all()
    moved = simplify_per_part("pymeshlab quadric", v, f, parts, {0: 100, 1: 100})
    assert moved.vertices_kept == "moved"


def test_open3d_boundary_weight_does_not_lock(two_parts):
    # why open3d's per-part row says "weighted": its border vertices still move
    v, f, parts = two_parts
    out = simplify_per_part("open3d quadric", v, f, parts, {0: 40, 1: 40})
    assert out.borders == "weighted"
    assert not rows_present(v, part_border_vertices(f, parts), out).all()


def test_per_part_refusals(two_parts):
    v, f, parts = two_parts
    with pytest.raises(ValueError, match="known"):
        simplify_per_part("vertex clustering", v, f, parts, {0: 1, 1: 1})
    with pytest.raises(ValueError, match="no target"):
        simplify_per_part("meshoptimizer simplify", v, f, parts, {0: 10})
