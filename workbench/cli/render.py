"""``workbench render``: one scene drawn offscreen, untimed, as every path is drawn
(:func:`workbench.paths.drawing.render`: the image :func:`~workbench.measurement.rows.measure`
reads for the same arguments) and written as a PNG, with a colour bar when a field is shown;
on the headless GL context or the es2008 software rasterizer. ``--domains D`` (sort-last)
splits the mesh into D domains, draws them on Dask workers and composites them by depth; a
chunked scene (a folder written by ``--write-chunked``) is drawn on the workers from its files
(:mod:`.render_sortlast`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import (
    add_cluster_output_arguments,
    add_device_argument,
    image_size,
    key_value,
    view_angles,
)
from .field_options import add_field_arguments, fields_epilog, load_with_fields
from .render_image import check_drawn, check_extent, write_image

# workbench.distributed.sortlast.METHODS, not imported here: it imports Dask
COMPOSITE_METHODS = ("local", "tree", "swap", "active-tree", "active-swap", "radix")


def add_parser(subparsers) -> None:
    """Add ``render`` to the ``workbench`` command's subparsers."""
    from ..paths.registry import paths_for

    mesh_paths = paths_for("mesh")
    spacetime_paths = paths_for("spacetime")
    p = subparsers.add_parser(
        "render", help="render one scene to a PNG",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Render a mesh file (LS-DYNA .k, d3plot, meshio or trimesh formats), a "
                    "built-in scene (car, crash[:S], d3plot, semicylinders[:N], panels[:Q]) or a "
                    "spacetime scene (spacetime:radial[:N], spacetime:bar) offscreen, through the "
                    "one measurement function (untimed); or a chunked scene's folder (written by "
                    "--write-chunked) on Dask workers.",
        epilog="render paths:\n  FE meshes:        " + ", ".join(mesh_paths) +
               "\n  spacetime scenes: " + ", ".join(spacetime_paths) +
               "\nany option of a path's style: --option KEY=VALUE (e.g. "
               "--option edge_overdraw=skirts"
               "\n  --option height_scale=800 for a spacetime path, "
               "--option clip_planes=((1,0,0,0),))\n" + fields_epilog())
    p.add_argument("mesh", help="mesh file, built-in scene name or chunked scene folder")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--field", help="node or element field to colour by (a d3plot's: below)")
    add_field_arguments(p)
    p.add_argument("--path", metavar="PATH",
                   help="render path (default: gouraud; pixel_color or element_color with --field; "
                        "spacetime_pixel on a spacetime scene); listed below")
    p.add_argument("-O", "--option", type=key_value, action="append", metavar="KEY=VALUE",
                   help="any style option of the path (repeatable)")
    p.add_argument("--wireframe", action="store_true", help="overdraw element edges")
    p.add_argument("--show-deleted", choices=("hide", "ghost"), default="hide",
                   help="elements deleted at the step (erosion, a d3plot's element deletion): "
                        "hidden (default), or ghost: drawn translucent (GL only)")
    p.add_argument("--all-faces", action="store_true",
                   help="draw every face of solid elements, not only the boundary faces")
    p.add_argument("--strips", choices=("none", "triangle", "quad"), default="none",
                   help="draw a triangle list (default), meshoptimizer triangle strips or quad "
                        "strips")
    p.add_argument("--fepatch", default="A", metavar="SET",
                   help="fe2003 parameters of the fe_* texture paths: A, B or "
                        "'alpha_g1,d,l_outer,l_inner' in degrees and mm (default A)")
    p.add_argument("--view", type=view_angles, default=(30.0, 25.0), metavar="AZ,EL",
                   help="azimuth and elevation in degrees (default 30,25)")
    p.add_argument("--up", choices=("y", "z"), default="z",
                   help="world axis shown upwards (default z, as in most CAE models)")
    p.add_argument("--size", type=image_size, default=(1000, 800), metavar="WxH",
                   help="image size (default 1000x800)")
    p.add_argument("--projection", choices=("orthographic", "perspective"), default="orthographic")
    p.add_argument("--step", type=int, default=0, help="time step to draw (default 0)")
    p.add_argument("--bands", type=int, default=0, help="number of contour bands (0: smooth)")
    p.add_argument("--colormap", help="matplotlib colormap name (default: the path's own)")
    p.add_argument("--crease", type=float, default=30.0, help="Gouraud crease angle in degrees")
    p.add_argument("--samples", type=int, default=0, help="MSAA samples (0: none)")
    p.add_argument("--units", default="", help="units of the field, for the colour bar label")
    p.add_argument("--raw", action="store_true", help="write the bare image without a colour bar")
    add_device_argument(p)
    _add_software_arguments(p)
    _add_sortlast_arguments(p)
    p.set_defaults(func=cmd_render)


def _add_software_arguments(p) -> None:
    """``--rasterizer`` and the software rasterizer's settings."""
    p.add_argument("--rasterizer", choices=("gl", "software"), default="gl",
                   help="draw through the headless GL context (default) or with the es2008 "
                        "software rasterizer on the CPU (mesh paths, orthographic views)")
    p.add_argument("--generator", choices=("halfspace", "table"), default="halfspace",
                   help="software fragment generator: half-space tests (default) or the span "
                        "look-up table (needs --subpixel-bits 0, its default)")
    p.add_argument("--table-size", type=int, default=10, metavar="S",
                   help="span table size S in pixels (default 10; 15 and 20 as in es2008)")
    p.add_argument("--subpixel-bits", type=int, metavar="B",
                   help="software vertex snapping: 8 as llvmpipe (default), 0 for the table")
    p.add_argument("--threads", type=int, help="software rasterizer threads (default: all cores)")


def _add_sortlast_arguments(p) -> None:
    """``--domains`` and how the domains are made, composited and drawn on Dask."""
    p.add_argument("--domains", type=int, metavar="D",
                   help="sort-last: split the mesh into D domains, draw them with the software "
                        "rasterizer on Dask workers and composite them by depth")
    p.add_argument("--split", choices=("space", "part"), default="space",
                   help="domains by recursive bisection in space (default) or by whole parts")
    p.add_argument("--composite", choices=COMPOSITE_METHODS, default="local",
                   help="compositing schedule: local (default: each worker composites its own "
                        "domains, then sends its drawn pixels once), binary tree or swap of "
                        "whole frames, or active-tree, active-swap, radix (direct send) of "
                        "drawn pixels only")
    p.add_argument("--write-chunked", metavar="FOLDER",
                   help="with --domains and --rasterizer software: write the domains once as a "
                        "chunked scene (Parquet per domain) to the new FOLDER and draw them "
                        "from there, each worker loading only its own; render FOLDER draws "
                        "it again")
    p.add_argument("--workers", type=int,
                   help="local Dask worker processes (default: one per core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="an existing Dask scheduler (tcp://host:port) instead of a local cluster")
    add_cluster_output_arguments(p)


def _check_field_and_step(scene, args) -> None:
    """KeyError for a ``--field`` the mesh does not have, ValueError for a ``--step`` outside
    its steps."""
    fields = [*scene.node_fields, *scene.element_fields]
    if args.field is not None and args.field not in fields:
        known = sorted(fields) or ["(none)"]
        raise KeyError(f"{scene.name} has no field {args.field!r}; fields: {', '.join(known)}")
    if not 0 <= args.step < scene.n_steps:
        raise ValueError(f"{scene.name} has {scene.n_steps} steps; --step {args.step} is outside")


def still_title(mesh, path_name: str, step: int) -> str:
    """The title of a still of ``mesh``: ``NAME (PATH)``, then for a mesh of several states
    the state, its time and where the state deletes elements ``deleted: N``
    (:func:`~workbench.animation.decoration.state_stamp`, as the animated frames)."""
    from ..animation.decoration import state_stamp

    title, deleted = f"{mesh.name} ({path_name})", mesh.n_deleted(step)
    if mesh.n_steps == 1 and not deleted:
        return title
    time = None if mesh.times is None else float(mesh.times[step])
    return f"{title}, {state_stamp(step, time, deleted)}"


def _render_options(args, kind: str) -> dict:
    """The path options of ``workbench render``: the mesh flags (mesh paths only; set on a
    spacetime path they are refused), ``--colormap`` and every ``--option``."""
    flags = {"field": args.field, "step": args.step, "bands": args.bands,
             "wireframe": args.wireframe, "crease_deg": args.crease, "strips": args.strips,
             "fepatch": args.fepatch, "deleted": args.show_deleted}
    if kind == "mesh":
        options = dict(flags)
    else:
        from ..paths import Style

        default = Style()
        given = [k for k, v in flags.items() if v != getattr(default, k)]
        if given:
            raise ValueError(f"--{given[0].replace('_deg', '').replace('_', '-')} applies to the "
                             f"mesh paths, not to a spacetime scene")
        options = {}
    options.update(dict(args.option or ()))
    if args.colormap is not None:
        options["colormap"] = args.colormap
    if "colormap" in options:  # refused by name even where no field is drawn with it
        from ..paths.colormap import colormap_lut

        colormap_lut(options["colormap"])
    return options


def _check_output_and_cluster(args, chunked: bool) -> None:
    """Refuse (ValueError) an output that exists and is not a regular file, one that is not a
    PNG file name, and Dask options without ``--domains`` (or a ``chunked`` scene)."""
    from ..output.targets import output_target

    if output_target(args.output).suffix.lower() != ".png":
        raise ValueError(f"-o {args.output}: render writes a PNG image; give a file name "
                         f"ending in .png")
    if args.domains is None and not chunked:
        given = [f"--{name.replace('_', '-')}" for name in ("scheduler", "workers",
                                                            "worker_devices")
                 if getattr(args, name, None) is not None]
        if given:
            verb = "apply" if len(given) > 1 else "applies"
            raise ValueError(f"{' and '.join(given)} {verb} to sort-last rendering: give "
                             f"--domains D as well")


def _backend(args, path):
    """(backend, path drawn on it): the GL context, or the software rasterizer of
    ``--generator`` … with the path it draws (``--subpixel-bits`` by default 0 for the span
    table, 8 for the half-space tests)."""
    if args.rasterizer != "software":
        from ..gl import create_context

        return create_context(device=args.device), path
    from ..algo.softraster import RasterOptions
    from ..paths import SoftwareRasterizer

    bits = args.subpixel_bits
    if bits is None:
        bits = 0 if args.generator == "table" else 8
    backend = SoftwareRasterizer(RasterOptions(
        generator=args.generator, table_size=args.table_size, subpixel_bits=bits,
        threads=args.threads))
    return backend, backend.path(path)


def cmd_render(args) -> int:
    """Draw the scene, write ``--output``, print what was drawn; 0."""
    from ..paths import as_backend, make_path, path_class, render
    from ..paths.registry import scene_path
    from .render_sortlast import (
        check_write_chunked,
        is_chunked_scene,
        render_chunked_scene,
        render_domains,
    )

    chunked = is_chunked_scene(args.mesh)
    _check_output_and_cluster(args, chunked)
    if chunked:
        return render_chunked_scene(args)
    check_write_chunked(args)
    scene, args.field = load_with_fields(args, all_faces=args.all_faces)
    is_mesh = scene.kind == "mesh"
    if is_mesh:
        _check_field_and_step(scene, args)
    path_name = scene_path(scene, args.path, args.field, source=args.mesh)
    kind = "mesh" if "mesh" in path_class(path_name).scene_kinds else "spacetime"
    path = make_path(path_name, **_render_options(args, kind))
    backend, path = _backend(args, path)
    size = args.size
    camera = path.default_camera(scene, size, view=args.view, projection=args.projection,
                                 up=args.up, style=path.style)
    check_extent(scene, args.step)
    if args.domains is not None:
        return render_domains(args, scene, path, camera, size)
    image = render(backend, scene, path, camera=camera, size=size, samples=args.samples)
    check_drawn(image, scene, camera, size, args.step)
    out = Path(args.output)
    field = args.field if args.field is not None else getattr(path.style, "field", None)
    write_image(out, image, path, field if is_mesh else None, args,
                still_title(scene, path_name, args.step) if is_mesh
                else f"{scene.name} ({path_name})", scene=scene if is_mesh else None)
    strips = f", {path.strips} strip{'s' * (path.strips != 1)}" if path.strips else ""
    print(f"{out}: {scene.name}, {path.triangles} triangles, {path.vertices_sent} "
          f"vertices sent{strips}, path {path_name}"
          + (f", {as_backend(backend).renderer_of(path)}" if args.rasterizer == "software"
             else ""))
    return 0
