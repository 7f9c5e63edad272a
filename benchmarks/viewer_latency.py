"""Latency of the live Jupyter view: from a camera event to the compressed frame that is sent.

For each scene a viewer (:func:`workbench.view`, frames of ``--size``) is made and a left drag
started; then each of ``--events`` timed ``pointer_move`` events (4 pixels right, then back
left, an orbit of 180·4/H degrees each) is handed to the canvas's ``handle_event``, the frame
is taken with ``get_frame`` (draw into the offscreen framebuffer and read back) and encoded as
jupyter_rfb encodes a frame while the view moves (its ``array2compressed`` at the canvas's
``quality``: a JPEG by simplejpeg where it is installed). The latency of one event is the wall
time from the ``handle_event`` call to the encoded bytes; what the browser then adds
(transfer, decoding, display) is not counted. Three events are drawn before timing.

The table gives per scene the median latency with its quartiles and range, the median of each
part (event: the camera uniforms; frame: draw and read-back; encode) and the median size of
an encoded frame. The design target is 100 ms for the car at 800 × 600 on llvmpipe: a camera
event only sets uniforms (nothing uploaded or derived again). Times hold for the renderer
and the machine printed above the table; on a shared or busy machine they are noisy.

Scenes: ``car`` (the shared LS-DYNA deck, Gouraud) and ``semicylinders`` (the es2008 benchmark
scene, 8 sheets of 250 × 250 quads, 1 M triangles, its distance field in 10 bands per pixel);
``--quick`` draws the benchmark scene with 64 × 64 quads a sheet.

Run: ``.venv/bin/python benchmarks/viewer_latency.py [--events 30] [--size 800x600] [--quick]
[--scene car --scene semicylinders] [--device N]``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import statistics
import sys
import time

import numpy as np

# (path, style options) each scene is viewed with
CASES = {"car": (None, {}),
         "semicylinders": ("pixel_color", {"field": "distance", "bands": 10})}
WARMUP = 3
STEP_PX = 4.0


def parse_size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must be WxH, got {text!r}") from None
    if width <= 0 or height <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    return width, height


def event(kind: str, x: float, y: float) -> dict:
    return dict(type=kind, x=x, y=y, button=1, buttons=(1,) if kind != "pointer_up" else (),
                modifiers=(), ntouches=0, touches={})


def measure_scene(spec: str, name: str, size: tuple[int, int], events: int,
                  device: int | None) -> dict:
    """Latencies of ``events`` camera events on scene ``spec`` (case ``name``), in ms."""
    from jupyter_rfb._utils import array2compressed  # what the canvas's send encodes with

    from workbench import view

    path, options = CASES[name]
    start = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):  # jupyter_rfb displays its output area
        viewer = view(spec, path, size=size, device=device, **options)
    prepare_s = time.perf_counter() - start
    canvas = viewer.canvas
    try:
        canvas.get_frame()
        x, y = size[0] / 2, size[1] / 2
        canvas.handle_event(event("pointer_down", x, y))
        canvas.handle_event(event("pointer_move", x + 10.0, y))  # past a click's travel
        x += 10.0
        parts = {"total": [], "event": [], "frame": [], "encode": [], "bytes": []}
        for i in range(WARMUP + events):
            x += STEP_PX if i % 2 == 0 else -STEP_PX
            t0 = time.perf_counter()
            canvas.handle_event(event("pointer_move", x, y))
            t1 = time.perf_counter()
            frame = canvas.get_frame()
            t2 = time.perf_counter()
            _, data = array2compressed(frame, canvas.quality)
            t3 = time.perf_counter()
            if i >= WARMUP:
                for key, value in (("total", t3 - t0), ("event", t1 - t0), ("frame", t2 - t1),
                                   ("encode", t3 - t2)):
                    parts[key].append(value * 1e3)
                parts["bytes"].append(len(data))
        canvas.handle_event(event("pointer_up", x, y))
        live = viewer.live
        return dict(scene=live.scene.name, path=live.path_name, triangles=live.path.triangles,
                    size=f"{size[0]}x{size[1]}", quality=canvas.quality, prepare_s=prepare_s,
                    **parts)
    finally:
        viewer.close()


def row(result: dict) -> str:
    total = np.asarray(result["total"])
    q1, median, q3 = np.percentile(total, [25, 50, 75])
    med = {k: statistics.median(result[k]) for k in ("event", "frame", "encode", "bytes")}
    return (f"| {result['scene']} | {result['path']} | {result['triangles']:,} | "
            f"{result['size']} | {len(total)} | {median:.1f} | {q1:.1f}–{q3:.1f} | "
            f"{total.min():.1f}–{total.max():.1f} | {med['event']:.2f} | {med['frame']:.1f} | "
            f"{med['encode']:.1f} | {result['quality']} | {med['bytes'] / 1024:.0f} | "
            f"{result['prepare_s']:.1f} |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--events", type=int, default=30, help="timed events per scene (30)")
    parser.add_argument("--size", type=parse_size, default=(800, 600), metavar="WxH",
                        help="frame size (default 800x600)")
    parser.add_argument("--scene", action="append", choices=sorted(CASES),
                        help="scene to measure (repeatable; default: all)")
    parser.add_argument("--quick", action="store_true",
                        help="the es2008 scene with 64 x 64 quads a sheet, not 250 x 250")
    parser.add_argument("--device", type=int, help="EGL device index")
    args = parser.parse_args(argv)
    if args.events < 1:
        parser.error("--events must be at least 1")
    from workbench.gl import create_context, renderer

    ctx = create_context(device=args.device)
    print(f"renderer: {renderer(ctx)}\n")
    ctx.release()
    print("| scene | path | triangles | size | events | median ms | quartiles ms | range ms | "
          "event ms | frame ms | encode ms | JPEG quality | KiB | prepare s |")
    print("|---|---|---:|---|---:|---:|---|---|---:|---:|---:|---:|---:|---:|")
    for name in args.scene or list(CASES):
        spec = "semicylinders:64" if name == "semicylinders" and args.quick else name
        try:
            result = measure_scene(spec, name, args.size, args.events, args.device)
        except FileNotFoundError as exc:
            print(f"<!-- {name}: skipped: {exc} -->", file=sys.stderr)
            continue
        print(row(result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
