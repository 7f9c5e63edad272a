"""The experiments' declarations: per experiment of :mod:`workbench.reproductions` one module
of the same name holding ``DECLARED``, the :class:`~workbench.experiment.declare.Declaration`
of its tables (every column with unit and legend) and of the claims the report states from
them; :mod:`.common` holds the columns many tables share (those of
:func:`workbench.measurement.rows.measure`'s row, image errors, wire-frame overlap).

The experiment registers with ``@experiment(name, description, declared=DECLARED)``; the
harness checks its tables against the declaration, writes the legends under them, and the
report and the shape tests read it (see :mod:`workbench.experiment.declare`).
"""
