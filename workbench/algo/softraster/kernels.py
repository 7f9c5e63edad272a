"""The compiled steps of the software rasterizer, one kernel per step of es2008's Table 2.

Every kernel is a numba function over flat arrays, those that travel together grouped in the
NamedTuples of :mod:`.state`; :mod:`.pipeline` calls them in order and times each. The same
source runs interpreted by Python (``kernel.py_func``) for the table's "vectorisation off"
column. Per-element steps run in parallel (``prange`` over vertices, triangles or screen
tiles); the two steps the paper leaves scalar — fragment generation and the depth-tested
write — run tile by tile, each tile owned by one thread and visited in triangle order, so the
image is the same for any number of threads.

Arithmetic follows what a GL driver does where it decides pixels: vertex placement in float32
(``mvp · (p − origin)`` as the vertex shader computes it, the perspective divide and the
viewport transform), snapping and edge functions in exact integers (:mod:`.rule`), colours
converted to 8 bits by rounding. Planes of depth and attributes are float64.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import prange

# shading kinds, one per mesh render path
CONSTANT, FLAT, GOURAUD, VERTEX_COLOR, PIXEL_COLOR, ELEMENT_COLOR = range(6)
GUARD = float(1 << 29)  # |fixed coordinate| limit: edge functions stay below 2^62


# ----------------------------------------------------------------------------- helpers
@numba.njit(cache=True, inline="always")
def texel_rgba(texels, texf, linear, s):
    """RGBA in [0, 1] (float32) of the one-row texture ``texels`` (n, 4) uint8 at coordinate
    ``s``, clamp to edge, nearest or linear filtering (8-bit weights); ``texf`` is
    ``texels / 255`` in float32."""
    n = texels.shape[0]
    if not linear:
        i = int(np.floor(s * np.float32(n)))
        i = min(max(i, 0), n - 1)
        return texf[i, 0], texf[i, 1], texf[i, 2], texf[i, 3]
    # linear filtering as llvmpipe does it for 8-bit texels: the weight rounded to 1/256, the
    # blend rounded to 8 bits (checked against llvmpipe: identical over a 4096-pixel ramp)
    u = s * np.float32(n) - np.float32(0.5)
    fl = np.floor(u)
    w = np.int64(np.rint((u - fl) * np.float32(256.0)))
    i0 = int(fl)
    i1 = min(max(i0 + 1, 0), n - 1)
    i0 = min(max(i0, 0), n - 1)
    scale = np.float32(255.0)
    return (np.float32((np.int64(texels[i0, 0]) * 256 + (np.int64(texels[i1, 0])
                        - np.int64(texels[i0, 0])) * w + 128) // 256) / scale,
            np.float32((np.int64(texels[i0, 1]) * 256 + (np.int64(texels[i1, 1])
                        - np.int64(texels[i0, 1])) * w + 128) // 256) / scale,
            np.float32((np.int64(texels[i0, 2]) * 256 + (np.int64(texels[i1, 2])
                        - np.int64(texels[i0, 2])) * w + 128) // 256) / scale,
            np.float32((np.int64(texels[i0, 3]) * 256 + (np.int64(texels[i1, 3])
                        - np.int64(texels[i0, 3])) * w + 128) // 256) / scale)


@numba.njit(cache=True, inline="always")
def unorm8(c):
    """An 8-bit channel from a float colour: clamped to [0, 1], times 255, rounded."""
    c = min(max(c, np.float32(0.0)), np.float32(1.0))
    return np.uint32(np.floor(c * np.float32(255.0) + np.float32(0.5)))


@numba.njit(cache=True, inline="always")
def pack(r, g, b):
    """Opaque RGBA8 packed little-endian (R in the lowest byte), as a uint32."""
    return unorm8(r) | (unorm8(g) << np.uint32(8)) | (unorm8(b) << np.uint32(16)) \
        | np.uint32(0xFF000000)


@numba.njit(cache=True, inline="always")
def headlight(nx, ny, nz):
    """``0.25 + 0.75·abs(n_z)/len(n)`` (float32) for an eye-space normal n; 0.25 for a zero
    normal."""
    len2 = nx * nx + ny * ny + nz * nz
    if len2 > 0:
        return np.float32(0.25) + np.float32(0.75) * (abs(nz) / np.sqrt(len2))
    return np.float32(0.25)


# ----------------------------------------------------------------------------- transform and light
@numba.njit(cache=True, parallel=True)
def transform(pos, mvp, width, height, bits, fx, fy, fz, ok):
    """Window placement of every vertex: ``pos`` (V, 3) float32 relative to the upload origin,
    ``mvp`` (4, 4) float32; writes fixed-point image coordinates ``fx``, ``fy`` (int64, pixel
    centres on multiples of 2^bits), window depth ``fz`` (float32) and ``ok`` (finite, in front
    of the eye, within the guard band)."""
    hw = np.float32(width * 0.5)
    hh = np.float32(height * 0.5)
    half = np.float32(0.5)
    scale = np.float32(1 << bits)
    top = (height - 1) << bits
    for v in prange(pos.shape[0]):
        x, y, z = pos[v, 0], pos[v, 1], pos[v, 2]
        cx = mvp[0, 0] * x + mvp[0, 1] * y + mvp[0, 2] * z + mvp[0, 3]
        cy = mvp[1, 0] * x + mvp[1, 1] * y + mvp[1, 2] * z + mvp[1, 3]
        cz = mvp[2, 0] * x + mvp[2, 1] * y + mvp[2, 2] * z + mvp[2, 3]
        cw = mvp[3, 0] * x + mvp[3, 1] * y + mvp[3, 2] * z + mvp[3, 3]
        sx = ((cx / cw) * hw + hw - half) * scale
        sy = ((cy / cw) * hh + hh - half) * scale
        good = cw > 0 and abs(sx) < GUARD and abs(sy) < GUARD  # NaN fails every comparison
        ok[v] = good
        if good:
            fx[v] = np.int64(np.rint(sx))
            fy[v] = top - np.int64(np.rint(sy))
            fz[v] = (cz / cw) * half + half
        else:
            fx[v] = 0
            fy[v] = 0
            fz[v] = np.float32(np.nan)


@numba.njit(cache=True, parallel=True)
def light_vertices(kind, view, normals, s, texels, texf, linear, attr):
    """Per-vertex shading inputs ``attr`` (V, A) float32 for the Gouraud kinds: GOURAUD → the
    headlight of the crease-split normal; VERTEX_COLOR → lit colour RGB and transfer α, and
    where A is 5 the headlight (for the missing colour of triangles without a value);
    PIXEL_COLOR → texture coordinate and headlight. ``view`` (3, 3) float32, ``normals`` (V, 3)
    float32, ``s`` (V,) float32 texture coordinates."""
    for v in prange(attr.shape[0]):
        nx = view[0, 0] * normals[v, 0] + view[0, 1] * normals[v, 1] + view[0, 2] * normals[v, 2]
        ny = view[1, 0] * normals[v, 0] + view[1, 1] * normals[v, 1] + view[1, 2] * normals[v, 2]
        nz = view[2, 0] * normals[v, 0] + view[2, 1] * normals[v, 1] + view[2, 2] * normals[v, 2]
        light = headlight(nx, ny, nz)
        if kind == GOURAUD:
            attr[v, 0] = light
        elif kind == PIXEL_COLOR:
            attr[v, 0] = s[v]
            attr[v, 1] = light
        else:  # VERTEX_COLOR
            r, g, b, a = texel_rgba(texels, texf, linear, s[v])
            attr[v, 0] = r * light
            attr[v, 1] = g * light
            attr[v, 2] = b * light
            attr[v, 3] = a
            if attr.shape[1] > 4:
                attr[v, 4] = light


@numba.njit(cache=True, inline="always")
def _eye(view, pos, v, r):
    """Row ``r`` of ``view · (p, 1)`` in float32, summed in the vertex shader's order."""
    return view[r, 0] * pos[v, 0] + view[r, 1] * pos[v, 1] + view[r, 2] * pos[v, 2] + view[r, 3]


