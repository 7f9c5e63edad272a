"""The tables and claims of :mod:`workbench.reproductions.table_software_raster` (es2008 Tables
2-3): the software rasterizer against llvmpipe, per-step times, the span table and sort-last
compositing."""

from __future__ import annotations

from workbench.experiment.declare import (
    Claim,
    Column,
    Declaration,
    Table,
    interval_columns,
)
from workbench.experiment.report import interval, num

from .common import columns

SCENE = Column("scene", "", "the es2008 benchmark: 8 semi-cylindrical sheets, quads per sheet "
               "in the label")
TRIANGLES = Column("triangles", "", "triangles of the scene")
TABLE_FIT = Column("table_fit_pct", "%", "share of the triangles drawn from the span table")

TABLE = Table(
    "table",
    SCENE, TRIANGLES, columns("size", "renderer", "case", "path", "wall_ms", "wall_ms_min",
                              "wall_ms_max", "mtri_per_s"),
    Column("speed_vs_llvmpipe_floor", "×", "llvmpipe's position-only wall time over this "
           "row's (separate measurements)"),
    Column("speed_vs_llvmpipe_same", "×", "llvmpipe's wall time for the same shading over this "
           "row's (separate measurements)"),
    Column("fragments", "", "fragments the software rasterizer shaded"),
    TABLE_FIT,
    Column("table_MB", "MB", "memory of the span table used"),
    columns("reference"),
    Column("differing_pct", "%", "share of the pixels differing from the EGL image of the same "
           "shading"),
    columns("max_diff_255"),
    Column("threads", "", "threads the software rasterizer drew with"),
    Column("fragment_pool_MB", "MB", "memory of the rasterizer's fragment pool"),
    Column("draw_peak_MB", "MB", "peak memory the draw allocated (tracemalloc; empty where not "
           "traced)"),
    Column("process_peak_MB", "MB", "the process's peak resident memory after the draw (empty "
           "where not traced)"),
    Column("differing_px_vs_half_space_0_bits", "px", "pixels differing from the half-space "
           "generator on the same 0-bit rule (0 required)"),
)

STEPS = Table(
    "steps",
    Column("step", "", "the pipeline step (\"total\" sums them)"),
    Column("vectorised", "", "whether the paper vectorised the step (Y/N)"),
    Column("small_off_ms", "ms", "the step's time on a small case with the kernels interpreted "
           "by Python (vectorisation off)"),
    Column("small_on_ms", "ms", "the step's time on the small case compiled (on)"),
    Column("small_ratio", "×", "small_off_ms over small_on_ms"),
    Column("{scene} es2008 pipeline ms", "ms", "the step's time in the paper's pipeline (span "
           "table S = 10, no early depth) on {scene}"),
    Column("{scene} GL rule + early depth ms", "ms", "the step's time in the default pipeline "
           "(llvmpipe's pixel rule, early depth) on {scene}"),
    Column("paper 1M off s", "s", "the paper's Table 2, 1 M triangles, vectorisation off"),
    Column("paper 1M on s", "s", "the paper's Table 2, 1 M triangles, vectorisation on"),
    Column("paper 1M ratio", "×", "the paper's Table 2 ratio off / on"),
    Column("paper 16.6M off s", "s", "the paper's Table 3, 16.6 M triangles, vectorisation "
           "off"),
    Column("paper 16.6M on s", "s", "the paper's Table 3, 16.6 M triangles, vectorisation on"),
    Column("paper 16.6M ratio", "×", "the paper's Table 3 ratio off / on"),
)

INTERLEAVED = Table(
    "interleaved",
    SCENE, TRIANGLES, columns("size", "renderer"),
    Column("case", "", "the software rasterizer's draw (GL rule, all threads)"),
    Column("against", "", "llvmpipe's draw it is timed against"),
    Column("software_ms", "ms", "the software rasterizer's median wall time in the interleaved "
           "run"),
    Column("llvmpipe_ms", "ms", "llvmpipe's median wall time in the interleaved run"),
    interval_columns("speed_vs_llvmpipe", "llvmpipe's time over the software rasterizer's, "
                     "interleaved"),
)

