"""fe2003's preprocessing, stage by stage: from an FE shell mesh to a simplified surface with a
normal map and a wire-frame texture, and the original mesh with the same wire-frame texture.

Stages (timed separately, as in the paper's Table 2):

1. **features, subpatches, lines** -- G0/G1/closing feature edges, feature-divided patches,
   least-squares planar subpatches within ``d``, the line network of subpatch borders, and its
   simplification within eq. 1's bound (a node where the line's neighbourhood changes -- three
   or more border edges, or other subpatches on either side -- is fixed).
2. **retriangulation** -- each subpatch's border loops, with the removed line nodes left out,
   projected on its plane and triangulated by hole bridging and ear clipping. A subpatch whose
   loops are not simple polygons in its plane (a fold, a pinch, a line simplified into its
   neighbour) keeps its original elements, and its border lines are restored in every
   neighbour, so that no crack opens between them; this repeats until no subpatch fails.
   Then fe2003's bound ``d`` is certified: every subpatch's one-sided distance to the new
   surface is measured exactly, and a subpatch beyond the bound is regrown with half its fit
   tolerance (stage 1 again for the changed borders), or, as a last resort, keeps its
   original elements (see :func:`certified_triangles`).
3. **textures** -- the atlas of the subpatch planes, the two-component normal map of the
   original crease-split vertex normals (dilated at subpatch borders, coarser than the wire
   frame by an integer factor) and the wire frame of every original element, as element ids
   and corners (the default) or as fe2003's signed-distance texture; elements the atlas scale
   leaves too narrow for the encoding get their edges drawn as lines.

Everything is float64 and GL-free; the result is two :class:`TexturedSurface`: ``original``
(every element, triangulated) and ``simplified``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...scene.derived import as_coords, as_elements, gouraud_split, triangulate
from .atlas import build_atlas, plane_frames
from .certify import array_digest, subpatch_distance_bounds, subpatch_neighbours
from .features import G0, feature_edges, patches, planar_subpatches
from .lines import line_tolerance, simplify_polyline
from .normalmap import dropped_axis
from .polygon import polygon_area, triangulate_polygon
from .surface import TexturedSurface

__all__ = [
    "PAPER_DISTANCE_RULE",
    "PAPER_RULES",
    "PAPER_TEXTURE_RULE",
    "PARAMETER_SETS",
    "FEModel",
    "FEPatchParams",
    "border_network",
    "build_model",
    "certified_triangles",
    "parse_params",
    "simplified_triangles",
]

STAGES = ("features, subpatches, lines", "retriangulation", "textures")
WIRE_ENCODINGS = ("corners", "distance")


@dataclass(frozen=True)
class FEPatchParams:
    """fe2003 Table 1 parameters: G1 angle (degrees), subpatch distance ``d`` and line bounds
    ``l_outer``/``l_inner`` (model units)."""

    alpha_g1_deg: float
    d: float
    l_outer: float
    l_inner: float
    name: str = ""

    def __post_init__(self) -> None:
        if not 0.0 < self.alpha_g1_deg < 180.0:
            raise ValueError(f"alpha_g1_deg must be in (0, 180), got {self.alpha_g1_deg}")
        for key in ("d", "l_outer", "l_inner"):
            if not np.isfinite(getattr(self, key)) or getattr(self, key) < 0:
                raise ValueError(f"{key} must be finite and >= 0, got {getattr(self, key)}")

    @property
    def label(self) -> str:
        return self.name or (f"{self.alpha_g1_deg:g},{self.d:g},{self.l_outer:g},"
                             f"{self.l_inner:g}")


PARAMETER_SETS = {"A": FEPatchParams(12.0, 1.0, 0.5, 8.0, "A"),
                  "B": FEPatchParams(18.0, 3.0, 2.5, 15.0, "B")}

# build_model's keywords for the paper's own construction, which the defaults improve on:
# the distance bound (subpatch nodes within d of their plane, not certified; the new surface
# may lie up to 2d from the original) and the texture scale (the smallest element extent
# spans 3 texels per axis, a full-resolution normal map, a 3-texel border)
PAPER_DISTANCE_RULE = {"fit_share": 1.0, "certify": False}
PAPER_TEXTURE_RULE = {"wire_encoding": "distance", "texels_per_edge": 3.0, "border": 3,
                      "scale_quantile": 0.0, "scale_by": "extent", "atlas_turns": 1,
                      "normal_reduction": 1, "min_width": None}
PAPER_RULES = {**PAPER_DISTANCE_RULE, **PAPER_TEXTURE_RULE}


def parse_params(spec) -> FEPatchParams:
    """``"A"``, ``"B"``, ``"alpha_g1,d,l_outer,l_inner"`` or an :class:`FEPatchParams`."""
    if isinstance(spec, FEPatchParams):
        return spec
    text = str(spec).strip()
    if text.upper() in PARAMETER_SETS:
        return PARAMETER_SETS[text.upper()]
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 4:
        raise ValueError(f"fe2003 parameters must be 'A', 'B' or 'alpha_g1,d,l_outer,l_inner', "
                         f"got {spec!r}")
    return FEPatchParams(*values)


@dataclass
class FEModel:
    """The result of :func:`build_model`: both surfaces and what each stage did.

    ``seconds`` per stage of :data:`STAGES` (the retriangulation includes certifying the
    distance bound, ``certify_seconds`` of it); ``subpatch`` (M,) labels; ``fallback`` the
    labels of subpatches kept as original elements; counts of features, patches, lines and line
    nodes. ``fit_share``: subpatch fit tolerance over ``d``; ``distance_bound``: the largest
    certified per-subpatch distance original → simplified (model units, NaN when not
    certified), so the one-sided Hausdorff distance is at most it; ``split_subpatches`` and
    ``kept_subpatches``: subpatches regrown or kept as original elements for the bound;
    ``narrow_elements``: elements whose edges are drawn as lines because the atlas scale
    leaves them narrower than the wire texture can outline; ``wire_encoding`` "corners" or
    "distance" (see :func:`build_model`).
    """

    params: FEPatchParams
    original: TexturedSurface
    simplified: TexturedSurface
    subpatch: np.ndarray
    n_elements: int
    n_patches: int
    n_subpatches: int
    features: dict
    line_nodes: int
    line_nodes_kept: int
    n_lines: int
    fallback: np.ndarray
    atlas_size: tuple[int, int]
    seconds: dict = field(default_factory=dict)
    fit_share: float = 1.0
    distance_bound: float = np.nan
    certify_seconds: float = 0.0
    split_subpatches: int = 0
    kept_subpatches: int = 0
    narrow_elements: int = 0
    wire_encoding: str = "corners"

    @property
    def rgba_texels_per_element(self) -> float:
        """Texture memory of both maps in RGBA texels (4 bytes) per original element."""
        return self.simplified.texture_bytes / 4.0 / max(self.n_elements, 1)


# --------------------------------------------------------------------------- line network
@dataclass
class BorderNetwork:
    """Subpatch borders: directed border edges per subpatch and the undirected line network.

    ``directed`` (B, 3) rows (a, b, subpatch) in element winding; ``bad`` labels of subpatches
    with an edge used three or more times inside them; ``lines`` list of (node array, closed,
    subpatch labels); ``fixed`` (N,) bool.
    """

    directed: np.ndarray
    bad: np.ndarray
    lines: list
    fixed: np.ndarray


def _border_edges(elements, labels, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """((B, 3) directed border edges (a, b, subpatch) in element winding, labels of subpatches
    with an edge used three or more times inside them)."""
    e = np.asarray(elements, np.int64)
    lab = np.asarray(labels, np.int64)
    a = e.ravel()
    b = e[:, [1, 2, 3, 0]].ravel()
    s = np.repeat(lab, 4)
    ok = a != b
    a, b, s = a[ok], b[ok], s[ok]
    key = np.minimum(a, b) * n_nodes + np.maximum(a, b)
    order = np.lexsort((key, s))
    ks, kk = s[order], key[order]
    start = np.r_[True, (ks[1:] != ks[:-1]) | (kk[1:] != kk[:-1])]
    group = np.cumsum(start) - 1
    per = np.bincount(group)[group]
    border = order[per == 1]
    return np.c_[a[border], b[border], s[border]], np.unique(ks[per >= 3])


def unpinched(elements, labels, n_nodes: int, rounds: int = 8) -> np.ndarray:
    """``labels`` with pinches removed: where a subpatch's border passes a node twice (the
    subpatch touches itself there), its elements at that node become subpatches of their own,
    for a few rounds. Returns (M,) int64 labels 0..S-1."""
    lab = np.asarray(labels, np.int64).copy()
    e = np.asarray(elements, np.int64)
    for _ in range(rounds):
        directed, _ = _border_edges(e, lab, n_nodes)
        key = directed[:, 2] * n_nodes + directed[:, 0]
        u, count = np.unique(key, return_counts=True)
        pinch = u[count > 1]
        if not len(pinch):
            break
        corner_key = lab[:, None] * n_nodes + e
        hit = np.isin(corner_key, pinch).any(axis=1)
        idx = np.flatnonzero(hit)
        lab[idx] = lab.max() + 1 + np.arange(len(idx))
    _, lab = np.unique(lab, return_inverse=True)
    return lab.astype(np.int64)


def border_network(elements, labels, n_nodes: int) -> BorderNetwork:
    """The borders of the subpatches ``labels`` ((M,) per element) of ``elements`` (M, 4): an
    element edge is a border edge of subpatch s when s's elements use it once. Lines run between
    fixed nodes: nodes with other than two border edges, or whose two border edges separate
    other subpatches; closed lines without a fixed node are reported with ``closed`` True."""
    directed, bad = _border_edges(elements, labels, n_nodes)
    a, b, s = directed[:, 0], directed[:, 1], directed[:, 2]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * n_nodes + hi
    # undirected line network: unique border edges with their subpatch signature
    ukey, inverse, ucount = np.unique(key, return_inverse=True, return_counts=True)
    bs = s
    smin = np.full(len(ukey), np.iinfo(np.int64).max)
    smax = np.full(len(ukey), -1)
    np.minimum.at(smin, inverse, bs)
    np.maximum.at(smax, inverse, bs)
    ulo, uhi = ukey // n_nodes, ukey % n_nodes
    sig = np.c_[ucount, smin, smax]
    degree = np.bincount(np.r_[ulo, uhi], minlength=n_nodes)
    fixed = degree != 2
    fixed &= degree > 0
    # degree-2 nodes whose two edges carry different signatures are fixed too
    ends = np.r_[ulo, uhi]
    eid = np.r_[np.arange(len(ukey)), np.arange(len(ukey))]
    o = np.argsort(ends, kind="stable")
    ends_s, eid_s = ends[o], eid[o]
    first = np.searchsorted(ends_s, np.arange(n_nodes))
    two = np.flatnonzero(degree == 2)
    e1, e2 = eid_s[first[two]], eid_s[first[two] + 1]
    fixed[two[(sig[e1] != sig[e2]).any(axis=1)]] = True
    # walk the lines
    visited = np.zeros(len(ukey), bool)
    lines = []

    def other(edge: int, node: int) -> int:
        return int(uhi[edge] if ulo[edge] == node else ulo[edge])

    def walk(node: int, edge: int) -> list[int]:
        nodes = [node]
        while True:
            visited[edge] = True
            node = other(edge, node)
            nodes.append(node)
            if fixed[node]:
                return nodes
            f = first[node]
            nxt = eid_s[f] if eid_s[f] != edge else eid_s[f + 1]
            if visited[nxt]:
                return nodes  # closed line back at its start
            edge = int(nxt)

    for node in np.flatnonzero(fixed):
        f = first[node]
        for k in range(degree[node]):
            edge = int(eid_s[f + k])
            if not visited[edge]:
                nodes = walk(int(node), edge)
                lines.append((np.array(nodes), False, _labels_of(sig[edge])))
    for edge in np.flatnonzero(~visited):
        if visited[edge]:
            continue
        nodes = walk(int(ulo[edge]), int(edge))
        if nodes[-1] == nodes[0]:
            nodes = nodes[:-1]
        lines.append((np.array(nodes), True, _labels_of(sig[edge])))
    return BorderNetwork(directed=directed, bad=bad, lines=lines, fixed=fixed)


def _labels_of(sig) -> tuple[int, ...]:
    count, lo, hi = (int(v) for v in sig)
    if count == 1:
        return (lo,)
    if count == 2:
        return (lo, hi)
    return (lo, hi) + (-1,) * (count - 2)  # non-manifold: more than two subpatches


def _simplify_lines(network: BorderNetwork, coords, frames, params, memo=None) -> np.ndarray:
    """(N,) bool: nodes removed from the line network. ``memo``: a dict kept between calls on
    the same coordinates and parameters; a line with the same nodes, fixed nodes, bound and
    planes is not simplified again.

    Two lines between the same two fixed nodes would both become the same chord and close
    nothing: each of them keeps at least its node farthest from the chord. A line that returns
    to its start node is simplified as a closed line around it.
    """
    removed = np.zeros(len(coords), bool)
    pairs: dict = {}
    for nodes, closed, _ in network.lines:
        if not closed:
            key = (min(nodes[0], nodes[-1]), max(nodes[0], nodes[-1]))
            pairs[key] = pairs.get(key, 0) + 1
    for nodes, closed, labels in network.lines:
        fixed = None
        if not closed and nodes[0] == nodes[-1]:
            nodes, closed = nodes[:-1], True
            fixed = np.zeros(len(nodes), bool)
            fixed[0] = True
        if len(labels) > 2 or len(nodes) < (4 if closed else 3):
            continue
        normals = [frames[s][1][2] for s in labels]
        if len(labels) == 1:
            tol = params.l_outer
        else:
            tol = line_tolerance(normals[0], normals[1], params.l_inner, params.l_outer)
        points = coords[nodes]
        if not closed and pairs[(min(nodes[0], nodes[-1]), max(nodes[0], nodes[-1]))] > 1:
            chord = points[-1] - points[0]
            off = points - points[0]
            length = np.linalg.norm(chord)
            dist = np.linalg.norm(off if length == 0 else np.cross(off, chord / length), axis=1)
            fixed = np.zeros(len(nodes), bool)
            fixed[int(np.argmax(dist[1:-1])) + 1] = True
        planes = [(n, -float(n @ frames[s][0])) for n, s in zip(normals, labels)]
        key = None
        if memo is not None:
            key = array_digest(nodes, np.asarray(fixed if fixed is not None else [], bool),
                               np.array([tol, float(closed),
                                         *(v for n, o in planes for v in (*n, o))]))
        if key is not None and key in memo:
            keep = memo[key]
        else:
            keep = simplify_polyline(points, tol, fixed=fixed, planes=planes, d=params.d,
                                     closed=closed)
            if key is not None:
                memo[key] = keep
        gone = np.ones(len(nodes), bool)
        gone[keep] = False
        removed[nodes[gone]] = True
    return removed


# --------------------------------------------------------------------------- retriangulation
def _loops(directed: np.ndarray) -> list[np.ndarray] | None:
    """Closed node loops of one subpatch's directed border edges; None where a node has two
    outgoing edges or an edge leads nowhere (pinched or inconsistently wound borders)."""
    a, b = directed[:, 0], directed[:, 1]
    if len(np.unique(a)) != len(a):
        return None
    succ = dict(zip(a.tolist(), b.tolist()))
    seen = set()
    loops = []
    for start in a.tolist():
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        node = succ[start]
        while node != start:
            if node in seen or node not in succ:
                return None
            loop.append(node)
            seen.add(node)
            node = succ[node]
        loops.append(np.array(loop))
    return loops


def _triangulate_subpatch(loops, removed, coords, frame) -> np.ndarray | None:
    """(K, 3) node triangles of one subpatch's simplified loops in its plane, wound like the
    elements; None when the loops do not form a simple polygon with holes."""
    kept = [loop[~removed[loop]] for loop in loops]
    if any(len(k) < 3 for k in kept):
        return None
    nodes = np.concatenate(kept)
    origin, axes = frame
    pts = (coords[nodes] - origin) @ axes[:2].T
    local, start = [], 0
    for k in kept:
        local.append(np.arange(start, start + len(k)))
        start += len(k)
    areas = [polygon_area(pts, loop) for loop in local]
    outer = int(np.argmax(np.abs(areas)))
    holes = [loop for i, loop in enumerate(local) if i != outer]
    # a hole runs against the outer loop when the elements are wound consistently
    if any(np.sign(areas[i]) == np.sign(areas[outer]) for i in range(len(local)) if i != outer):
        return None
    try:
        tri = triangulate_polygon(pts, local[outer], holes)
    except ValueError:
        return None
    if areas[outer] < 0:  # elements wound clockwise in this frame
        tri = tri[:, ::-1]
    return nodes[tri]


def _memo_triangulation(loops, removed, coords, frame, memo):
    """:func:`_triangulate_subpatch`, looked up in ``memo`` (a dict, or None) first."""
    if memo is None:
        return _triangulate_subpatch(loops, removed, coords, frame)
    kept = [loop[~removed[loop]] for loop in loops]
    key = array_digest(np.array([len(k) for k in kept]), *kept, frame[0], frame[1])
    if key not in memo:
        memo[key] = _triangulate_subpatch(loops, removed, coords, frame)
    return memo[key]


def simplified_triangles(elements, coords, labels, network: BorderNetwork,
                         removed: np.ndarray, frames, triangulation=None,
                         keep=(), memo=None) -> tuple[dict, np.ndarray, np.ndarray]:
    """({label: (K, 3) node triangles}, fallback labels, final ``removed``): every subpatch
    retriangulated from its simplified border loops; those that fail keep their original
    element triangles and restore their border nodes, which re-triangulates the neighbours.
    ``triangulation``: the elements' :func:`triangulate`, computed when not given; ``keep``:
    labels that keep their original elements from the start (their border nodes restored);
    ``memo``: a dict kept between calls on the same coordinates, so that a subpatch with the
    same simplified loops and plane is not triangulated again.
    """
    e = np.asarray(elements, np.int64)
    lab = np.asarray(labels, np.int64)
    removed = removed.copy()
    d = network.directed
    order = np.argsort(d[:, 2], kind="stable")
    d = d[order]
    bounds = np.searchsorted(d[:, 2], np.arange(lab.max() + 2))
    loops = {}
    for s in range(lab.max() + 1):
        if bounds[s] == bounds[s + 1]:
            continue
        loops[s] = None if s in set(network.bad.tolist()) else _loops(d[bounds[s]:bounds[s + 1]])
    result: dict = {}
    failed = {int(s) for s in keep if int(s) in loops}  # kept as original elements
    restored: set[int] = set()  # border lines restored after a failure with simplified ones
    for s in failed:
        nodes = np.unique(d[bounds[s]:bounds[s + 1], :2])
        removed[nodes] = False
    todo = set(loops) - failed
    while todo:
        new_fail = []
        for s in sorted(todo):
            tri = None if loops[s] is None else _memo_triangulation(loops[s], removed, coords,
                                                                  frames[s], memo)
            if tri is None:
                new_fail.append(s)
            else:
                result[s] = tri
        todo = set()
        restore = []
        for s in new_fail:
            result.pop(s, None)
            if s in restored or loops[s] is None:
                failed.add(s)
            else:
                restored.add(s)
                todo.add(s)
            nodes = np.unique(d[bounds[s]:bounds[s + 1], :2])
            restore.append(nodes[removed[nodes]])
        restore = np.concatenate(restore) if restore else np.zeros(0, np.int64)
        if len(restore):
            removed[restore] = False
            mark = np.zeros(len(removed), bool)
            mark[restore] = True
            touched = np.unique(d[mark[d[:, 0]] | mark[d[:, 1]], 2])
            todo |= {int(s) for s in touched if s not in failed}
    fallback = np.array(sorted(failed), np.int64)
    if len(fallback):
        tri = triangulation if triangulation is not None else triangulate(e, coords)
        of = lab[tri.element_of]
        for s in fallback:
            result[int(s)] = tri.triangles[of == s].astype(np.int64)
    return result, fallback, removed


# --------------------------------------------------------------------------- distance bound
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


# --------------------------------------------------------------------------- textures
def _corner_normals(e: np.ndarray, coords: np.ndarray, crease_deg: float,
                    plane_normal: np.ndarray, triangulation) -> np.ndarray:
    """(M, 4, 3) unit normals at the element corners, smooth across edges flatter than
    ``crease_deg``; a zero normal (degenerate element) takes its subpatch's plane normal."""
    split = gouraud_split(e, [coords], crease_deg, triangulation)
    n = split.normals(coords)[split.elements]
    zero = np.linalg.norm(n, axis=2) < 0.5
    if zero.any():
        rows = np.nonzero(zero)[0]
        n[zero] = plane_normal[rows]
    return n


