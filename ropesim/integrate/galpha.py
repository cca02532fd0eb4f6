"""The structural integrator: generalized-alpha (Chung & Hulbert 1993), implicit, second order, with modified Newton.

For M x'' = F(t, x, x') - b x' (b the linear drag; the added mass in M), one step from (x_n, v_n, a_n) solves

    M a_(n+1-am) = F(t_(n+1-af), x_(n+1-af), v_(n+1-af)) - b v_(n+1-af),
    x_(n+1) = x_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_(n+1)),   v_(n+1) = v_n + h ((1 - gam) a_n + gam a_(n+1)),

with y_(n+1-a) = (1 - a) y_(n+1) + a y_n. From the user's rho_inf (the spectral radius at h omega -> infinity,
``integrator.rho_inf``, 0 <= rho_inf <= 1): am = (2 rho - 1) / (rho + 1), af = rho / (rho + 1), gam = 1/2 - am + af,
beta = (1 - am + af)^2 / 4: second order, unconditionally stable, and the largest damping of the high modes for
the least of the low ones. rho_inf = 1 is the trapezoidal rule (no numerical dissipation, energy kept to second
order), rho_inf = 0 annihilates the highest modes in one step (asymptotic annihilation).

The unknown is X = x_(n+1-af), the point where the forces are evaluated. Everything else is linear in it:
V = v_(n+1-af) = Vk + (X - Xk) / beta_v with beta_v = beta h / gam, and the equation, times
c2 = (1 - af) beta h^2 / (1 - am), reads M (X - Xa) = c2 (F(X, V) - b V) (Xk, Xa, Vk known from the step's start;
:func:`step_start`). Newton's matrix is M + c2 K + (c2 / beta_v) (C + b), K and C the forces' stiffness and
damping: the same block-banded shape as SDIRK2's M + s^2 K + s C (:mod:`ropesim.integrate.sdirk`), which is
assembled with s = sqrt(c2): the stiffness is exact, the linear drag is corrected on the diagonal, and the other
damping's weight is off by the factor gam sqrt((1 - af) / ((1 - am) beta)) (1 at rho_inf = 1, at most 1.06 at
rho_inf = 0), which slows Newton's convergence by a few per cent and never changes its solution. Each line is
banded and a system's points and free rigid bodies are joined by a Schur complement (:mod:`ropesim.model.schur`),
as in SDIRK2; a body's six unknowns (its reference point and a rotation vector on its orientation) are stepped as
the nodes are (:mod:`ropesim.integrate.galpha_bodies`).

Modified Newton: the matrix is factored when the step size changes by more than REUSE_WITHIN or when Newton converges
slowly (an update not smaller than RATE_REFACTOR times the one before it), and is otherwise reused, across steps too.
A free body's updates are watched on their own (its block goes stale as it turns): with a matrix from an earlier
step, one above BODY_RATE_REFACTOR times the body's last is not convergence, and factors the matrix again. Without
that, the stale block's few 1e-15 m of error a step, divided by beta_v into the body's velocities, added up over many
small steps (the tumbling tripod at 78 us: its angular velocity 1.1e-6 rad/s off after 0.1 s, 6e-8 with it, near a
fresh matrix every step). With fixed steps Newton stops once its remaining error is below NEWTON_SHARE of the step's
own truncation estimate (at most NEWTON_LOOSEST; :func:`solve_step`). A full update that raises the residual (a
contact switching on, a segment going slack) is halved (a backtracking line search). The non-smooth terms are not
regularised beyond what the force terms already do (the seabed's onset and the friction have their own smoothing
lengths, see the seabed's docs), with two exceptions (:mod:`ropesim.model.forces.seabed`): MoorDyn's two-way seabed
damping (``damping_both_ways``), a force that jumps by c A |v . n| at first contact, grows in over the seabed's
delta_d for galpha; and ropesim's own one-way damping, which switches on and off at v . n = 0, does so smoothly over
v_reg; compressive geometric stiffness is left out of the matrix as in SDIRK2.

For a stiff line read by its tension (a mooring), rho_inf = 0 is the setting: af = 0, so the force balance is
solved at the step's end itself and the tension at a step end (EA times its strain) is the solved one; with
af > 0 the step end is extrapolated from the force point by 1 / (1 - af), and on WD0050 at 0.1 s steps the
fairlead tension was 20 times less accurate at rho_inf = 0.9 (6.3 % of its range against 0.32 %; 5.6 % at 0.5,
3.5 % at 0.2). The default stays 0.9: at 0 the scheme's error constant is 4 times larger (a soft line's
positions take twice the steps at a tolerance), the vacuum pendulum's energy error no longer falls at its
order over the accuracy tests' steps (slopes 2.5, 2.0), and a run continued from a frame, whose a_n is
recomputed from the forces, differs by 2e-4 m instead of 8e-7 m (a_n lags the true acceleration by a step).

The energy ledger books each step's flows from their powers at this step's and the last step's force points,
read off at the step's middle on the line through both (:func:`book`): second order for every rho_inf.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..model import jit
from ..model.banded import factor, solve, woodbury
from ..model.forces.added_mass import added_mass_times
from ..model.forces.seabed import WITH_SEABED, depth
from ..model.forces.sea import WITH_WAVES, hold_waves
from ..model.jacobian import Jacobian, band_width
from ..model.bodies import WITH_BODIES, place_attachments
from ..model.junctions import (WITH_JUNCTIONS, add_junction_added_mass_jacobian, fold_junctions,
                               junction_added_mass_residual)
from ..model.schur import model_groups, schur_factor, schur_solve
from ..model.terms import (WITH_ADDED_MASS, WITH_APPLIED, accelerations, applied_accelerations, coupling_reach,
                           newton_matrix, solve_accelerations)
from .base import Integrator, Method
from .health import BOX, DRAG, FLUID, HELD, INTERNAL, NEWTON_FAILED, OK, SEABED, due, end_step, held_power, place, power
from .galpha_bodies import (body_alpha, dense_output_bodies, error_ratio_bodies, fluid_power_bodies,
                            keep_step_start_bodies, raw_error_bodies, rotation_stride, rows_bodies,
                            start_accelerations_bodies, state_names, step_end_bodies, step_start_bodies)
from .galpha_adaptive import (ACCEPTED, EST_MAX, EST_SUM, H_MAX, H_MIN, H_NEXT, NEWTON_FRACTION, NEWTON_SHRINK,
                              REJECTED, RTOL, SMALLEST, T0, T1, TOL, LIMITING, WITH_ADAPTIVE, dense_output, error_ratio,
                              land, new_adapt, next_step, raw_error)
from .sdirk import take_back_half, take_update
from .sdirk_bodies import place_stage, take_back_half_bodies, take_body_update

DEFAULT_RHO_INF = 0.9
NEWTON_TOL = 1e-9        # on the largest position update, times the shortest segment: a strain of 1e-9 (EA 1e-9,
# 1.7 N on WD0050's chain; SDIRK2's 1e-11 cost galpha two to three more iterations a step at a mooring's steps)
NEWTON_TOL_STEP = 0.01   # [s] below this fixed step Newton's tolerance shrinks with the step, down to NEWTON_TOL_FLOOR:
# the velocity update is the position update times 1 / (beta_v dt), so a fixed strain left per step grows into the
# velocities as the step shrinks (a tumbling body's quaternion stopped converging below 0.3 ms at 1e-9)
NEWTON_TOL_FLOOR = 1e-11  # SDIRK2's
NEWTON_STRAIN = 1e-6      # with adaptive steps Newton stops at a hundredth of the tolerance, but at most this strain
# of the shortest segment (an unconverged solve is an error in every segment's force balance, EA times it)
NEWTON_SHARE = 0.1       # with fixed steps Newton stops once its remaining error is below this share of the step's own
# truncation estimate (Hairer & Wanner IV.8 stop at 0.01 to 0.1 of the error tolerance), times h / NEWTON_TOL_STEP
# below that step: a position error e left in X is an error e / beta_v in V, which grows as 1 / h against the
# velocity's own local error (without the factor, a pinned chain at 1 ms left solve errors of 0.74 times the scheme's
# own error; with it 0.056, tests/test_from_run.py): the solve then adds at most a tenth to the step's error. On
# WD0050 at 0.1 s, 4.0 instead of 6.25 iterations a step, the fairlead tension's error 0.4672 % of its range instead
# of 0.4662 %
NEWTON_LOOSEST = 1e-4     # ... but never looser than this strain of the shortest segment: the estimate is unfiltered
# (a stiff mode's, at a touchdown, is many times its true error), and without a ceiling WD0050's Newton failed at a
# touchdown at 0.1 s after steps stopped centimetres short of their force balance. Not at rho_inf = 1: a solve within
# a tenth of each step's position error is not within a tenth of the energy's, which the trapezoidal rule keeps
# bounded (the vacuum pendulum's energy error at 2 ms grew by 15 %, its fitted order 2.18 instead of 2.00). Nor
# on a system of lines (points, free bodies): the clump weight's stiff wires at 1 ms took 10 % more error (fitted
# order 2.08 against 2 +- 0.05), 25 % with the carried rate below, and the torque-free body's energy and the tumbling
# body's velocities no longer converged at second order with it (tests/test_galpha*.py)
CARRY_GROWTH = 2.0        # with the share, a step's first update is judged by the last measured rate of a first
# update (the carried matrix's contraction, kept in control[FIRST_RATE]); each step that stops on it doubles it, so
# one in a few steps measures it again (WD0050 at 6.25 ms: 1.74 iterations a step instead of 2.01, the error the
# same to 3 digits; at 1.25 instead of 2: 1.61, but 10 % more error at 25 ms; the rate at a step's end, Radau5's
# choice, was 30 times too optimistic: an error of 2.9 % at 0.1 s)
NEWTON_MAX_ITER = 60     # residual evaluations per step, halvings included
RATE_REFACTOR = 0.1      # an update larger than this times the one before it: factor the matrix again (two
# iterations' cost; at 0.25 a stale matrix crawled on at rates of 0.15 to 0.23 for ten iterations at WD0050's touchdown)
REUSE_WITHIN = 0.25      # a matrix factored for a step within this fraction of the step is reused
BACKTRACK_ABOVE = 1e3    # halve an update that raised the residual, unless it was within this many times NEWTON_TOL
# (of the shortest segment, at most the step's tolerance times it: a looser stopping test keeps the line search)
MAX_HALVINGS = 8
BODY_RATE_REFACTOR = 1e-3   # a free body's update larger than this times its last: factor again (see solve_step)

# the control array: the step the matrix was factored for (0: none), whether a_n holds the start's acceleration,
# the last step (0: none), the rate of the last measured first update (0: none)
FACTORED_H, STARTED, LAST_H, FIRST_RATE = 0, 1, 2, 3
# the statistics: Newton iterations, factorisations, steps taken
ITERATIONS, FACTORISATIONS, STEPS = 0, 1, 2


def coefficients(rho_inf: float) -> tuple[float, float, float, float]:
    """(alpha_m, alpha_f, gamma, beta) of Chung & Hulbert's generalized-alpha for a spectral radius rho_inf."""
    am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
    af = rho_inf / (rho_inf + 1.0)
    gam = 0.5 - am + af
    return am, af, gam, 0.25 * (1.0 - am + af) ** 2


