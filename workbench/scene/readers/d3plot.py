"""LS-DYNA d3plot reader (through lasso-python): shell geometry of every state plus shell results.

A d3plot's state "displacement" array holds the current node coordinates (the database's IU
flag writes geometry, not displacement), so it becomes ``FEMesh.steps`` (T, N, 3) as it is;
``FEMesh.nodes`` is the initial geometry and ``FEMesh.times`` the state times. Shell element
fields, (T, M) each and present when the file has the data:

* ``"von_mises"``: von Mises stress of the mid-surface integration point (stress units of the
  model, e.g. MPa for mm/ms/kg... decks), from the six stress components;
* ``"plastic_strain"``: effective plastic strain of the mid-surface integration point;
* ``"thickness"``: current shell thickness;
* ``"alive"``: 1 for an element in use, 0 for a deleted one (nothing is dropped);
* ``"stress_xx"``, ``"stress_yy"``, ``"stress_zz"``, ``"stress_xy"``, ``"stress_yz"``,
  ``"stress_zx"``: the six components of the shell's mid-surface (membrane) stress tensor, the
  mean of the written through-thickness layers (:func:`through_thickness_mean`), for section
  forces (:mod:`workbench.algo.forcetube`). They can be left out (``stress_components=False``)
  to save memory on large results.

**Stress coordinates.** LS-DYNA writes the shell stress tensor of a d3plot in the *global*
Cartesian system, and lasso-python's ``element_shell_stress`` ((T, shells, layers, 6), ordered
xx, yy, zz, xy, yz, zx) holds it as written; only the force/moment resultants are in element
axes. The one exception is a deck that sets ``CMPFLG = 1`` in ``*DATABASE_EXTENT_BINARY``:
then orthotropic and anisotropic materials are written in their material axes, and nothing
in the file says so — such results would need transforming before their tensors are used.

The mid-surface point of ``von_mises`` and ``plastic_strain`` follows the d3plot layer order:
with 3 layers (LS-DYNA's default MAXINT) they are written mid, inner, outer, so the first;
otherwise bottom to top, so the middle one (the mean of the two middle ones for an even
count). Shells of rigid parts carry no stress, strain or thickness in a d3plot; their values
are NaN. Beams, solids and thick shells are not read. Part ids are the user part ids, names
come from the part titles.

Refused with :class:`~workbench.scene.readers.errors.ParseError`: a file lasso-python cannot
read, or one without shell or solid elements.
"""

from __future__ import annotations

import logging
import os
import re
from dataclasses import dataclass
from pathlib import Path
from warnings import warn as _warn

import numpy as np

from ..mesh import FEMesh
from .errors import ParseError, ParseWarning, build_mesh

