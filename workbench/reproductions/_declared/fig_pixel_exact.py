"""The tables and claims of :mod:`workbench.reproductions.fig_pixel_exact` (st2005): per vertex
against per pixel on spacetime slices with exact images, slicing, the sweeps and stability."""

from __future__ import annotations

from workbench.experiment.declare import (
    Claim,
    Column,
    Declaration,
    Table,
    interval_columns,
)
from workbench.experiment.report import interval, num, span

from .common import columns, timing

TARGET = Column("target_polygons", "", "the slice size asked for, in polygons")
CELLS = Column("cells", "", "the space mesh, cells across x cells down (or its label)")
TETS = Column("tets", "", "tetrahedra of the spacetime mesh")
POLYGONS = Column("polygons", "", "polygons of the slice drawn")
PATH = Column("path", "", "per_vertex or per_pixel colour")
CASE = Column("case", "", "what the row checks")
ERRORS = (
    Column("max_diff_255", "1/255", "largest colour error against the exact image, over the "
           "covered pixels"),
    Column("mean_diff_255", "1/255", "mean colour error against the exact image"),
    Column("share_over_1", "", "share of the covered pixels more than 1/255 off the exact "
           "image"),
    Column("share_over_1_off_edges", "", "the same share, pixels within 0.01 px of an element "
           "edge set aside (there the rasterizer may pick the neighbour)"),
    Column("max_diff_255_off_edges", "1/255", "largest colour error off element edges"),
    Column("uncovered", "px", "pixels the exact image covers and the render left white"),
)
CRACKS = Column("crack_pixels", "px", "background pixels enclosed by the surface in an "
                "oblique perspective view (cracks)")
NAN_PIXELS = Column("nan_pixels", "px", "pixels whose exact colour is NaN")

TABLE = Table(
    "table",
    TARGET, CELLS, TETS, POLYGONS,
    Column("quads", "", "quadrilaterals among the polygons"),
    Column("slice_ms", "ms", "median time to slice one frame (incremental)"),
    PATH,
    Column("edge_overdraw", "", "element edges: none, lines over the fill (\"over\", the "
           "paper's), lines behind it (\"behind\"), lines and skirts behind it (\"skirts\")"),
    Column("element_store", "", "where the element records are: a buffer texture (\"buffer\") "
           "or the paper's 2-D texture rectangle (\"texture\")"),
    timing(),
    Column("prepare_ms", "ms", "time to upload the slice, program linking included"),
    columns("bytes_uploaded"), ERRORS, CRACKS, columns("renderer", "size"),
    Column("wall_vs_per_vertex", "×", "wall time over per vertex's without overdraw (separate "
           "measurements)"),
)

SLICING = Table(
    "slicing",
    TETS,
    Column("build_s", "s", "time to build the slicer"),
    Column("sort_s", "s", "time to sort the tetrahedra by time"),
    Column("frames", "", "frames sliced as t advances"),
    Column("polygons_median", "", "median polygons per slice"),
    Column("polygons_max", "", "most polygons of a slice"),
    Column("incremental_ms_median", "ms", "median time of an incremental slice"),
    Column("incremental_ms_max", "ms", "slowest incremental slice"),
    Column("first_frame_ms", "ms", "time of the first slice"),
    Column("shared_facets_s", "s", "time to derive the shared facets (once per mesh)"),
    Column("with_outer_ms_median", "ms", "median incremental slice with the domain-boundary "
           "edges"),
    Column("brute_force_ms_median", "ms", "median time slicing every tetrahedron from scratch"),
    Column("speedup", "×", "brute_force_ms_median over incremental_ms_median"),
    Column("last_slice_area_error", "", "relative error of the last slice's area against the "
           "domain's"),
)

SWEEP = Table(
    "sweep",
    Column("sweep", "", "what is varied: the quadrisection threshold or the mesh resolution"),
    CELLS,
    Column("threshold_mm2", "mm²", "the quadrisection threshold (empty: none)"),
    Column("threshold_vs_mean_area", "", "the threshold over the mean polygon area"),
    POLYGONS, PATH, columns("wall_ms", "gpu_ms"), ERRORS, CRACKS,
    Column("crack_pixels_skirts", "px", "crack pixels with skirts"),
    columns("renderer"),
    Column("fit_U_err_max", "kJ/m³", "the fitted solution's largest strain energy density "
           "error against the closed form"),
)

