"""The ``states`` table of :mod:`workbench.reproductions.simplify_tradeoff`: how far a
decimation holds over the states of a crash result.

crash2000 §3.2 decimates each part once with its vertices unchanged, so that the simplified
topology takes the coordinates of every time step. Our decimator certifies its one-sided bound
(original → simplified, per part) at the coordinates it saw; here every simplification of an
animated mesh is measured at every state with the certified metric
(:func:`workbench.algo.simplify.states.distances_over_states`, a bracket per state and part,
1 % of the part's tolerance wide), against each part's tolerance (0.5 % of the part's
bounding-sphere diameter at state 0):

* ours decimated at state 0 only, and ours certified at every state (``hausdorff_decimate``
  given the further states);
* at our state-0 count, per part (each part asked for our count of that part), every reference
  simplifier of :data:`~workbench.references.simplifiers.PART_SIMPLIFIERS` at state 0, and
  meshoptimizer's ``simplifyWithAttributes`` given the displacements of up to five further
  states as vertex attributes. A tool that keeps the vertices is measured at each state's
  coordinates directly; a tool that moves them has coordinates at state 0 only, so each of its
  vertices is carried along its nearest original triangle of its part
  (:func:`workbench.references.carried.carry_along`).

The eroding crash is written as a d3plot with lasso-python and read back through the d3plot
reader. Where a result deletes elements, each state is measured between the original triangles
drawn at it and the simplified ones drawn at it: ours hide a simplified triangle with the
element it descends from (certified at every state, the triangles deleted at different states
are decimated apart); a peer's triangles descend from no element, so all of them are drawn.

Rows: one per (scene, method, state, part) and, first at each state, one with ``part`` "worst"
for the part of the largest ratio; a tool that fails gives one row with ``failure`` set.
Distances in model units (mm).
"""

from __future__ import annotations

import ctypes
import inspect
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from workbench.algo.simplify import hausdorff_decimate
from workbench.algo.simplify.states import StateBounds, bounds_over_states, distances_over_states
from workbench.experiment.context import ExperimentContext
from workbench.references.carried import carry_along
from workbench.references.simplifiers import PART_SIMPLIFIERS, Simplified, simplify_per_part
from workbench.scene import generators
from workbench.scene.mesh import FEMesh

from ._declared.simplify_tradeoff import STATES

STATES_PCT = 0.5  # tolerance, % of each part's bounding-sphere diameter at state 0
BRACKET = 0.01  # bracket width of every distance, a share of its part's tolerance
TINY_PANELS = 400  # tiny: the smallest stamped panels, crushed over TINY_STATES states
TINY_STATES = 3
ATTRIBUTE_STATES = 5  # further states whose displacements meshoptimizer gets as attributes

OURS_STATE0 = "ours, decimated at state 0"
OURS_ALL = "ours, certified at every state"
MESHOPT_ATTRIBUTES = "meshoptimizer simplifyWithAttributes (displacements)"
KEPT = "kept"
CARRIED = "moved (carried along its nearest original triangle)"
OURS_SCOPE, OURS_BORDERS = "per part", "slide (shared: in both parts)"


@dataclass
class Animated:
    """An animated triangle mesh: ``steps`` (T, N, 3) float64, ``triangles`` (K, 3) int64,
    ``parts`` (K,) the part label of each triangle, ``alive`` (T, K) bool which are drawn at
    each state (None: all of them, no erosion)."""

    label: str
    steps: np.ndarray
    triangles: np.ndarray
    parts: np.ndarray
    alive: np.ndarray | None = None


def _animated(label: str, mesh: FEMesh) -> Animated:
    tri = mesh.triangulation
    steps = mesh.nodes[None] if mesh.steps is None else mesh.steps
    return Animated(label, np.asarray(steps, np.float64), tri.triangles.astype(np.int64),
                    mesh.parts[tri.element_of], mesh.triangles_alive())


def _read_back(mesh: FEMesh) -> FEMesh:
    """``mesh`` written as a d3plot with lasso-python and read by the d3plot reader."""
    from workbench.output.d3plot import write_d3plot
    from workbench.scene.readers import load

    with tempfile.TemporaryDirectory() as folder:
        return load(write_d3plot(mesh, Path(folder)))


