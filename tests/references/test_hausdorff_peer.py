"""Our certified Hausdorff bracket beside an independent one (``cascading-upper-bounds``, Sacht &
Jacobson 2024) on pairs whose one-sided distance is known exactly, and the wrapper's contract.

Every pair is built so that its exact value holds *for the float64 coordinates as given*:
integer or dyadic coordinates (midpoints and far offsets add no rounding), planes parallel to
the axes or z = slope · x with a dyadic slope, offsets that are whole numbers. Both brackets
must contain the exact value (ours as it is, the peer's within its stated rounding slack, since
it does not widen its bracket) and overlap each other. Where the exact value comes from a
formula evaluated in float64 (h / sqrt(1 + h²)), it is granted 4 units in the last place.
"""

import math

import numpy as np
import pytest
from meshes import quad_grid

from workbench.algo.hausdorff import hausdorff
from workbench.references.cascading_upper_bounds import (
    PEER,
    brackets_overlap,
    compare_with_peer,
    default_tol,
    peer_hausdorff,
    peer_unavailable,
)

pytestmark = pytest.mark.skipif(peer_unavailable() is not None,
                                reason=peer_unavailable() or "")


# --------------------------------------------------------------------------- exact pairs
def sheet(n, m=None, size=4.0, z=0.0):
    """An n×m grid over [0, size]², two triangles per cell, at height z (dyadic if size is)."""
    return quad_grid(n, n if m is None else m, span=((0.0, size), (0.0, size)), z=z,
                     triangles=True)


def bumpy(n=4):
    """A height field on integer coordinates with quarter-integer heights: every midpoint of
    its edges is exact in float64."""
    v, f = sheet(n, size=float(n))
    i, j = v[:, 0].astype(int), v[:, 1].astype(int)
    v[:, 2] = 0.25 * ((i * j + 2 * i) % 5) - 0.5
    return v, f


def refined(v, f):
    """Every triangle split 4 ways at its edge midpoints (a soup: vertices repeated). Covers
    exactly the same surface where the midpoints are exact."""
    c = v[f]
    m01, m12, m20 = (c[:, 0] + c[:, 1]) / 2, (c[:, 1] + c[:, 2]) / 2, (c[:, 2] + c[:, 0]) / 2
    tris = np.concatenate([np.stack(t, axis=1) for t in (
        (c[:, 0], m01, m20), (m01, c[:, 1], m12), (m20, m12, c[:, 2]), (m01, m12, m20))])
    return tris.reshape(-1, 3), np.arange(3 * len(tris)).reshape(-1, 3)


def lifted_vertex(d, n=4):
    """An n×n sheet over [0, n]² with its middle vertex lifted by d."""
    v, f = sheet(n, size=float(n))
    v[np.flatnonzero((v[:, 0] == n // 2) & (v[:, 1] == n // 2)), 2] = d
    return v, f


def pyramid(h):
    """The square [-1, 1]² as four triangles around its centre, lifted to h."""
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0, 0, h]], float)
    return v, np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])


def flat_square():
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def sliver_square(thin, z=0.0):
    """The unit square as four triangles around an interior point (0.5, thin): the triangle on
    the bottom edge has height ``thin`` over a base of 1 (a cap sliver)."""
    v = np.array([[0, 0, z], [1, 0, z], [1, 1, z], [0, 1, z], [0.5, thin, z]], float)
    return v, np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])


def needle_square(thin, z=0.0):
    """The unit square as four triangles around the point (thin, thin) near its corner: two
    needles (an edge of length ~thin·√2) and two slivers."""
    v, f = sliver_square(0.0, z)
    v[4, :2] = thin
    return v, f


def strips(n, z=0.0):
    """The unit square as 2n triangles, n strips 1/n wide and 1 long (aspect n)."""
    x = np.arange(n + 1) / n
    v = np.concatenate([np.stack([x, np.zeros_like(x), np.full_like(x, z)], 1),
                        np.stack([x, np.ones_like(x), np.full_like(x, z)], 1)])
    i = np.arange(n)
    f = np.concatenate([np.stack([i, i + 1, n + 2 + i], 1), np.stack([i, n + 2 + i, n + 1 + i], 1)])
    return v, f


def segment_above(d):
    """A degenerate triangle (a segment, vertex repeated) at height d over [0, 1]²."""
    return np.array([[0.25, 0.5, d], [0.75, 0.5, d]]), np.array([[0, 1, 1]])