@numba.njit(cache=True, parallel=True)
def light_triangles(pos, tris, view, fx, fy, bits, out):
    """Flat lighting, as GL's ``cross(dFdx(p_eye), dFdy(p_eye))``: the headlight of the normal
    of the gradient of the float32 eye-space vertex positions (as the vertex shader computes
    them) over the *snapped* image positions (``fx``, ``fy``), which is what a GL driver
    differentiates; ``pos`` (V, 3) float32 relative to the origin, ``view`` (4, 4) float32;
    ``out`` (K,) float32 (0.25 for a triangle without area)."""
    inv = 1.0 / (1 << bits)
    for k in prange(tris.shape[0]):
        out[k] = _flat_light(pos, view, fx, fy, inv, tris[k, 0], tris[k, 1], tris[k, 2])


@numba.njit(cache=True, inline="always")
def _flat_light(pos, view, fx, fy, inv, a, b, c):
    """The flat light of triangle (a, b, c) (:func:`light_triangles`); ``inv`` is one over the
    sub-pixel scale of the snapped ``fx``, ``fy``."""
    x1, y1 = (fx[b] - fx[a]) * inv, (fy[b] - fy[a]) * inv
    x2, y2 = (fx[c] - fx[a]) * inv, (fy[c] - fy[a]) * inv
    det = x1 * y2 - y1 * x2
    if det == 0:
        return np.float32(0.25)
    ea0, ea1, ea2 = _eye(view, pos, a, 0), _eye(view, pos, a, 1), _eye(view, pos, a, 2)
    e1x = np.float64(_eye(view, pos, b, 0)) - ea0
    e1y = np.float64(_eye(view, pos, b, 1)) - ea1
    e1z = np.float64(_eye(view, pos, b, 2)) - ea2
    e2x = np.float64(_eye(view, pos, c, 0)) - ea0
    e2y = np.float64(_eye(view, pos, c, 1)) - ea1
    e2z = np.float64(_eye(view, pos, c, 2)) - ea2
    gxx, gyx = (e1x * y2 - e2x * y1) / det, (e2x * x1 - e1x * x2) / det
    gxy, gyy = (e1y * y2 - e2y * y1) / det, (e2y * x1 - e1y * x2) / det
    gxz, gyz = (e1z * y2 - e2z * y1) / det, (e2z * x1 - e1z * x2) / det
    nx = gxy * gyz - gxz * gyy
    ny = gxz * gyx - gxx * gyz
    nz = gxx * gyy - gxy * gyx
    len2 = nx * nx + ny * ny + nz * nz
    return np.float32(0.25 + 0.75 * abs(nz) / np.sqrt(len2)) if len2 > 0 else np.float32(0.25)


