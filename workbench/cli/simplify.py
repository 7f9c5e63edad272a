"""``workbench simplify``: Hausdorff-bounded decimation (crash2000) of a mesh, part by part,
optionally written to a mesh file."""

from __future__ import annotations


def add_parser(subparsers) -> None:
    """Add ``simplify`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "simplify", help="Hausdorff-bounded decimation (crash2000), per part",
        description="Half-edge collapses until the certified one-sided Hausdorff "
                    "distance would exceed the tolerance; vertices never move.")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    p.add_argument("--tol", type=float, default=0.5,
                   help="tolerance, %% of each part's bounding-sphere diameter (default 0.5)")
    p.add_argument("-o", "--output", help="write the simplified surface (.ply, .obj, .stl, ...)")
    p.set_defaults(func=cmd_simplify)


def cmd_simplify(args) -> int:
    """Print the triangle counts, time, tolerance and collapses, and write ``--output``; 0."""
    from ..algo.simplify import hausdorff_decimate
    from ..output.export import write_surface
    from ..output.targets import output_target
    from ..scene.builtin import load_mesh

    if args.output:
        output_target(args.output)  # refused before the decimation, not after it
    mesh = load_mesh(args.mesh)
    tri = mesh.triangulation
    d = hausdorff_decimate(mesh.nodes, tri.triangles, args.tol / 100.0, relative=True,
                           parts=mesh.parts[tri.element_of])
    print(f"{mesh.name}: {len(tri.triangles)} -> {len(d.triangles)} triangles in "
          f"{d.seconds:.2f} s; one-sided Hausdorff certified <= {args.tol:g} % of each part's "
          f"bounding-sphere diameter ({d.tol_abs.min():.4g} to {d.tol_abs.max():.4g} "
          f"{mesh.units}); {d.collapses} collapses")
    if args.output:
        out = write_surface(args.output, mesh.nodes, d.triangles)
        print(f"  written to {out}")
    return 0
