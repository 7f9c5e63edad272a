"""Synthetic FE scenes of the papers' kinds and sizes: pure numpy, float64, returning :class:`FEMesh`.

- :func:`semicylinders` — the es2008 benchmark: stacked semi-cylindrical sheets with a distance field.
- :func:`stamped_panel`, :func:`stamped_panels` — quad-dominant stamped sheet-metal parts (beads,
  flanges, holes, a few per cent triangles) of any size, e.g. the crash2000 Table 1 model sizes.
- :func:`refine` — conforming k×k refinement of any FE shell mesh (fields and time steps follow).
- :func:`crash_sequence` — time steps of a smooth progressive front crush with per-node displacement
  and per-element plastic strain.

Lengths are millimetres unless a function says otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .derived import element_normals, node_normals
from .mesh import FEMesh, MeshError

__all__ = ["semicylinders", "stamped_panel", "stamped_panels", "refine", "crash_sequence",
           "box_in_box"]


def _smoothstep(x: np.ndarray | float) -> np.ndarray:
    """C1 ramp from 0 (x <= 0) to 1 (x >= 1)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _positive_int(value, what: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{what} must be an integer, got {value!r}")
    if value < minimum:
        raise ValueError(f"{what} must be >= {minimum}, got {value}")
    return int(value)


def _positive_float(value, what: str) -> float:
    value = float(value)
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"{what} must be a positive finite number, got {value!r}")
    return value


# ===================================================================== es2008 benchmark
def semicylinders(sheets: int = 8, n: int = 250, radius: float = 100.0, spacing: float = 10.0,
                  height: float | None = None) -> FEMesh:
    """The es2008 benchmark scene: ``sheets`` semi-cylindrical sheets of n×n quads, one behind the other.

    The paper (Kawai et al., section 3) gives only: 8 semi-cylindrical sheets placed in depth order,
    each a 250 by 250 grid, 1 M triangles in total, a scalar proportional to the distance from the
    centre of each sheet, rendered at 1000×1000 with triangles of about 5×5 pixels. Assumed here:

    - The viewer looks along −z (OpenGL's default view). Each sheet is the front half of a circular
      cylinder of ``radius`` whose axis is parallel to y; sheet k is sheet 0 moved back by
      ``k * spacing`` along −z, so every sheet lies strictly behind the previous one at every (x, y)
      (the sheets never intersect) and, seen from the front, each hides the ones behind it.
    - The sheets are ``height`` tall (default ``2 * radius``, so the front view of a sheet is a
      square that fills a square image, like the paper's 1000×1000 one).
    - Grid: n equal angle steps around the half circle (x from −radius to +radius) by n equal steps
      along y; quads are wound counter-clockwise seen from +z (normals towards the viewer).
    - "Centre of a sheet": its midpoint on the surface (the apex of the arc at half height). The
      node field ``"distance"`` is the Euclidean distance to that point in model units (factor 1).

    Sizes: ``sheets * (n + 1)**2`` nodes, ``sheets * n**2`` quads = ``2 * sheets * n**2`` triangles
    (1 000 000 at the defaults). Part id = sheet index, 0 at the front. Units mm (the scene is
    artificial; only ratios matter). Refused: ``sheets`` or ``n`` below 1, non-positive sizes.
    """
    sheets = _positive_int(sheets, "sheets")
    n = _positive_int(n, "n")
    radius = _positive_float(radius, "radius")
    spacing = _positive_float(spacing, "spacing")
    height = 2.0 * radius if height is None else _positive_float(height, "height")

    # symmetric steps, so that the middle node (the centre, for even n) sits exactly at x = y = 0
    steps = np.arange(n + 1) - n / 2.0
    phi = steps * (np.pi / n)               # angle from the viewing axis, −90° .. 90°
    y = steps * (height / n)
    # node (i along the arc, j along y) of one sheet, flattened j-major: index j * (n + 1) + i
    x_arc = np.broadcast_to(radius * np.sin(phi), (n + 1, n + 1))
    z_arc = np.broadcast_to(radius * np.cos(phi), (n + 1, n + 1))
    y_col = np.broadcast_to(y[:, None], (n + 1, n + 1))
    sheet_nodes = np.stack([x_arc, y_col, z_arc], axis=-1).reshape(-1, 3)
    per_sheet = (n + 1) ** 2

    apex = np.array([0.0, 0.0, radius])
    distance = np.linalg.norm(sheet_nodes - apex, axis=1)

    offsets = -spacing * np.arange(sheets, dtype=np.float64)
    nodes = np.repeat(sheet_nodes[None], sheets, axis=0)
    nodes[:, :, 2] += offsets[:, None]

    i = np.arange(n, dtype=np.int64)
    base = (i[None, :] + (n + 1) * i[:, None]).reshape(-1)  # lower-left node of each cell
    quad = np.stack([base, base + 1, base + n + 2, base + n + 1], axis=1)
    elements = (quad[None] + per_sheet * np.arange(sheets, dtype=np.int64)[:, None, None])

    return FEMesh(
        nodes=nodes.reshape(-1, 3),
        elements=elements.reshape(-1, 4).astype(np.int32),
        parts=np.repeat(np.arange(sheets, dtype=np.int32), n * n),
        node_fields={"distance": np.tile(distance, sheets)},
        part_names={k: f"sheet {k}" for k in range(sheets)},
        name=f"semicylinders_{sheets}x{n}x{n}",
        units="mm",
    )


# ===================================================================== stamped sheet metal
_SIDES = ("x-", "x+", "y-", "y+")


