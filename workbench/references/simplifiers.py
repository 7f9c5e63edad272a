"""Reference simplifiers and distance tools, wrapped to one shape for the experiment tables.

The workbench's own decimator and metric are in :mod:`workbench.algo`; these are today's tools it
is measured against, run as each library documents them, each timed around its own call:

* simplifiers at a given triangle count: pymeshlab's quadric edge collapse, libigl's ``qslim``
  and ``decimate``, open3d's quadric decimation (all move or create vertices) and meshoptimizer's
  ``meshopt_simplify`` (an index array into the same vertices, like ours);
* distances: pymeshlab's sampled Hausdorff, libigl's ``hausdorff`` and open3d's float32
  ``RaycastingScene.compute_distance`` at given points.

A tool that fails or returns an empty mesh gives a result with ``failure`` set, never an
exception: the tables report it. Inputs are float64 vertices (N, 3) and int triangles (K, 3).

Every result states the constraints it ran under, as the tables print them: ``scope`` ("whole
mesh": the tool sees one surface and may collapse across part borders; "per part": each part
simplified on its own, as ours), ``borders`` (the parts' borders: "free", "locked" -- every
border vertex of every part kept in place --, or "weighted" -- only penalised) and whether the
vertices are kept (an index array into the input's vertices) or moved.
:func:`simplify_per_part` runs each tool per part with its border constraint, as far as the
installed version offers one (checked by the tests, not taken from the documentation):

* pymeshlab ``preserveboundary=True`` keeps every border vertex; ``optimalplacement=False``
  also keeps every other vertex (collapses onto an end point);
* meshoptimizer ``SIMPLIFY_LOCK_BORDER`` keeps every border vertex;
* open3d only weights the border quadrics (``boundary_weight``): border vertices still slide
  and move, so its per-part row is "weighted", not locked;
* libigl's ``qslim`` and ``decimate`` have no border option: per part with borders free. They
  assume an oriented manifold, so each connected component is oriented first
  (``igl.bfs_orient``); input that stays non-manifold is a failure, not run.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["Simplified", "SIMPLIFIERS", "PART_SIMPLIFIERS", "simplify_with", "simplify_per_part",
           "part_border_vertices", "pymeshlab_hausdorff", "igl_hausdorff", "open3d_distances"]


@dataclass
class Simplified:
    """A reference simplifier's output: vertices (V', 3) float64, triangles (K', 3) int64 into
    them, wall seconds, whether the vertices are the input's (an index array only), and why it
    failed (None when it did not). ``scope`` and ``borders`` name the constraints it ran under
    (see the module notes); ``parts`` (K',) labels the output triangles of a per-part run."""

    method: str
    vertices: np.ndarray
    triangles: np.ndarray
    seconds: float
    shares_vertices: bool
    failure: str | None = None
    scope: str = "whole mesh"
    borders: str = "free"
    parts: np.ndarray | None = None

    @property
    def vertices_kept(self) -> str:
        """"kept" for an index array into the input's vertices, else "moved"."""
        return "kept" if self.shares_vertices else "moved"


def _pymeshlab_quadric(v, f, target, optimal_placement=True, preserve_boundary=True):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f.astype(np.int32)))
    ms.meshing_decimation_quadric_edge_collapse(targetfacenum=int(target),
                                                preserveboundary=preserve_boundary,
                                                preservenormal=True,
                                                optimalplacement=optimal_placement)
    m = ms.current_mesh()
    if optimal_placement:
        return m.vertex_matrix(), m.face_matrix(), False
    return v, _indices_into(v, m.vertex_matrix(), m.face_matrix()), True


def _pymeshlab_kept(v, f, target):
    return _pymeshlab_quadric(v, f, target, optimal_placement=False)


def _pymeshlab_free(v, f, target):
    return _pymeshlab_quadric(v, f, target, preserve_boundary=False)


def _indices_into(v, u, g):
    """Triangles g into vertices u, re-indexed into v; u must hold copies of rows of v (a tool
    that returns a subset of its input's vertices). ValueError when a vertex is not found."""
    fields = [("x", "f8"), ("y", "f8"), ("z", "f8")]
    keys = np.ascontiguousarray(v, np.float64).view(fields).ravel()
    wanted = np.ascontiguousarray(u, np.float64).view(fields).ravel()
    order = np.argsort(keys)
    at = np.minimum(np.searchsorted(keys[order], wanted), len(keys) - 1)
    rows = order[at]
    if not np.array_equal(v[rows], np.asarray(u, np.float64)):
        raise ValueError("the tool moved a vertex it was to keep")
    return rows[np.asarray(g, np.int64)]


# extra address space a libigl decimation may take before it is stopped (bytes): on an
# inconsistently oriented part of the car its qslim allocated without bound
_IGL_HEADROOM = 2 << 30


