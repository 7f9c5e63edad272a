"""``workbench info``: the renderer, the OpenGL version, every EGL device of this machine, the
versions of the libraries the workbench uses, and where the shared data is."""

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


def cmd_info(args) -> int:
    """Print the renderer, the EGL devices, versions and the shared data folder; 0."""
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
