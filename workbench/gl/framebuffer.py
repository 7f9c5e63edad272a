"""Offscreen framebuffers: RGBA8 colour, 24-bit depth, optional MSAA, read back to numpy."""

from __future__ import annotations

import moderngl
import numpy as np


class Framebuffer:
    """An offscreen RGBA8 + depth target of ``size = (width, height)`` pixels.

    With ``samples > 0`` drawing goes to a multisampled target and :meth:`read` resolves it into
    a single-sampled one first. Images come back as (H, W, 4) uint8 with row 0 at the top.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], samples: int = 0) -> None:
        width, height = (int(s) for s in size)
        if width <= 0 or height <= 0:
            raise ValueError(f"framebuffer size must be positive, got {size}")
        if samples and samples > ctx.max_samples:
            raise ValueError(f"{samples} samples asked, the driver allows {ctx.max_samples}")
        self.ctx, self.size, self.samples = ctx, (width, height), int(samples)
        self.fbo = ctx.framebuffer(
            color_attachments=[ctx.renderbuffer(self.size, 4, samples=self.samples)],
            depth_attachment=ctx.depth_renderbuffer(self.size, samples=self.samples),
        )
        self._resolve = None
        if self.samples:
            self._resolve = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size, 4)])

    @property
    def width(self) -> int:
        return self.size[0]

    @property
    def height(self) -> int:
        return self.size[1]

    def use(self) -> None:
        """Bind for drawing, with the viewport covering the whole target."""
        self.fbo.use()
        self.ctx.viewport = (0, 0, *self.size)

    def clear(self, color=(1.0, 1.0, 1.0, 1.0), depth: float = 1.0) -> None:
        self.use()
        self.fbo.clear(*color, depth=depth)

    def read(self) -> np.ndarray:
        """(H, W, 4) uint8 RGBA, row 0 at the top (waits for drawing to finish)."""
        source = self.fbo
        if self._resolve is not None:
            self.ctx.copy_framebuffer(self._resolve, self.fbo)
            source = self._resolve
        data = source.read(components=4, alignment=1)
        image = np.frombuffer(data, np.uint8).reshape(self.height, self.width, 4)
        return image[::-1].copy()

    def read_depth(self) -> np.ndarray:
        """(H, W) float32 window-space depth in [0, 1], row 0 at the top (single-sampled only)."""
        if self.samples:
            raise ValueError("depth read-back of a multisampled framebuffer is not supported")
        data = self.fbo.read(attachment=-1, dtype="f4")
        return np.frombuffer(data, np.float32).reshape(self.height, self.width)[::-1].copy()

    def release(self) -> None:
        for fbo in (self.fbo, self._resolve):
            if fbo is not None:
                for attachment in (*fbo.color_attachments, fbo.depth_attachment):
                    if attachment is not None:
                        attachment.release()
                fbo.release()
