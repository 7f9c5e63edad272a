"""``animate`` of an eroding crash read from a d3plot file: per-state upload and draw of the
shells in use, against the same result drawn whole (its ``alive`` field dropped), interleaved.

The scene: the shared car refined k × k (the built-in ``car`` when the deck is absent),
crushed over S states with erosion (``crash_sequence(failure_strain=2.5)``: 0 elements deleted
at the first states, then more at each), written as a d3plot with lasso-python (coordinates of
every state, plastic strain on one layer, ``alive``) and read back through the workbench's
d3plot reader, so the benchmark covers what a user's file goes through. Full: k = 11, 20
states (528 286 shells); quick: k = 2, 8 states.

Rows, per path (``flat``; ``element_color`` of the plastic strain): ``eroding upload`` /
``plain upload`` (``set_step``: coordinates, values, and where the elements in use change the
index buffers; ms a state) and ``eroding draw`` / ``plain draw`` (the draw of an
800 × 600 frame, waited for; the read-back apart), each pair interleaved state by state
(state 0 a warm-up), with the ratio eroding / plain; and one untimed row ``scene`` with the
sizes, the deleted elements per state, the write and read seconds, the file's bytes and the
process's peak resident memory.

Run: ``workbench bench eroding_d3plot [--quick]``.
"""

from __future__ import annotations

import resource
import tempfile
import time
from pathlib import Path

from workbench.measurement.bench import Case, benchmark, needs_gl, needs_module
from workbench.output.d3plot import write_d3plot

SIZE = (800, 600)
FAILURE_STRAIN = 2.5


def eroding_crash(k: int, states: int):
    """The car refined ``k`` × ``k``, crushed over ``states`` states with erosion."""
    from workbench.scene.builtin import load_scene
    from workbench.scene.generators import crash_sequence, refine

    car = load_scene("car")
    rigid = [part for part, title in car.part_names.items() if "rigid" in title.lower()]
    big = refine(car, k) if k > 1 else car
    return crash_sequence(big, steps=states, still_parts=rigid, failure_strain=FAILURE_STRAIN)


def _frames(ctx, mesh, path: str, field: str | None):
    """An iterator over the frames of ``mesh`` through ``path`` (every state once)."""
    from workbench.animation.frames import FrameLoop
    from workbench.paths import make_path

    style = make_path(path, field=field).style
    return iter(FrameLoop(ctx, mesh, path, style, steps=list(range(mesh.n_steps)), size=SIZE))


@benchmark("eroding_d3plot", "animate of an eroding crash read from a d3plot, against it whole",
           cases=[Case("car crushed", {"k": 11, "states": 20}, {"k": 2, "states": 8})],
           requires=[needs_gl, needs_module("lasso")])
def eroding_d3plot(bench, k: int = 11, states: int = 20) -> None:
    from workbench.gl import create_context
    from workbench.scene.mesh import ALIVE, FEMesh
    from workbench.scene.readers import load

    crash = eroding_crash(k, states)
    with tempfile.TemporaryDirectory(prefix="eroding-d3plot-") as name:
        start = time.perf_counter()
        file = write_d3plot(crash, Path(name))
        written = time.perf_counter() - start
        size = sum(p.stat().st_size for p in Path(name).iterdir())
        del crash
        start = time.perf_counter()
        mesh = load(file)
        read = time.perf_counter() - start
    plain = FEMesh(mesh.nodes, mesh.elements, mesh.parts, mesh.steps,
                   element_fields={k: v for k, v in mesh.element_fields.items() if k != ALIVE},
                   times=mesh.times, name="plain")
    ctx = create_context()
    try:
        for path, field in (("flat", None), ("element_color", "plastic_strain")):
            for what in ("upload", "draw"):
                frames = {"eroding": _frames(ctx, mesh, path, field),
                          "plain": _frames(ctx, plain, path, field)}

                def clock(which: str, what: str = what, frames: dict = frames):
                    def run() -> float:
                        frame = next(frames[which])
                        return (frame.upload_ms if what == "upload" else frame.draw_ms) / 1e3
                    return run

                try:
                    bench.interleave({f"eroding {what}": clock("eroding"),
                                      f"plain {what}": clock("plain")},
                                     [(f"eroding {what}", f"plain {what}")], warmup=1,
                                     repeat=states - 1, reported=True, path=path)
                finally:  # each loop's path released while the context is current
                    for loop in frames.values():
                        loop.close()
        bench.record("scene", shells=mesh.n_elements, nodes=mesh.n_nodes, states=mesh.n_steps,
                     deleted=" ".join(str(mesh.n_deleted(s)) for s in range(mesh.n_steps)),
                     write_s=written, read_s=read, file_bytes=size,
                     peak_rss_gib=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20)
    finally:
        ctx.release()
