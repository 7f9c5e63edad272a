"""Values without a result drawn honestly (the no-result rule of :mod:`workbench.paths.colormap`):
every triangle that has a non-finite value is drawn whole in the no-result colour, on the GL
context and in the software rasterizer, by every path that draws a field.

The scene: a 16 × 16 quad grid over ±0.9 (a gentle cosine bump, so the headlight varies over
it), seen by ``Camera.fit(0, 1, margin=1)`` top down (an element about 5 pixels wide) and
obliquely, with a block of nodes without a value (``f_block``), the nodes of a rigid part
(part 2, the right third: ``f_rigid``, and its elements: ``c_rigid``) and the same fields
with every value (``f``, ``c``). For each path and backend: (a) no pixel of a scale colour in
the pixels of the triangles with a missing value (the region), nor within 2 pixels of the
triangles whose values are all missing; (b) the GL and software images agree as everywhere
else (at most 0.5 % of the pixels, by 1/255 in the region); (c) outside the region the image
is the one of the field without missing values, pixel for pixel. The old behaviour (the
sentinel interpolated) is injected as a fault (:func:`~workbench.paths.colormap.
legacy_mark_missing`) to show that these checks catch it.
"""

from dataclasses import replace

import matplotlib
import numpy as np
import pytest
from scipy import ndimage

from workbench.algo.composite.merge import composite
from workbench.animation.decoration import Decoration
from workbench.distributed.chunked import ChunkedScene, render_chunked, write_chunked
from workbench.gl import Camera
from workbench.measurement.rows import WHITE, default_camera
from workbench.output.figures import field_figure
from workbench.paths import ColorScale, SoftwareRasterizer, Style, colormap, prepared
from workbench.paths.colormap import (
    NO_RESULT_COLOR,
    T_LIMIT,
    constant_range,
    legacy_mark_missing,
    mark_missing,
    missing_count,
    no_result_label,
    no_result_text,
    parts_without_result,
    scale_colour_mask,
    scale_colour_pixels,
)
from workbench.paths.flange import FlangeStyle
from workbench.scene.mesh import FEMesh

SIZE = (96, 96)
N = 16
SOFTWARE = SoftwareRasterizer()
GREEN = np.rint(np.multiply(NO_RESULT_COLOR, 255)).astype(np.uint8)
NODE_RANGE, ELEMENT_RANGE = (-1.4, 1.4), (0.0, float(N * N))
# maps the no-result colour is documented to stay 24/255 away from, lit or not
LISTED_MAPS = ("viridis", "plasma", "inferno", "magma", "cividis", "turbo", "jet", "coolwarm",
               "RdBu", "Spectral", "rainbow", "hot", "gray", "cool", "spring")


