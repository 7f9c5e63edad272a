"""The tables and claims of :mod:`workbench.reproductions.table_bvh_distance` (crash2000 §4,
Table 2): the hierarchies, the references, connectivity, flanges and force tubes."""

from __future__ import annotations

from workbench.experiment.declare import Claim, Column, Declaration, Table
from workbench.experiment.report import num, span

from .common import columns

SCENE = Column("scene", "", "the model queried (the car deck, a refinement, generated panels "
               "standing in, or the paper's)")
BUILD_S = Column("build_s", "s", "time to build the hierarchies (median of 3 runs)")
QUERY_S = Column("query_s", "s", "time to query every node (median of 3 runs)")
QPS = Column("queries_per_s", "1/s", "node queries per second, build apart")
MAX_ABS = Column("max_abs_error_mm", "mm", "largest distance error against exact arithmetic "
                 "(references: against our float64 distances)")
NODES_WITHIN = Column("nodes_within", "", "nodes within 1.5 mm of another part")

TABLE = Table(
    "table",
    SCENE,
    Column("nodes", "", "nodes of the model"),
    Column("elements", "", "elements of the model"),
    Column("parts", "", "parts of the model"),
    Column("kind", "", "the bounding volumes: AABB or OBB"),
    Column("elements_per_leaf", "", "elements per leaf of the hierarchy"),
    Column("n_bvs", "", "bounding volumes of the hierarchies (#BVs)"),
    Column("point_bv_tests", "", "point/bounding-volume tests"),
    Column("point_element_tests", "", "point/element tests"),
    Column("plane_skips", "", "elements skipped by the point-to-plane test"),
    Column("plane_skip_pct", "%", "plane_skips as a share of the leaf elements reached"),
    BUILD_S, QUERY_S, QPS, NODES_WITHIN,
    Column("checked_nodes", "", "nodes checked against exact rational arithmetic (a random "
           "sample)"),
    Column("checked_within", "", "checked nodes within the cut-off in both"),
    MAX_ABS,
    Column("max_rel_error", "", "largest relative distance error against exact arithmetic"),
    Column("same_nodes_within", "", "whether exactly the same nodes are within the cut-off"),
    Column("max_change_translated_1e6_mm", "mm", "largest change of a distance when the model "
           "is translated by 10^6 mm"),
)

REFERENCES = Table(
    "references",
    SCENE,
    Column("tool", "", "the tool answering the queries (ours, libigl, open3d, trimesh, coal, "
           "fcpw)"),
    Column("queries", "", "node queries answered"),
    BUILD_S, QUERY_S, QPS,
    Column("speed_vs_ours", "×", "queries per second over our faster exact path's"),
    MAX_ABS,
    Column("nodes_off", "", "nodes off the exact distance by more than 1e-6 mm"),
    Column("nodes_flagged", "", "nodes the check flags"),
    Column("constraints", "", "precision, threads and rules the tool ran with (or why it did "
           "not run)"),
    Column("cutoff_disagreements", "", "nodes on the other side of the 1.5 mm cut-off from the "
           "exact answer"),
)

CONNECTIVITY = Table(
    "connectivity",
    Column("part_a", "", "one part of the pair"),
    Column("part_b", "", "the other part"),
    Column("min_distance_mm", "mm", "the smallest node-to-element distance between them"),
    NODES_WITHIN,
)

FLANGE = Table(
    "flange",
    SCENE,
    Column("view", "", "the image: the distance map or the flange view"),
    columns("wall_ms", "gpu_ms", "derive_ms", "covered_px", "renderer"),
)

FORCETUBE = Table(
    "forcetube",
    Column("case", "", "the tube: the closed form, or a crush step of the car's rails"),
    Column("max_rel_error_vs_closed_form", "", "largest relative error of the section force "
           "against the closed form"),
    # the car's rails only: absent without the shared car deck
    Column("planes", "", "section planes along the rail", optional=True),
    Column("max_compression_kN", "kN", "largest axial compression", optional=True),
    Column("max_tension_kN", "kN", "largest axial tension", optional=True),
    Column("elements_cut", "", "elements the planes cut", optional=True),
    Column("equal_forces", "", "whether the hierarchy gives the brute-force forces exactly",
           optional=True),
    Column("hierarchy_s", "s", "time of the planes through the hierarchy", optional=True),
    Column("brute_force_s", "s", "time of the planes by brute force", optional=True),
)


def distance_claims(tables) -> list[str]:
    """The largest of our models: queries per second, exactness, and libigl and open3d."""
    rows = [r for r in tables("table") if r.get("queries_per_s")
            and not str(r["scene"]).startswith("paper")]
    if not rows:
        return []
    scene = rows[-1]["scene"]  # the largest of our scenes comes last
    ours = [r for r in rows if r["scene"] == scene]
    errors = [r["max_abs_error_mm"] for r in ours if r.get("max_abs_error_mm") is not None]
    out = [f"{scene} ({ours[0]['nodes']:,} nodes): "
           f"{span([r['queries_per_s'] / 1e6 for r in ours])} M queries/s, largest error "
           f"against exact rational arithmetic {num(max(errors) if errors else None)} mm"]
    for r in tables("references"):
        if r["scene"] == scene and r["tool"] in ("libigl", "open3d") and r.get("queries_per_s"):
            out.append(f"{r['tool']} {num(r['queries_per_s'] / 1e6)} M queries/s "
                       f"({num(r['speed_vs_ours'])}× ours), largest error "
                       f"{num(r['max_abs_error_mm'])} mm, {r['nodes_flagged']} nodes flagged")
    return out + ["separate measurements"]


def distance_headline(tables) -> list[str]:
    """The largest of our models: queries per second, exactness, libigl's and open3d's speed."""
    rows = [r for r in tables("table") if r.get("queries_per_s")
            and not str(r["scene"]).startswith("paper")]
    if not rows:
        return []
    scene = rows[-1]["scene"]
    ours = [r for r in rows if r["scene"] == scene]
    errors = [r["max_abs_error_mm"] for r in ours if r.get("max_abs_error_mm") is not None]
    peers = [f"{r['tool']} {num(r['speed_vs_ours'])}×" for r in tables("references")
             if r["scene"] == scene and r["tool"] in ("libigl", "open3d")
             and r.get("speed_vs_ours")]
    return [f"{scene} ({ours[0]['nodes']:,} nodes): "
            f"{span([r['queries_per_s'] / 1e6 for r in ours])} M exact queries/s (largest error "
            f"{num(max(errors) if errors else None)} mm); {', '.join(peers) or 'no peer'} ours"]


DECLARED = Declaration(
    paper="crash2000 §4, Table 2",
    tables=(TABLE, REFERENCES, CONNECTIVITY, FLANGE, FORCETUBE),
    claims=(Claim("node queries per second and exactness, against libigl and open3d",
                  {"table": ("scene", "nodes", "queries_per_s", "max_abs_error_mm"),
                   "references": ("scene", "tool", "queries_per_s", "speed_vs_ours",
                                  "max_abs_error_mm", "nodes_flagged")},
                  distance_claims),),
    headline=Claim("node queries per second against libigl and open3d",
                   {"table": ("scene", "nodes", "queries_per_s", "max_abs_error_mm"),
                    "references": ("scene", "tool", "speed_vs_ours")},
                   distance_headline),
)
