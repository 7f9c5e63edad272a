"""Where the shared sample data (the LS-DYNA car deck and the d3plot result) is found."""

from __future__ import annotations

import os
from pathlib import Path

CAR_DECK = Path("lsopt_car6") / "car6_crash_v3.k"
D3PLOT = Path("lasso_simple_d3plot") / "d3plot"


def shared_data_dir() -> Path | None:
    """The shared data folder: ``$WORKBENCH_DATA``, else ``shared/data`` beside the checkout.

    Returns None when neither exists (a user's clone without the shared data).
    """
    candidates = []
    if os.environ.get("WORKBENCH_DATA"):
        candidates.append(Path(os.environ["WORKBENCH_DATA"]))
    repo = Path(__file__).resolve().parents[1]
    candidates += [repo.parent / "shared" / "data", Path.cwd().parent / "shared" / "data"]
    for path in candidates:
        if path.is_dir():
            return path
    return None


def shared_file(relative: Path | str) -> Path | None:
    """A file inside the shared data folder, or None when it is absent."""
    root = shared_data_dir()
    if root is None:
        return None
    path = root / relative
    return path if path.exists() else None
