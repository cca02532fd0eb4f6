"""The stiff integrator: a two-stage, L-stable, singly diagonally implicit Runge-Kutta method (SDIRK2).

Alexander (1977): gamma = 1 - 1/sqrt(2), c = (gamma, 1), A = [[gamma, 0], [1 - gamma, gamma]], b = A's last row
(stiffly accurate). Second order; L-stable, so it is stable at any time step and damps modes far faster than
1/h (the stiff springs' stretching vibrations) instead of ringing them. For y = (x, v) and
y' = F = (v, a(x, v) - gamma_drag v), each stage solves Y = Yhat + beta F(t_s, Y) with beta = gamma h; drag is
inside F, so it is implicit too and strong drag never destabilises a step. Eliminating the stage velocity
V = (X - Xhat) / beta leaves, for the positions X of the free nodes,

    R(X) = M (1 + beta gamma_drag) (X - Xhat) - beta M Vhat - beta^2 M a(X, V(X)) = 0,

solved by Newton's method. Its Jacobian, M (1 + beta gamma_drag) + beta^2 H + beta C_v (H the force terms'
stiffness, C_v their velocity damping, each term's blocks from its own module through the term list's
:func:`~ropesim.model.terms.coupling_jacobian` and :func:`~ropesim.model.terms.node_jacobian`), couples each
node only to its neighbours and second neighbours: a block banded matrix (:mod:`ropesim.model.jacobian`),
factored by a banded Cholesky in O(N) per iteration (:mod:`ropesim.model.banded`). On a closed loop the
wrap-around couples the first and last nodes; a Woodbury correction of rank w D (w = 1, or 2 with bending)
handles it, still O(N). Negative (compressive) geometric stiffness is left out
of the Jacobian so the matrix stays symmetric positive definite: Newton then converges a little more slowly
where springs are compressed, but to the same exact stage solution. Held nodes sit at x0 + V (t + c_s h) in
every stage.

A system of lines: each line's block is banded as a rope's, and the lines meet only at free points, whose line
ends move as one (:mod:`ropesim.model.junctions`), and at free rigid bodies, whose line ends follow them: a
point's nodes share one unknown, its equation the sum of its nodes' (its residual folded onto its first node);
a body's unknowns are its reference point and a rotation vector, its equation its Newton-Euler equations
(:mod:`ropesim.integrate.sdirk_bodies`). The matrix is solved with each line banded and the points' and bodies'
unknowns by a Schur complement (:mod:`ropesim.model.schur`), still O(N). Behind the compile-time switches of
junctions and bodies: a rope compiles none of it.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..model.jacobian import Jacobian, band_width
from ..model.forces.added_mass import added_mass_times
from ..model.junctions import (WITH_JUNCTIONS, add_junction_added_mass_jacobian, fold_junctions,
                               junction_added_mass_residual)
from ..model.bodies import WITH_BODIES
from ..model.schur import model_groups, schur_factor, schur_solve
from ..model.terms import (WITH_ADDED_MASS, WITH_APPLIED, accelerations, applied_accelerations, body_accelerations,
                           coupling_reach, newton_matrix, solve_accelerations)
from ..model.banded import factor, solve, woodbury
from .base import Integrator, Method
from .sdirk_bodies import (body_stage, end_step_bodies, guess_stage, next_stage, place_stage, stage_rows,
                           start_step, take_back_half_bodies, take_body_update)
from .health import BOX, DRAG, FLUID, HELD, INTERNAL, NEWTON_FAILED, OK, SEABED, due, end_step, held_power, place, power
from ..model import jit

GAMMA = 1.0 - 1.0 / math.sqrt(2.0)
NEWTON_TOL = 1e-11      # Newton stops when no free node's position changes by more than this times l
NEWTON_MAX_ITER = 60     # residual evaluations per stage, halvings included
BACKTRACK_ABOVE = 1e3    # halve a step that raised the residual, unless it was within this many tolerances
MAX_HALVINGS = 8


@dataclass(frozen=True)
class Sdirk(Method):
    """The stiff integrator's description; the loop is :func:`advance_sdirk`."""

    name: str
    order: int
    doc: str
    kind: str = "implicit"
    unconditionally_stable = True

    @property
    def family(self) -> type:
        return SdirkFamily

    @property
    def evaluations(self) -> int:
        """Nominal force evaluations per step: two stages of about two Newton iterations (counted exactly in
        the accuracy report)."""
        return 4

    @property
    def reuses_last_force(self) -> bool:
        return False

    @property
    def stability_limit(self) -> float:
        return math.inf

    def amplification(self, h: float, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0):
        lin = np.array([[0.0, 1.0], [-omega * omega, -(gamma_force + gamma_drag)]]) * h
        inverse = np.linalg.inv(np.eye(2) - GAMMA * lin)
        k1 = inverse @ lin
        k2 = inverse @ lin @ (np.eye(2) + (1 - GAMMA) * k1)
        return np.eye(2) + (1 - GAMMA) * k1 + GAMMA * k2


