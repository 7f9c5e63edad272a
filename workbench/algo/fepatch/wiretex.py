"""The signed-distance wire-frame texture of fe2003 §4.2.

Every element outlines itself. Around and inside each element, texels hold signed perpendicular
distances in texels (positive inside) to the lines of the element's edges, two channels per
element: the first the nearer of edges 0 and 2, the second the nearer of edges 1 and 3. The
outline is the zero isoline of either channel, restricted to where the other channel is not
negative, under bilinear interpolation. Opposite edges share a channel, which is exact as long as
an element holds some texels between them.

Elements are two-coloured across shared edges (a checkerboard on a quad grid): colour 0 writes
the channel pair ``WIRE_PAIRS[0]`` = (G, B), colour 1 writes ``WIRE_PAIRS[1]`` = (R, A), so that
the ring of texels an element writes outside itself, needed by the bilinear lookup across its
edges, lands in the other pair inside its neighbours. Where the mesh is not two-colourable (odd
cycles, triangle fans), two neighbours of the same colour write the same pair; each side of their
shared edge keeps its own element's positive distance, so the edge has no zero crossing and shows
at best partly (where the sampled distances dip below the line's half width):
:func:`checkerboard` reports those edges for drawing as lines.

Where elements of one pair meet (diagonal neighbours on a grid), a texel inside one of them keeps
that element's values and a texel outside all of them the smallest value per channel among those
that reach it: a channel is then positive only inside the strip of an element's own edges, and
the diagonal neighbours' fields never make a zero crossing between them. This needs elements
about three texels wide (:data:`MIN_WIDTH`, an element's smaller height,
:func:`element_widths`); narrower, the rings of opposite edges overlap and outlines break up:
at two and a half texels the outline still decodes at the texel centres, but a magnified view
shows interior lines doubled and broken between the nodes.

A triangle (a, b, c, c) has edges ab and ca in the first channel and bc alone in the second; the
two lines in the first channel meet at a, where the bilinear lookup rounds the corner slightly.

:func:`checkerboard` colours the elements; :func:`wire_texture` writes the texture from the
elements' corners in texel units; :func:`decode_wire` and :func:`on_outline` read it back exactly
as the fragment shader does.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from workbench.algo.fepatch.surface import WIRE_PAIRS

__all__ = ["MIN_WIDTH", "RING", "WIRE_RANGE", "checkerboard", "decode_wire", "element_widths",
           "on_outline", "wire_texture"]

RING = 1.5  # texels written outside an element: a bilinear lookup across its edges needs > 1
WIRE_RANGE = 2.0  # texels of byte 0 / 255
_DEGENERATE = 1e-9  # texels: an edge shorter than this is a repeated corner
# texels: elements at least this wide (some corner this far from each edge's line) keep their
# whole outline, magnified too; at 2.5 the texel centres still decode it but a magnified view
# breaks interior lines, at 2 a sheared element's acute corners lose parts of it. Narrower
# elements are drawn as lines where the texture scale leaves them so.
MIN_WIDTH = 3.0


def _edge_table(elements: np.ndarray):
    """(lo, hi, owner) of every non-degenerate edge of the valid elements, and the validity mask
    (at least 3 distinct nodes)."""
    m = len(elements)
    s = np.sort(elements, axis=1)
    valid = 1 + (s[:, 1:] != s[:, :-1]).sum(axis=1) >= 3
    u, v = elements.ravel(), elements[:, [1, 2, 3, 0]].ravel()
    owner = np.repeat(np.arange(m), 4)
    keep = (u != v) & valid[owner]
    u, v, owner = u[keep], v[keep], owner[keep]
    return np.minimum(u, v), np.maximum(u, v), owner, valid


def checkerboard(elements) -> tuple[np.ndarray, np.ndarray]:
    """Two-colour elements across shared edges: (colour (M,) int8 in {0, 1}, line_edges (E, 2)
    int64).

    ``elements`` (M, 4) node indices; a triangle repeats its third node (``e[3] == e[2]``), and
    edges whose two nodes coincide are not edges. An edge is shared when two or more elements use
    it. Colours are the parity of the breadth-first depth over the edge-adjacency graph, each
    connected component starting with colour 0, so a two-colourable mesh gets a proper
    colouring. ``line_edges`` are the shared edges (node pairs, smaller node first, sorted, each
    once) with two users of the same colour: the texture cannot show them. Elements with fewer
    than 3 distinct nodes get colour 0 and take no part in the adjacency. Refuses arrays that are
    not (M, 4) or hold negative indices.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components, shortest_path

    e = np.asarray(elements)
    if e.ndim != 2 or e.shape[1] != 4 or not np.issubdtype(e.dtype, np.integer):
        raise ValueError(f"elements must be (M, 4) integer node indices, got {e.shape} {e.dtype}")
    e = e.astype(np.int64)
    m = len(e)
    if m == 0:
        return np.zeros(0, np.int8), np.zeros((0, 2), np.int64)
    if e.min() < 0:
        raise ValueError("elements hold negative node indices")
    lo, hi, owner, _ = _edge_table(e)
    order = np.lexsort((owner, hi, lo))
    lo, hi, owner = lo[order], hi[order], owner[order]
    same_next = (lo[1:] == lo[:-1]) & (hi[1:] == hi[:-1])
    # consecutive users of one edge are adjacent (a chain covers edges with more than two users)
    a, b = owner[:-1][same_next], owner[1:][same_next]
    a, b = a[a != b], b[a != b]
    adj = coo_matrix((np.ones(len(a)), (a, b)), shape=(m, m)).tocsr()
    _, label = connected_components(adj, directed=False)
    _, first = np.unique(label, return_index=True)
    # one search from a virtual root linked to one element of every component
    root = m
    rows = np.r_[a, b, np.full(len(first), root)]
    cols = np.r_[b, a, first]
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(m + 1, m + 1)).tocsr()
    depth = shortest_path(graph, method="D", directed=True, unweighted=True, indices=root)
    colour = ((depth[:m].astype(np.int64) - 1) % 2).astype(np.int8)

    # edges whose users include two of the same colour
    start = np.flatnonzero(np.r_[True, ~same_next])
    c = colour[owner].astype(np.int64)
    ones = np.add.reduceat(c, start)
    count = np.diff(np.r_[start, len(owner)])
    clash = (ones >= 2) | (count - ones >= 2)
    line_edges = np.c_[lo[start[clash]], hi[start[clash]]]
    return colour, line_edges.astype(np.int64).reshape(-1, 2)


