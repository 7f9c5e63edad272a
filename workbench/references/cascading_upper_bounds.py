"""A certified Hausdorff bracket from another tool, beside ours: ``cascading-upper-bounds``.

``cascading-upper-bounds`` (PyPI; Sacht & Jacobson, *Cascading upper bounds for triangle soup
Pompeiu-Hausdorff distance*, SGP 2024) computes, like :func:`workbench.algo.hausdorff.hausdorff`,
a bracket ``lower <= H <= upper`` of the **one-sided** distance ``H = sup_{p ∈ A} d(p, B)``
from triangle soup A to triangle soup B. Its one entry, as installed (1.0.0, a compiled
nanobind extension)::

    pompeiu_hausdorff(VA, FA, VB, FB, tol=1e-8, max_factor=1e6, normalize=False)
        -> (lower, upper, dA, ms_bvh, ms_bounds)

``VA``/``VB`` (N, 3) float64, ``FA``/``FB`` (K, 3) int32. ``lower`` is the largest float64
distance (libigl's AABB point-triangle distance) of a vertex of A, or of the edge midpoints its
refinement inserts; ``upper`` the largest per-triangle "cascading" upper bound (vertex
distances plus edge lengths, circumradius, Kang's bound, bisector bound). It splits the
triangle of A with the largest bound 4 ways (edge midpoints), one at a time, until
``upper - lower <= tol * dA``. Where A lies on B (coincident faces) its bounds shrink only with
the triangles' size: a surface against an identical copy reaches 1e-4 of the diagonal but
not 1e-5 within 1e4 times A's faces, and the car deck against its decimation (mostly
coincident) takes it seconds where the larger bunny takes it hundredths (the ``hausdorff_peer``
table of ``simplify_tradeoff``).

**Its tolerance**: ``tol`` bounds the bracket's width, ``upper - lower``; it is absolute (model
units) with ``normalize=False`` (``dA`` returned as 1.0), and a share of the diagonal of the
bounding box of *every row of* ``VA`` with ``normalize=True`` (``dA`` that diagonal). Ours is
the same quantity: ``tol`` (model units, default 1e-4 of the diagonal of A's *used* vertices)
bounds ``upper - lower``. :func:`peer_hausdorff` therefore hands ours over unchanged, absolute,
``normalize=False``: equal tolerance means equal bracket width to reach, in model units.
``ms_bvh`` (the build of B's tree) and ``ms_bounds`` (everything after it) are the peer's own
timings in milliseconds; we time the call ourselves (:attr:`PeerBracket.seconds`) and keep its
two beside.

**What it cannot take, found by trying it** (the wrapper refuses or converts, never passes on):

* unreferenced vertices of A are measured as if they were on A (its first lower bound is
  over every row of ``VA``): a far or NaN one gives ``lower`` above ``upper`` or ``inf``. The
  wrapper hands it A's used vertices only (and B's, which does no harm);
* ``tol <= 0`` does not end (a width of 0 is out of reach: it subdivides on, until
  ``max_factor`` or memory runs out; still running after 20 s on 32 triangles when tried);
  refused, as a non-finite ``tol`` is;
* no triangles in A or B crashes the process (segmentation fault); out-of-range or negative
  indices are read unchecked; non-finite coordinates of used vertices give ``inf``/NaN bounds:
  all refused with ValueError by :func:`~workbench.algo.nearest.bvh.check_triangles`, as ours
  refuses
  them; more than 2**31 - 1 vertices cannot be indexed in int32: refused;
* more refinement than ``max_factor`` times A's faces or vertices raises RuntimeError
  ("Exceeded maximum number of faces or vertices"); we pass its default, 1e6 (in effect no
  limit), and report the error as the result's ``failure``, not as an exception.

Degenerate triangles are taken (measured as their edges); float32 or Fortran-order input is
converted by nanobind, but the wrapper hands over C-order float64 and int32 itself.

**Rounding**: it works on the raw coordinates (no translation to a local origin) and does not
widen its bracket for float64 rounding: on A against itself it returns ``lower`` 1e-16 above the
exact 0 near the origin and 2e-10 above it at coordinates around 1e6. :attr:`PeerBracket.rounding`
(:data:`PEER_ROUNDING` times the largest coordinate magnitude of both meshes) is the slack we grant
it where we check its bracket against ours or against an exact value; its raw bracket is what we
report.

**Slivers**: its point-triangle distance (libigl's, as the ``libigl`` package computes it
too) loses the plane of a thin tilted triangle: a segment 2^-40·√2 above the middle of a sliver
2^-20 thin, in the plane y = z, comes out 1.5e-6 away (exact 1.3e-12), and 2^-4·√2 above it
1.5e-10 relatively too far. Its ``lower`` is then above the exact distance, beyond any rounding
slack, and its bracket excludes it; the comparison reports the brackets as not overlapping
(``tests/references/test_hausdorff_peer.py`` keeps the case).

**Constraints it runs under** (for any comparison of times): one thread (the CPU time of a call
equals its wall time, measured here on 160 k vertices), float64, raw coordinates; ours runs on
every core (numba ``prange``), translated to A's bounding-box centre, and its time includes its
own input checks while the peer's input conversion (compacting A, int32 indices) is done before
its timed call. The first call in a process loads the extension: :func:`warm_up` runs it once
on a small pair, untimed, before the first timed call.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..algo.hausdorff import DEFAULT_REL_TOL, HausdorffResult, hausdorff
from ..algo.nearest.bvh import check_triangles

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["OUR_BRACKET_CONSTRAINTS", "PEER", "PEER_CONSTRAINTS", "PEER_MAX_FACTOR",
           "PEER_ROUNDING", "PeerBracket", "PeerComparison", "brackets_overlap",
           "compare_with_peer", "default_tol", "peer_hausdorff", "peer_unavailable", "warm_up"]

PEER = "cascading-upper-bounds"
# the peer's own default: refinement up to a million times A's faces and vertices (no limit
# in practice; the count is capped at 2**31 - 1 inside)
PEER_MAX_FACTOR = 1e6
# the slack granted to the peer's unwidened float64 bracket, share of the largest coordinate
# magnitude (it computes on raw coordinates): some 450 units in the last place
PEER_ROUNDING = 1e-13
PEER_CONSTRAINTS = ("one-sided A→B, float64 on raw coordinates, one thread, bracket not widened "
                    "for rounding, midpoint 4-split of one triangle at a time, "
                    f"max_factor {PEER_MAX_FACTOR:g}")
OUR_BRACKET_CONSTRAINTS = ("one-sided A→B, float64 translated to A's box centre, all cores "
                           "(numba), bracket widened for float64 rounding, plane cuts")
_INT32_MAX = 2 ** 31 - 1
_warm = False


@dataclass(frozen=True)
class PeerBracket:
    """The peer's one-sided bracket from A to B: ``lower <= H <= upper`` in model units (NaN
    where it failed: ``failure`` says why), as it returned them, not widened.

    ``seconds``: wall time of its call (our clock, input conversion excluded); ``tol`` (model
    units): the bracket width it was asked to reach, passed absolute; ``tol_reached``:
    ``upper - lower <= tol``; ``ms_bvh``/``ms_bounds``: its own timings (ms) of B's tree and of
    the bounds; ``rounding`` (model units): the slack granted to its float64 rounding where its
    bracket is checked (:data:`PEER_ROUNDING` of the largest coordinate magnitude)."""

    lower: float
    upper: float
    seconds: float
    tol: float
    tol_reached: bool
    ms_bvh: float
    ms_bounds: float
    rounding: float
    failure: str | None = None
    tool: str = PEER
    constraints: str = PEER_CONSTRAINTS

    @property
    def width(self) -> float:
        """``upper - lower`` (model units)."""
        return self.upper - self.lower

    def holds(self, value: float) -> bool:
        """Whether ``value`` (model units) lies in the bracket widened by ``rounding``."""
        return self.lower - self.rounding <= value <= self.upper + self.rounding


def brackets_overlap(a_lower: float, a_upper: float, b_lower: float, b_upper: float,
                     slack: float = 0.0) -> bool:
    """Whether [a_lower, a_upper] and [b_lower, b_upper] share a value, within ``slack``
    (model units). Two certified brackets of the same distance must. False where a bound is
    NaN."""
    if any(math.isnan(x) for x in (a_lower, a_upper, b_lower, b_upper)):
        return False
    return bool(max(a_lower, b_lower) <= min(a_upper, b_upper) + slack)


def peer_unavailable() -> str | None:
    """Why the peer cannot be imported; None when it can."""
    try:
        import cascading_upper_bounds  # noqa: F401
    except Exception as exc:  # a broken install is as absent as a missing one
        return f"{PEER} is not importable ({type(exc).__name__}: {exc})"
    return None


def default_tol(va: ArrayLike, fa: ArrayLike) -> float:
    """Our default tolerance for A: 1e-4 of the diagonal of the bounding box of A's used
    vertices (model units); A refused as :func:`~workbench.algo.nearest.bvh.check_triangles`
    does."""
    v, f = check_triangles(va, fa, "A (va, fa)")
    used = v[np.unique(f)]
    return DEFAULT_REL_TOL * float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))


def _compact(v: np.ndarray, f: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Used vertices only (C-order float64) and int32 triangles into them."""
    used, inverse = np.unique(f, return_inverse=True)
    if len(used) > _INT32_MAX:
        raise ValueError(f"{what}: {len(used)} used vertices cannot be indexed in int32 "
                         f"({PEER} takes int32 triangles)")
    return (np.ascontiguousarray(v[used], np.float64),
            np.ascontiguousarray(inverse.reshape(f.shape), np.int32))


