"""Seeded adversarial scenes of the numerical stress suite (:mod:`workbench.reliability.numerics`):
spacetime tetrahedra to slice, triangles to rasterize, meshes to draw on GL and in software, and
fields to colour.

* :func:`spacetime_case` -- independent tetrahedra, near-zero-volume, with corners at equal
  times, or far from the origin, and the slice times that probe them (every corner time
  exactly, its neighbours in float64, midpoints).
* :func:`raster_scene` -- a closed fan of about 1 000 thin triangles around one vertex (apex on
  a pixel centre, off the grid, or with spokes through pixel centres) and a closed convex mesh
  (a subdivided octahedron under an integer shear), in model coordinates that the software
  rasterizer's float32 transform maps exactly (dyadic, few bits) through :data:`RASTER_VIEW` and
  :func:`raster_projection`.
* :func:`scene_mesh` -- those, a sliver sheet and a sliver sheet 1e7 away, as FE meshes with a
  node field, for the GL paths.
* :func:`field_sheet` -- a sheet of separate square patches facing the camera, one value per
  patch, for the colour checks; :func:`nan_sheet` a connected sheet with missing values.
"""

from __future__ import annotations

import math

import numpy as np

from .numerics_cases import (
    EPS_RANGE,
    fan_ring,
    fit_to_offset,
    grid,
    log_uniform,
    refine_with_slivers,
    split_quads,
)

SLICE_KINDS = ("near-zero volume", "equal times", "far offset")
TETS_PER_CASE = 6
RASTER_KINDS = ("fan, apex on a pixel centre", "fan, apex off the grid",
                "fan, spokes through pixel centres", "closed mesh")
RASTER_SIZE = (64, 64)
RASTER_VIEW = np.eye(4)
SCENE_KINDS = ("fan", "closed mesh", "sliver sheet", "far sliver sheet")


# --------------------------------------------------------------------------- g. spacetime
def spacetime_case(kind: str, rng):
    """(SpacetimeMesh, slice times, label): :data:`TETS_PER_CASE` independent tetrahedra of
    generator ``kind`` (one of :data:`SLICE_KINDS`): a fourth corner ε·size off the
    hyperplane of the other three (ε from 1e-15 to 1e-2; redrawn where the volume computes to 0,
    which the mesh refuses); two or three corners at one time; or moved by an integer offset of
    1e3–1e7 in x and y (exact). The times are every corner time, the floats next to it, the
    midpoints between consecutive ones and a few random ones."""
    from ..algo.spacetime.mesh import SpacetimeMesh

    if kind not in SLICE_KINDS:
        raise ValueError(f"slice generator must be one of {SLICE_KINDS}, got {kind!r}")
    tets, smallest = [], 1.0
    while len(tets) < TETS_PER_CASE:
        size = 2.0 ** rng.uniform(-3, 3)
        p = rng.normal(size=(3, 3)) * size
        if kind == "equal times":
            p[1, 2] = p[0, 2]
            w = rng.uniform(-0.5, 1.5, 3)
            q = (w / w.sum()) @ p if abs(w.sum()) > 0.1 else p.mean(axis=0)
            q = q + rng.normal(size=3) * size * 0.5
            if rng.random() < 0.5:
                q[2] = p[0, 2]  # three corners at one time: a face in the plane
        else:
            eps = log_uniform(rng, *EPS_RANGE)
            w = rng.uniform(-0.5, 1.5, 3)
            q = (w / w.sum()) @ p if abs(w.sum()) > 0.1 else p.mean(axis=0)
            normal = np.cross(p[1] - p[0], p[2] - p[0])
            q = q + eps * size * normal / np.linalg.norm(normal)
            smallest = min(smallest, eps)
        tet = np.vstack([p, q])
        if kind == "far offset":
            offset = np.array([float(np.rint(log_uniform(rng, 1e3, 1e7))) * rng.choice((-1, 1))
                               for _ in range(2)] + [0.0])
            tet = fit_to_offset(tet, offset) + offset
        try:
            SpacetimeMesh(tet, np.arange(4)[None])  # refuses a volume that computes to 0
        except ValueError:
            continue
        tets.append(tet)
    points = np.concatenate(tets)
    mesh = SpacetimeMesh(points, np.arange(len(points)).reshape(-1, 4))
    corner_times = np.unique(points[:, 2])
    times = set(corner_times.tolist())
    times |= set(np.nextafter(corner_times, np.inf).tolist())
    times |= set(np.nextafter(corner_times, -np.inf).tolist())
    times |= set((0.5 * (corner_times[1:] + corner_times[:-1])).tolist())
    times |= set(rng.uniform(corner_times[0], corner_times[-1], 4).tolist())
    label = f"eps {smallest:.1e}" if kind == "near-zero volume" else kind
    return mesh, sorted(times), label


