"""The fields of a d3plot read on request (for :mod:`workbench.scene.readers.d3plot`): nodal
displacement, velocity and acceleration, the scalars of the stress tensor, and the choice of
the shell layer.

**What is read.** :func:`~workbench.scene.readers.d3plot.read_d3plot` always gives the fields
of its module notes (von Mises, plastic strain, thickness, alive and the membrane stress
components); the others of :data:`FIELDS` only when named in its ``extra_fields`` (``"all"``:
every one the file offers). A result of 500 000 shells and 20 states holds 80 MB per (T, M)
float64 field, so nothing is derived that nobody asked for: the command line asks for the
field it draws, ``workbench info`` names what a file offers (:func:`offered_fields`, from the
header alone) without deriving it.

**Node fields**, (T, N) each: ``displacement`` (magnitude) and ``displacement_x|y|z``, the
state's coordinates minus the initial ones (both float32 in the file, so the difference is
exact in float64); ``velocity`` and ``acceleration`` with their ``_x|y|z`` components, where the
states hold them (LS-DYNA's IV and IA flags), in the model's units (length/time, length/time²).

**Stress scalars** (:mod:`workbench.scene.stress_tensor`): ``signed_von_mises``,
``principal_max|mid|min``, ``max_shear``, ``pressure``, ``triaxiality`` (and ``von_mises``),
from the global-coordinate stress tensor of the chosen shell layer; solid faces get those of
their solid's tensor averaged over its integration points (the layer does not apply).

**Layers** (:data:`LAYERS`): ``mid`` (default), ``bottom``, ``top``, ``max``, ``min``. With 3
layers written (LS-DYNA's default) they are in the order mid, inner (bottom), outer (top);
with any other count bottom to top, the mid surface the middle one (the mean tensor of the two
middle ones for an even count). ``max`` and ``min`` are taken over the written layers of the
derived scalar (the largest von Mises of the layers, say), not of the tensor, leaving out a
layer where it is undefined (triaxiality without deviatoric stress). The layer applies
to every layered shell field: the stress scalars, ``von_mises`` and ``plastic_strain``;
``stress_xx`` ... stay the membrane (through-thickness mean) components the force tubes need.
``mid`` is the default because it keeps earlier results as they were and because bottom and
top follow each shell's normal, which is not oriented consistently across the parts of a car
model (bottom of one part, top of the next); in bending the surfaces carry more (``max`` is the
layer for a failure check).
"""

from __future__ import annotations

import numpy as np

from ..stress_tensor import SCALARS, principal_stresses, stress_scalar
from .d3plot_family import STRESS_COMPONENTS, header_fields

RIGID_MATERIAL_TYPE = 20  # LS-DYNA's *MAT_RIGID: a part without stress, strain or thickness
LAYERS = ("mid", "bottom", "top", "max", "min")
DEFAULT_LAYER = "mid"
AXES = ("x", "y", "z")
# the node vectors by field name, with lasso-python's array of each
NODE_VECTORS = {"displacement": "node_displacement", "velocity": "node_velocity",
                "acceleration": "node_acceleration"}

# every field of a d3plot by name, with what it is (the command line's help)
FIELDS: dict[str, str] = {
    "displacement": "node: magnitude of the displacement (state minus initial coordinates)",
    **{f"displacement_{a}": f"node: {a} component of the displacement" for a in AXES},
    "velocity": "node: magnitude of the velocity",
    **{f"velocity_{a}": f"node: {a} component of the velocity" for a in AXES},
    "acceleration": "node: magnitude of the acceleration",
    **{f"acceleration_{a}": f"node: {a} component of the acceleration" for a in AXES},
    **{name: f"element, layered: {what}" for name, what in SCALARS.items()},
    "plastic_strain": "element, layered: effective plastic strain",
    "thickness": "element: current shell thickness",
    "alive": "element: 1 in use, 0 deleted (erosion)",
    **{f"stress_{c}": f"element: membrane (through-thickness mean) stress {c}"
       for c in STRESS_COMPONENTS},
}


def check_layer(layer: str) -> str:
    """``layer`` when it is one of :data:`LAYERS`; ValueError naming them otherwise."""
    if layer not in LAYERS:
        raise ValueError(f"unknown shell layer {layer!r}; choose one of {', '.join(LAYERS)}")
    return layer


class EveryField(set):
    """The names of ``extra_fields="all"``: those the file cannot give are left out without a
    note."""


def requested_fields(extra_fields) -> set[str]:
    """The names of ``extra_fields`` (an iterable of names of :data:`FIELDS`, one name, or
    ``"all"``: :class:`EveryField`); ValueError naming the known ones for another name."""
    if isinstance(extra_fields, str):
        if extra_fields == "all":
            return EveryField(FIELDS)
        extra_fields = [extra_fields]
    names = set(extra_fields)
    unknown = sorted(names - set(FIELDS))
    if unknown:
        raise ValueError(f"no d3plot field {unknown[0]!r}; known: {', '.join(FIELDS)}")
    return names


