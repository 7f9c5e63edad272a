"""The ``workbench`` command: info, doctor, render, animate, hausdorff, simplify, penetrations,
list, run, reproduce, explode, sweep, stress, results and bench, one module per command
(:data:`COMMANDS`), each adding its own parser (``add_parser(subparsers)``) that calls its
``cmd_<command>(args)``.

Bad input (an unreadable or malformed mesh file, an empty mesh, a missing OpenGL driver, an
unknown name) ends with a one-line message on stderr and exit status 2, never a traceback (set
WORKBENCH_DEBUG=1 to see one).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import warnings
from importlib import metadata

from .arguments import EXIT_BAD_INPUT, OneLineParser, refused

# the command modules, in the order their commands are listed; imported when the parser is
# built, so that ``python -m workbench.cli.sweep`` runs a module not yet imported
COMMANDS = ("info", "doctor", "render", "animate", "hausdorff", "simplify", "penetrations",
            "experiments", "explode", "sweep", "stress", "results", "bench")
# where the names of the former single-module command line are now
_MOVED = {"cmd_info": "info", "VERSIONED": "info", "cmd_render": "render",
          "cmd_hausdorff": "hausdorff", "cmd_simplify": "simplify", "cmd_list": "experiments",
          "cmd_run": "experiments", "cmd_reproduce": "experiments", "cmd_explode": "explode",
          "cmd_sweep": "sweep", "cmd_stress": "stress"}

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "build_parser", "main", *_MOVED]


def __getattr__(name: str):
    """The command functions by their former names (``workbench.cli.cmd_render`` …), imported
    on first use."""
    if name in _MOVED:
        return getattr(importlib.import_module(f"{__name__}.{_MOVED[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def build_parser() -> argparse.ArgumentParser:
    """The ``workbench`` parser with every command of :data:`COMMANDS`."""
    parser = OneLineParser(
        prog="workbench",
        description="Comparable OpenGL render paths for finite-element visualization, measured "
                    "side by side for run time and error on a headless (EGL) context.")
    parser.add_argument("--version", action="version",
                        version=f"%(prog)s {metadata.version('workbench')}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").add_parser(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A reader's warning as one line on stderr (what was read as missing, and where)."""
    print(f"workbench: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    """Run the command ``argv`` names (default ``sys.argv[1:]``); its exit status."""
    args = build_parser().parse_args(argv)
    from ..gl.context import GLUnavailable
    from ..scene.mesh import MeshError
    from ..scene.readers import ParseWarning

    warnings.simplefilter("always", ParseWarning)  # every missing value, not the first only
    warnings.showwarning = _show_warning

    try:
        return args.func(args)
    except (OSError, ValueError, KeyError, MeshError, GLUnavailable) as exc:
        if os.environ.get("WORKBENCH_DEBUG"):
            raise
        return refused(exc)
