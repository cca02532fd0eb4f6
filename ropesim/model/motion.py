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
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import jit

Motion = namedtuple("Motion", ["moving", "base", "amp", "omega", "phase", "ramp", "path_t", "path_d", "span", "accel"])


def motion_of(dim: int, held_idx: np.ndarray, drives) -> Motion:
    """The held nodes' prescribed motion (all zero and ``moving`` False for pins and constant drives).

    ``drives``: (nodes, drive) pairs, the node indices a drive moves and its motion (velocity, amplitude,
    period, phase, path_table, ramp_time: a rope's ``[[driven]]`` entry or a system's driven point)."""
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
    moving = any(drive.moving for _, drive in drives)
    return Motion(moving, base, amp, omega, phase, ramp, np.asarray(times, dtype=float), path_d, span,
                  np.zeros((dim, h)))


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


@jit.kernel
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


@jit.kernel
def place_moving(x, v, held, t, t_piece):
    """Put every held node at its prescribed place at time t, set its velocity in ``v`` and in ``held.v``,
    and its acceleration in ``held.motion.accel``; a path on its piece that holds ``t_piece`` (the middle of
    the step a stage belongs to, or t itself for a step's end state; see the module doc)."""
    idx, x0, hv, m = held
    dim = x.shape[0]
    for j in range(idx.shape[0]):
        i = idx[j]
        for d in range(dim):
            s, ds, dds = offset(m, j, d, t, t_piece)
            x[d, i] = x0[d, j] + m.base[d, j] * t + s
            hv[d, j] = m.base[d, j] + ds
            v[d, i] = hv[d, j]
            m.accel[d, j] = dds
