"""The keyword reader on element kinds other tools write (thick shells, higher-order solid
options, tetrahedra with blank n5..n8, beams and SPH particles), on strict ids and part ids,
on a free-format deck cut inside its last card, on NUL bytes and on deep include chains."""

import warnings

import numpy as np
import pytest

from workbench.reliability import expected_mesh, mesh_problem
from workbench.scene.readers import ParseError, load

CUBE = [(1, 0, 0, 0), (2, 10, 0, 0), (3, 10, 10, 0), (4, 0, 10, 0),
        (5, 0, 0, 10), (6, 10, 0, 10), (7, 10, 10, 10), (8, 0, 10, 10)]


def node(nid, x, y, z) -> str:
    return f"{nid:8d}{x:16.6f}{y:16.6f}{z:16.6f}"


def card(*values, width=8) -> str:
    return "".join(f"{v:{width}d}" for v in values)


def write(folder, name, lines, end="\n") -> str:
    path = folder / name
    path.write_text("\n".join(lines) + end)
    return path


def part(pid, title="p"):
    return ["*PART", title, f"{pid:10d}{1:10d}{1:10d}"]


def quiet_load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(path)


# --------------------------------------------------------------------------- element kinds
def test_a_thick_shell_is_drawn_as_its_eight_node_solid_beside_shells(tmp_path):
    path = write(tmp_path, "tshell.k", [
        *part(1), *part(2), "*NODE", *[node(*n) for n in CUBE],
        "*ELEMENT_TSHELL", card(7, 2, 1, 2, 3, 4, 5, 6, 7, 8),
        "*ELEMENT_SHELL", card(7, 1, 1, 2, 3, 4),  # shells number apart from thick shells
    ])
    mesh = load(path)
    assert mesh.n_elements == 1 + 6
    assert mesh.element_ids.tolist() == [7] * 7
    assert sorted(mesh.parts.tolist()) == [1] + [2] * 6
    faces = mesh.node_ids[mesh.elements[mesh.parts == 2]]
    assert sorted(sorted(f) for f in faces.tolist()) == sorted(sorted(f) for f in [
        [1, 2, 3, 4], [5, 6, 7, 8], [1, 2, 6, 5], [2, 3, 7, 6], [3, 4, 8, 7], [4, 1, 5, 8]])


def test_a_thick_shell_id_given_twice_is_refused(tmp_path):
    path = write(tmp_path, "twice.k", [
        *part(2), "*NODE", *[node(*n) for n in CUBE], "*ELEMENT_TSHELL",
        card(7, 2, 1, 2, 3, 4, 5, 6, 7, 8), card(7, 2, 1, 2, 3, 4, 5, 6, 7, 8)])
    with pytest.raises(ParseError, match="thick shell id 7 is defined twice"):
        load(path)


@pytest.mark.parametrize("keyword", ["*ELEMENT_SOLID_H8TOH20", "*ELEMENT_SOLID"])
def test_h8toh20_reads_as_the_hexahedron_of_its_card(tmp_path, keyword):
    path = write(tmp_path, "h20.k", [*part(3), "*NODE", *[node(*n) for n in CUBE], keyword,
                                     card(1, 3), card(1, 2, 3, 4, 5, 6, 7, 8)])
    mesh = load(path)
    assert mesh.n_elements == 6 and set(mesh.parts.tolist()) == {3}


def test_a_tetrahedron_with_blank_n5_to_n8_is_a_tetrahedron(tmp_path):
    blank = write(tmp_path, "blank.k", [*part(1), "*NODE", *[node(*n) for n in CUBE[:5]],
                                        "*ELEMENT_SOLID", card(1, 1), card(1, 2, 4, 5)])
    repeated = write(tmp_path, "repeated.k", [
        *part(1), "*NODE", *[node(*n) for n in CUBE[:5]], "*ELEMENT_SOLID", card(1, 1),
        card(1, 2, 4, 5, 5, 5, 5, 5)])
    a, b = load(blank), load(repeated)
    assert a.n_elements == 4
    assert np.array_equal(a.elements, b.elements) and np.array_equal(a.nodes, b.nodes)


