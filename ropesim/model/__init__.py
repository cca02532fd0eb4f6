"""The model: a validated scene laid out as arrays for the compiled kernel, and the force terms acting on it."""
