"""The members of a d3plot family and what a damaged one loses (for
:mod:`workbench.scene.readers.d3plot`): each member ends with LS-DYNA's end-of-file marker right
after its last whole state, so a cut or damaged end, a missing member, bytes after a marker and
a header that does not fit its files are found before lasso-python reads a state; and the
shell (solid) fields of a header whose flags do not fit its counts, or that gives impossible
values, are dropped with a note. Every loss is a note (one line) the reader warns with;
ParseError where the header does not fit the files at all.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import ParseError

STRESS_COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "zx")  # d3plot (and lasso-python) order
END_MARKER = -999999.0  # LS-DYNA's end-of-file marker, one word after a member's last state
STATE_ARRAYS = ("global_timesteps", "node_displacement", "node_velocity", "node_acceleration",
                "element_shell_stress",
                "element_shell_effective_plastic_strain", "element_shell_thickness",
                "element_shell_is_alive", "element_solid_stress",
                "element_solid_effective_plastic_strain", "element_solid_is_alive")


@dataclass
class Member:
    """One file of a d3plot family: its states begin at byte ``start`` (after the geometry in
    the first file, at 0 in the others) and are ``state_bytes`` long each; it holds ``states``
    whole states before its end-of-file marker, of which lasso-python reads ``read`` (more
    when nonzero bytes follow the marker, fewer when the member is cut)."""

    path: Path
    start: int
    state_bytes: int
    states: int
    read: int


def family_members(path: Path) -> list[Path]:
    """The first file and the further members beside it (``d3plot01``, ``d3plot02``, ...: the
    name and a number), in the order of their numbers, as lasso-python reads them."""
    pattern = re.compile(re.escape(path.name) + r"([0-9]+)$")
    found = [(int(m.group(1)), child) for child in path.parent.iterdir()
             if (m := pattern.match(child.name)) and child.is_file()]
    return [path] + [child for _, child in sorted(found)]


def _data_end(path: Path, block: int = 1 << 16) -> int:
    """One past the last nonzero byte of the file (LS-DYNA pads members with zeros)."""
    size = path.stat().st_size
    with path.open("rb") as f:
        for stop in range(size, 0, -block):
            start = max(0, stop - block)
            f.seek(start)
            nonzero = np.flatnonzero(np.frombuffer(f.read(stop - start), np.uint8))
            if len(nonzero):
                return start + int(nonzero[-1]) + 1
    return 0


def _family(path: Path, plot) -> tuple[list[Member], list[str]]:
    """The members of the family lasso-python read as ``plot``, and one note per loss or
    damage found in them (module notes); ParseError when the header does not fit the files.

    A member without an end-of-file marker after a whole state (cut, or its end damaged) keeps
    the states lasso-python reads from it while their times follow on from the states before
    them and precede those after (finite, at least 0): the whole states before a cut, not
    stray bytes read as states."""
    header = plot.header
    word, ftype = int(header.wordsize), np.dtype(header.ftype)
    state_bytes = int(plot._compute_n_bytes_per_state())
    if state_bytes < word:
        raise ParseError(path, f"the header gives states of {state_bytes} bytes: it is damaged")
    if plot.geometry_section_size < 0:
        raise ParseError(path, "the header gives a geometry of negative size: it is damaged")
    members, found, times = [], [], []
    for index, member in enumerate(family_members(path)):
        start = int(plot.geometry_section_size) if index == 0 else 0
        end = _data_end(member)
        data = np.memmap(member, np.uint8, "r") if end else np.zeros(0, np.uint8)
        read = max(0, (end - start) // state_bytes)
        # the marker lies before the data's end, after the first whole states that fit
        ends = start + state_bytes * np.arange(max(0, (end - start - word) // state_bytes + 1))
        marker = np.flatnonzero(_words(data, ends, ftype) == END_MARKER)
        last = (end - 1) // word * word  # the word of the last nonzero byte
        complete = end >= word and last + word <= len(data) and \
            _words(data, [last], ftype)[0] == END_MARKER
        states = int(marker[0]) if len(marker) else None
        times.append(_words(data, start + state_bytes * np.arange(read), ftype))
        del data
        name = member.name
        if states is None and index == 0 and end <= start:
            states = read = 0
            if end < start and complete:
                raise ParseError(path, f"the header does not fit the file: the geometry it "
                                       f"describes ends at byte {start}, the file's data at "
                                       f"byte {end} (the header is damaged)")
            if end < start:
                found.append(f"{name} is cut inside its geometry (at byte {end} of the "
                             f"{start} the header describes): no state is read from it")
        elif states is None and complete:
            raise ParseError(path, f"the header does not fit {name}: its states of "
                                   f"{state_bytes} bytes (the header's size) do not end at "
                                   f"the end-of-file marker at byte {last} (the header is "
                                   f"damaged, or {name} is not of this d3plot)")
        elif states is not None and read > states:
            found.append(f"{name}: nonzero bytes after its end-of-file marker (byte "
                         f"{start + states * state_bytes}) are not states: ignored")
        members.append(Member(member, start, state_bytes, states, read))
    notes = []
    previous = -np.inf
    for k, m in enumerate(members):
        if m.states is None:
            after = [t[0] for t, n in zip(times[k + 1:], members[k + 1:]) if len(t)
                     and (n.states is None or n.states > 0)]
            limit = after[0] if after else np.inf
            m.states, last_time = 0, previous
            for t in times[k]:
                if not (np.isfinite(t) and last_time < t < limit and t >= 0):
                    break
                m.states, last_time = m.states + 1, t
            span = f" (t = {times[k][0]:g} to {last_time:g})" if m.states else ""
            notes.append(f"{m.path.name} is cut, or its end damaged (no end-of-file marker after "
                         f"its last whole state, {m.path.stat().st_size} bytes): "
                         f"{m.states} of its states read{span}, the rest of it is missing")
        kept = times[k][:min(m.states, m.read)]
        previous = kept[-1] if len(kept) else previous
    notes += found
    numbers = [int(m.path.name[len(path.name):]) for m in members[1:]]
    for gap in sorted(set(range(1, max(numbers, default=0) + 1)) - set(numbers)):
        notes.append(f"{path.name}{gap:02d} is missing: the states it holds are not read "
                     f"(those of the members after it are)")
    if sum(min(m.states, m.read) for m in members) == 0:
        why = f": {path.name}01, which would hold them, is missing" if len(members) == 1 else ""
        notes.append(f"no state read{why}: no fields, no deformed geometry")
    return members, notes


def _words(data: np.ndarray, positions, ftype: np.dtype) -> np.ndarray:
    """The float64 values of the words of type ``ftype`` at the byte ``positions`` of
    ``data``."""
    positions = np.asarray(positions, dtype=np.int64)
    if not len(positions):
        return np.zeros(0)
    return data[positions[:, None] + np.arange(ftype.itemsize)].view(ftype).ravel() \
        .astype(np.float64)


def _select_states(arrays: dict, members: list[Member], ArrayType) -> None:
    """Keep in ``arrays`` only the states of the members' whole states (lasso-python also reads
    nonzero bytes after a member's end-of-file marker as states)."""
    if all(m.read <= m.states for m in members):
        return
    keep, offset = [], 0
    for m in members:
        keep.extend(range(offset, offset + min(m.states, m.read)))
        offset += m.read
    for name in STATE_ARRAYS:
        key = getattr(ArrayType, name)
        if key in arrays and len(arrays[key]) == offset:
            arrays[key] = np.asarray(arrays[key])[keep]


