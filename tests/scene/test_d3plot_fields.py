"""The fields a crash engineer reads from a d3plot, each checked against an independent
computation from the raw arrays lasso-python reads back (float32 values, compared in float64):
stress scalars of every shell layer choice, nodal displacement, velocity and acceleration,
the per-part node average, the envelope and the differences to a state or another run.

Independent references: von Mises, pressure, signed von Mises and triaxiality from exact
rational arithmetic (``fractions.Fraction`` of the float32 components, one rounding at the
end); principal stresses from ``numpy.linalg.eig`` (the general, nonsymmetric solver) on each
3 x 3 matrix in a loop; maximum shear from ``eig`` of the deviator formed exactly; von Mises
also from those principal stresses. Tolerances (derived where used):

* ``EXACT_REL``: a value the kernel forms from exactly representable differences, squares and
  sums without cancellation (von Mises, pressure, triaxiality) has a relative error of a few
  units of 2**-53 (about 1e-16 each, under ten roundings); the reference one rounding.
  1e-12 relative leaves a margin of 1000.
* ``EIGEN_REL``: eigenvalues of a symmetric matrix computed by a backward-stable solver are
  off by at most c * eps * ||A|| (Weyl), c small for 3 x 3 (both solvers, plus the deviator's
  and the mean's roundings: under 100 eps, 2e-14); so principal stresses are compared to 1e-12
  times the Frobenius norm of the tensor, the maximum shear to 1e-12 times that of its
  deviator (it is computed from the deviator), absolute. A swapped component moves them by a
  fraction of the norm, ten orders of magnitude more.
"""

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import ADVERSARIAL_STRESSES, write_rich_d3plot

from workbench.scene import fringes
from workbench.scene.mesh import FEMesh
from workbench.scene.readers import read_d3plot
from workbench.scene.readers.d3plot_fields import FIELDS, LAYERS, offered_by_file
from workbench.scene.stress_tensor import (
    SCALARS,
    max_shear,
    pressure,
    principal_stresses,
    signed_von_mises,
    stress_scalar,
    triaxiality,
    von_mises,
)

EXACT_REL = 1e-12
EIGEN_REL = 1e-12
RIGID_PART = 12
LAYER_INDEX = {"mid": 0, "bottom": 1, "top": 2}  # 3 layers written: mid, inner, outer


# ---------------------------------------------------------------- independent references
def reference_scalars(t) -> dict[str, float]:
    """Every scalar of :data:`SCALARS` of one tensor (6 values), computed without the kernel."""
    t = [float(v) for v in t]
    if not all(math.isfinite(v) for v in t):
        return dict.fromkeys(SCALARS, math.nan)
    xx, yy, zz, xy, yz, zx = (Fraction(v) for v in t)
    j2 = ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2) / 6 + xy ** 2 + yz ** 2 + zx ** 2
    trace = xx + yy + zz
    mises = math.sqrt(float(3 * j2))
    matrix = np.array([[t[0], t[3], t[5]], [t[3], t[1], t[4]], [t[5], t[4], t[2]]])
    s1, s2, s3 = sorted(np.linalg.eig(matrix)[0].real, reverse=True)
    mean = trace / 3
    deviator = np.array([[float(xx - mean), t[3], t[5]], [t[3], float(yy - mean), t[4]],
                         [t[5], t[4], float(zz - mean)]])
    d = np.linalg.eig(deviator)[0].real
    return {"von_mises": mises, "signed_von_mises": -mises if trace < 0 else mises,
            "principal_max": s1, "principal_mid": s2, "principal_min": s3,
            "max_shear": (d.max() - d.min()) / 2, "pressure": float(-mean),
            "triaxiality": math.nan if j2 == 0 else float(mean) / mises,
            # not a field: von Mises from the principal stresses, a second reference
            "mises_from_principal": math.sqrt(((s1 - s2) ** 2 + (s2 - s3) ** 2
                                               + (s3 - s1) ** 2) / 2),
            "norm": float(np.linalg.norm(matrix)), "deviator_norm": float(np.linalg.norm(deviator))}


