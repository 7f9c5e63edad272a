"""The geometric checks of the numerical stress suite (:mod:`workbench.reliability.numerics`),
each against exact rational arithmetic (:mod:`~workbench.reliability.exact`,
:mod:`~workbench.reliability.exact_planar`). Promises, in model units, with u = 2⁻⁵³:

a. **point–triangle distance** (:func:`workbench.algo.nearest.triangle.closest_point_on_triangle`,
   looked up on its module at every query, so that a test may replace it): the distance
   within 1e-12·R of the exact one, ``R = max_i |p − corner_i|`` (the issue's target; the row
   reports it in those units and its note in units of the documented 64·u·R, which also
   bounds it); the returned point within :data:`POINT_ULPS`·u·M of the triangle (exactly
   measured; M the largest coordinate magnitude of p and the corners).
b. **part distances** (batched, both hierarchies and the brute force of
   :mod:`workbench.algo.nearest.parts`): each node's distance within the documented rounding
   (64·u·(d + D) + 2·8·u·M: the kernel, and the translation of the node and of the corners; D
   the longest edge, M the largest coordinate norm) of the exact distance to the other parts,
   inf exactly when that lies beyond the cut-off (either within the rounding of it), and the
   part named lies at the minimum distance (to twice the rounding).
c. **Hausdorff brackets** (:func:`workbench.algo.hausdorff.hausdorff`, both directions, with
   and without the sample estimates where it has them): ``lower ≤ H ≤ upper`` for the exact H
   (decided in exact arithmetic; where only an interval of H is known, the bracket must meet
   it). The worst is the largest amount by which an exact value lies outside, in u·M.
d. **simplifier bounds** (:func:`workbench.algo.simplify.hausdorff_decimate`): for sample
   points of every input triangle (corners, points ¼, ½ and ¾ along the edges, three interior
   points; dyadic, exact), the exact distance to the simplified surface at most that triangle's
   reported bound, and at most the part's tolerance. The worst is the largest
   ``distance − bound`` in u·D (D the diagonal of the mesh's box; ≤ 0 keeps the promise).

g. **spacetime slice areas** (:func:`workbench.algo.spacetime.slicing.slice_at`): every
   tetrahedron with tmin < t ≤ tmax cut once, and its polygon's area within
   :data:`SLICE_ULPS`·u·D·(D + M) of the exact area of the section (D the spatial diameter of
   the tetrahedron, M its largest ``|x|``, ``|y|``): corners built by one interpolation each are
   within a few u·(D + M) of the exact ones, and the area moves by at most the perimeter times that.
"""

from __future__ import annotations

import inspect
import math
from fractions import Fraction

import numpy as np

from .exact import exact_point_triangle_sq, exact_sq_error, sqrt_fraction
from .exact_planar import tet_slice_area
from .numerics_cases import (
    DISTANCE_KINDS,
    HAUSDORFF_KINDS,
    PART_KINDS,
    SIMPLIFY_KINDS,
    case_rng,
    distance_case,
    exact_point_sq,
    part_mesh,
    simplify_mesh,
    surface_pair,
)
from .numerics_scenes import SLICE_KINDS, spacetime_case

U = 2.0 ** -53
TARGET_REL = 1e-12  # the target: distance error ≤ 1e-12 of R
POINT_ULPS = 8.0  # the closest point lies within this many u·M of the triangle
SLICE_ULPS = 16.0  # slice areas within this many u·D·(D + M) of the exact ones
def _sample_weights() -> list[tuple[Fraction, Fraction, Fraction]]:
    quarter, half = Fraction(1, 4), Fraction(1, 2)
    out = [(Fraction(1), Fraction(0), Fraction(0)), (Fraction(0), Fraction(1), Fraction(0)),
           (Fraction(0), Fraction(0), Fraction(1))]
    for s in (quarter, half, 1 - quarter):
        out += [(1 - s, s, Fraction(0)), (Fraction(0), 1 - s, s), (s, Fraction(0), 1 - s)]
    out += [(half, quarter, quarter), (quarter, half, quarter), (quarter, quarter, half)]
    return out


