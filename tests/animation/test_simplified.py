"""``workbench animate --simplify``: the simplified triangles drawn at every state's coordinates,
each frame the image of those triangles placed at its state, stamped with the bound
``bounds_over_states`` certifies there (``exceeds`` above the tolerance), certified at every
state drawn with ``--states all``, and bad input refused in one line."""

import math
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from meshes import quad_grid, write_d3plot

from workbench.algo.simplify import hausdorff_decimate
from workbench.algo.simplify.states import bounds_over_states
from workbench.animation import simplified
from workbench.animation.decoration import Decoration
from workbench.animation.frames import FrameLoop
from workbench.animation.simplified import simplify_animation
from workbench.cli import main
from workbench.output.figures import TITLE_HEIGHT
from workbench.paths import make_path
from workbench.paths.base import RenderPath
from workbench.paths.drawing import render
from workbench.scene.mesh import FEMesh
from workbench.scene.readers import load

SIZE = (64, 48)
VIEW = (30.0, 25.0)
PERCENT = 1.0
STATES = [0, 1, 2]


def write_plate(folder: Path) -> Path:
    """A three-state d3plot of a flat 12 × 12 plate in two parts (x < 6, x > 6), tilting about
    the y axis state by state, on which a bump of height 0, 0.05 and 2 rises in the second
    part, with a plastic strain per element."""
    from lasso.dyna import ArrayType, D3plot

    nodes, quads = quad_grid(12, 12)
    x, y = nodes[:, 0], nodes[:, 1]
    bump = np.exp(-((x - 9.0) ** 2 + (y - 6.0) ** 2) / 4.0)
    centre_x = nodes[quads].mean(axis=1)[:, 0]
    plot = D3plot()
    plot.arrays[ArrayType.node_coordinates] = nodes.astype(np.float32)
    plot.arrays[ArrayType.node_ids] = np.arange(1, len(nodes) + 1, dtype=np.int32)
    plot.arrays[ArrayType.element_shell_node_indexes] = quads.astype(np.int32)
    plot.arrays[ArrayType.element_shell_part_indexes] = (centre_x > 6).astype(np.int32)
    plot.arrays[ArrayType.element_shell_ids] = np.arange(1, len(quads) + 1, dtype=np.int32)
    plot.arrays[ArrayType.part_ids] = np.array([1, 2], np.int32)
    plot.arrays[ArrayType.global_timesteps] = np.array([0.0, 1e-3, 2e-3], np.float32)
    plot.arrays[ArrayType.node_displacement] = np.stack(
        [nodes + np.c_[0 * x, 0 * y, a * bump + 0.25 * t * x]
         for t, a in enumerate((0.0, 0.05, 2.0))]).astype(np.float32)
    plastic = np.zeros((3, len(quads), 3), np.float32)
    plastic[:, :, 0] = np.arange(3)[:, None] * centre_x[None, :] / 100.0
    plot.arrays[ArrayType.element_shell_effective_plastic_strain] = plastic
    path = folder / "d3plot"
    plot.write_d3plot(str(path))
    return path


@pytest.fixture(scope="module")
def plate_file(tmp_path_factory):
    return write_plate(tmp_path_factory.mktemp("plate"))


@pytest.fixture(scope="module")
def plate(plate_file):
    return load(plate_file)


@pytest.fixture(scope="module")
def first(plate):
    return simplify_animation(plate, STATES, PERCENT)


def measured(mesh, certified="first"):
    """The decimation and its bounds at every state, computed here as the module should."""
    tri = mesh.triangulation
    parts = mesh.parts[tri.element_of]
    further = {"states": mesh.steps[1:]} if certified == "all" else {}
    d = hausdorff_decimate(mesh.steps[0], tri.triangles, PERCENT / 100, parts=parts, **further)
    return d, bounds_over_states(mesh.steps, tri.triangles, parts, d, states=STATES)


def animate(source, out, *options: str) -> int:
    """The exit status of ``workbench animate SOURCE -o OUT OPTIONS`` (the parser's refusals
    exit)."""
    try:
        return main(["animate", str(source), "-o", str(out), "--size", f"{SIZE[0]}x{SIZE[1]}",
                     "--view", f"{VIEW[0]},{VIEW[1]}", *options])
    except SystemExit as exc:
        return exc.code


def stamps_of(monkeypatch) -> list[tuple[int, str]]:
    """(state, stamp) of every frame stamped from now on."""
    seen = []
    original = simplified.SimplifiedAnimation.stamp

    def recording(self, step):
        seen.append((step, original(self, step)))
        return seen[-1][1]

    monkeypatch.setattr(simplified.SimplifiedAnimation, "stamp", recording)
    return seen