# --------------------------------------------------------------------------- e. raster
def raster_projection(size=RASTER_SIZE, depth: float = 64.0) -> np.ndarray:
    """The orthographic clip matrix of the raster scenes: model x, y in pixels about the image
    centre (x = window x − W/2), z in [−depth, depth] to window depth ½ − z/(2·depth).
    Powers of two for a power-of-two size, so the float32 transform is exact."""
    proj = np.eye(4)
    proj[0, 0], proj[1, 1], proj[2, 2] = 2.0 / size[0], 2.0 / size[1], -1.0 / depth
    return proj


def _grid_round(x, bits: int):
    return np.ldexp(np.rint(np.ldexp(np.asarray(x, np.float64), bits)), -bits)


def raster_scene(kind: str, rng, size=RASTER_SIZE):
    """(positions (V, 3), triangles (K, 3), outline (P, 2) or None, label): a scene of generator
    ``kind`` (one of :data:`RASTER_KINDS`) in the model coordinates of :func:`raster_projection`
    (pixels about the image centre, dyadic). A fan's ``outline`` is its ring (model x, y), in
    order; a closed mesh has none."""
    if kind not in RASTER_KINDS:
        raise ValueError(f"raster generator must be one of {RASTER_KINDS}, got {kind!r}")
    w, h = size
    radius = 0.45 * min(w, h)
    if kind == "closed mesh":
        return _closed_mesh(rng, radius)
    if kind == "fan, spokes through pixel centres":
        # apex on a pixel centre, ring on the pixel centres of an annulus: every spoke and
        # many edges run exactly through pixel centres (ties of the fill rule)
        apex = np.array([0.5, 0.5])
        i, j = np.mgrid[-w // 2:w // 2, -h // 2:h // 2]
        cx, cy = i.ravel() + 0.5, j.ravel() + 0.5
        r = np.hypot(cx - apex[0], cy - apex[1])
        keep = (r >= radius - 1.5) & (r <= radius)
        angle = np.arctan2(cy[keep] - apex[1], cx[keep] - apex[0])
        ring = np.c_[cx[keep], cy[keep]][np.argsort(angle, kind="stable")]
        # one point per direction (the apex, two ring points in line make no triangle)
        d = ring - apex
        g = np.gcd(np.abs(d[:, 0] * 2).astype(int), np.abs(d[:, 1] * 2).astype(int))
        _, first = np.unique(np.c_[(d[:, 0] * 2) // g, (d[:, 1] * 2) // g], axis=0,
                             return_index=True)
        ring = ring[np.sort(first)]
        label = f"{len(ring)} triangles"
    else:
        bits = 8 if kind == "fan, apex on a pixel centre" else 12
        apex = np.array([0.5, 0.5]) if bits == 8 else _grid_round(rng.uniform(-2, 2, 2), 12)
        theta = fan_ring(rng)
        ring = _grid_round(apex + radius * np.c_[np.cos(theta), np.sin(theta)], bits)
        label = f"{len(ring)} triangles, apex ({apex[0]:g}, {apex[1]:g})"
    positions = np.c_[np.vstack([apex, ring]), np.zeros(len(ring) + 1)]
    k = np.arange(len(ring))
    triangles = np.c_[np.zeros(len(ring), np.int64), 1 + k, 1 + (k + 1) % len(ring)]
    return positions, triangles, ring, label


def _closed_mesh(rng, radius: float):
    """An octahedron, its faces subdivided into m² triangles on an integer lattice, wound
    outward, under an integer shear of positive determinant, scaled by a power of two to fit
    ``radius``: convex and closed, every vertex dyadic."""
    m = int(rng.integers(2, 5))
    r = 4 * m
    verts, index, faces = [], {}, []

    def vid(p):
        key = tuple(int(v) for v in p)
        if key not in index:
            index[key] = len(verts)
            verts.append(key)
        return index[key]

    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                a, b, c = (np.array(v) * r for v in ([sx, 0, 0], [0, sy, 0], [0, 0, sz]))
                if sx * sy * sz < 0:
                    b, c = c, b
                # lattice point (u, v) of the face: a + (b − a)·u/m + (c − a)·v/m, integers
                lattice = {(u, v): vid(a + (b - a) * u // m + (c - a) * v // m)
                           for u in range(m + 1) for v in range(m + 1 - u)}
                for i in range(m):
                    for j in range(m - i):
                        faces.append((lattice[i, j], lattice[i + 1, j], lattice[i, j + 1]))
                        if i + j < m - 1:
                            faces.append((lattice[i + 1, j], lattice[i + 1, j + 1],
                                          lattice[i, j + 1]))
    while True:
        shear = rng.integers(-2, 3, (3, 3)) + np.eye(3, dtype=np.int64) * 3
        if round(np.linalg.det(shear)) > 0:
            break
    pts = np.array(verts, np.float64) @ shear.T.astype(np.float64)
    # each axis scaled by a power of two (x, y to fill the radius, z the depth range): a
    # diagonal map of positive determinant keeps the mesh convex, closed and wound outward
    for axis, reach in ((0, radius), (1, radius), (2, 32.0)):
        pts[:, axis] *= 2.0 ** math.floor(math.log2(reach / np.abs(pts[:, axis]).max()))
    # vertices on pixel centres (ties of the fill rule) or anywhere on the 1/256 grid
    shift = [0.5, 0.5] if rng.random() < 0.5 else _grid_round(rng.uniform(-1, 1, 2), 8)
    pts[:, :2] += shift
    return pts, np.array(faces, np.int64), None, f"{len(faces)} triangles, m {m}"


# --------------------------------------------------------------------------- f. FE scenes
def scene_mesh(kind: str, rng):
    """(FEMesh with node field ``f``, label) of generator ``kind`` (one of
    :data:`SCENE_KINDS`): the raster fan and closed mesh, a dyadic sheet refined with sliver and
    needle children, and that sheet moved 1e7 units (an integer offset, exact)."""
    from ..scene.mesh import FEMesh

    if kind not in SCENE_KINDS:
        raise ValueError(f"scene generator must be one of {SCENE_KINDS}, got {kind!r}")
    if kind in ("fan", "closed mesh"):
        raster = "fan, apex off the grid" if kind == "fan" else "closed mesh"
        positions, triangles, _, label = raster_scene(raster, rng)
    else:
        nodes, quads = grid(6, 4)
        nodes[:, 2] = rng.integers(-1, 2, len(nodes)) * 0.5
        positions, triangles, eps = refine_with_slivers(rng, nodes, split_quads(rng, quads),
                                                        0.8, 40)
        label = f"eps {eps:.1e}"
        if kind == "far sliver sheet":
            offset = np.array([1.0e7, -1.0e7, 5.0e6])
            positions = fit_to_offset(positions, offset) + offset
            label += ", offset 1e7"
    centre = positions.mean(axis=0)
    field = np.hypot(*(positions[:, :2] - centre[:2]).T) + positions[:, 2] - centre[2]
    return FEMesh(nodes=positions, elements=triangles, node_fields={"f": field}), label


# --------------------------------------------------------------------------- h. fields
def field_sheet(values, columns: int = 8, cell: float = 1.0, gap: float = 0.25):
    """An FE mesh of ``len(values)`` separate square quads (side ``cell``, ``gap`` apart, in
    rows of ``columns``) in the plane z = 0, each with its own four nodes: the node field ``v``
    and the element field ``e`` hold one value per quad. Returns (mesh, quad corners (Q, 4, 3))."""
    from ..scene.mesh import FEMesh

    values = np.asarray(values, np.float64)
    q = np.arange(len(values))
    x0, y0 = (q % columns) * (cell + gap), (q // columns) * (cell + gap)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64) * cell
    corners = np.zeros((len(q), 4, 3))
    corners[:, :, 0] = x0[:, None] + square[:, 0]
    corners[:, :, 1] = y0[:, None] + square[:, 1]
    mesh = FEMesh(nodes=corners.reshape(-1, 3), elements=np.arange(4 * len(q)).reshape(-1, 4),
                  node_fields={"v": np.repeat(values, 4)}, element_fields={"e": values})
    return mesh, corners


def nan_sheet(rng, n: int = 10):
    """(FEMesh, missing node mask, missing element mask): a connected n × n grid sheet at
    z = 0 with a smooth node field ``v`` and element field ``e``, NaN (or ±inf) on a block of
    nodes and of elements."""
    from ..scene.mesh import FEMesh

    nodes, quads = grid(n, n)
    v = np.sin(nodes[:, 0] * 0.7) + np.cos(nodes[:, 1] * 0.5)
    i0, j0 = (int(x) for x in rng.integers(2, n - 6, 2))
    bi, bj = nodes[:, 0], nodes[:, 1]
    missing = (bi >= i0) & (bi <= i0 + 3) & (bj >= j0) & (bj <= j0 + 3)
    v[missing] = rng.choice([np.nan, np.inf, -np.inf], int(missing.sum()))
    centre = nodes[quads].mean(axis=1)
    e = np.cos(centre[:, 0] * 0.6) * np.sin(centre[:, 1] * 0.4)
    e_missing = (centre[:, 0] > n - 6) & (centre[:, 0] < n - 2) & (centre[:, 1] > 1) & \
        (centre[:, 1] < 5)
    e[e_missing] = np.nan
    mesh = FEMesh(nodes=nodes, elements=quads, node_fields={"v": v}, element_fields={"e": e})
    return mesh, missing, e_missing
