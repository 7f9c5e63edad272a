"""fe2003 Tables 1-3: simplified FE meshes with a normal map and a wire-frame texture against the
original mesh with line overdraw, run time against error.

For every mesh of the suite (the car refined to the paper's size with a smooth displacement, the
car itself, generated stamped panels; quick: the car displaced unrefined, the car, 1 000 quads of
panels) and each of the paper's parameter sets A and B
(:data:`workbench.algo.fepatch.pipeline.PARAMETER_SETS`):

* ``params`` (Table 1): the parameter sets;
* ``preprocessing`` (Table 2): seconds per stage -- features + subpatches + lines,
  retriangulation (with the certification of the distance bound, also given alone), textures
  -- with patch, subpatch and line counts, texture memory and the certified bound, for the
  new rules (build_model's defaults) and, for set A, before each change (``rules``: "paper",
  the paper's construction and texture scale; "certified d, paper texture", the distance bound
  alone; "distance texture", the width scale rule with fe2003's distance texture, before the
  element-id wire frame);
* ``table3`` (Table 3; every column in ``table``): per render path configuration (``case``),
  triangles, GPU and wall time per frame, the speed factor
  against original + line overdraw, texture memory in RGBA texels (4 bytes) per element, and
  the errors the paper does not give: the certified one-sided Hausdorff distance original →
  simplified (upper end of a bracket of width 1e-4 of the bounding-box diagonal or 1 % of
  ``d``, whichever is smaller, model units and % of the diagonal, beside ``d``), wire-frame
  fidelity against the line-overdraw image (precision, recall and IoU of wire pixels with a
  one-pixel tolerance,
  :func:`workbench.measurement.images.wire_agreement`), and SSIM of the image against the
  ``reference`` (shaded paths against "original, shaded", wire paths against the overdraw);
  Set A's rows come also built with the paper's rules (``[paper]``), with the certified
  distance bound alone (``[certified d, paper texture]``) and with the distance texture under
  the width rule (``[distance texture]``), so that each change shows its cost: the bound in
  triangles and speed, the texture rule and the encoding in texels per element, speed and
  wire fidelity;
* ``sweep``: on the car refined 2×2 and displaced (quick: the car displaced, one configuration
  of each kind), the parameters scaled around sets A and B,
  and set A under the paper's rules, each change alone and the texture rule varied (wire
  encoding, texels across the scale-setting element width or extent, its quantile, narrow
  elements drawn as lines or not, normal map size; every build_model keyword in the row):
  speed factor against
  wire IoU and Hausdorff error (``sweep.png``);
* ``closeup`` and ``closeup.png``: wire fidelity magnified, some six elements across the view's
  radius (:func:`closeup_camera`), set A's wire frames (new rules and each rule before a
  change) against line overdraw, untimed;
* ``crops.png``: the same crop of original + line overdraw and simplified A + normal map + wire
  texture.

Lighting follows the workbench's two-sided headlight; the original is Gouraud-shaded with the
crease angle of set A, the simplified surfaces shade per pixel from the normal map. Model
units are millimetres.

Run: ``workbench run table_fe_texture_wireframe [--quick]``.
"""

from __future__ import annotations

import dataclasses
import inspect
from pathlib import Path

import numpy as np

from workbench.algo.fepatch.mesh_model import fepatch_model
from workbench.algo.fepatch.pipeline import (
    PAPER_RULES,
    PAPER_TEXTURE_RULE,
    PARAMETER_SETS,
    STAGES,
    FEPatchParams,
    build_model,
)
from workbench.algo.hausdorff import hausdorff
from workbench.experiment.context import Case, ExperimentContext
from workbench.experiment.registry import experiment
from workbench.gl import Camera
from workbench.measurement.images import compare_images, wire_agreement
from workbench.output.figures import save_image_grid
from workbench.output.tables import atomic_open
from workbench.paths import Style
from workbench.scene import generators
from workbench.scene.mesh import FEMesh

from ._declared.table_fe_texture_wireframe import DECLARED

