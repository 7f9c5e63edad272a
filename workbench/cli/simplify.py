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
    p.add_argument("--states", type=states_option, metavar="all|A:B:S",
                   help="a result with states (a d3plot, crash[:S]): decimate at the first "
                        "of these states and measure the certified one-sided distance of the same "
                        "topology at these states, per part against its tolerance; prints the "
                        "worst part of each state and the worst of all")
    p.add_argument("--certify-states", action="store_true",
                   help="with --states: certify the decimation at every one of those states, "
                        "not only the first (a collapse is kept only where the bound holds at "
                        "all of them; triangles a result deletes at different states are "
                        "decimated apart)")
    p.set_defaults(func=cmd_simplify)


def states_option(text: str):
    """``--states``: ``all`` (every state), ``K`` or ``A:B[:S]`` (as ``animate --steps``)."""
    from .animate import state_selection

    selection = state_selection(":" if text == "all" else text)
    return selection._replace(text=text, option="--states")


def cmd_simplify(args) -> int:
    """Print the triangle counts, time, tolerance and collapses, with ``--states`` the
    certified distance of the same topology at those states (decimated at the first of them,
    or certified at all of them with ``--certify-states``), and write ``--output``; 0.
    ValueError (one line) for ``--states`` on a mesh without states or outside them, and for
    ``--certify-states`` without ``--states``."""
    from ..algo.simplify import hausdorff_decimate
    from ..output.export import write_surface
    from ..output.targets import output_target
    from ..scene.builtin import load_mesh

    if args.output:
        output_target(args.output)  # refused before the decimation, not after it
    if args.certify_states and args.states is None:
        raise ValueError("--certify-states needs --states (the states to certify at)")
    mesh = load_mesh(args.mesh)
    states = None
    if args.states is not None:  # refused before the decimation, not after it
        if mesh.steps is None:
            raise ValueError(f"--states: {mesh.name} has no states (one geometry)")
        states = args.states.states(mesh)
    tri = mesh.triangulation
    alive = mesh.triangles_alive()
    further = {}
    reference = mesh.nodes if states is None else mesh.steps[states[0]]
    if args.certify_states:
        further = {"states": mesh.steps[states[1:]]} if len(states) > 1 else {}
        if alive is not None:
            further["alive"] = alive[states]
    d = hausdorff_decimate(reference, tri.triangles, args.tol / 100.0, relative=True,
                           parts=mesh.parts[tri.element_of], **further)
    print(f"{mesh.name}: {len(tri.triangles)} -> {len(d.triangles)} triangles in "
          f"{d.seconds:.2f} s; one-sided Hausdorff certified <= {args.tol:g} % of each part's "
          f"bounding-sphere diameter ({d.tol_abs.min():.4g} to {d.tol_abs.max():.4g} "
          f"{mesh.units}); {d.collapses} collapses"
          + (f"; certified at {d.states_certified} states" if args.certify_states else ""))
    if states is not None:
        _print_states(mesh, tri, d, states, alive)
    if args.output:
        out = write_surface(args.output, reference, d.triangles)
        print(f"  written to {out}")
    return 0


def _print_states(mesh, tri, decimation, states: list[int], alive=None) -> None:
    """The certified distance of ``decimation`` at ``states`` (between the triangles drawn at
    each, where ``alive`` (T, K) says which): the worst part of each state and the worst of
    all, as ratios to the part's tolerance (above 1: exceeded)."""
    from ..algo.simplify.states import bounds_over_states

    bounds = bounds_over_states(mesh.steps, tri.triangles, mesh.parts[tri.element_of],
                                decimation, states=states, alive=alive)
    print("  certified one-sided distance of the same topology at each state, worst part "
          "(distance / the part's tolerance):")
    for k, (state, part, ratio) in enumerate(bounds.worst_per_state()):
        upper = bounds.upper[k, list(bounds.part_labels).index(part)]
        flag = "  exceeds" if ratio > 1.0 else ""
        print(f"    state {state}: part {part}, {upper:.4g} {mesh.units}, {ratio:.3f}{flag}")
    state, part, ratio = bounds.worst()
    print(f"  worst: state {state}, part {part}, {ratio:.3f} x its tolerance"
          + (" (the decimation holds at every state measured)" if ratio <= 1.0 else ""))
