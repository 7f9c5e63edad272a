"""The es2008 benchmark scene: stacked semi-cylindrical sheets with a distance field."""

from __future__ import annotations

import numpy as np

from ..mesh import FEMesh
from .common import _positive_float, _positive_int


def semicylinders(sheets: int = 8, n: int = 250, radius: float = 100.0, spacing: float = 10.0,
                  height: float | None = None) -> FEMesh:
    """The es2008 benchmark scene: ``sheets`` semi-cylindrical sheets of n×n quads, one behind
    the other.

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