SPAN_TABLE = Table(
    "span_table",
    Column("S", "", "the span table's sub-pixel resolution S"),
    Column("entries", "", "entries of the table, 2 (2S)^5"),
    Column("MB", "MB", "memory of the table"),
    Column("paper_MB", "MB", "the paper's memory for the same S"),
    Column("build_s", "s", "time to build the table"),
    Column("cache_load_s", "s", "time to load it from the cache"),
    TABLE_FIT, columns("wall_ms"),
    Column("half_space_0_bits_wall_ms", "ms", "wall time of the half-space generator on the "
           "same 0-bit rule"),
    columns("reference"),
    Column("differing_px", "px", "pixels differing from the half-space generator's image (0 "
           "required)"),
)

COMPOSITE = Table(
    "composite",
    Column("scene", "", "the scene split into domains"),
    columns("size"),
    Column("split", "", "how the domains are split: by space or by part"),
    Column("domains", "", "domains D"),
    Column("method", "", "compositing: binary tree, binary swap, binary swap of drawn pixels "
           "(active-swap) or local"),
    Column("workers", "", "Dask worker processes"),
    Column("equal_to_one_process", "", "whether the composited image equals the one-process "
           "image"),
    Column("differing_px", "px", "pixels differing from the one-process image (colour, depth "
           "or triangle)"),
    Column("bytes_moved_MB", "MB", "bytes moved between workers"),
    Column("schedule_MB", "MB", "bytes of the compositing schedule"),
    Column("render_s", "s", "time rendering the domains"),
    Column("composite_s", "s", "time compositing"),
)


def speed_claims(tables) -> list[str]:
    """The interleaved speeds against llvmpipe, and the share of pixels off the GL image with
    llvmpipe's pixel rule."""
    out = []
    for r in tables("interleaved"):
        out.append(f"{r['scene']} at {r['size']}: {r['case']} {num(r['software_ms'])} ms, "
                   f"{interval(r, 'speed_vs_llvmpipe')} as fast as {r['against']} "
                   f"({num(r['llvmpipe_ms'])} ms)")
    gl_rule = [r for r in tables("table") if r.get("case") == "software bands, GL rule"]
    out += [f"{r['scene']}: with llvmpipe's pixel rule {num(r['differing_pct'])} % of the "
            f"pixels differ from the GL image" for r in gl_rule]
    return out + ["speeds interleaved"] if out else out


def speed_headline(tables) -> list[str]:
    """Software bands with llvmpipe's pixel rule on the largest scene against llvmpipe."""
    rows = [r for r in tables("interleaved") if r["case"] == "software bands, GL rule"]
    if not rows:
        return []
    r = rows[-1]
    return [f"{r['scene']} at {r['size']}: software bands {num(r['software_ms'])} ms, "
            f"{interval(r, 'speed_vs_llvmpipe')} as fast as {r['against']}, interleaved"]


DECLARED = Declaration(
    paper="es2008 Tables 2–3",
    tables=(TABLE, STEPS, INTERLEAVED, SPAN_TABLE, COMPOSITE),
    claims=(Claim("the software rasterizer's speed against llvmpipe",
                  {"interleaved": ("scene", "size", "case", "software_ms", "speed_vs_llvmpipe",
                                   "speed_vs_llvmpipe_lo", "speed_vs_llvmpipe_hi", "against",
                                   "llvmpipe_ms"),
                   "table": ("scene", "case", "differing_pct")},
                  speed_claims),),
    headline=Claim("the software bands' speed against llvmpipe",
                   {"interleaved": ("scene", "size", "case", "software_ms",
                                    "speed_vs_llvmpipe", "speed_vs_llvmpipe_lo",
                                    "speed_vs_llvmpipe_hi", "against")},
                   speed_headline),
)
