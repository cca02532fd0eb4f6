"""The force terms, in the order the kernel adds them: the one list a new term joins.

``TERMS`` lists each term's :class:`~ropesim.model.forces.Term` record (its parameters and Python hooks);
:class:`ModelParams` is the bundle of every term's parameters that the compiled code receives; and the
compiled functions below call each term's kernel behind its compile-time switch (``if WITH_SEABED:``, the
term's :class:`~ropesim.model.jit.Switch`). The rope's springs are always on; every other term is compiled
and runs only when the scene declares it: :func:`switches` gives a scene's switches, and
:func:`ropesim.model.jit.specialise` the copy of a compiled function (and of every compiled function it
calls) with the undeclared terms' branches removed before Numba types them. An undeclared term receives
empty parameters of the same types, so the bundle has one layout for every scene.

Besides one switch per optional term there are two derived from the term records (:data:`WITH_VELOCITY_TERMS`,
:data:`WITH_APPLIED`), :data:`~ropesim.model.banded.WITH_WRAP_AROUND` for a closed loop's Newton matrix,
:data:`WITH_MOTION` for held nodes with a prescribed motion, and a sea's own (its waves, the evaluation they take,
the lines' fraction rule: :func:`ropesim.model.forces.sea.sea_switches`).

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

from .forces.added_mass import ADDED_MASS_TERM, WITH_ADDED_MASS, add_added_mass_jacobian, apply_added_mass
from .forces.bending import EI_TERM, WITH_EI_BENDING, add_ei_bending, add_ei_jacobian, ei_energy
from .forces.buoyancy import BUOYANCY_TERM, WITH_BUOYANCY, add_buoyancy
from .forces.fluid import (BODY_DRAG_TERM, FLOW_PUSH_TERM, FLOW_TERM, FLUID_DRAG_TERM, VISCOUS_DRAG_TERM,
                           WITH_BODY_DRAG, WITH_FLOW_PUSH, WITH_FLUID_DRAG, WITH_VISCOUS_DRAG, add_fluid_forces,
                           add_fluid_jacobian)
from .forces.flow_inertia import FLOW_INERTIA_TERM, WITH_FLOW_INERTIA, add_flow_inertia
from .forces.sea import SEA_TERM, WITH_SEA, add_sea_drag, add_sea_forces, add_sea_jacobian, sea_switches, water_state
from .forces.gravity import GRAVITY as GRAVITY_TERM
from .forces.gravity import WITH_GRAVITY
from .forces.guides import GUIDES as GUIDES_TERM
from .forces.guides import WITH_GUIDES, add_guides, add_guides_jacobian
from .forces.springs import AXIAL_DAMPING as AXIAL_DAMPING_TERM
from .forces.springs import BENDING as BENDING_TERM
from .forces.springs import ROPE, WITH_AXIAL_DAMPING, WITH_BENDING
from .forces.springs import add_axial_damping, add_pair_springs, set_chain_springs
from .forces.seabed import (SEABED_TERM, WITH_SEABED, add_seabed_contact, add_seabed_friction, add_seabed_jacobian,
                            seabed_energy)
from .forces.thrower import THROWER as THROWER_TERM
from .forces.thrower import WITH_THROWER, add_thrower, add_thrower_jacobian
from .banded import WITH_WRAP_AROUND
from .forces.fluid import neighbours
from .junctions import WITH_JUNCTIONS, junction_bundle, move_junctions, no_junctions
from .bodies import WITH_BODIES, bodies_bundle, body_energy, free_bodies, move_bodies, no_bodies
from .body_sea import WITH_BODY_SEA, body_sea_bundle
from .layout import junctions, line_layouts, line_table, point_ends
from .jacobian import pair_damper_blocks, pair_spring_blocks
from . import jit

TERMS = (ROPE, BENDING_TERM, GRAVITY_TERM, BUOYANCY_TERM, THROWER_TERM, GUIDES_TERM, AXIAL_DAMPING_TERM,
         FLUID_DRAG_TERM, VISCOUS_DRAG_TERM, BODY_DRAG_TERM, FLOW_TERM, FLOW_PUSH_TERM, ADDED_MASS_TERM, SEABED_TERM,
         EI_TERM, FLOW_INERTIA_TERM, SEA_TERM)

WITH_VELOCITY_TERMS = jit.Switch("velocity_terms", "a term beyond the thrower's and guides' depends on velocity "
                                                   "(Term.velocity)")
WITH_APPLIED = jit.Switch("applied", "a term whose work the ledger books as box_work (the thrower, the guides)")
WITH_MOTION = jit.Switch("motion", "a held node with a prescribed motion beyond x0 + V t")

ModelParams = namedtuple("ModelParams", [
    "inv_mass", "node_length", "lines", "neighbours", "junctions", "bodies", "spring", "bending", "gravity", "buoyancy",
    "thrower", "guides", "axial", "fluid_drag", "viscous_drag", "body_drag", "flow", "flow_push", "added_mass",
    "seabed", "bending_ei", "flow_inertia", "sea"])
"""What the compiled code knows of the model's forces: 1 / m per node (N,), each node's share of unstretched
length (N,) [m], the lines' nodes (L, 2) (first, one past the last: :func:`ropesim.model.layout.line_table`),
the nodes whose chord gives each node's tangent (2, N) (:func:`ropesim.model.forces.fluid.neighbours`), a
system's free points (:class:`ropesim.model.junctions.Junctions`) and free rigid bodies
(:class:`ropesim.model.bodies.Bodies`), and each term's parameters, in TERMS order (see each term's module for
its layout)."""

Layout = namedtuple("Layout", ["mass", "held", "node_length", "lines"])
"""What a term's ``params`` builder gets besides the scene: per-node mass [kg], held (bool) and length [m], and
the lines (:class:`ropesim.model.layout.LineLayout`)."""


def model_params(scene, layout: Layout) -> ModelParams:
    """Every term's parameters for ``scene`` (empty ones for the terms it does not switch on)."""
    values = [term.params(scene, layout) if term.declared(scene) else term.empty() for term in TERMS]
    n = len(layout.mass)
    around = np.tile(np.arange(n, dtype=np.int64), (2, 1))   # a node on no line: its own neighbour, no tangent
    for line in layout.lines:
        around[:, line.first:line.end] = neighbours(line.first, line.nodes, line.closed)
    added = values[TERMS.index(ADDED_MASS_TERM)]
    groups = junctions(scene, layout.lines)
    points = junction_bundle(groups, added) if groups else no_junctions()
    ends = point_ends(scene, layout.lines)
    bodies = bodies_bundle(scene, ends, added, layout.mass) if free_bodies(scene) else no_bodies()
    if bodies is not None and scene.sea is not None:   # free bodies under a free surface (model/body_sea.py)
        bodies = bodies._replace(sea=body_sea_bundle(scene, free_bodies(scene), values[TERMS.index(SEA_TERM)]))
    return ModelParams(1.0 / layout.mass, layout.node_length, line_table(layout.lines), around, points, bodies,
                       *values)


