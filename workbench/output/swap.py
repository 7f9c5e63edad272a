"""A folder of outputs replaced as a whole: built in a hidden staging folder beside it, then
put in its place with renames, so that a reader sees the old set or the new one, never half.

Names beside the target ``<dir>/<name>``: ``.<name>.<random>.<pid>.partial`` (a staging
folder, :func:`staging_folder`) and ``.<name>.<pid>.old`` (the previous folder set aside for
the moment of the swap, :func:`swap_in`). What a process killed midway left is cleaned up by
the next one (:func:`clean_dead_swaps`): its staging folder removed, a previous folder put back
where the target is missing (the kill fell between the two renames). Folders of processes
still running are left alone (:func:`process_alive`).
"""

from __future__ import annotations

import glob
import os
import shutil
import tempfile
from pathlib import Path

from .tables import current_umask
from .targets import output_folder


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` still runs on this machine (a zombie does not: its writes are
    over)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:  # a killed child nobody has reaped yet is a zombie: its writes are over
        with open(f"/proc/{pid}/stat", "rb") as stat:
            return stat.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True


def staging_folder(out: Path) -> Path:
    """A new, empty staging folder for ``out`` beside it (``.<name>.<random>.<pid>.partial``),
    with the permissions the umask gives a folder (not mkdtemp's 0700)."""
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.",
                                    suffix=f".{os.getpid()}.partial"))
    os.chmod(staging, 0o777 & ~current_umask())
    return staging


def swap_in(staging: Path, out: Path) -> None:
    """Put ``staging`` in the place of ``out``: the previous folder is set aside as
    ``.<name>.<pid>.old`` first and removed last (a kill in between leaves it for
    :func:`clean_dead_swaps` to put back). Refuses (ValueError) an ``out`` that has become a
    symbolic link or something other than a folder."""
    if not os.path.lexists(output_folder(out)):
        os.replace(staging, out)
        return
    old = out.with_name(f".{out.name}.{os.getpid()}.old")
    shutil.rmtree(old, ignore_errors=True)
    os.replace(out, old)
    os.replace(staging, out)
    shutil.rmtree(old, ignore_errors=True)


def clean_dead_swaps(out: Path) -> list[Path]:
    """Remove what processes that died while replacing ``out`` left beside it: their staging
    folders, and a previous folder set aside (put back where ``out`` is missing). Returns what
    was removed or put back."""
    done = []
    for entry in sorted(out.parent.glob(f".{glob.escape(out.name)}.*")):
        parts = entry.name.rsplit(".", 2)
        if len(parts) != 3 or parts[2] not in ("partial", "old") or not parts[1].isdigit():
            continue
        if process_alive(int(parts[1])) and int(parts[1]) != os.getpid():
            continue
        if parts[2] == "old" and not os.path.lexists(out):
            os.replace(entry, out)
        else:
            shutil.rmtree(entry, ignore_errors=True)
        done.append(entry)
    return done
