"""Two sets of stored results compared measurement by measurement: "did this commit make path
P slower?", "how does this machine compare with that one?".

A side is chosen by a selector: a run id, a commit or a machine id (or a unique prefix of one);
a commit or a machine selects every run recorded for it. Rows are paired when they are the same
measurement: the same experiment, table and experiment size, the same text-valued parameters
(scene, path, style, case …; the renderer, the EGL device and the run's own columns are left out
so that two machines can be compared), and the same position among the rows equal in all of those.

Each measured quantity of a pair gives one line of the comparison:

* a time with raw samples (``wall_ms`` with ``wall_samples_ms``): ratio B / A of the medians
  with a 95 % bootstrap interval (:func:`~workbench.measurement.stats.ratio_of_medians_interval`);
* a value with its own interval (``X`` with ``X_lo``/``X_hi``, such as an interleaved ratio):
  ratio B / A with the interval ``[B_lo / A_hi, B_hi / A_lo]``.

**Drift.** A shared machine runs faster or slower from one minute to the next, and every time
measured in that stretch moves with it (measured on a 2-core llvmpipe machine: whole runs
25 % apart, while the paths of one scene measured together stay within a few per cent of each
other). Times are therefore compared relative to their group's drift: the median B / A ratio
of the times of one experiment, table and scene. A line's ``drift`` is that median and
``relative`` its ratio divided by it (its interval too). The drift is reported, not flagged: it
is the machine's speed as much as the code's. A group of fewer than three times (a benchmark
case timing one function) has no drift: its times are compared as they are. Ratios that carry
their own interval (measured interleaved in one run) are already free of drift and are
compared as they are.

A line is *flagged* as changed only when its whole (relative) interval lies beyond the
threshold band ``[1 / (1 + threshold), 1 + threshold]`` (default 10 %): the change is larger
than the threshold with 95 % confidence, not merely different from nothing. Error columns
(image differences) are compared exactly: their values in A and B and whether any changed.
"""

from __future__ import annotations

import re
import statistics
from collections import Counter, defaultdict
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ..measurement.stats import CONFIDENCE, ratio_of_medians_interval
from ..output.tables import finite_number

if TYPE_CHECKING:
    from .store import ResultsStore

THRESHOLD = 0.10
MIN_DRIFT_TIMES = 3  # times a group needs for its drift: with one, the drift is its own ratio
# columns that are not the measurement's parameters: who ran it, and where (the renderer and
# the EGL device the harness stamps on each row drawn on it)
RUN_COLUMNS = {"run_id", "row_index", "renderer", "egl_device", "experiment", "table",
               "experiment_size", "error"}
ERROR_COLUMNS = ("max_diff_255", "mean_diff_255", "share_differing", "psnr_db", "ssim")
_TIMED = re.compile(r"(_ms|_s)(_min|_max|_lo|_hi)?$|_samples_ms$|^repeats$|_pairs$")
_SELECTOR = re.compile(r"^[A-Za-z0-9_.-]+$")


def select_runs(store: ResultsStore, selector: str) -> list[str]:
    """The run ids ``selector`` names: a run id, a commit or a machine id, or a prefix of one
    that names exactly one of them. ValueError when it names nothing, or several runs,
    commits or machines at once."""
    if not isinstance(selector, str) or not _SELECTOR.match(selector):
        raise ValueError(f"a run selector is a run id, commit or machine id, got {selector!r}")
    runs = store.query("SELECT run_id, \"commit\", machine_id FROM runs").to_pylist()
    for column in ("run_id", "commit", "machine_id"):
        values = {r[column] for r in runs if r[column] and str(r[column]).startswith(selector)}
        if len(values) > 1:
            raise ValueError(f"{selector!r} is the start of {len(values)} {column}s: "
                             f"{', '.join(sorted(values)[:4])} …; give more of it")
        if values:
            value = values.pop()
            return sorted(r["run_id"] for r in runs if r[column] == value)
    raise ValueError(f"no run, commit or machine in the results store {store.root} starts "
                     f"with {selector!r}")


def _rows(store: ResultsStore, run_ids: Sequence[str]) -> list[dict[str, Any]]:
    quoted = ", ".join("'" + r.replace("'", "''") + "'" for r in run_ids)
    return store.query(f"SELECT * FROM rows WHERE run_id IN ({quoted}) "
                       f"ORDER BY run_id, experiment, \"table\", row_index").to_pylist()


def _is_parameter(column: str, value: Any) -> bool:
    return (isinstance(value, str) and column not in RUN_COLUMNS
            and not _TIMED.search(column))


def measurement_key(row: dict[str, Any]) -> tuple:
    """What makes ``row`` the same measurement in another run: experiment, table, experiment
    size and the text-valued parameters (not the renderer, not times)."""
    params = tuple(sorted((c, v) for c, v in row.items() if _is_parameter(c, v)))
    return (row.get("experiment"), row.get("table"), row.get("experiment_size"), params)


def _keyed(rows: list[dict[str, Any]]) -> dict[tuple, dict[str, Any]]:
    """Rows by (measurement key, occurrence); with several runs the last run's row wins."""
    seen: Counter = Counter()
    keyed: dict[tuple, dict[str, Any]] = {}
    last_run = None
    for row in rows:
        if row.get("run_id") != last_run:
            seen.clear()
            last_run = row.get("run_id")
        key = measurement_key(row)
        keyed[(key, seen[key])] = row
        seen[key] += 1
    return keyed