def _drop_damaged_layouts(plot, arrays: dict, ArrayType, stress_components: bool,
                          notes: list[str]) -> set[str]:
    """Remove the shell (solid) state arrays that lasso-python placed by a header that looks
    damaged: its output flags disagree with its count of values per shell (NV2D; per solid,
    NV3D), or the values read are impossible (a thickness not above 0, a negative plastic
    strain, a value not finite), as when a flag and a history count change together. Returns
    the fields not read, with a note naming them."""
    h, A = plot.header, ArrayType
    rigid = getattr(getattr(plot, "_material_section_info", None), "n_rigid_shells", 0)
    layers = h.n_shell_tshell_layers
    shells = (layers * (6 * h.has_shell_tshell_stress + h.has_shell_tshell_pstrain
                        + h.n_shell_tshell_history_vars)
              + 8 * h.has_shell_forces + 4 * h.has_shell_extra_variables
              + 12 * h.has_element_strain + 6 * layers * h.has_solid_shell_plastic_strain_tensor
              + 6 * h.has_solid_shell_thermal_strain_tensor)
    solids = h.n_solid_layers * (6 * h.has_solid_stress + h.has_solid_pstrain
                                 + h.n_solid_history_vars)
    dropped = set()
    for kind, present, count, computed, keys, names in (
            ("shell", h.n_shells - rigid > 0, h.n_shell_vars, shells,
             {"thickness": A.element_shell_thickness, "stress": A.element_shell_stress,
              "plastic strain": A.element_shell_effective_plastic_strain},
             ["von_mises", *(f"stress_{c}" for c in STRESS_COMPONENTS if stress_components),
              "plastic_strain", "thickness"]),
            ("solid", h.n_solids > 0, h.n_solid_vars, solids,
             {"stress": A.element_solid_stress,
              "plastic strain": A.element_solid_effective_plastic_strain},
             ["von_mises", "plastic_strain"])):
        if not present or count <= 0:
            continue
        # a solid record may hold values no flag names (lasso-python reads past them)
        differ = computed != count if kind == "shell" else computed > count
        why = f"its {kind} output flags give {computed} values per {kind}, its count " \
              f"{count}" if differ else ""
        if kind == "solid" and not why and not h.has_solid_stress \
                and count - computed >= 6 * h.n_solid_layers:
            notes.append(f"the header's flags name {computed} of the {count} values per solid: "
                         f"a solid stress may be there, but it is not read (von_mises)")
        for what, key in keys.items():
            values = np.asarray(arrays.get(key, np.zeros(0)), dtype=np.float64)
            bad = ~np.isfinite(values) | ((values <= 0) if what == "thickness" else
                                          (values < 0) if what == "plastic strain" else False)
            if not why and bad.any():
                why = f"it gives an impossible {kind} {what} ({values[bad].flat[0]:g})"
        if why:
            for key in keys.values():
                arrays.pop(key, None)
            dropped.update(names)
            notes.append(f"the header looks damaged: {why}; the {kind} fields are not read: "
                         f"{', '.join(names)}")
    return dropped


