"""The tables and claims of :mod:`workbench.reproductions.table_quad_strips` (crash2000 Table 1):
quad strips against triangle strips, the paper's table beside ours, the cutoff sweep and the
draws."""

from __future__ import annotations

from workbench.experiment.declare import Claim, Column, Declaration, Table
from workbench.experiment.report import num

from .common import WIRE, columns, timing

TABLE = Table(
    "table",
    Column("scene", "", "the mesh stripped"),
    Column("kind", "", "what the mesh is (generated panels, the car, a car part, a refinement)"),
    Column("elements", "", "shell elements of the mesh"),
    Column("quads", "", "quadrilateral elements"),
    Column("triangle_elements", "", "triangular elements (stripped as degenerate quads)"),
    Column("degenerate", "", "degenerate quads (a repeated node)"),
    Column("verts_4n", "", "4n: the vertices of the elements sent one by one, as in the paper"),
    Column("tri_strips", "", "meshoptimizer triangle strips"),
    Column("tri_verts", "", "vertices the triangle strips send"),
    Column("tri_verts_pct", "%", "tri_verts as a share of 4n"),
    Column("tri_length", "", "mean triangles per triangle strip"),
    Column("tri_strip_ms", "ms", "time meshoptimizer took to strip"),
    Column("quad_strips", "", "our quad strips (bandification)"),
    Column("quad_leftover", "", "quads left out of every strip"),
    Column("quad_verts", "", "vertices the quad strips send"),
    Column("quad_verts_pct", "%", "quad_verts as a share of 4n"),
    Column("quad_length", "", "mean triangles per quad strip"),
    Column("quad_passes", "", "bandification passes"),
    Column("quad_strip_ms", "ms", "time our stripping took"),
    Column("quad_over_tri_verts", "×", "vertices sent by quad strips over those of triangle "
           "strips"),
)

PAPER = Table(
    "paper",
    Column("#quads (paper / ours)", "", "quads of the paper's mesh and of ours of that size"),
    Column("paper tri-strips", "", "the paper's triangle strips"),
    Column("paper tri #verts %", "%", "the paper's triangle-strip vertices as a share of 4n"),
    Column("paper tri length", "", "the paper's mean triangles per triangle strip"),
    Column("meshopt tri-strips", "", "meshoptimizer's triangle strips of our mesh"),
    Column("meshopt #verts %", "%", "meshoptimizer's strip vertices as a share of 4n"),
    Column("meshopt length", "", "meshoptimizer's mean triangles per strip"),
    Column("paper quad-strips", "", "the paper's quad strips"),
    Column("paper quad #verts %", "%", "the paper's quad-strip vertices as a share of 4n"),
    Column("paper quad length", "", "the paper's mean triangles per quad strip"),
    Column("our quad-strips", "", "our quad strips"),
    Column("our quad #verts %", "%", "our quad-strip vertices as a share of 4n"),
    Column("our quad length", "", "our mean triangles per quad strip"),
    Column("our stripping ms", "ms", "time our stripping took"),
)

CUTOFF = Table(
    "cutoff",
    Column("scene", "", "the mesh stripped"),
    Column("cutoff", "", "the bandification cutoff"),
    Column("strips", "", "quad strips at this cutoff"),
    Column("leftover_quads", "", "quads left out of every strip"),
    Column("verts", "", "vertices the quad strips send"),
    Column("verts_pct", "%", "verts as a share of 4n"),
    Column("length", "", "mean triangles per strip"),
    Column("passes", "", "bandification passes"),
    Column("strip_ms", "ms", "time the stripping took"),
    Column("meshopt_verts_pct", "%", "meshoptimizer's triangle-strip vertices as a share of 4n"),
)

DRAW = Table(
    "draw",
    columns("renderer", "scene", "size", "case", "path", "style", "triangles", "vertices",
            "vertices_sent", "strips"),
    Column("vs_invocations", "", "vertex-shader invocations of one draw (pipeline statistics "
           "query; empty where the driver has none)"),
    columns("bytes_per_step"), timing(),
    Column("wall_over_list", "×", "wall time over the indexed list with the strip diagonal"),
    columns("reference", "differing_px", "max_diff_255", *WIRE),
)


def strip_claims(tables) -> list[str]:
    """The largest generated panels and the car: the vertices quad and triangle strips send."""
    rows = [r for r in tables("table") if r.get("quad_verts_pct") is not None]
    if not rows:
        return []
    panels = [r for r in rows if str(r["scene"]).startswith("panels")]
    picked = [max(panels, key=lambda r: r["quads"])] if panels else []
    picked += [r for r in rows if r["scene"] == "car"][:1]  # the largest panels and the car
    return [f"{r['scene']} ({r['quads']:,} quads): quad strips send "
            f"{num(r['quad_verts_pct'])} % of 4n vertices, triangle strips "
            f"{num(r['tri_verts_pct'])} %" for r in picked]


def strip_headline(tables) -> list[str]:
    """The largest generated panels: the vertices quad and triangle strips send."""
    return strip_claims(tables)[:1]


DECLARED = Declaration(
    paper="crash2000 Table 1",
    tables=(TABLE, PAPER, CUTOFF, DRAW),
    claims=(Claim("vertices sent by quad and triangle strips",
                  {"table": ("scene", "quads", "quad_verts_pct", "tri_verts_pct")},
                  strip_claims),),
    headline=Claim("vertices sent by quad and triangle strips on the largest panels",
                   {"table": ("scene", "quads", "quad_verts_pct", "tri_verts_pct")},
                   strip_headline),
)
