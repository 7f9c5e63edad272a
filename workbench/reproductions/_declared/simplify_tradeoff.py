"""The tables and claims of :mod:`workbench.reproductions.simplify_tradeoff` (crash2000 §3.2):
Hausdorff-bounded decimation against today's simplifiers, the certified metric, the certified
peer and the equal-error view."""

from __future__ import annotations

from workbench.experiment.declare import HEADLINE_CHARS, Claim, Column, Declaration, Table
from workbench.experiment.report import num

SCENE = Column("scene", "", "the mesh simplified")
METHOD = Column("method", "", "the simplifier and its variant")
SCOPE = Column("scope", "", "whole mesh, or per part (each part asked for our count of it)")
BORDERS = Column("borders", "", "how part borders are treated (locked, sliding, free)")
VERTICES = Column("vertices", "", "whether vertices are kept in place or moved")
TOL_PCT = Column("tol_pct", "%", "our tolerance, a share of each part's bounding-sphere "
                 "diameter")
INPUT = Column("input_triangles", "", "triangles of the original mesh")
TRIANGLES = Column("triangles", "", "triangles of the simplified mesh")
SECONDS = Column("seconds", "s", "time of the simplification")
TARGET = Column("target_triangles", "", "the count asked for (ours)")
FAILURE = Column("failure", "", "why the tool failed (empty: it did not)")
H_LOWER = Column("hausdorff_lower_mm", "mm", "lower end of the certified one-sided Hausdorff "
                 "bracket, original → simplified")
H_UPPER = Column("hausdorff_mm", "mm", "upper end of the certified one-sided Hausdorff "
                 "bracket, original → simplified")
SAMPLES = Column("sample_points", "", "points pymeshlab's sampled distance used")

TABLE = Table(
    "table",
    SCENE, METHOD, SCOPE, BORDERS, VERTICES, TOL_PCT, INPUT, TRIANGLES, SECONDS,
    Column("certified_max", "mm", "our decimator's own certified bound"),
    Column("within_tol_per_part", "", "whether every part is within its tolerance"),
    Column("border_vertices_kept", "", "share of the parts' border vertices kept in place"),
    Column("bytes_saved_by_sharing", "B", "bytes the shared vertex buffer saves"),
    H_LOWER, H_UPPER,
    Column("hausdorff_pct_diag", "%", "hausdorff_mm as a share of the bounding-box diagonal"),
    Column("hausdorff_bracket_reached", "", "whether the bracket reached its width"),
    Column("hausdorff_mean_mm", "mm", "mean one-sided distance"),
    Column("metric_s", "s", "time of the certified metric"),
    Column("symmetric_hausdorff_lower_mm", "mm", "lower end of the symmetric Hausdorff "
           "bracket"),
    Column("symmetric_hausdorff_mm", "mm", "upper end of the symmetric Hausdorff bracket"),
    Column("pymeshlab_hausdorff_mm", "mm", "pymeshlab's sampled one-sided distance"),
    SAMPLES,
    Column("pymeshlab_outside_bracket", "", "whether pymeshlab's value falls outside the "
           "certified bracket"),
    Column("hausdorff_over_ours", "×", "the row's lower distance over our upper one at the "
           "same count"),
    Column("time_over_ours", "×", "the row's time over ours (separate measurements)"),
    TARGET,
    Column("stopped_at", "", "the count the tool stopped at where it could not reach ours"),
    FAILURE,
)

EQUAL_ERROR = Table(
    "equal_error",
    SCENE, TOL_PCT, METHOD, SCOPE, BORDERS, VERTICES,
    Column("error", "mm", "E: our certified one-sided distance, the error every peer must "
           "reach"),
    Column("error_pct_diag", "%", "E as a share of the bounding-box diagonal"),
    TRIANGLES,
    Column("over_ours", "×", "triangles over ours at the same error"),
    SECONDS,
    Column("calls", "", "simplifier calls of the bisection"),
    Column("meshoptimizer_at_this_error", "", "triangles meshoptimizer (whole mesh) needs at "
           "this row's error"),
    H_UPPER, FAILURE,
)

