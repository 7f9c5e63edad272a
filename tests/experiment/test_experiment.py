"""Measurement harness: image error, tables, timing, registry, figures, pyrender reference."""

import ctypes
import math
import tempfile
from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.experiment import EXPERIMENTS, discover, experiment, run_experiment
from workbench.experiment.registry import clean_dead_runs
from workbench.gl import Camera, Framebuffer, create_context
from workbench.gl.context import egl, keeping_current, timer_queries_meaningful
from workbench.measurement.images import compare_images, coverage, difference_map
from workbench.measurement.rows import measure
from workbench.measurement.timing import Timing, time_call, time_draw
from workbench.output import tables as tables_module
from workbench.output.figures import MIN_PANEL_HEIGHT, save_field_figure, save_image_grid, save_png
from workbench.output.tables import atomic_write_text, markdown_table, read_table, write_table
from workbench.paths import RenderPath
from workbench.references.pyrender import PyrenderReference

# the workbench paths' lighting: colour · (0.25 + 0.75 |n·l|), headlight along the view direction
VERT = """#version 330
uniform mat4 mvp;
in vec3 position;
in vec3 normal;
out vec3 v_normal;
void main() { v_normal = normal; gl_Position = mvp * vec4(position, 1.0); }
"""
FRAG = """#version 330
uniform vec3 light;
uniform vec3 base;
in vec3 v_normal;
out vec4 color;
void main() {
    float lit = 0.25 + 0.75 * abs(dot(normalize(v_normal), light));
    color = vec4(base * lit, 1.0);
}
"""
BASE = (0.9, 0.4, 0.1)


@pytest.fixture(scope="module")
def ctx():
    return create_context()


@dataclass
class Quad:
    """The scene of :class:`QuadDraw`: four corners and their normals."""

    corners: np.ndarray
    normals: np.ndarray
    name: str = "quad"
    kind = "quad"

    def bounds(self):
        return self.corners.min(axis=0), self.corners.max(axis=0)


class QuadDraw(RenderPath):
    """A lit quad as a tiny render path, kept out of the registry: ``prepare(ctx, Quad,
    camera)`` makes the GL objects once, ``draw()`` draws into the bound target."""

    needs = frozenset()

    def __init__(self):
        super().__init__()
        self.name = "test quad"
        self._objects = []

    def prepare(self, ctx, scene, camera):
        corners, normals = scene.corners, scene.normals
        self.ctx = ctx
        self.prog = ctx.program(vertex_shader=VERT, fragment_shader=FRAG)
        self.set_camera(camera)
        self.prog["base"].value = BASE
        order = [0, 1, 2, 0, 2, 3]
        data = np.c_[camera.relative(corners)[order], np.asarray(normals, np.float32)[order]]
        self.vbo = ctx.buffer(data.astype(np.float32).tobytes())
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "3f 3f", "position", "normal")])
        self._objects = [self.vao, self.vbo, self.prog]
        self.triangles, self.vertices, self.vertices_sent = 2, 6, 6
        self.bytes_uploaded = data.nbytes

    def set_camera(self, camera):
        self.prog["mvp"].write(camera.mvp_bytes())
        light = np.asarray(camera.eye) - np.asarray(camera.target)
        self.prog["light"].value = tuple(light / np.linalg.norm(light))

    def set_step(self, step):
        return 0

    def draw(self):
        self.ctx.disable(self.ctx.CULL_FACE)
        self.vao.render()

    def release(self):
        for obj in self._objects:
            obj.release()
        self._objects = []


def quad_path(ctx, camera, corners, normals) -> QuadDraw:
    """A prepared :class:`QuadDraw` of the quad."""
    path = QuadDraw()
    path.prepare(ctx, Quad(corners, normals), camera)
    return path


def quad(offset=0.0):
    """A 1 × 0.75 quad facing +Z near ``offset`` and an orthographic camera (64 × 48 pixels)
    whose pixel edges fall on the quad's edges; normals tilt outwards so shading varies."""
    o = np.array([offset, -offset, offset])
    corners = o + np.array([[-0.5, -0.25, 0], [0.5, -0.25, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]])
    tilt = corners - o
    normals = np.c_[1.2 * tilt[:, :2], np.ones(4)]
    return o, corners, normals / np.linalg.norm(normals, axis=1, keepdims=True)


