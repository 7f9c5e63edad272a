"""The certified distance of one decimation at every state of a result
(:mod:`workbench.algo.simplify.states`), against answers known exactly: a flat plate whose
removed vertices move by a known height at a later state, and rigid motions, which change no
distance."""

import numpy as np
import pytest
from meshes import quad_grid, split_quads

from workbench.algo.simplify import hausdorff_decimate
from workbench.algo.simplify.states import bounds_over_states
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
