"""The arrays the element hierarchy's kernels (:mod:`.queries`) share, grouped by what they hold.

Each group is a NamedTuple, which numba passes to a compiled function as one argument and reads
field by field at no cost; a kernel takes the fields it needs before its loops, one assignment
each (never by unpacking a tuple of them, see :mod:`workbench.algo.nearest.state`). Every field
keeps one type from call to call, so that one compiled version serves every call. Coordinates
are the hierarchy's local ones (the mesh's less its origin), in the mesh's units.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Forest(NamedTuple):
    """The forest of bounding-volume trees, one per part under a top level, flat."""

    bv: np.ndarray         # (nodes, 6) AABB lo, hi or (nodes, 15) OBB centre, axes, half extents
    obb: bool              # whether ``bv`` holds oriented boxes
    left: np.ndarray       # (nodes,) int64 first child, -1 for a leaf
    right: np.ndarray      # (nodes,) int64 second child
    start: np.ndarray      # (nodes,) int64 first element (tree order) of a node
    end: np.ndarray        # (nodes,) int64 one past its last
    node_part: np.ndarray  # (nodes,) int64 part index of a part-tree node, -1 at the top level
    root: int              # the forest's root
    depth: int             # most nodes on a root-to-leaf path
    max_leaf: int          # most elements in a leaf


class Elements(NamedTuple):
    """The elements in tree order, as the nearest-element search measures them."""

    corners: np.ndarray  # (E, 2, 3, 3) float64 corners of each element's triangles
    n_tri: np.ndarray    # (E,) int64 how many triangles each has (0, 1 or 2)
    slab: np.ndarray     # (E, 5) float64 unit normal and the interval of normal·x over its nodes


class Exclusion(NamedTuple):
    """Per point, the part indices it ignores, in CSR form: point i ignores
    ``own[ptr[i]:ptr[i + 1]]``."""

    ptr: np.ndarray  # (P + 1,) int64
    own: np.ndarray  # (ptr[-1],) int64 part indices (-1: not in the hierarchy)


class LeafSearch(NamedTuple):
    """Scratch of one nearest-element search: the node stack and a leaf's elements sorted by
    their slab distance."""

    stack: np.ndarray    # (2 depth + 4,) int64 nodes to visit
    stack_d: np.ndarray  # (2 depth + 4,) float64 their squared distances
    tmp: np.ndarray      # (3,) float64 a closest point being measured
    leaf_g: np.ndarray   # (max_leaf,) float64 squared slab distances
    leaf_j: np.ndarray   # (max_leaf,) int64 their elements
