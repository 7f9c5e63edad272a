"""Render paths against analytic pixel answers on small orthographic scenes.

Every scene is seen by ``Camera.fit(centre, 1, margin=1)``: looking down −Z with +Y up, the
view spans ±1 model unit around the centre, so in an S×S image one pixel is 2/S units wide and
pixel (i, j) has its centre at x = (j + ½)·2/S − 1, y = 1 − (i + ½)·2/S relative to the centre.
A surface facing the camera has |n·l| = 1, so its lit colour equals its unlit colour.
"""

import moderngl
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.gl import Camera, Framebuffer
from workbench.measurement.rows import measure
from workbench.paths import PATHS, ColorScale, MeshPath, Style, colormap_lut, make_path, scale_for
from workbench.paths.colormap import NO_RESULT_COLOR
from workbench.paths.fields import provoking_vertices
from workbench.scene.mesh import FEMesh

SIZE = 64
BACKGROUND = np.array([255, 255, 255, 255], np.uint8)
FIELD_PATHS = {"vertex_color": "x", "pixel_color": "x", "element_color": "cell"}
# quad_wire draws its own wire frame in the fill pass and refuses the line-overdraw one
LINE_WIRE = {name: name != "quad_wire" for name in PATHS}
# the paths that draw any FE mesh directly (the fe2003 texture paths draw a preprocessed surface
# of one configuration and are tested in test_fetexture_paths)
# the mesh paths that take a plain Style (flange fixes its field: tests/paths/test_flange.py)
MESH_PATHS = sorted(name for name, cls in PATHS.items()
                    if issubclass(cls, MeshPath) and cls.style_class is Style)


def grid(nx=1, ny=1, x0=-0.5, x1=0.5, y0=-0.5, y1=0.5, offset=(0.0, 0.0, 0.0), z=None):
    """An nx × ny quad grid in the plane z = 0 (or z = z(x, y)), with fields x, xy and cell."""
    nodes, quads = quad_grid(nx, ny, span=((x0, x1), (y0, y1)), z=z)
    return FEMesh(nodes + np.asarray(offset, np.float64), quads,
                  node_fields={"x": nodes[:, 0], "xy": nodes[:, 0] + 0.5 * nodes[:, 1]},
                  element_fields={"cell": np.arange(len(quads), dtype=np.float64)})


def camera(centre=(0.0, 0.0, 0.0), **kw):
    return Camera.fit(np.asarray(centre, np.float64), 1.0, margin=1.0, **kw)


def render(ctx, name, mesh, cam, size=SIZE, **style):
    """(image, path) of one path drawn once on white, untimed; the path is released."""
    m = measure(ctx, mesh, name, Style(**style), camera=cam, size=(size, size), timed=False)
    return m.image, m.path


def covered(image):
    return (image != BACKGROUND).any(axis=-1)


def pixel_centres(size=SIZE, centre=(0.0, 0.0)):
    """(size, size) world x and y of the pixel centres (row 0 at the top)."""
    c = (np.arange(size) + 0.5) * 2.0 / size - 1.0
    return np.meshgrid(c + centre[0], -c + centre[1])


def colors(image, mask):
    return {tuple(c) for c in image[mask][:, :3].tolist()}


# --------------------------------------------------------------------------- registry, errors
def test_registry_and_bad_names():
    assert set(PATHS) == {"position", "flat", "gouraud", "vertex_color", "pixel_color",
                          "element_color", "quad_wire", "fe_wire_texture", "fe_normal_map",
                          "fe_normal_wire", "spacetime_vertex", "spacetime_pixel", "flange",
                          "exploded"}
    assert MESH_PATHS == sorted(set(PATHS) - {"fe_wire_texture", "fe_normal_map",
                                              "fe_normal_wire", "spacetime_vertex",
                                              "spacetime_pixel", "flange", "exploded"})
    with pytest.raises(ValueError, match="known paths"):
        make_path("phong")
    for cls in PATHS.values():
        assert cls.needs <= {"triangles", "edges", "gouraud", "fepatch", "part_distances"}
    assert "edges" in make_path("flat", Style(wireframe=True)).needs
    assert "edges" not in make_path("flat").needs
    assert make_path("position").needs == {"triangles"}


