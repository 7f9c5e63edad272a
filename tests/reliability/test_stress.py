"""The reader reliability suite (workbench.reliability): a bounded run, its checks, and the reader
defects it found."""

import argparse
import warnings

import numpy as np
import pytest

from workbench.cli.stress import add_parser as add_stress_parser
from workbench.reliability import (
    BENIGN,
    BOM,
    KINDS,
    OUTCOMES,
    comma_deck,
    default_decks,
    expected_mesh,
    fixed_deck,
    mesh_problem,
    mutated_deck,
    run_reader_stress,
    same_mesh,
    thickness_deck,
)
from workbench.reliability import read_outcome as _read
from workbench.scene.readers import ParseError
from workbench.scene.readers.keyword import read_keyword


@pytest.fixture(scope="module")
def report():
    return run_reader_stress(n=200, seed=0)


def test_bounded_run_has_no_failures(report):
    assert report.totals["wrong mesh"] == 0, "\n".join(map(str, report.failures))
    assert report.totals["other exception"] == 0, "\n".join(map(str, report.failures))
    assert report.totals["hang"] == 0, "\n".join(map(str, report.failures))
    assert report.ok, "\n".join(map(str, report.failures))
    assert sum(report.totals.values()) == 200


def test_benign_variants_read_identically(report):
    for kind in BENIGN:
        row = report.counts[kind]
        assert row["identical"] == sum(row.values()), (kind, row)


def test_every_kind_is_drawn_and_tabled(report):
    assert all(sum(report.counts[kind].values()) > 0 for kind in KINDS)
    table = report.table()
    assert all(kind in table for kind in KINDS) and all(o in table for o in OUTCOMES)


@pytest.mark.parametrize("kind", BENIGN)
@pytest.mark.parametrize("make", [fixed_deck, comma_deck, thickness_deck])
def test_benign_kind_reads_the_same_mesh(tmp_path, make, kind):
    decks = {"deck": make()}
    index = next(i for i in range(500) if mutated_deck(i, 7, decks).kind == kind)
    original, mutated = tmp_path / "a.k", tmp_path / "b.k"
    original.write_bytes(decks["deck"])
    mutated.write_bytes(mutated_deck(index, 7, decks).text)
    assert same_mesh(read_keyword(original), read_keyword(mutated))


def test_mutations_are_reproducible_from_seed_and_index():
    decks = {"fixed": fixed_deck(), "comma": comma_deck()}
    assert mutated_deck(42, 3, decks) == mutated_deck(42, 3, decks)
    assert [mutated_deck(i, 3, decks).text for i in range(20)] != \
        [mutated_deck(i, 4, decks).text for i in range(20)]


def test_the_strict_reference_agrees_with_the_reader_on_every_default_deck(tmp_path):
    for name, text in default_decks().items():
        path = tmp_path / f"{name}.k"
        path.write_bytes(text)
        mesh = read_keyword(path)
        expected = expected_mesh(text)
        assert len(expected.node_ids) == mesh.n_nodes and \
            len(expected.element_ids) == mesh.n_elements
        assert mesh_problem(mesh, text) == "", name


def _rebuilt(mesh, **changes):
    """A copy of ``mesh`` with some arrays replaced (what a broken reader returns)."""
    from workbench.scene.mesh import FEMesh

    kwargs = dict(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts,
                  element_fields=dict(mesh.element_fields), node_ids=mesh.node_ids,
                  element_ids=mesh.element_ids, part_names=mesh.part_names, name=mesh.name)
    kwargs.update(changes)
    return FEMesh(**kwargs)


def _flat_z(mesh):
    return _rebuilt(mesh, nodes=mesh.nodes * [1.0, 1.0, 0.0])


def _triangles(mesh):
    elements = mesh.elements.copy()
    elements[:, 3] = elements[:, 2]
    return _rebuilt(mesh, elements=elements)


def _reversed_parts(mesh):
    return _rebuilt(mesh, parts=mesh.parts[::-1])


def _thicker(mesh):
    fields = dict(mesh.element_fields)
    fields["thickness"] = fields["thickness"] * 1.001
    return _rebuilt(mesh, element_fields=fields)


def _one_element_less(mesh):
    keep = slice(0, mesh.n_elements - 1)
    fields = {k: v[keep] for k, v in mesh.element_fields.items()}
    return _rebuilt(mesh, elements=mesh.elements[keep], parts=mesh.parts[keep],
                    element_ids=mesh.element_ids[keep], element_fields=fields)


def _renumbered_nodes(mesh):
    return _rebuilt(mesh, node_ids=np.roll(mesh.node_ids, 1))


BROKEN_READERS = {  # a broken reader -> the quantity the suite must name
    "flattened z": (_flat_z, "coordinates"),
    "quads as triangles": (_triangles, "connectivity"),
    "part ids reversed": (_reversed_parts, "part ids"),
    "thickness off by 0.1 %": (_thicker, "thickness"),
    "an element dropped": (_one_element_less, "element ids"),
    "node ids shifted": (_renumbered_nodes, "connectivity"),
}


@pytest.mark.parametrize("broken", sorted(BROKEN_READERS))
def test_the_suite_fails_on_a_broken_reader_naming_what_differs(broken):
    """A check that cannot fail is no check: each broken reader makes the suite fail, and its
    failures name the quantity the reader gets wrong."""
    damage, quantity = BROKEN_READERS[broken]

    def reader(path):
        return damage(read_keyword(path))

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = run_reader_stress(n=30, seed=3, reader=reader)
    assert not report.ok
    originals = [f for f in report.failures if f.kind == "original"]
    assert originals  # (a flat deck's z is already flat: not every deck need differ)
    assert all(f.outcome == "wrong mesh" and quantity in f.message for f in originals), \
        [f.message for f in originals]
    assert report.totals["wrong mesh"] > 0


