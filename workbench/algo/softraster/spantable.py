"""The span look-up table of es2008 (Kawai et al., section 2.4): the covered run of every scan
line of every small triangle, indexed by the triangle's integer vertex offsets.

With 0 sub-pixel bits (see :mod:`.rule`) the vertices lie on pixel centres, so the pixels a
triangle covers, taken relative to its vertex v0, depend only on the offsets
``(tx1, ty1) = v1 − v0`` and ``(tx2, ty2) = v2 − v0`` (image coordinates: x to the right, y
*down*, in pixels). Pixel (tx, ty) relative to v0 is covered exactly when
:func:`.rule.coverage_mask` (``bits = 0``) covers it — the same edge functions and the same tie
rule, evaluated here in exact integer arithmetic per scan line.

* **Layout.** Two int8 arrays ``lo`` and ``hi`` of shape ``(2S, 2S, 2S, 2S, 2S)`` for the
  threshold size ``S``, indexed ``[tx1 + S, ty1 + S, tx2 + S, ty2 + S, ty + S]`` for offsets
  and scan line ``ty`` (the pixel row relative to v0's row) in ``[−S, S − 1]``. An entry is
  ``first covered tx + S`` (``lo``) and ``last covered tx + S`` (``hi``) of that scan line;
  ``−1`` in both where the line covers nothing, and everywhere for a zero-area triangle. A
  covered run is contiguous (the triangle is convex), so the pair describes it exactly, and
  covered pixels lie in the vertices' bounding box, so ``tx, ty ∈ [−S, S − 1]`` always.
  This is the paper's ``ScanLineMinTx`` / ``ScanLineMaxTx``, except that y points down (the
  paper draws y up) and the fill rule is this project's, not the paper's.
* **Memory.** ``2·(2S)^5`` bytes: 6.4 MB, 49 MB and 205 MB for S = 10, 15 and 20 (MB = 10^6
  bytes), the figures of the paper (:data:`PAPER_MB`).
* **Cache.** A table is built once per process (numba, parallel over ``tx1``; about a second
  for S = 20) and kept on disk as ``spantable-v<FORMAT_VERSION>-S<S>.npz`` under the cache
  folder: ``$WORKBENCH_CACHE`` if set, else ``$XDG_CACHE_HOME/workbench``, else
  ``~/.cache/workbench``. The file is written to a temporary file in the same folder and
  renamed over the final name (``os.replace``), so an interrupted write never leaves a partial
  table under that name. A file that cannot be read, has the wrong shape, dtype or size, or
  fails its CRC-32 is rebuilt and replaced, never trusted. A folder that cannot be written
  only costs the disk copy (a warning); the table is still returned. So does a cache path that
  exists and is not a regular file (a FIFO, a device, a folder, a symbolic link): it is never
  replaced, and is read only where a regular file lies behind its links.
* **Refused** (ValueError): a size that is not an integer in 2..63 (int8 must hold
  ``2S − 1``), and offsets outside ``[−S, S − 1]`` in :func:`table_spans`.
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

from .rule import edge_bias

FORMAT_VERSION = 1  # bump when the rule or the layout changes: old cache files are ignored
MIN_SIZE, MAX_SIZE = 2, 63
PAPER_MB = {10: 6.4, 15: 49.0, 20: 205.0}  # es2008 section 2.4, table sizes in 10^6 bytes


def check_size(size) -> int:
    """``size`` as an int in 2..63; ValueError otherwise."""
    ok = isinstance(size, (int, np.integer)) and not isinstance(size, (bool, np.bool_))
    if not ok or not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(
            f"span table size must be an integer in {MIN_SIZE}..{MAX_SIZE} "
            f"(int8 must hold 2*size - 1), got {size!r}"
        )
    return int(size)


@numba.njit(cache=True, parallel=True)
def _build_kernel(s, lo, hi):
    """Fill ``lo``, ``hi`` (int8, (2s,)*5) in place; exact int64 arithmetic."""
    n = 2 * s
    for i in numba.prange(n):
        ax = np.zeros(3, np.int64)
        ay = np.zeros(3, np.int64)
        ex = np.zeros(3, np.int64)
        ey = np.zeros(3, np.int64)
        eb = np.zeros(3, np.int64)
        for j in range(n):
            for k in range(n):
                for m in range(n):
                    x1, y1 = np.int64(i - s), np.int64(j - s)
                    x2, y2 = np.int64(k - s), np.int64(m - s)
                    area = x1 * y2 - y1 * x2
                    if area == 0:
                        for r in range(n):
                            lo[i, j, k, m, r] = -1
                            hi[i, j, k, m, r] = -1
                        continue
                    if area < 0:  # positive orientation, as rule.oriented: swap v1 and v2
                        x1, y1, x2, y2 = x2, y2, x1, y1
                    # edges v0→v1, v1→v2, v2→v0: start (ax, ay), direction (ex, ey), tie bias
                    ax[0], ay[0], ex[0], ey[0] = 0, 0, x1, y1
                    ax[1], ay[1], ex[1], ey[1] = x1, y1, x2 - x1, y2 - y1
                    ax[2], ay[2], ex[2], ey[2] = x2, y2, -x2, -y2
                    for e in range(3):
                        eb[e] = edge_bias(ex[e], ey[e])
                    for r in range(n):
                        py = np.int64(r - s)
                        left, right = -s, s - 1
                        for e in range(3):
                            dx, dy = ex[e], ey[e]
                            # covered ⇔ E − bias = c − dy·px ≥ 0 with
                            # E = dx·(py − ay) − dy·(px − ax)
                            c = dx * (py - ay[e]) + dy * ax[e] - eb[e]
                            if dy > 0:  # px ≤ c / dy
                                right = min(right, c // dy)  # floor (Python semantics)
                            elif dy < 0:  # px ≥ c / dy = ceil(c / dy)
                                left = max(left, -(c // (-dy)))
                            elif c < 0:  # horizontal edge: the whole row or nothing
                                left, right = 1, 0
                        if left <= right:
                            lo[i, j, k, m, r] = left + s
                            hi[i, j, k, m, r] = right + s
                        else:
                            lo[i, j, k, m, r] = -1
                            hi[i, j, k, m, r] = -1


def build_span_table(size: int) -> tuple[np.ndarray, np.ndarray]:
    """The int8 arrays ``(lo, hi)`` of shape ``(2S,)*5`` for ``S = size`` (layout in the module
    docstring), computed now; nothing is cached."""
    s = check_size(size)
    shape = (2 * s,) * 5
    lo = np.empty(shape, np.int8)
    hi = np.empty(shape, np.int8)
    _build_kernel(s, lo, hi)
    return lo, hi


@dataclass(frozen=True)
class SpanTable:
    """A span table: ``size`` S, arrays ``lo`` / ``hi`` (read-only int8, see module docstring),
    ``build_s`` (seconds the build took; None when it was loaded from the cache) and ``path``
    (the cache file it is stored in, or None)."""

    size: int
    lo: np.ndarray
    hi: np.ndarray
    build_s: float | None
    path: Path | None

    @property
    def nbytes(self) -> int:
        """Bytes of ``lo`` and ``hi`` together: ``2·(2S)^5``."""
        return int(self.lo.nbytes + self.hi.nbytes)


_TABLES: dict[int, SpanTable] = {}  # the tables of this process, by size


def forget_tables() -> None:
    """Drop the tables held by this process (the disk cache is left as it is)."""
    _TABLES.clear()


def default_cache_dir() -> Path:
    """``$WORKBENCH_CACHE``, else ``$XDG_CACHE_HOME/workbench``, else ``~/.cache/workbench``."""
    if os.environ.get("WORKBENCH_CACHE"):
        return Path(os.environ["WORKBENCH_CACHE"])
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"]) / "workbench"
    return Path.home() / ".cache" / "workbench"


def cache_path(size: int, cache_dir=None) -> Path:
    """The cache file of the size-``size`` table under ``cache_dir`` (default:
    :func:`default_cache_dir`)."""
    folder = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    return folder / f"spantable-v{FORMAT_VERSION}-S{check_size(size)}.npz"


def _crc(lo: np.ndarray, hi: np.ndarray) -> int:
    return zlib.crc32(np.ascontiguousarray(hi).data, zlib.crc32(np.ascontiguousarray(lo).data))


def _load(path: Path, size: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The arrays stored at ``path`` if they are a valid size-``size`` table, else None."""
    shape = (2 * size,) * 5
    if not path.is_file():
        return None  # opening a FIFO or a device would block or read without end
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = z["meta"]
            lo, hi = z["lo"], z["hi"]
        ok = (
            meta.shape == (3,)
            and int(meta[0]) == FORMAT_VERSION
            and int(meta[1]) == size
            and lo.shape == shape
            and hi.shape == shape
            and lo.dtype == np.int8
            and hi.dtype == np.int8
            and int(meta[2]) == _crc(lo, hi)
        )
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile, zlib.error):
        # missing, unreadable, truncated, not a zip, failed zip CRC, missing member: rebuild
        return None
    return (lo, hi) if ok else None


