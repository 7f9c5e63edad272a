"""The fe2003 texture paths against analytic pixel answers on synthetic textured surfaces.

The scene is an 8 × 8 grid of square cells 0.2 model units wide in a plane z = const, far from
the world origin (x = 10⁵), seen by ``Camera.fit(centre, 1, margin=1)`` looking down −Z: in a
128 × 128 image a pixel is 1/64 unit and a cell 12.8 pixels. The atlas gives each cell 6 × 6
texels; the wire map is computed here by brute force from the analytic signed distances of each
cell, following the convention of :mod:`workbench.algo.fepatch.surface`.
"""

import types

import numpy as np
import pytest
from meshes import quad_grid

import workbench.paths.fetexture  # noqa: F401  (registers the paths)
from workbench.algo.fepatch import pipeline
from workbench.algo.fepatch.normalmap import decode_normals, encode_normals
from workbench.algo.fepatch.surface import TexturedSurface
from workbench.algo.fepatch.wireid import corner_table, element_map
from workbench.gl import Camera
from workbench.measurement.rows import measure
from workbench.paths import PATHS, Style, make_path
from workbench.scene.mesh import FEMesh

SIZE = 128
N, CELL, TEXELS, MARGIN = 8, 0.2, 6, 4  # cells per side, cell width, texels per cell, border
PIXEL = 2.0 / SIZE
FAR = np.array([1.0e5, 0.0, 0.0])
WIRE = (1.0, 0.0, 0.0)
WIRE_RGB = np.array([255, 0, 0], np.uint8)
NAMES = ("fe_wire_texture", "fe_normal_map", "fe_normal_wire")


# --------------------------------------------------------------------------- synthetic surface
def grid_nodes(centre=FAR, z=None):
    """(nodes (N+1)², quads) of the grid around ``centre`` (z = z(x, y) relative, default 0)."""
    return quad_grid(N, N, cell=CELL, centred=True, z=z, origin=centre)


def grid_uv():
    """(N+1)² node texel coordinates: u along x, v along y."""
    return quad_grid(N, N, cell=TEXELS, origin=(MARGIN, MARGIN), dim=2)[0]


def wire_map(wire_range=2.0, ring=1.5):
    """(H, W, 4) uint8 wire map of the grid cells by brute force over all cells.

    Cell (row i, column j) with corners (a, b, c, d) = nodes (i, j), (i, j+1), (i+1, j+1),
    (i+1, j) has edges 0 = ab (v = v0) and 2 = cd (v = v1), 1 = bc (u = u1) and 3 = da (u = u0);
    colour (i + j) mod 2 picks the channel pair. Per colour, a texel inside a cell of that colour
    holds that cell's two distances; a texel outside all of them but at most ``ring`` texels
    outside some holds, per channel, the smallest distance among those, so that no channel
    turns positive where the texel is outside every cell and two cells meeting at a corner do
    not draw spurious diagonals; texels no cell reaches hold −wire_range.
    """
    size = 2 * MARGIN + N * TEXELS
    centre = np.arange(size) + 0.5
    U, V = np.meshgrid(centre, centre)  # row = v, column = u
    out = np.full((size, size, 4), -wire_range)
    for colour, (ch1, ch2) in enumerate(((1, 2), (0, 3))):
        d1s, d2s = [], []
        for i in range(N):
            for j in range(N):
                if (i + j) % 2 == colour:
                    u0, v0 = MARGIN + j * TEXELS, MARGIN + i * TEXELS
                    d1s.append(np.minimum(V - v0, v0 + TEXELS - V))  # edges 0 and 2
                    d2s.append(np.minimum(U - u0, u0 + TEXELS - U))  # edges 1 and 3
        d1, d2 = np.array(d1s), np.array(d2s)
        inner = np.minimum(d1, d2)
        reached = inner >= -ring
        deepest = np.argmax(np.where(reached, inner, -np.inf), axis=0)[None]
        first = np.take_along_axis(d1, deepest, 0)[0]
        second = np.take_along_axis(d2, deepest, 0)[0]
        outside_all = inner.max(axis=0) < 0
        first = np.where(outside_all, np.where(reached, d1, np.inf).min(axis=0), first)
        second = np.where(outside_all, np.where(reached, d2, np.inf).min(axis=0), second)
        any_reached = reached.any(axis=0)
        out[..., ch1] = np.where(any_reached, first, -wire_range)
        out[..., ch2] = np.where(any_reached, second, -wire_range)
    return np.clip(np.rint(out / wire_range * 127.5 + 127.5), 0, 255).astype(np.uint8)


