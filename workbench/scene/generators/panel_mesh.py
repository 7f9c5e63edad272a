"""The mesh of one stamped sheet-metal part from its plan (:mod:`.panel_plan`).

The part is a structured grid over the flat blank (top face plus flanges) with the corners cut
away, corner relief where two flanges meet, holes cut out of the top face and a share of the
quads split into triangles; the grid is then formed in 3-D (dome, beads, flanges bent down) and
the sheet thinned where it was stretched. Lengths are millimetres.
"""

from __future__ import annotations

import numpy as np

from .common import _smoothstep
from .panel_plan import _PanelPlan, _segment_distance


def _cell_elements(ii: np.ndarray, jj: np.ndarray, missing: np.ndarray, stride: int) -> np.ndarray:
    """(len(ii), 4) elements of grid cells (i, j), node (i, j) = j * stride + i; a cell with
    ``missing`` corner c (0..3 counter-clockwise from (i, j)) becomes the triangle of the other
    three."""
    base = jj.astype(np.int64) * stride + ii
    quads = np.stack([base, base + 1, base + stride + 1, base + stride], axis=1)
    tri = missing >= 0
    if tri.any():
        k = missing[tri]
        rows = quads[tri]
        r = np.arange(len(rows))
        a, b, c = rows[r, (k + 1) % 4], rows[r, (k + 2) % 4], rows[r, (k + 3) % 4]
        quads[tri] = np.stack([a, b, c, c], axis=1)
    return quads


def _element_edges(elements: np.ndarray) -> np.ndarray:
    """(K, 2) sorted node pairs of every element edge (a triangle's three, a quad's four)."""
    nxt = np.roll(elements, -1, axis=1)
    tri = elements[:, 3] == elements[:, 2]
    nxt[tri, 2] = elements[tri, 0]
    valid = np.ones(elements.shape, bool)
    valid[tri, 3] = False
    a, b = elements[valid], nxt[valid]
    return np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1)


