"""Golden images: every render path on the GL context and every path the software rasterizer
draws, each against a reference PNG of a small scene in ``tests/golden`` under the thresholds
of :mod:`golden_images` (whose docstring gives the measured variation and the reasons);
``pytest --update-golden`` rewrites the references. A shader edit that moves one band edge by
one pixel fails the comparison."""

import json

import golden_images
import numpy as np
import pytest
from golden_images import (
    CASES,
    GOLDEN_DIR,
    OTHER_RENDERER,
    RAMP_BANDS,
    RAMP_CASES,
    RAMP_CELLS,
    SAME_RENDERER,
    check,
    compare,
    read_png,
    reference_for,
    render_case,
    sidecar,
    slug,
    update,
)

import workbench.gl.shaders as shaders
from workbench.gl import renderer
from workbench.paths import PATHS, SoftwareRasterizer
from workbench.paths.colormap import ColorScale
from workbench.paths.software import SoftwarePath

GL_CASES = [case for case in CASES if case.backend == "gl"]
SOFTWARE_CASES = [case for case in CASES if case.backend == "software"]
# the paths the software rasterizer refuses, and why: it implements the six shadings of the
# plain mesh paths (workbench.paths.software.SHADING_OF) and raises ValueError for any other
SOFTWARE_REFUSED = {
    "quad_wire": "its outlines come from per-fragment derivatives of strip wire coordinates",
    "fe_wire_texture": "an fe2003 texture path: draws a textured surface with its textures",
    "fe_normal_map": "an fe2003 texture path: draws a textured surface with its textures",
    "fe_normal_wire": "an fe2003 texture path: draws a textured surface with its textures",
    "spacetime_vertex": "draws a spacetime scene (polynomial elements), not an FE mesh",
    "spacetime_pixel": "draws a spacetime scene (polynomial elements), not an FE mesh",
    "flange": "its part-distance field and transfer function are not a software shading",
    "exploded": "moves, culls and ghosts the halves in several GL passes",
}
# the injected fault: the colormap coordinate moved by one ramp pixel (1/32 of the range)
COORD_LINE = "return t * colormap_st.x + colormap_st.y;"
SHIFT = 1.0 / RAMP_CELLS
MAX_REFERENCE_BYTES = 300_000  # all references together


@pytest.fixture(scope="module")
def gl_renderer(ctx):
    """The GL_RENDERER string of the module's context (e.g. "llvmpipe (LLVM 15.0.6, ...)")."""
    return renderer(ctx)


def test_every_path_has_a_golden_case_on_each_backend_that_draws_it():
    refused = set()
    for name in PATHS:
        try:
            SoftwarePath(name)
        except ValueError as exc:
            assert "draws the mesh paths" in str(exc), exc
            refused.add(name)
    assert refused == set(SOFTWARE_REFUSED)
    assert {case.path for case in GL_CASES} == set(PATHS)
    assert {case.path for case in SOFTWARE_CASES} == set(PATHS) - refused
    assert len({case.id for case in CASES}) == len(CASES)


@pytest.mark.parametrize("case", GL_CASES, ids=lambda case: case.id)
def test_gl_image_matches_its_reference(ctx, gl_renderer, case, tmp_path, update_golden):
    image = render_case(case, ctx)
    assert (image[..., :3] != 255).any(axis=-1).mean() > 0.1  # the scene is in the picture
    assert check(case, image, gl_renderer, tmp_path, update_golden).ok


@pytest.mark.parametrize("case", SOFTWARE_CASES, ids=lambda case: case.id)
def test_software_image_matches_its_reference(case, tmp_path, update_golden):
    image = render_case(case)
    assert (image[..., :3] != 255).any(axis=-1).mean() > 0.1  # the scene is in the picture
    assert check(case, image, SoftwareRasterizer().renderer, tmp_path, update_golden).ok


