"""``workbench explode``: the ghost2013 exploded-view animation of one part, offscreen
(:func:`workbench.animation.exploded.explode_animation`).

Each frame is drawn, counting the focus part's visible pixels as it is drawn; the occlusion
ratio r then advances the offset of the two halves
(:meth:`~workbench.paths.exploded.ExplodedPath.step_animation`, s_u = 1, speed ∝ r^p with
``--ratio-exponent p``). r, the focus's visible and unoccluded pixel counts and the offset are
printed per frame, the frames are written as an animated GIF or as a strip PNG (frames side by
side), and the last line names the first frame K of N whose r is at or below the path's
``revealed_below`` (0: every pixel of the focus visible): ``revealed at frame K of N: S % of
its pixels visible (P_OCC of P_UNOCC), offset O of o_max M``, or ``not revealed within N frames:
S % of its pixels visible (…) in the last frame, …`` (S = 100·p_occ/p_unocc; offsets in model
units). A focus part with no pixels in the view (smaller than a pixel, edge-on) is refused.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .arguments import add_device_argument, image_size, view_angles

FORMATS = (".gif", ".png")


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``explode`` to the ``workbench`` command's subparsers; returns its parser."""
    p = subparsers.add_parser(
        "explode", help="animate an exploded view revealing one part (ghost2013)",
        description="Keep the focus part in place, split the rest of the assembly by a plane and "
                    "move the halves apart frame by frame until the focus is revealed (offset "
                    "driven by occlusion queries, capped at the assembly diameter, front half "
                    "ghosted beyond 0.7 of it). Writes an animated GIF or a strip PNG.")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    add_device_argument(p)
    p.add_argument("--focus", type=int, required=True, metavar="PART",
                   help="part id of the object of interest")
    p.add_argument("--view", type=view_angles, default=(30.0, 25.0), metavar="AZ,EL",
                   help="azimuth and elevation in degrees (default 30,25)")
    p.add_argument("--up", choices=("y", "z"), default="z",
                   help="world axis shown upwards (default z)")
    p.add_argument("--frames", type=int, default=30, metavar="N", help="frames (default 30)")
    p.add_argument("--plane", default="auto", metavar="auto|x|y|z|A,B,C",
                   help="split plane normal through the focus (default auto)")
    p.add_argument("--ratio-exponent", type=float, default=0.5, metavar="P",
                   help="p in the growth speed s_u*(o_max - offset)*r^p, in (0, 1]: 1 is the "
                        "thesis's, the default 0.5 reaches the reveal offset in fewer frames")
    p.add_argument("--size", type=image_size, default=(400, 300), metavar="WxH",
                   help="frame size (default 400x300)")
    p.add_argument("-o", "--output", required=True, help="OUT.gif (animation) or OUT.png (strip)")
    p.set_defaults(func=cmd_explode)
    return p


def _progress(frames: int):
    """(tqdm bar over the frame numbers, its write-a-line function), on stderr. The bar shows
    from the second frame on, so that a run refused at its first frame (a focus without pixels)
    leaves only the one line of the refusal on stderr."""
    from tqdm import tqdm

    bar = tqdm(range(frames), desc="explode", unit="frame", file=sys.stderr, delay=1e-3)
    return bar, bar.write


def _focus_mesh(spec: str, focus: int):
    """The FE mesh ``spec``; ValueError for another kind of scene, KeyError when it has no
    part ``focus``."""
    from ..scene.builtin import load_mesh

    scene = load_mesh(spec)
    ids = sorted(int(p) for p in np.unique(scene.parts))
    if focus not in ids:
        raise KeyError(f"{scene.name} has no part {focus}; part ids: {ids}")
    return scene


def cmd_explode(args) -> int:
    """Animate, print a line per frame, write ``--output`` and the reveal; 0."""
    from ..animation.exploded import explode_animation
    from ..gl import create_context
    from ..measurement.rows import default_camera
    from ..output.figures import save_animation
    from ..output.targets import output_target
    from ..paths import make_path
    from ..paths.exploded import exploded_camera

    out = output_target(args.output)
    if out.suffix.lower() not in FORMATS:
        raise ValueError(f"output {out} must end in .gif (animation) or .png (strip)")
    if args.frames < 1:
        raise ValueError(f"--frames must be at least 1, got {args.frames}")
    scene = _focus_mesh(args.mesh, args.focus)
    path = make_path("exploded", focus=args.focus, plane=args.plane, speed=1.0,
                     ratio_exponent=args.ratio_exponent)
    ctx = create_context(device=args.device)
    camera = exploded_camera(default_camera(scene, args.size, view=args.view, up=args.up), scene)
    steps, write = _progress(args.frames)

    def report(i: int, offset: float, r: float, path) -> None:
        counts = path.last_occlusion
        write(f"frame {i + 1:>3}/{args.frames}: offset {offset:.4g}, r {r:.3f} "
              f"({counts['p_occ']} of {counts['p_unocc']} px visible) -> "
              f"offset {path.offset:.4g}, alpha {path.alpha:.3f}")

    try:
        run = explode_animation(ctx, scene, path, camera, args.size, args.frames, steps=steps,
                                on_frame=report)
    finally:
        steps.close()
    out.parent.mkdir(parents=True, exist_ok=True)
    save_animation(out, run.frames)
    print(f"{out}: {len(run.frames)} frames of {scene.name}, focus part {args.focus}")
    print(_reveal_line(run))
    return 0


def _reveal_line(run) -> str:
    """The last line: the first frame that revealed the focus, or that none did and how much
    of it the last frame shows, with the pixel counts and the offset of that frame."""
    frame = run.revealed_frame
    k = (frame or len(run.frames)) - 1
    share = (f"{100.0 * min(1.0, run.p_occ[k] / run.p_unocc[k]):.3g} % of its pixels visible "
             f"({run.p_occ[k]} of {run.p_unocc[k]})")
    where = f"offset {run.offsets[k]:.3g} of o_max {run.o_max:.3g}"
    n = len(run.frames)
    if frame is None:
        return (f"not revealed within {n} frame{'s' * (n != 1)}: {share} in the last frame, "
                f"{where}")
    return f"revealed at frame {frame} of {n}: {share}, {where}"
