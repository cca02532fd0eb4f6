"""Analyses of a trajectory: energy, the towed rope's steady state, the shooter's loop, the run summary."""
