"""The force terms, in the order the kernel adds them: the one list a new term joins.

``TERMS`` lists each term's :class:`~ropesim.model.forces.Term` record (its parameters and Python hooks);
:class:`ModelParams` is the bundle of every term's parameters that the compiled code receives; and the
compiled functions below call each term's kernel behind its flag. The rope's springs are always on; every
other term runs only when the scene declares it, and an undeclared term receives empty parameters of the
same types, so every scene compiles to one signature and reloads from Numba's cache.

Compiled entry points, each the term list in one form:

- :func:`accelerations`: every term's acceleration (all integrators; drag excluded, see
  :mod:`ropesim.model.forces`);
- :func:`applied_accelerations`: the non-conservative terms' part alone (``Term.applied``), whose work the
  energy ledger books as ``box_work``;
- :func:`mechanical_energy`: kinetic plus the conservative terms' energy (``Term.energy``), for the blow-up
  check;
- :func:`coupling_jacobian` and :func:`node_jacobian`: each term's blocks of the stiff integrator's Newton
  matrix (:mod:`ropesim.model.jacobian`), couplings between nodes and node-local blocks.
"""

from collections import namedtuple

import numpy as np
from numba import njit

from .forces.gravity import GRAVITY as GRAVITY_TERM
from .forces.guides import GUIDES as GUIDES_TERM
from .forces.guides import add_guides, add_guides_jacobian
from .forces.springs import BENDING as BENDING_TERM
from .forces.springs import ROPE
from .forces.springs import add_pair_springs, set_chain_springs
from .forces.thrower import THROWER as THROWER_TERM
from .forces.thrower import add_thrower, add_thrower_jacobian
from .jacobian import pair_spring_blocks

TERMS = (ROPE, BENDING_TERM, GRAVITY_TERM, THROWER_TERM, GUIDES_TERM)

# Positions in ModelParams.flags (uint8), one per optional term: each Term's ``flag``.
BENDING, GRAVITY, THROWER, GUIDES = BENDING_TERM.flag, GRAVITY_TERM.flag, THROWER_TERM.flag, GUIDES_TERM.flag
N_FLAGS = 4

ModelParams = namedtuple("ModelParams", ["inv_mass", "flags", "spring", "bending", "gravity", "thrower", "guides"])
"""What the compiled code knows of the model's forces: 1 / m per node (N,), the on/off flags (N_FLAGS,) and
each term's parameters, in TERMS order (see each term's module for its layout)."""


def model_params(scene, mass: np.ndarray) -> ModelParams:
    """Every term's parameters for ``scene`` (empty ones for the terms it does not declare) and the flags."""
    flags = np.zeros(N_FLAGS, dtype=np.uint8)
    values = []
    for term in TERMS:
        declared = term.declared(scene)
        if declared and term.flag is not None:
            flags[term.flag] = 1
        values.append(term.params(scene, mass) if declared else term.empty())
    return ModelParams(1.0 / mass, flags, *values)


def declared_terms(scene) -> tuple:
    """The scene's terms, in TERMS order."""
    return tuple(term for term in TERMS if term.declared(scene))


def coupling_reach(scene) -> int:
    """How far along the rope the scene's terms couple nodes (the Newton matrix's block half-width)."""
    return max(term.reach for term in declared_terms(scene))


@njit(cache=True, error_model="numpy")
def accelerations(x, v, acc, p):
    """Overwrite ``acc`` (D, N) with the acceleration [m/s^2] of every node, drag excluded."""
    closed = p.spring[2] != 0.0
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    set_chain_springs(x, acc, p.inv_mass, p.spring[0], p.spring[1], closed, g)  # overwrites acc; gravity included
    if p.flags[BENDING]:
        add_pair_springs(x, acc, p.inv_mass, p.bending[0], p.bending[1], 2, closed)
    if p.flags[THROWER]:
        add_thrower(x, v, acc, p.inv_mass, p.thrower, g)
    if p.flags[GUIDES]:
        add_guides(x, v, acc, p.guides, p.thrower, p.flags[THROWER] != 0, g)


@njit(cache=True, error_model="numpy")
def applied_accelerations(x, v, out, p):
    """Overwrite ``out`` (D, N) with the non-conservative terms' part of the acceleration [m/s^2] alone (the
    thrower's and guides'); zero when none is on. The energy ledger books their work as ``box_work``."""
    out[:] = 0.0
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    if p.flags[THROWER]:
        add_thrower(x, v, out, p.inv_mass, p.thrower, g)
    if p.flags[GUIDES]:
        add_guides(x, v, out, p.guides, p.thrower, p.flags[THROWER] != 0, g)


@njit(cache=True, error_model="numpy", inline="always")
def any_applied(flags):
    """True when a non-conservative term (``Term.applied``: the thrower, the guides) is on."""
    return flags[THROWER] != 0 or flags[GUIDES] != 0


def has_applied(p: ModelParams) -> bool:
    """:func:`any_applied`, from Python without compiling."""
    return bool(p.flags[THROWER] or p.flags[GUIDES])


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
def mechanical_energy(x, v, mass, p):
    """(kinetic + spring + bending + gravitational energy [J], largest spring length / rest length, its node).

    Checked every few steps by the run loop to catch a blow-up (runaway energy or an insane stretch).
    """
    dim, n = x.shape
    closed = p.spring[2] != 0.0
    e, stretch, node = _springs_energy_and_stretch(x, p.spring[0], p.spring[1], 1, closed)
    if p.flags[BENDING]:
        e += _springs_energy_and_stretch(x, p.bending[0], p.bending[1], 2, closed)[0]
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    for i in range(n):
        v2 = 0.0
        for d in range(dim):
            v2 += v[d, i] * v[d, i]
        e += 0.5 * mass[i] * v2 + mass[i] * g * x[1, i]
    return e, stretch, node


@njit(cache=True, error_model="numpy")
def coupling_jacobian(x, jac, scale, free, p):
    """Add ``scale`` times the coupling terms' stiffness (the rope's springs, bending) to ``jac``."""
    closed = p.spring[2] != 0.0
    pair_spring_blocks(x, jac, p.spring[0], p.spring[1], 1, closed, scale, free)
    if p.flags[BENDING]:
        pair_spring_blocks(x, jac, p.bending[0], p.bending[1], 2, closed, scale, free)


@njit(cache=True, error_model="numpy")
def node_jacobian(x, v, band, beta, mass, free, p):
    """Add the node-local terms' blocks (the thrower's, the guides') to the Newton matrix's ``band``, for a
    stage of coefficient beta = gamma h (see :mod:`ropesim.model.jacobian`)."""
    if p.flags[THROWER]:
        add_thrower_jacobian(x, band, beta, mass, free, p.thrower)
    if p.flags[GUIDES]:
        add_guides_jacobian(x, v, band, beta, mass, free, p.guides, p.thrower, p.flags[THROWER] != 0)
