"""Boundary surface of large solid meshes: solid elements per second of ``boundary_surface``.

Models (unit cells on a regular grid, node ids in grid order, LS-DYNA *ELEMENT_SOLID layout):

* **hex**: an n x n x n block of hexahedra (default n = 100: 1 000 000 solids, 6 M faces);
* **tet**: an m x m x m block of cells split into 6 Kuhn tetrahedra each
  (default m = 56: 1 053 696 solids, 4.2 M faces);
* **tet-shuffled**: the tet model with randomly permuted node ids and solid order (no locality).

Each model: one warm-up call (numba kernels compile or load from cache), then ``--repeat`` timed
calls (wall seconds, ``time.perf_counter``); the median is reported with solids per second.
The boundary is checked: 6 n^2 quads for the hex block, 12 m^2 triangles for the tet block.
Target: >= 2 M solids/s per model on the 2-core development machine.

Run: ``.venv/bin/python benchmarks/solid_faces_bench.py [--hex 100] [--tet 56] [--repeat 5]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from workbench.scene.solids import boundary_surface

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
    nodes, hexes = grid(m)
    t = hexes[:, KUHN].reshape(-1, 4)
    return nodes, np.concatenate([t, np.repeat(t[:, 3:], 4, axis=1)], axis=1)


def shuffled(nodes: np.ndarray, solids: np.ndarray, seed: int = 0):
    rng = np.random.default_rng(seed)
    relabel = rng.permutation(len(nodes)).astype(np.int32)
    new_nodes = np.empty_like(nodes)
    new_nodes[relabel] = nodes
    return new_nodes, relabel[solids][rng.permutation(len(solids))]


def bench(name: str, nodes: np.ndarray, solids: np.ndarray, expect: int, repeat: int) -> float:
    elements, _, _ = boundary_surface(solids, nodes)  # warm-up
    assert len(elements) == expect, (name, len(elements), expect)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        boundary_surface(solids, nodes)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    rate = len(solids) / med
    print(f"{name:13s} {len(solids):>9,d} solids  {len(elements):>8,d} boundary faces  "
          f"median {med:6.3f} s (min {min(times):.3f}, max {max(times):.3f})  "
          f"{rate / 1e6:5.2f} M solids/s  {'ok' if rate >= 2e6 else 'BELOW 2 M/s'}")
    return rate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hex", type=int, default=100, help="hex block edge in cells")
    ap.add_argument("--tet", type=int, default=56, help="tet block edge in cells (x 6 tets)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-shuffled", action="store_true", help="skip the shuffled tet model")
    args = ap.parse_args()
    nodes, hexes = grid(args.hex)
    bench("hex", nodes, hexes, 6 * args.hex**2, args.repeat)
    del nodes, hexes
    nodes, tets = tet_model(args.tet)
    bench("tet", nodes, tets, 12 * args.tet**2, args.repeat)
    if not args.no_shuffled:
        bench("tet-shuffled", *shuffled(nodes, tets), 12 * args.tet**2, args.repeat)


if __name__ == "__main__":
    main()
