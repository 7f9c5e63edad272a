"""Every element kind of a d3plot and a keyword deck: thick shells drawn as solids (faces, part,
fields, erosion), beams and SPH particles kept beside the surface (workbench.scene.kinds) with
their parts, ids, per-state alive flags, fields and radius, and drawn; what is not drawn is
named with its count.

The d3plots are written with lasso-python. Its writer gets the SPH sections wrong (the node
and material list is concatenated on a missing axis, the flag section's first word is the
variable count instead of the section length 11, and the state data is laid out by variable
instead of by particle), so :class:`_Writer` writes those three parts itself, as lasso-python's
reader (the format's layout) reads them: per SPH node its node and material number (1-based),
11 flag words (length, radius flag, nine zeros), and per state and particle the material
number (negative once deleted) followed by the radius."""

import warnings

import numpy as np
import pytest

from workbench.cli.info import mesh_lines
from workbench.scene.kinds import Beams, Particles
from workbench.scene.mesh import FEMesh, MeshError
from workbench.scene.readers import ParseError, ParseWarning, load

T = 3  # states


def _writer():
    from lasso.dyna import ArrayType as A
    from lasso.dyna import D3plot

    class _Writer(D3plot):
        def _write_geom_sph_element_data_flags(self, fp, settings):
            if settings.header["nmsph"] <= 0:
                return 0
            flags = [11, int(A.sph_radius in self.arrays)] + [0] * 9
            return fp.write(settings.pack(np.array(flags), dtype_hint=np.integer))

        def _write_geom_sph_node_and_materials(self, fp, settings):
            if settings.header["nmsph"] <= 0:
                return 0
            data = np.column_stack([self.arrays[A.sph_node_indexes] + 1,
                                    self.arrays[A.sph_node_material_index] + 1])
            return fp.write(settings.pack(data, dtype_hint=np.integer))

        def _write_states_sph(self, fp, i, settings):
            if settings.header["nmsph"] <= 0:
                return 0
            material = (self.arrays[A.sph_node_material_index] + 1).astype(np.float64)
            deleted = self.arrays[A.sph_deletion][i] != 0
            columns = [np.where(deleted, -material, material)]
            if A.sph_radius in self.arrays:
                columns.append(self.arrays[A.sph_radius][i])
            return fp.write(settings.pack(np.column_stack(columns), dtype_hint=np.floating))

    return _Writer, A


TSHELL_STRESS = np.arange(T * 3 * 6, dtype=np.float32).reshape(T, 1, 3, 6) / 7.0


def write_kinds_d3plot(folder, shells=True, sph_radius=True):
    """A d3plot of one shell (part 1, id 1), one thick shell (part 3, id 21: a unit cube at
    x 3..4), two beams (part 2, ids 11 and 12; 12 deleted at the last state, axial force
    1..6) and two SPH particles (part 4, radius 0.1, the second deleted at the last state), in
    three states at the same coordinates; the thick shell is deleted at the last state."""
    writer, A = _writer()
    plot = writer()
    coords = np.array([
        [0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0],
        [3, 0, 0], [4, 0, 0], [4, 1, 0], [3, 1, 0], [3, 0, 1], [4, 0, 1], [4, 1, 1], [3, 1, 1],
        [0, 3, 0], [1, 3, 0]], np.float32)
    arrays = plot.arrays
    arrays[A.node_coordinates] = coords
    arrays[A.node_ids] = np.arange(1, len(coords) + 1).astype(np.int32)
    if shells:
        arrays[A.element_shell_node_indexes] = np.array([[0, 1, 2, 3]], np.int32)
        arrays[A.element_shell_part_indexes] = np.array([0], np.int32)
        arrays[A.element_shell_ids] = np.array([1], np.int32)
        arrays[A.element_shell_stress] = np.ones((T, 1, 3, 6), np.float32)
        arrays[A.element_shell_is_alive] = np.ones((T, 1), np.float32)
        arrays[A.element_tshell_node_indexes] = np.arange(6, 14, dtype=np.int32)[None]
        arrays[A.element_tshell_part_indexes] = np.array([2], np.int32)
        arrays[A.element_tshell_ids] = np.array([21], np.int32)
        arrays[A.element_tshell_stress] = TSHELL_STRESS
        arrays[A.element_tshell_effective_plastic_strain] = np.array(
            [[[0.1, 0.2, 0.3]]] * T, np.float32)
        arrays[A.element_tshell_is_alive] = np.array([[1], [1], [0]], np.float32)
    arrays[A.element_beam_node_indexes] = np.array([[4, 5, 0, 0, 0], [1, 4, 0, 0, 0]], np.int32)
    arrays[A.element_beam_part_indexes] = np.array([1, 1], np.int32)
    arrays[A.element_beam_ids] = np.array([11, 12], np.int32)
    arrays[A.element_beam_axial_force] = np.array([[1, 2], [3, 4], [5, 6]], np.float32)
    arrays[A.element_beam_is_alive] = np.array([[1, 1], [1, 1], [1, 0]], np.float32)
    arrays[A.sph_node_indexes] = np.array([14, 15], np.int32)
    arrays[A.sph_node_material_index] = np.array([3, 3], np.int32)
    arrays[A.sph_deletion] = np.array([[0, 0], [0, 0], [0, 1]], np.float32)
    if sph_radius:
        arrays[A.sph_radius] = np.full((T, 2), 0.1, np.float32)
    arrays[A.part_ids] = np.array([1, 2, 3, 4], np.int32)
    arrays[A.global_timesteps] = np.array([0, 1, 2], np.float32)
    arrays[A.node_displacement] = np.stack([coords] * T)
    path = folder / "d3plot"
    plot.write_d3plot(str(path))
    return path


