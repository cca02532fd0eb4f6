"""Prescribed motion of held nodes: x(t) = x0 + V t + r(t) [sinusoid(t) + path(t)] (see ``[[driven]]``).

Pinned nodes and constant-velocity drives need nothing from here: the compiled loops place them at x0 + V t
themselves. When any drive moves otherwise (``Motion.moving``), the loops call :func:`place_moving` whenever
time changes: it puts every held node where it must be at time t, sets its velocity in ``v``, and writes the
held nodes' current velocity and acceleration into the ``Held`` bundle's ``v`` and ``Motion.accel`` arrays,
which the loops read for the supports' power on the rope (a support pushes m a - F, with a the prescribed
acceleration). The path is piecewise linear: its velocity jumps at its rows, and its acceleration there (an
impulse) is left out of the supports' power, a ledger error of the order of the jump times the step.

Which piece of the path a time takes: the one that holds ``t_piece``, evaluated at t (and extended past its
rows if t lies beyond them). The loops pass the middle of the step being taken for every stage of it, so a
step between two rows moves the node on one straight piece from its first stage to its last: a stage that
lands on a row (the last stage of a step ending there, a Yoshida drift past it) keeps the step's own
velocity, and every method keeps its order, as MoorDyn moves a coupled point on one piece for the whole
coupling step. (A stage deciding by its own time took the next piece's velocity at a row, and every method
fell to first order.) A state at a step's end is placed with ``t_piece = t``: on the path, the row's next
piece. A step that straddles a row (the rows not a whole number of steps apart) cannot keep the order: keep
the path's row spacing a multiple of dt.

Parameters (per held node j, axis d): ``base`` (D, H) the constant velocity V; ``amp``, ``omega``, ``phase``
(D, H) the sinusoid A sin(omega t + phase) - A sin(phase); ``ramp`` (H,) the ramp time; ``path_t`` (K,) and
``path_d`` (D, K) every path's rows, concatenated, and ``span`` (H, 2) the rows of node j's path (empty if
none); ``accel`` (D, H) written by :func:`place_moving`.

A driven rigid body moves its points rigidly (switch :data:`WITH_RIGID_MOTION`): its six degrees of freedom
(three in 2-D) follow the same law, q_k(t) = q_k(0) + V_k t + r(t) [sinusoid_k(t) + path_k(t)], the
translations of its reference point r and its orientation angles (about x, then y, then z: R = Rz Ry Rx; about z
in 2-D), and a held node j on it (``rigid[j]`` = the body, ``arm[:, j]`` its point in the body frame) sits at
r + R arm, with velocity r' + w x rho and acceleration r'' + alpha x rho + w x (w x rho), rho = R arm, w and
alpha the angular velocity and acceleration of the angles' rates (:func:`rigid_state`). ``bodies`` holds each
driven body's motion as a :class:`Motion` over its six rows (x, y, z, then the angles about x, y, z [rad]), whose
``accel`` holds its pose at t = 0 (the reference point, then the angles).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import jit

Motion = namedtuple("Motion", ["moving", "base", "amp", "omega", "phase", "ramp", "path_t", "path_d", "span", "accel",
                               "rigid", "arm", "bodies"])

Held = namedtuple("Held", ["idx", "x0", "v", "motion"])
"""The held (pinned or driven) nodes: indices (H,), positions at t = 0 (D, H) [m], velocities (D, H) [m/s]
(constant, or for a prescribed motion the current ones, kept up to date by the loops), and their
:class:`Motion`: what the compiled loops and :func:`place_moving` take."""

WITH_RIGID_MOTION = jit.Switch("rigid_motion", "a driven rigid body moving its points")


def motion_of(dim: int, held_idx: np.ndarray, drives, rigid=()) -> Motion:
    """The held nodes' prescribed motion (all zero and ``moving`` False for pins and constant drives).

    ``drives``: (nodes, drive) pairs, the node indices a drive moves and its motion (velocity, amplitude,
    period, phase, path_table, ramp_time: a rope's ``[[driven]]`` entry or a system's driven point); ``rigid``:
    (driven rigid body, [(node, arm (3,))]) pairs, each body's motion and the nodes on its points."""
    h = len(held_idx)
    base, amp, omega, phase = (np.zeros((dim, h)) for _ in range(4))
    ramp, span = np.zeros(h), np.zeros((h, 2), dtype=np.int64)
    times, rows = [], []
    where = {int(i): j for j, i in enumerate(held_idx)}
    for nodes, drive in drives:
        first = len(times)
        if drive.path_table is not None:
            table = np.asarray(drive.path_table)
            times.extend(table[:, 0])
            rows.extend(table[:, 1:])
        for node in nodes:
            j = where[node]
            base[:, j] = drive.velocity
            ramp[j] = drive.ramp_time
            if drive.amplitude is not None:
                amp[:, j] = drive.amplitude
                omega[:, j] = [2.0 * math.pi / T if a != 0.0 else 0.0 for a, T in zip(drive.amplitude, drive.period)]
                phase[:, j] = np.radians(drive.phase)
            span[j] = (first, len(times))
    path_d = np.asarray(rows, dtype=float).T.copy() if rows else np.zeros((dim, 0))
    moving = any(drive.moving for _, drive in drives) or bool(rigid)
    body_of = arm = bodies = None   # nothing of rigid motion without driven bodies (read behind WITH_RIGID_MOTION)
    if rigid:
        body_of, arm = np.full(h, -1, dtype=np.int64), np.zeros((3, h))
        for b, (_, nodes) in enumerate(rigid):
            for node, node_arm in nodes:
                body_of[where[int(node)]] = b
                arm[:, where[int(node)]] = node_arm
        bodies = _body_motions(dim, [body for body, _ in rigid])
    return Motion(moving, base, amp, omega, phase, ramp, np.asarray(times, dtype=float), path_d, span,
                  np.zeros((dim, h)), body_of, arm, bodies)


