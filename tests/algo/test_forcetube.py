"""Force tubes (crash2000 §4.2): section planes, section forces against closed forms, the tie
rule for nodes and edges on the plane, the tube mesh, and the d3plot's stress fields."""

import numpy as np
import pytest

from workbench.algo.forcetube import (
    STRESS_FIELDS,
    TUBE_FIELD,
    crossing_elements,
    force_tube,
    prismatic_tube,
    section_force,
    section_planes,
    stress_tensor,
    tube_mesh,
    with_tube,
)
from workbench.scene.mesh import FEMesh

REL = 1e-9


def inputs(mesh, step=0):
    return (mesh.coordinates(step), mesh.elements, mesh.element_field("thickness", step),
            stress_tensor(mesh, step))


def uniform(mesh, tensor):
    """(M, 3, 3) copies of one stress tensor."""
    return np.broadcast_to(np.asarray(tensor, float), (mesh.n_elements, 3, 3)).copy()


# --------------------------------------------------------------------------- synthetic tube
@pytest.mark.parametrize("sides", [3, 8, 13])
def test_prismatic_tube_force_is_exact_for_every_plane_and_step(sides):
    sigma = [120.0, -80.0, 0.5]
    mesh, exact = prismatic_tube(sides, length=90.0, radius=7.0, thickness=1.3, stress=sigma,
                                 segments=9, steps=3, stretch=0.05, shift=(2.0, -1.0, 0.5))
    perimeter = sides * 2 * 7.0 * np.sin(np.pi / sides)
    assert np.allclose(exact, np.array(sigma) * 1.3 * perimeter, rtol=1e-15)
    rng = np.random.default_rng(sides)
    for step in range(3):
        coords = mesh.coordinates(step)
        ring = 4 * sides  # first node of ring 4
        planes = [(coords[ring], [1.0, 0, 0]),                   # through a ring of nodes/edges
                  (coords[ring], [-1.0, 0, 0]),                  # the same, normal reversed
                  (coords[ring] + [2.7, 0, 0], [1.0, 0, 0]),     # between rings
                  (coords[ring], [1.0, 0.15, -0.2]),             # oblique through one node
                  (coords[ring + 1], [2.0, -0.3, 0.1])]          # oblique through another
        for _ in range(5):                                       # oblique, anywhere inside
            planes.append((coords[ring] + [rng.uniform(-20, 20), 0, 0],
                           [1.0, *rng.uniform(-0.3, 0.3, 2)]))
        for point, normal in planes:
            n = np.asarray(normal) / np.linalg.norm(normal)
            f = section_force(*inputs(mesh, step), point, normal)
            expected = exact[step] * np.sign(n[0]) * np.array([1.0, 0, 0])
            assert np.abs(f - expected).max() <= REL * abs(exact[step]), (step, point, normal)
            assert abs(f @ n - exact[step] * abs(n[0])) <= REL * abs(exact[step])


def test_tension_pulls_along_the_normal_and_compression_against_it():
    mesh, exact = prismatic_tube(6, stress=[50.0, -50.0], steps=2)
    for step, sign in ((0, 1.0), (1, -1.0)):
        f = section_force(*inputs(mesh, step), [33.0, 0, 0], [1.0, 0, 0])
        assert f[0] == pytest.approx(sign * abs(exact[0]), rel=REL)   # + side pulls − side
        assert abs(f[1]) + abs(f[2]) <= REL * abs(exact[0])


def test_force_tube_on_the_prismatic_tube_matches_the_closed_form():
    sigma = [10.0, 200.0, -30.0, 0.0]
    mesh, exact = prismatic_tube(8, length=100.0, radius=10.0, thickness=2.0, stress=sigma,
                                 segments=10, steps=4, stretch=0.1, shift=(5.0, 3.0, -2.0))
    tube = force_tube(mesh, [[0, 0, 0], [100.0, 0, 0]], per_segment=12, blend=0)
    assert tube.force.shape == (4, 12, 3) and tube.steps.tolist() == [0, 1, 2, 3]
    for step in range(4):  # the control points follow the stretch and the shift
        lam = 1 + 0.1 * step
        shift = step * np.array([5.0, 3.0, -2.0])
        assert np.allclose(tube.control_points[step], [shift, [100.0 * lam, 0, 0] + shift])
        assert np.allclose(tube.normals[step], [1.0, 0, 0])
        scale = max(abs(exact[step]), 1.0)
        assert np.abs(tube.axial[step] - exact[step]).max() <= REL * scale
        assert np.abs(tube.force[step, :, 1:]).max() <= REL * scale
        assert np.allclose(tube.magnitude[step], abs(exact[step]), rtol=REL, atol=REL)
        assert (tube.crossed[step] == 8).all()