SDIRK2 = Sdirk("sdirk2", 2,
               "The stiff integrator: L-stable two-stage SDIRK (Alexander 1977), second order, stable at any "
               "time step; each stage a Newton solve with the rope's banded Jacobian (O(N)), drag implicit.")

Newton = namedtuple("Newton", ["jac", "wood", "rhs", "cyclic", "tol", "step", "groups", "body"])
"""The Newton solve's matrix (:class:`~ropesim.model.jacobian.Jacobian`), Woodbury arrays, right-hand side
(N D,), whether the loop wraps around, the tolerance [m] on the largest position update, the last update
(N D,), a system's groups of nodes that move as one (:class:`~ropesim.model.schur.Groups`), and its free
bodies' stage state (:class:`~ropesim.integrate.sdirk_bodies.BodyStage`); None for what a scene does not have."""

Stage = namedtuple("Stage", ["xh", "vh", "X", "V", "acc", "acc_box", "tmp"])
"""A stage's known part (xh, vh), its unknowns (X, V), the accelerations there and scratch, all (D, N)."""


def node_arrays(model) -> tuple:
    """Per node: (free (not held), mass [kg], linear drag b [kg/s], 0 at held nodes). A plain tuple, the type the
    static solver hands :func:`~ropesim.model.terms.newton_matrix` too: a scene with a static start then compiles
    the Newton matrix once, for both (a named tuple is another type to Numba, and compiled it again)."""
    return np.ascontiguousarray(~model.held), model.mass, np.where(model.held, 0.0, model.drag)


class SdirkFamily(Integrator):
    """The stiff family: SDIRK2 with a banded Newton solve per stage; ``stats[0]`` counts Newton iterations."""

    STATE = ("stats",)

    def __init__(self, model, grid, method: Sdirk):
        super().__init__(model, grid, method)
        scene = model.scene
        dim, n = model.dim, model.nodes
        w, cyclic = band_width(any(line.closed for line in model.lines), n, coupling_reach(scene))
        nt, m = dim * n, w * dim
        jac = Jacobian(np.zeros(((w + 1) * dim, nt)), np.zeros((m, m)), np.zeros((dim, dim)), w)
        tol = NEWTON_TOL * min(line.segment_length for line in model.lines)
        grouped = {WITH_JUNCTIONS.name, WITH_BODIES.name} & model.switches
        groups = model_groups(model, w) if grouped else None   # a rope's: none
        body = body_stage(model, groups) if WITH_BODIES.name in model.switches else None
        self.newton = Newton(jac, woodbury(nt, m), np.zeros(nt), cyclic, tol, np.zeros(nt), groups, body)
        shape = (dim, n)
        self.stage = Stage(*(np.zeros(shape) for _ in Stage._fields))
        self.nodes = node_arrays(model)
        self.stats = np.zeros(1, dtype=np.int64)

    @staticmethod
    def template():
        return advance_sdirk

    @property
    def force_evaluations(self) -> int:
        """Newton iterations so far."""
        return int(self.stats[0])

    def loop_args(self, n, frames):
        return ((self.x, self.v, self.ledger, self.stats), self.stage, self.newton, self.held, self.nodes,
                self.model.params, self.limits, self.schedule(n), frames, self.bodies)


@jit.kernel(inline="always")
def stage_velocities(stage, beta, held, params, body, groups):
    """The stage's velocities V = (X - xh) / beta at its positions X (held nodes: their own velocity; a free
    body's line ends where its stage pose puts them), the state at which :func:`stage_residual` takes the
    accelerations. Inlined: a call hands over the parameter bundle by value, which a small rope's Newton
    iteration would feel."""
    xh, X, V = stage.xh, stage.X, stage.V
    held_idx, held_v = held.idx, held.v
    dim, n = X.shape
    for d in range(dim):
        for i in range(n):
            V[d, i] = (X[d, i] - xh[d, i]) / beta
    for j in range(held_idx.shape[0]):
        for d in range(dim):
            V[d, held_idx[j]] = held_v[d, j]
    if WITH_BODIES:
        place_stage(body, X, V, beta, params.bodies, groups.arm)


