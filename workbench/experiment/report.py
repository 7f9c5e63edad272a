"""The measured claims of the README and ``docs/results.md``, written from the results store.

Nothing in them is typed: each experiment's latest stored run (full size where there is one,
else quick) gives its claims (:data:`CLAIMS`, one function per experiment reading that run's
tables) and its tables; each names the run, the machine and renderer it ran on, its size, the
commit and the load on the machine when it started. A ratio measured interleaved is given with
its 95 % interval (``1.13× [1.07, 1.22]``); a ratio of two separate measurements says so.

:func:`write_report` rewrites the part of the README between ``<!-- results:begin -->`` and
``<!-- results:end -->`` and the whole of ``docs/results.md``, each atomically.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..output.tables import atomic_write_text, format_number, markdown_table

if TYPE_CHECKING:
    from ..results.store import ResultsStore

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
Tables = Callable[[str], list[dict[str, Any]]]


@dataclass(frozen=True)
class Source:
    """The stored run an experiment's claims come from, and where it ran."""

    experiment: str
    run_id: str
    size: str
    started: str
    commit: str | None
    dirty: bool | None
    cpu: str | None
    cores: int | None
    renderer: str | None
    driver: str | None
    load_1m: float | None

    @property
    def where(self) -> str:
        """``renderer (driver); CPU, N cores`` of the run."""
        gl = f"{self.renderer} ({self.driver})" if self.driver else str(self.renderer)
        return f"{gl}; {self.cpu}, {self.cores} cores"

    @property
    def which(self) -> str:
        """``size, commit abc1234 (dirty), 2026-12-03, load 0.4``."""
        commit = (self.commit or "no commit")[:7] + (" (dirty)" if self.dirty else "")
        load = "" if self.load_1m is None else f", load {self.load_1m:.1f}"
        return f"{self.size} size, commit {commit}, {self.started[:10]}{load}"


def latest_sources(store: ResultsStore) -> dict[str, Source]:
    """Per experiment, its latest stored run at full size, else at quick size (tiny runs and
    sweeps are not reported)."""
    if not {"experiment", "experiment_size"} <= set(
            store.query("SELECT * FROM rows LIMIT 0").column_names):
        return {}  # nothing an experiment wrote
    found = store.query(
        "SELECT r.experiment, r.experiment_size, r.run_id, any_value(u.started) AS started, "
        "any_value(u.\"commit\") AS \"commit\", any_value(u.dirty) AS dirty, "
        "any_value(m.cpu) AS cpu, any_value(m.logical_cores) AS cores, "
        "any_value(m.renderer) AS renderer, any_value(m.driver) AS driver, "
        "any_value(u.load_1m) AS load_1m "
        "FROM rows r JOIN runs u USING (run_id) LEFT JOIN machines m USING (machine_id) "
        "WHERE r.experiment_size IN ('full', 'quick') AND r.experiment NOT LIKE 'sweep:%' "
        "GROUP BY ALL").to_pylist()
    best: dict[str, Source] = {}
    for row in found:
        source = Source(row["experiment"], row["run_id"], row["experiment_size"],
                        str(row["started"]), row["commit"], row["dirty"], row["cpu"],
                        row["cores"], row["renderer"], row["driver"], row["load_1m"])
        old = best.get(source.experiment)
        if old is None or (source.size == "full", source.started) > (old.size == "full",
                                                                     old.started):
            best[source.experiment] = source
    return dict(sorted(best.items()))


def _quoted(text: str) -> str:
    """``text`` as an SQL string literal."""
    return "'" + str(text).replace("'", "''") + "'"


def stored_table(store: ResultsStore, source: Source, table: str) -> list[dict[str, Any]]:
    """The rows of ``table`` of ``source``'s experiment in its run, in their order, with only
    the columns that table has (the store's views hold every table's columns)."""
    result = store.query(f"SELECT * FROM rows WHERE run_id = {_quoted(source.run_id)} AND "
                         f"experiment = {_quoted(source.experiment)} AND \"table\" = "
                         f"{_quoted(table)} ORDER BY row_index")
    rows = result.to_pylist()
    keep = [c for c in result.column_names
            if c not in ("run_id", "row_index", "experiment", "table", "experiment_size")
            and not c.endswith("_samples_ms") and any(r[c] is not None for r in rows)]
    return [{c: r[c] for c in keep} for r in rows]


def stored_table_names(store: ResultsStore, source: Source) -> list[str]:
    """The tables ``source``'s experiment stored in its run, main table first."""
    names = store.query(
        f"SELECT DISTINCT \"table\" FROM rows WHERE run_id = {_quoted(source.run_id)} AND "
        f"experiment = {_quoted(source.experiment)}").column("table").to_pylist()
    return sorted(names, key=lambda n: (n != "table", n))


