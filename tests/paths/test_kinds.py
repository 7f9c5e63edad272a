"""Beams and SPH particles drawn over the surface (workbench.paths.kinds): visible where they
project, not drawn once deleted, depth-tested against the shells, coloured by part or by the
drawn field through the surface's colour scale; left out with a warning where a path cannot
draw them.

The scene is seen straight down the z axis at 10 pixels per model unit (an orthographic camera
over x, y in [0, 10] on a 100 x 100 image): pixel column = 10 x, row = 100 - 10 y."""

import warnings

import numpy as np
import pytest

from workbench.gl.camera import Camera
from workbench.paths import SoftwareRasterizer, make_path, render
from workbench.paths.kinds import PART_COLORS, KindWarning
from workbench.scene.kinds import Beams, Particles
from workbench.scene.mesh import FEMesh

SIZE = (100, 100)
CAMERA = Camera.fit((5.0, 5.0, 0.0), 5.0, margin=1.0)
BEAM_RGB = tuple(np.round(PART_COLORS[2] * 255).astype(int))  # beams are part 2, unlit
PARTICLE_PART = 3
R_SMALL, R_LARGE = 0.5, 0.8  # particle radii, model units: 5 and 8 pixels


def scene() -> FEMesh:
    """A 4 x 4 shell (part 1) at z = 0; beams (part 2): A at y = 1 and B at y = 3 beside it
    (B deleted at state 1), C above the shell (z = 1) and D below it (z = -1); two particles
    (part 3) of radius 0.5 at (2, 7) and 0.8 at (7, 7) (the second deleted at state 1). State
    1 moves every node by +1 in y."""
    nodes = np.array([
        [0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0],  # shell
        [6, 1, 0.5], [9, 1, 0.5], [6, 3, 0.5], [9, 3, 0.5],  # beams A, B
        [1, 1.5, 1], [3, 1.5, 1], [1, 2.5, -1], [3, 2.5, -1],  # beams C (above), D (below)
        [2, 7, 0], [7, 7, 0]], float)  # particles
    steps = np.stack([nodes, nodes + [0.0, 1.0, 0.0]])
    alive = np.ones((2, 4))
    alive[1, 1] = 0
    beams = Beams(parts=[2, 2, 2, 2], ids=[11, 12, 13, 14],
                  nodes=[[4, 5], [6, 7], [8, 9], [10, 11]],
                  fields={"alive": alive, "stress": np.full(4, 0.25)})
    particles = Particles(parts=[PARTICLE_PART] * 2, ids=[21, 22], node=[12, 13],
                          radius=[R_SMALL, R_LARGE], fields={"alive": [[1, 1], [1, 0]]})
    return FEMesh(nodes, np.array([[0, 1, 2, 3]]), parts=[1], steps=steps,
                  element_fields={"stress": np.array([0.25])}, beams=beams,
                  particles=particles, name="kinds")


def draw(mesh, step, path="flat", **style):
    return render(_ctx, mesh, path, make_path(path, **style).style, CAMERA, SIZE, step=step)


@pytest.fixture(autouse=True)
def _context(ctx):
    global _ctx
    _ctx = ctx


def beam_pixels(image, rows=slice(None), cols=slice(None)) -> int:
    """Pixels of the beams' part colour in the window."""
    window = image[rows, cols, :3].astype(int)
    return int((np.abs(window - BEAM_RGB).sum(axis=-1) == 0).sum())


def particle_mask(image) -> np.ndarray:
    """Pixels of a particle: the part colour (red) shaded by 0.25..1, nothing else is red."""
    rgb = image[..., :3].astype(int)
    return (rgb[..., 0] > rgb[..., 1] + 20) & (rgb[..., 0] > rgb[..., 2] + 20)


def row(y: float) -> int:
    return int(100 - 10 * y)


def disc_count(cx: float, cy: float, r: float) -> tuple[int, int]:
    """(pixel centres within ``r`` pixels of (cx, cy), those within r ± 0.5): the exact
    footprint of a round point sprite of size 2r, and the ring a half-pixel error in its
    centre or size can change."""
    i, j = np.mgrid[0:SIZE[1], 0:SIZE[0]]
    d = np.hypot(j + 0.5 - cx, i + 0.5 - cy)
    return int((d <= r).sum()), int((np.abs(d - r) <= 0.5).sum())


