"""The reference tools' part distances against a brute force that follows the own-part rule."""

import math
import sys

import numpy as np
import pytest

from workbench.algo.nearest.triangle import points_triangles_distance
from workbench.references import distances as distance_refs
from workbench.references.distances import (
    TOOLS,
    RefResult,
    available_tools,
    compare_with_exact,
    own_part_groups,
    reference_part_distances,
)
from workbench.scene.generators import stamped_panels
from workbench.scene.mesh import FEMesh

EPS32 = float(np.finfo(np.float32).eps)


def need(tool):
    """Skip, with the reason, where an optional tool is not installed."""
    if tool not in available_tools():
        pytest.skip(distance_refs._import_error(tool))


def brute_force(mesh, cutoff=math.inf):
    """Every node's distance to every triangle of a part that is none of its own parts (the
    parts of every element using the node), minimum over all of them, inf above ``cutoff`` and
    for nodes no element uses."""
    part_ids, index = np.unique(mesh.parts, return_inverse=True)
    own = np.zeros((mesh.n_nodes, len(part_ids)), bool)
    for corner in range(4):
        own[mesh.elements[:, corner], index] = True
    tri = mesh.nodes[mesh.triangles]
    tri_part = index[mesh.triangulation.element_of]
    out = np.empty(mesh.n_nodes)
    for start in range(0, mesh.n_nodes, 400):
        rows = slice(start, start + 400)
        d = points_triangles_distance(mesh.nodes[rows], tri)
        d[own[rows][:, tri_part]] = np.inf
        out[rows] = d.min(axis=1)
    out[~own.any(axis=1)] = np.inf
    return np.where(out <= cutoff, out, np.inf)


@pytest.fixture(scope="module")
def panels():
    """Four stamped parts 1.5 mm apart, part 0 split in two (part 4) so that 20 nodes belong to
    two parts."""
    mesh = stamped_panels(2000, parts=4, seed=1)
    centre_x = mesh.nodes[mesh.elements].mean(axis=1)[:, 0]
    first = mesh.parts == 0
    parts = mesh.parts.copy()
    parts[first & (centre_x > np.median(centre_x[first]))] = 4
    return FEMesh(mesh.nodes, mesh.elements, parts, name="panels")


@pytest.fixture(scope="module")
def exact(panels):
    return brute_force(panels)


def hand_mesh(lift=0.0):
    """Parts 0 and 1: unit squares at z = 0 sharing the edge x = 1 (nodes 1, 2); part 2: a
    2 × 1 rectangle at z = 0.5 above both; part 3: a triangle at z = 10; node 13 used by no
    element, 0.2 above part 0. ``lift`` adds a second step with part 2 ``lift`` lower."""
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0],
                      [0, 0, .5], [2, 0, .5], [2, 1, .5], [0, 1, .5],
                      [0, 0, 10], [1, 0, 10], [0, 1, 10], [.5, .5, .2]], np.float64)
    elements = [[0, 1, 2, 3], [1, 4, 5, 2], [6, 7, 8, 9], [10, 11, 12, 12]]
    steps = None
    if lift:
        moved = nodes.copy()
        moved[6:10, 2] -= lift
        steps = np.stack([nodes, moved])
    return FEMesh(nodes, np.array(elements), np.array([0, 1, 2, 3]), steps=steps, name="hand")


# expected distances on hand_mesh at cut-off 1: shared nodes 1 and 2 measure to part 2 only
# (0.5, not 0), part 3 is beyond the cut-off, node 13 is used by no element (inf, not measured)
HAND = np.array([.5] * 10 + [np.inf] * 4)
# a cut-off beyond every distance of the test meshes: the tools' full nearest distances
ALL = 1e9


# ----------------------------------------------------------------------------- the API
def test_tools_and_availability():
    assert TOOLS == ("libigl", "open3d", "trimesh", "coal", "fcpw")
    tools = available_tools()
    assert set(tools) <= set(TOOLS)
    # the project's own dependencies
    assert {"libigl", "open3d", "trimesh", "coal", "fcpw"} <= set(tools)


@pytest.mark.parametrize("tool", ["scipy", "", "LIBIGL", None])
def test_unknown_tool_refused(tool):
    with pytest.raises(ValueError, match="unknown distance tool"):
        reference_part_distances(tool, hand_mesh(), 1.0)


@pytest.mark.parametrize("cutoff", [0, -1.0, math.nan, math.inf, -math.inf, "1", None, True])
def test_bad_cutoff_refused(cutoff):
    with pytest.raises(ValueError, match="cutoff"):
        reference_part_distances("libigl", hand_mesh(), cutoff)


@pytest.mark.parametrize("kwargs", [dict(step=1), dict(step=-1), dict(step=0.0),
                                    dict(sample=0), dict(sample=2.5)])
