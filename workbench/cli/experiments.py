"""``workbench list``, ``run``, ``reproduce`` and ``warm``: the registered experiments, one of
them, or all of them with a progress bar, each writing ``figures/<experiment>/`` and appending
its rows to the results store (one run record for the command); ``warm`` compiles every kernel
the experiments use (their tiny runs, thrown away), as ``install.sh`` does once."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from .arguments import add_device_argument, apply_process_options
from .results import add_results_option, store_of


def add_parser(subparsers) -> None:
    """Add ``list``, ``run`` and ``reproduce`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser("list", help="list the registered experiments")
    p.set_defaults(func=cmd_list)

    p = subparsers.add_parser("run", help="run one experiment, writing figures/<experiment>/")
    p.add_argument("experiment")
    p.add_argument("--quick", action="store_true", help="small sizes and few repetitions")
    p.add_argument("--figures", default="figures", help="output folder (default figures/)")
    _add_drawing_arguments(p)
    add_results_option(p)
    p.set_defaults(func=cmd_run)

    p = subparsers.add_parser("reproduce",
                              help="run every registered experiment, with a progress bar")
    p.add_argument("--quick", action="store_true", help="small sizes and few repetitions")
    p.add_argument("--figures", default="figures", help="output folder (default figures/)")
    _add_drawing_arguments(p)
    add_results_option(p)
    p.set_defaults(func=cmd_reproduce)

    p = subparsers.add_parser(
        "warm", help="compile every kernel the experiments use (their tiny runs, thrown away)",
        description="Run every experiment (or the NAMEs) at its tiny size into a temporary "
                    "folder, untimed and unrecorded, so that the compiled kernels are in the "
                    "disk cache before anything is timed. install.sh runs it once.")
    p.add_argument("names", nargs="*", metavar="NAME", help="experiments (default: all)")
    p.add_argument("--jobs", type=int, default=2,
                   help="processes at once (default 2; each compiles its own kernels)")
    p.set_defaults(func=cmd_warm)


def _add_drawing_arguments(p) -> None:
    """``--device`` and ``--verbose`` of ``run`` and ``reproduce``."""
    add_device_argument(p)
    p.add_argument("--verbose", action="store_true",
                   help="show Dask's INFO log lines of the experiments' clusters (default: "
                        "warnings and errors only)")


def cmd_list(args) -> int:
    from ..experiment.registry import discover

    for name, exp in sorted(discover().items()):
        print(f"{name:<28} {exp.description}")
    return 0


def start_recording(args, command: str):
    """The :class:`~workbench.results.recording.Recorder` of this command's run in the
    store ``--results`` (or the environment, or ``<figures>/results``) names."""
    from ..results.recording import start_run

    size = "quick" if getattr(args, "quick", False) else "full"
    return start_run(store_of(args, args.figures).root, command, size=size)


def cmd_run(args) -> int:
    from ..experiment.registry import discover, get_experiment, run_experiment

    discover()
    get_experiment(args.experiment)  # an unknown name is refused before anything is recorded
    apply_process_options(args)
    recorder = start_recording(args, f"run {args.experiment}" + " --quick" * args.quick)
    rows, out_dir = run_experiment(args.experiment, figures_root=Path(args.figures),
                                   quick=args.quick,
                                   progress=lambda msg: print(f"  {msg}", flush=True),
                                   recorder=recorder)
    print(f"{args.experiment}: {len(rows)} rows -> {out_dir}")
    print(f"results: run {recorder.run_id}, {recorder.appended} rows -> "
          f"{recorder.store.root}", file=sys.stderr)
    return 0


def cmd_reproduce(args) -> int:
    from tqdm import tqdm

    from ..experiment.registry import discover, run_experiment

    names = sorted(discover())
    apply_process_options(args)
    recorder = start_recording(args, "reproduce" + " --quick" * args.quick)
    bar = tqdm(names, desc="reproduce", unit="experiment")
    for name in bar:
        bar.set_postfix_str(name)
        start = time.perf_counter()
        rows, out_dir = run_experiment(name, figures_root=Path(args.figures), quick=args.quick,
                                       progress=lambda msg: bar.write(f"  {name}: {msg}"),  # noqa: B023
                                       recorder=recorder)
        bar.write(f"{name}: {len(rows)} rows -> {out_dir} "
                  f"({time.perf_counter() - start:.0f} s)")
    print(f"results: run {recorder.run_id}, {recorder.appended} rows -> "
          f"{recorder.store.root}", file=sys.stderr)
    return 0


def cmd_warm(args) -> int:
    """Warm the named experiments (all by default) in ``--jobs`` processes; 0, or 2 with one
    line for an unknown name or a bad ``--jobs``."""
    from ..experiment.registry import discover, warm_all

    found = discover()
    names = args.names or sorted(found)
    unknown = [n for n in names if n not in found]
    if unknown:
        print(f"workbench warm: error: unknown experiment {unknown[0]!r}; known: "
              f"{', '.join(sorted(found))}", file=sys.stderr)
        return 2
    if args.jobs < 1:
        print(f"workbench warm: error: --jobs must be >= 1, got {args.jobs}", file=sys.stderr)
        return 2
    start = time.perf_counter()
    warm_all(names, jobs=args.jobs, progress=lambda msg: print(f"  warmed {msg}", flush=True))
    print(f"warm: {len(names)} experiments in {time.perf_counter() - start:.0f} s")
    return 0
