"""The compiled ends of a coupling step (:mod:`ropesim.coupling`): moving the coupled objects, and their forces.

A coupling step is one call of :func:`begin_step`, the integrator's loop, and one call of :func:`held_forces`
(on the accelerations of the loop's last force evaluation, when its method's last one is at the step's end time)
or of :func:`end_forces` (which evaluates them at the end state first), each entered without Numba's type
dispatch (:class:`ropesim.model.jit.Direct`), so that a coupling step of one internal step costs little more than
the step.

The coupled objects, K of them, in the layout of the coupling's arrays (``Objects``): ``kind`` (K,) 0 for a
point, 1 for a body; ``first`` (K,) its first degree of freedom; ``body`` (K,) a body's column among the bodies
that move their points rigidly (:mod:`ropesim.model.motion`), -1 for a point; ``rows`` its held rows
``held_rows[row_start[k]:row_start[k + 1]]`` (a point's line ends; a body's attachments); ``dof_rows`` a body's
degrees of freedom among a driven body's six rows ((0, 1, 2, 3, 4, 5) in 3-D, (0, 1, 5) in 2-D).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from . import jit
from .motion import WITH_RIGID_MOTION, place_moving
from .terms import WITH_MOTION, accelerations

Objects = namedtuple("Objects", ["kind", "first", "body", "row_start", "held_rows", "dof_rows"])

POINT, BODY = 0, 1


@jit.kernel
def begin_step(t0, positions, velocities, objects, held, x, v):
    """Move every coupled object on positions + velocities (t - t0) from time t0 [s] (a point's line ends
    through the held nodes' x0 + V t, a body through its rigid motion's pose at t = 0 and rates), then put every
    held node where its motion puts it at t0 (velocities too). Returns -1, or, moving nothing, the first value
    that is not a finite number: k for positions[k], K + k for velocities[k] (K values each)."""
    count = positions.shape[0]
    for k in range(count):
        if not np.isfinite(positions[k]):
            return k
    for k in range(count):
        if not np.isfinite(velocities[k]):
            return count + k
    idx, x0, hv, m = held
    dim = x.shape[0]
    for k in range(objects.kind.shape[0]):
        f = objects.first[k]
        if objects.kind[k] == POINT:
            for r in range(objects.row_start[k], objects.row_start[k + 1]):
                j = objects.held_rows[r]
                for d in range(dim):
                    x0[d, j] = positions[f + d] - velocities[f + d] * t0
                    hv[d, j] = velocities[f + d]
                    m.base[d, j] = velocities[f + d]
        elif WITH_RIGID_MOTION:
            b = objects.body[k]
            for q in range(objects.dof_rows.shape[0]):
                row = objects.dof_rows[q]
                m.bodies.accel[row, b] = positions[f + q] - velocities[f + q] * t0
                m.bodies.base[row, b] = velocities[f + q]
    if WITH_MOTION:
        place_moving(x, v, held, t0, t0)
    else:
        for j in range(idx.shape[0]):
            i = idx[j]
            for d in range(dim):
                x[d, i] = x0[d, j] + hv[d, j] * t0
                v[d, i] = hv[d, j]
    return -1


@jit.kernel
def end_forces(x, v, acc, params, t, mass, objects, held, out):
    """:func:`held_forces` of the accelerations at state (x, v) and time t, evaluated into ``acc``."""
    accelerations(x, v, acc, params, t)
    m = held.motion
    if WITH_RIGID_MOTION:
        held_forces(x, acc, t, mass, objects, held.idx, m.bodies.accel, m.bodies.base, out)
    else:
        held_forces(x, acc, t, mass, objects, held.idx, m.base, m.base, out)


@jit.kernel
def held_forces(x, acc, t, mass, objects, idx, pose0, rates, out):
    """Write into ``out`` the force on each coupled point, and the force and moment about its reference point
    on each coupled body, at time t: the net force m acc of every term on their held nodes ``idx`` (accelerations
    ``acc`` of an evaluation at time t, held nodes at x), without their inertia (a system's nodes have no linear
    [drag]). A body's reference point is at pose0 + rates t (the rigid motion's first three rows; unread without
    rigid motion). It takes these arrays rather than the held nodes' bundle: a compiled call unpacks every array it
    is handed, and the bundle holds some twenty."""
    dim = x.shape[0]
    for k in range(objects.kind.shape[0]):
        f = objects.first[k]
        fx = fy = fz = mx = my = mz = 0.0
        rx = ry = rz = 0.0
        if WITH_RIGID_MOTION and objects.kind[k] == BODY:
            b = objects.body[k]
            rx = pose0[0, b] + rates[0, b] * t
            ry = pose0[1, b] + rates[1, b] * t
            if dim == 3:
                rz = pose0[2, b] + rates[2, b] * t
        for r in range(objects.row_start[k], objects.row_start[k + 1]):
            i = idx[objects.held_rows[r]]
            gx = mass[i] * acc[0, i]
            gy = mass[i] * acc[1, i]
            gz = mass[i] * acc[2, i] if dim == 3 else 0.0
            fx += gx
            fy += gy
            fz += gz
            ax = x[0, i] - rx
            ay = x[1, i] - ry
            az = x[2, i] - rz if dim == 3 else 0.0
            mx += ay * gz - az * gy
            my += az * gx - ax * gz
            mz += ax * gy - ay * gx
        out[f] = fx
        out[f + 1] = fy
        if dim == 3:
            out[f + 2] = fz
        if objects.kind[k] == BODY:
            if dim == 3:
                out[f + 3] = mx
                out[f + 4] = my
                out[f + 5] = mz
            else:
                out[f + 2] = mz
