"""The tables and claims of :mod:`workbench.reproductions.table_fe_texture_wireframe` (fe2003
Tables 1-3): simplified FE meshes with a normal map and a wire-frame texture against the
original with line overdraw."""

from __future__ import annotations

from workbench.algo.fepatch.pipeline import STAGES
from workbench.experiment.declare import Claim, Column, Declaration, Table
from workbench.experiment.report import num

from .common import WIRE, columns, timing

SCENE = Column("scene", "", "the mesh simplified (the car, refined or displaced, or generated "
               "panels)")
SET = Column("set", "", "the paper's parameter set (A or B)")
RULES = Column("rules", "", "the construction rules: the new ones, or a rule before a change "
               "(\"paper\", \"certified d, paper texture\", \"distance texture\")")
CASE = Column("case", "", "what was drawn: original or simplified, shading and wire frame")
D_MM = Column("d_mm", "mm", "d: the distance bound of the simplification")
TRIANGLES = Column("triangles", "", "triangles drawn")
LINE_EDGES = Column("line_edges", "", "edges drawn as lines")
NARROW = Column("narrow_elements", "", "elements drawn as lines because the atlas scale leaves "
                "them narrower than the wire texture can outline")
TEXELS = Column("rgba_texels_per_element", "", "texture memory in RGBA texels (4 bytes) per "
                "original element")
FIT_SHARE = Column("fit_share", "", "the subpatch fit tolerance over d")
ENCODING = Column("wire_encoding", "", "the wire texture: \"corners\" (element ids) or "
                  "\"distance\" (fe2003's distance texture)")
SPEED = Column("speed_vs_overdraw", "×", "wall time of the original + line overdraw over this "
               "row's (separate measurements)")
HAUSDORFF = Column("hausdorff_mm", "mm", "certified one-sided Hausdorff distance original → "
                   "simplified (upper end of its bracket)")
ERRORS = (D_MM, HAUSDORFF,
          Column("hausdorff_lower_mm", "mm", "lower end of the Hausdorff bracket"),
          Column("hausdorff_pct_diag", "%", "hausdorff_mm as a share of the bounding-box "
                 "diagonal"),
          Column("hausdorff_s", "s", "time to certify the Hausdorff bracket"),
          Column("within_d", "", "whether the certified distance is within d"))

PARAMS = Table(
    "params",
    SET,
    Column("alpha_g1_deg", "°", "the crease angle below which edges are G1 (smooth)"),
    D_MM,
    Column("l_outer_mm", "mm", "the outer line length limit"),
    Column("l_inner_mm", "mm", "the inner line length limit"),
)

PREPROCESSING = Table(
    "preprocessing",
    SCENE, SET, RULES,
    Column("elements", "", "elements of the original mesh"),
    Column("patches", "", "patches between feature lines"),
    Column("subpatches", "", "subpatches, each retriangulated and textured"),
    Column("g0_edges", "", "G0 feature edges (creases)"),
    Column("g1_edges", "", "G1 feature edges"),
    Column("closing_edges", "", "edges added to close patches"),
    Column("line_nodes", "", "nodes on feature lines"),
    Column("line_nodes_kept", "", "line nodes kept by the line simplification"),
    Column("fallback_subpatches", "", "subpatches kept as original elements"),
    Column("original_triangles", "", "triangles of the original mesh"),
    Column("simplified_triangles", "", "triangles of the simplified mesh"),
    Column("atlas", "", "texture atlas size, width x height in texels"),
    TEXELS, ENCODING, NARROW, FIT_SHARE,
    Column("split_subpatches", "", "subpatches regrown for the distance bound"),
    Column("kept_subpatches", "", "subpatches kept as original elements for the bound"),
    Column("certified_bound_mm", "mm", "the largest certified per-subpatch distance original → "
           "simplified"),
    [Column(f"{stage} s", "s", f"time of the stage: {stage}") for stage in STAGES],
    Column("certification s", "s", "time certifying the distance bound (part of the "
           "retriangulation)"),
    Column("total s", "s", "time of every stage"),
)

