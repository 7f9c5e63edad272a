"""``workbench stress readers|render|all``: the reliability suites (:mod:`workbench.reliability`):
mutated keyword decks and damaged d3plots for the readers; far offsets, the soak and
determinism for the render paths. Each suite's table and failures are printed, then OK or
FAILED; exit status 1 on any failure."""

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
    """``workbench stress readers|render|all``: print each suite's table and failures; 1 when
    any check failed."""
    from ..reliability import run_d3plot_stress, run_reader_stress, run_render_stress

    apply_process_options(args)  # the render suite's processes draw on it too
    ok = True
    if args.suite in ("readers", "all"):
        report = run_reader_stress(args.n, args.seed)
        ok &= _print_report(f"reader stress: {report.n} mutations, seed {report.seed}, "
                            f"{report.seconds:.1f} s", report, "read(s)")
        damaged = run_d3plot_stress(args.n, args.seed)
        if damaged is None:
            print("d3plot stress: skipped (the shared d3plot is absent: set WORKBENCH_DATA)")
        else:
            ok &= _print_report(f"d3plot stress: {damaged.n} damaged copies, seed "
                                f"{damaged.seed}, {damaged.seconds:.1f} s", damaged, "read(s)")
    if args.suite in ("render", "all"):
        render = run_render_stress(args.cycles)
        ok &= _print_report(f"render stress: far offset, {args.cycles} soak cycles, "
                            f"determinism, {render.seconds:.1f} s", render, "check(s)")
    sys.stdout.flush()
    return 0 if ok else 1


def add_parser(subparsers) -> None:
    """Add the ``stress`` command to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "stress", help="reliability suites: mutated decks for the readers, far-offset, soak and "
                       "determinism checks for the render paths",
        description="readers: mutate keyword decks at random and check every read against an "
                    "independent strict decoding of the deck (node ids, coordinates, "
                    "connectivity, part ids, thickness: identical for benign changes, else "
                    "ParseError or the mesh the strict decoding gives); damaged d3plots against "
                    "the undamaged read. "
                    "render: images 10^3 and 10^7 units from the origin equal to those at it, "
                    "prepare/draw/release cycles that keep no GL object and no memory, the same "
                    "image in other processes. all: both. Exit status 1 on any failure.")
    p.add_argument("suite", choices=["readers", "render", "all"], help="which suite to run")
    p.add_argument("--n", type=at_least(1), default=200, help="reader mutations (default 200)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the mutations (default 0)")
    p.add_argument("--cycles", type=at_least(1), default=300,
                   help="prepare/draw/release cycles of the render soak (default 300)")
    add_device_argument(p)
    p.set_defaults(func=cmd_stress)
