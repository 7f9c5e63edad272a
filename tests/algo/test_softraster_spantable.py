"""The es2008 span look-up table against the brute-force rule (coverage_mask, 0 sub-pixel
bits): exhaustively for small sizes, by sampling for S = 10 and S = 20; its memory against
the paper; the disk cache (reload, damaged files, atomic writes); refusals."""

import os
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.softraster import spantable as stmod
from workbench.algo.softraster.rule import coverage_mask
from workbench.algo.softraster.spantable import (
    FORMAT_VERSION,
    PAPER_MB,
    SpanTable,
    build_span_table,
    cache_path,
    default_cache_dir,
    forget_tables,
    span_table,
    table_spans,
)


def expected_rows(s, tx1, ty1, tx2, ty2):
    """(lo, hi) rows of length 2s from the brute-force mask, v0 at pixel (s, s) of a 2s × 2s
    image (so a column index is tx + s); asserts each covered run is contiguous."""
    m = coverage_mask([[s, s], [s + tx1, s + ty1], [s + tx2, s + ty2]], 2 * s, 2 * s, bits=0)
    any_ = m.any(axis=1)
    first = np.where(any_, m.argmax(axis=1), -1)
    last = np.where(any_, 2 * s - 1 - m[:, ::-1].argmax(axis=1), -1)
    assert np.array_equal(m.sum(axis=1), np.where(any_, last - first + 1, 0))  # contiguous
    return first, last


def assert_matches(table_lo, table_hi, s, offsets):
    for tx1, ty1, tx2, ty2 in offsets:
        lo, hi = expected_rows(s, tx1, ty1, tx2, ty2)
        idx = (tx1 + s, ty1 + s, tx2 + s, ty2 + s)
        assert np.array_equal(table_lo[idx], lo), (tx1, ty1, tx2, ty2)
        assert np.array_equal(table_hi[idx], hi), (tx1, ty1, tx2, ty2)


@pytest.fixture
def fresh():
    """No tables held by the process before and after the test."""
    forget_tables()
    yield
    forget_tables()


@pytest.fixture(scope="module")
def table20(tmp_path_factory):
    forget_tables()
    t = span_table(20, cache_dir=tmp_path_factory.mktemp("spancache20"))
    yield t
    forget_tables()


@pytest.fixture(scope="module")
def table10():
    return build_span_table(10)


# --- the table against the rule -------------------------------------------------------------


@pytest.mark.parametrize("s", [4, 5])
def test_every_triangle_of_a_small_table_matches_the_rule(s):
    lo, hi = build_span_table(s)
    assert lo.shape == hi.shape == (2 * s,) * 5 and lo.dtype == hi.dtype == np.int8
    r = range(-s, s)
    assert_matches(lo, hi, s, [(a, b, c, d) for a in r for b in r for c in r for d in r])


def test_random_triangles_of_size_10_match_the_rule(table10):
    offsets = np.random.default_rng(2008).integers(-10, 10, size=(4000, 4))
    assert_matches(*table10, 10, offsets.tolist())


def test_random_triangles_of_size_20_match_the_rule(table20):
    assert table20.build_s is not None and table20.path is not None
    offsets = np.random.default_rng(20).integers(-20, 20, size=(2000, 4))
    assert_matches(table20.lo, table20.hi, 20, offsets.tolist())


@settings(max_examples=150, deadline=None)
@given(st.lists(st.integers(-20, 19), min_size=4, max_size=4))
def test_hypothesis_triangles_of_size_20_match_the_rule(table20, offsets):
    assert_matches(table20.lo, table20.hi, 20, [offsets])


def test_zero_area_triangles_cover_nothing_and_entries_are_consistent(table10):
    lo, hi = table10
    tx1, ty1, tx2, ty2 = np.ogrid[-10:10, -10:10, -10:10, -10:10]
    zero = tx1 * ty2 - ty1 * tx2 == 0
    assert zero.sum() > 1000
    assert (lo[zero] == -1).all() and (hi[zero] == -1).all()
    # −1 in both or in neither, first ≤ last, everything within 0..2S−1
    assert np.array_equal(lo == -1, hi == -1)
    assert (lo <= hi).all() and lo.min() == -1 and hi.max() <= 19
    # most non-degenerate triangles cover something
    assert (lo[~zero] >= 0).any(axis=-1).mean() > 0.9