@dataclass(frozen=True)
class GeneralizedAlpha(Method):
    """The structural integrator's description; the loop is :func:`advance_galpha`."""

    name: str
    order: int
    doc: str
    kind: str = "implicit"
    rho_inf: float = DEFAULT_RHO_INF
    unconditionally_stable = True
    starts_from_x_and_v = False

    @property
    def family(self) -> type:
        return GeneralizedAlphaFamily

    @property
    def evaluations(self) -> int:
        """Nominal force evaluations per step: about two Newton iterations (counted exactly in the accuracy
        report)."""
        return 2

    @property
    def reuses_last_force(self) -> bool:
        return False

    @property
    def stability_limit(self) -> float:
        return math.inf

    def amplification(self, h: float, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0,
                      rho_inf: float | None = None):
        """One step's 3x3 map of (x, v, a) for x'' = -omega^2 x - (gamma_force + gamma_drag) x' (the scheme
        carries the acceleration: its spectral radius is rho_inf as h omega -> infinity)."""
        am, af, gam, beta = coefficients(self.rho_inf if rho_inf is None else rho_inf)
        k, c = omega * omega, gamma_force + gamma_drag
        # unknowns (x1, v1, a1) from (x0, v0, a0): three linear equations
        lhs = np.array([[1.0, 0.0, -beta * h * h], [0.0, 1.0, -gam * h],
                        [(1 - af) * k, (1 - af) * c, 1 - am]])
        rhs = np.array([[1.0, h, (0.5 - beta) * h * h], [0.0, 1.0, (1 - gam) * h],
                        [-af * k, -af * c, -am]])
        return np.linalg.solve(lhs, rhs)


