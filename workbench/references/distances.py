"""Today's distance tools on the crash2000 part-distance queries (§4.1), for the experiment tables.

The workbench computes, for every node, the exact float64 distance to the nearest element of
*another* part up to a cut-off. Its rule: a node's own parts are the parts of every element that
uses the node; its distance is to the elements of any other part. None of the reference tools
knows parts, so each is run the like-for-like way: nodes are grouped by their set of own parts,
and for each distinct set one structure is built over the triangles of every part *not* in the
set and queried with that group's nodes (a typical car has most nodes in one part, so about one
build per part plus one per set of parts that share nodes). Only fcpw takes the cut-off (as a
search radius); the others find the nearest triangle. Distances above the cut-off become ``inf``
afterwards, as ours.

* ``libigl`` -- ``igl.AABB`` (``init`` + ``squared_distance``): float64, exact point-triangle
  distances; libigl's ``parallel_for`` spreads a call over all cores when it has at least
  10 000 points and runs serially below that.
* ``open3d`` -- ``RaycastingScene.compute_distance``: Embree point queries in float32 (coordinates
  and arithmetic), all cores (TBB). Approximate: its error grows with the coordinates'
  magnitude (on raw car coordinates it has been seen 0.46 mm off where the exact distance was
  1e-9 mm). The scene's BVH is built on its first query; a one-point query right after adding
  the triangles puts that build in ``seconds_build``.
* ``trimesh`` -- ``trimesh.proximity.closest_point``: float64 closest points on the candidates
  of a Python broad phase (KD-tree nearest vertex, then an r-tree box query), one thread. Not
  quite exact: where the two best candidates' *squared* distances differ by less than
  ``trimesh.tol.merge`` (1e-8) it keeps the one whose face normal points at the node, which can
  be up to 1e-8 / (2 d) farther than the nearest (7e-9 mm seen on the car at d = 0.68 mm). It
  needs the optional ``rtree`` package; without it the wrapper uses trimesh's
  ``closest_point_naive`` (every triangle for every point, the true minimum) and says so. Slow,
  so by default it runs on a random sample of nodes (:data:`TRIMESH_SAMPLE`, fixed seed);
  unqueried nodes are NaN.
* ``coal`` -- the FCL successor: a ``BVHModelOBBRSS`` per excluded set and ``coal.distance`` to
  a radius-0 ``Sphere`` at each node (closed-form sphere-triangle distance, float64; the BVH
  traversal with ``rel_err = abs_err = 0`` is exact), one Python call per node, one thread.
  Optional: without the ``coal`` package the result says so (``available`` False).
* ``fcpw`` -- FCPW (Sawhney, *Fastest Closest Points in the West*): ``scene_3D`` with one
  object, a vectorized (SIMD-wide nodes) surface-area BVH, and ``find_closest_points``: float32
  coordinates and arithmetic, approximate like open3d; all cores (one ``std::thread`` per
  hardware thread, queries split evenly). It is the one tool here that takes the cut-off: each
  node's squared search radius is the squared cut-off rounded up to float32, so the search
  prunes there as ours does. Reading the distances out of the returned interaction list (a
  Python loop over its objects) is timed apart (``seconds_extract``), not as query time.

Every wrapper hands the tool coordinates relative to a float64 local origin (the centre of the
bounding box; a float64 subtraction, so nothing is lost) and returns float64 distances in model
units. ``local_origin=False`` hands over the raw coordinates instead, to show what a tool does
with car-scale coordinates (open3d's float32 is the known failure).

The conventions are those of :mod:`workbench.algo.nearest.parts`, so that the tools answer the
same queries: triangles are the mesh's triangulation (quads split along the shorter diagonal,
one topology for every step, measured at the step's coordinates); degenerate elements have no
triangle, so no tool measures to them, yet their parts still count among their nodes' own
parts; a node no element uses is not queried and gets ``inf``; a distance is kept when it is at
most the cut-off, a finite number > 0. Each build covers nearly the whole model, so the cost grows
with the number of distinct own-part sets (parts, plus the sets of parts that share nodes).
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from numbers import Real
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..scene.mesh import FEMesh

__all__ = ["TOOLS", "TRIMESH_SAMPLE", "RefResult", "available_tools", "compare_with_exact",
           "own_part_groups", "reference_part_distances"]

TOOLS = ("libigl", "open3d", "trimesh", "coal", "fcpw")
# trimesh's default number of query nodes (a random sample, fixed seed) when a mesh has more
TRIMESH_SAMPLE = 2000
# trimesh's naive query tiles every triangle for every point: points per call so that a call
# holds about this many (point, triangle) pairs
_NAIVE_PAIRS = 1_000_000


@dataclass
class RefResult:
    """One reference tool's part distances on one mesh.

    ``distance`` (N,) float64 in model units, ``inf`` above the cut-off and for nodes no element
    uses, NaN for nodes the tool was not asked about (a sample, or an unavailable tool);
    ``queried`` (N,) bool marks the nodes it was asked about; ``seconds_build`` and
    ``seconds_query`` are wall seconds summed over the excluded part sets (``seconds_extract``:
    reading results out of the tool's own containers where that is timed apart, fcpw's
    interaction list); ``queries`` is the
    number of nodes queried; ``constraints`` says how the tool ran (API, precision, exactness,
    threads, per excluded part set, sampling, origin); ``available`` is False when the tool is
    not installed or failed, ``reason`` then says why.
    """

    tool: str
    distance: np.ndarray
    seconds_build: float
    seconds_query: float
    queries: int
    constraints: str
    available: bool
    reason: str = ""
    builds: int = 0
    seconds_extract: float = 0.0
    queried: np.ndarray | None = field(default=None, repr=False)
    cutoff: float = math.inf
    local_origin: bool = True

    @property
    def queries_per_second(self) -> float:
        """Nodes queried per second of query time (build excluded); NaN when nothing ran."""
        if not self.queries or self.seconds_query <= 0:
            return math.nan
        return self.queries / self.seconds_query


# ------------------------------------------------------------------------- availability
def _import_error(tool: str) -> str | None:
    """Why ``tool`` cannot be imported, None when it can."""
    module = {"libigl": "igl", "open3d": "open3d", "trimesh": "trimesh", "coal": "coal",
              "fcpw": "fcpw"}[tool]
    try:
        __import__(module)
    except Exception as exc:  # a broken install is as absent as a missing one
        return f"{tool} is not importable ({type(exc).__name__}: {exc})"
    return None


def _has_rtree() -> bool:
    try:
        import rtree  # noqa: F401
    except Exception:
        return False
    return True


def available_tools() -> tuple[str, ...]:
    """The tools of :data:`TOOLS` that import here, in that order."""
    return tuple(t for t in TOOLS if _import_error(t) is None)


# ------------------------------------------------------------------------- own parts
def own_part_groups(mesh: FEMesh) -> list[tuple[np.ndarray, np.ndarray]]:
    """Nodes grouped by their own parts: ``[(parts, nodes), ...]``, ``parts`` the sorted part ids
    of every element using the nodes (empty for nodes no element uses), ``nodes`` sorted node
    indices. Groups come sorted by their part tuples."""
    elements = mesh.elements
    part_ids, part_index = np.unique(mesh.parts, return_inverse=True)
    n_parts = len(part_ids)
    keys = np.unique(elements.astype(np.int64) * n_parts
                     + part_index.astype(np.int64)[:, None])
    node, part = keys // n_parts, keys % n_parts
    count = np.bincount(node, minlength=mesh.n_nodes)
    groups: dict[tuple[int, ...], list[np.ndarray]] = {}
    single = count[node] == 1
    order = np.argsort(part[single], kind="stable")
    single_nodes, single_parts = node[single][order], part[single][order]
    starts = np.flatnonzero(np.r_[True, single_parts[1:] != single_parts[:-1]])
    starts = starts[starts < len(single_parts)]  # none when no node is in one part only
    for begin, end in zip(starts, np.r_[starts[1:], len(single_parts)]):
        groups.setdefault((int(single_parts[begin]),), []).append(single_nodes[begin:end])
    multi = ~single
    if multi.any():
        m_node, m_part = node[multi], part[multi]
        bounds = np.flatnonzero(np.r_[True, m_node[1:] != m_node[:-1], True])
        for begin, end in zip(bounds[:-1], bounds[1:]):
            groups.setdefault(tuple(int(p) for p in m_part[begin:end]), []).append(
                m_node[begin:begin + 1])
    unused = np.flatnonzero(count == 0)
    if len(unused):
        groups[()] = [unused]
    out = []
    for key in sorted(groups):
        out.append((part_ids[list(key)].astype(np.int32) if key else np.zeros(0, np.int32),
                    np.sort(np.concatenate(groups[key])).astype(np.int64)))
    return out


# ------------------------------------------------------------------------- the tools
class _Libigl:
    name = "libigl"

    def __init__(self):
        import igl

        self.igl = igl

    def describe(self, n_points_max: int) -> str:
        threads = ("all cores (libigl parallel_for, calls of >= 10 000 points)"
                   if n_points_max >= 10_000 else "one thread (calls under 10 000 points run "
                   "serially in libigl's parallel_for)")
        return ("igl.AABB init + squared_distance, float64, exact point-triangle distance; "
                f"{threads}")

    def build(self, vertices, triangles):
        tree = self.igl.AABB()
        tri = np.ascontiguousarray(triangles, np.int64)
        tree.init(vertices, tri)
        return tree, vertices, tri

    def query(self, structure, points, cutoff):
        tree, vertices, tri = structure
        squared, _, _ = tree.squared_distance(vertices, tri, points)
        return np.sqrt(np.asarray(squared, np.float64))


class _Open3d:
    name = "open3d"

    def __init__(self):
        import open3d

        self.o3d = open3d

    def describe(self, n_points_max: int) -> str:
        return ("open3d RaycastingScene.compute_distance (Embree point query), float32 "
                "coordinates and arithmetic: approximate; nthreads=0 (TBB, all cores); BVH built "
                "on a one-point query right after add_triangles (counted as build)")

    def build(self, vertices, triangles):
        core = self.o3d.core
        scene = self.o3d.t.geometry.RaycastingScene()
        scene.add_triangles(core.Tensor(np.ascontiguousarray(vertices, np.float32)),
                            core.Tensor(np.ascontiguousarray(triangles, np.uint32)))
        scene.compute_distance(core.Tensor(np.ascontiguousarray(vertices[:1], np.float32)))
        return scene

    def query(self, scene, points, cutoff):
        pts = self.o3d.core.Tensor(np.ascontiguousarray(points, np.float32))
        return scene.compute_distance(pts).numpy().astype(np.float64)


class _Trimesh:
    name = "trimesh"

    def __init__(self):
        import trimesh

        self.trimesh = trimesh
        self.rtree = _has_rtree()

    def describe(self, n_points_max: int) -> str:
        if self.rtree:
            return ("trimesh.proximity.closest_point, float64 closest points on the candidates "
                    "of a Python broad phase (scipy KD-tree nearest vertex, rtree box query); "
                    "not quite exact: where two candidates' squared distances differ by less "
                    "than trimesh.tol.merge (1e-8) it returns the one whose face normal points "
                    "at the node, up to 1e-8 / (2 d) farther than the nearest; one thread")
        return ("trimesh.proximity.closest_point needs the rtree package, absent here: "
                "trimesh.proximity.closest_point_naive instead (every triangle for every node, "
                "float64, exact); one thread")

    def build(self, vertices, triangles):
        mesh = self.trimesh.Trimesh(vertices=vertices, faces=triangles, process=False,
                                    validate=False)
        # build now what the query would build on first use: the r-tree of triangle boxes, or
        # the (K, 3, 3) corner array the naive query tiles
        _ = mesh.triangles_tree if self.rtree else mesh.triangles
        return mesh

    def query(self, mesh, points, cutoff):
        proximity = self.trimesh.proximity
        if self.rtree:
            return np.asarray(proximity.closest_point(mesh, points)[1], np.float64)
        chunk = max(1, _NAIVE_PAIRS // max(1, len(mesh.faces)))
        out = np.empty(len(points))
        for start in range(0, len(points), chunk):
            out[start:start + chunk] = proximity.closest_point_naive(
                mesh, points[start:start + chunk])[1]
        return out


class _Coal:
    name = "coal"

    def __init__(self):
        import coal

        self.coal = coal

    def describe(self, n_points_max: int) -> str:
        return ("coal BVHModelOBBRSS + coal.distance to a radius-0 Sphere per node (closed-form "
                "sphere-triangle distance, float64; DistanceRequest rel_err = abs_err = 0: exact "
                "traversal); one Python call per node, one thread")

    def build(self, vertices, triangles):
        coal = self.coal
        model = coal.BVHModelOBBRSS()
        model.beginModel(len(triangles), len(vertices))
        model.addVertices(np.ascontiguousarray(vertices, np.float64))
        model.addTriangles(np.ascontiguousarray(triangles, np.int64))
        model.endModel()
        return model

    def query(self, model, points, cutoff):
        coal = self.coal
        sphere = coal.Sphere(0.0)
        compute = coal.ComputeDistance(model, sphere)
        request = coal.DistanceRequest()
        request.rel_err = 0.0
        request.abs_err = 0.0
        result = coal.DistanceResult()
        identity = coal.Transform3s()
        at = coal.Transform3s()
        out = np.empty(len(points))
        for i, p in enumerate(points):
            at.setTranslation(p)
            result.clear()
            out[i] = compute(identity, at, request, result)
        return out


class _Fcpw:
    name = "fcpw"

    def __init__(self):
        import fcpw

        self.fcpw = fcpw
        self.seconds_extract = 0.0

    def describe(self, n_points_max: int) -> str:
        return ("fcpw scene_3D, vectorized bvh_surface_area aggregate, find_closest_points: "
                "float32 coordinates and arithmetic, approximate; squared search radius = the "
                "squared cut-off rounded up to float32 (the tool prunes at the cut-off); all "
                f"cores ({os.cpu_count()} std::threads, queries split evenly); reading the "
                "distances out of the interaction list (a Python loop) timed apart")

    def build(self, vertices, triangles):
        fcpw = self.fcpw
        scene = fcpw.scene_3D()
        scene.set_object_count(1)
        scene.set_object_vertices(np.asfortranarray(vertices, np.float32), 0)
        scene.set_object_triangles(np.asfortranarray(triangles, np.int32), 0)
        scene.build(fcpw.aggregate_type.bvh_surface_area, True, False, False)
        return scene

    def query(self, scene, points, cutoff):
        radius_sq = np.float32(cutoff * cutoff)
        if float(radius_sq) < cutoff * cutoff:
            radius_sq = np.nextafter(radius_sq, np.float32(np.inf))
        radii = np.full(len(points), radius_sq, np.float32)
        found = self.fcpw.interaction_3D_list()
        scene.find_closest_points(np.asfortranarray(points, np.float32), radii, found)
        start = time.perf_counter()
        d = np.fromiter((i.d for i in found), np.float64, len(points))
        self.seconds_extract += time.perf_counter() - start
        # no triangle within the radius: fcpw leaves the largest float32 as the distance
        return np.where(d < 1e38, d, np.inf)


_TOOL_CLASSES = {"libigl": _Libigl, "open3d": _Open3d, "trimesh": _Trimesh, "coal": _Coal,
                 "fcpw": _Fcpw}


# ------------------------------------------------------------------------- the queries
def _check_cutoff(cutoff) -> float:
    if isinstance(cutoff, bool) or not isinstance(cutoff, (Real, np.floating, np.integer)):
        raise ValueError(f"cutoff must be a finite number > 0 (model units), got {cutoff!r}")
    value = float(cutoff)
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"cutoff must be a finite number > 0 (model units), got {cutoff!r}")
    return value


def reference_part_distances(tool: str, mesh: FEMesh, cutoff: float, *, step: int = 0,
                             local_origin: bool = True, sample: int | None = None,
                             seed: int = 0) -> RefResult:
    """Every node's distance to the nearest element of another part by reference ``tool`` (one
    of :data:`TOOLS`), ``inf`` above ``cutoff``: the rule and the tools' ways are in the module
    docstring.

    ``step`` picks the time step whose coordinates are measured; ``local_origin`` (default)
    hands the tool coordinates relative to the float64 centre of the bounding box, False the
    raw ones;
    ``sample`` queries at most that many nodes, drawn at random with ``seed`` (None: all nodes,
    except trimesh, which samples :data:`TRIMESH_SAMPLE`; drawn among the nodes elements use);
    unqueried nodes are NaN, nodes no element uses ``inf``.

    An unknown tool, a cut-off that is not a finite number > 0, a step out of range or a sample
    below 1 are refused with ValueError. A tool that is not installed or raises gives a result
    with ``available`` False and the reason, never an exception.
    """
    if tool not in TOOLS:
        raise ValueError(f"unknown distance tool {tool!r}; known: {', '.join(TOOLS)}")
    cutoff = _check_cutoff(cutoff)
    coords = mesh.coordinates(mesh.step_index(step))
    triangulation = mesh.triangulation
    n = mesh.n_nodes
    if sample is None and tool == "trimesh":
        sample = TRIMESH_SAMPLE
    if sample is not None:
        if isinstance(sample, bool) or not isinstance(sample, (int, np.integer)) or sample < 1:
            raise ValueError(f"sample must be a positive integer, got {sample!r}")
    used = mesh.used_nodes()
    queried = np.zeros(n, bool)
    sampled = sample is not None and sample < len(used)
    if sampled:
        queried[np.random.default_rng(seed).choice(used, int(sample), replace=False)] = True
    else:
        queried[used] = True
    distance = np.full(n, np.nan)
    distance[~np.isin(np.arange(n), used)] = np.inf  # used by no element: not measured

    def unavailable(reason: str) -> RefResult:
        return RefResult(tool, np.full(n, np.nan), 0.0, 0.0, 0, "", False, reason, cutoff=cutoff,
                         queried=np.zeros(n, bool), local_origin=bool(local_origin))

    missing = _import_error(tool)
    if missing is not None:
        return unavailable(missing)
    runner = _TOOL_CLASSES[tool]()

    if local_origin:
        origin = (coords[used].min(axis=0) + coords[used].max(axis=0)) / 2.0
    else:
        origin = np.zeros(3)
    points_all = coords - origin  # float64: exact enough, and a copy the tools may keep
    triangles = triangulation.triangles
    triangle_part = mesh.parts[triangulation.element_of]

    seconds_build = seconds_query = 0.0
    builds = queries = largest = 0
    try:
        for own, nodes in own_part_groups(mesh):
            nodes = nodes[queried[nodes]]
            if not len(nodes):
                continue
            targets = triangles[~np.isin(triangle_part, own)]
            if not len(targets):  # nothing of another part to measure to
                distance[nodes] = np.inf
                continue
            used_nodes, local = np.unique(targets, return_inverse=True)
            vertices = np.ascontiguousarray(points_all[used_nodes])
            faces = local.reshape(targets.shape)
            points = np.ascontiguousarray(points_all[nodes])
            start = time.perf_counter()
            structure = runner.build(vertices, faces)
            seconds_build += time.perf_counter() - start
            extracted = getattr(runner, "seconds_extract", 0.0)
            start = time.perf_counter()
            d = runner.query(structure, points, cutoff)
            seconds_query += time.perf_counter() - start
            seconds_query -= getattr(runner, "seconds_extract", 0.0) - extracted
            d = np.asarray(d, np.float64)
            distance[nodes] = np.where(d <= cutoff, d, np.inf)
            builds += 1
            queries += len(nodes)
            largest = max(largest, len(nodes))
    except Exception as exc:  # a reference tool's failure is a result, not a crash
        return unavailable(f"{tool} failed: {type(exc).__name__}: {exc}")

    where = (f"coordinates relative to the float64 local origin {np.round(origin, 3).tolist()}"
             if local_origin else "raw model coordinates")
    limit = ("search radius = the cut-off" if tool == "fcpw" else
             "no cut-off in the API: nearest triangle found")
    how = (f"{runner.describe(largest)}; one structure per excluded part set ({builds} built: "
           f"the triangles of every part but the queried nodes' own parts); {limit}, "
           f"distances above {cutoff:g} set to inf; {where}; {os.cpu_count()} cores here")
    if tool == "fcpw":
        how += f"; reading the distances out took {runner.seconds_extract:.3g} s more"
    if sampled:
        how += (f"; sampled: {queries} of {len(used)} used nodes queried (random, seed {seed}), "
                f"the rest NaN, queries/s on the sample")
    return RefResult(tool, distance, seconds_build, seconds_query, queries, how, True, "",
                     builds=builds, queried=queried, cutoff=cutoff,
                     local_origin=bool(local_origin),
                     seconds_extract=getattr(runner, "seconds_extract", 0.0))


# ------------------------------------------------------------------------- accuracy
def compare_with_exact(exact: ArrayLike, ref: ArrayLike | RefResult, *,
                       tolerance: float = 1e-6) -> dict[str, Any]:
    """A reference tool's distances against the exact ones, node by node.

    ``exact`` (N,) and ``ref`` (N,) (or a :class:`RefResult`) in model units, ``inf`` above the
    cut-off; nodes where ``ref`` is NaN (not queried) are left out. Returns ``compared`` (nodes
    compared), ``both_within`` (nodes within the cut-off for both), ``max_abs_error`` and
    ``max_rel_error`` over those (relative to the exact distance; ``inf`` where the exact distance
    is 0 and the reference is not), ``worst_node`` (index of the largest absolute error, -1 when
    none), ``off`` (nodes off by more than ``tolerance``), ``missed`` (exact within the cut-off,
    reference beyond), ``extra`` (reference within, exact beyond), ``cutoff_disagreements``
    (``missed + extra``), ``flagged`` ((N,) bool: off or disagreeing about the cut-off),
    ``n_flagged`` and ``agree`` (nothing flagged).
    """
    if isinstance(ref, RefResult):
        ref = ref.distance
    exact = np.asarray(exact, np.float64)
    ref = np.asarray(ref, np.float64)
    if exact.shape != ref.shape or exact.ndim != 1:
        raise ValueError(f"exact and ref must be (N,) arrays of one length, got {exact.shape} "
                         f"and {ref.shape}")
    if not tolerance >= 0:
        raise ValueError(f"tolerance must be >= 0, got {tolerance!r}")
    compared = ~np.isnan(ref) & ~np.isnan(exact)
    exact_in = np.isfinite(exact) & compared
    ref_in = np.isfinite(ref) & compared
    both = exact_in & ref_in
    missed = exact_in & ~ref_in
    extra = ref_in & ~exact_in
    error = np.zeros_like(exact)
    error[both] = np.abs(ref[both] - exact[both])
    rel = np.zeros_like(exact)
    positive = both & (exact > 0)
    rel[positive] = error[positive] / exact[positive]
    rel[both & (exact == 0) & (error > 0)] = np.inf
    off = both & (error > tolerance)
    flagged = off | missed | extra
    return dict(
        compared=int(compared.sum()),
        both_within=int(both.sum()),
        max_abs_error=float(error.max()) if both.any() else 0.0,
        max_rel_error=float(rel.max()) if both.any() else 0.0,
        worst_node=int(np.argmax(error)) if both.any() else -1,
        tolerance=float(tolerance),
        off=int(off.sum()),
        missed=int(missed.sum()),
        extra=int(extra.sum()),
        cutoff_disagreements=int(missed.sum() + extra.sum()),
        flagged=flagged,
        n_flagged=int(flagged.sum()),
        agree=not flagged.any(),
    )
