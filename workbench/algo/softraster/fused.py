"""The fused, tile-parallel software rasterizer: the image of the paper's steps, bit for bit,
from one compiled loop per screen tile.

:mod:`.pipeline` runs es2008's steps as separate passes over all triangles, each streaming the
whole batch through memory, so that a second thread gains little. Here, after the per-vertex
transform and light (the pipeline's own step), the triangles go through three passes:

1. **clip** (:func:`classify`) — every triangle once, in parallel over runs of triangles
   (:data:`RUNS_PER_THREAD` per thread, a thread taking the next run when done): the clip
   test of :func:`.kernels.clip_triangles`, its box of pixel centres and the screen tiles of
   ``RasterOptions.tile`` pixels it meets, counted per run and tile with their estimated work;
2. **bin** (:func:`place`) — every kept triangle, in the same runs, copied into the list of
   each of its tiles in triangle order: its index, fixed-point vertices and depths (read here
   in triangle order, where the vertices are near one another, so that a tile reads its list
   in order rather than gather);
3. **tiles** (:func:`draw_tiles`) — in parallel, each tile owned by one thread: for each of
   the tile's triangles in index order the box clipped to the tile, the depth plane
   (:func:`.kernels._plane`, the same arithmetic), a hierarchical depth test that skips a
   triangle lying wholly behind what the tile's 8 × 8 blocks already hold (exact: it allows
   for the rounding of the plane), the edge functions (the integer rule of :mod:`.rule`), and
   per covered pixel centre the depth, the depth test, the attribute and clip planes (once,
   for the first fragment that passes), the clip distances, the colour (as
   :func:`.kernels.interpolate_color` computes it; the flat light as
   :func:`.kernels.light_triangles`, for the triangles seen only) and the write (as
   :func:`.kernels.write_fragments` decides it).

No fragment is stored. The threads take the tiles one at a time, the largest estimated work
(triangles and box pixels) first, each the next tile when it is done (numba's dynamic
schedule, chunk size 1): an estimate cannot see how many triangles the hierarchical test will
skip, and tiles dealt up front by it left one thread idle for a third of the pass. A tile's
pixels depend only on its triangles in index order, so the image does not depend on the
thread count or on which thread drew it, and of two
fragments at one depth the lower triangle index wins, as under GL's ``LESS`` test.

With ``early_depth`` (the default) the depth test comes before the clip planes and the colour;
without, every covered fragment is clipped and coloured first (the paper's order, no
hierarchical test; the image is the same). Triangles go through the passes in sessions of
:data:`SESSION` (the lists hold 44 bytes a triangle and tile; ``RasterOptions.session`` is the
steps'). The times go to :class:`~.pipeline.RenderStats` under "clip triangle", "bin" and
"generate fragment" (everything per tile); the other steps after transform and light stay 0,
as does ``fragment_bytes`` (no fragment pool); ``fragments`` counts the pixel centres covered
by triangles that the hierarchical test let through.
"""

from __future__ import annotations

from contextlib import contextmanager

import numba
import numpy as np
from numba import prange

from . import kernels
from .kernels import CONSTANT, ELEMENT_COLOR, FLAT, GOURAUD, VERTEX_COLOR, _flat_light
from .state import Bins, Screen, Target

DROPPED, SEVERAL = -1, -2  # tile codes of a triangle: drawn nowhere, in more than one tile
BOX_PIXEL_WORK = 1  # work estimate of a tile: per box pixel tested …
TRIANGLE_WORK = 4  # … and per triangle set up
SESSION = 1 << 22  # triangles binned and drawn at a time: the bin holds 44 bytes a triangle
RUNS_PER_THREAD = 8  # runs of triangles per thread in the clip and bin passes, taken in turn
HIZ_SHIFT = 3  # blocks of 2^HIZ_SHIFT pixels a side: their largest depths reject hidden triangles
# bound on the rounding of ``zc + za·i + zb·j`` in float64, relative to |zc| + |za·i| + |zb·j|,
# twice (the corners', the fragment's) and then some: 2·3u/(1 − 3u) < 7e-16
HIZ_SLACK = 2e-15