def tolerance(name: str, ref: dict) -> float:
    """The absolute tolerance of ``name`` for the tensor of ``ref`` (module notes)."""
    if name.startswith("principal_"):
        return EIGEN_REL * ref["norm"]
    if name == "max_shear":
        return EIGEN_REL * ref["deviator_norm"]
    return EXACT_REL * abs(ref[name])


def assert_close(name: str, got: float, ref: dict) -> None:
    want = ref[name]
    if math.isnan(want):
        assert math.isnan(got), (name, got, ref)
    else:
        assert abs(got - want) <= tolerance(name, ref), (name, got, want, ref)


def raw_arrays(path):
    """lasso-python's arrays of ``path``, read anew (float32 as written)."""
    from lasso.dyna import D3plot

    return {k: np.asarray(v) for k, v in D3plot(str(path)).arrays.items()}


@pytest.fixture(scope="module")
def rich(tmp_path_factory):
    return write_rich_d3plot(tmp_path_factory.mktemp("rich") / "run")


@pytest.fixture(scope="module")
def raw(rich):
    return raw_arrays(rich)


@pytest.fixture(scope="module")
def meshes(rich):
    """{layer: the rich d3plot read with every field at that layer}."""
    return {layer: read_d3plot(rich, extra_fields="all", layer=layer) for layer in LAYERS}


# ---------------------------------------------------------------- the stress kernel
def test_the_test_file_holds_the_adversarial_tensors(raw):
    stress = raw["element_shell_stress"].reshape(-1, 6)
    assert (stress[:len(ADVERSARIAL_STRESSES)] == ADVERSARIAL_STRESSES).all()
    assert raw["element_shell_stress"].shape == (4, 7, 3, 6)  # the rigid shell has none


def test_every_stress_scalar_of_every_layer_equals_an_independent_computation(raw, meshes):
    stress = raw["element_shell_stress"].astype(np.float64)  # (T, deformable, 3 layers, 6)
    mesh = meshes["mid"]
    columns = np.flatnonzero(mesh.parts != RIGID_PART)  # the shells written with results
    refs = [[[reference_scalars(stress[t, s, k]) for k in range(3)]
             for s in range(stress.shape[1])] for t in range(len(stress))]
    checked = 0
    for layer, mesh in meshes.items():
        for name in SCALARS:
            values = mesh.element_fields[name]
            assert np.isnan(values[:, mesh.parts == RIGID_PART]).all()
            for t in range(len(stress)):
                for s, column in enumerate(columns):
                    got = float(values[t, column])
                    if layer in LAYER_INDEX:
                        assert_close(name, got, refs[t][s][LAYER_INDEX[layer]])
                    else:  # the extreme of the layers' values (where defined), with that
                        # layer's tolerance
                        pick = max if layer == "max" else min
                        defined = [r for r in refs[t][s] if not math.isnan(r[name])]
                        ref = pick(defined, key=lambda r, n=name: r[n]) if defined else \
                            refs[t][s][0]
                        assert_close(name, got, ref)
                    checked += 1
    assert checked == len(LAYERS) * len(SCALARS) * 4 * 7


def test_von_mises_equals_von_mises_from_the_principal_stresses(raw):
    tensors = raw["element_shell_stress"].reshape(-1, 6).astype(np.float64)
    got = von_mises(tensors)
    for value, t in zip(got, tensors):
        ref = reference_scalars(t)
        assert abs(value - ref["mises_from_principal"]) <= EIGEN_REL * ref["norm"]


def test_plastic_strain_follows_the_layer(raw, meshes):
    strain = raw["element_shell_effective_plastic_strain"].astype(np.float64)  # (T, S, 3)
    for layer, mesh in meshes.items():
        values = mesh.element_fields["plastic_strain"][:, mesh.parts != RIGID_PART]
        for t, s in np.ndindex(values.shape):
            layers = [float(v) for v in strain[t, s]]
            want = layers[LAYER_INDEX[layer]] if layer in LAYER_INDEX else \
                (max if layer == "max" else min)(layers)
            assert values[t, s] == want


