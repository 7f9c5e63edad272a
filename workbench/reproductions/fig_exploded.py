"""ghost2013: occlusion-driven ghosted exploded views, on the car deck and on a generated box of
panels with a known answer, over view directions from perpendicular to nearly parallel to the
split plane's normal.

**Scenes.** *box*: six panels (parts 1-6) of the cube [-1, 1]^3 around part 7, the cube
[-0.2, 0.2]^3 (the object of interest); manual plane x through the object's centre; views
tilted about z from the +y view (elevation 0, orthographic). For a view at angle θ to the split
plane (``v = cos θ·ŷ + sin θ·x̂``) each half must slide on screen past the object's half
width plus the front panel's cut edge, so the reveal offset is
``o*(θ) = a + (a + B)·tan θ`` with a = 0.2 (object half size) and B = 1 (box half size):
0.2 at θ = 0 (view perpendicular to the normal); the measured value (the smallest offset with
r <= 0.01, by bisection with ``set_offset``) is beside it. *car*: the shared car deck; the
object of interest is the part most hidden from the default view (30°, 25°): each part's
``r`` is measured at offset 0 and the largest (ties: more pixels) wins — the rows name it.
Manual plane y through it; the views turn from the default view projected perpendicular to y
(θ = 0) towards y. Without the shared data the car rows are skipped with a message.

**View sweep** (``table.md``, the returned rows). θ is the angle between the view direction
and the split plane (0° = the plane's normal perpendicular to the view, 90° = the view along
the normal): 0, 20, 40, 60, 75, 85°. Per scene, θ, plane (the manual one and the automatic
one, ``auto_plane``, chosen for that view; its own angle to the view is given) and ratio
exponent p (1, the thesis's speed ∝ r, and 1/2, ∝ √r): the animation (``step_animation``,
s_u = 1, dt = 0.1) over N frames (quick 40, full 60); frames to full reveal (the first frame
whose r <= 0.01, frame 0 at offset 0; "not within N" otherwise), the offset then and at the
end over o_max (the bounding-box diagonal), the final r (measured after the last step) and
phase ("hold": halted revealed), α at the end (the front half's opacity from ``ghost_alpha``),
the share of the object's pixels showing through the ghosted front half at the end (pixels
tinted by the object's colour in the drawn frame over those of the object drawn alone).

**Occlusion cost** (same rows, wall clock with ``ctx.finish``, medians over the frames). Each
frame is drawn without and with its in-frame count; the count's cost is the difference plus
``step_animation``'s readback (or its separate pass, where the frame could not be counted),
against the draw without it (``occlusion_over_draw``); ``counted_in_frame_pct`` says how many
frames were counted as drawn. Beside it the separate ``p_occ`` pass (``measure_occlusion``
with ``p_unocc`` cached), as each frame would need it otherwise (``separate_over_draw``). On
llvmpipe the timer query around ``draw`` closes before the deferred rasterization runs (it
reads ~0 ms), so the GPU columns are not comparable and the wall clock ratios are the ones to
read.

**Comparison** (``compare.md``). At each automatic-plane row's (p = 1) final offset D (the total
displacement of each half), the revealed share 1 − r of: the occlusion-driven result (1 − its
final r); a uniform explosion (every part, the object included, pushed from the assembly's
bounding-box centre by D, ``uniform_explosion``; drawn as a translated copy of the mesh, camera
refitted to it along the same view, r by the same occlusion queries); and a plane explosion at
the fixed offset D along the manual plane (``set_offset``, no dynamics; not chosen for the
view). Along the automatic plane a fixed offset D would reveal exactly what the dynamics
reached: what the dynamics adds is finding D, which the table shows in the sweep.

**Figures.** ``strip_box.png``, ``strip_car.png`` (8 frames of the animation side by side) and
``box.gif``, ``car.gif`` (every frame, a progress bar along the bottom edge): the box at θ = 20°
along the manual plane, the car at the default view along the automatic plane.

Targets (reported, not asserted): full reveal within 30 frames at s_u = 1 for θ <= 60° on both
scenes with offset <= o_max; where the reveal needs more than o_max, >= 99 % of the object's
pixels showing through the ghosted half; occlusion-driven revealing more than uniform and fixed
offset at equal displacement; the occlusion queries at most 1x the draw.

Run: ``workbench run fig_exploded [--quick]``.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from workbench.algo.explode import o_max_of, occlusion_ratio, uniform_explosion
from workbench.animation.frames import draw_frames
from workbench.experiment.context import Case, ExperimentContext
from workbench.experiment.registry import experiment
from workbench.gl import GpuTimer
from workbench.gl.camera import up_frame
from workbench.measurement.rows import default_camera
from workbench.output.figures import save_animation, save_image_grid, with_progress_bar
from workbench.paths import make_path, prepared
from workbench.paths.exploded import exploded_camera
from workbench.scene import generators
from workbench.scene.mesh import FEMesh

from ._declared.fig_exploded import DECLARED

ANGLES = (0.0, 20.0, 40.0, 60.0, 75.0, 85.0)
EXPONENTS = (1.0, 0.5)  # the thesis's r, and r^0.5
REVEALED = 0.01  # r at or below which the object counts as fully revealed
TARGET_FRAMES = 30
TARGET_ANGLE = 60.0
BOX_FOCUS, BOX_HALF, FOCUS_HALF = 7, 1.0, 0.2
DEFAULT_VIEW = (30.0, 25.0)
STRIP_FRAMES = 8
BAR_PX = 3
TINY_SIZE, TINY_FRAMES = (80, 60), 10  # every row and column, numbers meaningless


# ---------------------------------------------------------------------------- scenes
def box_scene() -> FEMesh:
    """Panels 1..6 of [−B, B]³ and part 7, the cube [−a, a]³ (:func:`box_in_box`)."""
    return generators.box_in_box(BOX_HALF, FOCUS_HALF)


def box_reveal_offset(theta_deg: float) -> float:
    """Closed-form reveal offset of the box for the x plane and the view at θ to it."""
    t = math.tan(math.radians(theta_deg))
    return FOCUS_HALF + (FOCUS_HALF + BOX_HALF) * t


# ---------------------------------------------------------------------------- cameras
def view_angles(direction) -> tuple[float, float]:
    """(azimuth, elevation) in degrees of ``default_camera(..., up="z")`` looking along
    ``direction`` (from the eye toward the target)."""
    d = -np.asarray(direction, np.float64)
    local = up_frame("z").T @ (d / np.linalg.norm(d))
    el = math.degrees(math.asin(max(-1.0, min(1.0, local[1]))))
    az = math.degrees(math.atan2(local[0], local[2]))
    return az, el


def camera_along(scene, size, direction):
    """The default camera looking along ``direction``, its depth range widened for the
    exploded halves (:func:`exploded_camera`)."""
    return exploded_camera(default_camera(scene, size, view=view_angles(direction), up="z"),
                           scene)


def default_view_camera(scene, size):
    """The default camera at :data:`DEFAULT_VIEW`, its depth range widened for the halves."""
    return exploded_camera(default_camera(scene, size, view=DEFAULT_VIEW, up="z"), scene)


def view_dir(camera) -> np.ndarray:
    """The unit view direction of ``camera`` (eye toward target)."""
    v = np.asarray(camera.target, np.float64) - np.asarray(camera.eye, np.float64)
    return v / np.linalg.norm(v)


def sweep_direction(w, n, theta_deg) -> np.ndarray:
    """The view direction at ``theta_deg`` degrees from ``w`` (in the plane) towards the
    plane's normal ``n``."""
    t = math.radians(theta_deg)
    return math.cos(t) * w + math.sin(t) * n