def offered_fields(header) -> list[str]:
    """The names of :data:`FIELDS` that a d3plot with lasso-python's ``header``
    (``D3plotHeader``) can give, in the order of :data:`FIELDS`."""
    h = header
    have = set(header_fields(h))
    for name, flag in (("displacement", h.has_node_displacement),
                       ("velocity", h.has_node_velocity),
                       ("acceleration", h.has_node_acceleration)):
        if flag:
            have.update([name, *(f"{name}_{a}" for a in AXES)])
    if "von_mises" in have:  # a stress tensor: every scalar of it
        have.update(SCALARS)
    return [name for name in FIELDS if name in have]


def mid_surface(values: np.ndarray, layer_axis: int = 2) -> np.ndarray:
    """The mid-surface values of shell data with the through-thickness layers on ``layer_axis``.

    Three layers are in d3plot order mid, inner, outer (the first is taken); any other count is
    ordered bottom to top (the middle one, or the mean of the two middle ones when even).
    """
    values = np.asarray(values)
    n = values.shape[layer_axis]
    if n == 0:
        raise ValueError("no integration-point layers")
    if n == 3 or n == 1:
        return np.take(values, 0, axis=layer_axis)
    if n % 2:
        return np.take(values, n // 2, axis=layer_axis)
    pair = np.take(values, [n // 2 - 1, n // 2], axis=layer_axis).astype(np.float64)
    return pair.mean(axis=layer_axis)


def shell_layer(values: np.ndarray, layer: str, layer_axis: int = 1) -> np.ndarray:
    """The values of one layer (``mid``, ``bottom``, ``top``; module notes) of shell data with
    the written layers on ``layer_axis``."""
    n = values.shape[layer_axis]
    if layer == "mid" or n == 1:
        return mid_surface(values, layer_axis=layer_axis)
    bottom, top = (1, 2) if n == 3 else (0, n - 1)
    return np.take(values, bottom if layer == "bottom" else top, axis=layer_axis)


def layered_scalars(stress: np.ndarray, names, layer: str) -> dict[str, np.ndarray]:
    """{name: (T, S)} the stress scalars ``names`` of shell stresses (T, S, L, 6) at ``layer``
    (over the layers for ``max`` and ``min``), one state at a time (the float64 copies of a
    state's tensors are the only temporaries)."""
    names = list(names)
    out = {name: np.empty(stress.shape[:2]) for name in names}
    for t in range(len(stress)):
        state = np.asarray(stress[t], dtype=np.float64)  # (S, L, 6)
        if layer in ("max", "min"):
            reduce = (np.fmax if layer == "max" else np.fmin).reduce  # NaN: left out
            for name, values in _scalars(names, state).items():
                out[name][t] = reduce(values, axis=1)
        else:
            for name, values in _scalars(names, shell_layer(state, layer, 1)).items():
                out[name][t] = values
    return out


def _scalars(names: list[str], tensors: np.ndarray) -> dict[str, np.ndarray]:
    """{name: values} of the stress scalars ``names`` of (..., 6) ``tensors``, the principal
    stresses computed once for all three."""
    principal = None
    out = {}
    for name in names:
        if name.startswith("principal_"):
            if principal is None:
                principal = principal_stresses(tensors)
            out[name] = principal[..., ("principal_max", "principal_mid",
                                        "principal_min").index(name)]
        else:
            out[name] = stress_scalar(name, tensors)
    return out


def layered_strain(strain: np.ndarray, layer: str) -> np.ndarray:
    """(T, S) plastic strain of (T, S, L) shell values at ``layer`` (over the layers for
    ``max`` and ``min``), one state at a time."""
    out = np.empty(np.shape(strain)[:2])
    for t in range(len(out)):
        state = np.asarray(strain[t], dtype=np.float64)  # (S, L)
        if layer == "max":
            out[t] = state.max(axis=1)
        elif layer == "min":
            out[t] = state.min(axis=1)
        else:
            out[t] = shell_layer(state, layer, layer_axis=1)
    return out


def node_fields(arrays: dict, ArrayType, names: set[str], steps, nodes: np.ndarray,
                n_states: int, notes: list[str]) -> dict[str, np.ndarray]:
    """The node fields of ``names`` (module notes), (T, N) each; one note per vector the states
    do not hold."""
    out = {}
    for vector, key in NODE_VECTORS.items():
        wanted = [n for n in names if n == vector or n.startswith(f"{vector}_")]
        if not wanted:
            continue
        values = arrays.get(getattr(ArrayType, key))
        if values is None or np.shape(values) != (n_states, len(nodes), 3):
            if not isinstance(names, EveryField):
                notes.append(f"{', '.join(sorted(wanted))} asked for, but the states hold no "
                             f"node {vector}")
            continue
        # the states' "displacement" is the current coordinates, read as the steps
        values = np.asarray(steps) - nodes if vector == "displacement" else \
            np.asarray(values, dtype=np.float64)
        for name in wanted:
            if name == vector:
                out[name] = np.sqrt((values ** 2).sum(axis=2))
            else:
                out[name] = np.ascontiguousarray(values[..., AXES.index(name[-1])])
    return out


def element_fields(fields: dict, arrays: dict, ArrayType, elements, n_states: int,
                   names: set[str], layer: str, notes: list[str]) -> None:
    """Add to ``fields`` ((T, M) element fields of the reader) the stress scalars of ``names``
    and, for a layer other than ``mid``, ``von_mises`` and ``plastic_strain`` of that layer:
    shells by :func:`layered_scalars`, solid faces by their solid's mean tensor, NaN where
    there is no value (rigid shells, a kind without the data). One note per name the file
    cannot give."""
    n_shells, face_of = elements.n_shells, elements.face_of
    n_columns = len(elements.connectivity)
    scalars = [n for n in SCALARS if n in names or (n == "von_mises" and layer != "mid")]
    spread = _shell_spreader(arrays, ArrayType, elements, n_states)
    shell_stress = arrays.get(ArrayType.element_shell_stress)
    if shell_stress is not None and (np.ndim(shell_stress) != 4 or len(shell_stress) != n_states
                                     or np.shape(shell_stress)[3] != 6):
        shell_stress = None
    solid_stress = arrays.get(ArrayType.element_solid_stress)
    if solid_stress is not None and (np.ndim(solid_stress) != 4 or len(solid_stress) != n_states):
        solid_stress = None
    shell_values = {} if shell_stress is None or not n_shells or not scalars else \
        layered_scalars(shell_stress, scalars, layer)
    solid_mean = None
    if solid_stress is not None and len(face_of) and any(n not in fields for n in scalars):
        solid_mean = np.asarray(solid_stress, dtype=np.float64).mean(axis=2)
    for name in scalars:
        on_shells = name in shell_values
        if not on_shells and solid_mean is None:
            if name in names and not isinstance(names, EveryField):
                notes.append(f"{name} asked for, but the states hold no stress")
            continue
        column = fields.get(name)
        if column is None:  # a new field: the solid faces too (von_mises has them already)
            column = np.full((n_states, n_columns), np.nan)
            if solid_mean is not None:
                column[:, n_shells:n_shells + len(face_of)] = \
                    stress_scalar(name, solid_mean)[:, face_of]
        if on_shells:
            column[:, :n_shells] = spread(shell_values[name])
        fields[name] = column
    strain = arrays.get(ArrayType.element_shell_effective_plastic_strain)
    if layer != "mid" and strain is not None and n_shells and "plastic_strain" in fields \
            and np.ndim(strain) == 3 and len(strain) == n_states:
        fields["plastic_strain"][:, :n_shells] = spread(layered_strain(strain, layer))


def deformable_shells(arrays: dict, ArrayType, shell_part_index: np.ndarray) -> np.ndarray:
    """(S,) bool, the shells (by their part indexes) of parts that are not rigid: the ones a
    d3plot writes results for (every shell where the file gives no material types)."""
    deformable = np.ones(len(shell_part_index), bool)
    if ArrayType.part_material_type in arrays:
        material = np.asarray(arrays[ArrayType.part_material_type])
        inside = shell_part_index < len(material)
        deformable[inside] = material[shell_part_index[inside]] != RIGID_MATERIAL_TYPE
    return deformable


def _shell_spreader(arrays: dict, ArrayType, elements, n_states: int):
    """A function taking (T, S) values of the shells written with results (every shell, or
    the deformable ones: a rigid part's shells have none) to (T, shells), NaN where none."""
    n_shells = elements.n_shells
    deformable = deformable_shells(arrays, ArrayType, elements.part_index[:n_shells])

    def spread(values: np.ndarray) -> np.ndarray:
        if values.shape[1] == n_shells:
            return values
        full = np.full((n_states, n_shells), np.nan)
        if values.shape[1] == deformable.sum():
            full[:, deformable] = values
        return full

    return spread


def add_requested(fields: dict, arrays: dict, ArrayType, elements, n_states: int, steps,
                  names: set[str], layer: str, notes: list[str]) -> dict[str, np.ndarray]:
    """The reader's hook: add to ``fields`` the element fields of ``names`` and of ``layer``
    (:func:`element_fields`); return the node fields of ``names`` (:func:`node_fields`)."""
    if not n_states:
        return {}
    element_fields(fields, arrays, ArrayType, elements, n_states, names, layer, notes)
    return node_fields(arrays, ArrayType, names, steps, elements.nodes, n_states, notes)


def offered_by_file(path) -> list[str]:
    """:func:`offered_fields` of the d3plot at ``path``, from its header alone (no state is
    read); empty where lasso-python cannot read the header."""
    from lasso.dyna import D3plotHeader

    try:
        return offered_fields(D3plotHeader().load_file(str(path)))
    except Exception:  # lasso raises many types; the reader says why when the file is read
        return []
