"""The one frame loop (:func:`draw_frames`), and the frames of a time-dependent FE mesh drawn
through one render path (:class:`FrameLoop`: a crash, crash2000, played over its states).

:func:`draw_frames` draws a prepared path (:class:`~workbench.paths.drawing.Prepared`) once per
state of a sequence: an optional update first (``set_step``, an explosion's own extra draw),
waited for and timed, then the target bound, cleared (outside the clock), the draw waited for
and timed, and the image read back (timed apart). Every sequence of frames in the package goes
through it: ``animate`` (:class:`FrameLoop`), ``explode``
(:func:`workbench.animation.exploded.explode_animation`), the ghost2013 experiment
(``fig_exploded``) and the live view (:class:`workbench.viewer.live.LiveView`, one frame per
request). What happens between frames (an explosion's ``step_animation``) is the caller's, done
when the loop hands it a frame.

:class:`FrameLoop` prepares the path once — topology, index buffer and colour texture uploaded
once — with one camera fitted to the box of every state
(``FEMesh.bounds(all_steps=True)``), then per state uploads only what changes with it
(:meth:`~workbench.paths.base.RenderPath.set_step`: coordinates, normals where the path has
them, time-dependent field values), draws and reads the image back. Each frame is the image
``workbench render MESH --step k --raw`` draws with the same path, style, size and view: the
same camera, the same preparation (:func:`~workbench.paths.drawing.prepared`), and the same
clear, draw and read-back as :func:`~workbench.paths.drawing.render`.

Colour scale: ``"fixed"`` keeps the path's own, by default the field's range over all states
(:func:`~workbench.paths.colormap.scale_for`), on every frame; ``"per-step"`` maps each state's
own range. The mesh paths fix their scale when they are prepared (the normalisation of the
values and the transfer function's texture follow from it) and have no call that changes it,
so ``"per-step"`` prepares the path again for every state, topology included: its frames are
those of ``render --step k -O value_range=(lo_k,hi_k)``, and its uploads per state are whole
preparations.

No file formats here: the frames are arrays; writing them is the caller's.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..paths.backends import as_backend
from ..paths.base import RenderPath
from ..paths.colormap import no_result_text
from ..paths.drawing import WHITE, Prepared, prepared
from ..paths.mesh import MeshPath
from ..paths.registry import make_path, path_class

if TYPE_CHECKING:
    import moderngl

    from ..gl import Camera
    from ..paths.backends import Backend
    from ..scene.mesh import FEMesh

SCALES = ("fixed", "per-step")
Background = tuple[float, float, float, float]

# mesh paths whose preparation depends on the state drawn, so that set_step alone does not
# draw another state as render --step draws it: the flange distances are measured in the
# state prepared, the exploded view splits the parts of that state
STATE_BOUND_PATHS = {"flange": "measures its part distances in the one state it is prepared for",
                     "exploded": "splits the parts of the one state it is prepared for"}


@dataclass(frozen=True)
class Drawn:
    """One frame of :func:`draw_frames`: ``state`` (the item of the sequence it drew),
    ``image`` ((H, W, 4) uint8 RGBA, row 0 at the top; None when not read), ``update_ms`` (wall
    ms of the update, waited for; 0 without one), ``sent`` (what the update returned where it
    is a byte count, say ``set_step``'s; else 0), ``draw_ms`` (wall ms of the draw, waited for,
    the clear before it excluded) and ``read_ms`` (wall ms of the read-back; 0 when not
    read)."""

    state: Any
    image: np.ndarray | None
    update_ms: float
    sent: int
    draw_ms: float
    read_ms: float


def draw_frames(ready: Prepared, states: Iterable[Any], *,
                update: Callable[[Any], object] | None = None,
                background: Background = WHITE, read: bool = True) -> Iterator[Drawn]:
    """The one frame loop: for each item of ``states`` (any iterable: step indices, frame
    numbers, a progress bar over them), ``update(state)`` where given (waited for and timed),
    then ``ready``'s target bound and cleared to ``background`` (RGBA in [0, 1]) and the
    clear waited for outside the clock, ``ready.path.draw()`` waited for and timed, and with
    ``read`` the image read back (timed apart); yields a :class:`Drawn` per state, lazily, so
    that the caller acts on the path between frames (an explosion's ``step_animation``).
    ``ready`` stays prepared; releasing it is its context manager's job."""
    backend = ready.backend
    for state in states:
        sent, update_ms = 0, 0.0
        if update is not None:
            start = time.perf_counter()
            returned = update(state)
            backend.finish()
            update_ms = (time.perf_counter() - start) * 1e3
            if isinstance(returned, (int, np.integer)) and not isinstance(returned, bool):
                sent = int(returned)
        ready.bind()
        ready.target.clear(background)
        backend.finish()
        start = time.perf_counter()
        ready.path.draw()
        backend.finish()
        draw_ms = (time.perf_counter() - start) * 1e3
        image, read_ms = None, 0.0
        if read:
            start = time.perf_counter()
            image = ready.target.read()
            read_ms = (time.perf_counter() - start) * 1e3
        yield Drawn(state, image, update_ms, sent, draw_ms, read_ms)


@dataclass(frozen=True)
class Frame:
    """One state drawn: ``step`` (the state's index), ``time`` (the mesh's time of that state,
    in the reader's time unit; None for a mesh without times), ``image`` ((H, W, 4) uint8
    RGBA, row 0 at the top), ``value_range`` (the colour scale's (lo, hi) in field units;
    None without a field), ``upload_ms`` (wall ms of the state's uploads, waited for:
    ``set_step``, or with a per-step scale the whole preparation), ``draw_ms`` (wall ms of the
    draw and the read-back, the clear before it excluded), ``bytes_uploaded`` (what those
    uploads sent), ``bytes_per_step`` (the prepared path's own count of one ``set_step``) and
    ``no_result`` (the legend text of the field's values without one in that state, say ``no
    result: 12 nodes``; None where every value is finite or without a field), ``deleted`` (the
    elements deleted in that state, not drawn or ghosted: erosion)."""

    step: int
    time: float | None
    image: np.ndarray
    value_range: tuple[float, float] | None
    upload_ms: float
    draw_ms: float
    bytes_uploaded: int
    bytes_per_step: int
    no_result: str | None = None
    deleted: int = 0


def state_value_range(mesh: FEMesh, field: str, step: int) -> tuple[float, float]:
    """(lo, hi) of ``field`` in state ``step``, finite values of the elements in use only
    (:meth:`~workbench.scene.mesh.FEMesh.field_range`), as
    :func:`~workbench.paths.colormap.scale_for` makes a range over all states: a constant
    field gets ``(v, v + 1)``, a state without a finite value ``(0, 1)``."""
    lo, hi = mesh.field_range(field, step)
    return lo, hi if hi > lo else lo + 1.0


def check_steps(mesh: FEMesh, steps: Sequence[int]) -> list[int]:
    """``steps`` as a list of state indices; ValueError (naming the mesh's number of states)
    for an empty selection or a state outside ``0 … n_steps − 1``."""
    n = mesh.n_steps
    states = f"{mesh.name} has {n} state{'s' * (n != 1)} (0..{n - 1})"
    if not len(steps):
        raise ValueError(f"no state selected; {states}")
    for k in steps:
        if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)):
            raise ValueError(f"a state is an integer index, got {k!r}")
        if not 0 <= k < n:
            raise ValueError(f"state {k} is out of range: {states}")
    return [int(k) for k in steps]


