"""crash2000 Table 1: quad strips by bandification against triangle strips, and what strips are
worth.

**Stripping table** (``table.md``), in the paper's columns: #quads, #verts = 4n (triangles count
as degenerate quads, as in the paper), then for meshoptimizer's triangle strips (of the mesh's
triangles, quads split along the shorter diagonal) and for our quad strips: #strips, #verts sent
(and % of 4n), mean triangles per strip, and the stripping time. Meshes: generated stamped
panels of the paper's five sizes, the car model (whole, each part, and its 2×2, 4×4 and 8×8
refinements) and the d3plot model. Strips are built over the node indices of the elements.
``paper.md`` puts the paper's own Table 1 beside the measured rows of the five sizes.

**Draw table** (``draw.md``): Gouraud shading of the largest meshes drawn as the indexed
triangle list (shorter and strip diagonals), meshoptimizer triangle strips and quad strips with
primitive restart, the line-overdraw wire frame and the single-pass ``quad_wire``; GPU and wall
time, vertices sent, vertex-shader invocations (pipeline statistics query) and the pixels each
stripped image differs from the unstripped image of the same triangles (0 is the requirement).
The wire-frame rows compare the single-pass wire pixels with the line overdraw's.

**Cutoff sweep** (``cutoff.md``, ``cutoff.png``): vertex share and strip count against the
bandification cutoff.

Run: ``workbench run table_quad_strips [--quick]``.
"""

from __future__ import annotations

from collections.abc import Iterator
from itertools import islice
from pathlib import Path

from workbench.algo.strips import quad_strips, tri_strips
from workbench.experiment.context import Case, ExperimentContext
from workbench.experiment.registry import experiment
from workbench.gl import Camera, VertexShaderInvocations
from workbench.measurement.images import difference_map, wire_agreement
from workbench.measurement.timing import time_call
from workbench.output.figures import save_image_grid
from workbench.output.tables import atomic_open
from workbench.paths import Style
from workbench.scene import generators

from ._declared.table_quad_strips import DECLARED

PAPER_SIZES = (2_215, 26_284, 51_473, 104_749, 255_641)
# crash2000 Table 1 as printed: #quads, #verts, opTriStripper (#strips, #verts, length),
# QuadStripper (#strips, #verts, length)
PAPER_TABLE_1 = (
    (2215, 8860, 560, 5657, 8.1, 231, 4848, 19.0),
    (26284, 105136, 11708, 78370, 4.7, 4085, 60365, 12.8),
    (51473, 205892, 13138, 131450, 8.0, 5806, 113308, 17.5),
    (104749, 418996, 36203, 283374, 5.8, 19667, 244244, 10.4),
    (255641, 1022564, 74590, 678418, 7.1, 35298, 575528, 14.3),
)
CUTOFFS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64)


def models(exp: ExperimentContext) -> Iterator[Case]:
    """The stripping suite as cases of each ``kind`` ("paper size", "car", "car part", "car
    refined", "d3plot"), smallest first within each kind: the same in quick runs (stripping is
    fast; quick runs draw and sweep smaller meshes); tiny: the smallest of each kind (the
    panels of the paper's first size, the car, its first part, its 2×2 refinement, the d3plot).
    The car and the d3plot are skipped, said, where the shared data is absent."""
    for n in exp.pick(PAPER_SIZES, PAPER_SIZES, PAPER_SIZES[:1]):
        yield Case(f"panels {n}", generators.stamped_panels(n), "paper size")
    car = exp.builtin("car")
    if car is not None:
        yield Case("car", car, "car")
        parts = (Case(f"car part {part}", car.part(part), "car part")
                 for part in sorted(car.part_names))
        yield from islice((c for c in parts if c.scene.n_elements), exp.pick(None, None, 1))
        for k in exp.pick((2, 4, 8), (2, 4, 8), (2,)):
            yield Case(f"car {k}x{k}", generators.refine(car, k), "car refined")
    d3plot = exp.builtin("d3plot")
    if d3plot is not None:
        yield Case("d3plot", d3plot, "d3plot")


