"""The compositing schedules of :func:`workbench.distributed.sortlast.render_sortlast` as Dask
tasks, and the worker-side functions those tasks run.

Each ``submit_*`` function takes the client, the run's key prefix, the futures of the domain
frames (frame i from domain i) and ``where``, the worker address of each domain's rank, and
submits the schedule's tasks — each placed (as a preference) on the worker of the rank that
receives — returning the final future and, for the schedules that send encoded pieces, the
pieces' futures. Nothing here waits for a result.
"""

from __future__ import annotations

import numpy as np

from ..algo.composite.merge import Region, assemble, composite, crop, swap_plan, tree_plan
from ..algo.softraster.frame import Frame


def submit_tree(client, run, frames, where, height, width):
    """Binary-tree tasks; returns the final future and the schedule's pixels sent."""
    plan = tree_plan(len(frames))
    held = dict(enumerate(frames))
    for k, pairs in enumerate(plan.rounds):
        for receiver, sender in pairs:
            held[receiver] = client.submit(
                composite, held[receiver], held.pop(sender),
                key=f"{run}-tree-round{k}-d{receiver}-d{sender}", pure=False,
                workers=[where[receiver]], allow_other_workers=True)
    return held[0], plan.bytes_moved(height, width, 1)


def submit_swap(client, run, frames, where, height, width):
    """Binary-swap tasks; returns the final future and the schedule's pixels sent."""
    plan = swap_plan(len(frames), height, width)

    def submit(fn, *args, key, rank_domain):
        return client.submit(fn, *args, key=f"{run}-swap-{key}", pure=False,
                             workers=[where[rank_domain]], allow_other_workers=True)

    folded = {keeper: submit(composite, frames[keeper], frames[sender],
                             key=f"fold-d{keeper}-d{sender}", rank_domain=keeper)
              for keeper, sender in plan.fold}
    held = [folded.get(d, frames[d]) for d in plan.ranks]
    for k, exchanges in enumerate(plan.rounds):
        for e in exchanges:
            low_d, high_d = plan.ranks[e.lower], plan.ranks[e.upper]
            low_part, high_part = e.lower_keeps.within(e.held), e.upper_keeps.within(e.held)
            # each rank cuts out the half it gives up, on its own worker
            to_low = submit(_cut, held[e.upper], low_part,
                            key=f"round{k}-cut-d{high_d}-to-d{low_d}", rank_domain=high_d)
            to_high = submit(_cut, held[e.lower], high_part,
                             key=f"round{k}-cut-d{low_d}-to-d{high_d}", rank_domain=low_d)
            # and composites the half it keeps with the half it receives, lower domain first
            held[e.lower] = submit(_merge, held[e.lower], low_part, to_low, None,
                                   key=f"round{k}-merge-d{low_d}", rank_domain=low_d)
            held[e.upper] = submit(_merge, to_high, None, held[e.upper], high_part,
                                   key=f"round{k}-merge-d{high_d}", rank_domain=high_d)
    if len(held) == 1:
        final = held[0]
    else:
        final = submit(_gather, height, width, plan.regions, *held, key="gather",
                       rank_domain=plan.ranks[0])
    return final, plan.bytes_moved(1)