def nan_grid(n: int = N) -> FEMesh:
    """The scene of the module docstring."""
    x = np.linspace(-0.9, 0.9, n + 1)
    X, Y = np.meshgrid(x, x)
    nodes = np.stack([X.ravel(), Y.ravel(), (0.25 * np.cos(2 * X) * np.cos(1.5 * Y)).ravel()], 1)
    j, i = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (j * (n + 1) + i).ravel()
    quads = np.stack([a, a + 1, a + n + 2, a + n + 1], 1)
    parts = np.where(i.ravel() >= 2 * n // 3, 2, 1)
    f = nodes[:, 0] + 0.5 * nodes[:, 1]
    ni, nj = np.arange(len(nodes)) % (n + 1), np.arange(len(nodes)) // (n + 1)
    block = f.copy()
    block[(ni >= 4) & (ni <= 8) & (nj >= 5) & (nj <= 10)] = np.nan
    rigid = f.copy()
    only_rigid = np.ones(len(nodes), bool)
    only_rigid[np.unique(quads[parts == 1])] = False
    rigid[only_rigid] = np.nan
    c = np.arange(len(quads), dtype=np.float64)
    c_rigid = np.where(parts == 2, np.nan, c)
    return FEMesh(nodes, quads, parts=parts, name="nan_grid", steps=np.stack([nodes, nodes]),
                  node_fields={"f": f, "f_block": block, "f_rigid": rigid,
                               "f_steps": np.stack([f, block])},
                  element_fields={"c": c, "c_rigid": c_rigid})


@pytest.fixture(scope="module")
def mesh():
    return nan_grid()


def camera(mesh, view):
    if view == "top":
        return Camera.fit(np.zeros(3), 1.0, margin=1.0)
    return default_camera(mesh, SIZE, view=(30.0, 40.0))


def draw(backend, mesh, name, style, cam, *, step=None, after=None):
    """(image, region, core, scale): ``name`` with ``style`` drawn once on white; ``region`` the
    pixels of triangles with a missing value, ``core`` those of triangles whose values are all
    missing (from the software rasterizer's winning triangles: the GL coverage is the same);
    ``after(path)`` runs on the prepared path before the draw."""
    with prepared(backend, mesh, name, style, cam, SIZE, step=step) as ready:
        if after is not None:
            after(ready.path)
        ready.target.clear(WHITE)
        ready.path.draw()
        image = ready.target.read()
        scale = ready.path.scale
    region, core = missing_pixels(mesh, name if name != "flange" else "pixel_color",
                                  style if name != "flange" else
                                  Style(field="part_distance", value_range=scale.value_range),
                                  cam, step)
    return image, region, core, scale


def missing_pixels(mesh, name, style, cam, step=None):
    """(region, core) of :func:`draw`, from a software draw of the same triangle list."""
    style = replace(style, strips="none", wireframe=False)  # the same triangles, listed
    with prepared(SOFTWARE, mesh, name, style, cam, SIZE, step=step) as ready:
        ready.target.clear(WHITE)
        ready.path.draw()
        won = ready.target.frame.triangle.copy()
        data = ready.path.data
    step = data.style.step if step is None else step
    tris = data.triangle_list()
    if data.field_per == "node":
        node = np.arange(mesh.n_nodes) if data.vertex_node is None else data.vertex_node
        bad = ~np.isfinite(mesh.node_field(style.field, step))[node][tris]
        some, every = bad.any(axis=1), bad.all(axis=1)
    else:
        some = every = ~np.isfinite(mesh.element_field(style.field, step))[
            data.triangle_element]
    drawn = won >= 0
    at = np.maximum(won, 0)
    return drawn & some[at], drawn & every[at]


def lit_green(image, region):
    """Whether every pixel of ``region`` is the no-result colour times a light in [0.25, 1]."""
    px = image[region][:, :3].astype(int)
    return bool(((px[:, 0] == 0) & (px[:, 2] == 0) & (px[:, 1] >= 63)).all())


def finite_twin(style):
    """The style drawing the same field with every value."""
    return replace(style, field={"f_block": "f", "f_rigid": "f", "c_rigid": "c"}[style.field])


CASES = [
    ("pixel_color", dict(field="f_block")),
    ("pixel_color", dict(field="f_block", bands=6)),
    ("vertex_color", dict(field="f_block")),
    ("vertex_color", dict(field="f_block", bands=6)),
    ("pixel_color", dict(field="f_block", hide_range=(0.6, 2.0))),
    ("vertex_color", dict(field="f_block", hide_range=(-2.0, -0.3))),
    ("pixel_color", dict(field="f_block", clip_planes=((1.0, 0.0, 0.0, 0.45),))),
    ("pixel_color", dict(field="f_rigid", bands=9, colormap="coolwarm")),
    ("vertex_color", dict(field="f_rigid")),
    ("element_color", dict(field="c_rigid")),
    ("element_color", dict(field="c_rigid", bands=5, hide_range=(0.0, 60.0))),
]


def style_of(options):
    rng = ELEMENT_RANGE if options["field"].startswith("c") else NODE_RANGE
    return Style(value_range=rng, **options)


# --------------------------------------------------------------------------- the colour
def test_the_no_result_colour_is_no_colour_of_the_listed_maps():
    # lit by any factor in [0.25, 1], 24/255 from every lit colour of every listed map
    lights = np.linspace(0.25, 1.0, 61)
    ours = np.rint(lights[:, None] * GREEN)
    for name in LISTED_MAPS:
        lut = matplotlib.colormaps[name].resampled(256)(np.arange(256))[:, :3] * 255
        theirs = np.unique(np.rint(lights[:, None, None] * lut).reshape(-1, 3), axis=0)
        nearest = min(np.abs(theirs - p).max(axis=1).min() for p in ours)
        assert nearest >= 24, f"{name}: the no-result colour within {nearest}/255"
        image = ours.astype(np.uint8)[None]
        assert not scale_colour_mask(image, ColorScale(name)).any()


def test_labels_and_counts(mesh):
    assert no_result_label(1, "node") == "no result: 1 node"
    assert no_result_label(12, "element") == "no result: 12 elements"
    assert no_result_label(3, None) == "no result"
    assert no_result_label(12, "element", [8]) == "no result: 12 elements, part 8"
    assert no_result_label(9, "element", [1, 2, 3, 4, 5]) == \
        "no result: 9 elements, parts 1, 2, 3 +2"
    assert missing_count(mesh, "f_block") == (30, "node")
    assert missing_count(mesh, "f_steps", 0) == (0, "node")
    assert missing_count(mesh, "c_rigid") == (int((mesh.parts == 2).sum()), "element")
    values, missing = mark_missing([0.5, np.nan, np.inf, -1e60, 1e60])
    assert values.tolist() == [0.5, 0.0, 0.0, -T_LIMIT, T_LIMIT]
    assert missing.tolist() == [False, True, True, False, False]


# --------------------------------------------------------------------------- the checker
def test_the_checker_counts_scale_colours_near_a_region():
    scale = ColorScale("viridis", (0.0, 1.0))
    image = np.full((20, 20, 3), 255, np.uint8)
    image[5:15, 5:15] = GREEN // 2  # the region, lit by one half
    region = np.zeros((20, 20), bool)
    region[5:15, 5:15] = True
    assert scale_colour_pixels(image, region, scale, k=3) == 0
    lit = np.rint(0.6 * scale.texture_data()[200, :3]).astype(np.uint8)
    image[5:15, 14] = lit  # a rim inside the region
    image[5:15, 17] = lit  # a rim 3 pixels outside it
    image[0, 0] = lit  # far away
    assert scale_colour_pixels(image, region, scale, k=0) == 10
    assert scale_colour_pixels(image, region, scale, k=2) == 10
    assert scale_colour_pixels(image, region, scale, k=3) == 20
    assert scale_colour_mask(image, scale).sum() == 21
    with pytest.raises(ValueError, match="region"):
        scale_colour_pixels(image, region[1:], scale)
    with pytest.raises(ValueError, match="k must"):
        scale_colour_pixels(image, region, scale, k=-1)


# --------------------------------------------------------------------------- paths and backends
@pytest.mark.parametrize("name,options", CASES)
@pytest.mark.parametrize("view", ["top", "oblique"])
def test_missing_values_are_drawn_in_the_no_result_colour(ctx, mesh, name, options, view):
    cam = camera(mesh, view)
    style = style_of(options)
    images = {}
    for label, backend in (("gl", ctx), ("software", SOFTWARE)):
        image, region, core, scale = draw(backend, mesh, name, style, cam)
        assert region.sum() > 100 and core.any()
        # (a) no scale colour in the region or within 2 pixels of the wholly missing triangles
        assert scale_colour_pixels(image, region, scale, k=0) == 0, label
        if name != "element_color" and view == "top":
            # seen from the top the ring of triangles around the wholly missing ones is wider
            # than 2 pixels (obliquely, and next to a missing element, 2 pixels may reach a
            # neighbour with a value of its own)
            ring = ndimage.binary_dilation(core, np.ones((5, 5), bool))
            assert not (ring & (image != 255).any(axis=-1) & ~region).any()
            assert scale_colour_pixels(image, core, scale, k=2) == 0, label
        assert lit_green(image, region), label
        # (c) elsewhere the image of the field with every value, pixel for pixel
        twin, *_ = draw(backend, mesh, name, finite_twin(style), cam)
        assert not lit_green(twin, region)
        assert np.array_equal(image[~region], twin[~region]), label
        images[label] = image
    # (b) GL and software agree as they do without missing values
    differ = (images["gl"] != images["software"]).any(axis=-1)
    assert differ.mean() <= 0.005, f"{100 * differ.mean():.2f} % differ"
    assert np.abs(images["gl"][region].astype(int) - images["software"][region]).max() <= 1


def test_the_legacy_sentinel_is_caught(ctx, mesh, monkeypatch):
    # the fault the stress suite injects: the old sentinel interpolated, no flag
    cam = camera(mesh, "top")
    style = style_of(dict(field="f_block"))
    monkeypatch.setattr(colormap, "mark_missing", legacy_mark_missing)
    for backend in (ctx, SOFTWARE):
        for name in ("pixel_color", "vertex_color"):
            image, region, core, scale = draw(backend, mesh, name, style, cam)
            assert scale_colour_pixels(image, region, scale, k=0) > 0
            assert scale_colour_pixels(image, core, scale, k=2) > 0


# --------------------------------------------------------------------------- strips, domains, steps
@pytest.mark.parametrize("strips", ["triangle", "quad"])
def test_strips_flag_the_same_triangles(ctx, mesh, strips):
    cam = camera(mesh, "oblique")
    style = style_of(dict(field="f_block", strips=strips, quad_diagonal="strip"))
    image, region, _, scale = draw(ctx, mesh, "pixel_color", style, cam)
    listed, *_ = draw(ctx, mesh, "pixel_color", replace(style, strips="none"), cam)
    assert scale_colour_pixels(image, region, scale, k=0) == 0 and lit_green(image, region)
    assert np.array_equal(image, listed)


@pytest.mark.parametrize("name,field", [("pixel_color", "f_block"),
                                        ("vertex_color", "f_rigid"),
                                        ("element_color", "c_rigid")])
def test_domains_draw_the_whole_image(ctx, mesh, name, field, tmp_path):
    """Sort-last: GL domains (``draw_triangles``), software domains (``render_triangles``)
    and a chunked scene each give the one-draw image, no-result colour included."""
    cam = camera(mesh, "oblique")
    style = style_of(dict(field=field))
    whole_gl, region, _, _ = draw(ctx, mesh, name, style, cam)
    whole_sw, *_ = draw(SOFTWARE, mesh, name, style, cam)
    with prepared(ctx, mesh, name, style, cam, SIZE) as ready:
        n = ready.path.triangles
        halves = [np.arange(0, n // 2), np.arange(n // 2, n)]
        ready.target.clear(WHITE)
        for ids in halves:
            ready.path.draw_triangles(ids)
        assert np.array_equal(ready.target.read(), whole_gl)
    with prepared(SOFTWARE, mesh, name, style, cam, SIZE) as ready:
        frames = [ready.path.render_triangles(ids) for ids in halves]
        assert np.array_equal(composite(*frames).color, whole_sw)
        folder = write_chunked(ready.path, halves, tmp_path / "scene")
        flagged = no_result_triangles(mesh, ready.path)
    scene = ChunkedScene(folder)
    assert np.array_equal(render_chunked(scene, cam, SIZE).color, whole_sw)
    assert lit_green(whole_sw, region)
    assert scene.no_result == flagged > 0


def no_result_triangles(mesh, path):
    """Triangles of a prepared software ``path`` with a missing value."""
    data = path.data
    if data.field_per == "element":
        return int((~np.isfinite(mesh.element_field(data.style.field))[
            data.triangle_element]).sum())
    node = np.arange(mesh.n_nodes) if data.vertex_node is None else data.vertex_node
    bad = ~np.isfinite(mesh.node_field(data.style.field))[node]
    return int(bad[data.triangle_list()].any(axis=1).sum())


@pytest.mark.parametrize("backend", ["gl", "software"])
def test_a_missing_set_that_changes_with_the_step(ctx, mesh, backend):
    backend = ctx if backend == "gl" else SOFTWARE
    cam = camera(mesh, "top")
    style = style_of(dict(field="f_steps"))
    finite, *_ = draw(backend, mesh, "pixel_color", replace(style, field="f"), cam)
    region, _ = missing_pixels(mesh, "pixel_color", replace(style, field="f_block"), cam)
    with prepared(backend, mesh, "pixel_color", style, cam, SIZE) as ready:
        images = []
        for step in (0, 1, 0):
            ready.path.set_step(step)
            ready.target.clear(WHITE)
            ready.path.draw()
            images.append(ready.target.read())
            assert ready.path.missing_values == (30 if step else 0)
    assert np.array_equal(images[0], finite) and np.array_equal(images[2], finite)
    assert lit_green(images[1], region)
    assert np.array_equal(images[1][~region], finite[~region])


def test_flange_distance_map_draws_far_nodes_without_a_value(ctx):
    # a plate at z = 0 over x 0..100, a second 1 mm above over x 0..20: beyond the cutoff of
    # 30 mm the plate's nodes have no distance, and their triangles no colour of the map
    from meshes import quad_grid

    a, b = quad_grid(20, 4, span=((0, 100), (0, 20)), z=0.0), \
        quad_grid(4, 4, span=((0, 20), (0, 20)), z=1.0)
    plates = FEMesh(np.concatenate([a[0], b[0]]), np.concatenate([a[1], b[1] + len(a[0])]),
                    parts=np.repeat([0, 1], [len(a[1]), len(b[1])]), name="plates")
    cam = default_camera(plates, SIZE, view=(0.0, 90.0))
    image, region, core, scale = draw(ctx, plates, "flange",
                                      FlangeStyle(show="distance", cutoff=30.0), cam)
    assert region.sum() > 500 and core.any()
    assert scale_colour_pixels(image, region, scale, k=0) == 0
    assert scale_colour_pixels(image, core, scale, k=2) == 0
    assert lit_green(image, region)


# --------------------------------------------------------------------------- extreme values
def test_constant_and_extreme_ranges():
    assert constant_range(7.0) == (7.0, 8.0)
    lo, hi = constant_range(1e30)
    assert lo == 1e30 and hi > lo
    lo, hi = constant_range(-1e30)
    assert lo == -1e30 and hi > lo
    lo, hi = constant_range(1.7e308)
    assert np.isfinite(lo) and lo < hi == 1.7e308
    with pytest.raises(ValueError, match="finite"):
        constant_range(np.nan)
    scale = ColorScale("viridis", (-1e308, 1e308))
    assert np.allclose(scale.normalise([-1e308, 0.0, 1e308]), [0.0, 0.5, 1.0])
    assert np.isfinite(scale.texel_values()).all()


def extreme_mesh():
    """The grid with fields of extreme magnitudes, each beside its twin of ordinary ones (the
    same normalised values) where it has one."""
    mesh = nan_grid()
    x = mesh.nodes[:, 0]
    mesh.node_fields.update({
        "constant": np.full(len(x), 1e30), "seven": np.full(len(x), 7.0),
        "tiny": 1e-30 * (x + 1.0), "x+1": x + 1.0,
        "vast": x * 1e300, "x": x,
        "wide": np.sign(x) * 10.0 ** (30 * np.abs(x) / 0.9)})  # −1e30 … 1e30
    return mesh


TWINS = {"constant": "seven", "tiny": "x+1", "vast": "x"}


@pytest.mark.parametrize("field,value_range", [("constant", None), ("tiny", None),
                                               ("vast", None), ("wide", None),
                                               ("wide", (0.0, 1e-30))])
@pytest.mark.parametrize("name", ["pixel_color", "vertex_color"])
def test_extreme_values_draw_scale_colours_alike(ctx, name, field, value_range):
    # constant fields, magnitudes 1e-30 … 1e300, values 1e60 ranges beyond the scale: every
    # pixel a scale colour (the vertex path's blends of distant colours aside), none in the
    # no-result colour, the image of the ordinary twin where there is one, GL and software
    # alike (a scale of (0, 1e-30) put t = 1e60 into float32 and llvmpipe's texel addressing)
    mesh = extreme_mesh()
    cam = camera(mesh, "top")
    style = Style(field=field, value_range=value_range)
    images = []
    for backend in (ctx, SOFTWARE):
        image, region, _, scale = draw(backend, mesh, name, style, cam)
        covered = (image != 255).any(axis=-1)
        assert not region.any() and covered.sum() > 0.5 * covered.size
        assert not (image[..., :3] == GREEN).all(axis=-1).any()
        if name == "pixel_color":
            assert scale_colour_mask(image, scale)[covered].all()
        if field in TWINS:
            twin, *_ = draw(backend, mesh, name, replace(style, field=TWINS[field]), cam)
            assert np.array_equal(image, twin)
        images.append(image)
    # by 1/255 on at most 1 % of the pixels: the shading's rounding on this small image (the
    # ordinary field x differs on 0.95 % of them)
    differ = (images[0] != images[1]).any(axis=-1)
    assert differ.mean() <= 0.01 and np.abs(images[0].astype(int) - images[1]).max() <= 1


# --------------------------------------------------------------------------- legends
def bar_column_green(image, left):
    return int((image[:, left:, :3] == GREEN).all(axis=-1).sum())


def test_the_legend_names_the_parts_without_any_result(mesh):
    # part 2 has no value of c_rigid at all; f_block lacks values in a block of nodes only
    # (both parts keep some); f_rigid has values at the nodes part 2 shares with part 1, but
    # every element of part 2 has a node without one, so it is drawn without a result
    assert parts_without_result(mesh, "c_rigid") == [2]
    assert parts_without_result(mesh, "f_rigid") == [2]
    assert parts_without_result(mesh, "f_block") == []
    n = int((mesh.parts == 2).sum())
    assert no_result_text(mesh, "c_rigid") == f"no result: {n} elements, part 2"
    assert no_result_text(mesh, "c") is None
    # a deleted element of part 2 with a value does not give part 2 a result
    values = mesh.element_fields["c_rigid"].copy()
    first = int(np.flatnonzero(mesh.parts == 2)[0])
    values[first] = 1.0
    alive = np.ones(mesh.n_elements)
    alive[first] = 0.0
    eroded = FEMesh(mesh.nodes, mesh.elements, mesh.parts,
                    element_fields={"c_rigid": values, "alive": alive})
    assert parts_without_result(eroded, "c_rigid") == [2]
    alive[first] = 1.0
    assert parts_without_result(FEMesh(mesh.nodes, mesh.elements, mesh.parts, element_fields={
        "c_rigid": values, "alive": alive}), "c_rigid") == []


def test_the_colour_bar_states_the_no_result_colour():
    image = np.full((100, 120, 4), 255, np.uint8)
    for text in (None, "no result: 30 nodes"):
        fig = field_figure(image, value_range=(0.0, 1.0), colormap="viridis", label="f",
                           units="mm", no_result=text)
        fig.canvas.draw()
        drawn = np.asarray(fig.canvas.buffer_rgba())
        texts = [t.get_text() for t in fig.texts]
        green = bar_column_green(drawn, drawn.shape[1] - 140)
        if text is None:
            assert green == 0 and not any("no result" in t for t in texts)
        else:
            assert green > 50 and "no result:\n30 nodes" in texts


def test_animation_frames_state_their_missing_values(ctx, mesh):
    from workbench.animation.frames import FrameLoop

    loop = FrameLoop(ctx, mesh, "pixel_color", style_of(dict(field="f_steps")), steps=[0, 1],
                     size=SIZE)
    frames = list(loop)
    assert [f.no_result for f in frames] == [None, "no result: 30 nodes"]
    decorate = Decoration("nan_grid", "f_steps", "mm")
    left = decorate.bar_box(SIZE).left
    assert bar_column_green(decorate(frames[0]), left) == 0
    assert bar_column_green(decorate(frames[1]), left) > 50


def test_a_rendered_png_states_the_no_result_colour(ctx, mesh, tmp_path):
    # ``workbench render``'s writer: the bar states the count of the step drawn, or nothing
    from types import SimpleNamespace

    from PIL import Image

    from workbench.cli.render_image import write_image

    image, *_ = draw(ctx, mesh, "pixel_color", style_of(dict(field="f_steps")), camera(mesh, "top"))
    path = SimpleNamespace(scale=ColorScale("viridis", NODE_RANGE), style=Style(field="f_steps"))
    for step, expected in ((0, False), (1, True)):
        args = SimpleNamespace(raw=False, units="", bands=0, step=step)
        out = tmp_path / f"step{step}.png"
        write_image(out, image, path, "f_steps", args, "nan_grid", scene=mesh)
        png = np.asarray(Image.open(out).convert("RGB"))
        assert (bar_column_green(png, png.shape[1] - 140) > 50) == expected


def test_chunked_scenes_of_the_sentinel_are_read_without_a_value(mesh, tmp_path):
    # a scene written before NaN was kept holds −1e30 where a node has no value
    import pyarrow as pa
    import pyarrow.parquet as pq

    from workbench.algo.softraster import Shading

    assert Shading().missing_color == NO_RESULT_COLOR
    cam = camera(mesh, "top")
    with prepared(SOFTWARE, mesh, "pixel_color", style_of(dict(field="f_block")), cam,
                  SIZE) as ready:
        folder = write_chunked(ready.path, [np.arange(ready.path.triangles)], tmp_path / "s")
    file = folder / "domain-00000" / "vertices.parquet"
    table = pq.read_table(file)
    values = table.column("value").to_numpy()
    assert np.isnan(values).any()
    old = table.set_column(table.column_names.index("value"), "value",
                           pa.array(np.where(np.isnan(values), colormap.NO_VALUE, values)))
    before = render_chunked(ChunkedScene(folder), cam, SIZE).color
    pq.write_table(old, file)
    loaded = ChunkedScene(folder).load(0).values
    assert np.array_equal(np.isnan(loaded), np.isnan(values))
    assert np.array_equal(render_chunked(ChunkedScene(folder), cam, SIZE).color, before)