GALPHA = GeneralizedAlpha(
    "galpha", 2,
    "The structural integrator: generalized-alpha (Chung & Hulbert 1993), implicit, second order, stable at "
    "any step, high modes damped by integrator.rho_inf; modified Newton on the banded matrix (O(N)).")

Work = namedtuple("Work", ["Xk", "Xa", "Vk", "X", "V", "acc", "acc_box", "tmp"])
"""The step's known parts (Xk, Xa, Vk), its unknowns at the force point (X, V), accelerations there and scratch,
all (D, N)."""

Newton = namedtuple("Newton", ["jac", "wood", "rhs", "cyclic", "tol", "step", "groups", "body", "loosest",
                               "backtrack"])
"""As SDIRK2's (:class:`ropesim.integrate.sdirk.Newton`), the free bodies' arrays those of
:class:`ropesim.integrate.galpha_bodies.BodyAlpha`; with fixed steps ``loosest`` [m] is the most the stopping test
may allow for a step's share of its truncation estimate (0: the adaptive steps, rho_inf = 1 and systems of lines,
Newton stops at ``tol``); ``backtrack`` [m]: an update above it that raised the residual is halved."""

Nodes = namedtuple("Nodes", ["free", "mass", "drag"])
"""Per node: free (not held), mass [kg], linear drag b [kg/s] (0 at held nodes)."""