@dataclass
class _PanelPlan:
    """Everything random about one stamped part, drawn once, independent of the element size."""

    length: float                       # top face along x (mm)
    width: float                        # top face along y (mm)
    flanges: dict[str, float]           # side -> flange depth (mm), bent down by 90°
    crown: float                        # height of the top face's dome (mm)
    beads: list[tuple[float, ...]]      # (x0, y0, x1, y1, half width, height) in top-face mm
    holes: list[tuple[float, float, float]]  # (cx, cy, radius) in top-face mm
    thickness: float                    # nominal sheet thickness (mm)
    triangle_share: float               # wanted share of triangles among all elements
    seed: int                           # for the quad splits
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    relief: float = 10.0                # corner relief: flanges stop this far from a corner (mm)

    def developed(self) -> tuple[float, float]:
        """Length and width of the flat blank (top face plus flanges), mm."""
        f = self.flanges
        return (self.length + f.get("x-", 0.0) + f.get("x+", 0.0),
                self.width + f.get("y-", 0.0) + f.get("y+", 0.0))


def _segment_distance(px, py, x0, y0, x1, y1):
    dx, dy = x1 - x0, y1 - y0
    t = np.clip(((px - x0) * dx + (py - y0) * dy) / max(dx * dx + dy * dy, 1e-300), 0.0, 1.0)
    return np.hypot(px - (x0 + t * dx), py - (y0 + t * dy))


def _draw_features(plan: _PanelPlan, rng: np.random.Generator, n_beads: int, n_holes: int,
                   h: float) -> None:
    """Place holes first (so a part asked for holes gets at least one where it fits), then beads
    that keep clear of the holes and the edges. ``h`` is the expected element size, so that every
    feature spans a few elements."""
    L, W = plan.length, plan.width
    holes: list[tuple[float, float, float]] = []
    edge = max(25.0, 2.0 * h)
    r_fit = 0.9 * (min(L, W) / 2.0 - edge)   # largest radius that keeps clear of the edges
    for _ in range(n_holes):
        for _try in range(60):
            r = min(max(rng.uniform(15.0, 50.0), 1.8 * h), r_fit)
            if r < 1.8 * h:
                break
            margin = r + edge
            cx, cy = rng.uniform(margin, L - margin), rng.uniform(margin, W - margin)
            if all(np.hypot(cx - hx, cy - hy) > r + hr + max(30.0, 2 * h) for hx, hy, hr in holes):
                holes.append((float(cx), float(cy), float(r)))
                break
    beads: list[tuple[float, ...]] = []
    for _ in range(n_beads):
        for _try in range(60):
            half = max(rng.uniform(10.0, 20.0), 2.2 * h)
            height = rng.uniform(4.0, 9.0)
            margin = half + max(20.0, h)
            if 2 * margin >= min(L, W):
                break
            kind = rng.integers(3)
            if kind == 0:   # along x
                y0 = y1 = rng.uniform(margin, W - margin)
                span = rng.uniform(0.45, 0.8) * (L - 2 * margin)
                x0 = rng.uniform(margin, L - margin - span)
                x1 = x0 + span
            elif kind == 1:  # along y
                x0 = x1 = rng.uniform(margin, L - margin)
                span = rng.uniform(0.45, 0.8) * (W - 2 * margin)
                y0 = rng.uniform(margin, W - margin - span)
                y1 = y0 + span
            else:            # diagonal
                x0, x1 = np.sort(rng.uniform(margin, L - margin, 2))
                y0, y1 = rng.uniform(margin, W - margin, 2)
                if np.hypot(x1 - x0, y1 - y0) < 0.3 * min(L, W):
                    continue
            clear = all(
                _segment_distance(np.array(hx), np.array(hy), x0, y0, x1, y1) > hr + half + 5.0
                for hx, hy, hr in holes
            )
            if clear:
                beads.append((float(x0), float(y0), float(x1), float(y1), float(half), float(height)))
                break
    plan.holes = holes
    plan.beads = beads


def _grid_counts(plan: _PanelPlan, hx: float, hy: float) -> tuple[dict[str, int], int, int]:
    """Flange element counts per side and top-face element counts along x and y for spacings hx, hy."""
    nf = {s: (max(1, int(round(d / (hx if s[0] == "x" else hy)))) if d > 0 else 0)
          for s, d in plan.flanges.items()}
    for s in _SIDES:
        nf.setdefault(s, 0)
    return nf, max(2, int(round(plan.length / hx))), max(2, int(round(plan.width / hy)))


def _cell_elements(ii: np.ndarray, jj: np.ndarray, missing: np.ndarray, stride: int) -> np.ndarray:
    """(len(ii), 4) elements of grid cells (i, j), node (i, j) = j * stride + i; a cell with
    ``missing`` corner c (0..3 counter-clockwise from (i, j)) becomes the triangle of the other three."""
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


