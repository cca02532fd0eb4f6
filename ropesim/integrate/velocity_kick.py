"""The splitting schemes' kick when forces depend on velocity: four RK4 sub-stages at frozen positions.

A kick of length tau solves v' = f(v) with the positions frozen: f(v) = M^-1 F(x, v), F every force (the
position-only part computed once, the velocity-dependent part, fluid drag, axial damping, the thrower and
guides, the linear drag -b v, at each sub-stage) and M the mass with added mass (:mod:`ropesim.model.forces.
added_mass`). One classical RK4 step over tau has local error O(tau^5), so the composition keeps each
scheme's order up to 4 (a plain kick, an explicit Euler step in v, would drop every scheme to first order; the
exact drag kick of the splitting loop needs forces linear in v). It is explicit in v: stable while the
largest velocity-damping rate lambda satisfies lambda |c| h < 2.78 for every kick coefficient c (the
stability bound includes it, see :func:`ropesim.analysis.stability.predicted_dt`).

The ledger books each flow with the same RK4 quadrature over the kick: the linear drag's loss b |v|^2, the
supports' power -m a . V on held nodes, and the power of the thrower's and guides', the fluid's and the
axial damping's forces. Held nodes keep their velocity V throughout.

Free rigid bodies are kicked with the nodes: their twist (v, w) is an RK4 unknown beside the node velocities, at
the frozen pose, its slope from the Newton-Euler solve (:mod:`ropesim.model.bodies`, the gyroscopic moment
w x I w included), and their attachment nodes take the velocity v + w x rho at every sub-stage and at the end.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from ..model.bodies import WITH_BODIES, place_attachments
from ..model.terms import (WITH_APPLIED, applied_accelerations, body_accelerations, solve_accelerations,
                           velocity_accelerations)
from ..model import jit

RK4_A = (0.0, 0.5, 0.5, 1.0)          # each sub-stage's offset along the kick, as a fraction of tau
RK4_B = (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0)

VelocityScratch = namedtuple("VelocityScratch", ["slopes", "y", "a", "a_box", "body_slopes", "body_y"])
"""The sub-stages' slopes (4, D, N), the sub-stage velocity (D, N), its acceleration (D, N) and the thrower's
and guides' part of it (D, N); the free bodies' slopes (4, 6, B) and sub-stage twist (6, B)."""


def velocity_scratch(dim: int, nodes: int, bodies: int = 0) -> VelocityScratch:
    """The scratch for ``nodes`` nodes and ``bodies`` free bodies (None in their place without any)."""
    return VelocityScratch(np.zeros((4, dim, nodes)), np.zeros((dim, nodes)), np.zeros((dim, nodes)),
                           np.zeros((dim, nodes)), np.zeros((4, 6, bodies)) if bodies else None,
                           np.zeros((6, bodies)) if bodies else None)


@jit.kernel
def velocity_kick(x, v, acc_x, tau, t, params, mass, gamma, held, scratch, bodies):
    """Kick ``v`` (and the free bodies' twists, ``bodies`` = (pose, twist)) over ``tau`` [s] at time ``t`` [s] by
    RK4 (see the module doc); ``acc_x`` (D, N) holds the position-only accelerations, ``gamma`` (N,) the linear
    drag rates b / m (0 at held nodes).

    Returns the energy [J] of each flow over the kick: (drag loss, held work, box work, fluid work, internal
    work, seabed work).
    """
    dim, n = x.shape
    slopes, y, a, a_box = scratch.slopes, scratch.y, scratch.a, scratch.a_box
    held_idx, held_v, motion = held.idx, held.v, held.motion
    drag = supports = box = fluid = internal = seabed = 0.0
    for s in range(4):
        c = RK4_A[s] * tau
        for d in range(dim):
            for i in range(n):
                y[d, i] = v[d, i] + c * slopes[s - 1, d, i] if s > 0 else v[d, i]
        if WITH_BODIES:
            for d in range(6):
                for b in range(bodies.twist.shape[1]):
                    scratch.body_y[d, b] = bodies.twist[d, b] + (c * scratch.body_slopes[s - 1, d, b] if s > 0
                                                                 else 0.0)
            place_attachments(x, y, params.bodies, bodies.pose, scratch.body_y)
        for d in range(dim):
            for i in range(n):
                a[d, i] = acc_x[d, i]
        p_fluid, p_internal, p_seabed = velocity_accelerations(x, y, a, params, t)
        p_support = 0.0
        for j in range(held_idx.shape[0]):
            i = held_idx[j]
            for d in range(dim):
                p_support -= mass[i] * (a[d, i] - motion.accel[d, j]) * held_v[d, j]
        p_drag = 0.0
        for d in range(dim):
            for i in range(n):
                a[d, i] -= gamma[i] * y[d, i]
                p_drag += gamma[i] * mass[i] * y[d, i] * y[d, i]
        p_fluid += solve_accelerations(x, y, a, params)
        if WITH_BODIES:
            p_fluid += body_accelerations(x, y, a, params, bodies.pose, scratch.body_y, scratch.body_slopes[s], t,
                                          s == 0)   # positions frozen: the bodies' mass matrices factored once
        p_box = 0.0
        if WITH_APPLIED:
            applied_accelerations(x, y, a_box, params)
            for d in range(dim):
                for i in range(n):
                    p_box += mass[i] * a_box[d, i] * y[d, i]
        for d in range(dim):
            for i in range(n):
                slopes[s, d, i] = a[d, i]
        for j in range(held_idx.shape[0]):
            for d in range(dim):
                slopes[s, d, held_idx[j]] = 0.0
        w = RK4_B[s] * tau
        drag += w * p_drag
        supports += w * p_support
        box += w * p_box
        fluid += w * p_fluid
        internal += w * p_internal
        seabed += w * p_seabed
    for d in range(dim):
        for i in range(n):
            v[d, i] += tau * (RK4_B[0] * slopes[0, d, i] + RK4_B[1] * slopes[1, d, i] + RK4_B[2] * slopes[2, d, i]
                              + RK4_B[3] * slopes[3, d, i])
    if WITH_BODIES:
        sl = scratch.body_slopes
        for d in range(6):
            for b in range(bodies.twist.shape[1]):
                bodies.twist[d, b] += tau * (RK4_B[0] * sl[0, d, b] + RK4_B[1] * sl[1, d, b] + RK4_B[2] * sl[2, d, b]
                                             + RK4_B[3] * sl[3, d, b])
        place_attachments(x, v, params.bodies, bodies.pose, bodies.twist)
    return drag, supports, box, fluid, internal, seabed