# ---------------------------------------------------------------- image comparison


def synthetic(h=24, w=32, seed=0, opaque=False):
    image = np.random.default_rng(seed).integers(0, 256, (h, w, 4), dtype=np.uint8)
    if opaque:
        image[..., 3] = 255
    return image


def test_identical_images_compare_perfect():
    a = synthetic()
    d = compare_images(a, a.copy())
    assert (d.max_abs, d.mean_abs, d.share_differing) == (0, 0.0, 0.0)
    assert d.psnr == math.inf and d.ssim == 1.0


def test_one_changed_pixel_is_counted_exactly():
    a = synthetic()
    b = a.copy()
    b[5, 7, 1] = a[5, 7, 1] - 7 if a[5, 7, 1] >= 7 else a[5, 7, 1] + 7
    d = compare_images(a, b)
    h, w = a.shape[:2]
    assert d.max_abs == 7
    assert d.share_differing == pytest.approx(1 / (h * w))
    assert d.mean_abs == pytest.approx(7 / (h * w * 3))
    assert d.psnr == pytest.approx(10 * math.log10(255**2 / (49 / (h * w * 3))))
    assert 0.0 < d.ssim < 1.0
    assert difference_map(a, b)[5, 7] == 7 and difference_map(a, b).sum() == 7


def test_alpha_difference_counts_but_not_in_psnr():
    a = synthetic()
    b = a.copy()
    b[0, 0, 3] ^= 0x10
    d = compare_images(a, b)
    assert d.max_abs == 16 and d.share_differing > 0 and d.psnr == math.inf


def test_mask_restricts_statistics():
    a = np.zeros((16, 16, 3), np.uint8)
    b = a.copy()
    b[:8] = 10  # the top half differs
    mask = np.zeros((16, 16), bool)
    mask[8:] = True
    assert compare_images(a, b, mask).max_abs == 0
    assert compare_images(a, b, ~mask).share_differing == 1.0
    assert compare_images(a, b).share_differing == 0.5


def test_compare_refuses_bad_input():
    a = synthetic()
    with pytest.raises(ValueError, match="shape"):
        compare_images(a, a[:, :-1])
    with pytest.raises(TypeError):
        compare_images(a.astype(np.float32), a.astype(np.float32))
    with pytest.raises(ValueError, match="no pixels"):
        compare_images(a, a, np.zeros(a.shape[:2], bool))


def test_coverage_marks_pixels_off_background():
    image = np.full((8, 8, 4), 255, np.uint8)
    image[2:4, 3:6] = (255, 0, 0, 255)
    image[7, 7, 3] = 0  # alpha only
    rgba, rgb = coverage(image, (1.0, 1.0, 1.0, 1.0)), coverage(image, (255, 255, 255))
    assert rgba.sum() == 7 and rgb.sum() == 6 and rgb[2:4, 3:6].all()


# ---------------------------------------------------------------- tables


ROWS = [
    {"path": "per-vertex", "triangles": 1000, "gpu_ms": 0.125, "psnr": math.inf, "ok": True},
    {"path": "per|pixel", "triangles": 2_000_000, "gpu_ms": 1234567.891, "ssim": 0.987654321,
     "ok": False, "note": None},
]


def test_write_table_round_trip(tmp_path):
    csv_path, md_path = write_table(ROWS, tmp_path, title="demo")
    assert csv_path == tmp_path / "table.csv" and md_path == tmp_path / "table.md"
    columns = ["path", "triangles", "gpu_ms", "psnr", "ok", "ssim", "note"]
    back = read_table(csv_path)
    assert [list(r) for r in back] == [columns, columns]
    assert back == [{c: r.get(c) for c in columns} for r in ROWS]

    lines = md_path.read_text().splitlines()
    table = [line for line in lines if line.startswith("|")]
    assert lines[0] == "# demo"
    assert len(table) == 2 + len(ROWS)
    assert set(table[1]) <= set("|-: ")
    assert len({len(line) for line in table}) == 1  # aligned
    assert "∞" in table[2] and "per\\|pixel" in table[3] and "1.235e+06" in table[3]


