"""``workbench render``: one scene drawn offscreen through the one measurement function
(untimed) and written as a PNG, with a colour bar when a field is shown; on the headless GL
context or the es2008 software rasterizer. ``--domains D`` (sort-last) splits the mesh into D
domains, draws them with the software rasterizer on Dask workers and composites them by depth.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import image_size, key_value, view_angles

# workbench.experiment.sortlast.METHODS, not imported here: it imports Dask
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
                    "built-in scene (car, d3plot, semicylinders[:N], panels[:Q]) or a spacetime "
                    "scene (spacetime:radial[:N], spacetime:bar) offscreen, through the one "
                    "measurement function (untimed).",
        epilog="render paths:\n  FE meshes:        " + ", ".join(mesh_paths) +
               "\n  spacetime scenes: " + ", ".join(spacetime_paths) +
               "\nany option of a path's style: --option KEY=VALUE (e.g. "
               "--option edge_overdraw=skirts"
               "\n  --option height_scale=800 for a spacetime path, "
               "--option clip_planes=((1,0,0,0),))")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--field", help="node or element field to colour by")
    p.add_argument("--path", metavar="PATH",
                   help="render path (default: gouraud; pixel_color or element_color with --field; "
                        "spacetime_pixel on a spacetime scene); listed below")
    p.add_argument("-O", "--option", type=key_value, action="append", metavar="KEY=VALUE",
                   help="any style option of the path (repeatable)")
    p.add_argument("--wireframe", action="store_true", help="overdraw element edges")
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
    p.add_argument("--workers", type=int,
                   help="local Dask worker processes (default: one per core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="an existing Dask scheduler (tcp://host:port) instead of a local cluster")


def _check_field_and_step(scene, args) -> None:
    """KeyError for a ``--field`` the mesh does not have, ValueError for a ``--step`` outside
    its steps."""
    fields = [*scene.node_fields, *scene.element_fields]
    if args.field is not None and args.field not in fields:
        known = sorted(fields) or ["(none)"]
        raise KeyError(f"{scene.name} has no field {args.field!r}; fields: {', '.join(known)}")
    if not 0 <= args.step < scene.n_steps:
        raise ValueError(f"{scene.name} has {scene.n_steps} steps; --step {args.step} is outside")


def _render_options(args, kind: str) -> dict:
    """The path options of ``workbench render``: the mesh flags (mesh paths only; set on a
    spacetime path they are refused), ``--colormap`` and every ``--option``."""
    flags = {"field": args.field, "step": args.step, "bands": args.bands,
             "wireframe": args.wireframe, "crease_deg": args.crease, "strips": args.strips,
             "fepatch": args.fepatch}
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


def _check_output_and_cluster(args) -> None:
    """Refuse (ValueError) an output that exists and is not a regular file, one that is not a
    PNG file name, and Dask options without ``--domains``."""
    from ..experiment.targets import output_target

    if output_target(args.output).suffix.lower() != ".png":
        raise ValueError(f"-o {args.output}: render writes a PNG image; give a file name "
                         f"ending in .png")
    if args.domains is None:
        given = [f"--{name}" for name in ("scheduler", "workers")
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

        return create_context(), path
    from ..algo.softraster import RasterOptions
    from ..paths import SoftwareRasterizer

    bits = args.subpixel_bits
    if bits is None:
        bits = 0 if args.generator == "table" else 8
    backend = SoftwareRasterizer(RasterOptions(
        generator=args.generator, table_size=args.table_size, subpixel_bits=bits,
        threads=args.threads))
    return backend, backend.path(path)


def _write_image(out: Path, image, path, field: str | None, args, title: str) -> None:
    """``image`` as a PNG at ``out``: with a colour bar of ``field`` when there is one and a
    colour scale, unless ``--raw``."""
    from ..experiment.figures import save_field_figure, save_png

    out.parent.mkdir(parents=True, exist_ok=True)
    scale = getattr(path, "scale", None)
    if field is not None and not args.raw and scale is not None:
        save_field_figure(out, image, value_range=scale.value_range,
                          colormap=path.style.colormap, label=field, units=args.units,
                          title=title, bands=args.bands)
    else:
        save_png(out, image)


# the widest model drawn (model units): beyond it the float32 coordinates relative to its
# centre and the matrices that scale them near float32's limit, 3.4e38 (1e38 draws nothing)
FLOAT32_EXTENT = 0.1 * 3.4028235e38


def _extent_of(mesh, step: int) -> tuple[float, str]:
    """(extent, words): the largest side of the box of ``mesh``'s referenced nodes at ``step``
    (model units), and words naming it with the node farthest from the nodes' median (the
    stray node that makes the box that wide)."""
    import numpy as np

    nodes = mesh.coordinates(step)
    used = mesh.used_nodes()
    points = nodes[used]
    extent = float(np.max(points.max(axis=0) - points.min(axis=0)))
    distance = np.linalg.norm(points - np.median(points, axis=0), axis=1)
    far = int(used[np.argmax(distance)])
    label = (f"node {int(mesh.node_ids[far])}" if mesh.node_ids is not None
             else f"node index {far}")
    x, y, z = nodes[far]
    return extent, (f"its extent of {extent:.3g} {mesh.units} ({label} at ({x:.3g}, {y:.3g}, "
                    f"{z:.3g}) lies {distance.max():.3g} {mesh.units} from the median node)")


def _check_extent(scene, step: int) -> None:
    """Refuse (ValueError) an FE mesh wider than :data:`FLOAT32_EXTENT`: its coordinates
    relative to its centre, and the matrices that scale them, overflow float32 and draw
    nothing."""
    if scene.kind != "mesh":
        return
    extent, words = _extent_of(scene, step)
    if extent > FLOAT32_EXTENT:
        raise ValueError(f"{scene.name}: {words} is beyond what float32 coordinates relative "
                         f"to its centre can draw (at most {FLOAT32_EXTENT:.3g})")


def _check_drawn(image, scene, camera, size: tuple[int, int], step: int) -> None:
    """Refuse (ValueError, one line) an image in which no pixel differs from the white
    background: nothing of the scene was drawn, so no image is written. For an FE mesh whose
    elements all project thinner than a pixel the line says so, with the model's extent and
    its farthest node: the camera is fitted to the box of every referenced node, so one node
    far out (1e20 mm among millimetre-sized elements) makes the view that wide."""
    import numpy as np

    from ..experiment.compare import coverage
    from ..experiment.measure import WHITE

    if coverage(image, WHITE).any():
        return
    why = ""
    if scene.kind == "mesh":
        win = camera.project(scene.coordinates(step), size)[:, :2]
        tri = scene.triangles
        a, b, c = win[tri[:, 0]], win[tri[:, 1]], win[tri[:, 2]]
        ab, ac, bc = b - a, c - a, c - b
        area2 = np.abs(ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
        longest = np.max([np.hypot(*e.T) for e in (ab, ac, bc)], axis=0)
        # each triangle's width across its longest edge, in pixels
        widths = np.divide(area2, longest, out=np.zeros_like(area2), where=longest > 0)
        if widths.max() < 1.0:
            why = (f"; every element is thinner than a pixel (the widest {widths.max():.2g} "
                   f"px) in the view fitted to {_extent_of(scene, step)[1]}")
    raise ValueError(f"the {size[0]}x{size[1]} image shows nothing of {scene.name}: no pixel "
                     f"differs from the background{why}")


def cmd_render(args) -> int:
    """Draw the scene, write ``--output``, print what was drawn; 0."""
    from ..experiment.measure import measure
    from ..paths import make_path, path_class
    from ..paths.registry import scene_path
    from ..scene.builtin import load_scene

    _check_output_and_cluster(args)
    scene = load_scene(args.mesh, all_faces=args.all_faces)
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
    _check_extent(scene, args.step)
    if args.domains is not None:
        return _render_sortlast(args, scene, path, camera, size)
    result = measure(backend, scene, path, camera=camera, size=size, samples=args.samples,
                     timed=False)
    _check_drawn(result.image, scene, camera, size, args.step)
    out = Path(args.output)
    field = args.field if args.field is not None else getattr(path.style, "field", None)
    _write_image(out, result.image, path, field if is_mesh else None, args,
                 f"{scene.name} ({path_name})")
    strips = f", {path.strips} strip{'s' * (path.strips != 1)}" if path.strips else ""
    print(f"{out}: {result.row['scene']}, {path.triangles} triangles, {path.vertices_sent} "
          f"vertices sent{strips}, path {path_name}"
          + (f", {result.row['renderer']}" if args.rasterizer == "software" else ""))
    return 0


def _render_sortlast(args, mesh, path, camera, size) -> int:
    """``render --domains D``: the mesh split into D domains, drawn on Dask workers by the
    software rasterizer or (``--rasterizer gl``) each worker's own EGL context, composited by
    depth (sort-last) and written like a plain render."""
    from ..experiment.cluster import sweep_cluster
    from ..experiment.sortlast import GLDomains, SoftwareDomains, render_sortlast
    from ..scene.domains import split_domains

    if args.all_faces:
        raise ValueError("--domains loads the scene again on each worker; --all-faces is not "
                         "passed on")
    domains = split_domains(mesh, args.domains, by=args.split)
    gl = args.rasterizer == "gl"
    if gl:
        render_domain = GLDomains(args.mesh, path.name, path.style, camera, size)
    else:
        render_domain = SoftwareDomains(args.mesh, path.name, path.style, camera, size,
                                        path.options)
    # GLDomains opens its own context in each worker process
    with sweep_cluster(args.workers, args.scheduler, gl=False) as cluster:
        color, stats = render_sortlast(cluster.client, render_domain, domains,
                                       method=args.composite, color_only=True)
    _check_drawn(color, mesh, camera, size, args.step)
    out = Path(args.output)
    if gl:
        path.scale = path.check_mesh(mesh)  # the colour scale of the bar
    else:
        path.prepare(None, mesh, camera)
    _write_image(out, color, path, args.field, args,
                 f"{mesh.name} ({path.name}, {args.domains} domains)")
    print(f"{out}: {mesh.name}, {len(mesh.triangles)} triangles in {args.domains} domains "
          f"by {args.split} on {stats.workers} workers; {args.composite} compositing "
          f"{stats.composite_s:.3f} s, {stats.bytes_moved / 1e6:.1f} MB moved between workers")
    return 0
