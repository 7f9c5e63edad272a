"""What the ``workbench`` command's modules share: argument types ("A,B", "WxH", KEY=VALUE),
the parser whose refusals are one line, and the one-line report of refused input with exit
status :data:`EXIT_BAD_INPUT`."""

from __future__ import annotations

import argparse
import ast
import math
import sys

EXIT_BAD_INPUT = 2


def pair(text: str, sep: str, kind=float) -> tuple:
    """Two finite numbers separated by ``sep``."""
    try:
        a, b = text.lower().split(sep)
        values = kind(a), kind(b)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected two numbers separated by {sep!r}, got {text!r}") from None
    if not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"expected two finite numbers, got {text!r}")
    return values


def view_angles(text: str) -> tuple[float, float]:
    """``AZ,EL`` of ``--view``: azimuth and elevation in degrees."""
    return pair(text, ",")


def image_size(text: str) -> tuple[int, int]:
    """``WxH`` of ``--size``: a positive width and height in pixels."""
    w, h = pair(text, "x", int)
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    return w, h


def at_least(minimum: int):
    """An argparse type: an integer ``>= minimum`` (refused in one line otherwise)."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be at least {minimum}, got {value}")
        return value

    parse.__name__ = f"integer >= {minimum}"
    return parse


def key_value(text: str) -> tuple[str, object]:
    """``KEY=VALUE`` of ``--option``: VALUE read as a Python literal (number, tuple, bool), or
    as a float (``nan``, ``inf``), else kept as a string."""
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    try:
        return key.strip(), ast.literal_eval(value)
    except (ValueError, SyntaxError):
        pass
    try:  # nan and inf are numbers the literal syntax does not spell
        return key.strip(), float(value)
    except ValueError:
        return key.strip(), value


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose refusals are one line (``PROG: error: …``) and exit status 2,
    without the usage block (``--help`` shows it)."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def refused(exc: BaseException) -> int:
    """Report input a command refused as one line on stderr, ``workbench: error: MESSAGE`` (a
    KeyError's message without its quotes); returns :data:`EXIT_BAD_INPUT`."""
    message = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
    print(f"workbench: error: {message}", file=sys.stderr)
    return EXIT_BAD_INPUT


def add_device_argument(parser: argparse.ArgumentParser) -> None:
    """``--device N``: the EGL device a drawing command draws on (default
    ``WORKBENCH_EGL_DEVICE``, else 0); checked when the context is made."""
    parser.add_argument("--device", metavar="N",
                        help="EGL device index to draw on (default: $WORKBENCH_EGL_DEVICE, "
                             "else 0; workbench info lists the devices)")


def device_list(text: str) -> tuple[int, ...]:
    """``--worker-devices 0,1,…``: EGL device indices (0 or more), comma-separated."""
    try:
        devices = tuple(int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected EGL device indices separated by commas, got {text!r}") from None
    if any(d < 0 for d in devices):
        raise argparse.ArgumentTypeError(f"EGL device indices are 0 or more, got {text!r}")
    return devices


def add_cluster_output_arguments(parser: argparse.ArgumentParser) -> None:
    """``--worker-devices`` (the EGL devices Dask workers are pinned to) and ``--verbose``
    (Dask's INFO log lines)."""
    parser.add_argument("--worker-devices", type=device_list, metavar="I,J,...",
                        help="EGL devices the Dask workers draw on, dealt out in turn "
                             "(default: each host's devices round-robin)")
    parser.add_argument("--verbose", action="store_true",
                        help="show Dask's INFO log lines (default: warnings and errors only)")


def say_worker_devices(devices: dict[str, str | None]) -> None:
    """One line on stderr per Dask worker: its address and the EGL device it draws on."""
    for address, device in sorted(devices.items()):
        print(f"worker {address}: EGL device {device or '(none)'}", file=sys.stderr)


def apply_process_options(args) -> None:
    """For commands whose experiments make their own contexts and clusters: make
    ``args.device`` (if given) the EGL device of this process and the processes it starts
    (``WORKBENCH_EGL_DEVICE``), ValueError (one line) for an index this machine does not have;
    and with ``args.verbose`` show Dask's INFO log lines of the clusters it starts."""
    import os

    from ..gl.devices import DEVICE_ENV, device_index

    if getattr(args, "device", None) is not None:
        os.environ[DEVICE_ENV] = str(device_index(args.device))
    if getattr(args, "verbose", False):
        from ..distributed.cluster import VERBOSE_ENV

        os.environ[VERBOSE_ENV] = "1"