class GeneralizedAlphaFamily(Integrator):
    """Generalized-alpha with a modified-Newton solve on the banded matrix. Its complete state adds to x and v the
    acceleration a_n, the statistics, the control flags and the factored matrix (reused across steps)."""

    def __init__(self, model, grid, method: GeneralizedAlpha):
        super().__init__(model, grid, method)
        scene = model.scene
        rho = getattr(scene.integrator, "rho_inf", None)
        self.rho_inf = method.rho_inf if rho is None else float(rho)
        self.coefficients = np.array(coefficients(self.rho_inf))
        dim, n = model.dim, model.nodes
        w, cyclic = band_width(any(line.closed for line in model.lines), n, coupling_reach(scene))
        nt, m = dim * n, w * dim
        jac = Jacobian(np.zeros(((w + 1) * dim, nt)), np.zeros((m, m)), np.zeros((dim, dim)), w)
        shortest = min(line.segment_length for line in model.lines)
        tol = shortest * max(NEWTON_TOL_FLOOR, NEWTON_TOL * min(1.0, grid.dt / NEWTON_TOL_STEP))
        grouped = {WITH_JUNCTIONS.name, WITH_BODIES.name} & model.switches
        groups = model_groups(model, w) if grouped else None   # a rope's: none
        body = body_alpha(model, groups) if WITH_BODIES.name in model.switches else None
        self.newton = Newton(jac, woodbury(nt, m), np.zeros(nt), cyclic, tol, np.zeros(nt), groups, body,
                             NEWTON_LOOSEST * shortest if self.rho_inf < 1.0 and groups is None else 0.0,
                             BACKTRACK_ABOVE * min(tol, NEWTON_TOL * shortest))
        self.work = Work(*(np.zeros((dim, n)) for _ in Work._fields))
        self.nodes = Nodes(np.ascontiguousarray(~model.held), model.mass, np.where(model.held, 0.0, model.drag))
        self.acc_n = np.zeros((dim, n))
        self.stats = np.zeros(3, dtype=np.int64)
        self.control = np.zeros(4)
        self.powers = np.zeros(6)
        # the factored matrix is state: a resumed run reuses it exactly as the uninterrupted one did
        self.matrix = {"band": jac.band, "corner": jac.corner,
                       **{f"wood_{f}": a for f, a in zip(self.newton.wood._fields, self.newton.wood)}}
        if groups is not None:
            self.matrix.update(schur_w=groups.w, schur_s=groups.s, schur_piv=groups.piv, schur_own=groups.own)
        for name, array in self.matrix.items():
            setattr(self, name, array)
        self.STATE = ("acc_n", "stats", "control", "powers", *self.matrix)
        self.adapt = None
        tol = scene.integrator.tolerance
        if body is not None:   # A_n, and the adaptive steps' last step's ends (from the bodies' starting state)
            for start, now in ((body.pose0, self.pose), (body.pose1, self.pose), (body.twist0, self.twist),
                               (body.twist1, self.twist)):
                start[:] = now
            for name, array in state_names(body, tol is not None).items():
                setattr(self, name, array)
                self.STATE += (name,)
        if tol is not None:   # the scheme's own steps; x, v on the grid by dense output
            rtol = scene.integrator.relative_tolerance or 0.0
            self.adapt = new_adapt(self.x, self.v, self.ledger, grid.dt, tol, rtol)
            strain = NEWTON_STRAIN * shortest
            self.newton = self.newton._replace(tol=max(NEWTON_TOL * shortest, min(NEWTON_FRACTION * tol, strain)),
                                               loosest=0.0)
            for name in self.adapt._fields:
                setattr(self, f"adapt_{name}", getattr(self.adapt, name))
            self.STATE += tuple(f"adapt_{name}" for name in self.adapt._fields)

    @classmethod
    def switches_for(cls, model, method) -> frozenset:
        """The model's switches, and the adaptive steps' with a tolerance."""
        adaptive = getattr(model.scene.integrator, "tolerance", None) is not None
        return model.switches | ({WITH_ADAPTIVE.name} if adaptive else set())

    def step_report(self) -> dict | None:
        """What the adaptive steps did, for summary.json (None with fixed steps)."""
        if self.adapt is None:
            return None
        clock, counts = self.adapt.clock, self.adapt.counts
        return {"tolerance_m": float(clock[TOL]), "relative_tolerance": float(clock[RTOL]),
                "steps_taken": int(counts[ACCEPTED]), "steps_rejected": int(counts[REJECTED]),
                "estimated_error_m": float(clock[EST_SUM]), "largest_local_error_m": float(clock[EST_MAX]),
                "smallest_step_s": float(clock[H_MIN]) if counts[ACCEPTED] else None,
                "largest_step_s": float(clock[H_MAX]) if counts[ACCEPTED] else None,
                "newton_iterations": int(self.stats[ITERATIONS]), "factorisations": int(self.stats[FACTORISATIONS])}

    @staticmethod
    def template():
        return advance_galpha

    @property
    def force_evaluations(self) -> int:
        """Newton iterations so far (one force evaluation each), plus the start's."""
        return int(self.stats[ITERATIONS])

    @property
    def factorisations(self) -> int:
        return int(self.stats[FACTORISATIONS])

    def _run(self, n, frames):
        return self.loop((self.x, self.v, self.acc_n, self.ledger, self.stats, self.control, self.powers), self.work,
                         self.newton, self.coefficients, self.held, self.nodes, self.model.params, self.limits,
                         self.schedule(n), frames, self.bodies, self.adapt)


@jit.kernel
def start_acceleration(x, v, an, tmp, t, held, nodes, params, bodies, body):
    """a_n = the accelerations at (x, v) at time t (drag, added mass, points and free bodies included; zero at held
    nodes); the free bodies' A_n into ``body``."""
    free, mass, drag = nodes
    dim, n = x.shape
    accelerations(x, v, an, params, t)
    for d in range(dim):
        for i in range(n):
            an[d, i] -= drag[i] * v[d, i] / mass[i]
    if WITH_ADDED_MASS or WITH_JUNCTIONS:
        solve_accelerations(x, v, an, params)
    if WITH_BODIES:
        start_accelerations_bodies(x, v, an, params, bodies.pose, bodies.twist, body, t)
    for i in range(n):
        if not free[i]:
            for d in range(dim):
                an[d, i] = 0.0


