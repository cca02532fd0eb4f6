"""The force terms, in the order the kernel adds them: the one list a new term joins.

``TERMS`` lists each term's :class:`~ropesim.model.forces.Term` record (its parameters and Python hooks);
:class:`ModelParams` is the bundle of every term's parameters that the compiled code receives; and the
compiled functions below call each term's kernel behind its flag. The rope's springs are always on; every
other term runs only when the scene declares it, and an undeclared term receives empty parameters of the
same types, so every scene compiles to one signature and reloads from Numba's cache.

Compiled entry points, each the term list in one form:

- :func:`accelerations`: every term's force / m (all integrators; the linear [drag] b v and added mass
  excluded, see :mod:`ropesim.model.forces`), returning the power of the fluid and internal-damping terms;
- :func:`position_accelerations` and :func:`velocity_accelerations`: the same terms split into those that
  depend on positions alone and those that depend on velocities (the splitting schemes' RK4 kicks evaluate
  the second kind several times at frozen positions);
- :func:`added_mass`: the post-pass a = M^-1 F of the added-mass term;
- :func:`applied_accelerations`: the thrower's and guides' part alone, whose work the ledger books as
  ``box_work``;
- :func:`mechanical_energy`: kinetic plus the conservative terms' energy, for the blow-up check;
- :func:`coupling_jacobian` and :func:`node_jacobian`: each term's blocks of the stiff integrator's Newton
  matrix (:mod:`ropesim.model.jacobian`), couplings between nodes and node-local blocks, assembled with the
  mass by :func:`newton_matrix`.
"""

from collections import namedtuple

import numpy as np

from .forces.added_mass import ADDED_MASS_TERM, add_added_mass_jacobian, apply_added_mass
from .forces.bending import EI_TERM, add_ei_bending, add_ei_jacobian, ei_energy
from .forces.buoyancy import BUOYANCY_TERM, add_buoyancy
from .forces.fluid import (BODY_DRAG_TERM, FLOW_PUSH_TERM, FLOW_TERM, FLUID_DRAG_TERM, VISCOUS_DRAG_TERM,
                           add_fluid_forces, add_fluid_jacobian)
from .forces.flow_inertia import FLOW_INERTIA_TERM, add_flow_inertia
from .forces.gravity import GRAVITY as GRAVITY_TERM
from .forces.guides import GUIDES as GUIDES_TERM
from .forces.guides import add_guides, add_guides_jacobian
from .forces.springs import AXIAL_DAMPING as AXIAL_DAMPING_TERM
from .forces.springs import BENDING as BENDING_TERM
from .forces.springs import ROPE
from .forces.springs import add_axial_damping, add_pair_springs, set_chain_springs
from .forces.seabed import (SEABED_TERM, add_seabed_contact, add_seabed_friction, add_seabed_jacobian,
                            seabed_energy)
from .forces.thrower import THROWER as THROWER_TERM
from .forces.thrower import add_thrower, add_thrower_jacobian
from .jacobian import pair_damper_blocks, pair_spring_blocks
from . import jit

TERMS = (ROPE, BENDING_TERM, GRAVITY_TERM, BUOYANCY_TERM, THROWER_TERM, GUIDES_TERM, AXIAL_DAMPING_TERM,
         FLUID_DRAG_TERM, VISCOUS_DRAG_TERM, BODY_DRAG_TERM, FLOW_TERM, FLOW_PUSH_TERM, ADDED_MASS_TERM, SEABED_TERM,
         EI_TERM, FLOW_INERTIA_TERM)

# Positions in ModelParams.flags (uint8), one per optional term: each Term's ``flag``.
BENDING, GRAVITY, THROWER, GUIDES = BENDING_TERM.flag, GRAVITY_TERM.flag, THROWER_TERM.flag, GUIDES_TERM.flag
AXIAL_DAMPING, BUOYANCY = AXIAL_DAMPING_TERM.flag, BUOYANCY_TERM.flag
FLUID_DRAG, VISCOUS_DRAG, BODY_DRAG = FLUID_DRAG_TERM.flag, VISCOUS_DRAG_TERM.flag, BODY_DRAG_TERM.flag
FLOW, FLOW_PUSH, ADDED_MASS = FLOW_TERM.flag, FLOW_PUSH_TERM.flag, ADDED_MASS_TERM.flag
SEABED, EI_BENDING, FLOW_INERTIA = SEABED_TERM.flag, EI_TERM.flag, FLOW_INERTIA_TERM.flag
N_FLAGS = 15

ModelParams = namedtuple("ModelParams", [
    "inv_mass", "flags", "node_length", "spring", "bending", "gravity", "buoyancy", "thrower", "guides", "axial",
    "fluid_drag", "viscous_drag", "body_drag", "flow", "flow_push", "added_mass", "seabed", "bending_ei",
    "flow_inertia"])
"""What the compiled code knows of the model's forces: 1 / m per node (N,), the on/off flags (N_FLAGS,), each
node's share of unstretched length (N,) [m], and each term's parameters, in TERMS order (see each term's
module for its layout)."""

