"""The element kinds of a d3plot beside shells and solids: thick shells, beams, SPH particles.

Read through lasso-python's arrays, for :func:`~workbench.scene.readers.d3plot.read_d3plot`:

* **Thick shells** (8-node) are drawn as the solids they are shaped like: their arrays are
  appended to the solid arrays before the solids are read (:func:`merge_thick_shells`), so they
  are drawn by their boundary faces, keep their part and id, and get the solid fields (von
  Mises of the stress averaged over the written layers, the mean plastic strain, ``alive``).
  Where the solids and thick shells write different numbers of integration points or layers,
  both are averaged over them first (the mean is what the solid fields use); an array the other
  kind lacks, or whose shape does not fit, is NaN on it.
* **Beams** (:class:`~workbench.scene.kinds.Beams`; spot welds, rods, trusses and discrete
  springs are beams in a d3plot): end nodes n1, n2 (the orientation node is not kept), part,
  id, and the fields ``"axial_force"`` and ``"torsion_moment"`` (the model's force and moment
  units) and ``"alive"`` where the file has them.
* **SPH particles** (:class:`~workbench.scene.kinds.Particles`): node, part (the SPH material
  index of the file, numbered as the parts), the fields ``"pressure"``, ``"density"``,
  ``"plastic_strain"`` and ``"alive"`` (0 where the state's deletion flag is set) where
  written. The radius drawn is the file's per-state SPH radius where it is written and
  positive; otherwise half the initial distance to the nearest other particle
  (:func:`spacing_radius`), with a note.

Named in a note (a ParseWarning of the reader), never dropped silently: airbag particles and
rigid road segments (not drawn). A file holding only beams and/or SPH particles is refused
(ParseError naming what it holds): a mesh is drawn from its surface.
"""

from __future__ import annotations

import numpy as np

from ..kinds import Beams, Particles

# per-element arrays whose element axis is the first (geometry); the state arrays' is the second
_GEOMETRY = ("node_indexes", "part_indexes", "ids")


def merge_thick_shells(arrays: dict, ArrayType) -> int:
    """Append the thick shells' arrays to the solids' in ``arrays`` (changed in place, a
    copy of lasso-python's dict); returns the number of thick shells (0: nothing changed)."""
    prefix_t, prefix_s = "element_tshell_", "element_solid_"
    tshells = arrays.get(ArrayType.element_tshell_node_indexes)
    if tshells is None or len(tshells) == 0:
        return 0
    n_t = len(tshells)
    solids = arrays.get(ArrayType.element_solid_node_indexes)
    n_s = 0 if solids is None else len(solids)
    suffixes = {k[len(prefix_t):] for k in arrays if k.startswith(prefix_t)} | \
        {k[len(prefix_s):] for k in arrays if k.startswith(prefix_s)}
    for suffix in sorted(suffixes):
        key_s, key_t = prefix_s + suffix, prefix_t + suffix
        solid, thick = arrays.pop(key_s, None), arrays.pop(key_t, None)
        axis = 0 if suffix in _GEOMETRY else 1
        if n_s == 0:  # no solids: the thick shells' arrays are the solids'
            if thick is not None:
                arrays[key_s] = np.asarray(thick)
            continue
        if solid is None and suffix in _GEOMETRY:
            continue  # e.g. ids of the thick shells but not of the solids: none kept
        merged = _concat(solid, thick, axis, n_s, n_t)
        if merged is not None:
            arrays[key_s] = merged
    return n_t


def _concat(solid, thick, axis: int, n_s: int, n_t: int) -> np.ndarray | None:
    """``solid`` then ``thick`` along the element ``axis``; a missing or unfitting side is NaN
    (geometry arrays must fit: None when they do not)."""
    if solid is None or thick is None:
        have = np.asarray(solid if solid is not None else thick)
        if axis == 0 or have.ndim < 2:
            return None
        shape = list(have.shape)
        shape[1] = n_t if solid is not None else n_s
        nan = np.full(shape, np.nan)
        parts = [have, nan] if solid is not None else [nan, have]
        return np.concatenate([p.astype(np.float64) for p in parts], axis=1)
    solid, thick = np.asarray(solid), np.asarray(thick)
    if axis == 0:
        if solid.shape[1:] != thick.shape[1:]:
            return None
        return np.concatenate([solid, thick.astype(solid.dtype)])
    if solid.ndim == thick.ndim and solid.ndim >= 3 and solid.shape[3:] == thick.shape[3:] \
            and solid.shape[2] != thick.shape[2]:  # different point counts: their means
        solid = solid.astype(np.float64).mean(axis=2, keepdims=True)
        thick = thick.astype(np.float64).mean(axis=2, keepdims=True)
    if solid.shape[2:] != thick.shape[2:] or len(solid) != len(thick):
        thick = np.full((len(solid), n_t, *solid.shape[2:]), np.nan)
    return np.concatenate([solid.astype(np.float64), thick.astype(np.float64)], axis=1)


