"""The workbench command: rendering, experiments, and one-line errors with exit status 2."""

import subprocess
import sys

import numpy as np
import pytest
from meshes import DECK, quad_grid
from PIL import Image

from workbench.cli import main


@pytest.fixture()
def deck(tmp_path):
    path = tmp_path / "plate.k"
    path.write_text(DECK)
    return path


def test_render_writes_the_image_of_a_plate(deck, tmp_path):
    out = tmp_path / "plate.png"
    assert main(["render", str(deck), "--view", "0,0", "--up", "y", "--size", "80x60",
                 "--projection", "orthographic", "-o", str(out)]) == 0
    image = np.asarray(Image.open(out))
    assert image.shape[:2] == (60, 80)
    drawn = (image[..., :3] != 255).any(axis=2)
    # the 100 x 100 plate is framed to 105 units of height (margin 1.05): 57 of the 60 rows,
    # and 57 of the 80 columns (the view is 140 units wide)
    rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    assert abs(len(rows) - 57) <= 1 and abs(len(cols) - 57) <= 1
    assert drawn.sum() == len(rows) * len(cols)


def test_render_draws_the_same_plate_with_quad_strips(deck, tmp_path, capsys):
    images = []
    for strips in ("none", "quad"):
        out = tmp_path / f"plate_{strips}.png"
        assert main(["render", str(deck), "--view", "0,0", "--up", "y", "--size", "80x60",
                     "--strips", strips, "-o", str(out)]) == 0
        images.append(np.asarray(Image.open(out)))
    assert (images[0] == images[1]).all()
    printed = capsys.readouterr().out
    assert "6 vertices sent" in printed and "4 vertices sent, 1 strip," in printed


def grid_deck(n: int, cell: float) -> str:
    """A flat n × n quad plate as a fixed-format keyword deck."""
    coords, quads = quad_grid(n, n, cell=cell)
    nodes = [f"{k + 1:8d}" + "".join(f"{c:16.1f}" for c in xyz) for k, xyz in enumerate(coords)]
    elements = [f"{k + 1:8d}{1:8d}" + "".join(f"{a + 1:8d}" for a in quad)
                for k, quad in enumerate(quads)]
    return "\n".join(["*KEYWORD", "*NODE", *nodes, "*ELEMENT_SHELL", *elements, "*END", ""])


def test_render_the_plate_simplified_with_a_wire_texture(tmp_path):
    # a flat 4 x 4 plate simplifies to two triangles; the texture still outlines its elements,
    # so the image has wire lines inside the plate, not only along its border
    deck = tmp_path / "grid.k"
    deck.write_text(grid_deck(4, 25.0))
    out = tmp_path / "plate_fe.png"
    assert main(["render", str(deck), "--view", "0,0", "--up", "y", "--size", "170x130",
                 "--path", "fe_normal_wire", "--fepatch", "B", "-o", str(out)]) == 0
    image = np.asarray(Image.open(out))[..., :3].astype(int)
    wire = (image == 0).all(axis=2)
    drawn = (image != 255).any(axis=2)
    rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    # the three inner element lines each way are there, within a pixel, along the whole plate
    for k in (1, 2, 3):
        x = round(c0 + k * (c1 - c0) / 4 - 0.5)
        y = round(r0 + k * (r1 - r0) / 4 - 0.5)
        assert wire[r0:r1, x - 1:x + 2].any(axis=1).mean() > 0.95
        assert wire[y - 1:y + 2, c0:c1].any(axis=0).mean() > 0.95
    # and little else: 4 + 4 lines of one or, where a line falls on a pixel boundary, two pixels
    assert wire.sum() <= 8 * 2 * max(r1 - r0, c1 - c0)
    assert main(["render", str(deck), "--path", "fe_normal_wire", "--fepatch", "C",
                 "-o", str(tmp_path / "bad.png")]) != 0


@pytest.mark.usefixtures("car_deck")
def test_render_car_with_field_writes_a_colour_bar_figure(tmp_path):
    out = tmp_path / "car.png"
    assert main(["render", "car", "--field", "thickness", "--bands", "4", "--wireframe",
                 "--size", "320x200", "-o", str(out)]) == 0
    image = np.asarray(Image.open(out).convert("RGB"))
    # the figure is wider than the render: a colour bar sits beside it
    assert image.shape[1] > 320


