"""``workbench explode``: the ghost2013 exploded-view animation of one part, offscreen.

Each frame is drawn, counting the focus part's visible pixels as it is drawn; the occlusion
ratio r then advances the offset of the two halves
(:meth:`~workbench.paths.exploded.ExplodedPath.step_animation`, s_u = 1, speed ∝ r^p with
``--ratio-exponent p``). r and the offset are printed per frame, the frames are written as an animated GIF or
as a strip PNG (frames side by side), and the last line says how much of the focus is visible
at the end: ``revealed R after F frames, offset O of o_max M`` (R = p_occ/p_unocc, 0 to 1).

Each frame carries a thin progress bar along its bottom edge (its length is the frame's
position in the animation), so frames whose scene no longer changes stay distinct frames of
the GIF.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

FORMATS = (".gif", ".png")
BAR_PX = 3  # height of the frame progress bar


def add_explode_parser(sub, pair, size) -> argparse.ArgumentParser:
    """Register ``explode`` on the ``workbench`` sub-command set ``sub``; ``pair`` and ``size``
    are the CLI's "A,B" and "WxH" argument types."""
    p = sub.add_parser(
        "explode", help="animate an exploded view revealing one part (ghost2013)",
        description="Keep the focus part in place, split the rest of the assembly by a plane and "
                    "move the halves apart frame by frame until the focus is revealed (offset "
                    "driven by occlusion queries, capped at the assembly diameter, front half "
                    "ghosted beyond 0.7 of it). Writes an animated GIF or a strip PNG.")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    p.add_argument("--focus", type=int, required=True, metavar="PART",
                   help="part id of the object of interest")
    p.add_argument("--view", type=lambda s: pair(s, ","), default=(30.0, 25.0), metavar="AZ,EL",
                   help="azimuth and elevation in degrees (default 30,25)")
    p.add_argument("--up", choices=("y", "z"), default="z",
                   help="world axis shown upwards (default z)")
    p.add_argument("--frames", type=int, default=30, metavar="N", help="frames (default 30)")
    p.add_argument("--plane", default="auto", metavar="auto|x|y|z|A,B,C",
                   help="split plane normal through the focus (default auto)")
    p.add_argument("--ratio-exponent", type=float, default=0.5, metavar="P",
                   help="p in the growth speed s_u*(o_max - offset)*r^p, in (0, 1]: 1 is the "
                        "thesis's, the default 0.5 reaches the reveal offset in fewer frames")
    p.add_argument("--size", type=size, default=(400, 300), metavar="WxH",
                   help="frame size (default 400x300)")
    p.add_argument("-o", "--output", required=True, help="OUT.gif (animation) or OUT.png (strip)")
    p.set_defaults(func=cmd_explode)
    return p


def _progress(frames: int):
    """(iterable of frame numbers, write-a-line function): tqdm's bar where installed."""
    try:
        from tqdm import tqdm
    except ImportError:
        return range(frames), print
    bar = tqdm(range(frames), desc="explode", unit="frame", file=sys.stderr)
    return bar, bar.write


def cmd_explode(args) -> int:
    from .experiment.figures import save_animation, with_progress_bar
    from .experiment.measure import default_camera
    from .gl import Framebuffer, create_context
    from .paths import make_path
    from .scene.builtin import load_scene
    from .scene.mesh import FEMesh

    out = Path(args.output)
    if out.suffix.lower() not in FORMATS:
        raise ValueError(f"output {out} must end in .gif (animation) or .png (strip)")
    if args.frames < 1:
        raise ValueError(f"--frames must be at least 1, got {args.frames}")
    scene = load_scene(args.mesh)
    if not isinstance(scene, FEMesh):
        raise ValueError(f"{args.mesh!r} is not an FE mesh: the exploded view splits the parts "
                         f"of a mesh")
    ids = sorted(int(p) for p in np.unique(scene.parts))
    if args.focus not in ids:
        raise KeyError(f"{scene.name} has no part {args.focus}; part ids: {ids}")
    path = make_path("exploded", focus=args.focus, plane=args.plane, speed=1.0,
                     ratio_exponent=args.ratio_exponent)
    ctx = create_context()
    from .paths.exploded import exploded_camera

    camera = exploded_camera(default_camera(scene, args.size, view=args.view, up=args.up), scene)
    fb = Framebuffer(ctx, args.size)
    frames = []
    try:
        with path:
            path.prepare(ctx, scene, camera)
            steps, write = _progress(args.frames)
            for i in steps:
                fb.use()
                fb.clear()
                path.draw()
                frames.append(with_progress_bar(fb.read(), i + 1, args.frames, BAR_PX))
                offset = path.offset
                r = path.step_animation()
                write(f"frame {i + 1:>3}/{args.frames}: offset {offset:.4g}, r {r:.3f} -> "
                      f"offset {path.offset:.4g}, alpha {path.alpha:.3f}")
            if hasattr(steps, "close"):
                steps.close()
            fb.use()
            p_unocc, p_occ, _ = path.measure_occlusion()
            offset, o_max = path.offset, path.settings.o_max
    finally:
        fb.release()
    out.parent.mkdir(parents=True, exist_ok=True)
    save_animation(out, frames)
    revealed = p_occ / p_unocc if p_unocc else 0.0
    print(f"{out}: {len(frames)} frames of {scene.name}, focus part {args.focus}")
    print(f"revealed {revealed:.3g} after {len(frames)} frames, offset {offset:.3g} of "
          f"o_max {o_max:.3g}")
    return 0
