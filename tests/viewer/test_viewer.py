"""The live Jupyter view (workbench.viewer): the orbit maths (float64, no GL), the widget driven
by synthetic jupyter_rfb events and controls (frames drawn on the headless context), the lazy
``workbench.view`` facade, and the example notebook executed by a kernel of this interpreter."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.gl import Camera
from workbench.scene.mesh import FEMesh
from workbench.viewer.orbit import Orbit

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "docs" / "viewer.ipynb"

angles = st.floats(-170.0, 170.0)
sizes = st.tuples(st.integers(16, 2000), st.integers(16, 2000))
projections = st.sampled_from(["orthographic", "perspective"])
ups = st.sampled_from(["y", "z"])
LO, HI = (-1000.0, 20.0, 5.0), (3000.0, 1400.0, 1400.0)  # a car-like box far from the origin


def orbit_of(size, projection, up, view=(30.0, 25.0)) -> Orbit:
    return Orbit.fitted(LO, HI, size, angles=view, projection=projection, up=up)


def same_camera(a: Camera, b: Camera) -> None:
    scale = np.linalg.norm(np.subtract(HI, LO))
    for name in ("eye", "target"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), atol=1e-9 * scale)
    np.testing.assert_allclose(a.up, b.up, atol=1e-9)
    np.testing.assert_allclose(a.projection_matrix(), b.projection_matrix(), rtol=1e-9,
                               atol=1e-12)


# ---------------------------------------------------------------------------- orbit maths
@given(sizes, projections, ups, angles, angles, st.floats(-500, 500), st.floats(-500, 500))
def test_an_orbit_then_its_inverse_returns_the_camera(size, projection, up, d_az, d_el, px, py):
    start = orbit_of(size, projection, up).panned(px, py)
    back = start.orbited(d_az, d_el).orbited(-d_az, -d_el)
    same_camera(back.camera(), start.camera())
    dragged = start.dragged(px, py).dragged(-px, -py)
    same_camera(dragged.camera(), start.camera())


@given(sizes, projections, ups, angles, st.floats(-80.0, 80.0))
def test_orbiting_the_fitted_view_is_the_camera_fitted_at_the_new_angles(size, projection, up,
                                                                          az, el):
    turned = orbit_of(size, projection, up, (0.0, 0.0)).orbited(az, el).camera()
    fitted = Camera.fit_box(LO, HI, azimuth=az, elevation=el, projection=projection,
                            aspect=size[0] / size[1], up=up)
    for name in ("eye", "target", "up", "origin"):
        np.testing.assert_allclose(getattr(turned, name), getattr(fitted, name), atol=1e-6)
    assert (turned.near, turned.far) == pytest.approx((fitted.near, fitted.far))


@given(sizes, projections, ups, angles, angles)
def test_an_orbit_keeps_the_box_centre_at_the_image_centre(size, projection, up, az, el):
    view = orbit_of(size, projection, up).orbited(az, el)
    centre = view.camera().project(view.center[None], size)[0, :2]
    np.testing.assert_allclose(centre, np.array(size) / 2.0, atol=1e-6 * max(size))


@given(sizes, projections, ups, st.floats(0.01, 100.0), st.floats(-300, 300),
       st.floats(-300, 300))
def test_zoom_keeps_the_target_fixed(size, projection, up, factor, px, py):
    start = orbit_of(size, projection, up).panned(px, py)
    before, after = start.camera(), start.zoomed(factor).camera()
    np.testing.assert_array_equal(after.target, before.target)
    np.testing.assert_array_equal(after.eye, before.eye)
    target = before.origin + before.target
    np.testing.assert_allclose(after.project(target[None], size)[0, :2],
                               before.project(target[None], size)[0, :2], atol=1e-6)
    assert start.zoomed(factor).pixel_size() == pytest.approx(start.pixel_size() / factor)
    same_camera(start.zoomed(factor).zoomed(1.0 / factor).camera(), before)


@given(sizes, projections, ups, angles, st.floats(-400, 400), st.floats(-400, 400))
def test_a_pan_drag_moves_the_point_at_the_target_with_the_pointer(size, projection, up, az,
                                                                    dx, dy):
    start = orbit_of(size, projection, up).orbited(az, 0.0)
    camera = start.camera()
    target = camera.origin + camera.target
    moved = start.panned(dx, dy).camera().project(target[None], size)[0, :2]
    np.testing.assert_allclose(moved - camera.project(target[None], size)[0, :2], (dx, dy),
                               atol=1e-6 * max(size) + 1e-6 * np.hypot(dx, dy))


@given(st.floats(-2000, 2000))
def test_the_wheel_zooms_out_towards_the_user_and_in_away(dy):
    start = orbit_of((800, 600), "orthographic", "z")
    zoom = start.wheeled(dy).zoom
    assert zoom == pytest.approx(2.0 ** (-dy / 400.0))
    assert start.wheeled(dy).wheeled(-dy).zoom == pytest.approx(1.0)
    assert start.wheeled(100.0).zoom < 1.0 < start.wheeled(-100.0).zoom


def test_orbit_refusals():
    with pytest.raises(ValueError, match="zero extent"):
        Orbit.fitted((0, 0, 0), (0, 0, 0), (10, 10))
    with pytest.raises(ValueError, match="zoom factor must be positive"):
        orbit_of((10, 10), "orthographic", "z").zoomed(0.0)
    with pytest.raises(ValueError, match="size must be two positive integers"):
        orbit_of((10, 0), "orthographic", "z")
    with pytest.raises(ValueError, match="up must be"):
        orbit_of((10, 10), "orthographic", "x")
    with pytest.raises(ValueError, match="projection must be"):
        orbit_of((10, 10), "fisheye", "z")


# ---------------------------------------------------------------------------- scenes
def corner() -> FEMesh:
    """Two right triangles meeting at the origin, one in z = 0 and one in x = 0: seen along −z
    the first shows left of the box centre, seen along −x the second shows right of it."""
    nodes = [(0, 0, 0), (2, 0, 0), (0, 2, 0), (0, 0, 2)]
    return FEMesh(np.array(nodes, float), np.array([[0, 1, 2], [0, 2, 3]]), name="corner")


def plate(steps: int = 1) -> FEMesh:
    """A 6 × 4 grid of quads in z = 0 with a node field ``h`` (= x); step k moves it by k/2
    along x and bends it up along y."""
    x, y = np.meshgrid(np.linspace(0, 3, 7), np.linspace(0, 2, 5), indexing="ij")
    nodes = np.c_[x.ravel(), y.ravel(), np.zeros(x.size)]
    index = np.arange(x.size).reshape(x.shape)
    quads = np.stack([index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]], -1)
    moved = [nodes + np.c_[np.full(x.size, k / 2), np.zeros(x.size), k * y.ravel() ** 2 / 4]
             for k in range(steps)]
    return FEMesh(nodes, quads.reshape(-1, 4), steps=np.array(moved) if steps > 1 else None,
                  node_fields={"h": nodes[:, 0]}, name="plate")


@pytest.fixture
def make_view(ctx):
    """``make_view(scene, path, **options)``: a viewer of 160 × 120 pixels seen along −z with
    +y up, closed after the test."""
    from workbench.viewer import view

    made = []

    def make(scene, path=None, **options):
        options = {"size": (160, 120), "angles": (0.0, 0.0), "up": "y", **options}
        made.append(view(scene, path, **options))
        return made[-1]

    yield make
    for viewer in made:
        viewer.close()


def covered(frame: np.ndarray) -> np.ndarray:
    """bool (H, W): pixels that differ from the white background."""
    return (frame < 255).any(axis=2)


def centroid(frame: np.ndarray) -> np.ndarray:
    """(x, y) pixel centroid of the covered pixels."""
    rows, cols = np.nonzero(covered(frame))
    return np.array([cols.mean() + 0.5, rows.mean() + 0.5])


def drag(canvas, start, end, button=1, modifiers=(), steps=1) -> None:
    """A press at ``start``, ``steps`` moves to ``end`` and a release there."""
    base = dict(button=button, modifiers=modifiers, ntouches=0, touches={})
    canvas.handle_event(dict(type="pointer_down", x=start[0], y=start[1], buttons=(button,),
                             **base))
    for t in np.linspace(0, 1, steps + 1)[1:]:
        x, y = np.add(start, t * np.subtract(end, start))
        canvas.handle_event(dict(type="pointer_move", x=x, y=y, buttons=(button,), **base))
    canvas.handle_event(dict(type="pointer_up", x=end[0], y=end[1], buttons=(), **base))


# ---------------------------------------------------------------------------- the widget
def test_a_left_drag_of_half_the_height_orbits_by_90_degrees(make_view):
    viewer = make_view(corner())
    canvas = viewer.canvas
    before = canvas.get_frame()
    assert before.shape == (120, 160, 3) and before.dtype == np.uint8
    assert centroid(before)[0] < 80 - 10  # the z = 0 triangle, left of the centre
    drag(canvas, (100, 60), (40, 60), steps=3)  # 60 px of 120: azimuth +90°
    assert viewer.live.orbit.azimuth == pytest.approx(90.0)
    after = canvas.get_frame()
    assert centroid(after)[0] > 80 + 10  # now the x = 0 triangle, right of the centre


def test_the_wheel_zooms_about_the_centre(make_view):
    viewer = make_view(corner())
    canvas = viewer.canvas

    def wheel(dy):
        canvas.handle_event(dict(type="wheel", x=80, y=60, dx=0.0, dy=dy, buttons=(),
                                 modifiers=()))
        return canvas.get_frame()

    small = wheel(400.0)  # zoomed out by 2
    fitted = wheel(-400.0)  # back: twice as wide, four times the pixels
    assert covered(fitted).sum() == pytest.approx(4 * covered(small).sum(), rel=0.05)
    np.testing.assert_allclose(centroid(fitted) - (80, 60), 2 * (centroid(small) - (80, 60)),
                               atol=1.0)
    np.testing.assert_array_equal(wheel(400.0), small)


@pytest.mark.parametrize("button, modifiers", [(2, ()), (1, ("Shift",))])
def test_a_right_or_shift_drag_pans_with_the_pointer(make_view, button, modifiers):
    viewer = make_view(plate())
    canvas = viewer.canvas
    canvas.handle_event(dict(type="wheel", x=80, y=60, dx=0.0, dy=800.0, buttons=(),
                             modifiers=()))  # a quarter of the size: nothing leaves the frame
    before = canvas.get_frame()
    drag(canvas, (50, 50), (70, 40), button=button, modifiers=modifiers, steps=2)
    after = canvas.get_frame()
    np.testing.assert_allclose(centroid(after) - centroid(before), (20, -10), atol=1.0)
    assert covered(after).sum() == pytest.approx(covered(before).sum(), rel=0.1)


def test_a_resize_draws_at_the_physical_size_and_maps_the_pointer(make_view):
    viewer = make_view(corner())
    canvas = viewer.canvas
    canvas.handle_event(dict(type="resize", width=100, height=60, pwidth=200, pheight=120,
                             ratio=2.0))
    assert canvas.get_frame().shape == (120, 200, 3)
    drag(canvas, (60, 30), (45, 30))  # 15 logical = 30 frame pixels of 120: 45°
    assert viewer.live.orbit.azimuth == pytest.approx(45.0)


def test_old_style_events_and_a_double_click_reset(make_view):
    viewer = make_view(corner())
    canvas = viewer.canvas
    before = canvas.get_frame()
    canvas.handle_event(dict(event_type="wheel", x=0, y=0, dx=0, dy=-100, modifiers=()))
    assert viewer.live.orbit.zoom > 1.0
    canvas.handle_event(dict(type="double_click", x=0, y=0, button=1, buttons=(1,),
                             modifiers=()))
    np.testing.assert_array_equal(canvas.get_frame(), before)


def test_the_step_slider_draws_the_step(make_view):
    viewer = make_view(plate(steps=3))
    path = viewer.live.path
    first = viewer.canvas.get_frame()
    viewer.controls["step"].value = 2
    moved = viewer.canvas.get_frame()
    assert (moved != first).any()
    assert viewer.live.path is path  # set_step uploaded the step; nothing was prepared again
    np.testing.assert_array_equal(moved, make_view(plate(steps=3), step=2).canvas.get_frame())


def test_style_controls_draw_what_a_view_made_with_that_style_draws(make_view):
    viewer = make_view(plate(), field="h")
    assert viewer.live.path_name == "pixel_color"
    assert set(viewer.controls) == {"bands", "value_range"}
    smooth = viewer.canvas.get_frame()
    viewer.controls["bands"].value = 4
    banded = viewer.canvas.get_frame()
    assert (banded != smooth).any()
    np.testing.assert_array_equal(banded, make_view(plate(), field="h", bands=4)
                                  .canvas.get_frame())
    viewer.controls["value_range"].value = (1.0, 2.0)
    np.testing.assert_array_equal(viewer.canvas.get_frame(), make_view(
        plate(), field="h", bands=4, value_range=(1.0, 2.0)).canvas.get_frame())


def test_a_refused_control_value_is_shown_and_the_view_stays(make_view):
    viewer = make_view(plate(), field="h")
    before = viewer.canvas.get_frame()
    viewer.controls["value_range"].value = (1.5, 1.5)
    assert viewer.status.value.startswith("refused: value_range must be finite with lo < hi")
    np.testing.assert_array_equal(viewer.canvas.get_frame(), before)


def test_the_flange_threshold_control_prepares_the_path_again(make_view):
    from workbench.scene.generators import box_in_box

    viewer = make_view(box_in_box(n=6), "flange", threshold=0.2, cutoff=2.0)
    assert set(viewer.controls) == {"bands", "threshold"}
    narrow = viewer.canvas.get_frame()
    viewer.controls["threshold"].value = 0.6
    wide = viewer.canvas.get_frame()
    assert covered(wide).sum() > covered(narrow).sum()
    np.testing.assert_array_equal(wide, make_view(box_in_box(n=6), "flange", threshold=0.6,
                                                  cutoff=2.0).canvas.get_frame())


def settle(canvas, frames: int = 80) -> np.ndarray:
    """Frames until the explosion stops moving (at most ``frames``); the last one."""
    for _ in range(frames):
        frame = canvas.get_frame()
        if not canvas.live.animating:
            return frame
    raise AssertionError(f"the explosion still moves after {frames} frames")


def test_a_click_on_a_part_of_an_exploded_view_makes_it_the_focus(make_view):
    from workbench.scene.generators import box_in_box

    viewer = make_view(box_in_box(n=4), "exploded", focus=7, angles=(30.0, 25.0))
    canvas, live = viewer.canvas, viewer.live
    revealed = settle(canvas)
    with live.ctx:
        ids = live.path.id_image(live.size)
    assert (ids == 7).any()  # the inner cube is revealed
    drag(canvas, (80, 60), (90, 60))  # a drag is no click
    assert live.path.style.focus == 7
    settle(canvas)
    with live.ctx:
        ids = live.path.id_image(live.size)
    part = max(range(1, 7), key=lambda p: (ids == p).sum())  # the face showing most
    rows, cols = np.nonzero(ids == part)
    x, y = cols[len(cols) // 2] + 0.5, rows[len(rows) // 2] + 0.5
    azimuth = live.orbit.azimuth
    drag(canvas, (x, y), (x + 2, y))  # a click: under 3 pixels of travel, nothing turns
    assert live.orbit.azimuth == azimuth
    assert live.path.style.focus == part and viewer.controls["focus"].value == part
    refocused = canvas.get_frame()
    assert (refocused != revealed).any()


def test_a_click_on_another_path_picks_nothing(make_view):
    viewer = make_view(corner())
    drag(viewer.canvas, (40, 60), (40, 60))
    assert viewer.live.pick(40, 60) is None and viewer.controls == {}


def test_a_spacetime_scene_is_refused(make_view):
    with pytest.raises(ValueError, match="draws FE meshes"):
        make_view("spacetime:bar")


# ---------------------------------------------------------------------------- the facade
def test_workbench_view_is_lazy_and_the_package_imports_without_jupyter():
    script = (
        "import sys\n"
        "sys.modules['jupyter_rfb'] = None\n"  # an import of it raises ImportError
        "import workbench, workbench.viewer\n"
        "assert 'jupyter_rfb' not in sys.modules or sys.modules['jupyter_rfb'] is None\n"
        "assert 'ipywidgets' not in sys.modules\n"
        "assert workbench.view is workbench.viewer.view\n"
        "try:\n"
        "    workbench.view('semicylinders:4')\n"
        "except ImportError:\n"
        "    print('refused')\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "refused"
    import workbench

    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        workbench.nothing  # noqa: B018


# ---------------------------------------------------------------------------- the notebook
def test_the_saved_notebook_shows_a_frame():
    cells = json.loads(NOTEBOOK.read_text(encoding="utf-8"))["cells"]
    outputs = [o for c in cells if c["cell_type"] == "code" for o in c["outputs"]]
    assert any("image/png" in o.get("data", {}) for o in outputs)


def test_the_notebook_executes_and_shows_an_image(tmp_path):
    import nbclient
    import nbformat
    from jupyter_client.kernelspec import KernelSpecManager
    from jupyter_client.manager import AsyncKernelManager

    from workbench.gl import GLUnavailable, create_context

    try:
        create_context().release()
    except GLUnavailable as exc:
        pytest.skip(str(exc))
    # a kernel of this very interpreter, whatever kernels the machine has installed
    spec = tmp_path / "kernels" / "workbench-test"
    spec.mkdir(parents=True)
    spec.joinpath("kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "workbench (test)", "language": "python"}))
    km = AsyncKernelManager(kernel_name="workbench-test",
                            kernel_spec_manager=KernelSpecManager(kernel_dirs=[str(spec.parent)]))
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    nbclient.NotebookClient(notebook, km=km, timeout=300, store_widget_state=False,
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for c in notebook.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert images
    import base64
    import io

    from PIL import Image

    frame = np.asarray(Image.open(io.BytesIO(base64.b64decode(images[-1].data["image/png"]))))
    assert covered(frame[..., :3]).mean() > 0.05  # the scene, not an empty frame
    from workbench.data import CAR_DECK, shared_file

    said = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    shown = "car" if shared_file(CAR_DECK) is not None else "semicylinders:16"
    assert said.startswith(f"{shown}: ")



def test_the_live_view_hides_a_deleted_shell_at_its_state(ctx, tmp_path):
    """The notebook viewer's drawing side: at the state that deletes the triangle shell, its
    frame is the image of the live shell alone drawn with the viewer's camera, and covers
    fewer pixels than the state before."""
    from meshes import write_d3plot

    from workbench.paths import make_path, render
    from workbench.scene.readers import load
    from workbench.viewer.live import LiveView

    size = (64, 48)
    mesh = load(write_d3plot(tmp_path))
    live = mesh.subset(mesh.alive(2))
    live.element_fields.pop("alive")
    view = LiveView(mesh, "flat", size=size)
    try:
        view.set_step(1)
        before = view.frame()
        view.set_step(2)
        eroded, camera = view.frame(), view.camera()
    finally:
        view.release()
    with ctx:  # the viewer made its own context current
        alone = render(ctx, live, "flat", make_path("flat").style, camera, size, step=2)
    np.testing.assert_array_equal(eroded, alone[..., :3])
    covered = (eroded != 255).any(axis=-1).sum()
    assert 0 < covered < (before != 255).any(axis=-1).sum()



def test_the_viewer_states_the_state_and_shows_the_colour_bar(make_view, tmp_path):
    """The stamp above the canvas follows the step slider (time and deleted elements); the
    colour bar beside it is the scale drawn, as tall as the frame, and shows the no-result key
    with the rigid part where a part has no result."""
    import io

    import matplotlib
    from meshes import write_d3plot
    from PIL import Image

    from workbench.paths.colormap import NO_RESULT_COLOR, no_result_text
    from workbench.scene.readers import load

    for name in ("eroded", "rigid"):
        (tmp_path / name).mkdir()
    mesh = load(write_d3plot(tmp_path / "eroded"))
    viewer = make_view(mesh, field="von_mises", units="MPa", time_units="s")
    assert viewer.stamp.value == f"{mesh.name}, state 0, t = 0 s"
    viewer.controls["step"].value = 2
    assert viewer.stamp.value == f"{mesh.name}, state 2, t = 0.002 s, deleted: 1"
    bar = np.asarray(Image.open(io.BytesIO(viewer.bar.value)).convert("RGB"))
    assert bar.shape[0] == viewer.live.size[1] + 20  # the frame's height and its margins
    # the bar's middle column, top to bottom, runs through viridis from its top colour to its
    # bottom one (the ends within 8 % of the map: matplotlib resamples its 256 colours to the
    # bar's height; the two rows at each end are the bar's antialiased frame)
    column = bar[:, 12 + 9].astype(int)
    column = column[(column != 255).any(axis=-1) & (column != 0).any(axis=-1)][2:-2]  # frame
    lut = np.rint(matplotlib.colormaps["viridis"](np.arange(256))[:, :3] * 255)
    gap = np.abs(column[:, None] - lut[None]).max(axis=-1)
    index = gap.argmin(axis=1)
    assert gap.min(axis=1).max() <= 8 and len(column) > 50
    assert index[0] >= 235 and index[-1] <= 20 and (np.diff(index) <= 0).all()
    green = np.array(NO_RESULT_COLOR) * 255
    assert not (bar == green).all(axis=-1).any()  # every shell has a value
    assert make_view(plate()).bar.layout.display == "none"  # no field, no bar

    rigid = load(write_d3plot(tmp_path / "rigid", rigid=True))
    assert no_result_text(rigid, "von_mises") == "no result: 1 element, part 9"
    viewer = make_view(rigid, field="von_mises")
    bar = np.asarray(Image.open(io.BytesIO(viewer.bar.value)).convert("RGB"))
    assert (bar == green).all(axis=-1).sum() > 50
    assert viewer.live.stamp() == "state 0, t = 0"
