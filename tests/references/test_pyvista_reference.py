"""pyvista/VTK as a reference renderer: our camera, our lighting as far as VTK allows, our image.

The agreement bounds were measured on llvmpipe (semicylinders n=6, 576 triangles, 96×80, 4×
MSAA on both sides): SSIM 0.991 against our Gouraud image at 25°/15° and 0.995 at −60°/30°,
identical coverage; the asserts leave a margin below.
"""

import ctypes

import numpy as np
import pytest

from workbench.gl import Camera, Framebuffer
from workbench.gl.context import egl, keeping_current
from workbench.measurement.images import compare_drawn, coverage
from workbench.measurement.rows import measure
from workbench.paths import Style, make_path
from workbench.references.pyvista import PyvistaReference, versions
from workbench.scene import generators
from workbench.scene.mesh import FEMesh

WHITE = (1.0, 1.0, 1.0)
BASE = (0.9, 0.4, 0.1)
SSIM_BOUND = 0.97  # measured 0.991 and 0.995 (module notes)
COVERAGE_TOLERANCE = 0.02  # share of the covered pixels either side may cover alone


def gouraud_inputs(mesh: FEMesh):
    """(vertices, triangles, normals) of the crease-split Gouraud triangles of step 0."""
    split = mesh.gouraud(Style().crease_deg)
    coords = mesh.coordinates(0)
    return coords[split.vertex_node], split.triangles, split.normals(coords)


def our_gouraud(ctx, mesh, camera, size) -> np.ndarray:
    """(H, W, 3) uint8: our Gouraud path with 4× MSAA, untimed."""
    image = measure(ctx, mesh, make_path("gouraud", Style()), camera=camera, size=size,
                    samples=4, timed=False).image
    return image[..., :3]


def vtk_image(mesh, camera, size, **kwargs) -> np.ndarray:
    with PyvistaReference(*gouraud_inputs(mesh), camera, size,
                          base_color=Style().base_color, **kwargs) as reference:
        return reference.render()


def plate(corner_lo, corner_hi, n: int = 4, z: float = 0.0) -> FEMesh:
    """An n × n plate of quads in the plane z, wound counter-clockwise seen from +z."""
    x = np.linspace(corner_lo[0], corner_hi[0], n + 1)
    y = np.linspace(corner_lo[1], corner_hi[1], n + 1)
    nodes = np.array([[xi, yj, z] for yj in y for xi in x], np.float64)
    quads = [[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i] for j in range(n) for i in range(n)]
    return FEMesh(nodes=nodes, elements=np.array(quads, np.int32))


def current_context() -> int | None:
    return ctypes.cast(egl().eglGetCurrentContext(), ctypes.c_void_p).value


