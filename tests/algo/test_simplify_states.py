"""The certified distance of one decimation at every state of a result
(:mod:`workbench.algo.simplify.states`), against answers known exactly: a flat plate whose
removed vertices move by a known height at a later state, and rigid motions, which change no
distance."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid, split_quads

from workbench.algo.simplify import hausdorff_decimate
from workbench.algo.simplify.states import bounds_over_states, distances_over_states
from workbench.cli import main

H = 0.3  # the height a removed vertex is lifted by at state 2 (model units)


@pytest.fixture(scope="module")
def plate():
    """A flat 8 x 8 plate of 10 x 10 units in two parts (left, right halves), decimated at 0.5 %,
    and its four states: 0 as decimated, 1 the same, 2 one vertex the decimation removed lifted
    by H, 3 state 2 rotated and moved far away (a rigid motion)."""
    nodes, quads = quad_grid(8, 8, cell=1.25)
    triangles = split_quads(quads)
    centre = nodes[triangles].mean(axis=1)
    parts = np.where(centre[:, 0] < 5.0, 1, 2)
    d = hausdorff_decimate(nodes, triangles, 0.005, relative=True, parts=parts)
    removed = np.setdiff1d(np.arange(len(nodes)), d.triangles.ravel())
    # a removed vertex inside the left half, away from the parts' common boundary
    lifted = next(int(v) for v in removed if 1.0 < nodes[v, 0] < 3.0 and 1 < nodes[v, 1] < 9)
    up = nodes.copy()
    up[lifted, 2] += H
    c, s = np.cos(0.7), np.sin(0.7)
    rotation = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array(
        [[1, 0, 0], [0, c, -s], [0, s, c]])
    moved = up @ rotation.T + [1e5, -3e4, 2e4]
    return np.stack([nodes, nodes, up, moved]), triangles, parts, d, lifted


def test_a_lifted_removed_vertex_is_its_height_away_and_rigid_motions_change_nothing(plate):
    steps, triangles, parts, d, lifted = plate
    b = bounds_over_states(steps, triangles, parts, d)
    left = list(b.part_labels).index(1)
    right = list(b.part_labels).index(2)
    width = 0.01 * b.tol_abs  # the bracket's width asked for: 1 % of each part's tolerance
    # the flat plate is its own simplification: 0 at states 0 and 1 (a bracket around 0)
    assert (b.lower[:2] <= 0).all() and (b.upper[:2] <= width).all()
    # state 2: the lifted vertex is a point of the original H above the simplified plane, and
    # no point is farther (every other vertex is in the plane): the distance is exactly H
    assert b.lower[2, left] <= H <= b.upper[2, left] <= H + width[left]
    assert b.upper[2, right] <= width[right]  # the other part did not move
    # state 3, a rigid motion of state 2 far from the origin: the same distance, up to the
    # rounding of the moved coordinates themselves (a few ulps of 1e5, 1.5e-11 each)
    moved = 1e-10
    assert b.lower[3, left] <= H + moved and H - moved <= b.upper[3, left] <= H + width[left]
    assert b.worst()[1] == 1 and b.worst()[2] == pytest.approx(H / b.tol_abs[left], rel=0.011)
    assert [w[0] for w in b.worst_per_state()] == [0, 1, 2, 3]


def test_state_zero_keeps_the_certificate_of_the_decimation(plate):
    steps, triangles, parts, d, _ = plate
    wavy = steps[:1].copy()
    wavy[0, :, 2] = 0.4 * np.sin(wavy[0, :, 0]) * np.cos(0.7 * wavy[0, :, 1])
    d = hausdorff_decimate(wavy[0], triangles, 0.005, relative=True, parts=parts)
    b = bounds_over_states(wavy, triangles, parts, d)
    assert len(d.triangles) < len(triangles) and (b.ratio <= 1.0).all()
    assert (b.upper <= d.certified_max).all()  # the certificate bounds the bracket's upper end


def test_refusals(plate):
    steps, triangles, parts, d, _ = plate
    with pytest.raises(ValueError, match="steps must be"):
        bounds_over_states(steps[0], triangles, parts, d)
    with pytest.raises(ValueError, match="indices of the"):
        bounds_over_states(steps[:, :10], triangles, parts, d)
    with pytest.raises(ValueError, match="parts must be"):
        bounds_over_states(steps, triangles, parts[:-1], d)
    with pytest.raises(ValueError, match="tol must be"):
        bounds_over_states(steps, triangles, parts, d, tol=0.0)


def test_simplify_states_prints_the_worst_part_of_each_state(capsys):
    assert main(["simplify", "crash:2", "--states", "all"]) == 0
    out = capsys.readouterr().out
    lines = [line.strip() for line in out.splitlines() if line.strip().startswith("state ")]
    assert [line.split(":")[0] for line in lines] == ["state 0", "state 1"]
    assert "exceeds" not in lines[0] and lines[1].endswith("exceeds")  # crushed at state 1
    assert "worst: state 1, part " in out
    for argv in (["simplify", "crash:2", "--states", "5"], ["simplify", "car", "--states", "all"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--states" in err


# ---------------------------------------------------------------- decimation over every state
def test_a_decimation_certified_at_every_state_holds_at_every_state(plate):
    """The lifted vertex of state 2 is H (far above the tolerance) out of the plane, and every
    other vertex keeps its coordinates bit for bit: the adversarial case for skipping a state
    whose coordinates are those of a state already checked. Measured by the independent
    metric at every state, the bound holds, and the lifted vertex is kept."""
    steps, triangles, parts, d0, lifted = plate
    d = hausdorff_decimate(steps[0], triangles, 0.005, relative=True, parts=parts,
                           states=steps[1:])
    assert d.states_certified == 4 and len(d.triangles) < len(triangles)
    assert lifted in d.triangles and lifted not in d0.triangles
    b = bounds_over_states(steps, triangles, parts, d)
    assert (b.ratio <= 1.0).all()
    assert np.nanmax(d.bounds) <= d.tol_abs.max() and (d.parts == parts[d.source]).all()


def _bent(nodes, amplitude, wavelength, phase):
    """``nodes`` bent by a sine across x: z += amplitude sin(2π x / wavelength + phase)."""
    out = nodes.copy()
    out[:, 2] += amplitude * np.sin(2 * np.pi * out[:, 0] / wavelength + phase)
    return out


@settings(max_examples=12, deadline=None)
@given(amplitude=st.floats(0.01, 0.6), wavelength=st.floats(4.0, 30.0),
       phase=st.floats(0.0, 6.3), offset=st.sampled_from([0.0, 1e4, -3e5]))
def test_every_state_within_tolerance_under_random_bending(amplitude, wavelength, phase, offset):
    """A 10 x 10 plate in two parts bent by a growing sine over three states, and moved far
    away at the last: the decimation certified at every state is within each part's tolerance
    at every state, measured by the independent metric (its upper end; the tolerance derived:
    the decimation certifies distance <= tol, the metric's upper end is within 1 % of tol
    above the exact distance, so ratio <= 1.01 -- asserted at 1.0 + that 1 %)."""
    nodes, quads = quad_grid(10, 10, cell=1.0)
    triangles = split_quads(quads)
    parts = np.where(nodes[triangles].mean(axis=1)[:, 0] < 5.0, 1, 2)
    steps = np.stack([nodes, _bent(nodes, amplitude / 2, wavelength, phase),
                      _bent(nodes, amplitude, wavelength, phase) + offset])
    d = hausdorff_decimate(steps[0], triangles, 0.005, relative=True, parts=parts,
                           states=steps[1:])
    b = bounds_over_states(steps, triangles, parts, d)
    assert (b.ratio <= 1.0 + 0.01).all()
    # the decimation's own bounds are upper bounds at every state: its largest in each part
    # is at least the metric's lower end at every state
    for p, label in enumerate(b.part_labels):
        assert np.nanmax(d.bounds[parts == label]) >= b.lower[:, p].max()


def test_eroded_triangles_vanish_with_their_simplified_triangles():
    """A block of the plate is deleted at state 2, where a vertex inside it is lifted far out
    of the plane. With ``alive``, at every state the simplified triangles drawn (those whose
    source is drawn) certify the drawn original triangles (independent metric), and every
    simplified triangle's corners are corners of original triangles drawn at the same states."""
    nodes, quads = quad_grid(8, 8, cell=1.25)
    triangles = split_quads(quads)
    centre = nodes[triangles].mean(axis=1)
    parts = np.where(centre[:, 0] < 5.0, 1, 2)
    block = (centre[:, 0] > 1.0) & (centre[:, 0] < 4.0) & (centre[:, 1] > 2.5) & \
        (centre[:, 1] < 7.5)
    inside = np.setdiff1d(np.unique(triangles[block]), np.unique(triangles[~block]))
    steps = np.stack([nodes, nodes, nodes])
    steps[2, inside[0], 2] += 2.0
    alive = np.ones((3, len(triangles)), bool)
    alive[2, block] = False
    d = hausdorff_decimate(steps[0], triangles, 0.005, relative=True, parts=parts,
                           states=steps[1:], alive=alive)
    assert len(d.triangles) < len(triangles)
    for state in range(3):
        drawn = alive[state, d.source]
        b = distances_over_states(steps, triangles[alive[state]], parts[alive[state]],
                                  d.triangles[drawn], d.parts[drawn], d.part_labels, d.tol_abs,
                                  states=[state])
        assert (b.ratio <= 1.0).all()
        both = bounds_over_states(steps, triangles, parts, d, alive=alive, states=[state])
        assert np.array_equal(both.upper, b.upper)
    pattern = {}
    for tri, live in zip(triangles, alive.T):
        for x in tri:
            pattern.setdefault(int(x), set()).add(tuple(live))
    for tri, src in zip(d.triangles, d.source):
        assert all(tuple(alive[:, src]) in pattern[int(x)] for x in tri)
    # without alive the lifted vertex must stay; the deleted block lets it go
    d_all = hausdorff_decimate(steps[0], triangles, 0.005, relative=True, parts=parts,
                               states=steps[1:])
    assert inside[0] in d_all.triangles


def test_refusals_of_states_and_alive(plate):
    steps, triangles, parts, _, _ = plate
    with pytest.raises(ValueError, match="states must be"):
        hausdorff_decimate(steps[0], triangles, states=steps[:, :10])
    bad = steps[1:].copy()
    bad[0, 3, 1] = np.nan
    with pytest.raises(ValueError, match="states must be finite"):
        hausdorff_decimate(steps[0], triangles, states=bad)
    with pytest.raises(ValueError, match="alive must be"):
        hausdorff_decimate(steps[0], triangles, states=steps[1:],
                           alive=np.ones((3, len(triangles)), bool))


def test_simplify_certify_states_holds_where_the_first_state_alone_exceeds(capsys):
    assert main(["simplify", "crash:2", "--states", "all", "--certify-states"]) == 0
    out = capsys.readouterr().out
    lines = [line.strip() for line in out.splitlines() if line.strip().startswith("state ")]
    assert len(lines) == 2 and not any("exceeds" in line for line in lines)
    assert "certified at 2 states" in out and "holds at every state measured" in out
    assert main(["simplify", "crash:2", "--certify-states"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--certify-states needs --states" in err