VIEW = {"azimuth": -35.0, "elevation": 25.0, "up": "z"}
WIRE = (0.0, 0.0, 0.0)
OVERDRAW = "original + line overdraw"
SHADED = "original, shaded"
BRACKET_REL = 1e-4  # of the bounding-box diagonal, ...
BRACKET_OF_D = 0.01  # ... or of d, whichever is smaller: narrow enough to tell "within d"
TABLE3 = ("renderer", "scene", "size", "case", "rules", "triangles", "line_edges", "gpu_ms",
          "wall_ms", "speed_vs_overdraw", "rgba_texels_per_element", "hausdorff_mm", "d_mm",
          "wire_precision_1px", "wire_recall_1px", "wire_iou_1px", "ssim")
# build_model keywords of the rows that show each change on its own: the paper's construction
# (before both), the certified distance bound with the paper's texture rule (before the
# texture changes), and the width rule with fe2003's distance texture (before the element-id
# encoding); "new" is build_model's defaults
DISTANCE_TEXTURE = {"wire_encoding": "distance"}
RULES = {"paper": PAPER_RULES, "certified d, paper texture": PAPER_TEXTURE_RULE,
         "distance texture": DISTANCE_TEXTURE, "new": {}}
NEW = "new"
# the sweep's configurations at the quick size: the sets, one scaled, and one of each change
# of set A's rules
QUICK_SWEEP = ("A", "B", "Bx2", "A, paper rules", "A, paper texture rule",
               "A, d/2 fit, not certified", "A, width 1 q0.1, no narrow lines", "A, extent 1.5",
               "A, no turns", "A, normal map 1/4", "A, distance texture, width 3")
# the tiny size: every table, row kind and column, numbers meaningless
TINY_SIZE, TINY_CLOSEUP_SIZE = (160, 120), (120, 120)
# the sets, one scaled, the paper's rules and a texture rule without narrow lines
TINY_SWEEP = ("A", "B", "A/2", "A, paper rules", "A, width 1 q0.1, no narrow lines")


# ---------------------------------------------------------------------------- scenes
def refined_car(car: FEMesh, k: int) -> Case:
    """The car refined k×k with the smooth displacement."""
    return Case(f"car {k}x{k} displaced", generators.displaced(generators.refine(car, k)))


def cases(exp: ExperimentContext, car: FEMesh | None) -> tuple[list[Case], Case | None]:
    """The meshes of Tables 2-3 at the run's size and the sweep's mesh: the car refined 8×8
    (quick: 2×2) and displaced, the car and the stamped panels where ``car`` is given, and the
    car refined 2×2 and displaced for the sweep (quick: the car displaced), None without the
    car; at the tiny size the panels alone, small, for both. The quick size keeps the paper's
    texture-memory target (at most 12 RGBA texels per element for set A): the car refined 2×2
    needs 11.5, the car itself 13.8."""
    panels = Case("stamped panels", generators.stamped_panels(200, parts=1) if exp.tiny
                  else generators.stamped_panels(exp.pick(26_284, 1_000)))
    if exp.tiny or car is None:
        return [panels], (panels if exp.tiny else None)
    first = refined_car(car, exp.pick(8, 2))
    return [first, Case("car", car), panels], refined_car(car, exp.pick(2, 1))


# ---------------------------------------------------------------------------- rows
def params_rows() -> list[dict]:
    return [{"set": name, "alpha_g1_deg": p.alpha_g1_deg, "d_mm": p.d, "l_outer_mm": p.l_outer,
             "l_inner_mm": p.l_inner} for name, p in PARAMETER_SETS.items()]


def preprocessing_row(case: Case, model, rules: str = NEW) -> dict:
    """Table 2's row of ``model`` of ``case``, built with ``rules``; stage times in seconds."""
    row = {"scene": case.label, "set": model.params.label, "rules": rules,
           "elements": model.n_elements,
           "patches": model.n_patches, "subpatches": model.n_subpatches,
           "g0_edges": model.features["G0"], "g1_edges": model.features["G1"],
           "closing_edges": model.features["closing"], "line_nodes": model.line_nodes,
           "line_nodes_kept": model.line_nodes_kept, "fallback_subpatches": len(model.fallback),
           "original_triangles": len(model.original.triangles),
           "simplified_triangles": len(model.simplified.triangles),
           "atlas": f"{model.atlas_size[0]}x{model.atlas_size[1]}",
           "rgba_texels_per_element": model.rgba_texels_per_element,
           "wire_encoding": model.wire_encoding,
           "narrow_elements": model.narrow_elements, "fit_share": model.fit_share,
           "split_subpatches": model.split_subpatches,
           "kept_subpatches": model.kept_subpatches,
           "certified_bound_mm": model.distance_bound}
    for stage in STAGES:
        row[f"{stage} s"] = model.seconds[stage]
    row["certification s"] = model.certify_seconds
    row["total s"] = sum(model.seconds.values())
    return row