def test_bad_step_or_sample_refused(kwargs):
    with pytest.raises(ValueError):
        reference_part_distances("libigl", hand_mesh(), 1.0, **kwargs)


def test_own_part_groups():
    groups = {tuple(parts.tolist()): nodes.tolist()
              for parts, nodes in own_part_groups(hand_mesh())}
    assert groups == {(): [13], (0,): [0, 3], (0, 1): [1, 2], (1,): [4, 5], (2,): [6, 7, 8, 9],
                      (3,): [10, 11, 12]}


# ----------------------------------------------------------------------------- the rule
@pytest.mark.parametrize("tool", TOOLS)
def test_own_part_rule_and_cutoff_on_hand_mesh(tool):
    need(tool)
    result = reference_part_distances(tool, hand_mesh(), 1.0, sample=14)
    assert isinstance(result, RefResult) and result.available, result.reason
    assert result.distance.dtype == np.float64 and result.distance.shape == (14,)
    # float32 holds these coordinates and distances exactly enough for every tool
    assert np.isinf(result.distance[10:]).all()
    np.testing.assert_allclose(result.distance[:10], HAND[:10], rtol=0, atol=1e-6)
    # one build per own-part set of the used nodes: five; node 13 is not asked about
    assert result.builds == 5 and result.queries == 13 and not result.queried[13]
    assert "per excluded part set" in result.constraints


def test_nothing_else_to_measure_to_is_inf():
    """Two coincident triangles of parts 5 and 7 on the same nodes: every node owns both parts,
    so there is no other part (distance inf, no build), although the geometry touches."""
    mesh = FEMesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.]]),
                  np.array([[0, 1, 2, 2], [0, 2, 1, 1]]), np.array([5, 7]))
    (own, nodes), = own_part_groups(mesh)
    assert own.tolist() == [5, 7] and nodes.tolist() == [0, 1, 2]
    result = reference_part_distances("libigl", mesh, 1.0)
    assert np.isinf(result.distance).all() and result.builds == 0


def test_step_coordinates_are_used():
    result = reference_part_distances("libigl", hand_mesh(lift=0.25), 1.0, step=1)
    expected = np.array([.25] * 10 + [np.inf] * 4)
    np.testing.assert_allclose(result.distance, expected, rtol=0, atol=1e-12)
    still = reference_part_distances("libigl", hand_mesh(lift=0.25), 1.0, step=0)
    np.testing.assert_allclose(still.distance, HAND, rtol=0, atol=1e-12)


def test_brute_force_follows_the_rule(panels, exact):
    """The reference itself: a node shared by parts 0 and 4 measures to parts 1-3 only."""
    own, shared = next((p, n) for p, n in own_part_groups(panels) if len(p) == 2)
    assert own.tolist() == [0, 4] and len(shared) == 20
    tri_part = panels.parts[panels.triangulation.element_of]
    tri = panels.nodes[panels.triangles]
    to = {key: points_triangles_distance(panels.nodes[shared], tri[np.isin(tri_part, parts)])
          .min(axis=1) for key, parts in (("own", [0, 4]), ("others", [1, 2, 3]))}
    assert (to["own"] == 0).all()  # on both of its own parts
    assert (to["others"] > 1.0).all()
    np.testing.assert_array_equal(exact[shared], to["others"])


# ----------------------------------------------------------------------------- accuracy
@pytest.mark.parametrize("tool", ["libigl", "coal"])
def test_exact_tools_equal_brute_force(tool, panels, exact):
    need(tool)
    result = reference_part_distances(tool, panels, ALL)
    assert result.available and result.queries == panels.n_nodes
    assert "float64" in result.constraints
    assert np.isfinite(result.distance).all()
    np.testing.assert_allclose(result.distance, exact, rtol=0, atol=1e-9)
    summary = compare_with_exact(exact, result, tolerance=1e-9)
    assert summary["agree"] and summary["compared"] == panels.n_nodes


def test_trimesh_on_its_sample(panels, exact):
    import trimesh

    result = reference_part_distances("trimesh", panels, ALL, sample=250, seed=3)
    assert result.available and result.queries == 250
    assert result.queried.sum() == 250 and np.isnan(result.distance[~result.queried]).all()
    assert "sampled: 250 of" in result.constraints
    d, e = result.distance[result.queried], exact[result.queried]
    # the true minimum within 1e-9, but for trimesh's documented tie-break (see the module)
    assert (np.abs(d - e) <= 1e-9 + trimesh.tol.merge / (2 * np.maximum(e, 1e-300))).all()
    again = reference_part_distances("trimesh", panels, ALL, sample=250, seed=3)
    assert (again.queried == result.queried).all()  # the seed fixes the sample


