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

**Fields on request.** More fields are derived only when asked for (``extra_fields``): nodal
displacement, velocity and acceleration (magnitude and components), principal stresses,
maximum shear, pressure, signed von Mises and triaxiality; ``layer`` chooses the shell layer
(mid, bottom, top, max, min over the layers) of the layered ones, von Mises and plastic strain
included. The default stays the mid surface and today's fields, so that a large result costs
no memory for fields nobody draws: the command line asks for the one it draws. Names, layer
order and why ``mid`` is the default: :mod:`~workbench.scene.readers.d3plot_fields`.

The mid-surface point of ``von_mises`` and ``plastic_strain`` follows the d3plot layer order:
with 3 layers (LS-DYNA's default MAXINT) they are written mid, inner, outer, so the first;
otherwise bottom to top, so the middle one (the mean of the two middle ones for an even
count). Shells of rigid parts carry no stress, strain or thickness in a d3plot; their values
are NaN. Solids, thick shells, beams and SPH particles: see the module notes of
:mod:`~workbench.scene.readers.d3plot_kinds`. Part ids are the user part ids, names
come from the part titles.

**Damaged families.** Each member of a family ends with the end-of-file marker (-999999.0)
right after its last whole state (:func:`family_layout`). Named in a ParseWarning, never
dropped silently: a member cut or with a damaged end (its whole states before are read), a
member missing from the numbering, no state at all (``d3plot01`` missing), bytes after a
marker, announced fields, times, coordinates or ids not read, and the shell (solid) fields of a
header whose flags do not fit its counts or that gives impossible values (not read). A lost
last member cannot be told from the end of the run. Refused with ParseError: a file
lasso-python cannot read, no shell or solid element, a member without data, a header whose
state size misses a member's marker or whose geometry runs past a complete first file. Every
message is one line: lasso-python's log and tracebacks are captured and reduced.
"""

from __future__ import annotations

import logging
import os
import re
import warnings as _python_warnings
from dataclasses import dataclass
from pathlib import Path
from warnings import warn as _warn

import numpy as np

from ..mesh import FEMesh
from ..stress_tensor import von_mises
from . import d3plot_fields
from . import d3plot_kinds as kinds
from .d3plot_family import (
    STRESS_COMPONENTS,
    Member,
    _data_end,
    _drop_damaged_layouts,
    _expected_fields,
    _family,
    _select_states,
    family_members,
)
from .d3plot_fields import mid_surface
from .errors import ParseError, ParseWarning, build_mesh


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
                stress_components: bool = True, extra_fields=(),
                layer: str = d3plot_fields.DEFAULT_LAYER) -> FEMesh:
    """Read a d3plot family (``d3plot``, ``d3plot01``, ...) into an :class:`FEMesh` with steps.

    ``path`` is the first file of the family; a later member (``d3plot01``) is read from the
    first one beside it. See the module notes for the fields. ``units`` labels the coordinates.
    Solid elements are drawn by their boundary faces (every face with ``all_faces``), each
    keeping its solid's id and part; the shell fields are NaN on them. ``stress_components``
    reads the six mid-surface stress components as element fields. ``extra_fields`` names
    further fields to derive (``"all"``: every one) and ``layer`` the shell layer of the
    layered fields (:mod:`~workbench.scene.readers.d3plot_fields`; ValueError for an unknown
    name). What could not be read is named in a ParseWarning (module notes); ParseError for a
    file that cannot be read.
    """
    from lasso.dyna import ArrayType

    requested = d3plot_fields.requested_fields(extra_fields)
    d3plot_fields.check_layer(layer)

    path = _first_member(Path(path))
    plot, warnings = _lasso_read(path)
    arrays = dict(plot.arrays)
    members, notes = getattr(plot, "family", None) or _family(path, plot)
    _select_states(arrays, members, ArrayType)
    dropped = _drop_damaged_layouts(plot, arrays, ArrayType, stress_components, notes)
    kinds.merge_thick_shells(arrays, ArrayType)  # drawn as solids
    if kinds.only_kinds_message(arrays, ArrayType):
        raise ParseError(path, kinds.only_kinds_message(arrays, ArrayType) + warnings.summary())
    elements = _elements(path, arrays, ArrayType, warnings, all_faces)
    parts, part_names = _parts(path, arrays, ArrayType, warnings, elements.part_index)
    n_states = sum(min(m.states, m.read) for m in members)
    steps, times = _steps_and_times(arrays, ArrayType, elements.nodes, n_states, notes)
    fields, node_fields = {}, {}
    if n_states:
        fields = _shell_fields(arrays, ArrayType, elements, n_states, stress_components)
        if elements.n_solids:
            _solid_fields(fields, arrays, ArrayType, elements.face_of, elements.n_shells,
                          n_states)
        node_fields = d3plot_fields.add_requested(fields, arrays, ArrayType, elements,
                                                  n_states, steps, requested, layer, notes)
        lost = [name for name in _expected_fields(plot, stress_components)
                if name not in fields and name not in dropped]
        if lost:
            notes.append(f"fields the header announces were not read: {', '.join(lost)}")

    node_ids = arrays.get(ArrayType.node_ids)
    if warnings.failures:  # a failed section can take the user ids with it: say which
        lost = [what for what, gone in (
            ("user part ids (parts are numbered 1, 2, ... in their internal order)",
             ArrayType.part_ids not in arrays and ArrayType.part_titles_ids not in arrays),
            ("node ids", node_ids is None), ("element ids", elements.element_ids is None))
            if gone]
        if lost:
            notes.append(f"not read, as a section failed: {'; '.join(lost)}")
    mesh = build_mesh(
        path, nodes=elements.nodes, elements=elements.connectivity, parts=parts,
        steps=steps, times=times, element_fields=fields, node_fields=node_fields,
        part_names=part_names,
        node_ids=None if node_ids is None else np.asarray(node_ids, dtype=np.int64),
        element_ids=elements.element_ids, name=path.name, units=units,
        **_kinds(path, arrays, ArrayType, warnings, elements.nodes, n_states, notes))
    for failure in warnings.failures:  # read, but with sections missing: say which
        _warn(ParseWarning(path, f"lasso-python could not read {failure}: what it holds is "
                                 f"missing"), stacklevel=2)
    for note in notes:
        _warn(ParseWarning(path, note), stacklevel=2)
    return mesh


def _kinds(path: Path, arrays, ArrayType, warnings, nodes: np.ndarray, n_states: int,
           notes: list[str]) -> dict:
    """``beams`` and ``particles`` of the d3plot (:mod:`.d3plot_kinds`), notes for what is not
    drawn added to ``notes``."""
    def part_ids(part_index: np.ndarray) -> np.ndarray:
        return _parts(path, arrays, ArrayType, warnings, part_index)[0]

    notes.extend(kinds.not_drawn_notes(arrays, ArrayType))
    return {"beams": kinds.read_beams(arrays, ArrayType, n_states, part_ids),
            "particles": kinds.read_particles(arrays, ArrayType, n_states, nodes, part_ids,
                                              notes)}


def _first_member(path: Path) -> Path:
    """The first file of the d3plot family ``path`` belongs to: ``d3plot`` for ``d3plot01``
    when it lies beside it, else ``path`` itself."""
    member = re.fullmatch(r"(d3plot.*?)(\d{2,})", path.name, flags=re.IGNORECASE)
    if member and (path.parent / member.group(1)).is_file():
        return path.parent / member.group(1)
    return path


def _lasso_read(path: Path):
    """(lasso-python's D3plot of the family at ``path``, the warnings it logged while reading);
    ParseError when it cannot read the file at all. Its log, Python warnings and numpy floating
    point messages are captured: nothing of them reaches the console."""
    from lasso.dyna import D3plot

    warnings = _LassoWarnings()
    # lasso-python logs under "lasso..." and, for some modules, under their file path
    loggers = [logging.getLogger("lasso")] + [
        logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
        if re.search(r"(^|[\\/])lasso[\\/]", name)]
    saved = [(logger, logger.propagate) for logger in loggers]
    for logger in loggers:
        logger.addHandler(warnings)
        logger.propagate = False  # its tracebacks are ours to report, in one line each
    try:
        with _python_warnings.catch_warnings(), np.errstate(all="ignore"):
            _python_warnings.simplefilter("ignore")
            plot = _guarded(D3plot)(str(path))
    except ParseError as exc:  # the family does not fit the header
        raise ParseError(path, exc.message + warnings.summary()) from None
    except Exception as exc:  # lasso raises many types; all mean "cannot read this file"
        raise ParseError(path, _unreadable(path, exc) + warnings.summary()) from exc
    finally:
        for logger, propagate in saved:
            logger.removeHandler(warnings)
            logger.propagate = propagate
    return plot, warnings


def _guarded(D3plot):
    """lasso-python's D3plot refusing an airbag particle section (announced by the header's
    NPEFG) whose counts do not fit the file: it would loop over them for hours."""

    class Guarded(D3plot):
        def _read_particle_data(self):
            npefg = self.header.raw_header.get("npefg", 0)
            if 0 < npefg <= 10_000_000 and self._buffer:
                w, at = self.header.wordsize, self.geometry_section_size
                counts = [self._buffer.read_number(at + k * w, self.header.itype)
                          for k in (0, 1, 3) if at + (k + 1) * w <= self._buffer.size]
                if len(counts) < 3 or min(counts) < 0 \
                        or 9 * w * sum(int(c) for c in counts) > self._buffer.size:
                    raise ValueError(f"the airbag particle section the header announces "
                                     f"(NPEFG {npefg}) does not fit the file")
            super()._read_particle_data()

        def _read_states(self, filepath):
            # before lasso-python sizes its buffers by a header that may not fit the files
            self.family = _family(Path(filepath), self)
            super()._read_states(filepath)

    return Guarded


def _unreadable(path: Path, exc: Exception) -> str:
    """Why lasso-python could not read the family at ``path``, in one line: a member without
    data by its name, else the exception's type and first line (never a traceback's)."""
    for member in family_members(path):
        if _data_end(member) == 0:
            return (f"{member.name} holds no data (empty or all zero): the states it should "
                    f"hold are missing")
    lines = [line.strip() for line in str(exc).splitlines()
             if line.strip() and not line.lstrip().startswith("Traceback")]
    return f"lasso-python could not read it: {type(exc).__name__}: {(lines or [''])[0]}"


# --------------------------------------------------------------------------- the family
def family_layout(path: str | os.PathLike[str]) -> list[Member]:
    """The members of the d3plot family at ``path`` (the first file, then ``d3plot01``, ...)
    with where their states lie; ParseError as :func:`read_d3plot` for a family that cannot
    be read or whose header does not fit its files."""
    path = _first_member(Path(path))
    plot, _ = _lasso_read(path)
    return _family(path, plot)[0]


def _steps_and_times(arrays: dict, ArrayType, nodes: np.ndarray, n_states: int,
                     notes: list[str]):
    """(steps, times) of ``n_states`` states (None, None without states); coordinates or times
    that could not be read are replaced, with a note: the initial geometry, the state index."""
    if not n_states:
        return None, None
    steps = arrays.get(ArrayType.node_displacement)
    if steps is None or np.shape(steps) != (n_states, *nodes.shape):
        notes.append("the states hold no readable node coordinates: every state is drawn on "
                     "the initial geometry")
        steps = np.broadcast_to(nodes, (n_states, *nodes.shape))
    times = arrays.get(ArrayType.global_timesteps)
    if times is None or np.shape(times) != (n_states,):
        notes.append("the state times could not be read: the states are numbered 0, 1, ... "
                     "instead")
        times = np.arange(n_states)
    return np.asarray(steps, dtype=np.float64), np.asarray(times, dtype=np.float64)


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
        raise ParseError(path, "no shell, solid or thick shell elements in the d3plot"
                         + warnings.summary())
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
        if solid_ids is not None and len(solid_ids) == len(solids) and \
                (element_ids is not None or n_shells == 0):
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
    deformable = d3plot_fields.deformable_shells(arrays, ArrayType,
                                                 elements.part_index[:n_shells])

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
        last line of the traceback it logged), never the traceback itself. The shell layout
        check is left out: :func:`_drop_damaged_layouts` reports it."""
        out = []
        for record in self.records:
            if str(record.msg).startswith("n_shell_vars != n_shell_vars_computed"):
                continue
            text = _record_text(record)
            if record.exc_info and record.exc_info[1] is not None:
                text += f"\n{type(record.exc_info[1]).__name__}: {record.exc_info[1]}"
            lines = [line.strip() for line in text.splitlines() if line.strip()]
            heading = next((i for i, line in enumerate(lines) if line.startswith("Traceback")),
                           len(lines))
            what = " ".join(lines[:heading]) or "a section"
            what = re.sub(r"^A failure in (.*?) was caught:?$", r"\1", what)
            why = lines[-1] if heading < len(lines) - 1 else ""
            phrase = f"{what} ({why})" if why else what
            out.append(phrase.replace("Traceback (most recent call last):", "").strip())
        return out

    def summary(self) -> str:
        failures = self.failures
        return f" (lasso-python could not read {'; '.join(failures[:3])})" if failures else ""


def _record_text(record: logging.LogRecord) -> str:
    """The message of a log record; lasso-python's own message may not format (a ``%d`` given
    a string): then every placeholder takes its argument's text."""
    try:
        return record.getMessage()
    except (TypeError, ValueError, KeyError):
        args = record.args if isinstance(record.args, tuple) else (record.args,)
        texts = iter(str(arg) for arg in args)
        return re.sub(r"%[-#0 +]*\d*(?:\.\d+)?[a-zA-Z]",
                      lambda m: next(texts, m.group(0)), str(record.msg))