def test_the_default_read_derives_nothing_more_and_keeps_the_mid_layer(rich, meshes):
    mesh = read_d3plot(rich)
    assert mesh.node_fields == {}
    assert set(mesh.element_fields) == {"von_mises", "plastic_strain", "thickness", "alive",
                                        *(f"stress_{c}" for c in ("xx", "yy", "zz", "xy",
                                                                   "yz", "zx"))}
    assert np.array_equal(mesh.element_fields["von_mises"],
                          meshes["mid"].element_fields["von_mises"], equal_nan=True)
    one = read_d3plot(rich, extra_fields=["principal_min"], layer="top")
    assert set(one.element_fields) - set(mesh.element_fields) == {"principal_min"}
    assert np.array_equal(one.element_fields["principal_min"],
                          meshes["top"].element_fields["principal_min"], equal_nan=True)


def test_adversarial_tensors_by_name():
    tensors = ADVERSARIAL_STRESSES.astype(np.float64)
    principal = principal_stresses(tensors)
    assert (principal[0] == 0).all() and max_shear(tensors)[0] == 0
    assert (principal[1] == 250).all() and max_shear(tensors)[1] == 0  # hydrostatic
    assert np.isnan(triaxiality(tensors)[[0, 1, 2, 10]]).all()  # von Mises 0: undefined
    assert triaxiality(tensors)[3] == pytest.approx(1 / 3, rel=1e-15)  # uniaxial tension
    assert signed_von_mises(tensors)[5] == von_mises(tensors)[5] > 0  # trace 0 counts as +
    assert signed_von_mises(tensors)[7] == -von_mises(tensors)[7]
    # 1e6 hydrostatic plus a deviator of 1/16: the shear keeps its digits
    ref = reference_scalars(tensors[8])
    assert abs(max_shear(tensors)[8] - ref["max_shear"]) <= 1e-14 * ref["max_shear"]
    assert pressure(tensors)[10] == -1e6


def test_missing_values_give_nan_and_bad_shapes_are_refused():
    tensors = np.array([[np.nan] * 6, [1, 2, 3, np.inf, 0, 0], [1, 2, 3, 4, 5, 6]])
    for name in SCALARS:
        values = stress_scalar(name, tensors)
        assert np.isnan(values[:2]).all() and np.isfinite(values[2]), name
    with pytest.raises(ValueError, match=r"\(\.\.\., 6\)"):
        von_mises(np.zeros((3, 5)))
    with pytest.raises(KeyError, match="principal_max"):
        stress_scalar("principal_4", tensors)


float32s = st.floats(-1e4, 1e4, width=32)


@settings(max_examples=150, deadline=None)
@given(st.lists(float32s, min_size=6, max_size=6), st.sampled_from([0.0, 1e3, -1e6, 1e6]))
def test_every_scalar_equals_the_independent_one_on_random_tensors(t, offset):
    t = np.array(t, np.float32)
    t[:3] += np.float32(offset)  # a large hydrostatic part, still float32
    tensors = t.astype(np.float64)[None]
    ref = reference_scalars(t)
    for name in SCALARS:
        assert_close(name, float(stress_scalar(name, tensors)[0]), ref)


# ---------------------------------------------------------------- node fields
def test_displacement_velocity_acceleration_equal_the_raw_arrays(raw, meshes):
    mesh = meshes["mid"]
    initial = raw["node_coordinates"].astype(np.float64)
    current = raw["node_displacement"].astype(np.float64)
    for name, vectors in (("displacement", current - initial[None]),
                          ("velocity", raw["node_velocity"].astype(np.float64)),
                          ("acceleration", raw["node_acceleration"].astype(np.float64))):
        for t, n in np.ndindex(vectors.shape[:2]):
            v = [float(c) for c in vectors[t, n]]
            for axis, value in zip("xyz", v):
                assert mesh.node_fields[f"{name}_{axis}"][t, n] == value
            magnitude = math.hypot(*v)
            assert abs(mesh.node_fields[name][t, n] - magnitude) <= EXACT_REL * magnitude
    assert (mesh.node_fields["displacement"][0] == 0).all()


