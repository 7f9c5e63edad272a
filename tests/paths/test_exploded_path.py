"""The exploded-view path (ghost2013) on a generated box of six panels around a small inner box:
occlusion counts, reveal, picking after the explosion, the animation, the CLI and refusals."""

import numpy as np
import pytest
from meshes import write_keyword_deck
from PIL import Image

from workbench.algo.explode import cull_back_faces
from workbench.cli import main
from workbench.gl import Framebuffer
from workbench.measurement.rows import default_camera
from workbench.paths import make_path
from workbench.paths.exploded import NO_PART, ExplodeStyle, exploded_camera
from workbench.scene.generators import box_in_box
from workbench.scene.mesh import FEMesh

SIZE = (240, 160)  # wider than the box: room beside it for the moved halves
FOCUS = 7


def box_scene() -> FEMesh:
    """Panels 1..6 of the cube [−1, 1]³ and part 7, the cube [−0.2, 0.2]³ inside."""
    return box_in_box(1.0, 0.2)


@pytest.fixture(scope="module")
def mesh():
    return box_scene()


@pytest.fixture
def prepared(ctx, mesh):
    """The path on the box seen along +y (from the −y side), split by the x plane."""
    camera = default_camera(mesh, SIZE, view=(0.0, 0.0))
    path = make_path("exploded", focus=FOCUS, plane="x")
    path.prepare(ctx, mesh, camera)
    fb = Framebuffer(ctx, SIZE)
    fb.use()
    yield path, fb, camera
    fb.release()
    path.release()


def _draw(path, fb, draw=None):
    fb.clear()
    (draw or path.draw)()
    return fb.read()


def _orange(image):
    """Pixels in the focus colour (orange: red well above blue) against the grey panels."""
    return int(((image[..., 0].astype(int) - image[..., 2]) > 30).sum())


def test_hidden_at_zero_revealed_at_large_offset(prepared):
    path, fb, _ = prepared
    assert path.front_side() == 1 or path.front_side() == -1
    p_unocc, p_occ, _ = path.measure_occlusion()
    assert p_unocc > 500 and p_occ == 0
    assert path.occlusion_ratio() > 0.99
    path.set_offset(1.5)
    p_unocc, p_occ, _ = path.measure_occlusion()
    assert (p_unocc - p_occ) / p_unocc <= 0.01
    # part of the way: partly revealed
    path.set_offset(0.1)
    assert 0.05 < path.occlusion_ratio() < 0.95


@pytest.mark.parametrize("offset", [0.0, 0.1, 0.15, 1.5])
def test_occlusion_counts_match_pixel_counts(prepared, offset):
    path, fb, _ = prepared
    path.set_offset(offset)
    p_unocc, p_occ, _ = path.measure_occlusion()
    assert p_unocc == _orange(_draw(path, fb, path.draw_focus))
    assert p_occ == _orange(_draw(path, fb))
    assert p_occ == int((path.id_image() == FOCUS).sum())


def test_pick_after_explosion(prepared, mesh):
    path, fb, camera = prepared
    centre = camera.project(np.array([[0.0, -1.0, 0.0]]), SIZE)[0]
    cx, cy = int(centre[0]), int(centre[1])
    beyond = camera.project(np.array([[1.4, -1.0, 0.0]]), SIZE)[0]  # right of the box
    bx, by = int(beyond[0]), int(beyond[1])
    assert path.pick(cx, cy) == 3  # the front panel (y−) hides the focus
    assert path.pick(bx, by) is None  # nothing drawn right of the box yet
    path.set_offset(1.0)
    assert path.pick(cx, cy) == FOCUS
    # the + half of the front panel now covers x in [1, 2]: picked where it lies
    assert path.pick(bx, by) == 3
    # and where the image shows it (the colour image is not empty there)
    image = _draw(path, fb)
    assert (image[by, bx, :3] < 250).any()
    ids = path.id_image()
    assert ids[by, bx] == 3 and ids[cy, cx] == FOCUS and ids[2, 2] == NO_PART


