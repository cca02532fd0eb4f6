"""Parameter sweeps: every combination of ``--set`` values, in parallel or on a Dask cluster, resumable."""