def test_beams_are_drawn_along_their_segments_and_a_deleted_one_is_not():
    mesh = scene()
    first, second = draw(mesh, 0), draw(mesh, 1)
    # A: x 6..9 (columns 60..90) at y = 1 (row 90), then at y = 2 (row 80)
    assert 29 <= beam_pixels(first, row(1) - 1, slice(55, 95)) + \
        beam_pixels(first, row(1), slice(55, 95)) <= 31
    assert beam_pixels(second, slice(row(2) - 1, row(2) + 1), slice(55, 95)) in (30, 31)
    assert beam_pixels(second, slice(row(1) - 2, row(1) + 2), slice(55, 95)) == 0
    # B: drawn at state 0 (y = 3), deleted at state 1: no pixel where it would be (y = 4)
    assert beam_pixels(first, slice(row(3) - 1, row(3) + 1), slice(55, 95)) in (30, 31)
    assert beam_pixels(second, slice(row(4) - 2, row(4) + 2), slice(55, 95)) == 0
    assert beam_pixels(second, slice(row(3) - 2, row(3) + 2), slice(55, 95)) == 0
    # C above the shell is seen over it; D below it is hidden by it (depth test)
    assert beam_pixels(first, slice(row(1.5) - 1, row(1.5) + 1), slice(5, 35)) in (20, 21)
    assert beam_pixels(first, slice(row(2.5) - 1, row(2.5) + 1), slice(5, 35)) == 0
    # in all: A, B and C at state 0; A and C at state 1
    assert beam_pixels(first) in range(80, 84) and beam_pixels(second) in range(50, 53)


def test_particles_cover_the_disc_of_their_projected_radius_and_a_deleted_one_is_gone():
    mesh = scene()
    first, second = draw(mesh, 0), draw(mesh, 1)
    mask0, mask1 = particle_mask(first), particle_mask(second)
    for (x, y, r), window in (((2, 7, R_SMALL), (slice(20, 40), slice(5, 35))),
                              ((7, 7, R_LARGE), (slice(15, 45), slice(55, 85)))):
        expected, ring = disc_count(10 * x, row(y), 10 * r)
        got = int(mask0[window].sum())
        assert abs(got - expected) <= ring // 2, (x, got, expected, ring)
    # state 1: the small one moved to y = 8, the large one deleted
    expected, ring = disc_count(20, row(8), 5)
    assert abs(int(mask1[10:30, 5:35].sum()) - expected) <= ring // 2
    assert mask1[15:45, 55:85].sum() == 0 and mask1[:, 45:].sum() == 0


def test_beams_take_the_drawn_element_field_through_the_surface_scale():
    mesh = scene()
    image = draw(mesh, 0, "element_color", field="stress", value_range=(0.0, 1.0))
    shell = image[row(3.5), 5, :3]  # the shell's colour at 0.25 (lit face-on: unlit colour)
    beam = image[row(1), 70, :3]  # beam A, also 0.25
    assert tuple(beam) == tuple(shell) and tuple(beam) != BEAM_RGB
    # a beam without a value: the no-result colour, pure green
    values = np.full(4, 0.25)
    values[0] = np.nan
    b = mesh.beams
    mesh = FEMesh(mesh.nodes, mesh.elements, mesh.parts, mesh.steps,
                  element_fields=mesh.element_fields, particles=mesh.particles,
                  beams=Beams(parts=b.parts, ids=b.ids, nodes=b.nodes,
                              fields={**b.fields, "stress": values}))
    image = draw(mesh, 0, "element_color", field="stress", value_range=(0.0, 1.0))
    assert tuple(image[row(1), 70, :3]) == (0, 255, 0)