def test_field_errors(ctx):
    mesh, cam = grid(), camera()
    with pytest.raises(KeyError, match="xy"):  # the message lists the mesh's fields
        make_path("pixel_color", Style(field="stress")).prepare(ctx, mesh, cam)
    with pytest.raises(ValueError, match="element_color"):
        make_path("pixel_color", Style(field="cell")).prepare(ctx, mesh, cam)
    with pytest.raises(ValueError, match="pixel_color"):
        make_path("element_color", Style(field="x")).prepare(ctx, mesh, cam)
    with pytest.raises(ValueError, match="Style.field"):
        make_path("vertex_color").prepare(ctx, mesh, cam)
    with pytest.raises(ValueError, match="clip planes"):
        Style(clip_planes=[(0, 0, 0, 1)])
    with pytest.raises(ValueError, match="colormap"):
        ColorScale("no-such-map")
    path = make_path("flat")
    path.prepare(ctx, mesh, cam)
    with pytest.raises(ValueError, match="out of range"):
        path.set_step(1)
    with pytest.raises(ValueError, match="origin"):
        path.set_camera(camera(centre=(0.1, 0.0, 0.0)))
    path.release()


# --------------------------------------------------------------------------- colormap on the CPU
def test_colorscale_matches_its_texture():
    scale = ColorScale("viridis", (-2.0, 6.0))
    lut = colormap_lut("viridis")
    # texel centres: value lo + i/255·range gives entry i exactly; the ends clamp
    i = np.array([0, 1, 100, 254, 255])
    assert np.allclose(scale.evaluate(-2.0 + 8.0 * i / 255) * 255, lut[i])
    assert np.allclose(scale.evaluate([-10.0, 60.0]) * 255, lut[[0, 255]])
    # halfway between two texels: their mean
    assert np.allclose(scale.evaluate(-2.0 + 8.0 * 10.5 / 255) * 255,
                       (lut[10] + lut[11].astype(float)) / 2)
    bands = ColorScale("viridis", (0.0, 1.0), bands=4)
    got = bands.evaluate(np.linspace(0, 1, 400)) * 255
    assert len(np.unique(got, axis=0)) == 4
    assert np.allclose(got[0], lut[0]) and np.allclose(got[-1], lut[255])
    hidden = ColorScale("viridis", (0.0, 1.0), hide_range=(0.25, 0.5))
    vis = hidden.visible(np.array([0.1, 0.3, 0.45, 0.6]))
    assert vis.tolist() == [True, False, False, True]


def test_scale_for_defaults_to_field_range():
    mesh = grid()
    assert scale_for(mesh, "x").value_range == (-0.5, 0.5)
    mesh.node_fields["flat"] = np.full(mesh.n_nodes, 3.0)
    assert scale_for(mesh, "flat").value_range == (3.0, 4.0)


# --------------------------------------------------------------------------- coverage
@pytest.mark.parametrize("name", MESH_PATHS)
def test_quad_covers_known_pixels_only(ctx, name):
    # the quad [-0.5, 0.5]² covers pixels 16..47 in rows and columns; nothing else is touched
    image, path = render(ctx, name, grid(), camera(), field=FIELD_PATHS.get(name))
    mask = covered(image)
    rows, cols = np.nonzero(mask)
    assert (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1) == (16, 48, 16, 48)
    assert mask.sum() == 32 * 32
    assert path.triangles == 2 and path.vertices == 4


@pytest.mark.parametrize("name", ["position", "flat", "gouraud"])
def test_uncoloured_quad_facing_camera_has_base_colour(ctx, name):
    base = (0.2, 0.6, 0.4)
    image, _ = render(ctx, name, grid(), camera(), base_color=base)
    got = image[covered(image)][:, :3].astype(float)
    assert np.abs(got - np.array(base) * 255).max() <= 1.0