# ---------------------------------------------------------------------------- measuring
def _tinted(image) -> int:
    """Pixels showing the object's (orange) colour: red well above blue; grey parts have
    red = blue."""
    return int(((image[..., 0].astype(int) - image[..., 2].astype(int)) > 12).sum())


def animate(ctx, scene, focus, plane, camera, size, frames, exponent=1.0, keep_images=False):
    """Run the animation for ``frames`` frames through the one frame loop
    (:func:`~workbench.animation.frames.draw_frames`); returns the per-frame record.

    Each frame is drawn twice at the same state: first, as the loop's update, without the
    in-frame count (timed on the wall clock and the GPU timer), then by the loop with it (their
    wall clock difference is the count's cost); then ``step_animation`` reads the count and
    moves the halves (its wall clock: the readback, or the separate pass on a ghosted frame);
    the separate ``p_occ`` pass alone, as every frame would need it without the in-frame count,
    is timed after it for comparison."""
    path = make_path("exploded", focus=focus, plane=plane, speed=1.0, dt=0.1,
                     ratio_exponent=exponent)
    rec = {key: [] for key in ("r", "offset", "alpha", "in_frame", "step_wall", "sep_gpu",
                               "sep_wall", "d_gpu", "d_wall", "c_wall", "images")}
    with prepared(ctx, scene, path, camera=camera, size=size) as ready:
        timer = GpuTimer(ctx)

        def uncounted(_frame) -> None:
            ready.bind()
            path.count_in_draw = False
            ready.target.clear()
            ctx.finish()
            start = time.perf_counter()
            with timer:
                path.draw()
            ctx.finish()
            rec["d_wall"].append((time.perf_counter() - start) * 1e3)
            rec["d_gpu"].append(timer.elapsed_ms)
            path.count_in_draw = True

        for drawn in draw_frames(ready, range(frames), update=uncounted, read=keep_images):
            rec["c_wall"].append(drawn.draw_ms)
            if keep_images:
                rec["images"].append(with_progress_bar(drawn.image, drawn.state + 1, frames,
                                                       BAR_PX))
            rec["r"].append(path.step_animation())
            rec["step_wall"].append(path.last_occlusion["wall_ms"])
            rec["in_frame"].append(path.last_occlusion["in_frame"])
            rec["offset"].append(path.offset)
            rec["alpha"].append(path.alpha)
            path.measure_occlusion()
            rec["sep_gpu"].append(path.last_occlusion["gpu_ms"])
            rec["sep_wall"].append(path.last_occlusion["wall_ms"])
        ready.bind()
        p_unocc, p_occ, _ = path.measure_occlusion()
        rec["final_r"] = occlusion_ratio(p_unocc, p_occ)
        shown = _tinted(ready.image())
        ready.target.clear()
        path.draw_focus()
        alone = _tinted(ready.target.read())
        rec["ghost_visible"] = shown / alone if alone else None
        rec["o_max"] = path.settings.o_max
        rec["normal"] = np.asarray(path.normal, np.float64)
        rec["phase"] = path.state.phase
    return rec