# ---------------------------------------------------------------- formatting
def num(value: Any, digits: int = 3) -> str:
    """A number for a sentence (``digits`` significant digits); "n/a" for None."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return format_number(float(value), digits)


def interval(row: dict[str, Any], name: str) -> str:
    """``1.13× [1.07, 1.22]`` from the columns ``name``, ``name_lo``, ``name_hi``."""
    return (f"{num(row.get(name))}× [{num(row.get(f'{name}_lo'))}, "
            f"{num(row.get(f'{name}_hi'))}]")


# ---------------------------------------------------------------- the claims
def render_paths_claims(tables: Tables) -> list[str]:
    out = []
    for r in tables("targets"):
        out.append(f"{r['scene']} at {r['size']} ({r['triangles']:,} triangles): per-pixel "
                   f"bands {num(r['contour_wall_ms'])} ms, "
                   f"{interval(r, 'contour_over_position_only')} the position-only draw; with "
                   f"4× MSAA and read-back {interval(r, 'contour_msaa_over_pyrender')} "
                   f"pyrender's time (SSIM {num(r['pyrender_ssim'])} against it)")
    return out + ["ratios interleaved"] if out else out


def span(values: list[float], digits: int = 3) -> str:
    """``a`` or ``a–b``: the range of ``values`` (None left out); "n/a" for none."""
    values = sorted(v for v in values if v is not None)
    if not values:
        return "n/a"
    lo, hi = num(values[0], digits), num(values[-1], digits)
    return lo if lo == hi else f"{lo}–{hi}"


def software_raster_claims(tables: Tables) -> list[str]:
    out = []
    for r in tables("interleaved"):
        out.append(f"{r['scene']} at {r['size']}: {r['case']} {num(r['software_ms'])} ms, "
                   f"{interval(r, 'speed_vs_llvmpipe')} as fast as {r['against']} "
                   f"({num(r['llvmpipe_ms'])} ms)")
    gl_rule = [r for r in tables("table") if r.get("case") == "software bands, GL rule"]
    out += [f"{r['scene']}: with llvmpipe's pixel rule {num(r['differing_pct'])} % of the "
            f"pixels differ from the GL image" for r in gl_rule]
    return out + ["speeds interleaved"] if out else out


def bvh_claims(tables: Tables) -> list[str]:
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


def fe_texture_claims(tables: Tables) -> list[str]:
    rows = [r for r in tables("table3") if r.get("speed_vs_overdraw") is not None]
    wanted = [r for r in rows if "simplified A" in r["case"] and "wire" in r["case"]]
    return [f"{r['scene']}: {r['case']} {r['triangles']:,} triangles, {num(r['wall_ms'])} ms, "
            f"{num(r['speed_vs_overdraw'])}× the original with line overdraw (separate "
            f"measurements), wire IoU {num(r.get('wire_iou_1px'))}, certified distance "
            f"{num(r.get('hausdorff_mm'))} mm" for r in wanted[:2]]


def pixel_exact_claims(tables: Tables) -> list[str]:
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


def exploded_claims(tables: Tables) -> list[str]:
    out = []
    rows = tables("table")
    for scene in dict.fromkeys(r["scene"] for r in rows):
        mine = [r for r in rows if r["scene"] == scene]
        # "not within N" where the part was not revealed: the store keeps the column as text
        frames = [int(r["frames_to_reveal"]) for r in mine
                  if str(r["frames_to_reveal"]).isdigit()]
        out.append(f"{scene}: part {mine[0]['focus_part']} revealed in {len(frames)} of "
                   f"{len(mine)} views (up to {num(max(r['sweep_deg'] for r in mine))}° from "
                   f"the split plane), within {max(frames) if frames else 'n/a'} frames; the "
                   f"in-frame count costs {span([r['occlusion_over_draw'] for r in mine])}× the "
                   f"draw, a separate pass {span([r['separate_over_draw'] for r in mine])}× "
                   f"(separate measurements)")
    return out


def quad_strips_claims(tables: Tables) -> list[str]:
    rows = [r for r in tables("table") if r.get("quad_verts_pct") is not None]
    if not rows:
        return []
    panels = [r for r in rows if str(r["scene"]).startswith("panels")]
    picked = [max(panels, key=lambda r: r["quads"])] if panels else []
    picked += [r for r in rows if r["scene"] == "car"][:1]  # the largest panels and the car
    return [f"{r['scene']} ({r['quads']:,} quads): quad strips send "
            f"{num(r['quad_verts_pct'])} % of 4n vertices, triangle strips "
            f"{num(r['tri_verts_pct'])} %" for r in picked]


def simplify_claims(tables: Tables) -> list[str]:
    seen, out = set(), []
    for r in tables("table"):
        if r.get("method") == "ours (Hausdorff-bounded)" and r["scene"] not in seen:
            seen.add(r["scene"])
            out.append(f"{r['scene']} at {num(r['tol_pct'])} %: {r['input_triangles']:,} → "
                       f"{r['triangles']:,} triangles, certified one-sided distance "
                       f"{num(r.get('hausdorff_mm'))} mm in {num(r['seconds'])} s")
    for r in tables("hausdorff_peer"):
        if r.get("ours_s") is None or r.get("peer_s") is None:
            continue
        out.append(f"{r['model']} → {r['triangles']:,} triangles, certified bracket at "
                   f"{num(r['tol_share_of_diagonal'])} of the diagonal: ours {num(r['ours_s'])} s, "
                   f"cascading-upper-bounds {num(r['peer_s'])} s (its time "
                   f"{num(r['time_ratio'])}× [{num(r['time_ratio_min'])}, "
                   f"{num(r['time_ratio_max'])}] ours, interleaved), brackets "
                   f"{'overlap' if r.get('overlap') else 'DISJOINT'}")
    return out


CLAIMS: dict[str, tuple[str, Callable[[Tables], list[str]]]] = {
    "render_paths": ("es2008", render_paths_claims),
    "table_software_raster": ("es2008 Tables 2–3", software_raster_claims),
    "table_bvh_distance": ("crash2000 §4, Table 2", bvh_claims),
    "simplify_tradeoff": ("crash2000 §3.2", simplify_claims),
    "table_quad_strips": ("crash2000 Table 1", quad_strips_claims),
    "table_fe_texture_wireframe": ("fe2003 Tables 1–3", fe_texture_claims),
    "fig_pixel_exact": ("st2005", pixel_exact_claims),
    "fig_exploded": ("ghost2013", exploded_claims),
}


def claims_of(store: ResultsStore, source: Source) -> list[str]:
    """The claims of ``source``'s experiment (none for an experiment without a claim
    function; a claim that its stored tables cannot give is named as missing)."""
    entry = CLAIMS.get(source.experiment)
    if entry is None:
        return []
    try:
        return entry[1](lambda table: stored_table(store, source, table))
    except (KeyError, TypeError) as exc:
        return [f"(not in this run's tables: {exc})"]


# ---------------------------------------------------------------- the two documents
def readme_section(store: ResultsStore) -> str:
    """The README's table of measured claims, one row per experiment."""
    sources = latest_sources(store)
    rows = []
    for experiment, (paper, _) in CLAIMS.items():
        source = sources.get(experiment)
        if source is None:
            rows.append({"paper": paper, "experiment": f"`{experiment}`",
                         "measured": "not in the results store yet", "where": ""})
            continue
        rows.append({"paper": paper, "experiment": f"`{experiment}`",
                     "measured": "; ".join(claims_of(store, source)) or "(no claim rows)",
                     "where": f"{source.where}; {source.which}"})
    note = ("Written by `workbench results report` from the latest stored run of each "
            "experiment; ratios marked interleaved come with their 95 % interval.")
    return f"{BEGIN}\n{note}\n\n{markdown_table(rows)}{END}"