# --------------------------------------------------------------------------- colour
def test_pixel_color_matches_cpu_colormap_per_pixel(ctx):
    mesh = grid()
    image, _ = render(ctx, "pixel_color", mesh, camera(), field="xy", colormap="plasma")
    x, y = pixel_centres()
    mask = covered(image)
    expected = scale_for(mesh, "xy", "plasma").evaluate(x + 0.5 * y)[..., :3] * 255
    err = np.abs(image[..., :3].astype(float) - expected)[mask]
    assert err.max() <= 1.0


def test_vertex_color_interpolates_vertex_colours(ctx):
    # field x: vertex colours are those of x = ±0.5; between them vertex_color interpolates RGB
    # linearly in x, while pixel_color follows the (nonlinear) colormap
    mesh, cam = grid(), camera()
    vertex, _ = render(ctx, "vertex_color", mesh, cam, field="x")
    pixel, _ = render(ctx, "pixel_color", mesh, cam, field="x")
    mask = covered(vertex)
    x, _ = pixel_centres()
    scale = scale_for(mesh, "x")
    c0, c1 = scale.evaluate(-0.5)[:3] * 255, scale.evaluate(0.5)[:3] * 255
    w = (x + 0.5)[..., None]
    expected = c0 + w * (c1 - c0)
    assert np.abs(vertex[..., :3].astype(float) - expected)[mask].max() <= 1.0
    # (so at the vertices, w = 0 and 1, it takes exactly the colormap colours of their values)
    diff = np.abs(vertex.astype(int) - pixel.astype(int))[mask]
    assert diff.max() > 3


def test_bands_give_band_count_colours(ctx):
    mesh = grid()
    image, _ = render(ctx, "pixel_color", mesh, camera(), field="xy", bands=5)
    mask = covered(image)
    assert len(colors(image, mask)) == 5
    x, y = pixel_centres()
    scale = scale_for(mesh, "xy", bands=5)
    t = scale.normalise(x + 0.5 * y)
    clear = np.abs(t * 5 - np.rint(t * 5)) > 1e-3  # not on a band boundary
    expected = scale.evaluate(x + 0.5 * y)[..., :3] * 255
    assert np.abs(image[..., :3].astype(float) - expected)[mask & clear].max() <= 1.0


@pytest.mark.parametrize("name", ["pixel_color", "vertex_color"])
def test_hide_range_discards_by_alpha_test(ctx, name):
    # field x on 8 × 1 elements (vertex columns every 1/8), values in [-0.1, 0.2] hidden
    mesh = grid(8, 1)
    scale = scale_for(mesh, "x", hide_range=(-0.1, 0.2))
    image, _ = render(ctx, name, mesh, camera(), field="x", hide_range=(-0.1, 0.2))
    x = pixel_centres()[0][32]
    inside = np.abs(x) <= 0.5
    drawn = covered(image)[32]  # one row through the quad
    if name == "pixel_color":  # per pixel: the texture's α at the pixel's value
        alpha = scale.evaluate(x)[:, 3]
        assert not drawn[(x > -0.09) & (x < 0.19)].any()
    else:  # per vertex: α of the vertex values, interpolated (vertices at 0 and 1/8 hidden)
        xs = np.linspace(-0.5, 0.5, 9)
        alpha = np.interp(x, xs, scale.evaluate(xs)[:, 3])
        assert not drawn[(x > -0.05) & (x < 0.17)].any()
    sure = inside & (np.abs(alpha - 0.5) > 0.02)
    assert (drawn[sure] == (alpha[sure] >= 0.5)).all()
    assert drawn[inside & (x < -0.2)].all() and drawn[inside & (x > 0.3)].all()


def test_element_color_one_colour_per_element(ctx):
    # 2 × 2 elements with values 0..3: each element's 16 × 16 pixel block has its own colour
    mesh = grid(2, 2)
    image, path = render(ctx, "element_color", mesh, camera(), field="cell")
    scale = scale_for(mesh, "cell")
    for e, (r, c) in enumerate([(1, 0), (1, 1), (0, 0), (0, 1)]):  # element rows go up in y
        block = image[16 + 16 * r: 32 + 16 * r, 16 + 16 * c: 32 + 16 * c, :3].reshape(-1, 3)
        expected = scale.evaluate(float(e))[:3] * 255
        assert np.abs(block - expected).max() <= 1.0
    assert path.vertices == 9 and path.triangles == 8