def measured_reveal_offset(ctx, scene, focus, plane, camera, size, o_max, iters=18):
    """The smallest offset (bisection) at which r <= REVEALED, None if not within o_max."""
    with prepared(ctx, scene, make_path("exploded", focus=focus, plane=plane), camera=camera,
                  size=size) as ready:
        path = ready.path

        def r_at(o):
            path.set_offset(o)
            return path.occlusion_ratio()

        if r_at(o_max) > REVEALED:
            return None
        lo, hi = 0.0, o_max
        for _ in range(iters):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if r_at(mid) <= REVEALED else (mid, hi)
        return hi


def r_fixed(ctx, scene, focus, plane, camera, size, offset) -> float:
    """The occlusion ratio r of ``focus`` with the halves held at ``offset`` (no dynamics)."""
    with prepared(ctx, scene, make_path("exploded", focus=focus, plane=plane), camera=camera,
                  size=size) as ready:
        ready.path.set_offset(offset)
        return ready.path.occlusion_ratio()


def uniform_mesh(scene: FEMesh, displacement: float) -> FEMesh:
    """A copy of ``scene`` with every part translated by ``uniform_explosion``."""
    ids = [int(p) for p in np.unique(scene.parts)]
    lo, hi = scene.bounds()
    centre = 0.5 * (np.asarray(lo) + np.asarray(hi))
    subs = [scene.part(p) for p in ids]
    centres = [0.5 * (s.nodes.min(axis=0) + s.nodes.max(axis=0)) for s in subs]
    moves = uniform_explosion(np.array(centres), centre, displacement)
    nodes, elements, parts, base = [], [], [], 0
    for pid, sub, move in zip(ids, subs, moves):
        nodes.append(sub.nodes + move)
        elements.append(sub.elements + base)
        parts += [pid] * len(sub.elements)
        base += len(sub.nodes)
    return FEMesh(np.concatenate(nodes), np.concatenate(elements), np.array(parts),
                  name=f"{scene.name} uniform")


def r_uniform(ctx, scene, focus, direction, size, displacement) -> float:
    """The occlusion ratio r of ``focus`` in the uniform explosion by ``displacement``, seen
    along ``direction`` with the camera refitted to it."""
    moved = uniform_mesh(scene, displacement)
    return r_fixed(ctx, moved, focus, "x", camera_along(moved, size, direction), size, 0.0)