def _panel_topology(plan: _PanelPlan, nf: dict[str, int], ntx: int, nty: int):
    """Elements of one part in full-grid node numbering (node (i, j) -> j * (nx + 1) + i).

    Returns (elements (M, 4) int64, node top-face x (nx+1,), node y (ny+1,), flange depth along
    x per node column, along y per node row).
    """
    L, W = plan.length, plan.width
    nx = nf["x-"] + ntx + nf["x+"]
    ny = nf["y-"] + nty + nf["y+"]

    def axis(n_minus, n_top, n_plus, size, d_minus, d_plus):
        idx = np.arange(n_minus + n_top + n_plus + 1, dtype=np.float64)
        top = np.clip((idx - n_minus) / n_top, 0.0, 1.0) * size
        depth = np.zeros_like(idx)
        if n_minus:
            depth = np.where(idx < n_minus, (n_minus - idx) * d_minus / n_minus, depth)
        if n_plus:
            depth = np.where(idx > n_minus + n_top, (idx - n_minus - n_top) * d_plus / n_plus, depth)
        return top, depth

    xs, sx = axis(nf["x-"], ntx, nf["x+"], L, plan.flanges.get("x-", 0.0), plan.flanges.get("x+", 0.0))
    ys, sy = axis(nf["y-"], nty, nf["y+"], W, plan.flanges.get("y-", 0.0), plan.flanges.get("y+", 0.0))

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

    # holes in the top face: cells whose centre is inside are removed; a kept cell with exactly one
    # corner inside becomes the triangle of its other three corners (chamfers the staircase)
    xc = 0.5 * (xs[:-1] + xs[1:])
    yc = 0.5 * (ys[:-1] + ys[1:])
    top_cell = ~in_xf[None, :] & ~in_yf[:, None]
    top_node = (sx == 0)[None, :] & (sy == 0)[:, None]
    node_in = np.zeros((ny + 1, nx + 1), bool)
    for cx, cy, r in plan.holes:
        keep &= ~(top_cell & ((xc[None, :] - cx) ** 2 + (yc[:, None] - cy) ** 2 < r * r))
        node_in |= top_node & ((xs[None, :] - cx) ** 2 + (ys[:, None] - cy) ** 2 < r * r)
    corner_in = np.stack([node_in[:-1, :-1], node_in[:-1, 1:], node_in[1:, 1:], node_in[1:, :-1]], axis=-1)
    missing = np.where(corner_in.sum(axis=-1) == 1, np.argmax(corner_in, axis=-1), -1)  # (ny, nx)
    stride = nx + 1

    # a tight hole can leave two cells touching at one node only (a pinched boundary); remove the
    # cell nearer the hole's centre until no node around any hole is pinched
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

    jj, ii = np.nonzero(keep)
    quads = _cell_elements(ii, jj, missing[jj, ii], stride)

    # random splits of quads into two triangles, up to the wanted triangle share
    is_tri = quads[:, 3] == quads[:, 2]
    n_tri, n_quad = int(is_tri.sum()), int((~is_tri).sum())
    s = plan.triangle_share
    n_split = int(round(max(0.0, (s * (n_quad + n_tri) - n_tri) / (2.0 - s))))
    n_split = min(n_split, n_quad)
    if n_split:
        rng = np.random.default_rng([plan.seed, 0x5917])
        chosen = rng.choice(np.flatnonzero(~is_tri), size=n_split, replace=False)
        split = np.zeros(len(quads), bool)
        split[chosen] = True
        diag = rng.integers(2, size=n_split).astype(bool)
        q = quads[split]
        # diagonal 0-2: (0,1,2)+(0,2,3); diagonal 1-3: (0,1,3)+(1,2,3); both keep the winding
        first = np.where(diag[:, None], q[:, [0, 1, 3, 3]], q[:, [0, 1, 2, 2]])
        second = np.where(diag[:, None], q[:, [1, 2, 3, 3]], q[:, [0, 2, 3, 3]])
        out = np.repeat(quads, np.where(split, 2, 1), axis=0)
        pos = np.flatnonzero(split) + np.arange(n_split)  # index in `out` of each split's first child
        out[pos] = first
        out[pos + 1] = second
        quads = out
    return quads, xs, ys, sx, sy


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
    for side, coord, edge in (("x-", dev_x, 0.0), ("x+", dev_x, L), ("y-", dev_y, 0.0), ("y+", dev_y, W)):
        if plan.flanges.get(side, 0.0) > 0:
            bend = np.maximum(bend, np.exp(-(((coord - edge) / 8.0) ** 2)))
    thickness = plan.thickness * (1.0 - 0.10 * bead - 0.03 * np.clip(crown_shape, 0, None) - 0.06 * bend)

    ox, oy, oz = plan.origin
    nodes = np.stack([X + ox, Y + oy, z + oz], axis=-1).reshape(-1, 3)
    thickness = thickness.reshape(-1)

    used, inverse = np.unique(elements, return_inverse=True)
    elements = inverse.reshape(elements.shape)
    nodes, thickness = nodes[used], thickness[used]
    t_elem = thickness[elements].mean(axis=1)
    strain = np.log(plan.thickness / t_elem)
    return nodes, elements, thickness, strain


def _draw_plan(rng: np.random.Generator, length: float, width: float, flange_depths: dict[str, float],
               triangle_share: float, seed: int, origin=(0.0, 0.0, 0.0)) -> _PanelPlan:
    return _PanelPlan(
        length=length, width=width, flanges=dict(flange_depths),
        crown=float(rng.uniform(0.03, 0.07) * min(length, width)),
        beads=[], holes=[],
        thickness=float(rng.choice([0.7, 0.8, 1.0, 1.2, 1.5, 2.0])),
        triangle_share=triangle_share, seed=int(seed), origin=tuple(float(v) for v in origin),
    )


def _check_share(triangle_share: float) -> float:
    triangle_share = float(triangle_share)
    if not 0.0 <= triangle_share < 0.5:
        raise ValueError(f"triangle_share must be in [0, 0.5), got {triangle_share}")
    return triangle_share


