"""Active-pixel sort-last compositing (es2008, section 1; IceT's bounding box + run lengths):
the domain frames of :mod:`.composite` merged by the same rule, but every (sub-)image sent
between ranks carries only its drawn pixels (``triangle != NO_TRIANGLE``).

**Encoding.** An :class:`EncodedPiece` holds one region of an image: the bounding rectangle of
its drawn pixels, inside it the runs of skipped and drawn pixels (row-major, in the narrowest
unsigned type that holds them), and the drawn pixels' data in that order — the colour channels
that vary (one that does not is sent once), the depth as is, the triangle index as an offset
from the smallest in the narrowest unsigned type. :func:`encode` adds the empty pixels' shared
colour and depth, so that :func:`decode` gives the region back bit for bit. A piece whose
encoding would not be smaller than the plain sub-image (or, for :func:`encode`, whose empty
pixels differ) goes plain, so no piece costs more than the full-frame schedules send for it.

**Compositing.** A rank holds :class:`ActivePixels`: the drawn pixels of its region by flat
image index, sorted. :func:`merge` is :func:`.composite.composite` on them (drawn beats empty,
then the smaller depth, then the smaller triangle index; the first operand's fragment where the
keys are equal), at a cost in drawn pixels, not in region pixels. Pieces sent carry no empty
pixels: where no frame draws, ``functools.reduce(composite, frames)`` shows frame 0's pixel,
and rank 0, which holds frame 0, receives the result, so :func:`paint` writes the drawn pixels
of the result over frame 0.

**Schedules** (D frames, rank i holding frame i, merges in domain order) are in
:mod:`.active_schedules`: the tree, binary swap and radix-k over these pieces.

A distributed run follows the plans with, per rank: :meth:`ActivePixels.from_frame` once;
:meth:`ActivePixels.cut` + :meth:`ActivePixels.pack` to send (the picklable
:class:`EncodedPiece` travels; :attr:`EncodedPiece.nbytes` is its size);
:meth:`EncodedPiece.unpack` + :func:`merge` (:func:`merge_ordered` for a radix-k group, in
member order) to receive; :func:`paint` over its own frame on rank 0. GL-free and Dask-free.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..softraster.frame import CLEAR_DEPTH, NO_TRIANGLE, Frame
from .merge import Region, _check

_UNSIGNED = (np.uint8, np.uint16, np.uint32, np.uint64)


def _narrow(values: np.ndarray, largest: int) -> np.ndarray:
    """``values`` (0 … ``largest`` < 2**64) in the narrowest unsigned type."""
    return values.astype(next(t for t in _UNSIGNED if largest <= np.iinfo(t).max), copy=False)


def _rows(a: np.ndarray) -> np.ndarray:
    """A 1-D view of the (n, C) array ``a`` with one element per row (fast gathers)."""
    a = np.ascontiguousarray(a)
    size = a.dtype.itemsize * a.shape[1]
    kind = {1: np.uint8, 2: np.uint16, 4: np.uint32, 8: np.uint64}.get(size)
    return a.view(kind if kind is not None else np.dtype((np.void, size))).reshape(len(a))


def _divmod(index: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """(row, column) of flat indices into rows of ``width`` (np.divmod is much slower)."""
    rows = index // max(width, 1)
    return rows, index - rows * width


def _varying(color: np.ndarray) -> np.ndarray:
    """Per channel of the (n ≥ 1, C) array ``color``: whether it takes more than one value."""
    rows = _rows(color)
    if rows.dtype.kind != "u":  # compare bit patterns, as below
        bits = _bits(color).reshape(len(color), color.shape[1], -1)
        return (bits != bits[0]).any(axis=(0, 2))
    differ = np.bitwise_or.reduce(rows ^ rows[0])  # bits that differ from the first pixel
    return np.frombuffer(differ.tobytes(), np.uint8).reshape(color.shape[1], -1).any(axis=1)


def _ranges(first: np.ndarray, count: np.ndarray) -> np.ndarray:
    """The concatenated ranges ``first[i] … first[i] + count[i] − 1`` (int64)."""
    offset = np.cumsum(count) - count
    return np.arange(int(offset[-1] + count[-1]) if len(count) else 0) + np.repeat(
        first - offset, count)


def _runs(index: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first index, index after the last, data position of the first) of each run of
    consecutive values of the strictly increasing, non-empty ``index``."""
    breaks = np.flatnonzero(index[1:] - index[:-1] != 1) + 1
    first = np.concatenate(([0], breaks))
    return index[first], np.concatenate((index[breaks - 1], index[-1:])) + 1, first


