"""``workbench results``: the results store of every run — query it with SQL, compare two runs
(or commits, or machines), follow a quantity over the runs with its change points, draw a
Pareto figure of any query, and regenerate the measured claims of the README and
docs/results.md (or a static site) from it.

The store is ``--results DIR``, else ``$WORKBENCH_RESULTS``, else ``figures/results``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .arguments import refused

RESULTS_HELP = ("results store folder (default: $WORKBENCH_RESULTS, else <figures>/results)")


def add_results_option(parser) -> None:
    """Add ``--results DIR`` (the results store) to a command's parser."""
    parser.add_argument("--results", metavar="DIR", help=RESULTS_HELP)


def store_of(args, figures: str | Path = "figures"):
    """The :class:`~workbench.results.store.ResultsStore` that ``args.results`` (or the
    environment, or ``figures``) names."""
    from ..results.store import ResultsStore, results_root

    return ResultsStore(results_root(getattr(args, "results", None), figures=figures))


def add_parser(subparsers) -> None:
    """Add ``results`` and its subcommands to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "results", help="query, compare and report the stored results of every run",
        description="Every run of `workbench run`, `reproduce` and `sweep` appends its "
                    "rows to one results store (Parquet). Query it with DuckDB SQL over the "
                    "views rows, runs and machines (joined by run_id and machine_id), compare "
                    "two runs, plot time against error, or regenerate the measured claims.")
    sub = p.add_subparsers(dest="results_command", required=True)

    q = sub.add_parser("query", help="run SQL over the views rows, runs, machines",
                       description="Run one DuckDB SQL statement over the views `rows` (every "
                                   "stored row, with run_id, experiment, table), `runs` (one "
                                   "per run: commit, dirty, started, load, libraries, with the "
                                   "machine's cpu and renderer) and `machines` (fingerprints).")
    q.add_argument("sql", help='e.g. "SELECT path, median(wall_ms) FROM rows GROUP BY path"')
    q.add_argument("--csv", metavar="FILE", help="write the result as CSV instead of printing")
    q.add_argument("--limit", type=int, default=200, metavar="N",
                   help="print at most N rows (default 200; --csv writes all)")
    add_results_option(q)
    q.set_defaults(func=cmd_query)

    c = sub.add_parser("compare", help="pair equal measurements of two runs and flag changes",
                       description="Pair the equal measurements (experiment, table, parameters) "
                                   "of A and B — each a run id, a commit or a machine id, or a "
                                   "unique prefix — and report per pair the time ratio B/A with "
                                   "its 95 %% interval, relative to the drift of its group "
                                   "(the median ratio of the times of one experiment, table "
                                   "and scene), and the error columns. A change is flagged "
                                   "when its whole interval lies beyond the threshold (slower "
                                   "than 1+T or faster than 1/(1+T)). Exit status 1 when any "
                                   "is.")
    c.add_argument("a", help="run id, commit or machine id (or a unique prefix)")
    c.add_argument("b", help="run id, commit or machine id (or a unique prefix)")
    c.add_argument("--threshold", type=float, default=None, metavar="T",
                   help="a change is flagged when its 95 %% interval lies beyond 1+T (or below "
                        "1/(1+T)); default 0.10")
    c.add_argument("--all", action="store_true", help="list every pair, not only flagged ones")
    c.add_argument("--no-drift", action="store_true",
                   help="compare times as they are, not relative to their group's drift")
    c.add_argument("--csv", metavar="FILE", help="write every pair as CSV")
    add_results_option(c)
    c.set_defaults(func=cmd_compare)

    h = sub.add_parser("history", help="a quantity over the stored runs, with its change points",
                       description="List every measurement of QUANTITY (a stored column: "
                                   "COLUMN, EXPERIMENT/COLUMN or EXPERIMENT/TABLE/COLUMN) over "
                                   "the stored runs of each machine, oldest first, and the "
                                   "change points E-divisive means finds in it (each split "
                                   "kept where a permutation test finds it significant at "
                                   "--alpha). Measurements are paired as `results compare` "
                                   "pairs them; quick and full runs, and machines, are never "
                                   "mixed; tiny runs are left out. Exit status 0.")
    h.add_argument("quantity", help="e.g. wall_ms, render_paths/wall_ms or "
                                    "simplify_tradeoff/states/ratio")
    h.add_argument("--machine", metavar="ID", help="only machines whose id starts with ID")
    h.add_argument("--size", choices=("full", "quick", "tiny"),
                   help="only runs of this experiment size (default full and quick, apart)")
    h.add_argument("--where", action="append", default=[], metavar="COLUMN=VALUE",
                   help="only rows whose COLUMN is VALUE (text); may be repeated")
    h.add_argument("--alpha", type=float, default=None, metavar="P",
                   help="significance of a change point (default 0.02)")
    h.add_argument("--all", action="store_true",
                   help="list every measurement, not only those with a change point")
    h.add_argument("--runs", action="store_true", help="print each run's value and interval")
    h.add_argument("--csv", metavar="FILE", help="write every run of every measurement as CSV")
    add_results_option(h)
    h.set_defaults(func=cmd_history)

    f = sub.add_parser("pareto", help="figure of time against error from a query",
                       description="Plot the rows of a query as time against error, with the "
                                   "front of the rows no other is both faster and more exact "
                                   "than.")
    f.add_argument("sql", help="a query returning the time and error columns")
    f.add_argument("-o", "--out", required=True, metavar="PNG", help="figure file")
    f.add_argument("--time", default="wall_ms", help="time column (default wall_ms)")
    f.add_argument("--error", default="max_diff_255", help="error column (default max_diff_255)")
    f.add_argument("--label", default="path", help="column naming each point (default path)")
    add_results_option(f)
    f.set_defaults(func=cmd_pareto)

    r = sub.add_parser("report", help="regenerate the README's claims, docs/results.md and "
                                      "the benchmarks of docs/history.md",
                       description="Write the measured claims of the README (between its "
                                   "results markers: one headline per experiment), "
                                   "docs/results.md (every claim and stored table) and the "
                                   "benchmarks section of docs/history.md from the latest "
                                   "stored run of each experiment and benchmark, each ratio "
                                   "with its interval and the machine it ran on.")
    r.add_argument("--readme", default="README.md", metavar="FILE")
    r.add_argument("--doc", default="docs/results.md", metavar="FILE")
    r.add_argument("--history", metavar="FILE",
                   help="the page whose benchmarks section is rewritten (default "
                        "docs/history.md where it exists; 'none' to leave it)")
    r.add_argument("--html", metavar="DIR",
                   help="write only a static site of the store into DIR (replaced whole; "
                        "opens from disk): experiments with their claims, tables, Pareto plots "
                        "and figures, runs, machines and each claim's history")
    r.add_argument("--figures", metavar="DIR",
                   help="where the experiments' figure folders are, for --html (default: the "
                        "store's parent folder where the store folder is named 'results', "
                        "else figures)")
    add_results_option(r)
    r.set_defaults(func=cmd_report)


def _print_table(table, limit: int | None = None) -> None:
    from ..output.tables import markdown_table

    rows = table.to_pylist()
    shown = rows if limit is None else rows[:limit]
    print(markdown_table(shown, columns=table.column_names), end="")
    if limit is not None and len(rows) > limit:
        print(f"({len(rows) - limit} more rows; --limit N or --csv FILE for all)")


def cmd_query(args) -> int:
    """``workbench results query``: print the result (or write it as CSV); 0."""
    import duckdb

    from ..output.tables import write_table

    store = store_of(args)
    try:
        table = store.query(args.sql)
    except duckdb.Error as exc:
        return refused(ValueError(f"query refused by DuckDB: {str(exc).splitlines()[0]}"))
    if args.csv:
        out = Path(args.csv)
        write_table(table.to_pylist(), out.parent if str(out.parent) else Path("."),
                    out.stem, columns=table.column_names)
        print(f"{len(table)} rows -> {out.with_suffix('.csv')}")
    else:
        _print_table(table, args.limit)
    return 0


def cmd_compare(args) -> int:
    """``workbench results compare A B``: the flagged pairs (or all), a summary line; 1 when a
    change is flagged, 0 otherwise."""
    from ..output.tables import markdown_table, write_table
    from ..results.compare import THRESHOLD, compare_runs, summary

    threshold = THRESHOLD if args.threshold is None else args.threshold
    lines = compare_runs(store_of(args), args.a, args.b, threshold=threshold,
                         drift=not args.no_drift)
    if args.csv:
        out = Path(args.csv)
        write_table(lines, out.parent if str(out.parent) else Path("."), out.stem)
    shown = lines if args.all else [line for line in lines if line["flagged"]]
    columns = ["experiment", "table", "measurement", "quantity", "a", "b", "ratio", "drift",
               "relative", "relative_lo", "relative_hi", "flagged", "errors_changed"]
    if shown:
        print(markdown_table(shown, columns=columns), end="")
    print(f"compare {args.a} -> {args.b}: {summary(lines)} (threshold {threshold:.0%})")
    return 1 if any(line["flagged"] for line in lines) else 0


def cmd_history(args) -> int:
    """``workbench results history QUANTITY``: per measurement its runs and change points; 0
    (2 with one line for an unknown column or a bad option)."""
    from ..output.tables import format_number, markdown_table, write_table
    from ..results.changepoints import ALPHA
    from ..results.history import histories

    where = {}
    for item in args.where:
        column, sep, value = item.partition("=")
        if not sep or not column:
            return refused(ValueError(f"--where takes COLUMN=VALUE, got {item!r}"))
        where[column] = value
    alpha = ALPHA if args.alpha is None else args.alpha
    if not 0 < alpha < 1:
        return refused(ValueError(f"--alpha must lie in (0, 1), got {alpha}"))
    try:
        found = histories(store_of(args), args.quantity, machine=args.machine, size=args.size,
                          where=where, alpha=alpha)
    except ValueError as exc:
        return refused(exc)
    if args.csv:
        out = Path(args.csv)
        rows = [{"experiment": h.experiment, "table": h.table, "measurement": h.measurement,
                 "quantity": h.quantity, "machine_id": h.machine_id, "size": h.size,
                 "run_id": p.run_id, "started": p.started, "commit": p.commit,
                 "value": p.value, "lo": p.lo, "hi": p.hi, "change_point": i in h.changes}
                for h in found for i, p in enumerate(h.points)]
        write_table(rows, out.parent if str(out.parent) else Path("."), out.stem)
    changed = [h for h in found if h.changes]
    for h in (found if args.all else changed):
        print(f"{h.name}: {len(h.points)} {h.size or ''} runs on machine {h.machine_id}"
              + (f", {h.missing} without a value" if h.missing else ""))
        for index, step in zip(h.changes, h.steps()):
            p = h.points[index]
            print(f"  change at run {p.run_id} (commit {(p.commit or '?')[:10]}, "
                  f"{p.started[:19]}): × {format_number(step, 3)}")
        if args.runs:
            print(markdown_table([{"run": p.run_id, "commit": (p.commit or "")[:10],
                                   "started": p.started[:19], "value": p.value, "lo": p.lo,
                                   "hi": p.hi, "change": "◆" if i in h.changes else ""}
                                  for i, p in enumerate(h.points)]), end="")
    print(f"history of {args.quantity}: {len(found)} measurements, {len(changed)} with a "
          f"change point (alpha {alpha:g})")
    return 0


def cmd_pareto(args) -> int:
    """``workbench results pareto``: the figure of the query's rows; 0."""
    import duckdb

    from ..sweep.pareto import save_pareto

    try:
        rows = store_of(args).query(args.sql).to_pylist()
    except duckdb.Error as exc:
        return refused(ValueError(f"query refused by DuckDB: {str(exc).splitlines()[0]}"))
    for column in (args.time, args.error):
        if rows and column not in rows[0]:
            return refused(ValueError(f"the query returns no column {column!r} (it returns "
                                      f"{', '.join(rows[0])})"))
    if not rows:
        return refused(ValueError("the query returns no rows"))
    for row in rows:
        row["path"] = str(row.get(args.label))  # the figure colours points by "path"
    save_pareto(Path(args.out), rows, time_column=args.time, metric=args.error,
                title=f"{args.error} against {args.time}", reference=None)
    print(f"{len(rows)} points -> {args.out}")
    return 0


