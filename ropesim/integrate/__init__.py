"""Time integration: the integrator contract, one module per family, and what every compiled loop shares."""
