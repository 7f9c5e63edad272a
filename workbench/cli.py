"""The ``workbench`` command: info, render, list, run and reproduce.

Bad input (an unreadable or malformed mesh file, an empty mesh, a missing OpenGL driver, an
unknown name) ends with a one-line message on stderr and exit status 2, never a traceback (set WORKBENCH_DEBUG=1 to see one).
"""

from __future__ import annotations

import argparse
import os
import sys
from importlib import metadata
from pathlib import Path

EXIT_BAD_INPUT = 2
VERSIONED = ("numpy", "scipy", "moderngl", "trimesh", "meshio", "lasso-python", "libigl", "pymeshlab",
             "open3d", "pyrender", "meshoptimizer", "scikit-image", "matplotlib")


def _pair(text: str, sep: str, kind=float) -> tuple:
    try:
        a, b = text.lower().split(sep)
        return kind(a), kind(b)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers separated by {sep!r}, got {text!r}")


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


def cmd_render(args) -> int:
    from .experiment.figures import save_field_figure, save_png
    from .gl import Camera, Framebuffer, create_context
    from .paths import Style, make_path
    from .scene.builtin import load_scene

    mesh = load_scene(args.mesh)
    if args.field is not None and args.field not in mesh.node_fields and args.field not in mesh.element_fields:
        known = sorted([*mesh.node_fields, *mesh.element_fields]) or ["(none)"]
        raise KeyError(f"{mesh.name} has no field {args.field!r}; fields: {', '.join(known)}")
    if not 0 <= args.step < mesh.n_steps:
        raise ValueError(f"{mesh.name} has {mesh.n_steps} steps; --step {args.step} is outside")
    path_name = args.path
    if path_name is None:
        if args.field is None:
            path_name = "gouraud"
        else:
            path_name = "element_color" if args.field in mesh.element_fields else "pixel_color"
    style = Style(field=args.field, step=args.step, colormap=args.colormap, bands=args.bands,
                  wireframe=args.wireframe, crease_deg=args.crease, strips=args.strips,
                  fepatch=args.fepatch)
    ctx = create_context()
    width, height = args.size
    camera = Camera.fit_box(*mesh.bounds(all_steps=True), azimuth=args.view[0], elevation=args.view[1],
                        projection=args.projection, aspect=width / height, up=args.up)
    fb = Framebuffer(ctx, (width, height), samples=args.samples)
    path = make_path(path_name, style)
    path.prepare(ctx, mesh, camera)
    if args.step:
        path.set_step(args.step)
    fb.clear()
    path.draw()
    image = fb.read()
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    if args.field is not None and not args.raw:
        save_field_figure(out, image, value_range=path.scale.value_range, colormap=args.colormap,
                          label=args.field, units=args.units, title=f"{mesh.name} ({path_name})",
                          bands=args.bands)
    else:
        save_png(out, image)
    strips = f", {path.strips} strip{'s' * (path.strips != 1)}" if path.strips else ""
    print(f"{out}: {mesh.name}, {path.triangles} triangles, {path.vertices_sent} vertices sent"
          f"{strips}, path {path_name}")
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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="workbench",
        description="Comparable OpenGL render paths for finite-element visualization, measured "
                    "side by side for run time and error on a headless (EGL) context.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {metadata.version('workbench')}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("info", help="renderer, OpenGL version, library versions, shared data")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("render", help="render one mesh to a PNG",
                       description="Render a mesh file (LS-DYNA .k, d3plot, meshio or trimesh formats) or a "
                                   "built-in scene (car, d3plot, semicylinders, panels) offscreen.")
    p.add_argument("mesh", help="mesh file or built-in scene name")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--field", help="node or element field to colour by")
    p.add_argument("--path", help="render path (default: gouraud; pixel_color or element_color with --field)")
    p.add_argument("--wireframe", action="store_true", help="overdraw element edges")
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
    p.add_argument("--colormap", default="viridis", help="matplotlib colormap name")
    p.add_argument("--crease", type=float, default=30.0, help="Gouraud crease angle in degrees")
    p.add_argument("--samples", type=int, default=0, help="MSAA samples (0: none)")
    p.add_argument("--units", default="", help="units of the field, for the colour bar label")
    p.add_argument("--raw", action="store_true", help="write the bare image without a colour bar")
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
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    from .gl.context import GLUnavailable
    from .scene.mesh import MeshError

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