def test_blended_planes_on_a_bent_trace_line_keep_the_closed_form():
    mesh, exact = prismatic_tube(8, length=100.0, radius=10.0, thickness=1.0, stress=75.0,
                                 segments=10)
    tube = force_tube(mesh, [[0, 0, 0], [50.0, 2.0, -1.0], [100.0, 0, 0]], per_segment=8,
                      blend=3)
    n = tube.normals[0]
    assert np.unique(np.round(n, 12), axis=0).shape[0] > 2  # oblique, several directions
    assert np.allclose(tube.axial[0], exact[0] * np.abs(n[:, 0]), rtol=REL, atol=0)
    assert np.allclose(tube.force[0], exact[0] * np.array([1.0, 0, 0]), rtol=0,
                       atol=REL * exact[0])


def test_a_tube_of_triangles_gives_the_same_force():
    mesh, exact = prismatic_tube(7, stress=40.0)
    q = mesh.elements
    tris = np.concatenate([q[:, [0, 1, 2, 2]], q[:, [0, 2, 3, 3]]])
    tri_mesh = FEMesh(mesh.nodes, tris, element_fields={
        name: np.concatenate([v, v]) for name, v in mesh.element_fields.items()})
    assert tri_mesh.is_triangle.all()
    for point, normal in (([41.0, 0, 0], [1.0, 0, 0]), ([50.0, 0, 0], [1.0, 0.2, 0.1])):
        n = np.asarray(normal) / np.linalg.norm(normal)
        f = section_force(*inputs(tri_mesh), point, normal)
        assert f @ n == pytest.approx(exact[0] * n[0], rel=REL)


def test_rotated_tube_with_its_stress_rotated_gives_the_rotated_force():
    mesh, exact = prismatic_tube(9, stress=60.0, thickness=0.8)
    rng = np.random.default_rng(3)
    rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    rot *= np.sign(np.linalg.det(rot))
    coords = mesh.nodes @ rot.T + [1200.0, -300.0, 450.0]  # car-like offsets
    sigma = rot @ np.diag([60.0, 0, 0]) @ rot.T
    axis = rot[:, 0]
    point = np.array([37.0, 1.0, -2.0]) @ rot.T + [1200.0, -300.0, 450.0]
    f = section_force(coords, mesh.elements, np.full(mesh.n_elements, 0.8),
                      uniform(mesh, sigma), point, axis)
    assert np.abs(f - exact[0] * axis).max() <= REL * exact[0]


# --------------------------------------------------------------------------- the tie rule
def test_edges_in_the_plane_are_counted_once():
    """Plane z = 0 holds two long edges of an 8-gon tube (corners at 0° and 180°): with a
    uniform σ_zz each cut line carries σ t L cos(π/8); counted twice the force would double."""
    sides, length, t = 8, 60.0, 1.5
    mesh, _ = prismatic_tube(sides, length=length, radius=5.0, thickness=t, segments=6)
    assert (mesh.nodes[:, 2] == 0).sum() == 2 * 7  # the two long edges lie exactly in z = 0
    stress = uniform(mesh, np.diag([0, 0, 20.0]))
    expected = 2 * length * np.cos(np.pi / sides) * t * 20.0
    for normal in ([0, 0, 1.0], [0, 0, -1.0]):
        f = section_force(mesh.nodes, mesh.elements, np.full(mesh.n_elements, t), stress,
                          [3.0, 0, 0], normal)
        assert f @ np.array(normal) == pytest.approx(expected, rel=REL)
        assert np.abs(f[:2]).max() <= REL * expected
    # σ_xx transmits nothing through a plane that contains the axis
    f = section_force(mesh.nodes, mesh.elements, np.full(mesh.n_elements, t),
                      uniform(mesh, np.diag([100.0, 0, 0])), [3.0, 0, 0], [0, 0, 1.0])
    assert np.abs(f).max() <= 1e-9


