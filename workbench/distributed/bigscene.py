"""Scenes larger than one process: the es2008 benchmark written sheet by sheet as a chunked scene
(:mod:`workbench.distributed.chunked`), and its sort-last run on a Dask cluster in which each worker
loads only its own domains (es2008 renders 200 M degrees of freedom off-line this way).

:func:`write_semicylinders_chunked` writes ``sheets`` semi-cylindrical sheets of n×n quads
(2 n² triangles each; ``sheets=8, n=2500`` is 100 M triangles) one sheet at a time: a sheet is
generated, drawn by a software mesh path with the whole scene's colour scale and written as one
domain, so the writer never holds more than one sheet. The sheets share no node, so each
sheet's vertices, normals and values equal those of the whole scene; global triangle indices
run sheet by sheet, as in the whole scene's triangle list.

:func:`run_chunked_sortlast` renders a chunked scene on a cluster (:class:`ChunkDomains`) and, for
the reference, in this process domain by domain
(:func:`~workbench.distributed.chunked.render_chunked`), and reports the times, the bytes the
compositing moved, each worker's peak memory and whether the images are equal.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .chunked import ChunkedScene, ChunkWriter, render_chunked
from .sortlast import ChunkDomains, domain_workers, peak_memory_mib, render_sortlast


def semicylinder_sheet(k: int, n: int, radius: float = 100.0, spacing: float = 10.0):
    """Sheet ``k`` of :func:`~workbench.scene.generators.semicylinders` (n×n quads) as a mesh
    of its own: the same nodes, quads and ``"distance"`` field as that sheet of the whole
    scene, part id ``k``."""
    from ..scene.generators import semicylinders
    from ..scene.mesh import FEMesh

    sheet = semicylinders(1, n, radius, spacing)
    nodes = sheet.nodes.copy()
    nodes[:, 2] += -spacing * np.float64(k)  # the whole scene's offset, in the same arithmetic
    return FEMesh(nodes=nodes, elements=sheet.elements,
                  parts=np.full(sheet.n_elements, k, np.int32),
                  node_fields={"distance": sheet.node_fields["distance"]},
                  part_names={k: f"sheet {k}"}, name=f"semicylinders_sheet{k}_{n}x{n}",
                  units="mm")


def write_semicylinders_chunked(folder: str | Path, sheets: int, n: int, path: str = "pixel_color",
                                bands: int = 10, replace: bool = False,
                                progress=None) -> Path:
    """Write the es2008 scene of ``sheets`` sheets of n×n quads, drawn by software mesh path
    ``path`` (field ``"distance"`` in ``bands`` bands where the path draws a field), to
    ``folder`` as a chunked scene of one domain per sheet; returns the folder. ``progress``
    (a callable of the sheet index) is called after each sheet. Refused (ValueError): a path
    that draws element fields (the scene has a node field only)."""
    from ..paths import SoftwareRasterizer, Style, prepared_path
    from ..paths.registry import path_class
    from ..paths.software import SoftwarePath

    first = semicylinder_sheet(0, n)
    lo, hi = first.field_range("distance")
    # the paths that draw a node field draw "distance" on the whole scene's range
    style = (Style(field="distance", bands=bands, value_range=(lo, hi))
             if getattr(path_class(path), "field_per", None) == "node" else None)
    with ChunkWriter(folder, replace, name=f"semicylinders_{sheets}x{n}x{n}") as writer:
        for k in range(sheets):
            mesh = first if k == 0 else semicylinder_sheet(k, n)
            first = None
            drawn = prepared_path(SoftwareRasterizer(), mesh, SoftwarePath(path, style),
                                  camera=SoftwarePath.default_camera(mesh, (64, 64)))
            writer.add(drawn, first_id=k * 2 * n * n)
            drawn.release()
            del mesh
            if progress is not None:
                progress(k)
    return Path(folder)


@dataclass
class ChunkedRun:
    """One sort-last run of a chunked scene: triangles, domains, workers; ``render_s`` and
    ``composite_s`` on the cluster (:class:`~workbench.distributed.sortlast.SortLastStats`),
    ``bytes_moved``; ``peak_mib`` per worker (resident set, MiB), the largest domain's
    in-memory size ``domain_mib`` and each worker's share ``share_mib`` (the in-memory size of
    the domains it is given, MiB); ``reference_s`` the one-process render; ``equal`` whether
    colour, depth and triangle indices equal the reference."""

    triangles: int
    domains: int
    workers: int
    method: str
    render_s: float
    composite_s: float
    bytes_moved: int
    peak_mib: dict[str, float]
    domain_mib: float
    share_mib: dict[str, float]
    reference_s: float
    equal: bool

    @property
    def triangles_per_s(self) -> float:
        """Triangles drawn per second of cluster render time."""
        return self.triangles / self.render_s if self.render_s else float("nan")


def run_chunked_sortlast(client, folder: str | Path, size: tuple[int, int] = (1000, 1000),
                         method: str = "swap", view: tuple[float, float] = (0.0, 0.0),
                         options=None, reference: bool = True) -> tuple[np.ndarray, ChunkedRun]:
    """Render the chunked scene in ``folder`` on ``client``'s cluster (every worker loads only
    its domains) with the camera fitted to the scene's bounds at ``view``, composite by
    ``method``, and (with ``reference``) render it in this process domain by domain for the
    reference; (the composited RGBA image, the run)."""
    from ..paths.software import SoftwarePath

    scene = ChunkedScene(folder)
    camera = SoftwarePath.fit_camera(*scene.bounds(), size, view=view, up="y")
    frame, stats = render_sortlast(client, ChunkDomains(str(folder), camera, tuple(size),
                                                        options),
                                   list(range(len(scene))), method=method)
    peaks = peak_memory_mib(client)
    sizes = [scene.domain_nbytes(i) / 2**20 for i in range(len(scene))]
    domain_mib = max(sizes)
    addresses = sorted(peaks)  # render_sortlast's placement, by worker rank in address order
    on = domain_workers(method, len(sizes), len(addresses))
    share_mib = {a: sum(size for size, w in zip(sizes, on) if w == k)
                 for k, a in enumerate(addresses)}
    equal, reference_s = True, float("nan")
    if reference:
        start = time.perf_counter()
        expected = render_chunked(scene, camera, size, options)
        reference_s = time.perf_counter() - start
        equal = (np.array_equal(frame.color, expected.color)
                 and np.array_equal(frame.depth, expected.depth)
                 and np.array_equal(frame.triangle, expected.triangle))
    return frame.color, ChunkedRun(scene.triangles, len(scene), stats.workers, method,
                                   stats.render_s, stats.composite_s, stats.bytes_moved, peaks,
                                   domain_mib, share_mib, reference_s, equal)