def _check_tol(tol) -> float:
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)):
        raise ValueError(f"tol must be a number (model units), got {tol!r}")
    if not (math.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be finite and > 0 (model units; {PEER} never ends at 0), "
                         f"got {tol!r}")
    return float(tol)


def warm_up() -> None:
    """Run the peer once on a small pair (untimed), once per process: the first call loads its
    extension. A no-op when it is not importable (the timed call then reports why)."""
    global _warm
    if _warm or peer_unavailable():
        return
    from cascading_upper_bounds import pompeiu_hausdorff

    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.4, 0.6, 0.3]], np.float64)
    f = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], np.int32)
    flat = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    pompeiu_hausdorff(v, f, v, flat, 1e-3, PEER_MAX_FACTOR, False)
    _warm = True


def peer_hausdorff(va: ArrayLike, fa: ArrayLike, vb: ArrayLike, fb: ArrayLike, *,
                   tol: float | None = None,
                   max_factor: float = PEER_MAX_FACTOR) -> PeerBracket:
    """The peer's certified bracket of the one-sided Hausdorff distance from mesh A (``va``
    (N, 3), ``fa`` (K, 3) int) to mesh B, in model units, at bracket width ``tol`` (model
    units; default ours, 1e-4 of the diagonal of A's used vertices) handed over absolute.

    The peer is warmed up once per process (:func:`warm_up`) before the timed call. A's and
    B's unreferenced vertices are dropped first (see the module notes). Refused with
    ValueError naming the input: what :func:`~workbench.algo.nearest.bvh.check_triangles` refuses
    (bad
    shapes, no triangles, bad indices, non-finite used coordinates), more than 2**31 - 1 used
    vertices, a ``tol`` that is not finite and > 0, a ``max_factor`` below 1. A peer that is
    not importable or raises returns a result with ``failure`` set and NaN bounds."""
    va, fa = check_triangles(va, fa, "A (va, fa)")
    vb, fb = check_triangles(vb, fb, "B (vb, fb)")
    tol = default_tol(va, fa) if tol is None else _check_tol(tol)
    if not (math.isfinite(max_factor) and max_factor >= 1):
        raise ValueError(f"max_factor must be finite and >= 1, got {max_factor!r}")
    a_v, a_f = _compact(va, fa, "A (va, fa)")
    b_v, b_f = _compact(vb, fb, "B (vb, fb)")
    rounding = PEER_ROUNDING * max(float(np.abs(a_v).max()), float(np.abs(b_v).max()))
    reason = peer_unavailable()
    if reason:
        return PeerBracket(math.nan, math.nan, 0.0, tol, False, math.nan, math.nan, rounding,
                           reason)
    from cascading_upper_bounds import pompeiu_hausdorff

    warm_up()
    start = time.perf_counter()
    try:
        lower, upper, _, ms_bvh, ms_bounds = pompeiu_hausdorff(a_v, a_f, b_v, b_f, tol,
                                                               float(max_factor), False)
    except RuntimeError as exc:
        return PeerBracket(math.nan, math.nan, time.perf_counter() - start, tol, False,
                           math.nan, math.nan, rounding, f"{PEER} raised: {exc}")
    seconds = time.perf_counter() - start
    return PeerBracket(float(lower), float(upper), seconds, tol, bool(upper - lower <= tol),
                       float(ms_bvh), float(ms_bounds), rounding)