def simplification_error(case: Case, model) -> dict:
    """Certified one-sided Hausdorff distance original → simplified surface (mm)."""
    orig, simp = model.original, model.simplified
    lo, hi = case.scene.bounds()
    diag = float(np.linalg.norm(hi - lo))
    tol = BRACKET_REL * diag
    if model.params.d > 0:
        tol = min(tol, BRACKET_OF_D * model.params.d)
    h = hausdorff(orig.positions, orig.triangles, simp.positions, simp.triangles,
                  one_sided=True, tol=tol, estimates=False)
    return {"hausdorff_mm": h.upper, "hausdorff_lower_mm": h.lower,
            "hausdorff_pct_diag": 100.0 * h.upper / diag, "hausdorff_s": h.seconds,
            "within_d": bool(h.upper <= model.params.d)}


class Drawer:
    """What every draw of one mesh shares: the camera (fitted to the mesh at ``VIEW``) and the
    image size (W, H); :meth:`draw` measures one path with the run's repeats."""

    def __init__(self, exp: ExperimentContext, mesh: FEMesh, size):
        self.exp, self.mesh, self.size = exp, mesh, size
        lo, hi = mesh.bounds()
        self.camera = Camera.fit_box(lo, hi, aspect=size[0] / size[1], **VIEW)

    def draw(self, name: str, style: Style, scene=None):
        """The :class:`~workbench.measurement.rows.Measurement` of path ``name`` drawing
        ``scene`` (default the mesh; or a TexturedSurface built by the caller)."""
        return self.exp.measure(self.mesh if scene is None else scene, name, style,
                                camera=self.camera, size=self.size)


def overdraw_style() -> Style:
    """The original with line overdraw: Gouraud at set A's crease angle, black lines."""
    return Style(crease_deg=PARAMETER_SETS["A"].alpha_g1_deg, wireframe=True, wire_color=WIRE)


def variant_label(name: str, rules: str, what: str) -> str:
    """The Table 3 case label of set ``name`` built with ``rules`` (the new rules unnamed)."""
    return f"simplified {name}{'' if rules == NEW else f' [{rules}]'} {what}"


def table3_configs(models: dict, variants: dict) -> list[tuple]:
    """(case label, path, set, rules, style) of every Table 3 row of one mesh; a style of None
    is made from the set's model."""
    crease = PARAMETER_SETS["A"].alpha_g1_deg
    configs = [(SHADED, "gouraud", None, NEW, Style(crease_deg=crease)),
               (OVERDRAW, "gouraud", None, NEW, overdraw_style()),
               ("original + wire texture", "fe_wire_texture", "A", NEW, None)]
    for name in models:
        configs += [(variant_label(name, NEW, "+ normal map"), "fe_normal_map", name, NEW, None),
                    (variant_label(name, NEW, "+ normal map + wire texture"), "fe_normal_wire",
                     name, NEW, None)]
    for name, rules in variants:
        configs.append((variant_label(name, rules, "+ normal map + wire texture"),
                        "fe_normal_wire", name, rules, None))
    return configs


