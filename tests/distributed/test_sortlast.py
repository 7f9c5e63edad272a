"""Sort-last rendering on a real 2-process LocalCluster: domains of a synthetic scene (axis-aligned
rectangles drawn in index order with a strict ``<`` depth test) rendered on the workers and
composited there must give the one-process image exactly; the transfer count must match what
the schedule sends between ranks on different workers."""

from __future__ import annotations

import logging
import sys

import cloudpickle
import dask
import numpy as np
import pytest
from distributed import Client, LocalCluster

from workbench.algo.composite.merge import binary_swap, binary_tree, swap_plan, tree_plan
from workbench.algo.softraster.frame import Frame
from workbench.distributed.sortlast import SortLastStats, render_sortlast
from workbench.scene.generators import semicylinders

# the workers cannot import this test module: ship its functions by value
cloudpickle.register_pickle_by_value(sys.modules[__name__])

WIDTH, HEIGHT, COUNT = 21, 15, 48
_rng = np.random.default_rng(7)
RECTS = np.c_[np.sort(_rng.integers(0, WIDTH + 1, (COUNT, 2)), axis=1),
              np.sort(_rng.integers(0, HEIGHT + 1, (COUNT, 2)), axis=1)]
DEPTH = _rng.choice(np.float32([0.25, 0.5, 0.75]), COUNT)  # many ties across domains
COLOR = _rng.integers(0, 256, (COUNT, 4)).astype(np.uint8)
PIXEL_BYTES = 4 + 4 + 8


def render_rects(indices: np.ndarray) -> Frame:
    """The rectangles ``indices`` drawn in index order with the LESS depth test, on a
    background set by the lowest index (interleaved domains each get their own; where every
    frame is empty the composite must show domain 0's, which is the one-pass render's)."""
    first = int(min(indices, default=0))
    frame = Frame.empty(WIDTH, HEIGHT, background=(40 * first % 256, 200, 100, 255))
    for i in sorted(int(i) for i in indices):
        x0, x1, y0, y1 = RECTS[i]
        window = (slice(y0, y1), slice(x0, x1))
        passed = DEPTH[i] < frame.depth[window]
        frame.color[window][passed] = COLOR[i]
        frame.depth[window][passed] = DEPTH[i]
        frame.triangle[window][passed] = i
    return frame


def render_wrong_size(indices: np.ndarray) -> Frame:
    return Frame.empty(4 + len(indices), 3)


def render_failing(indices: np.ndarray) -> Frame:
    if 1 in indices:
        raise RuntimeError("domain with rectangle 1 cannot be drawn")
    return render_rects(indices)


def interleaved(domains: int) -> list[np.ndarray]:
    return [np.arange(d, COUNT, domains, dtype=np.int64) for d in range(domains)]


@pytest.fixture(scope="module")
def client():
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                               dashboard_address=None, silence_logs=logging.CRITICAL)
    client = Client(cluster)
    client.wait_for_workers(2, timeout=120)  # started processes register in their own time
    yield client
    client.close()
    cluster.close()


def cross_worker_bytes(method: str, domains: int, workers: int = 2) -> int:
    """What the schedule sends between ranks on different workers, domain i rendered on worker
    i mod ``workers`` (the placement :func:`render_sortlast` asks for)."""
    frame_pixels = WIDTH * HEIGHT
    on = [d % workers for d in range(domains)]
    if method == "tree":
        pixels = sum(frame_pixels for pairs in tree_plan(domains).rounds
                     for receiver, sender in pairs if on[receiver] != on[sender])
        return pixels * PIXEL_BYTES
    plan = swap_plan(domains, HEIGHT, WIDTH)
    pixels = sum(frame_pixels for keeper, sender in plan.fold if on[keeper] != on[sender])
    rank_on = [on[d] for d in plan.ranks]
    pixels += sum(e.lower_keeps.pixels + e.upper_keeps.pixels for r in plan.rounds for e in r
                  if rank_on[e.lower] != rank_on[e.upper])
    pixels += sum(region.pixels for region, w in zip(plan.regions[1:], rank_on[1:])
                  if w != rank_on[0])
    return pixels * PIXEL_BYTES