def cmd_report(args) -> int:
    """``workbench results report``: rewrite the README's claims, docs/results.md and the
    benchmarks section of docs/history.md (with ``--html DIR``: write only the site, printing
    the path of its index); 0, or 2 for a refused folder or an empty store."""
    from ..experiment.report import write_report
    from ..output.targets import output_target

    if args.html is not None:
        return _report_html(args)

    # refused before the README is read: reading a FIFO would block
    readme, doc = map(output_target, (args.readme, args.doc))
    history = args.history or ("docs/history.md" if Path("docs/history.md").is_file()
                               else "none")
    written = write_report(store_of(args), readme, doc,
                           history=None if history == "none" else output_target(history))
    for path in written:
        print(f"wrote {path}", file=sys.stderr)
    return 0


def _report_html(args) -> int:
    """``workbench results report --html DIR``: the static site of the store; prints the path
    of its index; 0, or 2 (one error line) for a refused DIR or a store without runs."""
    import time

    from ..site import write_site

    store = store_of(args)
    figures = args.figures or (store.root.parent if store.root.name == "results"
                               else Path("figures"))
    start = time.perf_counter()
    try:
        index = write_site(store, args.html, figures)
    except ValueError as exc:
        return refused(exc)
    print(f"site written in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    print(index)
    return 0