# dyadic barycentric weights of the sample points of an input triangle (check d)
SAMPLE_WEIGHTS = _sample_weights()


def _documented_rounding(distance: float, longest: float, magnitude: float,
                         levels: int) -> float:
    """The rounding bound of the error model of :mod:`workbench.algo.nearest.triangle` (its
    constants,
    recomputed here so that a fault in its helpers cannot move the check)."""
    from ..algo.nearest.triangle import CONSTRUCTION_ERROR, DISTANCE_ERROR

    return (DISTANCE_ERROR * U * (distance + longest)
            + CONSTRUCTION_ERROR * U * magnitude * levels) * (1 + 1e-12)


# --------------------------------------------------------------------------- a.
def check_distances(report, n: int, seed: int) -> None:
    """Check a over ``n`` cases (8 queries each) of every distance generator."""
    from ..algo.nearest import triangle as kernels  # the kernel is looked up on it at every query
    from ..algo.nearest.triangle import DISTANCE_ERROR

    out = np.empty(3)
    for kind in DISTANCE_KINDS:
        dist = report.row("a. distance", kind, "1e-12 R")
        point = report.row("a. closest point", kind, "u M")
        worst_model = 0.0
        for i in range(n):
            label, queries = distance_case(kind, case_rng(seed, f"distance/{kind}", i))
            for j, row in enumerate(queries):
                p, a, b, c = (np.ascontiguousarray(x) for x in row)
                out[:] = np.nan
                sq = float(kernels.closest_point_on_triangle(p, a, b, c, out))
                d = math.sqrt(sq) if sq >= 0 else math.nan
                exact = exact_point_triangle_sq(p, a, b, c)
                error = exact_sq_error(d, exact)
                r = max(float(np.linalg.norm(p - x)) for x in (a, b, c))
                model = DISTANCE_ERROR * U * r
                ok = error <= model and error <= TARGET_REL * r
                rel = error / (TARGET_REL * r) if r > 0 else (0.0 if error == 0 else math.inf)
                worst_model = max(worst_model, error / model if r > 0 else (error > 0) * math.inf)
                dist.record(rel, ok, f"#{i}.{j} ({label}): error {error / r if r else error:.2e}"
                            f" R = {error / (U * r) if r else math.inf:.3g} u R, exact "
                            f"{sqrt_fraction(exact):.17g}, computed {d:.17g}")
                m = float(max(np.abs(np.concatenate([p, a, b, c])).max(), 1e-300))
                if np.isfinite(out).all():
                    off = math.sqrt(float(exact_point_triangle_sq(out, a, b, c)))
                else:
                    off = math.inf
                point.record(off / (U * m), off <= POINT_ULPS * U * m,
                             f"#{i}.{j} ({label}): point {off / (U * m):.3g} u M off the "
                             f"triangle")
        dist.note = f"worst {worst_model:.3g} of the documented 64 u R"
        point.note = f"promise <= {POINT_ULPS:g} u M"


# --------------------------------------------------------------------------- b.
def _own_parts(mesh) -> list[set]:
    own = [set() for _ in range(mesh.n_nodes)]
    for element, part in zip(mesh.elements, mesh.parts):
        for node in set(int(x) for x in element):
            own[node].add(int(part))
    return own


def exact_part_minima(mesh) -> list[dict[int, Fraction]]:
    """Per node, the exact squared distance to each other part (parts that no element using
    the node belongs to; only those within reach of the nearest, by bounding boxes), from the
    mesh's triangulation. Empty for unused nodes and nodes with no other part."""
    tr = mesh.triangulation
    tri = np.asarray(tr.triangles, np.int64)
    tri_part = np.asarray(mesh.parts)[np.asarray(tr.element_of)]
    corners = mesh.nodes[tri]
    own = _own_parts(mesh)
    out = []
    for node in range(mesh.n_nodes):
        minima = {}
        if own[node]:
            for part in sorted(set(tri_part.tolist()) - own[node]):
                minima[part] = exact_point_sq(mesh.nodes[node], corners[tri_part == part])
        out.append(minima)
    return out