def tilted(v, slope, lift=0.0):
    """``v`` moved onto the plane z = slope · x + lift (exact for dyadic slope, x and lift)."""
    v = v.copy()
    v[:, 2] = slope * v[:, 0] + lift
    return v


def inner(v):
    """[0, 1]² mapped onto [0.25, 0.75]² (exact)."""
    v = v.copy()
    v[:, :2] = 0.25 + 0.5 * v[:, :2]
    return v


def tilted_pairs(slopes, thins, d=0.0625):
    """Slivers in the plane z = slope · x (their thin side along y, so that far offsets keep
    them in it) and the inner half of the unit square lifted by d above it, either way, and
    slivers over slivers: every point of A is d / sqrt(1 + slope²) from the plane, and its
    foot (shifted by at most d/2 in x) stays on B."""
    out = []
    vq, fq = sheet(2, size=1.0)
    for s in slopes:
        exact = d / math.sqrt(1 + s * s)
        for thin in thins:
            vs, fs = sliver_square(thin)
            out += [(f"tilted {s:g}: square over slivers {thin:g}", tilted(inner(vq), s, d), fq,
                     tilted(vs, s), fs, exact),
                    (f"tilted {s:g}: slivers {thin:g} over a square", tilted(inner(vs), s, d), fs,
                     tilted(vq, s), fq, exact),
                    (f"tilted {s:g}: slivers over slivers {thin:g}", tilted(inner(vs), s, d), fs,
                     tilted(vs, s), fs, exact)]
    return out


def exact_pairs():
    """(name, va, fa, vb, fb, exact one-sided distance A → B), near the origin."""
    out = []
    v, f = bumpy()
    out.append(("itself", v, f, v.copy(), f.copy(), 0.0))
    vr, fr = refined(v, f)
    out.append(("against its refined copy", v, f, vr, fr, 0.0))
    out.append(("refined copy against it", vr, fr, v, f, 0.0))
    for d in (2.0 ** -20, 0.375, 7.0):
        out.append((f"coarse sheet {d:g} over a fine one", *sheet(3, z=d), *sheet(8), d))
        out.append((f"fine sheet {d:g} over a coarse one", *sheet(8, z=d), *sheet(3), d))
    for d in (2.0 ** -10, 0.5, 3.0):
        out.append((f"vertex lifted by {d:g} against the flat sheet", *lifted_vertex(d),
                    *sheet(4), d))
    for h in (0.0625, 0.75, 3.0):
        out.append((f"flat square against a pyramid {h:g}", *flat_square(), *pyramid(h),
                    h / math.sqrt(1 + h * h)))
        out.append((f"pyramid {h:g} against the flat square", *pyramid(h), *flat_square(), h))
    for thin in (1e-3, 1e-6, 1e-9, 1e-12):
        out.append((f"square 0.5 over slivers {thin:g}", *sliver_square(0.0, 0.5),
                    *sliver_square(thin), 0.5))
        out.append((f"slivers {thin:g} 0.5 over a square", *sliver_square(thin, 0.5),
                    *sheet(1, size=1.0), 0.5))
        out.append((f"slivers {thin:g} 0.25 over slivers", *sliver_square(thin, 0.25),
                    *sliver_square(thin), 0.25))
        out.append((f"needles {thin:g} 0.5 over needles", *needle_square(thin, 0.5),
                    *needle_square(thin / 2), 0.5))
    out += strip_pairs(50)
    out += tilted_pairs((0.5,), (1e-6, 1e-12))
    out.append(("a segment 0.5 over the square", *segment_above(0.5), *sheet(2, size=1.0), 0.5))
    return out


def strip_pairs(n):
    """A square and n strips of aspect n, each 0.125 over the other."""
    return [(f"strips (aspect {n}) 0.125 over a square", *strips(n, 0.125), *sheet(1, size=1.0),
             0.125),
            (f"square 0.125 over strips (aspect {n})", *sheet(1, size=1.0, z=0.125), *strips(n),
             0.125)]


OFFSETS = (0.0, 1e3, 1e6)
PAIRS = exact_pairs()
# the sweep adds thinner strips (ours takes seconds on the square over 1 000 strips) and more
# tilted slivers
SLOW_PAIRS = (PAIRS + strip_pairs(1000) + tilted_pairs((0.5,), (1e-3, 1e-9))
              + tilted_pairs((1.0, 4.0), (1e-3, 1e-6, 1e-9, 1e-12)))


