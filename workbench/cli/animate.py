"""``workbench animate``: a time-dependent FE mesh (a crash's d3plot: one topology, coordinates
and fields per state) played over its states, written as an MP4 or GIF.

The path is prepared once and each state uploads only its coordinates, normals and field
values (:class:`~workbench.animation.frames.FrameLoop`); every frame is the image
``workbench render MESH --step K --raw`` draws with the same options, decorated with the
state's time and, with a field, the colour bar (:mod:`workbench.animation.decoration`).
Printed: what was written, what preparing cost, and per state the median and range of the
upload and of the draw with its read-back (ms), with the bytes each state uploaded.

``--simplify PCT`` draws instead the mesh's triangles decimated once within a certified
one-sided Hausdorff distance of PCT % of each part's bounding-sphere diameter, at every state's
coordinates, a row under each frame giving the bound certified at its state
(:mod:`workbench.animation.simplified`).
"""

from __future__ import annotations

import argparse
import statistics
import sys
from typing import NamedTuple

from .arguments import add_device_argument, image_size, key_value, view_angles
from .field_options import add_field_arguments, load_with_fields


class StateSelection(NamedTuple):
    """``--steps`` as given (``text``) and read: ``start``, ``stop``, ``stride`` of a Python
    slice (None where left out); ``option`` the option's name, for the messages."""

    text: str
    start: int | None
    stop: int | None
    stride: int | None
    option: str = "--steps"

    def states(self, mesh) -> list[int]:
        """The states of ``mesh`` selected, as ``list(range(n_states))[start:stop:stride]``
        (negative indices counting from the end). Refused (ValueError naming the mesh's
        number of states): a start or stop beyond the states, and a selection of no state."""
        n = mesh.n_steps
        states = f"{mesh.name} has {n} state{'s' * (n != 1)} (0..{n - 1})"
        if self.start is not None and not -n <= self.start < n:
            raise ValueError(f"{self.option} {self.text}: state {self.start} is out of range; "
                             f"{states}")
        if self.stop is not None and not -n <= self.stop <= n:
            raise ValueError(f"{self.option} {self.text}: stop {self.stop} is out of range; "
                             f"{states}")
        chosen = list(range(n))[self.start:self.stop:self.stride]
        if not chosen:
            raise ValueError(f"{self.option} {self.text} selects no state; {states}")
        return chosen


