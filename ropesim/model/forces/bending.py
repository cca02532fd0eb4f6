"""Bending stiffness EI of a rope given in physical units: one energy, its forces, and its Newton block.

At each joint i between segment a = x_i - x_(i-1) and segment b = x_(i+1) - x_i (unit vectors t_a, t_b, angle
theta between them), the rope stores

    E_i = C_i (1 - t_a . t_b) = C_i (1 - cos theta),   C_i = EI / l_i,

l_i the mean of the two segments' rest lengths. For small angles this is EI theta^2 / (2 l_i) = EI kappa^2 l_i / 2
with the curvature kappa = theta / l_i: the Euler-Bernoulli bending energy, lumped at the joint (MoorDyn's
curvature 4 sin(theta / 2) / (l_a + l_b) gives the same energy to second order). The forces are its gradient,

    F_(i+1) = C_i (t_a - (t_a . t_b) t_b) / |b|,   F_(i-1) = -C_i (t_b - (t_a . t_b) t_a) / |a|,
    F_i = -(F_(i-1) + F_(i+1)),

a three-node couple with no net force. An open line's end nodes are no joints (free ends carry no moment),
unless clamped (``pinned.clamped``): a clamped end node is a joint between its end segment and the segment's
initial direction u, E = C (1 - u . t) with C = 2 EI / l (the joint covers half a segment), which pulls the
segment's far node back towards that direction. A loop's every node is a joint.

The stiff integrator's block is the energy's Hessian at small angles, C_i / l^2 (s s^T) x (I - q q^T) with
s = (1, -2, 1) over nodes i - 1, i, i + 1 and q the joint's tangent: positive semi-definite, what a straight
beam's bending stiffness is (its turning with the rope, and its dependence on stretch, are left out).

Parameters: ``bending_ei`` = (C (N,) [N m], 0 where there is no joint; the clamps' directions (2, 3), row 0
for node 0's and row 1 for the last node's, zero where the end is not clamped; each node's segment length l
(N,) [m]). A system's lines are joined end to end in the node arrays, but a line's end nodes carry C = 0 (no
joint), so no joint spans two lines.
"""

from __future__ import annotations

import math

import numpy as np

from . import Term
from ..jacobian import add_pair
from ..layout import line_layouts, per_node
from .. import jit

WITH_EI_BENDING = jit.Switch("ei_bending", "bending stiffness EI")


@jit.kernel
def _joint(i, n, closed):
    """Joint i's neighbours (lo, hi) and, for an open line's end node, its clamp row (0 or 1) with hi the
    segment's far node; row -1 for an interior joint."""
    if not closed and i == 0:
        return i, 1, 0
    if not closed and i == n - 1:
        return i, n - 2, 1
    return (i - 1 if i > 0 else n - 1), (i + 1 if i < n - 1 else 0), -1


@jit.kernel
def add_ei_bending(x, acc, inv_mass, bending, closed):
    """Add the bending couple's accelerations [m/s^2] of every joint (see the module doc)."""
    stiffness, clamps, segment = bending
    dim, n = x.shape
    for i in range(n):
        c = stiffness[i]
        if c == 0.0:
            continue
        lo, hi, row = _joint(i, n, closed)
        if row >= 0:
            _add_clamp(x, acc, inv_mass, c, clamps[row], i, hi)
            continue
        a0, a1 = x[0, i] - x[0, lo], x[1, i] - x[1, lo]
        b0, b1 = x[0, hi] - x[0, i], x[1, hi] - x[1, i]
        a2 = x[2, i] - x[2, lo] if dim == 3 else 0.0
        b2 = x[2, hi] - x[2, i] if dim == 3 else 0.0
        la = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        lb = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
        if la == 0.0 or lb == 0.0:
            continue
        a0, a1, a2 = a0 / la, a1 / la, a2 / la
        b0, b1, b2 = b0 / lb, b1 / lb, b2 / lb
        cos = a0 * b0 + a1 * b1 + a2 * b2
        fa, fb = c / la, c / lb
        # force on the node ahead (i + 1) and behind (i - 1); the joint takes minus their sum
        h0, h1, h2 = fb * (a0 - cos * b0), fb * (a1 - cos * b1), fb * (a2 - cos * b2)
        l0, l1, l2 = -fa * (b0 - cos * a0), -fa * (b1 - cos * a1), -fa * (b2 - cos * a2)
        acc[0, hi] += h0 * inv_mass[hi]
        acc[1, hi] += h1 * inv_mass[hi]
        acc[0, lo] += l0 * inv_mass[lo]
        acc[1, lo] += l1 * inv_mass[lo]
        acc[0, i] -= (h0 + l0) * inv_mass[i]
        acc[1, i] -= (h1 + l1) * inv_mass[i]
        if dim == 3:
            acc[2, hi] += h2 * inv_mass[hi]
            acc[2, lo] += l2 * inv_mass[lo]
            acc[2, i] -= (h2 + l2) * inv_mass[i]