def test_element_color_with_more_elements_than_nodes(ctx):
    # 4 × 4 quads given as 32 triangle elements over 25 nodes: duplicated provoking vertices
    quads = grid(4, 4)
    e = quads.elements
    tris = np.concatenate([e[:, [0, 1, 2, 2]], e[:, [0, 2, 3, 3]]])
    values = np.arange(len(tris), dtype=np.float64)[::-1].copy()
    mesh = FEMesh(quads.nodes, tris, element_fields={"v": values})
    image, path = render(ctx, "element_color", mesh, camera(), field="v")
    assert path.vertices > mesh.n_nodes and path.triangles == 32
    scale = scale_for(mesh, "v")
    x, y = pixel_centres()
    for k, t in enumerate(tris[:, :3]):
        a, b, c = mesh.nodes[t, :2]
        # pixels at least one pixel inside the triangle (barycentric margin)
        m = np.linalg.inv(np.array([[b[0] - a[0], c[0] - a[0]], [b[1] - a[1], c[1] - a[1]]]))
        u = m[0, 0] * (x - a[0]) + m[0, 1] * (y - a[1])
        v = m[1, 0] * (x - a[0]) + m[1, 1] * (y - a[1])
        inside = (u > 0.15) & (v > 0.15) & (1 - u - v > 0.15)
        assert inside.sum() >= 3
        expected = scale.evaluate(values[k])[:3] * 255
        assert np.abs(image[inside][:, :3] - expected).max() <= 1.0, k


def test_element_color_hides_elements_in_range(ctx):
    mesh = grid(2, 1)
    image, _ = render(ctx, "element_color", mesh, camera(), field="cell", hide_range=(0.5, 2.0))
    mask = covered(image)
    # element 0 (left, value 0) stays, element 1 (right, value 1) is hidden
    assert mask[:, 16:32].sum() == 16 * 32 and not mask[:, 32:].any()


@st.composite
def element_meshes(draw):
    """Small random shell meshes: quads and triangles over a few nodes (shared a lot)."""
    n = draw(st.integers(4, 12))
    m = draw(st.integers(1, 25))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    elements = []
    for _ in range(m):
        corners = rng.choice(n, size=4, replace=False)
        if rng.random() < 0.3:
            corners[3] = corners[2]
        elements.append(corners)
    return FEMesh(rng.random((n, 3)), np.array(elements))


@settings(max_examples=60, deadline=None)
@given(element_meshes())
def test_provoking_vertices_give_each_element_its_own(mesh):
    tri, el = mesh.triangles, mesh.triangulation.element_of
    vertex_node, out, provoking = provoking_vertices(tri, el, mesh.n_nodes, mesh.n_elements)
    # the same triangles, cyclically rotated (winding kept), duplicates standing for their node
    nodes = vertex_node[out]
    assert all(any((np.roll(a, r) == b).all() for r in range(3)) for a, b in zip(nodes, tri))
    # every element's triangles end in its provoking vertex, and no two elements share one
    assert (out[:, 2] == provoking[el]).all()
    drawn = np.unique(el)
    assert (provoking[drawn] >= 0).all() and len(np.unique(provoking[drawn])) == len(drawn)
    assert (vertex_node[: mesh.n_nodes] == np.arange(mesh.n_nodes)).all()
    # as few duplicates as possible: elements minus a maximum matching found by Kuhn's
    # augmenting paths over the nodes all of an element's triangles share
    shared = {e: set.intersection(*(set(t) for t in tri[el == e].tolist())) for e in drawn}
    match: dict[int, int] = {}

    def augment(e, seen):
        for v in shared[e]:
            if v not in seen:
                seen.add(v)
                if v not in match or augment(match[v], seen):
                    match[v] = e
                    return True
        return False

    matched = sum(augment(e, set()) for e in drawn)
    assert len(vertex_node) - mesh.n_nodes == len(drawn) - matched


