"""The experiments' harness: the registry, the context an experiment runs in, the report.

============  =======================================================================
``registry``  :func:`~.registry.experiment` registers an experiment; ``run_experiment``
              runs one and writes its tables and figures
``context``   :class:`~.context.ExperimentContext`: the sizes, the GL context and the
              measure call an experiment uses
``report``    the README's and ``docs/results.md``'s claims, written from the store
============  =======================================================================

Measuring lives in :mod:`workbench.measurement`, output files in :mod:`workbench.output`,
other tools in :mod:`workbench.references`, the store in :mod:`workbench.results`."""

from .registry import EXPERIMENTS, Experiment, discover, experiment, get_experiment, run_experiment

__all__ = ["EXPERIMENTS", "Experiment", "discover", "experiment", "get_experiment",
           "run_experiment"]
