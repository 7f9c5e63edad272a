"""Latency of the live Jupyter view: from a camera event to the compressed frame that is sent.

For each case a viewer (:func:`workbench.view`, frames of 800 × 600) is made and a left drag
started; then each timed ``pointer_move`` event (4 pixels right, then back left, an orbit of
180·4/H degrees each) is handed to the canvas's ``handle_event``, the frame is taken with
``get_frame`` (draw into the offscreen framebuffer and read back) and encoded as jupyter_rfb
encodes a frame while the view moves (its ``array2compressed`` at the canvas's ``quality``: a
JPEG by simplejpeg where it is installed). The latency of one event is the wall time from the
``handle_event`` call to the encoded bytes; what the browser then adds (transfer, decoding,
display) is not counted. Three events are drawn before timing (the warm-up); 30 events are
timed at full size, the bench's repetitions at quick size.

Rows per case: ``event total`` (the latency) and its parts ``event event`` (the camera
uniforms), ``event frame`` (draw and read-back) and ``event encode``; columns ``path``,
``triangles``, ``quality``, ``kib`` (median encoded frame) and ``prepare_s`` (making the
viewer). The design target is 100 ms for the car at 800 × 600 on llvmpipe.

Cases: ``car`` (the shared LS-DYNA deck, Gouraud) and ``semicylinders`` (the es2008 benchmark
scene, 8 sheets of 250 × 250 quads, 1 M triangles, its distance field in 10 bands per pixel;
quick: 64 × 64 quads a sheet).

Run: ``workbench bench viewer_latency [--quick]`` (needs an OpenGL context and jupyter_rfb).
"""

from __future__ import annotations

from workbench.data import CAR_DECK
from workbench.measurement.bench import Case, benchmark, needs_gl, needs_module

WARMUP, STEP_PX, SIZE, EVENTS = 3, 4.0, (800, 600), 30
BANDS = {"field": "distance", "bands": 10}


def event(kind: str, x: float, y: float) -> dict:
    """A jupyter_rfb pointer event of the left button at (x, y)."""
    return dict(type=kind, x=x, y=y, button=1, buttons=(1,) if kind != "pointer_up" else (),
                modifiers=(), ntouches=0, touches={})


@benchmark("viewer_latency", "the live Jupyter view: camera event to encoded frame",
           cases=[Case("car", {"scene": "car", "path": None}),
                  Case("semicylinders", {"scene": "semicylinders", "path": "pixel_color",
                                         "quads": 250},
                       {"scene": "semicylinders", "path": "pixel_color", "quads": 64})],
           requires=[needs_gl, needs_module("jupyter_rfb")])
def viewer_latency(bench, scene: str, path: str | None, quads: int = 0) -> None:
    import contextlib
    import io
    import statistics
    import time

    from jupyter_rfb._utils import array2compressed  # what the canvas's send encodes with

    from workbench import data, view

    if scene == "car":
        bench.require(data.shared_file(CAR_DECK) is None
                      and f"needs the shared data file {CAR_DECK}")
    spec = f"{scene}:{quads}" if quads else scene
    options = BANDS if path == "pixel_color" else {}
    start = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):  # jupyter_rfb displays its output area
        viewer = view(spec, path, size=SIZE, **options)
    prepare_s = time.perf_counter() - start
    canvas = viewer.canvas
    try:
        canvas.get_frame()
        x, y = SIZE[0] / 2, SIZE[1] / 2
        canvas.handle_event(event("pointer_down", x, y))
        canvas.handle_event(event("pointer_move", x + 10.0, y))  # past a click's travel
        where = {"x": x + 10.0, "i": 0}
        sizes = []

        def one_event() -> dict[str, float]:
            where["x"] += STEP_PX if where["i"] % 2 == 0 else -STEP_PX
            where["i"] += 1
            t0 = time.perf_counter()
            canvas.handle_event(event("pointer_move", where["x"], y))
            t1 = time.perf_counter()
            frame = canvas.get_frame()
            t2 = time.perf_counter()
            _, encoded = array2compressed(frame, canvas.quality)
            t3 = time.perf_counter()
            sizes.append(len(encoded))
            return {"total": t3 - t0, "event": t1 - t0, "frame": t2 - t1, "encode": t3 - t2}

        live = viewer.live
        timings = bench.time_reported(
            "event", one_event, warmup=WARMUP, repeat=bench.repeat if bench.quick else EVENTS,
            path=live.path_name, triangles=int(live.path.triangles),
            size=f"{SIZE[0]}x{SIZE[1]}", quality=canvas.quality, prepare_s=prepare_s)
        for row in bench.rows[-len(timings):]:
            row["kib"] = statistics.median(sizes[WARMUP:]) / 1024
        canvas.handle_event(event("pointer_up", where["x"], y))
    finally:
        viewer.close()
