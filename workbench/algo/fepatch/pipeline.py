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

The stages live in their own modules: the parameters and the paper's rules in :mod:`.params`,
the line network in :mod:`.borders`, the retriangulation in :mod:`.retriangulate`, the
certified distance bound in :mod:`.distance_bound`; this module runs them and assembles the
two surfaces.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...scene.crease import gouraud_split
from ...scene.derived import as_coords, as_elements, triangulate
from .atlas import build_atlas
from .borders import BorderNetwork, border_network, unpinched
from .distance_bound import CertifiedSurface, certified_triangles
from .features import G0, feature_edges, patches
from .normalmap import dropped_axis
from .params import (
    PAPER_DISTANCE_RULE,
    PAPER_RULES,
    PAPER_TEXTURE_RULE,
    PARAMETER_SETS,
    STAGES,
    WIRE_ENCODINGS,
    FEPatchParams,
    parse_params,
)
from .retriangulate import simplified_triangles
from .surface import TexturedSurface

__all__ = [
    "PAPER_DISTANCE_RULE",
    "PAPER_RULES",
    "PAPER_TEXTURE_RULE",
    "PARAMETER_SETS",
    "STAGES",
    "WIRE_ENCODINGS",
    "BorderNetwork",
    "CertifiedSurface",
    "FEModel",
    "FEPatchParams",
    "border_network",
    "build_model",
    "certified_triangles",
    "parse_params",
    "simplified_triangles",
    "unpinched",
]


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

    Takes more than 12 arguments because every stage's rule is a keyword-only option with the
    paper's or the measured default, which a caller names only to change it (the experiments
    pass :data:`PAPER_DISTANCE_RULE` and :data:`PAPER_TEXTURE_RULE` as ``**`` keywords); it is
    plain Python that calls the stages, no compiled kernel.
    """
    from . import wiretex

    corners_encoding, texels_per_edge, min_width, border = _encoding_rule(
        wire_encoding, texels_per_edge, min_width, border)
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
    seconds[STAGES[0]] = clock[STAGES[0]]
    seconds[STAGES[1]] = clock[STAGES[1]] + clock.get("certification", 0.0)

    t0 = time.perf_counter()
    if int(normal_reduction) != normal_reduction or normal_reduction < 1:
        raise ValueError(f"normal_reduction must be a positive integer, got {normal_reduction!r}")
    reduction = int(normal_reduction)
    atlas = build_atlas(c, e, sub, texels_per_edge=texels_per_edge, border=border,
                        per_subpatch=atlas_scale == "subpatch", quantile=scale_quantile,
                        multiple=reduction, scale_by=scale_by, turns=atlas_turns)
    v = _atlas_vertices(atlas, len(c))
    plane_n = np.array([frames[s][1][2] for s in range(len(frames))])
    axis_of_label = dropped_axis(plane_n)
    normal_axis = axis_of_label[v.label_of]
    corner_vertex = v.ids(np.repeat(sub, 4).reshape(-1, 4), e)
    corners_uv = v.uv[corner_vertex]
    corner_n = _corner_normals(e, c, p.alpha_g1_deg, plane_n[sub], orig_tri)
    vertex_normals = np.zeros((len(v.node_of), 3))
    vertex_normals[corner_vertex.ravel()] = corner_n.reshape(-1, 3)
    size = atlas.size
    nmap = _normal_map(corners_uv, corner_n, axis_of_label[sub], size, reduction, border)
    wire, line_nodes = _wire_frame(corners_encoding, e, corners_uv, sub, size, border,
                                   v.label_of, wire_range)
    narrow = np.zeros(len(e), bool) if min_width is None else \
        wiretex.element_widths(corners_uv) < min_width
    seconds[STAGES[2]] = time.perf_counter() - t0

    line_edges = _line_edges(e, corner_vertex, line_nodes, fe, narrow, len(c))
    original = TexturedSurface(
        positions=c[v.node_of], triangles=_element_triangles(corner_vertex, orig_tri),
        uv=v.uv, normal_axis=normal_axis, normals=vertex_normals, normal_map=nmap,
        line_edges=line_edges, **wire)
    simplified = _simplified_surface(c, v, cert.triangles, normal_axis, vertex_normals, nmap,
                                     line_edges, wire)
    on_lines = np.unique(np.concatenate([n for n, _, _ in network.lines])) if network.lines \
        else np.zeros(0, np.int64)
    return FEModel(
        params=p, original=original, simplified=simplified, subpatch=sub, n_elements=len(e),
        n_patches=int(patch.max()) + 1, n_subpatches=int(sub.max()) + 1,
        features=fe.counts(), line_nodes=len(on_lines),
        line_nodes_kept=int(len(on_lines) - cert.removed[on_lines].sum()),
        n_lines=len(network.lines), fallback=cert.fallback, atlas_size=size, seconds=seconds,
        fit_share=float(fit_share), distance_bound=cert.bound,
        certify_seconds=cert.certify_seconds, split_subpatches=cert.split,
        kept_subpatches=cert.kept, narrow_elements=int(narrow.sum()),
        wire_encoding=wire_encoding)


def _encoding_rule(wire_encoding: str, texels_per_edge, min_width, border):
    """(corners encoding?, texels per edge, min width, border) of ``wire_encoding`` with
    :func:`build_model`'s defaults filled in; refuses an unknown encoding."""
    from . import wireid, wiretex

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
    return corners_encoding, texels_per_edge, min_width, border