def sequences(exp: ExperimentContext) -> Iterator[Animated]:
    """The animated meshes of the table: the crash (the car deck crushed over 8 states; none
    without the shared data), the eroding crash written as a d3plot and read back, and, at full
    size, the shared d3plot result where it holds more than one state; tiny: the smallest
    stamped panels crushed over 3 states."""
    if exp.tiny:
        panels = generators.stamped_panels(TINY_PANELS)
        yield _animated("panels crushed", generators.crash_sequence(panels, steps=TINY_STATES))
        return
    crash = exp.builtin("crash")
    if crash is not None:
        yield _animated("crash", crash)
    eroded = exp.builtin("crash_eroded")
    if eroded is not None:
        yield _animated("crash_eroded (d3plot)", _read_back(eroded))
    d3plot = None if exp.quick else exp.builtin("d3plot")
    if d3plot is not None:
        n = 1 if d3plot.steps is None else len(d3plot.steps)
        if n > 1:
            yield _animated("d3plot", d3plot)
        else:
            exp.say(f"states table: d3plot skipped, it holds {n} state (nothing to carry over)")


def attributes_supported() -> str | None:
    """None where meshoptimizer's ``simplifyWithAttributes`` can be run here, else why not."""
    try:
        import meshoptimizer
        from meshoptimizer._loader import lib
    except ImportError as exc:
        return f"meshoptimizer is not importable ({exc})"
    wrapper = getattr(meshoptimizer, "simplify_with_attributes", None)
    if wrapper is None or not hasattr(lib, "meshopt_simplifyWithAttributes"):
        return "the installed meshoptimizer bindings offer no simplifyWithAttributes"
    if "vertex_lock" not in inspect.signature(wrapper).parameters:
        return "the installed simplifyWithAttributes has no vertex locks (an older signature)"
    return None


def _row(**values) -> dict:
    """A row with every declared column of the table, in the declared order."""
    stray = set(values) - set(STATES.names)
    if stray:
        raise KeyError(f"columns {sorted(stray)} are not declared for the states table")
    return {name: values.get(name) for name in STATES.names}


def _rows(base: dict, bounds: StateBounds, out_parts: np.ndarray) -> list[dict]:
    """The rows of one simplification: per state its worst part, then every part."""
    counts = {int(p): int((out_parts == p).sum()) for p in bounds.part_labels}
    rows = []
    ratio = bounds.ratio
    for k, state in enumerate(bounds.states):
        worst = int(np.argmax(ratio[k]))
        entries = [("worst", worst)] + [(int(label), p)
                                        for p, label in enumerate(bounds.part_labels)]
        for part, p in entries:
            label = int(bounds.part_labels[p])
            rows.append(_row(**base, state=int(state), part=part,
                             worst_part=label if part == "worst" else None,
                             tol_mm=float(bounds.tol_abs[p]),
                             hausdorff_lower_mm=float(bounds.lower[k, p]),
                             hausdorff_mm=float(bounds.upper[k, p]),
                             ratio=float(ratio[k, p]), part_triangles=counts[label]))
    return rows


