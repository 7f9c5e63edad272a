"""Offscreen framebuffers: RGBA8 colour, 24-bit or 32-bit float depth, optional MSAA, read back to
numpy."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import moderngl
import numpy as np

from .context import raw_gl

DEPTH_BITS = (24, 32)


def sample_counts(ctx: moderngl.Context) -> tuple[int, ...]:
    """The MSAA sample counts a framebuffer may ask for: 0 (none) and the powers of two up to
    the driver's maximum."""
    counts, n = [0], 1
    while n <= ctx.max_samples:
        counts.append(n)
        n *= 2
    return tuple(counts)


@contextmanager
def write_masks(ctx: moderngl.Context, color: bool = True,
                depth: bool = True) -> Iterator[moderngl.Framebuffer]:
    """Within the block the bound framebuffer (``ctx.fbo``) writes colour and depth only as
    asked; its previous masks and the viewport are restored after.

    moderngl applies a framebuffer's colour mask when the framebuffer is bound, not when the
    mask is set, so the framebuffer is bound again (keeping ``ctx.viewport``) after each change.
    """
    fbo, viewport = ctx.fbo, ctx.viewport
    previous = fbo.color_mask, fbo.depth_mask

    def apply(color_mask, depth_mask) -> None:
        fbo.color_mask, fbo.depth_mask = color_mask, depth_mask
        fbo.use()
        ctx.viewport = viewport

    apply((color,) * 4, depth)
    try:
        yield fbo
    finally:
        apply(*previous)


class Framebuffer:
    """An offscreen RGBA8 + depth target of ``size = (width, height)`` pixels.

    With ``samples > 0`` drawing goes to a multisampled target and :meth:`read` resolves it into
    a single-sampled one first. Images come back as (H, W, 4) uint8 with row 0 at the top.
    ``depth_bits`` is 24 (fixed point, moderngl's own depth buffer) or 32 (GL_DEPTH_COMPONENT32F,
    made through PyOpenGL since moderngl has no float depth buffer).
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], samples: int = 0,
                 depth_bits: int = 24) -> None:
        width, height = (int(s) for s in size)
        if width <= 0 or height <= 0:
            raise ValueError(f"framebuffer size must be positive, got {size}")
        limit = min(int(ctx.info["GL_MAX_RENDERBUFFER_SIZE"]),
                    *(int(v) for v in ctx.info["GL_MAX_VIEWPORT_DIMS"]))
        if width > limit or height > limit:
            raise ValueError(f"framebuffer {width}x{height} is larger than this driver allows: "
                             f"at most {limit} pixels a side")
        allowed = sample_counts(ctx)
        if int(samples) != samples or samples not in allowed:
            raise ValueError(f"{samples} MSAA samples asked; this driver allows "
                             f"{', '.join(str(n) for n in allowed)}")
        if depth_bits not in DEPTH_BITS:
            raise ValueError(f"depth_bits must be one of {DEPTH_BITS}, got {depth_bits}")
        self.ctx, self.size, self.samples = ctx, (width, height), int(samples)
        self.depth_bits = depth_bits
        color = ctx.renderbuffer(self.size, 4, samples=self.samples)
        self._float_depth = None
        if depth_bits == 24:
            depth = ctx.depth_renderbuffer(self.size, samples=self.samples)
            self.fbo = ctx.framebuffer(color_attachments=[color], depth_attachment=depth)
        else:
            self.fbo = self._float_depth_framebuffer(color)
        self._resolve = None
        if self.samples:
            self._resolve = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size, 4)])

    def _float_depth_framebuffer(self, color) -> moderngl.Framebuffer:
        GL = raw_gl()
        self._float_depth = GL.glGenRenderbuffers(1)
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, self._float_depth)
        GL.glRenderbufferStorageMultisample(GL.GL_RENDERBUFFER, self.samples,
                                            GL.GL_DEPTH_COMPONENT32F, *self.size)
        glo = GL.glGenFramebuffers(1)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, glo)
        GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0, GL.GL_RENDERBUFFER,
                                     color.glo)
        GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, GL.GL_RENDERBUFFER,
                                     self._float_depth)
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            raise ValueError("32-bit float depth framebuffer incomplete "
                             f"(status 0x{int(status):x})")
        self._color = color
        return self.ctx.detect_framebuffer(int(glo))

    def attachment_depth_bits(self) -> int:
        """The depth bits the driver reports for the depth attachment (GL query)."""
        GL = raw_gl()
        self.fbo.use()
        return int(GL.glGetFramebufferAttachmentParameteriv(
            GL.GL_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, GL.GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE))

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

    def clear(self, color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0),
              depth: float = 1.0) -> None:
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
        data = self.fbo.read(components=1, attachment=-1, dtype="f4")
        return np.frombuffer(data, np.float32).reshape(self.height, self.width)[::-1].copy()

    def release(self) -> None:
        if self.ctx.fbo in (self.fbo, self._resolve):
            # moderngl re-binds its last bound framebuffer after creating the next one; binding
            # a deleted one is GL_INVALID_OPERATION, so leave framebuffer 0 bound instead
            self.ctx.detect_framebuffer(0).use()
        if self._float_depth is not None:
            GL = raw_gl()
            GL.glDeleteRenderbuffers(1, [self._float_depth])
            self._float_depth = None
            self._color.release()
            self.fbo.release()  # the detected framebuffer has no attachment objects of its own
            self.fbo = None
        for fbo in (self.fbo, self._resolve):
            if fbo is not None:
                for attachment in (*fbo.color_attachments, fbo.depth_attachment):
                    if attachment is not None:
                        attachment.release()
                fbo.release()
