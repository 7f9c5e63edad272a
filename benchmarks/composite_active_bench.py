"""Sort-last compositing with whole frames against active pixels, in one process.

The es2008 benchmark (8 semi-cylindrical sheets of 250 × 250 quads, 1 M triangles, seen from
the front at 1000 × 1000 with per-pixel distance bands, as the compositing table of
``table_software_raster`` draws it; quick: 32 × 32 quads at 200 × 200) is split into 8
domains by space (:func:`workbench.distributed.domains.split_domains`) and each domain drawn
by the software rasterizer (untimed). The 8 frames are then composited, in this process, by:

* full-frame binary tree and binary swap (:mod:`workbench.algo.composite.merge`: whole
  frames or halves sent, 16 bytes a pixel);
* active-pixel binary tree, binary swap and radix-k with factors 2x2x2, 2x4, 4x2 and 8
  (direct send) (:mod:`workbench.algo.composite.schedules`: bounding box + run lengths of
  the drawn pixels sent).

Every result is checked against ``functools.reduce(composite, frames)`` and the one-process
image of all triangles first. Timed interleaved: each schedule's own composite seconds (the
whole in-process schedule, domain frames in, final frame out); each active schedule carries
``over_full_frame_swap``. Columns: ``rounds``, ``bytes_sent`` and its share of the full-frame
tree's and swap's (``share_of_tree``, ``share_of_swap``). Targets for the active schedules:
bytes <= 25 % of the full-frame schedules', composite <= 0.1 s at full size.

Run: ``workbench bench composite_active_bench [--quick]``.
"""

from __future__ import annotations

import functools

from workbench.measurement.bench import Case, benchmark

BANDS = dict(field="distance", bands=10)  # the compositing table's shading


def radix_factors(domains: int) -> list[tuple[int, ...]]:
    """All ordered factorisations of ``domains`` into factors >= 2 (2x2x2, 2x4, 4x2, 8 for 8)."""
    if domains == 1:
        return [()]
    return [(k,) + rest for k in range(2, domains + 1) if domains % k == 0
            for rest in radix_factors(domains // k)]


def same(a, b) -> bool:
    """Whether frames ``a`` and ``b`` hold the same colour, depth and triangle bytes."""
    return all(x.dtype == y.dtype and x.tobytes() == y.tobytes()
               for x, y in ((a.color, b.color), (a.depth, b.depth), (a.triangle, b.triangle)))


@benchmark("composite_active_bench", "sort-last compositing in one process: whole frames "
                                     "against active pixels",
           cases=[Case("es2008", {"quads": 250, "size": 1000, "domains": 8},
                       {"quads": 32, "size": 200, "domains": 8})])
def composite_active(bench, quads: int, size: int, domains: int) -> None:
    import numpy as np

    from workbench.algo.composite.merge import binary_swap, binary_tree, composite
    from workbench.algo.composite.schedules import active_radix, active_swap, active_tree
    from workbench.distributed.domains import split_domains
    from workbench.distributed.sortlast import SoftwareDomains
    from workbench.measurement.rows import default_camera
    from workbench.paths import Style
    from workbench.scene.generators import semicylinders

    camera = default_camera(semicylinders(8, quads), (size, size), view=(0.0, 0.0), up="y")
    render = SoftwareDomains(f"semicylinders:{quads}", "pixel_color", Style(**BANDS), camera,
                             (size, size))
    parts = split_domains(render.prepared().mesh, domains, by="space")
    frames = [render(ids) for ids in parts]
    expected = functools.reduce(composite, frames)
    if not same(expected, render(np.arange(render.prepared().triangles))):
        raise ValueError("the composite of the domains is not the one-process image")
    schedules = {"full-frame tree": binary_tree, "full-frame swap": binary_swap,
                 "active tree": active_tree, "active swap": active_swap}
    for factors in radix_factors(domains):
        schedules["active radix-k " + "x".join(map(str, factors))] = functools.partial(
            active_radix, factors=factors)
    stats = {}
    for name, schedule in schedules.items():
        out, stats[name] = schedule(frames)
        if not same(out, expected):
            raise ValueError(f"{name}: not functools.reduce(composite, frames)")
    tree, swap = stats["full-frame tree"].bytes_moved, stats["full-frame swap"].bytes_moved
    bench.interleave(
        {name: (lambda s=schedule: s(frames)[1].seconds) for name, schedule in schedules.items()},
        [(name, "full-frame swap") for name in schedules if name.startswith("active")],
        reported=True,
        columns_of={name: dict(rounds=s.rounds, bytes_sent=s.bytes_moved,
                               share_of_tree=s.bytes_moved / tree,
                               share_of_swap=s.bytes_moved / swap)
                    for name, s in stats.items()},
        triangles=int(render.prepared().triangles))