def declared_terms(scene) -> tuple:
    """The scene's terms, in TERMS order."""
    return tuple(term for term in TERMS if term.declared(scene))


def switches(scene) -> jit.Switches:
    """The compile-time switches of ``scene``'s terms: each declared term's, the two derived from their
    records (velocity-dependent terms, terms booked as box work), a closed loop's wrap-around in the Newton
    matrix, and a sea's own. :data:`WITH_MOTION` is the model's to add."""
    declared = declared_terms(scene)
    on = {term.switch.name for term in declared if term.switch is not None}
    if any(line.closed for line in line_layouts(scene)):
        on.add(WITH_WRAP_AROUND.name)
    if WITH_SEA.name in on:
        on |= sea_switches(scene)
    if junctions(scene):
        on.add(WITH_JUNCTIONS.name)
    if free_bodies(scene):
        on.add(WITH_BODIES.name)
        if scene.sea is not None:
            on.add(WITH_BODY_SEA.name)
    if any(term.velocity for term in declared) or junctions(scene) or free_bodies(scene):
        on.add(WITH_VELOCITY_TERMS.name)   # a junction's or a body's kick solves for its point or body
    if any(term.ledger == "box" for term in declared):
        on.add(WITH_APPLIED.name)
    return frozenset(on)


def coupling_reach(scene) -> int:
    """How far along the rope the scene's terms couple nodes (the Newton matrix's block half-width)."""
    return max(term.reach for term in declared_terms(scene))