def check_part_distances(report, count: int, seed: int) -> None:
    """Check b over ``count`` models of every part generator."""
    from ..algo.nearest import parts as pd

    functions = {
        "batched": lambda m, c: pd.batched_part_distances(m, c),
        "aabb": lambda m, c: pd.part_distances(m, c, kind="aabb"),
        "obb x10": lambda m, c: pd.part_distances(m, c, kind="obb", leaf_size=10),
        "brute force": lambda m, c: pd.brute_force_part_distances(m, c),
    }
    for kind in PART_KINDS:
        row = report.row("b. part distance", kind, "rounding")
        for i in range(count):
            mesh, cutoff, label = part_mesh(kind, case_rng(seed, f"parts/{kind}", i))
            minima = exact_part_minima(mesh)
            corners = mesh.nodes[np.asarray(mesh.triangulation.triangles, np.int64)]
            longest = float(np.sqrt(((corners[:, [1, 2, 0]] - corners) ** 2).sum(-1)).max())
            magnitude = float(np.linalg.norm(mesh.nodes, axis=1).max())
            for name, function in functions.items():
                result = function(mesh, cutoff)
                distance, part = (result if isinstance(result, tuple)
                                  else (result.distance, result.other_part))
                for node, per_part in enumerate(minima):
                    _check_node(row, f"#{i} {name} node {node} ({label})", per_part,
                                float(distance[node]), int(part[node]), cutoff, longest,
                                magnitude)
        row.note = "64u(d+D) + 16uM"


def _check_node(row, what, per_part, computed, part, cutoff, longest, magnitude) -> None:
    if not per_part:
        row.record(0.0 if math.isinf(computed) else math.inf,
                   math.isinf(computed) and part == -1, f"{what}: {computed} with no other part")
        return
    exact_sq = min(per_part.values())
    exact = sqrt_fraction(exact_sq)
    bound = _documented_rounding(exact, longest, magnitude, 2)
    if math.isinf(computed):
        ok = exact > cutoff - bound
        row.record(0.0 if ok else math.inf, ok, f"{what}: inf, exact {exact!r} <= cutoff "
                   f"{cutoff!r}")
        return
    error = exact_sq_error(computed, exact_sq)
    ok = error <= bound and exact <= cutoff + bound and part in per_part
    if ok:
        named = sqrt_fraction(per_part[part])
        ok = abs(named - exact) <= 2 * bound
    row.record(error / bound, ok, f"{what}: computed {computed!r} (part {part}), exact "
               f"{exact!r} (parts {sorted(per_part)}), cutoff {cutoff:.3g}")


# --------------------------------------------------------------------------- c.
def check_hausdorff(report, count: int, seed: int) -> None:
    """Check c over ``count`` pairs of every Hausdorff generator, both directions."""
    from ..algo.hausdorff import hausdorff

    modes = [{}]
    if "estimates" in inspect.signature(hausdorff).parameters:
        modes.append({"estimates": False})
    for kind in HAUSDORFF_KINDS:
        row = report.row("c. hausdorff", kind, "u M outside")
        for i in range(count):
            pair = surface_pair(kind, case_rng(seed, f"hausdorff/{kind}", i))
            both = np.concatenate([pair.va, pair.vb])
            scale = U * float(np.abs(both).max() + np.linalg.norm(np.ptp(both, axis=0)))
            for direction, args, (lo_sq, hi_sq) in (
                    ("A->B", (pair.va, pair.fa, pair.vb, pair.fb), pair.forward),
                    ("B->A", (pair.vb, pair.fb, pair.va, pair.fa), pair.backward)):
                for mode in modes:
                    r = hausdorff(*args, **mode)
                    lower, upper = float(r.lower), float(r.upper)
                    ok = (0.0 <= lower <= upper and Fraction(lower) ** 2 <= hi_sq
                          and Fraction(upper) ** 2 >= lo_sq)
                    outside = max(lower - sqrt_fraction(hi_sq), sqrt_fraction(lo_sq) - upper)
                    tag = "" if not mode else " without estimates"
                    row.record(outside / scale, ok, f"#{i} {direction}{tag} ({pair.label}): "
                               f"bracket [{lower!r}, {upper!r}], exact in "
                               f"[{sqrt_fraction(lo_sq)!r}, {sqrt_fraction(hi_sq)!r}]")
        row.note = f"{count} pairs x 2 directions x {len(modes)} modes"


