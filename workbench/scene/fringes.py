"""What a crash engineer does to a field before it is drawn as a fringe plot (GL-free): average
an element field to the nodes of each part (smooth fringes that never smear across parts),
take its envelope over the states, or its difference to a reference state or to another run
of the same model mapped by node or element id.

Each function takes an :class:`~workbench.scene.mesh.FEMesh` and a field name and returns a
new mesh holding the result as a new field, named as :func:`part_averaged`,
:func:`envelope`, :func:`relative_to_state` and :func:`relative_to_run` say, so that every
render path draws it as any other field. Values are float64 in the units of the field.
Deleted elements (erosion, ``alive`` 0) and missing values (NaN: rigid parts) take no part in
a mean or an envelope. Refused with KeyError: a field the mesh does not have; with ValueError
(one line): what cannot be computed (a static field relative to a state, runs whose ids or
states differ).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .mesh import FEMesh


def _values(mesh: FEMesh, field: str) -> tuple[str, np.ndarray]:
    """("node" or "element", the field's values); KeyError naming the fields otherwise."""
    if field in mesh.node_fields:
        return "node", mesh.node_fields[field]
    if field in mesh.element_fields:
        return "element", mesh.element_fields[field]
    known = sorted([*mesh.node_fields, *mesh.element_fields]) or ["(none)"]
    raise KeyError(f"{mesh.name} has no field {field!r}; fields: {', '.join(known)}")


def _with_field(mesh: FEMesh, kind: str, name: str, values: np.ndarray) -> FEMesh:
    """A copy of ``mesh`` sharing its arrays, with the ``kind`` field ``name`` set."""
    node_fields, element_fields = dict(mesh.node_fields), dict(mesh.element_fields)
    (node_fields if kind == "node" else element_fields)[name] = values
    return dataclasses.replace(mesh, node_fields=node_fields, element_fields=element_fields)


# ------------------------------------------------------------------ per-part node averages
def split_parts(mesh: FEMesh) -> tuple[FEMesh, np.ndarray]:
    """(mesh, origin): ``mesh`` with every node shared by elements of several parts copied
    once per part, each part using its own copies (elements, parts and element fields in
    their order; steps, node fields and node ids copied with the nodes, so a split node keeps
    its id), and ``origin`` (N',) the node of ``mesh`` each new node is a copy of. Nodes no
    element uses (the free ends of beams, SPH particles) follow as they are; beams and
    particles keep their places, a split node's at its first copy (its coordinates are every
    copy's)."""
    corners = mesh.elements.astype(np.int64)
    key = mesh.parts.astype(np.int64)[:, None] * mesh.n_nodes + corners  # (part, node)
    unique, inverse = np.unique(key, return_inverse=True)
    used = np.zeros(mesh.n_nodes, bool)
    used[corners.ravel()] = True
    origin = np.concatenate([unique % mesh.n_nodes, np.flatnonzero(~used)])
    node_map = np.full(mesh.n_nodes, -1, np.int64)
    node_map[origin[::-1]] = np.arange(len(origin))[::-1]  # each node's first copy
    split = FEMesh(
        nodes=mesh.nodes[origin], elements=inverse.reshape(corners.shape), parts=mesh.parts,
        steps=None if mesh.steps is None else mesh.steps[:, origin],
        node_fields={k: v[..., origin] for k, v in mesh.node_fields.items()},
        element_fields=dict(mesh.element_fields), part_names=dict(mesh.part_names),
        times=mesh.times, node_ids=None if mesh.node_ids is None else mesh.node_ids[origin],
        element_ids=mesh.element_ids, name=mesh.name, units=mesh.units,
        unavailable=dict(mesh.unavailable),
        beams=None if mesh.beams is None else mesh.beams.remapped(node_map),
        particles=None if mesh.particles is None else mesh.particles.remapped(node_map))
    return split, origin


def part_averaged(mesh: FEMesh, field: str) -> FEMesh:
    """The element field ``field`` averaged to the nodes of one part at a time: the mesh of
    :func:`split_parts` with the node field ``FIELD_smooth``, at each node (a part's own copy)
    the plain mean of the field over that part's elements using it, at each state over the
    elements alive at that state with a value (a triangle's repeated node counts once). NaN
    where no such element is left. (T, N') for a (T, M) field; (N',) for an (M,) one, over
    every element with a value (a static field has no state to be deleted at)."""
    from scipy import sparse

    kind, values = _values(mesh, field)
    if kind != "element":
        raise ValueError(f"{field!r} is a node field already; smoothing averages an element "
                         f"field to the nodes")
    split, _ = split_parts(mesh)
    # one entry per (element, distinct node of it)
    corners = np.sort(split.elements.astype(np.int64), axis=1)
    first = np.ones(corners.shape, bool)
    first[:, 1:] = corners[:, 1:] != corners[:, :-1]
    rows = np.repeat(np.arange(mesh.n_elements), 4).reshape(corners.shape)[first]
    incidence = sparse.csr_matrix((np.ones(len(rows)), (corners[first], rows)),
                                  shape=(split.n_nodes, mesh.n_elements))
    per_state = values.ndim == 2
    v = values if per_state else values[None]
    steps = range(len(v))
    alive = [mesh.alive(t) if per_state else np.ones(mesh.n_elements, bool) for t in steps]
    weight = np.stack(alive) & np.isfinite(v)
    sums = incidence @ np.where(weight, v, 0.0).T  # (N', T)
    counts = incidence @ weight.T.astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(counts > 0, sums / np.where(counts > 0, counts, 1.0), np.nan).T
    return _with_field(split, "node", f"{field}_smooth", mean if per_state else mean[0])


# ------------------------------------------------------------------ envelope
def envelope(mesh: FEMesh, field: str) -> FEMesh:
    """The maximum of ``field`` over the states, per node or element, as the static field
    ``FIELD_envelope``: over the states at which the element is alive (a node: used by an
    element alive), missing values left out; NaN where none is left. A static field is its
    own envelope."""
    kind, values = _values(mesh, field)
    if values.ndim == 2:
        values = values.copy()
        if mesh.erodes:
            for t in range(len(values)):
                values[t, ~(mesh.live_nodes(t) if kind == "node" else mesh.alive(t))] = np.nan
        values = np.fmax.reduce(values, axis=0)  # NaN only where every state is NaN
    return _with_field(mesh, kind, f"{field}_envelope", values)


# ------------------------------------------------------------------ differences
def relative_to_state(mesh: FEMesh, field: str, state: int) -> FEMesh:
    """``field`` minus its values at ``state`` (per node or element, every state), as
    ``FIELD_minus_stateK``; ValueError for a static field or a state out of range."""
    kind, values = _values(mesh, field)
    state = mesh.step_index(state, "--relative-to state")
    if values.ndim != 2:
        raise ValueError(f"{field!r} of {mesh.name} is static (one value for every state): "
                         f"relative to a state it is 0 everywhere")
    return _with_field(mesh, kind, f"{field}_minus_state{state}", values - values[state])


def id_mapping(ids: np.ndarray | None, other_ids: np.ndarray | None, what: str,
               names: tuple[str, str]) -> np.ndarray:
    """``index`` with ``other_ids[index] == ids``: where each of ``ids`` is in ``other_ids``
    (a repeated id, such as the faces of one solid, pairs its occurrences in order).
    ValueError in one line when either has no ids or they are not the same ids (``what``:
    "node" or "element"; ``names``: the two meshes, for the message)."""
    for found, name in zip((ids, other_ids), names):
        if found is None:
            raise ValueError(f"{name} has no {what} ids: the runs cannot be mapped by id")
    ids, other_ids = np.asarray(ids), np.asarray(other_ids)
    if len(ids) != len(other_ids):
        raise ValueError(f"{what} ids do not match: {names[0]} has {len(ids)} {what}s, "
                         f"{names[1]} {len(other_ids)}")
    mine, theirs = np.argsort(ids, kind="stable"), np.argsort(other_ids, kind="stable")
    if (ids[mine] != other_ids[theirs]).any():
        for a, b, first, second in ((ids, other_ids, *names), (other_ids, ids, *names[::-1])):
            missing = np.setdiff1d(a, b)
            if len(missing):
                raise ValueError(
                    f"{what} ids do not match: {len(missing)} of the {what} ids of {first} are "
                    f"not in {second} (first: {', '.join(map(str, missing[:3].tolist()))})")
        raise ValueError(f"{what} ids do not match: {names[0]} and {names[1]} repeat them "
                         f"differently")
    index = np.empty(len(ids), np.int64)
    index[mine] = theirs
    return index


def relative_to_run(mesh: FEMesh, other: FEMesh, field: str,
                    names: tuple[str, str] | None = None) -> FEMesh:
    """``field`` minus the same field of ``other``, another run of the same model, mapped by
    node or element id (:func:`id_mapping`), as ``FIELD_minus_run``. Both static, or both of
    the same number of states (compared state by state); ValueError otherwise, and where the
    ids do not match; KeyError where ``other`` lacks the field. ``names``: the two runs in
    messages (default: the meshes' names)."""
    kind, values = _values(mesh, field)
    other_kind, other_values = _values(other, field)
    names = names or (mesh.name, other.name)
    if other_kind != kind:
        raise ValueError(f"{field!r} is a {kind} field of {names[0]} but a {other_kind} field "
                         f"of {names[1]}")
    if values.ndim != other_values.ndim or (values.ndim == 2 and
                                            len(values) != len(other_values)):
        raise ValueError(f"the runs differ in their states: {names[0]} has {mesh.n_steps}, "
                         f"{names[1]} {other.n_steps}; they are compared state by state")
    ids = (mesh.node_ids, other.node_ids) if kind == "node" else \
        (mesh.element_ids, other.element_ids)
    index = id_mapping(*ids, kind, names)
    return _with_field(mesh, kind, f"{field}_minus_run", values - other_values[..., index])
