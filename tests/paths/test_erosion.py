"""Erosion: elements deleted part-way (the ``"alive"`` element field a d3plot gives) are not
drawn at the states where they are deleted, and the colour range is set by live elements only.

The reference is independent of the per-step index subset: the same mesh with the deleted
elements removed (``FEMesh.subset``), drawn with the same camera and colour scale, must give
the same image pixel for pixel; and the scene is built so that drawing the deleted elements
changes the picture (the fault the subset exists to prevent), which the test checks too."""

import itertools

import numpy as np
import pytest

from workbench.measurement.rows import default_camera
from workbench.paths import SoftwareRasterizer, make_path, render
from workbench.scene.mesh import FEMesh

SIZE = (64, 48)
NX, NY = 6, 4
DELETED = [3, 4, 9, 10, 16]  # a tear through the middle of the plate at state 1
FAILURE = 10.0  # the value a deleted element keeps: far above every live value (<= 1)


def plate() -> FEMesh:
    """A NX x NY quad plate in two parts, two states (the second lifted by 1 mm), an element
    field ``stress`` whose deleted elements hold the failure value, a node field ``u``."""
    x, y = np.meshgrid(np.arange(NX + 1, dtype=float), np.arange(NY + 1, dtype=float))
    nodes = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    quads = [[j * (NX + 1) + i, j * (NX + 1) + i + 1, (j + 1) * (NX + 1) + i + 1,
              (j + 1) * (NX + 1) + i] for j in range(NY) for i in range(NX)]
    m = len(quads)
    alive = np.ones((2, m))
    alive[1, DELETED] = 0
    stress = np.linspace(0.0, 1.0, m)[None, :].repeat(2, axis=0)
    stress[1, DELETED] = FAILURE
    steps = np.stack([nodes, nodes + [0.0, 0.0, 1.0]])
    return FEMesh(nodes, np.array(quads), parts=np.repeat([1, 2], m // 2), steps=steps,
                  element_fields={"alive": alive, "stress": stress},
                  node_fields={"u": np.linspace(0.0, 2.0, len(nodes))[None, :].repeat(2, 0)},
                  name="plate")


def test_the_mesh_says_which_elements_nodes_and_edges_are_in_use():
    mesh = plate()
    assert mesh.erodes and mesh.alive(0).all()
    assert np.flatnonzero(~mesh.alive(1)).tolist() == DELETED
    assert mesh.deleted_count(0) == {} and mesh.deleted_count(1) == {1: 4, 2: 1}
    live = [e for i, e in enumerate(mesh.elements.tolist()) if i not in DELETED]
    used = {n for e in live for n in e}
    assert set(np.flatnonzero(mesh.live_nodes(1)).tolist()) == used
    pairs = {tuple(sorted((e[k], e[(k + 1) % 4]))) for e in live for k in range(4)}
    got = {tuple(r) for r, keep in zip(mesh.edges.tolist(), mesh.live_edges(1)) if keep}
    assert got == pairs and mesh.live_edges(0).all()
    # no "alive" field, or one without a 0: nothing erodes
    quiet = FEMesh(mesh.nodes, mesh.elements, element_fields={"alive": np.ones(len(live) + 5)})
    assert not quiet.erodes and quiet.alive().all() and quiet.deleted_count() == {}


def test_the_colour_range_comes_from_live_elements_only():
    mesh = plate()
    stress, alive = mesh.element_fields["stress"], mesh.element_fields["alive"]
    assert mesh.field_range("stress") == (0.0, float(stress[alive != 0].max()))
    assert mesh.field_range("stress")[1] <= 1.0 < FAILURE
    u, used = mesh.node_fields["u"], np.stack([mesh.live_nodes(0), mesh.live_nodes(1)])
    assert mesh.field_range("u") == (float(u[used].min()), float(u[used].max()))
    static = FEMesh(mesh.nodes, mesh.elements, steps=mesh.steps,
                    element_fields={"alive": mesh.element_fields["alive"],
                                    "s": np.arange(mesh.n_elements, dtype=float)})
    assert static.field_range("s") == (0.0, float(mesh.n_elements - 1))  # live at state 0


CASES = [("flat", {}), ("element_color", {"field": "stress", "bands": 4}),
         ("pixel_color", {"field": "u", "bands": 5}), ("flat", {"wireframe": True})]


@pytest.mark.parametrize("backend, case", list(itertools.product(["gl", "software"], CASES)))
def test_a_deleted_element_is_not_drawn(ctx, backend, case):
    path, style = case
    if backend == "software" and style.get("wireframe"):
        pytest.skip("the software rasterizer draws no wire frame")
    mesh = plate()
    drawer = ctx if backend == "gl" else SoftwareRasterizer()
    camera = default_camera(mesh, SIZE)
    fixed = {**style, "value_range": (0.0, 2.0)} if "field" in style else style
    image = render(drawer, mesh, path, make_path(path, **fixed).style, camera, SIZE, step=1)
    live = mesh.subset(mesh.alive(1))
    live.element_fields.pop("alive")
    expected = render(drawer, live, path, make_path(path, **fixed).style, camera, SIZE,
                      step=1)
    np.testing.assert_array_equal(image, expected)
    # the fault: with every element drawn, the tear is covered
    whole = FEMesh(mesh.nodes, mesh.elements, mesh.parts, mesh.steps,
                   node_fields=mesh.node_fields,
                   element_fields={"stress": mesh.element_fields["stress"]}, name="whole")
    drawn = render(drawer, whole, path, make_path(path, **fixed).style, camera, SIZE, step=1)
    assert (drawn != image).any(axis=-1).sum() >= 20
    # and at state 0, where nothing is deleted, everything is drawn
    np.testing.assert_array_equal(
        render(drawer, mesh, path, make_path(path, **fixed).style, camera, SIZE, step=0),
        render(drawer, whole, path, make_path(path, **fixed).style, camera, SIZE, step=0))


def test_strips_of_an_eroding_mesh_say_they_draw_the_deleted_elements(ctx):
    from workbench.paths.mesh import ErosionWarning

    with pytest.warns(ErosionWarning, match="deletes 5 elements.*'flat' draws strips.*"
                                            "strips='none'"):
        render(ctx, plate(), "flat", make_path("flat", strips="quad").style, size=SIZE)


@pytest.mark.parametrize("backend", ["gl", "software"])
def test_a_sort_last_domain_draws_no_deleted_element(ctx, backend):
    """Domains of the triangle list (every triangle, in two halves, as sort-last draws them):
    the deleted elements' triangles leave no pixel, the live ones draw the live mesh's image."""
    from workbench.paths import prepared

    mesh = plate()
    drawer = ctx if backend == "gl" else SoftwareRasterizer()
    style = make_path("flat").style
    camera = default_camera(mesh, SIZE)
    live = mesh.subset(mesh.alive(1))
    live.element_fields.pop("alive")
    expected = render(drawer, live, "flat", style, camera, SIZE, step=1)
    covered = (expected[..., :3] != 255).any(axis=-1)
    dead_triangles = np.flatnonzero(~mesh.alive(1)[mesh.triangulation.element_of])
    with prepared(drawer, mesh, "flat", style, camera, SIZE, step=1) as ready:
        path, n = ready.path, ready.path.triangles
        if backend == "software":
            frame = path.render_triangles(np.arange(n))
            seen = np.unique(frame.triangle[frame.triangle >= 0])
            assert len(seen) and not np.isin(seen, dead_triangles).any()
            np.testing.assert_array_equal(frame.color, expected)
            return
        ready.bind()
        ready.target.clear((1.0, 1.0, 1.0, 1.0))
        ids = np.r_[np.arange(1, n, 2), np.arange(0, n, 2)]  # the halves, interleaved order
        path.draw_triangles(ids)
        image = ready.target.read()
        np.testing.assert_array_equal(image, expected)
        shown = (image[..., :3] != 255).any(axis=-1)
        assert shown.sum() == covered.sum() > 0


def test_ghost_draws_deleted_elements_translucent_over_the_live_ones(ctx):
    """``deleted="ghost"``: where only a deleted element lies, the pixel is base_color at
    GHOST_ALPHA over the white background (to the 8-bit rounding: 1 of 255); the live
    elements' pixels are the hidden image's. The software rasterizer refuses it."""
    from workbench.paths.style import GHOST_ALPHA

    mesh = plate()
    camera = default_camera(mesh, SIZE)
    hidden = render(ctx, mesh, "flat", make_path("flat").style, camera, SIZE, step=1)
    ghost_style = make_path("flat", deleted="ghost").style
    ghost = render(ctx, mesh, "flat", ghost_style, camera, SIZE, step=1)
    whole = FEMesh(mesh.nodes, mesh.elements, mesh.parts, mesh.steps, name="whole")
    every = render(ctx, whole, "flat", make_path("flat").style, camera, SIZE, step=1)
    covered = (hidden[..., :3] != 255).any(axis=-1)
    tear = (every[..., :3] != 255).any(axis=-1) & ~covered
    assert tear.sum() >= 20
    expected = 255 * (GHOST_ALPHA * np.array(ghost_style.base_color) + (1 - GHOST_ALPHA))
    assert np.abs(ghost[tear][:, :3] - expected).max() <= 1.0
    same = (ghost == hidden).all(axis=-1)
    assert same[covered].mean() >= 0.95  # all but the pixels where a ghost edge overlaps
    assert not same[tear].any()
    with pytest.raises(ValueError, match="ghost.*GL only"):
        render(SoftwareRasterizer(), mesh, "flat", ghost_style, camera, SIZE, step=1)
    with pytest.raises(ValueError, match="deleted must be one of"):
        make_path("flat", deleted="fade")


@pytest.mark.parametrize("backend", ["gl", "software"])
def test_a_d3plot_shell_deleted_at_the_last_state_is_not_drawn_there(ctx, tmp_path, backend):
    """The d3plot reader's ``alive`` field, written by lasso-python (two shells, the triangle
    deleted at state 2): at state 2 the image is the live shell's alone, at state 1 both."""
    from meshes import write_d3plot

    from workbench.scene.readers import load

    mesh = load(write_d3plot(tmp_path))
    assert mesh.deleted_count(2) == {9: 1} and mesh.deleted_count(1) == {}
    drawer = ctx if backend == "gl" else SoftwareRasterizer()
    camera = default_camera(mesh, SIZE)
    style = make_path("element_color", field="plastic_strain", value_range=(0.0, 0.05)).style
    for k in (1, 2):
        live = mesh.subset(mesh.alive(k))
        live.element_fields.pop("alive")
        image = render(drawer, mesh, "element_color", style, camera, SIZE, step=k)
        np.testing.assert_array_equal(
            image, render(drawer, live, "element_color", style, camera, SIZE, step=k))
        covered = (image[..., :3] != 255).any(axis=-1).sum()
        if k == 1:
            both = covered
    assert 0 < covered < both  # the triangle's pixels are gone at state 2


def test_render_show_deleted_ghost_on_the_command_line(ctx, tmp_path):
    from meshes import write_d3plot
    from PIL import Image

    from workbench.cli import main

    source = write_d3plot(tmp_path)
    images = {}
    for how in ("hide", "ghost"):
        out = tmp_path / f"{how}.png"
        assert main(["render", str(source), "--step", "2", "--size", "64x48", "--raw",
                     "--path", "flat", "--show-deleted", how, "-o", str(out)]) == 0
        images[how] = np.asarray(Image.open(out))
    changed = (images["hide"] != images["ghost"]).any(axis=-1)
    assert changed.sum() >= 20  # the deleted triangle, translucent
    assert (images["hide"][changed][:, :3] == 255).all()  # where nothing was drawn before


def test_the_exploded_path_hides_deleted_elements_and_keeps_its_parts(ctx):
    """Exploded (parts drawn as ranges of a part-sorted list): the deleted elements' pixels
    are background at the eroded state, every other pixel is the uneroded image's; ghost is
    refused there."""
    mesh = plate()
    whole = FEMesh(mesh.nodes, mesh.elements, mesh.parts, mesh.steps, name="whole")
    camera = default_camera(mesh, SIZE)
    style = make_path("exploded", focus=1).style
    eroded = render(ctx, mesh, "exploded", style, camera, SIZE, step=1)
    every = render(ctx, whole, "exploded", style, camera, SIZE, step=1)
    flat_live = render(ctx, mesh, "flat", make_path("flat").style, camera, SIZE, step=1)
    tear = ((every[..., :3] != 255).any(axis=-1)
            & (flat_live[..., :3] == 255).all(axis=-1))
    assert tear.sum() >= 20 and (eroded[tear] == 255).all()
    same = (eroded == every).all(axis=-1)
    assert same[~tear].mean() >= 0.98  # all but pixels on the tear's edges
    with pytest.raises(ValueError, match="exploded path hides deleted elements"):
        render(ctx, mesh, "exploded", make_path("exploded", focus=1, deleted="ghost").style,
               camera, SIZE, step=1)


def test_the_fe2003_texture_path_says_it_draws_deleted_elements(ctx):
    from workbench.paths.mesh import ErosionWarning

    mesh = plate()
    mesh.element_fields["alive"][0, 3] = 0  # deleted at the state the path draws
    with pytest.warns(ErosionWarning, match="deletes 1 elements at step 0.*'fe_wire_texture' "
                                            "draws one simplified surface"):
        render(ctx, mesh, "fe_wire_texture", size=SIZE)


def test_a_still_names_its_state_time_and_deleted_elements():
    from workbench.cli.render import still_title

    mesh = plate()
    assert still_title(mesh, "flat", 0) == "plate (flat), state 0"
    mesh.times = np.array([0.0, 2.5e-3])
    assert still_title(mesh, "flat", 1) == "plate (flat), state 1, t = 0.0025, deleted: 5"
    static = FEMesh(mesh.nodes, mesh.elements, name="static")
    assert still_title(static, "gouraud", 0) == "static (gouraud)"


def test_a_state_that_keeps_the_deleted_elements_sends_no_index(ctx):
    """The index is written only where the elements in use change, and then only the changed
    triangles: a state deleting what the state drawn before deleted sends the coordinates
    alone, and every state, in any order (elements deleted and given back), draws the image of
    a fresh preparation at that state."""
    from workbench.animation.frames import draw_frames
    from workbench.paths import prepared

    mesh = plate()
    steps = np.concatenate([mesh.steps, mesh.steps[1:] + [0.0, 0.0, 0.5]])
    alive = mesh.element_fields["alive"][[0, 1, 1]]
    mesh = FEMesh(mesh.nodes, mesh.elements, mesh.parts, steps,
                  element_fields={"alive": alive}, name="plate")
    camera = default_camera(mesh, SIZE)
    order = [0, 1, 2, 0, 2, 1]

    def fresh(step):
        return render(ctx, mesh, "flat", make_path("flat", wireframe=True).style, camera,
                      SIZE, step=step)

    with prepared(ctx, mesh, "flat", make_path("flat", wireframe=True).style, camera,
                  SIZE) as ready:
        images, sent = [], []
        for step in order:
            drawn = next(draw_frames(ready, [step], update=ready.path.set_step))
            images.append(drawn.image)
            sent.append(drawn.sent)
    for step, image in zip(order, images):
        np.testing.assert_array_equal(image, fresh(step))
    coordinates = mesh.n_nodes * 3 * 4
    assert sent[2] == coordinates  # 1 -> 2: the same elements deleted, no index
    # where the elements in use change, the 10 triangles of the 5 torn quads, 12 bytes each,
    # made degenerate (0 -> 1, 0 -> 2) or given back (2 -> 0) in place, and the wire frame's
    # edges (8 bytes each) written whole, the live ones first
    triangles, edges = 12 * 2 * len(DELETED), 8 * len(mesh.edges)
    assert sent[1] == sent[3] == sent[4] == coordinates + triangles + edges