@pytest.mark.usefixtures("d3plot_file")
def test_render_constant_field_of_the_d3plot(tmp_path):
    # the sample result has one state with zero stress everywhere: a constant field still gets a
    # scale
    out = tmp_path / "d3plot.png"
    assert main(["render", "d3plot", "--field", "von_mises", "--size", "200x150", "-o",
                 str(out)]) == 0
    assert out.stat().st_size > 1000


@pytest.mark.parametrize("text, expected", [
    (DECK.replace("100.0           100.0", "100.0           abc  "), ":5:"),
    (DECK.replace("       1       1       1       2       3       4",
                  "       1       1       1       2       3       9"), "9"),
    ("*KEYWORD\n*END\n", "plate.k"),
])
def test_bad_decks_end_with_one_line_and_status_2(tmp_path, text, expected):
    path = tmp_path / "plate.k"
    path.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "workbench.cli", "render", str(path), "-o",
                           str(tmp_path / "x.png")], capture_output=True, text=True)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("workbench: error:") and expected in lines[0]
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "x.png").exists()


def test_missing_file_and_unknown_field_are_bad_input(deck, tmp_path, capsys):
    assert main(["render", str(tmp_path / "none.k"), "-o", str(tmp_path / "x.png")]) == 2
    assert main(["render", str(deck), "--field", "stress", "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert "none.k" in err and "no field 'stress'" in err


@pytest.mark.parametrize("command", [["hausdorff", "spacetime:bar", "semicylinders:4"],
                                     ["simplify", "spacetime:bar"],
                                     ["explode", "spacetime:bar", "--focus", "1", "-o", "x.gif"]])
def test_mesh_commands_refuse_a_spacetime_scene_in_one_line(command, capsys):
    assert main(command) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "spacetime" in err[0] and "FE mesh" in err[0]


def test_list_names_the_render_paths_experiment(capsys):
    assert main(["list"]) == 0
    assert "render_paths" in capsys.readouterr().out


def test_run_refuses_an_unknown_experiment_naming_the_known_ones(capsys):
    assert main(["run", "no_such_experiment", "--quick"]) == 2
    err = capsys.readouterr().err
    assert "no_such_experiment" in err and "render_paths" in err


def test_info_names_the_renderer(capsys):
    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert "renderer" in out and "moderngl" in out


def test_info_of_a_d3plot_lists_its_fields_and_deleted_elements(tmp_path, capsys):
    """The lasso-written d3plot (two shells in parts 5 and 9; the triangle, part 9, deleted at
    the last of three states): sizes, times, each field with its range over live elements,
    and the deleted count per state and per part; a missing file is one line, exit 2."""
    from meshes import write_d3plot

    assert main(["info", str(write_d3plot(tmp_path))]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "d3plot: 5 nodes, 2 elements, 2 parts, 3 states (units mm)"
    assert "times: 0 .. 0.002" in out
    assert "element field 'plastic_strain' (per state): 0 .. 0.02" in out
    assert "element field 'alive': 1 in use, 0 deleted (erosion)" in out
    assert "deleted elements (erosion), per state: 0, 0, 1" in out
    assert [line for line in out if line.startswith("  part")] == ["  part 9: 0, 0, 1"]
    assert main(["info", str(tmp_path / "missing.k")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "missing.k" in err


def test_hausdorff_of_a_plate_and_its_lifted_copy(deck, tmp_path, capsys):
    lifted = tmp_path / "lifted.k"
    lifted.write_text(DECK.replace("             0.0\n", "             5.0\n"))
    assert main(["hausdorff", str(deck), str(lifted), "--width", "0"]) == 0
    out = capsys.readouterr().out
    assert "5 <= H <= 5 mm" in out and "reached" in out


def test_simplify_writes_a_surface_within_the_tolerance(tmp_path, capsys):
    # a 10 x 10 grid of unit quads, slightly curved: most of it collapses at 2 %
    rows = ["*KEYWORD", "*NODE"]
    for j in range(11):
        for i in range(11):
            z = 0.01 * (i - 5) ** 2
            rows.append(f"{j * 11 + i + 1:8d}{i:16.4f}{j:16.4f}{z:16.4f}")
    rows.append("*ELEMENT_SHELL")
    for j in range(10):
        for i in range(10):
            n = j * 11 + i + 1
            rows.append(f"{j * 10 + i + 1:8d}{1:8d}{n:8d}{n + 1:8d}{n + 12:8d}{n + 11:8d}")
    rows.append("*END")
    deck = tmp_path / "curved.k"
    deck.write_text("\n".join(rows) + "\n")
    out = tmp_path / "curved.ply"
    assert main(["simplify", str(deck), "--tol", "2", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "200 -> " in printed and out.stat().st_size > 0
    import trimesh

    from workbench.algo.hausdorff import hausdorff
    from workbench.scene.readers import load

    original = load(deck)
    simplified = trimesh.load(out, process=False)
    assert len(simplified.faces) < 200
    # the written surface is within 2 % of the bounding-sphere diameter of the original
    lo, hi = original.nodes.min(axis=0), original.nodes.max(axis=0)
    tol = 0.02 * float(np.linalg.norm(hi - lo))
    h = hausdorff(original.nodes, original.triangles, np.asarray(simplified.vertices),
                  np.asarray(simplified.faces), tol=1e-6)
    assert h.upper <= tol * (1 + 1e-6)


def test_render_reaches_a_spacetime_path(tmp_path, capsys):
    out = tmp_path / "slice.png"
    assert main(["render", "spacetime:radial:4", "--path", "spacetime_vertex", "-O",
                 "height_scale=800", "-O", "edge_overdraw=skirts", "--size", "64x64",
                 "-o", str(out)]) == 0
    image = np.asarray(Image.open(out))
    assert image.shape[:2] == (64, 64)
    assert (image[..., :3] != 255).any(axis=2).mean() > 0.8  # the plate fills the top view
    assert "path spacetime_vertex" in capsys.readouterr().out


def test_render_help_lists_every_path(capsys):
    from workbench.paths import PATHS

    with pytest.raises(SystemExit):
        main(["render", "--help"])
    printed = capsys.readouterr().out
    for name in PATHS:
        assert name in printed


@pytest.mark.parametrize("args, message", [
    (["spacetime:radial:4", "--path", "gouraud"], "draws mesh scenes"),
    (["spacetime:radial:4", "--bands", "3"], "--bands applies to the mesh paths"),
    (["semicylinders:2", "--path", "spacetime_pixel"], "draws spacetime scenes"),
    (["semicylinders:2", "-O", "glow=1"], "takes no option 'glow'"),
    (["spacetime:nowhere"], "no spacetime scene 'spacetime:nowhere'"),
    (["semicylinders:many"], "must be an integer"),
])
def test_render_refuses_mismatches_in_one_line(args, message, tmp_path, capsys):
    assert main(["render", *args, "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


FAR_DECK = """*KEYWORD
*NODE
1,1e20,0.0,0.0
2,1.00000000000001e20,0.0,0.0
3,1e20,100.0,0.0
*ELEMENT_SHELL
1,1,1,2,3,3
*END
"""


@pytest.mark.parametrize("args, message", [
    (["--size", "20000x10"], "at most"),
    (["--samples", "3"], "3 MSAA samples asked; this driver allows 0, 1"),
    (["--samples", "-1"], "-1 MSAA samples asked"),
    (["--view", "nan,nan"], "expected two finite numbers"),
    (["--view", "inf,0"], "expected two finite numbers"),
])
def test_render_refuses_what_the_driver_cannot_draw(args, message, tmp_path):
    """Each bad request ends in one line on stderr and exit status 2, never a traceback."""
    result = subprocess.run([sys.executable, "-m", "workbench.cli", "render", "semicylinders:2",
                             *args, "-o", str(tmp_path / "x.png")], capture_output=True, text=True)
    assert result.returncode == 2
    err = result.stderr.strip()
    assert message in err and len(err.splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "x.png").exists()


def test_render_refuses_coordinates_too_far_to_resolve(tmp_path, capsys):
    deck = tmp_path / "far.k"
    deck.write_text(FAR_DECK)
    assert main(["render", str(deck), "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert "magnitude 1e+20" in err and "translate it nearer the origin" in err


def test_an_include_without_its_thickness_parameter_draws_its_geometry_not_its_thickness(
        tmp_path):
    """A deck whose section thickness names a parameter it does not define (an include read
    without its master deck): the geometry is drawn with one warning line naming the
    parameter; drawing the thickness is refused in one line naming the parameter and the
    master deck to read, and nothing is written."""
    deck = tmp_path / "part.k"
    deck.write_text(DECK.replace("*NODE", "*PART\np\n         1         1\n*SECTION_SHELL\n"
                                          "         1\n&t\n*NODE"))

    def render(*options):
        out = tmp_path / "part.png"
        out.unlink(missing_ok=True)
        result = subprocess.run([sys.executable, "-m", "workbench.cli", "render", str(deck),
                                 "--size", "40x30", "-o", str(out), *options],
                                capture_output=True, text=True)
        return result, out

    result, out = render()
    assert result.returncode == 0 and out.exists()
    warned = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(warned) == 1 and f"{deck}:7: *SECTION_SHELL: parameter 't' is not defined" in \
        warned[0] and "the geometry is read" in warned[0]
    result, out = render("--field", "thickness")
    assert result.returncode == 2 and not out.exists()
    assert result.stderr.strip().splitlines()[-1] == (
        f"workbench: error: thickness cannot be drawn: {deck}:7: the thickness of part 1 uses "
        f"parameter 't', defined nowhere in this deck or its includes: read the master deck "
        f"that defines it")


@pytest.mark.parametrize("argv, message", [
    (["render", "spacetime:radial:4", "-O", "height_scale=nan", "-o", "x.png"],
     "height_scale must be non-negative and finite, got nan"),
    (["render", "spacetime:radial:4", "-O", "height_scale=abc", "-o", "x.png"],
     "height_scale must be a number, got 'abc'"),
    (["hausdorff", "semicylinders:2", "semicylinders:2", "--step", "999"],
     "--step 999 out of range"),
    (["hausdorff", "semicylinders:2", "semicylinders:2", "--step", "-1"],
     "argument --step: must be at least 0, got -1"),
    (["stress", "render", "--cycles", "0"], "argument --cycles: must be at least 1, got 0"),
    (["stress", "render", "--cycles", "-1"], "argument --cycles: must be at least 1, got -1"),
    (["stress", "readers", "--n", "-1"], "argument --n: must be at least 1, got -1"),
    (["render", "semicylinders:2", "--scheduler", "tcp://127.0.0.1:1", "-o", "x.png"],
     "--scheduler applies to sort-last rendering: give --domains D as well"),
    (["render", "semicylinders:2", "-o", "x.txt"], "render writes a PNG image"),
    (["render", "semicylinders:2", "--colormap", "nosuchmap", "-o", "x.png"],
     "unknown colormap 'nosuchmap'"),
])
def test_bad_command_lines_end_in_one_line_and_status_2(argv, message, tmp_path, capsys,
                                                        monkeypatch):
    """Each bad request is refused before anything is drawn or written: one line on stderr,
    exit status 2, no traceback and no output file."""
    monkeypatch.chdir(tmp_path)
    try:
        status = main(argv)
    except SystemExit as exc:  # argparse refuses its own arguments by exiting
        status = exc.code
    err = capsys.readouterr().err
    assert status == 2 and message in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not list(tmp_path.iterdir())


@pytest.mark.slow  # waits out the connection timeout (5 s)
def test_an_unreachable_scheduler_is_refused_soon(tmp_path, capsys):
    """Nothing listens on port 1 of the loopback: one line, status 2, well before the old
    30 s connection timeout (the bound is generous: it is the connect timeout that matters)."""
    import time

    start = time.monotonic()
    status = main(["render", "semicylinders:4", "--domains", "2", "--rasterizer", "software",
                   "--scheduler", "tcp://127.0.0.1:1", "-o", str(tmp_path / "x.png")])
    elapsed = time.monotonic() - start
    err = capsys.readouterr().err
    assert status == 2 and "127.0.0.1:1" in err and len(err.strip().splitlines()) == 1
    assert elapsed < 20 and not (tmp_path / "x.png").exists()
