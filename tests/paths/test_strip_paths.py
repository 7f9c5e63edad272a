"""Stripped drawing: quad strips and triangle strips against the unstripped triangle list, and the
single-pass quad wire frame against the line-overdraw wire frame."""

import functools

import numpy as np
import pytest
from meshes import quad_grid
from skimage.morphology import dilation, footprint_rectangle
from test_paths import render

from workbench.algo.strips import quad_strips
from workbench.gl import Camera, Framebuffer, VertexShaderInvocations
from workbench.measurement.rows import measure
from workbench.paths import Style, make_path
from workbench.scene.mesh import FEMesh

BACKGROUND = np.array([255, 255, 255, 255], np.uint8)
SHADED = {"position": None, "flat": None, "gouraud": None, "pixel_color": "h",
          "vertex_color": "h"}


def scene_with_defects():
    """A warped 14 × 10 quad grid with a sharp fold, a hole, two triangles, a degenerate element
    and a flipped element: strips break at the fold (crease split), the hole and the flip."""
    nodes, quads = quad_grid(
        14, 10, span=((-0.8, 0.8), (-0.6, 0.6)),
        z=lambda x, y: 0.2 * np.sin(3 * x) * np.cos(2 * y) + 0.4 * np.abs(x))  # fold along x = 0
    keep = np.ones(len(quads), bool)
    keep[[30, 31, 45]] = False  # a hole
    split = quads[[60, 61]]
    quads = quads[keep & ~np.isin(np.arange(len(quads)), [60, 61])]
    quads[17] = quads[17][::-1]  # a flipped element
    triangles = np.concatenate([np.c_[split[:, :3], split[:, 2]], np.c_[split[:, [0, 2, 3]],
                                                                          split[:, 3]]])
    degenerate = np.array([[0, 1, 0, 1]])
    elements = np.concatenate([quads, triangles, degenerate])
    return FEMesh(nodes, elements, node_fields={"h": nodes[:, 2] + 0.3 * nodes[:, 0]})


def oblique():
    return Camera.fit(np.array([0.0, 0.0, 0.2]), 1.0, azimuth=25, elevation=35)


# one image of one path on white, the path released (larger than test_paths' default)
draw = functools.partial(render, size=160)


@pytest.mark.parametrize("name", sorted(SHADED))
def test_quad_strips_draw_the_unstripped_image_pixel_for_pixel(ctx, name):
    mesh, cam = scene_with_defects(), oblique()
    kw = {"field": SHADED[name], "bands": 7 if name == "vertex_color" else 0}
    listed, flat_list = draw(ctx, name, mesh, cam, quad_diagonal="strip", **kw)
    stripped, strip_path = draw(ctx, name, mesh, cam, strips="quad", **kw)
    assert (listed != BACKGROUND).any(axis=-1).sum() > 4000
    assert listed.tobytes() == stripped.tobytes()
    assert strip_path.triangles == flat_list.triangles == 2 * 135 + 4
    assert strip_path.strips > 1 and strip_path.vertices_sent < flat_list.vertices_sent


@pytest.mark.parametrize("name", sorted(SHADED))
def test_triangle_strips_draw_the_same_triangles(ctx, name):
    # meshoptimizer may start a triangle at another of its corners, which can move a rounding
    # in the interpolation: at most 1/255 on a few pixels
    mesh, cam = scene_with_defects(), oblique()
    kw = {"field": SHADED[name], "bands": 7 if name == "vertex_color" else 0}
    listed, _ = draw(ctx, name, mesh, cam, quad_diagonal="strip", **kw)
    stripped, path = draw(ctx, name, mesh, cam, strips="triangle", quad_diagonal="strip", **kw)
    same_cover = (listed != BACKGROUND).any(-1) == (stripped != BACKGROUND).any(-1)
    assert same_cover.all()
    diff = np.abs(listed.astype(int) - stripped.astype(int)).max(axis=-1)
    assert diff.max() <= 1 and (diff > 0).mean() <= 0.002
    assert path.strips > 1


@pytest.mark.parametrize("name", ["gouraud", "vertex_color"])
def test_triangle_strips_equal_their_own_triangles_listed(ctx, name):
    # the 1/255 differences above come from the corner each triangle starts at: listed with the
    # corners in the strips' order, the same triangles draw the same image pixel for pixel
    from workbench.algo.strips import tri_strips, unstripify
    from workbench.paths import PATHS
    from workbench.paths.drawdata import Layout

    class StripOrderList(PATHS[name]):
        def layout(self, mesh, topology):
            listed = super().layout(mesh, topology).index
            n_vertices = len(topology.vertex_node)
            triangles = unstripify(tri_strips(listed, n_vertices).indices)
            return Layout(triangles, "triangles", len(triangles), 0, triangles.size)

    mesh, cam = scene_with_defects(), oblique()
    kw = {"field": SHADED[name], "bands": 7 if name == "vertex_color" else 0,
          "quad_diagonal": "strip"}
    stripped, _ = draw(ctx, name, mesh, cam, size=240, strips="triangle", **kw)
    listed = measure(ctx, mesh, StripOrderList(Style(**kw)), camera=cam, size=(240, 240),
                     timed=False).image
    assert (listed != BACKGROUND).any(axis=-1).sum() > 10000
    assert stripped.tobytes() == listed.tobytes()