def test_vtk_camera_has_our_projection_and_view():
    from vtkmodules.vtkRenderingCore import vtkCamera

    def matrix(m):
        return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])

    for projection in ("orthographic", "perspective"):
        camera = Camera.fit([1.0, 2.0, 3.0], 2.0, azimuth=30, elevation=10, up="z",
                            projection=projection, aspect=1.5)
        theirs = vtkCamera()
        PyvistaReference.set_vtk_camera(theirs, camera)
        # the window's aspect (0.7 here) must not matter: ours is explicit
        assert np.allclose(matrix(theirs.GetProjectionTransformMatrix(0.7, -1, 1)),
                           camera.projection_matrix(), rtol=1e-9, atol=1e-12)
        assert np.allclose(matrix(theirs.GetModelViewTransformMatrix()), camera.view_matrix(),
                           rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("offset", [0.0, 1e6])
@pytest.mark.parametrize("azimuth, elevation", [(25.0, 15.0), (-60.0, 30.0)])
def test_vtk_agrees_with_our_gouraud_image(ctx, offset, azimuth, elevation):
    mesh = generators.semicylinders(n=6)  # 576 triangles
    mesh = mesh.translated([offset, -offset, 0.5 * offset])
    size = (96, 80)
    lo, hi = mesh.bounds()
    camera = Camera.fit_box(lo, hi, aspect=size[0] / size[1], azimuth=azimuth,
                            elevation=elevation)
    theirs = vtk_image(mesh, camera, size)
    assert theirs.shape == (80, 96, 3) and theirs.dtype == np.uint8
    ours = our_gouraud(ctx, mesh, camera, size)
    covered_ours, covered_theirs = coverage(ours, WHITE), coverage(theirs, WHITE)
    assert covered_ours.sum() > 0.3 * covered_ours.size
    alone = np.sum(covered_ours ^ covered_theirs)
    assert alone <= COVERAGE_TOLERANCE * np.sum(covered_ours | covered_theirs)
    assert compare_drawn(theirs, ours, background=WHITE).ssim >= SSIM_BOUND


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_an_off_centre_plate_far_from_the_origin_lands_where_ours_does(ctx, projection):
    offset = np.array([1e6, 1e6, -1e6])
    # a plate in the upper right of a view fitted to the box [-1, 1]³ around the offset
    mesh = plate(offset[:2] + [0.3, 0.2], offset[:2] + [0.9, 0.7], z=offset[2])
    size = (80, 64)
    camera = Camera.fit(offset, np.sqrt(3.0), aspect=size[0] / size[1], projection=projection,
                        fov_deg=40.0)
    theirs = coverage(vtk_image(mesh, camera, size), WHITE)
    rows, cols = np.nonzero(theirs)
    assert len(rows) > 20
    # upper right: a mirrored camera or an ignored origin puts it elsewhere (or nowhere)
    assert rows.mean() < size[1] / 2 < cols.mean()
    corners = mesh.nodes[[0, 4, 24, 20]]
    projected = camera.project(corners, size)
    # 4× multisampling: an edge pixel counts once one sample is covered, so within one pixel
    assert abs(cols.min() - projected[:, 0].min()) <= 1
    assert abs(cols.max() + 1 - projected[:, 0].max()) <= 1
    assert abs(rows.min() - projected[:, 1].min()) <= 1
    assert abs(rows.max() + 1 - projected[:, 1].max()) <= 1
    ours = coverage(our_gouraud(ctx, mesh, camera, size), WHITE)
    assert np.sum(ours ^ theirs) <= COVERAGE_TOLERANCE * np.sum(ours | theirs)


def lit_centre(normal, azimuth: float = 0.0) -> np.ndarray:
    """RGB at the centre of a plate (normal ``normal`` at every vertex) seen from ``azimuth``,
    drawn by VTK in BASE."""
    mesh = plate((-1.0, -1.0), (1.0, 1.0), n=2)
    split = mesh.gouraud(Style().crease_deg)
    coords = mesh.coordinates(0)
    normals = np.tile(np.asarray(normal, np.float64), (split.n_vertices, 1))
    camera = Camera.fit([0.0, 0.0, 0.0], 1.0, azimuth=azimuth)
    with PyvistaReference(coords[split.vertex_node], split.triangles, normals, camera, (32, 32),
                          base_color=BASE) as reference:
        return reference.render()[16, 16].astype(float)


def test_lighting_is_ambient_plus_diffuse_of_a_headlight():
    base = np.array(BASE) * 255
    # facing the light: the base colour; at 60° from it: 0.25 + 0.75 · 0.5 of it
    assert np.abs(lit_centre([0.0, 0.0, 1.0]) - base).max() <= 2
    tilted = [0.0, np.sin(np.radians(60)), np.cos(np.radians(60))]
    assert np.abs(lit_centre(tilted) - 0.625 * base).max() <= 2
    # seen from behind (back-facing triangles): VTK's two-sided lighting flips the normal, so
    # it lights the back as the front, as ours does
    assert np.abs(lit_centre([0.0, 0.0, 1.0], azimuth=180.0) - base).max() <= 2
    # where VTK differs: a front-facing triangle whose normals point away gets ambient only
    # (ours: |n·l| = 1, the base colour)
    assert np.abs(lit_centre([0.0, 0.0, -1.0]) - 0.25 * base).max() <= 2


def test_our_context_stays_current_and_draws_after_vtk(ctx):
    mesh = plate((-1.0, -1.0), (1.0, 1.0))
    size = (32, 32)
    camera = Camera.fit([0.0, 0.0, 0.0], 1.5, azimuth=20.0)
    path = make_path("gouraud", Style())
    path.prepare(ctx, mesh, camera)
    fb = Framebuffer(ctx, size)

    def draw() -> np.ndarray:
        fb.use()
        fb.clear()
        path.draw()
        return fb.read()

    before, ours = draw(), current_context()
    reference = PyvistaReference(*gouraud_inputs(mesh), camera, size)
    assert current_context() == ours
    reference.render()
    assert current_context() == ours
    assert np.array_equal(draw(), before)
    reference.release()
    assert current_context() == ours
    assert np.array_equal(draw(), before)
    path.release()
    fb.release()


def test_without_a_current_context_vtk_draws_on_the_device_and_leaves_none(ctx):
    EGL = egl()
    mesh = plate((-1.0, -1.0), (1.0, 1.0))
    camera = Camera.fit([0.0, 0.0, 0.0], 1.5)
    with keeping_current() as restore:
        restore.display = display = EGL.eglGetCurrentDisplay()
        EGL.eglMakeCurrent(display, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE, EGL.EGL_NO_CONTEXT)
        image = vtk_image(mesh, camera, (24, 24))
        assert not current_context()
    assert coverage(image, WHITE)[12, 12]


def test_timing_release_and_versions(ctx):
    mesh = plate((-1.0, -1.0), (1.0, 1.0))
    reference = PyvistaReference(*gouraud_inputs(mesh), Camera.fit([0.0, 0.0, 0.0], 1.5),
                                 (24, 24), samples=0)
    try:
        t = reference.time(warmup=1, repeat=5)
        assert reference.renderer_name and reference.version.startswith("VTK 9.")
    finally:
        reference.release()
    assert t.repeats == 5 and t.wall_ms_min <= t.wall_ms <= t.wall_ms_max and t.readback_ms > 0
    assert t.gpu_ms is None or t.gpu_ms_min <= t.gpu_ms <= t.gpu_ms_max
    with pytest.raises(RuntimeError, match="released"):
        reference.render()
    reference.release()  # twice is harmless
    assert versions() == reference.version


def test_pyvista_reference_refuses_bad_input():
    mesh = plate((-1.0, -1.0), (1.0, 1.0), n=1)
    vertices, triangles, normals = gouraud_inputs(mesh)
    camera = Camera.fit([0.0, 0.0, 0.0], 1.0)
    with pytest.raises(ValueError, match="indices"):
        PyvistaReference(vertices, [[0, 1, 4]], normals, camera, (8, 8))
    with pytest.raises(ValueError, match="zero length"):
        PyvistaReference(vertices, triangles, np.zeros_like(normals), camera, (8, 8))
    with pytest.raises(ValueError, match="size"):
        PyvistaReference(vertices, triangles, normals, camera, (0, 8))
    with pytest.raises(ValueError, match="samples"):
        PyvistaReference(vertices, triangles, normals, camera, (8, 8), samples=3)
    with pytest.raises(ValueError, match="finite"):
        PyvistaReference(vertices * np.nan, triangles, normals, camera, (8, 8))
