"""The ghost2013 exploded-view animation of one part, drawn offscreen frame by frame
(:func:`explode_animation`).

Each frame is drawn, counting the focus part's visible pixels as it is drawn; the occlusion
ratio r then advances the offset of the two halves
(:meth:`~workbench.paths.exploded.ExplodedPath.step_animation`). The counts and r of every
frame are kept, so the first frame that reveals the focus (r at or below the path's
``revealed_below``) is known, not only the state at the end. Each frame carries a thin
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
    """What an animation drew: ``frames`` (uint8 images with their progress bar); per frame the
    ``offsets`` it was drawn at (model units) and the focus's pixel counts in it, ``p_unocc``
    (drawn alone) and ``p_occ`` (visible with both halves), and its occlusion ratio ``ratios``
    (r, 1 hidden, 0 fully visible); the ``threshold`` r at or below which the focus counts as
    revealed (the path's ``revealed_below``); the ``offset`` the animation ends at (after the
    last frame's step) and its cap ``o_max`` (model units)."""

    frames: list[np.ndarray]
    offsets: list[float]
    p_unocc: list[int]
    p_occ: list[int]
    ratios: list[float]
    threshold: float
    offset: float
    o_max: float

    @property
    def revealed_frame(self) -> int | None:
        """The first frame (1-based) whose r is at or below ``threshold``, None when no frame
        revealed the focus."""
        return next((i + 1 for i, r in enumerate(self.ratios) if r <= self.threshold), None)

    @property
    def revealed(self) -> float:
        """The share of the focus's pixels visible in the last frame, p_occ / p_unocc (0 to 1,
        a few more pixels with the halves than alone counted as 1; 0 without frames)."""
        return min(1.0, self.p_occ[-1] / self.p_unocc[-1]) if self.p_occ else 0.0


def explode_animation(ctx: moderngl.Context, scene: FEMesh, path: ExplodedPath, camera: Camera,
                      size: tuple[int, int], count: int, *,
                      steps: Iterable[int] | None = None,
                      on_frame: Callable[[int, float, float, ExplodedPath], object] | None = None,
                      ) -> ExplodeAnimation:
    """``count`` frames of the exploded path ``path`` (unprepared) animating ``scene`` on the
    GL context ``ctx``, seen by ``camera``, ``size`` (W, H) pixels each.

    ``steps`` iterates the frame numbers (default ``range(count)``; a progress bar over it,
    say); ``on_frame(i, offset, r, path)`` is called after frame ``i`` with the offset it was
    drawn at and the occlusion ratio ``r`` that advanced the animation (the frame's pixel
    counts are in ``path.last_occlusion``). The frames are drawn by the one frame loop
    (:func:`~workbench.animation.frames.draw_frames`) through the path prepared by
    :func:`~workbench.paths.drawing.prepared`. A focus part with no pixels in this view (smaller
    than a pixel, seen edge-on) has nothing to reveal and is refused with ValueError after the
    first frame. The path and the framebuffer are released on the way out, also when a frame
    raises.
    """
    from ..output.figures import with_progress_bar
    from ..paths.drawing import prepared
    from .frames import draw_frames

    frames, offsets, p_unocc, p_occ, ratios = [], [], [], [], []
    with prepared(ctx, scene, path, camera=camera, size=size) as ready:
        for drawn in draw_frames(ready, range(count) if steps is None else steps):
            i = drawn.state
            frames.append(with_progress_bar(drawn.image, i + 1, count, BAR_PX))
            offset = path.offset
            r = path.step_animation()
            counts = path.last_occlusion
            if counts["p_unocc"] == 0:
                raise ValueError(f"focus part {path.style.focus} has no pixels in this "
                                 f"{size[0]}x{size[1]} view (smaller than a pixel or seen "
                                 f"edge-on): there is nothing to reveal")
            offsets.append(offset)
            p_unocc.append(int(counts["p_unocc"]))
            p_occ.append(int(counts["p_occ"]))
            ratios.append(float(r))
            if on_frame is not None:
                on_frame(i, offset, r, path)
        offset, o_max = path.offset, path.settings.o_max
        threshold = path.settings.revealed_below
    return ExplodeAnimation(frames, offsets, p_unocc, p_occ, ratios, threshold, offset, o_max)
