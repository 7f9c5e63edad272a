"""Timing that states its uncertainty: the stopping rule in the timing functions, interleaved
ratios (and why they are interleaved), and GPU times only where they mean something."""

import time

import numpy as np
import pytest

from workbench.experiment.context import ExperimentContext
from workbench.gl.context import timer_queries_meaningful
from workbench.measurement.interleave import Clock, draw_clock, interleaved_ratios, time_interleaved
from workbench.measurement.rows import measure
from workbench.measurement.stats import StoppingRule
from workbench.measurement.timing import EMPTY_GPU_NOTE, empty_gpu_note, time_call
from workbench.paths import Style, prepared
from workbench.scene import generators


def busy(ms: float) -> None:
    """Spin for ``ms`` milliseconds (a sleep would yield to the noisy scheduler)."""
    end = time.perf_counter() + ms / 1e3
    while time.perf_counter() < end:
        pass


# ---------------------------------------------------------------- the stopping rule
def test_time_call_stops_early_on_steady_work_and_at_the_maximum_on_noisy_work():
    steady = time_call(lambda: busy(1.0), warmup=0, repeat=5,
                       stop=StoppingRule(rel_half_width=0.2, min_samples=5, max_samples=40))
    assert 6 <= steady.repeats < 40  # n = 5 cannot reach 95 %: at least 6
    assert steady.wall_ms_lo <= steady.wall_ms <= steady.wall_ms_hi
    assert (steady.wall_ms_hi - steady.wall_ms_lo) / 2 <= 0.2 * steady.wall_ms
    rng = np.random.default_rng(1)
    noisy = time_call(lambda: busy(float(rng.choice([0.2, 2.0]))), warmup=0, repeat=5,
                      stop=StoppingRule(rel_half_width=0.01, min_samples=5, max_samples=12))
    assert noisy.repeats == 12 and len(noisy.wall_samples_ms) == 12


def test_without_a_rule_the_count_is_exactly_repeat():
    t = time_call(lambda: None, warmup=2, repeat=7)
    assert t.repeats == 7 and len(t.wall_samples_ms) == 7


# ---------------------------------------------------------------- interleaved ratios
def test_interleaved_rounds_run_the_clocks_in_turn():
    order = []
    clocks = {name: Clock(lambda n=name: order.append(n), lambda n=name: order.append(f"set {n}"))
              for name in ("a", "b")}
    times = time_interleaved(clocks, [("a", "b")], StoppingRule(1.0, 5, 5), warmup=1)
    assert len(times["a"]) == len(times["b"]) == 5
    assert order == ["set a", "a", "set b", "b"] * 6


def test_interleaving_cancels_a_drift_that_biases_sequential_timing():
    """The machine slows down while measuring (each call 5 % slower than the one before): A
    takes twice B at any moment. Timed in turn, the ratio is 2 within its interval; timed one
    after the other, far from it."""
    calls = [0]

    def work(ms: float) -> None:
        calls[0] += 1
        busy(ms * (1.0 + 0.05 * calls[0]))

    clocks = {"a": Clock(lambda: work(2.0)), "b": Clock(lambda: work(1.0))}
    ratio = interleaved_ratios(clocks, [("a", "b")],
                               StoppingRule(0.05, min_samples=20, max_samples=20))[("a", "b")]
    assert ratio.interval.n == 20
    # per pair B runs one call later: 2 (1 + .05 k) / (1 + .05 (k + 1)) is within 4 % of 2
    assert 1.85 <= ratio.interval.lo and ratio.interval.hi <= 2.05

    calls[0] = 0
    a = time_call(lambda: work(2.0), warmup=0, repeat=20)
    b = time_call(lambda: work(1.0), warmup=0, repeat=20)
    assert a.wall_ms / b.wall_ms < 1.5  # sequential: about 2 · 1.525 / 2.525 = 1.21


def test_ratios_must_name_given_clocks():
    with pytest.raises(ValueError, match="not given"):
        time_interleaved({"a": Clock(lambda: None)}, [("a", "b")], StoppingRule())


@pytest.mark.gl
def test_interleaved_draws_each_leave_their_own_image(ctx):
    mesh = generators.semicylinders(n=4)
    flat, bands = Style(), Style(field="distance", bands=5)
    with prepared(ctx, mesh, "flat", flat, size=(64, 48)) as a, \
            prepared(ctx, mesh, "pixel_color", bands, size=(64, 48)) as b:
        ratio = interleaved_ratios({"flat": draw_clock(a), "bands": draw_clock(b)},
                                   [("bands", "flat")], StoppingRule(1.0, 5, 6))
        images = a.target.read(), b.target.read()
    assert ratio[("bands", "flat")].interval.n >= 5
    for image, (name, style) in zip(images, (("flat", flat), ("pixel_color", bands))):
        alone = measure(ctx, mesh, name, style, size=(64, 48), timed=False).image
        assert np.array_equal(image, alone)


# ---------------------------------------------------------------- GPU time
@pytest.mark.gl
def test_measure_states_its_interval_and_gpu_time_only_where_meaningful(ctx):
    mesh = generators.semicylinders(n=2)
    row = measure(ctx, mesh, "flat", size=(32, 24), repeats=5,
                  stop=StoppingRule(0.5, min_samples=5, max_samples=9)).row
    assert 5 <= row["repeats"] <= 9 and len(row["wall_samples_ms"]) == row["repeats"]
    assert row["wall_ms_min"] <= row["wall_ms_lo"] <= row["wall_ms"] <= row["wall_ms_hi"]
    if timer_queries_meaningful(ctx):
        assert row["gpu_ms"] is not None and row["gpu_ms"] >= 0
    else:
        assert row["gpu_ms"] is None and row["gpu_ms_min"] is None


SOFTWARE = "llvmpipe (LLVM 15.0.6, 256 bits)"


def test_empty_gpu_columns_on_a_software_renderer_get_a_note():
    rows = [{"renderer": SOFTWARE, "gpu_ms": None, "draw_gpu_ms": None, "wall_ms": 1.0}]
    (note,) = empty_gpu_note(rows)
    assert note == EMPTY_GPU_NOTE.format(columns="draw_gpu_ms, gpu_ms", renderers=SOFTWARE)
    # a value, a GPU renderer, or no GPU column: no note
    assert empty_gpu_note([{**rows[0], "gpu_ms": 0.5}]) == []
    assert empty_gpu_note([{**rows[0], "renderer": "NVIDIA H200/PCIe/SSE2"}]) == []
    assert empty_gpu_note([{"renderer": SOFTWARE, "wall_ms": 1.0}]) == []
    # rows without a renderer column: the run's renderer, where it is known
    assert empty_gpu_note([{"draw_gpu_ms": None}], SOFTWARE) != []
    assert empty_gpu_note([{"draw_gpu_ms": None}]) == []


def test_experiment_tables_say_why_gpu_time_is_empty(tmp_path):
    exp = ExperimentContext("x", tmp_path, "tiny")
    exp.table([{"renderer": SOFTWARE, "gpu_ms": None, "wall_ms": 1.0,
                "wall_samples_ms": (1.0, 1.1)}], "t", "T")
    text = (tmp_path / "t.md").read_text()
    assert "gpu_ms empty: llvmpipe" in text and "wall_samples_ms" not in text
    assert "wall_samples_ms" not in (tmp_path / "t.csv").read_text()
    assert exp.tables == [("t", [{"renderer": SOFTWARE, "gpu_ms": None, "wall_ms": 1.0,
                                  "wall_samples_ms": (1.0, 1.1)}])]