def triangles_of(quads):
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def element_wire(quads) -> dict:
    """The grid's element-id wire frame (one subpatch, elements in quad order)."""
    size = 2 * MARGIN + N * TEXELS
    corners = grid_uv()[quads]
    owner = element_map(corners, (size, size), border=1)
    table, frac = corner_table(corners, (size, size))
    return {"element_map": np.where(owner < 0, 65535, owner).astype(np.uint16),
            "corner_table": table, "corner_frac": frac,
            "element_base": np.zeros((N + 1) ** 2, np.int32)}


def surface(centre=FAR, normal=(0.0, 0.0, 1.0), axis=2, wire=True, line_edges=None, z=None):
    """The grid as a TexturedSurface with a constant normal map and vertex normals; ``wire``
    True or "distance" (the distance texture), "corners" (element ids and corners) or False."""
    nodes, quads = grid_nodes(centre, z)
    size = 2 * MARGIN + N * TEXELS
    texel = encode_normals(np.asarray(normal, np.float64)[None], axis)[0]
    frame = element_wire(quads) if wire == "corners" else \
        {"wire_map": wire_map()} if wire else {}
    return TexturedSurface(
        positions=nodes, triangles=triangles_of(quads), uv=grid_uv(),
        normal_axis=np.full(len(nodes), axis), normals=np.tile(normal, (len(nodes), 1)),
        normal_map=np.tile(texel, (size, size, 1)).astype(np.uint8), line_edges=line_edges,
        **frame)


def camera(centre=FAR, **kw):
    return Camera.fit(np.asarray(centre, np.float64), 1.0, margin=1.0, **kw)


def draw(ctx, name, surf, cam, **style):
    """(image, path) of one path drawing the surface ``surf`` once on white, untimed; the path
    is released."""
    style = {"wire_color": WIRE, **style}
    m = measure(ctx, surf, name, Style(**style), camera=cam, size=(SIZE, SIZE), timed=False)
    return m.image, m.path


def is_wire(image):
    return (image[..., :3] == WIRE_RGB).all(axis=-1)


def covered(image):
    return (image[..., :3] != 255).any(axis=-1)


def pixel_centres():
    """(SIZE, SIZE) x, y of the pixel centres relative to the view centre (row 0 at the top)."""
    c = (np.arange(SIZE) + 0.5) * PIXEL - 1.0
    return np.meshgrid(c, -c)


def edge_distance_px():
    """(SIZE, SIZE) distance in pixels from each pixel centre to the nearest cell edge."""
    x, y = pixel_centres()
    lines = (np.arange(N + 1) - N / 2) * CELL
    half = N / 2 * CELL
    across = np.abs(x[..., None] - lines).min(-1), np.abs(y[..., None] - lines).min(-1)
    along = np.maximum(np.abs(y) - half, 0.0), np.maximum(np.abs(x) - half, 0.0)
    d = np.minimum(np.hypot(across[0], along[0]), np.hypot(across[1], along[1]))
    return d / PIXEL


def recall(wire, points):
    """Fraction of (K, 2) view points (x, y) with a wire pixel within one pixel (3 × 3)."""
    col = np.floor((points[:, 0] + 1.0) / PIXEL).astype(int)
    row = np.floor((1.0 - points[:, 1]) / PIXEL).astype(int)
    padded = np.pad(wire, 1)
    hit = np.zeros(len(points), bool)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            hit |= padded[row + 1 + dr, col + 1 + dc]
    return hit.mean()


def edge_points():
    """Points every half pixel along the cell edges inside the grid (view coordinates); the
    grid's own border is left out: the outline rule draws an edge within half a pixel on each
    side, and outside the surface there are no fragments."""
    lines = (np.arange(1, N) - N / 2) * CELL
    s = np.arange(-N / 2 * CELL, N / 2 * CELL + 1e-9, PIXEL / 2)
    a, b = np.meshgrid(lines, s)
    return np.concatenate([np.c_[a.ravel(), b.ravel()], np.c_[b.ravel(), a.ravel()]])


# --------------------------------------------------------------------------- tests
def test_registry_and_refusals(ctx):
    for name in NAMES:
        assert PATHS[name].needs == frozenset({"fepatch"})
        assert not hasattr(make_path(name), "surface")
    surf, cam = surface(), camera()
    for style, match in (({"step": 1}, "step 0"), ({"wireframe": True}, "wireframe"),
                         ({"strips": "triangle"}, "strips")):
        with pytest.raises(ValueError, match=match):
            draw(ctx, "fe_normal_map", surf, cam, **style)
    with pytest.raises(ValueError, match="no wire_map"):
        draw(ctx, "fe_normal_wire", surface(wire=False), cam)
    no_normals = surface()
    no_normals.normals = None
    with pytest.raises(ValueError, match="no normals"):
        draw(ctx, "fe_wire_texture", no_normals, cam)
    with pytest.raises(ValueError, match="FE mesh or a TexturedSurface"):
        make_path("fe_normal_map").prepare(ctx, None, cam)
    path = make_path("fe_normal_map")
    path.prepare(ctx, surf, cam)
    with pytest.raises(ValueError, match="step 0"):
        path.set_step(1)
    with pytest.raises(ValueError, match="origin"):
        path.set_camera(camera(centre=(0.0, 0.0, 0.0)))
    path.release()


