"""``workbench info``: the renderer, the OpenGL version, every EGL device of this machine, the
versions of the libraries the workbench uses, and where the shared data is; ``workbench info
MESH``: what a mesh file or built-in scene holds (sizes, parts, states and times, the node and
element fields with their ranges, and the elements deleted per part and state)."""

from __future__ import annotations

import sys
from importlib import metadata

from .arguments import add_device_argument

VERSIONED = ("numpy", "scipy", "moderngl", "trimesh", "meshio", "lasso-python", "libigl",
             "pymeshlab", "open3d", "pyrender", "pyvista", "vtk", "meshoptimizer",
             "scikit-image", "matplotlib", "distributed", "jupyter-rfb")


def add_parser(subparsers) -> None:
    """Add ``info`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser("info",
                              help="renderer, OpenGL version, EGL devices, library versions, "
                                   "shared data")
    p.add_argument("mesh", nargs="?", metavar="MESH",
                   help="a mesh file or built-in scene: print what it holds instead (sizes, "
                        "parts, states, fields, deleted elements per part and state)")
    p.add_argument("--all-faces", action="store_true",
                   help="with MESH: every face of its solids, not only their boundary")
    add_device_argument(p)
    p.set_defaults(func=cmd_info)


def device_table(devices) -> list[str]:
    """The lines listing ``devices`` (:class:`~workbench.gl.devices.EGLDevice`, probed): index,
    GL vendor and renderer, DRM render node (else device file), CUDA device id and UUID where
    the driver gives them, and the identity rows record."""
    header = ("index", "vendor", "renderer", "DRM node", "CUDA", "UUID", "identity")
    rows = [(str(d.index), d.vendor or "?", d.renderer or "(no context)",
             d.render_node or d.drm_file or "-", "-" if d.cuda_device is None else
             str(d.cuda_device), d.uuid or "-", d.identity) for d in devices]
    widths = [max(len(r[i]) for r in (header, *rows)) for i in range(len(header))]
    return ["  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip()
            for row in (header, *rows)]


def mesh_lines(mesh, offered=()) -> list[str]:
    """What ``mesh`` (an :class:`~workbench.scene.mesh.FEMesh`) holds, a line each: sizes,
    parts, states with their times, every field with its kind, shape and range over the live
    elements (no value where it has none), the fields of ``offered`` (names its file can give
    on request) it does not hold, and, where elements are deleted (erosion), the count per
    state and part."""
    import numpy as np

    from ..scene.kinds import kind_lines
    from ..scene.mesh import ALIVE

    lines = [f"{mesh.name}: {mesh.n_nodes} nodes, {mesh.n_elements} elements, "
             f"{len(np.unique(mesh.parts))} parts, {mesh.n_steps} state"
             f"{'s' * (mesh.n_steps != 1)} (units {mesh.units})"]
    if mesh.times is not None:
        times = np.asarray(mesh.times, np.float64)
        lines.append(f"times: {times[0]:.6g} .. {times[-1]:.6g}")
    lines += kind_lines(mesh)  # beams and SPH particles, where the mesh has them
    for kind, fields in (("node", mesh.node_fields), ("element", mesh.element_fields)):
        for name in sorted(fields):
            values = fields[name]
            if name == ALIVE:
                lines.append(f"element field {name!r}: 1 in use, 0 deleted (erosion)")
                continue
            lo, hi = mesh.field_range(name)
            finite = np.isfinite(values).any()
            per = "per state" if values.ndim == 2 else "static"
            value = f"{lo:.6g} .. {hi:.6g}" if finite else "no value"
            missing = int((~np.isfinite(values)).sum())
            lines.append(f"{kind} field {name!r} ({per}): {value}"
                         + (f", {missing} values without a result" if missing else ""))
    more = [name for name in offered if name not in mesh.node_fields
            and name not in mesh.element_fields]
    if more:
        lines.append(f"fields on request (render --field NAME, --layer for the layered; "
                     f"render --help says what each is): {', '.join(more)}")
    if mesh.erodes:
        lines.append("deleted elements (erosion), per state: " + ", ".join(
            str(mesh.n_deleted(k)) for k in range(mesh.n_steps)))
        counts = [mesh.deleted_count(k) for k in range(mesh.n_steps)]
        for part in sorted(set().union(*counts)):
            title = mesh.part_names.get(part)
            lines.append(f"  part {part}" + (f" ({title})" if title else "") + ": "
                         + ", ".join(str(c.get(part, 0)) for c in counts))
    else:
        lines.append("deleted elements (erosion): none")
    return lines


def cmd_info(args) -> int:
    """Print the renderer, the EGL devices, versions and the shared data folder (or, with a
    mesh, what it holds: :func:`mesh_lines`); 0."""
    if args.mesh is not None:
        from ..scene.builtin import load_mesh
        from ..scene.readers.d3plot_fields import offered_by_file
        from .field_options import d3plot_file

        file = d3plot_file(args.mesh)
        offered = offered_by_file(file) if file is not None else ()
        for line in mesh_lines(load_mesh(args.mesh, all_faces=args.all_faces), offered):
            print(line)
        return 0
    from ..data import shared_data_dir
    from ..gl import create_context, renderer
    from ..gl.context import gl_version, probed_devices
    from ..gl.devices import DEVICE_ENV, current_device

    devices = probed_devices()
    ctx = create_context(device=args.device)
    print(f"workbench {metadata.version('workbench')}")
    print(f"renderer  {renderer(ctx)}")
    print(f"OpenGL    {gl_version(ctx)}")
    device = current_device()
    print(f"device    {device.identity if device else '(EGL does not say)'}")
    print(f"EGL devices ({len(devices)}; choose with --device N or {DEVICE_ENV}):")
    for line in device_table(devices):
        print(f"  {line}")
    print(f"python    {sys.version.split()[0]}")
    for name in VERSIONED:
        try:
            print(f"{name:<13} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            print(f"{name:<13} (not installed)")
    data = shared_data_dir()
    print(f"shared data {data if data else '(not found: set WORKBENCH_DATA)'}")
    return 0