def test_fields_a_file_lacks_are_named_and_unknown_names_refused(tmp_path):
    from meshes import write_d3plot

    from workbench.scene.readers import ParseWarning

    path = write_d3plot(tmp_path)
    with pytest.warns(ParseWarning, match="velocity asked for, but the states hold no node "
                                          "velocity"):
        mesh = read_d3plot(path, extra_fields=["velocity", "pressure"])
    assert "velocity" not in mesh.node_fields and "pressure" in mesh.element_fields
    with pytest.raises(ValueError, match="no d3plot field 'speed'"):
        read_d3plot(path, extra_fields=["speed"])
    with pytest.raises(ValueError, match="unknown shell layer 'outer'"):
        read_d3plot(path, layer="outer")
    offered = offered_by_file(path)
    assert "principal_max" in offered and "velocity" not in offered
    assert set(offered) <= set(FIELDS)


# ---------------------------------------------------------------- per-part node averages
def two_part_mesh() -> FEMesh:
    """Quads e0 (part 1), e1 (part 2), triangle e2 (part 2) and e3 (part 1, a triangle on
    e0's nodes 0, 1, 4); node 1 and 4 shared by both parts; two states, e3 deleted at the
    second, e1 without a value (NaN) at the second."""
    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0],
                      [3, 0, 0]], float)
    elements = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [2, 6, 5, 5], [0, 1, 4, 4]])
    values = np.array([[2.0, 10.0, 4.0, 6.0], [2.0, np.nan, 4.0, 6.0]])
    alive = np.array([[1, 1, 1, 1], [1, 1, 1, 0]], float)
    steps = np.stack([nodes, nodes + [0, 0, 1]])
    return FEMesh(nodes, elements, parts=[1, 2, 2, 1], steps=steps,
                  element_fields={"v": values, "alive": alive},
                  node_ids=np.arange(10, 17), element_ids=np.array([5, 6, 7, 8]))


def test_a_node_shared_by_two_parts_gets_each_parts_own_mean():
    mesh = two_part_mesh()
    smooth = fringes.part_averaged(mesh, "v")
    values = smooth.node_fields["v_smooth"]
    assert smooth.n_nodes == 9  # nodes 1 and 4 copied once more
    by = {(int(smooth.node_ids[n]), part): n for e, part in zip(smooth.elements, smooth.parts)
          for n in e}
    # state 0: part 1 elements e0 = 2, e3 = 6; part 2 e1 = 10, e2 = 4 (its repeated node once)
    want0 = {(10, 1): 4.0, (11, 1): 4.0, (14, 1): 4.0, (13, 1): 2.0,
             (11, 2): 10.0, (14, 2): 10.0, (12, 2): 7.0, (15, 2): 7.0, (16, 2): 4.0}
    # state 1: e3 deleted, e1 without a value: part 1 is e0 alone, part 2 e2 alone
    want1 = {(10, 1): 2.0, (11, 1): 2.0, (14, 1): 2.0, (13, 1): 2.0,
             (11, 2): np.nan, (14, 2): np.nan, (12, 2): 4.0, (15, 2): 4.0, (16, 2): 4.0}
    assert set(by) == set(want0)
    for state, want in ((0, want0), (1, want1)):
        got = {key: values[state, n] for key, n in by.items()}
        assert got.keys() == want.keys()
        for key in want:
            assert got[key] == want[key] or (np.isnan(got[key]) and np.isnan(want[key])), key
    # no node is used by two parts; coordinates of every state and ids follow the copies
    for n in range(smooth.n_nodes):
        assert len(set(smooth.parts[(smooth.elements == n).any(axis=1)].tolist())) == 1
    origin = [int(i) - 10 for i in smooth.node_ids]
    assert np.array_equal(smooth.steps, mesh.steps[:, origin])
    assert np.array_equal(smooth.element_fields["v"], mesh.element_fields["v"], equal_nan=True)
    with pytest.raises(ValueError, match="node field already"):
        fringes.part_averaged(smooth, "v_smooth")