PEER = Table(
    "hausdorff_peer",
    Column("model", "", "the mesh decimated (the bunny, the car deck, or panels)"),
    INPUT, TARGET, TRIANGLES,
    Column("decimation", "", "the decimation both brackets measure"),
    Column("tol_mm", "mm", "the bracket width handed to both"),
    Column("tol_share_of_diagonal", "", "tol_mm over the bounding-box diagonal"),
    Column("ours_lower_mm", "mm", "our bracket's lower end"),
    Column("ours_upper_mm", "mm", "our bracket's upper end"),
    Column("ours_tol_reached", "", "whether our bracket reached the width"),
    Column("ours_s", "s", "our median wall time"),
    Column("ours_s_min", "s", "our fastest round"),
    Column("ours_s_max", "s", "our slowest round"),
    Column("peer_lower_mm", "mm", "cascading-upper-bounds' lower end"),
    Column("peer_upper_mm", "mm", "cascading-upper-bounds' upper end"),
    Column("peer_tol_reached", "", "whether the peer's bracket reached the width"),
    Column("peer_s", "s", "the peer's median wall time"),
    Column("peer_s_min", "s", "the peer's fastest round"),
    Column("peer_s_max", "s", "the peer's slowest round"),
    Column("time_ratio", "×", "median per-round ratio peer ÷ ours (interleaved rounds)"),
    Column("time_ratio_min", "×", "smallest per-round ratio"),
    Column("time_ratio_max", "×", "largest per-round ratio"),
    Column("faster", "", "which is faster, every round agreeing"),
    Column("overlap", "", "whether the brackets overlap (they must)"),
    Column("repeats", "", "timed rounds"),
    Column("peer_failure", "", "why the peer failed (empty: it did not)"),
)

METRIC = Table(
    "metric",
    SCENE,
    Column("tool", "", "the distance tool and its setting"),
    Column("value", "mm", "the distance the tool gives"),
    H_LOWER, H_UPPER,
    Column("width_reached", "", "whether the bracket reached its width"),
    SECONDS, SAMPLES,
    Column("outside_bracket", "", "whether the value falls outside our tightest bracket"),
    Column("worst_point_error", "mm", "largest error of a point's distance against the exact "
           "one"),
    Column("exact_at_worst_point", "mm", "the exact distance at that point"),
)


STATES = Table(
    "states",
    SCENE, METHOD,
    Column("states_seen", "", "the states whose coordinates the simplifier saw (ours at every "
           "state: certified at each)"),
    SCOPE, BORDERS,
    Column("vertices", "", "kept in place (an index array: every state's coordinates apply), "
           "or moved (each carried along its nearest original triangle of its part, from state "
           "0 to every state)"),
    TOL_PCT,
    Column("state", "", "the state measured (0: the state decimated)"),
    Column("part", "", "the part measured, or \"worst\": the part of the largest ratio at this "
           "state"),
    Column("worst_part", "", "on a \"worst\" row, that part's label"),
    Column("tol_mm", "mm", "the part's tolerance (tol_pct of its bounding-sphere diameter at "
           "state 0)"),
    Column("hausdorff_lower_mm", "mm", "lower end of the certified one-sided Hausdorff "
           "bracket, original part → simplified part, both at this state (1 % of tol_mm wide)"),
    Column("hausdorff_mm", "mm", "upper end of that bracket"),
    Column("ratio", "×", "hausdorff_mm / tol_mm: above 1, the part leaves its tolerance at this "
           "state"),
    INPUT,
    Column("target_triangles", "", "the count asked for: ours decimated at state 0 (each part "
           "asked for our count of it)"),
    Column("triangles", "", "triangles of the whole simplified mesh"),
    Column("part_triangles", "", "triangles of the row's part in the simplified mesh"),
    Column("stopped_at", "", "the count the tool stopped at where it could not reach ours"),
    Column("seconds", "s", "time of the simplification (all parts)"),
    Column("states_certified", "", "states our decimator certified the bound at (1: the state "
           "decimated only)"),
    FAILURE,
)


def decimation_claims(tables) -> list[str]:
    """Per scene our first decimation, and ours against cascading-upper-bounds."""
    seen, out = set(), []
    for r in tables("table"):
        if r.get("method") == "ours (Hausdorff-bounded)" and r["scene"] not in seen:
            seen.add(r["scene"])
            out.append(f"{r['scene']} at {num(r['tol_pct'])} %: {r['input_triangles']:,} → "
                       f"{r['triangles']:,} triangles, certified one-sided distance "
                       f"{num(r.get('hausdorff_mm'))} mm in {num(r['seconds'])} s")
    for r in tables("hausdorff_peer"):
        if r.get("ours_s") is None or r.get("peer_s") is None:
            continue
        out.append(f"{r['model']} → {r['triangles']:,} triangles, certified bracket at "
                   f"{num(r['tol_share_of_diagonal'])} of the diagonal: ours {num(r['ours_s'])} s, "
                   f"cascading-upper-bounds {num(r['peer_s'])} s (its time "
                   f"{num(r['time_ratio'])}× [{num(r['time_ratio_min'])}, "
                   f"{num(r['time_ratio_max'])}] ours, interleaved), brackets "
                   f"{'overlap' if r.get('overlap') else 'DISJOINT'}")
    return out


OURS_STATE0 = "ours, decimated at state 0"
OURS_ALL = "ours, certified at every state"


