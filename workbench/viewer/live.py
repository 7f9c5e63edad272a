"""The drawing side of a live view: one mesh path prepared once on an EGL context of its own
(:func:`~workbench.paths.drawing.prepared`, held open while the path is shown), drawn on request
into an offscreen framebuffer by the one frame loop
(:func:`~workbench.animation.frames.draw_frames`) and read back as an RGB frame (no Jupyter
here).

What each interaction costs:

* **camera** (:meth:`LiveView.orbit_by`, :meth:`~LiveView.pan_by`, :meth:`~LiveView.zoom_by`,
  :meth:`~LiveView.reset_view`): a new :class:`~workbench.viewer.orbit.Orbit` and
  ``path.set_camera`` — uniforms only, nothing uploaded or derived again;
* **time step** (:meth:`LiveView.set_step`): ``path.set_step`` — the step's coordinates, normals
  and field values into the buffers allocated at prepare time; the flange path prepares again
  instead, since its distance field is derived per step;
* **style** (:meth:`LiveView.restyle`: bands, value range, flange threshold, exploded focus …):
  the path is made again from the changed options and prepared (what the scene derived stays
  cached on it: a new flange threshold reuses the part distances, a new focus the
  triangulation); on a refusal the previous path stays;
* **resize** (:meth:`LiveView.resize`): a new framebuffer and the camera's aspect.

The exploded path (ghost2013) animates: after each frame :meth:`LiveView.frame` advances the
explosion by the occlusion count of that frame (``ExplodedPath.step_animation``) and
``animating`` says whether the halves still move by a quarter pixel or more, so another frame
is wanted. :meth:`LiveView.pick` reads the part under a pixel through the path's own colour
picking (``ExplodedPath.pick``).

Every GL call runs with the view's context current (``with ctx``), and the context that was
current before is current again after, so several views and other contexts coexist in one
process.
"""

from __future__ import annotations

from contextlib import ExitStack
from typing import TYPE_CHECKING, Any

import numpy as np

from ..animation.decoration import state_stamp
from ..animation.frames import draw_frames
from ..gl import create_context
from ..paths.drawing import WHITE, Prepared, prepared
from ..paths.exploded import ExplodedPath, exploded_camera
from ..paths.flange import FlangePath
from ..paths.registry import make_path, scene_path
from .orbit import Orbit

if TYPE_CHECKING:
    from ..gl import Camera, Framebuffer
    from ..paths.base import RenderPath
    from ..scene.mesh import FEMesh

SETTLED_PX = 0.25  # an explosion moving less than this per frame (image pixels) has settled


def as_mesh(scene: Any) -> FEMesh:
    """``scene`` as an FE mesh: a mesh as it is, a spec string loaded by
    :func:`workbench.scene.builtin.load_scene` (a built-in name or a mesh file). ValueError for a
    scene of another kind (a spacetime scene, say)."""
    if isinstance(scene, str):
        from ..scene.builtin import load_scene

        spec, scene = scene, load_scene(scene)
    else:
        spec = getattr(scene, "name", type(scene).__name__)
    if getattr(scene, "kind", None) != "mesh":
        raise ValueError(f"the live view draws FE meshes; {spec!r} is a "
                         f"{getattr(scene, 'kind', type(scene).__name__)} scene")
    return scene


