"""es2008 Tables 2 and 3: the vectorized software rasterizer with a span look-up table, against
llvmpipe in the same run, and sort-last compositing of domains on Dask.

**Main table** (``table.md``): the es2008 benchmark — 8 semi-cylindrical sheets of 250 × 250
quads (1 M triangles) at 1000 × 1000, seen from the front as in the paper's Fig. 5 — and the
same scene with 1024 × 1024 quads per sheet (16.8 M triangles, beyond the paper's 16.6 M), drawn
by the EGL paths on the GL context (position-only, the floor; flat; per-pixel band contours)
and by the software rasterizer (:mod:`workbench.algo.softraster`) with the same shading: with
llvmpipe's pixel rule (half-space generator, 8 sub-pixel bits, with and without early depth
rejection), with 0 sub-pixel bits, and with the span table for S = 10, 15, 20. Per row: wall
time (median of the timed draws, through :func:`~workbench.measurement.rows.measure`),
triangles/s, the speed against llvmpipe's position-only draw and against llvmpipe's draw of the
same shading in this run, fragments, table-fit share, and the image against the EGL image of
the same shading (share of differing pixels, largest difference; the EGL row named in
``reference``). Quick runs: 125 × 125 quads per sheet at 500 × 500 (the paper's triangle size)
and 250 × 250 at 1000 × 1000; tiny runs: 16 × 16 at 100 × 100 and 24 × 24 at 120 × 120.

**Interleaved** (``interleaved.md``): the speeds the README states — llvmpipe's position-only
floor, flat and band draws over the software rasterizer's (GL rule, all threads) — measured
interleaved (one draw of each in turn, repeated until each ratio's 95 % interval is within
±2 %, quick ±5 %), each with its interval.

**Steps** (``steps.md``, ``steps.png``): the paper's Table 2 columns for the paper's pipeline
(span table S = 10, no early depth rejection): each step vectorised or not, its time with the
kernels interpreted by Python (vectorisation off) and compiled (on) on a small case and their
ratio, its time on both benchmark scenes, the paper's Table 2 and 3 beside.

**Span table** (``span_table.md``): memory against the paper's 6.4 / 49 / 205 MB, build and
cache-load time, table-fit share, and the draw against the half-space generator on the same
0-bit rule (identical images required).

**Compositing** (``composite.md``): the benchmark split into D = 1, 2, 4, 8 domains (by space
and by part), rendered by the software rasterizer on a LocalCluster of 2 worker processes and
composited by binary tree and binary swap of whole frames, binary swap of drawn pixels only
(``active-swap``) and local compositing with one piece per other worker (``local``): equality
with the one-process image, bytes moved between workers, render and compositing seconds (tiny:
D = 1, 2 on a small image).

Run: ``workbench run table_software_raster [--quick]``.
"""

from __future__ import annotations

import resource
import statistics
import time
import tracemalloc
from contextlib import ExitStack
from dataclasses import dataclass

import numpy as np

from workbench.algo.softraster import STEPS, RasterOptions
from workbench.algo.softraster.spantable import (
    PAPER_MB,
    build_span_table,
    forget_tables,
    span_table,
)
from workbench.experiment.context import ExperimentContext
from workbench.experiment.registry import experiment
from workbench.measurement.images import compare_images, difference_map
from workbench.measurement.interleave import draw_clock, interleaved_ratios
from workbench.measurement.rows import default_camera
from workbench.output.figures import save_image_grid
from workbench.output.tables import atomic_open
from workbench.paths import SoftwareRasterizer, Style, prepared, prepared_path
from workbench.paths.software import SoftwarePath
from workbench.scene.generators import semicylinders

from ._declared.table_software_raster import DECLARED