def results_document(store: ResultsStore) -> str:
    """``docs/results.md``: per experiment its claims, its run and every stored table."""
    from .registry import EXPERIMENTS, discover

    discover()
    sources = latest_sources(store)
    parts = ["# Measured results", "",
             "Written by `workbench results report` from the results store; do not edit. Each "
             "experiment's latest stored run (full size where there is one) is shown with the "
             "machine it ran on. Times hold for that renderer only; compare ratios. Ratios "
             "measured interleaved carry `_lo`/`_hi` (95 % interval) and `_pairs` columns.", ""]
    runs = [{"experiment": s.experiment, "run": s.run_id, "size": s.size,
             "started": s.started, "commit": (s.commit or "")[:10], "dirty": s.dirty,
             "renderer": s.renderer, "driver": s.driver, "cpu": s.cpu, "cores": s.cores,
             "load_1m": s.load_1m} for s in sources.values()]
    parts += ["## The runs", "", markdown_table(runs)]
    for experiment, source in sources.items():
        known = EXPERIMENTS.get(experiment)
        title = f"{experiment}: {known.description}" if known else experiment
        parts += [f"## {title}", "", f"Run {source.run_id}: {source.where}; {source.which}.",
                  ""]
        parts += [f"- {claim}" for claim in claims_of(store, source)] + [""]
        for table in stored_table_names(store, source):
            parts += [f"### {table}", "", markdown_table(stored_table(store, source, table))]
    return "\n".join(parts)


def replace_section(text: str, section: str, name: str = "README") -> str:
    """``text`` with the part from :data:`BEGIN` to :data:`END` replaced by ``section``;
    ValueError naming ``name`` where the markers are missing or out of order."""
    start, end = text.find(BEGIN), text.find(END)
    if start < 0 or end < start:
        raise ValueError(f"{name} has no '{BEGIN}' … '{END}' section to write the results into")
    return text[:start] + section + text[end + len(END):]


def write_report(store: ResultsStore, readme: str | os.PathLike[str],
                 doc: str | os.PathLike[str]) -> list[Path]:
    """Rewrite the results section of ``readme`` and the whole of ``doc`` from ``store``;
    returns both paths. Refuses an empty store and a README without the markers, before
    writing either."""
    if not latest_sources(store):
        raise ValueError(f"the results store {store.root} holds no experiment run "
                         f"(run `workbench reproduce` or `workbench run NAME` first)")
    readme, doc = Path(readme), Path(doc)
    text = replace_section(readme.read_text(encoding="utf-8"), readme_section(store),
                           str(readme))
    document = results_document(store)
    atomic_write_text(readme, text)
    doc.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(doc, document)
    return [readme, doc]
