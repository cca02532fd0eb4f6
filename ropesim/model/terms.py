"""The single ordered list of force terms, each behind its on/off flag.

The rope's springs are always on; every other term runs only when the scene declares it, and an undeclared
term receives empty parameters of the same types, so every scene compiles to one signature and reloads
from Numba's cache.
"""

import numpy as np
from numba import njit

from .forces.guides import add_guides
from .forces.springs import add_pair_springs, set_chain_springs
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
    closed = spring[2] != 0.0
    g = gravity[0] if flags[GRAVITY] else 0.0
    set_chain_springs(x, acc, inv_mass, spring[0], spring[1], closed, g)  # overwrites acc; gravity included
    if flags[BENDING]:
        add_pair_springs(x, acc, inv_mass, bending[0], bending[1], 2, closed)
    if flags[THROWER]:
        add_thrower(x, v, acc, inv_mass, thrower, g)
    if flags[GUIDES]:
        add_guides(x, v, acc, guides, thrower, flags[THROWER] != 0, g)


@njit(cache=True, error_model="numpy")
def box_accelerations(x, v, acc_box, forces):
    """Overwrite ``acc_box`` (D, N) with the thrower's and guides' part of the acceleration [m/s^2] alone.

    The energy ledger books their work separately from the conservative forces'; zero when neither is on.
    """
    inv_mass, flags, spring, bending, gravity, thrower, guides = forces
    acc_box[:] = 0.0
    g = gravity[0] if flags[GRAVITY] else 0.0
    if flags[THROWER]:
        add_thrower(x, v, acc_box, inv_mass, thrower, g)
    if flags[GUIDES]:
        add_guides(x, v, acc_box, guides, thrower, flags[THROWER] != 0, g)


@njit(cache=True, error_model="numpy")
def _springs_energy_and_stretch(x, k, rest, stride, closed):
    dim, n = x.shape
    count = n if closed else n - stride
    energy = 0.0
    worst = 0.0
    where = -1
    for i in range(count):
        j = i + stride
        if j >= n:
            j -= n
        r2 = 0.0
        for d in range(dim):
            delta = x[d, j] - x[d, i]
            r2 += delta * delta
        r = np.sqrt(r2)
        energy += 0.5 * k * (r - rest) * (r - rest)
        if not r <= worst:  # also catches NaN
            worst = r
            where = i
    return energy, worst / rest, where


@njit(cache=True, error_model="numpy")
def mechanical_energy(x, v, mass, forces):
    """(kinetic + spring + bending + gravitational energy [J], largest spring length / rest length, its node).

    Checked every few steps by the run loop to catch a blow-up (runaway energy or an insane stretch).
    """
    inv_mass, flags, spring, bending, gravity, thrower, guides = forces
    dim, n = x.shape
    closed = spring[2] != 0.0
    e, stretch, node = _springs_energy_and_stretch(x, spring[0], spring[1], 1, closed)
    if flags[BENDING]:
        e += _springs_energy_and_stretch(x, bending[0], bending[1], 2, closed)[0]
    g = gravity[0] if flags[GRAVITY] else 0.0
    for i in range(n):
        v2 = 0.0
        for d in range(dim):
            v2 += v[d, i] * v[d, i]
        e += 0.5 * mass[i] * v2 + mass[i] * g * x[1, i]
    return e, stretch, node