def stamped_panel(nx: int, ny: int, length: float = 600.0, width: float = 400.0, *,
                  flange_depth: float = 25.0, flanges=_SIDES, beads: int | None = None,
                  holes: int | None = None, triangle_share: float = 0.03,
                  seed: int = 0) -> FEMesh:
    """One stamped sheet-metal part: a structured nx × ny grid over the flat blank, formed in 3-D.

    The blank is the ``length`` × ``width`` top face (mm, x and y) plus a ``flange_depth`` strip
    on each side named in ``flanges`` (of "x-", "x+", "y-", "y+"). nx and ny count elements
    across the whole blank. Forming: the top face is a shallow dome (crown 3–7 % of its smaller
    side) with ``beads`` raised ridges (4–9 mm high, smooth trapezoid profile); every flange is
    bent down by 90° along a grid line, so the bend is a sharp crease; flanges stop short of the
    corners (corner relief). ``holes`` round holes (radius 15–50 mm) remove the elements whose
    centre lies inside, leaving inner boundary loops; a kept element with one corner inside
    becomes a triangle. Further quads are split into two triangles until about
    ``triangle_share`` of all elements are triangles. ``beads``/``holes`` of None draw 1–3 each
    from ``seed``; features that do not fit the part at this resolution are left out.

    Node field ``"thickness"`` (mm): the nominal thickness, thinned smoothly on beads, over the
    dome and around bends. Element field ``"thickness_strain"``: ln(nominal / element mean
    thickness). The same arguments give the same mesh. Refused: grids too coarse for the
    flanges (fewer than 2 top-face elements along a side), non-positive sizes, unknown sides.
    """
    nx = _positive_int(nx, "nx", 2)
    ny = _positive_int(ny, "ny", 2)
    length = _positive_float(length, "length")
    width = _positive_float(width, "width")
    flange_depth = float(flange_depth)
    if not np.isfinite(flange_depth) or flange_depth < 0:
        raise ValueError(f"flange_depth must be >= 0, got {flange_depth}")
    unknown = set(flanges) - set(_SIDES)
    if unknown:
        raise ValueError(f"unknown flange sides {sorted(unknown)}; use {_SIDES}")
    triangle_share = _check_share(triangle_share)
    rng = np.random.default_rng(seed)
    depths = {s: (flange_depth if s in flanges else 0.0) for s in _SIDES}
    plan = _draw_plan(rng, length, width, depths, triangle_share, seed)
    dev_l, dev_w = plan.developed()
    hx, hy = dev_l / nx, dev_w / ny
    nf = {s: (max(1, int(round(d / (hx if s[0] == "x" else hy)))) if d > 0 else 0)
          for s, d in depths.items()}
    ntx, nty = nx - nf["x-"] - nf["x+"], ny - nf["y-"] - nf["y+"]
    if ntx < 2 or nty < 2:
        raise ValueError(f"grid {nx}x{ny} is too coarse for {flange_depth} mm flanges on "
                         f"{length}x{width} mm: the top face would get {ntx}x{nty} elements")
    n_beads = int(rng.integers(1, 4)) if beads is None else _positive_int(beads, "beads", 0)
    n_holes = int(rng.integers(1, 4)) if holes is None else _positive_int(holes, "holes", 0)
    _draw_features(plan, rng, n_beads, n_holes, max(length / ntx, width / nty))
    nodes, elements, thickness, strain = _build_panel(plan, nf, ntx, nty)
    return FEMesh(
        nodes=nodes, elements=elements.astype(np.int32),
        parts=np.zeros(len(elements), np.int32),
        node_fields={"thickness": thickness},
        element_fields={"thickness_strain": strain},
        part_names={0: "panel 0"},
        name=f"stamped_panel_{nx}x{ny}_s{seed}",
        units="mm",
    )


