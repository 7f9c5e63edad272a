"""Outputs go only to a regular file or a new path: a device, FIFO, socket, directory or
symbolic link in the way is refused in one line (exit status 2) and left as it was, and no
output folder is written through a symbolic link."""

import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest
from meshes import DECK
from PIL import Image

from workbench.cli import main
from workbench.experiment import EXPERIMENTS, experiment, run_experiment
from workbench.output.tables import atomic_open, atomic_write_bytes, atomic_write_text, write_table
from workbench.output.targets import output_folder, output_target
from workbench.results.store import ResultsStore
from workbench.sweep import load_config, run_sweep

OUTSIDE_BYTES = b"not to be touched\n"


@pytest.fixture()
def deck(tmp_path):
    path = tmp_path / "plate.k"
    path.write_text(DECK)
    return path


def render(deck, out) -> int:
    return main(["render", str(deck), "--size", "40x30", "-o", str(out)])


def fifo(path: Path) -> Path:
    os.mkfifo(path)
    return path


def outside_link(tmp_path: Path, name: str) -> Path:
    """``tmp_path/out/<name>``: a symbolic link to a file outside that folder."""
    (tmp_path / "elsewhere").mkdir(exist_ok=True)
    target = tmp_path / "elsewhere" / f"target-{name}"
    target.write_bytes(OUTSIDE_BYTES)
    (tmp_path / "out").mkdir(exist_ok=True)
    link = tmp_path / "out" / name
    link.symlink_to(target)
    return link


def kind_of(path: Path) -> str:
    mode = os.lstat(path).st_mode
    return ("link" if stat.S_ISLNK(mode) else "fifo" if stat.S_ISFIFO(mode)
            else "dir" if stat.S_ISDIR(mode) else "chr" if stat.S_ISCHR(mode)
            else "file" if stat.S_ISREG(mode) else "other")


def assert_one_line_refusal(capsys, path, kind: str) -> None:
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1, captured.err
    assert captured.err.startswith("workbench: error: ")
    assert f"{path} is a {kind}" in captured.err
    assert captured.out == ""  # nothing drawn and reported


def no_temporary_files(folder: Path) -> bool:
    return not [p for p in folder.iterdir() if p.name.endswith(".tmp")]


# ------------------------------------------------------------------ render -o


def test_render_refuses_a_fifo(deck, tmp_path, capsys):
    out = fifo(tmp_path / "out.png")
    assert render(deck, out) == 2
    assert_one_line_refusal(capsys, out, "FIFO")
    assert kind_of(out) == "fifo" and no_temporary_files(tmp_path)


def test_render_refuses_a_symlink_out_of_the_folder(deck, tmp_path, capsys):
    link = outside_link(tmp_path, "out.png")
    target = link.readlink()
    assert render(deck, link) == 2
    assert_one_line_refusal(capsys, link, "symbolic link")
    assert kind_of(link) == "link" and link.readlink() == target
    assert target.read_bytes() == OUTSIDE_BYTES


def test_render_refuses_a_directory(deck, tmp_path, capsys):
    out = tmp_path / "out.png"
    out.mkdir()
    (out / "kept").write_text("kept")
    assert render(deck, out) == 2
    assert_one_line_refusal(capsys, out, "directory")
    assert [p.name for p in out.iterdir()] == ["kept"] and no_temporary_files(tmp_path)


def test_render_refuses_dev_null(deck, capsys):
    assert render(deck, "/dev/null") == 2
    assert_one_line_refusal(capsys, "/dev/null", "character device")
    assert kind_of(Path("/dev/null")) == "chr"


def test_render_refuses_a_device_named_like_a_png(deck, tmp_path, capsys):
    # /dev/full under a .png name: the name passes the suffix check, the node must stay
    out = tmp_path / "full.png"
    try:
        os.mknod(out, stat.S_IFCHR | 0o666, os.makedev(1, 7))
    except (PermissionError, OSError) as exc:
        pytest.skip(f"cannot make a device node here: {exc}")
    assert render(deck, out) == 2
    assert_one_line_refusal(capsys, out, "character device")
    assert kind_of(out) == "chr" and os.stat(out).st_rdev == os.makedev(1, 7)


def test_render_writes_a_new_path_and_replaces_a_regular_file(deck, tmp_path):
    out = tmp_path / "new" / "out.png"
    assert render(deck, out) == 0
    first = np.asarray(Image.open(out))
    assert first.shape[:2] == (30, 40)
    out.write_bytes(b"old contents")
    assert render(deck, out) == 0
    assert kind_of(out) == "file" and (np.asarray(Image.open(out)) == first).all()


def test_results_report_refuses_a_fifo_readme_before_reading_it(tmp_path, capsys):
    readme = fifo(tmp_path / "README.md")
    status = main(["results", "report", "--readme", str(readme), "--doc",
                   str(tmp_path / "results.md"), "--results", str(tmp_path / "store")])
    assert status == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and f"{readme} is a FIFO" in captured.err
    assert kind_of(readme) == "fifo" and not (tmp_path / "results.md").exists()


# ------------------------------------------------------------------ the writers