def _worst_over_states(rows, scene: str, method: str):
    """The row of the largest ratio of ``method`` on ``scene`` over every state (among its
    "worst" rows); None where it has none."""
    worst = [r for r in rows if r.get("scene") == scene and r.get("method") == method
             and r.get("part") == "worst" and r.get("ratio") is not None]
    return max(worst, key=lambda r: r["ratio"]) if worst else None


def state_claims(tables) -> list[str]:
    """Per animated scene: ours decimated at state 0 against ours certified at every state,
    the worst ratio of certified distance to tolerance over every state and part, triangles
    and time; then each peer's worst ratio at our count."""
    rows = tables("states")
    out = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        first = _worst_over_states(rows, scene, OURS_STATE0)
        if first is None:
            continue
        at0 = [r for r in rows if r["scene"] == scene and r["method"] == OURS_STATE0
               and r["part"] == "worst" and r["state"] == 0]
        text = (f"{scene} at {num(first['tol_pct'])} %: decimated at state 0, "
                f"{first['triangles']:,} triangles in {num(first['seconds'])} s, worst "
                f"certified distance / tolerance {num(at0[0]['ratio']) if at0 else '?'} at "
                f"state 0 and {num(first['ratio'])} over every state (state {first['state']}, "
                f"part {first['worst_part']})")
        every = _worst_over_states(rows, scene, OURS_ALL)
        if every is not None:
            text += (f"; certified at every state: {every['triangles']:,} triangles in "
                     f"{num(every['seconds'])} s, worst {num(every['ratio'])} (state "
                     f"{every['state']})")
        else:
            text += "; certified at every state: not run"
        out.append(text)
        peers = [m for m in dict.fromkeys(r["method"] for r in rows if r["scene"] == scene)
                 if not m.startswith("ours")]
        said = []
        for method in peers:
            mine = [r for r in rows if r["scene"] == scene and r["method"] == method]
            top = _worst_over_states(rows, scene, method)
            if top is None:
                if any(r.get("failure") for r in mine):
                    said.append(f"{method} failed")
                continue
            first = [r for r in mine if r["part"] == "worst" and r["state"] == 0]
            stopped = top.get("stopped_at")
            said.append(f"{method} {num(first[0]['ratio']) if first else '?'} → "
                        f"{num(top['ratio'])}"
                        + (f" (stopped at {stopped:,} triangles)" if stopped else ""))
        if said:
            out.append(f"{scene}, peers at our state-0 count, worst ratio at state 0 → over "
                       "every state: " + "; ".join(said))
    return out


def decimation_headline(tables) -> list[str]:
    """Where the states table has the crash: its triangles and worst ratio of certified
    distance to tolerance over every state, decimated at state 0 and certified at every state.
    Else our first decimation of the first scene, its certified distance measured at the
    coordinates it was decimated at."""
    rows = tables("states")
    first = _worst_over_states(rows, "crash", OURS_STATE0)
    every = _worst_over_states(rows, "crash", OURS_ALL)
    if first is not None and every is not None:
        n_states = len({x["state"] for x in rows if x["scene"] == "crash"})
        text = (f"crash, {n_states} states, {num(first['tol_pct'])} % per part: decimated at "
                f"state 0, {first['triangles']:,} triangles reach {num(first['ratio'])}× the "
                f"tolerance; certified at every state, {every['triangles']:,} stay within "
                f"{num(every['ratio'])}×")
        if len(text) <= HEADLINE_CHARS:
            return [text]
    for r in tables("table"):
        if r.get("method") == "ours (Hausdorff-bounded)":
            return [f"{r['scene']} at {num(r['tol_pct'])} %: {r['input_triangles']:,} → "
                    f"{r['triangles']:,} triangles, certified {num(r.get('hausdorff_mm'))} mm "
                    f"at the state decimated, in {num(r['seconds'])} s"]
    return []


STATE_READS = ("scene", "method", "tol_pct", "state", "part", "worst_part", "ratio",
               "triangles", "stopped_at", "seconds", "failure")

DECLARED = Declaration(
    paper="crash2000 §3.2",
    tables=(TABLE, EQUAL_ERROR, PEER, METRIC, STATES),
    claims=(Claim("certified decimation, and the certified metric against its peer",
                  {"table": ("scene", "method", "tol_pct", "input_triangles", "triangles",
                             "hausdorff_mm", "seconds"),
                   "hausdorff_peer": ("model", "triangles", "tol_share_of_diagonal", "ours_s",
                                      "peer_s", "time_ratio", "time_ratio_min",
                                      "time_ratio_max", "overlap")},
                  decimation_claims),
            Claim("a state-0 decimation over the states of the crash, against one certified "
                  "at every state and the peers",
                  {"states": STATE_READS},
                  state_claims)),
    headline=Claim("certified decimation over the states of the crash (else of the first scene)",
                   {"table": ("scene", "method", "tol_pct", "input_triangles", "triangles",
                              "hausdorff_mm", "seconds"),
                    "states": STATE_READS},
                   decimation_headline),
)