def check_animated_path(name: str) -> None:
    """Refuse (ValueError) a path a frame loop cannot draw state after state by ``set_step``:
    one that draws no FE mesh the mesh way (the fe2003 texture paths draw a surface built for
    state 0) or one of :data:`STATE_BOUND_PATHS`."""
    cls = path_class(name)
    if not isinstance(cls, type) or not issubclass(cls, MeshPath):
        raise ValueError(f"path {name!r} cannot be animated: it draws a surface built for one "
                         f"state; animate a mesh path (gouraud, pixel_color, element_color, ...)")
    if name in STATE_BOUND_PATHS:
        raise ValueError(f"path {name!r} cannot be animated: it {STATE_BOUND_PATHS[name]}")


class FrameLoop:
    """The frames of ``mesh`` in ``steps`` drawn through path ``path`` (a registry name) with
    ``style`` (its style class; default the path's) into a ``size`` (W, H) target with
    ``samples`` MSAA samples on ``backend`` (a GL context or a backend of
    :mod:`workbench.paths.backends`), seen from azimuth and elevation ``view`` (degrees) with
    ``up`` upwards in ``projection``; ``scale`` "fixed" or "per-step" (module notes).

    Everything that can be refused is refused on construction (ValueError, KeyError for an
    unknown field): a path :func:`check_animated_path` refuses, an empty selection or a state
    out of range (:func:`check_steps`), an unknown scale, ``"per-step"`` without a field or
    with a ``value_range`` of the style's own, and what the path's ``check_mesh`` refuses of
    the mesh and style (a field the mesh lacks, a field of the other kind). :attr:`field` is
    the field the path colours by (None for a path without a colour scale, whatever the
    style's ``field``), :attr:`colour_scale` its fixed scale. The camera (:attr:`camera`) is
    :meth:`~workbench.paths.base.RenderPath.fit_camera` over the box of every state, the one
    ``render`` fits. Iterating draws the frames (:class:`Frame`) one by one; the path and the
    target are released when the iteration ends or is closed. :attr:`prepare_ms` and
    :attr:`prepare_bytes` then hold what the preparations cost (ms waited for, bytes): one
    preparation with a fixed scale, one per state with a per-step one.
    """

    def __init__(self, backend: moderngl.Context | Backend, mesh: FEMesh, path: str,
                 style: object | None = None, *, steps: Sequence[int],
                 size: tuple[int, int] = (800, 600), view: tuple[float, float] = (30.0, 25.0),
                 up: str = "z", projection: str = "orthographic", scale: str = "fixed",
                 samples: int = 0) -> None:
        if getattr(mesh, "kind", None) != "mesh":
            raise ValueError(f"a frame loop draws an FE mesh, got {type(mesh).__name__}")
        check_animated_path(path)
        if scale not in SCALES:
            raise ValueError(f"scale must be one of {SCALES}, got {scale!r}")
        self.backend, self.mesh, self.name = as_backend(backend), mesh, path
        self.steps = check_steps(mesh, steps)
        self.size = tuple(int(v) for v in size)
        self.scale, self.samples = scale, samples
        style = style if style is not None else path_class(path).style_class()
        # the first state selected is the one prepared, as render --step prepares it
        self.style = replace(style, step=self.steps[0])
        self.colour_scale = make_path(path, self.style).check_mesh(mesh)
        self.field = None if self.colour_scale is None else self.style.field
        if scale == "per-step":
            if self.field is None:
                raise ValueError(f"a per-step colour scale needs a field; path {path!r} "
                                 f"colours by none")
            if self.style.value_range is not None:
                raise ValueError(f"value_range {self.style.value_range} fixes the colour "
                                 f"scale; a per-step scale takes each state's own range")
        self.camera: Camera = RenderPath.fit_camera(*mesh.bounds(all_steps=True), self.size,
                                                    view=view, projection=projection, up=up)
        self.prepare_ms = 0.0
        self.prepare_bytes = 0

    def no_result(self, step: int) -> str | None:
        """The legend text of the field's non-finite values in state ``step``
        and the parts without any (:func:`~workbench.paths.colormap.no_result_text`); None where
        there are none."""
        if self.field is None:
            return None
        return no_result_text(self.mesh, self.field, step)

    def deleted(self, step: int) -> int:
        """The number of elements deleted in state ``step`` (0 for a mesh without erosion)."""
        return self.mesh.n_deleted(step)

    def time_of(self, step: int) -> float | None:
        """The mesh's time of state ``step`` (None for a mesh without times)."""
        times = self.mesh.times
        return None if times is None else float(times[step])

    def __iter__(self) -> Iterator[Frame]:
        if self.scale == "fixed":
            yield from self._fixed()
        else:
            yield from self._per_step()

    def _fixed(self) -> Iterator[Frame]:
        """Prepared once; per state ``set_step``, draw, read back (:func:`draw_frames`)."""
        value_range = None if self.colour_scale is None else self.colour_scale.value_range
        with prepared(self.backend, self.mesh, self.name, self.style, self.camera, self.size,
                      samples=self.samples) as ready:
            self.prepare_ms, self.prepare_bytes = ready.prepare_ms, ready.path.bytes_uploaded
            for drawn in draw_frames(ready, self.steps, update=ready.path.set_step):
                k = drawn.state
                yield Frame(k, self.time_of(k), drawn.image, value_range, drawn.update_ms,
                            drawn.draw_ms + drawn.read_ms, drawn.sent,
                            ready.path.bytes_per_step, self.no_result(k), self.deleted(k))

    def _per_step(self) -> Iterator[Frame]:
        """Prepared again for every state, with that state's value range; each preparation
        draws its one frame through :func:`draw_frames`."""
        self.prepare_ms, self.prepare_bytes = 0.0, 0
        for k in self.steps:
            value_range = state_value_range(self.mesh, self.field, k)
            style = replace(self.style, step=k, value_range=value_range)
            with prepared(self.backend, self.mesh, self.name, style, self.camera, self.size,
                          samples=self.samples) as ready:
                sent = ready.path.bytes_uploaded
                self.prepare_ms += ready.prepare_ms
                self.prepare_bytes += sent
                for drawn in draw_frames(ready, (k,)):
                    yield Frame(k, self.time_of(k), drawn.image, value_range, ready.prepare_ms,
                                drawn.draw_ms + drawn.read_ms, sent, ready.path.bytes_per_step,
                                self.no_result(k), self.deleted(k))