def test_swapping_v1_and_v2_does_not_change_the_fill(table10):
    lo, hi = table10
    assert np.array_equal(lo, lo.transpose(2, 3, 0, 1, 4))
    assert np.array_equal(hi, hi.transpose(2, 3, 0, 1, 4))


def test_table_spans_lists_the_covered_runs(table20):
    # the paper's Fig. 4 triangle (tx1, ty1, tx2, ty2) = (10, 4, 4, 10), here with y down
    spans = table_spans(table20, 10, 4, 4, 10)
    lo, hi = expected_rows(20, 10, 4, 4, 10)
    rows = [(ty - 20, int(lo[ty]) - 20, int(hi[ty]) - 20) for ty in range(40) if lo[ty] >= 0]
    assert spans == rows
    assert [ty for ty, _, _ in spans] == list(range(spans[0][0], spans[-1][0] + 1))
    assert 0 <= spans[0][0] and spans[-1][0] <= 10  # within the bounding box
    assert all(0 <= a <= b <= 10 for _, a, b in spans)
    assert table_spans(table20, 1, 1, 2, 2) == []  # zero area


# --- memory -----------------------------------------------------------------------------------


@pytest.mark.parametrize("s", [4, 10])
def test_memory_is_two_bytes_per_scan_line_entry(fresh, s):
    t = span_table(s, cache=False)
    assert t.nbytes == 2 * (2 * s) ** 5 and t.path is None
    if s in PAPER_MB:
        assert abs(t.nbytes / 1e6 - PAPER_MB[s]) <= 0.01 * PAPER_MB[s]


def test_size_20_memory_matches_the_paper(table20):
    assert table20.nbytes == 2 * 40**5
    assert abs(table20.nbytes / 1e6 - PAPER_MB[20]) <= 0.01 * PAPER_MB[20]
    assert not table20.lo.flags.writeable and not table20.hi.flags.writeable


# --- the cache --------------------------------------------------------------------------------


def test_second_call_in_a_fresh_process_loads_from_disk(fresh, tmp_path):
    built = span_table(5, cache_dir=tmp_path)
    assert built.build_s is not None and built.build_s > 0
    assert built.path == cache_path(5, tmp_path) and built.path.is_file()
    assert f"v{FORMAT_VERSION}" in built.path.name and "S5" in built.path.name
    assert span_table(5, cache_dir=tmp_path) is built  # held by the process
    forget_tables()
    loaded = span_table(5, cache_dir=tmp_path)
    assert loaded.build_s is None and loaded.path == built.path
    assert np.array_equal(loaded.lo, built.lo) and np.array_equal(loaded.hi, built.hi)
    assert sorted(os.listdir(tmp_path)) == [built.path.name]


def test_size_20_reloads_equal(table20):
    forget_tables()
    loaded = span_table(20, cache_dir=table20.path.parent)
    assert loaded.build_s is None
    assert np.array_equal(loaded.lo, table20.lo) and np.array_equal(loaded.hi, table20.hi)
    assert os.listdir(table20.path.parent) == [table20.path.name]


def _truncate(p):
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])


def _garbage(p):
    p.write_bytes(b"not a span table" * 100)


def _wrong_shape(p):
    lo = np.full((8,) * 5, -1, np.int8)
    np.savez(p, lo=lo, hi=lo, meta=np.array([FORMAT_VERSION, 5, stmod._crc(lo, lo)]))


def _flipped_byte(p):
    with zipfile.ZipFile(p) as z:
        info = z.getinfo("lo.npy")
    data = bytearray(p.read_bytes())
    # a byte inside the stored lo array (its local header is 30 bytes + name + extra field)
    at = info.header_offset + 30 + len(info.filename) + 200 + info.file_size // 2
    data[at] ^= 0x40
    p.write_bytes(bytes(data))


def _wrong_content(p):
    # a well-formed file whose arrays no longer match the checksum recorded with them
    with np.load(p) as z:
        lo, hi, meta = np.array(z["lo"]), z["hi"], z["meta"]
    lo[1, 2, 3, 4, 5] += 1
    np.savez(p, lo=lo, hi=hi, meta=meta)


def _no_meta(p):
    lo, hi = build_span_table(5)
    np.savez(p, lo=lo, hi=hi)