def _refuse_non_regular(path: Path) -> Path:
    """``path`` where it is a regular file or absent; ValueError for anything else (a symbolic
    link, folder, FIFO, device), which the cache never replaces."""
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise ValueError(f"{path} exists and is not a regular file")
    return path


def _save(path: Path, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Write the table atomically (temporary file in the same folder, then ``os.replace``);
    False with a warning where the folder cannot be written or ``path`` exists and is not a
    regular file."""
    meta = np.array([FORMAT_VERSION, lo.shape[0] // 2, _crc(lo, hi)], np.int64)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _refuse_non_regular(path)
        fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, lo=lo, hi=hi, meta=meta)
            os.replace(tmp, _refuse_non_regular(path))
        finally:  # also on KeyboardInterrupt: no temporary file stays behind
            if os.path.exists(tmp):
                os.unlink(tmp)
        return True
    except (OSError, ValueError) as exc:
        warnings.warn(f"span table not cached at {path}: {exc}", RuntimeWarning, stacklevel=3)
        return False


def _frozen(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def span_table(size: int, cache: bool = True, cache_dir=None) -> SpanTable:
    """The size-``size`` span table, built at most once per process and, with ``cache``, kept
    on disk under ``cache_dir`` (default :func:`default_cache_dir`): loaded from there when a
    valid file exists, otherwise built (or taken from this process) and written there."""
    s = check_size(size)
    path = cache_path(s, cache_dir) if cache else None
    held = _TABLES.get(s)
    if held is not None and (path is None or held.path == path):
        return held
    if path is not None:
        arrays = _load(path, s)
        if arrays is not None:
            table = SpanTable(s, _frozen(arrays[0]), _frozen(arrays[1]), None, path)
            _TABLES[s] = table
            return table
    if held is not None:
        lo, hi, build_s = held.lo, held.hi, held.build_s
    else:
        t0 = time.perf_counter()
        lo, hi = build_span_table(s)
        build_s = time.perf_counter() - t0
        lo, hi = _frozen(lo), _frozen(hi)
    if path is not None and not _save(path, lo, hi):
        path = None
    table = SpanTable(s, lo, hi, build_s, path)
    _TABLES[s] = table
    return table


def table_spans(table: SpanTable, tx1: int, ty1: int, tx2: int,
                ty2: int) -> list[tuple[int, int, int]]:
    """``(ty, first tx, last tx)`` of every non-empty scan line of the triangle with offsets
    ``(tx1, ty1)``, ``(tx2, ty2)`` (pixels, relative to v0, image orientation), top row first;
    offsets outside ``[−S, S − 1]`` are refused."""
    s = table.size
    offsets = (tx1, ty1, tx2, ty2)
    if not all(-s <= int(v) <= s - 1 and int(v) == v for v in offsets):
        raise ValueError(f"offsets must be integers in {-s}..{s - 1} for size {s}, got {offsets}")
    idx = tuple(int(v) + s for v in offsets)
    lo, hi = table.lo[idx], table.hi[idx]
    return [(r - s, int(lo[r]) - s, int(hi[r]) - s) for r in range(2 * s) if lo[r] >= 0]
