"""workbench: comparable OpenGL render paths for finite-element visualization, measured side by
side."""

__version__ = "0.1.0"
