"""The ``states`` table of simplify_tradeoff and the carrying of moved vertices over states.

Carrying (:mod:`workbench.references.carried`): a rigid motion moves a carried point rigidly
(its distance to the surface unchanged), a point on the surface stays on it under any
deformation, a point follows its own part only, and bad input is refused. The table
(:mod:`workbench.reproductions._simplify_states`) at the tiny size (the smallest panels crushed
over 3 states, seconds): every method at every state, ratios that are the bracket over the
tolerance, ours within the tolerance where it certified, a moved peer's state 0 its own output.
"""

import numpy as np
import pytest
from declared import declaration

from workbench.algo.nearest.bvh import TriangleBVH
from workbench.algo.simplify.states import distances_over_states
from workbench.experiment.context import ExperimentContext
from workbench.output.tables import read_table
from workbench.references.carried import attach, carry_along
from workbench.references.simplifiers import PART_SIMPLIFIERS, simplify_per_part
from workbench.reproductions import _simplify_states as states

EPS = np.finfo(np.float64).eps


def sheet(n=10, width=100.0, depth=60.0, z0=0.0):
    """A wavy sheet of (n-1)² quads split in two triangles: (vertices, triangles)."""
    x, y = np.meshgrid(np.linspace(0, width, n), np.linspace(0, depth, n))
    z = z0 + 10 * np.sin(x / 30) * np.cos(y / 20)
    v = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    q = np.arange(n * n).reshape(n, n)
    a, b, c, d = q[:-1, :-1].ravel(), q[:-1, 1:].ravel(), q[1:, 1:].ravel(), q[1:, :-1].ravel()
    return v, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def surface_distance(vertices, triangles, points):
    return TriangleBVH(vertices, triangles).nearest(points)[0]


def test_a_rigid_motion_moves_carried_points_rigidly():
    rng = np.random.default_rng(3)
    v, f = sheet()
    points = v[rng.integers(0, len(v), 60)] + rng.normal(0, 4, (60, 3))
    motions = [(rotation(rng), rng.normal(0, 500, 3)) for _ in range(3)]
    steps = np.stack([v] + [v @ r.T + t for r, t in motions])
    carried = carry_along(steps, f, points)
    # rounding: a few operations on coordinates of magnitude `scale`, each within eps
    scale = np.abs(steps).max() + np.abs(points).max()
    slack = 64 * EPS * scale
    assert np.abs(carried[0] - points).max() <= slack
    d0 = surface_distance(v, f, points)
    assert d0.max() > 1.0  # the points are off the surface: their offsets are carried too
    for k, (r, t) in enumerate(motions, start=1):
        assert np.abs(carried[k] - (points @ r.T + t)).max() <= slack
        dk = surface_distance(steps[k], f, carried[k])
        assert np.abs(dk - d0).max() <= slack


def test_a_point_on_the_surface_stays_on_it_under_deformation():
    rng = np.random.default_rng(4)
    v, f = sheet()
    # points on the surface at state 0: random barycentric points of random triangles
    tri = rng.integers(0, len(f), 80)
    w = rng.dirichlet(np.ones(3), 80)
    points = np.einsum("mi,mij->mj", w, v[f[tri]])
    # a bend and a crush, far from rigid
    bent = v.copy()
    bent[:, 2] += 0.004 * (v[:, 0] - 50) ** 2
    crushed = v * np.array([0.6, 1.0, 1.0]) + np.array([0.0, 0.0, 5.0]) * np.sin(v[:, :1] / 7)
    steps = np.stack([v, bent, crushed])
    carried = carry_along(steps, f, points)
    for k in range(3):
        slack = 64 * EPS * np.abs(steps[k]).max()
        assert surface_distance(steps[k], f, carried[k]).max() <= slack, k
    # and off the surface it keeps its distance along a triangle's normal where it is inside
    # the triangle: the offset turns with it
    at = attach(v, f, points)
    assert at.distance.max() <= 64 * EPS * np.abs(v).max()
    assert np.allclose(at.barycentric.sum(axis=1), 1.0) and (at.barycentric >= 0).all()


def test_each_point_follows_its_own_part():
    v, f = sheet(z0=0.0)
    u, g = sheet(z0=3.0)
    steps0 = np.concatenate([v, u])
    tris = np.concatenate([f, g + len(v)])
    parts = np.repeat([1, 2], len(f))
    # part 2 moves up by 100 at state 1, part 1 stays
    later = steps0.copy()
    later[len(v):, 2] += 100.0
    steps = np.stack([steps0, later])
    point = v[[55]] + np.array([[0.0, 0.0, 1.0]])  # 1 above part 1, 2 below part 2
    own = carry_along(steps, tris, point, parts=parts, point_parts=np.array([2]))
    free = carry_along(steps, tris, point)
    assert free[1, 0, 2] == pytest.approx(point[0, 2], abs=1e-9)  # nearest is part 1: stays
    assert own[1, 0, 2] == pytest.approx(point[0, 2] + 100.0, abs=1e-9)  # part 2's: moves


@pytest.mark.parametrize("call, message", [
    (lambda s, f, p: carry_along(s[0], f, p), "steps"),
    (lambda s, f, p: carry_along(s, f + 10_000, p), "triangles"),
    (lambda s, f, p: carry_along(s, f, p[:, :2]), "points"),
    (lambda s, f, p: carry_along(s, f, p * np.nan), "non-finite"),
    (lambda s, f, p: carry_along(s, f, p, parts=np.zeros(len(f), int),
                                 point_parts=np.ones(len(p), int)), "no triangle"),
    (lambda s, f, p: carry_along(s, f, p, parts=np.zeros(len(f), int)), "both"),
    (lambda s, f, p: carry_along(s, f, p, reference=5), "outside"),
])
def test_bad_input_is_refused(call, message):
    v, f = sheet(n=4)
    with pytest.raises(ValueError, match=message):
        call(np.stack([v, v]), f, v[:3])