@jit.kernel
def stage_residual(stage, rhs, beta, t_stage, nodes, params, body, groups):
    """From the accelerations ``stage.acc`` at the stage's X and V (:func:`stage_velocities`), write minus the
    residual of m (V - vh) = beta (a(X, V) m - b V) (plus A_i (V - vh) with added mass), times beta, into ``rhs``
    (a body's: its own, into its group's, see :mod:`ropesim.integrate.sdirk_bodies`). Returns its squared norm.

    The accelerations are the caller's to take (:func:`solve_stage`): called from here, the term list would be
    linked into this function's own compiled library, and optimised and emitted there once more."""
    xh, vh, X, acc = stage.xh, stage.vh, stage.X, stage.acc
    free, mass, drag = nodes
    dim, n = X.shape
    for i in range(n):
        for d in range(dim):
            u = i * dim + d
            if free[i]:
                m = mass[i]
                rhs[u] = -((m + beta * drag[i]) * (X[d, i] - xh[d, i]) - beta * m * vh[d, i]
                           - beta * beta * m * acc[d, i])
            else:
                rhs[u] = 0.0
        if WITH_ADDED_MASS and free[i]:   # + A_i (X - xh - beta vh)
            w0 = X[0, i] - xh[0, i] - beta * vh[0, i]
            w1 = X[1, i] - xh[1, i] - beta * vh[1, i]
            w2 = X[2, i] - xh[2, i] - beta * vh[2, i] if dim == 3 else 0.0
            extra = added_mass_times(X, i, w0, w1, w2, params.added_mass, params.neighbours)
            for d in range(dim):
                rhs[i * dim + d] -= extra[d]
    if WITH_JUNCTIONS:   # a point's equation: the sum of its nodes' (with their added mass)
        if WITH_ADDED_MASS:
            junction_added_mass_residual(X, xh, vh, beta, rhs, params.junctions, params.neighbours)
        fold_junctions(rhs, params.junctions, dim)
    norm = 0.0
    if WITH_BODIES:
        norm += stage_rows(body, X, acc, beta, beta, t_stage, params, groups, rhs)
    for u in range(rhs.shape[0]):
        norm += rhs[u] * rhs[u]
    return norm


@jit.kernel
def take_update(X, rhs, step):
    """X += the Newton update in ``rhs``, kept in ``step``. Returns (its largest component [m], that node)."""
    dim, n = X.shape
    worst = 0.0
    worst_node = -1
    for i in range(n):
        for d in range(dim):
            dx = rhs[i * dim + d]
            step[i * dim + d] = dx
            X[d, i] += dx
            if not abs(dx) <= worst:
                worst = abs(dx)
                worst_node = i
    return worst, worst_node


@jit.kernel
def take_back_half(X, step):
    """Halve the last update ``step`` and take that half back from X."""
    dim, n = X.shape
    for i in range(n):
        for d in range(dim):
            step[i * dim + d] *= 0.5
            X[d, i] -= step[i * dim + d]


@jit.kernel(inline="always")
def solve_stage(stage, newton, beta, t_stage, t_piece, held, nodes, params):
    """Newton solve of one stage: X = xh + beta V, V = vh + beta (a(X, V) - gamma V). Returns
    (iterations, node, fluid power [W], internal-damping power [W]): iterations < 0 when it failed, naming the
    node that moved most in the last one. With added mass the stage's equation is M (V - vh) = beta (F - b V),
    M = m I + A per node (:mod:`ropesim.model.forces.added_mass`)."""
    xh, vh, X, V = stage.xh, stage.vh, stage.X, stage.V
    free = nodes[0]
    band, rhs = newton.jac.band, newton.rhs
    dim, n = X.shape
    p = band.shape[0] - 1
    for d in range(dim):
        for i in range(n):
            X[d, i] = xh[d, i] + beta * vh[d, i]
    if WITH_BODIES:
        guess_stage(newton.body, beta)
    place(X, V, held, t_stage, t_piece)   # a path: the step's piece (t_piece its middle)
    worst_node = -1
    last = np.inf            # the residual's norm before the last update
    stride = 0.0             # the last update's largest component [m]
    halvings = 0
    for it in range(NEWTON_MAX_ITER):
        stage_velocities(stage, beta, held, params, newton.body, newton.groups)
        fluid, internal, seabed = accelerations(X, V, stage.acc, params, t_stage)
        norm = stage_residual(stage, rhs, beta, t_stage, nodes, params, newton.body, newton.groups)
        if norm > last and stride > BACKTRACK_ABOVE * newton.tol and halvings < MAX_HALVINGS:
            # the full step made the residual worse (a contact switching on, friction reversing): go back half
            # of it and look again; a smooth problem never gets here, so its iterates are Newton's own
            halvings += 1
            stride *= 0.5
            take_back_half(X, newton.step)
            if WITH_BODIES:
                take_back_half_bodies(newton.body)
            continue
        last = norm
        halvings = 0
        newton_matrix(X, V, newton.jac, beta, nodes, params, t_stage)
        if WITH_JUNCTIONS or WITH_BODIES:   # each line banded, the points' and bodies' unknowns by a Schur complement
            if WITH_JUNCTIONS and WITH_ADDED_MASS:
                add_junction_added_mass_jacobian(X, band, params.junctions, params.neighbours)
            if not schur_factor(band, newton.jac.w, params.lines, newton.groups):
                return -1, 0, 0.0, 0.0, 0.0
            schur_solve(band, newton.jac.w, params.lines, newton.groups, rhs)
        else:
            if not factor(band, newton.jac.corner, newton.cyclic, p, newton.wood):
                return -1, 0, 0.0, 0.0, 0.0
            solve(band, newton.jac.corner, newton.cyclic, p, rhs, newton.wood)
        stride, worst_node = take_update(X, rhs, newton.step)
        if WITH_BODIES:
            stride = max(stride, take_body_update(newton.body, newton.groups))
        if stride <= newton.tol:
            for d in range(dim):
                for i in range(n):
                    if free[i]:
                        V[d, i] = (X[d, i] - xh[d, i]) / beta
            if WITH_BODIES:
                place_stage(newton.body, X, V, beta, params.bodies, newton.groups.arm)
            return it + 1, -1, fluid, internal, seabed
    return -1, worst_node, 0.0, 0.0, 0.0


