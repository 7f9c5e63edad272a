"""The one path protocol and the one measurement function: every registered path, drawn through
``measure``, released in all cases; scenes derive only what paths declare."""

import sys

import numpy as np
import pytest

from workbench.algo.fepatch.mesh_model import fepatch_model
from workbench.algo.spacetime.exact import colour_error, element_boundary, exact_image
from workbench.algo.spacetime.fields import STEEL
from workbench.algo.spacetime.raster import PixelGrid
from workbench.algo.spacetime.scene import spacetime_scene
from workbench.gl import renderer
from workbench.measurement.rows import default_camera, measure
from workbench.paths import PATHS, GLPath, Style, make_path, path_class, path_options
from workbench.paths.colormap import colormap_lut
from workbench.paths.spacetime import SpacetimeStyle
from workbench.scene import generators
from workbench.scene.needs import MESH_ITEMS, derivation_cost, derive, derived_items

SIZE = (96, 72)


@pytest.fixture(scope="module")
def radial():
    return spacetime_scene("radial", cells=6)


def _mesh(n=4):
    return generators.semicylinders(n=n)


def test_every_path_is_registered_with_one_protocol():
    assert {"spacetime_vertex", "spacetime_pixel", "fe_wire_texture", "fe_normal_map",
            "fe_normal_wire", "gouraud", "pixel_color", "position"} <= set(PATHS)
    for name in PATHS:
        cls = path_class(name)
        assert issubclass(cls, GLPath)
        assert cls.scene_kinds <= {"mesh", "spacetime", "surface"}
        for method in ("prepare", "set_camera", "set_step", "draw", "release"):
            assert callable(getattr(cls, method))
    assert "shading" not in path_options("spacetime_pixel")
    assert make_path("spacetime_vertex").style.shading == "per_vertex"
    with pytest.raises(ValueError, match="no option 'shading'"):
        make_path("spacetime_pixel", shading="per_vertex")


def test_spacetime_path_through_measure_matches_the_exact_image(ctx, radial):
    style = SpacetimeStyle(height_scale=800.0, U_max=100.0)
    result = measure(ctx, radial, "spacetime_pixel", style, size=(120, 120), timed=False)
    grid = PixelGrid.fit(*radial.bounds(), 120, 120)
    exact = exact_image(radial.corners, radial.element, radial.coeffs, radial.centre,
                        radial.extent, STEEL, grid, t=radial.t, U_max=100.0,
                        table=colormap_lut("inferno"), height_scale=800.0)
    labels = np.where(exact.polygon >= 0, exact.polygon, -1)
    inner = exact.covered & ~element_boundary(labels)
    err = np.abs(result.image[..., :3].astype(float) - 255 * exact.rgb).max(axis=2)
    assert err[inner].max() <= 1.0 + 1e-9
    assert colour_error(result.image, exact)["uncovered"] == 0
    row = result.row
    assert row["path"] == "spacetime_pixel" and row["scene"] == "spacetime:radial:6"
    assert row["triangles"] >= len(radial.corners) and row["covered_px"] == exact.covered.sum()
    assert row["wall_ms"] is None  # untimed


def test_spacetime_measure_times_and_releases(ctx, radial):
    result = measure(ctx, radial, "spacetime_vertex", size=SIZE, repeats=5, warmup=0)
    assert result.path.ctx is None  # released
    row = result.row
    assert row["repeats"] == 5
    assert row["wall_ms_min"] <= row["wall_ms"] <= row["wall_ms_max"]
    assert row["renderer"] == renderer(ctx)


def test_fe2003_paths_through_measure_draw_outlines_from_the_scene_model(ctx):
    mesh = generators.stamped_panels(400)
    camera = default_camera(mesh, SIZE, view=(0.0, 90.0))
    images = {}
    for name in ("fe_normal_map", "fe_normal_wire"):
        result = measure(ctx, mesh, name, Style(wire_color=(1.0, 0.0, 0.0)), camera=camera,
                         size=SIZE, timed=False)
        images[name] = result.image
        assert result.path.ctx is None
    # the model was derived once, by the scene, for the parameter set asked for
    assert ("fepatch", "A") in derived_items(mesh)
    red = {name: int((image[..., :3] == (255, 0, 0)).all(axis=-1).sum())
           for name, image in images.items()}
    # the wire texture draws the outlines; without it only the surface's few line edges are red
    assert red["fe_normal_wire"] > 50 and red["fe_normal_wire"] > 2 * red["fe_normal_map"]
    # a TexturedSurface built by the caller is a scene too
    surface = fepatch_model(mesh, "A").simplified
    direct = measure(ctx, surface, "fe_normal_wire", Style(wire_color=(1.0, 0.0, 0.0)),
                     camera=camera, size=SIZE, timed=False)
    assert np.array_equal(direct.image, images["fe_normal_wire"])


class _Boom(RuntimeError):
    pass


def test_a_draw_that_raises_still_releases(ctx, monkeypatch):
    path = make_path("gouraud")
    released = []
    real_release = path.release

    def release():
        released.append(len(path._objects))
        real_release()

    def draw():
        raise _Boom("draw failed")

    monkeypatch.setattr(path, "release", release)
    monkeypatch.setattr(path, "draw", draw)
    with pytest.raises(_Boom):
        measure(ctx, _mesh(), path, size=SIZE, repeats=5)
    assert released and released[0] > 0  # GL objects existed and were released
    assert path.ctx is None and path._objects == []


def test_prepared_path_is_a_context_manager(ctx):
    mesh = _mesh()
    camera = default_camera(mesh, SIZE)
    path = make_path("flat")
    with pytest.raises(_Boom):
        with path:
            path.prepare(ctx, mesh, camera)
            assert path._objects
            raise _Boom()
    assert path.ctx is None and path._objects == []


def test_scene_derives_only_what_the_path_declares(ctx):
    mesh = _mesh()
    measure(ctx, mesh, "position", size=SIZE, timed=False)
    assert derived_items(mesh) == {("triangles",)}  # no Gouraud split, no edges
    row = measure(ctx, mesh, "gouraud", Style(wireframe=True), size=SIZE, timed=False).row
    assert derived_items(mesh) == {("triangles",), ("edges",), ("gouraud", 30.0)}
    assert row["derive_bytes"] > 0
    again = measure(ctx, mesh, "gouraud", Style(wireframe=True), size=SIZE, timed=False).row
    assert again["derive_ms"] == 0 and again["derive_bytes"] == 0  # cached by the scene


def test_a_path_deriving_undeclared_data_is_refused(ctx, monkeypatch):
    path = make_path("position")
    monkeypatch.setattr(path, "needs", frozenset())
    with pytest.raises(RuntimeError, match="without declaring"):
        measure(ctx, _mesh(), path, size=SIZE, timed=False)


def test_derivation_cost_accounts_every_item_once():
    mesh = _mesh(8)
    everything = derivation_cost(mesh, MESH_ITEMS, Style())
    assert derived_items(mesh) == set()  # a fresh copy was used
    assert set(everything.items) == set(MESH_ITEMS)
    part = derive(mesh, {"triangles"}, Style())
    assert part.nbytes == everything.items["triangles"][1]
    assert part.nbytes == (mesh.triangulation.triangles.nbytes
                           + mesh.triangulation.element_of.nbytes
                           + mesh.triangulation.corners.nbytes)
    assert everything.nbytes > part.nbytes


def test_measure_refuses_too_few_repeats(ctx):
    with pytest.raises(ValueError, match="repeats"):
        measure(ctx, _mesh(), "position", size=SIZE, repeats=3)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