Layout = namedtuple("Layout", ["mass", "held", "node_length"])
"""What a term's ``params`` builder gets besides the scene: per-node mass [kg], held (bool) and length [m]."""


def model_params(scene, layout: Layout) -> ModelParams:
    """Every term's parameters for ``scene`` (empty ones for the terms it does not switch on) and the flags."""
    flags = np.zeros(N_FLAGS, dtype=np.uint8)
    values = []
    for term in TERMS:
        declared = term.declared(scene)
        if declared and term.flag is not None:
            flags[term.flag] = 1
        values.append(term.params(scene, layout) if declared else term.empty())
    return ModelParams(1.0 / layout.mass, flags, layout.node_length, *values)


def declared_terms(scene) -> tuple:
    """The scene's terms, in TERMS order."""
    return tuple(term for term in TERMS if term.declared(scene))


def coupling_reach(scene) -> int:
    """How far along the rope the scene's terms couple nodes (the Newton matrix's block half-width)."""
    return max(term.reach for term in declared_terms(scene))


def velocity_terms_on(p: ModelParams) -> bool:
    """True when a term beyond the thrower's and guides' depends on velocities (``Term.velocity``)."""
    return any(p.flags[t.flag] for t in TERMS if t.velocity)


def has_applied(p: ModelParams) -> bool:
    """:func:`any_applied`, from Python without compiling."""
    return bool(p.flags[THROWER] or p.flags[GUIDES])


@jit.kernel(inline="always")
def any_applied(flags):
    """True when a term of the ledger's ``box_work`` (the thrower, the guides) is on."""
    return flags[THROWER] != 0 or flags[GUIDES] != 0


@jit.kernel(inline="always")
def any_fluid(flags):
    """True when a term acting through the fluid (drag on the relative velocity, a flow's push) is on."""
    return (flags[FLUID_DRAG] != 0 or flags[VISCOUS_DRAG] != 0 or flags[BODY_DRAG] != 0
            or flags[FLOW_PUSH] != 0)


@jit.kernel(inline="always")
def position_accelerations(x, acc, p):
    """Overwrite ``acc`` (D, N) with the acceleration [m/s^2] of the terms that depend on positions alone.
    Inlined into its callers, as :func:`velocity_accelerations` is: a call hands over the whole parameter bundle
    by value, which cost rk4 20 % on a 21-node rope."""
    closed = p.spring[2] != 0.0
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    set_chain_springs(x, acc, p.inv_mass, p.spring[0], p.spring[1], closed, g, p.spring[3] != 0.0)
    if p.flags[BENDING]:
        add_pair_springs(x, acc, p.inv_mass, p.bending[0], p.bending[1], 2, closed)
    if p.flags[BUOYANCY]:
        add_buoyancy(acc, p.buoyancy)
    if p.flags[SEABED]:
        add_seabed_contact(x, acc, p.inv_mass, p.seabed)
    if p.flags[EI_BENDING]:
        add_ei_bending(x, acc, p.inv_mass, p.bending_ei, closed)


@jit.kernel(inline="always")
def velocity_accelerations(x, v, acc, p, t):
    """Add the acceleration [m/s^2] of the terms that depend on velocities or time (the thrower, the guides,
    axial damping, fluid forces, the accelerating water's, the seabed's damping and friction) at time t [s];
    returns the power [W] of the fluid, of the axial damping and of the seabed."""
    closed = p.spring[2] != 0.0
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    if p.flags[THROWER]:
        add_thrower(x, v, acc, p.inv_mass, p.thrower, g)
    if p.flags[GUIDES]:
        add_guides(x, v, acc, p.guides, p.thrower, p.flags[THROWER] != 0, g)
    internal = 0.0
    if p.flags[AXIAL_DAMPING]:
        internal = add_axial_damping(x, v, acc, p.inv_mass, p.axial[0], closed)
    fluid = 0.0
    if any_fluid(p.flags):
        fluid = add_fluid_forces(x, v, acc, p, t)
    if p.flags[FLOW_INERTIA]:
        fluid += add_flow_inertia(x, v, acc, p.inv_mass, p.flow_inertia, p.flow, t, closed)
    seabed = 0.0
    if p.flags[SEABED]:
        seabed = add_seabed_friction(x, v, acc, p.inv_mass, p.seabed, closed)
    return fluid, internal, seabed


@jit.kernel
def accelerations(x, v, acc, p, t):
    """Overwrite ``acc`` (D, N) with every term's force / m [m/s^2] at time t [s], the linear [drag] b v and
    added mass excluded; returns the power [W] of the fluid, the axial damping and the seabed."""
    position_accelerations(x, acc, p)
    return velocity_accelerations(x, v, acc, p, t)


@jit.kernel
def added_mass(x, v, acc, p):
    """With added mass on, turn ``acc`` (every force / m, drag included) into M^-1 F; returns the power [W] of
    the fluid's inertial force (0 without added mass)."""
    if p.flags[ADDED_MASS]:
        return apply_added_mass(x, v, acc, p.added_mass, p.inv_mass, p.spring[2] != 0.0)
    return 0.0


