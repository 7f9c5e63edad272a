"""Buffer textures (GL_TEXTURE_BUFFER, a ``samplerBuffer`` in GLSL), which moderngl does not wrap.

A buffer texture is a flat array of texels read by index with ``texelFetch(sampler, i)``: no
rows, no filtering, and far more texels than a 2-D texture row allows (GL guarantees 65 536,
Mesa and current GPUs allow 2²⁷ and more). The data lives in a moderngl buffer; the texture
object around it is made through PyOpenGL on the current (moderngl) context.
"""

from __future__ import annotations

import moderngl
import numpy as np

from .context import raw_gl


class TextureBuffer:
    """A float32 RGBA buffer texture holding ``data`` ((N, 4) float32, N texels).

    ``use(unit)`` binds it to a texture unit for a ``samplerBuffer`` uniform. Refuses data of
    another shape or dtype, and more texels than the renderer's GL_MAX_TEXTURE_BUFFER_SIZE
    (ValueError).
    """

    def __init__(self, ctx: moderngl.Context, data: np.ndarray) -> None:
        data = np.asarray(data)
        if data.ndim != 2 or data.shape[1] != 4 or data.dtype != np.float32:
            raise ValueError(f"texture buffer data must be (N, 4) float32, "
                             f"got {data.shape} {data.dtype}")
        limit = int(ctx.info.get("GL_MAX_TEXTURE_BUFFER_SIZE", 65536))
        if len(data) > limit:
            raise ValueError(f"{len(data)} texels exceed this renderer's buffer texture limit "
                             f"of {limit}")
        self.ctx = ctx
        self.texels = len(data)
        self.buffer = ctx.buffer(np.ascontiguousarray(data).tobytes() or bytes(16))
        GL = self._gl = raw_gl()
        self.glo = int(GL.glGenTextures(1))
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, self.glo)
        GL.glTexBuffer(GL.GL_TEXTURE_BUFFER, GL.GL_RGBA32F, self.buffer.glo)
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, 0)

    @property
    def nbytes(self) -> int:
        return self.texels * 16

    def use(self, unit: int = 0) -> None:
        GL = self._gl
        GL.glActiveTexture(GL.GL_TEXTURE0 + int(unit))
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, self.glo)

    def release(self) -> None:
        if self.glo:
            self._gl.glDeleteTextures([self.glo])
            self.glo = 0
            self.buffer.release()