def test_tie_rule_on_single_elements():
    """Two unit squares sharing the edge x = 0 in the plane x = 0: only the one on the
    negative side counts the edge; one touching the plane at a node counts nothing."""
    nodes = np.array([[-1, 0, 0], [0, 0, 0], [0, 1, 0], [-1, 1, 0], [1, 0, 0], [1, 1, 0],
                      [0, 2, 0], [-1, 3, 0], [1, 3, 0]], float)
    left, right = [0, 1, 2, 3], [1, 4, 5, 2]
    touch_neg, touch_pos = [6, 7, 7, 7], [6, 8, 8, 8]  # triangles meeting x = 0 at node 6 only
    sigma = np.diag([10.0, 0, 0])

    def force(*elements):
        el = np.array(elements)
        return section_force(nodes, el, np.ones(len(el)), uniform(FEMesh(nodes, el), sigma),
                             [0, 0, 0], [1.0, 0, 0])

    assert np.allclose(force(left), [10.0, 0, 0], rtol=REL)   # edge from the negative side
    assert np.allclose(force(right), 0.0)                     # edge from the positive side
    assert np.allclose(force(left, right), [10.0, 0, 0], rtol=REL)
    assert np.allclose(force(touch_neg), 0.0) and np.allclose(force(touch_pos), 0.0)
    assert np.allclose(force(left, right, touch_neg, touch_pos), [10.0, 0, 0], rtol=REL)
    el = np.array([left, right, touch_neg, touch_pos])
    assert crossing_elements(nodes, el, [0, 0, 0], [1.0, 0, 0]).tolist() == [0, 2]


def test_cut_callable_superset_and_subset():
    mesh, exact = prismatic_tube(8, stress=10.0)
    args = inputs(mesh)
    everything = section_force(*args, [45.0, 0, 0], [1.0, 0.1, 0],
                               cut=lambda p, n: np.arange(mesh.n_elements).repeat(2))
    assert everything[0] == pytest.approx(exact[0], rel=REL)
    nothing = section_force(*args, [45.0, 0, 0], [1.0, 0, 0], cut=lambda p, n: [])
    assert (nothing == 0).all()
    calls = []
    tube = force_tube(mesh, [[0, 0, 0], [100.0, 0, 0]], per_segment=4, blend=0,
                      cut=lambda step: (lambda p, n: calls.append(step) or
                                        crossing_elements(mesh.coordinates(step),
                                                          mesh.elements, p, n)))
    assert calls == [0] * 4 and np.allclose(tube.axial, exact[0], rtol=REL)


def test_trace_line_that_cuts_nothing_gives_zero_force():
    mesh, _ = prismatic_tube(8, stress=100.0)
    tube = force_tube(mesh, [[200.0, 0, 0], [300.0, 0, 0]], per_segment=5, blend=0)
    assert (tube.force == 0).all() and (tube.axial == 0).all() and (tube.crossed == 0).all()
    assert (section_force(*inputs(mesh), [500.0, 0, 0], [1.0, 0, 0]) == 0).all()


def test_selection_parts_and_deleted_elements():
    mesh, exact = prismatic_tube(8, stress=10.0)
    half = mesh.nodes[mesh.elements].mean(axis=1)[:, 1] > 0  # the faces on the +y side
    alive = np.where(half, 1.0, 0.0)
    mesh.element_fields["alive"] = alive
    tube = force_tube(mesh, [[0, 0, 0], [100.0, 0, 0]], per_segment=3, blend=0)
    assert (tube.crossed == half.reshape(10, 8)[0].sum()).all()
    assert (np.abs(tube.axial) < exact[0]).all()
    with pytest.raises(ValueError, match="no element .* is selected"):
        force_tube(mesh, [[0, 0, 0], [100.0, 0, 0]], parts=[7])