# ----------------------------------------------------------------------------- clip triangle
@numba.njit(cache=True, parallel=True)
def clip_triangles(tris, k0, fx, fy, fz, ok, clipd, width, height, bits, keep):
    """``keep[k]`` for triangles ``k0 + k``: vertices placed, non-zero area, a pixel centre of
    the image inside the bounding box, not wholly before the near or beyond the far plane, not
    wholly outside one clip plane (``clipd`` (V, P) signed distances)."""
    wmax = (width - 1) << bits
    hmax = (height - 1) << bits
    for k in prange(keep.shape[0]):
        a, b, c = tris[k0 + k, 0], tris[k0 + k, 1], tris[k0 + k, 2]
        good = ok[a] and ok[b] and ok[c]
        if good:
            area = (fx[b] - fx[a]) * (fy[c] - fy[a]) - (fy[b] - fy[a]) * (fx[c] - fx[a])
            lo_x, hi_x = min(fx[a], fx[b], fx[c]), max(fx[a], fx[b], fx[c])
            lo_y, hi_y = min(fy[a], fy[b], fy[c]), max(fy[a], fy[b], fy[c])
            good = area != 0 and hi_x >= 0 and hi_y >= 0 and lo_x <= wmax and lo_y <= hmax
            # a pixel centre (multiple of 2^bits) within [lo, hi] on both axes
            good = good and (-((-lo_x) >> bits)) <= (hi_x >> bits) \
                and (-((-lo_y) >> bits)) <= (hi_y >> bits)
        if good:
            za, zb, zc = fz[a], fz[b], fz[c]
            good = not (za < 0 and zb < 0 and zc < 0) and not (za > 1 and zb > 1 and zc > 1)
        if good:
            for p in range(clipd.shape[1]):
                if clipd[a, p] < 0 and clipd[b, p] < 0 and clipd[c, p] < 0:
                    good = False
        keep[k] = good


