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
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

__all__ = ["Simplified", "SIMPLIFIERS", "simplify_with", "pymeshlab_hausdorff", "igl_hausdorff",
           "open3d_distances"]


@dataclass
class Simplified:
    """A reference simplifier's output: vertices (V', 3) float64, triangles (K', 3) int64 into
    them, wall seconds, whether the vertices are the input's (an index array only), and why it
    failed (None when it did not)."""

    method: str
    vertices: np.ndarray
    triangles: np.ndarray
    seconds: float
    shares_vertices: bool
    failure: str | None = None


def _pymeshlab_quadric(v, f, target):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f.astype(np.int32)))
    ms.meshing_decimation_quadric_edge_collapse(targetfacenum=int(target), preserveboundary=True,
                                                preservenormal=True)
    m = ms.current_mesh()
    return m.vertex_matrix(), m.face_matrix(), False


def _igl(name):
    def run(v, f, target):
        import igl

        # returns (U, G, J, I): vertices, faces, birth faces, birth vertices
        u, g, _, _ = getattr(igl, name)(np.asfortranarray(v), np.asfortranarray(f, np.int32),
                                        int(target))
        return u, g, False
    return run


def _open3d_quadric(v, f, target):
    import open3d as o3d

    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v),
                                     o3d.utility.Vector3iVector(f.astype(np.int32)))
    out = mesh.simplify_quadric_decimation(target_number_of_triangles=int(target))
    return np.asarray(out.vertices), np.asarray(out.triangles), False


def _meshopt(v, f, target):
    import meshoptimizer

    # float32 positions, relative to the centre so that far-away models keep their digits
    centre = (v.min(axis=0) + v.max(axis=0)) / 2
    positions = np.ascontiguousarray(v - centre, np.float32)
    indices = np.ascontiguousarray(f, np.uint32).ravel()
    out = np.empty_like(indices)
    n = meshoptimizer.simplify(out, indices, positions, target_index_count=3 * int(target),
                               target_error=1.0)
    return v, out[:n].reshape(-1, 3).astype(np.int64), True


SIMPLIFIERS = {
    "pymeshlab quadric": _pymeshlab_quadric,
    "libigl qslim": _igl("qslim"),
    "libigl decimate": _igl("decimate"),
    "open3d quadric": _open3d_quadric,
    "meshoptimizer simplify": _meshopt,
}


def simplify_with(method: str, vertices, triangles, target_triangles: int) -> Simplified:
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


def pymeshlab_hausdorff(va, fa, vb, fb, samples: int) -> dict:
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


def igl_hausdorff(va, fa, vb, fb) -> dict:
    """libigl's ``hausdorff`` (symmetric, as documented) and its seconds."""
    import igl

    start = time.perf_counter()
    value = igl.hausdorff(np.asarray(va, np.float64), np.asarray(fa, np.int64),
                          np.asarray(vb, np.float64), np.asarray(fb, np.int64))
    return dict(value=float(value), seconds=time.perf_counter() - start)


def open3d_distances(points, vb, fb) -> dict:
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