def _pinched_nodes(elements: np.ndarray) -> np.ndarray:
    """Nodes on more than two boundary edges (where two boundary loops touch)."""
    if not len(elements):
        return np.zeros(0, np.int64)
    edges = _element_edges(elements)
    big = np.int64(edges.max() + 1)
    keys, counts = np.unique(edges[:, 0] * big + edges[:, 1], return_counts=True)
    once = keys[counts == 1]
    nodes, degree = np.unique(np.concatenate([once // big, once % big]), return_counts=True)
    return nodes[degree > 2]


def _grid_axis(n_minus: int, n_top: int, n_plus: int, size: float, d_minus: float,
               d_plus: float) -> tuple[np.ndarray, np.ndarray]:
    """Node coordinates along one grid axis: the top-face coordinate (clamped to 0 .. ``size``
    on the flanges) and the flange depth, for ``n_minus`` flange cells, ``n_top`` top-face cells
    and ``n_plus`` flange cells of depths ``d_minus`` and ``d_plus``."""
    idx = np.arange(n_minus + n_top + n_plus + 1, dtype=np.float64)
    top = np.clip((idx - n_minus) / n_top, 0.0, 1.0) * size
    depth = np.zeros_like(idx)
    if n_minus:
        depth = np.where(idx < n_minus, (n_minus - idx) * d_minus / n_minus, depth)
    if n_plus:
        depth = np.where(idx > n_minus + n_top, (idx - n_minus - n_top) * d_plus / n_plus, depth)
    return top, depth


def _flange_cells(plan: _PanelPlan, nf: dict[str, int], ntx: int,
                  nty: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(keep (ny, nx) bool, cell columns inside an x flange (nx,), cell rows inside a y flange
    (ny,)): the blank's cells without the corners where two flanges overlap and without the
    corner relief."""
    L, W = plan.length, plan.width
    nx = nf["x-"] + ntx + nf["x+"]
    ny = nf["y-"] + nty + nf["y+"]
    ci = np.arange(nx)
    cj = np.arange(ny)
    in_xf = (ci < nf["x-"]) | (ci >= nf["x-"] + ntx)        # cell columns inside an x flange
    in_yf = (cj < nf["y-"]) | (cj >= nf["y-"] + nty)
    keep = ~(in_xf[None, :] & in_yf[:, None])                  # (ny, nx): corners cut away
    # corner relief: a flange stops short of a corner where the perpendicular flange starts
    rel_x = max(1, int(np.ceil(plan.relief / (W / nty))))
    rel_y = max(1, int(np.ceil(plan.relief / (L / ntx))))
    cut_j = np.zeros(ny, bool)
    if nf["y-"]:
        cut_j |= (cj >= nf["y-"]) & (cj < nf["y-"] + rel_x)
    if nf["y+"]:
        cut_j |= (cj < nf["y-"] + nty) & (cj >= nf["y-"] + nty - rel_x)
    cut_i = np.zeros(nx, bool)
    if nf["x-"]:
        cut_i |= (ci >= nf["x-"]) & (ci < nf["x-"] + rel_y)
    if nf["x+"]:
        cut_i |= (ci < nf["x-"] + ntx) & (ci >= nf["x-"] + ntx - rel_y)
    keep &= ~(in_xf[None, :] & cut_j[:, None])
    keep &= ~(in_yf[:, None] & cut_i[None, :])
    return keep, in_xf, in_yf


def _cut_holes(plan: _PanelPlan, keep: np.ndarray, xs, ys, sx, sy, in_xf,
               in_yf) -> tuple[np.ndarray, np.ndarray]:
    """(keep, missing): the holes in the top face. Cells whose centre is inside a hole are
    removed from ``keep`` (changed in place); a kept cell with exactly one corner inside becomes
    the triangle of its other three corners (chamfers the staircase): ``missing`` (ny, nx) is
    that corner (0..3, see :func:`_cell_elements`) or -1."""
    xc = 0.5 * (xs[:-1] + xs[1:])
    yc = 0.5 * (ys[:-1] + ys[1:])
    top_cell = ~in_xf[None, :] & ~in_yf[:, None]
    top_node = (sx == 0)[None, :] & (sy == 0)[:, None]
    node_in = np.zeros((len(ys), len(xs)), bool)
    for cx, cy, r in plan.holes:
        keep &= ~(top_cell & ((xc[None, :] - cx) ** 2 + (yc[:, None] - cy) ** 2 < r * r))
        node_in |= top_node & ((xs[None, :] - cx) ** 2 + (ys[:, None] - cy) ** 2 < r * r)
    corner_in = np.stack([node_in[:-1, :-1], node_in[:-1, 1:], node_in[1:, 1:], node_in[1:, :-1]],
                         axis=-1)
    missing = np.where(corner_in.sum(axis=-1) == 1, np.argmax(corner_in, axis=-1), -1)  # (ny, nx)
    return keep, missing


def _unpinch_holes(plan: _PanelPlan, keep: np.ndarray, missing: np.ndarray, xs,
                   ys) -> np.ndarray:
    """``keep`` (changed in place) without pinches around the holes: a tight hole can leave two
    cells touching at one node only (a pinched boundary); the cell nearer the hole's centre is
    removed until no node around any hole is pinched."""
    ny, nx = keep.shape
    stride = nx + 1
    xc = 0.5 * (xs[:-1] + xs[1:])
    yc = 0.5 * (ys[:-1] + ys[1:])
    for cx, cy, r in plan.holes:
        i0, i1 = np.searchsorted(xc, [cx - r, cx + r])
        j0, j1 = np.searchsorted(yc, [cy - r, cy + r])
        i0, i1, j0, j1 = max(i0 - 3, 0), min(i1 + 3, nx), max(j0 - 3, 0), min(j1 + 3, ny)
        for _ in range(50):
            wj, wi = np.nonzero(keep[j0:j1, i0:i1])
            wj, wi = wj + j0, wi + i0
            pinched = _pinched_nodes(_cell_elements(wi, wj, missing[wj, wi], stride))
            pi, pj = pinched % stride, pinched // stride
            inner = (pi > i0) & (pi < i1) & (pj > j0) & (pj < j1)
            if not inner.any():
                break
            for i, j in zip(pi[inner], pj[inner]):
                around = [(jc, ic) for jc in (j - 1, j) for ic in (i - 1, i) if keep[jc, ic]]
                jc, ic = min(around, key=lambda c: (xc[c[1]] - cx) ** 2 + (yc[c[0]] - cy) ** 2)
                keep[jc, ic] = False
    return keep


def _split_quads(quads: np.ndarray, share: float, seed: int) -> np.ndarray:
    """``quads`` with randomly chosen quads split into two triangles (each child in place of its
    parent, winding kept), up to the wanted triangle ``share``; the choice is drawn from
    ``seed``."""
    is_tri = quads[:, 3] == quads[:, 2]
    n_tri, n_quad = int(is_tri.sum()), int((~is_tri).sum())
    n_split = int(round(max(0.0, (share * (n_quad + n_tri) - n_tri) / (2.0 - share))))
    n_split = min(n_split, n_quad)
    if n_split:
        rng = np.random.default_rng([seed, 0x5917])
        chosen = rng.choice(np.flatnonzero(~is_tri), size=n_split, replace=False)
        split = np.zeros(len(quads), bool)
        split[chosen] = True
        diag = rng.integers(2, size=n_split).astype(bool)
        q = quads[split]
        # diagonal 0-2: (0,1,2)+(0,2,3); diagonal 1-3: (0,1,3)+(1,2,3); both keep the winding
        first = np.where(diag[:, None], q[:, [0, 1, 3, 3]], q[:, [0, 1, 2, 2]])
        second = np.where(diag[:, None], q[:, [1, 2, 3, 3]], q[:, [0, 2, 3, 3]])
        out = np.repeat(quads, np.where(split, 2, 1), axis=0)
        # index in `out` of each split's first child
        pos = np.flatnonzero(split) + np.arange(n_split)
        out[pos] = first
        out[pos + 1] = second
        quads = out
    return quads


def _panel_topology(plan: _PanelPlan, nf: dict[str, int], ntx: int, nty: int):
    """Elements of one part in full-grid node numbering (node (i, j) -> j * (nx + 1) + i).

    Returns (elements (M, 4) int64, node top-face x (nx+1,), node y (ny+1,), flange depth along
    x per node column, along y per node row).
    """
    L, W = plan.length, plan.width
    f = plan.flanges
    xs, sx = _grid_axis(nf["x-"], ntx, nf["x+"], L, f.get("x-", 0.0), f.get("x+", 0.0))
    ys, sy = _grid_axis(nf["y-"], nty, nf["y+"], W, f.get("y-", 0.0), f.get("y+", 0.0))
    keep, in_xf, in_yf = _flange_cells(plan, nf, ntx, nty)
    keep, missing = _cut_holes(plan, keep, xs, ys, sx, sy, in_xf, in_yf)
    keep = _unpinch_holes(plan, keep, missing, xs, ys)
    jj, ii = np.nonzero(keep)
    quads = _cell_elements(ii, jj, missing[jj, ii], len(xs))
    return _split_quads(quads, plan.triangle_share, plan.seed), xs, ys, sx, sy


def _build_panel(plan: _PanelPlan, nf: dict[str, int], ntx: int, nty: int):
    """Nodes (compacted), elements, node thickness and element thickness strain of one part."""
    elements, xs, ys, sx, sy = _panel_topology(plan, nf, ntx, nty)
    L, W = plan.length, plan.width
    X, Y = np.meshgrid(xs, ys)
    depth = sx[None, :] + sy[:, None]

    crown_shape = np.sin(np.pi * X / L) * np.sin(np.pi * Y / W)
    z = plan.crown * crown_shape
    bead = np.zeros_like(X)
    for x0, y0, x1, y1, half, height in plan.beads:
        r = _segment_distance(X, Y, x0, y0, x1, y1)
        profile = 1.0 - _smoothstep((r - 0.35 * half) / (0.65 * half))
        bead = np.maximum(bead, profile)
        z += height * profile
    z -= depth

    # thinning where the sheet was stretched: on beads, over the dome, around the bend lines
    dev_x = np.where(X <= 0.0, -sx[None, :], np.where(X >= L, L + sx[None, :], X))
    dev_y = np.where(Y <= 0.0, -sy[:, None], np.where(Y >= W, W + sy[:, None], Y))
    bend = np.zeros_like(X)
    for side, coord, edge in (("x-", dev_x, 0.0), ("x+", dev_x, L), ("y-", dev_y, 0.0),
                              ("y+", dev_y, W)):
        if plan.flanges.get(side, 0.0) > 0:
            bend = np.maximum(bend, np.exp(-(((coord - edge) / 8.0) ** 2)))
    thickness = plan.thickness * (1.0 - 0.10 * bead - 0.03 * np.clip(crown_shape, 0, None)
                                  - 0.06 * bend)

    ox, oy, oz = plan.origin
    nodes = np.stack([X + ox, Y + oy, z + oz], axis=-1).reshape(-1, 3)
    thickness = thickness.reshape(-1)

    used, inverse = np.unique(elements, return_inverse=True)
    elements = inverse.reshape(elements.shape)
    nodes, thickness = nodes[used], thickness[used]
    t_elem = thickness[elements].mean(axis=1)
    strain = np.log(plan.thickness / t_elem)
    return nodes, elements, thickness, strain