@pytest.mark.parametrize("encoding", ["distance", "corners"])
@pytest.mark.parametrize("name", ["fe_wire_texture", "fe_normal_wire"])
def test_wire_texture_outlines_the_cells(ctx, name, encoding):
    image, _ = draw(ctx, name, surface(wire=encoding), camera(), base_color=(0.5, 0.5, 0.5))
    wire = is_wire(image)
    d = edge_distance_px()[wire]
    # one-pixel lines: about one wire pixel per pixel of inner edge length (the two lines
    # through the view centre lie on pixel borders and are drawn on both sides)
    length = 2 * (N - 1) * N * CELL / PIXEL
    assert 0.95 * length <= wire.sum() <= 1.2 * length
    assert (d <= 1.0).mean() >= 0.98, f"precision {(d <= 1.0).mean():.3f}"
    assert d.max() <= 1.5  # nothing wire away from the edges
    r = recall(wire, edge_points())
    assert r >= 0.98, f"recall {r:.3f}"
    # pixels inside the cells keep the lit base colour
    inside = (edge_distance_px() > 2.0) & covered(image)
    assert inside.sum() > 0.4 * (N * CELL / PIXEL) ** 2
    assert (np.abs(image[inside][:, :3] - 127.5) <= 1.0).all()


@pytest.mark.parametrize("normal, axis", [((0.8, 0.36, 0.48), 0), ((-0.8, 0.36, 0.48), 0),
                                          ((0.36, 0.8, 0.48), 1), ((0.36, 0.48, 0.8), 2)])
def test_normal_map_headlight(ctx, normal, axis):
    cam = camera(azimuth=20.0, elevation=10.0)
    surf = surface(normal=normal, axis=axis, wire=False)
    image, _ = draw(ctx, "fe_normal_map", surf, cam, base_color=(1.0, 1.0, 1.0))
    mask = covered(image)
    assert mask.sum() > 0.4 * SIZE * SIZE
    decoded = decode_normals(surf.normal_map[0, 0][None], axis)[0]
    n_eye = cam.view_matrix()[:3, :3] @ decoded
    expected = 255.0 * (0.25 + 0.75 * abs(n_eye[2]))
    assert np.abs(image[mask][:, :3].astype(float) - expected).max() <= 2.0
    # a normal tilted the other way about the view gives another light: the map is used
    exact = 255.0 * (0.25 + 0.75 * abs((cam.view_matrix()[:3, :3] @ normal)[2]))
    assert abs(exact - expected) <= 2.0


def test_normal_map_is_per_pixel(ctx):
    """A normal field varying across the atlas lights each pixel from its own texel."""
    surf = surface(wire=False)
    size = surf.normal_map.shape[0]
    angle = np.linspace(-1.2, 1.2, size)  # radians about y, along u (columns)
    normals = np.stack([np.sin(angle), np.zeros(size), np.cos(angle)], axis=1)
    surf.normal_map = np.tile(encode_normals(normals, 2)[None], (size, 1, 1))
    image, _ = draw(ctx, "fe_normal_map", surf, camera(), base_color=(1.0, 1.0, 1.0))
    mask = covered(image)
    x, _ = pixel_centres()
    u = MARGIN + (x + N / 2 * CELL) / CELL * TEXELS  # texel coordinate of each pixel
    # bilinear lookup between texel centres of the decoded texels
    texels = surf.normal_map[0].astype(np.float64)
    lookup = np.stack([np.interp(u[mask] - 0.5, np.arange(size), texels[:, k]) for k in (0, 1)],
                      axis=1)
    expected = 255.0 * (0.25 + 0.75 * np.abs(decode_normals(lookup, 2)[:, 2]))
    got = image[mask][:, 0].astype(float)
    assert np.ptp(got) > 60  # the light does vary across the surface
    assert np.abs(got - expected).max() <= 2.0


@pytest.mark.parametrize("projection, encoding", [("orthographic", "distance"),
                                                  ("perspective", "distance"),
                                                  ("perspective", "corners")])
