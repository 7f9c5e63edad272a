"""The one frame loop (``draw_frames``): each frame is the image ``paths.render`` draws of the
state it shows, the update's bytes and times are reported, frames are drawn only when asked
(so what the caller does between two frames shows in the next), and every sequence of frames
in the package — ``animate``, ``explode``, ``fig_exploded``, the live view — goes through it."""

import ast
from pathlib import Path

import numpy as np
import pytest
from meshes import write_d3plot

from workbench.animation.frames import draw_frames
from workbench.paths import make_path, prepared, render
from workbench.scene.readers import load

ROOT = Path(__file__).resolve().parents[2]
SIZE = (64, 48)
VIEW = (0.0, 30.0)
LOOPS = ("workbench/animation/frames.py", "workbench/animation/exploded.py",
         "workbench/reproductions/fig_exploded.py", "workbench/viewer/live.py")


@pytest.fixture(scope="module")
def mesh(tmp_path_factory):
    """A three-state d3plot (two shells rising by 0.5 a state)."""
    return load(write_d3plot(tmp_path_factory.mktemp("crash")))


def camera_of(mesh):
    return make_path("gouraud").fit_camera(*mesh.bounds(all_steps=True), SIZE, view=VIEW)


def test_each_frame_is_the_image_render_draws_of_its_state(ctx, mesh):
    camera = camera_of(mesh)
    style = make_path("element_color", field="plastic_strain").style
    with prepared(ctx, mesh, "element_color", style, camera, SIZE) as ready:
        drawn = list(draw_frames(ready, range(mesh.n_steps), update=ready.path.set_step))
        per_step = ready.path.bytes_per_step
    assert [d.state for d in drawn] == [0, 1, 2]
    # coordinates and values each state, and at the last, which deletes the triangle
    # shell, its one triangle's index (12 bytes) made degenerate in place
    assert drawn[0].sent == drawn[1].sent == per_step > 0 and drawn[2].sent == per_step + 12
    assert all(d.update_ms >= 0 and d.draw_ms > 0 and d.read_ms > 0 for d in drawn)
    images = [d.image for d in drawn]
    assert not np.array_equal(images[0], images[2])  # the shells rose: the frames differ
    for k, image in enumerate(images):
        np.testing.assert_array_equal(
            image, render(ctx, mesh, "element_color", style, camera, SIZE, step=k))


def test_frames_are_drawn_when_asked_and_unread_on_request(ctx, mesh):
    """The caller's change between two frames (here the state, set by hand) shows in the next
    frame; ``read=False`` draws without reading back; the background is the caller's."""
    camera = camera_of(mesh)
    with prepared(ctx, mesh, "gouraud", camera=camera, size=SIZE) as ready:
        frames = draw_frames(ready, ["first", "second"], background=(0.0, 0.0, 0.0, 1.0))
        first = next(frames)
        ready.path.set_step(2)
        second = next(frames)
        assert next(frames, None) is None
        unread = list(draw_frames(ready, [0], read=False))
    assert (first.state, second.state) == ("first", "second")
    assert (first.image[0, 0, :3] == 0).all()  # the black background in a corner
    np.testing.assert_array_equal(
        second.image, render(ctx, mesh, "gouraud", camera=camera, size=SIZE, step=2,
                             background=(0.0, 0.0, 0.0, 1.0)))
    assert not np.array_equal(first.image, second.image)
    assert unread[0].image is None and unread[0].read_ms == 0


@pytest.mark.parametrize("module", LOOPS)
def test_every_sequence_of_frames_goes_through_the_one_loop(module):
    """``animate`` (FrameLoop), ``explode``, ``fig_exploded`` and the live view call
    ``draw_frames``; none of them calls ``.draw()`` of a path in a loop of its own."""
    tree = ast.parse((ROOT / module).read_text(encoding="utf-8"))
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)]
    names = {getattr(c.func, "id", getattr(c.func, "attr", None)) for c in calls}
    if module.endswith("frames.py"):
        assert "draw_frames" in {f.name for f in ast.walk(tree)
                                 if isinstance(f, ast.FunctionDef)}
        return
    assert "draw_frames" in names
    own = [loop for loop in ast.walk(tree) if isinstance(loop, (ast.For, ast.While))
           and not (isinstance(loop, ast.For) and isinstance(loop.iter, ast.Call)
                    and getattr(loop.iter.func, "id", None) == "draw_frames")
           and any(isinstance(n, ast.Call) and getattr(n.func, "attr", None) == "draw"
                   for n in ast.walk(loop))]
    assert own == []
