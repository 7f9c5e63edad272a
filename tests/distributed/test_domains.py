"""Domain decomposition for sort-last rendering: partitions of a mesh's triangles by space
(recursive centroid bisection) and by whole parts."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.distributed.domains import split_domains
from workbench.scene.generators import semicylinders
from workbench.scene.mesh import FEMesh

SHEETS = semicylinders(sheets=4, n=8)  # 4 parts of 128 triangles, 512 in all


def assert_partition(domains, mesh, count):
    assert len(domains) == count
    for d in domains:
        assert d.dtype == np.int64 and d.ndim == 1 and len(d) > 0
        assert (np.diff(d) > 0).all()  # sorted, no repeats
    together = np.sort(np.concatenate(domains))
    np.testing.assert_array_equal(together, np.arange(len(mesh.triangles)))


def centroids(mesh, step=0):
    return mesh.coordinates(step)[mesh.triangles].mean(axis=1)


@pytest.mark.parametrize("count", [1, 2, 3, 4, 5, 7, 8, 13, 512])
def test_space_partition_covers_once_and_balances(count):
    domains = split_domains(SHEETS, count)
    assert_partition(domains, SHEETS, count)
    sizes = [len(d) for d in domains]
    # balanced within one triangle: every domain holds floor(K / count) or ceil(K / count)
    assert max(sizes) - min(sizes) <= 1
    assert min(sizes) == 512 // count


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 60), st.integers(1, 6))
def test_space_balances_any_count(count, n):
    mesh = semicylinders(sheets=2, n=n)
    triangles = len(mesh.triangles)
    if count > triangles:
        with pytest.raises(ValueError, match="non-empty domains"):
            split_domains(mesh, count)
        return
    domains = split_domains(mesh, count)
    assert_partition(domains, mesh, count)
    sizes = [len(d) for d in domains]
    assert max(sizes) - min(sizes) <= 1


def test_space_cuts_across_the_longest_axis():
    # the sheets' centroids span x and y alike (200 mm) and z less: the first cut is across x
    low, high = split_domains(SHEETS, 2)
    c = centroids(SHEETS)
    assert c[low, 0].max() <= c[high, 0].min()
    # four domains: each half is cut again across its own longest axis (y now), so the four
    # boxes are disjoint quadrants of the x-y plane
    quads = split_domains(SHEETS, 4)
    boxes = [(c[d, 0].min(), c[d, 0].max(), c[d, 1].min(), c[d, 1].max()) for d in quads]
    assert boxes[0][3] <= boxes[1][2] and boxes[2][3] <= boxes[3][2]
    assert boxes[0][1] <= boxes[2][0]


def test_space_uses_step_zero_coordinates():
    # step 0 stretches y tenfold: the first cut must follow y, not the nodes' x
    stretched = SHEETS.nodes * [1.0, 10.0, 1.0]
    mesh = FEMesh(SHEETS.nodes, SHEETS.elements, SHEETS.parts,
                  steps=np.stack([stretched, SHEETS.nodes]))
    low, high = split_domains(mesh, 2)
    c = centroids(mesh, 0)
    assert c[low, 1].max() <= c[high, 1].min()
    assert not c[low, 0].max() <= c[high, 0].min()


@pytest.mark.parametrize("count", [1, 2, 3, 4])
def test_part_partition_keeps_parts_whole(count):
    domains = split_domains(SHEETS, count, by="part")
    assert_partition(domains, SHEETS, count)
    part_of = SHEETS.parts[SHEETS.triangulation.element_of]
    seen = set()
    for d in domains:
        parts = set(np.unique(part_of[d]).tolist())
        assert not parts & seen
        seen |= parts
        # whole: every triangle of each of its parts is in the domain
        assert len(d) == np.isin(part_of, list(parts)).sum()
    assert seen == {0, 1, 2, 3}
    assert [d[0] for d in domains] == sorted(d[0] for d in domains)


def test_part_groups_are_greedily_balanced():
    # parts of 40, 30, 20 and 10 quads (80, 60, 40, 20 triangles): largest first into the
    # lightest domain gives {80, 20} and {60, 40}
    parts = np.repeat(np.int32([3, 1, 0, 2]), [40, 30, 20, 10])
    mesh = FEMesh(SHEETS.nodes, SHEETS.elements[:100], parts)
    part_of = mesh.parts[mesh.triangulation.element_of]
    domains = split_domains(mesh, 2, by="part")
    assert_partition(domains, mesh, 2)
    groups = sorted(sorted(set(part_of[d].tolist())) for d in domains)
    assert groups == [[0, 1], [2, 3]]
    assert sorted(len(d) for d in domains) == [100, 100]
    # three domains: 80 | 60 | 40 + 20
    assert sorted(len(d) for d in split_domains(mesh, 3, by="part")) == [60, 60, 80]


def test_refusals():
    with pytest.raises(ValueError, match="integer >= 1"):
        split_domains(SHEETS, 0)
    with pytest.raises(ValueError, match="integer >= 1"):
        split_domains(SHEETS, -2)
    with pytest.raises(ValueError, match="integer >= 1"):
        split_domains(SHEETS, 2.5)
    with pytest.raises(ValueError, match="513 non-empty domains"):
        split_domains(SHEETS, 513)
    with pytest.raises(ValueError, match="4 parts with triangles cannot make 5"):
        split_domains(SHEETS, 5, by="part")
    with pytest.raises(ValueError, match="unknown domain split 'octree'"):
        split_domains(SHEETS, 2, by="octree")
