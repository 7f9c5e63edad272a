"""The shaders of the render paths (package data), named after the path that uses them."""
