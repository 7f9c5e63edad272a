"""Runs of the workbench command whose result would be wrong end either right or refused with
one line and exit status 2: a sweep point turned by NaN degrees, a mesh with one node 1e20 mm
out, and the exploded view's report of the frame that revealed its focus part."""

from __future__ import annotations

import math
import re

import pytest
from meshes import write_keyword_deck

from workbench.algo.explode import occlusion_ratio
from workbench.cli import main
from workbench.paths.exploded import ExplodeStyle
from workbench.scene.generators import box_in_box
from workbench.sweep import Point, load_config, run_point

# ------------------------------------------------------------------------------- sweeps
SWEEP = """[grid]
scene = "semicylinders:4"
path = "gouraud"
size = "64x48"
view = {view}
"""


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "Traceback" not in err[0]
    return err[0]


@pytest.mark.parametrize("view", ["[nan, nan]", "[30, inf]", "[-inf, 0]", "[true, false]",
                                  "[30]"])
def test_a_sweep_view_that_is_not_two_finite_angles_is_refused_naming_file_and_key(
        tmp_path, capsys, view):
    config = tmp_path / "views.toml"
    config.write_text(SWEEP.format(view=view))
    with pytest.raises(ValueError) as info:
        load_config(config)
    assert str(info.value).startswith(f"{config}: grid key 'view': ")
    out = tmp_path / "out"
    assert main(["sweep", str(config), "--out", str(out)]) == 2
    line = _one_error_line(capsys)
    assert line.startswith(f"workbench: error: {config}: grid key 'view': ")
    assert not out.exists()


def test_a_sweep_of_finite_views_is_read(tmp_path):
    config = tmp_path / "views.toml"
    config.write_text(SWEEP.format(view="[[0, 0], [-30.5, 89]]"))
    assert load_config(config).grid["view"] == [(0.0, 0.0), (-30.5, 89.0)]


def test_a_sweep_point_that_draws_nothing_fails_with_that_reason(ctx, monkeypatch):
    """A point made without the config's checks (view NaN degrees) draws a blank image: its
    row carries the error, which is what counts a point as failed."""
    import workbench.distributed.cluster as cluster

    monkeypatch.setattr(cluster, "worker_context", lambda: ctx)
    common = dict(index=0, scene="semicylinders:4", path="gouraud", size=(64, 48),
                  timed=False)
    blank = run_point(Point(**common, view=(math.nan, math.nan)), 1, "test")
    assert blank["error"] == ("ValueError: the image shows nothing of the scene: no pixel of "
                              "the 64x48 image differs from the background")
    assert "covered_px" not in blank
    drawn = run_point(Point(**common, view=(30.0, 25.0)), 1, "test")
    assert "error" not in drawn and drawn["covered_px"] > 0


# ------------------------------------------------------------------------------- render
PLATE_AND_FAR_STRIP = """*KEYWORD
*PART
plate
         1         1
*SECTION_SHELL
         1
       1.0       1.0       1.0       1.0
*NODE
       1             0.0             0.0             0.0
       2           100.0             0.0             0.0
       3           100.0           100.0             0.0
       4             0.0           100.0             0.0
       5          {far:6}             0.0             0.0
       6          {far:6}           100.0             0.0
*ELEMENT_SHELL
       1       1       1       2       3       4
       2       1       2       5       6       3
*END
"""


def test_render_refuses_a_mesh_drawn_as_nothing_naming_its_extent_and_far_node(
        ctx, tmp_path, capsys):
    """One node 1e20 mm out widens the fitted view until every element is thinner than a
    pixel: no image showing nothing is written with exit status 0."""
    deck = tmp_path / "far.k"
    deck.write_text(PLATE_AND_FAR_STRIP.format(far="1e20"))
    out = tmp_path / "far.png"
    assert main(["render", str(deck), "--size", "80x60", "-o", str(out)]) == 2
    line = _one_error_line(capsys)
    assert "the 80x60 image shows nothing of far.k: no pixel differs from the background" in line
    assert "every element is thinner than a pixel" in line
    assert "extent of 1e+20 mm (node 5 at (1e+20, 0, 0)" in line
    assert not out.exists()


def test_render_refuses_a_mesh_beyond_float32_before_drawing(ctx, tmp_path, capsys):
    deck = tmp_path / "huge.k"
    deck.write_text(PLATE_AND_FAR_STRIP.format(far="1e39"))
    out = tmp_path / "huge.png"
    assert main(["render", str(deck), "--size", "80x60", "-o", str(out)]) == 2
    line = _one_error_line(capsys)
    assert "extent of 1e+39 mm (node 5 at (1e+39, 0, 0)" in line
    assert "beyond what float32 coordinates relative to its centre can draw" in line
    assert not out.exists()