def _normal_map(corners_uv: np.ndarray, corner_n: np.ndarray, axis: np.ndarray, size,
                reduction: int, border: int) -> np.ndarray:
    """The two-component normal map of the corner normals ``corner_n`` (M, 4, 3), ``reduction``
    times coarser per axis than the atlas ``size`` and dilated past the ``border``."""
    from .bake import normal_map

    return normal_map(corners_uv / reduction, corner_n, axis,
                      (size[0] // reduction, size[1] // reduction),
                      dilate=max(1, -(-border // reduction)))


@dataclass
class _AtlasVertices:
    """The surfaces' vertices: one per (subpatch, node) of the atlas, sorted by (subpatch,
    node), so that a pair is found by bisection. ``node_of`` and ``label_of`` (V,) its node
    and subpatch, ``uv`` (V, 2) its atlas texels, ``key`` (V,) subpatch · ``n_nodes`` + node."""

    node_of: np.ndarray
    label_of: np.ndarray
    uv: np.ndarray
    key: np.ndarray
    n_nodes: int

    def ids(self, s_arr, n_arr) -> np.ndarray:
        """Vertex ids of (subpatch, node) pairs."""
        return np.searchsorted(self.key, np.asarray(s_arr, np.int64) * self.n_nodes + n_arr)


def _atlas_vertices(atlas, n_nodes: int) -> _AtlasVertices:
    """The vertices of ``atlas`` (see :class:`_AtlasVertices`)."""
    labels = sorted(atlas.uv)
    vnodes = [atlas.uv[s][0] for s in labels]
    node_of = np.concatenate(vnodes)
    uv = np.concatenate([atlas.uv[s][1] for s in labels])
    label_of = np.repeat(labels, [len(v) for v in vnodes])
    return _AtlasVertices(node_of=node_of, label_of=label_of, uv=uv,
                          key=label_of.astype(np.int64) * n_nodes + node_of, n_nodes=n_nodes)


def _wire_frame(corners_encoding: bool, e: np.ndarray, corners_uv: np.ndarray, sub: np.ndarray,
                size, border: int, label_of: np.ndarray, wire_range: float):
    """(the wire frame's TexturedSurface fields, (K, 2) node pairs of the edges the texture
    cannot show): the element-id wire frame (:func:`_element_wire`, no such edges) or fe2003's
    signed-distance texture (edges between same-colour neighbours of its checkerboard)."""
    from . import wiretex

    if corners_encoding:
        return _element_wire(corners_uv, sub, size, border, label_of), np.zeros((0, 2), np.int64)
    colour, line_nodes = wiretex.checkerboard(e)
    wire = {"wire_map": wiretex.wire_texture(corners_uv, colour, size, wire_range=wire_range),
            "wire_range": wire_range}
    return wire, line_nodes


def _line_edges(e: np.ndarray, corner_vertex: np.ndarray, line_nodes, fe, narrow: np.ndarray,
                n_nodes: int) -> np.ndarray:
    """(K, 2) vertex pairs of the line pass: edges the texture cannot show (``line_nodes``:
    same-colour neighbours; elements too ``narrow`` at the atlas scale) and the outer boundary
    (G0 features of ``fe``), whose outline the texture could draw only on its inner half."""
    line_nodes = np.concatenate([np.asarray(line_nodes, np.int64).reshape(-1, 2),
                                 fe.of_kind(G0).astype(np.int64), _element_edges(e[narrow])])
    return _edge_vertices(e, corner_vertex, line_nodes, n_nodes)


def _simplified_surface(c: np.ndarray, v: _AtlasVertices, tris: dict, normal_axis: np.ndarray,
                        vertex_normals: np.ndarray, nmap, line_edges: np.ndarray,
                        wire: dict) -> TexturedSurface:
    """The simplified surface: the original's vertices, only those the new triangles ``tris``
    ({subpatch: (K, 3) nodes}) and the line pass use, with the same textures."""
    s_tri = np.concatenate([v.ids(np.full(t.shape, s), t) for s, t in sorted(tris.items())])
    used = np.zeros(len(v.node_of), bool)
    used[s_tri.ravel()] = True
    used[line_edges.ravel()] = True
    remap = np.cumsum(used) - 1
    return TexturedSurface(
        positions=c[v.node_of[used]], triangles=remap[s_tri], uv=v.uv[used],
        normal_axis=normal_axis[used], normals=vertex_normals[used], normal_map=nmap,
        line_edges=remap[line_edges], **_used_vertices(wire, used))


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
