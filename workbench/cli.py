"""The ``workbench`` command: info, render, hausdorff, simplify, list, run, reproduce, sweep
and stress.

Bad input (an unreadable or malformed mesh file, an empty mesh, a missing OpenGL driver, an
unknown name) ends with a one-line message on stderr and exit status 2, never a traceback (set WORKBENCH_DEBUG=1 to see one).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import warnings
from importlib import metadata
from pathlib import Path

EXIT_BAD_INPUT = 2
VERSIONED = ("numpy", "scipy", "moderngl", "trimesh", "meshio", "lasso-python", "libigl", "pymeshlab",
             "open3d", "pyrender", "meshoptimizer", "scikit-image", "matplotlib")


def _pair(text: str, sep: str, kind=float) -> tuple:
    """Two finite numbers separated by ``sep``."""
    try:
        a, b = text.lower().split(sep)
        pair = kind(a), kind(b)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers separated by {sep!r}, got {text!r}")
    if not all(math.isfinite(v) for v in pair):
        raise argparse.ArgumentTypeError(f"expected two finite numbers, got {text!r}")
    return pair


def _size(text: str) -> tuple[int, int]:
    w, h = _pair(text, "x", int)
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    return w, h


def cmd_info(args) -> int:
    from .data import shared_data_dir
    from .gl import create_context, renderer
    from .gl.context import gl_version

    ctx = create_context()
    print(f"workbench {metadata.version('workbench')}")
    print(f"renderer  {renderer(ctx)}")
    print(f"OpenGL    {gl_version(ctx)}")
    print(f"python    {sys.version.split()[0]}")
    for name in VERSIONED:
        try:
            print(f"{name:<13} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            print(f"{name:<13} (not installed)")
    data = shared_data_dir()
    print(f"shared data {data if data else '(not found: set WORKBENCH_DATA)'}")
    return 0


def _option(text: str) -> tuple[str, object]:
    """``KEY=VALUE`` of ``--option``: VALUE read as a Python literal (number, tuple, bool), else
    kept as a string."""
    import ast

    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    try:
        return key.strip(), ast.literal_eval(value)
    except (ValueError, SyntaxError):
        return key.strip(), value


def _render_options(args, kind: str) -> dict:
    """The path options of ``workbench render``: the mesh flags (mesh paths only; set on a
    spacetime path they are refused), ``--colormap`` and every ``--option``."""
    flags = {"field": args.field, "step": args.step, "bands": args.bands,
             "wireframe": args.wireframe, "crease_deg": args.crease, "strips": args.strips,
             "fepatch": args.fepatch}
    if kind == "mesh":
        options = dict(flags)
    else:
        from .paths import Style

        default = Style()
        given = [k for k, v in flags.items() if v != getattr(default, k)]
        if given:
            raise ValueError(f"--{given[0].replace('_deg', '').replace('_', '-')} applies to the "
                             f"mesh paths, not to a spacetime scene")
        options = {}
    if args.colormap is not None:
        options["colormap"] = args.colormap
    options.update(dict(args.option or ()))
    return options


def cmd_render(args) -> int:
    from .experiment.figures import save_field_figure, save_png
    from .experiment.measure import measure
    from .gl import create_context
    from .paths import default_path, make_path, path_class
    from .scene.builtin import load_scene

    scene = load_scene(args.mesh, all_faces=args.all_faces)
    is_mesh = scene.kind == "mesh"
    if is_mesh:
        fields = [*scene.node_fields, *scene.element_fields]
        if args.field is not None and args.field not in fields:
            known = sorted(fields) or ["(none)"]
            raise KeyError(f"{scene.name} has no field {args.field!r}; fields: {', '.join(known)}")
        if not 0 <= args.step < scene.n_steps:
            raise ValueError(f"{scene.name} has {scene.n_steps} steps; --step {args.step} is outside")
    path_name = args.path or default_path(scene, args.field)
    kinds = path_class(path_name).scene_kinds
    if scene.kind not in kinds:
        raise ValueError(f"path {path_name!r} draws {' or '.join(sorted(kinds))} scenes; "
                         f"{args.mesh!r} is {'an FE mesh' if is_mesh else 'a spacetime scene'}")
    path = make_path(path_name, **_render_options(args, "mesh" if "mesh" in kinds else "spacetime"))
    if args.rasterizer == "software":
        from .algo.softraster import RasterOptions
        from .paths import SoftwareRasterizer

        bits = args.subpixel_bits
        if bits is None:
            bits = 0 if args.generator == "table" else 8
        backend = SoftwareRasterizer(RasterOptions(
            generator=args.generator, table_size=args.table_size, subpixel_bits=bits,
            threads=args.threads))
        path = backend.path(path)
    else:
        backend = create_context()
    size = args.size
    camera = path.default_camera(scene, size, view=args.view, projection=args.projection,
                                 up=args.up, style=path.style)
    if args.domains is not None:
        return _render_sortlast(args, scene, path, camera, size)
    result = measure(backend, scene, path, camera=camera, size=size, samples=args.samples,
                     timed=False)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    scale = getattr(path, "scale", None)
    field = args.field if args.field is not None else getattr(path.style, "field", None)
    if is_mesh and field is not None and not args.raw and scale is not None:
        save_field_figure(out, result.image, value_range=scale.value_range,
                          colormap=path.style.colormap, label=field, units=args.units,
                          title=f"{scene.name} ({path_name})", bands=args.bands)
    else:
        save_png(out, result.image)
    strips = f", {path.strips} strip{'s' * (path.strips != 1)}" if path.strips else ""
    print(f"{out}: {result.row['scene']}, {path.triangles} triangles, {path.vertices_sent} "
          f"vertices sent{strips}, path {path_name}"
          + (f", {result.row['renderer']}" if args.rasterizer == "software" else ""))
    return 0


def _render_sortlast(args, mesh, path, camera, size) -> int:
    """``render --domains D``: the mesh split into D domains, drawn by the software rasterizer
    on Dask workers and composited by depth (sort-last), written like a plain render."""
    from .experiment.cluster import sweep_cluster
    from .experiment.figures import save_field_figure, save_png
    from .experiment.sortlast import SoftwareDomains, render_sortlast
    from .scene.domains import split_domains

    if args.rasterizer != "software":
        raise ValueError("--domains draws the domains with the software rasterizer: add "
                         "--rasterizer software")
    if args.all_faces:
        raise ValueError("--domains loads the scene again on each worker; --all-faces is not "
                         "passed on")
    domains = split_domains(mesh, args.domains, by=args.split)
    render_domain = SoftwareDomains(args.mesh, path.name, path.style, camera, size, path.options)
    with sweep_cluster(args.workers, args.scheduler, gl=False) as cluster:
        frame, stats = render_sortlast(cluster.client, render_domain, domains,
                                       method=args.composite)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    path.prepare(None, mesh, camera)  # the colour scale of the bar
    scale = getattr(path, "scale", None)
    if args.field is not None and not args.raw and scale is not None:
        save_field_figure(out, frame.color, value_range=scale.value_range,
                          colormap=path.style.colormap, label=args.field, units=args.units,
                          title=f"{mesh.name} ({path.name}, {args.domains} domains)",
                          bands=args.bands)
    else:
        save_png(out, frame.color)
    print(f"{out}: {mesh.name}, {len(mesh.triangles)} triangles in {args.domains} domains "
          f"by {args.split} on {stats.workers} workers; {args.composite} compositing "
          f"{stats.composite_s:.3f} s, {stats.bytes_moved / 1e6:.1f} MB moved between workers")
    return 0


def cmd_hausdorff(args) -> int:
    from .algo.hausdorff import hausdorff
    from .scene.builtin import load_scene

    a, b = load_scene(args.mesh_a), load_scene(args.mesh_b)
    va, fa = a.coordinates(args.step), a.triangles
    vb, fb = b.coordinates(args.step if args.step < b.n_steps else 0), b.triangles
    lo, hi = va[a.used_nodes()].min(axis=0), va[a.used_nodes()].max(axis=0)
    diagonal = float(((hi - lo) ** 2).sum() ** 0.5)
    width = args.width / 100.0 * diagonal
    h = hausdorff(va, fa, vb, fb, one_sided=not args.symmetric, tol=width)
    kind = "symmetric" if args.symmetric else "one-sided, A to B"
    units = a.units or "model units"
    print(f"Hausdorff distance ({kind}): {h.lower:.9g} <= H <= {h.upper:.9g} {units} "
          f"(width {h.width:.3g}, {'reached' if h.tol_reached else 'NOT reached'}: "
          f"{args.width:g} % of A's diagonal {diagonal:.6g})")
    print(f"  {100 * h.upper / diagonal:.6g} % of the diagonal; mean {h.mean:.6g}, "
          f"RMS {h.rms:.6g} (sample estimates); {h.seconds:.2f} s")
    p, q = h.location
    on, other = ("A", "B") if h.forward is None or h.location is h.forward.location else ("B", "A")
    print(f"  attained at {on} ({p[0]:.6g}, {p[1]:.6g}, {p[2]:.6g}), nearest {other} point "
          f"({q[0]:.6g}, {q[1]:.6g}, {q[2]:.6g})")
    return 0


def cmd_simplify(args) -> int:
    import numpy as np
    import trimesh

    from .algo.simplify import hausdorff_decimate
    from .scene.builtin import load_scene

    mesh = load_scene(args.mesh)
    tri = mesh.triangulation
    d = hausdorff_decimate(mesh.nodes, tri.triangles, args.tol / 100.0, relative=True,
                           parts=mesh.parts[tri.element_of])
    print(f"{mesh.name}: {len(tri.triangles)} -> {len(d.triangles)} triangles in "
          f"{d.seconds:.2f} s; one-sided Hausdorff certified <= {args.tol:g} % of each part's "
          f"bounding-sphere diameter ({d.tol_abs.min():.4g} to {d.tol_abs.max():.4g} "
          f"{mesh.units}); {d.collapses} collapses")
    if args.output:
        used = np.unique(d.triangles)
        remap = np.full(len(mesh.nodes), -1, np.int64)
        remap[used] = np.arange(len(used))
        out = Path(args.output)
        out.parent.mkdir(parents=True, exist_ok=True)
        data = trimesh.Trimesh(mesh.nodes[used], remap[d.triangles], process=False).export(
            file_type=out.suffix.lstrip(".") or "ply")
        from .experiment.tables import atomic_write_bytes, atomic_write_text

        if isinstance(data, str):
            atomic_write_text(out, data)
        else:
            atomic_write_bytes(out, data)
        print(f"  written to {out}")
    return 0


def cmd_list(args) -> int:
    from .experiment.registry import discover

    for name, exp in sorted(discover().items()):
        print(f"{name:<28} {exp.description}")
    return 0


def cmd_run(args) -> int:
    from .experiment.registry import discover, run_experiment

    discover()
    rows, out_dir = run_experiment(args.experiment, figures_root=Path(args.figures), quick=args.quick,
                                   progress=lambda msg: print(f"  {msg}", flush=True))
    print(f"{args.experiment}: {len(rows)} rows -> {out_dir}")
    return 0


def cmd_reproduce(args) -> int:
    from tqdm import tqdm

    from .experiment.registry import discover, run_experiment

    names = sorted(discover())
    bar = tqdm(names, desc="reproduce", unit="experiment")
    for name in bar:
        bar.set_postfix_str(name)
        rows, out_dir = run_experiment(name, figures_root=Path(args.figures), quick=args.quick,
                                       progress=lambda msg: bar.write(f"  {name}: {msg}"))
        bar.write(f"{name}: {len(rows)} rows -> {out_dir}")
    return 0


class _Parser(argparse.ArgumentParser):
    """An argument parser whose refusals are one line (``PROG: error: …``) and exit status 2,
    without the usage block (``--help`` shows it)."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="workbench",
        description="Comparable OpenGL render paths for finite-element visualization, measured "
                    "side by side for run time and error on a headless (EGL) context.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {metadata.version('workbench')}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("info", help="renderer, OpenGL version, library versions, shared data")
    p.set_defaults(func=cmd_info)

    from .paths.registry import paths_for

    mesh_paths = paths_for("mesh")
    spacetime_paths = paths_for("spacetime")
    p = sub.add_parser(
        "render", help="render one scene to a PNG",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Render a mesh file (LS-DYNA .k, d3plot, meshio or trimesh formats), a built-in "
                    "scene (car, d3plot, semicylinders[:N], panels[:Q]) or a spacetime scene "
                    "(spacetime:radial[:N], spacetime:bar) offscreen, through the one measurement "
                    "function (untimed).",
        epilog="render paths:\n  FE meshes:        " + ", ".join(mesh_paths) +
               "\n  spacetime scenes: " + ", ".join(spacetime_paths) +
               "\nany option of a path's style: --option KEY=VALUE (e.g. --option edge_overdraw=skirts"
               "\n  --option height_scale=800 for a spacetime path, --option clip_planes=((1,0,0,0),))")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--field", help="node or element field to colour by")
    p.add_argument("--path", metavar="PATH",
                   help="render path (default: gouraud; pixel_color or element_color with --field; "
                        "spacetime_pixel on a spacetime scene); listed below")
    p.add_argument("-O", "--option", type=_option, action="append", metavar="KEY=VALUE",
                   help="any style option of the path (repeatable)")
    p.add_argument("--wireframe", action="store_true", help="overdraw element edges")
    p.add_argument("--all-faces", action="store_true",
                   help="draw every face of solid elements, not only the boundary faces")
    p.add_argument("--strips", choices=("none", "triangle", "quad"), default="none",
                   help="draw a triangle list (default), meshoptimizer triangle strips or quad strips")
    p.add_argument("--fepatch", default="A", metavar="SET",
                   help="fe2003 parameters of the fe_* texture paths: A, B or "
                        "'alpha_g1,d,l_outer,l_inner' in degrees and mm (default A)")
    p.add_argument("--view", type=lambda s: _pair(s, ","), default=(30.0, 25.0), metavar="AZ,EL",
                   help="azimuth and elevation in degrees (default 30,25)")
    p.add_argument("--up", choices=("y", "z"), default="z",
                   help="world axis shown upwards (default z, as in most CAE models)")
    p.add_argument("--size", type=_size, default=(1000, 800), metavar="WxH", help="image size (default 1000x800)")
    p.add_argument("--projection", choices=("orthographic", "perspective"), default="orthographic")
    p.add_argument("--step", type=int, default=0, help="time step to draw (default 0)")
    p.add_argument("--bands", type=int, default=0, help="number of contour bands (0: smooth)")
    p.add_argument("--colormap", help="matplotlib colormap name (default: the path's own)")
    p.add_argument("--crease", type=float, default=30.0, help="Gouraud crease angle in degrees")
    p.add_argument("--samples", type=int, default=0, help="MSAA samples (0: none)")
    p.add_argument("--units", default="", help="units of the field, for the colour bar label")
    p.add_argument("--raw", action="store_true", help="write the bare image without a colour bar")
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
    p.add_argument("--domains", type=int, metavar="D",
                   help="sort-last: split the mesh into D domains, draw them with the software "
                        "rasterizer on Dask workers and composite them by depth")
    p.add_argument("--split", choices=("space", "part"), default="space",
                   help="domains by recursive bisection in space (default) or by whole parts")
    p.add_argument("--composite", choices=("tree", "swap"), default="tree",
                   help="compositing schedule: binary tree (default) or binary swap")
    p.add_argument("--workers", type=int, help="local Dask worker processes (default: one per core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="an existing Dask scheduler (tcp://host:port) instead of a local cluster")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("hausdorff", help="certified Hausdorff distance between two meshes",
                       description="Exact float64 Hausdorff distance from mesh A to mesh B (or "
                                   "symmetric) as a certified bracket lower <= H <= upper.")
    p.add_argument("mesh_a", help="mesh file or built-in scene name (A, the original)")
    p.add_argument("mesh_b", help="mesh file or built-in scene name (B)")
    p.add_argument("--symmetric", action="store_true", help="max of both directions")
    p.add_argument("--width", type=float, default=0.01,
                   help="bracket width to reach, %% of A's bounding-box diagonal (default 0.01)")
    p.add_argument("--step", type=int, default=0, help="time step of the coordinates (default 0)")
    p.set_defaults(func=cmd_hausdorff)

    p = sub.add_parser("simplify", help="Hausdorff-bounded decimation (crash2000), per part",
                       description="Half-edge collapses until the certified one-sided Hausdorff "
                                   "distance would exceed the tolerance; vertices never move.")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    p.add_argument("--tol", type=float, default=0.5,
                   help="tolerance, %% of each part's bounding-sphere diameter (default 0.5)")
    p.add_argument("-o", "--output", help="write the simplified surface (.ply, .obj, .stl, ...)")
    p.set_defaults(func=cmd_simplify)

    p = sub.add_parser("list", help="list the registered experiments")
    p.set_defaults(func=cmd_list)

    p = sub.add_parser("run", help="run one experiment, writing figures/<experiment>/")
    p.add_argument("experiment")
    p.add_argument("--quick", action="store_true", help="small sizes and few repetitions")
    p.add_argument("--figures", default="figures", help="output folder (default figures/)")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("reproduce", help="run every registered experiment, with a progress bar")
    p.add_argument("--quick", action="store_true", help="small sizes and few repetitions")
    p.add_argument("--figures", default="figures", help="output folder (default figures/)")
    p.set_defaults(func=cmd_reproduce)

    from .experiment.sweep import add_sweep_parser
    from .explode_cli import add_explode_parser
    from .stress import add_stress_parser

    add_explode_parser(sub, _pair, _size)
    add_sweep_parser(sub)
    add_stress_parser(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A reader's warning as one line on stderr (what was read as missing, and where)."""
    print(f"workbench: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    from .gl.context import GLUnavailable
    from .scene.mesh import MeshError
    from .scene.readers import ParseWarning

    warnings.simplefilter("always", ParseWarning)  # every missing value, not the first only
    warnings.showwarning = _show_warning

    try:
        return args.func(args)
    except (OSError, ValueError, KeyError, MeshError, GLUnavailable) as exc:
        if os.environ.get("WORKBENCH_DEBUG"):
            raise
        message = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        print(f"workbench: error: {message}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