TABLE = Table(
    "table",
    columns("renderer"), SCENE, columns("size"), CASE, SET, RULES, TRIANGLES, LINE_EDGES,
    timing(), SPEED,
    Column("gpu_speed_vs_overdraw", "×", "GPU time of the original + line overdraw over this "
           "row's"),
    TEXELS,
    Column("texture_mb", "MiB", "texture memory"),
    NARROW, columns("ssim", "reference", *WIRE), ERRORS,
)

TABLE3 = Table(
    "table3",
    columns("renderer"), SCENE, columns("size"), CASE, RULES, TRIANGLES, LINE_EDGES,
    columns("gpu_ms", "wall_ms"), SPEED, TEXELS, HAUSDORFF, D_MM,
    columns("wire_precision_1px", "wire_recall_1px", "wire_iou_1px", "ssim"),
)

SWEEP = Table(
    "sweep",
    SCENE, CASE,
    Column("alpha_g1_deg", "°", "the crease angle below which edges are G1"),
    D_MM,
    Column("l_outer_mm", "mm", "the outer line length limit"),
    Column("l_inner_mm", "mm", "the inner line length limit"),
    FIT_SHARE,
    Column("certify", "", "whether the distance bound is certified"),
    ENCODING,
    Column("texels_per_edge", "", "texels across the scale-setting element width or extent"),
    Column("scale_by", "", "what sets the atlas scale: element \"width\" or \"extent\""),
    Column("scale_quantile", "", "the quantile of the subpatch's element widths (extents) that "
           "spans texels_per_edge"),
    Column("atlas_turns", "", "in-plane turns tried for each subpatch's smallest rectangle"),
    Column("border", "", "texels around each subpatch in the atlas"),
    Column("normal_reduction", "", "the normal map's size reduction factor"),
    Column("min_width", "", "elements narrower than this many texels are drawn as lines"),
    TRIANGLES, LINE_EDGES, NARROW,
    Column("preprocessing_s", "s", "time to build the simplified model"),
    columns("wall_ms"), SPEED, TEXELS, columns(*WIRE), ERRORS[1:],
)

CLOSEUP = Table(
    "closeup",
    SCENE,
    Column("view", "", "the magnified view"),
    CASE, RULES, ENCODING, columns(*WIRE, "ssim"),
)


def table3_claims(tables) -> list[str]:
    """Simplified A with its wire texture: triangles, time, speed, wire IoU and distance."""
    rows = [r for r in tables("table3") if r.get("speed_vs_overdraw") is not None]
    wanted = [r for r in rows if "simplified A" in r["case"] and "wire" in r["case"]]
    return [f"{r['scene']}: {r['case']} {r['triangles']:,} triangles, {num(r['wall_ms'])} ms, "
            f"{num(r['speed_vs_overdraw'])}× the original with line overdraw (separate "
            f"measurements), wire IoU {num(r.get('wire_iou_1px'))}, certified distance "
            f"{num(r.get('hausdorff_mm'))} mm" for r in wanted[:2]]


def table3_headline(tables) -> list[str]:
    """The first scene's simplified A with its wire texture against line overdraw."""
    rows = [r for r in tables("table3") if r.get("speed_vs_overdraw") is not None
            and "simplified A" in r["case"] and "wire" in r["case"]]
    if not rows:
        return []
    r = rows[0]
    return [f"{r['scene']}: set A with normal map and wire texture, {r['triangles']:,} "
            f"triangles, {num(r['speed_vs_overdraw'])}× line overdraw's speed, wire IoU "
            f"{num(r.get('wire_iou_1px'))}, within {num(r.get('hausdorff_mm'))} mm"]


DECLARED = Declaration(
    paper="fe2003 Tables 1–3",
    tables=(PARAMS, PREPROCESSING, TABLE, TABLE3, SWEEP, CLOSEUP),
    claims=(Claim("simplified set A with the wire texture against line overdraw",
                  {"table3": ("scene", "case", "triangles", "wall_ms", "speed_vs_overdraw",
                              "wire_iou_1px", "hausdorff_mm")},
                  table3_claims),),
    headline=Claim("simplified set A with the wire texture against line overdraw",
                   {"table3": ("scene", "case", "triangles", "speed_vs_overdraw",
                               "wire_iou_1px", "hausdorff_mm")},
                   table3_headline),
)