def _meshopt_attributes(steps: np.ndarray, triangles: np.ndarray, parts: np.ndarray,
                        targets: dict, states: np.ndarray) -> Simplified:
    """meshoptimizer's ``simplifyWithAttributes`` per part at state 0, its border locked
    (``SIMPLIFY_LOCK_BORDER``), each vertex's displacements from state 0 to ``states`` as its
    attributes, weighted by 1 / the tool's position scale (``simplify_scale``: positions are
    normalised by it, so a displacement weighs as much as a position of the same length).
    The installed bindings declare no argument types for this function (their Python float
    error target cannot be passed), so the C function is called through the prototype its
    wrapper calls, with vertex locks."""
    import meshoptimizer
    from meshoptimizer._loader import lib

    P, size = ctypes.POINTER, ctypes.c_size_t
    fn = ctypes.CFUNCTYPE(size, P(ctypes.c_uint), P(ctypes.c_uint), size, P(ctypes.c_float),
                          size, size, P(ctypes.c_float), size, P(ctypes.c_float), size,
                          P(ctypes.c_ubyte), size, ctypes.c_float, ctypes.c_uint,
                          P(ctypes.c_float))(
        ctypes.cast(lib.meshopt_simplifyWithAttributes, ctypes.c_void_p).value)

    def run(v, f, target):
        used, local = np.unique(f, return_inverse=True)
        x0 = v[0, used]
        centre = (x0.min(axis=0) + x0.max(axis=0)) / 2
        positions = np.ascontiguousarray(x0 - centre, np.float32)
        moved = v[states][:, used] - x0[None]  # (S, n, 3)
        attributes = np.ascontiguousarray(moved.transpose(1, 0, 2).reshape(len(used), -1),
                                          np.float32)
        count = attributes.shape[1]
        weights = np.full(count, 1.0 / max(float(meshoptimizer.simplify_scale(positions)),
                                           1e-30), np.float32)
        indices = np.ascontiguousarray(local.reshape(-1), np.uint32)
        out = np.empty_like(indices)
        f32 = P(ctypes.c_float)
        n = fn(out.ctypes.data_as(P(ctypes.c_uint)), indices.ctypes.data_as(P(ctypes.c_uint)),
               len(indices), positions.ctypes.data_as(f32), len(positions), 12,
               attributes.ctypes.data_as(f32), 4 * count, weights.ctypes.data_as(f32), count,
               None, 3 * int(target), 1.0, meshoptimizer.SIMPLIFY_LOCK_BORDER, None)
        return used[out[:n].astype(np.int64)].reshape(-1, 3)

    out_f, out_p, seconds = [], [], 0.0
    for label in np.unique(parts):
        start = time.perf_counter()
        try:
            g = run(steps, triangles[parts == label], max(int(targets[int(label)]), 1))
            failure = None if len(g) else "returned an empty mesh"
        except Exception as exc:  # a reference tool's failure is a result, not a crash
            g, failure = None, f"{type(exc).__name__}: {exc}"
        seconds += time.perf_counter() - start
        if failure:
            return Simplified(MESHOPT_ATTRIBUTES, np.zeros((0, 3)), np.zeros((0, 3), np.int64),
                              seconds, False, f"part {label}: {failure}", "per part", "locked")
        out_f.append(g)
        out_p.append(np.full(len(g), label, parts.dtype))
    return Simplified(MESHOPT_ATTRIBUTES, steps[0], np.concatenate(out_f), seconds, True, None,
                      "per part", "locked", np.concatenate(out_p))


def attribute_states(n_states: int) -> np.ndarray:
    """Up to :data:`ATTRIBUTE_STATES` further states, evenly spread, the last among them."""
    if n_states < 2:
        return np.zeros(0, np.int64)
    picked = np.round(np.linspace(1, n_states - 1, min(ATTRIBUTE_STATES, n_states - 1)))
    return np.unique(picked.astype(np.int64))


def _carried_steps(seq: Animated, out: Simplified) -> tuple[np.ndarray, np.ndarray]:
    """(triangles, steps) of a tool that moved its vertices: its referenced vertices, each
    carried from state 0 along the original triangles of its part."""
    used, local = np.unique(out.triangles, return_inverse=True)
    local = local.reshape(-1)
    point_parts = np.empty(len(used), out.parts.dtype)
    point_parts[local] = np.repeat(out.parts, 3)
    steps = carry_along(seq.steps, seq.triangles, out.vertices[used], parts=seq.parts,
                        point_parts=point_parts)
    return local.reshape(-1, 3), steps


