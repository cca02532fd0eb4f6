"""Parameter sweeps: every combination of ``--set`` values, in parallel or on a Dask cluster, resumable.

``plan`` parses the axes and resolves every combination, ``points`` runs them in local processes (``dask`` on
a cluster), ``core`` orchestrates a sweep and writes ``results.csv``, ``plot`` draws its figures.
"""
