"""``workbench bench``: run the benchmark modules of ``benchmarks/`` on the measurement harness
(:mod:`workbench.measurement.bench`) and record their rows in the results store.

Each benchmark's rows are appended under one run of the store (command ``bench …``, with the
machine, commit and libraries) with ``experiment = "bench:<name>"``, ``table = <case>`` and
``experiment_size`` the size, so that ``workbench results compare A B`` pairs two bench runs
(or commits) and flags a slower one as it does for experiments. The rows are also written as
``bench.csv``/``bench.md`` into ``--out`` (replaced atomically).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from .arguments import at_least, refused

PREFIX = "bench:"


def add_parser(subparsers) -> None:
    """Add ``bench`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "bench", help="run benchmarks and store their rows in the results store",
        description="Run the benchmark modules (all, or those named): each case timed with the "
                    "project's timing (warm-up untimed, repetitions, median with its 95 % "
                    "interval; comparisons interleaved), its rows appended to the results "
                    "store with the run's provenance. Compare two runs with `workbench "
                    "results compare`.")
    p.add_argument("names", nargs="*", metavar="NAME", help="benchmarks to run (default: all)")
    p.add_argument("--quick", action="store_true", help="the quick sizes (seconds each)")
    p.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    p.add_argument("--repeat", type=at_least(5), metavar="N",
                   help="timed repetitions per function (default 7; 5 with --quick)")
    p.add_argument("--store", "--results", dest="results", metavar="DIR",
                   help="results store folder (default: $WORKBENCH_RESULTS, else "
                        "figures/results)")
    p.add_argument("--out", default="figures/bench", metavar="DIR",
                   help="folder of the bench.csv/bench.md table (default figures/bench)")
    p.add_argument("--set", action="append", default=[], dest="overrides",
                   type=parameter_setting, metavar="KEY=VALUE",
                   help="set a parameter of every case of the benchmarks named (repeatable; "
                        "VALUE read as an integer, a number, true/false, else text), e.g. "
                        "`distance_fcpw_bench --set hierarchy=true`; the rows carry it")
    p.add_argument("--dir", metavar="DIR",
                   help="benchmark modules folder (default: $WORKBENCH_BENCHMARKS, else the "
                        "checkout's benchmarks/)")
    p.set_defaults(func=cmd_bench)


def cmd_bench(args) -> int:
    """``workbench bench``: list, or run and record; 0, or 2 for an unknown name."""
    from ..measurement.bench import check_overrides, discover, get_benchmark, run_benchmark
    from ..output.tables import table_columns, write_table
    from ..output.targets import output_folder
    from .results import store_of

    registry = discover(args.dir)
    if args.list:
        for name in sorted(registry):
            b = registry[name]
            cases = ", ".join(c.name for c in b.cases)
            print(f"{name}: {b.description} (cases: {cases})")
        return 0
    names = list(dict.fromkeys(args.names)) or sorted(registry)
    overrides = dict(args.overrides)
    if overrides and not args.names:
        return refused(ValueError("--set needs the benchmarks it applies to named"))
    try:
        for name in names:
            get_benchmark(name)
            check_overrides(name, overrides)
    except (KeyError, ValueError) as exc:
        return refused(exc)
    out = output_folder(Path(args.out), create=True)
    size = "quick" if args.quick else "full"
    from ..results.recording import start_run

    settings = "".join(f" --set {key}={value}" for key, value in overrides.items())
    recorder = start_run(store_of(args).root, "bench " + " ".join(names) + settings
                         + " --quick" * args.quick, size=size)
    table = []
    for name in names:
        result = run_benchmark(name, size, args.repeat, progress=_say, overrides=overrides)
        by_case: dict[str, list[dict]] = {}
        for row in result.rows:
            by_case.setdefault(row["case"], []).append(row)
        for case, rows in by_case.items():
            recorder.append(rows, experiment=PREFIX + name, table=case, experiment_size=size)
        table += [{"benchmark": name, **row} for row in result.rows]
        table += [{"benchmark": name, "case": case, "skipped": reason}
                  for case, reason in result.skipped.items()]
    if table:
        columns = [c for c in table_columns(table) if any(r.get(c) is not None for r in table)]
        write_table(table, out, "bench", columns=columns, title=f"workbench bench ({size}), run "
                    f"{recorder.run_id}")
    print(f"stored {recorder.appended} rows of {len(names)} benchmarks under run "
          f"{recorder.run_id} in {recorder.store.root}; table {out / 'bench.md'}")
    return 0


def parameter_setting(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` → ``(KEY, value)``, the value an int, a float, a bool (``true``/``false``)
    or else the text; an argparse type (refused in one line without ``=`` or a key)."""
    key, equals, value = text.partition("=")
    if not equals or not key.isidentifier():
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE with KEY a parameter name, "
                                         f"got {text!r}")
    if value.lower() in ("true", "false"):
        return key, value.lower() == "true"
    for kind in (int, float):
        try:
            return key, kind(value)
        except ValueError:
            pass
    return key, value


parameter_setting.__name__ = "KEY=VALUE"


def _say(line: str) -> None:
    print(line, file=sys.stderr, flush=True)