# es2008 Tables 2 (1 M triangles) and 3 (16.6 M): step → (vec-off s, vec-on s, ratio) each
PAPER_STEPS = {
    "transform and light": ((0.982, 0.043, 24), (10.712, 0.663, 17)),
    "clip triangle": ((0.011, 0.003, 4), (0.187, 0.076, 3)),
    "depth gradient": ((0.121, 0.010, 12), (2.154, 0.171, 13)),
    "scalar gradient": ((0.172, 0.015, 12), (2.901, 0.216, 14)),
    "range and TC": ((0.197, 0.008, 26), (2.615, 0.149, 18)),
    "collect table-fit": ((0.314, 0.053, 13), (4.100, 0.798, 9)),
    "generate fragment": ((0.289, 0.288, 1), (2.693, 2.687, 1)),
    "interpolate z": ((0.427, 0.036, 12), (3.338, 0.259, 13)),
    "interpolate color": ((0.617, 0.068, 9), (4.661, 0.581, 8)),
    "write fragment": ((0.295, 0.296, 1), (1.513, 1.511, 1)),
}
PAPER_RUNS = (("es2008 1 M", 1.0e6, 0.82), ("es2008 16.6 M (Pantheon)", 16.6e6, 16.6 / 2.33))
BANDS = dict(field="distance", bands=10)
TABLE_SIZES = (10, 15, 20)
HALF_SPACE_0_BITS = "software bands, 0 sub-pixel bits"
PAPER_PIPELINE = "software bands, span table S=10, no early depth (es2008)"


@dataclass
class Bench:
    label: str
    mesh: object
    size: tuple[int, int]
    main: bool  # the 1 M benchmark (the figures, the span-table rows and compositing use it)


def benches(exp: ExperimentContext):
    """The benchmark (8 sheets of 250 × 250 quads at 1000 × 1000; quick 125 × 125 at 500 × 500,
    tiny 16 × 16 at 100 × 100) and the large scene (1024 × 1024 quads at 1000 × 1000; quick
    250 × 250, tiny 24 × 24 at 120 × 120)."""
    n = exp.pick(250, 125, 16)
    yield Bench(f"benchmark 8x{n}x{n}", semicylinders(8, n),
                exp.pick((1000, 1000), (500, 500), (100, 100)), True)
    n = exp.pick(1024, 250, 24)
    yield Bench(f"large 8x{n}x{n}", semicylinders(8, n),
                exp.pick((1000, 1000), (1000, 1000), (120, 120)), False)


def software_configs(main: bool):
    """(label, path, style options, raster options) of the software rows."""
    yield "software flat, GL rule", "flat", {}, RasterOptions()
    yield "software bands, GL rule", "pixel_color", BANDS, RasterOptions()
    yield ("software bands, GL rule, no early depth", "pixel_color", BANDS,
           RasterOptions(early_depth=False))
    yield HALF_SPACE_0_BITS, "pixel_color", BANDS, RasterOptions(subpixel_bits=0)
    for size in TABLE_SIZES if main else (10,):
        yield (f"software bands, span table S={size}", "pixel_color", BANDS,
               RasterOptions(generator="table", table_size=size, subpixel_bits=0))
    yield (PAPER_PIPELINE, "pixel_color", BANDS,
           RasterOptions(generator="table", subpixel_bits=0, early_depth=False))
    yield ("software bands, GL rule, 1 thread", "pixel_color", BANDS, RasterOptions(threads=1))


def step_probe(repeats: int):
    """A :func:`measure` probe: the median seconds of each step over ``repeats`` more draws."""
    def probe(path) -> dict:
        samples = {name: [] for name, _ in STEPS}
        for _ in range(repeats):
            path.target.clear()
            path.draw()
            for name, value in path.stats.seconds.items():
                samples[name].append(value)
        stats = path.stats
        return dict(fragments=stats.fragments, kept=stats.kept, table_fit=stats.table_fit,
                    threads=stats.threads, table_MB=stats.table_bytes / 1e6,
                    fragment_pool_MB=stats.fragment_bytes / 1e6,
                    steps_ms={name: 1e3 * statistics.median(v) for name, v in samples.items()})
    return probe


def peak_memory(path) -> dict:
    """A probe: the largest numpy allocation total during one more draw (tracemalloc) and the
    process's peak resident set so far."""
    path.target.clear()
    tracemalloc.start()
    try:
        path.draw()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return dict(draw_peak_MB=peak / 1e6,
                process_peak_MB=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3)