# --------------------------------------------------------------------------- the frames
@pytest.mark.parametrize("path", ["flat", "gouraud"])
def test_frames_are_the_simplified_triangles_at_each_state(ctx, plate, first, path):
    """Each frame is the image of the simplified triangles placed at that state's coordinates
    (a static mesh of them, drawn with the camera fitted to their nodes over every state):
    pixel for pixel with flat shading, by coverage with Gouraud normals (whose crease split
    sees the first and last states of an animated mesh); and it is not the full mesh's."""
    triangles = first.decimation.triangles
    assert 0 < len(triangles) < first.input_triangles
    used = np.unique(triangles)
    box = plate.steps[:, used].reshape(-1, 3)
    camera = RenderPath.fit_camera(box.min(axis=0), box.max(axis=0), SIZE, view=VIEW,
                                   projection="orthographic", up="z")
    frames = list(FrameLoop(ctx, first.mesh, path, steps=STATES, size=SIZE, view=VIEW))
    full = list(FrameLoop(ctx, plate, path, steps=STATES, size=SIZE, view=VIEW))
    for frame, whole in zip(frames, full):
        k = frame.step
        static = FEMesh(nodes=plate.steps[k], elements=triangles, parts=first.decimation.parts)
        expected = render(ctx, static, path, camera=camera, size=SIZE)
        if path == "flat":
            assert np.array_equal(frame.image, expected), k
        else:
            covered = (frame.image[..., :3] < 255).any(axis=2)
            assert np.array_equal(covered, (expected[..., :3] < 255).any(axis=2)), k
        assert not np.array_equal(frame.image, whole.image), k
    assert not np.array_equal(frames[0].image, frames[2].image)  # the plate tilted


def test_the_simplified_mesh_shares_nodes_states_and_node_fields(plate, first):
    mesh = first.mesh
    assert mesh.nodes is plate.nodes and mesh.steps is plate.steps and mesh.times is plate.times
    assert np.array_equal(mesh.triangles, first.decimation.triangles)
    assert np.array_equal(mesh.parts, first.decimation.parts)
    assert mesh.node_fields.keys() == plate.node_fields.keys()


# --------------------------------------------------------------------------- the stamps
def test_each_frame_is_stamped_with_its_certified_bound(ctx, plate_file, plate, tmp_path,
                                                        capsys, monkeypatch):
    d, bounds = measured(plate)
    worst = bounds.worst_per_state()
    assert worst[0][2] <= 1.0 < worst[2][2]  # made at state 0, left behind by the bump
    stamps = stamps_of(monkeypatch)
    out = tmp_path / "plate.gif"
    assert animate(plate_file, out, "--simplify", f"{PERCENT:g}") == 0
    assert [k for k, _ in stamps] == STATES
    for (k, stamp), (state, part, ratio) in zip(stamps, worst):
        assert state == k
        assert stamp == (f"simplified 1 %: {len(d.triangles)} of {len(plate.triangles)} "
                         f"triangles; certified ≤ {math.ceil(ratio * 100) / 100:.2f} × "
                         f"tolerance (part {part})" + (": exceeds" if ratio > 1.0 else ""))
    # the frame, its title and bar as without --simplify, the stamp's row under them
    plain = Decoration("plate (gouraud)")(next(iter(FrameLoop(
        ctx, plate, "gouraud", steps=[0], size=SIZE, view=VIEW))))
    read = iio.imread(out, index=None)
    assert read.shape[:3] == (3, plain.shape[0] + TITLE_HEIGHT, plain.shape[1])
    row = read[2, plain.shape[0]:, :, :3].astype(int)
    assert (row[..., 0] - row[..., 2] > 60).any()  # dark red: exceeds
    assert not (read[0, plain.shape[0]:, :, 0].astype(int) - read[0, plain.shape[0]:, :, 2]
                > 60).any()
    printed = capsys.readouterr()
    assert "certified at state 0" in printed.out and "(exceeds)" in printed.out
    assert "animate: decimating 288 triangles at 1 %" in printed.err


def test_stamp_rounds_the_ratio_up(first):
    for k, (_, part, ratio) in zip(STATES, first.bounds.worst_per_state()):
        shown = float(first.stamp(k).split("≤ ")[1].split(" ×")[0])
        assert ratio <= shown < ratio + 0.01 + 1e-12
        assert first.worst(k) == (part, ratio)


# --------------------------------------------------------------------------- --states all
def test_states_all_certifies_every_state_drawn(plate_file, plate, first, tmp_path,
                                                monkeypatch):
    every = simplify_animation(plate, STATES, PERCENT, "all")
    assert every.decimation.states_certified == len(STATES)
    _, bounds = measured(plate, "all")
    assert np.array_equal(every.bounds.upper, bounds.upper)
    # the bracket's upper end is within 1 % of the tolerance of a distance certified <= 1
    assert every.bounds.ratio.max() <= 1.01
    assert len(every.decimation.triangles) > len(first.decimation.triangles)
    stamps = stamps_of(monkeypatch)
    assert animate(plate_file, tmp_path / "all.gif", "--simplify", "1", "--states", "all") == 0
    assert len(stamps) == 3 and not any("exceeds" in t for _, t in stamps)