def quiet(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(path)


# --------------------------------------------------------------------------- the model
def test_the_model_refuses_beams_and_particles_that_do_not_fit_its_nodes():
    nodes, quad = np.eye(3), np.array([[0, 1, 2, 2]])
    with pytest.raises(MeshError, match="1 beams reference missing nodes"):
        FEMesh(nodes, quad, beams=Beams(parts=[1], nodes=[[0, 3]]))
    with pytest.raises(MeshError, match="1 SPH particles reference missing nodes"):
        FEMesh(nodes, quad, particles=Particles(parts=[1], node=[-1], radius=[1.0]))
    with pytest.raises(MeshError, match="SPH radius must be finite and > 0"):
        FEMesh(nodes, quad, particles=Particles(parts=[1], node=[0], radius=[0.0]))
    with pytest.raises(MeshError, match=r"beam field 'alive' must be \(1,\) or \(1, 1\)"):
        FEMesh(nodes, quad, beams=Beams(parts=[1], nodes=[[0, 1]], fields={"alive": [1, 0]}))
    with pytest.raises(MeshError, match="empty mesh"):  # beams alone: no surface to draw
        FEMesh(nodes, np.zeros((0, 4), int), beams=Beams(parts=[1], nodes=[[0, 1]]))


def test_a_sub_mesh_keeps_the_beams_and_particles_whose_nodes_it_keeps():
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [5, 5, 5], [6, 6, 6]], float)
    mesh = FEMesh(nodes, np.array([[0, 1, 2, 2], [2, 3, 4, 4]]), parts=[1, 2],
                  beams=Beams(parts=[7, 7], ids=[1, 2], nodes=[[0, 2], [3, 4]],
                              fields={"f": [1.0, 2.0]}),
                  particles=Particles(parts=[8], node=[4], radius=[0.5]))
    sub = mesh.part(1)
    assert sub.beams.nodes.tolist() == [[0, 2]] and sub.beams.ids.tolist() == [1]
    assert sub.beams.fields["f"].tolist() == [1.0] and sub.particles is None
    assert np.allclose(mesh.bounds()[1], [6, 6, 6])
    moved = mesh.translated([1, 0, 0])
    assert moved.beams is mesh.beams and moved.particles is mesh.particles


# --------------------------------------------------------------------------- d3plot
def test_a_d3plot_gives_thick_shells_beams_and_particles(tmp_path):
    from workbench.scene.readers.d3plot import von_mises

    mesh = quiet(write_kinds_d3plot(tmp_path))
    # thick shell: the 6 faces of its cube after the shell, its part and id, solid fields
    assert mesh.n_elements == 1 + 6
    assert mesh.parts.tolist() == [1] + [3] * 6
    assert mesh.element_ids.tolist() == [1] + [21] * 6
    expected = von_mises(TSHELL_STRESS.astype(np.float64).mean(axis=2))[:, 0]
    np.testing.assert_allclose(mesh.element_fields["von_mises"][:, 1:],
                               np.repeat(expected[:, None], 6, axis=1), rtol=1e-12)
    np.testing.assert_allclose(mesh.element_fields["plastic_strain"][:, 1:], 0.2, rtol=1e-6)
    assert mesh.n_deleted(1) == 0 and mesh.n_deleted(2) == 6
    assert mesh.deleted_count(2) == {3: 6}
    # beams: end nodes, user part id, ids, fields, alive per state
    beams = mesh.beams
    assert beams.nodes.tolist() == [[4, 5], [1, 4]] and beams.parts.tolist() == [2, 2]
    assert beams.ids.tolist() == [11, 12]
    assert beams.fields["axial_force"].tolist() == [[1, 2], [3, 4], [5, 6]]
    assert [beams.alive(t).tolist() for t in range(T)] == [[True, True]] * 2 + [[True, False]]
    # particles: node, part, radius per state, deleted at the last state
    particles = mesh.particles
    assert particles.node.tolist() == [14, 15] and particles.parts.tolist() == [4, 4]
    np.testing.assert_allclose(particles.radius, 0.1, rtol=1e-6)
    assert particles.alive(1).all() and particles.alive(2).tolist() == [True, False]
    lines = mesh_lines(mesh)
    assert any("7 surface elements" in x and "2 beams, 2 SPH particles" in x for x in lines)
    assert "beams: 2 in parts 2; deleted per state: 0, 0, 1; fields: alive, axial_force, " \
           "torsion_moment" in lines
    assert "SPH particles: 2 in parts 4; deleted per state: 0, 0, 1; fields: alive" in lines