def test_selection_radius_and_parts_restrict_the_unbounded_planes():
    """Two parallel tubes 50 apart: the planes cut both unless the selection tube or the part
    selection keeps to the one the trace line follows."""
    mesh, exact = prismatic_tube(8, stress=10.0)
    other = mesh.translated([0, 50.0, 0])
    both = FEMesh(np.concatenate([mesh.nodes, other.nodes]),
                  np.concatenate([mesh.elements, other.elements + mesh.n_nodes]),
                  parts=np.repeat([1, 2], mesh.n_elements),
                  element_fields={k: np.concatenate([v, v])
                                  for k, v in mesh.element_fields.items()})
    line = [[0, 0, 0], [100.0, 0, 0]]
    assert np.allclose(force_tube(both, line, per_segment=4, blend=0).axial, 2 * exact[0])
    for kwargs in ({"selection_radius": 15.0}, {"parts": [1]}):
        tube = force_tube(both, line, per_segment=4, blend=0, **kwargs)
        assert np.allclose(tube.axial, exact[0], rtol=REL), kwargs


# --------------------------------------------------------------------------- section planes
def test_planes_are_orthogonal_to_their_segments_and_evenly_spaced():
    pts = np.array([[0, 0, 0], [10.0, 0, 0], [10.0, 30.0, 0], [10.0, 30.0, -4.0]])
    points, normals = section_planes(pts, per_segment=5, blend=0)
    assert points.shape == normals.shape == (15, 3)
    for k in range(3):
        seg = pts[k + 1] - pts[k]
        p = points[5 * k:5 * k + 5]
        assert np.allclose(normals[5 * k:5 * k + 5], seg / np.linalg.norm(seg))
        assert np.allclose(np.diff(p, axis=0), seg / 5)                 # even spacing
        assert np.allclose(p[0], pts[k] + seg / 10)                     # half a step in
        assert np.allclose(np.cross(p - pts[k], seg), 0)                # on the segment


def test_blended_normals_are_unit_and_turn_monotonically():
    pts = np.array([[0, 0, 0], [10.0, 0, 0], [10.0, 10.0, 0]])
    b = 2
    _, normals = section_planes(pts, per_segment=6, blend=b)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-15)
    d0, d1 = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    angle = np.arctan2(normals @ d1, normals @ d0)          # 0 along d0, 90° along d1
    assert np.allclose(normals[:, 2], 0)                     # in the plane of d0 and d1
    assert (np.diff(angle) >= -1e-15).all()                  # monotone
    blended = angle[6 - b:6 + b]
    assert ((blended > 0) & (blended < np.pi / 2)).all()
    assert np.allclose(np.diff(angle[6 - b - 1:6 + b + 1]), np.pi / 2 / (2 * b + 1))
    assert np.allclose(angle[:6 - b], 0) and np.allclose(angle[6 + b:], np.pi / 2)


# --------------------------------------------------------------------------- tube mesh
def test_tube_mesh_rings_radii_and_field():
    mesh, _ = prismatic_tube(8, stress=[10.0, 40.0], steps=2)
    mesh.element_fields["alive"] = np.ones((2, mesh.n_elements))
    mesh.element_fields["alive"][:, :8] = 0  # the first ring of faces is gone: less force there
    tube = force_tube(mesh, [[0, 0, 0], [100.0, 0, 0]], per_segment=10, blend=0)
    sides = 12
    tm = tube_mesh(tube, 1, radius_range=(2.0, 6.0), sides=sides)
    assert tm.n_nodes == sides * 10 and tm.n_elements == sides * 9 and tm.n_quads == tm.n_elements
    assert len(np.unique(tm.parts)) == 1
    rings = tm.nodes.reshape(10, sides, 3)
    offset = rings - tube.points[1][:, None, :]
    radius = np.linalg.norm(offset, axis=2)
    assert np.allclose(radius, radius[:, :1])                         # circles
    assert (radius >= 2.0 - 1e-12).all() and (radius <= 6.0 + 1e-12).all()
    assert radius[:, 0].argmax() > 0 and np.isclose(radius.max(), 6.0)  # step 1 holds the max
    assert np.allclose(offset @ np.array([1.0, 0, 0]), 0, atol=1e-12)   # in the plane
    assert np.allclose(tm.node_fields[TUBE_FIELD], np.repeat(tube.axial[1], sides))
    radial = tm.nodes[tm.elements].mean(axis=1) * [0, 1, 1]  # the trace line is the x axis
    assert (np.einsum("ij,ij->i", tm.face_normals(), radial) > 0).all()  # normals outward
    small = tube_mesh(tube, 0, radius_range=(2.0, 6.0), sides=sides)   # step 0: weaker force
    r0 = np.linalg.norm(small.nodes.reshape(10, sides, 3) - tube.points[0][:, None], axis=2)
    assert (r0[1:, 0] < radius[1:, 0]).all() and r0[0, 0] == radius[0, 0] == 2.0
    animated = tube_mesh(tube, None, radius_range=(2.0, 6.0), sides=sides)
    assert animated.steps.shape == (2, 120, 3)
    assert animated.node_fields[TUBE_FIELD].shape == (2, 120)
    assert np.array_equal(animated.steps[1], tm.nodes)
    with pytest.raises(ValueError, match="not computed"):
        tube_mesh(tube, 5, radius_range=(1, 2))


