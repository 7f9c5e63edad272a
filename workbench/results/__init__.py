"""The results store and what reads it: every measurement with its provenance, compared run to run.

================  ==============================================================
``store``         the store: a folder of Parquet files queried with DuckDB
``provenance``    the machine, renderer, code and library versions of a run
``recording``     a command's run recorded in the store (run record and rows)
``compare``       two stored runs compared measurement by measurement
``history``       a stored quantity over the runs of one machine, with its change points
``changepoints``  change points of a series (E-divisive means, permutation test)
================  =============================================================="""
