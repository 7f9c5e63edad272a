"""The tables and claims of :mod:`workbench.reproductions.render_paths`: every first render path
on the car and the es2008 semicylinders, and the targets the foundation is judged by."""

from __future__ import annotations

from workbench.experiment.declare import Claim, Column, Declaration, Table, interval_columns
from workbench.experiment.report import interval, num

from .common import columns, timing

TABLE = Table(
    "table",
    columns("renderer", "scene", "case", "path", "style", "size", "samples", "triangles",
            "vertices", "bytes_uploaded", "bytes_per_step"),
    timing(), columns("mtri_per_s"),
    Column("set_step_ms", "ms", "time to switch the path to another time step (scenes with "
           "steps only)", optional=True),
    columns("derive_ms", "derive_bytes"),
    Column("skipped_ms", "ms", "derivation time the path's needs saved: what deriving "
           "everything would have cost on top"),
    Column("skipped_bytes", "B", "bytes of derived data the path's needs saved"),
    columns("reference", "max_diff_255"),
    Column("share_differing", "", "share of the drawn pixels whose colour differs from the "
           "reference"),
    columns("psnr_db", "ssim"),
    Column("wall_over_ours", "×", "pyvista/VTK's wall time (render + read-back) over ours "
           "(draw + read-back), separate measurements"),
    Column("peer_version", "", "the versions of VTK and pyvista drawing the row"),
    Column("lighting", "", "VTK's lighting and where it differs from ours"),
)

TARGETS = Table(
    "targets",
    columns("renderer", "scene", "size", "triangles"),
    Column("contour_wall_ms", "ms", "wall time of the per-pixel band draw"),
    Column("position_only_wall_ms", "ms", "wall time of the bare position-only draw (the "
           "floor)"),
    Column("contour_msaa_incl_readback_ms", "ms", "per-pixel bands with 4x MSAA, draw + "
           "read-back"),
    Column("pyrender_incl_readback_ms", "ms", "pyrender's render of the same triangles, "
           "read-back included"),
    Column("pyvista_incl_readback_ms", "ms", "pyvista/VTK's render of the same triangles, "
           "read-back included"),
    interval_columns("contour_over_position_only", "per-pixel bands' time over the "
                     "position-only draw's, interleaved"),
    interval_columns("contour_msaa_over_pyrender", "per-pixel bands with 4x MSAA and "
                     "read-back over pyrender's time, interleaved"),
    interval_columns("contour_msaa_over_pyvista", "per-pixel bands with 4x MSAA and "
                     "read-back over pyvista/VTK's time, interleaved"),
    interval_columns("gouraud_msaa_over_pyvista", "Gouraud with 4x MSAA and read-back over "
                     "pyvista/VTK's time (the same triangles), interleaved"),
    Column("pyrender_ssim", "", "SSIM of pyrender's image against our 4x MSAA Gouraud image"),
    Column("pyvista_ssim", "", "SSIM of pyvista/VTK's image against our 4x MSAA Gouraud image"),
    Column("nodes", "", "nodes the mesh's elements use"),
    Column("crease_vertices_added", "", "vertices the crease split adds for Gouraud shading"),
    columns("bytes_per_step"),
    Column("bytes_at_prepare", "B", "bytes the per-pixel band path uploads when prepared"),
)


def targets_claims(tables) -> list[str]:
    """Per scene: the band draw's time, over the position-only draw and over pyrender."""
    out = []
    for r in tables("targets"):
        out.append(f"{r['scene']} at {r['size']} ({r['triangles']:,} triangles): per-pixel "
                   f"bands {num(r['contour_wall_ms'])} ms, "
                   f"{interval(r, 'contour_over_position_only')} the position-only draw; with "
                   f"4× MSAA and read-back {interval(r, 'contour_msaa_over_pyrender')} "
                   f"pyrender's time (SSIM {num(r['pyrender_ssim'])} against it)")
    return out + ["ratios interleaved"] if out else out


def targets_headline(tables) -> list[str]:
    """The largest scene: per-pixel bands against the position-only draw and pyrender."""
    rows = tables("targets")
    if not rows:
        return []
    r = max(rows, key=lambda r: r["triangles"])
    return [f"{r['triangles']:,} triangles at {r['size']}: per-pixel bands "
            f"{num(r['contour_wall_ms'])} ms, {interval(r, 'contour_over_position_only')} the "
            f"position-only draw, {interval(r, 'contour_msaa_over_pyrender')} pyrender's (4× "
            f"MSAA)"]


DECLARED = Declaration(
    paper="es2008",
    tables=(TABLE, TARGETS),
    claims=(Claim("per-pixel bands against the floor and pyrender",
                  {"targets": ("scene", "size", "triangles", "contour_wall_ms",
                               "contour_over_position_only", "contour_over_position_only_lo",
                               "contour_over_position_only_hi", "contour_msaa_over_pyrender",
                               "contour_msaa_over_pyrender_lo", "contour_msaa_over_pyrender_hi",
                               "pyrender_ssim")},
                  targets_claims),),
    headline=Claim("per-pixel bands of the largest scene against the floor and pyrender",
                   {"targets": ("size", "triangles", "contour_wall_ms",
                                "contour_over_position_only", "contour_over_position_only_lo",
                                "contour_over_position_only_hi", "contour_msaa_over_pyrender",
                                "contour_msaa_over_pyrender_lo",
                                "contour_msaa_over_pyrender_hi")},
                   targets_headline),
)
