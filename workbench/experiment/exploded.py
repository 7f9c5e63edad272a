"""The ghost2013 exploded-view animation of one part, drawn offscreen frame by frame
(:func:`explode_animation`).

Each frame is drawn, counting the focus part's visible pixels as it is drawn; the occlusion
ratio r then advances the offset of the two halves
(:meth:`~workbench.paths.exploded.ExplodedPath.step_animation`). Each frame carries a thin
progress bar along its bottom edge (its length is the frame's position in the animation), so
frames whose scene no longer changes stay distinct frames of a GIF.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import moderngl

    from ..gl import Camera
    from ..paths.exploded import ExplodedPath
    from ..scene.mesh import FEMesh

BAR_PX = 3  # height of the frame progress bar


@dataclass
class ExplodeAnimation:
    """What an animation drew: ``frames`` (uint8 images with their progress bar), how much of
    the focus is visible at the end (``revealed`` = p_occ / p_unocc, 0 to 1), and the final
    ``offset`` of the halves and its cap ``o_max`` (model units)."""

    frames: list[np.ndarray]
    revealed: float
    offset: float
    o_max: float


def explode_animation(ctx: moderngl.Context, scene: FEMesh, path: ExplodedPath, camera: Camera,
                      size: tuple[int, int], count: int, *,
                      steps: Iterable[int] | None = None,
                      on_frame: Callable[[int, float, float, ExplodedPath], object] | None = None,
                      ) -> ExplodeAnimation:
    """``count`` frames of the exploded path ``path`` (unprepared) animating ``scene`` on the
    GL context ``ctx``, seen by ``camera``, ``size`` (W, H) pixels each.

    ``steps`` iterates the frame numbers (default ``range(count)``; a progress bar over it,
    say); ``on_frame(i, offset, r, path)`` is called after frame ``i`` with the offset it was
    drawn at and the occlusion ratio ``r`` that advanced the animation. The path and the
    framebuffer are released on the way out, also when a frame raises.
    """
    from ..gl import Framebuffer
    from .figures import with_progress_bar

    fb = Framebuffer(ctx, size)
    frames = []
    try:
        with path:
            path.prepare(ctx, scene, camera)
            for i in range(count) if steps is None else steps:
                fb.use()
                fb.clear()
                path.draw()
                frames.append(with_progress_bar(fb.read(), i + 1, count, BAR_PX))
                offset = path.offset
                r = path.step_animation()
                if on_frame is not None:
                    on_frame(i, offset, r, path)
            fb.use()
            p_unocc, p_occ, _ = path.measure_occlusion()
            offset, o_max = path.offset, path.settings.o_max
    finally:
        fb.release()
    revealed = p_occ / p_unocc if p_unocc else 0.0
    return ExplodeAnimation(frames, revealed, offset, o_max)