# --------------------------------------------------------------------------- d.
def check_simplifier(report, count: int, seed: int) -> None:
    """Check d over ``count`` meshes of every simplifier generator."""
    from ..algo.simplify import hausdorff_decimate

    for kind in SIMPLIFY_KINDS:
        row = report.row("d. simplifier", kind, "u D outside")
        worst_tol, collapses = 0.0, 0
        for i in range(count):
            v, t, tol, label = simplify_mesh(kind, case_rng(seed, f"simplify/{kind}", i))
            dec = hausdorff_decimate(v, t, tol)
            collapses += dec.collapses
            faces = v[np.asarray(dec.triangles, np.int64)]
            tol_abs = float(dec.tol_abs[0])
            unit = U * float(np.linalg.norm(np.ptp(v, axis=0)))
            for k, tri in enumerate(t):
                bound = float(dec.bounds[k])
                if math.isnan(bound):
                    continue
                corners = [[Fraction(float(x)) for x in v[int(c)]] for c in tri]
                for w in SAMPLE_WEIGHTS:
                    point = [w[0] * corners[0][d] + w[1] * corners[1][d] + w[2] * corners[2][d]
                             for d in range(3)]
                    sq = exact_point_sq(point, faces)
                    ok = sq <= Fraction(bound) ** 2 and sq <= Fraction(tol_abs) ** 2
                    dist = sqrt_fraction(sq)
                    worst_tol = max(worst_tol, dist / tol_abs)
                    row.record((dist - bound) / unit, ok,
                               f"#{i} triangle {k} at {tuple(str(x) for x in w)} "
                               f"({label}): exact {dist!r}, bound {bound!r}, tol {tol_abs!r}")
        row.note = f"worst {worst_tol:.3g} of tol; {collapses} collapses"


# --------------------------------------------------------------------------- g.
def check_slices(report, count: int, seed: int) -> None:
    """Check g over ``count`` meshes of every slice generator."""
    from ..algo.spacetime.slicing import polygon_areas, slice_at

    for kind in SLICE_KINDS:
        row = report.row("g. slice area", kind, "u D(D+M)")
        for i in range(count):
            mesh, times, label = spacetime_case(kind, case_rng(seed, f"slices/{kind}", i))
            tets = mesh.points[mesh.simplices]
            for t in times:
                s = slice_at(mesh, t)
                cut = {int(e) for e in np.flatnonzero(
                    (tets[:, :, 2].min(axis=1) < t) & (tets[:, :, 2].max(axis=1) >= t))}
                got = [int(e) for e in s.element]
                if sorted(got) != sorted(cut):
                    row.record(math.inf, False, f"#{i} t={t!r} ({label}): cut {sorted(got)}, "
                               f"should be {sorted(cut)}")
                    continue
                for area, e in zip(polygon_areas(s), got):
                    corners = tets[e]
                    exact = tet_slice_area(corners, t)
                    xy = corners[:, :2]
                    diameter = float(max(np.linalg.norm(p - q) for p in xy for q in xy))
                    magnitude = float(np.abs(xy).max())
                    unit = U * diameter * (diameter + magnitude)
                    error = float(abs(Fraction(float(area)) - exact))
                    ok = error <= SLICE_ULPS * unit
                    row.record(error / unit if unit > 0 else (0.0 if error == 0 else math.inf),
                               ok, f"#{i} t={t!r} tet {e} ({label}): area {area!r}, exact "
                               f"{float(exact)!r}")
        row.note = f"promise <= {SLICE_ULPS:g}"
