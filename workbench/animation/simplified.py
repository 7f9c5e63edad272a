"""The simplified surface an animation draws (``workbench animate --simplify``): a mesh's
triangles decimated once, part by part, within a certified one-sided Hausdorff distance
(:func:`~workbench.algo.simplify.hausdorff_decimate`, crash2000 section 3.2), drawn at the
coordinates of every state, each frame stamped, in a row under it, with the bound certified at
its state.

The decimation never moves a vertex, so the simplified triangles index the mesh's own nodes and
take every state's coordinates and node fields as they are. It is made at the first state drawn
(``"first"``) or certified at every state drawn (``"all"``, the decimation's ``states``).
Either way the bound of each frame is measured again at its state
(:func:`~workbench.algo.simplify.states.bounds_over_states`, once, before any frame is drawn):
the largest ratio over the parts of the certified distance from the original triangles to the
simplified ones, both at that state, to the part's tolerance; above 1 the frame leaves the
tolerance.

Element fields, ids and erosion follow the element of the input triangle each simplified
triangle descends from (the decimation's ``source``): a simplified triangle is hidden where
that element is deleted. With erosion, the decimation is told which triangles are drawn at
each state it certifies (its ``alive``: triangles deleted at different states are decimated
apart), and each frame's bound is measured between the triangles drawn at its state.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..algo.simplify import Decimation, hausdorff_decimate
from ..algo.simplify.states import StateBounds, bounds_over_states
from ..output.figures import MARGIN, TITLE_HEIGHT, new_figure
from ..scene.mesh import FEMesh

if TYPE_CHECKING:
    from .decoration import Decoration
    from .frames import Frame

STATES = ("first", "all")
def grouped(n: int) -> str:
    """``n`` with its thousands apart: ``8 732``."""
    return f"{n:,}".replace(",", " ")


@dataclass(frozen=True)
class SimplifiedAnimation:
    """A mesh's simplified surface over the states drawn: ``mesh`` (the simplified triangles
    as the elements of an :class:`~workbench.scene.mesh.FEMesh` sharing the input's nodes,
    states, times and node fields; element fields where the decimation gives each triangle's
    source), ``decimation``, ``bounds`` (certified at each state drawn), ``percent`` (the
    tolerance, % of each part's bounding-sphere diameter), ``certified`` (``"first"`` or
    ``"all"``), ``input_triangles``, the wall seconds of the decimation and the bounds, and
    ``deleted``: per state drawn, the elements the input mesh deletes (erosion)."""

    mesh: FEMesh
    decimation: Decimation
    bounds: StateBounds
    percent: float
    certified: str
    input_triangles: int
    decimate_s: float
    bounds_s: float
    deleted: dict[int, int] = dataclasses.field(default_factory=dict)

    def worst(self, step: int) -> tuple[int, float]:
        """(part label, ratio) of the largest ratio of bound to tolerance at state ``step``;
        KeyError for a state not measured."""
        hit = np.flatnonzero(self.bounds.states == step)
        if not len(hit):
            raise KeyError(f"state {step} was not measured")
        ratio = self.bounds.ratio[hit[0]]
        p = int(np.argmax(ratio))
        return int(self.bounds.part_labels[p]), float(ratio[p])

    def stamp(self, step: int) -> str:
        """``simplified 0.5 %: 810 of 8 732 triangles; certified ≤ 0.99 × tolerance (part
        3)`` at state ``step``: the worst part's ratio rounded up to two decimals, so that the
        text stays a bound; ``: exceeds`` after it where the ratio is above 1."""
        part, ratio = self.worst(step)
        text = (f"simplified {self.percent:g} %: {grouped(len(self.decimation.triangles))} of "
                f"{grouped(self.input_triangles)} triangles; certified ≤ "
                f"{math.ceil(ratio * 100) / 100:.2f} × tolerance (part {part})")
        return text + (": exceeds" if ratio > 1.0 else "")

    def decorate(self, decoration: Decoration) -> Callable[[Frame], np.ndarray]:
        """``decoration``, then under each decorated frame a row as high as its title row
        holding the frame's :meth:`stamp` (dark red where the bound exceeds the tolerance)."""

        def decorated(frame: Frame) -> np.ndarray:
            # the elements the result deletes, not the simplified triangles they hide
            image = decoration(replace(frame, deleted=self.deleted.get(frame.step, 0)))
            row = stamp_row(image.shape[1], self.stamp(frame.step),
                            self.worst(frame.step)[1] > 1.0)
            return np.concatenate([image, row])

        return decorated

    def summary(self) -> str:
        """One line: the triangles kept, where the decimation was certified, what it cost and
        the worst state."""
        states = self.bounds.states
        where = (f"state {states[0]}" if self.certified == "first"
                 else f"the {len(states)} states drawn")
        state, part, ratio = self.bounds.worst()
        return (f"simplified {self.percent:g} %: {grouped(len(self.decimation.triangles))} of "
                f"{grouped(self.input_triangles)} triangles, certified at {where} "
                f"({self.decimate_s:.3g} s), bounds at {len(states)} state"
                f"{'s' * (len(states) != 1)} ({self.bounds_s:.3g} s); worst: state {state}, "
                f"part {part}, {ratio:.3f} × its tolerance"
                + (" (exceeds)" if ratio > 1.0 else ""))