def test_with_tube_keeps_the_model():
    mesh, _ = prismatic_tube(6, stress=[10.0, 20.0, 30.0], steps=3, stretch=0.1)
    mesh.node_ids = np.arange(mesh.n_nodes) + 100
    mesh.element_ids = np.arange(mesh.n_elements) + 500
    mesh.parts[:6] = 4
    tube = force_tube(mesh, [[0, 0, 0], [100.0, 0, 0]], per_segment=5, blend=0)
    tm = tube_mesh(tube, 2, radius_range=(1.0, 3.0), sides=8)
    both = with_tube(mesh, tm)
    m, n = mesh.n_elements, mesh.n_nodes
    assert np.array_equal(both.elements[:m], mesh.elements)
    assert np.array_equal(both.parts[:m], mesh.parts)
    assert np.array_equal(both.node_ids[:n], mesh.node_ids)
    assert np.array_equal(both.element_ids[:m], mesh.element_ids)
    assert len(np.unique(both.element_ids)) == both.n_elements
    assert (both.parts[m:] == 5).all() and both.part_names[5] == "force tube"
    assert both.n_steps == 3 and np.array_equal(both.steps[:, :n], mesh.steps)
    assert np.array_equal(both.steps[0, n:], tm.nodes)
    field = both.node_fields[TUBE_FIELD]
    assert np.isnan(field[:n]).all() and np.array_equal(field[n:], tm.node_fields[TUBE_FIELD])
    assert np.isnan(both.element_fields["stress_xx"][:, m:]).all()
    assert np.array_equal(both.element_fields["stress_xx"][:, :m], mesh.element_fields["stress_xx"])


# --------------------------------------------------------------------------- d3plot
def write_stress_d3plot(folder):
    from lasso.dyna import ArrayType, D3plot

    plot = D3plot()
    coords = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    plot.arrays[ArrayType.node_coordinates] = coords
    plot.arrays[ArrayType.element_shell_node_indexes] = np.array([[0, 1, 2, 3]], np.int32)
    plot.arrays[ArrayType.element_shell_part_indexes] = np.array([0], np.int32)
    plot.arrays[ArrayType.global_timesteps] = np.array([0.0, 1e-3], np.float32)
    plot.arrays[ArrayType.node_displacement] = np.stack([coords, coords]).astype(np.float32)
    stress = np.zeros((2, 1, 3, 6), np.float32)
    stress[:, 0, :, :] = np.arange(1, 7, dtype=np.float32)        # xx=1 … xz=6 in every layer
    stress[1, 0, :, 0] = [30.0, 10.0, 80.0]                      # step 1: mid, inner, outer
    plot.arrays[ArrayType.element_shell_stress] = stress
    plot.arrays[ArrayType.element_shell_thickness] = np.full((2, 1), 1.25, np.float32)
    path = folder / "d3plot"
    plot.write_d3plot(str(path))
    return path


