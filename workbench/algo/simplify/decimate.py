"""The entry point of the decimation: :func:`hausdorff_decimate` and its result,
:class:`Decimation`.

The input is checked and brought to normal form (:mod:`~workbench.algo.simplify.inputs`), the
vertices that never move and the feature lines are found
(:mod:`~workbench.algo.simplify.constraints`), one compiled call does every collapse
(:mod:`~workbench.algo.simplify.collapse`) and the final bounds are computed from the supports
(:mod:`~workbench.algo.simplify.certify`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .certify import _final_bounds, certificate_rounding, certification_depths
from .collapse import _decimate
from .constraints import _constraints
from .inputs import (
    _box_centre,
    _check_inputs,
    _distinct_faces,
    _part_tolerances,
    _quadrics,
    _repeated_index,
    _unit_normals,
)
from .rules import REJECT_REASONS
from .state import Originals, Surface


@dataclass
class Decimation:
    """Result of :func:`hausdorff_decimate`.

    ``triangles`` index the caller's vertex array (no vertex is moved or added); ``parts`` is
    the part label of each output triangle. ``part_labels`` (P,) are the input's part labels,
    sorted, and ``tol_abs`` (P,) each one's tolerance in model units (:meth:`tol_for` looks one
    up by label). ``bounds`` has one entry per input triangle: a certified upper bound of the
    largest distance from a point of that triangle to the simplified surface (model units; NaN
    for input triangles with a repeated vertex index, which were dropped); ``certified_max`` is
    their maximum, an upper bound of the one-sided Hausdorff distance original → simplified.
    These bounds are certificates that the tolerance holds, measured against the few faces
    that certify each triangle; they can be far above the true distance (flat parts often sit
    within micrometres of the result yet report a bound near tol). For the distance itself use
    an exact metric such as :mod:`workbench.algo.hausdorff`.
    ``collapses`` counts half-edge collapses done, ``rejected`` the collapses refused, by
    reason (see :mod:`~workbench.algo.simplify.rules`), ``seconds`` the wall time of the call,
    ``passes`` how often the queue was filled. ``source`` (K',) int64 is the input triangle each
    output triangle descends from (a collapse renames a corner of a triangle, never merges
    two): its element, its fields and whether it is drawn at a state. ``states_certified`` is
    the number of coordinate sets the bounds hold at (1: only the vertices the decimation saw)
    and ``bounds`` the largest over them.
    ``bytes_saved`` is the size of the vertex array a separate simplified mesh would store
    (referenced vertices × 3 × 8 bytes for float64; multiply by the number of time steps for a
    time-dependent result), which sharing the original buffer saves.
    """

    triangles: np.ndarray
    parts: np.ndarray
    part_labels: np.ndarray
    tol_abs: np.ndarray
    collapses: int
    rejected: dict[str, int]
    seconds: float
    bounds: np.ndarray
    certified_max: float
    bytes_saved: int
    input_triangles: int
    passes: int
    dropped: int = 0
    notes: list[str] = field(default_factory=list)
    states_certified: int = 1
    source: np.ndarray | None = None

    def tol_for(self, label: int) -> float:
        """The tolerance (model units) of the part labelled ``label``; KeyError if none."""
        hit = np.flatnonzero(self.part_labels == label)
        if len(hit) == 0:
            raise KeyError(f"no part {label}")
        return float(self.tol_abs[hit[0]])

    @property
    def ratio(self) -> float:
        """Output triangles per input triangle."""
        return len(self.triangles) / max(self.input_triangles, 1)


def hausdorff_decimate(vertices, triangles, tol: float = 0.005, *, relative: bool = True,
                       parts=None, feature_deg: float = 30.0, keep_boundary: bool = True,
                       max_normal_deg: float = 60.0, max_depth: int | None = None,
                       passes: int = 2, slide_shared: bool = True,
                       feature_min_length: float | None = 10.0, states=None,
                       alive=None) -> Decimation:
    """Decimate a triangle mesh by half-edge collapses within a certified one-sided Hausdorff
    distance from the original surface (crash2000, section 3.2).

    ``vertices`` (N, 3) float64 model units, ``triangles`` (K, 3) integer indices; the result
    indexes the SAME vertex array (vertices are never moved or created). ``tol`` is, with
    ``relative=True`` (default), a fraction of each part's bounding-sphere diameter -- the sphere
    around the part's axis-aligned bounding box (centre = box centre, diameter = box diagonal,
    as :meth:`FEMesh.bounding_sphere`), which is at most √3 times the smallest enclosing sphere;
    0.005 is the paper's 0.5 %. With ``relative=False`` it is a length in model units.

    ``parts`` (K,) labels decimate each part on its own, against its own tolerance: a part's
    original triangles are certified against that part's faces only. With ``slide_shared``
    (default) a vertex inside the common boundary of two parts slides along it in both parts at
    once (:mod:`~workbench.algo.simplify.constraints` says which vertices are corners); without
    it, and always where three or more parts meet, vertices used by more than one part never
    move. Either way every part stays drawable on its own and shares the vertices along its
    borders with its neighbours.
    Feature edges (the angle between the orientation-corrected normals of their two faces above
    ``feature_deg`` degrees, on a connected set of such edges at least ``feature_min_length``
    times its part's tolerance long in all: a shorter crease is detail the tolerance lets go,
    like the noise of a scanned surface; None keeps every crease), the common boundaries of
    parts and, with ``keep_boundary``, boundary edges are kept as polylines: a vertex on two
    of them only slides along them, a vertex on one or on three or more, or where its polyline
    turns by more than ``feature_deg``, never moves. ``max_normal_deg`` bounds how far a changed
    face may turn per collapse and from the face it descends from; ``max_depth`` is the
    subdivision depth of the certification (deeper certifies closer to tol, slower): None
    (default) picks it per input triangle from its longest edge and its tolerance
    (:func:`certification_depths`, 5 to 10), an integer fixes it;
    ``passes`` is how often the queue is refilled with every remaining half-edge.

    ``states`` (S, N, 3) float64, optional, are further coordinates of the same vertices (the
    other time steps of a result): a collapse is then accepted only when the bound holds with
    the vertices at ``vertices`` AND at each of ``states``, the tolerance of a part being the
    one at ``vertices``. The rules (normals, degenerate faces) and the order of the collapses
    see ``vertices`` only. ``alive`` (S + 1, K) bool, optional, says which input triangles are
    drawn at ``vertices`` and at each of ``states`` (eroded elements are not): the triangles
    with the same pattern of states form a group of their own within their part, decimated
    apart from the others with the common boundaries of groups kept like those of parts, so
    that a simplified triangle is drawn at exactly the states its input triangles are, and
    an input triangle is certified only at the states it is drawn at.

    Guarantee: every point of every input triangle is within its part's tolerance of the
    simplified surface (at every certified state at which it is drawn), certified by the
    convexity bound of
    :func:`~workbench.algo.nearest.triangle.triangle_bounds` (recomputed with that function for the
    returned ``bounds``), not by sampling. Computation runs in float64 relative to the centre
    of the mesh's bounding box, so far-away models keep their digits.

    Takes more than 12 arguments because it is the public call of the decimation: the mesh and
    the tolerance, then keyword options that each change one rule, default as the paper does.

    Non-manifold input (edges with three or more faces, bow-tie vertices) and duplicate faces
    are accepted: what cannot be collapsed safely is left as it is, duplicate faces are kept
    once (the others are certified against it), zero-area triangles keep their vertices in
    place, triangles with a repeated vertex index are dropped (they have no area; their
    ``bounds`` are NaN). Refused with ValueError: arrays of
    the wrong shape or type, indices out of range, non-finite coordinates, no triangles, a
    non-positive tol, angles out of range, max_depth outside [0, 12], passes < 1, a negative
    feature_min_length.
    """
    start = time.perf_counter()
    v_in, t_in, tol, p_in = _check_inputs(vertices, triangles, tol, parts, feature_deg,
                                          max_normal_deg, max_depth, passes, feature_min_length)
    further, live_in = _check_states(states, alive, v_in, len(t_in))
    k_in = len(t_in)
    repeated = _repeated_index(t_in)
    keep = np.flatnonzero(~repeated)
    notes: list[str] = []
    if repeated.any():
        notes.append(f"{int(repeated.sum())} triangles with a repeated vertex index dropped")
    t_orig = t_in[keep]
    p_orig = p_in[keep]
    live = live_in[:, keep]
    labels, part_index, tol_of_label = _part_tolerances(v_in, t_orig, p_orig, tol, relative)
    # each part and pattern of drawn states is decimated as a part of its own
    group_part, group = _groups(part_index, live)
    group_tol = tol_of_label[group_part]
    # every state relative to the same origin: a vertex that does not move keeps its coordinates
    centre = _box_centre(v_in, t_orig)
    Vs = np.stack([v_in - centre, *(x - centre for x in further)])
    V = Vs[0]
    F, fgroup, orig_face = _distinct_faces(t_orig, group)
    orig = np.ascontiguousarray(V[t_orig])
    n_origin, face_area, degenerate = _unit_normals(V[F])
    constraints = _constraints(V, F, fgroup, n_origin, degenerate, group_tol, feature_deg,
                               keep_boundary, slide_shared, feature_min_length)
    quadrics = _quadrics(V, F, n_origin, face_area)

    alive = np.ones(len(F), np.bool_)
    orig_depth = certification_depths(orig, tol_of_label[part_index], max_depth)
    # certify against each tolerance less the bound of the certificate's own rounding, and
    # report the bounds rounded up by it: a reported bound <= tol holds for the exact distance
    margin = certificate_rounding(Vs, t_orig, tol_of_label, orig_depth)
    originals = Originals(orig, (tol_of_label - margin)[part_index], orig_face, orig_depth,
                          t_orig, np.ascontiguousarray(live))
    cos_max = float(np.cos(np.radians(float(max_normal_deg))))
    sup, sup_n, collapses, rejected, n_passes = _decimate(
        Surface(V, Vs, F, fgroup, alive, n_origin), originals, quadrics, constraints, cos_max,
        int(passes))
    kept_bounds = _final_bounds(Vs, F, originals, sup, sup_n)
    if np.isnan(kept_bounds).any():
        notes.append(f"{int(np.isnan(kept_bounds).sum())} triangles drawn at no certified "
                     f"state: no bound")

    bounds = np.full(k_in, np.nan)
    bounds[keep] = np.nextafter(kept_bounds + margin[part_index], np.inf)
    out_faces = np.flatnonzero(alive)
    first_of_face = np.full(len(F), len(orig_face), np.int64)
    np.minimum.at(first_of_face, orig_face, np.arange(len(orig_face)))
    out = np.ascontiguousarray(F[out_faces], np.int32)
    n_used = len(np.unique(out))
    return Decimation(
        triangles=out,
        parts=np.ascontiguousarray(labels[group_part[fgroup[out_faces]]], np.int32),
        part_labels=labels.astype(np.int32),
        tol_abs=tol_of_label,
        collapses=int(collapses),
        rejected={name: int(c) for name, c in zip(REJECT_REASONS, rejected)},
        seconds=time.perf_counter() - start,
        bounds=bounds,
        certified_max=float(np.nanmax(bounds)),
        bytes_saved=int(n_used * 3 * v_in.itemsize),
        input_triangles=k_in,
        passes=int(n_passes),
        dropped=int(repeated.sum()),
        notes=notes,
        states_certified=len(Vs),
        source=keep[first_of_face[out_faces]],
    )


def _check_states(states, alive, vertices: np.ndarray, k: int):
    """``states`` as a list of (N, 3) float64 arrays (empty for None) and ``alive`` as an
    (S + 1, K) bool array (all True for None); ValueError for the shapes and values
    :func:`hausdorff_decimate` refuses."""
    further = []
    if states is not None:
        arr = np.asarray(states)
        if arr.ndim != 3 or arr.shape[1:] != vertices.shape or arr.dtype.kind not in "fiu":
            raise ValueError(f"states must be a numeric (S, {len(vertices)}, 3) array, got "
                             f"{arr.dtype} {arr.shape}")
        arr = np.asarray(arr, np.float64)
        if not np.isfinite(arr).all():
            raise ValueError("states must be finite")
        further = list(arr)
    if alive is None:
        return further, np.ones((len(further) + 1, k), np.bool_)
    live = np.asarray(alive)
    if live.shape != (len(further) + 1, k) or live.dtype != np.bool_:
        raise ValueError(f"alive must be a ({len(further) + 1}, {k}) bool array (the input "
                         f"triangles drawn at the vertices and at each state), got {live.dtype} "
                         f"{live.shape}")
    return further, live


def _groups(part_index: np.ndarray, live: np.ndarray):
    """The groups of the input triangles, one per part and pattern of drawn states (columns
    of ``live`` (S + 1, K)): each group's part index (G,) and each triangle's group (K,)
    int32, groups in the order of (part, pattern)."""
    if live.all():  # no erosion: the groups are the parts
        return np.arange(int(part_index.max()) + 1), np.ascontiguousarray(part_index, np.int32)
    rows = np.concatenate([part_index[:, None].astype(np.int64),
                           live.T.astype(np.int64)], axis=1)
    unique, group = np.unique(rows, axis=0, return_inverse=True)
    return unique[:, 0], np.ascontiguousarray(group.ravel(), np.int32)