@jit.kernel(inline="always")
def position_accelerations(x, acc, p):
    """Overwrite ``acc`` (D, N) with the acceleration [m/s^2] of the terms that depend on positions alone.
    Inlined into its callers, as :func:`velocity_accelerations` is: a call hands over the whole parameter bundle
    by value, which cost rk4 20 % on a 21-node rope."""
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    for line in range(p.lines.shape[0]):
        spring = p.spring[line]
        set_chain_springs(x, acc, p.inv_mass, spring[0], spring[1], spring[2] != 0.0, g, spring[3] != 0.0,
                          p.lines[line, 0], p.lines[line, 1])
    closed = p.spring[0, 2] != 0.0   # a loop is a rope of one line (second-neighbour springs are a rope's too)
    if WITH_BENDING:
        add_pair_springs(x, acc, p.inv_mass, p.bending[0], p.bending[1], 2, closed)
    if WITH_BUOYANCY:
        add_buoyancy(acc, p.buoyancy)
    if WITH_SEABED:
        add_seabed_contact(x, acc, p.inv_mass, p.seabed)
    if WITH_EI_BENDING:
        add_ei_bending(x, acc, p.inv_mass, p.bending_ei, closed)


@jit.kernel(inline="always")
def velocity_accelerations(x, v, acc, p, t):
    """Add the acceleration [m/s^2] of the terms that depend on velocities or time (the thrower, the guides,
    axial damping, fluid forces, the accelerating water's, the seabed's damping and friction) at time t [s];
    returns the power [W] of the fluid, of the axial damping and of the seabed."""
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    if WITH_THROWER:
        add_thrower(x, v, acc, p.inv_mass, p.thrower, g)
    if WITH_GUIDES:
        add_guides(x, v, acc, p.guides, p.thrower, WITH_THROWER, g)
    internal = 0.0
    if WITH_AXIAL_DAMPING:
        for line in range(p.lines.shape[0]):
            if p.axial[line] != 0.0:
                internal += add_axial_damping(x, v, acc, p.inv_mass, p.axial[line], p.spring[line, 2] != 0.0,
                                              p.lines[line, 0], p.lines[line, 1])
    fluid = 0.0
    if WITH_SEA:   # water below the surface, air above: drag split, buoyancy and inertia on the wet part
        water_state(x, p, t)
        if WITH_FLUID_DRAG or WITH_BODY_DRAG:
            fluid = add_sea_drag(x, v, acc, p)
        fluid += add_sea_forces(x, v, acc, p)
    elif WITH_FLUID_DRAG or WITH_VISCOUS_DRAG or WITH_BODY_DRAG or WITH_FLOW_PUSH:
        fluid = add_fluid_forces(x, v, acc, p, t)
    if WITH_FLOW_INERTIA:
        fluid += add_flow_inertia(x, v, acc, p.inv_mass, p.flow_inertia, p.flow, t, p.neighbours)
    seabed = 0.0
    if WITH_SEABED:
        seabed = add_seabed_friction(x, v, acc, p.inv_mass, p.seabed, p.neighbours)
    return fluid, internal, seabed


@jit.kernel
def accelerations(x, v, acc, p, t):
    """Overwrite ``acc`` (D, N) with every term's force / m [m/s^2] at time t [s], the linear [drag] b v and
    added mass excluded; returns the power [W] of the fluid, the axial damping and the seabed."""
    position_accelerations(x, acc, p)
    return velocity_accelerations(x, v, acc, p, t)


@jit.kernel
def solve_accelerations(x, v, acc, p):
    """Turn ``acc`` (every force / m, drag included) into the accelerations: M^-1 F at each node with added mass,
    and a system's free points moved as one (:mod:`ropesim.model.junctions`); returns the power [W] of the
    fluid's inertial force. Called wherever forces become accelerations, when either is on."""
    power = 0.0
    if WITH_ADDED_MASS:
        power += apply_added_mass(x, v, acc, p.added_mass, p.inv_mass, p.neighbours)
    if WITH_JUNCTIONS:
        power += move_junctions(x, v, acc, p.inv_mass, p.junctions, p.neighbours)
    return power


@jit.kernel(inline="always")
def body_accelerations(x, v, acc, p, pose, twist, out, t, moved=True):
    """The free bodies' accelerations into ``out`` (6, B) and their attachments' into ``acc``, from ``acc`` holding
    every force / m (:func:`ropesim.model.bodies.move_bodies`), the bodies at ``pose``, ``twist`` at time t [s];
    returns the power [W] of the fluid's forces on the bodies. Called after :func:`solve_accelerations`.
    ``moved`` False: the nodes and the poses are where they were at the last call (a velocity kick's sub-stage),
    so the bodies' mass matrices are too."""
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    return move_bodies(x, v, acc, p.inv_mass, p.neighbours, g, p.flow, p.bodies, pose, twist, out, t, moved)


@jit.kernel(inline="always")
def bodies_energy(p, pose, twist):
    """The free bodies' kinetic, gravitational and buoyancy energy [J] (:func:`ropesim.model.bodies.body_energy`)."""
    return body_energy(p.bodies, pose, twist, p.gravity[0] if WITH_GRAVITY else 0.0)