def test_part_averaging_keeps_the_beams_and_particles_in_place():
    # a beam from the seam node 4 to a free node, and a particle on another free node: both
    # stay, at the coordinates of every state, with their ids, parts and alive
    from workbench.scene.kinds import Beams, Particles

    mesh = two_part_mesh()
    nodes = np.vstack([mesh.nodes, [[1, 2, 0], [3, 2, 0]]])
    steps = np.concatenate([mesh.steps, np.stack([nodes[7:], nodes[7:] + [0, 0, 1]])], axis=1)
    beams = Beams(parts=[30], ids=[900], fields={"alive": [[1.0], [0.0]]}, nodes=[[4, 7]])
    particles = Particles(parts=[40], ids=[950], fields={}, node=[8], radius=[0.25])
    mesh = FEMesh(nodes, mesh.elements, mesh.parts, steps, element_fields=mesh.element_fields,
                  node_ids=np.arange(10, 19), beams=beams, particles=particles)
    smooth = fringes.part_averaged(mesh, "v")
    for state in range(2):
        ends = smooth.coordinates(state)[smooth.beams.nodes[0]]
        np.testing.assert_array_equal(ends, mesh.coordinates(state)[[4, 7]])
        np.testing.assert_array_equal(smooth.coordinates(state)[smooth.particles.node],
                                      mesh.coordinates(state)[[8]])
    assert smooth.beams.ids.tolist() == [900] and smooth.particles.parts.tolist() == [40]
    assert smooth.beams.fields["alive"].tolist() == [[1.0], [0.0]]
    assert smooth.n_nodes == 11  # nodes 1 and 4 copied once more, the free nodes kept
    assert np.isnan(smooth.node_fields["v_smooth"][:, smooth.particles.node]).all()


def test_part_averages_of_the_d3plot_equal_a_loop_over_its_elements(meshes):
    mesh = meshes["max"]
    smooth = fringes.part_averaged(mesh, "principal_max")
    values, field = smooth.node_fields["principal_max_smooth"], mesh.element_fields[
        "principal_max"]
    for t in range(mesh.n_steps):
        sums: dict = {}
        for m, (e, part) in enumerate(zip(mesh.elements, mesh.parts)):
            if mesh.element_fields["alive"][t, m] == 0 or np.isnan(field[t, m]):
                continue
            for node in set(e.tolist()):
                sums.setdefault((int(mesh.node_ids[node]), int(part)), []).append(
                    float(field[t, m]))
        for n in range(smooth.n_nodes):
            part = int(smooth.parts[(smooth.elements == n).any(axis=1)][0])
            found = sums.get((int(smooth.node_ids[n]), part))
            if found is None:  # the rigid part: no value
                assert np.isnan(values[t, n])
            else:
                want = math.fsum(found) / len(found)
                assert abs(values[t, n] - want) <= EXACT_REL * max(abs(want), 1e-300)


# ---------------------------------------------------------------- envelope and differences
def test_the_envelope_is_the_maximum_over_the_live_states(meshes):
    mesh = meshes["mid"]
    for name, kind in (("von_mises", "element"), ("displacement", "node")):
        got = (fringes.envelope(mesh, name).node_fields if kind == "node"
               else fringes.envelope(mesh, name).element_fields)[f"{name}_envelope"]
        values = mesh.node_fields.get(name, mesh.element_fields.get(name))
        assert got.shape == values.shape[1:]
        for i in range(values.shape[1]):
            live = [float(values[t, i]) for t in range(mesh.n_steps)
                    if kind == "node" or mesh.element_fields["alive"][t, i] != 0]
            live = [v for v in live if not math.isnan(v)]
            assert got[i] == max(live) if live else math.isnan(got[i])
    # the triangle (deleted at the last state) leaves its last value, its largest, out
    tri = int(np.flatnonzero(mesh.element_fields["alive"][-1] == 0)[0])
    vm = mesh.element_fields["von_mises"][:, tri]
    assert vm[-1] > vm[:-1].max()
    assert fringes.envelope(mesh, "von_mises").element_fields["von_mises_envelope"][tri] \
        == vm[:-1].max()