def egl_rows(exp: ExperimentContext, bench: Bench, camera) -> tuple[list[dict], dict, dict]:
    """(rows, images by case, wall ms by path) of the EGL paths on the GL context:
    position-only (the floor), flat and per-pixel bands."""
    rows, images, gl_wall = [], {}, {}
    triangles = len(bench.mesh.triangles)
    for label, name, options in (("EGL position-only (the floor)", "position", {}),
                                 ("EGL flat", "flat", {}), ("EGL bands", "pixel_color", BANDS)):
        m = exp.measure(bench.mesh, name, Style(**options), camera=camera, size=bench.size,
                        repeats=exp.pick(7, 5))
        gl_wall[name] = m.row["wall_ms"]
        images[label] = m.image
        rows.append(dict(scene=bench.label, triangles=triangles, size=m.row["size"],
                         renderer=m.row["renderer"], case=label, path=name,
                         wall_ms=m.row["wall_ms"], wall_ms_min=m.row["wall_ms_min"],
                         wall_ms_max=m.row["wall_ms_max"],
                         mtri_per_s=triangles / m.row["wall_ms"] / 1e3))
        exp.say(f"{bench.label} {label}: {m.row['wall_ms']:.1f} ms")
    return rows, images, gl_wall


def software_probe(exp: ExperimentContext, bench: Bench, label: str):
    """The probe of a software row: the per-step times (over 3 more draws on the benchmark, 2
    on the large scene; tiny 1), and on the large scene's default row its memory."""
    steps = step_probe(exp.pick(3, 3, 1) if bench.main else exp.pick(2, 2, 1))
    if bench.main or label != "software bands, GL rule":
        return steps
    return lambda path: {**steps(path), **peak_memory(path)}


def bench_rows(exp: ExperimentContext, bench: Bench) -> tuple[list[dict], dict]:
    """(rows, images by case) of one scene: the EGL paths, then the software rasterizer's
    configurations against the EGL image of the same shading."""
    mesh, size = bench.mesh, bench.size
    camera = default_camera(mesh, size, view=(0.0, 0.0), up="y")
    rows, images, gl_wall = egl_rows(exp, bench, camera)
    triangles = len(mesh.triangles)
    for label, name, options, raster in software_configs(bench.main):
        path = SoftwarePath(name, Style(**options), raster)
        m = exp.measure(mesh, path, camera=camera, size=size, repeats=exp.pick(7, 5),
                        probe=software_probe(exp, bench, label),
                        backend=SoftwareRasterizer(raster))
        images[label] = m.image
        reference = "EGL bands" if name == "pixel_color" else "EGL flat"
        diff = compare_images(images[reference], m.image)
        wall = m.row["wall_ms"]
        row = dict(scene=bench.label, triangles=triangles, size=m.row["size"],
                   renderer=m.row["renderer"], case=label, path=name, wall_ms=wall,
                   wall_ms_min=m.row["wall_ms_min"], wall_ms_max=m.row["wall_ms_max"],
                   mtri_per_s=triangles / wall / 1e3,
                   speed_vs_llvmpipe_floor=gl_wall["position"] / wall,
                   speed_vs_llvmpipe_same=gl_wall[name] / wall,
                   fragments=m.row["fragments"], table_fit_pct=100.0 * m.row["table_fit"]
                   / max(m.row["kept"], 1), table_MB=m.row["table_MB"], reference=reference,
                   differing_pct=100.0 * diff.share_differing,
                   max_diff_255=diff.max_abs, threads=m.row["threads"],
                   fragment_pool_MB=m.row["fragment_pool_MB"],
                   draw_peak_MB=m.row.get("draw_peak_MB"),
                   process_peak_MB=m.row.get("process_peak_MB"), steps_ms=m.row["steps_ms"])
        if label != HALF_SPACE_0_BITS and "span table" in label:
            row["differing_px_vs_half_space_0_bits"] = int(
                (m.image != images[HALF_SPACE_0_BITS]).any(axis=-1).sum())
        rows.append(row)
        exp.say(f"{bench.label} {label}: {wall:.1f} ms, {row['mtri_per_s']:.1f} M triangles/s, "
                f"{row['speed_vs_llvmpipe_floor']:.2f}x llvmpipe's floor, "
                f"{row['differing_pct']:.3f} % pixels differ from EGL")
    return rows, images