def test_provoking_vertices_need_no_duplicate_on_a_grid():
    mesh = grid(7, 5)
    vertex_node, _, _ = provoking_vertices(mesh.triangles, mesh.triangulation.element_of,
                                           mesh.n_nodes, mesh.n_elements)
    assert len(vertex_node) == mesh.n_nodes


# --------------------------------------------------------------------------- lighting
def folded_pair():
    """Two quads meeting at a 90° ridge along the y axis, the ridge towards the camera."""
    c, h = 0.45, 0.45
    nodes = np.array([[0, -h, 0], [0, h, 0], [-c, h, -c], [-c, -h, -c],
                      [c, -h, -c], [c, h, -c]], np.float64)
    return FEMesh(nodes, np.array([[0, 1, 2, 3], [0, 4, 5, 1]]))


def test_flat_and_gouraud_on_a_fold(ctx):
    mesh = folded_pair()
    cam = camera(azimuth=20.0)
    base = np.array((0.75, 0.75, 0.78))
    # |n·l| of the two faces for an eye 20° towards +x: cos 65° (left) and cos 25° (right)
    face = {f: base * (0.25 + 0.75 * np.cos(np.radians(a))) * 255
            for f, a in (("L", 65), ("R", 25))}
    flat, _ = render(ctx, "flat", mesh, cam)
    mask = covered(flat)
    assert len(colors(flat, mask)) == 2
    sharp, _ = render(ctx, "gouraud", mesh, cam, crease_deg=30.0)
    smooth, _ = render(ctx, "gouraud", mesh, cam, crease_deg=120.0)
    ridge = cam.project([[0.0, 0.0, 0.0]], (SIZE, SIZE))[0, 0]
    cols = np.arange(SIZE)[None, :].repeat(SIZE, 0)
    for image in (flat, sharp):
        assert (covered(image) == mask).all()
        for side, sel in (("L", cols < ridge - 1), ("R", cols > ridge + 1)):
            got = image[mask & sel][:, :3].astype(float)
            assert np.abs(got - face[side]).max() <= 1.0, side
    # smoothed: the ridge vertices take the mean normal (|n·l| = cos 20°), faces are graded
    assert len(colors(smooth, mask)) > 10
    near_ridge = mask & (np.abs(cols + 0.5 - ridge) < 1.0)
    ridge_colour = base * (0.25 + 0.75 * np.cos(np.radians(20))) * 255
    assert np.abs(smooth[near_ridge][:, :3] - ridge_colour).max() <= 6.0
    assert np.abs(sharp[near_ridge][:, :3] - ridge_colour).min() > 3.0


@pytest.mark.parametrize("name", ["flat", "gouraud", "pixel_color"])
def test_back_face_lit_like_front(ctx, name):
    # a quad tilted 50° about y, seen from the front and from behind: same brightness
    mesh = grid(z=lambda X, Y: np.tan(np.radians(50)) * X)
    kw = {"field": "xy"} if name == "pixel_color" else {}
    front, _ = render(ctx, name, mesh, camera(), **kw)
    back, _ = render(ctx, name, mesh, camera(azimuth=180.0), **kw)
    # seen from behind the image is mirrored left-right
    assert covered(front).sum() == covered(back).sum() > 0
    assert np.abs(front.astype(int) - back[:, ::-1].astype(int)).max() <= 1
    if name != "pixel_color":
        expected = 0.75 * (0.25 + 0.75 * np.cos(np.radians(50))) * 255
        assert np.abs(front[covered(front)][:, 0] - expected).max() <= 1.0


def test_cull_back_drops_the_back_face(ctx):
    mesh = grid()
    front, _ = render(ctx, "flat", mesh, camera(), cull_back=True)
    back, _ = render(ctx, "flat", mesh, camera(azimuth=180.0), cull_back=True)
    assert covered(front).sum() == 32 * 32 and not covered(back).any()