def stripping_row(exp: ExperimentContext, case: Case) -> dict:
    """Our quad strips and meshoptimizer's triangle strips of ``case``: counts, vertices sent
    (and % of 4n), triangles per strip, and the median stripping wall ms of ``exp.repeats``."""
    mesh = case.scene
    four_n = 4 * mesh.n_elements
    quads = quad_strips(mesh.elements)
    tri = tri_strips(mesh.triangles, mesh.n_nodes)
    t_quad = time_call(lambda: quad_strips(mesh.elements), repeat=exp.repeats)
    t_tri = time_call(lambda: tri_strips(mesh.triangles, mesh.n_nodes), repeat=exp.repeats)
    return {
        "scene": case.label, "kind": case.kind, "elements": mesh.n_elements, "quads": mesh.n_quads,
        "triangle_elements": len(quads.triangles), "degenerate": len(quads.degenerate),
        "verts_4n": four_n,
        "tri_strips": tri.n_strips, "tri_verts": tri.n_vertices,
        "tri_verts_pct": 100 * tri.n_vertices / four_n,
        "tri_length": tri.mean_triangles_per_strip, "tri_strip_ms": t_tri.wall_ms,
        "quad_strips": quads.n_strips, "quad_leftover": len(quads.leftover),
        "quad_verts": quads.vertex_count, "quad_verts_pct": 100 * quads.vertex_count / four_n,
        "quad_length": quads.mean_triangles_per_strip, "quad_passes": quads.passes,
        "quad_strip_ms": t_quad.wall_ms,
        "quad_over_tri_verts": quads.vertex_count / tri.n_vertices,
    }


def paper_rows(rows: list[dict]) -> list[dict]:
    """The paper's Table 1 beside the measured rows of the same sizes."""
    measured = {r["scene"]: r for r in rows if r["kind"] == "paper size"}
    out = []
    for quads, verts, t_strips, t_verts, t_len, q_strips, q_verts, q_len in PAPER_TABLE_1:
        r = measured.get(f"panels {quads}")
        if r is None:
            continue
        out.append({
            "#quads (paper / ours)": f"{quads} / {r['quads']}",
            "paper tri-strips": t_strips, "paper tri #verts %": 100 * t_verts / verts,
            "paper tri length": t_len,
            "meshopt tri-strips": r["tri_strips"], "meshopt #verts %": r["tri_verts_pct"],
            "meshopt length": r["tri_length"],
            "paper quad-strips": q_strips, "paper quad #verts %": 100 * q_verts / verts,
            "paper quad length": q_len,
            "our quad-strips": r["quad_strips"], "our quad #verts %": r["quad_verts_pct"],
            "our quad length": r["quad_length"], "our stripping ms": r["quad_strip_ms"],
        })
    return out


def cutoff_rows(case: Case, cutoffs) -> list[dict]:
    """Our quad strips of ``case`` at each bandification cutoff beside meshoptimizer's share."""
    mesh = case.scene
    four_n = 4 * mesh.n_elements
    tri = tri_strips(mesh.triangles, mesh.n_nodes)
    rows = []
    for cutoff in cutoffs:
        quads = quad_strips(mesh.elements, cutoff)
        t = time_call(lambda c=cutoff: quad_strips(mesh.elements, c), warmup=0, repeat=5)
        rows.append({"scene": case.label, "cutoff": cutoff, "strips": quads.n_strips,
                     "leftover_quads": len(quads.leftover), "verts": quads.vertex_count,
                     "verts_pct": 100 * quads.vertex_count / four_n,
                     "length": quads.mean_triangles_per_strip, "passes": quads.passes,
                     "strip_ms": t.wall_ms, "meshopt_verts_pct": 100 * tri.n_vertices / four_n})
    return rows