# (llvmpipe's draw, the software draw it is set against): the speeds the README states
INTERLEAVED = (("EGL position-only (the floor)", "software bands, GL rule"),
               ("EGL flat", "software flat, GL rule"),
               ("EGL bands", "software bands, GL rule"))


def interleaved_rows(exp: ExperimentContext, bench: Bench) -> list[dict]:
    """The software rasterizer's speed against llvmpipe for each pair of :data:`INTERLEAVED`:
    llvmpipe's wall ms over the software rasterizer's (GL rule, all threads), both drawn in
    turn, with the ratio's 95 % interval and the pairs' median times."""
    mesh, size = bench.mesh, bench.size
    camera = default_camera(mesh, size, view=(0.0, 0.0), up="y")
    drawn = {"EGL position-only (the floor)": (exp.gl, "position", {}),
             "EGL flat": (exp.gl, "flat", {}), "EGL bands": (exp.gl, "pixel_color", BANDS),
             "software flat, GL rule": (SoftwareRasterizer(), "flat", {}),
             "software bands, GL rule": (SoftwareRasterizer(), "pixel_color", BANDS)}
    with ExitStack() as stack:
        clocks = {label: draw_clock(stack.enter_context(
                      prepared(backend, mesh, name, Style(**options), camera, size)))
                  for label, (backend, name, options) in drawn.items()}
        ratios = interleaved_ratios(clocks, INTERLEAVED, exp.ratio_stop())
    rows = []
    for (gl_case, software_case), ratio in ratios.items():
        rows.append(dict(scene=bench.label, triangles=len(mesh.triangles),
                         size=f"{size[0]}x{size[1]}", renderer=exp.renderer, case=software_case,
                         against=gl_case,
                         software_ms=statistics.median(ratio.denominator_ms),
                         llvmpipe_ms=statistics.median(ratio.numerator_ms),
                         **ratio.as_row("speed_vs_llvmpipe")))
        exp.say(f"{bench.label} interleaved: {software_case} {ratio.interval.estimate:.2f}x "
                f"{gl_case} [{ratio.interval.lo:.2f}, {ratio.interval.hi:.2f}]")
    return rows


def small_case_steps(exp: ExperimentContext) -> dict:
    """Each step's seconds with the kernels interpreted and compiled, on a small case (8 sheets
    of 10 × 10 quads at 100 × 100; tiny 4 × 4 at 40 × 40)."""
    mesh = semicylinders(8, exp.pick(10, 10, 4))
    size = exp.pick((100, 100), (100, 100), (40, 40))
    camera = default_camera(mesh, size, view=(0.0, 0.0), up="y")
    path = SoftwarePath("pixel_color", Style(**BANDS),
                        RasterOptions(generator="table", subpixel_bits=0, early_depth=False))
    prepared_path(SoftwareRasterizer(path.options), mesh, path, camera=camera, size=size)
    path.draw()  # compiled once
    on = {name: [] for name, _ in STEPS}
    for _ in range(5):
        path.target.clear()
        path.draw()
        for name, value in path.stats.seconds.items():
            on[name].append(value)
    path.target.clear()
    path.draw(vectorized=False)
    off = dict(path.stats.seconds)
    exp.say(f"small case ({len(mesh.triangles)} triangles, {path.stats.fragments} fragments): "
            f"interpreted {sum(off.values()):.2f} s")
    return dict(triangles=len(mesh.triangles), fragments=path.stats.fragments,
                off=off, on={k: statistics.median(v) for k, v in on.items()})