def test_perspective_headlight_points_at_the_eye(ctx):
    # flat shading of the plane z = 0 under a perspective camera on the +z axis: the light
    # comes from the eye, so |n·l| at a pixel is D / |eye − p| for the point p the pixel sees
    mesh = grid(x0=-3, x1=3, y0=-3, y1=3)
    cam = camera(projection="perspective", fov_deg=60.0)
    image, _ = render(ctx, "flat", mesh, cam, base_color=(1.0, 1.0, 1.0))
    D = cam.eye[2]
    u, v = pixel_centres()
    p = np.stack([u, v], axis=-1) * np.tan(np.radians(30.0)) * D
    expected = (0.25 + 0.75 * D / np.sqrt(D**2 + (p**2).sum(axis=-1))) * 255
    assert np.abs(image[..., 0] - expected).max() <= 1.0
    assert image[..., 0].max() - image[..., 0].min() > 20  # the light really varies


# --------------------------------------------------------------------------- wire frame
@pytest.mark.parametrize("name", ["flat", "gouraud", "pixel_color"])
def test_wireframe_draws_element_edges_not_diagonals(ctx, name):
    # two quads whose edges run through pixel centres: x at columns 16, 32, 48, y at rows 16, 48
    p = 2.0 / SIZE
    x0, x1, x2 = (np.array([16, 32, 48]) + 0.5) * p - 1.0
    y_top, y_bottom = 1.0 - 16.5 * p, 1.0 - 48.5 * p
    mesh = grid(2, 1, x0, x2, y_bottom, y_top)
    kw = {"field": "x"} if name == "pixel_color" else {}
    image, path = render(ctx, name, mesh, camera(), wireframe=True, wire_color=(1.0, 0.0, 0.0),
                         **kw)
    wire = (image[..., 0] == 255) & (image[..., 1] == 0) & (image[..., 2] == 0)
    assert path.edges == 7
    for col in (16, 32, 48):
        assert wire[17:48, col].all()
    for row in (16, 48):
        assert wire[row, 17:48].all()
    # quad diagonals: no wire pixel within half a pixel of them, away from the edges
    x, y = pixel_centres()
    for a, b in _diagonals(mesh):
        (ax, ay), (bx, by) = mesh.nodes[a, :2], mesh.nodes[b, :2]
        d = np.abs((bx - ax) * (y - ay) - (by - ay) * (x - ax)) / np.hypot(bx - ax, by - ay)
        away = (np.abs(x - x0) > 2 * p) & (np.abs(x - x1) > 2 * p) & (np.abs(x - x2) > 2 * p) & \
               (np.abs(y - y_top) > 2 * p) & (np.abs(y - y_bottom) > 2 * p)
        near = (d < 0.5 * p) & away & (x > min(ax, bx)) & (x < max(ax, bx))
        assert near.sum() > 5 and not wire[near].any()


def _diagonals(mesh):
    """The node pairs of each quad's split diagonal (the edge two of its triangles share)."""
    out = []
    el = mesh.triangulation.element_of
    for e in np.unique(el):
        a, b = mesh.triangles[el == e]
        shared = sorted(set(a.tolist()) & set(b.tolist()))
        out.append(shared)
    return out


# --------------------------------------------------------------------------- clip planes
@pytest.mark.parametrize("offset", [0.0, 1e6])
@pytest.mark.parametrize("name", ["position", "pixel_color", "element_color"])
def test_clip_plane_removes_negative_half(ctx, name, offset):
    o = np.array([offset, -offset, offset])
    mesh = grid(offset=o)
    # keep x - o_x >= 0 (world plane (1, 0, 0, -o_x)); the quad's right half: columns 32..47
    image, _ = render(ctx, name, mesh, camera(o), field=FIELD_PATHS.get(name),
                      clip_planes=[(1.0, 0.0, 0.0, -o[0])])
    mask = covered(image)
    assert mask.sum() == 16 * 32 and not mask[:, :32].any()
    two, _ = render(ctx, name, mesh, camera(o), field=FIELD_PATHS.get(name),
                    clip_planes=[(1.0, 0.0, 0.0, -o[0]), (0.0, -1.0, 0.0, o[1])])
    # and y - o_y <= 0 as well: the bottom-right quarter
    assert covered(two).sum() == 16 * 16 and not covered(two)[:32].any()