def test_d3plot_stress_components_are_the_layer_mean_in_d3plot_order(tmp_path):
    from workbench.scene.readers.d3plot import read_d3plot

    mesh = read_d3plot(write_stress_d3plot(tmp_path))
    values = {name: mesh.element_fields[name][:, 0] for name in STRESS_FIELDS}
    assert [values[name][0] for name in STRESS_FIELDS] == [1, 2, 3, 4, 5, 6]
    assert values["stress_xx"][1] == pytest.approx(40.0)  # not the mid layer (30)
    assert np.allclose(mesh.element_fields["von_mises"].shape, (2, 1))
    s = stress_tensor(mesh, 0)[0]
    assert np.array_equal(s, [[1, 4, 6], [4, 2, 5], [6, 5, 3]])
    assert "stress_xx" not in read_d3plot(tmp_path / "d3plot",
                                          stress_components=False).element_fields


def test_shared_d3plot_stresses_and_a_section(d3plot_file):
    from workbench.scene.readers import load

    mesh = load(d3plot_file)
    for name in (*STRESS_FIELDS, "thickness"):
        values = mesh.element_fields[name]
        assert values.shape == (1, 4696) and np.isfinite(values).all(), name
    s = stress_tensor(mesh, 0)
    assert s.shape == (4696, 3, 3) and np.array_equal(s, s.transpose(0, 2, 1))
    # the tensile specimen lies in y = 0, its gauge length along z
    tube = force_tube(mesh, [[0, 0, -30.0], [0, 0, 30.0]], per_segment=6, blend=0)
    assert np.isfinite(tube.force).all() and (tube.crossed > 0).all()
    f = section_force(*inputs(mesh), [0, 0, 0.1], [0, 0, 1.0])
    assert f.shape == (3,) and np.isfinite(f).all()


# --------------------------------------------------------------------------- refusals
@pytest.mark.parametrize("points, message", [
    ([[0, 0, 0]], "at least 2 control points"),
    ([[0, 0, 0], [np.nan, 0, 0]], "finite"),
    ([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]],
     "zero-length segment between control points 1 and 2"),
    ([[0, 0, 0], [1, 0, 0], [0, 0, 0]], "turns straight back"),
    ([[0, 0, 0], [1, 0, 0]], "blend 5 needs per_segment ≥ 10"),
])
def test_bad_trace_lines_are_refused(points, message):
    mesh, _ = prismatic_tube(5)
    blend = 5 if "blend" in message else 2
    with pytest.raises(ValueError, match=message):
        section_planes(points, per_segment=8, blend=blend)
    with pytest.raises(ValueError, match=message):
        force_tube(mesh, points, per_segment=8, blend=blend)


def test_bad_mesh_input_is_refused():
    mesh, _ = prismatic_tube(5)
    plain = FEMesh(mesh.nodes, mesh.elements,
                   element_fields={"thickness": np.ones(mesh.n_elements)})
    with pytest.raises(ValueError, match=r"no element fields \['stress_xx'.*stress_zx'\]"):
        force_tube(plain, [[0, 0, 0], [10.0, 0, 0]])
    with pytest.raises(ValueError, match="no stress fields"):
        stress_tensor(plain, 0)
    coords = mesh.nodes.copy()
    coords[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"coords must be finite; not finite at nodes \[3\]"):
        section_force(coords, *inputs(mesh)[1:], [5.0, 0, 0], [1.0, 0, 0])
    steps = np.stack([mesh.nodes, coords])
    moving = FEMesh(mesh.nodes, mesh.elements, steps=steps, element_fields=mesh.element_fields)
    with pytest.raises(ValueError, match="non-finite coordinates at step 1"):
        force_tube(moving, [[0, 0, 0], [10.0, 0, 0]])
    with pytest.raises(ValueError, match="normal must not be zero"):
        section_force(*inputs(mesh), [5.0, 0, 0], [0, 0, 0])


def test_planes_found_through_the_hierarchy_give_the_brute_force_forces():
    from workbench.algo.forcetube import BRUTE_FORCE

    mesh, exact = prismatic_tube(sides=10, length=300.0, radius=30.0, thickness=2.0,
                                 stress=[50.0, -120.0], segments=15, steps=2, stretch=0.02)
    line = [[10.0, 0.0, 0.0], [150.0, 5.0, 0.0], [290.0, 0.0, 3.0]]
    through = force_tube(mesh, line, per_segment=6)
    brute = force_tube(mesh, line, per_segment=6, cut=BRUTE_FORCE)
    assert np.array_equal(through.force, brute.force)
    assert np.array_equal(through.crossed, brute.crossed) and through.crossed.min() > 0
