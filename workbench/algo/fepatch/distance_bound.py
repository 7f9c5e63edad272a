"""fe2003's distance bound, certified: subpatches, simplified lines and retriangulation whose
one-sided distance from the original surface is within ``d`` (stages 1 and 2 of
:mod:`.pipeline`); a subpatch beyond the bound is regrown with half its fit tolerance or, as a
last resort, keeps its original elements. Lengths are model units, times seconds."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .atlas import plane_frames
from .borders import BorderNetwork, _simplify_lines, border_network, unpinched
from .certify import subpatch_distance_bounds, subpatch_neighbours
from .features import planar_subpatches
from .params import STAGES, FEPatchParams
from .retriangulate import simplified_triangles


@dataclass
class CertifiedSurface:
    """The simplified triangles of :func:`certified_triangles` and how they were certified.

    ``labels`` (M,) final subpatch labels; ``triangles`` {label: (K, 3) node triangles};
    ``fallback`` labels kept as original elements; ``removed`` (N,) bool line nodes left out;
    ``network`` and ``frames`` of the final labels; ``bound`` the largest certified
    per-subpatch distance (model units; NaN when not certified); ``rounds`` of splitting;
    ``split`` subpatches split for the bound and ``kept`` subpatches that keep their original
    elements for it; ``certify_seconds`` spent measuring.
    """

    labels: np.ndarray
    triangles: dict
    fallback: np.ndarray
    removed: np.ndarray
    network: BorderNetwork
    frames: dict
    bound: float
    rounds: int
    split: int
    kept: int
    certify_seconds: float


def _lines_and_triangles(e, c, labels, params, triangulation, clock: dict, keep=(),
                         memo=None):
    """(network, frames, triangles, fallback, removed) of subpatch ``labels``; seconds are
    added to ``clock`` under the first two :data:`STAGES`. ``memo``: {"lines": dict,
    "triangles": dict} kept between calls (see :func:`_simplify_lines` and
    :func:`simplified_triangles`), or None."""
    memo = memo or {}
    t0 = time.perf_counter()
    frames = plane_frames(c, e, labels)
    network = border_network(e, labels, len(c))
    removed = _simplify_lines(network, c, frames, params, memo.get("lines"))
    t1 = time.perf_counter()
    tris, fallback, removed = simplified_triangles(e, c, labels, network, removed, frames,
                                                   triangulation, keep=keep,
                                                   memo=memo.get("triangles"))
    clock[STAGES[0]] = clock.get(STAGES[0], 0.0) + t1 - t0
    clock[STAGES[1]] = clock.get(STAGES[1], 0.0) + time.perf_counter() - t1
    return network, frames, tris, fallback, removed


def _split(e, c, labels, fit, bad) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """(labels, fit, unsplittable): every subpatch of ``bad`` regrown with half its fit
    tolerance ``fit`` ((M,) per element, model units); subpatches that stay whole are listed
    as unsplittable (by their new label) and keep their old tolerance."""
    lab = np.asarray(labels, np.int64).copy()
    fit = fit.copy()
    whole = []
    next_label = int(lab.max()) + 1
    for s in bad:
        sel = np.flatnonzero(lab == s)
        parts = planar_subpatches(e[sel], c, np.zeros(len(sel), np.int64), 0.5 * fit[sel[0]])
        if parts.max() == 0:
            whole.append(sel[0])
            continue
        lab[sel] = next_label + parts
        fit[sel] *= 0.5
        next_label += int(parts.max()) + 1
    renumbered = unpinched(e, lab, len(c))
    return renumbered, fit, [int(renumbered[k]) for k in whole]


def certified_triangles(e, c, patch_labels, params: FEPatchParams, triangulation, *,
                        fit_share: float = 1.0, certify: bool = True,
                        max_splits: int = 3, tol_share: float = 0.01,
                        clock: dict | None = None) -> CertifiedSurface:
    """Subpatches, simplified lines and retriangulation whose one-sided distance from the
    original surface is certified within ``params.d``.

    Subpatches grow with the fit tolerance ``fit_share · d`` (the paper's rule is
    ``fit_share`` = 1: nodes within ``d`` on either side of the plane, so that the new surface,
    which spans only the border nodes, may lie up to 2d from the interior). With ``certify``,
    every subpatch is then measured
    (:func:`~workbench.algo.fepatch.certify.subpatch_distance_bounds`, exact, bracket width
    ``tol_share · d``) and each one whose certified bound exceeds
    ``(1 − tol_share) · d`` is regrown with half its tolerance, for up to ``max_splits`` rounds;
    a subpatch still above after that, or one that does not split (a single element, or one
    already within half the tolerance), keeps its original elements (distance 0), and the
    neighbours that changed with it are measured again. So the returned surface has
    ``bound <= (1 − tol_share) · d``: an independent certificate with a bracket up to
    ``tol_share · d`` wide still finds it within ``d``.

    ``e`` (M, 4) int64, ``c`` (N, 3) float64 model units, ``patch_labels`` (M,)
    feature-divided patches; ``triangulation`` the elements' :func:`triangulate`. ``clock``
    (a dict) receives seconds: subpatch growth, splitting and lines under ``STAGES[0]``,
    retriangulation under ``STAGES[1]`` and measuring under "certification". Refuses
    ``fit_share`` outside (0, 1] and ``tol_share`` outside (0, 1).
    """
    if not 0.0 < fit_share <= 1.0:
        raise ValueError(f"fit_share must be in (0, 1], got {fit_share!r}")
    clock = {} if clock is None else clock
    d = params.d
    fit = np.full(len(e), d * fit_share)
    t0 = time.perf_counter()
    labels = unpinched(e, planar_subpatches(e, c, patch_labels, d * fit_share), len(c))
    clock[STAGES[0]] = clock.get(STAGES[0], 0.0) + time.perf_counter() - t0
    memo = {"lines": {}, "triangles": {}}  # the work of rounds before, for the next
    network, frames, tris, fallback, removed = _lines_and_triangles(e, c, labels, params,
                                                                    triangulation, clock,
                                                                    memo=memo)
    if not certify:
        return CertifiedSurface(labels, tris, fallback, removed, network, frames, np.nan, 0,
                                0, 0, 0.0)
    if not 0.0 < tol_share < 1.0:
        raise ValueError(f"tol_share must be in (0, 1), got {tol_share!r}")
    cache: dict = {}
    tol = tol_share * d if d > 0 else 1e-12
    accept = (1.0 - tol_share) * d
    keep: set[int] = set()
    rounds = split = 0
    seconds = 0.0
    while True:
        t0 = time.perf_counter()
        bounds = subpatch_distance_bounds(
            c, triangulation.triangles, labels[triangulation.element_of], tris, sorted(tris),
            subpatch_neighbours(e, labels), tol, cache)
        seconds += time.perf_counter() - t0
        bad = sorted(s for s, b in bounds.items() if b > accept)
        if not bad:
            break
        t0 = time.perf_counter()
        if rounds < max_splits:
            rounds += 1
            old = labels
            labels, fit, whole = _split(e, c, labels, fit, bad)
            split += len(bad) - len(whole)
            # a kept subpatch stays kept under its new label
            kept_elements = np.isin(old, list(keep))
            keep = set(np.unique(labels[kept_elements]).tolist()) | set(whole)
        else:
            keep |= set(bad)
        clock[STAGES[0]] = clock.get(STAGES[0], 0.0) + time.perf_counter() - t0
        network, frames, tris, fallback, removed = _lines_and_triangles(
            e, c, labels, params, triangulation, clock, keep=sorted(keep), memo=memo)
    clock["certification"] = seconds
    return CertifiedSurface(labels, tris, fallback, removed, network, frames,
                            max(bounds.values(), default=0.0), rounds, split, len(keep),
                            seconds)
