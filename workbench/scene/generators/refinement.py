"""Conforming k×k refinement of any FE shell mesh (node fields and time steps follow), and a
smooth bump displacement that makes flat regions curved."""

from __future__ import annotations

import numpy as np

from ..mesh import FEMesh, MeshError
from .common import _positive_float, _positive_int


def _normalise_elements(elements: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Elements with every triangle in the ``e[3] == e[2]`` form, and the triangle mask.

    A quad with one pair of equal neighbouring nodes is a triangle stored another way; it is
    rotated (winding kept) into the convention. Fewer than three distinct nodes, or equal nodes
    that are not neighbours, is refused.
    """
    e = elements.astype(np.int64)
    same = e == np.roll(e, -1, axis=1)           # same[:, c]: node c equals node c+1
    n_same = same.sum(axis=1)
    opposite = (e[:, 0] == e[:, 2]) | (e[:, 1] == e[:, 3])
    bad = np.flatnonzero((n_same > 1) | opposite)
    if len(bad):
        raise MeshError(f"{len(bad)} degenerate elements cannot be refined (fewer than three "
                        f"distinct nodes or repeated opposite nodes), first "
                        f"{[(int(i), e[i].tolist()) for i in bad[:5]]}")
    is_tri = n_same == 1
    rotate = is_tri & ~same[:, 2]
    if rotate.any():
        # rotate so that the equal pair sits at positions (2, 3)
        c = np.argmax(same[rotate], axis=1)
        shift = (c - 2) % 4
        idx = (np.arange(4)[None, :] + shift[:, None]) % 4
        e = e.copy()
        e[rotate] = np.take_along_axis(e[rotate], idx, axis=1)
    return e, is_tri


def _edge_nodes(edge: np.ndarray, fwd: np.ndarray, col: int, k: int,
                n_nodes: int) -> np.ndarray:
    """(rows, k-1) node ids along element edge ``col``, ordered from its start node: the k-1
    nodes of unique edge ``edge[:, col]`` are numbered after the ``n_nodes`` old nodes, from
    the edge's smaller node id (``fwd``: the element runs the edge that way)."""
    m = np.arange(1, k)
    j = np.where(fwd[:, col][:, None], m[None, :], k - m[None, :])
    return n_nodes + edge[:, col][:, None] * (k - 1) + (j - 1)


def _quad_children(eq: np.ndarray, q_edge: np.ndarray, q_fwd: np.ndarray, k: int,
                   n_nodes: int, quad_base: int) -> np.ndarray:
    """(nq, k*k, 4) children of the quads ``eq``, whose interior nodes are numbered from
    ``quad_base`` on, (k-1)² per quad."""
    nq, n_inner = len(eq), (k - 1) ** 2
    # quads: local grid G[j, i] at (s, t) = (i/k, j/k);
    # corners e0 (0,0), e1 (1,0), e2 (1,1), e3 (0,1)
    G = np.empty((nq, k + 1, k + 1), np.int64)
    if nq:
        rq = np.arange(nq)
        G[:, 0, 0], G[:, 0, k], G[:, k, k], G[:, k, 0] = eq[:, 0], eq[:, 1], eq[:, 2], eq[:, 3]
        if k > 1:
            G[:, 0, 1:k] = _edge_nodes(q_edge, q_fwd, 0, k, n_nodes)  # e0 -> e1 along s
            G[:, 1:k, k] = _edge_nodes(q_edge, q_fwd, 1, k, n_nodes)  # e1 -> e2 along t
            # e2 -> e3 runs against s
            G[:, k, 1:k] = _edge_nodes(q_edge, q_fwd, 2, k, n_nodes)[:, ::-1]
            # e3 -> e0 runs against t
            G[:, 1:k, 0] = _edge_nodes(q_edge, q_fwd, 3, k, n_nodes)[:, ::-1]
            G[:, 1:k, 1:k] = (quad_base + rq[:, None] * n_inner
                              + np.arange(n_inner)[None, :]).reshape(nq, k - 1, k - 1)
    ii, jj = np.meshgrid(np.arange(k), np.arange(k))      # child (j, i), row-major in j
    ii, jj = ii.ravel(), jj.ravel()
    return np.stack([G[:, jj, ii], G[:, jj, ii + 1], G[:, jj + 1, ii + 1], G[:, jj + 1, ii]],
                    axis=-1)                               # (nq, k*k, 4)


def _triangle_inner(k: int) -> tuple[np.ndarray, np.ndarray]:
    """(j, i) of a triangle's interior grid nodes (i, j >= 1, i + j <= k - 1), row-major."""
    jin, iin = np.nonzero(np.add.outer(np.arange(k + 1), np.arange(k + 1)) < k)
    inner = (jin > 0) & (iin > 0)
    return jin[inner], iin[inner]


def _triangle_children(et: np.ndarray, t_edge: np.ndarray, t_fwd: np.ndarray, k: int,
                       n_nodes: int, tri_base: int) -> np.ndarray:
    """(nt, k*k, 4) children of the triangles ``et`` (first three nodes), whose interior nodes
    are numbered from ``tri_base`` on, (k-1)(k-2)/2 per triangle."""
    nt, n_inner = len(et), (k - 1) * (k - 2) // 2
    m = np.arange(1, k)
    # triangles: local grid H[j, i] at P0 + (i/k)(P1 - P0) + (j/k)(P2 - P0), i + j <= k
    jin, iin = _triangle_inner(k)
    H = np.zeros((nt, k + 1, k + 1), np.int64)
    if nt:
        H[:, 0, 0], H[:, 0, k], H[:, k, 0] = et[:, 0], et[:, 1], et[:, 2]
        if k > 1:
            H[:, 0, 1:k] = _edge_nodes(t_edge, t_fwd, 0, k, n_nodes)  # e0 -> e1 along i
            # e1 -> e2: (i, j) = (k - m, m)
            H[:, m, k - m] = _edge_nodes(t_edge, t_fwd, 1, k, n_nodes)
            # e2 -> e0 runs against j
            H[:, 1:k, 0] = _edge_nodes(t_edge, t_fwd, 2, k, n_nodes)[:, ::-1]
            if n_inner:
                H[:, jin, iin] = (tri_base + np.arange(nt)[:, None] * n_inner
                                  + np.arange(n_inner)[None, :])
    uj, ui = np.nonzero(np.add.outer(np.arange(k), np.arange(k)) <= k - 1)   # upward
    dj, di = np.nonzero(np.add.outer(np.arange(k), np.arange(k)) <= k - 2)   # downward
    up = np.stack([H[:, uj, ui], H[:, uj, ui + 1], H[:, uj + 1, ui], H[:, uj + 1, ui]], axis=-1)
    down = np.stack([H[:, dj, di + 1], H[:, dj + 1, di + 1], H[:, dj + 1, di], H[:, dj + 1, di]],
                    axis=-1)
    return np.concatenate([up, down], axis=1)             # (nt, k*k, 4)


class _Refinement:
    """The linear maps from old node values to refined node values, and the refined topology.

    New nodes are numbered: the N old nodes first (unchanged), then k-1 nodes on every unique
    element edge, then the interior nodes of every quad and of every triangle.
    """

    def __init__(self, elements: np.ndarray, n_nodes: int, k: int):
        e, is_tri = _normalise_elements(elements)
        self.k, self.n_old = k, n_nodes
        quads, tris = np.flatnonzero(~is_tri), np.flatnonzero(is_tri)
        eq, et = e[quads], e[tris]

        # unique edges, each with k-1 nodes numbered from its smaller node id
        nq, nt = len(quads), len(tris)
        a = np.concatenate([eq.ravel(), et[:, :3].ravel()])
        b = np.concatenate([np.roll(eq, -1, axis=1).ravel(),
                            np.roll(et[:, :3], -1, axis=1).ravel()])
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        ukeys, inverse = np.unique(lo * np.int64(n_nodes) + hi, return_inverse=True)
        self.edge_lo, self.edge_hi = ukeys // n_nodes, ukeys % n_nodes
        inverse = inverse.ravel()
        forward = a < b
        q_edge, q_fwd = inverse[: 4 * nq].reshape(nq, 4), forward[: 4 * nq].reshape(nq, 4)
        t_edge, t_fwd = inverse[4 * nq:].reshape(nt, 3), forward[4 * nq:].reshape(nt, 3)
        n_edge_nodes = len(ukeys) * (k - 1)
        self.n_quad_inner = (k - 1) ** 2
        self.n_tri_inner = (k - 1) * (k - 2) // 2
        quad_base = n_nodes + n_edge_nodes
        tri_base = quad_base + nq * self.n_quad_inner
        self.n_new = tri_base + nt * self.n_tri_inner
        if self.n_new >= 2**31 or len(elements) * k * k >= 2**31:
            raise MeshError(f"refining by {k} would exceed int32 indices ({self.n_new} nodes)")

        # children keep their parent's position in the element order
        kk = k * k
        out = np.empty((len(elements), kk, 4), np.int64)
        out[quads] = _quad_children(eq, q_edge, q_fwd, k, n_nodes, quad_base)
        out[tris] = _triangle_children(et, t_edge, t_fwd, k, n_nodes, tri_base)
        self.elements = out.reshape(-1, 4).astype(np.int32)
        self.parent = np.repeat(np.arange(len(elements)), kk)
        self.eq, self.et = eq, et

        s = np.arange(1, k) / k
        self.edge_t = s
        S, T = np.meshgrid(s, s)                               # inner quad node (j, i) row-major
        S, T = S.ravel(), T.ravel()
        self.quad_w = np.stack([(1 - S) * (1 - T), S * (1 - T), S * T, (1 - S) * T])      # (4, n)
        if self.n_tri_inner:
            jin, iin = _triangle_inner(k)
            bi, bj = iin / k, jin / k
            self.tri_w = np.stack([1 - bi - bj, bi, bj])                                    # (3, n)

    def apply(self, values: np.ndarray, axis: int) -> np.ndarray:
        """Refined copy of per-node ``values`` (node axis ``axis``), by the same linear maps."""
        v = np.moveaxis(np.asarray(values, dtype=np.float64), axis, 0)
        rest = v.shape[1:]
        v = v.reshape(self.n_old, -1)
        out = np.empty((self.n_new, v.shape[1]), np.float64)
        out[: self.n_old] = v
        k, pos = self.k, self.n_old
        if k > 1:
            t = self.edge_t[None, :, None]
            ne = len(self.edge_lo)
            out[pos:pos + ne * (k - 1)] = (v[self.edge_lo][:, None] * (1 - t)
                                           + v[self.edge_hi][:, None] * t).reshape(-1, v.shape[1])
            pos += ne * (k - 1)
            n = len(self.eq) * self.n_quad_inner
            if n:
                acc = np.zeros((len(self.eq), self.n_quad_inner, v.shape[1]))
                for c in range(4):
                    acc += self.quad_w[c][None, :, None] * v[self.eq[:, c]][:, None, :]
                out[pos:pos + n] = acc.reshape(n, -1)
                pos += n
            n = len(self.et) * self.n_tri_inner
            if n:
                acc = np.zeros((len(self.et), self.n_tri_inner, v.shape[1]))
                for c in range(3):
                    acc += self.tri_w[c][None, :, None] * v[self.et[:, c]][:, None, :]
                out[pos:pos + n] = acc.reshape(n, -1)
                pos += n
        return np.moveaxis(out.reshape((self.n_new,) + rest), 0, axis)


def displaced(mesh: FEMesh, amplitude: float = 10.0, wavelength: float = 1200.0) -> FEMesh:
    """``mesh`` with a smooth bump field added along z, amplitude·sin(2πx/λ)·cos(2πy/λ) (model
    units), so that flat regions become curved: a simplifier then has something to lose."""
    amplitude = float(amplitude)
    wavelength = _positive_float(wavelength, "wavelength")
    x, y = mesh.nodes[:, 0], mesh.nodes[:, 1]
    nodes = mesh.nodes.copy()
    nodes[:, 2] += (amplitude * np.sin(2 * np.pi * x / wavelength)
                    * np.cos(2 * np.pi * y / wavelength))
    return FEMesh(nodes, mesh.elements, parts=mesh.parts, name=f"{mesh.name} displaced",
                  part_names=dict(mesh.part_names))


def refine(mesh: FEMesh, k: int) -> FEMesh:
    """Conforming k×k refinement: every quad into k² quads (bilinear), every triangle into k²
    triangles.

    New node positions are the parent's bilinear map (quads) or barycentric map (triangles) at
    parameters i/k; nodes on an element edge are shared by all elements using that edge, so a
    conforming mesh stays conforming (no duplicate nodes, no T-junctions). Node fields and the
    time steps are mapped by the same linear interpolation (a field linear in the coordinates is
    reproduced exactly); element fields, part ids and time values are copied to the children.

    Numbering: old node i stays node i; then k-1 nodes per unique edge, then interior nodes.
    The children of element m are rows ``m*k*k .. (m+1)*k*k - 1``: for a quad, child
    ``j*k + i`` covers parameters s ∈ [i/k, (i+1)/k], t ∈ [j/k, (j+1)/k] (s along e0→e1, t along
    e0→e3) with nodes (s,t), (s+1/k,t), (s+1/k,t+1/k), (s,t+1/k); every child keeps the parent's
    winding. Triangles stored as degenerate quads in another rotation are rotated into the
    ``e[3] == e[2]`` form. ``refine(mesh, 1)`` returns an equal mesh.

    Node ids of old nodes are kept and new nodes numbered after the largest; element ids are
    dropped (children have none). Refused: k < 1, elements with fewer than three distinct nodes,
    results that would not fit int32 indices.
    """
    k = _positive_int(k, "k")
    r = _Refinement(mesh.elements, mesh.n_nodes, k)
    node_ids = None
    if mesh.node_ids is not None:
        start = int(np.max(mesh.node_ids)) + 1
        node_ids = np.concatenate([np.asarray(mesh.node_ids),
                                   np.arange(start, start + r.n_new - r.n_old)])
    return FEMesh(
        nodes=r.apply(mesh.nodes, 0),
        elements=r.elements,
        parts=mesh.parts[r.parent],
        steps=None if mesh.steps is None else r.apply(mesh.steps, 1),
        node_fields={key: r.apply(v, v.ndim - 1) for key, v in mesh.node_fields.items()},
        element_fields={key: v[..., r.parent] for key, v in mesh.element_fields.items()},
        part_names=dict(mesh.part_names),
        times=None if mesh.times is None else np.array(mesh.times, copy=True),
        node_ids=node_ids,
        element_ids=None if k > 1 else (None if mesh.element_ids is None
                                        else np.array(mesh.element_ids, copy=True)),
        name=mesh.name if k == 1 else f"{mesh.name}_refined{k}",
        units=mesh.units,
    )