def test_a_d3plot_without_sph_radius_draws_half_the_spacing_and_says_so(tmp_path):
    with pytest.warns(ParseWarning, match="no usable SPH radius: 2 SPH particles are drawn "
                                          "with half the initial spacing"):
        mesh = load(write_kinds_d3plot(tmp_path, sph_radius=False))
    assert mesh.particles.radius.tolist() == [0.5, 0.5]  # particles 1 apart


def test_a_d3plot_of_beams_and_particles_only_is_refused_naming_them(tmp_path):
    with pytest.raises(ParseError, match="no shell, solid or thick shell elements in the "
                                         "d3plot: it holds 2 beams and 2 SPH particles only"):
        load(write_kinds_d3plot(tmp_path, shells=False))


def test_a_d3plot_draws_its_thick_shells_beams_and_particles_and_erodes_them(tmp_path, ctx):
    from workbench.gl.camera import Camera
    from workbench.paths import make_path, render
    from workbench.paths.kinds import PART_COLORS

    mesh = quiet(write_kinds_d3plot(tmp_path))
    camera = Camera.fit((2.0, 1.5, 0.5), 2.5, margin=1.0)  # x -0.5..4.5, y -1..4: 20 px/unit
    size = (100, 100)

    def image(step):
        return render(ctx, mesh, "flat", make_path("flat").style, camera, size, step=step)

    def col(x):
        return int(20 * (x + 0.5))

    def row(y):
        return int(100 - 20 * (y + 1.0))

    beam = np.round(PART_COLORS[2] * 255).astype(int)
    for step in range(T):
        picture = image(step)
        rgb = picture[..., :3].astype(int)
        cube = (rgb[row(0.9):row(0.1), col(3.1):col(3.9)] != 255).any(axis=-1)
        beams = (np.abs(rgb - beam).sum(axis=-1) == 0)
        red = (rgb[..., 2] > rgb[..., 1] + 15) & (rgb[..., 0] > rgb[..., 1] + 5)  # purple
        # the thick shell's top face covers its square until deleted at the last state
        assert cube.all() if step < 2 else not cube.any()
        # beam 12 (x 1..2 at y 0) is gone at the last state; beam 11 (x 2, y 0..1) stays
        assert beams[:, col(1.1):col(1.9)].sum() == (0 if step == 2 else 16)
        assert beams[row(0.9):row(0.1), col(1.95):col(2.05) + 1].sum() >= 15
        # the particles (part 4, purple; radius 0.1: 2 px) at (0, 3), and at (1, 3) until
        # deleted
        near = red[row(3.3):row(2.7), col(0.7):col(1.3)].sum()
        assert red[row(3.3):row(2.7), col(-0.3):col(0.3)].sum() >= 9
        assert near == 0 if step == 2 else near >= 9


# --------------------------------------------------------------------------- keyword decks
def node(nid, x, y, z=0.0):
    return f"{nid:8d}{x:16.6f}{y:16.6f}{z:16.6f}"


def card(*values):
    return "".join(f"{v:8d}" for v in values)


def sph(nid, pid, mass=1.0, nend=0):
    return f"{nid:8d}{pid:8d}{mass:16.6f}{nend:8d}"


DECK = ["*KEYWORD", "*PART", "shell", f"{1:10d}{1:10d}", "*PART", "beams", f"{2:10d}{1:10d}",
        "*PART", "sph", f"{3:10d}{1:10d}",
        "*NODE", node(1, 0, 0), node(2, 4, 0), node(3, 4, 4), node(4, 0, 4),
        node(5, 6, 1), node(6, 9, 1), node(7, 6, 3),
        node(11, 1, 7), node(12, 3, 7), node(13, 5, 7), node(14, 8, 7),
        "*ELEMENT_SHELL", card(1, 1, 1, 2, 3, 4),
        "*ELEMENT_BEAM", card(101, 2, 5, 6, 1), card(102, 2, 6, 7),
        "*ELEMENT_BEAM_THICKNESS", card(103, 2, 5, 7), "     1.0     1.0     0.0     0.0",
        "*ELEMENT_SPH", sph(11, 3, 1.0, 13), sph(14, 3),
        "*ELEMENT_DISCRETE", card(201, 2, 5, 6),
        "*END"]