def _expected_fields(plot, stress_components: bool) -> list[str]:
    """The fields of the module notes that the header says the states hold."""
    rigid = getattr(getattr(plot, "_material_section_info", None), "n_rigid_shells", 0)
    return header_fields(plot.header, rigid, stress_components)


def header_fields(h, rigid_shells: int = 0, stress_components: bool = True) -> list[str]:
    """The element fields of the module notes that a d3plot with lasso-python's header ``h``
    (``D3plotHeader``) holds in its states, ``rigid_shells`` of its shells having no results
    (unknown from the header alone: 0)."""
    shells = h.n_shells - rigid_shells > 0 and h.n_shell_vars > 0
    solids = h.n_solids > 0 and h.n_solid_vars > 0
    names = []
    if (shells and h.has_shell_tshell_stress) or (solids and h.has_solid_stress):
        names.append("von_mises")
        if shells and h.has_shell_tshell_stress and stress_components:
            names += [f"stress_{c}" for c in STRESS_COMPONENTS]
    if (shells and h.has_shell_tshell_pstrain) or (solids and h.has_solid_pstrain):
        names.append("plastic_strain")
    if shells and h.has_shell_extra_variables:
        names.append("thickness")
    if h.has_element_deletion_data and (h.n_shells > 0 or h.n_solids > 0):
        names.append("alive")
    return names