@jit.kernel
def _add_clamp(x, acc, inv_mass, c, u, end, next_node):
    """A clamp at node ``end``: E = c (1 - u . t), t the unit vector from ``end`` to ``next_node``; the force
    c (u - (u . t) t) / |b| on ``next_node`` and its opposite on the (held) end."""
    dim = x.shape[0]
    b0, b1 = x[0, next_node] - x[0, end], x[1, next_node] - x[1, end]
    b2 = x[2, next_node] - x[2, end] if dim == 3 else 0.0
    lb = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    if lb == 0.0:
        return
    b0, b1, b2 = b0 / lb, b1 / lb, b2 / lb
    cos = u[0] * b0 + u[1] * b1 + u[2] * b2
    f = c / lb
    for d, (ud, bd) in enumerate(((u[0], b0), (u[1], b1), (u[2], b2))):
        if d < dim:
            acc[d, next_node] += f * (ud - cos * bd) * inv_mass[next_node]
            acc[d, end] -= f * (ud - cos * bd) * inv_mass[end]


@jit.kernel
def ei_energy(x, bending, closed):
    """The bending energy, sum of C_i (1 - cos theta_i) [J] (a clamp's against its direction)."""
    stiffness, clamps, segment = bending
    dim, n = x.shape
    e = 0.0
    for i in range(n):
        c = stiffness[i]
        if c == 0.0:
            continue
        lo, hi, row = _joint(i, n, closed)
        if row >= 0:
            dot = lb2 = 0.0
            for d in range(dim):
                b = x[d, hi] - x[d, i]
                dot += clamps[row, d] * b
                lb2 += b * b
            if lb2 > 0.0:
                e += c * (1.0 - dot / math.sqrt(lb2))
            continue
        dot = la2 = lb2 = 0.0
        for d in range(dim):
            a = x[d, i] - x[d, lo]
            b = x[d, hi] - x[d, i]
            dot += a * b
            la2 += a * a
            lb2 += b * b
        if la2 > 0.0 and lb2 > 0.0:
            e += c * (1.0 - dot / math.sqrt(la2 * lb2))
    return e


@jit.kernel
def add_ei_jacobian(x, jac, beta, free, bending, closed):
    """Add beta^2 times the small-angle bending stiffness (see the module doc) to the Newton matrix ``jac``,
    as 2 pair(i-1, i) + 2 pair(i, i+1) - pair(i-1, i+1) of the block C_i / l^2 (I - q q^T); a clamp's, C / l^2
    (I - u u^T) on its end segment's far node."""
    stiffness, clamps, segment = bending
    dim, n = x.shape
    blk = jac.blk
    for i in range(n):
        c = stiffness[i]
        if c == 0.0:
            continue
        lo, hi, row = _joint(i, n, closed)
        if row >= 0:
            if free[hi]:
                u = clamps[row]
                scale = beta * beta * c / (segment[i] * segment[i])
                for a in range(dim):
                    for b in range(a + 1):
                        jac.band[a - b, hi * dim + b] += scale * ((1.0 if a == b else 0.0) - u[a] * u[b])
            continue
        q0, q1 = x[0, hi] - x[0, lo], x[1, hi] - x[1, lo]
        q2 = x[2, hi] - x[2, lo] if dim == 3 else 0.0
        ql = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
        if ql > 0.0:
            q0, q1, q2 = q0 / ql, q1 / ql, q2 / ql
        q = (q0, q1, q2)
        scale = beta * beta * c / (segment[i] * segment[i])
        for weight, j, k in ((2.0, lo, i), (2.0, i, hi), (-1.0, lo, hi)):
            for a in range(dim):
                for b in range(dim):
                    blk[a, b] = weight * scale * ((1.0 if a == b else 0.0) - q[a] * q[b])
            add_pair(jac, n, j, k, free[j], free[k])