def state_selection(text: str) -> StateSelection:
    """``--steps``: ``A:B[:S]``, each part optional, or ``K`` alone (state K: ``K:K+1``)."""
    parts = text.split(":")
    try:
        if len(parts) == 1:
            k = int(text)
            return StateSelection(text, k, k + 1 if k != -1 else None, None)
        if len(parts) > 3:
            raise ValueError
        parts += [""] * (3 - len(parts))
        start, stop, stride = (int(p) if p.strip() else None for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected K or A:B[:S] with integers, got {text!r}") from None
    if stride is not None and stride < 1:
        raise argparse.ArgumentTypeError(f"the stride S must be at least 1, got {text!r}")
    return StateSelection(text, start, stop, stride)


def positive_fps(text: str) -> float:
    """``--fps``: a positive, finite number of frames per second."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
    return value


def positive_percent(text: str) -> float:
    """``--simplify``: a positive, finite percentage."""
    return positive_fps(text)


def add_parser(subparsers) -> None:
    """Add ``animate`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "animate", help="play a crash (a mesh with time steps) as an MP4 or GIF",
        description="Draw every selected state of a mesh with time steps (a d3plot: one "
                    "topology, coordinates and fields per state) offscreen through one render "
                    "path, prepared once (topology uploaded once, each state uploading its "
                    "coordinates, normals and field values), with one camera fitted to every "
                    "state, and write the frames with the state's time and the colour bar as "
                    "an MP4 (H.264) or animated GIF. Each frame is the image `workbench render "
                    "MESH --step K --raw` draws with the same options.")
    p.add_argument("mesh", help="mesh file (a d3plot) or built-in scene name")
    p.add_argument("-o", "--output", required=True,
                   help="OUT.mp4 (H.264, even --size) or OUT.gif (256 colours a frame)")
    p.add_argument("--path", metavar="PATH",
                   help="render path (default: gouraud; pixel_color or element_color with "
                        "--field): any mesh path but flange and exploded")
    p.add_argument("--field", help="node or element field to colour by (a d3plot's fields: "
                                    "workbench render --help)")
    add_field_arguments(p)
    p.add_argument("--steps", type=state_selection, metavar="A:B:S",
                   help="states drawn, as a Python slice: from A (inclusive, default 0) to B "
                        "(exclusive, default the number of states) every S (default 1); "
                        "negative A, B count from the end; K alone draws state K "
                        "(default: every state)")
    p.add_argument("--scale", choices=("fixed", "per-step"), default="fixed",
                   help="colour scale: fixed over every state (default: the field's range over "
                        "all states, as render) or each state's own range (prepares the path "
                        "again for each state)")
    p.add_argument("--fps", type=positive_fps, default=10.0,
                   help="frames per second (default 10)")
    p.add_argument("--size", type=image_size, default=(800, 600), metavar="WxH",
                   help="size of the drawn image in pixels, even for MP4 (odd sizes are "
                        "refused, not padded; default 800x600); the time stamp and colour bar "
                        "are added around it")
    p.add_argument("--view", type=view_angles, default=(30.0, 25.0), metavar="AZ,EL",
                   help="azimuth and elevation in degrees (default 30,25)")
    p.add_argument("--up", choices=("y", "z"), default="z",
                   help="world axis shown upwards (default z)")
    p.add_argument("--bands", type=int, default=0, help="number of contour bands (0: smooth)")
    p.add_argument("--colormap", help="matplotlib colormap name (default: the path's own)")
    p.add_argument("--units", default="", help="units of the field, for the colour bar label")
    p.add_argument("--time-units", default="",
                   help="unit of the states' times, for the time stamp (a d3plot does not name "
                        "it: its times are in the model's time unit)")
    p.add_argument("--show-deleted", choices=("hide", "ghost"), default="hide",
                   help="elements deleted at a state (erosion): hidden (default), or ghost: "
                        "drawn translucent")
    p.add_argument("-O", "--option", type=key_value, action="append", metavar="KEY=VALUE",
                   help="any style option of the path (repeatable)")
    p.add_argument("--simplify", type=positive_percent, metavar="PCT",
                   help="draw the triangles decimated once, part by part, within a certified "
                        "one-sided Hausdorff distance of PCT %% of each part's bounding-sphere "
                        "diameter (as simplify --tol), at every state's coordinates; a row "
                        "under each frame gives the bound certified at its state, as a "
                        "multiple of the tolerance. Refused for a mesh without states")
    p.add_argument("--states", choices=("first", "all"),
                   help="with --simplify: decimate at the first state drawn (first, default) "
                        "or certify the decimation at every state drawn (all)")
    add_device_argument(p)
    p.set_defaults(func=cmd_animate)


def _style(args, path_name: str):
    """The path's style from ``--field``, ``--bands``, ``--colormap`` and every ``-O``, as
    render makes it; the state drawn is the frame loop's to set (``-O step`` is refused)."""
    from ..paths.registry import check_options, path_class

    options = {"field": args.field, "bands": args.bands}
    if args.show_deleted != "hide":
        options["deleted"] = args.show_deleted
    options.update(dict(args.option or ()))
    if args.colormap is not None:
        options["colormap"] = args.colormap
    if "step" in options:
        raise ValueError("-O step does not apply to animate: select states with --steps")
    return path_class(path_name).style_class(**check_options(path_name, options))


def _progress(total: int):
    """A tqdm bar over the frames on stderr, shown once a frame is done (a run refused before
    its first frame leaves only the line of the refusal)."""
    from tqdm import tqdm

    return tqdm(total=total, desc="animate", unit="frame", file=sys.stderr, delay=1e-3)