def save_cutoff_figure(path: Path, rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_v, ax_s) = plt.subplots(1, 2, figsize=(10, 4), dpi=100)
    for label in dict.fromkeys(r["scene"] for r in rows):
        sel = [r for r in rows if r["scene"] == label]
        cut = [r["cutoff"] for r in sel]
        line, = ax_v.plot(cut, [r["verts_pct"] for r in sel], "o-", label=f"{label}: quad strips")
        ax_v.axhline(sel[0]["meshopt_verts_pct"], color=line.get_color(), ls="--",
                     label=f"{label}: meshoptimizer triangle strips")
        ax_s.plot(cut, [r["strips"] for r in sel], "o-", color=line.get_color(),
                  label=f"{label}: strips")
        ax_s.plot(cut, [r["leftover_quads"] for r in sel], "x:", color=line.get_color(),
                  label=f"{label}: leftover quads")
    for ax in (ax_v, ax_s):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("bandification cutoff (quads)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    ax_v.set_ylabel("vertices sent (% of 4n)")
    ax_s.set_ylabel("count")
    ax_s.set_yscale("log")
    fig.suptitle("Quad strips: vertex share and strip count against the cutoff")
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png")
    plt.close(fig)


DRAW_CONFIGS = (
    # case, path, style keywords, the case whose image this one is compared with
    ("list, shorter diagonal", "gouraud", {}, None),
    ("list, strip diagonal", "gouraud", {"quad_diagonal": "strip"}, None),
    ("meshopt triangle strips", "gouraud", {"strips": "triangle", "quad_diagonal": "strip"},
     "list, strip diagonal"),
    ("quad strips", "gouraud", {"strips": "quad"}, "list, strip diagonal"),
    ("list + line-overdraw wire", "gouraud", {"quad_diagonal": "strip", "wireframe": True}, None),
    ("quad_wire (single pass)", "quad_wire", {}, None),
)


def vertex_shader_invocations(ctx):
    """A :func:`measure` probe: ``vs_invocations``, the vertex-shader invocations of one more
    draw of the prepared path (pipeline statistics query), None where the context has none."""
    def probe(path) -> dict:
        if not VertexShaderInvocations.supported(ctx):
            return {"vs_invocations": None}
        counter = VertexShaderInvocations(ctx)
        try:
            with counter:
                path.draw()
            return {"vs_invocations": counter.invocations}
        finally:
            counter.release()
    return probe


def draw_rows(exp: ExperimentContext, case: Case, size) -> tuple[list[dict], dict]:
    """Every draw configuration on ``case`` at ``size`` (W, H): the measurement, vertices sent
    and vertex-shader invocations, the pixels differing from the reference image, and the
    single-pass wire frame's agreement with the line overdraw's. Returns rows and images."""
    mesh = case.scene
    lo, hi = mesh.bounds()
    view = {"azimuth": -35.0, "elevation": 25.0, "up": "z"}
    camera = Camera.fit_box(lo, hi, aspect=size[0] / size[1], **view)
    gl_renderer = exp.renderer
    rows, images = [], {}
    for label, name, kw, reference in DRAW_CONFIGS:
        style = Style(**kw)
        m = exp.measure(mesh, name, style, camera=camera, size=size,
                        probe=vertex_shader_invocations(exp.gl))
        images[label] = image = m.image
        row = dict(renderer=gl_renderer, scene=case.label, size=f"{size[0]}x{size[1]}",
                   case=label, path=name, style=style.summary(), triangles=m.row["triangles"],
                   vertices=m.row["vertices"], vertices_sent=m.row["vertices_sent"],
                   strips=m.row["strips"], vs_invocations=m.row["vs_invocations"],
                   bytes_per_step=m.row["bytes_per_step"], **m.timing.as_row())
        if reference is not None:
            diff = difference_map(image, images[reference])
            row.update(reference=reference, differing_px=int((diff > 0).sum()),
                       max_diff_255=int(diff.max()))
        rows.append(row)
        exp.say(f"  {case.label} {size[0]}x{size[1]} {label}: wall {m.timing.wall_ms:.1f} ms, "
                f"{m.row['vertices_sent']} vertices sent")
    by = {r["case"]: r for r in rows}
    base = by["list, strip diagonal"]
    for r in rows:
        r["wall_over_list"] = r["wall_ms"] / base["wall_ms"]
    single, overdraw = images["quad_wire (single pass)"], images["list + line-overdraw wire"]
    wire = wire_agreement(single, overdraw, Style().wire_color)
    by["quad_wire (single pass)"].update(reference="list + line-overdraw wire", **wire)
    return rows, images


@experiment("table_quad_strips", "crash2000 Table 1: quad strips by bandification against "
                                 "meshoptimizer triangle strips, drawn stripped and unstripped",
            declared=DECLARED)
def run(exp: ExperimentContext) -> list[dict]:
    suite = list(models(exp))
    rows = []
    for case in suite:
        rows.append(stripping_row(exp, case))
        r = rows[-1]
        exp.say(f"{case.label}: quad strips {r['quad_verts_pct']:.1f} % of 4n "
                f"({r['quad_strip_ms']:.0f} ms), meshoptimizer {r['tri_verts_pct']:.1f} % "
                f"({r['tri_strip_ms']:.0f} ms)")
    exp.table(paper_rows(rows), "paper",
              "crash2000 Table 1 beside the measured stamped panels of the same sizes")

    by_label = {c.label: c for c in suite}
    largest = exp.pick("panels 255641", "panels 51473", "panels 2215")
    sweep_cases = [by_label[k] for k in (largest, exp.pick("car 8x8", "car 8x8", "car"))
                   if k in by_label]
    sweep = [r for c in sweep_cases for r in cutoff_rows(c, exp.pick(CUTOFFS, CUTOFFS[:6]))]
    exp.table(sweep, "cutoff", "Bandification cutoff sweep")
    save_cutoff_figure(exp.file("cutoff.png"), sweep)

    draw_cases = [by_label[k] for k in (largest, exp.pick("car 8x8", "car 2x2", "car"))
                  if k in by_label]
    draws = []
    for case in draw_cases:
        for size in exp.pick([(1000, 750), (250, 188)], [(500, 375)], [(160, 120)]):
            case_rows, images = draw_rows(exp, case, size)
            draws += case_rows
        stem = case.label.replace(" ", "_")
        save_image_grid(exp.file(f"{stem}_wire.png"),
                        [images["list + line-overdraw wire"], images["quad_wire (single pass)"]],
                        ["Gouraud + line-overdraw wire frame",
                         "quad_wire: one pass from quad strips"])
    exp.table(draws, "draw", "Drawing the largest meshes stripped and unstripped (Gouraud shading)")
    return rows