def test_animation_reveals_within_30_frames_and_holds(prepared):
    path, fb, camera = prepared
    o_max = path.settings.o_max
    ratios, offsets, in_frame = [], [], []
    for _ in range(30):
        _draw(path, fb)  # counts the focus as it draws
        ratios.append(path.step_animation())
        in_frame.append(path.last_occlusion["in_frame"])
        offsets.append(path.offset)
    assert all(in_frame)
    assert ratios[0] > 0.99  # hidden at the start
    assert max(offsets) <= o_max and min(offsets) > 0
    assert (np.diff(offsets) >= 0).all()  # monotone
    assert min(ratios[1:]) <= 0.01
    # halted once revealed: the offset stays and the focus stays fully visible
    assert path.state.phase == "hold" and offsets[-1] == offsets[-2]
    assert path.occlusion_ratio() == 0.0
    assert path.state.frame == 30
    path.set_camera(camera)  # a new view releases the hold
    assert path.state.phase == "collapse" and path.offset == offsets[-1]


# the eye on the split plane, well on its + side, and nearly along the normal on its − side
# (where the ghosted front half's culled back faces lie between the eye and the focus)
VIEWS = [(0.0, 0.0), (30.0, 10.0), (-85.0, 0.0)]


@pytest.mark.parametrize("view", VIEWS)
@pytest.mark.parametrize("offset, alpha", [(0.0, 1.0), (0.1, 1.0), (0.15, 0.6), (1.5, 0.5),
                                           (3.0, 0.52)])
def test_in_frame_count_equals_the_separate_pass(prepared, mesh, view, offset, alpha):
    path, fb, _ = prepared
    path.set_camera(exploded_camera(default_camera(mesh, SIZE, view=view), mesh))
    path.set_offset(offset, alpha)
    expected = path.measure_occlusion()[:2]
    path.count_in_draw = False
    plain = _draw(path, fb)
    path.count_in_draw = True
    counted = _draw(path, fb)
    assert (counted == plain).all()  # counting writes no colour
    path.step_animation()
    assert path.last_occlusion["in_frame"]
    assert (path.last_occlusion["p_unocc"], path.last_occlusion["p_occ"]) == expected


@pytest.mark.parametrize("offset", [0.1, 0.3])
def test_in_frame_count_restores_culled_back_faces(ctx, mesh, offset):
    # panels wound inwards: from the (30, 10) view the ghosted front half shows the camera its
    # back faces, which it culls; the count must still see them as the separate pass does
    # (without their depth it counts all 944 pixels of the focus as visible, not 0 and 50)
    inward = FEMesh(mesh.nodes, mesh.elements[:, ::-1], mesh.parts, name="inward box")
    camera = default_camera(inward, SIZE, view=VIEWS[1])
    path = make_path("exploded", focus=FOCUS, plane="x")
    fb = Framebuffer(ctx, SIZE)
    try:
        path.prepare(ctx, inward, camera)
        fb.use()
        path.set_offset(offset, 0.5)
        assert cull_back_faces(path.plane, path.offset, path.eye, path.front_side())
        expected = path.measure_occlusion()[:2]
        _draw(path, fb)
        path.step_animation()
        assert path.last_occlusion["in_frame"]
        assert (path.last_occlusion["p_unocc"], path.last_occlusion["p_occ"]) == expected
    finally:
        fb.release()
        path.release()


def test_stale_or_multisampled_frames_use_the_separate_pass(ctx, prepared, mesh):
    path, fb, _ = prepared
    path.set_offset(0.1)
    _draw(path, fb)
    path.set_offset(0.12)  # drawn at another offset: the frame's count is not used
    expected = path.measure_occlusion()[:2]
    path.step_animation()
    assert not path.last_occlusion["in_frame"]
    assert (path.last_occlusion["p_unocc"], path.last_occlusion["p_occ"]) == expected
    msaa = Framebuffer(ctx, SIZE, samples=4)
    try:
        msaa.use()
        path.set_offset(0.1)
        expected = path.measure_occlusion()[:2]
        msaa.clear()
        path.draw()
        path.step_animation()
        assert not path.last_occlusion["in_frame"]
        assert (path.last_occlusion["p_unocc"], path.last_occlusion["p_occ"]) == expected
    finally:
        msaa.release()
        fb.use()


