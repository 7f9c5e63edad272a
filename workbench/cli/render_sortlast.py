"""``workbench render`` on a Dask cluster (es2008's sort-last): ``--domains D`` splits the mesh
into D domains drawn on the workers and composited by depth; ``--write-chunked FOLDER`` writes
them once as a chunked scene (Parquet per domain) and draws from there, each worker loading
only its own domains; a chunked scene's folder given as the scene draws it again, with any
view and image size, without reading the mesh."""

from __future__ import annotations

from pathlib import Path

from .arguments import say_worker_devices
from .render_image import check_drawn, write_image

# style flags of ``render`` that a chunked scene fixes when it is written, and their defaults
FIXED_BY_CHUNKED = {"field": None, "path": None, "option": None, "wireframe": False,
                    "all_faces": False, "strips": "none", "fepatch": "A", "step": 0, "bands": 0,
                    "colormap": None, "crease": 30.0, "samples": 0, "domains": None,
                    "split": "space", "write_chunked": None, "rasterizer": "gl",
                    "generator": "halfspace", "table_size": 10, "subpixel_bits": None}


def is_chunked_scene(name: str) -> bool:
    """Whether ``name`` is a folder holding a chunked scene's manifest."""
    from ..distributed.chunked import MANIFEST

    return (Path(name) / MANIFEST).is_file()


def check_write_chunked(args) -> None:
    """Refuse (ValueError) ``--write-chunked`` without ``--domains`` and the software
    rasterizer, or to a folder that exists (nothing is replaced)."""
    if args.write_chunked is None:
        return
    if args.domains is None or args.rasterizer != "software":
        raise ValueError("--write-chunked writes the domains the software rasterizer draws: "
                         "give --domains D and --rasterizer software as well")
    if Path(args.write_chunked).exists():
        raise ValueError(f"--write-chunked {args.write_chunked}: it exists; give a new folder "
                         f"(nothing is replaced)")


def render_domains(args, mesh, path, camera, size) -> int:
    """``render --domains D``: the mesh split into D domains, drawn on Dask workers by the
    software rasterizer or (``--rasterizer gl``) each worker's own EGL context — or, with
    ``--write-chunked``, written as a chunked scene and drawn from it — composited by depth
    and written like a plain render."""
    from ..distributed.cluster import sweep_cluster
    from ..distributed.domains import split_domains
    from ..distributed.sortlast import ChunkDomains, GLDomains, SoftwareDomains, render_sortlast
    from ..paths import SoftwareRasterizer, prepared_path

    if args.all_faces:
        raise ValueError("--domains loads the scene again on each worker; --all-faces is not "
                         "passed on")
    domains = split_domains(mesh, args.domains, by=args.split)
    gl = args.rasterizer == "gl"
    if args.write_chunked is not None:
        from ..distributed.chunked import write_chunked

        prepared_path(SoftwareRasterizer(path.options), mesh, path, camera=camera)
        folder = write_chunked(path, domains, args.write_chunked)
        print(f"{folder}: chunked scene of {mesh.name}, {args.domains} domains by {args.split}")
        render_domain = ChunkDomains(str(folder.resolve()), camera, size, path.options)
        domains = list(range(len(domains)))
    elif gl:
        render_domain = GLDomains(args.mesh, path.name, path.style, camera, size)
    else:
        render_domain = SoftwareDomains(args.mesh, path.name, path.style, camera, size,
                                        path.options)
    # GLDomains opens its own context in each worker process
    with sweep_cluster(args.workers, args.scheduler, gl=False, devices=args.worker_devices,
                       verbose=args.verbose) as cluster:
        say_worker_devices(cluster.devices)
        color, stats = render_sortlast(cluster.client, render_domain, domains,
                                       method=args.composite, color_only=True)
    check_drawn(color, mesh, camera, size, args.step)
    out = Path(args.output)
    if gl:
        path.scale = path.check_mesh(mesh)  # the colour scale of the bar
    elif args.write_chunked is None:
        prepared_path(SoftwareRasterizer(path.options), mesh, path, camera=camera)
    write_image(out, color, path, args.field, args,
                f"{mesh.name} ({path.name}, {args.domains} domains)", scene=mesh)
    print(f"{out}: {mesh.name}, {len(mesh.triangles)} triangles in {args.domains} domains "
          f"by {args.split} on {stats.workers} workers; {args.composite} compositing "
          f"{stats.composite_s:.3f} s, {stats.bytes_moved / 1e6:.1f} MB moved between workers")
    return 0


