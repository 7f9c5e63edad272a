"""``workbench hausdorff``: the certified Hausdorff distance between two meshes, as a bracket
lower <= H <= upper, one-sided (A to B) or symmetric."""

from __future__ import annotations

from .arguments import at_least


def add_parser(subparsers) -> None:
    """Add ``hausdorff`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "hausdorff", help="certified Hausdorff distance between two meshes",
        description="Exact float64 Hausdorff distance from mesh A to mesh B (or "
                    "symmetric) as a certified bracket lower <= H <= upper.")
    p.add_argument("mesh_a", help="mesh file or built-in scene name (A, the original)")
    p.add_argument("mesh_b", help="mesh file or built-in scene name (B)")
    p.add_argument("--symmetric", action="store_true", help="max of both directions")
    p.add_argument("--width", type=float, default=0.01,
                   help="bracket width to reach, %% of A's bounding-box diagonal (default 0.01)")
    p.add_argument("--step", type=at_least(0), default=0,
                   help="time step of the coordinates (default 0); B's last step where B has "
                        "fewer")
    p.set_defaults(func=cmd_hausdorff)


def cmd_hausdorff(args) -> int:
    """Print the bracket, its share of A's diagonal, and where it is attained; 0."""
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
    return 0