def shifted(pair, offset, axes=(0, 1, 2)):
    """The pair moved by the whole number ``offset`` along (x, -y, z) (exact for these
    coordinates) with its axes permuted to ``axes``."""
    name, va, fa, vb, fb, exact = pair
    shift = np.array([offset, -offset, offset])
    return name, va[:, axes] + shift, fa, vb[:, axes] + shift, fb, exact


def check_both(va, fa, vb, fb, exact, tol=None):
    """Both brackets at the same tolerance: each holds ``exact``, and they overlap. Returns
    (ours, peer)."""
    tol = default_tol(va, fa) if tol is None else tol
    ours = hausdorff(va, fa, vb, fb, tol=tol)
    peer = peer_hausdorff(va, fa, vb, fb, tol=tol)
    assert peer.failure is None, peer.failure
    formula = 4 * np.finfo(float).eps * exact
    assert ours.lower - formula <= exact <= ours.upper + formula, (
        f"ours [{ours.lower!r}, {ours.upper!r}] excludes {exact!r}")
    assert peer.lower - peer.rounding - formula <= exact <= peer.upper + peer.rounding + formula, (
        f"peer [{peer.lower!r}, {peer.upper!r}] ± {peer.rounding:.3g} excludes {exact!r}")
    assert brackets_overlap(ours.lower, ours.upper, peer.lower, peer.upper, peer.rounding), (
        f"ours [{ours.lower!r}, {ours.upper!r}], peer [{peer.lower!r}, {peer.upper!r}]")
    return ours, peer


@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("pair", PAIRS, ids=[p[0] for p in PAIRS])
def test_both_brackets_hold_the_exact_distance(pair, offset):
    name, va, fa, vb, fb, exact = shifted(pair, offset)
    check_both(va, fa, vb, fb, exact)


@pytest.mark.slow
@pytest.mark.parametrize("offset", (1e4, 1e5, 1e6 + 0.5))
@pytest.mark.parametrize("axes", [(0, 1, 2), (2, 0, 1), (1, 2, 0)])
@pytest.mark.parametrize("pair", SLOW_PAIRS, ids=[p[0] for p in SLOW_PAIRS])
def test_both_brackets_hold_the_exact_distance_turned(pair, offset, axes):
    """The sweep: more offsets, the axes permuted (sheets facing x and y), the thinner strips.
    At the default width: the peer cannot go much tighter on a surface against itself (at 1e-5
    of the diagonal it exceeds even 1e4 times A's faces)."""
    name, va, fa, vb, fb, exact = shifted(pair, offset, axes)
    check_both(va, fa, vb, fb, exact)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
def test_a_turned_surface_against_itself(seed):
    """Any coordinates, also rounded by a rotation and far from the origin: a surface against
    an identical copy of itself is at distance 0."""
    rng = np.random.default_rng(seed)
    v, f = bumpy(6)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    v = v @ q.T * rng.uniform(0.01, 100.0) + rng.uniform(-1e6, 1e6, size=3)
    check_both(v, f, v.copy(), f.copy(), 0.0)


def segment_over_sliver(thin, e, offset=0.0):
    """B: the sliver (0, 0, 0), (1, 0, 0), (0.5, thin, thin) in the plane y = z; A: a segment
    (a degenerate triangle) along x over its middle, moved by (0, e, -e) along the plane's
    normal, so that every point of A is e·√2 from the sliver's interior. Shifted by the whole
    number ``offset`` along (x, -y, z)."""
    shift = np.array([offset, -offset, offset])
    vb = np.array([[0, 0, 0], [1, 0, 0], [0.5, thin, thin]], float) + shift
    va = np.array([[0.4, thin / 2 + e, thin / 2 - e], [0.6, thin / 2 + e, thin / 2 - e]]) + shift
    return va, np.array([[0, 1, 1]]), vb, np.array([[0, 1, 2]]), e * math.sqrt(2)


# (thin, e) as powers of 2
SLIVERS = [(-t, -e) for t in (10, 20, 30, 40) for e in (4, 20, 40)]