def _body_motions(dim: int, bodies) -> Motion:
    """The driven bodies' motions over their six rows (see the module doc); empty without any."""
    count = len(bodies)
    rows = [0, 1, 2, 3, 4, 5] if dim == 3 else [0, 1, 5]   # each degree of freedom's row
    base, amp, omega, phase = (np.zeros((6, count)) for _ in range(4))
    ramp, span, pose0 = np.zeros(count), np.zeros((count, 2), dtype=np.int64), np.zeros((6, count))
    times, path = [], []
    for b, body in enumerate(bodies):
        turns = len(rows) - dim
        pose0[:dim, b] = body.position
        pose0[[r for r in rows[dim:]], b] = np.radians(body.orientation)
        if body.velocity is not None:   # a coupled body: none, its motion comes at every coupling step
            base[rows[:dim], b] = body.velocity
        if body.angular_velocity is not None:
            base[rows[dim:], b] = np.radians(body.angular_velocity)
        ramp[b] = body.ramp_time or 0.0
        scale = np.array([1.0] * dim + [math.pi / 180.0] * turns)   # angles in degrees
        if body.amplitude is not None:
            amp[rows, b] = np.asarray(body.amplitude) * scale
            omega[rows, b] = [2.0 * math.pi / T if a != 0.0 else 0.0 for a, T in zip(body.amplitude, body.period)]
            phase[rows, b] = np.radians(body.phase)
        first = len(times)
        if body.path_table is not None:
            table = np.asarray(body.path_table, dtype=float)
            times.extend(table[:, 0])
            for row in table[:, 1:]:
                full = np.zeros(6)
                full[rows] = row * scale
                path.append(full)
        span[b] = (first, len(times))
    path_d = np.asarray(path, dtype=float).T.copy() if path else np.zeros((6, 0))
    return Motion(bool(count), base, amp, omega, phase, ramp, np.asarray(times, dtype=float), path_d, span, pose0,
                  None, None, None)


@jit.kernel(inline="always")
def ramp_factor(t, ramp):
    """(r, dr/dt, d2r/dt2) of the ramp r = 10 s^3 - 15 s^4 + 6 s^5, s = t / T, until T, 1 after (and always
    when T = 0): "smootherstep", whose rate and acceleration are zero at both ends, so the held node's
    acceleration, and the force on its support, have no jump when the ramp starts or ends."""
    if ramp <= 0.0 or t >= ramp:
        return 1.0, 0.0, 0.0
    if t <= 0.0:
        return 0.0, 0.0, 0.0
    u = t / ramp
    return (u * u * u * (10.0 + u * (-15.0 + 6.0 * u)), u * u * (30.0 + u * (-60.0 + 30.0 * u)) / ramp,
            u * (60.0 + u * (-180.0 + 120.0 * u)) / (ramp * ramp))


@jit.kernel(literal_integers=False)   # rigid_state calls it with the axes 0 .. 5: one compile, not six
def offset(m, j, d, t, t_piece):
    """(position, velocity, acceleration) of held node j's motion along axis d at time t, beyond x0 + V t; a
    path on its piece that holds time ``t_piece`` (see the module doc)."""
    s = ds = dds = 0.0
    a = m.amp[d, j]
    if a != 0.0:
        arg = m.omega[d, j] * t + m.phase[d, j]
        w = m.omega[d, j]
        s = a * (math.sin(arg) - math.sin(m.phase[d, j]))
        ds = a * w * math.cos(arg)
        dds = -a * w * w * math.sin(arg)
    lo, hi = m.span[j, 0], m.span[j, 1]
    if hi > lo:
        # the row k that starts t_piece's piece: the last of rows lo+1 .. hi-2 at or before t_piece, else lo (a
        # binary search: a sea state's path has 10^5 rows and every stage of every step looks one up)
        k, top = lo, hi - 2
        while k < top:
            mid = (k + top + 1) // 2
            if m.path_t[mid] <= t_piece:
                k = mid
            else:
                top = mid - 1
        t0, t1 = m.path_t[k], m.path_t[k + 1]
        slope = (m.path_d[d, k + 1] - m.path_d[d, k]) / (t1 - t0)
        s += m.path_d[d, k] + slope * (t - t0)
        ds += slope
    r, dr, ddr = ramp_factor(t, m.ramp[j])
    return r * s, dr * s + r * ds, ddr * s + 2.0 * dr * ds + r * dds


