"""The experiment scripts, one per paper table or figure; each registers itself for
``workbench reproduce`` (see :mod:`workbench.experiment.registry`)."""
