"""GL layer: context, framebuffer read-back, queries and the float64-origin camera."""

import moderngl
import numpy as np
import pytest

from workbench.gl import (
    Camera,
    Framebuffer,
    GpuTimer,
    SamplesPassed,
    create_context,
    renderer,
    write_masks,
)
from workbench.gl.context import describe, is_software_renderer, timer_queries_meaningful

VERT = """#version 330
uniform mat4 mvp;
in vec3 position;
void main() { gl_Position = mvp * vec4(position, 1.0); }
"""
FRAG = """#version 330
out vec4 color;
void main() { color = vec4(1.0, 0.0, 0.0, 1.0); }
"""


@pytest.fixture(scope="module")
def ctx():
    return create_context()


def draw_quad(ctx, camera, corners, size=(64, 48), samples=0, depth_bits=24, depth=None):
    """Draw the float64 quad ``corners`` (4, 3) in red on white; return the image and samples
    passed.

    ``depth``, a list, receives the depth image (single-sampled targets only).
    """
    fb = Framebuffer(ctx, size, samples=samples, depth_bits=depth_bits)
    assert fb.attachment_depth_bits() == depth_bits
    prog = ctx.program(vertex_shader=VERT, fragment_shader=FRAG)
    prog["mvp"].write(camera.mvp_bytes())
    vbo = ctx.buffer(camera.relative(corners)[[0, 1, 2, 0, 2, 3]].tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f", "position")])
    fb.clear()
    ctx.enable(ctx.DEPTH_TEST)
    with SamplesPassed(ctx) as occlusion:
        vao.render()
    image = fb.read()
    if depth is not None:
        depth.append(fb.read_depth())
    for obj in (vao, vbo, prog):
        obj.release()
    fb.release()
    return image, occlusion.samples


def red_mask(image):
    return (image[..., 0] == 255) & (image[..., 1] == 0)


def test_renderer_is_named(ctx):
    assert renderer(ctx)


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_quad_covers_known_pixel_rectangle(ctx, offset):
    # orthographic camera on a 2 x 2 view (radius 1, aspect 4:3 widens x): 64 x 48 pixels span
    # x in [-4/3, 4/3] and y in [-1, 1], so a pixel is 1/24 model units wide.
    o = np.array([offset, -offset, offset])
    cam = Camera.fit(o, 1.0, margin=1.0, aspect=64 / 48)
    corners = o + np.array([[-0.5, -0.25, 0], [0.5, -0.25, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]])
    image, samples = draw_quad(ctx, cam, corners)
    mask = red_mask(image)
    rows, cols = np.nonzero(mask)
    # x: [-0.5, 0.5] → pixels 32 ± 12; y: [-0.25, 0.5] → rows from 24 - 12 = 12 to 24 + 6 = 30
    assert (cols.min(), cols.max() + 1) == (20, 44)
    assert (rows.min(), rows.max() + 1) == (12, 30)
    assert mask.sum() == 24 * 18 == samples


def test_project_matches_rasterised_corners(ctx):
    cam = Camera.fit([3.0, 2.0, 1.0], 2.0, azimuth=30, elevation=20, projection="perspective",
                     aspect=1.0)
    pts = cam.project([[3.0, 2.0, 1.0]], (100, 100))
    assert np.allclose(pts[0, :2], [50, 50])
    assert 0.0 < pts[0, 2] < 1.0


def test_near_far_enclose_sphere_tightly():
    for projection in ("orthographic", "perspective"):
        cam = Camera.fit([0, 0, 0], 5.0, azimuth=45, elevation=30, projection=projection,
                         margin=1.0)
        dist = np.linalg.norm(cam.eye - cam.target)
        assert np.isclose(cam.far - dist, 5.0)
        assert cam.near > 0 and np.isclose(dist - cam.near, 5.0)


def test_view_angles_are_oriented():
    # azimuth 90 puts the eye on +X; elevation 90 puts it on +Y; roll 90 turns +Y up into -X up
    assert np.allclose(Camera.fit([0, 0, 0], 1, azimuth=90, margin=1).eye / 2, [1, 0, 0])
    assert np.allclose(Camera.fit([0, 0, 0], 1, elevation=90, margin=1).eye / 2, [0, 1, 0])
    up = Camera.fit([0, 0, 0], 1, roll=90).up
    assert np.allclose(up, [-1, 0, 0]) or np.allclose(up, [1, 0, 0])
    cam = Camera.fit([0, 0, 0], 1, roll=90)
    # a point on +X appears above the centre once the image is rolled counter-clockwise
    assert cam.project([[0.5, 0, 0]], (100, 100))[0, 1] < 50


def test_z_up_frame():
    cam = Camera.fit([0, 0, 0], 1, up="z", margin=1)
    assert np.allclose(cam.eye / 2, [0, -1, 0]) and np.allclose(cam.up, [0, 0, 1])
    # +Z appears above the centre, +X to the right
    top, right = cam.project([[0, 0, 0.5], [0.5, 0, 0]], (100, 100))
    assert top[1] < 50 and right[0] > 50
    assert np.allclose(Camera.fit([0, 0, 0], 1, up="z", elevation=90, margin=1).eye / 2, [0, 0, 1])


def test_fit_box_frames_a_long_box_tightly():
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([4000.0, 1000.0, 1500.0])
    size = (400, 200)
    cam = Camera.fit_box(lo, hi, azimuth=-30, elevation=20, up="z", aspect=2.0, margin=1.0)
    corners = np.array([[x, y, z] for x in (0, 4000) for y in (0, 1000) for z in (0, 1500)])
    px = cam.project(corners, size)
    # every corner inside the image, and the outline touches its left/right or top/bottom edges
    assert (px[:, 0] >= -1e-6).all() and (px[:, 0] <= 400 + 1e-6).all()
    assert (px[:, 1] >= -1e-6).all() and (px[:, 1] <= 200 + 1e-6).all()
    assert np.isclose(px[:, 0].min(), 0) or np.isclose(px[:, 1].min(), 0)
    sphere = Camera.fit((lo + hi) / 2, np.linalg.norm(hi - lo) / 2, azimuth=-30, elevation=20,
                        up="z", aspect=2.0, margin=1.0)
    assert cam.half_height < sphere.half_height and (cam.near, cam.far) == (sphere.near, sphere.far)


def test_far_origin_keeps_subpixel_precision(ctx):
    # with world-space float32 upload, 1e7 offsets lose ~1 unit; relative upload keeps the edge
    # exact
    o = np.array([1e7, 1e7, 0.0])
    cam = Camera.fit(o, 1.0, margin=1.0)
    corners = o + np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]])
    image, _ = draw_quad(ctx, cam, corners, size=(64, 64))
    assert red_mask(image).sum() == 32 * 32


