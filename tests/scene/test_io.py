"""Mesh readers: LS-DYNA keyword decks, d3plot results, meshio and trimesh files."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from meshes import write_d3plot

from workbench.scene.readers import (
    MESHIO_SUFFIXES,
    ParseError,
    ParseWarning,
    detect_format,
    load,
)
from workbench.scene.readers.d3plot import mid_surface, von_mises


# --------------------------------------------------------------------------- writing small decks
def node(nid, x, y, z, width=8, coord=16) -> str:
    return f"{nid:{width}d}{x:{coord}.6f}{y:{coord}.6f}{z:{coord}.6f}{0:{width}d}{0:{width}d}"


def shell(eid, pid, *nodes, width=8) -> str:
    return "".join(f"{v:{width}d}" for v in (eid, pid, *nodes))


def write(folder, name, lines) -> str:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return path


SQUARE = [(101, 0.0, 0.0, 0.0), (102, 10.0, 0.0, 0.0), (103, 10.0, 10.0, 0.0),
          (104, 0.0, 10.0, 0.0), (105, 20.0, 0.0, 0.0)]


def two_element_deck(width=8, coord=16, header="*KEYWORD", suffix=""):
    return [
        header,
        "$ two shells: a quad and a triangle",
        f"*NODE{suffix}",
        *[node(*n, width=width, coord=coord) for n in SQUARE],
        f"*ELEMENT_SHELL{suffix}",
        shell(7, 3, 101, 102, 103, 104, width=width),
        shell(9, 3, 102, 105, 103, 103, width=width),
        "*END",
    ]


def ids_of(mesh):
    """Element connectivity as node ids (independent of the index order)."""
    return mesh.node_ids[mesh.elements]


# --------------------------------------------------------------------------- shared data
def test_car_deck(car_deck):
    mesh = load(car_deck)
    assert (mesh.n_nodes, mesh.n_elements) == (4395, 4366)
    assert sorted(np.unique(mesh.parts).tolist()) == list(range(1, 9))
    assert set(mesh.part_names) == set(range(1, 9))
    assert mesh.part_names[8] == "material type # 20 (Rigid)"
    assert "Kinematic/Isotropic Elastic-Plastic" in mesh.part_names[1]
    assert len(np.unique(mesh.node_ids)) == 4395 and len(np.unique(mesh.element_ids)) == 4366
    # element 1 of the deck: "1 2 1 3877 3881 3880"
    first = int(np.flatnonzero(mesh.element_ids == 1)[0])
    assert ids_of(mesh)[first].tolist() == [1, 3877, 3881, 3880]
    assert mesh.parts[first] == 2
    lo, hi = mesh.bounds()
    assert np.allclose(lo, [-355.384, 0.0, -254.0]) and np.allclose(hi, [4318.0, 1397.0, 1778.0])
    thickness = mesh.element_fields["thickness"]
    assert (thickness > 0).all()
    # section thicknesses through *PARAMETER (&tbumper = 3, &thood = 1, &trailf = 5) and the
    # 0.2 mm element thickness cards of the rigid part 8
    expected = {1: 2.0, 2: 3.0, 3: 1.0, 4: 1.0, 5: 5.0, 6: 2.0, 7: 2.0, 8: 0.2}
    for pid, t in expected.items():
        assert np.allclose(thickness[mesh.parts == pid], t), pid
    assert mesh.units == "mm"


def test_d3plot_sample(d3plot_file):
    mesh = load(d3plot_file)
    assert (mesh.n_nodes, mesh.n_elements) == (4915, 4696)
    assert mesh.steps.shape == (1, 4915, 3) and mesh.times.shape == (1,)
    # the state array holds coordinates (equal to the geometry at t = 0), not displacements
    assert np.abs(mesh.nodes).max() > 1.0
    assert np.array_equal(mesh.steps[0], mesh.nodes)
    for name in ("von_mises", "plastic_strain", "thickness", "alive"):
        values = mesh.element_fields[name]
        assert values.shape == (1, 4696) and np.isfinite(values).all(), name
    assert (mesh.element_fields["von_mises"] >= 0).all()
    assert np.allclose(mesh.element_fields["thickness"], 2.93, atol=1e-5)
    assert (mesh.element_fields["alive"] == 1).all()
    assert mesh.part_names == {1: "Zugprobe"} and (mesh.parts == 1).all()
    assert len(np.unique(mesh.element_ids)) == 4696


def test_d3plot_states_and_fields(tmp_path):
    mesh = load(write_d3plot(tmp_path))
    assert mesh.steps.shape == (3, 5, 3)
    assert np.allclose(mesh.times, [0.0, 1e-3, 2e-3])
    assert np.allclose(mesh.steps[2, :, 2], 1.0) and np.allclose(mesh.nodes[:, 2], 0.0)
    assert mesh.node_ids.tolist() == [10, 20, 30, 40, 50]
    assert mesh.element_ids.tolist() == [7, 8] and mesh.parts.tolist() == [5, 9]
    assert mesh.is_triangle.tolist() == [False, True]
    assert np.allclose(mesh.element_fields["von_mises"], 100.0)
    assert np.allclose(mesh.element_fields["plastic_strain"][:, 0], [0.0, 0.01, 0.02])
    assert np.allclose(mesh.element_fields["thickness"], 1.5)
    assert mesh.element_fields["alive"].tolist() == [[1, 1], [1, 1], [1, 0]]
    assert mesh.n_elements == 2  # a deleted element is kept, flagged


def test_d3plot_rigid_shells_get_nan(tmp_path):
    mesh = load(write_d3plot(tmp_path, rigid=True))
    vm = mesh.element_fields["von_mises"]
    assert np.allclose(vm[:, 0], 100.0) and np.isnan(vm[:, 1]).all()


def test_d3plot_family_member_reads_the_family(tmp_path):
    write_d3plot(tmp_path)
    assert (tmp_path / "d3plot01").exists()
    assert load(tmp_path / "d3plot01").steps.shape == (3, 5, 3)


def test_d3plot_garbage_is_a_parse_error(tmp_path):
    path = tmp_path / "d3plot"
    path.write_bytes(b"\x00\x01garbage" * 10)
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.path == path


stress_values = st.floats(-1e3, 1e3, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.lists(stress_values, min_size=6, max_size=6))
def test_von_mises_matches_principal_stresses(components):
    xx, yy, zz, xy, yz, zx = components
    principal = np.linalg.eigvalsh(np.array([[xx, xy, zx], [xy, yy, yz], [zx, yz, zz]]))
    s1, s2, s3 = principal
    reference = np.sqrt(((s1 - s2) ** 2 + (s2 - s3) ** 2 + (s3 - s1) ** 2) / 2)
    # LAPACK's eigenvalues are exact to a small multiple of the largest component (less so
    # beside subnormal-sized entries): the tolerance scales with it
    scale = max(1.0, float(np.abs(components).max()))
    assert von_mises(np.array(components)) == pytest.approx(reference, rel=1e-7, abs=1e-6 * scale)


def test_mid_surface_layer_order():
    layers = lambda n: np.arange(n, dtype=float).reshape(1, 1, n)  # noqa: E731
    assert mid_surface(layers(3))[0, 0] == 0  # mid, inner, outer
    assert mid_surface(layers(5))[0, 0] == 2  # bottom to top
    assert mid_surface(layers(4))[0, 0] == 1.5
    assert mid_surface(layers(1))[0, 0] == 0


# --------------------------------------------------------------------------- keyword decks
def test_fixed_width_blank_fields(tmp_path):
    path = write(tmp_path, "blank.k", [
        "*KEYWORD",
        "*NODE",
        "       1             1.5                            -2.0",  # blank y, no tc/rc
        "       2",  # all coordinates blank
        "       3            1.D2             0.0             0.0       0       0",
        "*ELEMENT_SHELL",
        "      11       4       1       2       3",  # blank n4: a triangle
        "*END",
    ])
    mesh = load(path)
    assert mesh.nodes.tolist() == [[1.5, 0.0, -2.0], [0.0, 0.0, 0.0], [100.0, 0.0, 0.0]]
    assert mesh.parts.tolist() == [4]
    assert mesh.is_triangle.tolist() == [True]


def test_free_format_and_mixed_cards(tmp_path):
    path = write(tmp_path, "free.k", [
        "*KEYWORD",
        "*NODE",
        "1, 0.0, 0.0, 0.0",
        "2,10.0,0,0,0,0",
        node(3, 10.0, 10.0, 0.0),
        "4,0.0,10.0",  # z omitted
        "*ELEMENT_SHELL",
        "5,2,1,2,3,4",
        shell(6, 2, 2, 3, 4, 4),
        "*END",
    ])
    mesh = load(path)
    assert mesh.node_ids.tolist() == [1, 2, 3, 4]
    assert np.allclose(mesh.nodes, [[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]])
    assert ids_of(mesh).tolist() == [[1, 2, 3, 4], [2, 3, 4, 4]]
    assert mesh.element_ids.tolist() == [5, 6] and mesh.parts.tolist() == [2, 2]


def test_comments_case_unknown_keywords_and_end(tmp_path):
    path = write(tmp_path, "mixed.k", [
        "$ a comment before anything",
        "*keyword",
        "*Control_Termination",
        "      0.15         0",
        "*node",
        "$#   nid               x               y               z      tc      rc",
        *[node(*n) for n in SQUARE[:4]],
        "$ comment inside a block",
        node(*SQUARE[4]),
        "*ELEMENT_BEAM",
        "       1       1     101     102     103",
        "*element_shell",
        shell(1, 1, 101, 102, 103, 104),
        "",
        "*End",
        "*ELEMENT_SHELL",
        "this would not parse",
    ])
    mesh = load(path)
    assert mesh.n_nodes == 5 and mesh.n_elements == 1 and mesh.beams.count == 1


def test_triangles(tmp_path):
    path = write(tmp_path, "tri.k", [
        "*NODE", *[node(*n) for n in SQUARE],
        "*ELEMENT_SHELL",
        shell(1, 1, 101, 102, 103, 103),
        shell(2, 1, 102, 105, 103),  # n4 blank
        shell(3, 1, 101, 102, 103, 104),
    ])
    mesh = load(path)
    assert mesh.is_triangle.tolist() == [True, True, False]
    assert (mesh.elements[:2, 3] == mesh.elements[:2, 2]).all()
    assert ids_of(mesh)[1].tolist() == [102, 105, 103, 103]


def test_element_shell_thickness_and_sections(tmp_path):
    path = write(tmp_path, "thick.k", [
        "*PARAMETER",
        "Rtsec     2.5       ",
        "*PART",
        "left part",
        "         1         4         1",
        "no section",
        "         2        99         1",
        "*SECTION_SHELL",
        "         4         2",
        "&tsec",
        "*NODE", *[node(*n) for n in SQUARE],
        "*ELEMENT_SHELL_THICKNESS",
        shell(1, 1, 101, 102, 103, 104),
        "             1.0             2.0             3.0             2.0",
        shell(3, 1, 101, 102, 103, 103),
        "             1.0             1.0                             ",
        shell(2, 1, 102, 105, 103, 103),
        "$ blank thickness card, the last of the block: the section's 2.5",
        "",
        "*ELEMENT_SHELL",
        shell(4, 1, 101, 102, 103, 104),
        shell(5, 2, 101, 102, 103, 104),  # part 2's section 99 is not defined
    ])
    mesh = load(path)
    thickness = mesh.element_fields["thickness"]
    assert mesh.element_ids.tolist() == [1, 3, 2, 4, 5]
    assert np.allclose(thickness[:4], [2.0, (1 + 1 + 2.5) / 3, 2.5, 2.5])
    assert np.isnan(thickness[4])


def test_part_titles(tmp_path):
    path = write(tmp_path, "parts.k", [
        "*PART",
        "front rail",
        "        11         1         1",
        "",  # an empty title
        "        12         1         1",
        "*PART_CONTACT",
        "roof",
        "        13         1         1",
        "       0.0       0.0",
        "hood",
        "        14         1         1",
        "       0.0       0.0",
        "",
        "*PART",
        "",
        "        15",
        "*PART_MOVE",
        "        13       1.0       0.0       0.0",
        "*NODE", *[node(*n) for n in SQUARE],
        "*ELEMENT_SHELL",
        *[shell(i, pid, 101, 102, 103, 104) for i, pid in enumerate((11, 12, 13, 14, 15), 1)],
    ])
    mesh = load(path)
    assert mesh.part_names == {11: "front rail", 13: "roof", 14: "hood"}
    assert mesh.parts.tolist() == [11, 12, 13, 14, 15]


def test_include_relative_to_the_including_file(tmp_path):
    write(tmp_path, "sub/deeper/elements.k", [
        "*ELEMENT_SHELL", shell(1, 1, 101, 102, 103, 104), shell(2, 1, 102, 105, 103, 103)])
    write(tmp_path, "sub/nodes.k", [
        "*KEYWORD", "*NODE", *[node(*n) for n in SQUARE], "*INCLUDE", "deeper/elements.k",
        "*END"])
    path = write(tmp_path, "main.k", ["*KEYWORD", "*INCLUDE", "$ the nodes", "sub/nodes.k",
                                      "*PART", "the part", "         1", "*END"])
    mesh = load(path)
    assert mesh.n_nodes == 5 and mesh.n_elements == 2 and mesh.part_names == {1: "the part"}


def test_i10_and_long_formats_read_alike(tmp_path):
    small = load(write(tmp_path, "small.k", two_element_deck()))
    variants = [
        two_element_deck(width=10, suffix=" %"),
        two_element_deck(width=10, header="*KEYWORD I10=Y"),
        two_element_deck(width=20, coord=20, header="*KEYWORD LONG=Y"),
        two_element_deck(width=20, coord=20, suffix="+"),
    ]
    for i, lines in enumerate(variants):
        mesh = load(write(tmp_path, f"variant{i}.k", lines))
        assert np.array_equal(mesh.nodes, small.nodes), i
        assert np.array_equal(ids_of(mesh), ids_of(small)), i
        assert mesh.parts.tolist() == [3, 3], i


def test_long_include_of_a_small_deck(tmp_path):
    write(tmp_path, "long.k", two_element_deck(width=20, coord=20)[1:])
    path = write(tmp_path, "master.k", ["*KEYWORD", "*INCLUDE +", "long.k"])
    assert load(path).n_elements == 2


ids = st.integers(-(2**40), 2**40)
coordinates = st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: float(f"{v:.7g}"))


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_random_decks_read_back(tmp_path, data):
    n = data.draw(st.integers(3, 12))
    ids = st.integers(-(10**7) + 1, 10**8 - 1).filter(bool)  # a node id 0 is refused
    node_ids = data.draw(st.lists(ids, min_size=n, max_size=n, unique=True))
    xyz = data.draw(st.lists(st.tuples(coordinates, coordinates, coordinates), min_size=n,
                             max_size=n))
    free = data.draw(st.lists(st.booleans(), min_size=2 * n, max_size=2 * n))
    lines = ["*NODE"]
    for k, (nid, (x, y, z)) in enumerate(zip(node_ids, xyz)):
        lines.append(f"{nid},{x!r},{y!r},{z!r}" if free[k]
                     else f"{nid:8d}{x:16.7g}{y:16.7g}{z:16.7g}")
    m = data.draw(st.integers(1, 8))
    cells = data.draw(st.lists(st.lists(st.sampled_from(node_ids), min_size=4, max_size=4),
                               min_size=m, max_size=m))
    lines.append("*ELEMENT_SHELL")
    for k, cell in enumerate(cells):
        values = (k * 1000 - 5, k % 3 + 1, *cell)
        lines.append(",".join(map(str, values)) if free[n + k % n] else shell(*values))
    mesh = load(write(tmp_path, "random.k", lines))
    assert mesh.node_ids.tolist() == node_ids
    assert np.array_equal(mesh.nodes, np.array(xyz, dtype=float))
    assert ids_of(mesh).tolist() == cells
    assert mesh.element_ids.tolist() == [k * 1000 - 5 for k in range(m)]
    assert mesh.parts.tolist() == [k % 3 + 1 for k in range(m)]


# --------------------------------------------------------------------------- refusals
def test_malformed_node_names_line_and_card(tmp_path):
    path = write(tmp_path, "bad.k", [
        "*KEYWORD", "*NODE", node(1, 0, 0, 0), "$ comment",
        "       2             abc             0.0             0.0",
        "*ELEMENT_SHELL", shell(1, 1, 1, 2, 2, 2)])
    with pytest.raises(ParseError) as info:
        load(path)
    err = info.value
    assert isinstance(err, ValueError)
    assert (err.path, err.line) == (path, 5)
    assert err.card == "       2             abc             0.0             0.0"
    assert "expected 3 coordinates" in err.message
    assert str(err).startswith(f"{path}:5: *NODE: expected 3 coordinates, got 'abc' in '")


def test_malformed_element_and_free_format_lines(tmp_path):
    base = ["*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL"]
    with pytest.raises(ParseError) as info:
        load(write(tmp_path, "a.k", base + [shell(1, 1, 101, 102, 103, 104), "2,1,101,x,103"]))
    assert info.value.line == 9 and "'x'" in info.value.message
    with pytest.raises(ParseError) as info:
        load(write(tmp_path, "b.k", base + ["       1       1 101 102 103 104"]))
    assert info.value.line == 8 and "node ids" in info.value.message


def test_malformed_line_in_included_file(tmp_path):
    inner = write(tmp_path, "parts/inner.k", [
        "*NODE", node(1, 0, 0, 0), node(2, 1, 0, 0), "$ the next one is broken",
        "       3        1.0.0           0.0             0.0"])
    path = write(tmp_path, "main.k", ["*KEYWORD", "*INCLUDE", "parts/inner.k",
                                      "*ELEMENT_SHELL", shell(1, 1, 1, 2, 3, 3)])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.path.resolve() == inner.resolve() and info.value.line == 5
    assert str(info.value).startswith(f"{info.value.path}:5: *NODE:")


def test_missing_thickness_card(tmp_path):
    path = write(tmp_path, "odd.k", [
        "*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL_THICKNESS",
        shell(1, 1, 101, 102, 103, 104), "             1.0", shell(2, 1, 101, 102, 103, 104)])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == 10


def test_missing_node_reference(tmp_path):
    path = write(tmp_path, "dangling.k", [
        "*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL",
        shell(1, 1, 101, 102, 103, 104), shell(2, 1, 101, 999, 103, 104),
        shell(3, 1, 998, 102, 103, 104)])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == 9
    assert "(2, 999)" in info.value.message and "(3, 998)" in info.value.message


def test_duplicate_ids(tmp_path):
    path = write(tmp_path, "dup.k", [
        "*NODE", *[node(*n) for n in SQUARE], node(102, 5, 5, 5), "*ELEMENT_SHELL",
        shell(1, 1, 101, 102, 103, 104)])
    with pytest.raises(ParseError, match="node id 102 is defined twice") as info:
        load(path)
    assert info.value.line == 7
    path = write(tmp_path, "dup2.k", [
        "*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL",
        shell(1, 1, 101, 102, 103, 104), shell(1, 1, 101, 102, 103, 104)])
    with pytest.raises(ParseError, match="element id 1 is defined twice"):
        load(path)


def test_empty_decks(tmp_path):
    with pytest.raises(ParseError, match="no shell or solid elements"):
        load(write(tmp_path, "empty.k", ["*KEYWORD", "*END"]))
    with pytest.raises(ParseError, match=r"\*ELEMENT_SOLID"):
        load(write(tmp_path, "solid.k", [
            "*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SOLID",
            "       1       1     101     102     103     104     105     105     105     105"]))


def test_include_errors(tmp_path):
    with pytest.raises(ParseError, match="not found") as info:
        load(write(tmp_path, "missing.k", ["*KEYWORD", "*INCLUDE", "nowhere.k"]))
    assert info.value.line == 3
    write(tmp_path, "b.k", ["*INCLUDE", "a.k"])
    with pytest.raises(ParseError, match="include cycle"):
        load(write(tmp_path, "a.k", ["*INCLUDE", "b.k"]))
    with pytest.raises(ParseError, match="INCLUDE_TRANSFORM"):
        load(write(tmp_path, "t.k", ["*INCLUDE_TRANSFORM", "b.k"]))


def test_unsupported_variants_and_parameters(tmp_path):
    with pytest.raises(ParseError, match="ELEMENT_SHELL_COMPOSITE"):
        load(write(tmp_path, "c.k", ["*ELEMENT_SHELL_COMPOSITE", shell(1, 1, 1, 2, 3, 4)]))
    with pytest.warns(ParseWarning, match=r"'tmissing' is not defined .* part 1 have no"):
        mesh = load(write(tmp_path, "p.k", [
            "*PART", "p", "         1         1", "*SECTION_SHELL", "         1",
            "&tmissing", "*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL",
            shell(1, 1, 101, 102, 103, 104)]))
    assert mesh.n_elements == 1 and np.isnan(mesh.element_fields["thickness"]).all()


def test_unknown_suffix_and_missing_file(tmp_path):
    path = tmp_path / "mesh.xyz123"
    path.write_text("")
    with pytest.raises(ParseError, match="supported") as info:
        load(path)
    assert "mesh.xyz123" in str(info.value) and ".k" in str(info.value)
    with pytest.raises(FileNotFoundError, match="nothere.k"):
        load(tmp_path / "nothere.k")
    assert detect_format("run/d3plot") == "d3plot" and detect_format("x.KEY") == "keyword"


# --------------------------------------------------------------------------- meshio and trimesh
def test_meshio_round_trip(tmp_path):
    import meshio

    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], float)
    cells = [("quad", np.array([[0, 1, 2, 3]])), ("triangle", np.array([[1, 4, 2]])),
             ("line", np.array([[0, 1]]))]
    path = tmp_path / "mesh.vtu"
    meshio.write(path, meshio.Mesh(
        points, cells, point_data={"temperature": np.arange(5.0), "velocity": np.ones((5, 3))},
        cell_data={"pressure": [np.array([1.5]), np.array([2.5]), np.array([9.0])]}))
    mesh = load(path)
    assert np.array_equal(mesh.nodes, points)
    assert mesh.elements.tolist() == [[0, 1, 2, 3], [1, 4, 2, 2]]
    assert mesh.node_fields.keys() == {"temperature"}
    assert np.array_equal(mesh.node_fields["temperature"], np.arange(5.0))
    assert mesh.element_fields["pressure"].tolist() == [1.5, 2.5]


def test_meshio_gmsh_physical_tags_become_parts(tmp_path):
    import meshio

    points = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0]], float)
    cells = [("quad", np.array([[0, 1, 2, 3]])), ("triangle", np.array([[1, 4, 2]]))]
    raw = meshio.Mesh(points, cells, cell_data={
        "gmsh:physical": [np.array([4]), np.array([6])],
        "gmsh:geometrical": [np.array([1]), np.array([2])]})
    raw.field_data = {"roof": np.array([4, 2]), "door": np.array([6, 2])}
    path = tmp_path / "mesh.msh"
    meshio.write(path, raw, file_format="gmsh22", binary=False)
    mesh = load(path)
    assert mesh.parts.tolist() == [4, 6] and mesh.part_names == {4: "roof", 6: "door"}
    assert np.allclose(mesh.nodes[:, 2], 0.0)


def test_meshio_abaqus_element_sets_become_parts(tmp_path):
    path = write(tmp_path, "model.inp", [
        "*NODE", "1, 0.0, 0.0, 0.0", "2, 1.0, 0.0, 0.0", "3, 1.0, 1.0, 0.0", "4, 0.0, 1.0, 0.0",
        "5, 2.0, 0.0, 0.0",
        "*ELEMENT, TYPE=S4, ELSET=ROOF", "1, 1, 2, 3, 4",
        "*ELEMENT, TYPE=S3, ELSET=DOOR", "2, 2, 5, 3"])
    mesh = load(path)
    assert mesh.elements.tolist() == [[0, 1, 2, 3], [1, 4, 2, 2]]
    assert mesh.parts.tolist() == [1, 2] and mesh.part_names == {1: "ROOF", 2: "DOOR"}


def test_meshio_errors_are_parse_errors(tmp_path):
    path = tmp_path / "broken.vtu"
    path.write_text("<VTKFile> not really")
    with pytest.raises(ParseError, match="meshio") as info:
        load(path)
    assert info.value.path == path
    import meshio

    path = tmp_path / "lines.vtu"
    meshio.write(path, meshio.Mesh(np.zeros((2, 3)), [("line", np.array([[0, 1]]))]))
    with pytest.raises(ParseError, match="no quad or triangle cells"):
        load(path)


def test_meshio_suffixes_are_known_to_meshio():
    import meshio

    known = set(meshio.extension_to_filetypes)
    assert set(MESHIO_SUFFIXES) <= known


def test_trimesh_stl_round_trip(tmp_path):
    import trimesh

    box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    path = tmp_path / "box.stl"
    box.export(path)
    mesh = load(path)
    assert mesh.n_nodes == 8 and mesh.n_elements == 12  # corners shared again
    assert mesh.is_triangle.all()
    lo, hi = mesh.bounds()
    assert np.allclose(lo, [-0.5, -1.0, -1.5]) and np.allclose(hi, [0.5, 1.0, 1.5])
    area = 0.5 * np.linalg.norm(
        np.cross(mesh.nodes[mesh.elements[:, 1]] - mesh.nodes[mesh.elements[:, 0]],
                 mesh.nodes[mesh.elements[:, 2]] - mesh.nodes[mesh.elements[:, 0]]), axis=1)
    assert area.sum() == pytest.approx(box.area)


def test_trimesh_errors_are_parse_errors(tmp_path):
    path = tmp_path / "broken.ply"
    path.write_bytes(b"ply\nformat nonsense\n")
    with pytest.raises(ParseError, match="trimesh") as info:
        load(path)
    assert info.value.path == path


# --------------------------------------------------------------------------- integer fields
def test_integral_floats_in_integer_fields_of_every_card_type_read(tmp_path):
    """Other pre-processors write integer fields as floats (``0.000E+00``, ``8.``); LS-DYNA
    reads an integral float there, in fixed columns and in comma format alike. Ids (node,
    element and part ids) take integral floats in decimal notation only."""
    path = write(tmp_path, "floats.k", [
        "*KEYWORD",
        "*PART",
        "floated part",
        "1.0,8.000E+00,1.0",
        "*SECTION_SHELL",
        "8,2,0.000E+00,0.000E+00,0.000E+00,0.000E+00,0",
        "1.5,1.5,1.5,1.5",
        "*NODE",
        "   101.0             0.0             0.0             0.0",
        "     102            10.0             0.0             0.0",
        "103.0,10.0,10.0,0.0",
        "     104             0.0            10.0             0.0",
        "*ELEMENT_SHELL",
        "    7.00     1.0   101.0   102.0   103.0   104.0",
        "8.0,1,101,102.0,103,103.000",
        "*END",
    ])
    mesh = load(path)
    assert mesh.node_ids.tolist() == [101, 102, 103, 104]
    assert mesh.element_ids.tolist() == [7, 8]
    assert ids_of(mesh).tolist() == [[101, 102, 103, 104], [101, 102, 103, 103]]
    assert np.allclose(mesh.element_fields["thickness"], 1.5)  # section 8 found as 8.000E+00
    assert mesh.parts.tolist() == [mesh.parts[0]] * 2


@pytest.mark.parametrize("card, field, value", [
    ("    7.50       1     101     102     103     104", "element id", "7.50"),
    ("7,1,101,102.5,103,104", "node ids", "102.5"),
    ("       7       1     101     102     103    1e30", "node ids", "1e30"),
    ("       7       1     101     102     103     nan", "node ids", "nan"),
])
def test_fractional_or_non_finite_integers_are_refused_naming_field_and_value(
        tmp_path, card, field, value):
    path = write(tmp_path, "frac.k", ["*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL", card])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == 8
    assert field in info.value.message and repr(value) in info.value.message


def test_fractional_section_integer_is_refused_naming_it(tmp_path):
    path = write(tmp_path, "sec.k", ["*SECTION_SHELL", "8,2,0.0,4.5,0,0,0", "1.0,1.0,1.0,1.0",
                                     "*NODE", *[node(*n) for n in SQUARE],
                                     "*ELEMENT_SHELL", shell(1, 8, 101, 102, 103, 104)])
    with pytest.raises(ParseError, match=r"expected an integer NIP, got '4.5'") as info:
        load(path)
    assert info.value.line == 2


@pytest.mark.parametrize("card, line", [
    ("      38_7             0.0             0.0             0.0", 3),  # fixed integer
    ("     106         1_000.0             0.0             0.0", 3),  # fixed float
    ("106,1_000.0,0.0,0.0", 3),  # comma float
    ("10_6,1.0,0.0,0.0", 3),  # comma integer
])
def test_underscores_in_numbers_are_refused(tmp_path, card, line):
    path = write(tmp_path, "under.k", ["*NODE", node(*SQUARE[0]), card,
                                       *[node(*n) for n in SQUARE[1:]]])
    with pytest.raises(ParseError) as info:
        load(path)
    assert info.value.line == line


@given(st.integers(-2**40, 2**40),
       st.sampled_from(["{:d}", "{:.1f}", "{:.15E}", "{:.0f}.", "{:+.2f}"]))
def test_integer_field_parser_takes_integral_values_in_any_notation(value, form):
    from workbench.scene.readers.cards import _convert

    text = form.format(value).encode()
    assert _convert(text, "i") == value


@given(st.floats(allow_nan=True, allow_infinity=True).filter(
    lambda x: not (np.isfinite(x) and x == np.floor(x))))
def test_integer_field_parser_refuses_fractional_and_non_finite(value):
    from workbench.scene.readers.cards import _convert

    with pytest.raises(ValueError):
        _convert(repr(value).encode(), "i")


# --------------------------------------------------------------------------- damaged decks
def test_deck_cut_off_inside_its_last_card_is_refused(tmp_path, car_deck):
    """``head -c`` through the last node card: the missing fields must not read as 0."""
    data = car_deck.read_bytes()
    start = data.index(b"*NODE")
    end = data.index(b"\n*", start + 1)  # the end of the node block's last card
    cut = tmp_path / "cut.k"
    cut.write_bytes(data[:end - 20])
    with pytest.raises(ParseError, match="the file ends inside this card") as info:
        load(cut)
    assert info.value.line == data[:end].count(b"\n") + 1


def test_a_whole_last_card_without_a_final_line_end_reads(tmp_path):
    lines = two_element_deck()[:-1]  # ends with the last element card, no *END
    path = tmp_path / "open.k"
    path.write_bytes("\n".join(lines).encode())
    mesh = load(path)
    assert ids_of(mesh).tolist() == [[101, 102, 103, 104], [102, 105, 103, 103]]


def test_free_format_card_cut_off_at_the_end_of_the_file(tmp_path):
    path = tmp_path / "cut.k"
    path.write_bytes(b"*NODE\n1,0.0,0.0,0.0\n2,10.0,0.0,0.0\n3,10.0,10.0,0.0\n*ELEMENT_SHELL\n"
                     b"1,1,1,2,3,3\n*NODE\n4,5.0,5.0")
    with pytest.raises(ParseError, match="ends inside this card") as info:
        load(path)
    assert info.value.line == 8


def test_stray_carriage_return_and_blank_ids_are_refused(tmp_path):
    body = [node(*n) for n in SQUARE]
    path = tmp_path / "cr.k"
    lines = ["*NODE", *body, "*ELEMENT_SHELL", shell(7, 3, 101, 102, 103, 104)]
    text = "\n".join(lines) + "\n"
    path.write_bytes(text.replace(body[2], body[2][:30] + "\r" + body[2][30:]).encode())
    with pytest.raises(ParseError, match="carriage return inside a line") as info:
        load(path)
    assert info.value.line == 4
    blank = write(tmp_path, "blank.k", ["*NODE", *body, "        " + body[0][8:],
                                        "*ELEMENT_SHELL", shell(7, 3, 101, 102, 103, 104)])
    with pytest.raises(ParseError, match="expected a node id, got a blank or 0") as info:
        load(blank)
    assert info.value.line == 7
    zero = write(tmp_path, "zero.k", ["*NODE", *body, "*ELEMENT_SHELL", "0,3,101,102,103,104"])
    with pytest.raises(ParseError, match="expected an element id") as info:
        load(zero)
    assert info.value.line == 8


@pytest.mark.parametrize("line_end", [b"\r\n", b"\r"])
def test_other_systems_line_ends_read_the_identical_mesh(tmp_path, line_end):
    lines = two_element_deck()
    plain = load(write(tmp_path, "plain.k", lines))
    other = tmp_path / "other.k"
    other.write_bytes(line_end.join(line.encode() for line in lines) + line_end)
    mesh = load(other)
    assert np.array_equal(mesh.nodes, plain.nodes) and np.array_equal(mesh.elements, plain.elements)
    assert mesh.node_ids.tolist() == plain.node_ids.tolist()


# --------------------------------------------------------------------------- solid elements
def solid_block_deck(n: int = 3, two_cards: bool = False, tets: bool = False) -> list[str]:
    """An n×n×n block of 10 mm hexahedra (or each cut into 6 tetrahedra), node ids from 1."""
    g = np.arange(n + 1)
    nid = lambda i, j, k: 1 + i + (n + 1) * (j + (n + 1) * k)  # noqa: E731
    lines = ["*KEYWORD", "*NODE"]
    for k in g:
        for j in g:
            for i in g:
                lines.append(node(nid(i, j, k), 10.0 * i, 10.0 * j, 10.0 * k))
    lines.append("*ELEMENT_SOLID")
    eid = 0
    for k in range(n):
        for j in range(n):
            for i in range(n):
                c = [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                     nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1),
                     nid(i, j + 1, k + 1)]
                cells = [c]
                if tets:  # the 6 tetrahedra around the diagonal c0-c6
                    cells = [[c[0], c[1], c[2], c[6]], [c[0], c[2], c[3], c[6]],
                             [c[0], c[3], c[7], c[6]], [c[0], c[7], c[4], c[6]],
                             [c[0], c[4], c[5], c[6]], [c[0], c[5], c[1], c[6]]]
                    cells = [t + [t[3]] * 4 for t in cells]
                for cell in cells:
                    eid += 1
                    if two_cards:
                        lines += [shell(eid, 5), "".join(f"{v:8d}" for v in cell)]
                    else:
                        lines.append(shell(eid, 5, *cell))
    return lines + ["*END"]


@pytest.mark.parametrize("two_cards", [False, True])
def test_solid_hexahedra_are_drawn_by_their_boundary_faces(tmp_path, two_cards):
    mesh = load(write(tmp_path, "block.k", solid_block_deck(3, two_cards)))
    assert mesh.n_elements == 6 * 3 * 3 == mesh.n_quads  # the outer quads only
    assert set(mesh.parts.tolist()) == {5}
    assert set(mesh.element_ids.tolist()) <= set(range(1, 28)) and 14 not in mesh.element_ids
    centre = mesh.nodes.mean(axis=0)
    e = mesh.nodes[mesh.elements]
    normal = np.cross(e[:, 1] - e[:, 0], e[:, 2] - e[:, 0])
    assert (np.einsum("ij,ij->i", normal, e.mean(axis=1) - centre) > 0).all()  # outward
    every = load(write(tmp_path, "block_all.k", solid_block_deck(3, two_cards)), all_faces=True)
    assert every.n_elements == 6 * 27


def test_solid_tetrahedra_give_the_outer_triangles_and_render(tmp_path):
    path = write(tmp_path, "tets.k", solid_block_deck(2, tets=True))
    mesh = load(path)
    assert mesh.n_elements == 6 * 2 * 2 * 2 and mesh.n_quads == 0
    area = 0.5 * np.linalg.norm(np.cross(*(mesh.nodes[mesh.elements[:, [1, 2]]].transpose(1, 0, 2)
                                         - mesh.nodes[mesh.elements[:, 0]])), axis=1)
    assert area.sum() == pytest.approx(6 * 20.0 * 20.0)
    from workbench.cli import main

    out = tmp_path / "tets.png"
    assert main(["render", str(path), "--size", "64x48", "-o", str(out)]) == 0


def test_solid_refusals_name_the_card(tmp_path):
    lines = solid_block_deck(1)
    bad = [*lines[:-2], shell(2, 5, 1, 2, 3, 4, 5, 6, 7, 99), "*END"]
    with pytest.raises(ParseError, match=r"undefined node ids; first \(element id, node id\): "
                                         r"\(2, 99\)") as info:
        load(write(tmp_path, "undefined.k", bad))
    assert info.value.line == len(bad) - 1
    pyramid = [*lines[:-2], shell(2, 5, 1, 2, 4, 3, 5, 5, 5, 5), "*END"]
    with pytest.raises(ParseError, match="a node pattern LS-DYNA does not define") as info:
        load(write(tmp_path, "pyramid.k", pyramid))
    assert info.value.line == len(pyramid) - 1
    ortho = [line.replace("*ELEMENT_SOLID", "*ELEMENT_SOLID_ORTHO") for line in lines]
    with pytest.raises(ParseError, match="not supported"):
        load(write(tmp_path, "ortho.k", ortho))


# --------------------------------------------------------------------------- parameters
def _sectioned_part(thickness_card: str) -> list[str]:
    return ["*PART", "p", "         1         1", "*SECTION_SHELL", "         1",
            thickness_card]


def test_include_uses_the_parameters_of_the_including_deck(tmp_path):
    """An included file's ``&t`` is defined by the deck that includes it: read through that
    deck the thickness is there; read alone its geometry is read, its thickness missing (NaN,
    drawn in the no-result colour), with one warning naming the parameter and the part."""
    part = write(tmp_path, "part.k", [*_sectioned_part("&t"), "*NODE",
                                      *[node(*n) for n in SQUARE], "*ELEMENT_SHELL",
                                      shell(1, 1, 101, 102, 103, 104)])
    master = write(tmp_path, "master.k", ["*KEYWORD", "*PARAMETER", "R t       1.25",
                                          "*INCLUDE", "part.k", "*END"])
    mesh = load(master)
    assert mesh.element_fields["thickness"].tolist() == [1.25]
    with pytest.warns(ParseWarning) as said:
        alone = load(part)
    assert [str(w.message) for w in said] == [
        f"{part}:6: *SECTION_SHELL: parameter 't' is not defined by *PARAMETER in this deck or "
        f"its includes (it defines no parameter): the geometry is read, the shells of part 1 "
        f"have no thickness (read the master deck that defines it for that)"]
    assert np.array_equal(alone.nodes, mesh.nodes) and np.array_equal(alone.elements,
                                                                       mesh.elements)
    assert np.isnan(alone.element_fields["thickness"]).all()


def test_rendering_a_missing_thickness_draws_the_no_result_colour():
    from workbench.gl import create_context
    from workbench.measurement.rows import measure
    from workbench.paths import Style, make_path
    from workbench.paths.colormap import NO_RESULT_COLOR
    from workbench.scene.mesh import FEMesh

    mesh = FEMesh(np.array([n[1:] for n in SQUARE[:4]]), np.array([[0, 1, 2, 3]]),
                  np.array([1]), element_fields={"thickness": np.array([np.nan])})
    ctx = create_context()
    path = make_path("element_color", Style(field="thickness", value_range=(0.0, 1.0)))
    m = measure(ctx, mesh, path, size=(32, 32), timed=False)
    assert path.missing_values == 1
    drawn = m.image[(m.image[..., :3] != 255).any(axis=-1)][:, :3].astype(float)
    missing = np.array(NO_RESULT_COLOR) * 255
    # the lit no-result colour (pure green times the headlight), no colour of the scale
    light = drawn.sum(axis=1, keepdims=True) / missing.sum()
    assert len(drawn) and (np.abs(drawn - light * missing) <= 1.5).all()


@pytest.mark.parametrize("lines, expected", [
    (["*PARAMETER", "R a       2.0", "*PARAMETER_EXPRESSION", "R t       2*a+0.5"], 4.5),
    (["*PARAMETER_EXPRESSION", "R t,sqrt(&a)*max(1.0,a)", "*PARAMETER", "R a       4.0"], 8.0),
    (["*PARAMETER", "R a       3.0", "*PARAMETER_EXPRESSION", "R t       a^2/(a-1)"], 4.5),
    (["*PARAMETER", "R a       -1.5", "*PARAMETER_EXPRESSION", "R t       -a"], 1.5),
])
def test_parameter_expressions_are_evaluated(tmp_path, lines, expected):
    path = write(tmp_path, "expr.k", [*lines, *_sectioned_part("&t"), "*NODE",
                                      *[node(*n) for n in SQUARE], "*ELEMENT_SHELL",
                                      shell(1, 1, 101, 102, 103, 104)])
    assert load(path).element_fields["thickness"][0] == pytest.approx(expected)


def test_negated_parameter_and_bad_expressions(tmp_path):
    body = ["*NODE", *[node(*n) for n in SQUARE], "*ELEMENT_SHELL", shell(1, 1, 101, 102, 103, 104)]
    mesh = load(write(tmp_path, "neg.k", ["*PARAMETER", "R t       -2.0", *_sectioned_part("-&t"),
                                          *body]))
    assert mesh.element_fields["thickness"][0] == 2.0
    with pytest.raises(ParseError, match="defined through itself") as info:
        load(write(tmp_path, "cycle.k", ["*PARAMETER_EXPRESSION", "R t       u+1",
                                         "R u       t*2", *_sectioned_part("&t"), *body]))
    assert info.value.line in (2, 3)
    with pytest.raises(ParseError, match="cannot evaluate") as info:
        load(write(tmp_path, "call.k", ["*PARAMETER_EXPRESSION", "R t       __import__(1)",
                                        *_sectioned_part("&t"), *body]))
    assert info.value.line == 2


def test_missing_or_extra_card_in_a_thickness_block_is_reported_where_it_breaks(tmp_path):
    elements = []
    for eid in range(1, 41):
        elements += [shell(eid, 1, 101, 102, 103, 104),
                     "             1.0             1.0             1.0             1.0"]
    missing = elements[:9] + elements[10:]  # element 5 lost its thickness card (line 9 + 5)
    path = write(tmp_path, "missing.k", ["*NODE", *[node(*n) for n in SQUARE],
                                         "*ELEMENT_SHELL_THICKNESS", *missing])
    with pytest.raises(ParseError, match="a card is missing or extra before this line") as info:
        load(path)
    assert info.value.line == 7 + 10  # element 6's card, where the thickness card belongs
    extra = elements[:20] + [elements[1]] + elements[20:]
    path = write(tmp_path, "extra.k", ["*NODE", *[node(*n) for n in SQUARE],
                                       "*ELEMENT_SHELL_THICKNESS", *extra])
    with pytest.raises(ParseError, match="an element card") as info:
        load(path)
    assert info.value.line == 7 + 21


@pytest.mark.parametrize("fraction, status", [(0.5, 2), (0.8, 0)])
def test_damaged_d3plot_says_what_is_missing_in_one_line_each(tmp_path, d3plot_file, fraction,
                                                               status):
    """lasso-python logs tracebacks for the sections it gives up on; the workbench reports each
    as one line (a warning when the mesh is still read, within the error otherwise)."""
    import subprocess
    import sys

    data = d3plot_file.read_bytes()
    damaged = tmp_path / "d3plot"
    damaged.write_bytes(data[:int(len(data) * fraction)])
    result = subprocess.run([sys.executable, "-m", "workbench.cli", "render", str(damaged),
                             "--size", "40x30", "-o", str(tmp_path / "x.png")],
                            capture_output=True, text=True)
    assert result.returncode == status
    lines = result.stderr.strip().splitlines()
    assert "Traceback" not in result.stderr and lines
    assert all(line.startswith("workbench: warning: " if status == 0 else "workbench: error: ")
               for line in lines)
    assert any("lasso-python could not read" in line for line in lines)
    if status == 0:  # the first file alone, cut: no state, and the cut is named
        assert any("cut inside its geometry" in line for line in lines)
        assert any("no state read" in line for line in lines)
        with pytest.warns(ParseWarning, match="lasso-python could not read") as record:
            mesh = load(damaged)
        assert any("_read_user_ids" in str(w.message) for w in record)
        assert mesh.element_ids is None  # the ids were in the section that failed


def write_solid_d3plot(folder):
    """Two 1 mm hexahedra side by side (part 3) and one shell on top of them (part 5)."""
    from lasso.dyna import ArrayType, D3plot

    plot = D3plot()
    coords = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1, 2)], np.float32)
    plot.arrays[ArrayType.node_coordinates] = coords
    n = lambda i, j, k: i + 3 * (j + 2 * k)  # noqa: E731
    plot.arrays[ArrayType.element_solid_node_indexes] = np.array(
        [[n(i, 0, 0), n(i + 1, 0, 0), n(i + 1, 1, 0), n(i, 1, 0),
          n(i, 0, 1), n(i + 1, 0, 1), n(i + 1, 1, 1), n(i, 1, 1)] for i in (0, 1)], np.int32)
    plot.arrays[ArrayType.element_solid_part_indexes] = np.array([0, 0], np.int32)
    plot.arrays[ArrayType.element_solid_ids] = np.array([11, 12], np.int32)
    plot.arrays[ArrayType.element_shell_node_indexes] = np.array(
        [[n(0, 0, 1), n(1, 0, 1), n(1, 1, 1), n(0, 1, 1)]], np.int32)
    plot.arrays[ArrayType.element_shell_part_indexes] = np.array([1], np.int32)
    plot.arrays[ArrayType.element_shell_ids] = np.array([7], np.int32)
    plot.arrays[ArrayType.part_ids] = np.array([3, 5], np.int32)
    plot.arrays[ArrayType.global_timesteps] = np.array([0.0, 1.0], np.float32)
    plot.arrays[ArrayType.node_displacement] = np.stack([coords, coords * 2]).astype(np.float32)
    plot.arrays[ArrayType.element_shell_thickness] = np.full((2, 1), 0.5, np.float32)
    stress = np.zeros((2, 2, 1, 6), np.float32)
    stress[:, 0, 0, 0] = 100.0  # solid 11: uniaxial 100
    stress[:, 1, 0, 3] = 10.0  # solid 12: shear 10, von Mises 10·sqrt(3)
    plot.arrays[ArrayType.element_solid_stress] = stress
    path = folder / "d3plot"
    plot.write_d3plot(str(path))
    return path


def test_d3plot_with_solids_reads_their_boundary_and_renders(tmp_path):
    path = write_solid_d3plot(tmp_path)
    mesh = load(path)
    assert mesh.n_elements == 1 + 10  # the shell, and the 10 outer quads of the two hexes
    assert mesh.parts.tolist() == [5] + [3] * 10
    assert mesh.element_ids[0] == 7 and set(mesh.element_ids[1:].tolist()) == {11, 12}
    thickness = mesh.element_fields["thickness"]
    assert np.allclose(thickness[:, 0], 0.5) and np.isnan(thickness[:, 1:]).all()
    assert mesh.steps.shape == (2, 12, 3)
    assert load(path, all_faces=True).n_elements == 1 + 12
    vm = mesh.element_fields["von_mises"]  # the solids' own stress colours their faces
    expected = np.where(mesh.element_ids[1:] == 11, 100.0, 10.0 * np.sqrt(3.0))
    assert np.isnan(vm[:, 0]).all() and np.allclose(vm[:, 1:], expected, rtol=1e-5)
    from workbench.cli import main

    assert main(["render", str(path), "--field", "thickness", "--size", "48x36",
                 "-o", str(tmp_path / "solid.png")]) == 0


# --------------------------------------------------------------------------- field parsers
@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_fixed_and_comma_node_cards_decode_every_value(tmp_path, data):
    """Random node ids and coordinates written in fixed columns (plain, exponent, Fortran ``D``,
    integral-float ids, blanks) or comma-separated decode to the values written."""
    n = data.draw(st.integers(1, 30))
    ids = data.draw(st.lists(st.integers(1, 10**7), min_size=n, max_size=n, unique=True))
    values = data.draw(st.lists(st.floats(-1e6, 1e6, allow_nan=False).map(
        lambda v: float(f"{v:.6g}")), min_size=3 * n, max_size=3 * n))
    lines = ["*NODE"]
    for k, nid in enumerate(ids):
        x, y, z = values[3 * k:3 * k + 3]
        style = data.draw(st.sampled_from(["fixed", "exponent", "fortran", "float_id", "comma",
                                           "blank_z"]))
        if style == "comma":
            lines.append(f"{nid},{x!r},{y!r},{z!r}")
            continue
        if style == "blank_z":
            z = 0.0
        text = {"fixed": "{:16.6g}", "exponent": "{:16.8E}", "fortran": "{:16.8E}",
                "float_id": "{:16.6g}", "blank_z": "{:16.6g}"}[style]
        cells = [text.format(v) for v in (x, y, z)]
        if style == "fortran":
            cells = [c.replace("E", "D") for c in cells]
        if style == "blank_z":
            cells[2] = " " * 16
        head = f"{float(nid):8.1f}" if style == "float_id" and nid < 10**6 else f"{nid:8d}"
        lines.append(head + "".join(cells))
    lines += ["*ELEMENT_SHELL", shell(1, 1, ids[0], ids[0], ids[0], ids[0])]
    mesh = load(write(tmp_path, "nodes.k", lines))
    assert mesh.node_ids.tolist() == ids
    expected = np.array(values, float).reshape(n, 3)
    expected[[i for i, line in enumerate(lines[1:n + 1]) if line.endswith(" " * 16)], 2] = 0.0
    assert np.allclose(mesh.nodes, expected, rtol=1e-7, atol=0)


def test_tabs_as_blanks_in_comma_cards_read_the_identical_mesh(tmp_path):
    plain = ["*NODE", *[f"{n[0]},{n[1]},{n[2]},{n[3]}" for n in SQUARE],
             "*ELEMENT_SHELL", "7,3,101,102,103,104", "9,3,102,105,103,103"]
    tabbed = [line.replace(",", ",\t") + ("\t" if i % 2 else "") for i, line in enumerate(plain)]
    a, b = load(write(tmp_path, "plain.k", plain)), load(write(tmp_path, "tabs.k", tabbed))
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.elements, b.elements)
    assert a.node_ids.tolist() == b.node_ids.tolist()
