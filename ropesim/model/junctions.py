"""Free points where lines meet: their line ends move as one body.

A system's free point (a connector, a clump weight, a buoy on a bridle) holds the end nodes of its lines. They
stay together: one position, one velocity, one acceleration, that of the assembly under every force on any of
them (MoorDyn's free point: its own mass and forces plus each attached line's end node's, ``Point::doRHS``).
The point's own mass, volume and drag area are lumped at the first of these nodes
(:func:`ropesim.model.layout.lumped_bodies`). After the force terms have given each node its F_k / m_k, the
point's acceleration is

    a = (sum_k (m_k I + A_k))^-1 sum_k F_k,

A_k each node's added-mass matrix (its line's, along its tangent, and the point's own rho Ca V in every
direction), and every node of the point gets it. The nodes start together and every integrator moves them
alike from then on (the same velocity, kicked by the same acceleration), so they stay together to the last
bit without being copied. The power of the fluid's inertial force on the point, (sum_k m_k a - sum_k F_k) . v,
is booked as fluid work, as a node's added mass is.

The stiff integrator's Newton solve and the static solver treat a point's nodes as one: its junction's nodes
share one unknown, solved for through a Schur complement (:mod:`ropesim.model.schur`); the point's equation is
the sum of its nodes' (:func:`fold_junctions`), with the added mass this module keeps out of the per-node pass
(:func:`junction_added_mass_residual`, :func:`add_junction_added_mass_jacobian`).

Parameters: ``Junctions`` = (start (J + 1,) int64, nodes (K,) int64: junction j's nodes are
``nodes[start[j]:start[j + 1]]``, the point's own first; added (2, K): each node's added-mass coefficients
a_n and a_t [kg], which the per-node added-mass pass leaves to this one).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from . import jit
from .forces.fluid import node_tangent

WITH_JUNCTIONS = jit.Switch("junctions", "free points where line ends move together")

Junctions = namedtuple("Junctions", ["start", "nodes", "added"])


def junction_bundle(groups: list[list[int]], added: np.ndarray) -> Junctions:
    """The compiled description of ``groups`` of nodes that move together (a system's free points); their
    added-mass coefficients are taken out of ``added`` (2, N), which the per-node pass then skips."""
    start = np.zeros(len(groups) + 1, dtype=np.int64)
    for j, group in enumerate(groups):
        start[j + 1] = start[j] + len(group)
    nodes = np.array([i for group in groups for i in group], dtype=np.int64)
    own = np.zeros((2, nodes.size))
    if added.size:
        own[:] = added[:, nodes]
        added[:, nodes] = 0.0
    return Junctions(start, nodes, own)


def no_junctions() -> None:
    """What a rope (or a system without free points joining two or more lines) has in their place: None, so the
    parameter bundle carries and compiles nothing of them (their fields are read only behind
    :data:`WITH_JUNCTIONS`)."""
    return None


@jit.kernel
def move_junctions(x, v, acc, inv_mass, junctions, around):
    """Give every node of each junction the junction's acceleration (see the module doc), from ``acc`` holding
    each node's F_k / m_k; returns the power [W] of the fluid's inertial force on the junctions."""
    start, nodes, added = junctions
    dim = x.shape[0]
    power = 0.0
    for j in range(start.shape[0] - 1):
        f0 = f1 = f2 = 0.0
        m00 = m01 = m02 = m11 = m12 = m22 = 0.0
        for k in range(start[j], start[j + 1]):
            i = nodes[k]
            m = 1.0 / inv_mass[i]
            f0 += m * acc[0, i]
            f1 += m * acc[1, i]
            if dim == 3:
                f2 += m * acc[2, i]
            a_n, a_t = added[0, k], added[1, k]
            q0, q1, q2 = node_tangent(x, i, around)
            extra = a_t - a_n   # m I + a_n (I - q q^T) + a_t q q^T = (m + a_n) I + (a_t - a_n) q q^T
            m00 += m + a_n + extra * q0 * q0
            m01 += extra * q0 * q1
            m02 += extra * q0 * q2
            m11 += m + a_n + extra * q1 * q1
            m12 += extra * q1 * q2
            m22 += m + a_n + extra * q2 * q2
        if dim == 2:
            det = m00 * m11 - m01 * m01
            a0 = (m11 * f0 - m01 * f1) / det
            a1 = (m00 * f1 - m01 * f0) / det
            a2 = 0.0
        else:   # the symmetric 3 x 3 system by its adjugate
            c00 = m11 * m22 - m12 * m12
            c01 = m02 * m12 - m01 * m22
            c02 = m01 * m12 - m02 * m11
            c11 = m00 * m22 - m02 * m02
            c12 = m01 * m02 - m00 * m12
            c22 = m00 * m11 - m01 * m01
            det = m00 * c00 + m01 * c01 + m02 * c02
            a0 = (c00 * f0 + c01 * f1 + c02 * f2) / det
            a1 = (c01 * f0 + c11 * f1 + c12 * f2) / det
            a2 = (c02 * f0 + c12 * f1 + c22 * f2) / det
        inertia = 0.0   # sum_k m_k, for the fluid's inertial force (sum_k m_k) a - sum_k F_k
        for k in range(start[j], start[j + 1]):
            i = nodes[k]
            inertia += 1.0 / inv_mass[i]
            acc[0, i] = a0
            acc[1, i] = a1
            if dim == 3:
                acc[2, i] = a2
        first = nodes[start[j]]
        power += (inertia * a0 - f0) * v[0, first] + (inertia * a1 - f1) * v[1, first]
        if dim == 3:
            power += (inertia * a2 - f2) * v[2, first]
    return power


@jit.kernel
def fold_junctions(rhs, junctions, dim):
    """Sum each junction's rows of ``rhs`` (flat, node-major: a residual or a force per node) into its first
    node's and zero the others': the point's one equation, as :func:`move_junctions` sums its forces."""
    start, nodes = junctions.start, junctions.nodes
    for j in range(start.shape[0] - 1):
        first = nodes[start[j]]
        for k in range(start[j] + 1, start[j + 1]):
            i = nodes[k]
            for d in range(dim):
                rhs[first * dim + d] += rhs[i * dim + d]
                rhs[i * dim + d] = 0.0


@jit.kernel
def junction_added_mass_residual(x, xh, vh, beta, rhs, junctions, around):
    """Subtract A_k (x - xh - beta vh) at every junction node from the stiff integrator's residual ``rhs``
    (flat, node-major): the added mass of the point's nodes, which the per-node pass leaves to this module."""
    start, nodes, added = junctions
    dim = x.shape[0]
    for k in range(nodes.shape[0]):
        i = nodes[k]
        a_n, a_t = added[0, k], added[1, k]
        if a_n == 0.0 and a_t == 0.0:
            continue
        q = node_tangent(x, i, around)
        w = (x[0, i] - xh[0, i] - beta * vh[0, i], x[1, i] - xh[1, i] - beta * vh[1, i],
             x[2, i] - xh[2, i] - beta * vh[2, i] if dim == 3 else 0.0)
        along = w[0] * q[0] + w[1] * q[1] + w[2] * q[2]
        for d in range(dim):
            rhs[i * dim + d] -= a_n * (w[d] - along * q[d]) + a_t * along * q[d]


@jit.kernel
def add_junction_added_mass_jacobian(x, band, junctions, around):
    """Add each junction node's added-mass block A_k = a_n (I - q q^T) + a_t q q^T to the Newton matrix's band
    (the tangent frozen, as :func:`ropesim.model.forces.added_mass.add_added_mass_jacobian` does per node)."""
    start, nodes, added = junctions
    dim = x.shape[0]
    for k in range(nodes.shape[0]):
        i = nodes[k]
        q = node_tangent(x, i, around)
        for a in range(dim):
            for b in range(a + 1):
                qq = q[a] * q[b]
                band[a - b, i * dim + b] += added[0, k] * ((1.0 if a == b else 0.0) - qq) + added[1, k] * qq