@contextlib.contextmanager
def _address_space_capped(headroom: int):
    """Within the block, allocations beyond the process's current address space plus
    ``headroom`` bytes fail (MemoryError / std::bad_alloc) instead of exhausting the machine;
    a no-op where the limit cannot be read or set."""
    try:
        import resource

        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        with open("/proc/self/statm") as fh:
            current = int(fh.read().split()[0]) * resource.getpagesize()
        cap = current + headroom
        if hard != resource.RLIM_INFINITY:
            cap = min(cap, hard)
        resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    except (ImportError, OSError, ValueError):
        yield
        return
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _repeated_directed_edges(f) -> int:
    """How many directed edges occur in more than one triangle (0 for a consistently oriented
    edge-manifold mesh)."""
    d = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).astype(np.int64)
    _, counts = np.unique(d[:, 0] * (int(d.max()) + 1) + d[:, 1], return_counts=True)
    return int((counts > 1).sum())


def _igl(name):
    def run(v, f, target):
        import igl

        # libigl's decimation assumes a consistently oriented manifold; FE meshes are wound
        # element by element, so each connected component is oriented first
        oriented, _ = igl.bfs_orient(np.asfortranarray(f, np.int32))
        repeated = _repeated_directed_edges(np.asarray(oriented))
        if repeated:
            raise ValueError(f"not an oriented manifold ({repeated} directed edges repeat "
                             "after orienting): libigl's decimation is not run")
        # returns (U, G, J, I): vertices, faces, birth faces, birth vertices
        with _address_space_capped(_IGL_HEADROOM):
            u, g, _, _ = getattr(igl, name)(np.asfortranarray(v),
                                            np.asfortranarray(oriented, np.int32), int(target))
        return u, g, False
    return run


def _open3d_quadric(v, f, target, boundary_weight=1.0):
    import open3d as o3d

    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v),
                                     o3d.utility.Vector3iVector(f.astype(np.int32)))
    out = mesh.simplify_quadric_decimation(target_number_of_triangles=int(target),
                                           boundary_weight=float(boundary_weight))
    return np.asarray(out.vertices), np.asarray(out.triangles), False


def _open3d_weighted(v, f, target):
    # the heaviest weight that still behaves: far larger ones keep fewer border vertices
    return _open3d_quadric(v, f, target, boundary_weight=1e3)


def _meshopt(v, f, target, lock_border=False):
    import meshoptimizer

    # float32 positions, relative to the centre so that far-away models keep their digits;
    # only the vertices f uses are passed (a per-part call would otherwise see them all)
    used, local = np.unique(f, return_inverse=True)
    centre = (v[used].min(axis=0) + v[used].max(axis=0)) / 2
    positions = np.ascontiguousarray(v[used] - centre, np.float32)
    indices = np.ascontiguousarray(local.reshape(-1), np.uint32)
    out = np.empty_like(indices)
    options = meshoptimizer.SIMPLIFY_LOCK_BORDER if lock_border else 0
    n = meshoptimizer.simplify(out, indices, positions, target_index_count=3 * int(target),
                               target_error=1.0, options=options)
    return v, used[out[:n].astype(np.int64)].reshape(-1, 3), True


def _meshopt_locked(v, f, target):
    return _meshopt(v, f, target, lock_border=True)


#: the reference simplifiers by name, on the whole mesh: part borders free (pymeshlab's open
#: boundary too)
SIMPLIFIERS = {
    "pymeshlab quadric": _pymeshlab_free,
    "libigl qslim": _igl("qslim"),
    "libigl decimate": _igl("decimate"),
    "open3d quadric": _open3d_quadric,
    "meshoptimizer simplify": _meshopt,
}


# per part: (runner, what it does to the part borders)
PART_SIMPLIFIERS = {
    "pymeshlab quadric": (_pymeshlab_quadric, "locked"),
    "pymeshlab quadric, vertices kept": (_pymeshlab_kept, "locked"),
    "libigl qslim": (_igl("qslim"), "free"),
    "libigl decimate": (_igl("decimate"), "free"),
    "open3d quadric": (_open3d_weighted, "weighted"),
    "meshoptimizer simplify": (_meshopt_locked, "locked"),
}


def part_border_vertices(triangles: ArrayLike, parts: ArrayLike) -> np.ndarray:
    """Sorted ids of the vertices on a border of some part: on an edge with one triangle of
    that part (triangles (K, 3) int, parts (K,) labels)."""
    t = np.asarray(triangles, np.int64)
    p = np.asarray(parts, np.int64)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    keyed = np.concatenate([np.tile(p, 3)[:, None], e], 1)
    rows, counts = np.unique(keyed, axis=0, return_counts=True)
    return np.unique(rows[counts == 1, 1:])


