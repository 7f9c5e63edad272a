"""Small meshes the tests build again and again: regular or jittered quad grids (as quads or
split into triangles), a random tiling of quads and triangles, a plate folded along a grid line,
and barycentric sample grids.

Imported by the test modules as ``from meshes import quad_grid`` (the tests folder is on the
import path when pytest runs). Every builder is deterministic: the same arguments give the same
node numbering, element order and winding and the same coordinates, bit for bit, so a test may
rely on them.

Node numbering: node (i, j), i along x and j along y, has index ``j * (nx + 1) + i`` (row by
row, x fastest) or, with ``ij=True``, ``i * (ny + 1) + j`` (column by column, y fastest); the
elements follow the same order. Every quad is (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1):
counter-clockwise seen from +z.
"""

from __future__ import annotations

import numpy as np


def grid_quads(nx: int, ny: int, *, ij: bool = False) -> np.ndarray:
    """(nx · ny, 4) int64 node indices of the quads of an nx × ny grid, numbered as the module
    docstring says."""
    if ij:
        i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij"))

        def node(a, b):
            return a * (ny + 1) + b
    else:
        j, i = (a.ravel() for a in np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij"))

        def node(a, b):
            return b * (nx + 1) + a
    return np.stack([node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)], axis=1)


def split_quads(quads: np.ndarray) -> np.ndarray:
    """(2M, 3) triangles of (M, 4) quads a b c d cut along a–c: first every (a, b, c), then
    every (a, c, d), wound as the quads."""
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def _node_indices(nx: int, ny: int, ij: bool) -> tuple[np.ndarray, np.ndarray]:
    """(i, j) grid indices of every node, numbered as the module docstring says."""
    i, j = np.arange(nx + 1), np.arange(ny + 1)
    if ij:
        return np.repeat(i, ny + 1), np.tile(j, nx + 1)
    return np.tile(i, ny + 1), np.repeat(j, nx + 1)


def _axis(n: int, cell: float, span, centred: bool) -> np.ndarray:
    """The n + 1 grid coordinates along one axis."""
    if span is not None:
        return np.linspace(span[0], span[1], n + 1)
    if centred:
        return (np.arange(n + 1) - n / 2) * cell
    return np.arange(n + 1) * cell