def step_rows(rows: list[dict], small: dict) -> list[dict]:
    """The per-step table: the small case interpreted and compiled, the paper's pipeline and
    the default one on both scenes, the paper's Tables 2 and 3 beside, and a total row."""
    ours = {r["scene"]: r["steps_ms"] for r in rows if r.get("case") == PAPER_PIPELINE}
    default = {r["scene"]: r["steps_ms"] for r in rows
               if r.get("case") == "software bands, GL rule"}
    out = []
    for name, vectorised in STEPS:
        off, on = small["off"][name], small["on"][name]
        paper = PAPER_STEPS.get(name)
        row = dict(step=name, vectorised="Y" if vectorised else "N",
                   small_off_ms=1e3 * off, small_on_ms=1e3 * on,
                   small_ratio=off / on if on > 0 else None)
        for scene, steps in ours.items():
            row[f"{scene} es2008 pipeline ms"] = steps[name]
        for scene, steps in default.items():
            row[f"{scene} GL rule + early depth ms"] = steps[name]
        if paper is not None:
            (a, b, c), (d, e, f) = paper
            row.update({"paper 1M off s": a, "paper 1M on s": b, "paper 1M ratio": c,
                        "paper 16.6M off s": d, "paper 16.6M on s": e, "paper 16.6M ratio": f})
        out.append(row)
    total = dict(step="total", vectorised="",
                 small_off_ms=sum(r["small_off_ms"] for r in out),
                 small_on_ms=sum(r["small_on_ms"] for r in out))
    total["small_ratio"] = total["small_off_ms"] / total["small_on_ms"]
    for key in out[0]:
        if key.endswith(" ms") or key.startswith("paper") and key.endswith(" s"):
            total[key] = sum(r.get(key) or 0.0 for r in out)
    out.append(total)
    return out


def span_table_rows(rows: list[dict]) -> list[dict]:
    """Per span-table size S: memory against the paper's, build and cache-load seconds, and the
    benchmark's draw with it against the half-space generator on the same 0-bit rule."""
    main_rows = {r["case"]: r for r in rows if r["scene"].startswith("benchmark")}
    half = main_rows.get(HALF_SPACE_0_BITS)
    out = []
    for size in TABLE_SIZES:
        start = time.perf_counter()
        build_span_table(size)
        build_s = time.perf_counter() - start
        span_table(size)  # make sure the cache holds it
        forget_tables()
        start = time.perf_counter()
        table = span_table(size)
        load_s = time.perf_counter() - start
        drawn = main_rows.get(f"software bands, span table S={size}", {})
        out.append(dict(S=size, entries=2 * (2 * size) ** 5, MB=table.nbytes / 1e6,
                        paper_MB=PAPER_MB[size], build_s=build_s, cache_load_s=load_s,
                        table_fit_pct=drawn.get("table_fit_pct"), wall_ms=drawn.get("wall_ms"),
                        half_space_0_bits_wall_ms=None if half is None else half["wall_ms"],
                        reference=HALF_SPACE_0_BITS,
                        differing_px=drawn.get("differing_px_vs_half_space_0_bits")))
    return out


COMPOSITE_METHODS = ("tree", "swap", "active-swap", "local")


def composite_rows(exp: ExperimentContext) -> list[dict]:
    """The benchmark (8 sheets of 250 × 250 quads at 1000 × 1000; quick 64 × 64 at 500 × 500,
    tiny 16 × 16 at 100 × 100) split into D = 1, 2, 4, 8 domains (tiny 1, 2) by space and by
    part, drawn on a LocalCluster of 2 worker processes and composited by every schedule of
    :data:`COMPOSITE_METHODS`, against the one-process image."""
    from workbench.distributed.cluster import sweep_cluster
    from workbench.distributed.domains import split_domains
    from workbench.distributed.sortlast import SoftwareDomains, render_sortlast

    n = exp.pick(250, 64, 16)
    spec = f"semicylinders:{n}"
    size = exp.pick((1000, 1000), (500, 500), (100, 100))
    camera = default_camera(semicylinders(8, n), size, view=(0.0, 0.0), up="y")
    render_domain = SoftwareDomains(spec, "pixel_color", Style(**BANDS), camera, size)
    one = render_domain(np.arange(render_domain.prepared().triangles))
    rows = []
    with sweep_cluster(workers=2) as cluster:
        for by in ("space", "part"):
            for count in exp.pick((1, 2, 4, 8), (1, 2, 4, 8), (1, 2)):
                domains = split_domains(render_domain.prepared().mesh, count, by=by)
                for method in COMPOSITE_METHODS:
                    frame, stats = render_sortlast(cluster.client, render_domain, domains,
                                                   method=method)
                    differing = int(((frame.color != one.color).any(axis=-1)
                                     | (frame.depth != one.depth)
                                     | (frame.triangle != one.triangle)).sum())
                    rows.append(dict(scene=spec, size=f"{size[0]}x{size[1]}", split=by,
                                     domains=count, method=method, workers=stats.workers,
                                     equal_to_one_process=differing == 0,
                                     differing_px=differing,
                                     bytes_moved_MB=stats.bytes_moved / 1e6,
                                     schedule_MB=stats.schedule_bytes / 1e6,
                                     render_s=stats.render_s, composite_s=stats.composite_s))
                    exp.say(f"composite {by} D={count} {method}: equal {differing == 0}, "
                            f"{stats.bytes_moved / 1e6:.1f} MB moved, {stats.composite_s:.3f} s")
    return rows