INTERLEAVED = Table(
    "interleaved",
    TARGET, POLYGONS, columns("size", "renderer"),
    Column("per_pixel_ms", "ms", "per pixel's wall time in the interleaved run"),
    Column("per_vertex_ms", "ms", "per vertex's wall time in the interleaved run"),
    interval_columns("per_pixel_over_per_vertex", "per pixel's time over per vertex's, "
                     "interleaved"),
)

STABILITY = Table(
    "stability",
    CASE,
    Column("offset_mm", "mm", "the domain's distance from the origin"),
    POLYGONS, ERRORS,
    Column("f32_global_U_err_rel", "", "largest relative error of U evaluated in global float32 "
           "coordinates"),
    Column("f32_local_U_err_rel", "", "largest relative error of U evaluated in element-local "
           "float32 coordinates"),
    NAN_PIXELS, columns("renderer"),
    Column("t_us", "µs", "the time of the slice"),
    Column("zero_area_polygons", "", "polygons of (numerically) zero area"),
    Column("nan_corners", "", "polygon corners that are not finite"),
    Column("area_error", "", "relative error of the slice's area against the domain's"),
    Column("zero_U_pixels", "px", "covered pixels where U vanishes"),
)


def exactness_claims(tables) -> list[str]:
    """The largest slice: pixels off the exact image per pixel and per vertex, cracks, and
    per pixel's time over per vertex's."""
    rows = [r for r in tables("table") if r.get("wall_vs_per_vertex") is not None]
    if not rows:
        return []
    top = max(r["polygons"] for r in rows)
    rows = [r for r in rows if r["polygons"] == top]
    plain = {r["path"]: r for r in rows
             if r["edge_overdraw"] == "none" and r["element_store"] == "buffer"}
    if not {"per_pixel", "per_vertex"} <= set(plain):
        return []
    pixel, vertex = plain["per_pixel"], plain["per_vertex"]
    out = [f"{top:,} polygons, no edge overdraw: per pixel {num(100 * pixel['share_over_1'])} "
           f"% of the covered pixels more than 1/255 off the exact image, per vertex "
           f"{num(100 * vertex['share_over_1'])} %; skirts leave "
           f"{span([r['crack_pixels'] for r in rows if r['edge_overdraw'] == 'skirts'])} crack "
           f"pixels"]
    out += [f"{r['polygons']:,} polygons at {r['size']}: per pixel "
            f"{interval(r, 'per_pixel_over_per_vertex')} per vertex's time "
            f"({num(r['per_pixel_ms'])} against {num(r['per_vertex_ms'])} ms), interleaved"
            for r in tables("interleaved")]
    return out


def exactness_headline(tables) -> list[str]:
    """The largest slice: pixels off the exact image per pixel and per vertex, and per
    pixel's time over per vertex's, interleaved."""
    rows = [r for r in tables("table") if r["edge_overdraw"] == "none"
            and r["element_store"] == "buffer" and r.get("share_over_1") is not None]
    timed = tables("interleaved")
    if not rows or not timed:
        return []
    top = max(r["polygons"] for r in rows)
    plain = {r["path"]: r for r in rows if r["polygons"] == top}
    if not {"per_pixel", "per_vertex"} <= set(plain):
        return []
    pixel, vertex = (num(100 * plain[p]["share_over_1"]) for p in ("per_pixel", "per_vertex"))
    return [f"{top:,} polygons: {pixel} % of pixels > 1/255 off the exact image per pixel, "
            f"{vertex} % per vertex, at {interval(timed[-1], 'per_pixel_over_per_vertex')} its "
            f"time"]


DECLARED = Declaration(
    paper="st2005",
    tables=(TABLE, SLICING, SWEEP, INTERLEAVED, STABILITY),
    claims=(Claim("pixels off the exact image, cracks, and per pixel's cost",
                  {"table": ("polygons", "path", "edge_overdraw", "element_store",
                             "wall_vs_per_vertex", "share_over_1", "crack_pixels"),
                   "interleaved": ("polygons", "size", "per_pixel_over_per_vertex",
                                   "per_pixel_over_per_vertex_lo",
                                   "per_pixel_over_per_vertex_hi", "per_pixel_ms",
                                   "per_vertex_ms")},
                  exactness_claims),),
    headline=Claim("pixels off the exact image, and per pixel's cost",
                   {"table": ("polygons", "path", "edge_overdraw", "element_store",
                              "share_over_1"),
                    "interleaved": ("per_pixel_over_per_vertex", "per_pixel_over_per_vertex_lo",
                                    "per_pixel_over_per_vertex_hi")},
                   exactness_headline),
)