def test_render_refuses_an_image_clipped_empty(ctx, tmp_path, capsys):
    deck = tmp_path / "plate.k"
    deck.write_text(PLATE_AND_FAR_STRIP.format(far="200.0"))
    out = tmp_path / "plate.png"
    assert main(["render", str(deck), "--size", "80x60", "-o", str(out)]) == 0
    assert out.exists()
    clipped = tmp_path / "clipped.png"
    assert main(["render", str(deck), "--size", "80x60", "-O", "clip_planes=((0,0,1,-1000),)",
                 "-o", str(clipped)]) == 2
    line = _one_error_line(capsys)
    assert line == ("workbench: error: the 80x60 image shows nothing of plate.k: no pixel "
                    "differs from the background")
    assert not clipped.exists()


def test_a_far_node_no_element_uses_does_not_stop_the_render(ctx, tmp_path):
    deck = tmp_path / "stray.k"
    deck.write_text(PLATE_AND_FAR_STRIP.format(far="1e20").replace(
        "       2       1       2       5       6       3\n", ""))
    out = tmp_path / "stray.png"
    assert main(["render", str(deck), "--size", "80x60", "-o", str(out)]) == 0
    assert out.exists()


# ------------------------------------------------------------------------------- explode
FRAME = re.compile(r"frame +(\d+)/(\d+): offset \S+, r \S+ \((\d+) of (\d+) px visible\)")


def _explode(deck, out, frames: int, capsys) -> tuple[list[tuple[int, int]], str]:
    """((p_occ, p_unocc) per frame as printed, the last line) of a run at view 30,25 with
    ratio exponent 1 (the thesis's: several frames to the reveal)."""
    assert main(["explode", str(deck), "--focus", "7", "--view", "30,25", "--ratio-exponent",
                 "1", "--frames", str(frames), "--size", "96x80", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    counts = [(int(m[3]), int(m[4])) for m in map(FRAME.match, lines) if m]
    assert len(counts) == frames
    return counts, lines[-1]


def _first_revealed(counts: list[tuple[int, int]]) -> int | None:
    """The first frame (1-based) whose r is at or below the reveal threshold."""
    threshold = ExplodeStyle().animation_settings(1.0).revealed_below
    return next((i + 1 for i, (p_occ, p_unocc) in enumerate(counts)
                 if occlusion_ratio(p_unocc, p_occ) <= threshold), None)


@pytest.fixture
def box_deck(tmp_path):
    deck = tmp_path / "box.k"
    write_keyword_deck(box_in_box(1.0, 0.2), deck, parts=True)
    return deck


def test_explode_reports_the_frame_that_revealed_the_focus(ctx, box_deck, tmp_path, capsys):
    counts, last = _explode(box_deck, tmp_path / "box.gif", 20, capsys)
    frame = _first_revealed(counts)
    assert frame is not None and 1 < frame < 20  # hidden at first, revealed on the way
    p_occ, p_unocc = counts[frame - 1]
    assert last.startswith(f"revealed at frame {frame} of 20: ")
    assert f"({p_occ} of {p_unocc})" in last


def test_explode_says_when_the_focus_was_not_revealed(ctx, box_deck, tmp_path, capsys):
    counts, last = _explode(box_deck, tmp_path / "box.gif", 3, capsys)
    assert _first_revealed(counts) is None
    p_occ, p_unocc = counts[-1]
    share = 100.0 * p_occ / p_unocc
    assert last.startswith(f"not revealed within 3 frames: {share:.3g} % of its pixels "
                           f"visible ({p_occ} of {p_unocc}) in the last frame, ")


def test_explode_refuses_a_focus_without_pixels(ctx, tmp_path, capsys):
    """The inner box, 2e-6 wide, lies between the pixel centres of a 96 x 80 image."""
    deck = tmp_path / "tiny.k"
    write_keyword_deck(box_in_box(1.0, 1e-6), deck, parts=True)
    out = tmp_path / "tiny.gif"
    assert main(["explode", str(deck), "--focus", "7", "--view", "0,0", "--frames", "5",
                 "--size", "96x80", "-o", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.err.strip() == ("workbench: error: focus part 7 has no pixels in this "
                                    "96x80 view (smaller than a pixel or seen edge-on): there "
                                    "is nothing to reveal")
    assert "revealed" not in captured.out
    assert not out.exists()