def quad_grid(nx: int, ny: int, *, cell=1.0, span=None, centred: bool = False, z=None,
              origin=None, jitter: float | None = None, seed=0, jitter_border: bool = True,
              ij: bool = False, triangles: bool = False,
              dim: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """(nodes (N, dim) float64, elements) of an nx × ny grid of quads in the x-y plane.

    Coordinates, in this order:

    * along each axis ``i · cell`` (``cell`` a number or (x, y) pair), ``(i − n/2) · cell``
      with ``centred``, or ``numpy.linspace(lo, hi, n + 1)`` with ``span=((x0, x1), (y0, y1))``;
    * z (``dim`` 3 only): 0 (None), a number or (N,) array, or ``z(x, y)`` of the (N,) node
      coordinates so far;
    * plus ``origin`` (``dim`` components; None adds nothing);
    * plus ``jitter``: a uniform offset in [−jitter, jitter] added to x and y of every node
      (``jitter_border=False``: of the inner nodes only), drawn as one (K, 2) array from
      ``numpy.random.default_rng(seed)`` (a Generator passed as ``seed`` is drawn from); None
      draws nothing.

    Elements: (nx · ny, 4) int64 quads numbered as the module docstring says, or with
    ``triangles`` (2 · nx · ny, 3) triangles (:func:`split_quads`). ``dim`` is 2 or 3."""
    cx, cy = (float(c) for c in np.broadcast_to(cell, 2))
    spans = (None, None) if span is None else span
    i, j = _node_indices(nx, ny, ij)
    x, y = _axis(nx, cx, spans[0], centred)[i], _axis(ny, cy, spans[1], centred)[j]
    columns = [x, y]
    if dim == 3:
        columns.append(np.zeros(len(x)) if z is None else z(x, y) if callable(z)
                       else np.broadcast_to(z, x.shape))
    elif dim != 2 or z is not None:
        raise ValueError("dim must be 3, or 2 without z")
    nodes = np.stack(columns, axis=1).astype(np.float64, copy=False)
    if origin is not None:
        nodes = nodes + np.asarray(origin, np.float64)
    if jitter is not None:
        rng = np.random.default_rng(seed)
        if jitter_border:
            nodes[:, :2] += rng.uniform(-jitter, jitter, (len(nodes), 2))
        else:
            inner = (i > 0) & (i < nx) & (j > 0) & (j < ny)
            nodes[inner, :2] += rng.uniform(-jitter, jitter, (int(inner.sum()), 2))
    quads = grid_quads(nx, ny, ij=ij)
    return nodes, split_quads(quads) if triangles else quads


def random_tiling(n: int, jitter: float, seed=0) -> np.ndarray:
    """(P, 4, 2) corners of the cells of an n × n grid of unit squares, inner nodes jittered by
    up to ``jitter`` (:func:`quad_grid` with ``ij``, drawn first): cell by cell, x outer, each
    cell by a coin toss the quad (a, b, c, d) or its two triangles (a, b, c, c), (a, c, d, d)."""
    rng = np.random.default_rng(seed)
    pts, _ = quad_grid(n, n, jitter=jitter, seed=rng, jitter_border=False, ij=True, dim=2)
    pts = pts.reshape(n + 1, n + 1, 2)
    polys = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = pts[i, j], pts[i + 1, j], pts[i + 1, j + 1], pts[i, j + 1]
            polys += [[a, b, c, d]] if rng.random() < 0.5 else [[a, b, c, c], [a, c, d, d]]
    return np.array(polys)


def folded(nodes: np.ndarray, at: float, angle_deg: float) -> np.ndarray:
    """A copy of ``nodes`` with the part x > ``at`` turned about the line x = ``at``, z = 0 by
    ``angle_deg`` upwards (its z replaced by the rise): a plate in z = 0 folded there."""
    out = nodes.copy()
    right = nodes[:, 0] > at
    t = np.radians(angle_deg)
    r = nodes[right, 0] - at
    out[right, 0] = at + r * np.cos(t)
    out[right, 2] = r * np.sin(t)
    return out


def barycentric_grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, v), (K,) each: the points i/n, j/n with i + j ≤ n, the weights of the second and
    third corner on a barycentric grid of spacing 1/n over a triangle."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1))
    keep = i + j <= n
    return i[keep] / n, j[keep] / n


def write_keyword_deck(mesh, file, parts: bool = False) -> None:
    """Write ``mesh`` as a standard-format keyword deck (ids from 1); with ``parts`` a *PART
    per part id (title ``part <id>``) and their *SECTION_SHELL 1 (1.0 thick)."""
    lines = ["*KEYWORD"]
    if parts:
        for pid in sorted(set(mesh.parts.tolist())):
            lines += ["*PART", f"part {pid}", f"{pid:10d}{1:10d}"]
        lines += ["*SECTION_SHELL", "         1", "       1.0       1.0       1.0       1.0"]
    lines.append("*NODE")
    lines += [f"{i + 1:8d}{p[0]:16.8f}{p[1]:16.8f}{p[2]:16.8f}" for i, p in enumerate(mesh.nodes)]
    lines.append("*ELEMENT_SHELL")
    lines += [f"{i + 1:8d}{pid:8d}" + "".join(f"{n + 1:8d}" for n in e)
              for i, (e, pid) in enumerate(zip(mesh.elements, mesh.parts))]
    lines.append("*END")
    file.write_text("\n".join(lines) + "\n")


# a two-part keyword deck
DECK = """*KEYWORD
*NODE
       1             0.0             0.0             0.0
       2           100.0             0.0             0.0
       3           100.0           100.0             0.0
       4             0.0           100.0             0.0
*ELEMENT_SHELL
       1       1       1       2       3       4
*END
"""


