"""``workbench animate`` and its frame loop: a multi-state d3plot drawn state by state with one
preparation, each frame equal to ``workbench render --step K --raw``, uploads per state equal to
the path's ``bytes_per_step``, one camera for the whole sequence, the colour bar fixed or per
state, MP4 and GIF written atomically, and bad input refused in one line."""

import imageio.v3 as iio
import numpy as np
import pytest
from meshes import write_d3plot
from PIL import Image

from workbench.animation.decoration import Decoration
from workbench.animation.frames import FrameLoop, state_value_range
from workbench.cli import main
from workbench.cli.animate import state_selection
from workbench.measurement.rows import measure
from workbench.paths import make_path
from workbench.paths.base import RenderPath
from workbench.scene.readers import load

SIZE = (64, 48)
VIEW = (0.0, 30.0)  # the plate seen from above its front edge: its rise in z moves it upwards
FIELD = "plastic_strain"  # per element, 0, 0.01, 0.02 in the three states


@pytest.fixture(scope="module")
def crash(tmp_path_factory):
    """A three-state d3plot (two shells rising by 0.5 a state) written with lasso-python."""
    return write_d3plot(tmp_path_factory.mktemp("crash"))


@pytest.fixture()
def mesh(crash):
    return load(crash)


def render(source, tmp_path, k: int, *options: str, size=SIZE, view=VIEW) -> np.ndarray:
    """The image ``workbench render SOURCE --step K --raw`` writes, as (H, W, 4) uint8."""
    out = tmp_path / f"render_{k}.png"
    assert main(["render", str(source), "--step", str(k), "--size", f"{size[0]}x{size[1]}",
                 "--view", f"{view[0]},{view[1]}", "--raw", "-o", str(out), *options]) == 0
    return np.asarray(Image.open(out))


def frames_of(ctx, mesh, path="gouraud", style=None, steps=None, size=SIZE, **kwargs):
    loop = FrameLoop(ctx, mesh, path, style, steps=range(mesh.n_steps) if steps is None
                     else steps, size=size, view=VIEW, **kwargs)
    return loop, list(loop)


# --------------------------------------------------------------------------- the frame loop
@pytest.mark.parametrize("path, field", [("gouraud", None), ("flat", None), ("position", None),
                                         ("quad_wire", None), ("element_color", FIELD),
                                         ("element_color", "alive")])
def test_frames_equal_render_of_each_state(ctx, crash, mesh, tmp_path, path, field):
    from contextlib import nullcontext

    from workbench.paths.mesh import ErosionWarning

    style = make_path(path, field=field).style
    # quad_wire draws strips, which keep the shell the d3plot deletes: it says so
    said = pytest.warns(ErosionWarning, match="quad_wire") if path == "quad_wire" else \
        nullcontext()
    with said:
        _, frames = frames_of(ctx, mesh, path, style)
    assert [f.step for f in frames] == [0, 1, 2]
    options = ["--path", path] + (["--field", field] if field else [])
    for frame in frames:
        assert frame.image.shape == (SIZE[1], SIZE[0], 4)
        assert np.array_equal(frame.image, render(crash, tmp_path, frame.step, *options))
    assert not np.array_equal(frames[0].image, frames[2].image)  # the plate moved


@pytest.mark.parametrize("path, field, per_vertex", [
    ("position", None, 12), ("gouraud", None, 24), ("element_color", FIELD, 16)])