def test_the_software_rasterizer_draws_the_shells_and_names_what_it_leaves_out():
    mesh = scene()
    with pytest.warns(KindWarning, match=r"software rasterizer .* 4 beams and 2 SPH particles "
                                         r"not drawn"):
        image = render(SoftwareRasterizer(), mesh, "flat", make_path("flat").style, CAMERA,
                       SIZE, step=0)
    assert beam_pixels(image) == 0 and particle_mask(image).sum() == 0
    assert (image[row(2), 5:35, :3] != 255).any(axis=-1).all()  # the shell is drawn


def test_a_path_drawing_its_own_way_names_the_kinds_it_leaves_out():
    mesh = scene()
    with pytest.warns(KindWarning, match=r"path 'fe_wire_texture' .* 4 beams and 2 SPH "
                                         r"particles"):
        make_path("fe_wire_texture")._check_scene(mesh)
    two = FEMesh(mesh.nodes, np.array([[0, 1, 2, 3], [0, 1, 2, 2]]), parts=[1, 5],
                 steps=mesh.steps, beams=mesh.beams, particles=mesh.particles)
    with pytest.warns(KindWarning, match=r"path 'exploded' .* 4 beams and 2 SPH particles"):
        render(_ctx, two, "exploded", make_path("exploded", focus=1).style, CAMERA, SIZE,
               step=0)


def test_a_mesh_without_beams_or_particles_draws_as_before():
    mesh = scene()
    bare = FEMesh(mesh.nodes, mesh.elements, mesh.parts, mesh.steps,
                  element_fields=mesh.element_fields)
    with warnings.catch_warnings():
        warnings.simplefilter("error", KindWarning)
        image = draw(bare, 0)
    assert beam_pixels(image) == 0 and particle_mask(image).sum() == 0
    # the surface is the same image with or without them, outside their pixels
    full = draw(mesh, 0)
    same = (full == image).all(axis=-1)
    assert same[row(3.5) - 2:row(3.5) + 2, 2:38].all()


def test_clip_planes_cut_beams_and_remove_particles_whose_centre_they_cut():
    kept = draw(scene(), 0, clip_planes=((-1.0, 0.0, 0.0, 7.5),))  # keep x <= 7.5
    assert beam_pixels(kept, slice(row(1) - 1, row(1) + 1), slice(55, 95)) in (15, 16)
    assert beam_pixels(kept, slice(None), slice(76, None)) == 0
    expected, ring = disc_count(70, row(7), 10 * R_LARGE)  # a point is clipped by its centre
    assert abs(int(particle_mask(kept)[15:45, 55:85].sum()) - expected) <= ring // 2
    cut = draw(scene(), 0, clip_planes=((-1.0, 0.0, 0.0, 6.5),))  # keep x <= 6.5
    assert particle_mask(cut)[15:45, 55:85].sum() == 0
    assert particle_mask(cut)[:, :45].sum() == particle_mask(kept)[:, :45].sum() > 0


def test_a_sort_last_domain_names_the_kinds_it_leaves_out():
    from workbench.paths import prepared

    mesh = scene()
    with prepared(_ctx, mesh, "flat", make_path("flat").style, CAMERA, SIZE, step=0) as ready:
        ready.bind()
        with pytest.warns(KindWarning, match="sort-last domain .* 4 beams and 2 SPH particles"):
            ready.path.draw_triangles(np.arange(ready.path.triangles))


def test_in_perspective_a_particle_covers_its_projected_radius():
    """The point size is twice the projection of one radius along the eye's up axis: the disc
    of that radius around the projected centre, as :meth:`Camera.project` gives them."""
    camera = Camera.fit((5.0, 5.0, 0.0), 5.0, projection="perspective", margin=1.0)
    image = render(_ctx, scene(), "flat", make_path("flat").style, camera, SIZE, step=0)
    centre, edge = camera.project([[7.0, 7.0, 0.0], [7.0, 7.0 + R_LARGE, 0.0]], SIZE)
    radius = float(np.hypot(*(edge[:2] - centre[:2])))
    expected, ring = disc_count(centre[0], centre[1], radius)
    x, y = int(centre[0]), int(centre[1])
    got = int(particle_mask(image)[y - 15:y + 15, x - 15:x + 15].sum())
    assert radius > 6 and abs(got - expected) <= ring // 2, (got, expected, radius)