@jit.kernel
def applied_accelerations(x, v, out, p):
    """Overwrite ``out`` (D, N) with the non-conservative terms' part of the acceleration [m/s^2] alone (the
    thrower's and guides'); zero when none is on. The energy ledger books their work as ``box_work``."""
    out[:] = 0.0
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    if p.flags[THROWER]:
        add_thrower(x, v, out, p.inv_mass, p.thrower, g)
    if p.flags[GUIDES]:
        add_guides(x, v, out, p.guides, p.thrower, p.flags[THROWER] != 0, g)


@jit.kernel
def _springs_energy_and_stretch(x, k, rest, stride, closed, slack):
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
        if not (slack and r < rest):
            energy += 0.5 * k * (r - rest) * (r - rest)
        if not r <= worst:  # also catches NaN
            worst = r
            where = i
    return energy, worst / rest, where


@jit.kernel
def mechanical_energy(x, v, mass, p):
    """(kinetic + spring + bending + gravitational + buoyancy energy [J], largest spring length / rest length,
    its node). Checked every few steps by the run loop to catch a blow-up (runaway energy or an insane
    stretch)."""
    dim, n = x.shape
    closed = p.spring[2] != 0.0
    e, stretch, node = _springs_energy_and_stretch(x, p.spring[0], p.spring[1], 1, closed, p.spring[3] != 0.0)
    if p.flags[BENDING]:
        e += _springs_energy_and_stretch(x, p.bending[0], p.bending[1], 2, closed, False)[0]
    if p.flags[SEABED]:
        e += seabed_energy(x, p.seabed)
    if p.flags[EI_BENDING]:
        e += ei_energy(x, p.bending_ei, closed)
    g = p.gravity[0] if p.flags[GRAVITY] else 0.0
    buoyant = p.flags[BUOYANCY] != 0
    for i in range(n):
        v2 = 0.0
        for d in range(dim):
            v2 += v[d, i] * v[d, i]
        e += 0.5 * mass[i] * v2 + mass[i] * g * x[1, i]
        if buoyant:
            e -= mass[i] * p.buoyancy[i] * x[1, i]
    return e, stretch, node


@jit.kernel
def coupling_jacobian(x, jac, beta, free, p):
    """Add the coupling terms' blocks for a stage of coefficient beta = gamma h: beta^2 times the springs' and
    bending's stiffness, beta times the axial damping."""
    closed = p.spring[2] != 0.0
    scale = beta * beta
    pair_spring_blocks(x, jac, p.spring[0], p.spring[1], 1, closed, scale, free, p.spring[3] != 0.0)
    if p.flags[BENDING]:
        pair_spring_blocks(x, jac, p.bending[0], p.bending[1], 2, closed, scale, free, False)
    if p.flags[AXIAL_DAMPING]:
        pair_damper_blocks(x, jac, p.axial[0], closed, beta, free)
    if p.flags[EI_BENDING]:
        add_ei_jacobian(x, jac, beta, free, p.bending_ei, p.spring[1], closed)


@jit.kernel
def node_jacobian(x, v, band, beta, mass, free, p, t):
    """Add the node-local terms' blocks (the thrower's, the guides', the fluid's, added mass) to the Newton
    matrix's ``band``, for a stage of coefficient beta = gamma h at time t (see :mod:`ropesim.model.jacobian`)."""
    if p.flags[THROWER]:
        add_thrower_jacobian(x, band, beta, mass, free, p.thrower)
    if p.flags[GUIDES]:
        add_guides_jacobian(x, v, band, beta, mass, free, p.guides, p.thrower, p.flags[THROWER] != 0)
    if p.flags[FLUID_DRAG] or p.flags[VISCOUS_DRAG] or p.flags[BODY_DRAG]:
        add_fluid_jacobian(x, v, band, beta, free, p, t)
    if p.flags[ADDED_MASS]:
        add_added_mass_jacobian(x, band, p.added_mass, free, p.spring[2] != 0.0)
    if p.flags[SEABED]:
        add_seabed_jacobian(x, v, band, beta, free, p.seabed, True)


@jit.kernel
def newton_matrix(x, v, jac, beta, nodes, p, t):
    """The matrix M (1 + beta gamma) + beta^2 H + beta C_v into ``jac`` (:mod:`ropesim.model.jacobian`): the
    mass and linear drag on the diagonal, then every term's blocks. ``nodes`` = (free (N,) bool, mass (N,),
    linear drag b (N,)); a held node's rows are the identity. The stiff integrator's Newton matrix for a stage
    of coefficient beta = gamma h, and the static solver's with beta its pseudo-time step."""
    free, mass, drag = nodes
    band, corner = jac.band, jac.corner
    dim, n = x.shape
    band[:] = 0.0
    corner[:] = 0.0
    coupling_jacobian(x, jac, beta, free, p)
    for i in range(n):
        if not free[i]:
            for d in range(dim):
                band[0, i * dim + d] = 1.0
                for e in range(d + 1, dim):
                    band[e - d, i * dim + d] = 0.0
            continue
        diag = mass[i] + beta * drag[i]
        for d in range(dim):
            band[0, i * dim + d] += diag
    node_jacobian(x, v, band, beta, mass, free, p, t)