def write(folder, lines, name="deck.k"):
    path = folder / name
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_deck_gives_its_beams_and_particles_and_names_what_it_does_not_draw(tmp_path):
    with pytest.warns(ParseWarning, match=r"1 element\(s\) not drawn: \*ELEMENT_DISCRETE") as got:
        mesh = load(write(tmp_path, DECK))
    assert not any("ELEMENT_BEAM" in str(w.message) or "ELEMENT_SPH" in str(w.message)
                   for w in got)
    beams, particles = mesh.beams, mesh.particles
    assert beams.ids.tolist() == [101, 102, 103] and beams.parts.tolist() == [2, 2, 2]
    assert mesh.node_ids[beams.nodes].tolist() == [[5, 6], [6, 7], [5, 7]]
    # NEND: 11..13 is a series of three; particle ids are their node ids
    assert particles.ids.tolist() == [11, 12, 13, 14]
    assert mesh.node_ids[particles.node].tolist() == [11, 12, 13, 14]
    # radius: half the distance to the nearest particle of the part (2, 2, 2, 3 apart)
    assert particles.radius.tolist() == [1.0, 1.0, 1.0, 1.5]
    lines = mesh_lines(mesh)
    assert any("1 surface elements" in x and "3 beams, 4 SPH particles" in x for x in lines)
    assert "beams: 3 in parts 2" in lines and "SPH particles: 4 in parts 3" in lines
    assert mesh.part_names == {1: "shell", 2: "beams", 3: "sph"}


def test_a_deck_draws_its_beams_and_particles(tmp_path, ctx):
    from workbench.gl.camera import Camera
    from workbench.paths import make_path, render
    from workbench.paths.kinds import PART_COLORS

    mesh = quiet(write(tmp_path, DECK))
    camera = Camera.fit((5.0, 5.0, 0.0), 5.0, margin=1.0)  # 10 px per unit
    picture = render(ctx, mesh, "flat", make_path("flat").style, camera, (100, 100))
    rgb = picture[..., :3].astype(int)
    beams = np.abs(rgb - np.round(PART_COLORS[2] * 255).astype(int)).sum(axis=-1) == 0
    assert beams[85:95, 62:80].sum() == 18  # 101: x 6..9 at y 1, away from 102 and 103
    assert beams.sum() >= 30 + 30 + 20  # and 102 (3 x 2 units), 103 (2 units)
    red = (rgb[..., 0] > rgb[..., 1] + 20) & (rgb[..., 0] > rgb[..., 2] + 20)
    # four discs of radius 10, 10, 10, 15 px centred on y = 7 (row 30); those of radius 10
    # and 15 touch their neighbours, so count them together against the exact footprints
    i, j = np.mgrid[0:100, 0:100]
    exact = np.zeros((100, 100), bool)
    for x, r in ((1, 10), (3, 10), (5, 10), (8, 15)):
        exact |= np.hypot(j + 0.5 - 10 * x, i + 0.5 - 30) <= r
    ring = int(sum((np.abs(np.hypot(j + 0.5 - 10 * x, i + 0.5 - 30) - r) <= 0.5).sum()
                   for x, r in ((1, 10), (3, 10), (5, 10), (8, 15))))
    assert abs(int(red.sum()) - int(exact.sum())) <= ring // 2


def test_deck_beams_and_particles_are_refused_where_they_do_not_fit(tmp_path):
    undefined = [line.replace(card(102, 2, 6, 7), card(102, 2, 6, 99)) for line in DECK]
    with pytest.raises(ParseError, match=r"1 record\(s\) reference undefined node ids; first "
                                         r"\(id, node id\): \(102, 99\)"):
        quiet(write(tmp_path, undefined))
    no_part = [line.replace(sph(14, 3), sph(14, 9)) for line in DECK]
    with pytest.raises(ParseError, match="part id 9 is not defined by any"):
        quiet(write(tmp_path, no_part, "part.k"))
    alone = [line for line in DECK if line not in ("*ELEMENT_SHELL", card(1, 1, 1, 2, 3, 4))]
    with pytest.raises(ParseError, match="no shell, solid or thick shell elements in the deck: "
                                         "it holds 3 beams and 4 SPH particles only"):
        quiet(write(tmp_path, alone, "alone.k"))