def most_hidden_part(ctx, scene, size) -> tuple[int, list[dict]]:
    """The part with the largest r from the default view at offset 0 (ties: more pixels), and
    every part's counts and r."""
    camera = default_view_camera(scene, size)
    found = []
    for p in sorted(int(v) for v in np.unique(scene.parts)):
        with prepared(ctx, scene, make_path("exploded", focus=p, plane="x"), camera=camera,
                      size=size) as ready:
            pu, po, _ = ready.path.measure_occlusion()
        found.append({"part": p, "p_unocc": pu, "p_occ": po, "r": occlusion_ratio(pu, po)})
    best = max(found, key=lambda f: (f["r"], f["p_unocc"]))
    return best["part"], found


# ---------------------------------------------------------------------------- rows
def sweep_row(rec, label, focus, kind, theta, v, frames, exponent) -> dict:
    """One row of the view sweep from an :func:`animate` record (see the module docstring)."""
    o_max, normal = rec["o_max"], rec["normal"]
    plane_angle = math.degrees(math.asin(min(1.0, abs(float(normal @ v)))))
    hit = next((i for i, r in enumerate(rec["r"]) if r <= REVEALED), None)
    draw = statistics.median(rec["d_wall"])
    occlusion = statistics.median(c - d + s for c, d, s in
                                  zip(rec["c_wall"], rec["d_wall"], rec["step_wall"]))
    separate = statistics.median(rec["sep_wall"])
    return {
        "scene": label, "focus_part": focus, "plane": kind, "ratio_exponent": exponent,
        "normal": ",".join(f"{c:.3f}" for c in normal),
        "view_to_plane_deg": theta if kind == "manual" else round(plane_angle, 2),
        "sweep_deg": theta, "frames": frames,
        "frames_to_reveal": hit if hit is not None else f"not within {frames}",
        "offset_at_reveal_over_o_max": ((rec["offset"][hit - 1] / o_max if hit else 0.0)
                                        if hit is not None else None),
        "final_r": rec["final_r"], "final_offset_over_o_max": rec["offset"][-1] / o_max,
        "final_phase": rec["phase"], "o_max": o_max, "final_alpha": rec["alpha"][-1],
        "visible_through_ghost_pct": (None if rec["ghost_visible"] is None
                                      else 100.0 * rec["ghost_visible"]),
        "draw_gpu_ms": gpu_median(rec["d_gpu"]), "draw_wall_ms": draw,
        "counted_in_frame_pct": 100.0 * sum(rec["in_frame"]) / len(rec["in_frame"]),
        "occlusion_wall_ms": occlusion,
        "occlusion_over_draw": occlusion / draw if draw > 0 else None,
        "separate_pass_gpu_ms": gpu_median(rec["sep_gpu"]),
        "separate_pass_wall_ms": separate,
        "separate_over_draw": separate / draw if draw > 0 else None}


def gpu_median(samples: list[float | None]) -> float | None:
    """The median GPU time (ms), None where the renderer's timer queries time nothing."""
    return None if any(v is None for v in samples) else statistics.median(samples)


def compare_row(ctx, scene, label, focus, manual, camera, direction, size, theta, rec) -> dict:
    """The revealed shares at the automatic row's final offset D (see the module docstring)."""
    d, o_max = rec["offset"][-1], rec["o_max"]
    ru = r_uniform(ctx, scene, focus, direction, size, d)
    rf = r_fixed(ctx, scene, focus, manual, camera, size, d)
    return {"scene": label, "focus_part": focus, "sweep_deg": theta,
            "displacement": d, "displacement_over_o_max": d / o_max,
            "occlusion_driven_revealed": 1.0 - rec["final_r"], "uniform_revealed": 1.0 - ru,
            "fixed_offset_manual_plane_revealed": 1.0 - rf,
            "beats_uniform": ru > rec["final_r"], "beats_fixed_offset": rf > rec["final_r"]}


