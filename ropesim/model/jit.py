"""How ropesim compiles its kernels: one decorator for every function the integration loops call.

``kernel`` is Numba's ``njit`` in nopython mode with three settings fixed for the whole code base:

- ``cache=True``: compiled machine code is kept on disk (see :mod:`ropesim.io.numba_cache`), so only the
  first run of a scene's methods compiles;
- ``error_model="numpy"``: a division by zero gives inf or nan, as in NumPy, instead of raising (the blow-up
  check then stops the run, and the loops need no zero tests);
- no reference counting (Numba's private ``_nrt=False``). Numba counts references to every array a compiled
  function receives: an atomic increment on entry and a decrement on exit, per array and per call. The
  force terms receive the model's parameter bundle (some twenty arrays) several times per stage, so the
  counting cost more than the forces on ropes of tens of nodes (rk4 on ``helicopter_mass``: 7.2 µs per step
  with counting, 1.8 µs without, measured on one loaded machine). A kernel only *borrows* the arrays it is
  given (the integrator holds them for the whole call) and allocates none, so the counting protects nothing.
  Numba refuses to compile a kernel that would allocate, so this cannot go wrong silently: such a function
  uses plain ``njit``. ``tests/test_performance_invariants.py`` checks that the compiled term list counts no
  references, so a Numba release that changed the option would be noticed.
"""

from __future__ import annotations

from numba import njit

OPTIONS = {"cache": True, "error_model": "numpy", "_nrt": False}


def kernel(function=None, *, inline: str = "never"):
    """Compile ``function`` as a ropesim kernel (see the module doc); ``@kernel`` or ``@kernel(inline="always")``
    (Numba's inlining at its own IR level, for small helpers called in the innermost loops)."""
    def decorate(fn):
        return njit(inline=inline, **OPTIONS)(fn)

    return decorate(function) if function is not None else decorate