def simplify_with(method: str, vertices: ArrayLike, triangles: ArrayLike,
                  target_triangles: int) -> Simplified:
    """Simplify with reference ``method`` (a key of :data:`SIMPLIFIERS`) towards
    ``target_triangles``; failures and empty outputs are reported in ``failure``."""
    try:
        run = SIMPLIFIERS[method]
    except KeyError:
        raise ValueError(f"unknown simplifier {method!r}; known: {sorted(SIMPLIFIERS)}") from None
    v = np.ascontiguousarray(vertices, np.float64)
    f = np.ascontiguousarray(triangles, np.int64)
    start = time.perf_counter()
    try:
        u, g, shares = run(v, f, target_triangles)
    except Exception as exc:  # a reference tool's failure is a result, not a crash
        return Simplified(method, np.zeros((0, 3)), np.zeros((0, 3), np.int64),
                          time.perf_counter() - start, False, f"{type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - start
    u = np.asarray(u, np.float64).reshape(-1, 3)
    g = np.asarray(g, np.int64).reshape(-1, 3)
    failure = None if len(g) else "returned an empty mesh"
    return Simplified(method, u, g, seconds, shares, failure)


def simplify_per_part(method: str, vertices: ArrayLike, triangles: ArrayLike, parts: ArrayLike,
                      targets: Mapping[int, int]) -> Simplified:
    """Simplify each part on its own with reference ``method`` (a key of
    :data:`PART_SIMPLIFIERS`), part ``label`` towards ``targets[label]`` triangles, under that
    tool's border constraint; the output is the parts' results together (``parts`` labels its
    triangles; vertices concatenated per part for tools that move them, the input's for tools
    that keep them). ``seconds`` is the sum over parts. A part whose tool fails or gives
    nothing makes the whole result a failure naming the part. ValueError for an unknown method
    or a label without a target."""
    try:
        run, borders = PART_SIMPLIFIERS[method]
    except KeyError:
        raise ValueError(f"unknown simplifier {method!r}; known: {sorted(PART_SIMPLIFIERS)}") \
            from None
    v = np.ascontiguousarray(vertices, np.float64)
    f = np.ascontiguousarray(triangles, np.int64)
    p = np.asarray(parts)
    labels = np.unique(p)
    missing = [int(x) for x in labels if x not in targets]
    if missing:
        raise ValueError(f"no target for parts {missing}")
    out_v, out_f, out_p = [], [], []
    offset, seconds, shares = 0, 0.0, True
    for label in labels:
        own = f[p == label]
        used, local = np.unique(own, return_inverse=True)
        start = time.perf_counter()
        try:
            u, g, shares = run(v[used], local.reshape(-1, 3), max(int(targets[label]), 1))
            failure = None if len(g) else "returned an empty mesh"
        except Exception as exc:  # a reference tool's failure is a result, not a crash
            failure = f"{type(exc).__name__}: {exc}"
        seconds += time.perf_counter() - start
        if failure:
            return Simplified(method, np.zeros((0, 3)), np.zeros((0, 3), np.int64), seconds,
                              False, f"part {label}: {failure}", "per part", borders)
        g = np.asarray(g, np.int64).reshape(-1, 3)
        if shares:
            out_f.append(used[g])
        else:
            out_v.append(np.asarray(u, np.float64).reshape(-1, 3))
            out_f.append(g + offset)
            offset += len(out_v[-1])
        out_p.append(np.full(len(g), label, p.dtype))
    vertices_out = v if shares else np.concatenate(out_v)
    return Simplified(method, vertices_out, np.concatenate(out_f), seconds, shares, None,
                      "per part", borders, np.concatenate(out_p))


def pymeshlab_hausdorff(va: ArrayLike, fa: ArrayLike, vb: ArrayLike, fb: ArrayLike,
                        samples: int) -> dict[str, float]:
    """pymeshlab's one-sided sampled Hausdorff from mesh A to mesh B with ``samples`` samples
    (vertices, edges and faces of A): ``max``, ``mean``, ``rms`` in model units and ``seconds``."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=np.asarray(va, np.float64),
                               face_matrix=np.asarray(fa, np.int32)))
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=np.asarray(vb, np.float64),
                               face_matrix=np.asarray(fb, np.int32)))
    start = time.perf_counter()
    out = ms.get_hausdorff_distance(sampledmesh=0, targetmesh=1, samplevert=True, sampleedge=True,
                                    sampleface=True, samplenum=int(samples))
    return dict(max=float(out["max"]), mean=float(out["mean"]), rms=float(out["RMS"]),
                seconds=time.perf_counter() - start)


def igl_hausdorff(va: ArrayLike, fa: ArrayLike, vb: ArrayLike,
                  fb: ArrayLike) -> dict[str, float]:
    """libigl's ``hausdorff`` (symmetric, as documented) and its seconds."""
    import igl

    start = time.perf_counter()
    value = igl.hausdorff(np.asarray(va, np.float64), np.asarray(fa, np.int64),
                          np.asarray(vb, np.float64), np.asarray(fb, np.int64))
    return dict(value=float(value), seconds=time.perf_counter() - start)


def open3d_distances(points: ArrayLike, vb: ArrayLike, fb: ArrayLike) -> dict[str, Any]:
    """open3d's ``RaycastingScene.compute_distance`` (float32) from ``points`` to mesh B: the
    distances (float64 copy), their max, and seconds (scene build included)."""
    import open3d as o3d

    start = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(np.asarray(vb, np.float32)),
                        o3d.core.Tensor(np.asarray(fb, np.uint32)))
    d = scene.compute_distance(o3d.core.Tensor(np.asarray(points, np.float32))).numpy()
    d = d.astype(np.float64)
    return dict(distances=d, max=float(d.max()) if len(d) else 0.0,
                seconds=time.perf_counter() - start)