def test_bytes_per_state_are_the_paths_bytes_per_step(ctx, mesh, path, field, per_vertex):
    """Coordinates (12 bytes a vertex), normals (12) where the path lights per vertex, field
    values (4) where it colours: set_step's bytes, the prepared path's bytes_per_step and the
    measured row's alike; and at the state that deletes the triangle shell, the 12 bytes of
    its one triangle made degenerate in place (the rest of the index is not sent again)."""
    style = make_path(path, field=field).style
    loop, frames = frames_of(ctx, mesh, path, style)
    row = measure(ctx, mesh, path, style, size=SIZE, timed=False).row
    assert row["bytes_per_step"] == row["vertices"] * per_vertex
    assert [f.deleted for f in frames] == [0, 0, 1]
    assert [f.bytes_uploaded for f in frames] == [row["bytes_per_step"]] * 2 + [
        row["bytes_per_step"] + 12]
    assert all(f.bytes_per_step == row["bytes_per_step"] for f in frames)
    assert loop.prepare_bytes == row["bytes_uploaded"] > row["bytes_per_step"]
    assert all(f.upload_ms >= 0 and f.draw_ms > 0 for f in frames)


def test_one_camera_fitted_to_every_state(ctx, mesh):
    loop, frames = frames_of(ctx, mesh)
    lo, hi = mesh.bounds(all_steps=True)
    assert np.allclose(lo, [0, 0, 0]) and np.allclose(hi, [2, 1, 1])  # z rises 0 → 1
    fitted = RenderPath.fit_camera(lo, hi, SIZE, view=VIEW)
    assert np.allclose(loop.camera.mvp(), fitted.mvp())
    # the last state leaves the box of the first: a camera fitted to it alone loses nodes
    first = RenderPath.fit_camera(*mesh.bounds(0), SIZE, view=VIEW)
    window = first.project(mesh.coordinates(2), SIZE)
    assert ((window[:, 1] < 0) | (window[:, 1] > SIZE[1])).any()
    tops = []
    for frame in frames:
        drawn = (frame.image[..., :3] != 255).any(axis=2)
        assert drawn.any()
        assert not (drawn[0].any() or drawn[-1].any() or drawn[:, 0].any()
                    or drawn[:, -1].any())  # every state inside the image
        tops.append(np.flatnonzero(drawn.any(axis=1))[0])
    assert tops[0] > tops[1] > tops[2]  # the plate rises through a camera that stays


def test_fixed_scale_is_the_range_over_all_states_and_one_bar(ctx, mesh):
    loop, frames = frames_of(ctx, mesh, "element_color", make_path("element_color",
                                                                   field=FIELD).style)
    everything = mesh.field_range(FIELD)  # written as float32
    assert everything == pytest.approx((0.0, 0.02))
    assert loop.colour_scale.value_range == everything
    assert all(f.value_range == everything for f in frames)
    decorate = Decoration("plate", FIELD, "1")
    box = decorate.bar_box(SIZE)
    bars = [box.of(decorate(f)) for f in frames]
    assert all(np.array_equal(bars[0], bar) for bar in bars[1:])
    assert (bars[0] != 255).any()  # the box holds the bar
    titled = [decorate(f) for f in frames]
    assert not np.array_equal(titled[0], titled[1])  # the time stamps differ
    for frame, image in zip(frames, titled):  # each pixel 4 × 4 (the frame under 160 rows)
        enlarged = np.repeat(np.repeat(frame.image[..., :3], 4, axis=0), 4, axis=1)
        assert np.array_equal(decorate.image_box(SIZE).of(image), enlarged)


def test_per_step_scale_draws_each_states_range(ctx, crash, mesh, tmp_path):
    style = make_path("element_color", field=FIELD).style
    loop, frames = frames_of(ctx, mesh, "element_color", style, scale="per-step")
    ranges = [state_value_range(mesh, FIELD, k) for k in range(3)]
    # constant per state: (v, v + 1)
    assert np.allclose(ranges, [(0.0, 1.0), (0.01, 1.01), (0.02, 1.02)])
    decorate = Decoration("plate", FIELD)
    box = decorate.bar_box(SIZE)
    bars = []
    for frame, (lo, hi) in zip(frames, ranges):
        assert frame.value_range == (lo, hi)
        expected = render(crash, tmp_path, frame.step, "--field", FIELD, "-O",
                          f"value_range=({lo!r},{hi!r})")
        assert np.array_equal(frame.image, expected)
        assert frame.bytes_uploaded > frame.bytes_per_step  # prepared again, topology too
        bars.append(box.of(decorate(frame)))
    assert not np.array_equal(bars[0], bars[1]) and not np.array_equal(bars[1], bars[2])


