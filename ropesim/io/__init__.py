"""Files: the run folder (frames, trajectory, summary), atomic writes, and where compiled kernels are cached."""