def _peer_rows(exp: ExperimentContext, seq: Animated, out: Simplified, ours,
               base: dict) -> list[dict]:
    target = len(ours.triangles)
    base = dict(base, method=out.method, scope=out.scope, borders=out.borders,
                vertices=KEPT if out.shares_vertices else CARRIED, target_triangles=target,
                triangles=len(out.triangles), seconds=out.seconds, failure=out.failure)
    if not out.failure:
        base["stopped_at"] = (len(out.triangles) if len(out.triangles) > target
                              + max(1, target // 100) else None)
        try:
            if out.shares_vertices:
                tri, moved = out.triangles, None
            else:
                tri, moved = _carried_steps(seq, out)
            drawn = None if seq.alive is None else np.ones((len(seq.steps), len(tri)), bool)
            bounds = distances_over_states(seq.steps, seq.triangles, seq.parts, tri, out.parts,
                                           ours.part_labels, ours.tol_abs,
                                           simplified_steps=moved, tol=BRACKET,
                                           alive=seq.alive, simplified_alive=drawn)
        except ValueError as exc:
            base["failure"] = f"not measured: {exc}"
    if base["failure"]:
        exp.say(f"  states {seq.label}: {out.method} fails ({base['failure']})")
        return [_row(**base)]
    exp.say(f"  states {seq.label}: {out.method} {len(out.triangles)} triangles, worst ratio "
            f"per state {_worst_text(bounds)}")
    return _rows(base, bounds, out.parts)


def _worst_text(bounds: StateBounds) -> str:
    return ", ".join(f"{r:.3g}" for _, _, r in bounds.worst_per_state())


def sequence_rows(exp: ExperimentContext, seq: Animated) -> list[dict]:
    """Every row of one animated mesh (see the module notes)."""
    steps, f, parts = seq.steps, seq.triangles, seq.parts
    base = dict(scene=seq.label, tol_pct=STATES_PCT, input_triangles=len(f), scope=OURS_SCOPE,
                borders=OURS_BORDERS, vertices=KEPT)
    tol = STATES_PCT / 100.0
    alive = seq.alive
    ours = hausdorff_decimate(steps[0], f, tol, relative=True, parts=parts,
                              alive=None if alive is None else alive[:1])
    bounds = bounds_over_states(steps, f, parts, ours, tol=BRACKET, alive=alive)
    rows = _rows(dict(base, method=OURS_STATE0, states_seen="state 0",
                      triangles=len(ours.triangles), seconds=ours.seconds,
                      states_certified=ours.states_certified), bounds, ours.parts)
    exp.say(f"  states {seq.label}: {OURS_STATE0} {len(ours.triangles)} triangles in "
            f"{ours.seconds:.2f} s, worst ratio per state {_worst_text(bounds)}")
    if len(steps) > 1:
        every = hausdorff_decimate(steps[0], f, tol, relative=True, parts=parts,
                                   states=steps[1:], alive=alive)
        b_all = bounds_over_states(steps, f, parts, every, tol=BRACKET, alive=alive)
        rows += _rows(dict(base, method=OURS_ALL, states_seen=f"states 0-{len(steps) - 1}",
                           triangles=len(every.triangles), seconds=every.seconds,
                           states_certified=every.states_certified), b_all, every.parts)
        exp.say(f"  states {seq.label}: {OURS_ALL} {len(every.triangles)} triangles in "
                f"{every.seconds:.2f} s, worst ratio per state {_worst_text(b_all)}")
    targets = {int(p): int((ours.parts == p).sum()) for p in np.unique(parts)}
    peer = dict(base, states_seen="state 0")
    for method in PART_SIMPLIFIERS:
        out = simplify_per_part(method, steps[0], f, parts, targets)
        rows += _peer_rows(exp, seq, out, ours, peer)
    why = attributes_supported()
    picked = attribute_states(len(steps))
    if why is None and len(picked):
        out = _meshopt_attributes(steps, f, parts, targets, picked)
        seen = "state 0, displacements at " + ", ".join(str(int(s)) for s in picked)
        rows += _peer_rows(exp, seq, out, ours, dict(peer, states_seen=seen))
    elif why is not None:
        exp.say(f"  states {seq.label}: {MESHOPT_ATTRIBUTES} left out: {why}")
    return rows


def state_rows(exp: ExperimentContext) -> list[dict]:
    """The ``states`` table: every animated mesh of :func:`sequences` (see the module notes)."""
    rows = []
    for seq in sequences(exp):
        exp.say(f"states table, {seq.label}: {len(seq.steps)} states, {len(seq.triangles)} "
                f"triangles, {len(np.unique(seq.parts))} parts")
        rows += sequence_rows(exp, seq)
    return rows