def test_frame_loop_refusals(ctx, mesh):
    with pytest.raises(ValueError, match="no state selected; d3plot has 3 states"):
        FrameLoop(ctx, mesh, "gouraud", steps=[])
    with pytest.raises(ValueError, match="state 3 is out of range: d3plot has 3 states"):
        FrameLoop(ctx, mesh, "gouraud", steps=[0, 3])
    with pytest.raises(ValueError, match="path .gouraud. colours by none"):
        FrameLoop(ctx, mesh, "gouraud", steps=[0], scale="per-step")
    with pytest.raises(ValueError, match="cannot be animated"):
        FrameLoop(ctx, mesh, "fe_normal_map", steps=[0])
    with pytest.raises(KeyError, match="no field 'stress'"):
        FrameLoop(ctx, mesh, "element_color", make_path("element_color", field="stress").style,
                  steps=[0])


# --------------------------------------------------------------------------- the command
@pytest.mark.parametrize("text, states", [("1:", [1, 2]), ("::2", [0, 2]), ("0:2", [0, 1]),
                                          ("-1", [2]), ("-2:", [1, 2]), ("1", [1])])
def test_steps_select_like_a_python_slice(mesh, text, states):
    assert state_selection(text).states(mesh) == states


def decorated_frames(ctx, mesh, steps=None):
    """The frames ``animate CRASH --field plastic_strain`` writes, before encoding."""
    style = make_path("element_color", field=FIELD).style
    _, frames = frames_of(ctx, mesh, "element_color", style, steps)
    decorate = Decoration("d3plot (element_color)", FIELD)
    return [decorate(f) for f in frames]


def animate(crash, out, *options: str) -> int:
    return main(["animate", str(crash), "-o", str(out), "--size", f"{SIZE[0]}x{SIZE[1]}",
                 "--view", f"{VIEW[0]},{VIEW[1]}", "--field", FIELD, *options])


def test_gif_holds_every_state(ctx, crash, mesh, tmp_path, capsys):
    out = tmp_path / "crash.gif"
    assert animate(crash, out) == 0
    read = iio.imread(out, index=None)
    expected = decorated_frames(ctx, mesh)
    assert read.shape == (3, *expected[0].shape)
    for got, want in zip(read, expected):  # 256 colours a frame: close, not equal
        assert np.abs(got[..., :3].astype(int) - want).mean() < 0.5
    printed = capsys.readouterr().out
    assert "3 frames of d3plot (3 states), path element_color" in printed
    # coordinates and values (80 bytes), and at the last state the deleted triangle (12)
    assert "80 or 92 bytes uploaded (the path's bytes_per_step: 80)" in printed
    assert "deleted elements per state (not drawn): 0, 0, 1" in printed
    assert [p.name for p in tmp_path.iterdir()] == ["crash.gif"]  # no temporary file left


def test_mp4_holds_the_selected_states(ctx, crash, mesh, tmp_path):
    out = tmp_path / "crash.mp4"
    assert animate(crash, out, "--steps", "0:3:2", "--fps", "5") == 0
    read = iio.imread(out, index=None, plugin="FFMPEG")
    expected = decorated_frames(ctx, mesh, steps=[0, 2])
    assert read.shape == (2, *expected[0].shape)
    for got, want in zip(read, expected):  # H.264 in 4:2:0 chroma: close, not equal
        assert np.abs(got.astype(int) - want).mean() < 2.0
    assert [p.name for p in tmp_path.iterdir()] == ["crash.mp4"]