def build_model(elements, coords, params="A", *, wire_encoding: str = "corners",
                texels_per_edge: float | None = None, border: int | None = None,
                wire_range: float = 2.0, atlas_scale: str = "subpatch", fit_share: float = 1.0,
                certify: bool = True, scale_quantile: float = 0.02,
                normal_reduction: int = 2, min_width: float | None | str = "encoding",
                scale_by: str = "width", atlas_turns: int = 8) -> FEModel:
    """Run every stage on ``elements`` (M, 4) and ``coords`` (N, 3) float64 (model units).

    ``params``: see :func:`parse_params`. ``wire_encoding``: "corners", the element-id wire
    frame of :mod:`workbench.algo.fepatch.wireid` (outlines computed from element corners, whole
    from about 1.5 texels of element width), or "distance", fe2003's signed-distance texture of
    :mod:`workbench.algo.fepatch.wiretex` (whole from about 3 texels). ``texels_per_edge``:
    texels across the smallest element along each plane axis, or across the ``scale_quantile``
    one (the paper's Nyquist rule asks for 2; default: the encoding's ``MIN_WIDTH``);
    ``border``: texels around each subpatch in the atlas (the wire frame's ring and the normal
    map's dilation; default 1 for "corners", 2 for "distance"); ``atlas_scale``: "subpatch"
    (one scale per subpatch and axis, as the paper) or "global".

    Distance bound: ``fit_share`` and ``certify``, the subpatch fit tolerance over ``d`` and
    the check-and-repair of the bound, see :func:`certified_triangles` (the paper's
    construction is :data:`PAPER_DISTANCE_RULE`).

    Texture memory: ``scale_quantile`` q makes the q-quantile of a subpatch's element extents
    (``scale_by`` "extent") or widths ("width"), not the smallest, span ``texels_per_edge``
    (see :func:`build_atlas`); every element narrower than ``min_width`` texels at that scale
    (:func:`element_widths`) has its edges drawn as lines, so that its outline shows although
    the texture cannot hold it ("encoding": the encoding's ``MIN_WIDTH``; None: no such lines).
    ``atlas_turns``: in-plane turns of each subpatch's axes tried for the smallest rectangle
    (see :func:`build_atlas`). ``normal_reduction`` (a positive integer) makes the normal map
    that many times coarser per axis than the wire frame; both share the texture coordinates
    (the atlas size is a multiple of it; default 2). The
    paper's rule is :data:`PAPER_TEXTURE_RULE`. Refuses empty meshes, non-finite coordinates
    and an unknown encoding.
    """
    from . import wireid, wiretex
    from .bake import normal_map

    if wire_encoding not in WIRE_ENCODINGS:
        raise ValueError(f"wire_encoding must be one of {', '.join(WIRE_ENCODINGS)}, got "
                         f"{wire_encoding!r}")
    corners_encoding = wire_encoding == "corners"
    encoding_width = wireid.MIN_WIDTH if corners_encoding else wiretex.MIN_WIDTH
    texels_per_edge = encoding_width if texels_per_edge is None else texels_per_edge
    min_width = encoding_width if isinstance(min_width, str) and min_width == "encoding" \
        else min_width
    if border is None:
        border = 1 if corners_encoding else 2
    p = parse_params(params)
    e = as_elements(elements).astype(np.int64)
    c = as_coords(coords, e)
    if len(e) == 0:
        raise ValueError("the mesh has no elements")
    # the original's own triangles (drawn as they are; not part of the preprocessing stages)
    orig_tri = triangulate(e, c)
    seconds = {}
    t0 = time.perf_counter()
    fe = feature_edges(e, c, p.alpha_g1_deg)
    patch = patches(e, fe)
    clock = {STAGES[0]: time.perf_counter() - t0}
    cert = certified_triangles(e, c, patch, p, orig_tri, fit_share=fit_share, certify=certify,
                               clock=clock)
    sub, frames, network = cert.labels, cert.frames, cert.network
    tris, fallback, removed = cert.triangles, cert.fallback, cert.removed
    seconds[STAGES[0]] = clock[STAGES[0]]
    seconds[STAGES[1]] = clock[STAGES[1]] + clock.get("certification", 0.0)

    t0 = time.perf_counter()
    if int(normal_reduction) != normal_reduction or normal_reduction < 1:
        raise ValueError(f"normal_reduction must be a positive integer, got {normal_reduction!r}")
    reduction = int(normal_reduction)
    atlas = build_atlas(c, e, sub, texels_per_edge=texels_per_edge, border=border,
                        per_subpatch=atlas_scale == "subpatch", quantile=scale_quantile,
                        multiple=reduction, scale_by=scale_by, turns=atlas_turns)
    labels = sorted(atlas.uv)
    # vertices: one per (subpatch, node) of the atlas
    vnodes = [atlas.uv[s][0] for s in labels]
    node_of = np.concatenate(vnodes)
    uv = np.concatenate([atlas.uv[s][1] for s in labels])
    label_of = np.repeat(labels, [len(v) for v in vnodes])
    plane_n = np.array([frames[s][1][2] for s in range(len(frames))])
    axis_of_label = dropped_axis(plane_n)
    normal_axis = axis_of_label[label_of]

    # vertices are sorted by (subpatch, node): a (subpatch, node) pair is found by bisection
    vertex_key = label_of.astype(np.int64) * len(c) + node_of

    def vertex(s_arr, n_arr):
        """Vertex ids of (subpatch, node) pairs."""
        return np.searchsorted(vertex_key, np.asarray(s_arr, np.int64) * len(c) + n_arr)

    corner_vertex = vertex(np.repeat(sub, 4).reshape(-1, 4), e)
    corners_uv = uv[corner_vertex]
    corner_n = _corner_normals(e, c, p.alpha_g1_deg, plane_n[sub], orig_tri)
    vertex_normals = np.zeros((len(node_of), 3))
    vertex_normals[corner_vertex.ravel()] = corner_n.reshape(-1, 3)
    size = atlas.size
    nmap = normal_map(corners_uv / reduction, corner_n, axis_of_label[sub],
                      (size[0] // reduction, size[1] // reduction),
                      dilate=max(1, -(-border // reduction)))
    if corners_encoding:
        wire = _element_wire(corners_uv, sub, size, border, label_of)
        line_nodes = np.zeros((0, 2), np.int64)
    else:
        colour, line_nodes = wiretex.checkerboard(e)
        wire = {"wire_map": wiretex.wire_texture(corners_uv, colour, size, wire_range=wire_range),
                "wire_range": wire_range}
    narrow = np.zeros(len(e), bool) if min_width is None else \
        wiretex.element_widths(corners_uv) < min_width
    seconds[STAGES[2]] = time.perf_counter() - t0

    # the line pass: edges the texture cannot show (same-colour neighbours, elements too narrow
    # at the atlas scale) and the outer boundary, whose outline the texture could draw only on
    # its inner half
    line_nodes = np.concatenate([np.asarray(line_nodes, np.int64).reshape(-1, 2),
                                 fe.of_kind(G0).astype(np.int64), _element_edges(e[narrow])])
    line_edges = _edge_vertices(e, corner_vertex, line_nodes, len(c))
    original = TexturedSurface(
        positions=c[node_of], triangles=_element_triangles(corner_vertex, orig_tri),
        uv=uv, normal_axis=normal_axis, normals=vertex_normals, normal_map=nmap,
        line_edges=line_edges, **wire)
    # simplified: the same vertices, only those the new triangles (and the line pass) use
    s_tri = np.concatenate([vertex(np.full(t.shape, s), t) for s, t in sorted(tris.items())])
    used = np.zeros(len(node_of), bool)
    used[s_tri.ravel()] = True
    used[line_edges.ravel()] = True
    remap = np.cumsum(used) - 1
    simplified = TexturedSurface(
        positions=c[node_of[used]], triangles=remap[s_tri], uv=uv[used],
        normal_axis=normal_axis[used], normals=vertex_normals[used], normal_map=nmap,
        line_edges=remap[line_edges], **_used_vertices(wire, used))
    on_lines = np.unique(np.concatenate([n for n, _, _ in network.lines])) if network.lines \
        else np.zeros(0, np.int64)
    return FEModel(
        params=p, original=original, simplified=simplified, subpatch=sub, n_elements=len(e),
        n_patches=int(patch.max()) + 1, n_subpatches=int(sub.max()) + 1,
        features=fe.counts(), line_nodes=len(on_lines),
        line_nodes_kept=int(len(on_lines) - removed[on_lines].sum()), n_lines=len(network.lines),
        fallback=fallback, atlas_size=size, seconds=seconds, fit_share=float(fit_share),
        distance_bound=cert.bound, certify_seconds=cert.certify_seconds,
        split_subpatches=cert.split, kept_subpatches=cert.kept,
        narrow_elements=int(narrow.sum()), wire_encoding=wire_encoding)


def _element_wire(corners_uv: np.ndarray, sub: np.ndarray, size, border: int,
                  label_of: np.ndarray) -> dict:
    """The element-id wire frame's TexturedSurface fields (see
    :mod:`workbench.algo.fepatch.wireid`): elements ordered by subpatch in the corner table,
    the element map holding each texel's element index within its subpatch (uint16 while every
    subpatch has fewer than 65 535 elements, else uint32), and per vertex (subpatch
    ``label_of``) the row of its subpatch's first element."""
    from . import wireid

    order = np.argsort(sub, kind="stable")
    count = np.bincount(sub, minlength=int(label_of.max(initial=-1)) + 1)
    first = np.r_[0, np.cumsum(count)[:-1]]
    rank = np.empty(len(sub), np.int64)
    rank[order] = np.arange(len(sub))
    local = rank - first[sub]
    dtype = np.uint16 if count.max() < np.iinfo(np.uint16).max else np.uint32
    owner = wireid.element_map(corners_uv, size, border=border)
    emap = np.full(owner.shape, np.iinfo(dtype).max, dtype)
    hit = owner != wireid.NO_ELEMENT
    emap[hit] = local[owner[hit]]
    table, frac = wireid.corner_table(corners_uv[order], size)
    return {"element_map": emap, "corner_table": table, "corner_frac": frac,
            "element_base": first[label_of].astype(np.int32)}


def _used_vertices(wire: dict, used: np.ndarray) -> dict:
    """``wire``'s TexturedSurface fields for the vertices ``used`` (a per-vertex field is cut)."""
    if "element_base" not in wire:
        return wire
    return {**wire, "element_base": wire["element_base"][used]}


def _element_edges(e: np.ndarray) -> np.ndarray:
    """(K, 2) node pairs of the non-degenerate edges of elements ``e`` (M, 4)."""
    pairs = np.stack([e, np.roll(e, -1, axis=1)], axis=2).reshape(-1, 2).astype(np.int64)
    return pairs[pairs[:, 0] != pairs[:, 1]]


def _edge_vertices(e: np.ndarray, corner_vertex: np.ndarray, pairs: np.ndarray,
                   n_nodes: int) -> np.ndarray:
    """(K, 2) vertex pairs of node ``pairs``: the corners of the first element using each edge."""
    if not len(pairs):
        return np.zeros((0, 2), np.int64)
    a, b = e.ravel(), e[:, [1, 2, 3, 0]].ravel()
    key = np.minimum(a, b) * n_nodes + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    want = np.unique(np.minimum(pairs[:, 0], pairs[:, 1]) * n_nodes
                     + np.maximum(pairs[:, 0], pairs[:, 1]))
    slot = order[np.searchsorted(key[order], want)]
    va = corner_vertex.ravel()[slot]
    vb = corner_vertex[:, [1, 2, 3, 0]].ravel()[slot]
    return np.c_[va, vb]


def _element_triangles(corner_vertex: np.ndarray, tri) -> np.ndarray:
    """The triangulation's triangles with element corners replaced by (subpatch, node) vertices."""
    return corner_vertex[tri.element_of[:, None], tri.corners.astype(np.intp)]
