"""The flange path's thickness-aware threshold (crash2000 §4.1): a node is shown where it is
closer to another part than half the sum of the two shell thicknesses; on the two sheets of
the issue, 5 mm and 3 mm thick 3 mm apart (1 mm penetration) the overlap shows, 0.8 mm sheets
1.5 mm apart (0.7 mm clear) show nothing, where the fixed 2 mm threshold does the opposite."""

import numpy as np
import pytest
from meshes import quad_grid

from workbench.measurement.images import coverage
from workbench.measurement.rows import default_camera, measure
from workbench.paths import make_path
from workbench.paths.flange import FlangeStyle
from workbench.scene.mesh import FEMesh

SIZE = (140, 60)


def sheets(gap: float, t1: float, t2: float) -> FEMesh:
    """Part 1 at z = 0 over x 0..50, part 2 at z = ``gap`` over x 20..70 (5 mm quads, y
    0..20), thickness t1 and t2."""
    blocks = [quad_grid(10, 4, span=((0, 50), (0, 20)), z=0.0),
              quad_grid(10, 4, span=((20, 70), (0, 20)), z=gap)]
    nodes = np.concatenate([b[0] for b in blocks])
    elements = np.concatenate([blocks[0][1], blocks[1][1] + len(blocks[0][0])])
    parts = np.repeat([1, 2], [len(blocks[0][1]), len(blocks[1][1])])
    thickness = np.where(parts == 1, t1, t2).astype(float)
    return FEMesh(nodes=nodes, elements=elements.astype(np.int32), parts=parts,
                  element_fields={"thickness": thickness}, name=f"sheets {gap}")


def drawn(ctx, mesh, camera, mask=None):
    sub = mesh if mask is None else mesh.subset(mask)
    return coverage(measure(ctx, sub, "position", camera=camera, size=SIZE, timed=False).image)


def shown(ctx, mesh, camera, style):
    return coverage(measure(ctx, mesh, "flange", style, camera=camera, size=SIZE,
                            timed=False).image)


def test_5mm_and_3mm_sheets_3mm_apart_show_the_overlap(ctx):
    mesh = sheets(3.0, 5.0, 3.0)
    camera = default_camera(mesh, SIZE, view=(0.0, 90.0))
    x = mesh.nodes[mesh.elements][:, :, 0]
    inside = ((x >= 20) & (x <= 50)).all(axis=1)  # every node over the other sheet
    touching = ((x >= 20) & (x <= 50)).any(axis=1)
    seen = shown(ctx, mesh, camera, FlangeStyle(threshold="thickness"))
    assert (seen >= drawn(ctx, mesh, camera, inside)).all()
    assert not (seen & ~drawn(ctx, mesh, camera, touching)).any()
    assert seen.sum() > 0.3 * drawn(ctx, mesh, camera).sum()
    # the fixed 2 mm threshold misses this 1 mm penetration altogether
    assert not shown(ctx, mesh, camera, FlangeStyle(threshold=2.0)).any()


def test_0_8mm_sheets_1_5mm_apart_show_nothing(ctx):
    mesh = sheets(1.5, 0.8, 0.8)
    camera = default_camera(mesh, SIZE, view=(0.0, 90.0))
    assert not shown(ctx, mesh, camera, FlangeStyle(threshold="thickness")).any()
    # where the fixed 2 mm threshold lights up the overlap
    x = mesh.nodes[mesh.elements][:, :, 0]
    inside = ((x >= 20) & (x <= 50)).all(axis=1)
    assert (shown(ctx, mesh, camera, FlangeStyle(threshold=2.0))
            >= drawn(ctx, mesh, camera, inside)).all()
    # the signed map shows both sheets' clearance over the overlap, nothing hidden there
    signed = shown(ctx, mesh, camera, FlangeStyle(threshold="thickness", show="distance"))
    assert signed.sum() == drawn(ctx, mesh, camera).sum()


def test_thickness_threshold_style_and_refusals(ctx):
    style = FlangeStyle(threshold="thickness", depth_range=2.0)
    assert style.field == "penetration_depth"
    assert style.value_range == (-2.0, 2.0) and style.hide_range == (-2.0, 0.0)
    assert make_path("flange", style).needs == {"gouraud", "penetration_depths"}
    assert make_path("flange").needs == {"gouraud", "part_distances"}
    with pytest.raises(ValueError, match="depth_range"):
        FlangeStyle(threshold="thickness", depth_range=0.0)
    with pytest.raises(ValueError, match="threshold must be a positive distance or"):
        FlangeStyle(threshold="thick")
    bare = sheets(3.0, 5.0, 3.0)
    del bare.element_fields["thickness"]
    camera = default_camera(bare, SIZE, view=(0.0, 90.0))
    with pytest.raises(ValueError, match="thickness"):
        measure(ctx, bare, "flange", FlangeStyle(threshold="thickness"), camera=camera,
                size=SIZE, timed=False)


def test_the_viewer_offers_the_depth_range_in_thickness_mode(ctx):
    """The depth range replaces the threshold control; changing it prepares the path again:
    at 5 mm the clearance of the first node beyond the overlap (4 - sqrt(34) = -1.83 mm) is no
    longer clamped to -1 mm, so the visible edge moves towards the overlap."""
    from workbench.viewer import view

    def make(**options):
        return view(sheets(3.0, 5.0, 3.0), "flange", threshold="thickness", size=(80, 40),
                    angles=(0.0, 0.0), up="y", **options)

    viewer, fresh = make(), make(depth_range=5.0)
    try:
        assert set(viewer.controls) == {"bands", "depth_range"}
        before = (viewer.canvas.get_frame() < 255).any(axis=2).sum()
        viewer.controls["depth_range"].value = 5.0
        after = viewer.canvas.get_frame()
        assert 0 < (after < 255).any(axis=2).sum() < before
        np.testing.assert_array_equal(after, fresh.canvas.get_frame())
    finally:
        viewer.close()
        fresh.close()
