"""The headless OpenGL context every render path and measurement shares."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType

import moderngl

EGL_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri"


class GLUnavailable(RuntimeError):
    """No headless OpenGL 3.3+ context could be created through EGL."""


def create_context(require: int = 330) -> moderngl.Context:
    """A standalone moderngl context on EGL (no display needed), OpenGL ``require`` or newer.

    Refuses with :class:`GLUnavailable` naming the Debian packages to install when EGL or a
    Mesa/GPU driver is missing.
    """
    try:
        ctx = moderngl.create_standalone_context(require=require, backend="egl")
    except Exception as exc:  # moderngl raises plain Exception for a missing libEGL or driver
        raise GLUnavailable(
            f"no headless OpenGL {require // 100}.{require % 100 // 10} context through EGL "
            f"({exc}); on Debian/Ubuntu install: apt-get install {EGL_PACKAGES}"
        ) from exc
    return ctx


def renderer(ctx: moderngl.Context) -> str:
    """The renderer string recorded in every measurement row (e.g.
    'llvmpipe (LLVM 15.0.6, 256 bits)')."""
    return str(ctx.info["GL_RENDERER"])


def gl_version(ctx: moderngl.Context) -> str:
    return str(ctx.info["GL_VERSION"])


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