def stamp_row(width: int, text: str, alarm: bool = False) -> np.ndarray:
    """(TITLE_HEIGHT, ``width``, 3) uint8: ``text`` centred on white, in the title's font
    made smaller (down to 6 points) where the text would pass the margins, dark red with
    ``alarm``."""
    fig = new_figure(width, TITLE_HEIGHT)
    line = fig.text(0.5, 0.5, text, ha="center", va="center",
                    color="darkred" if alarm else "black")
    fig.canvas.draw()
    wide = line.get_window_extent().width
    if wide > width - 2 * MARGIN:
        line.set_fontsize(max(6.0, line.get_fontsize() * (width - 2 * MARGIN) / wide))
        fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def check_simplify(mesh: FEMesh, steps: Sequence[int], percent: float, certified: str = "first",
                   field: str | None = None) -> None:
    """Refuse (ValueError, one line) what :func:`simplify_animation` cannot draw: a tolerance
    that is not a positive percentage, an unknown ``certified``, a mesh without states."""
    if not (math.isfinite(percent) and percent > 0):
        raise ValueError(f"--simplify {percent:g}: the tolerance must be a positive percentage")
    if certified not in STATES:
        raise ValueError(f"--states must be one of {', '.join(STATES)}, got {certified!r}")
    if mesh.steps is None:
        raise ValueError(f"--simplify draws a decimation over the states of a result; "
                         f"{mesh.name} has none (one geometry): use workbench simplify")


def simplify_animation(mesh: FEMesh, steps: Sequence[int], percent: float,
                       certified: str = "first", field: str | None = None,
                       progress: Callable[[str], None] | None = None) -> SimplifiedAnimation:
    """The :class:`SimplifiedAnimation` of ``mesh`` over the states ``steps`` (indices, the
    first one the state decimated) at a tolerance of ``percent`` % of each part's
    bounding-sphere diameter, certified at the first state or at ``"all"``; ``field`` the
    field drawn. ``progress`` is told what is being computed before each long step. Refused as
    :func:`check_simplify` refuses."""
    steps = [int(k) for k in steps]
    check_simplify(mesh, steps, percent, certified, field)
    say = progress or (lambda text: None)
    tri = mesh.triangulation
    parts = mesh.parts[tri.element_of]
    alive = mesh.triangles_alive()
    certify = steps[:1] if certified == "first" else steps
    further = {"states": mesh.steps[certify[1:]]} if len(certify) > 1 else {}
    if alive is not None:
        further["alive"] = alive[certify]
    say(f"decimating {grouped(len(tri.triangles))} triangles at {percent:g} % (state "
        f"{steps[0]}{' and the other states drawn' if len(certify) > 1 else ''})")
    start = time.perf_counter()
    decimation = hausdorff_decimate(mesh.steps[steps[0]], tri.triangles, percent / 100.0,
                                    relative=True, parts=parts, **further)
    decimate_s = time.perf_counter() - start
    say(f"certified bounds of {grouped(len(decimation.triangles))} triangles at {len(steps)} "
        f"state{'s' * (len(steps) != 1)}")
    start = time.perf_counter()
    bounds = bounds_over_states(mesh.steps, tri.triangles, parts, decimation, states=steps,
                                alive=alive)
    bounds_s = time.perf_counter() - start
    return SimplifiedAnimation(simplified_mesh(mesh, decimation, tri.element_of), decimation,
                               bounds, float(percent), certified, len(tri.triangles),
                               decimate_s, bounds_s, {k: mesh.n_deleted(k) for k in steps})


def simplified_mesh(mesh: FEMesh, decimation: Decimation,
                    element_of: np.ndarray) -> FEMesh:
    """The simplified triangles of ``decimation`` (made from ``mesh``'s triangulation, whose
    triangle ``i`` is of element ``element_of[i]``) as an FE mesh of triangles on ``mesh``'s
    nodes: its states, times, node fields, part names and units, the parts of the decimation
    and the element fields (erosion among them) and ids of the element each triangle's source
    triangle is of."""
    elements = np.asarray(element_of)[decimation.source]
    element_fields = {k: v[..., elements] for k, v in mesh.element_fields.items()}
    element_ids = None if mesh.element_ids is None else mesh.element_ids[elements]
    return FEMesh(nodes=mesh.nodes, elements=decimation.triangles, parts=decimation.parts,
                  steps=mesh.steps, node_fields=dict(mesh.node_fields),
                  element_fields=element_fields, part_names=dict(mesh.part_names),
                  times=mesh.times, node_ids=mesh.node_ids, element_ids=element_ids,
                  name=mesh.name, units=mesh.units, unavailable=dict(mesh.unavailable),
                  beams=mesh.beams, particles=mesh.particles)
