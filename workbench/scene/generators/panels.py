"""Stamped sheet-metal parts: one part of a given grid, or many side by side of a given size.

Quad-dominant parts with beads, flanges, holes and a few per cent triangles, of any size, e.g.
the crash2000 Table 1 model sizes. Lengths are millimetres.
"""

from __future__ import annotations

from collections.abc import Collection

import numpy as np

from ..mesh import FEMesh
from .common import _positive_float, _positive_int
from .panel_mesh import _build_panel, _panel_topology
from .panel_plan import _SIDES, _check_share, _draw_features, _draw_plan, _grid_counts, _PanelPlan


def stamped_panel(nx: int, ny: int, length: float = 600.0, width: float = 400.0, *,
                  flange_depth: float = 25.0, flanges: Collection[str] = _SIDES,
                  beads: int | None = None, holes: int | None = None,
                  triangle_share: float = 0.03, seed: int = 0) -> FEMesh:
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
    gap on small models, where one row is a step of a few per cent). Neighbouring parts face each
    other with parallel flanges ``gap`` mm apart (default 1.5 mm: the "potential flanges" of
    crash2000, distance ≤ 2 mm). Parts share no nodes (independently meshed components).

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
    plans = _row_layout(rng, parts, triangle_share, gap)
    dev_area = sum(np.prod(p.developed()) for p in plans)
    h = float(np.sqrt(dev_area * 0.93 / target_quads))  # ~7 % of the blank ends up cut or split
    for plan in plans:
        _draw_features(plan, rng, int(rng.integers(1, 4)), int(rng.integers(1, 4)), h)
    grids = _closest_grids(plans, h, target_quads)
    return _assembled(plans, grids, f"stamped_panels_{target_quads}_s{seed}")


def _row_layout(rng: np.random.Generator, parts: int, triangle_share: float,
                gap: float) -> list[_PanelPlan]:
    """Plans of ``parts`` parts in rows on the xy plane, ``gap`` mm apart, without features."""
    n_rows = max(1, int(round(np.sqrt(parts / 1.5))))
    per_row = np.full(n_rows, parts // n_rows)
    per_row[: parts % n_rows] += 1
    plans: list[_PanelPlan] = []
    y0 = 0.0
    for count in per_row:
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
    return plans


def _part_quads(plan: _PanelPlan, grid) -> int:
    """Quads of part ``plan`` meshed with ``grid`` (flange counts, top-face counts)."""
    elements = _panel_topology(plan, *grid)[0]
    return int((elements[:, 3] != elements[:, 2]).sum())


def _closest_grids(plans: list[_PanelPlan], h: float, target_quads: int) -> list:
    """The grid of every part, from one element size for all (starting at ``h`` mm), so that the
    quad count lands near ``target_quads``; single element rows of single parts close the last
    gap."""
    # one element size for all parts, found by a few secant-like steps on Q(h) ~ 1/h²
    best_h, best_err = h, np.inf
    for _ in range(12):
        q = sum(_part_quads(p, _grid_counts(p, h, h)) for p in plans)
        err = abs(q - target_quads) / target_quads
        if err < best_err:
            best_h, best_err = h, err
        if err < 0.002:
            break
        h *= float(np.sqrt(q / target_quads))
    grids = [_grid_counts(p, best_h, best_h) for p in plans]
    counts = [_part_quads(p, g) for p, g in zip(plans, grids)]

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
                q = _part_quads(plan, grid)
                gain = abs(miss) - abs(miss - counts[index] + q)
                if gain > 0 and (best is None or gain > best[0]):
                    best = (gain, index, grid, q)
        if best is None:
            break
        _, index, grids[index], counts[index] = best
    return grids


def _assembled(plans: list[_PanelPlan], grids: list, name: str) -> FEMesh:
    """The parts of ``plans`` meshed with ``grids`` as one mesh, part id = part index."""
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
        part_names={i: f"panel {i}" for i in range(len(plans))},
        name=name,
        units="mm",
    )