def only_kinds_message(arrays: dict, ArrayType) -> str | None:
    """Why a d3plot without shells, solids or thick shells cannot be drawn, naming the beams
    and SPH particles it holds; None where it has a surface."""
    for key in (ArrayType.element_shell_node_indexes, ArrayType.element_solid_node_indexes):
        if len(arrays.get(key, ())) > 0:
            return None
    held = [f"{n} {what}" for what, n in (
        ("beams", len(arrays.get(ArrayType.element_beam_node_indexes, ()))),
        ("SPH particles", len(arrays.get(ArrayType.sph_node_indexes, ())))) if n]
    return ("no shell, solid or thick shell elements in the d3plot" +
            (f": it holds {' and '.join(held)} only, and a mesh is drawn from its surface "
             f"elements" if held else ""))


def spacing_radius(points: np.ndarray) -> np.ndarray:
    """(P,) half the distance from each of ``points`` (P, 3) to its nearest other point, in
    their units; a point with no other (or only coincident ones) takes the median of the
    others' radii, or 1/200 of the points' box diagonal (1.0 for a single point)."""
    from scipy.spatial import cKDTree

    points = np.asarray(points, np.float64)
    radius = np.full(len(points), np.nan)
    if len(points) > 1:
        distance, _ = cKDTree(points).query(points, k=2)
        radius = distance[:, 1] / 2.0
    good = np.isfinite(radius) & (radius > 0)
    if not good.all():
        diagonal = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0
        fill = float(np.median(radius[good])) if good.any() else \
            (diagonal / 200.0 if diagonal > 0 else 1.0)
        radius[~good] = fill
    return radius


def read_beams(arrays: dict, ArrayType, n_states: int, part_ids) -> Beams | None:
    """The beams of the d3plot (None without); ``part_ids(part_index)`` gives user part ids."""
    nodes = arrays.get(ArrayType.element_beam_node_indexes)
    if nodes is None or len(nodes) == 0:
        return None
    nodes = np.asarray(nodes, np.int64)[:, :2]
    part_index = np.asarray(arrays.get(ArrayType.element_beam_part_indexes,
                                       np.zeros(len(nodes))), np.int64)
    ids = arrays.get(ArrayType.element_beam_ids)
    ids = None if ids is None or len(ids) != len(nodes) else np.asarray(ids, np.int64)
    fields = _state_fields(arrays, n_states, len(nodes), {
        "axial_force": ArrayType.element_beam_axial_force,
        "torsion_moment": ArrayType.element_beam_torsion_moment,
        "alive": ArrayType.element_beam_is_alive})
    return Beams(parts=part_ids(part_index), ids=ids, fields=fields, nodes=nodes)


def read_particles(arrays: dict, ArrayType, n_states: int, nodes: np.ndarray, part_ids,
                   notes: list[str]) -> Particles | None:
    """The SPH particles of the d3plot (None without); radius as the module notes say, a note
    in ``notes`` where it is not the file's."""
    node = arrays.get(ArrayType.sph_node_indexes)
    if node is None or len(node) == 0:
        return None
    node = np.asarray(node, np.int64)
    part_index = np.asarray(arrays.get(ArrayType.sph_node_material_index, np.zeros(len(node))),
                            np.int64)
    fields = _state_fields(arrays, n_states, len(node), {
        "pressure": ArrayType.sph_pressure, "density": ArrayType.sph_density,
        "plastic_strain": ArrayType.sph_effective_plastic_strain})
    deletion = arrays.get(ArrayType.sph_deletion)
    if deletion is not None and np.shape(deletion) == (n_states, len(node)) and n_states:
        fields["alive"] = 1.0 - np.asarray(deletion, np.float64)
    radius = arrays.get(ArrayType.sph_radius)
    radius = None if radius is None else np.asarray(radius, np.float64)
    if radius is None or not n_states or radius.shape != (n_states, len(node)) or \
            not (np.isfinite(radius) & (radius > 0)).all():
        inside = (node >= 0) & (node < len(nodes))
        radius = np.ones(len(node))
        radius[inside] = spacing_radius(nodes[node[inside]])
        notes.append(f"the d3plot gives no usable SPH radius: {len(node)} SPH particles are "
                     f"drawn with half the initial spacing to their nearest neighbour")
    return Particles(parts=part_ids(part_index), ids=None, fields=fields, node=node,
                     radius=radius)


def _state_fields(arrays: dict, n_states: int, count: int, names: dict) -> dict:
    """{name: (T, count) float64} of the arrays of ``names`` that fit (others left out)."""
    out = {}
    for name, key in names.items():
        values = arrays.get(key)
        if values is not None and n_states and np.shape(values) == (n_states, count):
            out[name] = np.asarray(values, np.float64)
    return out


def not_drawn_notes(arrays: dict, ArrayType) -> list[str]:
    """A note per kind the d3plot holds that is not drawn, with its count."""
    notes = []
    airbag = arrays.get(ArrayType.airbag_particle_position)  # (T, particles, 3)
    if airbag is not None and np.ndim(airbag) == 3 and np.shape(airbag)[1]:
        notes.append(f"{np.shape(airbag)[1]} airbag particles not drawn: they are not read")
    road = arrays.get(ArrayType.rigid_road_segment_node_ids)
    if road is not None and len(road):
        notes.append(f"{len(road)} rigid road segments not drawn: they are not read")
    return notes