def test_strips_change_the_diagonal_not_the_outline(ctx):
    # the default split (shorter diagonal) and the strips' split cover the same pixels
    mesh, cam = scene_with_defects(), oblique()
    shorter, _ = draw(ctx, "position", mesh, cam)
    strip, _ = draw(ctx, "position", mesh, cam, strips="quad")
    assert shorter.tobytes() == strip.tobytes()


def test_vertices_sent_count_the_strips(ctx):
    mesh = scene_with_defects()
    _, path = draw(ctx, "gouraud", mesh, oblique(), strips="quad")
    quads = quad_strips(mesh.gouraud(Style().crease_deg).elements)
    assert len(quads.degenerate) == 1 and len(quads.triangles) == 4
    assert path.vertices_sent == quads.vertex_count
    assert path.strips == quads.n_strips + len(quads.leftover) + len(quads.triangles)
    # the fold along x = 0 is a crease: its vertices are split, so no strip crosses it
    centre_x = mesh.nodes[mesh.elements].mean(axis=1)[:, 0]
    sides = [np.sign(centre_x[quads.quads[a:b]]) for a, b in
             zip(quads.quad_starts[:-1], quads.quad_starts[1:])]
    assert all((side == side[0]).all() for side in sides)
    unsplit = quad_strips(mesh.elements)
    assert any(len(set(np.sign(centre_x[unsplit.quads[a:b]]))) == 2
               for a, b in zip(unsplit.quad_starts[:-1], unsplit.quad_starts[1:]))


def test_vertex_shader_invocations_are_bounded_by_vertices_sent(ctx):
    if not VertexShaderInvocations.supported(ctx):
        pytest.skip("no pipeline statistics queries on this context")
    mesh, cam = scene_with_defects(), oblique()
    fb = Framebuffer(ctx, (64, 64))
    query = VertexShaderInvocations(ctx)
    try:
        for strips in ("none", "triangle", "quad"):
            path = make_path("gouraud", Style(strips=strips, quad_diagonal="strip"))
            path.prepare(ctx, mesh, cam)
            fb.clear()
            with query:
                path.draw()
            # every drawn vertex runs at least once, no index runs twice
            assert path.vertices <= query.invocations <= path.vertices_sent, strips
            path.release()
    finally:
        query.release()
        fb.release()


def test_element_color_refuses_strips(ctx):
    mesh = scene_with_defects()
    mesh.element_fields["cell"] = np.arange(mesh.n_elements, dtype=np.float64)
    with pytest.raises(ValueError, match="provoking vertex"):
        draw(ctx, "element_color", mesh, oblique(), field="cell", strips="quad")


def test_strip_style_is_checked():
    with pytest.raises(ValueError, match="strips must be one of"):
        Style(strips="fan")
    with pytest.raises(ValueError, match="quad_diagonal"):
        Style(quad_diagonal="longer")
    with pytest.raises(ValueError, match="strip's diagonal"):
        Style(strips="quad", quad_diagonal="shorter")
    with pytest.raises(ValueError, match="strip_cutoff"):
        Style(strip_cutoff=0)
    assert Style(strips="quad").diagonal == "strip" and Style().diagonal == "shorter"


# --------------------------------------------------------------------------- quad wire frame
def facing_grid(nx, ny, cell, shift=(0.0, 0.0)):
    """An nx × ny grid of square cells ``cell`` units wide, centred at ``shift``, facing the
    camera."""
    return FEMesh(*quad_grid(nx, ny, cell=cell, centred=True, origin=(*shift, 0.0)))


def wire_mask(image):
    return (image[..., :3] == 0).all(axis=-1)


def expected_lines(edges_px, inside):
    """Pixel indices (along one axis) an aliased one-pixel line puts on each edge: the centre
    within ½ pixel of an edge between two cells, within 1 pixel inside for an outer edge."""
    centres = np.arange(len(inside)) + 0.5
    hit = np.zeros(len(inside), bool)
    for i, e in enumerate(edges_px):
        reach = 1.0 if i in (0, len(edges_px) - 1) else 0.5
        hit |= inside & (np.abs(centres - e) <= reach)
    return hit