# ----------------------------------------------------------------------------- bin
@numba.njit(cache=True, inline="always")
def _box(tris, k, fx, fy, bits, width, height):
    """First/last pixel column and row whose centres triangle ``k``'s box holds, clamped to
    the image (as :func:`.kernels.range_and_tc`)."""
    a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
    lo_x, hi_x = min(fx[a], fx[b], fx[c]), max(fx[a], fx[b], fx[c])
    lo_y, hi_y = min(fy[a], fy[b], fy[c]), max(fy[a], fy[b], fy[c])
    return (max(-((-lo_x) >> bits), 0), min(hi_x >> bits, width - 1),
            max(-((-lo_y) >> bits), 0), min(hi_y >> bits, height - 1))


@numba.njit(cache=True, parallel=True)
def classify(tris, lit, screen, chunks, code, count, work):
    """The clip pass, over ``chunks`` consecutive runs of triangles in parallel (their window
    positions and clip distances from ``lit``, a :class:`~.state.Lit`; the image and its tiles
    ``screen``, a :class:`~.state.Screen`): ``code[k]`` the one tile (of ``2^shift`` pixels a
    side) triangle ``k`` meets, :data:`SEVERAL` or :data:`DROPPED` (by the clip test of
    :func:`.kernels.clip_triangles`); ``count[c, t]`` and ``work[c, t]`` the triangles of run c
    in tile t and their estimated work. Returns the triangles kept."""
    fx = lit.fx
    fy = lit.fy
    fz = lit.fz
    ok = lit.ok
    clipd = lit.clipd
    width = screen.width
    height = screen.height
    bits = screen.bits
    shift = screen.shift
    tiles_x = screen.tiles_x
    n = tris.shape[0]
    wmax = (width - 1) << bits
    hmax = (height - 1) << bits
    kept = np.zeros(chunks, np.int64)
    for ch in prange(chunks):
        held = 0
        for k in range(ch * n // chunks, (ch + 1) * n // chunks):
            code[k] = DROPPED
            a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
            if not (ok[a] and ok[b] and ok[c]):
                continue
            area = (fx[b] - fx[a]) * (fy[c] - fy[a]) - (fy[b] - fy[a]) * (fx[c] - fx[a])
            lo_x, hi_x = min(fx[a], fx[b], fx[c]), max(fx[a], fx[b], fx[c])
            lo_y, hi_y = min(fy[a], fy[b], fy[c]), max(fy[a], fy[b], fy[c])
            if area == 0 or hi_x < 0 or hi_y < 0 or lo_x > wmax or lo_y > hmax \
                    or (-((-lo_x) >> bits)) > (hi_x >> bits) \
                    or (-((-lo_y) >> bits)) > (hi_y >> bits):
                continue
            za, zb, zc = fz[a], fz[b], fz[c]
            if (za < 0 and zb < 0 and zc < 0) or (za > 1 and zb > 1 and zc > 1):
                continue
            clipped = False
            for p in range(clipd.shape[1]):
                if clipd[a, p] < 0 and clipd[b, p] < 0 and clipd[c, p] < 0:
                    clipped = True
            if clipped:
                continue
            held += 1
            i0, i1 = max(-((-lo_x) >> bits), 0), min(hi_x >> bits, width - 1)
            j0, j1 = max(-((-lo_y) >> bits), 0), min(hi_y >> bits, height - 1)
            tx0, tx1, ty0, ty1 = i0 >> shift, i1 >> shift, j0 >> shift, j1 >> shift
            if tx0 == tx1 and ty0 == ty1:
                t = ty0 * tiles_x + tx0
                code[k] = t
                count[ch, t] += 1
                work[ch, t] += TRIANGLE_WORK + BOX_PIXEL_WORK * (i1 - i0 + 1) * (j1 - j0 + 1)
                continue
            code[k] = SEVERAL
            for ty in range(ty0, ty1 + 1):
                rows = min(j1, (ty << shift) + (1 << shift) - 1) - max(j0, ty << shift) + 1
                for tx in range(tx0, tx1 + 1):
                    cols = min(i1, (tx << shift) + (1 << shift) - 1) - max(i0, tx << shift) + 1
                    t = ty * tiles_x + tx
                    count[ch, t] += 1
                    work[ch, t] += TRIANGLE_WORK + BOX_PIXEL_WORK * rows * cols
        kept[ch] = held
    return kept.sum()


@numba.njit(cache=True)
def layout(count, work):
    """The tile lists' layout and the order the tiles are drawn in. Returns ``(start, fill,
    order)``: tile t's triangles will be ``members[start[t]:start[t + 1]]``, run c's first slot
    in tile t ``fill[c, t]``; ``order`` the tiles that have triangles, the largest estimated
    work first."""
    chunks, n_tiles = count.shape
    start = np.zeros(n_tiles + 1, np.int64)
    fill = np.empty((chunks, n_tiles), np.int64)
    total = np.zeros(n_tiles, np.int64)
    for t in range(n_tiles):  # tile-major, run order inside a tile: triangle order
        at = start[t]
        for c in range(chunks):
            fill[c, t] = at
            at += count[c, t]
            total[t] += work[c, t]
        start[t + 1] = at
    by_work = np.argsort(-total, kind="mergesort")
    order = np.empty(n_tiles, np.int64)
    n = 0
    for t in by_work:
        if start[t + 1] > start[t]:
            order[n] = t
            n += 1
    return start, fill, order[:n]


@numba.njit(cache=True, inline="always")
def _record(tris, k, fx, fy, fz, slot, members, mxy, mz):
    """Triangle ``k`` into slot ``slot``: its index, fixed-point vertices and depths."""
    a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
    members[slot] = k
    mxy[slot, 0], mxy[slot, 1] = fx[a], fy[a]
    mxy[slot, 2], mxy[slot, 3] = fx[b], fy[b]
    mxy[slot, 4], mxy[slot, 5] = fx[c], fy[c]
    mz[slot, 0], mz[slot, 1], mz[slot, 2] = fz[a], fz[b], fz[c]


@numba.njit(cache=True, parallel=True)
def place(tris, lit, screen, code, fill, bins):
    """The bin pass, by the runs of :func:`classify`: every kept triangle into the slots of
    its tiles (``fill`` from :func:`layout`, advanced) in ``bins`` (a :class:`~.state.Bins`):
    ``members`` its index, ``mxy`` (·, 6) int32 its fixed-point vertices, ``mz`` (·, 3)
    float32 their depths, in the order of ``tris``."""
    fx = lit.fx
    fy = lit.fy
    fz = lit.fz
    width = screen.width
    height = screen.height
    bits = screen.bits
    shift = screen.shift
    tiles_x = screen.tiles_x
    members = bins.members
    mxy = bins.mxy
    mz = bins.mz
    chunks = fill.shape[0]
    n = code.shape[0]
    for ch in prange(chunks):
        for k in range(ch * n // chunks, (ch + 1) * n // chunks):
            t = code[k]
            if t >= 0:
                _record(tris, k, fx, fy, fz, fill[ch, t], members, mxy, mz)
                fill[ch, t] += 1
            elif t == SEVERAL:
                i0, i1, j0, j1 = _box(tris, k, fx, fy, bits, width, height)
                for ty in range(j0 >> shift, (j1 >> shift) + 1):
                    for tx in range(i0 >> shift, (i1 >> shift) + 1):
                        s = ty * tiles_x + tx
                        _record(tris, k, fx, fy, fz, fill[ch, s], members, mxy, mz)
                        fill[ch, s] += 1


# ----------------------------------------------------------------------------- tiles
@numba.njit(cache=True, inline="always")
def _triangle_color(kind, light, s, no_value, base, missing, texels, texf, linear,
                    alpha_test):
    """(packed RGBA8, visible) of a triangle of one colour (constant; flat or element colour
    with the flat ``light``, element colour at texture coordinate ``s``, or in the ``missing``
    colour where ``no_value``), as :func:`.kernels.interpolate_color` computes it."""
    if kind == CONSTANT:
        return kernels.pack(base[0], base[1], base[2]), True
    if kind == FLAT:
        return kernels.pack(base[0] * light, base[1] * light, base[2] * light), True
    if no_value:
        return kernels.pack(missing[0] * light, missing[1] * light, missing[2] * light), True
    r, g, b, a = kernels.texel_rgba(texels, texf, linear, s)
    return kernels.pack(r * light, g * light, b * light), not (alpha_test and a < 0.5)


@numba.njit(cache=True, inline="always")
def _pixel_color(kind, pl, i, j, no_value, base, missing, texels, texf, linear, alpha_test):
    """(packed RGBA8, visible) of the fragment at pixel (i, j) of a triangle whose attribute
    planes are ``pl[0, 1:, :]`` (in the ``missing`` colour, lit, where ``no_value``), as
    :func:`.kernels.interpolate_color` computes it."""
    if kind == GOURAUD:
        light = np.float32(pl[0, 1, 0] + pl[0, 1, 1] * i + pl[0, 1, 2] * j)
        return kernels.pack(base[0] * light, base[1] * light, base[2] * light), True
    if no_value:  # VERTEX_COLOR (light in plane 5) or PIXEL_COLOR (plane 2)
        q = 5 if kind == VERTEX_COLOR else 2
        light = np.float32(pl[0, q, 0] + pl[0, q, 1] * i + pl[0, q, 2] * j)
        return kernels.pack(missing[0] * light, missing[1] * light, missing[2] * light), True
    if kind == VERTEX_COLOR:
        r = np.float32(pl[0, 1, 0] + pl[0, 1, 1] * i + pl[0, 1, 2] * j)
        g = np.float32(pl[0, 2, 0] + pl[0, 2, 1] * i + pl[0, 2, 2] * j)
        b = np.float32(pl[0, 3, 0] + pl[0, 3, 1] * i + pl[0, 3, 2] * j)
        a = np.float32(pl[0, 4, 0] + pl[0, 4, 1] * i + pl[0, 4, 2] * j)
        return kernels.pack(r, g, b), not (alpha_test and a < 0.5)
    # PIXEL_COLOR
    s = np.float32(pl[0, 1, 0] + pl[0, 1, 1] * i + pl[0, 1, 2] * j)
    light = np.float32(pl[0, 2, 0] + pl[0, 2, 1] * i + pl[0, 2, 2] * j)
    r, g, b, a = kernels.texel_rgba(texels, texf, linear, s)
    return kernels.pack(r * light, g * light, b * light), not (alpha_test and a < 0.5)


@numba.njit(cache=True, inline="always")
def _block_max(depth, bmax, nmax, b, i0, j0, block):
    """``bmax[b]`` the largest depth of the block of ``block`` pixels a side at (``i0``,
    ``j0``), ``nmax[b]`` how many of its pixels hold it (depths that are not numbers left
    out)."""
    height, width = depth.shape
    m = np.float32(-np.inf)
    n = 0
    for j in range(j0, min(j0 + block, height)):
        for i in range(i0, min(i0 + block, width)):
            d = depth[j, i]
            if d > m:
                m = d
                n = 1
            elif d == m:
                n += 1
    bmax[b] = m
    nmax[b] = n


@numba.njit(cache=True, parallel=True)
def draw_tiles(order, start, bins, tris, ids, lit, look, early, screen, target, covered):
    """Every tile of ``order`` (:func:`layout`), each by one thread, drawn into ``target`` (a
    :class:`~.state.Target`: ``depth``, ``color`` packed RGBA8, ``triangle``): its triangles
    (``bins``, a :class:`~.state.Bins`, from ``start[t]``) in index order, each set up, its box
    within the tile tested against the edge functions, each covered fragment depth tested,
    clipped, coloured (``look``, a :class:`~.state.Look`; the vertices' attributes, clip
    distances and the triangles' texture coordinates from ``lit``, a :class:`~.state.Lit` of
    this session's triangles) and written; a triangle flagged in ``lit.tri_missing`` (read
    where ``any_missing``) in the ``missing`` colour. With ``early``, the depth test comes
    first, and a triangle whose depth plane lies behind the largest depth of the blocks its box
    meets is skipped before its coverage. ``covered[t]``: the fragments tile t generated (pixel
    centres covered by triangles not skipped)."""
    members = bins.members
    mxy = bins.mxy
    mz = bins.mz
    fx = lit.fx
    fy = lit.fy
    attr = lit.attr
    clipd = lit.clipd
    pos32 = lit.pos32
    view32 = lit.view32
    tri_s = lit.tri_s
    tri_missing = lit.tri_missing
    any_missing = lit.any_missing
    kind = look.code
    base = look.base
    missing = look.missing
    texels = look.texels
    texf = look.texf
    linear = look.linear
    alpha_test = look.alpha_test
    shift = screen.shift
    tiles_x = screen.tiles_x
    bits = screen.bits
    depth = target.depth
    color = target.color
    triangle = target.triangle
    height, width = depth.shape
    n_attr = attr.shape[1]
    n_clip = clipd.shape[1]
    inv = 1.0 / (1 << bits)
    per_triangle = kind == CONSTANT or kind == FLAT or kind == ELEMENT_COLOR
    tile = 1 << shift
    bs = min(shift, HIZ_SHIFT)
    block = 1 << bs
    per_row = tile >> bs
    for o in prange(order.shape[0]):
        # the tile's own: the planes of the triangle drawn (depth, the attributes, the clip
        # distances), and per block of the tile its largest depth and how many pixels hold it
        pl = np.empty((1, 1 + n_attr + n_clip + 3, 3))
        bmax = np.empty(per_row * per_row + 16, np.float32)
        nmax = np.empty(per_row * per_row + 8, np.int64)
        t = order[o]
        ti0, tj0 = (t % tiles_x) * tile, (t // tiles_x) * tile
        ti1, tj1 = min(ti0 + tile - 1, width - 1), min(tj0 + tile - 1, height - 1)
        for bj in range(per_row if early else 0):
            for bi in range(per_row):
                _block_max(depth, bmax, nmax, bj * per_row + bi, ti0 + bi * block,
                           tj0 + bj * block, block)
        generated = 0
        for q in range(start[t], start[t + 1]):
            x0, y0 = np.int64(mxy[q, 0]), np.int64(mxy[q, 1])
            x1, y1 = np.int64(mxy[q, 2]), np.int64(mxy[q, 3])
            x2, y2 = np.int64(mxy[q, 4]), np.int64(mxy[q, 5])
            i0 = max(-((-min(x0, x1, x2)) >> bits), ti0)
            i1 = min(max(x0, x1, x2) >> bits, ti1)
            j0 = max(-((-min(y0, y1, y2)) >> bits), tj0)
            j1 = min(max(y0, y1, y2) >> bits, tj1)
            if i0 > i1 or j0 > j1:
                continue
            # the depth plane over pixel centres, in the vertex order (as depth_gradient)
            xa, ya, xb, yb = x0 * inv, y0 * inv, x1 * inv, y1 * inv
            xc, yc = x2 * inv, y2 * inv
            kernels._plane(xa, ya, xb, yb, xc, yc, np.float64(mz[q, 0]),
                           np.float64(mz[q, 1]), np.float64(mz[q, 2]), pl, 0, 0)
            zc, za, zb = pl[0, 0, 0], pl[0, 0, 1], pl[0, 0, 2]
            if early:
                # hierarchical rejection: the plane is linear, so no covered pixel
                # centre's depth lies below its least value at the vertices, nor below
                # its least over the box (at a corner), less the rounding of either
                # evaluation (HIZ_SLACK, relative to the sum of the terms' sizes)
                low = max(min(zc + za * xa + zb * ya, zc + za * xb + zb * yb,
                              zc + za * xc + zb * yc),
                          zc + min(za * i0, za * i1) + min(zb * j0, zb * j1)) \
                    - HIZ_SLACK * (abs(zc) + abs(za) * max(i1, abs(xa), abs(xb), abs(xc))
                                   + abs(zb) * max(j1, abs(ya), abs(yb), abs(yc)))
                bi0, bi1 = (i0 - ti0) >> bs, (i1 - ti0) >> bs
                bj0, bj1 = (j0 - tj0) >> bs, (j1 - tj0) >> bs
                if bi1 - bi0 <= 1 and bj1 - bj0 <= 1:  # the blocks at the box's corners
                    far = max(bmax[bj0 * per_row + bi0], bmax[bj0 * per_row + bi1],
                              bmax[bj1 * per_row + bi0], bmax[bj1 * per_row + bi1])
                else:
                    far = np.float32(-np.inf)
                    for bj in range(bj0, bj1 + 1):
                        for bi in range(bi0, bi1 + 1):
                            far = max(far, bmax[bj * per_row + bi])
                if np.float32(low) > far:
                    continue
            if (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0) < 0:  # to positive area
                x1, y1, x2, y2 = x2, y2, x1, y1
            (dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, step0, step1,
             step2) = kernels._edges(x0, y0, x1, y1, x2, y2, bits)
            px0 = i0 << bits
            shaded = False
            k = members[q]
            tid = ids[k]
            no_value = any_missing and tri_missing[k] != 0
            tri_rgba = np.uint32(0)
            tri_visible = True
            for j in range(j0, j1 + 1):
                py = j << bits
                e0 = kernels._edge_at(dx0, dy0, x0, y0, px0, py, bias0)
                e1 = kernels._edge_at(dx1, dy1, x1, y1, px0, py, bias1)
                e2 = kernels._edge_at(dx2, dy2, x2, y2, px0, py, bias2)
                for i in range(i0, i1 + 1):
                    inside = (e0 | e1 | e2) >= 0  # all three ≥ 0 ⇔ their or ≥ 0
                    e0 -= step0
                    e1 -= step1
                    e2 -= step2
                    if not inside:
                        continue
                    generated += 1
                    z = zc + za * i + zb * j
                    if not 0.0 <= z <= 1.0:
                        continue
                    z32 = np.float32(z)
                    if early and not (z32 < depth[j, i] or (
                            z32 == depth[j, i] and tid < triangle[j, i])):
                        continue
                    if not shaded:  # the other planes, once a fragment needs them
                        shaded = True
                        a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
                        for p in range(n_attr):
                            kernels._plane(xa, ya, xb, yb, xc, yc, np.float64(attr[a, p]),
                                           np.float64(attr[b, p]), np.float64(attr[c, p]),
                                           pl, 0, 1 + p)
                        for p in range(n_clip):
                            kernels._plane(xa, ya, xb, yb, xc, yc, np.float64(clipd[a, p]),
                                           np.float64(clipd[b, p]),
                                           np.float64(clipd[c, p]), pl, 0, 1 + n_attr + p)
                        if per_triangle:
                            light = np.float32(0.0)
                            if kind != CONSTANT:
                                light = _flat_light(pos32, view32, fx, fy, inv, a, b, c)
                            tri_rgba, tri_visible = _triangle_color(
                                kind, light, tri_s[k] if kind == ELEMENT_COLOR
                                else np.float32(0.0), no_value, base, missing, texels, texf,
                                linear, alpha_test)
                    clipped = False
                    for p in range(1 + n_attr, 1 + n_attr + n_clip):
                        if pl[0, p, 0] + pl[0, p, 1] * i + pl[0, p, 2] * j < 0.0:
                            clipped = True
                    if clipped:
                        continue
                    if per_triangle:
                        rgba, visible = tri_rgba, tri_visible
                    else:
                        rgba, visible = _pixel_color(kind, pl, i, j, no_value, base, missing,
                                                     texels, texf, linear, alpha_test)
                    if not visible:
                        continue
                    d = depth[j, i]
                    if not early:
                        if z32 < d or (z32 == d and tid < triangle[j, i]):
                            depth[j, i] = z32
                            color[j, i] = rgba
                            triangle[j, i] = tid
                        continue
                    depth[j, i] = z32  # the depth test passed above
                    color[j, i] = rgba
                    triangle[j, i] = tid
                    bj, bi = (j - tj0) >> bs, (i - ti0) >> bs
                    blk = bj * per_row + bi
                    if d == bmax[blk]:  # one pixel fewer holds the block's largest depth
                        nmax[blk] -= 1
                        if nmax[blk] <= 0:
                            _block_max(depth, bmax, nmax, blk, ti0 + bi * block,
                                       tj0 + bj * block, block)
        covered[t] = generated


# ----------------------------------------------------------------------------- the draw
_HELPERS = ("_box", "_record", "_flat_light", "_triangle_color", "_pixel_color", "_block_max")


@contextmanager
def _plain(vectorized: bool):
    """This module's helpers as plain Python (``py_func``) for the block, unless
    ``vectorized``."""
    saved = {name: globals()[name] for name in _HELPERS}
    try:
        if not vectorized:
            globals().update({name: f.py_func for name, f in saved.items()})
        yield
    finally:
        globals().update(saved)


def _lend(workspace, name, n, dtype, columns=0):
    """An uninitialised array of ``n`` rows (of ``columns`` entries, if any): the first rows of
    one kept in ``workspace`` (a dict or None) when it holds enough of that dtype."""
    shape = (n, columns) if columns else (n,)
    if workspace is None:
        return np.empty(shape, dtype)
    held = workspace.get(name)
    if held is None or len(held) < n or held.shape[1:] != shape[1:] or held.dtype != dtype:
        held = workspace[name] = np.empty(shape, dtype)
    return held[:n]


def draw(tris, ids, lit, frame, color32, options, look, threads, stats, clock,
         vectorized=True, workspace=None) -> None:
    """Draw ``tris`` (K, 3) into ``frame`` (``color32`` its colour as one uint32 per pixel)
    from the transform and light step's ``lit`` (:class:`~.state.Lit`) with the shading
    ``look`` (:class:`~.state.Look`) and ``options``, on ``threads`` workers; counts go to
    ``stats``, seconds to ``clock`` (see the module). ``vectorized=False`` runs the kernels as
    plain Python; ``workspace`` lends the bin arrays from draw to draw."""
    with _plain(vectorized):
        _draw(tris, ids, lit, frame, color32, options, look, threads, stats, clock,
              (lambda fn: fn) if vectorized else (lambda fn: fn.py_func), workspace)


def _draw(tris, ids, lit, frame, color32, options, look, threads, stats, clock, kernel,
          workspace) -> None:
    width, height = frame.size
    bits = options.subpixel_bits
    tile = options.tile
    shift = tile.bit_length() - 1
    tiles_x = -(-width // tile)
    n_tiles = tiles_x * (-(-height // tile))
    screen = Screen(int(width), int(height), int(bits), int(shift), int(tiles_x))
    target = Target(frame.depth, color32, frame.triangle)
    for k0 in range(0, len(tris), SESSION):
        k1 = min(k0 + SESSION, len(tris))
        tri_s = lit.tri_s[k0:k1] if len(lit.tri_s) == len(tris) else lit.tri_s
        tri_missing = lit.tri_missing[k0:k1] if lit.any_missing else lit.tri_missing
        stats.sessions += 1
        code = _lend(workspace, "fused_code", k1 - k0, np.int32)
        runs = RUNS_PER_THREAD * threads
        count = np.zeros((runs, n_tiles), np.int64)
        work = np.zeros((runs, n_tiles), np.int64)
        with numba.parallel_chunksize(1):
            kept = int(kernel(classify)(tris[k0:k1], lit, screen, runs, code, count, work))
        stats.kept += kept
        clock.lap("clip triangle")
        if kept == 0:
            continue
        start, fill, order = kernel(layout)(count, work)
        slots = int(start[-1])
        members = _lend(workspace, "fused_members", slots, np.int32)
        mxy = _lend(workspace, "fused_xy", slots, np.int32, 6)
        mz = _lend(workspace, "fused_z", slots, np.float32, 3)
        bins = Bins(members, mxy, mz)
        with numba.parallel_chunksize(1):
            kernel(place)(tris[k0:k1], lit, screen, code, fill, bins)
        clock.lap("bin")
        covered = np.zeros(n_tiles, np.int64)
        with numba.parallel_chunksize(1):  # a thread takes the next tile when it is done
            kernel(draw_tiles)(order, start, bins, tris[k0:k1], ids[k0:k1],
                               lit._replace(tri_s=tri_s, tri_missing=tri_missing), look,
                               options.early_depth, screen, target, covered)
        stats.fragments += int(covered.sum())
        clock.lap("generate fragment")