@pytest.mark.parametrize("domains", [1, 2, 4])
@pytest.mark.parametrize("method", ["tree", "swap"])
def test_sortlast_equals_one_process_render(client, method, domains):
    whole = render_rects(np.arange(COUNT))
    parts = interleaved(domains)
    out, stats = render_sortlast(client, render_rects, parts, method=method)
    for name in ("color", "depth", "triangle"):
        got, want = getattr(out, name), getattr(whole, name)
        assert got.dtype == want.dtype
        np.testing.assert_array_equal(got, want, err_msg=name)
    frames = [render_rects(p) for p in parts]

    assert isinstance(stats, SortLastStats)
    assert (stats.domains, stats.method) == (domains, method)
    assert stats.render_s > 0 and stats.composite_s > 0
    schedule = binary_tree if method == "tree" else binary_swap
    assert stats.schedule_bytes == schedule(frames)[1].bytes_moved
    if domains == 1:
        assert stats.workers == 1 and stats.bytes_moved == 0 == stats.schedule_bytes
    else:
        assert stats.workers >= 2
        assert stats.bytes_moved > 0
        # honest count: exactly the schedule's traffic between ranks on different workers
        assert stats.bytes_moved == cross_worker_bytes(method, domains)
    if domains == 2:  # one rank per worker: everything the schedule sends crosses workers
        assert stats.bytes_moved == stats.schedule_bytes


def test_sortlast_three_domains_swap_folds(client):
    whole = render_rects(np.arange(COUNT))
    out, stats = render_sortlast(client, render_rects, interleaved(3), method="swap")
    np.testing.assert_array_equal(out.triangle, whole.triangle)
    np.testing.assert_array_equal(out.color, whole.color)
    assert stats.bytes_moved == cross_worker_bytes("swap", 3)


def test_sortlast_refusals(client):
    with pytest.raises(ValueError, match="unknown compositing method 'ring'"):
        render_sortlast(client, render_rects, interleaved(2), method="ring")
    with pytest.raises(ValueError, match="at least one domain"):
        render_sortlast(client, render_rects, [])
    with pytest.raises(ValueError, match="domain 1 must be a 1-D array"):
        render_sortlast(client, render_rects, [np.arange(3), np.zeros((2, 2), np.int64)])
    with pytest.raises(ValueError, match="differ in size"):
        render_sortlast(client, render_wrong_size, [np.arange(2), np.arange(3)])
    with pytest.raises(RuntimeError, match="rectangle 1 cannot be drawn"):
        render_sortlast(client, render_failing, interleaved(2), method="swap")


@pytest.mark.parametrize("by,domains", [("space", 2), ("space", 4), ("part", 4), ("space", 3)])
@pytest.mark.parametrize("method", ["tree", "swap"])
def test_software_domains_composite_to_the_one_process_image(client, by, domains, method):
    """The es2008 scene split into domains, rendered by the software rasterizer on the
    workers and composited there: the one-process frame, colour, depth and triangle."""
    from workbench.distributed.domains import split_domains
    from workbench.distributed.sortlast import SoftwareDomains
    from workbench.measurement.rows import default_camera
    from workbench.paths import Style

    mesh = semicylinders(4, 12)
    size = (160, 120)
    camera = default_camera(mesh, size, view=(20.0, 10.0), up="y")
    render_domain = SoftwareDomains("semicylinders:12", "pixel_color",
                                    Style(field="distance", bands=6), camera, size)
    assert render_domain.prepared().mesh.n_elements == 8 * 12 * 12  # the built-in has 8 sheets
    everything = render_domain(np.arange(render_domain.prepared().triangles))
    parts = split_domains(render_domain.prepared().mesh, domains, by=by)
    frame, stats = render_sortlast(client, render_domain, parts, method=method)
    assert (everything.triangle >= 0).sum() > 5000
    assert np.array_equal(frame.color, everything.color)
    assert np.array_equal(frame.depth, everything.depth)
    assert np.array_equal(frame.triangle, everything.triangle)
    assert stats.bytes_moved > 0 and stats.workers == 2