@pytest.mark.parametrize("offset", (0.0, 1e3))
@pytest.mark.parametrize("thin, e", SLIVERS, ids=[f"thin 2^{t} e 2^{e}" for t, e in SLIVERS])
def test_ours_holds_the_distance_to_a_tilted_sliver(thin, e, offset):
    va, fa, vb, fb, exact = segment_over_sliver(2.0 ** thin, 2.0 ** e, offset)
    ours = hausdorff(va, fa, vb, fb, tol=1e-4)
    formula = 4 * np.finfo(float).eps * exact
    assert ours.lower - formula <= exact <= ours.upper + formula


def test_the_peer_misses_the_distance_to_a_tilted_sliver_and_the_comparison_says_so():
    # the peer's point-triangle distance (libigl's, as the libigl package's own) loses the
    # sliver's plane: on a sliver 2^-20 thin with the segment 2^-40·√2 above it, it returns
    # 1.5e-6 for 1.3e-12, far beyond any rounding slack; our bracket holds, and the two do
    # not overlap. Should a later release fix it, this test fails: update the module notes
    va, fa, vb, fb, exact = segment_over_sliver(2.0 ** -20, 2.0 ** -40)
    c = compare_with_peer(va, fa, vb, fb, tol=1e-4, repeats=1)
    assert c.ours.lower <= exact <= c.ours.upper
    assert not c.peer.holds(exact) and c.peer.lower > 1e5 * exact
    assert not c.overlap


def test_the_exact_cases_can_fail():
    # the exact values are not a tautology: a bracket of the offset sheets excludes a wrong one
    _, va, fa, vb, fb, exact = next(p for p in PAIRS if p[0] == "coarse sheet 7 over a fine one")
    with pytest.raises(AssertionError):
        check_both(va, fa, vb, fb, exact * (1 + 1e-3))


# --------------------------------------------------------------------------- the wrapper
def test_the_peer_is_one_sided_and_gets_our_tolerance_absolute():
    v, f = pyramid(0.75)
    w, g = flat_square()
    up = peer_hausdorff(v, f, w, g, tol=1e-6)
    down = peer_hausdorff(w, g, v, f, tol=1e-6)
    assert up.holds(0.75) and not down.holds(0.75)  # A to B, not B to A
    assert down.holds(0.75 / math.sqrt(1 + 0.75 ** 2))
    assert up.tol == 1e-6 and down.tol_reached and down.width <= 1e-6
    # the default is ours: 1e-4 of A's diagonal, in model units
    assert peer_hausdorff(w * 10, g, v * 10, f).tol == pytest.approx(1e-4 * 20 * math.sqrt(2))


def test_unreferenced_vertices_of_a_are_not_measured():
    v, f = sheet(2, size=1.0, z=0.5)
    w, g = sheet(2, size=1.0)
    junk = np.array([[1e9, 0, 0], [np.nan, 0, 0]])
    base = peer_hausdorff(v, f, w, g, tol=1e-6)
    more = peer_hausdorff(np.vstack([junk, v]), f + 2, np.vstack([w, junk]), g, tol=1e-6)
    assert (more.lower, more.upper) == (base.lower, base.upper)
    assert base.holds(0.5)


@pytest.mark.parametrize("bad, message", [
    (dict(tol=0.0), "tol"), (dict(tol=-1.0), "tol"), (dict(tol=math.inf), "tol"),
    (dict(tol="1"), "tol"), (dict(fa=np.zeros((0, 3), int)), "no triangles"),
    (dict(fb=np.array([[0, 1, 99]])), "B (vb, fb)"),
    (dict(fa=np.array([[0, 1, -1]])), "A (va, fa)"),
    (dict(va=np.full((4, 3), np.nan)), "non-finite"), (dict(max_factor=0.5), "max_factor")])
def test_what_the_peer_cannot_take_is_refused_naming_it(bad, message):
    # each of these hangs, crashes or reads out of bounds inside the peer; refused before it
    v, f = flat_square()
    args = dict(va=v, fa=f, vb=v + [0, 0, 1], fb=f) | bad
    kwargs = {k: args.pop(k) for k in ("tol", "max_factor") if k in args}
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        peer_hausdorff(args["va"], args["fa"], args["vb"], args["fb"], **kwargs)


def test_a_refinement_beyond_max_factor_is_a_failure_not_an_exception():
    v, f = sheet(4, size=1.0, z=0.5)
    w, g = sheet(3, size=1.0)
    r = peer_hausdorff(v, f, w, g, tol=1e-9, max_factor=1.5)
    assert r.failure and "Exceeded maximum" in r.failure
    assert math.isnan(r.lower) and not r.tol_reached