@jit.kernel
def step_start(x, v, an, work, co, h):
    """The step's known parts: Xk = x + (1 - af) (h v + h^2 (1/2 - beta) a), Xa = Xk - c2 am a,
    Vk = v + (1 - af) h (1 - gam) a, and the predictor X = x + (1 - af) (h v + h^2 a / 2) (a_(n+1) = a_n)."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    c2 = (1.0 - af) * beta * h * h / (1.0 - am)
    dim, n = x.shape
    for d in range(dim):
        for i in range(n):
            a = an[d, i]
            xk = x[d, i] + (1.0 - af) * (h * v[d, i] + h * h * (0.5 - beta) * a)
            work.Xk[d, i] = xk
            work.Xa[d, i] = xk - c2 * am * a
            work.Vk[d, i] = v[d, i] + (1.0 - af) * h * (1.0 - gam) * a
            work.X[d, i] = x[d, i] + (1.0 - af) * (h * v[d, i] + 0.5 * h * h * a)


@jit.kernel
def residual(work, rhs, c2, beta_v, t_f, held, nodes, params, body, groups):
    """At the force point X, with V = Vk + (X - Xk) / beta_v (held nodes: their own velocity), minus the
    residual M (X - Xa) - c2 (F(X, V) - b V) into ``rhs`` (a point's: the sum of its nodes'). Returns (its
    squared norm, fluid, internal-damping and seabed power [W]). A free body's line ends sit where its pose at the
    force point puts them, its residual in its group (:mod:`ropesim.integrate.galpha_bodies`)."""
    Xk, Xa, Vk, X, V, acc = work.Xk, work.Xa, work.Vk, work.X, work.V, work.acc
    free, mass, drag = nodes
    dim, n = X.shape
    for d in range(dim):
        for i in range(n):
            V[d, i] = Vk[d, i] + (X[d, i] - Xk[d, i]) / beta_v
    for j in range(held.idx.shape[0]):
        for d in range(dim):
            V[d, held.idx[j]] = held.v[d, j]
    if WITH_BODIES:
        place_stage(body.stage, X, V, beta_v, params.bodies, groups.arm)
    fluid, internal, seabed = accelerations(X, V, acc, params, t_f)
    for i in range(n):
        for d in range(dim):
            u = i * dim + d
            if free[i]:
                m = mass[i]
                rhs[u] = -(m * (X[d, i] - Xa[d, i]) + c2 * (drag[i] * V[d, i] - m * acc[d, i]))
            else:
                rhs[u] = 0.0
        if WITH_ADDED_MASS and free[i]:   # + A_i (X - Xa)
            w0 = X[0, i] - Xa[0, i]
            w1 = X[1, i] - Xa[1, i]
            w2 = X[2, i] - Xa[2, i] if dim == 3 else 0.0
            extra = added_mass_times(X, i, w0, w1, w2, params.added_mass, params.neighbours)
            for d in range(dim):
                rhs[i * dim + d] -= extra[d]
    if WITH_JUNCTIONS:
        if WITH_ADDED_MASS:
            junction_added_mass_residual(X, Xa, Xa, 0.0, rhs, params.junctions, params.neighbours)
        fold_junctions(rhs, params.junctions, dim)
    norm = 0.0
    if WITH_BODIES:
        norm += rows_bodies(body, X, V, acc, c2, beta_v, t_f, nodes, params, groups, rhs)
    for u in range(rhs.shape[0]):
        norm += rhs[u] * rhs[u]
    return norm, fluid, internal, seabed


@jit.kernel
def friction_slope(x, v, band, weight, free, seabed):
    """Make the seabed friction's block its exact slope along the sliding velocity s (the shared assembly,
    :func:`~ropesim.model.forces.seabed.add_seabed_jacobian`, puts mu N / S on the whole plane, S = sqrt(|s|^2 +
    v_reg^2)): take away weight mu N s s^T / S^3, leaving mu N (I - s s^T / S^2) / S, which is the derivative of
    mu N s / S (with mu the larger of the two friction coefficients, as there). Without it a node sliding well
    above v_reg carries a damping S^2 / v_reg^2 times too large, and Newton converges linearly at large steps
    (measured on mooring_chain at h = 0.1 s: a rate of 0.7 per iteration, and no convergence in 60)."""
    bed, area = seabed
    dim, n = x.shape
    nx, ny = -bed[3], bed[2]
    mu = max(bed[6], bed[7])
    if mu <= 0.0:
        return
    for i in range(n):
        if not free[i]:
            continue
        sunk = depth(x[0, i], x[1, i], bed)
        if sunk <= 0.0:
            continue
        vn = v[0, i] * nx + v[1, i] * ny
        s0, s1, s2 = v[0, i] - vn * nx, v[1, i] - vn * ny, v[2, i] if dim == 3 else 0.0
        slide2 = s0 * s0 + s1 * s1 + s2 * s2
        big = math.sqrt(slide2 + bed[8] * bed[8])
        c = weight * mu * bed[4] * sunk * area[i] / (big * big * big)
        s = (s0, s1, s2)
        for a in range(dim):
            for b in range(a + 1):
                band[a - b, i * dim + b] -= c * s[a] * s[b]


@jit.kernel
def factor_matrix(work, newton, c2, beta_v, t_f, nodes, params):
    """Assemble and factor M + c2 K + (c2 / beta_v) (C + b) at the force point (see the module doc). False when
    it is singular."""
    X, V = work.X, work.V
    free, mass, drag = nodes
    band = newton.jac.band
    dim, n = X.shape
    s = math.sqrt(c2)
    newton_matrix(X, V, newton.jac, s, (free, mass, drag), params, t_f)   # a plain tuple, as the static solve's:
    # the same compiled copy serves both (a namedtuple is another type, and compiled it again: 2.5 s)
    for i in range(n):   # the linear drag's exact weight c2 / beta_v, not s
        if free[i]:
            for d in range(dim):
                band[0, i * dim + d] += (c2 / beta_v - s) * drag[i]
    if WITH_SEABED:
        friction_slope(X, V, band, c2 / beta_v, free, params.seabed)
    if WITH_JUNCTIONS or WITH_BODIES:
        if WITH_JUNCTIONS and WITH_ADDED_MASS:
            add_junction_added_mass_jacobian(X, band, params.junctions, params.neighbours)
        return schur_factor(band, newton.jac.w, params.lines, newton.groups)
    return factor(band, newton.jac.corner, newton.cyclic, band.shape[0] - 1, newton.wood)


@jit.kernel
def local_error(work, an, co, h, free):
    """The step's local truncation estimate at the iterate X, largest over the free nodes [m]: h^2 |beta - 1/6 +
    (am - af) / 2| |a_(n+1) - a_n| (unfiltered, :mod:`ropesim.integrate.galpha_adaptive`)."""
    am, af, beta = co[0], co[1], co[3]
    scale = 1.0 / ((1.0 - af) * beta * h * h)
    dim, n = work.X.shape
    worst = 0.0
    for i in range(n):
        if free[i]:
            e2 = 0.0
            for d in range(dim):
                e = (work.X[d, i] - work.Xk[d, i]) * scale - an[d, i]
                e2 += e * e
            worst = max(worst, e2)
    return h * h * abs(beta - 1.0 / 6.0 + 0.5 * (am - af)) * math.sqrt(worst)


@jit.kernel(inline="always")
def solve_step(work, newton, co, t, h, held, nodes, params, control, stats, an):
    """Newton's solve of one step for the force point X (modified Newton: the matrix reused while it converges
    fast). Returns (iterations, node, fluid, internal-damping and seabed power [W]); iterations < 0 when it
    failed, naming the node that moved most in the last update.

    It stops when the last update, or the remaining error estimated from it and the rate of convergence (for a first
    update with the share: the last measured first update's, see CARRY_GROWTH), is below ``newton.tol``, or with
    fixed steps below NEWTON_SHARE of the step's own truncation estimate at the iterate (:func:`local_error`; times
    h / NEWTON_TOL_STEP below that step), at most ``newton.loosest``."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    c2 = (1.0 - af) * beta * h * h / (1.0 - am)
    beta_v = beta * h / gam
    t_f = t + (1.0 - af) * h
    X, V = work.X, work.V
    band, rhs = newton.jac.band, newton.rhs
    p = band.shape[0] - 1
    place(X, V, held, t_f, t + 0.5 * h)
    refactor = control[FACTORED_H] == 0.0 or abs(h - control[FACTORED_H]) > REUSE_WITHIN * control[FACTORED_H]
    worst_node = -1
    last = np.inf
    stride = 0.0
    previous = 0.0
    turning = 0.0   # the bodies' last update (their points' largest displacement [m]): its own rate
    refreshed = False   # the matrix factored in this step
    halvings = 0
    for it in range(NEWTON_MAX_ITER):
        norm, fluid, internal, seabed = residual(work, rhs, c2, beta_v, t_f, held, nodes, params, newton.body,
                                                 newton.groups)
        if norm > last and stride > newton.backtrack and halvings < MAX_HALVINGS:
            halvings += 1   # the update made things worse: go back half of it (and factor afresh there)
            stride *= 0.5
            take_back_half(X, newton.step)
            if WITH_BODIES:
                take_back_half_bodies(newton.body.stage)
            refactor = True
            continue
        last = norm
        halvings = 0
        fresh = refactor
        if refactor:
            if not factor_matrix(work, newton, c2, beta_v, t_f, nodes, params):
                control[FACTORED_H] = 0.0
                return -1, 0, 0.0, 0.0, 0.0
            control[FACTORED_H] = h
            stats[FACTORISATIONS] += 1
            refactor = False
            refreshed = True
        if WITH_JUNCTIONS or WITH_BODIES:
            schur_solve(band, newton.jac.w, params.lines, newton.groups, rhs)
        else:
            solve(band, newton.jac.corner, newton.cyclic, p, rhs, newton.wood)
        previous = stride
        stride, worst_node = take_update(X, rhs, newton.step)
        slow_body = False
        if WITH_BODIES:
            moved = max(take_body_update(newton.body.stage, newton.groups), rotation_stride(newton.body))
            slow_body = (not refreshed and turning > 0.0 and moved > BODY_RATE_REFACTOR * turning
                         and moved > newton.tol * 1e-3)
            turning = moved
            stride = max(stride, moved)
        stats[ITERATIONS] += 1
        if previous > 0.0:
            rate = stride / previous
            if it == 1 and newton.loosest > 0.0:
                control[FIRST_RATE] = rate
        elif newton.loosest > 0.0 and control[FIRST_RATE] > 0.0:
            rate = control[FIRST_RATE]
        else:
            rate = 1.0
        left = stride * rate / (1.0 - rate) if rate < 1.0 else np.inf
        tol = newton.tol
        if newton.loosest > 0.0 and min(stride, left) > tol:
            tol = max(tol, min(newton.loosest, NEWTON_SHARE * min(1.0, h / NEWTON_TOL_STEP)
                                * local_error(work, an, co, h, nodes.free)))
        if not slow_body and (stride <= tol or left <= tol):
            if it == 0 and newton.loosest > 0.0:
                control[FIRST_RATE] = min(1.0, CARRY_GROWTH * control[FIRST_RATE])
            for d in range(X.shape[0]):
                for i in range(X.shape[1]):
                    V[d, i] = work.Vk[d, i] + (X[d, i] - work.Xk[d, i]) / beta_v
            for j in range(held.idx.shape[0]):
                for d in range(X.shape[0]):
                    V[d, held.idx[j]] = held.v[d, j]
            if WITH_BODIES:
                place_stage(newton.body.stage, X, V, beta_v, params.bodies, newton.groups.arm)
            return it + 1, -1, fluid, internal, seabed
        if it > 0 and not fresh and (rate > RATE_REFACTOR or slow_body):
            refactor = True   # the old matrix converges slowly here: factor it at this iterate
    control[FACTORED_H] = 0.0
    return -1, worst_node, 0.0, 0.0, 0.0


