"""Explicit Runge-Kutta methods as Butcher tables, run by one compiled loop.

For the rope, y = (x, v) and y' = F(t, y) = (v, a(x, v) - gamma v): the linear drag is an ordinary term of F
(a Runge-Kutta method keeps its order with any smooth force, so nothing special is needed), and held nodes
are placed at x0 + V (t + c_i h) at every stage, with stage velocity V and no acceleration. Stage s computes

    Y_s = y + h sum_{j<s} a_sj K_j,   K_s = F(t + c_s h, Y_s),   y <- y + h sum_s b_s K_s.

Free rigid bodies are stepped on their group (Runge-Kutta-Munthe-Kaas): within a step a body's orientation is
q = exp(phi) q_n, the rotation vector phi starting at 0 with the rate phi' = dexp^-1_phi(w)
(:func:`ropesim.model.rotation.dexp_inverse`), so the stages combine phi linearly, as any other coordinate, and
the step ends with q_(n+1) = exp(phi_(n+1)) q_n, a unit quaternion by construction; the method keeps its order.
The bodies' attachment nodes are put where their bodies hold them at every stage and at the step's end.

Unlike the splitting schemes these methods are not symplectic: their energy error drifts (RK4 dissipates).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..model.bodies import WITH_BODIES, place_attachments
from ..model.junctions import WITH_JUNCTIONS
from ..model.rotation import dexp_inverse, turn
from ..model.terms import (WITH_ADDED_MASS, WITH_APPLIED, accelerations, applied_accelerations, body_accelerations,
                           solve_accelerations)
from .base import Integrator, Method
from .health import BOX, DRAG, FLUID, HELD, INTERNAL, OK, SEABED, due, end_step, held_power, place, power
from ..model import jit


@dataclass(frozen=True)
class RungeKutta(Method):
    """An explicit Runge-Kutta method: ``a`` (strictly lower triangular, as rows), weights ``b``, nodes ``c``."""

    name: str
    order: int
    a: tuple[tuple[float, ...], ...]
    b: tuple[float, ...]
    c: tuple[float, ...]
    doc: str
    kind: str = "rk"
    drag_explicit = True

    @property
    def family(self) -> type:
        return RungeKuttaFamily

    @property
    def evaluations(self) -> int:
        return len(self.b)

    @property
    def reuses_last_force(self) -> bool:
        return False

    def amplification(self, h: float, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0):
        """One step's 2x2 map of (x, v) for x'' = -omega^2 x - (gamma_force + gamma_drag) x' (both explicit)."""
        lin = np.array([[0.0, 1.0], [-omega * omega, -(gamma_force + gamma_drag)]]) * h
        stages = []
        for s in range(len(self.b)):
            y = np.eye(2) + sum(self.a[s][j] * stages[j] for j in range(s)) if s else np.eye(2)
            stages.append(lin @ y)
        return np.eye(2) + sum(bs * k for bs, k in zip(self.b, stages))

    def tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = len(self.b)
        a = np.zeros((s, s))
        for i, row in enumerate(self.a):
            a[i, :len(row)] = row
        return a, np.array(self.b, dtype=float), np.array(self.c, dtype=float)


RK4 = RungeKutta(
    "rk4", 4,
    a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
    b=(1 / 6, 1 / 3, 1 / 3, 1 / 6),
    c=(0.0, 0.5, 0.5, 1.0),
    doc="Classical fourth-order Runge-Kutta, a non-symplectic comparison: 4 force evaluations per step, drag "
        "explicit (so strong drag limits its step too), energy slowly dissipated.")

RKScratch = namedtuple("RKScratch", ["xs", "vs", "kx", "kv", "acc", "acc_box", "pose", "twist", "phi", "kpose",
                                     "ktwist"])
"""Stage positions and velocities (D, N), stage derivatives (S, D, N), accelerations (D, N); the free bodies'
stage pose (7, B), twist (6, B) and rotation vector (3, B), and their stage derivatives (S, 6, B): (v, phi'),
then (a, alpha)."""


class RungeKuttaFamily(Integrator):
    """The explicit Runge-Kutta family: any :class:`RungeKutta` table, drag an ordinary term of the derivative."""

    def __init__(self, model, grid, method: RungeKutta):
        super().__init__(model, grid, method)
        stages = len(method.b)
        self.tables = method.tables()
        shape = self.x.shape
        bodies = self.pose.shape[1]
        body_scratch = ((np.zeros((7, bodies)), np.zeros((6, bodies)), np.zeros((3, bodies)),
                         np.zeros((stages, 6, bodies)), np.zeros((stages, 6, bodies))) if bodies else (None,) * 5)
        self.scratch = RKScratch(np.zeros(shape), np.zeros(shape), np.zeros((stages,) + shape),
                                 np.zeros((stages,) + shape), np.zeros(shape), np.zeros(shape), *body_scratch)
        self.gamma = np.where(model.held, 0.0, model.drag / model.mass)

    @staticmethod
    def template():
        return advance_rk

    @property
    def force_evaluations(self) -> int:
        return self.step * self.method.evaluations

    @property
    def last_accelerations(self) -> np.ndarray | None:
        # a last stage at c = 1 (rk4) is at the step's end time t + h, its held nodes placed there; its free nodes
        # at y + h sum_j a_sj K_j, which differs from the end state by O(h^2) (rk4: y + h K_3)
        return self.scratch.acc if self.method.c[-1] == 1.0 else None

    def loop_args(self, n, frames):
        m = self.model
        return ((self.x, self.v, self.ledger), self.tables, self.scratch, self.held, m.mass, self.gamma, m.params,
                self.limits, self.schedule(n), frames, self.bodies)


@jit.kernel
def stage_state(x, v, kx, kv, a, st, h, xs, vs):
    """Stage ``st``'s state into ``xs``, ``vs``: x + h sum_j a[st, j] kx[j], and the same for v."""
    dim, n = x.shape
    for d in range(dim):
        for i in range(n):
            px = x[d, i]
            pv = v[d, i]
            for j in range(st):
                w = a[st, j] * h
                if w != 0.0:
                    px += w * kx[j, d, i]
                    pv += w * kv[j, d, i]
            xs[d, i] = px
            vs[d, i] = pv


@jit.kernel
def combine(x, v, kx, kv, b, h):
    """The step's end: x += h sum_s b[s] kx[s], and the same for v."""
    dim, n = x.shape
    for d in range(dim):
        for i in range(n):
            dx = 0.0
            dv = 0.0
            for st in range(b.shape[0]):
                dx += b[st] * kx[st, d, i]
                dv += b[st] * kv[st, d, i]
            x[d, i] += h * dx
            v[d, i] += h * dv


@jit.kernel(inline="always")
def body_stage(bodies, scratch, a, st, h):
    """Stage ``st``'s body state into the scratch's pose, twist and rotation vector: r + h sum_j a[st, j] v_j,
    phi = h sum_j a[st, j] phi'_j, q = exp(phi) q_n, and the twist likewise."""
    pose, twist = bodies
    for b in range(pose.shape[1]):
        for d in range(6):
            dp = 0.0
            dt = 0.0
            for j in range(st):
                w = a[st, j] * h
                if w != 0.0:
                    dp += w * scratch.kpose[j, d, b]
                    dt += w * scratch.ktwist[j, d, b]
            if d < 3:
                scratch.pose[d, b] = pose[d, b] + dp
            else:
                scratch.phi[d - 3, b] = dp
            scratch.twist[d, b] = twist[d, b] + dt
        for d in range(4):
            scratch.pose[3 + d, b] = pose[3 + d, b]
        turn(scratch.pose[3:7], b, scratch.phi[0, b], scratch.phi[1, b], scratch.phi[2, b])


@jit.kernel(inline="always")
def body_rates(scratch, st):
    """Stage ``st``'s position-like derivatives: the velocity v and the rotation vector's rate dexp^-1_phi(w)."""
    twist, phi = scratch.twist, scratch.phi
    for b in range(twist.shape[1]):
        for d in range(3):
            scratch.kpose[st, d, b] = twist[d, b]
        r0, r1, r2 = dexp_inverse(phi[0, b], phi[1, b], phi[2, b], twist[3, b], twist[4, b], twist[5, b])
        scratch.kpose[st, 3, b] = r0
        scratch.kpose[st, 4, b] = r1
        scratch.kpose[st, 5, b] = r2


@jit.kernel(inline="always")
def combine_bodies(bodies, scratch, b_weights, h):
    """The step's end for the bodies: r += h sum_s b_s v_s, q <- exp(h sum_s b_s phi'_s) q, twist likewise."""
    pose, twist = bodies
    for b in range(pose.shape[1]):
        for d in range(6):
            dp = 0.0
            dt = 0.0
            for st in range(b_weights.shape[0]):
                dp += b_weights[st] * scratch.kpose[st, d, b]
                dt += b_weights[st] * scratch.ktwist[st, d, b]
            if d < 3:
                pose[d, b] += h * dp
            else:
                scratch.phi[d - 3, b] = h * dp
            twist[d, b] += h * dt
        turn(pose[3:7], b, scratch.phi[0, b], scratch.phi[1, b], scratch.phi[2, b])


@jit.kernel
def advance_rk(state, tables, scratch, held, mass, gamma, params, limits, schedule, frames, bodies):
    """Advance ``schedule.n_steps`` Runge-Kutta steps in place; the contract of :mod:`ropesim.integrate.base`.

    ``state`` = (x, v, ledger); ``tables`` = (a, b, c); ``gamma`` (N,) is b / m (zero for held nodes);
    ``bodies`` the free rigid bodies' state (pose, twist). Returns (steps done, frames written, status, node).
    """
    x, v, ledger = state
    a, b, c = tables
    xs, vs, kx, kv, acc, acc_box = scratch.xs, scratch.vs, scratch.kx, scratch.kv, scratch.acc, scratch.acc_box
    held_idx, held_v = held.idx, held.v
    h = schedule.h
    dim, n = x.shape
    stages = b.shape[0]
    frame = np.int64(0)   # not the literal 0: Numba would compile the frame saving twice (for 0, then int64)
    for s in range(schedule.n_steps):
        step = schedule.step0 + s
        t = step * h
        for st in range(stages):
            stage_state(x, v, kx, kv, a, st, h, xs, vs)
            place(xs, vs, held, t + c[st] * h, t + 0.5 * h)   # a path: this step's piece
            for j in range(held_idx.shape[0]):
                for d in range(dim):
                    vs[d, held_idx[j]] = held_v[d, j]
            if WITH_BODIES:
                body_stage(bodies, scratch, a, st, h)
                place_attachments(xs, vs, params.bodies, scratch.pose, scratch.twist)
                body_rates(scratch, st)
            fluid, internal, seabed = accelerations(xs, vs, acc, params, t + c[st] * h)
            lost = 0.0
            for d in range(dim):
                for i in range(n):
                    kx[st, d, i] = vs[d, i]
                    kv[st, d, i] = acc[d, i] - gamma[i] * vs[d, i]
                    lost += gamma[i] * mass[i] * vs[d, i] * vs[d, i]
            if WITH_ADDED_MASS or WITH_JUNCTIONS:
                fluid += solve_accelerations(xs, vs, kv[st], params)
            if WITH_BODIES:
                fluid += body_accelerations(xs, vs, kv[st], params, scratch.pose, scratch.twist, scratch.ktwist[st],
                                            t + c[st] * h)
            for j in range(held_idx.shape[0]):
                for d in range(dim):
                    kv[st, d, held_idx[j]] = 0.0
            wh = b[st] * h
            ledger[DRAG] += wh * lost
            ledger[HELD] += wh * held_power(acc, mass, held)
            ledger[FLUID] += wh * fluid
            ledger[INTERNAL] += wh * internal
            ledger[SEABED] += wh * seabed
            if WITH_APPLIED:
                applied_accelerations(xs, vs, acc_box, params)
                ledger[BOX] += wh * power(acc_box, vs, mass)
        combine(x, v, kx, kv, b, h)
        place(x, v, held, (step + 1) * h, (step + 1) * h)
        if WITH_BODIES:
            combine_bodies(bodies, scratch, b, h)
            place_attachments(x, v, params.bodies, bodies.pose, bodies.twist)
        done = step + 1
        if not due(done, schedule):
            continue  # nothing due: skip the call, whose array arguments cost more than a small rope's step
        status, node, frame = end_step(done, schedule, x, v, mass, params, ledger, limits, frames, frame, bodies)
        if status != OK:
            return s + 1, frame, status, node
    return schedule.n_steps, frame, OK, -1