@pytest.mark.parametrize("method", ["tree", "swap"])
def test_chunked_domains_composite_to_the_one_process_image(client, tmp_path, method):
    """Each worker loads only its domains of a chunked scene on disk; the composite equals the
    one-process image, and every worker reports its peak memory."""
    from workbench.distributed.bigscene import run_chunked_sortlast, write_semicylinders_chunked

    folder = write_semicylinders_chunked(tmp_path / "scene", 4, 12, bands=6)
    image, run = run_chunked_sortlast(client, folder, (160, 120), method=method,
                                      view=(20.0, 10.0))
    assert run.equal and run.triangles == 4 * 2 * 12 * 12 and run.domains == 4
    assert run.workers == 2 and run.bytes_moved > 0
    assert len(run.peak_mib) == 2 and all(v > 50 for v in run.peak_mib.values())
    assert (image[..., :3] < 250).any(axis=-1).sum() > 5000


def test_chunked_sortlast_on_a_scheduler_and_workers_started_apart(tmp_path):
    """The chunked scene rendered on a scheduler and two workers started as their own
    processes (the command-line tools of distributed), as on a real cluster."""
    from clusters import scheduler_and_workers

    from workbench.distributed.bigscene import run_chunked_sortlast, write_semicylinders_chunked

    folder = write_semicylinders_chunked(tmp_path / "scene", 3, 8, bands=4)
    with scheduler_and_workers(tmp_path) as address, Client(address, timeout=30) as remote:
        remote.wait_for_workers(2, timeout=60)
        _, run = run_chunked_sortlast(remote, folder, (96, 80), method="tree")
    assert run.equal and run.workers == 2 and run.domains == 3


@pytest.mark.parametrize("name,style", [("pixel_color", {"field": "distance", "bands": 6}),
                                        ("gouraud", {}), ("flat", {})])
@pytest.mark.parametrize("method", ["tree", "swap"])
def test_gl_domains_composite_to_the_one_context_image(client, name, style, method):
    """Each worker draws its domains through its own EGL context and reads back colour, depth
    and the winning triangle: the composite is the image one context draws, pixel for pixel."""
    from workbench.distributed.domains import split_domains
    from workbench.distributed.sortlast import GLDomains
    from workbench.measurement.rows import default_camera
    from workbench.paths import Style

    mesh = semicylinders(8, 12)
    size = (160, 120)
    camera = default_camera(mesh, size, view=(20.0, 10.0), up="y")
    render_domain = GLDomains("semicylinders:12", name, Style(**style), camera, size)
    _, path, target, _ = render_domain.prepared()
    target.use()
    target.clear()
    path.draw()  # the whole scene through one context, as render and measure draw it
    reference = target.read()
    frame, stats = render_sortlast(client, render_domain, split_domains(path.mesh, 4),
                                   method=method)
    assert (reference[..., :3] < 250).any(axis=-1).sum() > 5000
    assert np.array_equal(frame.color, reference)
    assert stats.workers == 2 and stats.bytes_moved > 0


def test_gl_domains_refuse_strips_and_wire_frames():
    from workbench.distributed.sortlast import GLDomains
    from workbench.measurement.rows import default_camera
    from workbench.paths import Style

    mesh = semicylinders(8, 4)
    camera = default_camera(mesh, (64, 48))
    for style in (Style(strips="triangle"), Style(wireframe=True)):
        render_domain = GLDomains("semicylinders:4", "gouraud", style, camera, (64, 48))
        with pytest.raises(ValueError, match="domains of a triangle list"):
            render_domain(np.arange(10))