@jit.kernel
def step_end(x, v, an, work, co, h, free):
    """From the solved force point: a_(n+1) = (X - Xk) / ((1 - af) beta h^2), x_(n+1) = x_n + (X - x_n) / (1 - af),
    v_(n+1) = v_n + h ((1 - gam) a_n + gam a_(n+1)); held nodes are left to :func:`place` (a_n = 0 there)."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    dim, n = x.shape
    scale = 1.0 / ((1.0 - af) * beta * h * h)
    for d in range(dim):
        for i in range(n):
            if not free[i]:
                an[d, i] = 0.0
                continue
            a1 = (work.X[d, i] - work.Xk[d, i]) * scale
            x[d, i] += (work.X[d, i] - x[d, i]) / (1.0 - af)
            v[d, i] += h * ((1.0 - gam) * an[d, i] + gam * a1)
            an[d, i] = a1


@jit.kernel
def book(ledger, powers, control, co, h, work, fluid, internal, seabed, held, nodes, params):
    """The step's flows into the ledger. Each flow's power P is known at the force points, this step's
    tau_1 = t_n + (1 - af) h and the last one's tau_0 = t_n - af h_last; the step books h P(t_n + h / 2) of the
    line through both (second order; the first step, without a last force point, books h P(tau_1)). ``powers``
    keeps this step's for the next (drag loss, held, fluid, internal, seabed, box [W])."""
    X, V, acc, acc_box, tmp = work.X, work.V, work.acc, work.acc_box, work.tmp
    free, mass, drag = nodes
    dim, n = X.shape
    af = co[1]
    lost = 0.0
    for d in range(dim):
        for i in range(n):
            lost += drag[i] * V[d, i] * V[d, i]
    if WITH_ADDED_MASS:   # the fluid's inertial force, m a - F
        for d in range(dim):
            for i in range(n):
                tmp[d, i] = acc[d, i] - drag[i] * V[d, i] / mass[i]
        fluid += solve_accelerations(X, V, tmp, params)
    box = 0.0
    if WITH_APPLIED:
        applied_accelerations(X, V, acc_box, params)
        box = power(acc_box, V, mass)
    now = (lost, held_power(acc, mass, held), fluid, internal, seabed, box)
    w0 = 0.0
    if control[LAST_H] > 0.0:   # P(mid) = P1 + (P1 - P0) (mid - tau_1) / (tau_1 - tau_0)
        w0 = h * ((1.0 - af) * h - 0.5 * h) / (h * (1.0 - af) + af * control[LAST_H])
    for k, column in enumerate((DRAG, HELD, FLUID, INTERNAL, SEABED, BOX)):
        ledger[column] += h * now[k] + w0 * (powers[k] - now[k])
        powers[k] = now[k]
    control[LAST_H] = h


