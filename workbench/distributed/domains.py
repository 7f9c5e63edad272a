"""Domain decomposition of an FE mesh's triangles for sort-last rendering (es2008, section 1):
each domain is rendered on its own and the frames are composited by depth
(:mod:`workbench.algo.composite.merge`).

A partition is a list of sorted int64 arrays of indices into ``mesh.triangles`` (the
triangulation of the elements, quads split in two), every triangle in exactly one array.
"""

from __future__ import annotations

import numpy as np

from ..scene.mesh import FEMesh

METHODS = ("space", "part")


def split_domains(mesh: FEMesh, count: int, by: str = "space") -> list[np.ndarray]:
    """A partition of ``mesh``'s triangles into ``count`` domains: ``count`` sorted int64
    arrays of triangle indices (into ``mesh.triangles``), each non-empty, together covering
    every triangle exactly once.

    * ``by="space"``: recursive bisection of the triangle centroids (coordinates of step 0, in
      model units). A group that is to become c domains is cut across the longest axis of its
      centroids' bounding box (the first such axis on a tie) into the ⌊c/2⌋ · n / c (rounded
      down) lowest centroids — ties in position go by triangle index — and the rest, which
      become ⌊c/2⌋ and c − ⌊c/2⌋ domains. Every domain gets ⌊K/count⌋ or ⌈K/count⌉ of the K
      triangles, for any ``count``. Domains come in bisection order (the low side first).
    * ``by="part"``: whole parts (``mesh.parts`` of each triangle's element), grouped greedily
      into ``count`` domains balanced by triangle count: parts by decreasing triangle count
      (then part id) each join the domain with the fewest triangles so far (then the first
      one). Domains are ordered by their lowest triangle index. Parts without triangles
      (degenerate elements only) take no part.

    Refused (ValueError): ``count`` not an integer ≥ 1, ``count`` above the number of
    triangles, ``by="part"`` with fewer parts than ``count``, an unknown ``by``.
    """
    if by not in METHODS:
        raise ValueError(f"unknown domain split {by!r}: expected one of {', '.join(METHODS)}")
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ValueError(f"domain count must be an integer >= 1, got {count!r}")
    count = int(count)
    triangles = mesh.triangles
    if count > len(triangles):
        raise ValueError(f"{mesh.name}: cannot split {len(triangles)} triangles into "
                         f"{count} non-empty domains")
    if by == "part":
        return _by_part(mesh, count)
    centroids = mesh.coordinates(0)[triangles].mean(axis=1)
    domains: list[np.ndarray] = []
    _bisect(centroids, np.arange(len(triangles), dtype=np.int64), count, domains)
    return domains


def _bisect(centroids: np.ndarray, indices: np.ndarray, count: int, out: list) -> None:
    """Append ``count`` domains of ``indices`` (sorted int64) to ``out``, low side first."""
    if count == 1:
        out.append(np.sort(indices))
        return
    points = centroids[indices]
    axis = int(np.argmax(points.max(axis=0) - points.min(axis=0)))
    low_count = count // 2
    n_low = len(indices) * low_count // count
    order = np.lexsort((indices, points[:, axis]))
    _bisect(centroids, indices[order[:n_low]], low_count, out)
    _bisect(centroids, indices[order[n_low:]], count - low_count, out)


def _by_part(mesh: FEMesh, count: int) -> list[np.ndarray]:
    part_of = mesh.parts[mesh.triangulation.element_of]
    parts, sizes = np.unique(part_of, return_counts=True)
    if len(parts) < count:
        raise ValueError(f"{mesh.name}: {len(parts)} parts with triangles cannot make "
                         f"{count} domains of whole parts")
    totals = np.zeros(count, np.int64)
    group_of_part = {}
    for i in sorted(range(len(parts)), key=lambda i: (-sizes[i], parts[i])):
        group = int(np.argmin(totals))
        group_of_part[int(parts[i])] = group
        totals[group] += sizes[i]
    group_of = np.array([group_of_part[int(p)] for p in parts])[np.searchsorted(parts, part_of)]
    domains = [np.flatnonzero(group_of == g).astype(np.int64) for g in range(count)]
    return sorted(domains, key=lambda d: int(d[0]))
