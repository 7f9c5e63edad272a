"""The ghost2013 test assembly: a box of six face parts with a smaller cube hidden inside."""

from __future__ import annotations

import numpy as np

from ..mesh import FEMesh
from .common import _positive_float, _positive_int


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
