"""GPU timer, occlusion (samples-passed) and primitive queries, wrapped for the measurement harness.

Each query measures the GL commands issued inside ``with query:``; reading its result waits
for those commands to finish. moderngl frees a query when it is garbage-collected.
"""

from __future__ import annotations

import moderngl


class _Query:
    kind: dict[str, bool] = {}

    def __init__(self, ctx: moderngl.Context) -> None:
        self.query = ctx.query(**self.kind)

    def __enter__(self):
        self.query.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        self.query.__exit__(*exc)


class GpuTimer(_Query):
    """GL_TIME_ELAPSED (ARB_timer_query). On llvmpipe this is the software rasterizer's time."""

    kind = {"time": True}

    @property
    def elapsed_ms(self) -> float:
        return self.query.elapsed / 1e6


class SamplesPassed(_Query):
    """GL_SAMPLES_PASSED: samples that pass the depth test (occlusion query)."""

    kind = {"samples": True}

    @property
    def samples(self) -> int:
        return int(self.query.samples)


class PrimitivesGenerated(_Query):
    """GL_PRIMITIVES_GENERATED: primitives that reach the rasterizer stage."""

    kind = {"primitives": True}

    @property
    def primitives(self) -> int:
        return int(self.query.primitives)
