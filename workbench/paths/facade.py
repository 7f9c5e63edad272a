"""The Python entry points the package root hands out: ``workbench.load`` and
``workbench.render`` (:func:`load`, :func:`render`).

``render`` takes a scene or its name, a path name and style options, and returns the image;
it draws through :func:`workbench.paths.drawing.render` (untimed) on one headless GL context
made on first use and reused, or on the software rasterizer. For a time, measure instead
(``workbench.measure``: :func:`workbench.measurement.rows.measure`), which draws the same
image for the same arguments.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .drawing import render as render_prepared
from .registry import make_path, scene_path

if TYPE_CHECKING:
    import moderngl

    from ..gl import Camera
    from ..scene.protocol import Scene
    from .backends import Backend

_CONTEXT: list[moderngl.Context] = []  # the one headless context render makes and reuses
SCENE_KINDS = ("mesh", "spacetime", "surface")


def load(path_or_name: str | os.PathLike[str], *, quick: bool = False) -> Scene:
    """The scene ``path_or_name`` names: a mesh file (an LS-DYNA keyword deck ``.k``/``.key``/
    ``.dyn``, a d3plot, or a file meshio or trimesh reads; coordinates in the file's units),
    else a built-in scene name (``car``, ``crash[:S]``, ``d3plot``, ``semicylinders[:N]`` —
    the es2008 benchmark —, ``panels[:Q]``, ``spacetime:radial[:N]``, ``spacetime:bar``),
    ``quick`` its quick size. An existing file wins over a built-in name.

    ValueError, one, for anything else: a name that is neither an existing file nor a built-in
    scene (naming both), a size that is not a positive integer, a file that cannot be read
    (the reader's :class:`~workbench.scene.readers.errors.ParseError`, a ValueError).
    FileNotFoundError only where a built-in scene's shared data is absent."""
    from ..scene.builtin import load_scene, scene_names

    if not isinstance(path_or_name, (str, os.PathLike)):
        raise ValueError(f"load takes a mesh file path or a built-in scene name, got "
                         f"{type(path_or_name).__name__}")
    spec = os.fspath(path_or_name)
    try:
        return load_scene(spec, quick=quick)
    except KeyError as exc:  # an unknown name of a built-in family (spacetime:x)
        raise ValueError(exc.args[0]) from None
    except FileNotFoundError:
        if Path(spec).exists():
            raise
        raise ValueError(f"{spec!r} is neither an existing mesh file nor a built-in scene; "
                         f"expected a mesh file (a keyword deck, a d3plot, a meshio or trimesh "
                         f"file) or one of {', '.join(scene_names())}") from None


def render(scene: Scene | str | os.PathLike[str], path: str = "gouraud", *,
           size: tuple[int, int] = (640, 480), camera: Camera | None = None, step: int = 0,
           backend: str | moderngl.Context | Backend = "gl", **style: Any) -> np.ndarray:
    """The image of ``scene`` (a loaded scene, or a file or name :func:`load` reads) drawn
    through render path ``path`` (a registry name) with the style options ``style``
    (``field``, ``bands``, ``value_range``, ``wireframe`` … as the path's style takes them)
    at time step ``step`` (FE meshes; 0 the first state), seen by ``camera`` (default the
    path family's camera showing all of the scene), ``size`` (W, H) pixels, on white.

    ``backend``: ``"gl"`` (one headless EGL context, made on first use and reused),
    ``"software"`` (the es2008 software rasterizer, mesh paths only), a moderngl context or a
    backend of :mod:`workbench.paths.backends`. Returns (H, W, 4) uint8 RGBA, row 0 at the
    top: the image ``workbench.measure`` reads for the same arguments. Untimed.

    Refused with ValueError: a scene that is none, an unknown path or one that does not draw
    scenes of this kind, a style option the path does not take, a step outside the mesh's
    states, a size that is not two positive integers, an unknown backend; KeyError for a
    field the mesh lacks."""
    if isinstance(scene, (str, os.PathLike)):
        scene = load(scene)
    if getattr(scene, "kind", None) not in SCENE_KINDS:
        raise ValueError(f"render takes a scene (an FE mesh, a spacetime scene, a textured "
                         f"surface) or a file or built-in name, got {type(scene).__name__}")
    width, height = _size(size)
    name = scene_path(scene, path)
    if scene.kind == "mesh":
        if isinstance(step, bool) or not isinstance(step, (int, np.integer)) \
                or not 0 <= step < scene.n_steps:
            raise ValueError(f"step must be a state of {scene.name} (0..{scene.n_steps - 1}), "
                             f"got {step!r}")
        style = {**style, "step": int(step)}
    elif step != 0:
        raise ValueError(f"a {scene.kind} scene has no time steps; step must be 0, got {step!r}")
    made = make_path(name, **style)
    return render_prepared(_backend(backend), scene, made, camera=camera, size=(width, height))


def _size(size: Any) -> tuple[int, int]:
    """``size`` as (W, H) positive integers; ValueError otherwise."""
    try:
        width, height = size
        ok = all(int(v) == v and v > 0 for v in (width, height))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"size is (width, height) in pixels, two positive integers; got "
                         f"{size!r}")
    return int(width), int(height)


def _backend(backend: Any) -> moderngl.Context | Backend:
    """The backend ``render`` draws on (see :func:`render`); ValueError for an unknown one."""
    if backend == "gl":
        if not _CONTEXT:
            from ..gl import create_context

            _CONTEXT.append(create_context())
        return _CONTEXT[0]
    if backend == "software":
        from .backends import SoftwareRasterizer

        return SoftwareRasterizer()
    from .backends import as_backend

    try:
        return as_backend(backend)
    except TypeError:
        raise ValueError(f"backend is 'gl', 'software', a moderngl context or a backend; got "
                         f"{backend!r}") from None