# ----------------------------------------------------------------------------- gradients
@numba.njit(cache=True, inline="always")
def _plane(x0, y0, x1, y1, x2, y2, a0, a1, a2, out, row, col):
    det = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)
    ax = ((a1 - a0) * (y2 - y0) - (a2 - a0) * (y1 - y0)) / det
    ay = ((a2 - a0) * (x1 - x0) - (a1 - a0) * (x2 - x0)) / det
    out[row, col, 0] = a0 - ax * x0 - ay * y0
    out[row, col, 1] = ax
    out[row, col, 2] = ay


@numba.njit(cache=True, parallel=True)
def depth_gradient(kept, tris, fx, fy, fz, bits, zplane):
    """``zplane`` (n, 1, 3) float64: window depth ``c + a·i + b·j`` at the centre of pixel
    (i, j), from the snapped vertex positions."""
    inv = 1.0 / (1 << bits)
    for m in prange(kept.shape[0]):
        k = kept[m]
        a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
        _plane(fx[a] * inv, fy[a] * inv, fx[b] * inv, fy[b] * inv, fx[c] * inv, fy[c] * inv,
               np.float64(fz[a]), np.float64(fz[b]), np.float64(fz[c]), zplane, m, 0)


@numba.njit(cache=True, parallel=True)
def scalar_gradient(kept, tris, fx, fy, bits, attr, clipd, planes):
    """``planes`` (n, A + P, 3) float64: the per-vertex attributes ``attr`` (V, A) and clip
    distances ``clipd`` (V, P) as planes over pixel centres, like :func:`depth_gradient`."""
    inv = 1.0 / (1 << bits)
    n_attr = attr.shape[1]
    for m in prange(kept.shape[0]):
        k = kept[m]
        a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
        x0, y0, x1, y1 = fx[a] * inv, fy[a] * inv, fx[b] * inv, fy[b] * inv
        x2, y2 = fx[c] * inv, fy[c] * inv
        for q in range(n_attr):
            _plane(x0, y0, x1, y1, x2, y2, np.float64(attr[a, q]), np.float64(attr[b, q]),
                   np.float64(attr[c, q]), planes, m, q)
        for p in range(clipd.shape[1]):
            _plane(x0, y0, x1, y1, x2, y2, np.float64(clipd[a, p]), np.float64(clipd[b, p]),
                   np.float64(clipd[c, p]), planes, m, n_attr + p)