def test_ghosted_front_half_is_translucent(prepared):
    path, fb, _ = prepared
    path.set_offset(0.05)
    opaque = _draw(path, fb)
    path.set_offset(0.05, alpha=0.5)
    ghost = _draw(path, fb)
    # the focus shows through the translucent front half (the + half: the eye lies on the
    # plane, a tie that front_sign gives to +1), not through the opaque back half
    assert path.front_side() == 1
    assert _orange(ghost) > _orange(opaque) + 50
    assert (ghost[:, : SIZE[0] // 2 - 20] == opaque[:, : SIZE[0] // 2 - 20]).all()


def test_cli_writes_gif(ctx, mesh, tmp_path, capsys):
    deck = tmp_path / "box.k"
    write_keyword_deck(mesh, deck)
    out = tmp_path / "out.gif"
    status = main(["explode", str(deck), "--focus", "7", "--view", "0,0", "--plane", "x",
                   "--frames", "12", "--size", "96x80", "-o", str(out)])
    assert status == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 12 and gif.size == (96, 80)
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[-1].startswith("revealed at frame ") and " of 12: " in lines[-1]
    assert lines[-1].endswith("of o_max 3.46")
    visible, _, total = lines[-1].split("(")[1].split(")")[0].split()
    assert 0.8 <= int(visible) / int(total) <= 1.0
    strip = tmp_path / "strip.png"
    assert main(["explode", str(deck), "--focus", "7", "--frames", "3", "--size", "40x30",
                 "-o", str(strip)]) == 0
    with Image.open(strip) as png:
        assert png.size == (120, 30)


def test_cli_refuses_missing_part(ctx, mesh, tmp_path, capsys):
    deck = tmp_path / "box.k"
    write_keyword_deck(mesh, deck)
    status = main(["explode", str(deck), "--focus", "9", "-o", str(tmp_path / "x.gif")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "no part 9" in err[0] and "[1, 2, 3, 4, 5, 6, 7]" in err[0]
    assert not (tmp_path / "x.gif").exists()
    status = main(["explode", str(deck), "--focus", "7", "--ratio-exponent", "2",
                   "-o", str(tmp_path / "x.gif")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "ratio_exponent must be in (0, 1]" in err[0]
    assert not (tmp_path / "x.gif").exists()


def test_refusals(ctx, mesh):
    camera = default_camera(mesh, SIZE)
    with pytest.raises(ValueError, match=r"no part 9; part ids: \[1, 2, 3, 4, 5, 6, 7\]"):
        make_path("exploded", focus=9).prepare(ctx, mesh, camera)
    with pytest.raises(ValueError, match="empty focus"):
        make_path("exploded").prepare(ctx, mesh, camera)
    inner = mesh.part(FOCUS)
    with pytest.raises(ValueError, match="whole"):
        make_path("exploded", focus=FOCUS).prepare(ctx, inner, default_camera(inner, SIZE))
    for bad in ("w", "0,0,0", "1,2", "nan,1,0"):
        with pytest.raises(ValueError, match="plane must be"):
            ExplodeStyle(focus=FOCUS, plane=bad)
    assert ExplodeStyle(focus=FOCUS, plane=" 1, 0 ,0").plane == "1,0,0"
    for bad in (0.0, 1.5, float("nan")):
        with pytest.raises(ValueError, match="ratio_exponent"):
            ExplodeStyle(focus=FOCUS, ratio_exponent=bad)


def test_automatic_plane_follows_the_camera(ctx, mesh):
    """The automatic plane is chosen again when the view changes; a manual one stays."""
    from workbench.measurement.rows import default_camera
    from workbench.paths import make_path

    views = [(0.0, 0.0), (90.0, 0.0)]
    cameras = [default_camera(mesh, (96, 80), view=v, up="y") for v in views]
    auto = make_path("exploded", focus=7, plane="auto")
    manual = make_path("exploded", focus=7, plane="x")
    normals = {}
    for path in (auto, manual):
        path.prepare(ctx, mesh, cameras[0])
        first = path.normal.copy()
        path.set_camera(cameras[1])
        normals[path.style.plane] = (first, path.normal.copy())
        for camera in cameras:
            view = np.asarray(camera.target) - np.asarray(camera.eye)
            view /= np.linalg.norm(view)
            if path is auto:
                path.set_camera(camera)
                # never within the rejection angle of the view it was chosen for
                assert abs(float(path.normal @ view)) < np.cos(np.radians(20.0))
        path.release()
    assert not np.allclose(np.abs(normals["auto"][0]), np.abs(normals["auto"][1]))
    assert np.array_equal(normals["x"][0], normals["x"][1])