@jit.kernel
def applied_accelerations(x, v, out, p):
    """Overwrite ``out`` (D, N) with the non-conservative terms' part of the acceleration [m/s^2] alone (the
    thrower's and guides'); zero when none is on. The energy ledger books their work as ``box_work``."""
    out[:] = 0.0
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    if WITH_THROWER:
        add_thrower(x, v, out, p.inv_mass, p.thrower, g)
    if WITH_GUIDES:
        add_guides(x, v, out, p.guides, p.thrower, WITH_THROWER, g)


@jit.kernel
def _springs_energy_and_stretch(x, k, rest, stride, closed, slack, first, end):
    """(energy [J], largest length / rest length, its first node) of the springs (i, i + stride) of the line
    of nodes ``first`` .. ``end`` - 1."""
    dim, n = x.shape
    count = end - first if closed else end - first - stride
    energy = 0.0
    worst = 0.0
    where = -1
    for i in range(first, first + count):
        j = i + stride
        if j >= end:
            j -= end - first
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
    e, stretch, node = 0.0, 0.0, -1
    for line in range(p.lines.shape[0]):
        spring = p.spring[line]
        energy, worst, where = _springs_energy_and_stretch(x, spring[0], spring[1], 1, spring[2] != 0.0,
                                                           spring[3] != 0.0, p.lines[line, 0], p.lines[line, 1])
        e += energy
        if not worst <= stretch:   # also catches NaN
            stretch, node = worst, where
    closed = p.spring[0, 2] != 0.0   # a loop is a rope of one line
    if WITH_BENDING:
        e += _springs_energy_and_stretch(x, p.bending[0], p.bending[1], 2, closed, False, 0, n)[0]
    if WITH_SEABED:
        e += seabed_energy(x, p.seabed)
    if WITH_EI_BENDING:
        e += ei_energy(x, p.bending_ei, closed)
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    for i in range(n):
        v2 = 0.0
        for d in range(dim):
            v2 += v[d, i] * v[d, i]
        e += 0.5 * mass[i] * v2 + mass[i] * g * x[1, i]
        if WITH_BUOYANCY:
            e -= mass[i] * p.buoyancy[i] * x[1, i]
    return e, stretch, node


@jit.kernel(inline="always")
def coupling_jacobian(x, jac, beta, free, p):
    """Add the coupling terms' blocks for a stage of coefficient beta = gamma h: beta^2 times the springs' and
    bending's stiffness, beta times the axial damping."""
    scale = beta * beta
    for line in range(p.lines.shape[0]):
        spring = p.spring[line]
        pair_spring_blocks(x, jac, spring[0], spring[1], 1, spring[2] != 0.0, scale, free, spring[3] != 0.0,
                           p.lines[line, 0], p.lines[line, 1])
    closed = p.spring[0, 2] != 0.0   # a loop is a rope of one line
    if WITH_BENDING:
        pair_spring_blocks(x, jac, p.bending[0], p.bending[1], 2, closed, scale, free, False, 0, x.shape[1])
    if WITH_AXIAL_DAMPING:
        for line in range(p.lines.shape[0]):
            if p.axial[line] != 0.0:
                pair_damper_blocks(x, jac, p.axial[line], p.spring[line, 2] != 0.0, beta, free, p.lines[line, 0],
                                   p.lines[line, 1])
    if WITH_EI_BENDING:
        add_ei_jacobian(x, jac, beta, free, p.bending_ei, closed)


@jit.kernel(inline="always")
def node_jacobian(x, v, band, beta, mass, free, p, t):
    """Add the node-local terms' blocks (the thrower's, the guides', the fluid's, added mass) to the Newton
    matrix's ``band``, for a stage of coefficient beta = gamma h at time t (see :mod:`ropesim.model.jacobian`)."""
    if WITH_THROWER:
        add_thrower_jacobian(x, band, beta, mass, free, p.thrower)
    if WITH_GUIDES:
        add_guides_jacobian(x, v, band, beta, mass, free, p.guides, p.thrower, WITH_THROWER)
    if WITH_SEA:
        water_state(x, p, t)
        add_sea_jacobian(x, v, band, beta, free, p)
    elif WITH_FLUID_DRAG or WITH_VISCOUS_DRAG or WITH_BODY_DRAG:
        add_fluid_jacobian(x, v, band, beta, free, p, t)
    if WITH_ADDED_MASS:
        add_added_mass_jacobian(x, band, p.added_mass, free, p.neighbours)
    if WITH_SEABED:
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
