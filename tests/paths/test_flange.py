"""The flange path (crash2000 §5, Fig. 9): the distance to another part per pixel, geometry
farther than the threshold hidden by the alpha test."""

import numpy as np
import pytest
from meshes import flange_plates

from workbench.algo.nearest.parts import flange_distances
from workbench.measurement.images import coverage
from workbench.measurement.rows import default_camera, measure
from workbench.paths import make_path
from workbench.paths.flange import FlangeStyle

SIZE = (300, 200)


@pytest.fixture(scope="module")
def plates():
    """Part 0: a plate at z = 0 over x 0..100; part 1 at z = 1 over x 0..40 (1 mm away);
    part 2 at z = 30 over x 60..100 (30 mm away)."""
    return flange_plates()


def test_distances_of_the_plates(plates):
    d = flange_distances(plates, 50.0)
    base = np.flatnonzero(plates.nodes[:, 2] == 0.0)
    near = base[plates.nodes[base, 0] <= 40.0]
    assert np.allclose(d.distance[near], 1.0, rtol=0, atol=1e-12)
    top = np.flatnonzero(plates.nodes[:, 2] == 30.0)
    assert np.allclose(d.distance[top], 30.0, rtol=0, atol=1e-12)


def test_flange_hides_exactly_the_elements_beyond_the_threshold(ctx, plates):
    camera = default_camera(plates, SIZE, view=(0.0, 90.0))
    flange = measure(ctx, plates, "flange", FlangeStyle(threshold=2.0), camera=camera,
                     size=SIZE, timed=False).image
    distance = flange_distances(plates, 50.0).distance
    within = distance[plates.elements] <= 2.0
    all_near, any_near = within.all(axis=1), within.any(axis=1)

    def drawn(mask):
        sub = plates.subset(mask)
        return coverage(measure(ctx, sub, "position", camera=camera, size=SIZE,
                                timed=False).image)

    shown = coverage(flange)
    assert all_near.any() and (~any_near).any() and (any_near & ~all_near).any()
    assert (shown >= drawn(all_near)).all()  # elements within the threshold are all there
    assert not (shown & ~drawn(any_near)).any()  # elements wholly beyond it are gone
    assert drawn(~any_near).sum() > 0.2 * shown.size


def test_distance_map_shows_everything(ctx, plates):
    camera = default_camera(plates, SIZE, view=(0.0, 90.0))
    m = measure(ctx, plates, "flange", FlangeStyle(show="distance"), camera=camera, size=SIZE,
                timed=False)
    every = measure(ctx, plates, "position", camera=camera, size=SIZE, timed=False)
    assert np.array_equal(coverage(m.image), coverage(every.image))
    assert m.path.scale.value_range == (0.0, 50.0)


def test_flange_style_refusals():
    with pytest.raises(ValueError, match="threshold"):
        FlangeStyle(threshold=0.0)
    with pytest.raises(ValueError, match="exceeds"):
        FlangeStyle(threshold=60.0, cutoff=50.0)
    with pytest.raises(ValueError, match="does not apply"):
        FlangeStyle(field="thickness")
    with pytest.raises(ValueError, match="show"):
        FlangeStyle(show="contours")
    with pytest.raises(ValueError, match="sets value_range"):
        FlangeStyle(value_range=(0.0, 9.0))
    assert make_path("flange").needs == {"gouraud", "part_distances"}