def drawn_rows(exp: ExperimentContext, case: Case, models: dict, variants: dict,
               drawer: Drawer) -> tuple[list[dict], dict]:
    """Table 3's measured columns of one mesh, and the images by case label. ``models``:
    {set: the mesh's cached model (new rules)}; ``variants``: {(set, rules): model built with
    other rules}, drawn as textured surfaces."""
    rows, images = [], {}
    for label, path_name, set_name, rules, style in table3_configs(models, variants):
        model = scene = None
        if set_name is not None and rules == NEW:  # the mesh's cached model of this set
            model = models[set_name]
        elif set_name is not None:
            model = variants[(set_name, rules)]
            scene = model.simplified
        if model is not None:
            style = Style(fepatch=set_name, crease_deg=model.params.alpha_g1_deg, wire_color=WIRE)
        m = drawer.draw(path_name, style, scene)
        images[label] = m.image
        row = dict(renderer=exp.renderer, scene=case.label, size="x".join(map(str, drawer.size)),
                   case=label, set=set_name or "", rules=rules if model is not None else "",
                   triangles=m.row["triangles"], line_edges=m.row["edges"], **m.timing.as_row())
        if model is not None:
            surface = model.original if path_name == "fe_wire_texture" else model.simplified
            row.update(rgba_texels_per_element=model.rgba_texels_per_element,
                       texture_mb=surface.texture_bytes / 2**20,
                       narrow_elements=model.narrow_elements)
        rows.append(row)
        exp.say(f"  {case.label} {label}: {m.row['triangles']} triangles, "
                f"wall {m.timing.wall_ms:.1f} ms")
    return rows, images


def add_image_comparisons(rows: list[dict], images: dict) -> None:
    """Speed against the overdraw, SSIM against the ``reference`` and the wire agreement with
    the overdraw, into ``rows`` of one mesh."""
    base = next(r for r in rows if r["case"] == OVERDRAW)
    for r in rows:
        r["speed_vs_overdraw"] = base["wall_ms"] / r["wall_ms"]
        # None on a software renderer, whose timer queries time nothing
        r["gpu_speed_vs_overdraw"] = (base["gpu_ms"] / r["gpu_ms"]
                                      if r["gpu_ms"] and base["gpu_ms"] else None)
        wire = "wire" in r["case"] or r["case"] == OVERDRAW
        reference = OVERDRAW if wire else SHADED
        if r["case"] != reference:
            r["ssim"] = compare_images(images[reference], images[r["case"]]).ssim
            r["reference"] = reference
        if wire and r["case"] != OVERDRAW:
            r.update(wire_agreement(images[r["case"]], images[OVERDRAW], WIRE))


def add_simplification_errors(exp: ExperimentContext, case: Case, rows: list[dict],
                              models: dict, variants: dict) -> None:
    """``d`` and the certified Hausdorff distance of each model, into its simplified rows."""
    by = {r["case"]: r for r in rows}
    measured = [(name, NEW, model) for name, model in models.items()]
    measured += [(name, rules, model) for (name, rules), model in variants.items()]
    for name, rules, model in measured:
        error = simplification_error(case, model)
        for label in (variant_label(name, rules, "+ normal map"),
                      variant_label(name, rules, "+ normal map + wire texture")):
            if label in by:
                by[label].update(d_mm=model.params.d, **error)
        exp.say(f"  {case.label} set {name} ({rules} rules): one-sided Hausdorff <= "
                f"{error['hausdorff_mm']:.3f} mm (d = {model.params.d} mm)")


def table3_rows(exp: ExperimentContext, case: Case, models: dict, variants: dict,
                drawer: Drawer) -> tuple[list[dict], dict]:
    """Table 3 rows of one mesh (see :func:`drawn_rows`), and the images by case label."""
    rows, images = drawn_rows(exp, case, models, variants, drawer)
    add_image_comparisons(rows, images)
    add_simplification_errors(exp, case, rows, models, variants)
    return rows, images


# ---------------------------------------------------------------------------- sweep
SWEEP_KEYS = ("fit_share", "certify", "wire_encoding", "texels_per_edge", "scale_by",
              "scale_quantile", "atlas_turns", "border", "normal_reduction", "min_width")


def scaled(p: FEPatchParams, f: float) -> FEPatchParams:
    """Parameter set ``p`` with its lengths scaled by ``f``, named ``<name>x<f>``."""
    return FEPatchParams(p.alpha_g1_deg, p.d * f, p.l_outer * f, p.l_inner * f,
                         f"{p.name}x{f:g}")