def _quantities(a: dict[str, Any], b: dict[str, Any], resamples: int,
                confidence: float) -> list[dict[str, Any]]:
    """(quantity, A, B, ratio, lo, hi) of every time with samples or value with an interval
    both rows have."""
    found = []
    for column in a:
        # wall_ms's samples are wall_samples_ms (gpu_ms: gpu_samples_ms)
        samples = f"{column[:-3]}_samples_ms" if column.endswith("_ms") else None
        a_value, b_value = finite_number(a.get(column)), finite_number(b.get(column))
        if a_value is None or b_value is None or a_value <= 0 or b_value <= 0:
            continue
        if samples and a.get(samples) and b.get(samples):
            i = ratio_of_medians_interval(a[samples], b[samples], confidence,
                                          resamples=resamples)
            found.append(dict(quantity=column, a=a_value, b=b_value, ratio=i.estimate,
                              ratio_lo=i.lo, ratio_hi=i.hi, timed=True))
            continue
        bounds = [finite_number(r.get(f"{column}_{end}")) for r in (a, b) for end in ("lo", "hi")]
        if all(v is not None and v > 0 for v in bounds):
            a_lo, a_hi, b_lo, b_hi = bounds
            found.append(dict(quantity=column, a=a_value, b=b_value, ratio=b_value / a_value,
                              ratio_lo=b_lo / a_hi, ratio_hi=b_hi / a_lo, timed=False))
    return found


def _describe(key: tuple) -> str:
    """``scene=…, path=…`` of a (measurement key, occurrence), ``#n`` after a repeated one."""
    (_, _, _, params), occurrence = key
    text = ", ".join(f"{c}={v}" for c, v in params if v)
    return text + (f" #{occurrence + 1}" if occurrence else "")


def compare_runs(store: ResultsStore, a: str, b: str, threshold: float = THRESHOLD,
                 confidence: float = CONFIDENCE, resamples: int = 2000,
                 drift: bool = True) -> list[dict[str, Any]]:
    """Compare the results selected by ``a`` with those selected by ``b`` (see
    :func:`select_runs`): one row per measured quantity of every paired measurement, with
    ``experiment``, ``table``, ``measurement`` (its parameters), ``quantity``, its values
    ``a`` and ``b``, ``ratio`` (B / A) with ``ratio_lo``/``ratio_hi``, the group's ``drift``
    (1 for a ratio that carries its own interval, and everywhere without ``drift``),
    ``relative`` (ratio / drift) with ``relative_lo``/``relative_hi``, ``flagged``, and the
    error columns' values in A and B with ``errors_changed``. Rows of one side without a peer
    on the other are not listed. Refuses a negative ``threshold``."""
    if not threshold >= 0:
        raise ValueError(f"threshold must be >= 0, got {threshold}")
    side_a, side_b = (_keyed(_rows(store, select_runs(store, s))) for s in (a, b))
    out = []
    for key, row_a in side_a.items():
        row_b = side_b.get(key)
        if row_b is None:
            continue
        errors = {}
        for column in ERROR_COLUMNS:
            if row_a.get(column) is not None or row_b.get(column) is not None:
                errors[f"{column}_a"], errors[f"{column}_b"] = row_a.get(column), row_b.get(column)
        changed = any(errors[f"{c}_a"] != errors[f"{c}_b"] for c in ERROR_COLUMNS
                      if f"{c}_a" in errors)
        group = (row_a.get("experiment"), row_a.get("table"), row_a.get("scene"))
        for q in _quantities(row_a, row_b, resamples, confidence):
            out.append(dict(experiment=row_a.get("experiment"), table=row_a.get("table"),
                            measurement=_describe(key), **q, group=group,
                            **errors, errors_changed=changed))
    drifts = _drifts(out) if drift else {}
    for line in out:
        d = drifts.get(line.pop("group"), 1.0) if line.pop("timed") else 1.0
        line.update(drift=d, relative=line["ratio"] / d, relative_lo=line["ratio_lo"] / d,
                    relative_hi=line["ratio_hi"] / d)
        line["flagged"] = (line["relative_lo"] > 1.0 + threshold
                           or line["relative_hi"] < 1.0 / (1.0 + threshold))
    return out


def _drifts(lines: list[dict[str, Any]]) -> dict[tuple, float]:
    """The median ratio of the times (quantities with samples) of each group that has
    :data:`MIN_DRIFT_TIMES` or more; a smaller group has no drift estimate (its own change
    would be taken for the machine's) and is compared as it is."""
    ratios: dict[tuple, list[float]] = defaultdict(list)
    for line in lines:
        if line["timed"]:
            ratios[line["group"]].append(line["ratio"])
    return {group: statistics.median(values) for group, values in ratios.items()
            if len(values) >= MIN_DRIFT_TIMES}


def summary(lines: list[dict[str, Any]]) -> str:
    """One line: how many quantities were paired and flagged, and the range of the drift."""
    flagged = sum(1 for line in lines if line["flagged"])
    share = flagged / len(lines) if lines else 0.0
    errors = sum(1 for line in lines if line.get("errors_changed"))
    drifts = sorted({round(line["drift"], 3) for line in lines if line["drift"] != 1.0})
    drift = (f", drift {drifts[0]:.3g}–{drifts[-1]:.3g}" if len(drifts) > 1
             else f", drift {drifts[0]:.3g}" if drifts else "")
    return (f"{len(lines)} paired quantities, {flagged} flagged as changed ({share:.1%}), "
            f"{errors} with changed errors{drift}")