def render_chunked_scene(args) -> int:
    """``render FOLDER``: a chunked scene drawn on Dask workers, each loading only its own
    domains, with the camera fitted to the scene's bounds at ``--view``, composited by
    ``--composite`` and written with the colour bar of its field. Refused (ValueError): the
    flags of the path and style, which the scene fixed when it was written, and a view that
    is not orthographic."""
    from ..distributed.chunked import ChunkedScene
    from ..distributed.cluster import sweep_cluster
    from ..distributed.sortlast import ChunkDomains, render_sortlast
    from ..measurement.images import coverage
    from ..paths.drawing import WHITE
    from ..paths.software import SoftwarePath

    given = [name for name, default in FIXED_BY_CHUNKED.items()
             if getattr(args, name, default) != default]
    if given:
        flag = "--" + given[0].replace("_", "-")
        raise ValueError(f"{flag} does not apply to a chunked scene: {args.mesh} fixed its "
                         f"path, field, style and domains when it was written")
    if args.projection != "orthographic":
        raise ValueError("a chunked scene is drawn by the software rasterizer: orthographic "
                         "views only")
    scene = ChunkedScene(args.mesh)
    size = args.size
    camera = SoftwarePath.fit_camera(*scene.bounds(), size, view=args.view, up=args.up)
    render_domain = ChunkDomains(str(Path(args.mesh).resolve()), camera, size)
    with sweep_cluster(args.workers, args.scheduler, gl=False, devices=args.worker_devices,
                       verbose=args.verbose) as cluster:
        say_worker_devices(cluster.devices)
        color, stats = render_sortlast(cluster.client, render_domain, list(range(len(scene))),
                                       method=args.composite, color_only=True)
    if not coverage(color, WHITE).any():
        raise ValueError(f"the {size[0]}x{size[1]} image shows nothing of {scene.name}: no "
                         f"pixel differs from the background")
    out = Path(args.output)
    manifest = scene.manifest
    _write_chunked_image(out, color, manifest, args,
                         f"{scene.name} ({manifest['path']}, {len(scene)} domains)")
    print(f"{out}: {scene.name}, {scene.triangles} triangles in {len(scene)} domains of "
          f"{args.mesh} on {stats.workers} workers; {args.composite} compositing "
          f"{stats.composite_s:.3f} s, {stats.bytes_moved / 1e6:.1f} MB moved between workers")
    return 0


def _write_chunked_image(out: Path, color, manifest: dict, args, title: str) -> None:
    """The image of a chunked scene, with the colour bar of its field and scale (unless
    ``--raw``), stating the triangles drawn in the no-result colour where there are any."""
    from ..output.figures import save_field_figure, save_png
    from ..paths.colormap import no_result_label

    out.parent.mkdir(parents=True, exist_ok=True)
    scale = manifest.get("scale")
    if manifest.get("field") and scale is not None and not args.raw:
        count = sum(int(d.get("no_result", 0)) for d in manifest["domains"])
        save_field_figure(out, color, value_range=tuple(scale["value_range"]),
                          colormap=scale["colormap"], label=manifest["field"], units=args.units,
                          title=title, bands=scale["bands"],
                          no_result=no_result_label(count, "triangle") if count else None)
    else:
        save_png(out, color)
