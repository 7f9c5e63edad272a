"""Ghosted exploded views: the offset dynamics against a box-in-box occlusion model with a
closed-form reveal offset, the front half's opacity, front/back and culling decisions, split
plane choice and refusals."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import settings as hypothesis_settings
from hypothesis import strategies as st

from workbench.algo.explode import (
    ExplodeSettings,
    ExplodeState,
    SplitPlane,
    auto_plane,
    cull_back_faces,
    explode_positions,
    front_sign,
    ghost_alpha,
    manual_plane,
    next_state,
    o_max_of,
    occlusion_ratio,
    point_sides,
    release,
    reveal_offset,
    uniform_explosion,
)
from workbench.scene.mesh import FEMesh


def box_points(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    return lo + corners * (hi - lo)


# --------------------------------------------------------------------- box-in-box scene
# An inner box (the object) inside an outer box of diagonal o_max; a linear occlusion model
# r(o) = max(0, 1 − o/o*) stands for the measured ratio, revealing the object at o*.
O_MAX = math.sqrt(3.0)  # outer box [0, 1]^3
SETTINGS = ExplodeSettings(o_max=O_MAX, speed=1.0, dt=0.1)  # ratio exponent 1/2
THESIS = ExplodeSettings(o_max=O_MAX, speed=1.0, dt=0.1, ratio_exponent=1.0)


def linear_r(offset, o_star):
    return max(0.0, 1.0 - offset / o_star)


def run(o_star, frames, settings=SETTINGS, state=None):
    state, offsets, ratios = state or ExplodeState(), [], []
    for _ in range(frames):
        r = linear_r(state.offset, o_star)
        ratios.append(r)
        state = next_state(state, r, settings)
        offsets.append(state.offset)
    return state, np.array(offsets), np.array(ratios)


def frames_to_reveal(o_star, settings, limit=400):
    _, _, ratios = run(o_star, limit, settings)
    hit = np.flatnonzero(ratios <= 0.01)
    return int(hit[0]) if len(hit) else None


def test_box_in_box_scene_agrees_with_closed_form():
    outer, inner = box_points((0, 0, 0), (1, 1, 1)), box_points((0.4, 0.4, 0.3), (0.6, 0.6, 0.7))
    assert o_max_of((outer.min(0), outer.max(0))) == pytest.approx(O_MAX)
    # viewed along -x with the plane normal y: the inner box is 0.2 wide along y
    plane = manual_plane("y", inner)
    assert reveal_offset(inner, plane, (-1, 0, 0)) == pytest.approx(0.2)


def test_thesis_ratio_reveals_within_30_frames_up_to_four_tenths_of_o_max():
    # s_u = 1, dt = 0.1, speed ∝ r: o* = 0.4 o_max takes 25 frames, 0.5 o_max 37
    for fraction in (0.05, 0.1, 0.2, 0.3, 0.4):
        assert frames_to_reveal(fraction * O_MAX, THESIS) <= 30
    assert 30 < frames_to_reveal(0.5 * O_MAX, THESIS) <= 40


def test_square_root_ratio_reveals_faster():
    # speed ∝ √r arrives in finitely many frames: o* = 0.66 o_max within 30 frames
    for fraction in (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.66):
        assert frames_to_reveal(fraction * O_MAX, SETTINGS) <= 30
    for fraction in (0.2, 0.4, 0.6, 0.8, 0.9):
        assert frames_to_reveal(fraction * O_MAX, SETTINGS) < frames_to_reveal(fraction * O_MAX,
                                                                               THESIS)


def check_converges_monotonically(o_star, settings, frames=400):
    """Monotone, no step longer than s_u·dt·o_max, never past o_max, never more than one step
    past o*, and held from the first frame at or beyond o*; returns the final state."""
    state, offsets, ratios = run(o_star, frames, settings)
    steps = np.diff(np.concatenate([[0.0], offsets]))
    assert (steps >= 0.0).all()  # monotone: never moves back
    assert steps.max() <= settings.max_step * (1 + 1e-12)
    assert offsets.max() <= min(settings.o_max, o_star + settings.max_step)
    past = np.flatnonzero(offsets >= o_star)
    if len(past):
        assert (offsets[past[0]:] == offsets[past[0]]).all()
    return state, offsets


@pytest.mark.parametrize("fraction", [0.02, 0.05, 0.1, 0.3, 0.5, 0.8])
def test_converges_monotonically_and_halts_within_one_step(fraction):
    o_star = fraction * O_MAX
    state, offsets = check_converges_monotonically(o_star, SETTINGS)
    assert state.phase == "hold" and state.ideal == state.offset
    assert o_star <= offsets[-1] <= o_star + SETTINGS.max_step
    # the thesis's r-proportional speed approaches o* from below without arriving, unless a
    # step from far below carries it past
    state, offsets = check_converges_monotonically(o_star, THESIS, frames=1000)
    if state.phase == "hold":
        assert o_star <= offsets[-1] <= o_star + THESIS.max_step
    else:
        assert 0.0 <= o_star - offsets[-1] <= 1e-3 * o_star


@hypothesis_settings(max_examples=60, deadline=None)
@given(fraction=st.floats(0.001, 1.5), exponent=st.floats(0.05, 1.0),
       speed_dt=st.floats(0.01, 1.0))
def test_converges_monotonically_property(fraction, exponent, speed_dt):
    s = ExplodeSettings(o_max=O_MAX, speed=speed_dt / 0.1, dt=0.1, ratio_exponent=exponent)
    check_converges_monotonically(fraction * O_MAX, s)


def test_released_explosion_shrinks_back_to_the_reveal_offset():
    o_big, o_star = 0.9 * O_MAX, 0.3 * O_MAX
    held = ExplodeState(offset=o_big, ideal=o_big, phase="hold")
    assert next_state(held, 0.0, SETTINGS).offset == o_big  # held: stays while revealed
    state = release(held)
    assert state.phase == "collapse" and state.offset == o_big
    state, offsets, _ = run(o_star, 300, state=state)
    assert offsets[0] == pytest.approx(0.9 * o_big)  # collapses at s_u·offset
    assert offsets.min() < o_star  # until the object is occluded again ...
    assert state.phase == "hold" and o_star <= state.offset <= o_star + SETTINGS.max_step


def test_visible_focus_never_explodes():
    state = ExplodeState()
    for _ in range(50):
        state = next_state(state, 0.0, SETTINGS)
        assert state.offset == 0.0 and state.ideal == 0.0 and state.phase == "collapse"
    assert state.frame == 50


@pytest.mark.parametrize("settings", [SETTINGS, THESIS], ids=["sqrt", "thesis"])
def test_enclosed_focus_approaches_o_max_monotonically(settings):
    state, offsets = ExplodeState(), []
    for _ in range(200):
        state = next_state(state, 1.0, settings)
        offsets.append(state.offset)
        assert state.ideal == O_MAX and state.phase == "grow"
    offsets = np.array(offsets)
    assert (np.diff(offsets) > 0).all()
    assert offsets.max() <= O_MAX and offsets[-1] == pytest.approx(O_MAX, rel=1e-6)


def test_revealed_halts_or_collapses():
    growing = ExplodeState(offset=1.0, ideal=O_MAX, phase="grow")
    held = next_state(growing, 0.0, SETTINGS)
    assert held.offset == 1.0 and held.ideal == 1.0 and held.phase == "hold"
    resting = ExplodeState(offset=1.0)
    nxt = next_state(resting, 0.0, SETTINGS)
    assert nxt.offset == pytest.approx(0.9) and nxt.ideal == 0.0
    # revealed_below: r at or below it counts as revealed
    s = ExplodeSettings(o_max=O_MAX, revealed_below=0.05)
    assert next_state(resting, 0.05, s).offset == pytest.approx(0.9)
    assert next_state(resting, 0.06, s).offset > 1.0
    assert next_state(growing, 0.05, s).offset == 1.0


def test_growth_speed_follows_the_ratio_exponent():
    state = ExplodeState(offset=0.0)
    for p in (1.0, 0.5, 0.25):
        s = ExplodeSettings(o_max=2.0, speed=1.0, dt=0.1, ratio_exponent=p)
        assert next_state(state, 0.25, s).offset == pytest.approx(0.1 * 2.0 * 0.25 ** p)


def test_offset_clipped_to_range():
    big = ExplodeSettings(o_max=1.0, speed=30.0, dt=0.1)
    assert next_state(ExplodeState(offset=0.5), 1.0, big).offset == 1.0
    assert next_state(ExplodeState(offset=0.5), 0.0, big).offset == 0.0
    assert next_state(ExplodeState(offset=5.0), 0.0,
                      ExplodeSettings(o_max=1.0)).offset == pytest.approx(0.9)


def test_occlusion_ratio():
    assert occlusion_ratio(100, 25) == 0.75
    assert occlusion_ratio(100, 100) == 0.0 and occlusion_ratio(100, 0) == 1.0
    assert occlusion_ratio(0, 0) == 0.0
    assert occlusion_ratio(100, 103) == 0.0
    with pytest.raises(ValueError, match=">= 0"):
        occlusion_ratio(-1, 0)


# --------------------------------------------------------------------- ghosting
def test_ghost_alpha():
    s = ExplodeSettings(o_max=2.0)
    assert ghost_alpha(0.0, s, 1.0) == 1.0
    assert ghost_alpha(1.0, s, 1.0) == 1.0  # below 0.7 o_max
    assert ghost_alpha(1.4, s, 1.0) == pytest.approx(1.0)
    assert ghost_alpha(2.0, s, 1.0) == pytest.approx(0.5)
    assert ghost_alpha(1.7, s, 1.0) == pytest.approx(0.75)  # linear in between
    xs = np.linspace(1.4, 2.0, 7)
    a = np.array([ghost_alpha(x, s, 1.0) for x in xs])
    assert np.allclose(np.diff(a), np.diff(a)[0]) and np.diff(a)[0] < 0
    # translucency scaled by r: solid when nothing is occluded
    assert ghost_alpha(2.0, s, 0.0) == 1.0
    assert ghost_alpha(2.0, s, 0.5) == pytest.approx(0.75)
    assert ghost_alpha(5.0, s, 1.0) == pytest.approx(0.5)  # past o_max taken as o_max
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        ghost_alpha(1.0, s, 1.5)
    with pytest.raises(ValueError, match="offset"):
        ghost_alpha(-0.1, s, 1.0)


# --------------------------------------------------------------------- front and culling
PLANE = SplitPlane(np.zeros(3), np.array([0.0, 0.0, 2.0]))


def test_plane_normalised_and_signed_distance():
    assert np.allclose(PLANE.normal, [0, 0, 1])
    assert np.allclose(PLANE.signed_distance([[0, 0, 3], [1, 1, -2]]), [3, -2])
    assert float(PLANE.signed_distance([0, 0, 3])) == 3.0
    assert point_sides(PLANE, [[0, 0, 3], [0, 0, -1], [0, 0, 0]]).tolist() == [1, -1, 1]


def test_front_sign_both_sides():
    assert front_sign(PLANE, 0.5, (0, 0, 10)) == 1
    assert front_sign(PLANE, 0.5, (3, 1, -10)) == -1
    # orthographic: eye far back along the view direction
    view = np.array([0.0, 0.3, 1.0])
    assert front_sign(PLANE, 0.5, -1e6 * view) == -1
    assert front_sign(PLANE, 0.5, 1e6 * view) == 1


def test_cull_back_faces():
    offset = 1.0
    # camera beyond the + half's translated plane: the + half is in front, cull it
    assert cull_back_faces(PLANE, offset, (0, 0, 10), +1)
    assert cull_back_faces(PLANE, offset, (0, 0, -10), -1)
    # camera between the original and the translated plane: looks into the cut, keep
    assert not cull_back_faces(PLANE, offset, (0, 0, 0.5), +1)
    assert not cull_back_faces(PLANE, offset, (0, 0, -0.5), -1)
    # the back half's cut opens toward the camera: keep
    assert not cull_back_faces(PLANE, offset, (0, 0, 10), -1)
    assert not cull_back_faces(PLANE, offset, (0, 0, -10), +1)
    # zero offset: nothing in between
    assert cull_back_faces(PLANE, 0.0, (0, 0, 0.5), +1)
    with pytest.raises(ValueError, match="side"):
        cull_back_faces(PLANE, offset, (0, 0, 1), 0)


# --------------------------------------------------------------------- planes
def test_o_max_of_mesh():
    nodes = box_points((0, 0, 0), (3, 4, 12))
    mesh = FEMesh(nodes, np.array([[0, 1, 2, 3], [4, 5, 6, 7]]))
    assert o_max_of(mesh) == pytest.approx(13.0)
    with pytest.raises(ValueError, match="single point"):
        o_max_of(((1, 1, 1), (1, 1, 1)))


def test_reveal_offset():
    flat = box_points((-2, -1, -0.1), (2, 1, 0.1))
    view = (1.0, 0.0, 0.0)
    assert reveal_offset(flat, manual_plane("z", flat), view) == pytest.approx(0.2)
    assert reveal_offset(flat, manual_plane("y", flat), view) == pytest.approx(2.0)
    assert reveal_offset(flat, manual_plane("x", flat), view) == math.inf
    # tilted normal: the object's extent along n⊥ over |n⊥|
    tilted = manual_plane((1, 0, 1), flat)
    assert reveal_offset(flat, tilted, view) == pytest.approx(0.2 / math.sqrt(0.5))


def test_auto_plane_picks_thin_axis_seen_from_side():
    rng = np.random.default_rng(1)
    flat = rng.uniform((-2, -1, -0.05), (2, 1, 0.05), size=(400, 3)) + (5, 5, 5)
    assembly = rng.uniform((0, 0, 0), (10, 10, 10), size=(400, 3))
    plane = auto_plane(flat, assembly, (1.0, 0.0, 0.0))
    assert abs(plane.normal[2]) > 0.99
    assert np.allclose(plane.point, 0.5 * (flat.min(0) + flat.max(0)))


def test_auto_plane_rejects_normals_near_view():
    flat = box_points((-2, -1, -0.1), (2, 1, 0.1))
    assembly = box_points((-5, -5, -5), (5, 5, 5))
    # looking straight down z the thin axis is rejected; y (extent 2) beats x (extent 4)
    plane = auto_plane(flat, assembly, (0.0, 0.0, -1.0))
    assert abs(plane.normal[2]) < math.cos(math.radians(20))
    assert np.allclose(np.abs(plane.normal), [0, 1, 0], atol=1e-9)
    # the thin axis 10 degrees off the view still loses: its halves slide mostly in depth
    view = (0.0, math.sin(math.radians(10)), -math.cos(math.radians(10)))
    assert abs(auto_plane(flat, assembly, view, reject_deg=5.0).normal[2]) < 0.5


def test_auto_plane_refused_when_all_rejected():
    pts = box_points((-1, -2, -3), (1, 2, 3))  # principal axes are the coordinate axes
    view = np.ones(3) / math.sqrt(3.0)  # 54.7 degrees from every axis
    assert auto_plane(pts, pts, view, reject_deg=50.0).normal.shape == (3,)
    with pytest.raises(ValueError, match="every candidate"):
        auto_plane(pts, pts, view, reject_deg=60.0)
    with pytest.raises(ValueError, match="reject_deg"):
        auto_plane(pts, pts, view, reject_deg=90.0)


def test_manual_plane_specs():
    obj = box_points((1, 2, 3), (3, 4, 7))
    for spec, n in (("x", (1, 0, 0)), ("Y", (0, 1, 0)), ("z", (0, 0, 1)),
                    ((0, 3, 4), (0, 0.6, 0.8))):
        plane = manual_plane(spec, obj)
        assert np.allclose(plane.normal, n) and np.allclose(plane.point, (2, 3, 5))
    with pytest.raises(ValueError, match="unknown split plane"):
        manual_plane("w", obj)
    with pytest.raises(ValueError, match="unknown split plane"):
        manual_plane((1, 2), obj)
    with pytest.raises(ValueError, match="non-zero"):
        manual_plane((0, 0, 0), obj)
    with pytest.raises(ValueError, match="empty"):
        manual_plane("x", np.zeros((0, 3)))


# --------------------------------------------------------------------- positions
def test_explode_positions():
    pts = np.array([[0.0, 0, 1], [0, 0, -1], [0, 0, 0]])
    out = explode_positions(pts, point_sides(PLANE, pts[:2]).tolist() + [0], 0.5, PLANE)
    assert np.allclose(out, [[0, 0, 1.5], [0, 0, -1.5], [0, 0, 0]])
    with pytest.raises(ValueError, match="sides"):
        explode_positions(pts, [2, 1, 1], 0.5, PLANE)
    with pytest.raises(ValueError, match="sides"):
        explode_positions(pts, [1, 1], 0.5, PLANE)


def test_uniform_explosion_same_distance():
    centres = np.array([[2.0, 0, 0], [0, 0, 5], [1, 1, 1], [0, 0, 0]])
    t = uniform_explosion(centres, (0, 0, 0), 3.0)
    assert np.allclose(np.linalg.norm(t[:3], axis=1), 3.0)
    assert np.allclose(t[0], [3, 0, 0]) and np.allclose(t[3], 0)
    assert np.allclose(np.cross(t[2], centres[2]), 0)
    with pytest.raises(ValueError, match="displacement"):
        uniform_explosion(centres, (0, 0, 0), -1.0)


# --------------------------------------------------------------------- refusals
@pytest.mark.parametrize("kwargs, match", [
    ({"o_max": 0.0}, "o_max"),
    ({"o_max": -1.0}, "o_max"),
    ({"o_max": float("nan")}, "o_max"),
    ({"o_max": 1.0, "speed": -1.0}, "speed"),
    ({"o_max": 1.0, "dt": -0.1}, "dt"),
    ({"o_max": 1.0, "ghost_start": 1.0}, "ghost_start"),
    ({"o_max": 1.0, "revealed_below": 1.0}, "revealed_below"),
    ({"o_max": 1.0, "ratio_exponent": 0.0}, "ratio_exponent"),
    ({"o_max": 1.0, "ratio_exponent": 1.5}, "ratio_exponent"),
])
def test_settings_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ExplodeSettings(**kwargs)


def test_unknown_phase_refused():
    with pytest.raises(ValueError, match="phase"):
        ExplodeState(phase="explode")


@pytest.mark.parametrize("r", [-0.1, 1.1, float("nan")])
def test_ratio_refused(r):
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        next_state(ExplodeState(), r, SETTINGS)


def test_points_refused():
    bad = np.array([[0.0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(ValueError, match="finite"):
        reveal_offset(bad, PLANE, (1, 0, 0))
    with pytest.raises(ValueError, match="finite"):
        auto_plane(box_points((0, 0, 0), (1, 1, 1)), bad, (1, 0, 0))
    with pytest.raises(ValueError, match="empty"):
        auto_plane(np.zeros((0, 3)), box_points((0, 0, 0), (1, 1, 1)), (1, 0, 0))
    with pytest.raises(ValueError, match="finite"):
        SplitPlane((0, 0, math.inf), (0, 0, 1))
    with pytest.raises(ValueError, match="non-zero"):
        SplitPlane((0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="non-zero"):
        reveal_offset(box_points((0, 0, 0), (1, 1, 1)), PLANE, (0, 0, 0))
