"""Other programs' APIs served by ropesim: :mod:`ropesim.compat.moordyn` (MoorDyn's Python API)."""
