"""The lumped-mass line's load conventions, written once in plain numpy, for the references to share.

Nothing here imports ropesim: these are the team's stated conventions, evaluated directly, so that a reference
built on them checks ropesim's implementation rather than copying it.

Conventions (SI units throughout; 2-D or 3-D; the LAST coordinate is vertical, positive up):

- Nodes 0..N; segment j joins nodes j and j+1 and has unstretched length l_j, diameter d, mass per metre mu.
- Node share of length L_i = half of each adjacent segment (end nodes: half of their single segment).
  Mass m_i = mu * L_i (unstretched lengths: mass is conserved when the line stretches).
- Node tangent q_i = unit(x_{i+1} - x_{i-1}) for inner nodes, unit vector of the single adjacent segment at
  the ends (MoorDyn's convention), oriented from node 0 towards node N.
- For the relative velocity u = v_i - U_flow: u_t = (u.q) q, u_n = u - u_t.
- Quadratic (Morison) drag: F = -1/2 rho Cd_n d L_i |u_n| u_n - 1/2 rho Cd_t pi d L_i |u_t| u_t.
- Linear anisotropic drag: F = -b_n L_i u_n - b_t L_i u_t  (b_n, b_t in N s/m per metre of line).
- Buoyancy: +rho (pi d^2 / 4) L_i g upward (unstretched volume).
- Axial spring: T_j = EA (|x_{j+1} - x_j| / l_j - 1), tension only (zero when slack) unless stated.

Which length the drag uses when the line stretches (unstretched l_j, or the current |x_{j+1} - x_j|) is a
choice: every function that needs it takes ``drag_length`` = "unstretched" (default) or "stretched".
MoorDyn uses the stretched length for drag; the difference is O(T / EA).
"""

from __future__ import annotations

import math

import numpy as np

RHO_WATER = 1025.0  # kg/m^3, sea water
RHO_AIR = 1.225  # kg/m^3, ISA sea level, 15 C
G = 9.80665  # m/s^2, standard gravity


def node_lengths(seg_lengths) -> np.ndarray:
    """L_i: half of each adjacent segment's length, shape (N+1,) for N segments."""
    seg = np.asarray(seg_lengths, dtype=float)
    L = np.zeros(seg.size + 1)
    L[:-1] += 0.5 * seg
    L[1:] += 0.5 * seg
    return L


def node_tangents(x) -> np.ndarray:
    """q_i, shape (N+1, D): unit(x_{i+1} - x_{i-1}) inside, the single adjacent segment at the ends."""
    x = np.asarray(x, dtype=float)
    q = np.empty_like(x)
    q[0] = x[1] - x[0]
    q[-1] = x[-1] - x[-2]
    q[1:-1] = x[2:] - x[:-2]
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def split_velocity(u, q):
    """(u_t, u_n) for relative velocities u and unit tangents q, row by row."""
    u = np.asarray(u, dtype=float)
    ut = np.sum(u * q, axis=-1, keepdims=True) * q
    return ut, u - ut


def drag_node_lengths(x, seg_lengths, drag_length: str = "unstretched") -> np.ndarray:
    """L_i used by drag: from the unstretched segment lengths, or from the current (stretched) ones."""
    if drag_length == "unstretched":
        return node_lengths(seg_lengths)
    if drag_length == "stretched":
        return node_lengths(np.linalg.norm(np.diff(np.asarray(x, dtype=float), axis=0), axis=1))
    raise ValueError(f"drag_length must be 'unstretched' or 'stretched', not {drag_length!r}")


def morison_node_forces(x, v, seg_lengths, d, rho, cd_n, cd_t, flow=None, drag_length="unstretched"):
    """Quadratic drag on every node, shape (N+1, D) [N].

    F_i = -1/2 rho Cd_n d L_i |u_n| u_n - 1/2 rho Cd_t pi d L_i |u_t| u_t, with u = v_i - flow.
    ``flow`` is the ambient fluid velocity, one vector for all nodes or one per node (default: still fluid).
    """
    x = np.asarray(x, dtype=float)
    u = np.asarray(v, dtype=float) - (0.0 if flow is None else np.asarray(flow, dtype=float))
    u = np.broadcast_to(u, x.shape)
    L = drag_node_lengths(x, seg_lengths, drag_length)[:, None]
    ut, un = split_velocity(u, node_tangents(x))
    fn = -0.5 * rho * cd_n * d * L * np.linalg.norm(un, axis=1, keepdims=True) * un
    ft = -0.5 * rho * cd_t * math.pi * d * L * np.linalg.norm(ut, axis=1, keepdims=True) * ut
    return fn + ft


def linear_drag_node_forces(x, v, seg_lengths, b_n, b_t, flow=None, drag_length="unstretched"):
    """Linear anisotropic drag on every node: F_i = -b_n L_i u_n - b_t L_i u_t [N]."""
    x = np.asarray(x, dtype=float)
    u = np.asarray(v, dtype=float) - (0.0 if flow is None else np.asarray(flow, dtype=float))
    u = np.broadcast_to(u, x.shape)
    L = drag_node_lengths(x, seg_lengths, drag_length)[:, None]
    ut, un = split_velocity(u, node_tangents(x))
    return -b_n * L * un - b_t * L * ut


def gravity_buoyancy_node_forces(seg_lengths, mu, d, rho, g, dim: int = 2) -> np.ndarray:
    """Weight plus buoyancy on every node, shape (N+1, dim): vertical (rho pi d^2/4 - mu) L_i g [N]."""
    L = node_lengths(seg_lengths)
    f = np.zeros((L.size, dim))
    f[:, -1] = (rho * math.pi * d * d / 4.0 - mu) * L * g
    return f


def axial_tensions(x, seg_lengths, EA, tension_only: bool = True) -> np.ndarray:
    """T_j = EA (|x_{j+1} - x_j| / l_j - 1), clipped at zero when ``tension_only`` [N]."""
    seg = np.linalg.norm(np.diff(np.asarray(x, dtype=float), axis=0), axis=1)
    T = EA * (seg / np.asarray(seg_lengths, dtype=float) - 1.0)
    return np.maximum(T, 0.0) if tension_only else T


def axial_node_forces(x, seg_lengths, EA, tension_only: bool = True) -> np.ndarray:
    """The springs' forces on the nodes, shape (N+1, D): +T_j e_j on node j, -T_j e_j on node j+1."""
    x = np.asarray(x, dtype=float)
    dx = np.diff(x, axis=0)
    e = dx / np.linalg.norm(dx, axis=1, keepdims=True)
    Te = axial_tensions(x, seg_lengths, EA, tension_only)[:, None] * e
    f = np.zeros_like(x)
    f[:-1] += Te
    f[1:] -= Te
    return f