def test_msaa_resolves_and_timer_reports(ctx):
    cam = Camera.fit([0, 0, 0], 1.0, margin=1.0)
    corners = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]])
    image, _ = draw_quad(ctx, cam, corners, size=(32, 32), samples=4)
    assert image.shape == (32, 32, 4) and red_mask(image).sum() == 16 * 16
    with GpuTimer(ctx) as timer:
        draw_quad(ctx, cam, corners)
    # a GPU reports a time; a software renderer's queries time nothing and report none
    if timer.meaningful:
        assert timer.elapsed_ms >= 0.0
    else:
        assert timer.elapsed_ms is None and is_software_renderer(renderer(ctx))


def test_every_shader_ships_with_the_package():
    from importlib import resources
    from pathlib import Path

    from workbench.gl.shaders import shader_source

    shipped = {p.name for p in resources.files("workbench.glsl").iterdir()
               if p.name.endswith(".glsl")}
    checkout = Path(__file__).resolve().parents[2] / "workbench" / "glsl"
    if checkout.is_dir():
        assert shipped == {p.name for p in checkout.glob("*.glsl")}
    assert shipped
    for name in shipped:
        assert shader_source(name).strip()


@pytest.mark.parametrize("samples", [0, 4])
def test_float_depth_framebuffer_draws_like_the_fixed_point_one(ctx, samples):
    cam = Camera.fit([0, 0, 0], 1.0, margin=1.0)
    corners = np.array([[-0.5, -0.5, 0.2], [0.5, -0.5, -0.2], [0.5, 0.5, -0.2], [-0.5, 0.5, 0.2]])
    images = {}
    for bits in (24, 32):
        depth = None if samples else []
        images[bits], _ = draw_quad(ctx, cam, corners, (48, 48), samples, bits, depth)
        if depth:
            # the tilted quad's depth varies across it; the far background stays 1
            inside = red_mask(images[bits])
            assert (depth[0][~inside] == 1.0).all() and np.ptp(depth[0][inside]) > 0.01
    assert red_mask(images[24]).sum() == red_mask(images[32]).sum() == 24 * 24
    with pytest.raises(ValueError):
        Framebuffer(ctx, (8, 8), depth_bits=16)