# --------------------------------------------------------------------------- element fields
def test_element_fields_follow_the_triangle_each_descends_from(ctx, plate):
    every = simplify_animation(plate, STATES, PERCENT, field="plastic_strain")
    tri = plate.triangulation
    sources = np.asarray(every.decimation.source)
    source = tri.triangles[sources]
    kept = np.zeros(plate.n_nodes, bool)
    kept[every.decimation.triangles.ravel()] = True
    # a corner the decimation kept is the corner of the triangle it descends from
    same = source == every.decimation.triangles
    assert (same | ~kept[source]).all()
    values = plate.element_fields["plastic_strain"][:, tri.element_of[sources]]
    assert np.array_equal(every.mesh.element_fields["plastic_strain"], values)
    # each frame: the simplified triangles at that state coloured by their elements' values
    style = make_path("element_color", field="plastic_strain").style
    loop = FrameLoop(ctx, every.mesh, "element_color", style, steps=STATES, size=SIZE,
                     view=VIEW)
    for frame in loop:
        static = FEMesh(nodes=plate.steps[frame.step], elements=every.decimation.triangles,
                        parts=every.decimation.parts,
                        element_fields={"plastic_strain": values[frame.step]})
        fixed = make_path("element_color", field="plastic_strain",
                          value_range=frame.value_range).style
        expected = render(ctx, static, "element_color", fixed, camera=loop.camera, size=SIZE)
        assert np.array_equal(frame.image, expected), frame.step


# --------------------------------------------------------------------------- refusals
@pytest.fixture(scope="module")
def eroding(tmp_path_factory):
    """A three-state d3plot whose triangle shell is deleted at state 2."""
    return write_d3plot(tmp_path_factory.mktemp("eroding"))


@pytest.fixture(scope="module")
def static(tmp_path_factory):
    """A mesh file without states."""
    path = tmp_path_factory.mktemp("static") / "plate.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    return path


REFUSALS = [
    ("plate", ("--simplify", "0"), "argument --simplify: must be positive"),
    ("plate", ("--simplify", "-1"), "argument --simplify: must be positive"),
    ("plate", ("--simplify", "nan"), "argument --simplify: must be positive"),
    ("plate", ("--states", "all"), "--states all applies to --simplify"),
    ("plate", ("--simplify", "1", "--states", "every"), "argument --states: invalid choice"),
    ("static", ("--simplify", "1"), "has none (one geometry)"),
]


@pytest.mark.parametrize("source, options, words", REFUSALS)
def test_bad_input_is_one_line_exit_2_and_writes_nothing(request, tmp_path, capsys, source,
                                                         options, words):
    path = request.getfixturevalue({"plate": "plate_file"}.get(source, source))
    folder = tmp_path / "out"
    folder.mkdir()
    assert animate(path, folder / "out.gif", *options) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("workbench") and ": error: " in err and "\n" not in err, err
    assert words in err, err
    assert list(folder.iterdir()) == []


def test_an_eroding_result_is_drawn_simplified(eroding, tmp_path, capsys):
    assert animate(eroding, tmp_path / "all.gif", "--simplify", "1", "--states", "all") == 0
    assert "simplified 1 %" in capsys.readouterr().out


def test_eroded_elements_vanish_with_the_simplified_triangles_they_descend_from(ctx, plate):
    """The plate with a block of its first part deleted at state 2: certified at every state,
    each frame's bound (between the triangles drawn at its state) is within the tolerance, and
    the frame at state 2 is the image of the simplified triangles whose elements are alive."""
    centre = plate.nodes[plate.elements].mean(axis=1)
    alive = np.ones((3, plate.n_elements), np.float32)
    alive[2, (centre[:, 0] > 1) & (centre[:, 0] < 5) & (centre[:, 1] > 3) & (centre[:, 1] < 9)] = 0
    eroded = FEMesh(nodes=plate.nodes, elements=plate.elements, parts=plate.parts,
                    steps=plate.steps, element_fields={"alive": alive}, name="eroded plate")
    every = simplify_animation(eroded, STATES, PERCENT, "all")
    assert every.bounds.ratio.max() <= 1.01
    tri = eroded.triangulation
    drawn = alive[2, tri.element_of[every.decimation.source]] != 0
    assert 0 < drawn.sum() < len(drawn)
    # the stamp counts the elements the result deletes, not the simplified triangles hidden
    assert every.deleted == {0: 0, 1: 0, 2: int((alive[2] == 0).sum())}
    loop = FrameLoop(ctx, every.mesh, "flat", make_path("flat").style, steps=[2], size=SIZE,
                     view=VIEW)
    frame = next(iter(loop))
    static = FEMesh(nodes=eroded.steps[2], elements=every.decimation.triangles[drawn],
                    parts=every.decimation.parts[drawn])
    expected = render(ctx, static, "flat", make_path("flat").style, camera=loop.camera,
                      size=SIZE)
    assert np.array_equal(frame.image, expected)