def test_another_renderer_uses_its_own_references_or_the_looser_threshold(tmp_path,
                                                                        monkeypatch):
    case, gpu = RAMP_CASES["gl"], "NVIDIA H100 80GB HBM3/PCIe/SSE2"
    made_on = sidecar()["gl"]
    assert made_on != gpu
    ref = reference_for(case, gpu)
    assert ref.threshold == OTHER_RENDERER and not ref.own and ref.made_on == made_on
    expected = read_png(ref.file)
    shifted = np.roll(expected, -1, axis=1)  # every band edge one pixel to the left
    assert check(case, shifted, gpu, tmp_path).ok  # within the looser threshold
    wrong = expected.copy()
    wrong[..., :3] = 255 - wrong[..., :3]  # the colours inverted: a wrong path
    with pytest.raises(AssertionError) as failure:
        check(case, wrong, gpu, tmp_path)
    assert gpu in str(failure.value) and made_on in str(failure.value)
    # --update-golden on that renderer writes references of its own, which it then uses
    monkeypatch.setattr(golden_images, "GOLDEN_DIR", tmp_path)
    (tmp_path / "renderer.json").write_text(json.dumps({"gl": made_on}))
    written = update(case, shifted, gpu)
    assert written == tmp_path / slug(gpu) / f"{case.id}.png"
    assert sidecar(tmp_path / slug(gpu)) == {"gl": gpu} and sidecar(tmp_path) == {"gl": made_on}
    own = reference_for(case, gpu)
    assert own.own and own.threshold == SAME_RENDERER and own.file == written
    assert np.array_equal(read_png(written), shifted)
    with pytest.raises(AssertionError, match="share, max_diff failed"):
        check(case, expected, gpu, tmp_path / "out")


def _ramp_fault(image, expected):
    """The pixels the one-pixel shift changed: exactly one column (the band edge's) of the 32
    covered rows, each by a band colour step; the comparison fails on both checks."""
    changed = (image != expected).any(axis=-1)
    rows, cols = np.nonzero(changed)
    assert changed.sum() == RAMP_CELLS and len(set(cols.tolist())) == 1
    assert cols[0] == 16 + RAMP_CELLS // RAMP_BANDS - 1  # the column left of the edge
    result = compare(image, expected, SAME_RENDERER)
    assert result.failed == ["share", "max_diff"] and result.max_diff > 50
    return result


def test_a_band_edge_moved_by_one_pixel_in_the_shader_fails(ctx, gl_renderer, monkeypatch,
                                                            tmp_path):
    case = RAMP_CASES["gl"]
    ref = reference_for(case, gl_renderer)
    # without the fault: the reference of this renderer, or where it has none a draw now
    expected = read_png(ref.file) if ref.own else render_case(case, ctx)
    assert compare(render_case(case, ctx), expected, SAME_RENDERER).ok
    original = shaders.shader_source
    edited = []

    def shifted(name):
        text = original(name)
        if COORD_LINE in text:
            edited.append(name)
        return text.replace(COORD_LINE, COORD_LINE.replace(";", f" + {SHIFT!r};"))

    monkeypatch.setattr(shaders, "shader_source", shifted)
    image = render_case(case, ctx)
    assert "pixel_color.frag.glsl" in edited
    _ramp_fault(image, expected)
    if ref.own:
        with pytest.raises(AssertionError, match="share, max_diff failed.*difference image: "):
            check(case, image, gl_renderer, tmp_path)
        assert (tmp_path / f"{case.id}-diff.png").exists()


def test_a_band_edge_moved_by_one_pixel_fails_on_the_software_rasterizer(monkeypatch,
                                                                         tmp_path):
    case = RAMP_CASES["software"]
    expected = read_png(reference_for(case, "software").file)
    a, b = ColorScale("viridis", (0.0, 1.0), bands=RAMP_BANDS).coord_transform
    original = ColorScale.coord_transform
    monkeypatch.setattr(ColorScale, "coord_transform",
                        property(lambda scale: (original.fget(scale)[0],
                                                original.fget(scale)[1] + SHIFT)))
    assert ColorScale("viridis", (0.0, 1.0), bands=RAMP_BANDS).coord_transform == (a, b + SHIFT)
    image = render_case(case)
    _ramp_fault(image, expected)
    with pytest.raises(AssertionError, match="share, max_diff failed.*difference image: "):
        check(case, image, SoftwareRasterizer().renderer, tmp_path)
    assert (tmp_path / f"{case.id}-diff.png").exists()


def test_references_are_small_and_cover_every_case():
    files = sorted(GOLDEN_DIR.glob("*.png"))
    assert {f.stem for f in files} == {case.id for case in CASES}
    assert sum(f.stat().st_size for f in GOLDEN_DIR.rglob("*.png")) < MAX_REFERENCE_BYTES
    for case in CASES:
        image = read_png(GOLDEN_DIR / f"{case.id}.png")
        assert image.shape == (case.size[1], case.size[0], 4)
        drawn = (image[..., :3] != 255).any(axis=-1).mean()
        assert 0.1 < drawn < 0.99, f"{case.id}: {100 * drawn:.0f} % of the pixels drawn"