def test_open3d_float32_error_grows_with_the_coordinates(panels, exact):
    local = reference_part_distances("open3d", panels, ALL)
    assert "float32" in local.constraints and "local origin" in local.constraints
    scale = np.abs(panels.nodes - panels.nodes.mean(axis=0)).max() + exact.max()
    err_local = np.abs(local.distance - exact).max()
    assert err_local <= 4 * EPS32 * scale
    far = panels.translated([1e6, 1e6, 1e6])
    # a local origin takes the translation away again
    moved = reference_part_distances("open3d", far, ALL)
    assert np.abs(moved.distance - exact).max() <= 4 * EPS32 * scale
    raw = reference_part_distances("open3d", far, ALL, local_origin=False)
    assert "raw model coordinates" in raw.constraints
    err_raw = np.abs(raw.distance - exact).max()
    assert err_raw > 100 * err_local and err_raw > 1e-3


def test_fcpw_float32_with_the_cutoff_as_search_radius(panels, exact):
    """fcpw: float32 errors of the order of the coordinates' float32 rounding, the cut-off
    handed over as its search radius, reading the results out timed apart."""
    need("fcpw")
    result = reference_part_distances("fcpw", panels, ALL)
    assert result.available and result.queries == panels.n_nodes
    assert "float32" in result.constraints and "search radius = the cut-off" in result.constraints
    assert "std::threads" in result.constraints
    scale = np.abs(panels.nodes - panels.nodes.mean(axis=0)).max() + exact.max()
    err = np.abs(result.distance - exact).max()
    assert 0 < err <= 4 * EPS32 * scale  # float32: not exact, but close
    assert result.seconds_extract > 0 and result.seconds_query > 0
    summary = compare_with_exact(exact, result, tolerance=1e-9)
    assert summary["off"] > 0  # float32 shows at 1e-9 mm
    # with a cut-off between the distances: what is beyond the radius is not found
    cut = reference_part_distances("fcpw", panels, 2.0)
    beyond, within = exact > 2.0 + 1e-3, exact <= 2.0 - 1e-3
    assert beyond.sum() >= 20 and within.sum() >= 20
    assert np.isinf(cut.distance[beyond]).all()
    np.testing.assert_allclose(cut.distance[within], exact[within], rtol=0,
                               atol=4 * EPS32 * scale)


@pytest.mark.parametrize("tool", TOOLS)
def test_beyond_cutoff_is_inf(tool, panels, exact):
    need(tool)
    cutoff = 2.0
    sample = 400 if tool == "trimesh" else None
    result = reference_part_distances(tool, panels, cutoff, sample=sample)
    asked = result.queried
    within = exact <= cutoff
    assert within[asked].sum() >= 20 and (~within[asked]).sum() >= 20  # both kinds were asked
    # float32 may put a node a hair's breadth from the cut-off on the other side: none here
    clear = asked & (np.abs(exact - cutoff) > 1e-3)
    assert np.isinf(result.distance[clear & ~within]).all()
    assert np.isfinite(result.distance[clear & within]).all()
    assert (result.distance[np.isfinite(result.distance)] <= cutoff).all()


# ----------------------------------------------------------------------------- comparing
def test_compare_with_exact_counts():
    exact = np.array([0.1, 0.2, np.inf, 0.5, np.inf, 0.0, 0.3, 0.0])
    ref = np.array([0.1, 0.2 + 2e-6, np.inf, np.inf, 0.3, np.nan, 0.3 + 5e-7, 1e-9])
    out = compare_with_exact(exact, ref, tolerance=1e-6)
    assert out["compared"] == 7 and out["both_within"] == 4
    assert out["max_abs_error"] == pytest.approx(2e-6)
    assert out["worst_node"] == 1
    assert out["max_rel_error"] == math.inf  # 1e-9 where the exact distance is 0
    assert out["off"] == 1 and out["missed"] == 1 and out["extra"] == 1
    assert out["cutoff_disagreements"] == 2
    assert out["flagged"].tolist() == [False, True, False, True, True, False, False, False]
    assert out["n_flagged"] == 3 and not out["agree"]
    same = compare_with_exact(exact, np.where(np.isnan(ref), np.nan, exact))
    assert same["agree"] and same["max_abs_error"] == 0
    with pytest.raises(ValueError):
        compare_with_exact(exact, ref[:-1])


# ----------------------------------------------------------------------------- missing tools
def test_absent_tool_is_a_result_with_the_reason(monkeypatch):
    monkeypatch.setitem(sys.modules, "coal", None)  # import coal now raises ImportError
    assert "coal" not in available_tools()
    result = reference_part_distances("coal", hand_mesh(), 1.0)
    assert not result.available and "coal is not importable" in result.reason
    assert np.isnan(result.distance).all() and result.queries == 0


def test_failing_tool_is_a_result(monkeypatch):
    def broken(self, structure, points, cutoff):
        raise RuntimeError("boom")

    monkeypatch.setattr(distance_refs._Libigl, "query", broken)
    result = reference_part_distances("libigl", hand_mesh(), 1.0)
    assert not result.available and "libigl failed" in result.reason and "boom" in result.reason
