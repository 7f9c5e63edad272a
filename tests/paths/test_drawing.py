"""How a path is drawn, and the package root's facade: ``paths.render`` and ``workbench.render``
draw exactly the image ``measure`` reads for the same path, camera and size, on GL and on the
software rasterizer; ``prepared`` releases what it made, also a target it replaced;
``workbench.load`` refuses what it cannot read in one ValueError; and the facade stays lazy:
``import workbench`` imports no GL."""

import subprocess
import sys

import numpy as np
import pytest

import workbench
from workbench.measurement.rows import default_camera, measure
from workbench.paths import SoftwareRasterizer, make_path, prepared, render
from workbench.scene.builtin import load_scene

SIZE = (72, 54)
SCENE = "semicylinders:6"  # the es2008 scene at 6 x 6 quads a sheet: small and quick


@pytest.fixture(scope="module")
def scene():
    return load_scene(SCENE)


@pytest.mark.parametrize("backend", ["gl", "software"])
@pytest.mark.parametrize("path, style", [("gouraud", {}),
                                         ("pixel_color", {"field": "distance", "bands": 6})])
def test_render_is_the_image_measure_reads(ctx, scene, backend, path, style):
    """Pixel equality, and a picture: the scene covers part of the frame, not all of it."""
    drawer = ctx if backend == "gl" else SoftwareRasterizer()
    camera = default_camera(scene, SIZE)
    measured = measure(drawer, scene, path, make_path(path, **style).style,
                       camera, SIZE, timed=False).image
    facade = workbench.render(scene, path, size=SIZE, camera=camera,
                              backend=ctx if backend == "gl" else backend, **style)
    untimed = render(drawer, scene, path, make_path(path, **style).style,
                     camera, SIZE)
    assert facade.shape == (SIZE[1], SIZE[0], 4) and facade.dtype == np.uint8
    covered = (facade[..., :3] != 255).any(axis=-1).mean()
    assert 0.05 < covered < 0.95
    np.testing.assert_array_equal(facade, measured)
    np.testing.assert_array_equal(untimed, measured)


def test_the_facade_draws_a_name_on_its_own_context_and_default_camera(scene):
    """A built-in name, the default camera and the context ``render`` makes and reuses: the
    image measure reads with the path family's default camera."""
    first = workbench.render(SCENE, "flat", size=SIZE)
    again = workbench.render(SCENE, "flat", size=SIZE)
    from workbench.paths.facade import _CONTEXT

    assert len(_CONTEXT) == 1
    np.testing.assert_array_equal(first, again)
    np.testing.assert_array_equal(first, measure(_CONTEXT[0], scene, "flat", size=SIZE,
                                                 timed=False).image)


@pytest.mark.parametrize("call, needle", [
    (lambda s: workbench.render(s, "no_such_path", size=SIZE, backend="software"),
     "unknown render path"),
    (lambda s: workbench.render(s, size=(0, 10), backend="software"), "two positive integers"),
    (lambda s: workbench.render(s, size=SIZE, step=3, backend="software"), "step must be"),
    (lambda s: workbench.render(s, size=SIZE, backend="vulkan"), "backend is 'gl'"),
    (lambda s: workbench.render(s, size=SIZE, backend="software", colour=1),
     "takes no option"),
    (lambda s: workbench.render(42, size=SIZE), "render takes a scene"),
])
def test_the_facade_refuses_bad_input_with_one_value_error(scene, call, needle):
    with pytest.raises(ValueError, match=needle):
        call(scene)


def test_load_reads_a_name_and_refuses_a_missing_file(tmp_path):
    assert workbench.load(SCENE).kind == "mesh"
    missing = tmp_path / "nowhere.k"
    with pytest.raises(ValueError, match="neither an existing mesh file nor a built-in scene"
                                         r".*semicylinders"):
        workbench.load(missing)
    with pytest.raises(ValueError, match="no spacetime scene"):
        workbench.load("spacetime:nothing")
    with pytest.raises(ValueError, match="mesh file path or a built-in scene name"):
        workbench.load(3)


def test_importing_workbench_imports_no_gl_and_hands_out_the_four_names():
    code = ("import sys, workbench\n"
            "heavy = [m for m in ('moderngl', 'numba', 'numpy', 'workbench.paths', "
            "'workbench.measurement') if m in sys.modules]\n"
            "assert not heavy, heavy\n"
            "names = [workbench.load, workbench.render, workbench.measure, workbench.view]\n"
            "assert [n.__module__ for n in names] == ['workbench.paths.facade', "
            "'workbench.paths.facade', 'workbench.measurement.rows', 'workbench.viewer'], names\n"
            "try:\n    workbench.nothing\nexcept AttributeError:\n    pass\n"
            "else:\n    raise SystemExit('workbench.nothing exists')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_prepared_releases_the_target_it_drew_into_last(ctx, scene):
    """A target replaced by ``resize`` is released at once, the new one on exit: nothing is
    released twice (moderngl raises then), and the new size is drawn."""
    with prepared(ctx, scene, "gouraud", size=SIZE) as ready:
        first = ready.target
        ready.resize((40, 30))
        assert ready.target is not first
        assert ready.image().shape == (30, 40, 4)
    with pytest.raises(ValueError):
        with prepared(SoftwareRasterizer(), scene, "gouraud", size=SIZE, samples=4):
            pass