# ----------------------------------------------------------------------------- the table
@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """(rows, the written table re-read, the animated mesh) of a tiny states table."""
    out = tmp_path_factory.mktemp("states")
    exp = ExperimentContext("simplify_tradeoff", out, "tiny",
                            declared=declaration("simplify_tradeoff"))
    rows = states.state_rows(exp)
    exp.table(rows, "states", "states")  # checked against the declaration
    return rows, read_table(out / "states.csv"), next(states.sequences(exp))


def test_every_method_at_every_state_and_part(tiny):
    rows, written, seq = tiny
    assert len(written) == len(rows)
    assert list(written[0]) == declaration("simplify_tradeoff").table("states").names
    methods = {states.OURS_STATE0, states.OURS_ALL, *PART_SIMPLIFIERS}
    if states.attributes_supported() is None:
        methods.add(states.MESHOPT_ATTRIBUTES)
    assert {r["method"] for r in rows} == methods
    labels = sorted(int(p) for p in np.unique(seq.parts))
    n_states = len(seq.steps)
    assert n_states == states.TINY_STATES
    for method in methods:
        mine = [r for r in rows if r["method"] == method]
        if mine[0]["failure"]:
            assert len(mine) == 1 and mine[0]["state"] is None
            continue
        for k in range(n_states):
            at = [r for r in mine if r["state"] == k]
            # the worst part first, then one row per part
            assert [r["part"] for r in at] == ["worst", *labels], (method, k)
            worst = max(at[1:], key=lambda r: r["ratio"])
            assert at[0]["worst_part"] == worst["part"]
            assert at[0]["ratio"] == worst["ratio"]
        kept = mine[0]["vertices"]
        assert kept == (states.KEPT if method.startswith(("ours", "meshoptimizer"))
                        or "vertices kept" in method else states.CARRIED), method


def test_ratios_are_the_certified_bracket_over_the_tolerance(tiny):
    rows, _, _ = tiny
    measured = [r for r in rows if not r["failure"]]
    assert measured
    for r in measured:
        assert 0 <= r["hausdorff_lower_mm"] <= r["hausdorff_mm"]
        assert r["ratio"] == pytest.approx(r["hausdorff_mm"] / r["tol_mm"], rel=1e-12)
        assert r["tol_mm"] > 0 and r["part_triangles"] > 0
    # every method measured against the same tolerance per part
    tol = {r["part"]: r["tol_mm"] for r in measured
           if r["method"] == states.OURS_STATE0 and r["part"] != "worst"}
    for r in measured:
        assert r["tol_mm"] == tol[r["worst_part"] if r["part"] == "worst" else r["part"]]


def test_ours_is_within_the_tolerance_where_it_certified(tiny):
    rows, _, _ = tiny
    # certified distance <= tol, and the bracket's upper end at most 1 % of tol above it
    at0 = [r for r in rows if r["method"] == states.OURS_STATE0 and r["state"] == 0]
    assert at0 and all(r["ratio"] <= 1.0 + states.BRACKET for r in at0)
    # the crush takes the state-0 decimation out of its tolerance later on: the table shows it
    later = [r["ratio"] for r in rows if r["method"] == states.OURS_STATE0 and r["state"] > 0]
    assert max(later) > 1.0
    every = [r for r in rows if r["method"] == states.OURS_ALL]
    assert every and all(r["ratio"] <= 1.0 + states.BRACKET for r in every)
    assert every[0]["states_certified"] == states.TINY_STATES


def test_a_moved_peer_is_measured_at_state_0_as_it_placed_its_vertices(tiny):
    rows, _, seq = tiny
    method = "pymeshlab quadric"
    mine = [r for r in rows if r["method"] == method and r["state"] == 0 and r["part"] != "worst"]
    assert mine and mine[0]["vertices"] == states.CARRIED
    targets = {r["part"]: r["part_triangles"] for r in rows
               if r["method"] == states.OURS_STATE0 and r["state"] == 0 and r["part"] != "worst"}
    out = simplify_per_part(method, seq.steps[0], seq.triangles, seq.parts, targets)
    labels = np.array([r["part"] for r in mine])
    tol = np.array([r["tol_mm"] for r in mine])
    own = distances_over_states(seq.steps[:1], seq.triangles, seq.parts, out.triangles,
                                out.parts, labels, tol, simplified_steps=out.vertices[None],
                                tol=states.BRACKET)
    for p, r in enumerate(mine):
        # the carried vertices at state 0 are the tool's own: the two brackets meet
        assert max(r["hausdorff_lower_mm"], own.lower[0, p]) <= (
            min(r["hausdorff_mm"], own.upper[0, p]) + 1e-9 * r["tol_mm"])


@pytest.mark.parametrize("n_states", [1, 2, 3, 8, 40])
def test_meshoptimizer_gets_a_few_further_states_the_last_among_them(n_states):
    picked = states.attribute_states(n_states)
    if n_states == 1:
        assert len(picked) == 0
        return
    assert 1 <= len(picked) <= states.ATTRIBUTE_STATES and picked[-1] == n_states - 1
    assert picked[0] >= 1 and (np.diff(picked) > 0).all()
