"""The single ordered list of force terms, each behind its on/off flag.

The rope's springs are always on; every other term runs only when the scene declares it, and an undeclared
term receives empty parameters of the same types, so every scene compiles to one signature and reloads
from Numba's cache.
"""

from numba import njit

from .forces.gravity import add_gravity
from .forces.guides import add_guides
from .forces.springs import add_pair_springs
from .forces.thrower import add_thrower

# Positions in the ``flags`` array (uint8), one per optional force term.
BENDING, GRAVITY, THROWER, GUIDES = 0, 1, 2, 3
N_FLAGS = 4


@njit(cache=True, error_model="numpy")
def accelerations(x, v, acc, forces):
    """Overwrite ``acc`` (D, N) with the acceleration [m/s^2] of every node, drag excluded.

    ``forces`` = (inv_mass, flags, spring, bending, gravity, thrower, guides): see :mod:`ropesim.build`.
    """
    inv_mass, flags, spring, bending, gravity, thrower, guides = forces
    acc[:] = 0.0
    closed = spring[2] != 0.0
    add_pair_springs(x, acc, inv_mass, spring[0], spring[1], 1, closed)
    if flags[BENDING]:
        add_pair_springs(x, acc, inv_mass, bending[0], bending[1], 2, closed)
    g = 0.0
    if flags[GRAVITY]:
        g = gravity[0]
        add_gravity(acc, g)
    if flags[THROWER]:
        add_thrower(x, v, acc, inv_mass, thrower, g)
    if flags[GUIDES]:
        add_guides(x, v, acc, guides, thrower, flags[THROWER] != 0, g)