@jit.kernel
def advance_galpha(state, work, newton, co, held, nodes, params, limits, schedule, frames, bodies, adapt):
    """Advance ``schedule.n_steps`` generalized-alpha steps in place; the contract of :mod:`ropesim.integrate.base`.

    ``state`` = (x, v, a_n, ledger, stats, control, last powers); ``adapt`` the adaptive steps' state
    (:mod:`ropesim.integrate.galpha_adaptive`; None with fixed steps). Returns (steps done, frames written,
    status, node)."""
    x, v, an, ledger, stats, control, powers = state
    h = schedule.h
    frame = np.int64(0)   # not the literal 0: Numba would compile the frame saving twice (for 0, then int64)
    if control[STARTED] == 0.0:
        start_acceleration(x, v, an, work.tmp, schedule.step0 * h, held, nodes, params, bodies, newton.body)
        stats[ITERATIONS] += 1
        control[STARTED] = 1.0
    if WITH_ADAPTIVE:
        return advance_adaptive(state, work, newton, co, held, nodes, params, limits, schedule, frames, bodies,
                                adapt)
    for s in range(schedule.n_steps):
        step = schedule.step0 + s
        t = step * h
        step_start(x, v, an, work, co, h)
        if WITH_BODIES:
            step_start_bodies(newton.body, bodies.pose, bodies.twist, co, h)
        if WITH_WAVES:
            hold_waves(params, True)
        its, node, fluid, internal, seabed = solve_step(work, newton, co, t, h, held, nodes, params, control, stats, an)
        if WITH_WAVES:
            hold_waves(params, False)
        if its < 0:
            return s, frame, NEWTON_FAILED, node
        if WITH_BODIES:
            fluid += fluid_power_bodies(work, params, newton.body, t + (1.0 - co[1]) * h)
        book(ledger, powers, control, co, h, work, fluid, internal, seabed, held, nodes, params)
        step_end(x, v, an, work, co, h, nodes.free)
        if WITH_BODIES:
            step_end_bodies(newton.body, bodies.pose, bodies.twist, co, h)
            place_attachments(x, v, params.bodies, bodies.pose, bodies.twist)
        stats[STEPS] += 1
        place(x, v, held, (step + 1) * h, (step + 1) * h)
        done = step + 1
        if not due(done, schedule):
            continue
        status, node, frame = end_step(done, schedule, x, v, nodes.mass, params, ledger, limits, frames, frame,
                                       bodies)
        if status != OK:
            return s + 1, frame, status, node
    return schedule.n_steps, frame, OK, -1