class LiveView:
    """``scene`` (an FE mesh or a spec string) drawn through mesh path ``path`` (default
    ``gouraud``, or with a ``field`` ``pixel_color`` for a node field and ``element_color`` for
    an element field) with the style options ``style``, in frames of ``size`` (W, H) pixels,
    on a new EGL context on device ``device`` (see :func:`workbench.gl.create_context`).
    ``units`` and ``time_units`` label the colour bar (:meth:`legend`) and the state's time
    (:meth:`stamp`).

    The first view is :meth:`Camera.fit_box` at ``angles`` (azimuth, elevation in degrees),
    ``projection`` and ``up`` axis. The exploded path without a ``focus`` focuses the lowest
    part id. Refused as the path and its style refuse (ValueError, KeyError for an unknown
    field), and as :func:`as_mesh` refuses a scene.
    """

    def __init__(self, scene: Any, path: str | None = None, *,
                 size: tuple[int, int] = (800, 600), device: int | str | None = None,
                 angles: tuple[float, float] = (30.0, 25.0), projection: str = "orthographic",
                 up: str = "z", units: str = "", time_units: str = "", **style: Any) -> None:
        self.scene = as_mesh(scene)
        self.units, self.time_units = units, time_units
        self.path_name = scene_path(self.scene, path, style.get("field"))
        self.options = dict(style)
        self.step = int(self.options.pop("step", 0))
        if self.path_name == "exploded" and self.options.get("focus") is None:
            self.options["focus"] = int(np.min(self.scene.parts))
        self.orbit = Orbit.fitted(*self.scene.bounds(all_steps=True), size, angles=angles,
                                  projection=projection, up=up)
        self.animating = self.path_name == "exploded"
        self.ctx = create_context(device=device)
        self._ready: Prepared | None = None
        self._held = ExitStack()  # keeps the prepared path (and its target) until it changes
        self._o_max: float | None = None
        try:
            with self.ctx:
                self._ready, self._held = self._prepared(self.options, self.step)
        except BaseException:
            self.release()
            raise

    @property
    def path(self) -> RenderPath | None:
        """The prepared path drawn now (None once released)."""
        return None if self._ready is None else self._ready.path

    @property
    def target(self) -> Framebuffer | None:
        """The offscreen framebuffer the frames are drawn into (None once released)."""
        return None if self._ready is None else self._ready.target

    # ------------------------------------------------------------------ preparing
    def _prepared(self, options: dict[str, Any], step: int) -> tuple[Prepared, ExitStack]:
        """A new path of ``path_name`` with ``options`` at ``step``, prepared for the current
        view and size (the context current) and held open by the returned stack (closing it
        releases the path and its target); ``_o_max`` follows it once it is prepared."""
        path = make_path(self.path_name, **options, step=step)
        o_max = None
        if isinstance(path, ExplodedPath):
            o_max = path.style.o_max
            o_max = float(o_max) if o_max is not None else _o_max_of(self.scene)
        with ExitStack() as stack:
            ready = stack.enter_context(prepared(self.ctx, self.scene, path,
                                                 camera=self._camera(o_max),
                                                 size=self.orbit.size))
            held = stack.pop_all()
        self._o_max = o_max
        return ready, held

    def restyle(self, **changes: Any) -> None:
        """Make the path again with its style options changed by ``changes`` (``bands=8``,
        ``value_range=(0, 2)``, ``threshold=1.5``, ``focus=3`` …) and prepare it; the step and
        the view stay. On a refusal (ValueError, KeyError) the previous path stays drawn."""
        options = {**self.options, **changes}
        step = int(options.pop("step", self.step))
        with self.ctx:
            ready, held = self._prepared(options, step)
            old, self._ready, self._held = self._held, ready, held
            old.close()
        self.options, self.step = options, step
        self.animating = isinstance(ready.path, ExplodedPath)

    # ------------------------------------------------------------------ the camera
    def camera(self) -> Camera:
        """The camera of the current view; an exploded path's with its depth range widened by
        twice the largest offset (:func:`~workbench.paths.exploded.exploded_camera`)."""
        return self._camera(self._o_max)

    def _camera(self, o_max: float | None) -> Camera:
        camera = self.orbit.camera()
        if o_max is not None:
            camera = exploded_camera(camera, self.scene, o_max)
        return camera

    def _set_orbit(self, orbit: Orbit) -> None:
        self.orbit = orbit
        with self.ctx:
            self.path.set_camera(self.camera())
        self.animating = isinstance(self.path, ExplodedPath)

    def orbit_by(self, dx: float, dy: float) -> None:
        """Orbit by a drag of ``dx``, ``dy`` frame pixels (:meth:`Orbit.dragged`)."""
        self._set_orbit(self.orbit.dragged(dx, dy))

    def pan_by(self, dx: float, dy: float) -> None:
        """Pan by a drag of ``dx``, ``dy`` frame pixels (:meth:`Orbit.panned`)."""
        self._set_orbit(self.orbit.panned(dx, dy))

    def zoom_by(self, wheel: float) -> None:
        """Zoom by a wheel turn of ``wheel`` units (:meth:`Orbit.wheeled`)."""
        self._set_orbit(self.orbit.wheeled(wheel))

    def reset_view(self) -> None:
        """Back to the fitted view."""
        self._set_orbit(self.orbit.reset())

    def resize(self, size: tuple[int, int]) -> None:
        """Frames of ``size`` (W, H) pixels from now on; ValueError for a size that is not
        positive."""
        orbit = self.orbit.resized(size)
        if orbit.size == self.orbit.size:
            return
        with self.ctx:
            self._ready.resize(orbit.size)
        self._set_orbit(orbit)

    @property
    def size(self) -> tuple[int, int]:
        """(W, H) of the frames, pixels."""
        return self.orbit.size

    # ------------------------------------------------------------------ steps and picking
    @property
    def n_steps(self) -> int:
        return self.scene.n_steps

    def set_step(self, step: int) -> None:
        """Draw time step ``step`` (ValueError outside the mesh's steps): ``path.set_step``,
        or for the flange path, whose distances are derived per step, a new preparation."""
        step = int(step)
        if not 0 <= step < self.n_steps:
            raise ValueError(f"{self.scene.name} has {self.n_steps} steps; step {step} is "
                             f"outside")
        if isinstance(self.path, FlangePath):
            self.restyle(step=step)
            return
        with self.ctx:
            self.path.set_step(step)
        self.step = step
        self.animating = isinstance(self.path, ExplodedPath)

    def pick(self, x: float, y: float) -> int | None:
        """The part id drawn at frame pixel (``x``, ``y``) (column, row from the top) by the
        exploded path's colour picking; None where no part is drawn, outside the frame, or for
        another path."""
        if not isinstance(self.path, ExplodedPath):
            return None
        column, row = int(np.floor(x)), int(np.floor(y))
        width, height = self.size
        if not (0 <= column < width and 0 <= row < height):
            return None
        with self.ctx:
            return self.path.pick(column, row, self.size)

    # ------------------------------------------------------------------ legends
    def stamp(self) -> str:
        """The current state as every still and frame states it: ``state K, t = T`` (the
        mesh's time of the state, in ``time_units``), then ``, deleted: N`` where elements
        are deleted in it (:func:`~workbench.animation.decoration.state_stamp`)."""
        times = self.scene.times
        time = None if times is None else float(times[self.step])
        return state_stamp(self.step, time, self.scene.n_deleted(self.step), self.time_units)

    def legend(self) -> np.ndarray | None:
        """(H, W, 3) uint8 the colour bar of the drawn field as tall as the frames (its scale,
        bands, ``field [units]`` and the no-result key of the current state, as ``workbench
        render`` draws it: :func:`~workbench.output.figures.colour_bar`); None for a path
        without a colour scale (or frames too low to hold a bar)."""
        from ..output.figures import NO_RESULT_KEY, colour_bar
        from ..paths.colormap import no_result_text

        path = self.path
        scale = getattr(path, "scale", None)
        if scale is None or self.size[1] < 2 * NO_RESULT_KEY:
            return None
        field, scene = path.style.field, self.scene
        known = field in scene.node_fields or field in scene.element_fields
        no_result = no_result_text(scene, field, self.step) if known else None
        return colour_bar(self.size[1], value_range=scale.value_range,
                          colormap=path.style.colormap, label=field or "value",
                          units=self.units, bands=path.style.bands, no_result=no_result)

    # ------------------------------------------------------------------ frames
    def frame(self) -> np.ndarray:
        """(H, W, 3) uint8 RGB of the current state on white, row 0 at the top. With the
        exploded path the explosion then advances one animation step (see ``animating``)."""
        with self.ctx:
            image = next(draw_frames(self._ready, (self.step,), background=WHITE)).image
            if isinstance(self.path, ExplodedPath):
                before = self.path.offset
                self.path.step_animation(size=self.size)
                moved = abs(self.path.offset - before)
                self.animating = moved >= SETTLED_PX * self.orbit.pixel_size()
        return np.ascontiguousarray(image[..., :3])

    def release(self) -> None:
        """Free the path, the framebuffer and the context; harmless when done already."""
        if self.ctx is None:
            return
        with self.ctx:
            self._held.close()
        self.ctx.release()
        self.ctx = self._ready = None


def _o_max_of(mesh: FEMesh) -> float:
    from ..algo.explode import o_max_of

    return float(o_max_of(mesh))