def test_relative_to_a_state(meshes):
    mesh = meshes["mid"]
    for name in ("von_mises", "displacement_x"):
        got = fringes.relative_to_state(mesh, name, 2)
        fields = got.node_fields if name in mesh.node_fields else got.element_fields
        values = mesh.node_fields.get(name, mesh.element_fields.get(name))
        assert np.array_equal(fields[f"{name}_minus_state2"], values - values[2], equal_nan=True)
    with pytest.raises(ValueError, match="out of range"):
        fringes.relative_to_state(mesh, "von_mises", 4)
    static = FEMesh(mesh.nodes, mesh.elements, element_fields={"t": np.ones(mesh.n_elements)})
    with pytest.raises(ValueError, match="static"):
        fringes.relative_to_state(static, "t", 0)


def test_relative_to_another_run_maps_by_id(tmp_path, meshes):
    mesh = meshes["mid"]
    # the same model stored in another order: the difference is 0 wherever there is a value
    same = read_d3plot(write_rich_d3plot(tmp_path / "same", permute=True), extra_fields="all")
    assert not np.array_equal(same.element_ids, mesh.element_ids)
    assert not np.array_equal(same.node_ids, mesh.node_ids)
    for name in ("principal_max", "displacement", "velocity_z"):
        diff = fringes.relative_to_run(mesh, same, name)
        fields = {**diff.node_fields, **diff.element_fields}[f"{name}_minus_run"]
        finite = np.isfinite(fields)
        assert finite.sum() > 0 and (fields[finite] == 0).all()
    # both stored in other orders
    again = read_d3plot(write_rich_d3plot(tmp_path / "again", permute=2), extra_fields="all")
    assert not np.array_equal(again.element_ids, same.element_ids)
    for name in ("principal_max", "velocity_z"):
        diff = fringes.relative_to_run(again, same, name)
        fields = {**diff.node_fields, **diff.element_fields}[f"{name}_minus_run"]
        finite = np.isfinite(fields)
        assert finite.sum() > 0 and (fields[finite] == 0).all()
    # another run (other values), permuted: each id minus the other run's value of that id
    other = read_d3plot(write_rich_d3plot(tmp_path / "other", seed=1, permute=True),
                        extra_fields="all")
    for name, kind in (("principal_max", "element"), ("velocity", "node")):
        got = {**fringes.relative_to_run(mesh, other, name).node_fields,
               **fringes.relative_to_run(mesh, other, name).element_fields}[f"{name}_minus_run"]
        ids, other_ids = (mesh.node_ids, other.node_ids) if kind == "node" else \
            (mesh.element_ids, other.element_ids)
        mine = {**mesh.node_fields, **mesh.element_fields}[name]
        theirs = {**other.node_fields, **other.element_fields}[name]
        where = {int(i): k for k, i in enumerate(other_ids)}
        for t in range(mesh.n_steps):
            for k, i in enumerate(ids):
                want = mine[t, k] - theirs[t, where[int(i)]]
                assert got[t, k] == want or (np.isnan(got[t, k]) and np.isnan(want))


def test_runs_whose_ids_differ_are_refused(tmp_path, meshes):
    mesh = meshes["mid"]
    renamed = read_d3plot(write_rich_d3plot(tmp_path / "renamed", rename_node=(101, 999)),
                          extra_fields="all")
    with pytest.raises(ValueError, match="node ids do not match: .*101"):
        fringes.relative_to_run(mesh, renamed, "displacement")
    fewer = mesh.subset(mesh.parts != RIGID_PART)
    with pytest.raises(ValueError, match="element ids do not match"):
        fringes.relative_to_run(mesh, fewer, "von_mises")
    static = FEMesh(mesh.nodes, mesh.elements, element_ids=mesh.element_ids,
                    element_fields={"von_mises": np.ones(mesh.n_elements)})
    with pytest.raises(ValueError, match="differ in their states"):
        fringes.relative_to_run(mesh, static, "von_mises")
    with pytest.raises(KeyError, match="no field 'principal_max'"):
        fringes.relative_to_run(mesh, static, "principal_max")
