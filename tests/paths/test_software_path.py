"""Every mesh path drawn by the software rasterizer against the same path on the EGL context:
the same pixels (exactly for coverage on llvmpipe, within 0.5 % for shading), through the one
measurement function and ``workbench render --rasterizer software``."""

import numpy as np
import pytest

from workbench.algo.softraster import RasterOptions
from workbench.cli import main
from workbench.gl import renderer
from workbench.measurement.rows import default_camera, measure
from workbench.paths import SoftwareRasterizer, Style
from workbench.paths.software import SoftwarePath
from workbench.scene.generators import crash_sequence, semicylinders, stamped_panels

SIZE = (320, 240)
SOFTWARE = SoftwareRasterizer()


@pytest.fixture(scope="module")
def panels():
    return crash_sequence(stamped_panels(3000, seed=1), steps=4)


@pytest.fixture(scope="module")
def sheets():
    return semicylinders(4, 24)


def differing_share(a, b) -> float:
    return float((a != b).any(axis=-1).mean())


CASES = [
    ("position", {}),
    ("flat", {}),
    ("gouraud", {}),
    ("vertex_color", dict(field="displacement", bands=7, step=3)),
    ("pixel_color", dict(field="displacement", bands=7, step=3)),
    ("pixel_color", dict(field="displacement", step=2)),
    ("pixel_color", dict(field="displacement", bands=5, step=3, hide_range=(100.0, 200.0))),
    ("element_color", dict(field="plastic_strain", bands=6, step=3)),
    ("flat", dict(step=3, magnification=2.5, clip_planes=((0.0, 1.0, 0.2, -50.0),))),
    ("pixel_color", dict(field="thickness", step=1, clip_planes=((1.0, 0.0, 0.0, 0.0),))),
]


@pytest.mark.parametrize("name,options", CASES)
@pytest.mark.parametrize("view", [(30.0, 25.0), (0.0, 90.0)])
def test_software_image_matches_the_gl_image(ctx, panels, name, options, view):
    camera = default_camera(panels, SIZE, view=view)
    gl = measure(ctx, panels, name, Style(**options), camera=camera, size=SIZE, timed=False)
    soft = measure(SOFTWARE, panels, SoftwarePath(name, Style(**options)), camera=camera, size=SIZE,
                   timed=False)
    assert gl.row["covered_px"] > 0.05 * SIZE[0] * SIZE[1]
    share = differing_share(soft.image, gl.image)
    # GL clips triangles into new vertices, this rasterizer tests each fragment: pixels along
    # a clip line may differ (about one per row of a 240-row image)
    limit = 0.01 if "clip_planes" in options else 0.005
    assert share <= limit, f"{name} {options}: {100 * share:.2f} % of the pixels differ"
    if name == "position" and "llvmpipe" in renderer(ctx):
        assert share == 0.0  # the same coverage, pixel for pixel


def test_software_coverage_of_the_es2008_scene_is_llvmpipes(ctx, sheets):
    camera = default_camera(sheets, SIZE, view=(0.0, 0.0), up="y")
    gl = measure(ctx, sheets, "position", camera=camera, size=SIZE, timed=False)
    soft = measure(SOFTWARE, sheets, SoftwarePath("position"), camera=camera, size=SIZE,
                   timed=False)
    if "llvmpipe" not in renderer(ctx):
        pytest.skip("pixel-exact coverage is llvmpipe's rule")
    assert np.array_equal(soft.image, gl.image)


def test_table_rule_deviates_only_along_edges(ctx, sheets):
    # 0 sub-pixel bits moves vertices by up to half a pixel: the coverage changes, a little
    camera = default_camera(sheets, SIZE, view=(0.0, 0.0), up="y")
    gl = measure(ctx, sheets, "position", camera=camera, size=SIZE, timed=False)
    soft = measure(SOFTWARE, sheets, SoftwarePath("position", options=RasterOptions(
        generator="table", subpixel_bits=0)), camera=camera, size=SIZE, timed=False)
    share = differing_share(soft.image, gl.image)
    assert 0.0 < share < 0.02


def test_measure_times_the_software_path(sheets):
    result = measure(SOFTWARE, sheets,
                     SoftwarePath("pixel_color", Style(field="distance", bands=8)),
                     size=SIZE, repeats=5, warmup=1)
    row = result.row
    assert row["renderer"].startswith("software rasterizer (half-space, 8 sub-pixel bits")
    assert row["gpu_ms"] is None and row["wall_ms"] > 0 and row["readback_ms"] >= 0
    assert row["triangles"] == 2 * 4 * 24 * 24 and row["covered_px"] > 0
    assert result.path.stats.kept > 0 and result.path.stats.fragments > row["covered_px"]


