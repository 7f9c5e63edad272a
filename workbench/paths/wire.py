"""The single-pass quad wire frame: Gouraud shading and element outlines in one fill pass.

``quad_wire`` draws the bandified quad strips (:mod:`workbench.algo.strips`) with a per-vertex
wire coordinate (u, v, w). Along a strip, vertex j gets u = ⌊j/2⌋ mod 2 and v = j mod 2, so
inside quad k the coordinate u runs 0 → 1 (or 1 → 0) from the edge shared with quad k − 1 to the
edge shared with quad k + 1, and v runs 0 → 1 across the strip: every quad edge lies on an integer
u or v, the diagonal on neither. A triangle element gets the corners (0, 0, 1), (0, 1, 0),
(1, 0, 0), one component zero on each edge; quads keep w = ½. The fragment shader paints
``Style.wire_color`` where a component is close to an edge's value, measured in pixels along the
minor axis of that iso-line (the component's change per pixel is ``max(|∂/∂x|, |∂/∂y|)``), like an
aliased one-pixel ``GL_LINES`` line: one pixel per step along the line's major axis, no second
pass of lines and no diagonals. An edge two elements share is drawn within ½ pixel on each side;
an edge of one element only (the model's boundary, a hole; flagged per triangle through its
provoking vertex) within 1 pixel on that element's side, so it is not lost where the line
overdraw would put half its pixels outside the surface. An edge lying exactly on a pixel
boundary is drawn on both sides (two pixels wide) rather than lost.

The coordinate is per strip, so the strips' vertices are uploaded once per strip they belong to
(the strip vertex count, about 0.55·4n instead of the n nodes) and drawn as
``GL_TRIANGLE_STRIP`` with primitive restart.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..algo.strips import RESTART, join_strips, quad_strips, unstripify
from .drawdata import Layout, Topology
from .mesh import MeshPath

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..scene.mesh import FEMesh

# boundary bits of the flat per-triangle mask: which iso-lines of the wire coordinate are
# element edges no other element shares
U0, U1, V0, V1, W0 = 1, 2, 4, 8, 16
TRIANGLE = 32  # u = 1 and v = 1 are corners of a triangle, not edges


def single_use_edges(elements: ArrayLike, pairs: ArrayLike) -> np.ndarray:
    """(P,) bool: whether each node pair of ``pairs`` (P, 2) is an edge of exactly one
    non-degenerate element of ``elements`` ((M, 4) node indices, triangles repeating c)."""
    from ..scene.derived import classify_elements

    e = np.asarray(elements, np.int64)
    quad, tri, _ = classify_elements(e)
    used = (quad | tri)[np.repeat(np.arange(len(e)), 4)]
    u, v = e.ravel(), e[:, [1, 2, 3, 0]].ravel()
    keep = used & (u != v)
    keys = np.sort((np.minimum(u, v) << 32 | np.maximum(u, v))[keep])
    p = np.asarray(pairs, np.int64).reshape(-1, 2)
    query = np.minimum(p[:, 0], p[:, 1]) << 32 | np.maximum(p[:, 0], p[:, 1])
    count = np.searchsorted(keys, query, "right") - np.searchsorted(keys, query, "left")
    return count == 1


@dataclass(eq=False)
class StripTopology(Topology):
    """A :class:`Topology` whose vertices are the strips' own: ``draw_index`` the strip index
    array (with restart markers) over them and ``n_strips`` the strips drawn."""

    draw_index: np.ndarray | None = None
    n_strips: int = 0


class QuadWirePath(MeshPath):
    """Gouraud shading with the element outlines drawn in the same pass from quad strips."""

    name = "quad_wire"
    needs = frozenset({"gouraud"})
    vertex_shader, fragment_shader = "quad_wire.vert.glsl", "quad_wire.frag.glsl"
    split = True

    def topology(self, mesh: FEMesh) -> StripTopology:
        """The crease-split vertices once per strip they belong to, with the wire coordinate
        and the boundary bits as static attributes; ValueError for a second wire frame or for
        anything but quad strips."""
        style = self.style
        if style.wireframe:
            raise ValueError("quad_wire draws its wire frame in the fill pass: wireframe=True "
                             "would add a second, line-overdraw wire frame")
        if style.strips == "triangle" or style.quad_diagonal == "shorter":
            raise ValueError("quad_wire always draws quad strips: use strips='none' or 'quad' "
                             "and quad_diagonal 'auto' or 'strip'")
        split = mesh.gouraud(style.crease_deg)
        quads = quad_strips(split.elements, style.strip_cutoff)
        source, lengths = quads.draw_sequences()
        source = source.astype(np.int64)
        # position of each draw vertex within its strip
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
        j = np.arange(len(source)) - np.repeat(starts, lengths)
        wire = np.empty((len(source), 3), np.float32)
        wire[:, 0] = (j // 2) % 2
        wire[:, 1] = j % 2
        wire[:, 2] = 0.5
        n_tris = len(quads.triangles)  # the last sequences, three vertices each
        if n_tris:
            wire[-3 * n_tris:] = np.tile(np.array([[0, 0, 1], [0, 1, 0], [1, 0, 0]], np.float32),
                                         (n_tris, 1))
        boundary = self._boundary_masks(mesh, quads, len(source))
        draw_index = join_strips(np.arange(len(source), dtype=np.uint32), lengths, RESTART)
        return StripTopology(np.asarray(split.vertex_node, np.int64)[source],
                             unstripify(draw_index), split=split, split_rows=source,
                             attributes=[(wire, "3f", "wire"), (boundary, "1f", "boundary")],
                             draw_index=draw_index, n_strips=len(lengths))

    @staticmethod
    def _boundary_masks(mesh, quads, n_draw: int) -> np.ndarray:
        """(n_draw,) float32 boundary bits of each triangle, on its provoking (last) vertex.

        Quad k of a strip is drawn by strip triangles 2k and 2k + 1, whose last vertices are
        v2k+2 and v2k+3; a triangle element's strip has one triangle, last vertex 2.
        """
        nodes = mesh.elements
        mask = np.zeros(n_draw, np.float32)
        # strip quads and leftover quads (one-quad strips entered through edge 0)
        q = np.concatenate([quads.quads, quads.leftover]).astype(np.int64)
        entry = np.concatenate([quads.entry_edges, np.zeros(len(quads.leftover), np.int8)])
        strip_of = np.repeat(np.arange(quads.n_strips), quads.strip_lengths)
        k = np.arange(len(quads.quads)) - quads.quad_starts[strip_of]
        last = np.concatenate([quads.vertex_starts[strip_of] + 2 * k + 2,
                               len(quads.vertices) + 4 * np.arange(len(quads.leftover)) + 2])
        parity = np.concatenate([k % 2, np.zeros(len(quads.leftover), np.int64)])
        bits = np.zeros(len(q), np.int64)
        for offset, even_bit, odd_bit in ((0, U0, U1), (1, V1, V1), (2, U1, U0), (3, V0, V0)):
            local = (entry.astype(np.int64) + offset) % 4
            pair = np.stack([nodes[q, local], nodes[q, (local + 1) % 4]], axis=1)
            alone = single_use_edges(nodes, pair)
            bits |= np.where(alone, np.where(parity == 0, even_bit, odd_bit), 0)
        mask[last] = bits
        mask[last + 1] = bits
        if len(quads.triangles):
            from ..scene.derived import triangulate

            tri = triangulate(nodes[quads.triangles], mesh.nodes).triangles.astype(np.int64)
            bits = np.full(len(tri), TRIANGLE, np.int64)
            for a, b, bit in ((0, 1, U0), (1, 2, W0), (2, 0, V0)):
                bits |= np.where(single_use_edges(nodes, tri[:, [a, b]]), bit, 0)
            first = len(quads.vertices) + 4 * len(quads.leftover)
            mask[first + 3 * np.arange(len(tri)) + 2] = bits
        return mask

    # this path's layout is only ever given its own topology (draw_data passes it on)
    def layout(self, mesh: FEMesh,  # type: ignore[override]
               topology: StripTopology) -> Layout:
        """The strips over the strip vertices, each sent once."""
        return Layout(topology.draw_index, "triangle_strip", len(topology.triangles),
                      topology.n_strips, len(topology.vertex_node))

    def _build(self, ctx, mesh, camera) -> None:
        super()._build(ctx, mesh, camera)
        self._program["wire_color"].value = self.style.wire_color
