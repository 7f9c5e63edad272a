"""Loading the shaders of the package ``workbench.glsl`` (its ``*.glsl`` files)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from functools import cache
from importlib import resources

import moderngl

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


@cache
def shader_source(name: str) -> str:
    """The text of ``glsl/<name>`` with ``#include "file"`` lines expanded (one level deep per
    file)."""
    path = resources.files("workbench.glsl") / name
    if not path.is_file():
        raise FileNotFoundError(f"shader {name!r} not found in the workbench glsl folder")
    text = path.read_text()
    return _INCLUDE.sub(lambda m: shader_source(m.group(1)), text)


def _with_defines(source: str, defines: Mapping[str, object] | None) -> str:
    if not defines:
        return source
    lines = "".join(f"#define {key} {value}\n" for key, value in defines.items())
    head, sep, rest = source.partition("\n")
    if not head.startswith("#version"):
        raise ValueError("shader must start with a #version line")
    return head + sep + lines + rest


def load_program(ctx: moderngl.Context, vertex: str, fragment: str | None = None,
                 geometry: str | None = None,
                 defines: Mapping[str, object] | None = None) -> moderngl.Program:
    """A program from shader files in ``glsl/``, with ``#define key value`` lines after
    ``#version``."""
    return ctx.program(
        vertex_shader=_with_defines(shader_source(vertex), defines),
        fragment_shader=(None if fragment is None
                         else _with_defines(shader_source(fragment), defines)),
        geometry_shader=(None if geometry is None
                         else _with_defines(shader_source(geometry), defines)),
    )