@jit.kernel(inline="always")
def _dof(bodies, b, d, t, t_piece):
    """(value, rate, acceleration) of driven body b's row d at time t."""
    s, ds, dds = offset(bodies, b, d, t, t_piece)
    return bodies.accel[d, b] + bodies.base[d, b] * t + s, bodies.base[d, b] + ds, dds


@jit.kernel
def rigid_state(bodies, b, t, t_piece):
    """Driven body b's pose and motion at time t (a path on the piece that holds ``t_piece``): its reference
    point, velocity and acceleration (3 each, world), its rotation matrix (9, row by row), angular velocity and
    angular acceleration (3 each, world), as one tuple of 24 numbers."""
    x0, dx0, ddx0 = _dof(bodies, b, 0, t, t_piece)
    x1, dx1, ddx1 = _dof(bodies, b, 1, t, t_piece)
    x2, dx2, ddx2 = _dof(bodies, b, 2, t, t_piece)
    a, da, dda = _dof(bodies, b, 3, t, t_piece)    # about x
    bb, db, ddb = _dof(bodies, b, 4, t, t_piece)   # about y
    c, dc, ddc = _dof(bodies, b, 5, t, t_piece)    # about z
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(bb), math.sin(bb), math.cos(c), math.sin(c)
    # R = Rz(c) Ry(b) Rx(a)
    r00, r01, r02 = cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa
    r10, r11, r12 = sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa
    r20, r21, r22 = -sb, cb * sa, cb * ca
    # w = c' e_z + b' u2 + a' u3, u2 = Rz e_y, u3 = Rz Ry e_x
    u20, u21 = -sc, cc
    u30, u31, u32 = cc * cb, sc * cb, -sb
    w0 = db * u20 + da * u30
    w1 = db * u21 + da * u31
    w2 = dc + da * u32
    # alpha = c'' e_z + b'' u2 + a'' u3 + b' (c' e_z x u2) + a' ((c' e_z + b' u2) x u3)
    o0, o1, o2 = db * u20, db * u21, dc   # c' e_z + b' u2
    al0 = ddb * u20 + dda * u30 + db * (-dc * u21) + da * (o1 * u32 - o2 * u31)
    al1 = ddb * u21 + dda * u31 + db * (dc * u20) + da * (o2 * u30 - o0 * u32)
    al2 = ddc + dda * u32 + da * (o0 * u31 - o1 * u30)
    return (x0, x1, x2, dx0, dx1, dx2, ddx0, ddx1, ddx2,
            r00, r01, r02, r10, r11, r12, r20, r21, r22, w0, w1, w2, al0, al1, al2)


@jit.kernel
def place_rigid(x, v, held, j, t, t_piece):
    """Put held node j, on a driven rigid body, where its body's motion puts it at time t (see the module doc)."""
    idx, _, hv, m = held
    i = idx[j]
    dim = x.shape[0]
    (r0, r1, r2, v0, v1, v2, a0, a1, a2, r00, r01, r02, r10, r11, r12, r20, r21, r22, w0, w1, w2, al0, al1,
     al2) = rigid_state(m.bodies, m.rigid[j], t, t_piece)
    s0, s1, s2 = m.arm[0, j], m.arm[1, j], m.arm[2, j]
    p0 = r00 * s0 + r01 * s1 + r02 * s2
    p1 = r10 * s0 + r11 * s1 + r12 * s2
    p2 = r20 * s0 + r21 * s1 + r22 * s2
    e0, e1, e2 = w1 * p2 - w2 * p1, w2 * p0 - w0 * p2, w0 * p1 - w1 * p0   # w x rho
    pos = (r0 + p0, r1 + p1, r2 + p2)
    vel = (v0 + e0, v1 + e1, v2 + e2)
    acc = (a0 + al1 * p2 - al2 * p1 + w1 * e2 - w2 * e1, a1 + al2 * p0 - al0 * p2 + w2 * e0 - w0 * e2,
           a2 + al0 * p1 - al1 * p0 + w0 * e1 - w1 * e0)
    for d in range(dim):
        x[d, i] = pos[d]
        hv[d, j] = vel[d]
        v[d, i] = vel[d]
        m.accel[d, j] = acc[d]


@jit.kernel
def place_moving(x, v, held, t, t_piece):
    """Put every held node at its prescribed place at time t, set its velocity in ``v`` and in ``held.v``,
    and its acceleration in ``held.motion.accel``; a path on its piece that holds ``t_piece`` (the middle of
    the step a stage belongs to, or t itself for a step's end state; see the module doc)."""
    idx, x0, hv, m = held
    dim = x.shape[0]
    for j in range(idx.shape[0]):
        i = idx[j]
        if WITH_RIGID_MOTION and m.rigid[j] >= 0:
            place_rigid(x, v, held, j, t, t_piece)
            continue
        for d in range(dim):
            s, ds, dds = offset(m, j, d, t, t_piece)
            x[d, i] = x0[d, j] + m.base[d, j] * t + s
            hv[d, j] = m.base[d, j] + ds
            v[d, i] = hv[d, j]
            m.accel[d, j] = dds