def test_beams_and_sph_are_read_beside_the_shells(tmp_path):
    path = write(tmp_path, "bird.k", [
        *part(1), *part(2), "*NODE", *[node(*n) for n in CUBE],
        "*ELEMENT_SHELL", card(1, 1, 1, 2, 3, 4),
        "*ELEMENT_BEAM", card(10, 2, 5, 6), card(11, 2, 6, 7), "",
        "*ELEMENT_SPH", "       5       2     1.0", "       6       2     1.0",
        "       7       2     1.0",
        "*ELEMENT_SPH", "       8       2     1.0",
    ])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # read, so nothing to name
        mesh = load(path)
    assert mesh.n_elements == 1
    assert mesh.beams.ids.tolist() == [10, 11] and mesh.beams.parts.tolist() == [2, 2]
    assert mesh.particles.ids.tolist() == [5, 6, 7, 8]
    assert mesh.node_ids[mesh.particles.node].tolist() == [5, 6, 7, 8]


# --------------------------------------------------------------------------- ids and parts
@pytest.mark.parametrize("element, what", [
    (card(1, 0, 1, 2, 3, 4), "expected a positive part id, got a blank or 0"),
    ("       1               1       2       3       4", "expected a positive part id, got a "
                                                          "blank or 0"),
    (card(1, -3, 1, 2, 3, 4), "expected a positive part id, got -3"),
    ("1,1e0,1,2,3,4", "expected an integer part id, got '1e0'"),
])
def test_blank_negative_or_exponent_part_ids_are_refused(tmp_path, element, what):
    path = write(tmp_path, "pid.k", ["*NODE", *[node(*n) for n in CUBE[:4]], "*ELEMENT_SHELL",
                                     element])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == 7 and what in info.value.message


def test_an_undefined_part_id_is_refused_where_parts_are_defined(tmp_path):
    path = write(tmp_path, "undefined.k", [
        *part(1), "*NODE", *[node(*n) for n in CUBE[:4]], "*ELEMENT_SHELL",
        card(1, 1, 1, 2, 3, 4), card(2, 9, 1, 2, 3, 3)])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == 11
    assert "part id 9 is not defined by any *PART" in info.value.message
    assert "defined: 1" in info.value.message


