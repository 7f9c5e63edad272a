"""Our certified Hausdorff bracket against cascading-upper-bounds (Sacht & Jacobson, SGP 2024),
timed interleaved: the ``hausdorff_peer`` table of the simplify_tradeoff experiment on its own.

Cases: the bunny (pymeshlab's sample, 56 172 triangles) and the shared car deck (8 732
triangles), each against pymeshlab's quadric edge collapse (whole mesh, vertices moved) to
1 000 and 4 000 triangles (quick: 1 000), one-sided original → decimated, both tools at our
default bracket width (1e-4 of the original's bounding-box diagonal, handed to the peer as the
same absolute width). One untimed round of both (numba's compilation, the peer's first call),
then the timed rounds, ours then the peer: ``ours`` (wall seconds of
:func:`~workbench.algo.hausdorff.hausdorff` with ``estimates=False``) and ``peer`` (its own
seconds), ``peer`` carrying ``over_ours``. Ours runs on every core (numba), the peer on one
thread. Columns: the target and the reached triangle counts, the bracket width ``tol``
(model units: mm for the car) and whether the two brackets overlap.

Run: ``workbench bench hausdorff_peer [--quick]`` (needs pymeshlab and the peer; the car case
the shared car deck).
"""

from __future__ import annotations

from workbench.data import CAR_DECK
from workbench.measurement.bench import Case, benchmark, needs_module, seconds_of

TARGETS = {"full": (1_000, 4_000), "quick": (1_000,)}


def peer_missing() -> str | None:
    """Why the peer cannot run here, or None."""
    from workbench.references.cascading_upper_bounds import peer_unavailable

    return peer_unavailable()


@benchmark("hausdorff_peer", "our certified Hausdorff bracket against cascading-upper-bounds, "
                             "interleaved",
           cases=[Case("bunny"), Case("car")],
           requires=[needs_module("pymeshlab", "trimesh"), peer_missing])
def hausdorff_peer(bench) -> None:
    import numpy as np

    from workbench import data
    from workbench.algo.hausdorff import hausdorff
    from workbench.references.cascading_upper_bounds import (
        brackets_overlap,
        peer_hausdorff,
        warm_up,
    )
    from workbench.references.simplifiers import simplify_with
    from workbench.reproductions.simplify_tradeoff import PEER_DECIMATION, smooth_closed_mesh
    from workbench.scene.readers import load

    if bench.case.name == "bunny":
        model = smooth_closed_mesh()
        bench.require(model is None and "pymeshlab's sample meshes are not installed")
        v, f = model.vertices, model.triangles
    else:
        path = data.shared_file(CAR_DECK)
        bench.require(path is None and f"needs the shared data file {CAR_DECK}")
        car = load(path)
        v, f = car.nodes, car.triangulation.triangles.astype(np.int64)
    used = v[np.unique(f)]
    tol = 1e-4 * float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    warm_up()
    for target in TARGETS[bench.size]:
        out = simplify_with(PEER_DECIMATION, v, f, target)
        if out.failure or not len(out.triangles):
            raise ValueError(f"{PEER_DECIMATION} to {target} triangles failed: {out.failure}")
        vb, fb = out.vertices, out.triangles
        ours = hausdorff(v, f, vb, fb, tol=tol, estimates=False)
        peer = peer_hausdorff(v, f, vb, fb, tol=tol)
        overlap = brackets_overlap(ours.lower, ours.upper, peer.lower, peer.upper)
        bench.interleave(
            {"ours": lambda vb=vb, fb=fb: seconds_of(
                lambda: hausdorff(v, f, vb, fb, tol=tol, estimates=False)),
             "peer": lambda vb=vb, fb=fb: peer_hausdorff(v, f, vb, fb, tol=tol).seconds},
            [("peer", "ours")], reported=True, input_triangles=len(f),
            target=str(target), triangles=len(fb), decimation=PEER_DECIMATION, tol=tol,
            overlap=bool(overlap))