def stamped_panels(target_quads: int, parts: int | None = None, seed: int = 0, *,
                   triangle_share: float = 0.03, gap: float = 1.5) -> FEMesh:
    """Several stamped parts side by side with about ``target_quads`` quads in total.

    Parts (like :func:`stamped_panel`: domed top face 300–750 × 250–550 mm, 15–40 mm flanges
    on all four sides, 1–3 beads, 1–3 holes, nominal thickness 0.7–2 mm) are laid out in rows
    on the xy plane (z up), meshed with one element size chosen so that the quad count lands
    within about 0.5 % of ``target_quads`` (single element rows of single parts close the last
    gap on small models, where one row is a step of a few per cent). Neighbouring parts face each other
    with parallel flanges ``gap`` mm apart (default 1.5 mm: the "potential flanges" of crash2000,
    distance ≤ 2 mm). Parts share no nodes (independently meshed components).

    ``parts`` defaults to about one part per 3 000 quads (at least 2, at most 256), which gives
    element sizes of 5–10 mm as in car crash models. Part id = part index. Fields as in
    :func:`stamped_panel`. Deterministic for a given (target_quads, parts, seed). Refused:
    targets below 200 quads per part, a non-positive gap.
    """
    target_quads = _positive_int(target_quads, "target_quads")
    if parts is None:
        parts = int(np.clip(round(target_quads / 3000), 2, 256))
    parts = _positive_int(parts, "parts")
    if target_quads < 200 * parts:
        raise ValueError(f"target_quads={target_quads} is too small for {parts} parts "
                         f"(need at least 200 quads per part)")
    gap = _positive_float(gap, "gap")
    triangle_share = _check_share(triangle_share)
    rng = np.random.default_rng(seed)

    n_rows = max(1, int(round(np.sqrt(parts / 1.5))))
    per_row = np.full(n_rows, parts // n_rows)
    per_row[: parts % n_rows] += 1
    plans: list[_PanelPlan] = []
    y0 = 0.0
    for row, count in enumerate(per_row):
        width = float(rng.uniform(250.0, 550.0))
        x0 = 0.0
        for _ in range(count):
            length = float(rng.uniform(300.0, 750.0))
            depths = {s: float(rng.uniform(15.0, 40.0)) for s in _SIDES}
            plan = _draw_plan(rng, length, width, depths, triangle_share,
                              seed=int(rng.integers(2**31)), origin=(x0, y0, 0.0))
            plans.append(plan)
            x0 += length + gap
        y0 += width + gap

    dev_area = sum(np.prod(p.developed()) for p in plans)
    h = float(np.sqrt(dev_area * 0.93 / target_quads))  # ~7 % of the blank ends up cut or split
    for plan in plans:
        _draw_features(plan, rng, int(rng.integers(1, 4)), int(rng.integers(1, 4)), h)

    def part_quads(plan: _PanelPlan, grid) -> int:
        elements = _panel_topology(plan, *grid)[0]
        return int((elements[:, 3] != elements[:, 2]).sum())

    # one element size for all parts, found by a few secant-like steps on Q(h) ~ 1/h²
    best_h, best_err = h, np.inf
    for _ in range(12):
        q = sum(part_quads(p, _grid_counts(p, h, h)) for p in plans)
        err = abs(q - target_quads) / target_quads
        if err < best_err:
            best_h, best_err = h, err
        if err < 0.002:
            break
        h *= float(np.sqrt(q / target_quads))
    grids = [_grid_counts(p, best_h, best_h) for p in plans]
    counts = [part_quads(p, g) for p, g in zip(plans, grids)]

    # small models: one element row more or less in one part is a step of a few per cent, so
    # close the remaining gap greedily with single-row changes
    for _ in range(4 * len(plans)):
        miss = sum(counts) - target_quads
        if abs(miss) <= 0.002 * target_quads:
            break
        best = None
        for index, (plan, (nf, ntx, nty)) in enumerate(zip(plans, grids)):
            for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                if min(ntx + dx, nty + dy) < 2:
                    continue
                grid = (nf, ntx + dx, nty + dy)
                q = part_quads(plan, grid)
                gain = abs(miss) - abs(miss - counts[index] + q)
                if gain > 0 and (best is None or gain > best[0]):
                    best = (gain, index, grid, q)
        if best is None:
            break
        _, index, grids[index], counts[index] = best

    all_nodes, all_elements, all_parts, all_t, all_s = [], [], [], [], []
    offset = 0
    for index, (plan, grid) in enumerate(zip(plans, grids)):
        nodes, elements, thickness, strain = _build_panel(plan, *grid)
        all_nodes.append(nodes)
        all_elements.append(elements + offset)
        all_parts.append(np.full(len(elements), index, np.int32))
        all_t.append(thickness)
        all_s.append(strain)
        offset += len(nodes)
    return FEMesh(
        nodes=np.concatenate(all_nodes),
        elements=np.concatenate(all_elements).astype(np.int32),
        parts=np.concatenate(all_parts),
        node_fields={"thickness": np.concatenate(all_t)},
        element_fields={"thickness_strain": np.concatenate(all_s)},
        part_names={i: f"panel {i}" for i in range(parts)},
        name=f"stamped_panels_{target_quads}_s{seed}",
        units="mm",
    )


# ===================================================================== refinement
def _normalise_elements(elements: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Elements with every triangle in the ``e[3] == e[2]`` form, and the triangle mask.

    A quad with one pair of equal neighbouring nodes is a triangle stored another way; it is
    rotated (winding kept) into the convention. Fewer than three distinct nodes, or equal nodes
    that are not neighbours, is refused.
    """
    e = elements.astype(np.int64)
    same = e == np.roll(e, -1, axis=1)           # same[:, c]: node c equals node c+1
    n_same = same.sum(axis=1)
    opposite = (e[:, 0] == e[:, 2]) | (e[:, 1] == e[:, 3])
    bad = np.flatnonzero((n_same > 1) | opposite)
    if len(bad):
        raise MeshError(f"{len(bad)} degenerate elements cannot be refined (fewer than three "
                        f"distinct nodes or repeated opposite nodes), first "
                        f"{[(int(i), e[i].tolist()) for i in bad[:5]]}")
    is_tri = n_same == 1
    rotate = is_tri & ~same[:, 2]
    if rotate.any():
        # rotate so that the equal pair sits at positions (2, 3)
        c = np.argmax(same[rotate], axis=1)
        shift = (c - 2) % 4
        idx = (np.arange(4)[None, :] + shift[:, None]) % 4
        e = e.copy()
        e[rotate] = np.take_along_axis(e[rotate], idx, axis=1)
    return e, is_tri


class _Refinement:
    """The linear maps from old node values to refined node values, and the refined topology.

    New nodes are numbered: the N old nodes first (unchanged), then k-1 nodes on every unique
    element edge, then the interior nodes of every quad and of every triangle.
    """

    def __init__(self, elements: np.ndarray, n_nodes: int, k: int):
        e, is_tri = _normalise_elements(elements)
        self.k, self.n_old = k, n_nodes
        quads, tris = np.flatnonzero(~is_tri), np.flatnonzero(is_tri)
        eq, et = e[quads], e[tris]

        # unique edges, each with k-1 nodes numbered from its smaller node id
        nq, nt = len(quads), len(tris)
        a = np.concatenate([eq.ravel(), et[:, :3].ravel()])
        b = np.concatenate([np.roll(eq, -1, axis=1).ravel(), np.roll(et[:, :3], -1, axis=1).ravel()])
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        ukeys, inverse = np.unique(lo * np.int64(n_nodes) + hi, return_inverse=True)
        self.edge_lo, self.edge_hi = ukeys // n_nodes, ukeys % n_nodes
        inverse = inverse.ravel()
        forward = a < b
        q_edge, q_fwd = inverse[: 4 * nq].reshape(nq, 4), forward[: 4 * nq].reshape(nq, 4)
        t_edge, t_fwd = inverse[4 * nq:].reshape(nt, 3), forward[4 * nq:].reshape(nt, 3)
        n_edge_nodes = len(ukeys) * (k - 1)
        self.n_quad_inner = (k - 1) ** 2
        self.n_tri_inner = (k - 1) * (k - 2) // 2
        quad_base = n_nodes + n_edge_nodes
        tri_base = quad_base + nq * self.n_quad_inner
        self.n_new = tri_base + nt * self.n_tri_inner
        if self.n_new >= 2**31 or len(elements) * k * k >= 2**31:
            raise MeshError(f"refining by {k} would exceed int32 indices ({self.n_new} nodes)")

        m = np.arange(1, k)

        def edge_nodes(edge, fwd, col):
            """(rows, k-1) node ids along element edge `col`, ordered from its start node."""
            j = np.where(fwd[:, col][:, None], m[None, :], k - m[None, :])
            return n_nodes + edge[:, col][:, None] * (k - 1) + (j - 1)

        # quads: local grid G[j, i] at (s, t) = (i/k, j/k); corners e0 (0,0), e1 (1,0), e2 (1,1), e3 (0,1)
        G = np.empty((nq, k + 1, k + 1), np.int64)
        if nq:
            rq = np.arange(nq)
            G[:, 0, 0], G[:, 0, k], G[:, k, k], G[:, k, 0] = eq[:, 0], eq[:, 1], eq[:, 2], eq[:, 3]
            if k > 1:
                G[:, 0, 1:k] = edge_nodes(q_edge, q_fwd, 0)              # e0 -> e1 along s
                G[:, 1:k, k] = edge_nodes(q_edge, q_fwd, 1)              # e1 -> e2 along t
                G[:, k, 1:k] = edge_nodes(q_edge, q_fwd, 2)[:, ::-1]     # e2 -> e3 runs against s
                G[:, 1:k, 0] = edge_nodes(q_edge, q_fwd, 3)[:, ::-1]     # e3 -> e0 runs against t
                G[:, 1:k, 1:k] = (quad_base + rq[:, None] * self.n_quad_inner
                                  + np.arange(self.n_quad_inner)[None, :]).reshape(nq, k - 1, k - 1)
        ii, jj = np.meshgrid(np.arange(k), np.arange(k))      # child (j, i), row-major in j
        ii, jj = ii.ravel(), jj.ravel()
        quad_children = np.stack([G[:, jj, ii], G[:, jj, ii + 1], G[:, jj + 1, ii + 1], G[:, jj + 1, ii]],
                                 axis=-1)                      # (nq, k*k, 4)

        # triangles: local grid H[j, i] at P0 + (i/k)(P1 - P0) + (j/k)(P2 - P0), i + j <= k;
        # interior nodes (i, j >= 1, i + j <= k - 1) in row-major order
        jin, iin = np.nonzero(np.add.outer(np.arange(k + 1), np.arange(k + 1)) < k)
        inner = (jin > 0) & (iin > 0)
        jin, iin = jin[inner], iin[inner]
        H = np.zeros((nt, k + 1, k + 1), np.int64)
        if nt:
            H[:, 0, 0], H[:, 0, k], H[:, k, 0] = et[:, 0], et[:, 1], et[:, 2]
            if k > 1:
                H[:, 0, 1:k] = edge_nodes(t_edge, t_fwd, 0)              # e0 -> e1 along i
                H[:, m, k - m] = edge_nodes(t_edge, t_fwd, 1)            # e1 -> e2: (i, j) = (k - m, m)
                H[:, 1:k, 0] = edge_nodes(t_edge, t_fwd, 2)[:, ::-1]     # e2 -> e0 runs against j
                if self.n_tri_inner:
                    H[:, jin, iin] = (tri_base + np.arange(nt)[:, None] * self.n_tri_inner
                                      + np.arange(self.n_tri_inner)[None, :])
        uj, ui = np.nonzero(np.add.outer(np.arange(k), np.arange(k)) <= k - 1)   # upward
        dj, di = np.nonzero(np.add.outer(np.arange(k), np.arange(k)) <= k - 2)   # downward
        up = np.stack([H[:, uj, ui], H[:, uj, ui + 1], H[:, uj + 1, ui], H[:, uj + 1, ui]], axis=-1)
        down = np.stack([H[:, dj, di + 1], H[:, dj + 1, di + 1], H[:, dj + 1, di], H[:, dj + 1, di]],
                        axis=-1)
        tri_children = np.concatenate([up, down], axis=1)     # (nt, k*k, 4)

        # children keep their parent's position in the element order
        kk = k * k
        out = np.empty((len(elements), kk, 4), np.int64)
        out[quads] = quad_children
        out[tris] = tri_children
        self.elements = out.reshape(-1, 4).astype(np.int32)
        self.parent = np.repeat(np.arange(len(elements)), kk)
        self.eq, self.et = eq, et

        s = np.arange(1, k) / k
        self.edge_t = s
        S, T = np.meshgrid(s, s)                               # inner quad node (j, i) row-major
        S, T = S.ravel(), T.ravel()
        self.quad_w = np.stack([(1 - S) * (1 - T), S * (1 - T), S * T, (1 - S) * T])      # (4, n)
        if self.n_tri_inner:
            bi, bj = iin / k, jin / k
            self.tri_w = np.stack([1 - bi - bj, bi, bj])                                    # (3, n)

    def apply(self, values: np.ndarray, axis: int) -> np.ndarray:
        """Refined copy of per-node ``values`` (node axis ``axis``), by the same linear maps."""
        v = np.moveaxis(np.asarray(values, dtype=np.float64), axis, 0)
        rest = v.shape[1:]
        v = v.reshape(self.n_old, -1)
        out = np.empty((self.n_new, v.shape[1]), np.float64)
        out[: self.n_old] = v
        k, pos = self.k, self.n_old
        if k > 1:
            t = self.edge_t[None, :, None]
            ne = len(self.edge_lo)
            out[pos:pos + ne * (k - 1)] = (v[self.edge_lo][:, None] * (1 - t)
                                           + v[self.edge_hi][:, None] * t).reshape(-1, v.shape[1])
            pos += ne * (k - 1)
            n = len(self.eq) * self.n_quad_inner
            if n:
                acc = np.zeros((len(self.eq), self.n_quad_inner, v.shape[1]))
                for c in range(4):
                    acc += self.quad_w[c][None, :, None] * v[self.eq[:, c]][:, None, :]
                out[pos:pos + n] = acc.reshape(n, -1)
                pos += n
            n = len(self.et) * self.n_tri_inner
            if n:
                acc = np.zeros((len(self.et), self.n_tri_inner, v.shape[1]))
                for c in range(3):
                    acc += self.tri_w[c][None, :, None] * v[self.et[:, c]][:, None, :]
                out[pos:pos + n] = acc.reshape(n, -1)
                pos += n
        return np.moveaxis(out.reshape((self.n_new,) + rest), 0, axis)


def displaced(mesh: FEMesh, amplitude: float = 10.0, wavelength: float = 1200.0) -> FEMesh:
    """``mesh`` with a smooth bump field added along z, amplitude·sin(2πx/λ)·cos(2πy/λ) (model
    units), so that flat regions become curved: a simplifier then has something to lose."""
    amplitude = float(amplitude)
    wavelength = _positive_float(wavelength, "wavelength")
    x, y = mesh.nodes[:, 0], mesh.nodes[:, 1]
    nodes = mesh.nodes.copy()
    nodes[:, 2] += amplitude * np.sin(2 * np.pi * x / wavelength) * np.cos(2 * np.pi * y / wavelength)
    return FEMesh(nodes, mesh.elements, parts=mesh.parts, name=f"{mesh.name} displaced",
                  part_names=dict(mesh.part_names))


def refine(mesh: FEMesh, k: int) -> FEMesh:
    """Conforming k×k refinement: every quad into k² quads (bilinear), every triangle into k² triangles.

    New node positions are the parent's bilinear map (quads) or barycentric map (triangles) at
    parameters i/k; nodes on an element edge are shared by all elements using that edge, so a
    conforming mesh stays conforming (no duplicate nodes, no T-junctions). Node fields and the
    time steps are mapped by the same linear interpolation (a field linear in the coordinates is
    reproduced exactly); element fields, part ids and time values are copied to the children.

    Numbering: old node i stays node i; then k-1 nodes per unique edge, then interior nodes.
    The children of element m are rows ``m*k*k .. (m+1)*k*k - 1``: for a quad, child
    ``j*k + i`` covers parameters s ∈ [i/k, (i+1)/k], t ∈ [j/k, (j+1)/k] (s along e0→e1, t along
    e0→e3) with nodes (s,t), (s+1/k,t), (s+1/k,t+1/k), (s,t+1/k); every child keeps the parent's
    winding. Triangles stored as degenerate quads in another rotation are rotated into the
    ``e[3] == e[2]`` form. ``refine(mesh, 1)`` returns an equal mesh.

    Node ids of old nodes are kept and new nodes numbered after the largest; element ids are
    dropped (children have none). Refused: k < 1, elements with fewer than three distinct nodes,
    results that would not fit int32 indices.
    """
    k = _positive_int(k, "k")
    r = _Refinement(mesh.elements, mesh.n_nodes, k)
    node_ids = None
    if mesh.node_ids is not None:
        start = int(np.max(mesh.node_ids)) + 1
        node_ids = np.concatenate([np.asarray(mesh.node_ids),
                                   np.arange(start, start + r.n_new - r.n_old)])
    return FEMesh(
        nodes=r.apply(mesh.nodes, 0),
        elements=r.elements,
        parts=mesh.parts[r.parent],
        steps=None if mesh.steps is None else r.apply(mesh.steps, 1),
        node_fields={key: r.apply(v, v.ndim - 1) for key, v in mesh.node_fields.items()},
        element_fields={key: v[..., r.parent] for key, v in mesh.element_fields.items()},
        part_names=dict(mesh.part_names),
        times=None if mesh.times is None else np.array(mesh.times, copy=True),
        node_ids=node_ids,
        element_ids=None if k > 1 else (None if mesh.element_ids is None
                                        else np.array(mesh.element_ids, copy=True)),
        name=mesh.name if k == 1 else f"{mesh.name}_refined{k}",
        units=mesh.units,
    )


# ===================================================================== crash sequence
_AXES = {"x": 0, "y": 1, "z": 2}


def crash_sequence(mesh: FEMesh, steps: int = 20, crush: float = 0.25, axis: str = "-x", *,
                   fold_wavelength: float | None = None, duration: float = 0.1,
                   still_parts=()) -> FEMesh:
    """A copy of ``mesh`` with ``steps`` time steps of a smooth, progressive front crush.

    The impactor comes from the ``axis`` side (one of "x", "y", "z", "-x", "-y", "-z": "x" makes
    the nodes of largest x the front, "-x" those of smallest x) and pushes the front back along
    the axis. The default "-x" suits car body coordinates, where x points rearwards (the shared
    LS-DYNA car deck has its bumper at x = 0 and the barrier at negative x).
    With depth d of a node behind the front, extent E of the model along the axis, progress
    τ = i / (steps - 1) and the smooth ramp c(τ) = crush · E · smoothstep(τ) (the crush depth):

    - axial: the front moves back by c; the crush zone of depth Z = 2.5 c is compressed smoothly,
      a node moving by c · φ(d / Z) with φ(r) = 1 - smoothstep(r) (nodes behind Z stay put);
    - buckling: folds of wavelength λ (``fold_wavelength``, default 8 % of E) across the axis,
      along each node's normal projected off the axis, of amplitude 0.25 λ tanh(c / λ) ·
      sin(2π d / λ) · φ(d / Z).

    Both parts only grow with τ and are perpendicular, so every node's displacement grows
    monotonically with time; nodes nearest the impact move most. Adds ``steps`` (T, N, 3),
    ``times`` (T,) in seconds over ``duration``, node field ``"displacement"`` (T, N): distance
    from step 0 in model units, and element field ``"plastic_strain"`` (T, M): a proxy from the
    element edges' stretch and the rotation of the element normal since step 0, beyond a 0.2 %
    yield, accumulated (it never decreases). Step 0 equals the input geometry; topology, parts and
    static fields are kept. ``still_parts``: part ids that do not move (a rigid barrier or pole);
    the front and extent are those of the other parts, and a node moves unless only still parts
    use it. Refused: meshes that already have time steps, steps < 2, crush not in (0, 1), an
    unknown axis, a model with no extent along the axis, only still parts.
    """
    if mesh.steps is not None:
        raise MeshError(f"{mesh.name}: already has {mesh.n_steps} time steps; crash a static mesh")
    steps = _positive_int(steps, "steps", 2)
    crush = float(crush)
    if not 0.0 < crush < 1.0:
        raise ValueError(f"crush must be in (0, 1) (a fraction of the model's extent), got {crush}")
    duration = _positive_float(duration, "duration")
    key = str(axis).lower()
    sign = -1.0 if key.startswith("-") else 1.0
    if key.lstrip("+-") not in _AXES:
        raise ValueError(f"axis must be one of x, y, z, -x, -y, -z, got {axis!r}")
    a_idx = _AXES[key.lstrip("+-")]
    a = np.zeros(3)
    a[a_idx] = sign

    nodes = mesh.nodes
    moving = np.zeros(len(nodes), bool)
    moving[mesh.elements[~np.isin(mesh.parts, np.asarray(still_parts, np.int64))].ravel()] = True
    if not moving.any():
        raise MeshError(f"{mesh.name}: every part is in still_parts {tuple(still_parts)}; nothing to crush")
    used = np.flatnonzero(moving)
    along = nodes @ a
    front, back = along[used].max(), along[used].min()
    extent = front - back
    if not extent > 0:
        raise MeshError(f"{mesh.name}: no extent along {axis!r} to crush")
    lam = 0.08 * extent if fold_wavelength is None else _positive_float(fold_wavelength, "fold_wavelength")
    depth = np.maximum(front - along, 0.0)

    # lateral direction: the node normal with its axial part removed (a fixed perpendicular axis
    # where the normal is along the axis), so that lateral and axial motion are perpendicular
    fallback = np.zeros(3)
    fallback[(a_idx + 2) % 3] = 1.0
    normal = node_normals(mesh.elements, nodes)
    lateral = normal - np.outer(normal @ a, a) + 0.05 * fallback
    norm = np.linalg.norm(lateral, axis=1, keepdims=True)
    lateral = np.where(norm > 1e-9, lateral / np.maximum(norm, 1e-300), fallback)
    wave = np.sin(2.0 * np.pi * depth / lam)

    tau = np.linspace(0.0, 1.0, steps)
    c = crush * extent * _smoothstep(tau)
    coords = np.empty((steps, len(nodes), 3))
    coords[0] = nodes
    for i in range(1, steps):
        phi = (1.0 - _smoothstep(depth / (2.5 * c[i]))) * moving
        amp = 0.25 * lam * np.tanh(c[i] / lam)
        coords[i] = nodes - np.outer(c[i] * phi, a) + (amp * wave * phi)[:, None] * lateral
    displacement = np.linalg.norm(coords - nodes[None], axis=2)

    # plastic strain proxy per element, accumulated over time
    e = mesh.elements
    tri = e[:, 3] == e[:, 2]

    def edges_and_normals(p):
        corners = p[e]                                        # (M, 4, 3)
        following = corners[:, [1, 2, 3, 0]]
        following[tri, 2] = corners[tri, 0]                   # triangle edges 0-1, 1-2, 2-0
        d = following - corners
        lengths = np.sqrt(np.einsum("mkc,mkc->mk", d, d))
        return lengths, element_normals(e, p)

    l0, n0 = edges_and_normals(nodes)
    strain = np.zeros((steps, len(e)))
    for i in range(1, steps):
        lengths, n = edges_and_normals(coords[i])
        stretch = np.abs(np.divide(lengths, l0, out=np.ones_like(l0), where=l0 > 0) - 1.0)
        turn = 1.0 - np.clip(np.einsum("mc,mc->m", n, n0), -1.0, 1.0)
        now = np.maximum(stretch.max(axis=1) + 0.5 * turn - 0.002, 0.0)
        strain[i] = np.maximum(strain[i - 1], now)

    node_fields = {key: (np.broadcast_to(v[0], (steps,) + v.shape[1:]).copy() if v.ndim == 2 else v)
                   for key, v in mesh.node_fields.items()}
    element_fields = {key: (np.broadcast_to(v[0], (steps,) + v.shape[1:]).copy() if v.ndim == 2 else v)
                      for key, v in mesh.element_fields.items()}
    node_fields["displacement"] = displacement
    element_fields["plastic_strain"] = strain
    return FEMesh(
        nodes=nodes.copy(),
        elements=mesh.elements,
        parts=mesh.parts,
        steps=coords,
        node_fields=node_fields,
        element_fields=element_fields,
        part_names=dict(mesh.part_names),
        times=np.linspace(0.0, duration, steps),
        node_ids=mesh.node_ids,
        element_ids=mesh.element_ids,
        name=f"{mesh.name}_crash",
        units=mesh.units,
    )


# ===================================================================== ghost2013 test assembly
def _grid(origin, u, v, n: int):
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    points = origin + (i[..., None] / n) * u + (j[..., None] / n) * v
    index = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    quads = np.stack([index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]], -1)
    return points.reshape(-1, 3), quads.reshape(-1, 4)


def _box_faces(lo, hi, n: int):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    ex, ey, ez = np.diag(hi - lo)
    return [_grid(o, u, v, n) for o, u, v in ((lo, ey, ez), (lo + ex, ey, ez), (lo, ex, ez),
                                              (lo + ey, ex, ez), (lo, ex, ey), (lo + ez, ex, ey))]


def box_in_box(box_half: float = 1.0, inner_half: float = 0.2, n: int = 8,
               inner_n: int = 2) -> FEMesh:
    """An assembly with an object inside: parts 1..6 are the faces (x−, x+, y−, y+, z−, z+) of
    the cube [−box_half, box_half]³, n × n quads each; part 7 is the cube
    [−inner_half, inner_half]³ (inner_n × inner_n quads a face), hidden from every side —
    the exploded-view scene with a known answer. Refused: inner_half ≥ box_half, sizes that
    are not positive, n or inner_n below 1."""
    box_half, inner_half = _positive_float(box_half, "box_half"), _positive_float(
        inner_half, "inner_half")
    if inner_half >= box_half:
        raise ValueError(f"inner_half {inner_half} must be below box_half {box_half}")
    n, inner_n = _positive_int(n, "n"), _positive_int(inner_n, "inner_n")
    faces = list(enumerate(_box_faces((-box_half,) * 3, (box_half,) * 3, n), start=1))
    faces += [(7, f) for f in _box_faces((-inner_half,) * 3, (inner_half,) * 3, inner_n)]
    nodes, elements, parts, base = [], [], [], 0
    for pid, (points, quads) in faces:
        nodes.append(points)
        elements.append(quads + base)
        parts += [pid] * len(quads)
        base += len(points)
    return FEMesh(np.concatenate(nodes), np.concatenate(elements).astype(np.int32),
                  np.array(parts, np.int32), name="box")

