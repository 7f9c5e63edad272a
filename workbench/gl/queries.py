"""GPU timer, occlusion (samples-passed) and primitive queries, wrapped for the measurement harness.

Each query measures the GL commands issued inside ``with query:``; reading its result waits
for those commands to finish. moderngl frees a query when it is garbage-collected.
"""

from __future__ import annotations

from typing import Any, Self

import moderngl
import numpy as np


class _Query:
    kind: dict[str, bool] = {}

    def __init__(self, ctx: moderngl.Context) -> None:
        self.query = ctx.query(**self.kind)

    def __enter__(self) -> Self:
        self.query.__enter__()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.query.__exit__(*exc)


class GpuTimer(_Query):
    """GL_TIME_ELAPSED (ARB_timer_query) in milliseconds, or None on a software renderer, whose
    timer queries do not time the draw (llvmpipe answers ~3e-05 ms for whole frames); see
    :func:`workbench.gl.context.timer_queries_meaningful`. ``meaningful`` says which."""

    kind = {"time": True}

    def __init__(self, ctx: moderngl.Context) -> None:
        from .context import timer_queries_meaningful

        super().__init__(ctx)
        self.meaningful = timer_queries_meaningful(ctx)

    @property
    def elapsed_ms(self) -> float | None:
        return self.query.elapsed / 1e6 if self.meaningful else None


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


GL_VERTEX_SHADER_INVOCATIONS = 0x82F0  # ARB_pipeline_statistics_query, core in GL 4.6


class VertexShaderInvocations:
    """GL_VERTEX_SHADER_INVOCATIONS: vertex shader runs inside ``with query:`` (pipeline
    statistics). The count includes runs a post-transform vertex cache did not save; it is the
    number the driver reports, not a computed one.

    :meth:`supported` says whether the context exposes the query (GL 4.6 or
    ``GL_ARB_pipeline_statistics_query``); constructing one without it raises RuntimeError.
    """

    def __init__(self, ctx: moderngl.Context) -> None:
        if not self.supported(ctx):
            raise RuntimeError("this GL context has no pipeline statistics queries "
                               "(GL 4.6 or GL_ARB_pipeline_statistics_query)")
        from .context import raw_gl

        self._gl = raw_gl()
        self._id = int(np.ravel(self._gl.glGenQueries(1))[0])
        self._count: int | None = None

    @staticmethod
    def supported(ctx: moderngl.Context) -> bool:
        return ctx.version_code >= 460 or "GL_ARB_pipeline_statistics_query" in ctx.extensions

    def __enter__(self) -> Self:
        self._count = None
        self._gl.glBeginQuery(GL_VERTEX_SHADER_INVOCATIONS, self._id)
        return self

    def __exit__(self, *exc: object) -> None:
        self._gl.glEndQuery(GL_VERTEX_SHADER_INVOCATIONS)

    @property
    def invocations(self) -> int:
        """Vertex shader invocations counted (waits for the measured commands to finish)."""
        if self._count is None:
            # 32-bit result: PyOpenGL's 64-bit variant fails on its own type table, and one draw
            # here never runs the vertex shader 2^32 times
            self._count = int(np.ravel(self._gl.glGetQueryObjectuiv(
                self._id, self._gl.GL_QUERY_RESULT))[0])
        return self._count

    def release(self) -> None:
        if self._id:
            self._gl.glDeleteQueries(1, [self._id])
            self._id = 0
