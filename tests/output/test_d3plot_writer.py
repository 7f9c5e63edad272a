"""A generated result written as a d3plot (:mod:`workbench.output.d3plot`) and read back by the
d3plot reader: coordinates at every state (to float32), parts, triangles, plastic strain and
element deletion as given."""

import numpy as np
import pytest

from workbench.output.d3plot import write_d3plot
from workbench.scene.mesh import FEMesh
from workbench.scene.readers import load


def test_a_written_result_reads_back_as_given(tmp_path):
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0],
                      [3, 0, 0]], float) + [1e3, -2e3, 5e2]
    elements = np.array([[0, 1, 2, 3], [1, 4, 5, 2], [4, 6, 5, 5]])
    steps = np.stack([nodes + [0.0, 0.0, 0.25 * t * t] for t in range(3)])
    alive = np.ones((3, 3), np.float32)
    alive[2, 1] = 0
    strain = np.arange(9, dtype=np.float32).reshape(3, 3) / 10
    mesh = FEMesh(nodes=nodes, elements=elements, parts=np.array([4, 4, 9]), steps=steps,
                  times=np.array([0.0, 1e-3, 2e-3]),
                  element_fields={"alive": alive, "plastic_strain": strain}, name="plates")
    read = load(write_d3plot(mesh, tmp_path))
    assert read.steps.shape == steps.shape
    # float32 storage: each coordinate within half an ulp of float32 at its magnitude
    assert np.abs(read.steps - steps).max() <= np.spacing(np.float32(2e3)) / 2
    assert sorted(np.unique(read.parts)) == [4, 9]
    assert [read.n_deleted(k) for k in range(3)] == [0, 0, 1]
    assert not read.alive(2)[1] and read.alive(2)[[0, 2]].all()
    assert np.allclose(read.element_field("plastic_strain", 2), strain[2])
    assert len(read.triangulation.triangles) == 5  # two quads and one triangle


def test_a_mesh_without_states_is_refused(tmp_path):
    mesh = FEMesh(nodes=np.eye(3), elements=np.array([[0, 1, 2]]), parts=np.array([1]))
    with pytest.raises(ValueError, match="has none"):
        write_d3plot(mesh, tmp_path)
