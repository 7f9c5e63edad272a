"""Render paths: comparable ways of drawing an FE mesh, all behind one small interface."""

from .base import PATHS, MeshPath, RenderPath, Style, make_path
from .colormap import ColorScale, colormap_lut, scale_for

__all__ = ["PATHS", "ColorScale", "MeshPath", "RenderPath", "Style", "colormap_lut", "make_path",
           "scale_for"]
