"""The ``egl_device`` column a table gains where its rows were drawn on the run's GL context
(:meth:`workbench.experiment.context.ExperimentContext.with_device`, tested in
``test_devices.py``), for the tests that check an experiment's own columns: it stands wherever
a table's first GL row put it."""

from __future__ import annotations


def own_columns(header: list[str]) -> list[str]:
    """``header`` without its ``egl_device`` column."""
    header = list(header)
    assert header.count("egl_device") <= 1, header
    return [c for c in header if c != "egl_device"]