def submit_active(client, run, frames, where, height, width, method, factors):
    """Active-pixel schedules (:mod:`workbench.algo.composite.active`): every rank turns its
    frame into its drawn pixels on its own worker; what travels are encoded pieces. Returns
    the final frame's future and the futures of every piece sent."""
    from ..algo.composite.active import ActivePixels
    from ..algo.composite.schedules import radix_plan

    pieces = []

    def submit(fn, *args, key, rank_domain):
        return client.submit(fn, *args, key=f"{run}-{method}-{key}", pure=False,
                             workers=[where[rank_domain]], allow_other_workers=True)

    def send(held_of, rank_domain, region, key):
        piece = submit(_pack, held_of, region, key=f"{key}-pack", rank_domain=rank_domain)
        pieces.append(piece)
        return piece

    held = {d: submit(ActivePixels.from_frame, f, key=f"active-d{d}", rank_domain=d)
            for d, f in enumerate(frames)}
    ranks = list(range(len(frames)))
    if method == "active-tree":
        for k, pairs in enumerate(tree_plan(len(frames)).rounds):
            for receiver, sender in pairs:
                piece = send(held.pop(sender), sender, None, f"round{k}-d{sender}")
                held[receiver] = submit(_merge_in, held[receiver], None, piece,
                                        key=f"round{k}-merge-d{receiver}",
                                        rank_domain=receiver)
        parts, ranks = {0: held[0]}, [0]  # the tree ends on rank 0: nothing to gather
    elif method == "active-swap":
        plan = swap_plan(len(frames), height, width)
        for keeper, sender in plan.fold:
            piece = send(held.pop(sender), sender, None, f"fold-d{sender}")
            held[keeper] = submit(_merge_in, held[keeper], None, piece,
                                  key=f"fold-merge-d{keeper}", rank_domain=keeper)
        ranks = list(plan.ranks)
        for k, exchanges in enumerate(plan.rounds):
            for e in exchanges:
                low_d, high_d = ranks[e.lower], ranks[e.upper]
                to_low = send(held[high_d], high_d, e.lower_keeps, f"round{k}-d{high_d}")
                to_high = send(held[low_d], low_d, e.upper_keeps, f"round{k}-d{low_d}")
                held[low_d] = submit(_merge_in, held[low_d], e.lower_keeps, to_low,
                                     key=f"round{k}-merge-d{low_d}", rank_domain=low_d)
                held[high_d] = submit(_merge_upper, to_high, held[high_d], e.upper_keeps,
                                      key=f"round{k}-merge-d{high_d}", rank_domain=high_d)
        parts = {d: held[d] for d in ranks}
    else:
        plan = radix_plan(len(frames), height, width, factors)
        for k, groups in enumerate(plan.rounds):
            new = {}
            for g in groups:
                for j, part in enumerate(g.parts):
                    receiver = g.members[j]
                    received = [send(held[m], m, part, f"round{k}-d{m}-to-d{receiver}")
                                for m in g.members if m != receiver]
                    new[receiver] = submit(_merge_group, j, part, held[receiver], *received,
                                           key=f"round{k}-merge-d{receiver}",
                                           rank_domain=receiver)
            held.update(new)
        parts = {d: held[d] for d in ranks}
    first = ranks[0]
    gathered = [send(parts[d], d, None, f"gather-d{d}") for d in ranks[1:]]
    final = submit(_paint, frames[0], parts[first], *gathered, key="paint", rank_domain=0)
    return final, pieces


