"""Added mass: the fluid a node drags along when it accelerates.

Node i's mass matrix is M_i = m_i I + A_i with A_i = a_n (I - q q^T) + a_t q q^T, q the node tangent (see
:mod:`ropesim.model.forces.fluid`), a_n = rho V Ca_n and a_t = rho V Ca_t for the rope's share of volume V
(MoorDyn's Ca and CaAx), plus rho Ca V of a body on the node in every direction. Given the net force F, the
acceleration is a = M^-1 F, here (m + a_n)^-1 (F - (F . q) q) + (m + a_t)^-1 (F . q) q: the post-pass
:func:`apply_added_mass` turns the accelerations F / m that every other term computed into that. The fluid's
inertial force on the node is F_a = m a - F; its power is booked as fluid work. Held nodes have no added mass
(their motion is prescribed). Parameters: (2, N) a_n and a_t per node [kg].
"""

from __future__ import annotations

import math

import numpy as np

from . import Term
from ..layout import line_volumes, lumped_bodies, per_node
from .fluid import node_tangent
from .. import jit

WITH_ADDED_MASS = jit.Switch("added_mass", "the fluid's added mass")


@jit.kernel
def apply_added_mass(x, v, acc, added, inv_mass, around):
    """Turn ``acc`` (D, N), each node's F / m, into M^-1 F (see the module doc); returns the power [W] of the
    fluid's inertial force m a - F on the nodes moving at ``v``."""
    dim, n = x.shape
    power = 0.0
    for i in range(n):
        a_n, a_t = added[0, i], added[1, i]
        if a_n == 0.0 and a_t == 0.0:
            continue
        m = 1.0 / inv_mass[i]
        qx, qy, qz = node_tangent(x, i, around)
        az = acc[2, i] if dim == 3 else 0.0
        along = acc[0, i] * qx + acc[1, i] * qy + az * qz          # F . q / m
        normal_scale = m / (m + a_n)
        along_scale = m / (m + a_t)
        nx = normal_scale * (acc[0, i] - along * qx) + along_scale * along * qx
        ny = normal_scale * (acc[1, i] - along * qy) + along_scale * along * qy
        power += m * ((nx - acc[0, i]) * v[0, i] + (ny - acc[1, i]) * v[1, i])
        acc[0, i] = nx
        acc[1, i] = ny
        if dim == 3:
            nz = normal_scale * (az - along * qz) + along_scale * along * qz
            power += m * (nz - az) * v[2, i]
            acc[2, i] = nz
    return power


@jit.kernel
def add_added_mass_jacobian(x, band, added, free, around):
    """Add each free node's added-mass block A_i = a_n (I - q q^T) + a_t q q^T to the Newton matrix's band (the
    stiff integrator's residual carries M_i = m_i I + A_i; the tangent is frozen in this block)."""
    dim, n = x.shape
    for i in range(n):
        if not free[i] or (added[0, i] == 0.0 and added[1, i] == 0.0):
            continue
        q = node_tangent(x, i, around)
        for a in range(dim):
            for b in range(a + 1):
                qq = q[a] * q[b]
                band[a - b, i * dim + b] += added[0, i] * ((1.0 if a == b else 0.0) - qq) + added[1, i] * qq


@jit.kernel
def added_mass_times(x, i, w0, w1, w2, added, around):
    """A_i w for node i (the added-mass matrix times a vector (w0, w1, w2)), as a tuple."""
    q = node_tangent(x, i, around)
    along = w0 * q[0] + w1 * q[1] + w2 * q[2]
    a_n, a_t = added[0, i], added[1, i]
    return (a_n * (w0 - along * q[0]) + a_t * along * q[0], a_n * (w1 - along * q[1]) + a_t * along * q[1],
            a_n * (w2 - along * q[2]) + a_t * along * q[2])


def _params(scene, layout) -> np.ndarray:
    n = len(layout.mass)
    added = np.zeros((2, n))
    if scene.added_mass is not None:
        rope_volume = line_volumes(layout.lines, layout.node_length)
        added[0] = scene.fluid.density * per_node(layout.lines, n, [line.ca_normal for line in layout.lines]) * rope_volume
        added[1] = scene.fluid.density * per_node(layout.lines, n, [line.ca_tangential for line in layout.lines]) \
            * rope_volume
    for body in lumped_bodies(scene, layout.lines):
        if body.ca > 0:
            added[:, body.node] += scene.fluid.density * body.ca * body.volume
    added[:, layout.held] = 0.0
    return added


ADDED_MASS_TERM = Term("added_mass", WITH_ADDED_MASS, _params, lambda: np.zeros((2, 0)), ledger="fluid", velocity=True,
                       active=lambda scene: scene.added_mass is not None or any(b.ca > 0 for b in lumped_bodies(scene)))
"""Added mass (it needs no force of its own: it changes how every force accelerates a node)."""
