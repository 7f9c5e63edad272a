"""``workbench info``: the renderer, the OpenGL version, the versions of the libraries the
workbench uses, and where the shared data is."""

from __future__ import annotations

import sys
from importlib import metadata

VERSIONED = ("numpy", "scipy", "moderngl", "trimesh", "meshio", "lasso-python", "libigl",
             "pymeshlab", "open3d", "pyrender", "meshoptimizer", "scikit-image", "matplotlib")


def add_parser(subparsers) -> None:
    """Add ``info`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser("info",
                              help="renderer, OpenGL version, library versions, shared data")
    p.set_defaults(func=cmd_info)


def cmd_info(args) -> int:
    """Print the renderer, versions and the shared data folder; 0."""
    from ..data import shared_data_dir
    from ..gl import create_context, renderer
    from ..gl.context import gl_version

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