# ------------------------------------------------------------------ interleaved comparison
def _spread(values) -> tuple[float, float, float]:
    """(median, min, max) of ``values``."""
    a = np.asarray(values, np.float64)
    return float(np.median(a)), float(a.min()), float(a.max())


@dataclass(frozen=True)
class PeerComparison:
    """Ours and the peer on one pair at one tolerance ``tol`` (model units), timed interleaved:
    ``ours_seconds`` and ``peer_seconds`` hold one wall time per round (ours, then the peer),
    after ``warmup`` untimed rounds; ``ours`` and ``peer`` are the last round's results (both
    deterministic)."""

    ours: HausdorffResult
    peer: PeerBracket
    tol: float
    ours_seconds: tuple[float, ...]
    peer_seconds: tuple[float, ...]
    warmup: int

    @property
    def ours_time(self) -> tuple[float, float, float]:
        """Our wall seconds: (median, min, max) over the rounds."""
        return _spread(self.ours_seconds)

    @property
    def peer_time(self) -> tuple[float, float, float]:
        """The peer's wall seconds: (median, min, max) over the rounds (NaN where it failed)."""
        if self.peer.failure:
            return math.nan, math.nan, math.nan
        return _spread(self.peer_seconds)

    @property
    def time_ratio(self) -> tuple[float, float, float]:
        """Peer seconds ÷ our seconds of the same round: (median, min, max) over the rounds;
        above 1 where ours is faster."""
        if self.peer.failure:
            return math.nan, math.nan, math.nan
        return _spread(np.asarray(self.peer_seconds) / np.asarray(self.ours_seconds))

    @property
    def faster(self) -> str:
        """"ours" or the peer's name: the side whose every round's ratio says so; "neither
        (ratios straddle 1)" where the rounds disagree; "" where the peer failed."""
        if self.peer.failure:
            return ""
        _, lo, hi = self.time_ratio
        if lo > 1:
            return "ours"
        if hi < 1:
            return PEER
        return "neither (ratios straddle 1)"

    @property
    def overlap(self) -> bool:
        """Whether both brackets share a value (the peer granted its ``rounding``): they must,
        as both certify the same distance."""
        return brackets_overlap(self.ours.lower, self.ours.upper, self.peer.lower,
                                self.peer.upper, self.peer.rounding)

    def row(self) -> dict:
        """The comparison's table columns (model units and seconds)."""
        (t_o, t_o_lo, t_o_hi), (t_p, t_p_lo, t_p_hi) = self.ours_time, self.peer_time
        r, r_lo, r_hi = self.time_ratio
        return dict(ours_lower_mm=self.ours.lower, ours_upper_mm=self.ours.upper,
                    ours_tol_reached=self.ours.tol_reached, ours_s=t_o, ours_s_min=t_o_lo,
                    ours_s_max=t_o_hi, peer_lower_mm=self.peer.lower,
                    peer_upper_mm=self.peer.upper, peer_tol_reached=self.peer.tol_reached,
                    peer_s=t_p, peer_s_min=t_p_lo, peer_s_max=t_p_hi, time_ratio=r,
                    time_ratio_min=r_lo, time_ratio_max=r_hi, faster=self.faster,
                    overlap=self.overlap, repeats=len(self.ours_seconds),
                    peer_failure=self.peer.failure)