def sweep_configs(exp: ExperimentContext) -> list[tuple[str, FEPatchParams, dict]]:
    """(case label, parameters, build_model keywords) of the sweep: the parameter sets scaled,
    and set A under the paper's rules, each change alone and the texture rule varied."""
    a, b = PARAMETER_SETS["A"], PARAMETER_SETS["B"]
    configs = [("A", a, {}), ("B", b, {}), ("A/2", scaled(a, 0.5), {}),
               ("Bx2", scaled(b, 2.0), {}),
               ("A, paper rules", a, PAPER_RULES),
               ("A, paper texture rule", a, PAPER_TEXTURE_RULE),
               ("A, d/2 fit, not certified", a, {"fit_share": 0.5, "certify": False}),
               ("A, width 1.5 q0.1", a, {"scale_quantile": 0.1}),
               ("A, width 1.25 q0.02", a, {"texels_per_edge": 1.25, "min_width": 1.25}),
               ("A, width 1 q0.1, no narrow lines", a, {"texels_per_edge": 1.0,
                                                       "scale_quantile": 0.1,
                                                       "min_width": None}),
               ("A, width 1.5 q0", a, {"scale_quantile": 0.0}),
               ("A, extent 1.5", a, {"scale_by": "extent"}),
               ("A, no turns", a, {"atlas_turns": 1}),
               ("A, normal map 1/1", a, {"normal_reduction": 1}),
               ("A, normal map 1/4", a, {"normal_reduction": 4}),
               ("A, distance texture, width 3", a, DISTANCE_TEXTURE),
               ("A, distance texture, width 2.5", a, {**DISTANCE_TEXTURE, "texels_per_edge": 2.5,
                                                      "min_width": 2.5})]
    if not exp.quick:
        configs += [("Ax2", scaled(a, 2.0), {}), ("A/4", scaled(a, 0.25), {}),
                    ("A, width 1.5 q0.3", a, {"scale_quantile": 0.3}),
                    ("A, width 1 q0.3, no narrow lines", a, {"texels_per_edge": 1.0,
                                                            "scale_quantile": 0.3,
                                                            "min_width": None})]
    kept = exp.pick(None, QUICK_SWEEP, TINY_SWEEP)
    return configs if kept is None else [c for c in configs if c[0] in kept]


def build_settings(kwargs: dict) -> dict:
    """Every :data:`SWEEP_KEYS` keyword of a build: ``kwargs`` over build_model's defaults."""
    defaults = inspect.signature(build_model).parameters
    return {k: kwargs.get(k, defaults[k].default) for k in SWEEP_KEYS}


def build_key(params: FEPatchParams, kwargs: dict) -> tuple:
    """What makes one model of a mesh: its parameters and build_model keywords."""
    return params, tuple(sorted(kwargs.items()))


def models_by_build(models: dict, variants: dict) -> dict:
    """Table 3's models of one mesh (see :func:`mesh_models`) by :func:`build_key`."""
    built = {build_key(PARAMETER_SETS[name], {}): model for name, model in models.items()}
    built.update({build_key(PARAMETER_SETS[name], RULES[rules]): model
                  for (name, rules), model in variants.items()})
    return built


def sweep_rows(exp: ExperimentContext, case: Case, drawer: Drawer,
               built: dict | None = None) -> list[dict]:
    """One row per :func:`sweep_configs` entry: its parameters and build keywords, speed
    against the overdraw, wire agreement and certified Hausdorff distance (mm). ``built``:
    models already built on this mesh, by :func:`build_key`, used instead of building them
    again (the build is deterministic; its seconds are those of that build)."""
    overdraw = drawer.draw("gouraud", overdraw_style())
    rows = []
    for label, params, kwargs in sweep_configs(exp):
        # rules of its own: built here, the simplified surface drawn as the scene
        model = (built or {}).get(build_key(params, kwargs))
        if model is None:
            model = build_model(case.scene.elements, case.scene.nodes, params, **kwargs)
        style = Style(crease_deg=params.alpha_g1_deg, wire_color=WIRE)
        m = drawer.draw("fe_normal_wire", style, model.simplified)
        row = dict(scene=case.label, case=label, alpha_g1_deg=params.alpha_g1_deg,
                   d_mm=params.d, l_outer_mm=params.l_outer, l_inner_mm=params.l_inner,
                   **build_settings(kwargs), triangles=m.row["triangles"],
                   line_edges=m.row["edges"], narrow_elements=model.narrow_elements,
                   preprocessing_s=sum(model.seconds.values()),
                   wall_ms=m.timing.wall_ms,
                   speed_vs_overdraw=overdraw.timing.wall_ms / m.timing.wall_ms,
                   rgba_texels_per_element=model.rgba_texels_per_element,
                   **wire_agreement(m.image, overdraw.image, WIRE),
                   **simplification_error(case, model))
        rows.append(row)
        exp.say(f"  sweep {label}: {m.row['triangles']} triangles, "
                f"speed x{row['speed_vs_overdraw']:.2f}, "
                f"wire IoU {row['wire_iou_1px']:.3f}, Hausdorff {row['hausdorff_mm']:.3f} mm, "
                f"{row['rgba_texels_per_element']:.1f} RGBA texels per element")
    return rows