def test_markdown_numbers_are_readable():
    text = markdown_table([{"x": 0.000123456}, {"x": 12.3456}, {"x": float("nan")}, {"x": 3}])
    cells = [line.split("|")[1].strip() for line in text.splitlines()[2:]]
    assert cells == ["1.235e-04", "12.35", "n/a", "3"]


def test_explicit_columns_pick_and_order(tmp_path):
    csv_path, _ = write_table(ROWS, tmp_path, "picked", columns=["ssim", "path"])
    assert read_table(csv_path) == [{"ssim": None, "path": "per-vertex"},
                                    {"ssim": 0.987654321, "path": "per|pixel"}]


class Unprintable:
    def __str__(self):
        raise RuntimeError("cannot format this value")


def test_failed_table_write_leaves_old_table(tmp_path):
    csv_path, md_path = write_table(ROWS, tmp_path)
    before = csv_path.read_bytes(), md_path.read_bytes()
    with pytest.raises(RuntimeError, match="cannot format"):
        write_table(ROWS + [{"path": Unprintable()}], tmp_path)
    assert (csv_path.read_bytes(), md_path.read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv", "table.md"]


def test_failure_inside_csv_write_removes_temp_file(tmp_path, monkeypatch):
    csv_path, md_path = write_table(ROWS, tmp_path)
    before = csv_path.read_bytes()
    calls = []

    def failing(value):  # fails in the second row, after the first reached the temp file
        calls.append(value)
        if len(calls) > 7:  # 7 columns per row
            raise OSError("disk full")
        return "" if value is None else value

    monkeypatch.setattr(tables_module, "_csv_value", failing)
    with pytest.raises(OSError, match="disk full"):
        write_table(ROWS, tmp_path)
    assert csv_path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv", "table.md"]


@settings(max_examples=30, deadline=None)
@given(st.lists(st.fixed_dictionaries({
    "x": st.floats(allow_nan=False),
    "n": st.integers(-10**12, 10**12),
    "name": st.text(alphabet="abc xyz-|,\"", min_size=1, max_size=8).filter(
        lambda t: t.strip() == t and t not in ("inf", "nan")),
}), max_size=4))
def test_csv_round_trip_is_exact(rows):
    with tempfile.TemporaryDirectory() as folder:
        csv_path, md_path = write_table(rows, folder)
        assert read_table(csv_path) == rows
        assert len([line for line in md_path.read_text().splitlines() if line.startswith("|")]) == (
            2 + len(rows) if rows else 0)


def test_atomic_write_text_replaces(tmp_path):
    path = tmp_path / "note.txt"
    atomic_write_text(path, "one")
    atomic_write_text(path, "two")
    assert path.read_text() == "two" and len(list(tmp_path.iterdir())) == 1


# ---------------------------------------------------------------- timing


def test_time_draw_reports_ordered_statistics(ctx):
    o, corners, normals = quad()
    camera = Camera.fit(o, 1.0, margin=1.0, aspect=64 / 48)
    path = quad_path(ctx, camera, corners, normals)
    fb = Framebuffer(ctx, (64, 48))
    calls = []

    def draw():
        calls.append(1)
        path.draw()

    t = time_draw(ctx, fb, draw, warmup=1, repeat=5)
    assert len(calls) == 6 and t.repeats == 5 and len(t.wall_samples_ms) == 5
    assert 0 < t.wall_ms_min <= t.wall_ms <= t.wall_ms_max
    assert t.wall_ms_min <= t.wall_ms_lo <= t.wall_ms <= t.wall_ms_hi <= t.wall_ms_max
    if timer_queries_meaningful(ctx):
        assert 0 <= t.gpu_ms_min <= t.gpu_ms <= t.gpu_ms_max
    else:  # a software renderer's timer queries time nothing: no GPU time at all
        assert t.gpu_ms is None and t.gpu_ms_min is None and t.gpu_samples_ms == ()
    assert t.readback_ms > 0
    assert set(t.as_row()) == {"gpu_ms", "gpu_ms_min", "gpu_ms_max", "wall_ms", "wall_ms_min",
                               "wall_ms_max", "readback_ms", "repeats", "wall_ms_lo",
                               "wall_ms_hi", "wall_samples_ms"}
    assert coverage(fb.read()).sum() == 24 * 18  # the framebuffer keeps the last draw
    with pytest.raises(ValueError, match="repeat"):
        time_draw(ctx, fb, draw, repeat=4)
    path.release()
    fb.release()


def test_time_call_is_wall_only_and_keeps_result():
    t = time_call(lambda: sum(range(1000)), warmup=0, repeat=5)
    assert isinstance(t, Timing) and t.result == 499500
    assert t.gpu_ms is None and t.readback_ms is None
    assert t.wall_ms_min <= t.wall_ms <= t.wall_ms_max
    with pytest.raises(ValueError):
        time_call(lambda: None, repeat=3)



def test_time_call_runs_its_setup_untimed_before_every_call():
    import time

    calls = []
    t = time_call(lambda: calls.append("run"), warmup=1, repeat=5,
                  setup=lambda: (calls.append("setup"), time.sleep(0.02)))
    assert calls == ["setup", "run"] * 6
    assert t.wall_ms_max < 20.0  # the 20 ms sleep of every setup is outside the clock

# ---------------------------------------------------------------- registry


def test_run_experiment_writes_table(tmp_path):
    seen = {}

    @experiment("dummy-harness-check", "two rows for the harness test")
    def run(exp):
        seen.update(out_dir=exp.out_dir, quick=exp.quick, size=exp.size)
        exp.say("halfway")
        return [{"case": "a", "ms": 1.5}, {"case": "b", "ms": 2.5, "extra": 3}]

    messages = []
    try:
        rows, out_dir = run_experiment("dummy-harness-check", tmp_path / "figures", quick=True,
                                       progress=messages.append, warm=False)
    finally:
        del EXPERIMENTS["dummy-harness-check"]
    assert out_dir == tmp_path / "figures" / "dummy-harness-check"
    # the experiment wrote into a staging folder beside it, swapped in whole afterwards
    assert seen["out_dir"].parent == out_dir.parent and not seen["out_dir"].exists()
    assert sorted(p.name for p in out_dir.parent.iterdir()) == ["dummy-harness-check"]
    assert seen["quick"] is True and seen["size"] == "quick" and messages == ["halfway"]
    assert read_table(out_dir / "table.csv") == [{"case": "a", "ms": 1.5, "extra": None},
                                                 {"case": "b", "ms": 2.5, "extra": 3}]
    assert (out_dir / "table.md").read_text().startswith("# dummy-harness-check")


@pytest.mark.gl
def test_run_experiment_releases_its_gl_context(tmp_path):
    EGL = egl()

    def current():
        return ctypes.cast(EGL.eglGetCurrentContext(), ctypes.c_void_p).value

    with keeping_current() as restore:  # the other tests' context is current again afterwards
        ctx = create_context()  # the caller's context, current when the runs start
        restore.display = EGL.eglGetCurrentDisplay()
        before = current()
        made = []


        @experiment("dummy-gl-release", "draws nothing, makes a GL context")
        def run(exp):
            made.append(exp.gl)
            assert exp.renderer and current() != before
            return [{"case": "a"}]

        @experiment("dummy-gl-fails", "makes a GL context, then fails")
        def fail(exp):
            made.append(exp.gl)
            raise RuntimeError("broken experiment")

        try:
            run_experiment("dummy-gl-release", tmp_path, size="tiny")
            assert current() == before
            with pytest.raises(RuntimeError, match="broken experiment"):
                run_experiment("dummy-gl-fails", tmp_path, size="tiny")
            # the caller's context is current again and still draws
            assert current() == before
            fb = ctx.simple_framebuffer((2, 2))
            fb.use()
            ctx.clear(0.0, 1.0, 0.0, 1.0)
            assert fb.read(components=4)[:4] == b"\x00\xff\x00\xff"
        finally:
            del EXPERIMENTS["dummy-gl-release"], EXPERIMENTS["dummy-gl-fails"]
            ctx.release()
    # released when each run ended, whether it returned rows or failed
    assert [type(c.mglo).__name__ for c in made] == ["InvalidObject", "InvalidObject"]


def test_discover_imports_every_module(tmp_path, monkeypatch):
    package = tmp_path / "harness_probe_scripts"
    package.mkdir()
    (package / "__init__.py").write_text("")
    for name in ("first", "second"):
        (package / f"{name}.py").write_text(
            "from workbench.experiment import experiment\n"
            f"@experiment('probe-{name}', 'registered on import')\n"
            "def run(exp):\n    return []\n")
    (package / "_private.py").write_text("raise RuntimeError('private modules are skipped')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        found = discover("harness_probe_scripts")
        assert {"probe-first", "probe-second"} <= set(found)
        assert found["probe-first"].description == "registered on import"
    finally:
        for name in ("probe-first", "probe-second"):
            EXPERIMENTS.pop(name, None)


def test_unknown_experiment_lists_known_ones(tmp_path):
    @experiment("dummy-known", "")
    def run(exp):
        return []

    try:
        with pytest.raises(KeyError, match="dummy-known"):
            run_experiment("no-such-experiment", tmp_path)
        with pytest.raises(ValueError, match="already registered"):
            experiment("dummy-known", "")(lambda out_dir, quick, progress: [])
    finally:
        del EXPERIMENTS["dummy-known"]
    assert not (tmp_path / "no-such-experiment").exists()


# ---------------------------------------------------------------- figures


def read_png(path):
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("RGBA"))


def contains_block(haystack, block):
    h, w = block.shape[:2]
    for i in range(haystack.shape[0] - h + 1):
        for j in range(haystack.shape[1] - w + 1):
            if np.array_equal(haystack[i:i + h, j:j + w], block):
                return True
    return False


def test_save_png_round_trip(tmp_path):
    image = synthetic(10, 12)
    save_png(tmp_path / "a.png", image)
    assert np.array_equal(read_png(tmp_path / "a.png"), image)


def has_colour(image, colour, tolerance=2):
    diff = np.abs(image[..., :3].astype(int) - np.asarray(colour)[:3])
    return bool((diff.max(axis=2) <= tolerance).any())


@pytest.mark.parametrize("bands, height", [(0, 160), (5, 40)])
def test_field_figure_shows_image_and_colour_bar(tmp_path, bands, height):
    import matplotlib

    image = np.full((height, 200, 4), 255, np.uint8)
    image[..., :3] = 128
    image[10:20, 5:45, :3] = np.random.default_rng(1).integers(0, 256, (10, 40, 3))
    path = save_field_figure(tmp_path / "field.png", image, value_range=(0.0, 2.0),
                             colormap="viridis", label="von Mises stress", units="MPa",
                             title="step 3", bands=bands)
    fig = read_png(path)
    k = -(-MIN_PANEL_HEIGHT // height)  # small images are shown with k x k pixel blocks
    shown = np.repeat(np.repeat(image, k, axis=0), k, axis=1)
    assert fig.shape[0] > shown.shape[0] and fig.shape[1] > shown.shape[1] + 20
    assert contains_block(fig, shown)  # every image pixel kept, nothing resampled
    cmap = matplotlib.colormaps["viridis"]
    if bands:
        cmap = cmap.resampled(bands)
        for i in range(bands):  # every band of the bar is there
            assert has_colour(fig, np.round(np.asarray(cmap(i)) * 255), tolerance=0)
    for end in (0.0, 1.0):
        assert has_colour(fig, np.round(np.asarray(cmap(end)) * 255), tolerance=8)


def test_field_figure_refuses_bad_range(tmp_path):
    image = np.zeros((10, 10, 4), np.uint8)
    with pytest.raises(ValueError, match="range"):
        save_field_figure(tmp_path / "x.png", image, value_range=(1, 1), colormap="viridis",
                          label="x", units="")
    with pytest.raises(ValueError, match="positive"):
        save_field_figure(tmp_path / "x.png", image, value_range=(0, 1), colormap="viridis",
                          label="x", units="", log=True)
    assert not list(tmp_path.iterdir())


def test_image_grid_places_panels_side_by_side(tmp_path):
    a, b = synthetic(160, 30, 1, opaque=True), synthetic(160, 30, 2, opaque=True)
    path = save_image_grid(tmp_path / "grid.png", [a, b, difference_map(a, b)],
                           ["per-vertex", "per-pixel", "difference"])
    fig = read_png(path)
    assert fig.shape[1] > 3 * 30 and fig.shape[0] < 2 * 160
    assert contains_block(fig, a) and contains_block(fig, b)
    with pytest.raises(ValueError, match="titles"):
        save_image_grid(tmp_path / "bad.png", [a, b], ["one"])


# ---------------------------------------------------------------- pyrender reference


def render_ours(ctx, camera, corners, normals, size):
    """(H, W, 4) uint8 image of one untimed draw of the quad on white."""
    return measure(ctx, Quad(corners, normals), QuadDraw(), camera=camera, size=size,
                   timed=False).image


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_pyrender_matches_our_camera_and_lighting(ctx, offset):
    size = (64, 48)
    o, corners, normals = quad(offset)
    camera = Camera.fit(o, 1.0, margin=1.0, aspect=64 / 48)
    # GL objects of the caller made before pyrender runs: they must still draw afterwards
    path = quad_path(ctx, camera, corners, normals)
    fb = Framebuffer(ctx, size)

    with PyrenderReference(corners, [[0, 1, 2], [0, 2, 3]], normals, camera, size,
                           base_color=BASE) as reference:
        theirs = reference.render()
    assert theirs.shape == (48, 64, 4) and theirs.dtype == np.uint8

    projected = camera.project(corners, size)
    rows, cols = np.nonzero(coverage(theirs))
    assert (cols.min(), cols.max() + 1) == tuple(np.round([projected[:, 0].min(),
                                                           projected[:, 0].max()]))
    assert (rows.min(), rows.max() + 1) == tuple(np.round([projected[:, 1].min(),
                                                           projected[:, 1].max()]))

    fb.clear()
    path.draw()
    ours = fb.read()
    assert np.array_equal(coverage(ours), coverage(theirs))
    assert compare_images(ours, theirs).ssim >= 0.9
    # the quad's centre faces the light: both give the base colour there
    assert np.abs(ours[30, 32, :3].astype(int) - theirs[30, 32, :3]).max() <= 3
    path.release()
    fb.release()


def test_pyrender_perspective_and_timing(ctx):
    size = (48, 48)
    o, corners, normals = quad()
    camera = Camera.fit(o, 1.0, projection="perspective", azimuth=0.0, fov_deg=40.0)
    reference = PyrenderReference(corners, [[0, 1, 2], [0, 2, 3]], normals, camera, size,
                                  colors=np.tile([230, 100, 25], (4, 1)))
    try:
        image = reference.render()
        t = reference.time(warmup=1, repeat=5)
    finally:
        reference.release()
    projected = camera.project(corners, size)
    rows, cols = np.nonzero(coverage(image))
    # 4x multisampling: an edge pixel counts once a sample is covered, so within one pixel
    assert abs(cols.min() - projected[:, 0].min()) <= 1
    assert abs(cols.max() + 1 - projected[:, 0].max()) <= 1
    assert abs(rows.min() - projected[:, 1].min()) <= 1
    assert abs(rows.max() + 1 - projected[:, 1].max()) <= 1
    ours = render_ours(ctx, camera, corners, normals, size)
    assert compare_images(ours, image).ssim >= 0.9
    assert t.repeats == 5 and t.wall_ms_min <= t.wall_ms <= t.wall_ms_max and t.readback_ms > 0
    assert t.gpu_ms is None or t.gpu_ms_min <= t.gpu_ms <= t.gpu_ms_max
    with pytest.raises(RuntimeError, match="released"):
        reference.render()


def test_pyrender_camera_has_our_projection():
    for projection in ("orthographic", "perspective"):
        camera = Camera.fit([1.0, 2.0, 3.0], 2.0, azimuth=30, elevation=10,
                            projection=projection, aspect=1.5)
        theirs = PyrenderReference.pyrender_camera(camera).get_projection_matrix(300, 200)
        assert np.allclose(theirs, camera.projection_matrix(), rtol=1e-6, atol=1e-9)


def test_pyrender_reference_refuses_bad_input():
    o, corners, normals = quad()
    camera = Camera.fit(o, 1.0)
    with pytest.raises(ValueError, match="indices"):
        PyrenderReference(corners, [[0, 1, 4]], normals, camera, (8, 8))
    with pytest.raises(ValueError, match="zero length"):
        PyrenderReference(corners, [[0, 1, 2]], np.zeros((4, 3)), camera, (8, 8))
    with pytest.raises(ValueError, match="not both"):
        PyrenderReference(corners, [[0, 1, 2]], normals, camera, (8, 8), colors=BASE,
                          base_color=BASE)


def test_tables_are_written_with_ordinary_permissions(tmp_path):
    import os
    import stat

    from workbench.output.tables import write_table

    mask = os.umask(0o022)
    try:
        csv_path, md_path = write_table([{"a": 1}], tmp_path)
    finally:
        os.umask(mask)
    for path in (csv_path, md_path):
        assert stat.S_IMODE(path.stat().st_mode) == 0o644


def test_an_experiments_output_folder_has_ordinary_permissions(tmp_path):
    import os
    import stat

    @experiment("dummy-mode", "an output folder as readable as any")
    def run(exp):
        return [{"a": 1}]

    mask = os.umask(0o022)
    try:
        _, out_dir = run_experiment("dummy-mode", tmp_path)
    finally:
        os.umask(mask)
        EXPERIMENTS.pop("dummy-mode", None)
    assert stat.S_IMODE(out_dir.stat().st_mode) == 0o755


def test_experiment_outputs_are_replaced_as_a_set(tmp_path):
    """A run that fails leaves the previous outputs whole; a killed run's leftovers (staging
    folder, the previous folder set aside, temporary files) are cleaned by the next run."""
    calls = []

    @experiment("dummy-set", "outputs as a set")
    def run(exp):
        calls.append(exp.out_dir)
        exp.file("figure.txt").write_text(f"run {len(calls)}")
        if len(calls) == 2:
            raise RuntimeError("failed halfway")
        return [{"run": len(calls)}]

    root = tmp_path / "figures"
    try:
        _, out_dir = run_experiment("dummy-set", root, warm=False)
        with pytest.raises(RuntimeError):
            run_experiment("dummy-set", root, warm=False)
        assert (out_dir / "figure.txt").read_text() == "run 1"  # the previous set, whole
        assert read_table(out_dir / "table.csv") == [{"run": 1}]
        assert sorted(p.name for p in root.iterdir()) == ["dummy-set"]
        # leftovers of a run killed between the two renames: the output folder set aside
        dead = 2**22 + 12345  # no such process
        (root / "dummy-set").rename(root / f".dummy-set.{dead}.old")
        (root / f".dummy-set.abc.{dead}.partial").mkdir()
        assert {p.name for p in clean_dead_runs(root, "dummy-set")} == {
            f".dummy-set.{dead}.old", f".dummy-set.abc.{dead}.partial"}
        assert (root / "dummy-set" / "figure.txt").read_text() == "run 1"  # put back
        (root / "dummy-set" / ".table.csv.x1y2.tmp").write_text("half")
        rows, out_dir = run_experiment("dummy-set", root, warm=False)
        assert rows == [{"run": 3}] and (out_dir / "figure.txt").read_text() == "run 3"
        assert sorted(p.name for p in out_dir.iterdir()) == ["figure.txt", "table.csv", "table.md"]
        assert sorted(p.name for p in root.iterdir()) == ["dummy-set"]
    finally:
        del EXPERIMENTS["dummy-set"]