def _row_runs(index: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(row, first column, column after the last) of each run of :func:`_runs`, a run that
    wraps to the next row cut at the row end."""
    start, stop, _ = _runs(index)
    row, last = start // width, (stop - 1) // width
    if (last > row).any():  # runs through whole rows: one run per row
        rows = last - row + 1
        row = _ranges(row, rows)
        start = np.maximum(row * width, np.repeat(start, rows))
        stop = np.minimum((row + 1) * width, np.repeat(stop, rows))
    return row, start - row * width, stop - row * width


def _to_global(local: np.ndarray, region: Region, width: int) -> np.ndarray:
    """Flat image indices (rows of ``width``) of flat indices into ``region``'s sub-image."""
    r, c = _divmod(local, region.right - region.left)
    return (r + region.top) * width + (c + region.left)


def _to_local(index: np.ndarray, region: Region, width: int) -> np.ndarray:
    """Flat indices into ``region``'s sub-image of flat image indices (rows of ``width``)."""
    r, c = _divmod(index, width)
    return (r - region.top) * (region.right - region.left) + (c - region.left)


def _inside(inner: Region, outer: Region) -> bool:
    return (outer.top <= inner.top <= inner.bottom <= outer.bottom
            and outer.left <= inner.left <= inner.right <= outer.right)


# --------------------------------------------------------------------------- active pixels
@dataclass(frozen=True, eq=False)
class ActivePixels:
    """The drawn pixels of ``region`` of an ``height`` × ``width`` image: ``index`` their flat
    image indices (``row * width + column``, int64, strictly increasing), ``color`` (n, C),
    ``depth`` (n,) and ``triangle`` (n,) their data in the frame's dtypes. Pixels of ``region``
    not listed are empty; pixels outside it are not described. Arrays are never modified."""

    height: int
    width: int
    region: Region
    index: np.ndarray
    color: np.ndarray
    depth: np.ndarray
    triangle: np.ndarray

    def __len__(self) -> int:
        return len(self.index)

    @classmethod
    def from_frame(cls, frame: Frame, region: Region | None = None) -> ActivePixels:
        """The drawn pixels of ``region`` (default: all) of ``frame``, a whole image. Refused
        (ValueError): arrays that do not make one frame, a region outside the image."""
        height, width = _check(frame, "frame")
        whole = Region(0, height, 0, width)
        region = whole if region is None else Region(*(int(v) for v in region))
        if not _inside(region, whole):
            raise ValueError(f"region {tuple(region)} is not inside the {height} x {width} image")
        rows, cols = slice(region.top, region.bottom), slice(region.left, region.right)
        index = np.flatnonzero(frame.triangle[rows, cols] != NO_TRIANGLE)
        if region != whole:
            index = _to_global(index, region, width)
        channels = frame.color.shape[2]
        color = _rows(frame.color.reshape(-1, channels))[index].view(frame.color.dtype)
        return cls(height, width, region, index.astype(np.int64, copy=False),
                   color.reshape(-1, channels), frame.depth.reshape(-1)[index],
                   frame.triangle.reshape(-1)[index])

    def cut(self, region: Region) -> ActivePixels:
        """The drawn pixels within ``region`` (inside this one's region; ValueError otherwise)."""
        region = Region(*(int(v) for v in region))
        if not _inside(region, self.region):
            raise ValueError(f"region {tuple(region)} is not inside {tuple(self.region)}")
        w = self.width
        if region.left > self.region.left or region.right < self.region.right:
            # the pixels of each row's part: one search per row end, not a test per pixel
            starts = np.arange(region.top, region.bottom) * w
            lo = np.searchsorted(self.index, starts + region.left)
            count = np.searchsorted(self.index, starts + region.right) - lo
            take = _ranges(lo, count)
        else:
            lo, hi = np.searchsorted(self.index, [region.top * w, region.bottom * w])
            take = slice(int(lo), int(hi))
        return _with(self, *(x[take] for x in _arrays(self)), region=region)

    def pack(self) -> EncodedPiece:
        """This region encoded for sending, without background: bounding box + runs, or the
        plain sub-image (empty pixels cleared) where that is not larger."""
        return _pack(self)


def merge(first: ActivePixels, second: ActivePixels) -> ActivePixels:
    """:func:`.composite.composite` of two frames' drawn pixels of one region: at every pixel
    drawn in either, the fragment with the smaller (depth, triangle) key, ``first``'s where the
    keys are equal. Costs O(n) in the drawn pixels and O(r log r) in their runs of consecutive
    pixels. Refused (ValueError): different regions or image sizes."""
    a, b = first, second
    if (a.height, a.width, a.region) != (b.height, b.width, b.region):
        raise ValueError(f"cannot merge pixels of region {tuple(a.region)} of a {a.height} x "
                         f"{a.width} image with region {tuple(b.region)} of {b.height} x {b.width}")
    if not len(b):
        return a
    if not len(a):
        return b
    if a.index[-1] < b.index[0] or b.index[-1] < a.index[0]:  # apart: no pixel in both
        lo, hi = (a, b) if a.index[0] < b.index[0] else (b, a)
        return _with(a, *(np.concatenate((x, y)) for x, y in zip(_arrays(lo), _arrays(hi))))
    # pixels come in runs of consecutive indices: cut the index line at every run end of
    # either, so that each segment between cuts lies in a run of a, of b, of both or neither
    sa, ea, oa = _runs(a.index)
    sb, eb, ob = _runs(b.index)
    cuts = np.unique(np.concatenate((sa, ea, sb, eb)))
    lo, length = cuts[:-1], np.diff(cuts)
    ka = np.maximum(np.searchsorted(sa, lo, "right") - 1, 0)
    kb = np.maximum(np.searchsorted(sb, lo, "right") - 1, 0)
    in_a, in_b = (sa[ka] <= lo) & (lo < ea[ka]), (sb[kb] <= lo) & (lo < eb[kb])
    keep = np.flatnonzero(in_a | in_b)
    lo, length, in_a, in_b = lo[keep], length[keep], in_a[keep], in_b[keep]
    a_first = oa[ka[keep]] + lo - sa[ka[keep]]  # data position of each segment's first pixel
    b_first = ob[kb[keep]] + lo - sb[kb[keep]]
    src = _ranges(np.where(in_a, a_first, len(a) + b_first), length)  # a's where both draw
    both = np.flatnonzero(in_a & in_b)
    if len(both):  # b wins only with a strictly smaller (depth, triangle) key
        at = _ranges((np.cumsum(length) - length)[both], length[both])
        ia, ib = src[at], _ranges(b_first[both], length[both])
        da, db = a.depth[ia], b.depth[ib]
        wins = db < da
        tied = np.flatnonzero(db == da)  # few: look at their triangles only
        wins[tied] = b.triangle[ib[tied]] < a.triangle[ia[tied]]
        wins = np.flatnonzero(wins)
        src[at[wins]] = len(a) + ib[wins]
    data = (np.concatenate((x, y))[src] for x, y in zip(_arrays(a)[1:], _arrays(b)[1:]))
    return _with(a, _ranges(lo, length), *data)


def _arrays(p: ActivePixels) -> tuple[np.ndarray, ...]:
    """index, colour (one element per pixel), depth, triangle."""
    return p.index, _rows(p.color), p.depth, p.triangle


def _with(like: ActivePixels, index, color, depth, triangle, region=None) -> ActivePixels:
    """``like``'s image and region (or ``region``) with these arrays (colour one element per
    pixel)."""
    color = color.view(like.color.dtype).reshape(len(index), like.color.shape[1])
    return ActivePixels(like.height, like.width, region or like.region, index, color, depth,
                        triangle)


def merge_ordered(parts: Sequence[ActivePixels]) -> ActivePixels:
    """``functools.reduce(merge, parts)``, merged pairwise in order (a balanced tree, so each
    pixel is touched O(log k) times). Refused (ValueError): no parts, or parts of different
    regions."""
    parts = list(parts)
    if not parts:
        raise ValueError("need at least one part to merge, got none")
    while len(parts) > 1:
        parts = [merge(*parts[i:i + 2]) if i + 1 < len(parts) else parts[i]
                 for i in range(0, len(parts), 2)]
    return parts[0]


def paint(base: Frame, parts: Sequence[ActivePixels]) -> Frame:
    """A copy of ``base`` (a whole image) with every drawn pixel of ``parts`` written over it:
    the final composite on rank 0 when ``base`` is frame 0 and ``parts`` tile the image.
    Refused (ValueError): parts of another image size."""
    height, width = _check(base, "base frame")
    out = Frame(base.color.copy(), base.depth.copy(), base.triangle.copy())
    channels = out.color.shape[2]
    color, depth, triangle = (_rows(out.color.reshape(-1, channels)), out.depth.reshape(-1),
                              out.triangle.reshape(-1))
    for part in parts:
        if (part.height, part.width) != (height, width):
            raise ValueError(f"pixels of a {part.height} x {part.width} image cannot be painted "
                             f"on a {height} x {width} frame")
        color[part.index] = _rows(part.color)
        depth[part.index] = part.depth
        triangle[part.index] = part.triangle
    return out


# --------------------------------------------------------------------------------- encoding
@dataclass(frozen=True, eq=False)
class EncodedPiece:
    """Region ``region`` of an ``height`` × ``width`` image as sent between ranks.

    Run-length form (``plain is None``): ``box`` the bounding rectangle of the drawn pixels
    (empty, at the region's corner, when none is); ``runs`` alternating skip / take counts over
    ``box`` in row-major order, starting with a skip, no run crossing the end of a box row;
    ``color`` the drawn pixels' channels flagged in ``varying``, ``color_fixed`` the first drawn
    pixel's colour (the channels not varying are that everywhere); ``depth`` as is;
    ``triangle`` offsets from ``triangle_base``, restored as ``triangle_dtype``;
    ``background_color`` (1, C) and ``background_depth`` (1,): every empty pixel's, or None —
    a piece sent while compositing carries none, since where no frame draws the result shows
    frame 0's pixel, which rank 0 holds. Plain form: ``plain`` the sub-image itself (the other
    arrays empty).

    :attr:`nbytes` counts the bytes of the arrays; the scalars describing the piece (sizes,
    regions, base, dtypes: a few dozen bytes) are not counted, as the full-frame schedules count
    no frame header."""

    height: int
    width: int
    region: Region
    box: Region
    runs: np.ndarray
    varying: np.ndarray
    color_fixed: np.ndarray
    color: np.ndarray
    depth: np.ndarray
    triangle_base: int
    triangle: np.ndarray
    triangle_dtype: np.dtype
    background_color: np.ndarray | None = None
    background_depth: np.ndarray | None = None
    plain: Frame | None = None

    @property
    def nbytes(self) -> int:
        arrays = (self.runs, self.varying, self.color_fixed, self.color, self.depth,
                  self.triangle, self.background_color, self.background_depth)
        return int(sum(a.nbytes for a in arrays if a is not None)
                   + (self.plain.nbytes if self.plain is not None else 0))

    def unpack(self) -> ActivePixels:
        """The drawn pixels this piece describes (exactly those packed). Refused
        (ValueError): runs that cross the end of a box row."""
        region = self.region
        if self.plain is not None:
            local = ActivePixels.from_frame(self.plain)
            return ActivePixels(self.height, self.width, region,
                                _to_global(local.index, region, self.width), local.color,
                                local.depth, local.triangle)
        skip, take = self.runs[0::2].astype(np.int64), self.runs[1::2].astype(np.int64)
        box = self.box
        at = np.cumsum(skip + take) - take  # each run's first pixel in the box
        row, column = _divmod(at, box.right - box.left)
        if (column + take > box.right - box.left).any():
            raise ValueError("malformed piece: a run crosses the end of a row of its box")
        index = _ranges((row + box.top) * self.width + column + box.left, take)
        color = np.empty((len(index), len(self.varying)), self.color_fixed.dtype)
        for j, k in enumerate(np.flatnonzero(self.varying)):  # a channel at a time: faster
            color[:, k] = self.color[:, j]
        for k in np.flatnonzero(~self.varying):
            color[:, k] = self.color_fixed[k]
        triangle = np.add(self.triangle, np.int64(self.triangle_base), dtype=np.int64).astype(
            self.triangle_dtype, copy=False)
        return ActivePixels(self.height, self.width, region, index, color, self.depth, triangle)


def _pack(active: ActivePixels, background: tuple[np.ndarray, np.ndarray] | None = None,
          frame: Frame | None = None, plain: bool = False) -> EncodedPiece:
    """``active`` run-length encoded (with ``background``: colour (1, C), depth (1,)), or
    plain when ``plain`` or when that is not larger: the sub-image from ``frame`` (the whole
    image) when given, else ``active``'s pixels over cleared ones."""
    region, n = active.region, len(active)
    color, depth, triangle = active.color, active.depth, active.triangle
    channels = color.shape[1]
    base, empty = 0, np.empty(0, np.uint8)
    if n and not plain:
        row, start, stop = _row_runs(active.index, active.width)
        box = Region(int(row[0]), int(row[-1]) + 1, int(start.min()), int(stop.max()))
        at = (row - box.top) * (box.right - box.left) + (start - box.left)  # in the box
        take = stop - start
        runs = np.empty(2 * len(take), np.int64)
        runs[0::2] = at - np.concatenate(([0], at[:-1] + take[:-1]))  # skips
        runs[1::2] = take
        runs = _narrow(runs, int(runs.max()))
        varying, color_fixed = _varying(color), color[0].copy()
        if not varying.all():
            color = np.empty((n, int(varying.sum())), color.dtype)
            for j, k in enumerate(np.flatnonzero(varying)):  # a channel at a time: faster
                color[:, j] = active.color[:, k]
        base, high = int(triangle.min()), int(triangle.max())
        triangle = _narrow(triangle.astype(np.int64) - base, high - base)  # modulo 2**64
    else:
        box, runs = Region(region.top, region.top, region.left, region.left), empty
        varying, color_fixed = np.zeros(channels, bool), np.zeros(channels, color.dtype)
        color, triangle = color[:, :0], empty
    piece = EncodedPiece(active.height, active.width, region, box, runs, varying, color_fixed,
                         color, depth, base, triangle, active.triangle.dtype,
                         *(background or (None, None)))
    pixel_bytes = (active.color.dtype.itemsize * channels + depth.dtype.itemsize
                   + active.triangle.dtype.itemsize)
    if not plain and piece.nbytes < region.pixels * pixel_bytes:
        return piece
    rows, cols = slice(region.top, region.bottom), slice(region.left, region.right)
    sub = (_write(_cleared(active), active) if frame is None else
           Frame(*(np.array(x[rows, cols]) for x in (frame.color, frame.depth, frame.triangle))))
    return EncodedPiece(active.height, active.width, region, region, empty, varying[:0],
                        color_fixed[:0], color[:0, :0], depth[:0], 0, empty,
                        active.triangle.dtype, plain=sub)


def _cleared(active: ActivePixels) -> Frame:
    """A sub-image of ``active``'s region with nothing drawn: colour 0, the clear depth."""
    region = active.region
    h, w = region.bottom - region.top, region.right - region.left
    return Frame(np.zeros((h, w, active.color.shape[1]), active.color.dtype),
                 np.full((h, w), CLEAR_DEPTH, active.depth.dtype),
                 np.full((h, w), NO_TRIANGLE, active.triangle.dtype))


def encode(frame: Frame, region: Region | None = None) -> EncodedPiece:
    """``region`` (default: all) of ``frame`` (a whole image) encoded exactly: :func:`decode`
    gives the sub-image back bit for bit. The empty pixels' colour and depth are stored once
    when they all share one bit pattern (a cleared frame's), else the region goes plain.
    Refused (ValueError): arrays that do not make one frame, a region outside the image."""
    active = ActivePixels.from_frame(frame, region)
    region = active.region
    rows, cols = slice(region.top, region.bottom), slice(region.left, region.right)
    empty = frame.triangle[rows, cols] == NO_TRIANGLE
    color, depth = frame.color[rows, cols][empty], frame.depth[rows, cols][empty]
    if all((b == b[:1]).all() for b in (_bits(color), _bits(depth.reshape(-1, 1)))):
        return _pack(active, (color[:1], depth[:1]), frame)
    return _pack(active, None, frame, plain=True)


def _bits(a: np.ndarray) -> np.ndarray:
    """The (n, C) array ``a``'s rows as raw bytes (equal rows: equal bit patterns)."""
    return np.ascontiguousarray(a).view(np.uint8).reshape(len(a), a.shape[1] * a.itemsize)


def decode(piece: EncodedPiece, under: Frame | None = None) -> Frame:
    """The sub-image of ``piece``'s region: its drawn pixels, and its empty pixels from the
    piece's own background or, for a piece sent without one, from ``under`` (a frame of the
    region's size). Refused (ValueError): a piece without background and no ``under``, or
    ``under`` of another size."""
    region = piece.region
    h, w = region.bottom - region.top, region.right - region.left
    if piece.plain is not None:
        under = piece.plain
    elif piece.background_color is not None:
        channels = len(piece.varying)
        under = Frame(np.empty((h, w, channels), piece.color_fixed.dtype),
                      np.empty((h, w), piece.depth.dtype), np.empty((h, w), piece.triangle_dtype))
        if len(piece.background_depth):  # else every pixel is drawn
            under.color[...] = piece.background_color[0]
            under.depth[...] = piece.background_depth[0]
        under.triangle[...] = NO_TRIANGLE
        return _write(under, piece.unpack())
    elif under is None:
        raise ValueError("the piece carries no background: give the frame to decode it over")
    elif _check(under, "frame under the piece") != (h, w):
        raise ValueError(f"frame under the piece is {under.depth.shape}, not ({h}, {w})")
    out = Frame(under.color.copy(), under.depth.copy(), under.triangle.copy())
    return out if piece.plain is not None else _write(out, piece.unpack())


def _write(out: Frame, active: ActivePixels) -> Frame:
    """``out`` (the sub-image of ``active``'s region) with ``active``'s pixels written in."""
    local = _to_local(active.index, active.region, active.width)
    out.color.reshape(-1, out.color.shape[2])[local] = active.color
    out.depth.reshape(-1)[local] = active.depth
    out.triangle.reshape(-1)[local] = active.triangle
    return out