def test_a_mesh_file_without_parts_keeps_the_part_ids_of_its_cards(tmp_path):
    path = write(tmp_path, "mesh.k", ["*NODE", *[node(*n) for n in CUBE[:4]], "*ELEMENT_SHELL",
                                      card(1, 5, 1, 2, 3, 4)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = load(path)
    assert mesh.parts.tolist() == [5] and mesh.part_names == {}


@pytest.mark.parametrize("text", ["1e1", "1.0E1", "1d1"])
def test_an_id_written_with_an_exponent_is_refused(tmp_path, text):
    path = write(tmp_path, "exp.k", [
        *part(1), "*NODE", f"{text:>8}" + node(1, 0, 0, 0)[8:],
        *[node(*n) for n in CUBE[1:4]], "*ELEMENT_SHELL", card(1, 1, 10, 2, 3, 4)])
    with pytest.raises(ParseError, match="expected an integer node id") as info:
        load(path)
    assert info.value.line == 5


def test_an_integral_decimal_id_is_still_read(tmp_path):
    path = write(tmp_path, "decimal.k", [
        *part(1), "*NODE", "    10.0" + node(1, 0, 0, 0)[8:], *[node(*n) for n in CUBE[1:4]],
        "*ELEMENT_SHELL", card(1, 1, 10, 2, 3, 4)])
    assert load(path).node_ids.tolist() == [10, 2, 3, 4]


# --------------------------------------------------------------------------- cut and damaged files
FREE = ["*PART", "p", "1,1,1", "*SECTION_SHELL", "1,2", "0.2,0.2,0.2,0.2",
        "*NODE", "1,0.,0.,0.", "2,10.,0.,0.", "3,10.,10.,0.", "4,0.,10.,1778",
        "*ELEMENT_SHELL", "1,1,1,2,3,4"]


@pytest.mark.parametrize("lines", [
    FREE[:6] + FREE[11:] + FREE[6:10] + ["4,0.,10.,17"],  # z 17 of 1778
    FREE[:-1] + ["1,1,1,2,3"],  # a quad that would become a triangle
    FREE[6:] + FREE[:5] + ["0.2,0.2,0.2,0.1"],  # T4 0.1 of 0.15
])
def test_a_free_format_deck_cut_inside_its_last_card_is_refused(tmp_path, lines):
    path = write(tmp_path, "cut.k", lines, end="")
    with pytest.raises(ParseError, match="the file ends inside this card") as info:
        load(path)
    assert info.value.line == len(lines)
    # the strict reference refuses the same text
    assert "must be refused" in mesh_problem(load(write(tmp_path, "whole.k", FREE)),
                                             (tmp_path / "cut.k").read_bytes())


@pytest.mark.parametrize("last", ["1,1,1,2,3,4,", "1,1,1,2,3,4\n"])
def test_a_free_format_card_with_a_comma_or_line_end_after_it_is_read(tmp_path, last):
    path = write(tmp_path, "whole.k", FREE[:-1] + [last.rstrip("\n")],
                 end="\n" if last.endswith("\n") else "")
    mesh = load(path)
    assert mesh.n_elements == 1 and not mesh.is_triangle[0]
    assert mesh.nodes[3].tolist() == [0.0, 10.0, 1778.0]
    assert np.allclose(mesh.element_fields["thickness"], 0.2)
    assert mesh_problem(mesh, path.read_bytes()) == ""


def test_a_comma_past_the_fields_read_makes_the_card_comma_separated(tmp_path):
    """A comma beyond the columns the reader converts still makes the card free format: the
    card is read as comma-separated fields (here refused), not as fixed columns."""
    lines = ["*NODE", *[node(*n) for n in CUBE[:4]], "*ELEMENT_SHELL",
             card(1, 1, 1, 2, 3, 4) + "       0     , 0"]
    with pytest.raises(ParseError, match="expected an integer element id") as info:
        load(write(tmp_path, "comma.k", lines))
    assert info.value.line == 7


@pytest.mark.parametrize("tail", ["       0  0    0       0       0", ",0,0,7,0"])
def test_n5_to_n8_of_a_shell_with_thickness_cards_are_checked(tmp_path, tail):
    head = card(1, 1, 1, 2, 3, 4)
    line = head + tail if tail[0] == " " else "1,1,1,2,3,4" + tail
    path = write(tmp_path, "eight.k", ["*NODE", *[node(*n) for n in CUBE[:4]],
                                       "*ELEMENT_SHELL_THICKNESS", line, f"{1.0:16}" * 4])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == 7
    assert ("n5..n8" in info.value.message) or ("8-node shells" in info.value.message)


def test_a_nul_byte_is_refused_at_its_line(tmp_path):
    path = tmp_path / "nul.k"
    path.write_bytes(b"*NODE\n       1             0.0\x00            0.0             0.0\n")
    with pytest.raises(ParseError, match="NUL byte") as info:
        load(path)
    assert info.value.line == 2


def test_a_deep_include_chain_is_refused_not_a_recursion_error(tmp_path):
    depth = 2000
    for k in range(depth):
        (tmp_path / f"i{k}.k").write_text(f"*INCLUDE\ni{k + 1}.k\n")
    (tmp_path / f"i{depth}.k").write_text("*NODE\n" + node(1, 0, 0, 0) + "\n")
    with pytest.raises(ParseError, match="includes nested deeper than 64 files"):
        load(tmp_path / "i0.k")


def test_a_chain_within_the_bound_is_read(tmp_path):
    for k in range(40):
        (tmp_path / f"i{k}.k").write_text(f"*INCLUDE\ni{k + 1}.k\n")
    (tmp_path / "i40.k").write_text("\n".join([*part(1), "*NODE", *[node(*n) for n in CUBE[:4]],
                                               "*ELEMENT_SHELL", card(1, 1, 1, 2, 3, 4)]) + "\n")
    assert quiet_load(tmp_path / "i0.k").n_elements == 1


def test_the_reference_decodes_a_long_format_deck_like_the_reader(tmp_path):
    from workbench.reliability import long_deck

    path = tmp_path / "long.k"
    path.write_bytes(long_deck())
    mesh = load(path)
    expected = expected_mesh(long_deck())
    assert mesh.node_ids.tolist() == expected.node_ids.tolist()
    assert np.allclose(mesh.element_fields["thickness"], (0.5 + 0.75 + 0.6 + 0.75) / 4)
    assert mesh_problem(mesh, long_deck()) == ""