def write_d3plot(folder, rigid=False):
    """A two-shell, two-part, three-state d3plot written with lasso-python into ``folder``
    (its path): stresses on three layers, plastic strain, thickness, and one shell deleted at
    the last state (``rigid``: the second part rigid, without results, nothing deleted)."""
    from lasso.dyna import ArrayType, D3plot

    plot = D3plot()
    coords = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], np.float32)
    plot.arrays[ArrayType.node_coordinates] = coords
    plot.arrays[ArrayType.node_ids] = np.array([10, 20, 30, 40, 50], np.int32)
    plot.arrays[ArrayType.element_shell_node_indexes] = np.array([[0, 1, 2, 3], [1, 4, 2, 2]],
                                                                 np.int32)
    plot.arrays[ArrayType.element_shell_part_indexes] = np.array([0, 1], np.int32)
    plot.arrays[ArrayType.element_shell_ids] = np.array([7, 8], np.int32)
    plot.arrays[ArrayType.part_ids] = np.array([5, 9], np.int32)
    plot.arrays[ArrayType.global_timesteps] = np.array([0.0, 1e-3, 2e-3], np.float32)
    plot.arrays[ArrayType.node_displacement] = np.stack(
        [coords + [0.0, 0.0, 0.5 * t] for t in range(3)]).astype(np.float32)
    n = 1 if rigid else 2
    stress = np.zeros((3, n, 3, 6), np.float32)
    stress[:, :, 0, 0] = 100.0  # mid surface (first of 3 layers): uniaxial 100
    stress[:, :, 1:, 3] = 50.0  # inner and outer: shear, which must not be picked
    plot.arrays[ArrayType.element_shell_stress] = stress
    plastic = np.zeros((3, n, 3), np.float32)
    plastic[:, :, 0] = [[0.0], [0.01], [0.02]]
    plot.arrays[ArrayType.element_shell_effective_plastic_strain] = plastic
    plot.arrays[ArrayType.element_shell_thickness] = np.full((3, n), 1.5, np.float32)
    if rigid:
        plot.arrays[ArrayType.part_material_type] = np.array([3, 20], np.int32)
    else:
        plot.arrays[ArrayType.element_shell_is_alive] = np.array([[1, 1], [1, 1], [1, 0]],
                                                                  np.float32)
    path = folder / "d3plot"
    plot.write_d3plot(str(path))
    return path


# adversarial stress tensors (xx, yy, zz, xy, yz, zx), all exact in float32: zero, hydrostatic,
# repeated eigenvalues, pure shear (trace 0), compression, and a large hydrostatic part under a
# small deviator (float32 holds 1e6 to 1/16)
ADVERSARIAL_STRESSES = np.array([
    [0, 0, 0, 0, 0, 0],
    [250, 250, 250, 0, 0, 0],
    [-80, -80, -80, 0, 0, 0],
    [100, 0, 0, 0, 0, 0],  # uniaxial: s2 = s3
    [120, 120, 0, 0, 0, 0],  # equibiaxial: s1 = s2
    [0, 0, 0, 40, 0, 0],  # pure shear
    [10, -10, 0, 0, 0, 0],  # pure shear, trace 0 in the diagonal
    [-300, -50, -20, 15, 0, 0],
    [1e6, 1e6 + 0.0625, 1e6, 0.0625, 0, 0],
    [-1e6, -1e6, -1e6 + 0.125, 0, 0.0625, 0.0625],
    [1e6, 1e6, 1e6, 0, 0, 0],
    [3, 3, 3, 1, 1, 1],  # eigenvalues 5, 2, 2
], np.float32)


