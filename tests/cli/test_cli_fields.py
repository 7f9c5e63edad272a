"""The field options of ``workbench render`` and ``animate`` on a d3plot: the help lists the
fields, ``info`` names those a file offers, ``--layer``, ``--smooth``, ``--envelope`` and
``--relative-to`` draw, and every refusal is one line with exit status 2."""

import numpy as np
import pytest
from meshes import DECK, write_rich_d3plot
from PIL import Image

from workbench.cli import main
from workbench.scene.readers.d3plot_fields import FIELDS


@pytest.fixture(scope="module")
def rich(tmp_path_factory):
    return write_rich_d3plot(tmp_path_factory.mktemp("rich") / "run")


def test_render_help_lists_every_field_and_what_is_done_to_it(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["render", "--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    for name, what in FIELDS.items():
        assert f"  {name}" in out and what in out, name
    for option in ("--layer", "--smooth", "--envelope", "--relative-to", "NAME_minus_stateK",
                   "NAME_smooth"):
        assert option in out


def test_info_lists_the_fields_the_file_offers(rich, capsys):
    assert main(["info", str(rich)]) == 0
    lines = capsys.readouterr().out.splitlines()
    offered = next(line for line in lines if line.startswith("fields on request"))
    names = offered.split(": ", 1)[1].split(", ")
    assert {"velocity", "acceleration_z", "displacement", "principal_max", "principal_min",
            "max_shear", "pressure", "triaxiality", "signed_von_mises"} <= set(names)
    assert "von_mises" not in names  # read by default: listed with its range above
    assert any(line.startswith("element field 'von_mises'") for line in lines)


def test_the_built_in_d3plot_offers_its_fields_and_layers(d3plot_file, tmp_path, capsys):
    # the built-in scene name reads the shared result as its file would be read
    assert main(["info", "d3plot"]) == 0
    offered = next(line for line in capsys.readouterr().out.splitlines()
                   if line.startswith("fields on request"))
    assert "principal_max" in offered and "displacement" in offered
    out = tmp_path / "p.png"
    assert main(["render", "d3plot", "--field", "principal_max", "--layer", "max", "--raw",
                 "--size", "40x30", "-o", str(out)]) == 0
    assert out.is_file()


def refused_in_one_line(capsys, argv, *words) -> str:
    """Run ``argv``, which must end with exit status 2 and one line on stderr naming
    ``words``."""
    try:
        status = main(argv)
    except SystemExit as exc:  # the parser's refusals
        status = exc.code
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1, err
    for word in words:
        assert word in err, err
    return err


def test_bad_field_options_are_refused_in_one_line(rich, tmp_path, capsys):
    out = str(tmp_path / "x.png")
    deck = tmp_path / "plate.k"
    deck.write_text(DECK)
    renamed = write_rich_d3plot(tmp_path / "renamed", rename_node=(101, 999))
    refused_in_one_line(capsys, ["render", str(rich), "--field", "von_mises", "--layer",
                                 "outer", "-o", out], "invalid choice: 'outer'")
    refused_in_one_line(capsys, ["render", str(deck), "--layer", "top", "-o", out],
                        "--layer applies to d3plot results")
    refused_in_one_line(capsys, ["render", str(rich), "--field", "von_mises", "--relative-to",
                                 "state:first", "-o", out], "state:K")
    refused_in_one_line(capsys, ["render", str(rich), "--field", "von_mises", "--relative-to",
                                 "state:4", "-o", out], "state 4 out of range")
    refused_in_one_line(capsys, ["render", str(rich), "--field", "displacement",
                                 "--relative-to", str(renamed), "-o", out],
                        "node ids do not match", "101")
    refused_in_one_line(capsys, ["render", str(rich), "--field", "von_mises", "--relative-to",
                                 str(tmp_path / "missing" / "d3plot"), "-o", out], "missing")
    refused_in_one_line(capsys, ["render", str(rich), "--smooth", "-o", out],
                        "--smooth changes the field drawn: give --field")
    refused_in_one_line(capsys, ["render", str(rich), "--field", "speed", "-o", out],
                        "no field 'speed'")
    refused_in_one_line(capsys, ["animate", str(rich), "--field", "von_mises", "--layer",
                                 "side", "-o", str(tmp_path / "x.gif")], "invalid choice")
    assert not (tmp_path / "x.png").exists()


def test_render_draws_a_derived_smoothed_field_of_a_layer(rich, tmp_path, capsys):
    out = tmp_path / "smooth.png"
    assert main(["render", str(rich), "--field", "principal_max", "--layer", "max",
                 "--relative-to", "state:0", "--envelope", "--smooth", "--step", "2",
                 "--size", "120x90", "-o", str(out)]) == 0
    assert "path pixel_color" in capsys.readouterr().out
    image = np.asarray(Image.open(out))
    assert (image[..., :3] != 255).any(axis=2).sum() > 1000


def test_smooth_fringes_do_not_mix_parts(tmp_path, capsys):
    """Two parts side by side sharing an edge, thickness 1 and 2 (an element field): averaged
    per part, every drawn pixel has the colour of 1 or of 2 (a smooth colour scale), while
    averaging across the parts would give the shared edge's nodes 1.5 and a gradient of
    colours on both sides."""
    from lasso.dyna import ArrayType, D3plot

    plot = D3plot()
    coords = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0]],
                      np.float32)
    plot.arrays[ArrayType.node_coordinates] = coords
    plot.arrays[ArrayType.node_ids] = np.arange(1, 7, dtype=np.int32)
    plot.arrays[ArrayType.element_shell_node_indexes] = np.array([[0, 1, 4, 3], [1, 2, 5, 4]],
                                                                 np.int32)
    plot.arrays[ArrayType.element_shell_part_indexes] = np.array([0, 1], np.int32)
    plot.arrays[ArrayType.element_shell_ids] = np.array([1, 2], np.int32)
    plot.arrays[ArrayType.part_ids] = np.array([1, 2], np.int32)
    plot.arrays[ArrayType.global_timesteps] = np.array([0.0], np.float32)
    plot.arrays[ArrayType.node_displacement] = coords[None]
    plot.arrays[ArrayType.element_shell_thickness] = np.array([[1.0, 2.0]], np.float32)
    plot.arrays[ArrayType.element_shell_stress] = np.zeros((1, 2, 3, 6), np.float32)
    plot.arrays[ArrayType.element_shell_effective_plastic_strain] = np.zeros((1, 2, 3),
                                                                             np.float32)
    (tmp_path / "two").mkdir()
    path = tmp_path / "two" / "d3plot"
    plot.write_d3plot(str(path))
    out = tmp_path / "two.png"
    assert main(["render", str(path), "--field", "thickness", "--smooth",
                 "--view", "0,0", "--up", "y", "--size", "120x60", "--raw",
                 "-o", str(out)]) == 0
    rgb = np.asarray(Image.open(out))[..., :3].reshape(-1, 3)
    drawn = rgb[(rgb != 255).any(axis=1)]
    colours = {tuple(c) for c in drawn.tolist()}
    assert len(drawn) > 3000 and len(colours) == 2, colours
