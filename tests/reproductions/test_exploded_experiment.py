"""The fig_exploded experiment end to end: its tables and figures at the tiny size (every table,
row kind and column), and what its tables show at the quick size (marked slow)."""

import pytest
from declared import assert_declared_tables
from PIL import Image

import workbench.data
from workbench.experiment.registry import discover, run_experiment
from workbench.output.tables import read_table


def _run(root, size):
    discover()
    return run_experiment("fig_exploded", figures_root=root, size=size)


@pytest.fixture(scope="module")
def tiny(experiment_run):
    return experiment_run("fig_exploded", "tiny")


@pytest.fixture(scope="module")
def result(experiment_run):
    return experiment_run("fig_exploded", "quick")


def _box(rows):
    return [r for r in rows if r["scene"] == "box"]


# ---------------------------------------------------------------------------- tiny size
def test_tiny_writes_every_table_with_its_declared_columns(tiny):
    out_dir = tiny[1]
    car = {"car_parts"} if (out_dir / "car_parts.csv").exists() else set()
    assert_declared_tables("fig_exploded", out_dir, {"table", "compare"} | car)


def test_tiny_writes_the_car_tables_and_rows(tiny, car_deck):
    rows, out_dir = tiny
    assert_declared_tables("fig_exploded", out_dir)  # car_parts among them
    assert {r["scene"] for r in rows} == {"box", "car"}
    assert {r["scene"] for r in read_table(out_dir / "compare.csv")} == {"box", "car"}


def test_sweep_covers_both_planes_exponents_and_angles(tiny):
    rows, _ = tiny
    box = _box(rows)
    for plane in ("manual", "auto"):
        for exponent in (1.0, 0.5):
            assert sorted(r["sweep_deg"] for r in box if r["plane"] == plane and
                          r["ratio_exponent"] == exponent) == [0, 20, 40, 60, 75, 85]
    for r in rows:
        assert 0.0 <= r["final_r"] <= 1.0 and 0.5 <= r["final_alpha"] <= 1.0
        assert 0.0 <= r["final_offset_over_o_max"] <= 1.0
        assert r["occlusion_wall_ms"] is not None and r["draw_wall_ms"] > 0
        assert r["separate_pass_wall_ms"] > 0


def test_one_comparison_per_angle_on_the_box(tiny):
    _, out_dir = tiny
    compare = [r for r in read_table(out_dir / "compare.csv") if r["scene"] == "box"]
    assert len(compare) == 6


def test_figures(tiny):
    rows, out_dir = tiny
    names = ["strip_box.png", "box.gif"]
    if any(r["scene"] == "car" for r in rows):
        names += ["strip_car.png", "car.gif"]
    for name in names:
        assert (out_dir / name).stat().st_size > 0
    for gif in [n for n in names if n.endswith(".gif")]:
        with Image.open(out_dir / gif) as im:
            assert im.n_frames > 1


def test_car_rows_name_their_focus(tiny, car_deck):
    rows, out_dir = tiny
    car = [r for r in rows if r["scene"] == "car"]
    assert len(car) == 24
    parts = read_table(out_dir / "car_parts.csv")
    hidden = max(parts, key=lambda p: (p["r"], p["p_unocc"]))
    assert hidden["r"] == 1.0
    assert {r["focus_part"] for r in car} == {hidden["part"]}


def test_no_car_rows_without_the_shared_deck(tmp_path, monkeypatch):
    monkeypatch.setattr(workbench.data, "shared_data_dir", lambda: None)
    rows, _ = _run(tmp_path, "tiny")
    assert rows and not [r for r in rows if r["scene"] == "car"]


# ---------------------------------------------------------------------------- quick size
@pytest.mark.slow
def test_box_reveals_within_30_frames_up_to_60_degrees(result):
    # the default speed ∝ √r up to 60 degrees; the thesis's ∝ r up to 40
    rows, _ = result
    for r in _box(rows):
        limit = 60 if r["ratio_exponent"] == 0.5 else 40
        if r["sweep_deg"] <= limit or r["plane"] == "auto":
            assert isinstance(r["frames_to_reveal"], int), r
            assert r["frames_to_reveal"] <= 30, r
            assert r["offset_at_reveal_over_o_max"] <= 1.0
            # halted once revealed: the focus stays fully visible
            assert r["final_phase"] == "hold" and r["final_r"] == 0.0, r
            # every frame was counted as it was drawn
            assert r["counted_in_frame_pct"] == 100.0


@pytest.mark.slow
def test_thesis_ratio_takes_more_than_30_frames_at_60_degrees(result):
    rows, _ = result
    row = next(r for r in _box(rows) if r["sweep_deg"] == 60 and r["plane"] == "manual" and
           r["ratio_exponent"] == 1.0)
    assert not isinstance(row["frames_to_reveal"], int) or row["frames_to_reveal"] > 30


@pytest.mark.slow
def test_box_reveal_offset_matches_closed_form(result):
    rows, _ = result
    for r in _box(rows):
        if r["plane"] == "manual" and r["closed_form_reveal_over_o_max"] <= 1.0:
            measured = r["measured_reveal_over_o_max"]
            assert measured is not None
            # r <= 0.01 allows a sliver: measured slightly below the exact offset
            assert 0.9 * r["closed_form_reveal_over_o_max"] <= measured <= \
                r["closed_form_reveal_over_o_max"] * 1.01 + 1e-3
        elif r["plane"] == "manual":  # needs more than o_max: ghosting shows the object
            assert r["frames_to_reveal"] == "not within 40"
            assert r["visible_through_ghost_pct"] >= 99.0 and r["final_alpha"] < 0.8


@pytest.mark.slow
def test_occlusion_driven_reveals_at_least_uniform_on_the_box(result):
    _, out_dir = result
    compare = [r for r in read_table(out_dir / "compare.csv") if r["scene"] == "box"]
    assert len(compare) == 6
    for r in compare:
        assert r["occlusion_driven_revealed"] >= r["uniform_revealed"], r
        assert r["occlusion_driven_revealed"] >= r["fixed_offset_manual_plane_revealed"], r