@pytest.mark.parametrize("output, options, words", [
    ("crash.avi", (), "write an animation as .mp4 (H.264) or .gif"),
    ("crash.gif", ("--steps", "2:2"), "--steps 2:2 selects no state; d3plot has 3 states"),
    ("crash.gif", ("--steps", "0:9"), "stop 9 is out of range; d3plot has 3 states"),
    ("crash.gif", ("--steps", "5"), "state 5 is out of range; d3plot has 3 states"),
    ("crash.gif", ("--device", "99"), "--device 99"),
    ("crash.mp4", ("--size", "63x48"), "--size 63x48: MP4 (H.264, yuv420p) needs an even"),
    ("crash.gif", ("--path", "flange"), "path 'flange' cannot be animated"),
    ("crash.gif", ("-O", "step=1"), "select states with --steps"),
])
def test_bad_input_is_one_line_and_writes_nothing(crash, tmp_path, capsys, output, options,
                                                  words):
    folder = tmp_path / "out"
    folder.mkdir()
    assert animate(crash, folder / output, *options) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("workbench: error: ") and "\n" not in err and words in err, err
    assert list(folder.iterdir()) == []


def test_output_that_is_no_regular_file_is_refused(crash, tmp_path, capsys):
    out = tmp_path / "crash.gif"
    out.mkdir()
    assert animate(crash, out) == 2
    assert "is a directory, not a regular file" in capsys.readouterr().err


def test_mp4_failing_mid_way_leaves_nothing(crash, tmp_path, monkeypatch):
    from workbench.animation import decoration

    drawn = []
    original = decoration.Decoration.__call__

    def failing(self, frame):
        if drawn:
            raise RuntimeError("stop at the second frame")
        drawn.append(frame.step)
        return original(self, frame)

    monkeypatch.setattr(decoration.Decoration, "__call__", failing)
    old = tmp_path / "crash.mp4"
    old.write_bytes(b"the previous video")
    with pytest.raises(RuntimeError, match="second frame"):
        animate(crash, old)
    assert drawn == [0]
    assert [p.name for p in tmp_path.iterdir()] == ["crash.mp4"]
    assert old.read_bytes() == b"the previous video"


# --------------------------------------------------------------------------- the shared d3plot
def test_shared_d3plot_frames_equal_render_of_every_state(ctx, d3plot_file, tmp_path):
    from workbench.scene.builtin import load_scene

    shared = load_scene("d3plot")
    style = make_path("element_color", field="von_mises").style
    loop = FrameLoop(ctx, shared, "element_color", style, steps=range(shared.n_steps),
                     size=(160, 120))
    frames = list(loop)
    assert len(frames) == shared.n_steps
    for frame in frames:
        expected = render("d3plot", tmp_path, frame.step, "--field", "von_mises",
                          size=(160, 120), view=(30.0, 25.0))
        assert np.array_equal(frame.image, expected)
        assert frame.bytes_uploaded == frame.bytes_per_step


def test_the_car_crash_frames_equal_render_of_every_state(ctx, car_deck, tmp_path):
    """The car's 8-state crash (built-in ``crash``): one preparation, then per state the
    coordinates, the Gouraud normals and the displacement only (the measured row's
    ``bytes_per_step``), each frame equal to ``render crash --step K``."""
    from workbench.scene.builtin import load_scene

    crash = load_scene("crash")
    style = make_path("pixel_color", field="displacement").style
    loop = FrameLoop(ctx, crash, "pixel_color", style, steps=range(crash.n_steps),
                     size=(160, 100))
    frames = list(loop)
    assert [f.step for f in frames] == list(range(8))
    row = measure(ctx, crash, "pixel_color", style, size=(160, 100), timed=False).row
    for frame in frames:
        assert frame.bytes_uploaded == frame.bytes_per_step == row["bytes_per_step"]
        expected = render("crash", tmp_path, frame.step, "--path", "pixel_color", "--field",
                          "displacement", size=(160, 100), view=(30.0, 25.0))
        assert np.array_equal(frame.image, expected), frame.step
    assert row["bytes_per_step"] == row["vertices"] * (12 + 12 + 4)  # xyz, normal, value
    assert loop.prepare_bytes == row["bytes_uploaded"] > row["bytes_per_step"]
    assert len({f.image.tobytes() for f in frames}) == 8  # the car moves every state