@pytest.mark.parametrize("shift_px", [0.25, 0.7])
def test_quad_wire_draws_each_edge_one_pixel_wide_and_no_diagonal(ctx, shift_px):
    # 128 px span 2 units: a 0.25-unit cell is 16 px; shifted off the pixel grid
    size, cell, px = 128, 0.25, 2 / 128
    mesh = facing_grid(4, 3, cell, shift=(shift_px * px, -shift_px * px))
    cam = Camera.fit(np.zeros(3), 1.0, margin=1.0)
    image, path = draw(ctx, "quad_wire", mesh, cam, size=size)
    wire = wire_mask(image)
    surface = (image != BACKGROUND).any(axis=-1)
    cols = 32 + shift_px + 16 * np.arange(5)  # edge x in pixels from the left
    rows = 40 + shift_px + 16 * np.arange(4)  # edge y in pixels from the top
    centres = np.arange(size) + 0.5
    in_x = (centres > cols[0]) & (centres < cols[-1])
    in_y = (centres > rows[0]) & (centres < rows[-1])
    assert (surface == np.outer(in_y, in_x)).all()
    expected = (np.outer(in_y, expected_lines(cols, in_x))
                | np.outer(expected_lines(rows, in_y), in_x))
    assert (wire == expected).all()
    # one wire pixel per row on each vertical edge: 5 edges
    assert (wire[in_y][:, in_x].sum(axis=1) >= 5).all()
    # the shaded interior, diagonals included, keeps the lit base colour
    interior = surface & ~wire
    assert len({tuple(c) for c in image[interior][:, :3].tolist()}) == 1
    assert path.vertices_sent == quad_strips(mesh.elements).vertex_count


def test_quad_wire_keeps_an_edge_on_a_pixel_boundary(ctx):
    # edges exactly between pixels: each inner edge is drawn on both sides rather than lost
    mesh = facing_grid(4, 3, 0.25)
    image, _ = draw(ctx, "quad_wire", mesh, Camera.fit(np.zeros(3), 1.0, margin=1.0), size=128)
    wire = wire_mask(image)
    assert np.flatnonzero(wire[60]).tolist() == [32, 47, 48, 63, 64, 79, 80, 95]
    assert np.flatnonzero(wire[:, 50]).tolist() == [40, 55, 56, 71, 72, 87]


def test_quad_wire_outlines_triangles_on_all_three_edges(ctx):
    nodes = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [-0.5, 0.5, 0]], np.float64)
    mesh = FEMesh(nodes, np.array([[0, 1, 2, 2]]))
    size = 128
    image, _ = draw(ctx, "quad_wire", mesh, Camera.fit(np.zeros(3), 1.0, margin=1.0), size=size)
    wire = wire_mask(image)
    rows, cols = np.nonzero(wire)
    # pixel centres in model units
    x = (cols + 0.5) * 2 / size - 1
    y = 1 - (rows + 0.5) * 2 / size
    px = 2 / size
    d_left, d_bottom = np.abs(x + 0.5), np.abs(y + 0.5)
    d_hyp = np.abs(x + y) / np.sqrt(2)
    assert (np.minimum(np.minimum(d_left, d_bottom), d_hyp) <= 1.0 * px).all()
    # each of the three edges is drawn along its length
    assert (d_hyp <= px).sum() >= 60 and (d_left <= px).sum() >= 60 and (d_bottom <= px).sum() >= 60


def test_quad_wire_matches_line_overdraw_within_a_pixel(ctx):
    mesh, cam = scene_with_defects(), oblique()
    single, path = draw(ctx, "quad_wire", mesh, cam, size=240)
    overdraw, _ = draw(ctx, "gouraud", mesh, cam, size=240, wireframe=True, quad_diagonal="strip")
    a, b = wire_mask(single), wire_mask(overdraw)
    near = footprint_rectangle((3, 3))
    recall = (b & dilation(a, near)).sum() / b.sum()
    precision = (a & dilation(b, near)).sum() / a.sum()
    assert recall >= 0.95 and precision >= 0.95
    # same shading away from the wire frames
    shaded = ~dilation(a | b, near) & (single != BACKGROUND).any(-1)
    assert np.abs(single[shaded].astype(int) - overdraw[shaded]).max() <= 1
    assert path.strips > 1


def test_quad_wire_refuses_a_second_wire_frame(ctx):
    with pytest.raises(ValueError, match="fill pass"):
        draw(ctx, "quad_wire", scene_with_defects(), oblique(), wireframe=True)
    with pytest.raises(ValueError, match="quad strips"):
        draw(ctx, "quad_wire", scene_with_defects(), oblique(), strips="triangle")