def _check_corners(corners_uv) -> np.ndarray:
    c = np.asarray(corners_uv, np.float64)
    if c.ndim != 3 or c.shape[1:] != (4, 2):
        raise ValueError(f"corners_uv must be (M, 4, 2) texel coordinates, got {c.shape}")
    if not np.isfinite(c).all():
        raise ValueError("corners_uv must be finite")
    return c


def _check_size(size) -> tuple[int, int]:
    try:
        w, h = (int(s) for s in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (W, H), got {size!r}") from None
    if w <= 0 or h <= 0 or (w, h) != tuple(size):
        raise ValueError(f"size must be two positive integers (W, H), got {size!r}")
    return w, h


def _edge_lines(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lines (M, 4, 3), valid (M,)): per element the lines (nx, ny, off) whose signed distance
    ``nx·x + ny·y + off`` (texels, positive inside) lines 0 and 2 give the first channel and
    lines 1 and 3 the second. A quad's line k is its edge k; a triangle (one repeated corner,
    vertices a, b, c in order with the repeated corner last) gets ab, bc, ca, bc. Elements with
    two or more repeated corners or no area are not valid."""
    m = len(c)
    edge = np.roll(c, -1, axis=1) - c
    zero = np.linalg.norm(edge, axis=2) <= _DEGENERATE
    nzero = zero.sum(axis=1)
    # a triangle: repeated corner k+1 == k; vertices a, b, c = corners k+2, k+3, k
    k = np.argmax(zero, axis=1)
    tri = np.stack([c[np.arange(m), (k + 2) % 4], c[np.arange(m), (k + 3) % 4],
                    c[np.arange(m), k]], axis=1)
    is_tri = nzero == 1
    start = np.where(is_tri[:, None, None], tri[:, [0, 1, 2, 1]], c)
    end = np.where(is_tri[:, None, None], tri[:, [1, 2, 0, 2]], np.roll(c, -1, axis=1))
    area2 = np.sum(c[:, :, 0] * np.roll(c[:, :, 1], -1, axis=1)
                   - np.roll(c[:, :, 0], -1, axis=1) * c[:, :, 1], axis=1)
    d = end - start
    length = np.linalg.norm(d, axis=2)
    valid = (nzero <= 1) & (np.abs(area2) > _DEGENERATE) & (length > _DEGENERATE).all(axis=1)
    sign = np.where(area2 > 0, 1.0, -1.0)[:, None]
    safe = np.where(length > _DEGENERATE, length, 1.0)
    # counter-clockwise (positive area in these axes): the inside is to the left of each edge
    nx = -d[:, :, 1] / safe * sign
    ny = d[:, :, 0] / safe * sign
    off = -(nx * start[:, :, 0] + ny * start[:, :, 1])
    return np.stack([nx, ny, off], axis=2), valid


def element_widths(corners_uv) -> np.ndarray:
    """(M,) float64 width of each element in texels: the smallest, over its edges, of the
    largest distance of its corners from the edge's line (a parallelogram's smaller height, a
    triangle's smallest height). ``corners_uv`` (M, 4, 2) in texel units; a triangle repeats a
    corner, whose zero-length edge is no edge. Elements with fewer than two edges get 0.
    Refuses bad shapes and non-finite corners."""
    c = _check_corners(corners_uv)
    d = np.roll(c, -1, axis=1) - c
    length = np.linalg.norm(d, axis=2)
    edge = length > _DEGENERATE
    n = np.stack([-d[..., 1], d[..., 0]], axis=-1) / np.where(edge, length, 1.0)[..., None]
    # distance of corner i from the line of edge k: |n_k · (c_i − c_k)|
    dist = np.abs(np.einsum("mkj,mij->mki", n, c) - np.einsum("mkj,mkj->mk", n, c)[..., None])
    height = np.where(edge, dist.max(axis=2), np.inf).min(axis=1)
    return np.where(edge.sum(axis=1) >= 2, height, 0.0)


@njit(cache=True)
def _raster_wire(lines, pair, valid, box, ring, best, val, outside):  # pragma: no cover
    for m in range(lines.shape[0]):
        if not valid[m]:
            continue
        p = pair[m]
        ln = lines[m]
        for i in range(box[m, 2], box[m, 3]):
            y = i + 0.5
            for j in range(box[m, 0], box[m, 1]):
                x = j + 0.5
                d0 = ln[0, 0] * x + ln[0, 1] * y + ln[0, 2]
                d1 = ln[1, 0] * x + ln[1, 1] * y + ln[1, 2]
                d2 = ln[2, 0] * x + ln[2, 1] * y + ln[2, 2]
                d3 = ln[3, 0] * x + ln[3, 1] * y + ln[3, 2]
                c1 = min(d0, d2)
                c2 = min(d1, d3)
                inner = min(c1, c2)
                if inner >= 0.0:
                    if inner > best[i, j, p]:
                        best[i, j, p] = inner
                        val[i, j, p, 0] = c1
                        val[i, j, p, 1] = c2
                elif inner >= -ring:
                    outside[i, j, p, 0] = min(outside[i, j, p, 0], c1)
                    outside[i, j, p, 1] = min(outside[i, j, p, 1], c2)


def wire_texture(corners_uv, colour, size, wire_range: float = WIRE_RANGE,
                 ring: float = RING) -> np.ndarray:
    """The (H, W, 4) uint8 wire-frame texture of elements with corners ``corners_uv`` (M, 4, 2)
    in texel units (texel (row i, column j) has its centre at (j + ½, i + ½)) and checkerboard
    ``colour`` (M,) in {0, 1}; ``size`` = (W, H).

    Each element writes its two channels (see the module docstring) into the pair
    ``WIRE_PAIRS[colour]`` at every texel whose centre lies inside it or at most ``ring`` texels
    outside (the smaller channel ≥ −ring) and within its bounding box grown by ``ring``. Where
    elements of one pair meet, a texel inside one of them keeps both channels of the element it
    lies deepest inside (largest smaller channel); a texel outside all of them keeps, per
    channel, the smallest value among the elements that reach it, so that no channel turns
    positive outside every element and two elements meeting at a node draw no spurious
    diagonals between them. Distances are clamped to ±``wire_range`` texels and stored as
    ``round(127.5 + 127.5·d/wire_range)``; texels no element writes hold −wire_range (byte 0),
    so a ring fades into "outside" without a zero crossing. Elements with fewer than three
    distinct corners or no area write nothing. Refuses bad shapes, non-finite corners, colours
    other than 0/1, a non-positive size or wire_range and a negative ring.
    """
    c = _check_corners(corners_uv)
    m = len(c)
    col = np.asarray(colour)
    if col.shape != (m,):
        raise ValueError(f"colour must be ({m},), got {col.shape}")
    if m and not np.isin(col, (0, 1)).all():
        raise ValueError("colour must hold 0 or 1 only")
    w, h = _check_size(size)
    if not (np.isfinite(wire_range) and wire_range > 0):
        raise ValueError(f"wire_range must be positive, got {wire_range}")
    if not (np.isfinite(ring) and ring >= 0):
        raise ValueError(f"ring must be non-negative, got {ring}")

    lines, valid = _edge_lines(c)
    lo = c.min(axis=1) - ring - 0.5
    hi = c.max(axis=1) + ring - 0.5
    # texel index range [first, last + 1) whose centres lie in the grown box, clipped to the atlas
    first = np.clip(np.ceil(lo), 0, [w, h]).astype(np.int64)
    last = np.clip(np.floor(hi) + 1, 0, [w, h]).astype(np.int64)
    box = np.stack([first[:, 0], last[:, 0], first[:, 1], last[:, 1]], axis=1)
    # float32 is ample for values quantised to 1/127.5 of wire_range
    best = np.full((h, w, 2), -np.inf, np.float32)
    val = np.full((h, w, 2, 2), -float(wire_range), np.float32)
    outside = np.full((h, w, 2, 2), np.inf, np.float32)
    _raster_wire(lines, col.astype(np.int64), valid, box, float(ring), best, val, outside)
    use = ~(best >= 0.0) & np.isfinite(outside[..., 0])
    val[use] = outside[use]

    byte = np.clip(np.floor(127.5 + 127.5 * val / wire_range + 0.5), 0, 255).astype(np.uint8)
    tex = np.empty((h, w, 4), np.uint8)
    for p, (ch0, ch1) in enumerate(WIRE_PAIRS):
        tex[..., ch0] = byte[:, :, p, 0]
        tex[..., ch1] = byte[:, :, p, 1]
    return tex


def decode_wire(texture, points, wire_range: float = WIRE_RANGE) -> np.ndarray:
    """(P, 2, 2) float64 distances in texels, [point, pair, channel], bilinearly interpolated
    from ``texture`` (H, W, 4) uint8 at ``points`` (P, 2) in texel units, as a GL sampler does
    (texel centres at half-integers, clamped to the edge). Pair p is ``WIRE_PAIRS[p]``. Refuses
    bad shapes and non-finite points."""
    tex = np.asarray(texture)
    if tex.ndim != 3 or tex.shape[2] != 4 or tex.dtype != np.uint8:
        raise ValueError(f"texture must be (H, W, 4) uint8, got {tex.shape} {tex.dtype}")
    pts = np.asarray(points, np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must be (P, 2), got {pts.shape}")
    if not np.isfinite(pts).all():
        raise ValueError("points must be finite")
    h, w = tex.shape[:2]
    x = np.clip(pts[:, 0] - 0.5, 0.0, w - 1)
    y = np.clip(pts[:, 1] - 0.5, 0.0, h - 1)
    x0 = np.minimum(np.floor(x).astype(np.int64), w - 1)
    y0 = np.minimum(np.floor(y).astype(np.int64), h - 1)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    order = [WIRE_PAIRS[0][0], WIRE_PAIRS[0][1], WIRE_PAIRS[1][0], WIRE_PAIRS[1][1]]
    t = tex[..., order].astype(np.float64)
    v = ((1 - fx) * (1 - fy) * t[y0, x0] + fx * (1 - fy) * t[y0, x1]
         + (1 - fx) * fy * t[y1, x0] + fx * fy * t[y1, x1])
    return ((v - 127.5) / 127.5 * wire_range).reshape(-1, 2, 2)


def on_outline(texture, points, h: float, wire_range: float = WIRE_RANGE) -> np.ndarray:
    """(P,) bool: whether ``points`` (P, 2) in texel units lie on an outline, the fragment
    shader's test: in either pair one channel is within ``h`` texels of zero (``|d| ≤ h``, a tie
    on a pixel boundary draws both pixels rather than neither) while the other is at least −h. ``h``
    is half the line width in texels (> 0)."""
    if not h > 0:
        raise ValueError(f"h must be positive, got {h}")
    d = decode_wire(texture, points, wire_range)
    a, b = d[:, :, 0], d[:, :, 1]
    hit = ((np.abs(a) <= h) & (b >= -h)) | ((np.abs(b) <= h) & (a >= -h))
    return hit.any(axis=1)
