"""``workbench list``, ``run`` and ``reproduce``: the registered experiments, one of them, or
all of them with a progress bar, each writing ``figures/<experiment>/`` and appending its rows
to the results store (one run record for the command)."""

from __future__ import annotations

import sys
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
        rows, out_dir = run_experiment(name, figures_root=Path(args.figures), quick=args.quick,
                                       progress=lambda msg: bar.write(f"  {name}: {msg}"),  # noqa: B023
                                       recorder=recorder)
        bar.write(f"{name}: {len(rows)} rows -> {out_dir}")
    print(f"results: run {recorder.run_id}, {recorder.appended} rows -> "
          f"{recorder.store.root}", file=sys.stderr)
    return 0