def test_refusals(sheets):
    with pytest.raises(ValueError, match="mesh paths"):
        SoftwarePath("spacetime_pixel")
    with pytest.raises(ValueError, match="wire frame"):
        SoftwarePath("flat", Style(wireframe=True))
    with pytest.raises(ValueError, match="strips"):
        SoftwarePath("flat", Style(strips="quad"))
    camera = default_camera(sheets, SIZE, projection="perspective")
    with pytest.raises(ValueError, match="orthographic"):
        measure(SOFTWARE, sheets, SoftwarePath("flat"), camera=camera, size=SIZE, timed=False)
    with pytest.raises(ValueError, match="MSAA"):
        measure(SOFTWARE, sheets, SoftwarePath("flat"), size=SIZE, samples=4, timed=False)


def test_cli_renders_with_the_software_rasterizer(tmp_path, capsys):
    from PIL import Image

    soft, gl = tmp_path / "soft.png", tmp_path / "gl.png"
    common = ["render", "semicylinders:16", "--field", "distance", "--bands", "6", "--raw",
              "--size", "200x160"]
    assert main([*common, "-o", str(soft), "--rasterizer", "software"]) == 0
    assert "software rasterizer" in capsys.readouterr().out
    assert main([*common, "-o", str(gl)]) == 0
    a, b = np.asarray(Image.open(soft)), np.asarray(Image.open(gl))
    assert a.shape == b.shape and differing_share(a, b) <= 0.005
    table = tmp_path / "table.png"
    assert main([*common, "-o", str(table), "--rasterizer", "software", "--generator", "table",
                 "--table-size", "15"]) == 0


@pytest.mark.parametrize("flags,message", [
    (["--wireframe"], "wire frame"),
    (["--projection", "perspective"], "orthographic"),
    (["--generator", "table", "--subpixel-bits", "8"], "subpixel_bits=0"),
    (["--threads", "0"], "threads"),
])
def test_cli_refuses_with_one_line(tmp_path, capsys, flags, message):
    code = main(["render", "semicylinders:8", "-o", str(tmp_path / "x.png"),
                 "--rasterizer", "software", *flags])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1


def test_cli_sort_last_render_equals_the_one_process_render(tmp_path, capsys):
    from PIL import Image

    one, many = tmp_path / "one.png", tmp_path / "many.png"
    common = ["render", "semicylinders:12", "--field", "distance", "--bands", "6", "--raw",
              "--size", "200x160", "--rasterizer", "software"]
    assert main([*common, "-o", str(one)]) == 0
    assert main([*common, "-o", str(many), "--domains", "3", "--split", "part",
                 "--composite", "swap", "--workers", "2"]) == 0
    assert "3 domains by part on 2 workers" in capsys.readouterr().out
    assert np.array_equal(np.asarray(Image.open(one)), np.asarray(Image.open(many)))


def test_cli_sort_last_of_gl_domains_writes_the_plain_gl_image(tmp_path, capsys):
    from PIL import Image

    one, many = tmp_path / "one.png", tmp_path / "many.png"
    common = ["render", "semicylinders:8", "--field", "distance", "--bands", "6", "--raw",
              "--size", "160x120"]
    assert main([*common, "-o", str(one)]) == 0
    assert main([*common, "-o", str(many), "--domains", "3", "--workers", "2"]) == 0
    assert "3 domains by space on 2 workers" in capsys.readouterr().out
    assert np.array_equal(np.asarray(Image.open(one)), np.asarray(Image.open(many)))


def test_flat_differs_only_where_gl_itself_draws_two_colours(ctx, sheets):
    # llvmpipe takes the flat normal from per-pixel float32 derivatives: a triangle whose light
    # lies on a rounding edge gets two colours; the software rasterizer gives it one
    camera = default_camera(sheets, SIZE, view=(0.0, 0.0), up="y")
    gl = measure(ctx, sheets, "flat", camera=camera, size=SIZE, timed=False)
    path = SoftwarePath("flat")
    path.prepare(None, sheets, camera)
    path.make_target(SIZE)
    path.target.clear()
    path.draw()
    triangle = path.target.frame.triangle.ravel()
    drawn = triangle >= 0
    key = gl.image[..., :3].astype(np.int64).reshape(-1, 3) @ np.array([1, 256, 65536])
    low = np.full(triangle.max() + 1, 2 ** 40)
    high = np.full(triangle.max() + 1, -1)
    np.minimum.at(low, triangle[drawn], key[drawn])
    np.maximum.at(high, triangle[drawn], key[drawn])
    differs = (path.target.frame.color != gl.image).any(axis=-1).ravel()
    assert not (differs & ~drawn).any()
    assert (high > low)[triangle[differs]].all()