def cmd_animate(args) -> int:
    """Draw the selected states, write ``--output``, print the costs; 0."""
    from ..animation.decoration import Decoration
    from ..animation.frames import FrameLoop, check_animated_path
    from ..gl import create_context
    from ..output.video import check_even, video_target, write_video
    from ..paths.registry import scene_path

    out = video_target(args.output)
    if out.suffix.lower() == ".mp4":
        check_even(args.size, "--size")
    if args.states is not None and args.simplify is None:
        raise ValueError(f"--states {args.states} applies to --simplify: give --simplify PCT")
    mesh, args.field = load_with_fields(args, mesh_only=True)
    steps = args.steps.states(mesh) if args.steps is not None else list(range(mesh.n_steps))
    path_name = scene_path(mesh, args.path, args.field, source=args.mesh)
    check_animated_path(path_name)
    style = _style(args, path_name)
    simplified = None
    if args.simplify is not None:
        from ..animation.simplified import simplify_animation

        simplified = simplify_animation(
            mesh, steps, args.simplify, args.states or "first", args.field,
            progress=lambda text: print(f"animate: {text} ...", file=sys.stderr))
    ctx = create_context(device=args.device)
    loop = FrameLoop(ctx, mesh if simplified is None else simplified.mesh, path_name, style,
                     steps=steps, size=args.size, view=args.view, up=args.up, scale=args.scale)
    decorate = Decoration(f"{mesh.name} ({path_name})", loop.field, args.units,
                          loop.style.colormap, loop.style.bands, args.time_units)
    if simplified is not None:
        decorate = simplified.decorate(decorate)
    costs: list[tuple] = []
    bar = _progress(len(steps))

    def decorated():
        for frame in loop:
            costs.append((frame.upload_ms, frame.draw_ms, frame.bytes_uploaded,
                          frame.bytes_per_step, frame.value_range, frame.deleted))
            bar.update()
            yield decorate(frame)

    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        count = write_video(out, decorated(), args.fps)
    finally:
        bar.close()
    for line in _report(out, count, mesh, path_name, loop, costs, args):
        print(line)
    if simplified is not None:
        print(simplified.summary())
    return 0


def _spread(values: list[float]) -> str:
    """``M ms (range A–B)``: median and range of milliseconds."""
    return f"{statistics.median(values):.3g} ms (range {min(values):.3g}–{max(values):.3g})"


def _report(out, count: int, mesh, path_name: str, loop, costs: list[tuple],
            args) -> list[str]:
    """The lines printed: what was written, what preparing cost, the per-state costs."""
    upload, draw, sent, per_step, ranges, deleted = (list(c) for c in zip(*costs))
    scale = ""
    if loop.field is not None:
        scale = f", {loop.field} on a {args.scale} scale"
        if args.scale == "fixed":
            scale += f" {ranges[0][0]:.4g}..{ranges[0][1]:.4g}"
    width, height = args.size
    n = mesh.n_steps
    lines = [f"{out}: {count} frame{'s' * (count != 1)} of {mesh.name} ({n} state"
             f"{'s' * (n != 1)}), path {path_name}{scale}, {width}x{height} at {args.fps:g} fps"]
    each = " or ".join(str(b) for b in sorted(set(sent)))
    draws = f"draw + read-back {_spread(draw)}"
    if args.scale == "fixed":
        lines += [f"prepared once: {loop.prepare_ms:.3g} ms, {loop.prepare_bytes} bytes "
                  f"(all prepare uploads, the first state included)",
                  f"per state: upload {_spread(upload)}, {draws}, {each} bytes uploaded "
                  f"(the path's bytes_per_step: {per_step[0]})"]
    else:
        lines += [f"per state, prepared again for its own scale: prepare {_spread(upload)}, "
                  f"{draws}, {each} bytes uploaded (set_step alone: {per_step[0]})"]
    if any(deleted):
        how = "ghosted" if loop.style.deleted == "ghost" else "not drawn"
        lines.append(f"deleted elements per state ({how}): "
                     + ", ".join(str(d) for d in deleted))
    return lines