def local_placement(domains: int, workers: int) -> list[int]:
    """The worker (0 … ``workers`` − 1) that renders each of ``domains`` domains for the
    ``"local"`` schedule: consecutive domains in equal blocks, so that each worker's frames
    composite in domain order before anything is sent."""
    return [i * workers // domains for i in range(domains)]


def submit_local(client, run, frames, where, color_only=False):
    """Local compositing, then direct send of drawn pixels: the frames are cut into runs of
    consecutive domains held by one worker; each run is composited on its worker
    (:func:`~workbench.algo.composite.kernels.composite_frames`), every run but the
    first sends its result's drawn pixels as one encoded piece, and the first run's worker
    composites those pieces in domain order over its own result. W workers send W − 1 pieces.
    Returns the final future (the frame, or its colour when ``color_only``) and the pieces'
    futures."""
    runs: list[list[int]] = []
    for d in range(len(frames)):
        if runs and where[runs[-1][-1]] == where[d]:
            runs[-1].append(d)
        else:
            runs.append([d])

    def submit(fn, *args, key, rank_domain):
        return client.submit(fn, *args, key=f"{run}-local-{key}", pure=False,
                             workers=[where[rank_domain]], allow_other_workers=True)

    first = runs[0]
    own = submit(_composite_run, *(frames[d] for d in first), key=f"run-d{first[0]}",
                 rank_domain=first[0])
    pieces = [submit(_composite_run_piece, *(frames[d] for d in r), key=f"run-d{r[0]}-piece",
                     rank_domain=r[0])
              for r in runs[1:]]
    final = submit(_composite_pieces, color_only, own, *pieces, key="final",
                   rank_domain=first[0])
    return final, pieces


# ------------------------------------------------------------------------ worker-side tasks
def _pack(pixels, region):
    """The encoded piece a rank sends: its drawn pixels (in ``region`` where given)."""
    return (pixels if region is None else pixels.cut(region)).pack()


def _merge_in(own, region, piece):
    """A rank's drawn pixels (cut to ``region`` where given) merged with a piece received from
    a later domain: the lower domain first."""
    from ..algo.composite.active import merge

    return merge(own if region is None else own.cut(region), piece.unpack())


def _merge_upper(piece, own, region):
    """The upper rank of a swap pair: the piece of the lower domain first, then its own part."""
    from ..algo.composite.active import merge

    return merge(piece.unpack(), own.cut(region))


def _merge_group(j: int, part, own, *pieces):
    """Radix-k member ``j`` of its group: the group's parts of ``part`` in member order, its own
    in place ``j``."""
    from ..algo.composite.active import merge_ordered

    items = [p.unpack() for p in pieces]
    items.insert(j, own.cut(part))
    return merge_ordered(items)


def _paint(frame0: Frame, own, *pieces) -> Frame:
    """Rank 0's final frame: every rank's drawn pixels painted over frame 0."""
    from ..algo.composite.active import paint

    return paint(frame0, [own] + [p.unpack() for p in pieces])


def piece_bytes(piece) -> int:
    """An encoded piece's bytes (run on the worker that holds it)."""
    return int(piece.nbytes)


def _cut(frame: Frame, region: Region) -> Frame:
    """A compact copy of the sub-image ``region`` of ``frame`` (what one rank sends)."""
    part = crop(frame, region)
    return Frame(np.ascontiguousarray(part.color), np.ascontiguousarray(part.depth),
                 np.ascontiguousarray(part.triangle))


def _merge(lower: Frame, lower_region: Region | None, upper: Frame,
           upper_region: Region | None) -> Frame:
    """``composite`` of the lower rank's and the upper rank's sub-images of one region, each
    cropped first where a region is given."""
    if lower_region is not None:
        lower = crop(lower, lower_region)
    if upper_region is not None:
        upper = crop(upper, upper_region)
    return composite(lower, upper)


def _gather(height: int, width: int, regions: tuple[Region, ...], *pieces: Frame) -> Frame:
    return assemble(height, width, regions, pieces)


def _composite_run(*frames: Frame) -> Frame:
    """The frames of one worker's run of consecutive domains, composited in order."""
    from ..algo.composite.kernels import composite_frames

    shapes = {f.color.shape for f in frames}
    if len(shapes) > 1:
        raise ValueError(f"domain frames differ in size: {sorted(shapes)} "
                         f"(rows, columns, channels)")
    return composite_frames(frames)


def _composite_run_piece(*frames: Frame):
    """A run's composite as the encoded piece of its drawn pixels (what the run sends)."""
    from ..algo.composite.active import ActivePixels

    return ActivePixels.from_frame(_composite_run(*frames)).pack()


def _composite_pieces(color_only: bool, own: Frame, *pieces):
    """The first run's composite with every later run's drawn pixels composited over it, in
    domain order: the final frame, or its colour."""
    from ..algo.composite.kernels import composite_pixels

    for piece in pieces:
        if (piece.height, piece.width) != own.depth.shape:
            raise ValueError(f"domain frames differ in size: {own.depth.shape} and "
                             f"{(piece.height, piece.width)} (rows, columns)")
    out = composite_pixels(own, [p.unpack() for p in pieces])
    return out.color if color_only else out


def color_of(frame: Frame) -> np.ndarray:
    """A frame's colour (what a display needs of the final frame)."""
    return frame.color
