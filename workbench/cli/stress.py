"""``workbench stress readers|render|numerics|all``: the reliability suites
(:mod:`workbench.reliability`): mutated keyword decks and damaged d3plots for the readers; far
offsets, the soak and determinism for the render paths; the geometric kernels and colour paths
against exact arithmetic on adversarial inputs (:mod:`workbench.reliability.numerics`). Each
suite's table and failures are printed, then OK or FAILED; exit status 1 on any failure."""

from __future__ import annotations

import sys

from .arguments import add_device_argument, apply_process_options, at_least


def _print_report(title: str, report, unit: str) -> bool:
    """Print a suite's title line, table and failures, then OK or FAILED; returns ``ok``."""
    print(title)
    print(report.table())
    for failure in report.failures:
        print(failure)
    print("OK" if report.ok else f"FAILED: {len(report.failures)} failing {unit}")
    return report.ok


def cmd_stress(args) -> int:
    """``workbench stress readers|render|numerics|all``: print each suite's table and failures;
    1 when any check failed."""
    from ..reliability import (
        DEFAULT_N,
        run_d3plot_stress,
        run_numerics_stress,
        run_reader_stress,
        run_render_stress,
    )

    apply_process_options(args)  # the render suite's processes draw on it too
    ok = True
    if args.suite in ("readers", "all"):
        n = args.n or READER_MUTATIONS
        report = run_reader_stress(n, args.seed)
        ok &= _print_report(f"reader stress: {report.n} mutations, seed {report.seed}, "
                            f"{report.seconds:.1f} s", report, "read(s)")
        damaged = run_d3plot_stress(n, args.seed)
        if damaged is None:
            print("d3plot stress: skipped (the shared d3plot is absent: set WORKBENCH_DATA)")
        else:
            ok &= _print_report(f"d3plot stress: {damaged.n} damaged copies, seed "
                                f"{damaged.seed}, {damaged.seconds:.1f} s", damaged, "read(s)")
    if args.suite in ("render", "all"):
        render = run_render_stress(args.cycles)
        ok &= _print_report(f"render stress: far offset, {args.cycles} soak cycles, "
                            f"determinism, {render.seconds:.1f} s", render, "check(s)")
    if args.suite in ("numerics", "all"):
        numerics = run_numerics_stress(args.n or DEFAULT_N, args.seed, gl=not args.no_gl)
        ok &= _print_report(f"numerics stress: {numerics.n} cases per distance generator, seed "
                            f"{numerics.seed}, {numerics.seconds:.1f} s", numerics, "row(s)")
    sys.stdout.flush()
    return 0 if ok else 1


READER_MUTATIONS = 200  # the readers' default --n


def add_parser(subparsers) -> None:
    """Add the ``stress`` command to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "stress", help="reliability suites: mutated decks for the readers, far-offset, soak and "
                       "determinism checks for the render paths, numerics against exact "
                       "arithmetic",
        description="readers: mutate keyword decks at random and check every read against an "
                    "independent strict decoding of the deck (node ids, coordinates, "
                    "connectivity, part ids, thickness: identical for benign changes, else "
                    "ParseError or the mesh the strict decoding gives); damaged d3plots against "
                    "the undamaged read. "
                    "render: images 10^3 and 10^7 units from the origin equal to those at it, "
                    "prepare/draw/release cycles that keep no GL object and no memory, the same "
                    "image in other processes. numerics: point-triangle distances, part "
                    "distances, Hausdorff brackets, the simplifier's bounds, rasterizer "
                    "coverage, GL against software images, spacetime slice areas and field "
                    "colours on adversarial inputs (slivers, needles, fans, far offsets, NaN "
                    "and extreme fields), each against an exact rational reference. all: every "
                    "suite. Exit status 1 on any failure.")
    p.add_argument("suite", choices=["readers", "render", "numerics", "all"],
                   help="which suite to run")
    p.add_argument("--n", type=at_least(1), default=None,
                   help=f"reader mutations (default {READER_MUTATIONS}); numerics: cases per "
                        f"distance generator, the other checks scaled from it (default 400, "
                        f"about a minute or two)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--no-gl", action="store_true",
                   help="numerics: skip the checks that draw on GL (their rows say so)")
    p.add_argument("--cycles", type=at_least(1), default=300,
                   help="prepare/draw/release cycles of the render soak (default 300)")
    add_device_argument(p)
    p.set_defaults(func=cmd_stress)
