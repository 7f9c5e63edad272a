"""The random plan of a stamped sheet-metal part: its size, flanges, crown, beads and holes.

A plan is drawn once from a random generator and does not depend on the element size, so that
one part can be meshed at several resolutions. Lengths are millimetres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
                beads.append((float(x0), float(y0), float(x1), float(y1), float(half),
                              float(height)))
                break
    plan.holes = holes
    plan.beads = beads


def _grid_counts(plan: _PanelPlan, hx: float, hy: float) -> tuple[dict[str, int], int, int]:
    """Flange element counts per side and top-face element counts along x and y for spacings
    hx, hy."""
    nf = {s: (max(1, int(round(d / (hx if s[0] == "x" else hy)))) if d > 0 else 0)
          for s, d in plan.flanges.items()}
    for s in _SIDES:
        nf.setdefault(s, 0)
    return nf, max(2, int(round(plan.length / hx))), max(2, int(round(plan.width / hy)))


def _draw_plan(rng: np.random.Generator, length: float, width: float,
               flange_depths: dict[str, float], triangle_share: float, seed: int,
               origin=(0.0, 0.0, 0.0)) -> _PanelPlan:
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