@pytest.mark.parametrize("method,factors,domains", [
    *[(m, None, d) for m in ("active-tree", "active-swap", "radix") for d in (1, 5, 6)],
    ("radix", (2, 3), 6), ("radix", (3, 2), 6)])
def test_active_pixel_schedules_on_the_cluster_equal_the_reduction(client, method, factors,
                                                                    domains):
    """Drawn pixels only, as encoded pieces between the workers: exactly the reduction of the
    frames, with fewer bytes than whole frames."""
    import functools

    from workbench.algo.composite.merge import composite

    parts = interleaved(domains)
    frame, stats = render_sortlast(client, render_rects, parts, method=method, factors=factors)
    expected = functools.reduce(composite, [render_rects(p) for p in parts])
    assert np.array_equal(frame.color, expected.color)
    assert np.array_equal(frame.depth, expected.depth)
    assert np.array_equal(frame.triangle, expected.triangle)
    if domains > 1:
        _, full = render_sortlast(client, render_rects, parts, method="swap")
        assert 0 < stats.schedule_bytes < full.schedule_bytes


@pytest.mark.parametrize("domains", [1, 2, 3, 5, 8])
def test_local_schedule_equals_the_reduction_and_sends_one_piece_per_other_worker(client,
                                                                                 domains):
    """Each worker composites its consecutive domains, then sends its drawn pixels once: the
    reduction of the frames exactly; with two workers one piece moves, and what moved is
    exactly that piece."""
    import functools

    from workbench.algo.composite.active import ActivePixels
    from workbench.algo.composite.merge import composite
    from workbench.distributed.schedules import local_placement

    parts = interleaved(domains)
    frames = [render_rects(p) for p in parts]
    expected = functools.reduce(composite, frames)
    out, stats = render_sortlast(client, render_rects, parts, method="local")
    for name in ("color", "depth", "triangle"):
        np.testing.assert_array_equal(getattr(out, name), getattr(expected, name), err_msg=name)
    color, _ = render_sortlast(client, render_rects, parts, method="local", color_only=True)
    assert color.dtype == np.uint8 and np.array_equal(color, expected.color)

    blocks = local_placement(domains, 2)
    assert blocks == sorted(blocks) and set(blocks) == ({0} if domains == 1 else {0, 1})
    if domains == 1:
        assert stats.workers == 1 and stats.bytes_moved == 0 == stats.schedule_bytes
        return
    second = [f for f, w in zip(frames, blocks) if w == 1]
    piece = ActivePixels.from_frame(functools.reduce(composite, second)).pack()
    assert stats.workers == 2
    assert stats.schedule_bytes == piece.nbytes == stats.bytes_moved


def test_color_only_fetches_the_colour_for_every_method(client):
    whole = render_rects(np.arange(COUNT))
    for method in ("tree", "swap", "active-swap", "radix"):
        color, stats = render_sortlast(client, render_rects, interleaved(4), method=method,
                                       color_only=True)
        assert np.array_equal(color, whole.color), method
        assert stats.schedule_bytes > 0


def test_local_schedule_refuses_frames_of_different_sizes(client):
    with pytest.raises(ValueError, match="differ in size"):
        render_sortlast(client, render_wrong_size, [np.arange(2), np.arange(3)], method="local")
    with pytest.raises(ValueError, match="differ in size"):  # met on one worker
        render_sortlast(client, render_wrong_size, [np.arange(2), np.arange(3), np.arange(4),
                                                    np.arange(5)], method="local")


def test_the_command_line_offers_every_compositing_method():
    from workbench.cli.render import COMPOSITE_METHODS
    from workbench.distributed.sortlast import METHODS

    assert sorted(COMPOSITE_METHODS) == sorted(METHODS)