def test_the_real_reader_passes_the_same_run():
    assert run_reader_stress(n=30, seed=3).ok


def test_wrong_mesh_is_detected(tmp_path):
    path = tmp_path / "deck.k"
    path.write_bytes(fixed_deck())
    mesh = read_keyword(path)
    lines = fixed_deck().split(b"\n")
    one_element_less = b"\n".join(line for line in lines
                                   if not line.startswith(b"       9       1"))
    assert "element ids: 0 missing [], 1 not in the deck [9]" in \
        mesh_problem(mesh, one_element_less)
    moved_node = fixed_deck().replace(b"            10.0             0.0",
                                      b"            11.0             0.0", 1)
    assert "coordinates of 1 node(s): node 2 read [10.0, 0.0, 0.0], expected [11.0" in \
        mesh_problem(mesh, moved_node)
    garbled_node = fixed_deck().replace(b"            10.0             0.0",
                                        b"            1x.0             0.0", 1)
    assert "must be refused" in mesh_problem(mesh, garbled_node)


def test_a_read_past_the_time_limit_is_a_hang(tmp_path):
    path = tmp_path / "deck.k"
    path.write_bytes(b"*NODE\n" + b"".join(b"%8d%16.1f%16.1f%16.1f\n" % (i, i, 0, 0)
                                           for i in range(1, 200001))
                     + b"*ELEMENT_SHELL\n       1       1       1       2       3       4\n")
    mesh, outcome, _ = _read(path, 1e-3)
    assert mesh is None and outcome == "hang"


def test_other_exception_types_are_reported(tmp_path, monkeypatch):
    from workbench.scene.readers import keyword

    def broken(path):
        raise RuntimeError("boom")

    monkeypatch.setattr(keyword, "read_keyword", broken)
    _mesh, outcome, message = _read(tmp_path / "x.k", 10.0)
    assert outcome == "other exception" and "RuntimeError" in message


def test_command_line(capsys):
    parser = argparse.ArgumentParser(prog="workbench")
    add_stress_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["stress", "readers", "--n", "24", "--seed", "5"])
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "24 mutations" in out and "OK" in out
    with pytest.raises(SystemExit):
        parser.parse_args(["stress", "renders"])


def test_default_decks_include_the_generated_ones():
    assert {"fixed", "comma", "thickness"} <= set(default_decks())


# --------------------------------------------------------------------------- regressions
def test_regression_utf8_bom_before_the_first_keyword(tmp_path):
    """A deck whose first line is a keyword lost that keyword behind a UTF-8 byte order mark
    (its *NODE block was skipped, so every element named undefined nodes)."""
    plain, marked = tmp_path / "plain.k", tmp_path / "marked.k"
    plain.write_bytes(comma_deck())
    marked.write_bytes(BOM + comma_deck())
    assert same_mesh(read_keyword(plain), read_keyword(marked))
    long_deck = b"*KEYWORD LONG=Y\n*NODE\n" + b"%20d%20.1f%20.1f%20.1f\n" * 3 % (
        1, 0, 0, 0, 2, 1, 0, 0, 3, 1, 1, 0) + b"*ELEMENT_SHELL\n" + \
        b"%20d%20d%20d%20d%20d%20d\n" % (1, 1, 1, 2, 3, 3)
    plain.write_bytes(long_deck)
    marked.write_bytes(BOM + long_deck)
    assert same_mesh(read_keyword(plain), read_keyword(marked))
    np.testing.assert_array_equal(read_keyword(marked).node_ids, [1, 2, 3])


def test_regression_bom_keeps_line_numbers(tmp_path):
    path = tmp_path / "bad.k"
    path.write_bytes(BOM + b"*NODE\n       1     abc\n")
    with pytest.raises(ParseError) as info:
        read_keyword(path)
    assert info.value.line == 2


# --------------------------------------------------------------------------- damaged d3plots
@pytest.mark.usefixtures("d3plot_file")
def test_damaged_d3plots_are_read_or_refused_never_anything_else():
    from workbench.reliability import run_d3plot_stress

    report = run_d3plot_stress(300, seed=0)
    assert report.ok, report.failures
    totals = {o: sum(c[o] for c in report.counts.values()) for o in ("read", "parse error")}
    assert totals["read"] > 0 and totals["parse error"] > 0 and sum(totals.values()) == 300


def test_regression_garbled_part_index_is_a_parse_error(tmp_path, d3plot_file):
    """Damage 175 of seed 0 garbles a shell part index to -1.6e9: once an IndexError."""
    from workbench.reliability import damaged_d3plot
    from workbench.scene.readers import ParseError
    from workbench.scene.readers.d3plot import read_d3plot

    kind, data = damaged_d3plot(d3plot_file.read_bytes(), 175, 0)
    (tmp_path / "d3plot").write_bytes(data)
    with pytest.raises(ParseError, match="part indexes out of range"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            read_d3plot(tmp_path / "d3plot")


def test_regression_lasso_message_that_does_not_format():
    """lasso-python once logged a '%d' message with a string argument: reporting it raised."""
    import logging

    from workbench.scene.readers.d3plot import _LassoWarnings

    handler = _LassoWarnings()
    handler.emit(logging.LogRecord("lasso", logging.WARNING, "x", 1, "part %d is broken",
                                   ("seven",), None))
    assert handler.failures == ["part seven is broken"]  # each placeholder takes its argument