@jit.kernel(inline="always")
def filtered_error_ratio(work, an, co, h, t_f, x, newton, nodes, params, clock, share):
    """The step's error estimate filtered by the factored Newton matrix, J^-1 M e (see
    :mod:`ropesim.integrate.galpha_adaptive`), over its allowance; returns (ratio, the largest error [m], its
    node)."""
    band, rhs = newton.jac.band, newton.rhs
    raw_error(work, an, co, h, nodes, rhs)
    if WITH_JUNCTIONS or WITH_BODIES:
        if WITH_JUNCTIONS:
            fold_junctions(rhs, params.junctions, x.shape[0])
        if WITH_BODIES:
            raw_error_bodies(newton.body, work.X, work.acc, co, h, t_f, params, newton.groups, rhs)
        schur_solve(band, newton.jac.w, params.lines, newton.groups, rhs)
    else:
        solve(band, newton.jac.corner, newton.cyclic, band.shape[0] - 1, rhs, newton.wood)
    ratio, error, node = error_ratio(rhs, x, work.X, co[1], clock[TOL], clock[RTOL], nodes.free, share)
    if WITH_BODIES:
        body_ratio, body_error = error_ratio_bodies(newton.body, newton.groups, co[1], clock[TOL], clock[RTOL], share)
        if body_ratio > ratio:
            return body_ratio, body_error, -1
    return ratio, error, node


@jit.kernel
def advance_adaptive(state, work, newton, co, held, nodes, params, limits, schedule, frames, bodies, adapt):
    """The grid steps ``schedule.step0`` + 1 ... + n_steps, each read off the scheme's own steps by dense output
    (:mod:`ropesim.integrate.galpha_adaptive`); the internal steps chosen by the error estimate."""
    x, v, an, ledger, stats, control, powers = state
    x1, v1, clock, counts = adapt.x1, adapt.v1, adapt.clock, adapt.counts
    free = nodes.free
    t_end = schedule.total_steps * schedule.h
    frame = np.int64(0)
    for s in range(schedule.n_steps):
        done = schedule.step0 + s + 1
        target = done * schedule.h if done < schedule.total_steps else t_end
        framed = done % schedule.save_every == 0 or done == schedule.total_steps   # a frame is saved at target
        while clock[T1] < target * (1.0 - 1e-13):
            t = clock[T1]
            planned = min(clock[H_NEXT], t_end - t)
            h = land(planned, target - t) if framed else planned
            cut = h < planned   # to land on a frame; a rejected step is the controller's again
            while True:
                if h < SMALLEST * t_end:
                    return s, frame, NEWTON_FAILED, -1
                step_start(x1, v1, an, work, co, h)
                if WITH_BODIES:
                    step_start_bodies(newton.body, newton.body.pose1, newton.body.twist1, co, h)
                if WITH_WAVES:
                    hold_waves(params, True)
                its, node, fluid, internal, seabed = solve_step(work, newton, co, t, h, held, nodes, params,
                                                                control, stats, an)
                if WITH_WAVES:
                    hold_waves(params, False)
                if its < 0:
                    counts[REJECTED] += 1
                    h *= NEWTON_SHRINK
                    cut = False
                    continue
                ratio, error, limiting = filtered_error_ratio(work, an, co, h, t + (1.0 - co[1]) * h, x1, newton,
                                                              nodes, params, clock, h / t_end)
                if ratio > 1.0:
                    counts[REJECTED] += 1
                    h = next_step(h, ratio)
                    cut = False
                    continue
                break
            for d in range(x1.shape[0]):
                for i in range(x1.shape[1]):
                    adapt.x0[d, i] = x1[d, i]
                    adapt.v0[d, i] = v1[d, i]
            for k in range(ledger.shape[0]):
                adapt.ledger0[k] = adapt.ledger1[k]
            if WITH_BODIES:
                fluid += fluid_power_bodies(work, params, newton.body, t + (1.0 - co[1]) * h)
            book(adapt.ledger1, powers, control, co, h, work, fluid, internal, seabed, held, nodes, params)
            step_end(x1, v1, an, work, co, h, free)
            if WITH_BODIES:
                keep_step_start_bodies(newton.body)
                step_end_bodies(newton.body, newton.body.pose1, newton.body.twist1, co, h)
                place_attachments(x1, v1, params.bodies, newton.body.pose1, newton.body.twist1)
            place(x1, v1, held, t + h, t + h)
            stats[STEPS] += 1
            counts[ACCEPTED] += 1
            clock[T0] = t
            clock[T1] = t + h
            clock[EST_MAX] = max(clock[EST_MAX], error)
            clock[EST_SUM] += error
            clock[H_MIN] = min(clock[H_MIN], h)
            clock[H_MAX] = max(clock[H_MAX], h)
            clock[LIMITING] = limiting
            if t + h < t_end:   # the last step, cut to reach t_end, says nothing of the next
                clock[H_NEXT] = planned if cut else next_step(h, ratio)   # a step cut to land on a frame neither
                # grows nor shrinks the next
        dense_output(adapt, target, x, v, ledger)
        if WITH_BODIES:
            dense_output_bodies(newton.body, clock[T0], clock[T1], target, bodies.pose, bodies.twist)
            place_attachments(x, v, params.bodies, bodies.pose, bodies.twist)
        place(x, v, held, target, target)
        if not due(done, schedule):
            continue
        status, node, frame = end_step(done, schedule, x, v, nodes.mass, params, ledger, limits, frames, frame,
                                       bodies)
        if status != OK:
            return s + 1, frame, status, node
    return schedule.n_steps, frame, OK, -1
