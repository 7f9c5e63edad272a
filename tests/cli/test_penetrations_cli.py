"""``workbench penetrations``: the summary, the CSV and Markdown tables and the picture of a
deck with a known answer, and one-line refusals with exit status 2."""

import csv

import numpy as np
import pytest
from penetration_decks import deck_text, parallel_sheets
from PIL import Image

from workbench.cli import main


@pytest.fixture()
def deck(tmp_path):
    """The 5 mm and 3 mm sheets 3 mm apart: 42 nodes penetrate by 1 mm."""
    path = tmp_path / "sheets.k"
    path.write_text(deck_text(parallel_sheets(3.0), [5.0, 3.0]))
    return path


def test_summary_and_tables(deck, tmp_path, capsys):
    out_csv, out_md = tmp_path / "p.csv", tmp_path / "p.md"
    assert main(["penetrations", str(deck), "--csv", str(out_csv), "--md", str(out_md),
                 "--limit", "3"]) == 0
    text = capsys.readouterr().out
    assert "66 nodes checked" in text and "42 penetrating nodes" in text
    assert "largest depth 1 mm" in text and "the 3 deepest of 42 rows" in text
    with open(out_csv, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 42
    assert list(rows[0]) == ["node", "part", "other_part", "element", "distance", "depth",
                             "node_thickness", "element_thickness"]
    assert {(r["part"], r["other_part"]) for r in rows} == {("1", "2"), ("2", "1")}
    assert np.allclose([float(r["depth"]) for r in rows], 1.0, rtol=0, atol=1e-11)
    assert {int(r["node"]) for r in rows if r["part"] == "1"} == {
        n for n, x, _, _ in parallel_sheets(3.0)[0][0] if 20 <= x <= 50}
    md = out_md.read_text()
    assert md.startswith("# Initial penetrations of sheets.k") and md.count("\n|") == 42 + 2
    assert "- `depth` (mm): penetration depth" in md
    assert not list(tmp_path.glob(".*.tmp"))  # written whole, nothing left behind


def test_no_penetration_writes_empty_tables(tmp_path, capsys):
    path = tmp_path / "clear.k"
    path.write_text(deck_text(parallel_sheets(1.5), [0.8, 0.8]))
    out_csv = tmp_path / "p.csv"
    assert main(["penetrations", str(path), "--csv", str(out_csv)]) == 0
    assert "0 penetrating nodes, none" in capsys.readouterr().out
    assert out_csv.read_text().splitlines() == [
        "node,part,other_part,element,distance,depth,node_thickness,element_thickness"]


def test_picture(ctx, deck, tmp_path):
    out = tmp_path / "p.png"
    assert main(["penetrations", str(deck), "--image", str(out), "--size", "120x80",
                 "--view", "0,90"]) == 0
    image = np.asarray(Image.open(out))
    assert image.shape[0] >= 80 and image.shape[1] > 120  # the image and its colour bar


def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.k"
    bad.write_text("*NODE\n       1             abc             0.0             0.0\n")
    assert main(["penetrations", str(bad)]) == 2
    assert main(["penetrations", str(tmp_path / "missing.k")]) == 2
    include = tmp_path / "include.k"
    include.write_text(deck_text(parallel_sheets(3.0), ["&tsheet", 3.0]))
    assert main(["penetrations", str(include)]) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if not line.startswith("workbench: warning")]
    assert len(lines) == 3 and all(line.startswith("workbench: ") for line in lines)
    assert "'tsheet'" in lines[2] and "master deck" in lines[2]
