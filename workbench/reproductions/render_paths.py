"""Every first render path side by side: time against error, on the car model and the es2008 scene.

For each scene the table has one row per path and option — GPU ms, wall ms, read-back ms,
million triangles per second, bytes uploaded (and per time step) — with the colour error of
each per-vertex path against the per-pixel path of the same style (the colour reference),
over the pixels either draws, and what the path's ``needs`` saved: ``derive_ms`` and
``derive_bytes`` of the scene data it made the mesh derive (triangulation, element edges,
crease-split Gouraud vertices), ``skipped_ms`` and ``skipped_bytes`` of the rest, which a scene
deriving everything would have computed for nothing (both from nothing, on a fresh copy of the
mesh). A scene's paths are measured together by
:func:`workbench.measurement.rows.measure_together` (their draws interleaved, each time with
its 95 % interval); GPU time is recorded only where the renderer's timer queries time the draw
(not on llvmpipe, where wall time — draw + ``finish`` — is the time).
In the same run the same triangles are drawn by pyrender and by pyvista/VTK through EGL at the
same size, with the same culling and comparable lighting (SSIM against our Gouraud image shows
the comparison is like for like), and a bare position-only draw gives the floor.
``targets.md`` holds the ratios the foundation is judged by, each measured interleaved with its
95 % interval.

Run: ``workbench run render_paths [--quick]``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from workbench.experiment.context import ExperimentContext
from workbench.experiment.registry import experiment
from workbench.gl import Camera
from workbench.measurement.images import compare_drawn, difference_image
from workbench.measurement.interleave import Clock, draw_clock, interleaved_ratios
from workbench.measurement.rows import Together, measure_together
from workbench.measurement.timing import time_call
from workbench.output.figures import save_field_figure, save_image_grid
from workbench.paths import Style, make_path, prepared
from workbench.paths.colormap import scale_for
from workbench.references.pyrender import PyrenderReference
from workbench.references.pyvista import LIGHTING as VTK_LIGHTING
from workbench.references.pyvista import PyvistaReference
from workbench.scene import generators
from workbench.scene.needs import MESH_ITEMS, derivation_cost

from ._declared.render_paths import DECLARED

BANDS = 10


def scenes(exp: ExperimentContext):
    """(label, mesh, step shown, field, element field or None, units, camera kwargs, image size).

    The car is put through a synthetic frontal crush (its rigid pole held still) so that it has
    time steps (12, quick 4, tiny 2) and a displacement field; its last step is shown at
    1000×625 (quick 640×400, tiny 80×50), skipped, with a message, when the shared data is
    absent. The semicylinders are the es2008 benchmark, n = 250 at 1000×1000 (quick 64 at
    500×500, tiny 4 at 64×64).
    """
    car = exp.builtin("car")
    if car is not None:
        rigid = [part for part, title in car.part_names.items() if "rigid" in title.lower()]
        car = generators.crash_sequence(car, steps=exp.pick(12, 4, 2), still_parts=rigid)
        yield ("car", car, car.n_steps - 1, "displacement", "thickness", "mm",
               {"azimuth": -35.0, "elevation": 20.0, "up": "z"},
               exp.pick((1000, 625), (640, 400), (80, 50)))
    n = exp.pick(250, 64, 4)
    yield (f"semicylinders n={n}", generators.semicylinders(n=n), 0, "distance", None, "mm",
           {"azimuth": 25.0, "elevation": 15.0}, exp.pick((1000, 1000), (500, 500), (64, 64)))


def path_configs(step: int, field: str, element_field: str | None, value_range, clip_plane):
    """(case, path name, style, MSAA samples, reference case or None); references come first."""
    plain = Style(step=step)
    smooth = replace(plain, field=field, value_range=value_range)
    banded = replace(smooth, bands=BANDS)
    lo, hi = value_range
    yield "position", "position", plain, 0, None
    yield "flat", "flat", plain, 0, None
    yield "gouraud", "gouraud", plain, 0, None
    yield "gouraud + wire", "gouraud", replace(plain, wireframe=True), 0, None
    yield "pixel smooth", "pixel_color", smooth, 0, None
    yield "vertex smooth", "vertex_color", smooth, 0, "pixel smooth"
    yield "pixel bands", "pixel_color", banded, 0, None
    yield "vertex bands", "vertex_color", banded, 0, "pixel bands"
    yield "pixel bands + wire", "pixel_color", replace(banded, wireframe=True), 0, None
    yield ("pixel transfer (hide low 30 %)", "pixel_color",
           replace(smooth, hide_range=(lo, lo + 0.3 * (hi - lo))), 0, None)
    yield "pixel bands + clip", "pixel_color", replace(banded, clip_planes=(clip_plane,)), 0, None
    if element_field is not None:
        yield "element flat", "element_color", replace(plain, field=element_field), 0, None
    if step > 0:
        yield ("pixel bands, deformation x3", "pixel_color", replace(banded, magnification=3.0),
               0, None)
    # pyrender always draws with 4x multisampling (pyvista/VTK is given 4x too): these rows
    # are their like-for-like peers
    yield "gouraud, 4x MSAA", "gouraud", plain, 4, None
    yield "pixel bands, 4x MSAA", "pixel_color", banded, 4, None


def path_rows(exp: ExperimentContext, label: str, mesh, configs, camera: Camera,
              size) -> tuple[list[dict], dict]:
    """One row per path configuration of :func:`path_configs` on ``mesh`` at ``size`` (W, H):
    the measurement, what the path's needs saved, and the colour error against its reference
    configuration where it has one. The configurations are measured together, their draws
    interleaved (:func:`~workbench.measurement.rows.measure_together`), so that their times
    hold against each other and against another run. Returns the rows and the images by
    configuration."""
    rows, images = [], {}
    costs: dict[float, dict] = {}
    probe = set_step_time(exp.repeats) if mesh.n_steps > 1 else None
    measured = measure_together(
        exp.gl, mesh, [Together(make_path(name, style), samples=samples, probe=probe)
                       for _, name, style, samples, _ in configs],
        camera=camera, size=size, repeats=exp.repeats, stop=exp.stop)
    for (case, name, style, samples, reference), m in zip(configs, measured):
        path = m.path
        images[case] = image = m.image
        row = dict(renderer=exp.renderer, scene=label, case=case, path=name,
                   style=style.summary(), size=f"{size[0]}x{size[1]}", samples=samples,
                   triangles=path.triangles, vertices=path.vertices,
                   bytes_uploaded=path.bytes_uploaded, bytes_per_step=path.bytes_per_step,
                   **m.timing.as_row(), mtri_per_s=path.triangles / m.timing.wall_ms / 1e3)
        if probe is not None:
            row["set_step_ms"] = m.row["set_step_ms"]
        row.update(needs_saving(mesh, path.needs, style, costs))
        if reference is not None:
            diff = compare_drawn(image, images[reference])
            row.update(reference=reference, max_diff_255=diff.max_abs,
                       share_differing=diff.share_differing, psnr_db=diff.psnr, ssim=diff.ssim)
        rows.append(row)
        exp.say(f"  {case}: wall {m.timing.wall_ms:.2f} ms, "
                f"needs skipped {row['skipped_bytes'] / 2**20:.1f} MiB")
    return rows, images


def pyrender_row(exp: ExperimentContext, label: str, mesh, step: int, camera: Camera, size,
                 ours: np.ndarray):
    """pyrender (EGL, always 4× MSAA) drawing the crease-split Gouraud triangles of step
    ``step`` at ``size``, timed with read-back and compared with our 4× MSAA Gouraud image
    ``ours``. Returns its row, its image, the crease split and the reference itself, still
    prepared (the caller releases it)."""
    split = mesh.gouraud(Style().crease_deg)
    coords = mesh.coordinates(step)
    ref = PyrenderReference(coords[split.vertex_node], split.triangles, split.normals(coords),
                            camera=camera, size=size, base_color=Style().base_color)
    ref_image = ref.render()
    ref_timing = ref.time(warmup=2, repeat=exp.repeats)
    diff = compare_drawn(ref_image, ours)
    row = dict(renderer=exp.renderer, scene=label, case="pyrender (EGL)", path="pyrender",
               size=f"{size[0]}x{size[1]}", samples=4, triangles=len(split.triangles),
               vertices=split.n_vertices, **ref_timing.as_row(),
               mtri_per_s=len(split.triangles) / ref_timing.wall_ms / 1e3,
               reference="gouraud, 4x MSAA", max_diff_255=diff.max_abs,
               share_differing=diff.share_differing, psnr_db=diff.psnr, ssim=diff.ssim)
    exp.say(f"  pyrender: wall {ref_timing.wall_ms:.2f} ms, SSIM vs gouraud 4x MSAA "
            f"{diff.ssim:.3f}")
    return row, ref_image, split, ref


def pyvista_row(exp: ExperimentContext, label: str, mesh, step: int, camera: Camera, size,
                split, ours: np.ndarray, ours_row: dict):
    """pyvista/VTK (its EGL render window, 4× MSAA) drawing the crease-split Gouraud triangles
    ``split`` of step ``step`` at ``size``, timed with read-back and compared with our 4× MSAA
    Gouraud image ``ours`` (RGB, over the pixels either draws). ``wall_over_ours`` is its wall
    time (render + read-back) over ours (``ours_row``: draw + read-back), from the two rows'
    separate measurements (the targets hold the ratio measured interleaved);
    ``peer_version`` names VTK's and pyvista's versions and ``lighting`` what VTK's lighting
    is and where it differs from ours. Returns its row, its image and the reference itself,
    still prepared (the caller releases it)."""
    coords = mesh.coordinates(step)
    ref = PyvistaReference(coords[split.vertex_node], split.triangles, split.normals(coords),
                           camera=camera, size=size, base_color=Style().base_color, samples=4)
    try:
        ref_image = ref.render()
        ref_timing = ref.time(warmup=2, repeat=exp.repeats)
    except BaseException:
        ref.release()
        raise
    diff = compare_drawn(ref_image, ours[..., :3], background=(1.0, 1.0, 1.0))
    ours_ms = ours_row["wall_ms"] + ours_row["readback_ms"]
    row = dict(renderer=exp.renderer, scene=label, case="pyvista/VTK (EGL)", path="pyvista",
               size=f"{size[0]}x{size[1]}", samples=ref.samples, triangles=len(split.triangles),
               vertices=split.n_vertices, **ref_timing.as_row(),
               mtri_per_s=len(split.triangles) / ref_timing.wall_ms / 1e3,
               reference="gouraud, 4x MSAA", max_diff_255=diff.max_abs,
               share_differing=diff.share_differing, psnr_db=diff.psnr, ssim=diff.ssim,
               wall_over_ours=ref_timing.wall_ms / ours_ms, peer_version=ref.version,
               lighting=VTK_LIGHTING)
    exp.say(f"  pyvista/VTK: wall {ref_timing.wall_ms:.2f} ms ({row['wall_over_ours']:.2f}x "
            f"ours), SSIM vs gouraud 4x MSAA {diff.ssim:.3f}")
    return row, ref_image, ref


def interleaved_targets(exp: ExperimentContext, mesh, configs: dict, camera: Camera, size,
                        ref: PyrenderReference, vtk: PyvistaReference) -> dict:
    """The ratios the targets state, each measured interleaved (A B A B …, see
    :mod:`workbench.measurement.interleave`) with its 95 % interval: per-pixel bands over the
    position-only draw; per-pixel bands with 4× MSAA and read-back over pyrender and over
    pyvista/VTK (both read back in their render); and Gouraud with 4× MSAA and read-back (the
    same triangles) over pyvista/VTK. The peers' ratios come from one run, every side drawn
    once per round."""
    def setting(case):
        _, name, style, samples, _ = configs[case]
        return dict(path=name, style=style, camera=camera, size=size, samples=samples)

    def with_readback(ready) -> Clock:
        clock = draw_clock(ready)
        return Clock(lambda: (clock.run(), ready.target.read()), clock.setup)

    with prepared(exp.gl, mesh, **setting("pixel bands")) as bands, \
            prepared(exp.gl, mesh, **setting("position")) as floor, \
            prepared(exp.gl, mesh, **setting("pixel bands, 4x MSAA")) as msaa, \
            prepared(exp.gl, mesh, **setting("gouraud, 4x MSAA")) as gouraud:
        floor_ratio = interleaved_ratios(
            {"bands": draw_clock(bands), "position": draw_clock(floor)},
            [("bands", "position")], exp.ratio_stop())[("bands", "position")]
        peers = interleaved_ratios(
            {"msaa": with_readback(msaa), "pyrender": Clock(ref.render),
             "gouraud": with_readback(gouraud), "pyvista": Clock(vtk.render)},
            [("msaa", "pyrender"), ("msaa", "pyvista"), ("gouraud", "pyvista")],
            exp.ratio_stop(max_samples=15))
    peer_ratio, vtk_ratio = peers[("msaa", "pyrender")], peers[("msaa", "pyvista")]
    gouraud_ratio = peers[("gouraud", "pyvista")]
    exp.say(f"  interleaved: pixel bands / position-only {floor_ratio.interval.estimate:.3f} "
            f"[{floor_ratio.interval.lo:.3f}, {floor_ratio.interval.hi:.3f}], 4x MSAA + "
            f"read-back / pyrender {peer_ratio.interval.estimate:.3f}, / pyvista "
            f"{vtk_ratio.interval.estimate:.3f}; gouraud 4x MSAA + read-back / pyvista "
            f"{gouraud_ratio.interval.estimate:.3f}")
    return {**floor_ratio.as_row("contour_over_position_only"),
            **peer_ratio.as_row("contour_msaa_over_pyrender"),
            **vtk_ratio.as_row("contour_msaa_over_pyvista"),
            **gouraud_ratio.as_row("gouraud_msaa_over_pyvista")}


def target_row(exp: ExperimentContext, label: str, mesh, size, rows: list[dict],
               reference: dict, vtk: dict, split, ratios: dict) -> dict:
    """The targets of one scene: the contour path against the position-only draw, against
    pyrender (its ``reference`` row) and against pyvista/VTK (its ``vtk`` row), and Gouraud
    against pyvista/VTK — the times from their own rows, the ratios measured interleaved
    (``ratios``, from :func:`interleaved_targets`) — and what a time step uploads against
    preparation."""
    by_case = {r["case"]: r for r in rows}
    contour, contour_msaa = by_case["pixel bands"], by_case["pixel bands, 4x MSAA"]
    return {
        "renderer": exp.renderer, "scene": label, "size": f"{size[0]}x{size[1]}",
        "triangles": contour["triangles"], "contour_wall_ms": contour["wall_ms"],
        "position_only_wall_ms": by_case["position"]["wall_ms"],
        "contour_msaa_incl_readback_ms": contour_msaa["wall_ms"] + contour_msaa["readback_ms"],
        "pyrender_incl_readback_ms": reference["wall_ms"],
        "pyvista_incl_readback_ms": vtk["wall_ms"],
        **ratios,
        "pyrender_ssim": reference["ssim"],
        "pyvista_ssim": vtk["ssim"],
        "nodes": len(mesh.used_nodes()), "crease_vertices_added": split.added,
        "bytes_per_step": contour["bytes_per_step"],
        "bytes_at_prepare": contour["bytes_uploaded"],
    }


def save_figures(exp: ExperimentContext, label: str, images: dict, ref_image: np.ndarray,
                 ssim: float, vtk_image: np.ndarray, vtk_ssim: float, value_range, field: str,
                 units: str) -> None:
    """The scene's per-pixel bands with the wire frame, per-vertex against per-pixel colour,
    ours beside pyrender (``ref_image``, ``ssim`` against ours) and ours beside pyvista/VTK
    (``vtk_image``, ``vtk_ssim``)."""
    stem = label.split()[0]
    save_field_figure(exp.file(f"{stem}_bands_wire.png"), images["pixel bands + wire"],
                      value_range=value_range, colormap=Style().colormap, label=field, units=units,
                      title=f"{label}: per-pixel bands + element wire frame", bands=BANDS)
    save_image_grid(exp.file(f"{stem}_vertex_vs_pixel.png"),
                    [images["vertex smooth"], images["pixel smooth"],
                     difference_image(images["vertex smooth"], images["pixel smooth"])],
                    ["colour per vertex", "colour per pixel (reference)", "|difference| x8"])
    save_image_grid(exp.file(f"{stem}_pyrender.png"), [images["gouraud, 4x MSAA"], ref_image],
                    ["workbench gouraud, 4x MSAA", f"pyrender (SSIM {ssim:.3f})"])
    save_image_grid(exp.file(f"{stem}_pyvista.png"), [images["gouraud, 4x MSAA"][..., :3],
                                                      vtk_image],
                    ["workbench gouraud, 4x MSAA", f"pyvista/VTK (SSIM {vtk_ssim:.3f})"])


@experiment("render_paths", "first render paths on the car and the es2008 semicylinders: time "
                            "against error, pyrender, pyvista/VTK and a bare draw beside them",
            declared=DECLARED)
def run(exp: ExperimentContext) -> list[dict]:
    rows: list[dict] = []
    targets: list[dict] = []
    for label, mesh, step, field, element_field, units, view, size in scenes(exp):
        exp.say(f"{label}: {mesh.n_elements} elements, {size[0]}x{size[1]}")
        lo, hi = mesh.bounds(all_steps=True)
        center = (lo + hi) / 2.0
        camera = Camera.fit_box(lo, hi, aspect=size[0] / size[1], **view)
        value_range = scale_for(mesh, field).value_range
        clip_plane = (*(-camera.view_matrix()[0, :3]), float(camera.view_matrix()[0, :3] @ center))
        configs = list(path_configs(step, field, element_field, value_range, clip_plane))
        scene_rows, images = path_rows(exp, label, mesh, configs, camera, size)
        reference, ref_image, split, ref = pyrender_row(exp, label, mesh, step, camera, size,
                                                        images["gouraud, 4x MSAA"])
        try:
            ours = next(r for r in scene_rows if r["case"] == "gouraud, 4x MSAA")
            vtk_row, vtk_image, vtk = pyvista_row(exp, label, mesh, step, camera, size, split,
                                                  images["gouraud, 4x MSAA"], ours)
            try:
                ratios = interleaved_targets(exp, mesh, {c[0]: c for c in configs}, camera,
                                             size, ref, vtk)
            finally:
                vtk.release()
        finally:
            ref.release()
        rows += scene_rows + [reference, vtk_row]
        targets.append(target_row(exp, label, mesh, size, scene_rows, reference, vtk_row, split,
                                  ratios))
        save_figures(exp, label, images, ref_image, reference["ssim"], vtk_image,
                     vtk_row["ssim"], value_range, field, units)
    exp.table(targets, "targets", "Targets: contour path against pyrender and a bare draw")
    return rows


def set_step_time(repeat: int):
    """A :func:`measure` probe giving ``set_step_ms``: the median wall ms of uploading one time
    step into the prepared path, cycling through the mesh's steps."""
    def probe(path) -> dict:
        steps = iter(np.resize(np.arange(path.mesh.n_steps), 64))
        return {"set_step_ms": time_call(lambda: path.set_step(int(next(steps))),
                                         repeat=repeat).wall_ms}
    return probe


def needs_saving(mesh, needs, style, costs: dict) -> dict:
    """What a path's ``needs`` made the scene derive and what they let it skip:
    ``derive_ms``/``derive_bytes`` of the items the path needs, ``skipped_ms``/``skipped_bytes``
    of the other mesh items (:data:`MESH_ITEMS`), in ms and bytes from nothing (a fresh copy of
    the mesh). Both come from one :func:`derivation_cost` of every mesh item per crease angle,
    kept in ``costs``, so that they add up to deriving everything."""
    crease = float(style.crease_deg)
    if crease not in costs:
        costs[crease] = derivation_cost(mesh, MESH_ITEMS, style).items
    items = costs[crease]
    own = set(needs) | ({"triangles"} if "gouraud" in needs else set())
    derived = [items[k] for k in items if k in own]
    skipped = [items[k] for k in items if k not in own]
    return {"derive_ms": sum(ms for ms, _ in derived), "derive_bytes": sum(b for _, b in derived),
            "skipped_ms": sum(ms for ms, _ in skipped), "skipped_bytes": sum(b for _, b in skipped)}

