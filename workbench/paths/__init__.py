"""Render paths: comparable ways of drawing a scene, all behind one protocol
(:class:`~workbench.paths.base.RenderPath`), in one registry (``PATHS``), drawn on a GL context
or by the software rasterizer (:mod:`workbench.paths.backends`). How a path is drawn — prepared,
drawn, released — is :mod:`workbench.paths.drawing` (``prepared``, ``render``), the one place a
path is prepared."""

from . import exploded, fetexture, fields, flange, spacetime, surface, wire  # noqa: F401  (each registers)
from .backends import GLBackend, SoftwareRasterizer, as_backend
from .base import GLPath, RenderPath
from .colormap import ColorScale, colormap_lut, scale_for
from .drawing import Prepared, prepared, prepared_path, render
from .mesh import MeshPath
from .registry import PATHS, check_options, default_path, make_path, path_class, path_options
from .style import Style

__all__ = ["PATHS", "ColorScale", "GLBackend", "GLPath", "MeshPath", "RenderPath",
           "Prepared", "SoftwareRasterizer", "Style", "as_backend", "check_options",
           "colormap_lut", "default_path", "make_path", "path_class", "path_options",
           "prepared", "prepared_path", "render", "scale_for"]