def sweep_rows(exp: ExperimentContext, case: Case, focus, manual, w, size, frames,
               known=None) -> tuple[list[dict], list[dict]]:
    """The view sweep's rows of one scene (manual plane ``manual`` with the views turned from
    ``w`` towards its normal) and its comparison rows; ``known(θ)``, where given, is the
    closed-form reveal offset."""
    ctx, label, scene = exp.gl, case.label, case.scene
    n = {"x": np.array([1.0, 0, 0]), "y": np.array([0, 1.0, 0]), "z": np.array([0, 0, 1.0])}[manual]
    rows, compare = [], []
    for theta in ANGLES:
        direction = sweep_direction(w, n, theta)
        camera = camera_along(scene, size, direction)
        v = view_dir(camera)
        for kind, plane in (("manual", manual), ("auto", "auto")):
            measured = None
            if kind == "manual":
                o_max = o_max_of(scene)
                measured = measured_reveal_offset(ctx, scene, focus, plane, camera, size, o_max)
            for exponent in EXPONENTS:
                rec = animate(ctx, scene, focus, plane, camera, size, frames, exponent)
                row = sweep_row(rec, label, focus, kind, theta, v, frames, exponent)
                if kind == "manual" and known is not None:
                    row["closed_form_reveal_over_o_max"] = known(theta) / rec["o_max"]
                if kind == "manual":
                    row["measured_reveal_over_o_max"] = (None if measured is None
                                                         else measured / rec["o_max"])
                rows.append(row)
                exp.say(f"{label} θ={theta:g}° {kind} p={exponent:g}: reveal frame "
                        f"{row['frames_to_reveal']}, final r {rec['final_r']:.3f}, "
                        f"offset/o_max {row['final_offset_over_o_max']:.3f}, occlusion/draw "
                        f"{row['occlusion_over_draw']:.2f}")
                if kind == "auto" and exponent == EXPONENTS[0]:
                    compare.append(compare_row(ctx, scene, label, focus, manual, camera,
                                               direction, size, theta, rec))
    return rows, compare


def figures(exp: ExperimentContext, case: Case, focus, plane, camera, size, frames) -> None:
    """``strip_<label>.png`` (:data:`STRIP_FRAMES` frames of the animation) and
    ``<label>.gif`` (every frame, with a progress bar)."""
    rec = animate(exp.gl, case.scene, focus, plane, camera, size, frames, keep_images=True)
    images = rec["images"]
    pick = np.unique(np.linspace(0, len(images) - 1, STRIP_FRAMES).round().astype(int))
    save_image_grid(exp.file(f"strip_{case.label}.png"), [images[i] for i in pick],
                    [f"frame {i + 1}: r {rec['r'][i]:.2f} -> offset {rec['offset'][i]:.3g}"
                     for i in pick], columns=4)
    save_animation(exp.file(f"{case.label}.gif"), images)


def car_rows(exp: ExperimentContext, car: FEMesh, size, frames) -> tuple[list[dict], list[dict]]:
    """The car's sweep and comparison rows, ``car_parts`` and its figures: the focus is the
    part most hidden from the default view, the manual plane y."""
    focus, scan = most_hidden_part(exp.gl, car, size)
    exp.table(scan, "car_parts",
              f"Car parts from the default view {DEFAULT_VIEW} at offset 0 "
              f"(focus: part {focus}, the most hidden)")
    exp.say(f"car: focus part {focus} (most hidden from {DEFAULT_VIEW})")
    default = view_dir(default_view_camera(car, size))
    n = np.array([0.0, 1.0, 0.0])
    w = default - float(default @ n) * n
    w /= np.linalg.norm(w)
    case = Case("car", car)
    rows, compare = sweep_rows(exp, case, focus, "y", w, size, frames)
    figures(exp, case, focus, "auto", default_view_camera(car, size), size, frames)
    return rows, compare


@experiment("fig_exploded", "ghost2013: occlusion-driven ghosted exploded views over view "
            "angles on the car and a box of panels, against uniform and fixed-offset explosions",
            declared=DECLARED)
def run(exp: ExperimentContext) -> list[dict]:
    size = exp.pick((400, 300), (200, 150), TINY_SIZE)
    frames = exp.pick(60, 40, TINY_FRAMES)
    exp.say(f"renderer: {exp.renderer}")

    box = Case("box", box_scene())
    w_box = np.array([0.0, 1.0, 0.0])  # the +y view: the x plane's normal perpendicular to it
    rows, compare = sweep_rows(exp, box, BOX_FOCUS, "x", w_box, size, frames,
                               known=box_reveal_offset)
    figures(exp, box, BOX_FOCUS, "x",
            camera_along(box.scene, size, sweep_direction(w_box, np.array([1.0, 0, 0]), 20.0)),
            size, frames)

    car = exp.builtin("car", "car rows")
    if car is not None:
        r, c = car_rows(exp, car, size, frames)
        rows += r
        compare += c

    exp.table(compare, "compare",
              "Revealed share (1 - r) at equal displacement D (each half's offset): "
              "occlusion-driven (auto plane), uniform explosion, fixed offset on the "
              "manual plane")
    return rows