def write_rich_d3plot(folder, seed=0, permute=False, rename_node=None):
    """A four-state d3plot written with lasso-python into ``folder`` (its path): parts 5 (a
    2 x 2 quad plate), 9 (two quads and a triangle sharing the plate's right edge) and 12
    (rigid: one quad, the fourth shell, without stress, strain or thickness); node ids
    101, 104, ... and shell ids 1001, 1003, ...; coordinates, velocities and accelerations
    drawn from ``seed``; shell stress on three layers (mid, inner, outer) starting with
    :data:`ADVERSARIAL_STRESSES`, then random tensors; plastic strain on three layers;
    thickness; the triangle deleted at the last state, with the largest stress (its failure
    value) there. ``permute`` (True or a seed): the same model with nodes and shells stored
    in another order (every id kept with its node or shell);
    ``rename_node``: (old id, new id) changed in the file."""
    from lasso.dyna import ArrayType, D3plot

    rng = np.random.default_rng(seed)
    n_states = 4
    coords = np.array([[x, y, 0] for y in range(3) for x in range(3)]
                      + [[3, 0, 0], [3, 1, 0], [4, 1, 0], [0, -1, 0], [1, -1, 0]], np.float32)
    quads = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7],
                      [0, 13, 12, 12],  # placeholder, replaced below (rigid quad)
                      [2, 9, 10, 5], [5, 10, 8, 8], [9, 11, 10, 10]], np.int32)
    quads[4] = [12, 13, 1, 0]  # the rigid quad below the plate, sharing nodes 0 and 1
    part_index = np.array([0, 0, 0, 0, 2, 1, 1, 1], np.int32)
    node_ids = 101 + 3 * np.arange(len(coords))
    shell_ids = 1001 + 2 * np.arange(len(quads))
    if rename_node is not None:
        node_ids[node_ids == rename_node[0]] = rename_node[1]
    n_shells, deformable = len(quads), part_index != 2
    moved = coords[None] + rng.normal(0, 0.1, (n_states, len(coords), 3)).cumsum(axis=0)
    moved[0] = coords
    stress = rng.normal(0, 200, (n_states, n_shells, 3, 6))
    flat = stress[:, deformable].reshape(-1, 6)
    flat[:len(ADVERSARIAL_STRESSES)] = ADVERSARIAL_STRESSES
    stress[:, deformable] = flat.reshape(n_states, -1, 3, 6)
    stress[-1, 6] *= 20
    strain = rng.uniform(0, 0.3, (n_states, n_shells, 3))
    thickness = rng.uniform(0.8, 1.6, (n_states, n_shells))
    alive = np.ones((n_states, n_shells))
    alive[-1, 6] = 0
    velocity = rng.normal(0, 5, (n_states, len(coords), 3))
    acceleration = rng.normal(0, 50, (n_states, len(coords), 3))
    node_order = np.arange(len(coords))
    shell_order = np.arange(n_shells)
    if permute is not False:
        order = np.random.default_rng(100 + int(permute))
        node_order, shell_order = order.permutation(len(coords)), order.permutation(n_shells)
    new_index = np.argsort(node_order)  # where each original node is stored
    plot = D3plot()
    a = plot.arrays
    a[ArrayType.node_coordinates] = coords[node_order]
    a[ArrayType.node_ids] = node_ids[node_order].astype(np.int32)
    a[ArrayType.element_shell_node_indexes] = new_index[quads[shell_order]].astype(np.int32)
    a[ArrayType.element_shell_part_indexes] = part_index[shell_order]
    a[ArrayType.element_shell_ids] = shell_ids[shell_order].astype(np.int32)
    a[ArrayType.part_ids] = np.array([5, 9, 12], np.int32)
    a[ArrayType.part_material_type] = np.array([3, 24, 20], np.int32)
    a[ArrayType.global_timesteps] = np.arange(n_states, dtype=np.float32) * 1e-3
    a[ArrayType.node_displacement] = moved[:, node_order].astype(np.float32)
    a[ArrayType.node_velocity] = velocity[:, node_order].astype(np.float32)
    a[ArrayType.node_acceleration] = acceleration[:, node_order].astype(np.float32)
    kept = deformable[shell_order]
    a[ArrayType.element_shell_stress] = stress[:, shell_order][:, kept].astype(np.float32)
    a[ArrayType.element_shell_effective_plastic_strain] = \
        strain[:, shell_order][:, kept].astype(np.float32)
    a[ArrayType.element_shell_thickness] = thickness[:, shell_order][:, kept].astype(np.float32)
    a[ArrayType.element_shell_is_alive] = alive[:, shell_order].astype(np.float32)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "d3plot"
    plot.write_d3plot(str(path))
    return path


def flange_plates():
    """Three parallel plates (mm) as an FEMesh named "plates": part 0 at z = 0 over x 0..100,
    part 1 at z = 1 over x 0..40 (1 mm from part 0), part 2 at z = 30 over x 60..100 (30 mm
    away); y 0..50 for all."""
    from workbench.scene.mesh import FEMesh

    blocks = [quad_grid(20, 10, span=((0, 100), (0, 50)), z=0.0),
              quad_grid(8, 10, span=((0, 40), (0, 50)), z=1.0),
              quad_grid(8, 10, span=((60, 100), (0, 50)), z=30.0)]
    first = np.cumsum([0] + [len(b[0]) for b in blocks[:-1]])
    nodes = np.concatenate([b[0] for b in blocks])
    elements = np.concatenate([b[1] + k for b, k in zip(blocks, first)]).astype(np.int32)
    parts = np.repeat(np.arange(3), [len(b[1]) for b in blocks]).astype(np.int32)
    return FEMesh(nodes=nodes, elements=elements, parts=parts, name="plates")