# ----------------------------------------------------------------------------- range and TC
@numba.njit(cache=True, parallel=True)
def range_and_tc(kept, tris, fx, fy, width, height, bits, verts, box):
    """Per kept triangle: ``verts`` (n, 6) int64 fixed-point vertices oriented to positive area
    (v0, v1, v2; their differences are es2008's triangle coordinates), ``box`` (n, 4) int32
    first/last pixel column and row whose centres the bounding box holds, clamped to the
    image."""
    for m in prange(kept.shape[0]):
        k = kept[m]
        a, b, c = tris[k, 0], tris[k, 1], tris[k, 2]
        area = (fx[b] - fx[a]) * (fy[c] - fy[a]) - (fy[b] - fy[a]) * (fx[c] - fx[a])
        if area < 0:
            b, c = c, b
        verts[m, 0], verts[m, 1] = fx[a], fy[a]
        verts[m, 2], verts[m, 3] = fx[b], fy[b]
        verts[m, 4], verts[m, 5] = fx[c], fy[c]
        lo_x, hi_x = min(fx[a], fx[b], fx[c]), max(fx[a], fx[b], fx[c])
        lo_y, hi_y = min(fy[a], fy[b], fy[c]), max(fy[a], fy[b], fy[c])
        box[m, 0] = max(-((-lo_x) >> bits), 0)
        box[m, 1] = min(hi_x >> bits, width - 1)
        box[m, 2] = max(-((-lo_y) >> bits), 0)
        box[m, 3] = min(hi_y >> bits, height - 1)


@numba.njit(cache=True, parallel=True)
def collect_table_fit(verts, size, fit):
    """``fit[m]``: all four triangle coordinates (v1 − v0, v2 − v0, in pixels; 0 sub-pixel
    bits) lie in [−size, size − 1], so the span table of that size holds the triangle."""
    for m in prange(verts.shape[0]):
        inside = True
        for q in range(2, 6):
            d = verts[m, q] - verts[m, q % 2]
            if d < -size or d > size - 1:
                inside = False
        fit[m] = inside