@jit.kernel
def advance_sdirk(state, stage, newton, held, nodes, params, limits, schedule, frames, bodies):
    """Advance ``schedule.n_steps`` SDIRK2 steps in place; the contract of :mod:`ropesim.integrate.base`.

    ``state`` = (x, v, ledger, stats), ``stats[0]`` counting Newton iterations (force evaluations). Returns
    (steps done, frames written, status, node).
    """
    x, v, ledger, stats = state
    xh, vh, X, V, acc, acc_box, tmp = stage
    free, mass, drag = nodes
    h = schedule.h
    dim, n = x.shape
    beta = GAMMA * h
    frame = np.int64(0)   # not the literal 0: Numba would compile the frame saving twice (for 0, then int64)
    for s in range(schedule.n_steps):
        step = schedule.step0 + s
        t = step * h
        for d in range(dim):
            for i in range(n):
                xh[d, i] = x[d, i]
                vh[d, i] = v[d, i]
        if WITH_BODIES:
            start_step(newton.body, bodies.pose, bodies.twist)
        for k in range(2):
            t_stage = t + (GAMMA if k == 0 else 1.0) * h
            its, node, fluid, internal, seabed = solve_stage(stage, newton, beta, t_stage, t + 0.5 * h, held, nodes,
                                                             params)
            if its < 0:
                return s, frame, NEWTON_FAILED, node
            stats[0] += its
            weight = (1.0 - GAMMA if k == 0 else GAMMA) * h
            lost = 0.0
            for d in range(dim):
                for i in range(n):
                    lost += drag[i] * V[d, i] * V[d, i]
            ledger[DRAG] += weight * lost
            ledger[HELD] += weight * held_power(acc, mass, held)
            if WITH_ADDED_MASS:   # the fluid's inertial force, m a - F, at the stage
                for d in range(dim):
                    for i in range(n):
                        tmp[d, i] = acc[d, i] - drag[i] * V[d, i] / mass[i]
                fluid += solve_accelerations(X, V, tmp, params)
            if WITH_BODIES:   # the fluid's forces on the bodies (drag, added mass) at the stage
                fluid += body_accelerations(X, V, acc, params, newton.body.pose, newton.body.twist, newton.body.out,
                                            t_stage)
            ledger[FLUID] += weight * fluid
            ledger[INTERNAL] += weight * internal
            ledger[SEABED] += weight * seabed
            if WITH_APPLIED:
                applied_accelerations(X, V, acc_box, params)
                ledger[BOX] += weight * power(acc_box, V, mass)
            if k == 0:
                ratio = (1.0 - GAMMA) / GAMMA
                for d in range(dim):
                    for i in range(n):
                        xh[d, i] = x[d, i] + (1.0 - GAMMA) * h * V[d, i]
                        vh[d, i] = v[d, i] + ratio * (V[d, i] - v[d, i])
                if WITH_BODIES:
                    next_stage(newton.body, bodies.twist, h, GAMMA)
        for d in range(dim):
            for i in range(n):
                x[d, i] = X[d, i]
                v[d, i] = V[d, i]
        if WITH_BODIES:
            end_step_bodies(newton.body, bodies.pose, bodies.twist)
        place(x, v, held, (step + 1) * h, (step + 1) * h)
        done = step + 1
        if not due(done, schedule):
            continue  # nothing due: skip the call, whose array arguments cost more than a small rope's step
        status, node, frame = end_step(done, schedule, x, v, mass, params, ledger, limits, frames, frame, bodies)
        if status != OK:
            return s + 1, frame, status, node
    return schedule.n_steps, frame, OK, -1
