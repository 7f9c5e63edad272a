"""Where the workbench may write: output files go only to a regular file (replaced whole) or to
a path that does not exist yet, output folders only to a real folder or a new path.

An existing target that is anything else — a device such as ``/dev/full``, a FIFO, a socket, a
folder where a file is expected (or a file where a folder is), or a symbolic link — is refused
with a ValueError naming the path and what it is, before anything is written. Symbolic links
are refused even where they point to a regular file or a folder: a write through one would
land outside the folder it was meant for, and replacing one would silently drop it.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

_KINDS = ((stat.S_ISLNK, "symbolic link"), (stat.S_ISDIR, "directory"),
          (stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"),
          (stat.S_ISFIFO, "FIFO"), (stat.S_ISSOCK, "socket"), (stat.S_ISREG, "regular file"))


def _kind(path: Path) -> str | None:
    """What ``path`` is (the link itself, not what it points to); None when it does not exist."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return None
    return next((name for test, name in _KINDS if test(mode)), "special file")


def output_target(path: str | os.PathLike[str]) -> Path:
    """``path`` as a Path where it is a regular file or does not exist yet (a file to write).

    Refuses (ValueError naming the path and what it is) an existing path of any other kind: a
    symbolic link (wherever it points), a directory, a device, a FIFO or a socket. Only the last
    component is examined: the folders above it are the caller's to choose.
    """
    path = Path(path)
    kind = _kind(path)
    if kind not in (None, "regular file"):
        raise ValueError(f"output {path} is a {kind}, not a regular file: nothing written")
    return path


def output_folder(path: str | os.PathLike[str], *, create: bool = False) -> Path:
    """``path`` as a Path where it is a real folder (not a symbolic link to one) or does not
    exist yet; with ``create`` a missing folder is made (with its parents) and checked again.

    Refuses (ValueError naming the path and what it is) a symbolic link, so that nothing is
    written through it out of the output folder, and anything else that is not a folder.
    """
    path = Path(path)
    kind = _kind(path)
    if kind is None and create:
        path.mkdir(parents=True, exist_ok=True)
        kind = _kind(path)  # something else may have appeared there meanwhile
    if kind not in (None, "directory"):
        raise ValueError(f"output folder {path} is a {kind}, not a folder: nothing written "
                         f"{'through' if kind == 'symbolic link' else 'to'} it")
    return path
