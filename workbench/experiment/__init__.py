"""The experiments' harness: the registry, the context an experiment runs in, what an experiment
declares, the report.

============  =======================================================================
``registry``  :func:`~.registry.experiment` registers an experiment; ``run_experiment``
              runs one and writes its tables and figures
``context``   :class:`~.context.ExperimentContext`: the sizes, the GL context and the
              measure call an experiment uses
``declare``   :class:`~.declare.Declaration`: an experiment's tables (columns with units and
              legends) and claims, declared once; tables are checked against it
``report``    the README's and ``docs/results.md``'s claims, written from the store
============  =======================================================================

Measuring lives in :mod:`workbench.measurement`, output files in :mod:`workbench.output`,
other tools in :mod:`workbench.references`, the store in :mod:`workbench.results`."""

from .registry import EXPERIMENTS, Experiment, discover, experiment, get_experiment, run_experiment

__all__ = ["EXPERIMENTS", "Experiment", "discover", "experiment", "get_experiment",
           "run_experiment"]