def test_the_interleaved_comparison_times_both_at_one_tolerance():
    v, f = lifted_vertex(0.5)
    w, g = sheet(4)
    c = compare_with_peer(v, f, w, g, repeats=3)
    assert len(c.ours_seconds) == len(c.peer_seconds) == 3 and c.warmup == 1
    assert c.tol == c.peer.tol == c.ours.tol == default_tol(v, f)
    assert c.overlap and c.faster in ("ours", PEER, "neither (ratios straddle 1)")
    med, lo, hi = c.time_ratio
    assert lo <= med <= hi and lo > 0
    row = c.row()
    assert row["repeats"] == 3 and row["peer_failure"] is None
    assert row["ours_s_min"] <= row["ours_s"] <= row["ours_s_max"]
    with pytest.raises(ValueError, match="repeats"):
        compare_with_peer(v, f, w, g, repeats=0)


def test_brackets_that_do_not_meet_do_not_overlap():
    assert brackets_overlap(0.0, 1.0, 1.0, 2.0)
    assert not brackets_overlap(0.0, 1.0, 1.0 + 1e-9, 2.0)
    assert brackets_overlap(0.0, 1.0, 1.0 + 1e-9, 2.0, slack=1e-9)
    assert not brackets_overlap(0.0, 1.0, math.nan, math.nan)


# --------------------------------------------------------------------------- the command
PLATE = """*KEYWORD
*NODE
       1             0.0             0.0{z}
       2           100.0             0.0{z}
       3           100.0           100.0{z}
       4             0.0           100.0{z}
       5            50.0            50.0{zc}
*ELEMENT_SHELL
       1       1       1       2       5       5
       2       1       2       3       5       5
       3       1       3       4       5       5
       4       1       4       1       5       5
*END
"""


def plate(path, z, zc):
    path.write_text(PLATE.format(z=f"{z:16.4f}", zc=f"{zc:16.4f}"))
    return str(path)


def test_the_command_prints_the_peer_beside_ours(tmp_path, capsys):
    from workbench.cli import main

    # a plate lifted by 5 mm with its centre lifted by 20 mm, against the flat plate: 20 mm
    lifted, flat = plate(tmp_path / "lifted.k", 5.0, 20.0), plate(tmp_path / "flat.k", 0.0, 0.0)
    assert main(["hausdorff", lifted, flat, "--peers", "--repeats", "2"]) == 0
    out = capsys.readouterr().out
    assert "20 <= H <= 20 mm" in out
    peer = next(line for line in out.splitlines() if line.strip().startswith("peer:"))
    lower, upper = (float(x) for x in peer.split(":")[1].split("mm")[0].split("<= H <="))
    assert lower <= 20.0 <= upper and upper - lower <= 1e-4 * math.sqrt(2 * 100 ** 2 + 20 ** 2)
    assert f"{PEER} (Sacht & Jacobson" in out and "2 rounds" in out
    assert "the brackets overlap" in out
    assert "ours is faster" in out or f"{PEER} is faster" in out or "neither" in out
    # both directions with --symmetric; the flat plate's farthest point from the lifted one
    assert main(["hausdorff", lifted, flat, "--peers", "--repeats", "1", "--symmetric"]) == 0
    out = capsys.readouterr().out
    assert "one-sided A to B" in out and "one-sided B to A" in out
    assert out.count("the brackets overlap") == 2


def test_the_command_says_when_the_brackets_contradict(tmp_path, capsys, monkeypatch):
    import dataclasses

    from workbench.cli import main
    from workbench.references import cascading_upper_bounds as hausdorff_peers

    real = hausdorff_peers.peer_hausdorff

    def wrong(*args, **kwargs):  # a peer bracket 1 mm above the truth
        r = real(*args, **kwargs)
        return dataclasses.replace(r, lower=r.lower + 1.0, upper=r.upper + 1.0)

    monkeypatch.setattr(hausdorff_peers, "peer_hausdorff", wrong)
    lifted, flat = plate(tmp_path / "lifted.k", 5.0, 20.0), plate(tmp_path / "flat.k", 0.0, 0.0)
    assert main(["hausdorff", lifted, flat, "--peers", "--repeats", "1"]) == 1
    assert "DO NOT overlap" in capsys.readouterr().out
