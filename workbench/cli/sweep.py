"""``workbench sweep CONFIG.toml``: run a sweep config (:mod:`workbench.sweep`) and print its
summary; exit status 1 when a point failed, 2 for bad input, 130 when interrupted.

``python -m workbench.cli.sweep CONFIG.toml …`` runs the same command on its own.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from .arguments import add_cluster_output_arguments, refused, say_worker_devices
from .results import add_results_option, store_of


def cmd_sweep(args) -> int:
    """``workbench sweep``: run the config, print the summary; 1 when a point failed."""
    from ..results.recording import start_run
    from ..sweep import load_config, run_sweep

    config = load_config(args.config)
    out = Path(args.out) if args.out else Path("figures") / "sweeps" / config.name
    recorder = start_run(store_of(args).root, f"sweep {args.config}" + " --quick" * args.quick,
                         size="quick" if args.quick else "full")
    try:
        result = run_sweep(config, out, workers=args.workers, scheduler=args.scheduler,
                           quick=args.quick, timed=False if args.untimed else None,
                           recorder=recorder, devices=args.worker_devices,
                           verbose=args.verbose)
    except KeyboardInterrupt:
        print(f"sweep {config.name}: interrupted; finished points are kept in {out / 'points'}",
              file=sys.stderr)
        return 130
    say_worker_devices(result.devices)
    print(f"{out / 'table.md'}, {out / 'pareto.png'}")
    print(result.summary)
    print(f"results: run {recorder.run_id}, {recorder.appended} rows -> "
          f"{recorder.store.root}", file=sys.stderr)
    return 1 if result.failed else 0


def add_parser(subparsers):
    """Add the ``sweep`` subcommand to an argparse ``subparsers``; returns its parser."""
    p = subparsers.add_parser(
        "sweep", help="run a TOML grid of scenes x paths x options on Dask, cached per point",
        description="Run the Cartesian product of a sweep config's [grid] on a Dask cluster "
                    "(a local one by default), caching each point under DIR/points; write "
                    "DIR/table.csv, DIR/table.md and DIR/pareto.png. Exit status 1 when a "
                    "point failed, 2 for bad input.")
    p.add_argument("config", help="sweep config (TOML)")
    p.add_argument("--out", metavar="DIR", help="output folder (default figures/sweeps/<name>)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the local cluster (default: one per CPU)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the existing Dask cluster at ADDRESS (tcp://host:port)")
    p.add_argument("--quick", action="store_true",
                   help="smaller built-in scenes and at most 5 timed repeats")
    p.add_argument("--untimed", action="store_true",
                   help="draw every point once without timing (error-only, fully parallel)")
    add_cluster_output_arguments(p)
    add_results_option(p)
    p.set_defaults(func=cmd_sweep)
    return p


def main(argv: list[str] | None = None) -> int:
    """``python -m workbench.cli.sweep CONFIG …``: the sweep subcommand on its own."""
    import argparse

    parser = argparse.ArgumentParser(prog="workbench")
    add_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["sweep", *(sys.argv[1:] if argv is None else argv)])
    from ..gl import GLUnavailable

    try:
        return args.func(args)
    except (OSError, ValueError, KeyError, GLUnavailable) as exc:
        if os.environ.get("WORKBENCH_DEBUG"):
            raise
        return refused(exc)


if __name__ == "__main__":
    sys.exit(main())