@pytest.mark.parametrize("write", [
    lambda p: atomic_write_text(p, "text"),
    lambda p: atomic_write_bytes(p, b"bytes"),
    lambda p: atomic_open(p, "wb").__enter__(),
], ids=["text", "bytes", "open"])
def test_atomic_writers_refuse_what_is_not_a_regular_file(tmp_path, write):
    folder = tmp_path / "out"
    folder.mkdir()
    pipe = fifo(folder / "pipe.csv")
    link = outside_link(tmp_path, "link.csv")
    directory = folder / "dir.csv"
    directory.mkdir()
    for path, kind in ((pipe, "FIFO"), (link, "symbolic link"), (directory, "directory")):
        with pytest.raises(ValueError, match=re.escape(f"{path} is a {kind}")):
            write(path)
    assert kind_of(pipe) == "fifo" and kind_of(link) == "link" and kind_of(directory) == "dir"
    assert link.resolve().read_bytes() == OUTSIDE_BYTES and not list(directory.iterdir())
    assert no_temporary_files(folder)


def test_atomic_writers_write_new_and_regular_files(tmp_path):
    path = tmp_path / "table.md"
    atomic_write_text(path, "first")
    atomic_write_bytes(path, b"second")
    assert kind_of(path) == "file" and path.read_bytes() == b"second"


def test_a_fifo_put_in_place_during_the_write_is_not_replaced(tmp_path):
    path = tmp_path / "table.md"
    with pytest.raises(ValueError, match="is a FIFO"):
        with atomic_open(path, "w") as handle:
            handle.write("rows")
            os.mkfifo(path)  # appears between the first check and the replace
    assert kind_of(path) == "fifo" and no_temporary_files(tmp_path)


def test_write_table_refuses_before_writing_either_file(tmp_path):
    fifo(tmp_path / "table.md")
    with pytest.raises(ValueError, match="table.md is a FIFO"):
        write_table([{"a": 1}], tmp_path, "table")
    assert not (tmp_path / "table.csv").exists()


def test_output_folder_refuses_links_and_files(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "link").symlink_to(real)
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="link is a symbolic link"):
        output_folder(tmp_path / "link", create=True)
    with pytest.raises(ValueError, match="file is a regular file"):
        output_folder(tmp_path / "file")
    assert output_folder(tmp_path / "new" / "sub", create=True).is_dir()
    assert output_folder(real) == real and output_target(tmp_path / "file").name == "file"


# ------------------------------------------------------------------ output folders


def test_an_experiment_output_folder_that_is_a_symlink_is_refused(tmp_path):
    ran = []

    @experiment("dummy-linked-output", "one row")
    def run(exp):
        ran.append(exp.out_dir)
        return [{"case": "a"}]

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "table.csv").write_bytes(OUTSIDE_BYTES)
    figures = tmp_path / "figures"
    figures.mkdir()
    (figures / "dummy-linked-output").symlink_to(elsewhere)
    try:
        with pytest.raises(ValueError, match="dummy-linked-output is a symbolic link"):
            run_experiment("dummy-linked-output", figures, size="tiny")
    finally:
        del EXPERIMENTS["dummy-linked-output"]
    assert ran == []  # refused before it ran
    assert sorted(p.name for p in elsewhere.iterdir()) == ["table.csv"]
    assert (elsewhere / "table.csv").read_bytes() == OUTSIDE_BYTES
    assert kind_of(figures / "dummy-linked-output") == "link"
    assert [p.name for p in figures.iterdir()] == ["dummy-linked-output"]


SWEEP = """
[grid]
scene = "semicylinders:4"
path = "gouraud"
size = "32x24"
"""


@pytest.mark.parametrize("where", ["folder", "points", "table"])
def test_a_sweep_refuses_links_in_its_output_folder(tmp_path, where):
    config_path = tmp_path / "sweep.toml"
    config_path.write_text(SWEEP)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    if where == "folder":
        out.symlink_to(elsewhere)
        linked = out
    else:
        out.mkdir()
        linked = out / ("points" if where == "points" else "table.md")
        linked.symlink_to(elsewhere if where == "points" else elsewhere / "table.md")
    with pytest.raises(ValueError, match=re.escape(f"{linked} is a symbolic link")):
        run_sweep(load_config(config_path), out, workers=1, progress=False)
    assert list(elsewhere.iterdir()) == [] and kind_of(linked) == "link"


def test_the_results_store_refuses_a_linked_folder_and_a_fifo(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    store = ResultsStore(tmp_path / "store")
    (tmp_path / "store").mkdir()
    (tmp_path / "store" / "rows").symlink_to(elsewhere)
    with pytest.raises(ValueError, match="rows is a symbolic link"):
        store.append_rows("run1", [{"a": 1}])
    assert list(elsewhere.iterdir()) == []
    (tmp_path / "store" / "machines").mkdir()
    pipe = fifo(tmp_path / "store" / "machines" / "m1.parquet")
    with pytest.raises(ValueError, match="m1.parquet is a FIFO"):
        store.record_machine({"machine_id": "m1"})
    assert kind_of(pipe) == "fifo"