def plot_steps(path, steps: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [r["step"] for r in steps if r["step"] != "total"]
    fig, ax = plt.subplots(figsize=(9, 6))
    y = np.arange(len(names))
    series = [(k, k) for k in steps[0] if k.endswith(" ms") and not k.startswith("small")]
    series.append(("paper 1M on s", "es2008 on one ES processor, 1 M (paper Table 2)"))
    height = 0.8 / len(series)
    for i, (key, label) in enumerate(series):
        scale = 1e3 if key.endswith(" s") else 1.0
        values = [(r.get(key) or 0.0) * scale for r in steps if r["step"] != "total"]
        ax.barh(y + i * height, values, height, label=label)
    ax.set_yticks(y + 0.4 - height / 2, names)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("time per step [ms] (log scale)")
    ax.set_title("es2008 rendering steps: ours (2 cores) and the paper's (one vector processor)")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    ax.grid(True, axis="x", alpha=0.3)
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)


def save_images(exp: ExperimentContext, images: dict) -> None:
    """``images.png``: the middle of the benchmark drawn by EGL, the software rasterizer with
    the GL rule and with the span table, and their differences from EGL."""
    egl = images["EGL bands"]
    h, w = egl.shape[:2]
    window = (slice(h // 2 - h // 8, h // 2 + h // 8), slice(w // 2 - w // 8, w // 2 + w // 8))
    soft = images["software bands, GL rule"]
    table = images["software bands, span table S=10"]
    save_image_grid(exp.file("images.png"),
                    [egl[window], soft[window], table[window],
                     difference_map(egl, soft)[window], difference_map(egl, table)[window]],
                    ["EGL (llvmpipe) bands", "software, GL rule", "software, span table S=10",
                     "|EGL - GL rule|", "|EGL - span table|"], columns=3)


def paper_rows() -> list[dict]:
    """The paper's runs (es2008 Tables 2 and 3) in the main table's columns."""
    return [dict(scene=label, triangles=int(triangles), size="1000x1000",
                 renderer="Earth Simulator, one vector processor (paper)",
                 case="es2008 (paper)", path="flat + band texture",
                 wall_ms=seconds * 1e3, mtri_per_s=triangles / seconds / 1e6)
            for label, triangles, seconds in PAPER_RUNS]


@experiment("table_software_raster", "es2008 Tables 2-3: the software rasterizer with a span "
            "look-up table against llvmpipe, per-step times, sort-last compositing on Dask",
            declared=DECLARED)
def run(exp: ExperimentContext) -> list[dict]:
    exp.say(f"renderer: {exp.renderer}")
    rows, images, interleaved = [], {}, []
    for bench in benches(exp):
        bench_out, bench_images = bench_rows(exp, bench)
        rows += bench_out
        interleaved += interleaved_rows(exp, bench)
        if bench.main:
            images = bench_images
    rows += paper_rows()
    exp.table(interleaved, "interleaved", "The software rasterizer against llvmpipe, measured "
                                          "interleaved (speed = llvmpipe ms / software ms)")
    small = small_case_steps(exp)
    steps = step_rows(rows, small)
    exp.table(steps, "steps", f"Per-step times (ms; paper columns in s); small case: "
                              f"{small['triangles']} triangles, {small['fragments']} fragments, "
                              f"kernels interpreted (off) and compiled (on)")
    plot_steps(exp.file("steps.png"), steps)
    exp.table(span_table_rows(rows), "span_table",
              "Span look-up table: memory, build, and its draw against half-space")
    exp.table(composite_rows(exp), "composite",
              "Sort-last compositing on a LocalCluster of 2 worker processes")
    save_images(exp, images)
    for row in rows:
        row.pop("steps_ms", None)
    return rows