# ----------------------------------------------------------------------------- bin
@numba.njit(cache=True, parallel=True)
def bin_triangles(box, shift, tiles_x, n_tiles, chunks):
    """Screen tiles of ``2^shift`` × ``2^shift`` pixels: each kept triangle listed in every tile its
    box meets, in triangle order. Returns ``(start, members, frag_start)``: tile t's triangles
    are ``members[start[t]:start[t + 1]]``; ``frag_start`` (n_tiles + 1) bounds each tile's
    fragment slots by the area of the boxes it clips. The triangles are counted and placed in
    ``chunks`` consecutive runs in parallel; the lists do not depend on ``chunks``."""
    n = box.shape[0]
    tile = 1 << shift
    count = np.zeros((chunks, n_tiles), np.int64)
    slots = np.zeros((chunks, n_tiles), np.int64)
    for c in prange(chunks):
        for m in range(c * n // chunks, (c + 1) * n // chunks):
            for ty in range(box[m, 2] >> shift, (box[m, 3] >> shift) + 1):
                j0, j1 = max(box[m, 2], ty * tile), min(box[m, 3], ty * tile + tile - 1)
                for tx in range(box[m, 0] >> shift, (box[m, 1] >> shift) + 1):
                    i0, i1 = max(box[m, 0], tx * tile), min(box[m, 1], tx * tile + tile - 1)
                    count[c, ty * tiles_x + tx] += 1
                    slots[c, ty * tiles_x + tx] += (i1 - i0 + 1) * (j1 - j0 + 1)
    start = np.zeros(n_tiles + 1, np.int64)
    frag_start = np.zeros(n_tiles + 1, np.int64)
    fill = np.empty((chunks, n_tiles), np.int64)
    for t in range(n_tiles):  # tile-major, chunk order inside a tile: triangle order
        at = start[t]
        for c in range(chunks):
            fill[c, t] = at
            at += count[c, t]
            frag_start[t + 1] += slots[c, t]
        start[t + 1] = at
        frag_start[t + 1] += frag_start[t]
    members = np.empty(start[n_tiles], np.int32)
    for c in prange(chunks):
        for m in range(c * n // chunks, (c + 1) * n // chunks):
            for ty in range(box[m, 2] >> shift, (box[m, 3] >> shift) + 1):
                for tx in range(box[m, 0] >> shift, (box[m, 1] >> shift) + 1):
                    t = ty * tiles_x + tx
                    members[fill[c, t]] = m
                    fill[c, t] += 1
    return start, members, frag_start


# ----------------------------------------------------------------------------- generate fragment
@numba.njit(cache=True, inline="always")
def _edges(x0, y0, x1, y1, x2, y2, bits):
    """The edge functions of a triangle of positive area in fixed point (``bits`` fraction
    bits): per edge its deltas, its bias (covered ⇔ E − bias ≥ 0, bias 1 on the edges that do
    not own their ties: :mod:`.rule`) and its step from one pixel centre to the next in x.
    Returns (dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, step0, step1, step2)."""
    dx0, dy0 = x1 - x0, y1 - y0
    dx1, dy1 = x2 - x1, y2 - y1
    dx2, dy2 = x0 - x2, y0 - y2
    bias0 = 0 if (dy0 < 0 or (dy0 == 0 and dx0 < 0)) else 1
    bias1 = 0 if (dy1 < 0 or (dy1 == 0 and dx1 < 0)) else 1
    bias2 = 0 if (dy2 < 0 or (dy2 == 0 and dx2 < 0)) else 1
    return dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, dy0 << bits, dy1 << bits, dy2 << bits


@numba.njit(cache=True, inline="always")
def _edge_at(dx, dy, x, y, px, py, bias):
    """An edge function from (x, y) along (dx, dy), less its bias, at the fixed-point pixel
    centre (px, py): ≥ 0 on the covered side."""
    return dx * (py - y) - dy * (px - x) - bias


@numba.njit(cache=True, parallel=True)
def generate_fragments(start, members, frags, setup, table, tile, tiles_x, bits, early, depth):
    """The fragments of each tile's triangles (``members[start[t]:start[t + 1]]``, set up in
    ``setup``, a :class:`~.state.Setup`), in triangle order, into the tile's slots of
    ``frags`` (a :class:`~.state.Fragments`: reads ``start``, writes ``tri``, ``i``, ``j``,
    ``count``): table-fit triangles from the span table ``table`` (a :class:`~.state.Span`,
    :mod:`.spantable`), the others by testing every pixel centre of their box against the
    three edge functions (the binned half-space rasterizer); tiles of ``tile`` pixels a side,
    ``tiles_x`` a row, ``bits`` sub-pixel bits. With ``early``, a fragment farther than what
    ``depth`` already holds is not generated: the depth buffer only decreases, so the write
    would reject it anyway (the image is the same)."""
    frag_start = frags.start
    frag_count = frags.count
    frag_tri = frags.tri
    frag_i = frags.i
    frag_j = frags.j
    verts = setup.verts
    box = setup.box
    fit = setup.fit
    zplane = setup.zplane
    lo_table = table.lo
    hi_table = table.hi
    size = table.size
    span = 2 * size
    for t in prange(start.shape[0] - 1):
        ti0 = (t % tiles_x) * tile
        tj0 = (t // tiles_x) * tile
        pos = frag_start[t]
        for q in range(start[t], start[t + 1]):
            m = members[q]
            i0, i1 = max(box[m, 0], ti0), min(box[m, 1], ti0 + tile - 1)
            j0, j1 = max(box[m, 2], tj0), min(box[m, 3], tj0 + tile - 1)
            x0, y0 = verts[m, 0], verts[m, 1]
            zc, za, zb = zplane[m, 0, 0], zplane[m, 0, 1], zplane[m, 0, 2]
            if fit[m]:
                base = ((((verts[m, 2] - x0 + size) * span + verts[m, 3] - y0 + size) * span
                         + verts[m, 4] - x0 + size) * span + verts[m, 5] - y0 + size) * span
                for j in range(j0, j1 + 1):
                    row = base + j - y0 + size
                    first = lo_table[row]
                    if first < 0:
                        continue
                    a = max(x0 + first - size, i0)
                    b = min(x0 + hi_table[row] - size, i1)
                    for i in range(a, b + 1):
                        if early and np.float32(zc + za * i + zb * j) > depth[j, i]:
                            continue
                        frag_tri[pos] = m
                        frag_i[pos] = i
                        frag_j[pos] = j
                        pos += 1
                continue
            x1, y1, x2, y2 = verts[m, 2], verts[m, 3], verts[m, 4], verts[m, 5]
            (dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, step0, step1,
             step2) = _edges(x0, y0, x1, y1, x2, y2, bits)
            px0 = i0 << bits
            zc, za, zb = zplane[m, 0, 0], zplane[m, 0, 1], zplane[m, 0, 2]
            for j in range(j0, j1 + 1):
                py = j << bits
                e0 = _edge_at(dx0, dy0, x0, y0, px0, py, bias0)
                e1 = _edge_at(dx1, dy1, x1, y1, px0, py, bias1)
                e2 = _edge_at(dx2, dy2, x2, y2, px0, py, bias2)
                for i in range(i0, i1 + 1):
                    # all three ≥ 0 ⇔ their bitwise or ≥ 0
                    if (e0 | e1 | e2) >= 0 and not (
                            early and np.float32(zc + za * i + zb * j) > depth[j, i]):
                        frag_tri[pos] = m
                        frag_i[pos] = i
                        frag_j[pos] = j
                        pos += 1
                    e0 -= step0
                    e1 -= step1
                    e2 -= step2
        frag_count[t] = pos - frag_start[t]


# ----------------------------------------------------------------------------- fragment calculation
@numba.njit(cache=True, parallel=True)
def interpolate_z(frags, zplane, planes, n_attr, frag_z):
    """Window depth of every fragment of ``frags`` (a :class:`~.state.Fragments`; float32), and
    the fragment-wise clipping: depth outside [0, 1] or a clip distance below 0 rejects it
    (depth set to +inf, which never passes)."""
    frag_start = frags.start
    frag_count = frags.count
    frag_tri = frags.tri
    frag_i = frags.i
    frag_j = frags.j
    n_planes = planes.shape[1] - n_attr
    for t in prange(frag_count.shape[0]):
        for f in range(frag_start[t], frag_start[t] + frag_count[t]):
            m, i, j = frag_tri[f], frag_i[f], frag_j[f]
            z = zplane[m, 0, 0] + zplane[m, 0, 1] * i + zplane[m, 0, 2] * j
            good = 0.0 <= z <= 1.0
            for p in range(n_planes):
                q = n_attr + p
                if planes[m, q, 0] + planes[m, q, 1] * i + planes[m, q, 2] * j < 0.0:
                    good = False
            frag_z[f] = np.float32(z) if good else np.float32(np.inf)


@numba.njit(cache=True, parallel=True)
def interpolate_color(frags, planes, kept, lit, look, frag_z, frag_rgba):
    """Packed RGBA8 of every fragment of ``frags`` (a :class:`~.state.Fragments`) not yet
    rejected, as the mesh path of ``look.code`` shades it (``look`` a :class:`~.state.Look`,
    the per-triangle light, texture coordinate and missing flags from ``lit``, a
    :class:`~.state.Lit`); a fragment whose colour fails the alpha test (α < ½, with
    ``alpha_test``) is rejected. A fragment of a triangle flagged in ``tri_missing`` (read
    where ``any_missing``) takes the ``missing`` colour times its light, never alpha tested
    (the no-result rule). The kinds whose colour is one per triangle (constant, flat, element
    colour) compute it once per run of the triangle's fragments."""
    frag_start = frags.start
    frag_count = frags.count
    frag_tri = frags.tri
    frag_i = frags.i
    frag_j = frags.j
    tri_light = lit.tri_light
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
    per_triangle = kind == CONSTANT or kind == FLAT or kind == ELEMENT_COLOR
    for t in prange(frag_count.shape[0]):
        last = -1
        color = np.uint32(0)
        visible = True
        for f in range(frag_start[t], frag_start[t] + frag_count[t]):
            if frag_z[f] == np.inf:
                continue
            m, i, j = frag_tri[f], frag_i[f], frag_j[f]
            if per_triangle:
                if m != last:
                    last = m
                    visible = True
                    if kind == CONSTANT:
                        color = pack(base[0], base[1], base[2])
                    elif kind == FLAT:
                        light = tri_light[kept[m]]
                        color = pack(base[0] * light, base[1] * light, base[2] * light)
                    else:  # ELEMENT_COLOR
                        s = tri_s[kept[m]]
                        light = tri_light[kept[m]]
                        if any_missing and tri_missing[kept[m]] != 0:
                            color = pack(missing[0] * light, missing[1] * light,
                                         missing[2] * light)
                        else:
                            r, g, b, a = texel_rgba(texels, texf, linear, s)
                            visible = not (alpha_test and a < 0.5)
                            color = pack(r * light, g * light, b * light)
                if visible:
                    frag_rgba[f] = color
                else:
                    frag_z[f] = np.float32(np.inf)
            elif kind == GOURAUD:
                light = np.float32(planes[m, 0, 0] + planes[m, 0, 1] * i + planes[m, 0, 2] * j)
                frag_rgba[f] = pack(base[0] * light, base[1] * light, base[2] * light)
            elif any_missing and tri_missing[kept[m]] != 0:  # VERTEX_COLOR or PIXEL_COLOR
                q = 4 if kind == VERTEX_COLOR else 1  # the light's plane
                light = np.float32(planes[m, q, 0] + planes[m, q, 1] * i + planes[m, q, 2] * j)
                frag_rgba[f] = pack(missing[0] * light, missing[1] * light, missing[2] * light)
            elif kind == VERTEX_COLOR:
                r = np.float32(planes[m, 0, 0] + planes[m, 0, 1] * i + planes[m, 0, 2] * j)
                g = np.float32(planes[m, 1, 0] + planes[m, 1, 1] * i + planes[m, 1, 2] * j)
                b = np.float32(planes[m, 2, 0] + planes[m, 2, 1] * i + planes[m, 2, 2] * j)
                a = np.float32(planes[m, 3, 0] + planes[m, 3, 1] * i + planes[m, 3, 2] * j)
                if alpha_test and a < 0.5:
                    frag_z[f] = np.float32(np.inf)
                else:
                    frag_rgba[f] = pack(r, g, b)
            else:  # PIXEL_COLOR
                s = np.float32(planes[m, 0, 0] + planes[m, 0, 1] * i + planes[m, 0, 2] * j)
                light = np.float32(planes[m, 1, 0] + planes[m, 1, 1] * i + planes[m, 1, 2] * j)
                r, g, b, a = texel_rgba(texels, texf, linear, s)
                if alpha_test and a < 0.5:
                    frag_z[f] = np.float32(np.inf)
                else:
                    frag_rgba[f] = pack(r * light, g * light, b * light)


# ----------------------------------------------------------------------------- write fragment
@numba.njit(cache=True, parallel=True)
def write_fragments(frags, frag_z, frag_rgba, kept, ids, target):
    """The depth-tested write of ``frags`` (a :class:`~.state.Fragments`) into ``target`` (a
    :class:`~.state.Target`), tile by tile: a fragment replaces the pixel when it is nearer,
    or as near and of a lower triangle index (an empty pixel, index −1, keeps its clear
    depth). Drawn in index order this is GL's ``LESS`` test (the first of equal depths
    stays); in any order it gives the same image."""
    frag_start = frags.start
    frag_count = frags.count
    frag_tri = frags.tri
    frag_i = frags.i
    frag_j = frags.j
    depth = target.depth
    color = target.color
    triangle = target.triangle
    for t in prange(frag_count.shape[0]):
        for f in range(frag_start[t], frag_start[t] + frag_count[t]):
            z = frag_z[f]
            i, j = frag_i[f], frag_j[f]
            d = depth[j, i]
            if z < d or (z == d and ids[kept[frag_tri[f]]] < triangle[j, i]):
                depth[j, i] = z
                color[j, i] = frag_rgba[f]
                triangle[j, i] = ids[kept[frag_tri[f]]]