def save_sweep_figure(path: Path, rows: list[dict], title: str) -> None:
    """Speed factor against wire IoU and against the Hausdorff distance, coloured by texture
    memory, each point named by its case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    speed = [r["speed_vs_overdraw"] for r in rows]
    for ax, key, xlabel in ((axes[0], "wire_iou_1px", "wire IoU against line overdraw (1 px)"),
                            (axes[1], "hausdorff_mm",
                             "one-sided Hausdorff original → simplified [mm]")):
        x = [r[key] for r in rows]
        sc = ax.scatter(x, speed, c=[r["rgba_texels_per_element"] for r in rows], cmap="viridis")
        for r, xi, yi in zip(rows, x, speed):
            ax.annotate(r["case"], (xi, yi), textcoords="offset points", xytext=(4, 4),
                        fontsize=8)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("speed factor against original + line overdraw")
        ax.grid(True, alpha=0.3)
    fig.colorbar(sc, ax=axes, label="texture memory [RGBA texels per element]")
    fig.suptitle(title)
    with atomic_open(path, "wb") as handle:
        fig.savefig(handle, format="png", dpi=100)
    plt.close(fig)


# ---------------------------------------------------------------------------- close-up
CLOSEUP_ELEMENTS = 6.0  # elements across the close-up view's radius


def closeup_camera(mesh: FEMesh) -> Camera:
    """A magnified view at ``VIEW``'s angles: centred on the node nearest to the top centre of the
    mesh's bounding box, ``CLOSEUP_ELEMENTS`` median element edges in radius; its near and far
    planes open so that the surface is not cut to the view sphere."""
    lo, hi = mesh.bounds()
    nodes = mesh.nodes
    e = np.asarray(mesh.elements)
    edge = np.linalg.norm(nodes[e] - nodes[np.roll(e, -1, axis=1)], axis=2)
    radius = CLOSEUP_ELEMENTS * float(np.median(edge[edge > 0]))
    top = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]])
    centre = nodes[np.argmin(np.linalg.norm(nodes - top, axis=1))]
    cam = Camera.fit(centre, radius, **VIEW)
    return dataclasses.replace(cam, near=0.01 * radius, far=cam.far + 100.0 * radius)


def closeup_rows(exp: ExperimentContext, case: Case, models: dict,
                 variants: dict) -> tuple[list, dict]:
    """Wire fidelity magnified (:func:`closeup_camera`): each wire path of set A against line
    overdraw, untimed, and the images by case label."""
    camera = closeup_camera(case.scene)
    size = exp.pick((400, 400), (400, 400), TINY_CLOSEUP_SIZE)
    overdraw = exp.measure(case.scene, "gouraud", overdraw_style(), camera=camera, size=size,
                           timed=False).image
    images = {OVERDRAW: overdraw}
    rows = []
    drawn = [(NEW, models["A"])] + [(rules, m) for (name, rules), m in variants.items()
                                     if name == "A"]
    for rules, model in drawn:
        label = variant_label("A", rules, "+ normal map + wire texture")
        image = exp.measure(model.simplified, "fe_normal_wire", Style(wire_color=WIRE),
                            camera=camera, size=size, timed=False).image
        images[label] = image
        rows.append(dict(scene=case.label, view=f"close-up, {size[0]}x{size[1]}",
                         case=label, rules=rules,
                         wire_encoding=model.wire_encoding,
                         **wire_agreement(image, overdraw, WIRE),
                         ssim=compare_images(overdraw, image).ssim))
        exp.say(f"  {case.label} close-up {label}: wire IoU {rows[-1]['wire_iou_1px']:.3f}")
    return rows, images


def save_first_figures(exp: ExperimentContext, case: Case, images: dict, near_images: dict,
                       size) -> None:
    """``closeup.png`` and ``crops.png`` of the first mesh."""
    save_image_grid(exp.file("closeup.png"), list(near_images.values()),
                    [f"{case.label}: {OVERDRAW}"]
                    + [label.replace(" + normal map + wire texture", "")
                       for label in list(near_images)[1:]], columns=3)
    h, w = size[1], size[0]
    y0, x0 = h // 3, w // 3
    simplified = "simplified A + normal map + wire texture"
    save_image_grid(exp.file("crops.png"),
                    [images[OVERDRAW][y0:y0 + h // 3, x0:x0 + w // 3],
                     images[simplified][y0:y0 + h // 3, x0:x0 + w // 3]],
                    [f"{case.label}: original + line overdraw", simplified])


# ---------------------------------------------------------------------------- the run
def mesh_models(exp: ExperimentContext, case: Case) -> tuple[dict, dict, list[dict]]:
    """The models of one mesh: {set: new rules, cached by the mesh}, {("A", rules): set A
    before each change}, and their preprocessing rows."""
    models, variants, pre = {}, {}, []
    for name in PARAMETER_SETS:
        models[name] = fepatch_model(case.scene, name)  # derived once, cached by the mesh
        pre.append(preprocessing_row(case, models[name]))
        exp.say(f"  set {name}: preprocessing {pre[-1]['total s']:.1f} s, "
                f"{pre[-1]['simplified_triangles']} of {pre[-1]['original_triangles']} "
                f"triangles")
    for rules, kwargs in RULES.items():  # set A before each change
        if rules == NEW:
            continue
        variants[("A", rules)] = build_model(case.scene.elements, case.scene.nodes, "A",
                                             **kwargs)
        pre.append(preprocessing_row(case, variants[("A", rules)], rules))
        exp.say(f"  set A, {rules} rules: preprocessing {pre[-1]['total s']:.1f} s, "
                f"{pre[-1]['simplified_triangles']} triangles")
    return models, variants, pre


@experiment("table_fe_texture_wireframe", "fe2003 Tables 1-3: simplified FE meshes with normal "
                                          "maps and a wire-frame texture against line overdraw",
            declared=DECLARED)
def run(exp: ExperimentContext) -> list[dict]:
    size = exp.pick((1000, 750), (500, 375), TINY_SIZE)
    exp.table(params_rows(), "params", "fe2003 Table 1: parameter sets")
    car = None if exp.tiny else exp.builtin("car")
    meshes, swept = cases(exp, car)
    pre, rows, sweep, closeups, built = [], [], [], [], None
    for i, case in enumerate(meshes):
        exp.say(f"{case.label}: {case.scene.n_elements} elements")
        models, variants, mesh_pre = mesh_models(exp, case)
        pre += mesh_pre
        mesh_rows, images = table3_rows(exp, case, models, variants, Drawer(exp, case.scene, size))
        rows += mesh_rows
        near_rows, near_images = closeup_rows(exp, case, models, variants)
        closeups += near_rows
        if i == 0:
            save_first_figures(exp, case, images, near_images, size)
        if case is swept:
            built = models_by_build(models, variants)
    if swept is not None:
        exp.say(f"sweep on {swept.label}")
        sweep = sweep_rows(exp, swept, Drawer(exp, swept.scene, size), built)
    exp.table(pre, "preprocessing", "fe2003 Table 2: preprocessing seconds")
    exp.table(closeups, "closeup",
              "Wire fidelity magnified: set A's wire frames against line overdraw")
    exp.table(rows, "table3", "fe2003 Table 3: time per frame against error (all columns: "
              "table.md)", columns=TABLE3)
    if sweep:
        exp.table(sweep, "sweep", "Parameter sweep: speed against error")
        save_sweep_figure(exp.file("sweep.png"), sweep,
                          f"{sweep[0]['scene']}: simplified + wire texture, speed against error")
    return rows
