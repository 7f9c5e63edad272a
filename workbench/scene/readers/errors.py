"""What every mesh reader shares: the :class:`ParseError` refusal, the :class:`ParseWarning`
for what a reader reads as missing, and :func:`build_mesh`.

The readers (:mod:`~workbench.scene.readers.keyword` and its modules,
:mod:`~workbench.scene.readers.d3plot` and :mod:`~workbench.scene.readers.meshio_trimesh`)
import from here, and the package (:func:`workbench.scene.readers.load`) imports the readers,
so that no reader depends on the module that dispatches to it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..mesh import FEMesh, MeshError


class ParseError(ValueError):
    """A mesh file that cannot be read: where (``path``, 1-based ``line``), what (``card``) and why.

    ``line``, ``card`` and ``keyword`` are None where they do not apply (a binary file, a whole
    file refused). ``message`` says what was expected. ``str()`` reads
    ``"file.k:123: *NODE: expected 3 coordinates, got 'abc' in '...'"``.
    """

    def __init__(self, path: str | os.PathLike[str], message: str, line: int | None = None,
                 card: str | None = None, keyword: str | None = None) -> None:
        self.path = Path(path)
        self.message = message
        self.line = line
        self.card = card
        self.keyword = keyword
        super().__init__(str(self))

    def __str__(self) -> str:
        where = str(self.path) if self.line is None else f"{self.path}:{self.line}"
        text = f"{where}: "
        if self.keyword:
            text += f"*{self.keyword}: "
        text += self.message
        if self.card is not None:
            text += f" in {self.card!r}"
        return text

    def __reduce__(self) -> tuple[type[ParseError], tuple[Any, ...]]:
        return (type(self), (self.path, self.message, self.line, self.card, self.keyword))


class ParseWarning(UserWarning):
    """Something a reader could not read and kept as missing (NaN) instead of refusing the
    file: ``str()`` reads ``"file.k:12: *SECTION_SHELL: parameter 't1' is not defined ..."``.
    Issued with :func:`warnings.warn`; ``workbench`` prints each as one line on stderr."""

    def __init__(self, path: str | os.PathLike[str], message: str, line: int | None = None,
                 keyword: str | None = None) -> None:
        self.path, self.message, self.line, self.keyword = Path(path), message, line, keyword
        where = str(self.path) if line is None else f"{self.path}:{line}"
        super().__init__(f"{where}: " + (f"*{keyword}: " if keyword else "") + message)


def build_mesh(path: str | os.PathLike[str], **kwargs: Any) -> FEMesh:
    """``FEMesh(**kwargs)``, with a refusal of the model reported as :class:`ParseError` on
    ``path``."""
    try:
        return FEMesh(**kwargs)
    except MeshError as exc:
        raise ParseError(path, str(exc)) from exc
