"""``workbench hausdorff``: the certified Hausdorff distance between two meshes, as a bracket
lower <= H <= upper, one-sided (A to B) or symmetric; with ``--peers`` beside the bracket of an
independent certified tool (``cascading-upper-bounds``) at the same bracket width, both timed
interleaved."""

from __future__ import annotations

from .arguments import at_least


def add_parser(subparsers) -> None:
    """Add ``hausdorff`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "hausdorff", help="certified Hausdorff distance between two meshes",
        description="Exact float64 Hausdorff distance from mesh A to mesh B (or "
                    "symmetric) as a certified bracket lower <= H <= upper. With --peers, "
                    "also the bracket of cascading-upper-bounds (Sacht & Jacobson, SGP 2024) "
                    "at the same width, both timed interleaved; exit status 1 where the two "
                    "brackets do not overlap.")
    p.add_argument("mesh_a", help="mesh file or built-in scene name (A, the original)")
    p.add_argument("mesh_b", help="mesh file or built-in scene name (B)")
    p.add_argument("--symmetric", action="store_true", help="max of both directions")
    p.add_argument("--width", type=float, default=0.01,
                   help="bracket width to reach, %% of A's bounding-box diagonal (default 0.01)")
    p.add_argument("--step", type=at_least(0), default=0,
                   help="time step of the coordinates (default 0); B's last step where B has "
                        "fewer")
    p.add_argument("--peers", action="store_true",
                   help="also cascading-upper-bounds' one-sided bracket at the same width (A to "
                        "B; with --symmetric both directions), timed against ours interleaved")
    p.add_argument("--repeats", type=at_least(1), default=3,
                   help="with --peers: timed rounds of ours then the peer, after one untimed "
                        "round (default 3)")
    p.set_defaults(func=cmd_hausdorff)


def cmd_hausdorff(args) -> int:
    """Print the bracket, its share of A's diagonal, and where it is attained; with
    ``--peers`` the peer's bracket and times beside ours. 0, or 1 where the brackets of ours
    and the peer do not overlap."""
    from ..algo.hausdorff import hausdorff
    from ..scene.builtin import load_mesh

    a, b = load_mesh(args.mesh_a), load_mesh(args.mesh_b)
    va, fa = a.finite_coordinates(a.step_index(args.step, "--step")), a.triangles
    vb, fb = b.finite_coordinates(min(args.step, b.n_steps - 1)), b.triangles
    lo, hi = va[a.used_nodes()].min(axis=0), va[a.used_nodes()].max(axis=0)
    diagonal = float(((hi - lo) ** 2).sum() ** 0.5)
    width = args.width / 100.0 * diagonal
    h = hausdorff(va, fa, vb, fb, one_sided=not args.symmetric, tol=width)
    kind = "symmetric" if args.symmetric else "one-sided, A to B"
    units = a.units or "model units"
    print(f"Hausdorff distance ({kind}): {h.lower:.9g} <= H <= {h.upper:.9g} {units} "
          f"(width {h.width:.3g}, {'reached' if h.tol_reached else 'NOT reached'}: "
          f"{args.width:g} % of A's diagonal {diagonal:.6g})")
    print(f"  {100 * h.upper / diagonal:.6g} % of the diagonal; mean {h.mean:.6g}, "
          f"RMS {h.rms:.6g} (sample estimates); {h.seconds:.2f} s")
    p, q = h.location
    on, other = ("A", "B") if h.forward is None or h.location is h.forward.location else ("B", "A")
    print(f"  attained at {on} ({p[0]:.6g}, {p[1]:.6g}, {p[2]:.6g}), nearest {other} point "
          f"({q[0]:.6g}, {q[1]:.6g}, {q[2]:.6g})")
    if not args.peers:
        return 0
    directions = [("A to B", va, fa, vb, fb)]
    if args.symmetric:
        directions.append(("B to A", vb, fb, va, fa))
    agree = True
    for name, v1, f1, v2, f2 in directions:
        agree &= _print_peer(name, v1, f1, v2, f2, width, args, units)
    return 0 if agree else 1


def _print_peer(direction: str, va, fa, vb, fb, width: float, args, units: str) -> bool:
    """Compare ours and the peer one-sided in ``direction`` and print it; whether the brackets
    overlap (True where the peer failed: nothing contradicts ours)."""
    from ..references.cascading_upper_bounds import PEER, compare_with_peer

    c = compare_with_peer(va, fa, vb, fb, tol=width, repeats=args.repeats, warmup=1)
    print(f"{PEER} (Sacht & Jacobson, SGP 2024), one-sided {direction}, the same bracket "
          f"width {width:.6g} {units} (absolute; {args.width:g} % of A's diagonal); "
          f"{args.repeats} rounds of ours then the peer after 1 untimed round, wall seconds "
          f"median [min, max]:")
    t, t_lo, t_hi = c.ours_time
    print(f"  ours: {c.ours.lower:.9g} <= H <= {c.ours.upper:.9g} {units} "
          f"({'reached' if c.ours.tol_reached else 'NOT reached'}), "
          f"{t:.4g} s [{t_lo:.4g}, {t_hi:.4g}] (all cores)")
    if c.peer.failure:
        print(f"  peer: failed: {c.peer.failure}")
        return True
    t, t_lo, t_hi = c.peer_time
    print(f"  peer: {c.peer.lower:.9g} <= H <= {c.peer.upper:.9g} {units} "
          f"({'reached' if c.peer.tol_reached else 'NOT reached'}), "
          f"{t:.4g} s [{t_lo:.4g}, {t_hi:.4g}] (one thread)")
    r, r_lo, r_hi = c.time_ratio
    faster = {"ours": "ours is faster", PEER: f"{PEER} is faster"}.get(
        c.faster, "neither is faster in every round")
    print(f"  peer / ours time {r:.3g} [{r_lo:.3g}, {r_hi:.3g}]: {faster}; the brackets "
          + ("overlap" if c.overlap else
             f"DO NOT overlap (peer granted {c.peer.rounding:.3g} for rounding): one of the two "
             f"is wrong"))
    return c.overlap
