"""Boundary surface of large solid meshes: solid elements per second of ``boundary_surface``.

Models (unit cells on a regular grid, node ids in grid order, LS-DYNA *ELEMENT_SOLID layout),
one case each:

* **hex**: an n x n x n block of hexahedra (full n = 100: 1 000 000 solids, 6 M faces;
  quick n = 20);
* **tet**: an m x m x m block of cells split into 6 Kuhn tetrahedra each (full m = 56:
  1 053 696 solids, 4.2 M faces; quick m = 12);
* **tet-shuffled**: the tet model with randomly permuted node ids and solid order (no
  locality).

Timed: ``boundary_surface(solids, nodes)`` (one untimed warm-up call compiles or loads the
numba kernels). The boundary is checked first: 6 n² quads for the hex block, 12 m² triangles
for the tet block. Rows: ``solids``, ``faces`` and ``solids_per_s`` (of the median); the
design target is >= 2 M solids/s per model on a 2-core machine.

Run: ``workbench bench solid_faces_bench [--quick]``.
"""

from __future__ import annotations

import numpy as np

from workbench.measurement.bench import Case, benchmark

CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
KUHN = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]


def grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes ((n+1)^3, 3) and the (n^3, 8) LS-DYNA hexahedra of an n x n x n unit block."""
    ax = np.arange(n + 1, dtype=np.float64)
    x, y, z = np.meshgrid(ax, ax, ax, indexing="ij")
    nodes = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    idx = np.arange(len(nodes), dtype=np.int32).reshape(n + 1, n + 1, n + 1)
    hexes = np.stack([idx[a:a + n, b:b + n, c:c + n].ravel() for a, b, c in CORNERS], 1)
    return nodes, hexes


def tet_model(m: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and the Kuhn tetrahedra (degenerate 8-node solids) of an m x m x m block."""
    nodes, hexes = grid(m)
    t = hexes[:, KUHN].reshape(-1, 4)
    return nodes, np.concatenate([t, np.repeat(t[:, 3:], 4, axis=1)], axis=1)


def shuffled(nodes: np.ndarray, solids: np.ndarray, seed: int = 0):
    """The same model with node ids and solid order permuted at random."""
    rng = np.random.default_rng(seed)
    relabel = rng.permutation(len(nodes)).astype(np.int32)
    new_nodes = np.empty_like(nodes)
    new_nodes[relabel] = nodes
    return new_nodes, relabel[solids][rng.permutation(len(solids))]


@benchmark("solid_faces_bench", "boundary surface of large solid meshes, solids per second",
           cases=[Case("hex", {"cells": 100}, {"cells": 20}),
                  Case("tet", {"cells": 56}, {"cells": 12}),
                  Case("tet-shuffled", {"cells": 56}, {"cells": 12})])
def solid_faces(bench, cells: int) -> None:
    from workbench.scene.solids import boundary_surface

    if bench.case.name == "hex":
        nodes, solids = grid(cells)
        expect = 6 * cells**2
    else:
        nodes, solids = tet_model(cells)
        expect = 12 * cells**2
        if bench.case.name == "tet-shuffled":
            nodes, solids = shuffled(nodes, solids)
    elements, _, _ = boundary_surface(solids, nodes)
    if len(elements) != expect:
        raise ValueError(f"{bench.case.name}: {len(elements)} boundary faces, expected {expect}")
    t = bench.time("boundary_surface", lambda: boundary_surface(solids, nodes),
                   solids=len(solids), faces=len(elements))
    bench.rows[-1]["solids_per_s"] = len(solids) / (t.wall_ms / 1e3)
