"""The real car model far from the origin renders like the car at home, and renders repeat
exactly."""

import numpy as np
import pytest

from workbench.gl import Camera
from workbench.measurement.images import compare_images
from workbench.measurement.rows import measure
from workbench.paths import Style

SIZE = (320, 200)


def render(ctx, mesh, path_name, style):
    """(H, W, 4) uint8 image of one untimed draw of the whole mesh on white."""
    center, radius = mesh.bounding_sphere()
    camera = Camera.fit(center, radius, azimuth=-35, elevation=20, up="z", aspect=SIZE[0] / SIZE[1])
    return measure(ctx, mesh, path_name, style, camera=camera, size=SIZE, timed=False).image


@pytest.mark.parametrize("path_name, style", [
    ("gouraud", Style(wireframe=True)),
    ("element_color", Style(field="thickness", bands=6)),
])
def test_car_translated_by_a_million_mm_renders_the_same(ctx, car, path_name, style):
    home = render(ctx, car, path_name, style)
    far = render(ctx, car.translated([1e6, -1e6, 1e6]), path_name, style)
    background = (home == 255).all(axis=2)
    assert (~background).mean() > 0.1  # the car fills a good part of the image
    assert compare_images(home, far).share_differing <= 0.005


def test_two_renders_are_byte_identical(ctx, car):
    style = Style(field="thickness", wireframe=True)
    first = render(ctx, car, "element_color", style)
    second = render(ctx, car, "element_color", style)
    assert first.tobytes() == second.tobytes()


def test_world_space_float32_would_not_be_stable(car):
    # the reason for the float64 origin: car coordinates 1e6 mm from the origin lose their
    # sub-millimetre detail when cast to float32 in world space
    far = car.nodes + 1e6
    error = np.abs(far.astype(np.float32).astype(np.float64) - far).max()
    assert error > 0.01