def compare_with_peer(va: ArrayLike, fa: ArrayLike, vb: ArrayLike, fb: ArrayLike, *,
                      tol: float | None = None, repeats: int = 5,
                      warmup: int = 1) -> PeerComparison:
    """Ours (:func:`~workbench.algo.hausdorff.hausdorff`, one-sided, the bracket only:
    ``estimates=False``, as the peer computes no mean) and the peer
    (:func:`peer_hausdorff`) from A to B at the same bracket width ``tol`` (model units;
    default ours, 1e-4 of A's used vertices' diagonal), alternating: ``warmup`` untimed rounds
    of both (numba's compiled code and the peer's first call), then ``repeats`` timed rounds
    of ours then the peer, each timed around its own call (wall clock). Refused with
    ValueError: ``repeats`` < 1, ``warmup`` < 0, and what either tool refuses."""
    if int(repeats) != repeats or repeats < 1:
        raise ValueError(f"repeats must be an integer >= 1, got {repeats!r}")
    if int(warmup) != warmup or warmup < 0:
        raise ValueError(f"warmup must be an integer >= 0, got {warmup!r}")
    va, fa = check_triangles(va, fa, "A (va, fa)")
    vb, fb = check_triangles(vb, fb, "B (vb, fb)")
    tol = default_tol(va, fa) if tol is None else _check_tol(tol)
    warm_up()
    ours_s, peer_s = [], []
    ours = peer = None
    for i in range(int(warmup) + int(repeats)):
        start = time.perf_counter()
        ours = hausdorff(va, fa, vb, fb, tol=tol, estimates=False)
        t_ours = time.perf_counter() - start
        peer = peer_hausdorff(va, fa, vb, fb, tol=tol)
        if i >= warmup:
            ours_s.append(t_ours)
            peer_s.append(peer.seconds)
    return PeerComparison(ours, peer, tol, tuple(ours_s), tuple(peer_s), int(warmup))
