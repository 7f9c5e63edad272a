"""``workbench list``, ``run`` and ``reproduce``: the registered experiments, one of them, or
all of them with a progress bar, each writing ``figures/<experiment>/``."""

from __future__ import annotations

from pathlib import Path


def add_parser(subparsers) -> None:
    """Add ``list``, ``run`` and ``reproduce`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser("list", help="list the registered experiments")
    p.set_defaults(func=cmd_list)

    p = subparsers.add_parser("run", help="run one experiment, writing figures/<experiment>/")
    p.add_argument("experiment")
    p.add_argument("--quick", action="store_true", help="small sizes and few repetitions")
    p.add_argument("--figures", default="figures", help="output folder (default figures/)")
    p.set_defaults(func=cmd_run)

    p = subparsers.add_parser("reproduce",
                              help="run every registered experiment, with a progress bar")
    p.add_argument("--quick", action="store_true", help="small sizes and few repetitions")
    p.add_argument("--figures", default="figures", help="output folder (default figures/)")
    p.set_defaults(func=cmd_reproduce)


def cmd_list(args) -> int:
    from ..experiment.registry import discover

    for name, exp in sorted(discover().items()):
        print(f"{name:<28} {exp.description}")
    return 0


def cmd_run(args) -> int:
    from ..experiment.registry import discover, run_experiment

    discover()
    rows, out_dir = run_experiment(args.experiment, figures_root=Path(args.figures),
                                   quick=args.quick,
                                   progress=lambda msg: print(f"  {msg}", flush=True))
    print(f"{args.experiment}: {len(rows)} rows -> {out_dir}")
    return 0


def cmd_reproduce(args) -> int:
    from tqdm import tqdm

    from ..experiment.registry import discover, run_experiment

    names = sorted(discover())
    bar = tqdm(names, desc="reproduce", unit="experiment")
    for name in bar:
        bar.set_postfix_str(name)
        rows, out_dir = run_experiment(name, figures_root=Path(args.figures), quick=args.quick,
                                       progress=lambda msg: bar.write(f"  {name}: {msg}"))  # noqa: B023
        bar.write(f"{name}: {len(rows)} rows -> {out_dir}")
    return 0
