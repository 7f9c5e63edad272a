"""Damaged d3plot families lose nothing silently: a cut or missing member, a changed header
byte and a failed section are named in a ParseWarning (or refused with ParseError), one line
each on the command line; and the d3plot reliability suite fails a reader that drops a field
or a state, or changes a value, naming what differs."""

import logging
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from workbench.reliability.d3plot import Damage, compare_read, run_d3plot_stress
from workbench.scene.mesh import FEMesh
from workbench.scene.readers import ParseError, ParseWarning
from workbench.scene.readers.d3plot import family_layout, read_d3plot
from workbench.scene.readers.d3plot_family import END_MARKER


def family_copy(folder, first):
    """A writable copy of the d3plot family of ``first`` in ``folder``; its first file."""
    for member in sorted(first.parent.iterdir()):
        if member.name.startswith(first.name):
            (folder / member.name).write_bytes(member.read_bytes())
    return folder / first.name


def read_quietly(path):
    """The read of ``path`` and the text of its ParseWarnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = read_d3plot(path)
    return mesh, [str(w.message) for w in caught if issubclass(w.category, ParseWarning)]


@pytest.fixture
def shared_copy(tmp_path, d3plot_file):
    return family_copy(tmp_path, d3plot_file)


# --------------------------------------------------------------------------- the shared family
def test_undamaged_shared_family_reads_without_warning(shared_copy):
    mesh, said = read_quietly(shared_copy)
    assert said == [] and mesh.n_steps == 1 and "thickness" in mesh.element_fields


def test_cut_d3plot01_names_the_lost_states(shared_copy):
    member = shared_copy.parent / "d3plot01"
    member.write_bytes(member.read_bytes()[:1_000_000])
    with pytest.warns(ParseWarning) as record:
        mesh = read_d3plot(shared_copy)
    text = [str(w.message) for w in record]
    assert any("d3plot01 is cut" in t and "0 of its states read" in t for t in text), text
    assert any("no state read" in t and "no fields" in t for t in text), text
    assert mesh.steps is None and mesh.element_fields == {}


def test_missing_d3plot01_names_the_lost_states(shared_copy):
    (shared_copy.parent / "d3plot01").unlink()
    with pytest.warns(ParseWarning, match=r"no state read: d3plot01, which would hold them, "
                                          r"is missing: no fields"):
        mesh = read_d3plot(shared_copy)
    assert mesh.steps is None and mesh.element_fields == {}


def test_empty_d3plot01_is_refused_by_name(shared_copy):
    (shared_copy.parent / "d3plot01").write_bytes(b"")
    with pytest.raises(ParseError, match="d3plot01 holds no data"):
        read_d3plot(shared_copy)


def flip(path, byte, mask):
    data = bytearray(path.read_bytes())
    data[byte] ^= mask
    path.write_bytes(bytes(data))


def test_changed_state_size_in_the_header_is_refused(shared_copy):
    flip(shared_copy, 18 * 4, 0x05)  # NGLBV, the count of global values in every state
    with pytest.raises(ParseError, match="the header does not fit d3plot01: its states of"):
        read_d3plot(shared_copy)


def test_changed_shell_flag_in_the_header_names_the_fields_not_read(shared_copy):
    flip(shared_copy, 43 * 4, 0x01)  # IOSHL(1): stresses written or not
    with pytest.warns(ParseWarning, match="the header looks damaged") as record:
        mesh = read_d3plot(shared_copy)
    text = " ".join(str(w.message) for w in record)
    for name in ("von_mises", "stress_xx", "plastic_strain", "thickness"):
        assert name in text and name not in mesh.element_fields
    assert "alive" in mesh.element_fields and mesh.n_steps == 1  # not placed by the flag


def test_every_header_byte_change_is_refused_or_read_with_what_differs_named(shared_copy):
    """Each byte of the 64 header words, xor 0x01 and 0xFF: ParseError, or a read whose every
    difference from the undamaged read is named in a warning (the suite's rule)."""
    layout = family_layout(shared_copy)
    reference = read_d3plot(shared_copy)
    original = shared_copy.read_bytes()
    outcomes = {"read": 0, "refused": 0}
    for byte in range(256):
        for mask in (0x01, 0xFF):
            flip(shared_copy, byte, mask)
            try:
                mesh, said = read_quietly(shared_copy)
            except ParseError as exc:
                assert "\n" not in str(exc) and "Traceback" not in str(exc)
                outcomes["refused"] += 1
            else:
                damage = Damage("header byte", shared_copy.name, byte, byte + 1, False, None)
                assert compare_read(mesh, said, reference, layout, damage) == ("read", ""), \
                    (byte, mask, said)
                outcomes["read"] += 1
            shared_copy.write_bytes(original)
    assert outcomes["read"] and outcomes["refused"]


@pytest.mark.parametrize("damage, status, expected", [
    ("missing", 0, "workbench: warning: .*no state read: d3plot01"),
    ("cut", 0, "workbench: warning: .*d3plot01 is cut"),
    # lasso-python logs this failure with a message that does not format, traceback included
    ("node count", 2, "workbench: error: .*node_coordinates"),
])
def test_command_line_prints_one_line_each_and_no_traceback(shared_copy, tmp_path, damage,
                                                            status, expected):
    member = shared_copy.parent / "d3plot01"
    if damage == "missing":
        member.unlink()
    elif damage == "cut":
        member.write_bytes(member.read_bytes()[:500_000])
    else:
        flip(shared_copy, 16 * 4 + 1, 0x80)  # NUMNP
    result = subprocess.run([sys.executable, "-m", "workbench.cli", "render", str(shared_copy),
                             "--size", "40x30", "-o", str(tmp_path / "x.png")],
                            capture_output=True, text=True)
    assert result.returncode == status, result.stderr
    assert "Traceback" not in result.stderr and "Traceback" not in result.stdout
    lines = result.stderr.strip().splitlines()
    assert lines and all(line.startswith("workbench: ") for line in lines), lines
    assert any(re.match(expected, line) for line in lines), lines


def test_lasso_failure_with_a_traceback_becomes_one_phrase():
    """lasso-python logs "A failure in %d was caught:\n%s" with the section's name and a whole
    traceback: the phrase keeps the section and the exception's line, not the traceback."""
    from workbench.scene.readers.d3plot import _LassoWarnings

    trace = ("Traceback (most recent call last):\n  File \"d3plot.py\", line 1, in x\n"
             "ValueError: cannot reshape array of size 0 into shape (5,3)\n")
    handler = _LassoWarnings()
    handler.emit(logging.LogRecord("lasso", logging.WARNING, "x", 1,
                                   "A failure in %d was caught:\n%s",
                                   ("_read_geometry_data, node_coordinates", trace), None))
    assert handler.failures == ["_read_geometry_data, node_coordinates (ValueError: cannot "
                                "reshape array of size 0 into shape (5,3))"]
    assert "Traceback" not in handler.summary()


# --------------------------------------------------------------------------- a family written here
def three_state_family(folder, members=2):
    """The three-state family of test_io's ``write_d3plot``, its states split over ``members``
    files the way LS-DYNA writes them (each ending with the end-of-file marker)."""
    sys.path.insert(0, str(Path(__file__).parent))
    from meshes import write_d3plot

    first = write_d3plot(folder)
    layout = family_layout(first)
    size = layout[1].state_bytes
    states = (folder / "d3plot01").read_bytes()[:3 * size]
    marker = np.float32(END_MARKER).tobytes()
    (folder / "d3plot01").unlink()
    bounds = [0, 2, 3] if members == 2 else [0, 3]
    for k, (a, b) in enumerate(zip(bounds, bounds[1:]), 1):
        (folder / f"d3plot{k:02d}").write_bytes(states[a * size:b * size] + marker + bytes(64))
    return first, size


def test_split_family_reads_every_state(tmp_path):
    first, _ = three_state_family(tmp_path)
    mesh, said = read_quietly(first)
    assert said == [] and np.allclose(mesh.times, [0.0, 1e-3, 2e-3])
    assert [m.states for m in family_layout(first)] == [0, 2, 1]


def test_missing_middle_member_is_named_and_the_rest_read(tmp_path):
    first, _ = three_state_family(tmp_path)
    (tmp_path / "d3plot01").unlink()
    with pytest.warns(ParseWarning, match="d3plot01 is missing: the states it holds are not "
                                          "read"):
        mesh = read_d3plot(first)
    assert np.allclose(mesh.times, [2e-3]) and np.allclose(mesh.steps[0, :, 2], 1.0)


def test_member_cut_inside_a_state_keeps_the_whole_states_before(tmp_path):
    first, size = three_state_family(tmp_path, members=1)
    reference = read_d3plot(first)
    member = tmp_path / "d3plot01"
    member.write_bytes(member.read_bytes()[:2 * size + size // 2])
    with pytest.warns(ParseWarning, match=r"d3plot01 is cut, or its end damaged .*: 2 of its "
                                          r"states read \(t = 0 to 0\.001\)"):
        mesh = read_d3plot(first)
    assert np.array_equal(mesh.steps, reference.steps[:2])
    for name, values in reference.element_fields.items():
        assert np.array_equal(mesh.element_fields[name], values[:2], equal_nan=True), name


def test_suite_passes_the_reader_on_a_split_family(tmp_path):
    first, _ = three_state_family(tmp_path)
    report = run_d3plot_stress(40, seed=0, source=first)
    assert report.ok, report.failures
    assert sum(row["read"] for row in report.counts.values()) > 0


# --------------------------------------------------------------------------- broken readers
def rebuilt(mesh, **changes):
    fields = dict(mesh.element_fields)
    args = dict(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts, steps=mesh.steps,
                times=mesh.times, element_fields=fields, part_names=mesh.part_names,
                node_ids=mesh.node_ids, element_ids=mesh.element_ids, name=mesh.name,
                units=mesh.units)
    args.update(changes)
    return FEMesh(**args)


def drops_thickness(path):
    mesh = read_d3plot(path)
    return rebuilt(mesh, element_fields={k: v for k, v in mesh.element_fields.items()
                                         if k != "thickness"})


def drops_the_last_state(path):
    mesh = read_d3plot(path)
    if mesh.steps is None:
        return mesh
    if mesh.n_steps == 1:
        return rebuilt(mesh, steps=None, times=None, element_fields={})
    return rebuilt(mesh, steps=mesh.steps[:-1], times=mesh.times[:-1],
                   element_fields={k: v[:-1] for k, v in mesh.element_fields.items()})


def perturbs_von_mises(path):
    mesh = read_d3plot(path)
    fields = {k: v.copy() for k, v in mesh.element_fields.items()}
    if "von_mises" in fields:
        fields["von_mises"][-1, 3] += 1.0
    return rebuilt(mesh, element_fields=fields)


@pytest.mark.parametrize("reader, outcome, named", [
    (drops_thickness, "silent loss", "field 'thickness' not read"),
    (drops_the_last_state, "silent loss", "1 of 1 states not read (t = 0)"),
    (perturbs_von_mises, "wrong data", "field 'von_mises' of state"),
])
def test_suite_fails_a_broken_reader_and_names_what_differs(d3plot_file, tmp_path, reader,
                                                            outcome, named):
    report = run_d3plot_stress(8, seed=0, reader=reader)
    assert not report.ok
    assert any(f"{outcome}: " in failure and named in failure
               for failure in report.failures), report.failures


@pytest.mark.parametrize("reader", [drops_thickness, drops_the_last_state, perturbs_von_mises])
def test_suite_fails_a_broken_reader_on_a_split_family(tmp_path, reader):
    first, _ = three_state_family(tmp_path)
    report = run_d3plot_stress(8, seed=0, source=first, reader=reader)
    assert not report.ok and report.failures[0].startswith("d3plot seed 0 undamaged copy")


def test_suite_passes_the_real_reader(d3plot_file):
    report = run_d3plot_stress(30, seed=0)
    assert report.ok, report.failures
    assert report.counts["missing member"]["read"] + report.counts["header byte"]["read"] > 0