def _params(scene, layout) -> tuple:
    """C_i = EI / l at every joint of a line with EI [N m], 2 EI / l at a clamped end, 0 at a free end and off the
    lines; the clamps' directions (a rope's); each node's segment length l [m]."""
    from ...scene.shapes import initial_positions

    n = len(layout.mass)
    c = per_node(layout.lines, n, [line.EI / line.segment_length for line in layout.lines])
    segment = per_node(layout.lines, n, [line.segment_length for line in layout.lines])
    clamps = np.zeros((2, 3))
    for line in layout.lines:
        if not line.closed:
            c[[line.first, line.end - 1]] = 0.0
    rope = scene.rope
    for node in (scene.pinned.clamped or ()) if scene.pinned else ():
        x = initial_positions(scene)
        end = scene.node(node)
        row, nxt = (0, 1) if end == 0 else (1, rope.nodes - 2)
        direction = x[:, nxt] - x[:, end]
        clamps[row, :scene.dimension] = direction / np.linalg.norm(direction)
        c[end] = 2.0 * rope.EI / rope.segment_length
    return c, clamps, segment


def _energy(model, x: np.ndarray) -> np.ndarray:
    """sum of C_i (1 - cos theta_i) [J] for frames x (..., N, D), a clamp's against its direction."""
    x = np.asarray(x)
    c, clamps, _ = model.params.bending_ei
    total = 0.0
    for line in model.lines:
        part = x[..., line.first:line.end, :]
        a = part - np.roll(part, 1, axis=-2)
        b = np.roll(part, -1, axis=-2) - part
        with np.errstate(invalid="ignore", divide="ignore"):   # an end's wrapped chord: weighed by C = 0 below
            cos = np.sum(a * b, axis=-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
        if not line.closed:
            dim = x.shape[-1]
            cos[..., 0] = np.sum(clamps[0, :dim] * b[..., 0, :], axis=-1) / np.linalg.norm(b[..., 0, :], axis=-1)
            cos[..., -1] = np.sum(clamps[1, :dim] * a[..., -1, :], axis=-1) / np.linalg.norm(a[..., -1, :], axis=-1)
        weight = c[line.first:line.end]
        total = total + np.einsum("...n,n->...", np.where(weight != 0.0, 1.0 - cos, 0.0), weight)
    return total


def _stiffness(model) -> float:
    """The bending's omega^2 bound, 16 C / (l^2 m) on the lightest free node [1/s^2] (a straight beam's
    zig-zag mode: the second difference's largest eigenvalue is 16)."""
    free = ~model.held
    c, _, l0 = model.params.bending_ei
    with np.errstate(invalid="ignore", divide="ignore"):   # off the lines l = 0 and C = 0
        rate = np.where(l0 > 0, 16.0 * np.maximum(c, np.roll(c, 1)) / (l0 * l0 * model.mass), 0.0)
    return float(np.max(rate[free], initial=0.0))


EI_TERM = Term("rope", WITH_EI_BENDING, _params, lambda: (np.zeros(0), np.zeros((2, 3)), np.zeros(0)),
               energy=_energy, node_stiffness=_stiffness,
               active=lambda scene: any(line.EI for line in line_layouts(scene)), reach=2, label="bending EI")
"""The lines' bending stiffness EI (``rope.EI``, a line's ``EI``)."""
