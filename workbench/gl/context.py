"""The headless OpenGL context every render path and measurement shares."""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from types import ModuleType

import moderngl

from .devices import EGLDevice, current_device, device_index, egl_devices

EGL_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri"


class GLUnavailable(RuntimeError):
    """No headless OpenGL 3.3+ context could be created through EGL."""


def create_context(require: int = 330, device: int | str | None = None) -> moderngl.Context:
    """A standalone moderngl context on EGL (no display needed), OpenGL ``require`` or newer,
    on EGL device ``device`` (default ``WORKBENCH_EGL_DEVICE``, else 0; see
    :func:`~workbench.gl.devices.device_index`).

    Refuses with ValueError a device index that is not one of this machine's (or that
    contradicts glcontext's own ``GLCONTEXT_DEVICE_INDEX``), and with :class:`GLUnavailable`
    naming the Debian packages to install when EGL or a Mesa/GPU driver is missing.
    """
    index = device_index(device)
    forced = os.environ.get("GLCONTEXT_DEVICE_INDEX")
    if forced is not None and forced.strip() != str(index):
        raise ValueError(f"GLCONTEXT_DEVICE_INDEX={forced} overrides the EGL device {index} "
                         f"asked for; unset it and use --device or WORKBENCH_EGL_DEVICE")
    try:
        ctx = moderngl.create_standalone_context(require=require, backend="egl",
                                                 device_index=index)
    except Exception as exc:  # moderngl raises plain Exception for a missing libEGL or driver
        raise GLUnavailable(
            f"no headless OpenGL {require // 100}.{require % 100 // 10} context through EGL "
            f"on device {index} ({exc}); on Debian/Ubuntu install: apt-get install "
            f"{EGL_PACKAGES}"
        ) from exc
    return ctx


def probed_devices() -> list[EGLDevice]:
    """:func:`~workbench.gl.devices.egl_devices` with each device's GL ``renderer`` and
    ``vendor`` read from a context made on it and released (the caller's current context is
    current again afterwards); a device on which no context can be made keeps None."""
    return [_probed(device) for device in egl_devices()]


def _probed(device: EGLDevice) -> EGLDevice:
    try:
        with keeping_current() as restore:
            ctx = moderngl.create_standalone_context(backend="egl", device_index=device.index)
            restore.display = egl().eglGetCurrentDisplay()
            try:
                return replace(device, renderer=str(ctx.info["GL_RENDERER"]),
                               vendor=str(ctx.info["GL_VENDOR"]))
            finally:
                ctx.release()
    except Exception:  # moderngl raises plain Exception where a device gives no context
        return device


def renderer(ctx: moderngl.Context) -> str:
    """The renderer string recorded in every measurement row (e.g.
    'llvmpipe (LLVM 15.0.6, 256 bits)')."""
    return str(ctx.info["GL_RENDERER"])


def gl_version(ctx: moderngl.Context) -> str:
    return str(ctx.info["GL_VERSION"])


# renderers that rasterize on the CPU: their GL_TIME_ELAPSED queries do not time the draw
# (llvmpipe answers ~3e-05 ms for whole frames), so no GPU time is recorded on them
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "swiftshader", "software rasterizer",
                      "lavapipe")


def is_software_renderer(name: str) -> bool:
    """Whether the renderer string ``name`` is a CPU rasterizer (Mesa llvmpipe, softpipe,
    swrast; SwiftShader; Microsoft's software rasterizer)."""
    name = name.lower()
    return any(kind in name for kind in SOFTWARE_RENDERERS)


def timer_queries_meaningful(ctx: moderngl.Context) -> bool:
    """Whether ``ctx``'s GL_TIME_ELAPSED queries time the draws: on a GPU, not on a software
    renderer."""
    return not is_software_renderer(renderer(ctx))


def describe(ctx: moderngl.Context) -> dict[str, str | None]:
    """What identifies the renderer of ``ctx``: ``renderer``, ``gl_vendor``, ``gl_version``,
    ``driver`` (Mesa's version, e.g. "Mesa 22.3.6", else the text after the GL version
    number) and ``egl_device`` (the identity of the current context's EGL device,
    :attr:`~workbench.gl.devices.EGLDevice.identity`: index and UUID, render node or DRM file,
    or "software"; None where EGL cannot say)."""
    version = gl_version(ctx)
    mesa = re.search(r"Mesa \S+", version)
    driver = mesa.group(0) if mesa else (version.split(" ", 1)[1] if " " in version else None)
    return {"renderer": renderer(ctx), "gl_vendor": str(ctx.info["GL_VENDOR"]),
            "gl_version": version, "driver": driver, "egl_device": _current_identity()}


def _current_identity() -> str | None:
    device = current_device()
    return device.identity if device is not None else None


def raw_gl() -> ModuleType:
    """PyOpenGL's ``GL`` module bound through EGL, for the few calls moderngl does not wrap.

    Calls act on whatever context is current (a moderngl standalone context is current after
    :func:`create_context`). Refuses a PYOPENGL_PLATFORM other than "egl".
    """
    platform = os.environ.get("PYOPENGL_PLATFORM")
    if platform not in (None, "egl"):
        raise GLUnavailable(f"PYOPENGL_PLATFORM is {platform!r}; the workbench needs 'egl'")
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    from OpenGL import GL

    return GL


def egl() -> ModuleType:
    """PyOpenGL's ``EGL`` module (PyOpenGL bound through EGL as in :func:`raw_gl`)."""
    raw_gl()
    from OpenGL import EGL

    return EGL


class _Restore:
    """Where to leave no context current if none was current on entry (settable)."""

    display = None


@contextmanager
def keeping_current(own_display=None) -> Iterator[_Restore]:
    """Make the EGL context that is current on entry current again on exit.

    moderngl draws in whichever context is current, so code that makes another context current
    (pyrender's, or a context made and released for one run) must hand the caller's back. If
    none was current on entry, make none current on ``own_display`` (settable on the yielded
    object) so that a released context does not stay current. RuntimeError when the previous
    context cannot be made current again.
    """
    EGL = egl()
    display = EGL.eglGetCurrentDisplay()
    draw = EGL.eglGetCurrentSurface(EGL.EGL_DRAW)
    read = EGL.eglGetCurrentSurface(EGL.EGL_READ)
    context = EGL.eglGetCurrentContext()
    restore = _Restore()
    restore.display = own_display
    try:
        yield restore
    finally:
        if context:
            if not EGL.eglMakeCurrent(display, draw, read, context):
                raise RuntimeError("could not make the previous EGL context current again")
        elif restore.display is not None:
            EGL.eglMakeCurrent(restore.display, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE,
                               EGL.EGL_NO_CONTEXT)
