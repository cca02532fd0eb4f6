"""Explicit Runge-Kutta methods as Butcher tables, run by one compiled loop.

For the rope, y = (x, v) and y' = F(t, y) = (v, a(x, v) - gamma v): the linear drag is an ordinary term of F
(a Runge-Kutta method keeps its order with any smooth force, so nothing special is needed), and held nodes
are placed at x0 + V (t + c_i h) at every stage, with stage velocity V and no acceleration. Stage s computes

    Y_s = y + h sum_{j<s} a_sj K_j,   K_s = F(t + c_s h, Y_s),   y <- y + h sum_s b_s K_s.

Unlike the splitting schemes these methods are not symplectic: their energy error drifts (RK4 dissipates).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..model.junctions import WITH_JUNCTIONS
from ..model.terms import WITH_ADDED_MASS, WITH_APPLIED, accelerations, applied_accelerations, solve_accelerations
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

RKScratch = namedtuple("RKScratch", ["xs", "vs", "kx", "kv", "acc", "acc_box"])
"""Stage positions and velocities (D, N), stage derivatives (S, D, N), accelerations (D, N)."""


class RungeKuttaFamily(Integrator):
    """The explicit Runge-Kutta family: any :class:`RungeKutta` table, drag an ordinary term of the derivative."""

    def __init__(self, model, grid, method: RungeKutta):
        super().__init__(model, grid, method)
        stages = len(method.b)
        self.tables = method.tables()
        shape = self.x.shape
        self.scratch = RKScratch(np.zeros(shape), np.zeros(shape), np.zeros((stages,) + shape),
                                 np.zeros((stages,) + shape), np.zeros(shape), np.zeros(shape))
        self.gamma = np.where(model.held, 0.0, model.drag / model.mass)

    @staticmethod
    def template():
        return advance_rk

    @property
    def force_evaluations(self) -> int:
        return self.step * self.method.evaluations

    def _run(self, n, frames):
        m = self.model
        return self.loop((self.x, self.v, self.ledger), self.tables, self.scratch, self.held, m.mass, self.gamma,
                         m.params, self.limits, self.schedule(n), frames)


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


@jit.kernel
def advance_rk(state, tables, scratch, held, mass, gamma, params, limits, schedule, frames):
    """Advance ``schedule.n_steps`` Runge-Kutta steps in place; the contract of :mod:`ropesim.integrate.base`.

    ``state`` = (x, v, ledger); ``tables`` = (a, b, c); ``gamma`` (N,) is b / m (zero for held nodes).
    Returns (steps done, frames written, status, node).
    """
    x, v, ledger = state
    a, b, c = tables
    xs, vs, kx, kv, acc, acc_box = scratch
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
            fluid, internal, seabed = accelerations(xs, vs, acc, params, t + c[st] * h)
            lost = 0.0
            for d in range(dim):
                for i in range(n):
                    kx[st, d, i] = vs[d, i]
                    kv[st, d, i] = acc[d, i] - gamma[i] * vs[d, i]
                    lost += gamma[i] * mass[i] * vs[d, i] * vs[d, i]
            if WITH_ADDED_MASS or WITH_JUNCTIONS:
                fluid += solve_accelerations(xs, vs, kv[st], params)
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
        done = step + 1
        if not due(done, schedule):
            continue  # nothing due: skip the call, whose array arguments cost more than a small rope's step
        status, node, frame = end_step(done, schedule, x, v, mass, params, ledger, limits, frames, frame)
        if status != OK:
            return s + 1, frame, status, node
    return schedule.n_steps, frame, OK, -1