def test_releasing_a_bound_framebuffer_leaves_no_gl_error(ctx):
    _ = ctx.error  # reading the error flag clears it
    for bits in (24, 32):
        fb = Framebuffer(ctx, (16, 16), depth_bits=bits)
        fb.clear()
        fb.release()
        Framebuffer(ctx, (16, 16)).release()
        assert ctx.error == "GL_NO_ERROR"


def test_write_masks_stop_colour_and_depth_writes_and_restore_them(ctx):
    prog = ctx.program(
        vertex_shader="#version 330\nin vec2 p; uniform float z;\n"
                      "void main() { gl_Position = vec4(p, z, 1.0); }",
        fragment_shader="#version 330\nuniform vec3 col; out vec4 c;\n"
                        "void main() { c = vec4(col, 1.0); }")
    vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], "f4").tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "2f", "p")])
    fb = Framebuffer(ctx, (8, 6))
    fb.clear()
    ctx.viewport = (0, 0, 4, 3)  # a sub-viewport survives the masks

    def fill(z, col):
        prog["z"].value, prog["col"].value = z, col
        vao.render()

    ctx.enable_only(moderngl.DEPTH_TEST)
    with write_masks(ctx, color=False, depth=True):
        fill(0.0, (1.0, 0.0, 0.0))  # depth 0.5 written, no colour
        assert ctx.viewport == (0, 0, 4, 3)
    assert (fb.read()[..., :3] == 255).all()
    fill(0.5, (0.0, 1.0, 0.0))  # behind the invisible quad: fails the depth test
    assert (fb.read()[..., :3] == 255).all()
    with write_masks(ctx, color=True, depth=False):
        fill(-0.5, (0.0, 0.0, 1.0))  # in front: drawn, its depth not kept
    fill(-0.25, (1.0, 0.0, 0.0))  # between: passes because the blue quad left no depth
    image = fb.read()
    assert (image[-3:, :4, :3] == (255, 0, 0)).all()  # row 0 at the top: the viewport's rows
    assert (image[:3, :, :3] == 255).all() and (image[:, 4:, :3] == 255).all()
    assert fb.fbo.color_mask == (True,) * 4 and fb.fbo.depth_mask
    fb.release()


@pytest.mark.parametrize("name, software", [
    ("llvmpipe (LLVM 15.0.6, 256 bits)", True), ("softpipe", True),
    ("Mesa Intel(R) UHD Graphics 630 (CFL GT2)", False), ("NVIDIA H200/PCIe/SSE2", False),
    ("AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 17.0.6, DRM 3.54, 6.5.0)", False),
    ("Google SwiftShader", True), ("lavapipe", True)])
def test_software_renderers_are_told_from_gpus(name, software):
    assert is_software_renderer(name) is software


def test_context_description_names_renderer_driver_and_device(ctx):
    info = describe(ctx)
    assert info["renderer"] == renderer(ctx) and info["gl_version"] == ctx.info["GL_VERSION"]
    assert info["gl_vendor"] == ctx.info["GL_VENDOR"]
    if "Mesa" in info["gl_version"]:
        assert info["driver"].startswith("Mesa ") and info["driver"] in info["gl_version"]
    # Mesa's EGL exposes EGL_EXT_device_query: the device is named by its identity
    from workbench.gl.devices import egl_devices

    if "Mesa" in info["gl_version"]:
        assert info["egl_device"] in {d.identity for d in egl_devices()}
    assert timer_queries_meaningful(ctx) is not is_software_renderer(info["renderer"])