# --------------------------------------------------------------------------- time steps
def two_step_mesh():
    mesh = grid()
    shift = np.array([4 * 2.0 / SIZE, 0.0, 0.0])  # 4 pixels to the right
    steps = np.stack([mesh.nodes, mesh.nodes + shift])
    return FEMesh(mesh.nodes, mesh.elements, steps=steps, node_fields=dict(mesh.node_fields),
                  element_fields={"cell": np.array([[0.0], [1.0]])})


@pytest.mark.parametrize("name", MESH_PATHS)
def test_magnification_moves_by_multiple_of_displacement(ctx, name):
    mesh = two_step_mesh()
    for magnification, cols in ((1.0, (20, 52)), (2.0, (24, 56)), (0.0, (16, 48))):
        image, _ = render(ctx, name, mesh, camera(), step=1, magnification=magnification,
                          field=FIELD_PATHS.get(name))
        c = np.nonzero(covered(image).any(axis=0))[0]
        assert (c.min(), c.max() + 1) == cols, magnification


@pytest.mark.parametrize("name", MESH_PATHS)
def test_set_step_uploads_coordinates_only(ctx, name, monkeypatch):
    mesh = two_step_mesh()
    fb = Framebuffer(ctx, (SIZE, SIZE))
    path = make_path(name, Style(field=FIELD_PATHS.get(name), magnification=2.0,
                                 wireframe=LINE_WIRE[name]))
    path.prepare(ctx, mesh, camera())
    fb.clear()
    path.draw()
    first = fb.read()
    writes = []
    for cls in (moderngl.Buffer, moderngl.Texture):
        original = cls.write

        def spy(self, data, *args, _original=original, **kw):
            writes.append(len(memoryview(data).cast("B")))
            return _original(self, data, *args, **kw)

        monkeypatch.setattr(cls, "write", spy)
    sent = path.set_step(1)
    per_vertex = 12 + (12 if name in ("gouraud", "vertex_color", "pixel_color", "quad_wire") else 0)
    expected = path.vertices * per_vertex
    if name == "element_color":  # a time-dependent element field: one value per vertex
        expected += path.vertices * 4
    assert sent == sum(writes) == expected == path.bytes_per_step
    assert len(writes) == per_vertex // 12 + (name == "element_color")
    assert path.bytes_uploaded > path.bytes_per_step  # topology went up once, at prepare
    monkeypatch.undo()
    fb.clear()
    path.draw()
    stepped = fb.read()
    path.release()
    fb.release()
    # the stepped draw equals a path prepared directly at step 1
    direct, _ = render(ctx, name, mesh, camera(), step=1, field=FIELD_PATHS.get(name),
                       magnification=2.0, wireframe=LINE_WIRE[name])
    assert stepped.tobytes() == direct.tobytes() != first.tobytes()


def test_time_dependent_node_field_goes_up_with_the_step(ctx):
    mesh = two_step_mesh()
    mesh.node_fields["xt"] = np.stack([mesh.nodes[:, 0], -mesh.nodes[:, 0]])
    path = make_path("pixel_color", Style(field="xt"))
    path.prepare(ctx, mesh, camera())
    assert path.set_step(1) == path.bytes_per_step == path.vertices * (12 + 12 + 4)
    path.release()