@pytest.mark.parametrize("damage", [_truncate, _garbage, _wrong_shape, _flipped_byte,
                                    _wrong_content, _no_meta])
def test_damaged_cache_file_is_rebuilt(fresh, tmp_path, damage):
    good = span_table(5, cache_dir=tmp_path)
    ref_lo, ref_hi = np.array(good.lo), np.array(good.hi)
    damage(good.path)
    forget_tables()
    rebuilt = span_table(5, cache_dir=tmp_path)
    assert rebuilt.build_s is not None  # not trusted: built again
    assert np.array_equal(rebuilt.lo, ref_lo) and np.array_equal(rebuilt.hi, ref_hi)
    forget_tables()
    assert span_table(5, cache_dir=tmp_path).build_s is None  # and the file repaired
    assert os.listdir(tmp_path) == [good.path.name]


@pytest.mark.parametrize("error", [OSError("disk full"), KeyboardInterrupt()])
def test_interrupted_write_leaves_no_file(fresh, tmp_path, monkeypatch, error):
    def dies_midway(f, **arrays):
        f.write(b"PK\x03\x04 partial")
        raise error

    monkeypatch.setattr(stmod.np, "savez", dies_midway)
    if isinstance(error, OSError):
        with pytest.warns(RuntimeWarning, match="not cached"):
            t = span_table(5, cache_dir=tmp_path)
        assert t.path is None and t.build_s is not None
        assert np.array_equal(t.lo, build_span_table(5)[0])
    else:
        with pytest.raises(KeyboardInterrupt):
            span_table(5, cache_dir=tmp_path)
    assert os.listdir(tmp_path) == []  # neither the final name nor a temporary file


def test_interrupted_rewrite_keeps_the_old_file(fresh, tmp_path, monkeypatch):
    good = span_table(5, cache_dir=tmp_path)
    _garbage(good.path)
    forget_tables()

    def dies_midway(f, **arrays):
        f.write(b"partial")
        raise OSError("disk full")

    monkeypatch.setattr(stmod.np, "savez", dies_midway)
    with pytest.warns(RuntimeWarning, match="not cached"):
        span_table(5, cache_dir=tmp_path)
    assert good.path.read_bytes() == b"not a span table" * 100  # untouched, not half-written
    assert os.listdir(tmp_path) == [good.path.name]


def test_cache_folder_from_the_environment(fresh, tmp_path, monkeypatch):
    monkeypatch.delenv("WORKBENCH_CACHE", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert default_cache_dir() == tmp_path / "home" / ".cache" / "workbench"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert default_cache_dir() == tmp_path / "xdg" / "workbench"
    monkeypatch.setenv("WORKBENCH_CACHE", str(tmp_path / "wb"))
    assert default_cache_dir() == tmp_path / "wb"
    t = span_table(4)
    assert t.path == tmp_path / "wb" / f"spantable-v{FORMAT_VERSION}-S4.npz" and t.path.is_file()


def test_uncached_table_writes_nothing(fresh, tmp_path, monkeypatch):
    monkeypatch.setenv("WORKBENCH_CACHE", str(tmp_path))
    t = span_table(4, cache=False)
    assert isinstance(t, SpanTable) and t.path is None and t.build_s is not None
    assert os.listdir(tmp_path) == []
    # a later cached call stores the table held by the process instead of building again
    cached = span_table(4)
    assert cached.lo is t.lo and cached.path is not None and cached.path.is_file()


# --- refusals ---------------------------------------------------------------------------------


@pytest.mark.parametrize("size", [0, 1, 64, 100, -3, 2.5, 10.0, "10", True, None])
def test_bad_sizes_are_refused(size):
    with pytest.raises(ValueError, match=r"integer in 2\.\.63"):
        span_table(size, cache=False)
    with pytest.raises(ValueError, match=r"integer in 2\.\.63"):
        build_span_table(size)


@pytest.mark.parametrize("offsets", [(10, 0, 0, 1), (0, -11, 0, 1), (0, 0, 1.5, 1)])
def test_offsets_outside_the_table_are_refused(fresh, offsets):
    t = span_table(10, cache=False)
    with pytest.raises(ValueError, match="offsets must be integers in -10..9"):
        table_spans(t, *offsets)