def test_wire_texture_matches_gouraud(ctx, projection, encoding):
    centre = FAR + [0.0, 0.0, 0.3]
    nodes, quads = grid_nodes(centre, z=lambda X, Y: 0.3 * np.sin(2.5 * X) * np.cos(1.5 * Y))
    mesh = FEMesh(nodes, quads)
    split = mesh.gouraud(30.0)
    vertex = np.asarray(split.vertex_node, np.int64)
    frame = element_wire(quads) if encoding == "corners" else {"wire_map": wire_map()}
    if encoding == "corners":
        frame["element_base"] = frame["element_base"][vertex]
    surf = TexturedSurface(positions=nodes[vertex], triangles=split.triangles,
                           uv=grid_uv()[vertex], normal_axis=np.full(len(vertex), 2),
                           normals=split.normals(mesh.nodes), **frame)
    cam = camera(centre, azimuth=30.0, elevation=25.0, projection=projection)
    ours, _ = draw(ctx, "fe_wire_texture", surf, cam)
    reference = measure(ctx, mesh, "gouraud", Style(), camera=cam, size=(SIZE, SIZE),
                        timed=False).image
    wire = is_wire(ours)
    assert wire.sum() > 200
    assert np.array_equal(covered(ours), covered(reference))
    diff = np.abs(ours.astype(int) - reference.astype(int))[~wire]
    assert diff.max() <= 1
    assert len(np.unique(reference[covered(reference) & ~wire][:, 0])) > 20  # shading varies


@pytest.mark.parametrize("name", NAMES)
def test_line_edges_are_drawn(ctx, name):
    idx = np.arange((N + 1) ** 2).reshape(N + 1, N + 1)
    diagonal = np.c_[idx[np.arange(N), np.arange(N)], idx[np.arange(1, N + 1), np.arange(1, N + 1)]]
    plain, _ = draw(ctx, name, surface(wire=False) if name == "fe_normal_map" else surface(),
                    camera())
    lined, path = draw(ctx, name, surface(wire=name != "fe_normal_map", line_edges=diagonal),
                       camera())
    assert path.edges == N
    s = np.linspace(-N / 2 * CELL, N / 2 * CELL, 400)
    new = is_wire(lined) & ~is_wire(plain)
    assert recall(new, np.c_[s, s]) >= 0.98
    x, y = pixel_centres()
    assert (np.abs(x - y)[new] / np.sqrt(2) <= PIXEL).all()  # only along the diagonal


def test_counters_and_far_origin(ctx):
    idx = np.arange((N + 1) ** 2).reshape(N + 1, N + 1)
    edges = np.c_[idx[0, :-1], idx[0, 1:]]
    far = surface(line_edges=edges)
    image_far, path = draw(ctx, "fe_normal_wire", far, camera())
    v = (N + 1) ** 2
    assert (path.triangles, path.vertices, path.edges) == (2 * N * N, v, N)
    assert path.vertices_sent == 3 * path.triangles
    assert path.bytes_per_step == v * 12
    assert path.bytes_uploaded >= far.texture_bytes + v * 12 + path.triangles * 12 + edges.nbytes
    near = surface(centre=(0.0, 0.0, 0.0), line_edges=edges)
    image_near, _ = draw(ctx, "fe_normal_wire", near, camera(centre=(0.0, 0.0, 0.0)))
    assert is_wire(image_far).sum() > 1000
    assert np.array_equal(image_far, image_near)


def test_clip_plane(ctx):
    plane = (1.0, 0.0, 0.0, -FAR[0])  # keeps x >= 10⁵, the right half of the view
    image, _ = draw(ctx, "fe_normal_wire", surface(), camera(), clip_planes=[plane])
    x, _ = pixel_centres()
    mask = covered(image)
    assert mask.any()
    assert (x[mask] >= -PIXEL).all()
    assert mask[np.abs(x) < N / 2 * CELL - PIXEL].sum() > 0
    assert ((mask & (x > PIXEL) & (np.abs(pixel_centres()[1]) < 0.7)).sum()
            > 0.3 * SIZE * SIZE * 0.35)


def test_model_built_once_per_mesh_and_parameters(ctx, monkeypatch):
    calls = []
    original, simplified = surface(), surface(normal=(0.36, 0.48, 0.8))

    def build_model(elements, coords, params):
        calls.append(params)
        return types.SimpleNamespace(original=original, simplified=simplified)

    monkeypatch.setattr(pipeline, "build_model", build_model)
    nodes, quads = grid_nodes()
    mesh, cam = FEMesh(nodes, quads), camera()
    for name, expected in (("fe_wire_texture", original), ("fe_normal_map", simplified),
                           ("fe_normal_wire", simplified)):
        path = make_path(name, Style(fepatch="B"))
        path.prepare(ctx, mesh, cam)
        assert path._surface is expected
        path.release()
    assert calls == ["B"]
    path = make_path("fe_normal_map", Style(fepatch="A"))
    path.prepare(ctx, mesh, cam)
    path.release()
    assert calls == ["B", "A"]