RIGID_MATERIAL_TYPE = 20
STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "zx")  # d3plot (and lasso-python) order


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of (..., 6) stress tensors ordered xx, yy, zz, xy, yz, zx.

    sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2) / 2 + 3 (sxy^2 + syz^2 + szx^2)), in the
    units of the input; float64.
    """
    s = np.asarray(stress, dtype=np.float64)
    if s.shape[-1] != 6:
        raise ValueError(f"stress must be (..., 6), got {s.shape}")
    xx, yy, zz, xy, yz, zx = np.moveaxis(s, -1, 0)
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                   + 3.0 * (xy ** 2 + yz ** 2 + zx ** 2))


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


def through_thickness_mean(values: np.ndarray, layer_axis: int = 2) -> np.ndarray:
    """float64 mean of shell data over the through-thickness layers on ``layer_axis``.

    With LS-DYNA's defaults (2 integration points through the thickness, 3 layers written:
    the mid surface as the mean of the two, then the inner and outer point) this is the
    membrane stress exactly, also for plastic states (2-point Gauss integration of the
    resultant); with more points the written layers are a subset of them and the mean is the
    membrane value exactly while the stress varies linearly through the thickness, an
    approximation otherwise.
    """
    values = np.asarray(values, dtype=np.float64)
    if values.shape[layer_axis] == 0:
        raise ValueError("no integration-point layers")
    return values.mean(axis=layer_axis)


def read_d3plot(path: str | os.PathLike[str], units: str = "mm", all_faces: bool = False,
                stress_components: bool = True) -> FEMesh:
    """Read a d3plot family (``d3plot``, ``d3plot01``, ...) into an :class:`FEMesh` with steps.

    ``path`` is the first file of the family; a later member (``d3plot01``) is read from the
    first one beside it. See the module notes for the fields. ``units`` labels the coordinates.
    Solid elements are drawn by their boundary faces (every face with ``all_faces``), each
    keeping its solid's id and part; the shell fields are NaN on them. ``stress_components``
    reads the six mid-surface stress components as element fields.
    """
    from lasso.dyna import ArrayType

    path = _first_member(Path(path))
    arrays, warnings = _lasso_arrays(path)
    elements = _elements(path, arrays, ArrayType, warnings, all_faces)
    parts, part_names = _parts(path, arrays, ArrayType, warnings, elements.part_index)
    steps = times = None
    if ArrayType.node_displacement in arrays and len(arrays[ArrayType.node_displacement]):
        steps = np.asarray(arrays[ArrayType.node_displacement], dtype=np.float64)
        times = np.asarray(arrays.get(ArrayType.global_timesteps, np.arange(len(steps))),
                           dtype=np.float64)
    n_states = 0 if steps is None else len(steps)
    fields = {}
    if n_states:
        fields = _shell_fields(arrays, ArrayType, elements, n_states, stress_components)
        if elements.n_solids:
            _solid_fields(fields, arrays, ArrayType, elements.face_of, elements.n_shells,
                          n_states)

    node_ids = arrays.get(ArrayType.node_ids)
    mesh = build_mesh(
        path, nodes=elements.nodes, elements=elements.connectivity, parts=parts,
        steps=steps, times=times, element_fields=fields, part_names=part_names,
        node_ids=None if node_ids is None else np.asarray(node_ids, dtype=np.int64),
        element_ids=elements.element_ids, name=path.name, units=units)
    for failure in warnings.failures:  # read, but with sections missing: say which
        _warn(ParseWarning(path, f"lasso-python could not read {failure}: what it holds is "
                                 f"missing"), stacklevel=2)
    return mesh


def _first_member(path: Path) -> Path:
    """The first file of the d3plot family ``path`` belongs to: ``d3plot`` for ``d3plot01``
    when it lies beside it, else ``path`` itself."""
    member = re.fullmatch(r"(d3plot.*?)(\d{2,})", path.name, flags=re.IGNORECASE)
    if member and (path.parent / member.group(1)).is_file():
        return path.parent / member.group(1)
    return path


def _lasso_arrays(path: Path):
    """(lasso-python's arrays of the d3plot family at ``path``, the warnings it logged while
    reading); ParseError when it cannot read the file at all."""
    from lasso.dyna import D3plot

    warnings = _LassoWarnings()
    logger = logging.getLogger("lasso")
    logger.addHandler(warnings)
    propagate, logger.propagate = logger.propagate, False  # its tracebacks are ours to report
    try:
        plot = D3plot(str(path))
    except Exception as exc:  # lasso raises many types; all mean "cannot read this file"
        raise ParseError(path, f"lasso-python could not read it: {type(exc).__name__}: "
                               f"{str(exc).strip()}") from exc
    finally:
        logger.removeHandler(warnings)
        logger.propagate = propagate
    return plot.arrays, warnings


def _need(path: Path, arrays, key, warnings: _LassoWarnings):
    """``arrays[key]``; ParseError naming what is missing (and what lasso-python gave up on)."""
    if key not in arrays:
        raise ParseError(path, f"no {key} in the d3plot" + warnings.summary())
    return arrays[key]


@dataclass
class _Elements:
    """What is drawn of a d3plot: the shells, then the faces of its solids."""

    nodes: np.ndarray  # (N, 3) initial coordinates
    connectivity: np.ndarray  # (M, 4) node indices: shells, then solid faces
    part_index: np.ndarray  # (M,) internal part index of each
    element_ids: np.ndarray | None  # (M,) user ids (a face: its solid's), None when unknown
    face_of: np.ndarray  # (M - n_shells,) the solid of each face
    n_shells: int
    n_solids: int


def _elements(path: Path, arrays, ArrayType, warnings: _LassoWarnings,
              all_faces: bool) -> _Elements:
    """The shells and solid faces of the d3plot (every face of the solids with ``all_faces``);
    ParseError for a file without either, or missing part indexes."""
    nodes = np.asarray(_need(path, arrays, ArrayType.node_coordinates, warnings),
                       dtype=np.float64)
    connectivity = np.asarray(arrays.get(ArrayType.element_shell_node_indexes, np.zeros((0, 4))),
                              dtype=np.int64)
    solids = np.asarray(arrays.get(ArrayType.element_solid_node_indexes, np.zeros((0, 8))),
                        dtype=np.int64)
    if len(connectivity) == 0 and len(solids) == 0:
        raise ParseError(path, "no shell or solid elements in the d3plot (beams and thick "
                               "shells are not read)" + warnings.summary())
    n_shells = len(connectivity)
    part_index = np.asarray(_need(path, arrays, ArrayType.element_shell_part_indexes, warnings)
                            if n_shells else np.zeros(0), dtype=np.int64)
    element_ids = arrays.get(ArrayType.element_shell_ids)
    element_ids = None if element_ids is None else np.asarray(element_ids, dtype=np.int64)
    face_of = np.zeros(0, np.int64)
    if len(solids):  # drawn by their boundary faces (every face with all_faces)
        from ..solids import boundary_surface

        solid_part_index = np.asarray(
            _need(path, arrays, ArrayType.element_solid_part_indexes, warnings), np.int64)
        try:
            faces, face_part_index, face_of = boundary_surface(solids, nodes, solid_part_index,
                                                               all_faces)
        except ValueError as exc:
            raise ParseError(path, f"solid elements: {exc}") from None
        connectivity = np.concatenate([connectivity, faces])
        part_index = np.concatenate([part_index, face_part_index])
        solid_ids = arrays.get(ArrayType.element_solid_ids)
        if solid_ids is not None and (element_ids is not None or n_shells == 0):
            shell_ids = element_ids if element_ids is not None else np.zeros(0, np.int64)
            element_ids = np.concatenate([shell_ids, np.asarray(solid_ids, np.int64)[face_of]])
        else:
            element_ids = None
    return _Elements(nodes, connectivity, part_index, element_ids, face_of, n_shells,
                     len(solids))


def _parts(path: Path, arrays, ArrayType, warnings: _LassoWarnings,
           part_index: np.ndarray) -> tuple[np.ndarray, dict[int, str]]:
    """:func:`_part_ids` of the elements; ParseError when their part indexes are out of range."""
    try:
        if len(part_index) and part_index.min() < 0:
            raise ValueError(f"index {int(part_index.min())}")
        return _part_ids(arrays, part_index, ArrayType)
    except (IndexError, ValueError) as exc:
        raise ParseError(path, f"element part indexes out of range ({exc}): the file is "
                               f"damaged" + warnings.summary()) from None


def _shell_fields(arrays, ArrayType, elements: _Elements, n_states: int,
                  stress_components: bool) -> dict[str, np.ndarray]:
    """The (T, M) shell fields of the module notes that the file holds, NaN on the solid faces
    and on the shells of rigid parts (which have no stress, strain or thickness records)."""
    n_shells = elements.n_shells
    n_faces = len(elements.connectivity) - n_shells  # solid faces carry no shell field: NaN
    deformable = np.ones(n_shells, bool)
    if ArrayType.part_material_type in arrays:
        material = np.asarray(arrays[ArrayType.part_material_type])
        shell_part_index = elements.part_index[:n_shells]
        inside = shell_part_index < len(material)
        deformable[inside] = material[shell_part_index[inside]] != RIGID_MATERIAL_TYPE

    def per_shell(values: np.ndarray) -> np.ndarray | None:
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 2 or len(values) != n_states:
            return None
        full = np.full((n_states, n_shells + n_faces), np.nan)
        if values.shape[1] == n_shells:
            full[:, :n_shells] = values
            return full
        if values.shape[1] == deformable.sum():
            full[:, :n_shells][:, deformable] = values
            return full
        return None

    fields = {}
    if ArrayType.element_shell_stress in arrays:
        fields["von_mises"] = per_shell(von_mises(mid_surface(
            arrays[ArrayType.element_shell_stress], layer_axis=2)))
        stress = np.asarray(arrays[ArrayType.element_shell_stress])
        if stress_components and stress.ndim == 4 and stress.shape[3] == 6:
            membrane = through_thickness_mean(stress, layer_axis=2)
            for k, name in enumerate(STRESS_COMPONENTS):
                fields[f"stress_{name}"] = per_shell(membrane[..., k])
    if ArrayType.element_shell_effective_plastic_strain in arrays:
        fields["plastic_strain"] = per_shell(mid_surface(
            arrays[ArrayType.element_shell_effective_plastic_strain], layer_axis=2))
    if ArrayType.element_shell_thickness in arrays:
        fields["thickness"] = per_shell(arrays[ArrayType.element_shell_thickness])
    if ArrayType.element_shell_is_alive in arrays:
        fields["alive"] = per_shell(arrays[ArrayType.element_shell_is_alive])
    return {k: v for k, v in fields.items() if v is not None}


def _solid_fields(fields: dict, arrays, ArrayType, face_of: np.ndarray, n_shells: int,
                  n_states: int) -> None:
    """Give the solid faces (the columns after ``n_shells``) their solid's values: von Mises
    of the solid's stress averaged over its integration points, the mean effective plastic
    strain, and alive; a field the shells lack is NaN on them."""
    n_faces = len(face_of)
    solid_values = {}
    if ArrayType.element_solid_stress in arrays:
        stress = np.asarray(arrays[ArrayType.element_solid_stress], dtype=np.float64)
        if stress.ndim == 4 and len(stress) == n_states:
            solid_values["von_mises"] = von_mises(stress.mean(axis=2))
    if ArrayType.element_solid_effective_plastic_strain in arrays:
        strain = np.asarray(arrays[ArrayType.element_solid_effective_plastic_strain], np.float64)
        if strain.ndim == 3 and len(strain) == n_states:
            solid_values["plastic_strain"] = strain.mean(axis=2)
    if ArrayType.element_solid_is_alive in arrays:
        alive = np.asarray(arrays[ArrayType.element_solid_is_alive], dtype=np.float64)
        if alive.ndim == 2 and len(alive) == n_states:
            solid_values["alive"] = alive
    for name, values in solid_values.items():
        if name not in fields:
            fields[name] = np.full((n_states, n_shells + n_faces), np.nan)
        fields[name][:, n_shells:] = values[:, face_of]


def _part_ids(arrays, part_index: np.ndarray, ArrayType) -> tuple[np.ndarray, dict[int, str]]:
    """User part ids of the shells and the part titles.

    The shells name parts by internal index; the user ids come from the numbering section
    (``part_ids``), else from the part titles section (written in internal order), else the
    index + 1.
    """
    title_ids = arrays.get(ArrayType.part_titles_ids)
    titles = arrays.get(ArrayType.part_titles)
    top = int(part_index.max()) + 1 if len(part_index) else 0
    user = None
    if ArrayType.part_ids in arrays and len(arrays[ArrayType.part_ids]) >= top:
        user = np.asarray(arrays[ArrayType.part_ids], dtype=np.int64)
    elif title_ids is not None and len(title_ids) >= top:
        user = np.asarray(title_ids, dtype=np.int64)
    parts = part_index + 1 if user is None else user[part_index]
    names = {}
    if title_ids is not None and titles is not None:
        for pid, title in zip(np.asarray(title_ids).tolist(), list(titles)):
            text = title.decode("latin-1") if isinstance(title, bytes) else str(title)
            if text.strip():
                names[int(pid)] = text.strip()
    used = set(np.unique(parts).tolist())
    return parts, {pid: name for pid, name in names.items() if pid in used}


class _LassoWarnings(logging.Handler):
    """Collects lasso-python's warnings (it logs, rather than raises, on damaged sections)."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)

    @property
    def failures(self) -> list[str]:
        """One phrase per section lasso-python gave up on: what it was reading and why (the
        last line of the traceback it logged)."""
        out = []
        for record in self.records:
            try:
                text = record.getMessage()
            except (TypeError, ValueError):  # lasso-python's own message may not format
                text = f"{record.msg} {record.args}"
            if record.exc_info and record.exc_info[1] is not None:
                text += f"\n{type(record.exc_info[1]).__name__}: {record.exc_info[1]}"
            lines = [line.strip() for line in text.splitlines() if line.strip()]
            what = re.sub(r"^A failure in (.*?) was caught:?$", r"\1", lines[0])
            why = lines[-1] if len(lines) > 1 else ""
            out.append(f"{what} ({why})" if why else what)
        return out

    def summary(self) -> str:
        failures = self.failures
        return f" (lasso-python could not read {'; '.join(failures[:3])})" if failures else ""