def test_missing_element_values_are_drawn_in_the_no_result_colour(ctx):
    # 2 × 2 elements, element 3 without a value (a rigid shell's stress): its block is the
    # no-result colour (not the base colour), the others keep their colormap colours
    mesh = grid(2, 2)
    mesh.element_fields["cell"][3] = np.nan
    base = (0.5, 0.5, 0.5)
    for hide in (None, (-10.0, 10.0)):
        image, path = render(ctx, "element_color", mesh, camera(), field="cell", base_color=base,
                             hide_range=hide)
        assert path.missing_values == 1
        missing = image[16:32, 32:48, :3].reshape(-1, 3)  # element 3: top right (rows go up in y)
        assert (missing == np.rint(np.multiply(NO_RESULT_COLOR, 255))).all()  # lit face-on
        if hide is None:
            scale = scale_for(mesh, "cell")
            block = image[16:32, 16:32, :3].reshape(-1, 3)
            assert np.abs(block - scale.evaluate(2.0)[:3] * 255).max() <= 1.0
        else:  # everything with a value is hidden, the missing element is not
            assert covered(image).sum() == 16 * 16


def test_missing_node_value_draws_its_triangles_in_the_no_result_colour(ctx):
    mesh = grid(2, 2)
    mesh.node_fields["x"] = mesh.node_fields["x"].copy()
    mesh.node_fields["x"][8] = np.nan  # the top right corner node
    image, path = render(ctx, "pixel_color", mesh, camera(), field="x", base_color=(0.5, 0.5, 0.5))
    assert path.missing_values == 1
    green = (image[..., :3] == np.rint(np.multiply(NO_RESULT_COLOR, 255))).all(axis=-1)
    # the top right element's triangles touching node 8 are green, the far corner element is not
    assert green[17:22, 42:47].all() and not green[40:47, 17:30].any()


def test_unreferenced_nodes_are_not_uploaded(ctx):
    base = grid()
    mesh = FEMesh(np.vstack([[9.0, 9.0, 9.0], base.nodes]), base.elements + 1)
    image, path = render(ctx, "flat", mesh, camera(), wireframe=True)
    assert path.vertices == 4 and path.edges == 4
    rows, cols = np.nonzero(covered(image))
    assert rows.min() >= 15 and rows.max() <= 48 and cols.min() >= 15 and cols.max() <= 48
    assert covered(image)[17:47, 17:47].all()


# --------------------------------------------------------------------------- stability
def curved_mesh(offset=(0.0, 0.0, 0.0)):
    mesh = grid(4, 4, -0.6, 0.6, -0.6, 0.6, offset, z=lambda X, Y: 0.3 * np.cos(2 * X) * np.cos(Y))
    return mesh


@pytest.mark.parametrize("name", MESH_PATHS)
def test_far_translation_renders_same_image(ctx, name):
    near, far = curved_mesh(), curved_mesh((1e6, 1e6, 1e6))
    images = []
    for mesh in (near, far):
        centre, _ = mesh.bounding_sphere()
        field = {"vertex_color": "xy", "pixel_color": "xy"}.get(name, FIELD_PATHS.get(name))
        image, _ = render(ctx, name, mesh, camera(centre, azimuth=30, elevation=25,
                                                  projection="perspective"),
                          field=field, wireframe=LINE_WIRE[name])
        images.append(image)
    differ = (np.abs(images[0].astype(int) - images[1].astype(int)) > 1).any(axis=-1)
    assert covered(images[0]).sum() > 500
    assert differ.mean() <= 0.005


@pytest.mark.parametrize("name", MESH_PATHS)
def test_repeated_draws_are_byte_identical(ctx, name):
    mesh = curved_mesh()
    fb = Framebuffer(ctx, (SIZE, SIZE))
    path = make_path(name, Style(field=FIELD_PATHS.get(name), wireframe=LINE_WIRE[name]))
    path.prepare(ctx, mesh, camera(azimuth=30, elevation=25))
    out = []
    for _ in range(2):
        fb.clear()
        path.draw()
        out.append(fb.read())
    assert covered(out[0]).any() and out[0].tobytes() == out[1].tobytes()
    path.release()
    fb.release()


def test_style_summary_names_what_differs_from_the_defaults():
    assert Style().summary() == ""
    words = Style(field="x", bands=10, wireframe=True, value_range=(0.0, 2.5)).summary().split()
    assert words == ["field=x", "value_range=(0,2.5)", "bands=10", "wireframe=True"]
