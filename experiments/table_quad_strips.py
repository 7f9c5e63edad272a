"""crash2000 Table 1: quad strips by bandification against triangle strips, and what strips are worth.

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

from dataclasses import dataclass
from pathlib import Path

from workbench.algo.strips import quad_strips, tri_strips
from workbench.data import CAR_DECK, D3PLOT, shared_file
from workbench.experiment.compare import difference_map, wire_agreement
from workbench.experiment.figures import save_image_grid
from workbench.experiment.measure import measure
from workbench.experiment.context import ExperimentContext
from workbench.experiment.registry import experiment
from workbench.experiment.tables import atomic_open, write_table
from workbench.experiment.timing import time_call
from workbench.gl import Camera, VertexShaderInvocations, create_context, renderer
from workbench.paths import Style
from workbench.scene import generators
from workbench.scene.builtin import builtin_scene

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


@dataclass
class Model:
    label: str
    kind: str  # "paper size", "car", "car part", "car refined", "d3plot"
    mesh: object


def models(say):
    """The stripping suite, smallest first within each kind (the same in quick runs: stripping
    is fast; quick runs draw and sweep smaller meshes)."""
    for n in PAPER_SIZES:
        yield Model(f"panels {n}", "paper size", generators.stamped_panels(n))
    if shared_file(CAR_DECK) is None:
        say(f"car skipped: {CAR_DECK} not found (set WORKBENCH_DATA to the shared data folder)")
    else:
        car = builtin_scene("car")
        yield Model("car", "car", car)
        for part in sorted(car.part_names):
            sub = car.part(part)
            if sub.n_elements:
                yield Model(f"car part {part}", "car part", sub)
        for k in (2, 4, 8):
            yield Model(f"car {k}x{k}", "car refined", generators.refine(car, k))
    if shared_file(D3PLOT) is None:
        say(f"d3plot skipped: {D3PLOT} not found")
    else:
        yield Model("d3plot", "d3plot", builtin_scene("d3plot"))


def stripping_row(model: Model, repeat: int) -> dict:
    mesh = model.mesh
    four_n = 4 * mesh.n_elements
    quads = quad_strips(mesh.elements)
    tri = tri_strips(mesh.triangles, mesh.n_nodes)
    t_quad = time_call(lambda: quad_strips(mesh.elements), repeat=repeat)
    t_tri = time_call(lambda: tri_strips(mesh.triangles, mesh.n_nodes), repeat=repeat)
    return {
        "mesh": model.label, "kind": model.kind, "elements": mesh.n_elements, "quads": mesh.n_quads,
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
    measured = {r["mesh"]: r for r in rows if r["kind"] == "paper size"}
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


def cutoff_rows(model: Model, cutoffs) -> list[dict]:
    mesh = model.mesh
    four_n = 4 * mesh.n_elements
    tri = tri_strips(mesh.triangles, mesh.n_nodes)
    rows = []
    for cutoff in cutoffs:
        quads = quad_strips(mesh.elements, cutoff)
        t = time_call(lambda c=cutoff: quad_strips(mesh.elements, c), warmup=0, repeat=5)
        rows.append({"mesh": model.label, "cutoff": cutoff, "strips": quads.n_strips,
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
    for label in dict.fromkeys(r["mesh"] for r in rows):
        sel = [r for r in rows if r["mesh"] == label]
        cut = [r["cutoff"] for r in sel]
        line, = ax_v.plot(cut, [r["verts_pct"] for r in sel], "o-", label=f"{label}: quad strips")
        ax_v.axhline(sel[0]["meshopt_verts_pct"], color=line.get_color(), ls="--",
                     label=f"{label}: meshoptimizer triangle strips")
        ax_s.plot(cut, [r["strips"] for r in sel], "o-", color=line.get_color(), label=f"{label}: strips")
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
    # row label, path, style keywords, baseline row for the pixel comparison
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


def draw_rows(ctx, model: Model, size, repeat: int, say) -> tuple[list[dict], dict]:
    mesh = model.mesh
    lo, hi = mesh.bounds()
    view = {"azimuth": -35.0, "elevation": 25.0, "up": "z"}
    camera = Camera.fit_box(lo, hi, aspect=size[0] / size[1], **view)
    gl_renderer = renderer(ctx)
    rows, images = [], {}
    for label, name, kw, baseline in DRAW_CONFIGS:
        style = Style(**kw)
        m = measure(ctx, mesh, name, style, camera=camera, size=size, repeats=repeat,
                    probe=vertex_shader_invocations(ctx))
        images[label] = image = m.image
        row = dict(renderer=gl_renderer, mesh=model.label, size=f"{size[0]}x{size[1]}", path=label,
                   path_name=name, parameters=style.summary(), triangles=m.row["triangles"],
                   vertices=m.row["vertices"], vertices_sent=m.row["vertices_sent"],
                   strips=m.row["strips"], vs_invocations=m.row["vs_invocations"],
                   bytes_per_step=m.row["bytes_per_step"], **m.timing.as_row())
        if baseline is not None:
            diff = difference_map(image, images[baseline])
            row.update(baseline=baseline, pixels_differing=int((diff > 0).sum()),
                       max_diff_255=int(diff.max()))
        rows.append(row)
        say(f"  {model.label} {size[0]}x{size[1]} {label}: wall {m.timing.wall_ms:.1f} ms, "
            f"{m.row['vertices_sent']} vertices sent")
    by = {r["path"]: r for r in rows}
    base = by["list, strip diagonal"]
    for r in rows:
        r["wall_over_list"] = r["wall_ms"] / base["wall_ms"]
    single, overdraw = images["quad_wire (single pass)"], images["list + line-overdraw wire"]
    wire = wire_agreement(single, overdraw, Style().wire_color)
    by["quad_wire (single pass)"].update(baseline="list + line-overdraw wire", **wire)
    return rows, images


@experiment("table_quad_strips", "crash2000 Table 1: quad strips by bandification against "
                                 "meshoptimizer triangle strips, drawn stripped and unstripped")
def run(exp: ExperimentContext) -> list[dict]:
    out_dir, quick, say = exp.out_dir, exp.quick, exp.say
    repeat = 5 if quick else 9
    suite = list(models(say))
    rows = []
    for model in suite:
        rows.append(stripping_row(model, repeat))
        r = rows[-1]
        say(f"{model.label}: quad strips {r['quad_verts_pct']:.1f} % of 4n "
            f"({r['quad_strip_ms']:.0f} ms), meshoptimizer {r['tri_verts_pct']:.1f} % "
            f"({r['tri_strip_ms']:.0f} ms)")
    write_table(paper_rows(rows), out_dir, "paper",
                title="crash2000 Table 1 beside the measured stamped panels of the same sizes")

    by_label = {m.label: m for m in suite}
    sweep_models = [by_label[k] for k in ("panels 51473" if quick else "panels 255641", "car 8x8")
                    if k in by_label]
    sweep = [r for m in sweep_models for r in cutoff_rows(m, CUTOFFS[:6] if quick else CUTOFFS)]
    write_table(sweep, out_dir, "cutoff", title="Bandification cutoff sweep")
    save_cutoff_figure(out_dir / "cutoff.png", sweep)

    ctx = create_context()
    sizes = [(500, 375)] if quick else [(1000, 750), (250, 188)]
    draw_models = [by_label[k] for k in ("panels 51473" if quick else "panels 255641",
                                         "car 2x2" if quick else "car 8x8") if k in by_label]
    draws = []
    for model in draw_models:
        for size in sizes:
            model_rows, images = draw_rows(ctx, model, size, repeat, say)
            draws += model_rows
        stem = model.label.replace(" ", "_")
        save_image_grid(out_dir / f"{stem}_wire.png",
                        [images["list + line-overdraw wire"], images["quad_wire (single pass)"]],
                        ["Gouraud + line-overdraw wire frame", "quad_wire: one pass from quad strips"])
    write_table(draws, out_dir, "draw", title="Drawing the largest meshes stripped and unstripped "
                                              "(Gouraud shading)")
    return rows

