"""Render paths: comparable ways of drawing a scene, all behind one protocol
(:class:`~workbench.paths.base.RenderPath`) and in one registry (``PATHS``)."""

from . import fetexture, fields, flange, spacetime, surface, wire  # noqa: F401  (each registers)
from . import exploded  # noqa: F401  (registers)
from .base import (PATHS, GLPath, MeshPath, RenderPath, Style, check_options, make_path,
                   path_class, path_options)
from .colormap import ColorScale, colormap_lut, scale_for

__all__ = ["PATHS", "ColorScale", "GLPath", "MeshPath", "RenderPath", "Style", "check_options",
           "colormap_lut", "make_path", "path_class", "path_options", "scale_for"]
