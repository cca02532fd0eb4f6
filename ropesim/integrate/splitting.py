"""Splitting (drift-kick) schemes: the methods as data, and the one compiled loop that runs them all.

A scheme advances one step h as

    drift(a_0 h), kick(b_0 h), drift(a_1 h), kick(b_1 h), ..., kick(b_{s-1} h), drift(a_s h)

where drift(c) moves positions, x += c v, and kick(c) moves velocities under the forces at the current
positions. Time advances in the drifts, so held nodes are put at x0 + V t with t the drift's end time and every
force sees positions of one instant. Linear drag is integrated exactly within each kick: with gamma = b / m,
the kick solves v' = a - gamma v for a time c, v <- e^(-gamma c) v + (1 - e^(-gamma c)) / gamma a. Putting
-b v into a plain kick instead would drop every scheme to first order; done this way each keeps its order
with drag on and drag never limits the time step. The thrower's and guides' forces are linear in velocity too:
with their edges smoothed (``edge_width`` > 0) the nodes they touch get the exact kick of
:mod:`ropesim.integrate.contact`; with sharp edges they stay in the plain kick (an explicit Euler step in v:
first order, as before).

:func:`advance_splitting` runs every scheme on every scene. Each kick stage takes one of two forms, chosen
once per model: the general stage (every force through the term list, :func:`ropesim.model.terms.accelerations`)
or, for a 2-D rope whose only forces are its springs and gravity, the plain stage of
:mod:`ropesim.integrate.plain`, written for that physics alone; trajectories are bit-identical either way.
Everything around the stages (drifts, held nodes, the step and frame schedule, the blow-up check) is shared.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..model import jit
from ..model.bodies import WITH_BODIES, drift_bodies, place_attachments, save_bodies
from ..model.terms import (WITH_APPLIED, WITH_GRAVITY, WITH_MOTION, WITH_VELOCITY_TERMS, accelerations,
                           applied_accelerations, bodies_energy, mechanical_energy, position_accelerations)
from .base import Integrator, Method
from .contact import exact_contact_kicks
from .health import (BOX, DRAG, E0, FLUID, HELD, INTERNAL, OK, SCALE, SEABED, balance_status, flows, save_frame,
                     verdict)
from .kick import box_work, kick_drift
from .plain import (BULK_FIXED, BULK_PER_STAGE, WITH_PLAIN_STAGE, applies, chain_energy, inactive_bundle, plain_bundle,
                    settle_drag)
from ..model.motion import place_moving
from .velocity_kick import velocity_kick, velocity_scratch


@dataclass(frozen=True)
class SplittingScheme(Method):
    """A drift-kick composition: ``drift`` has one more entry than ``kick``."""

    name: str
    order: int
    drift: tuple[float, ...]
    kick: tuple[float, ...]
    doc: str
    kind: str = "splitting"
    exact_contact_kicks = True

    @property
    def family(self) -> type:
        return Splitting

    @property
    def evaluations(self) -> int:
        """Force evaluations per step (first-same-as-last reuse counted when the scheme allows it)."""
        return len(self.kick) - (1 if self.reuses_last_force else 0)

    @property
    def reuses_last_force(self) -> bool:
        """True when a step ends with a kick at the positions the next step starts kicking from."""
        return len(self.kick) > 1 and self.drift[0] == 0.0 and self.drift[-1] == 0.0

    @property
    def backward_kicks(self) -> bool:
        return min(self.kick) < 0.0

    @property
    def kick_span(self) -> float:
        return max(abs(c) for c in self.kick)

    def amplification(self, h: float, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0):
        """One step's 2x2 map of (x, v) for x'' = -omega^2 x - gamma_force x' - gamma_drag x'.

        ``gamma_drag`` is integrated exactly in the kicks, like the scene's drag; ``gamma_force`` is a
        velocity-dependent force evaluated in the kick (the thrower's and guides' damping).
        """
        m = np.eye(2)
        for k, c in enumerate(self.kick):
            m = np.array([[1.0, self.drift[k] * h], [0.0, 1.0]]) @ m
            ch = c * h
            decay = math.exp(-gamma_drag * ch)
            gain = -math.expm1(-gamma_drag * ch) / gamma_drag if gamma_drag > 0 else ch
            m = np.array([[1.0, 0.0], [-gain * omega * omega, decay - gain * gamma_force]]) @ m
        return np.array([[1.0, self.drift[-1] * h], [0.0, 1.0]]) @ m


def _yoshida4() -> SplittingScheme:
    cbrt2 = 2.0 ** (1.0 / 3.0)
    w1 = 1.0 / (2.0 - cbrt2)
    w0 = -cbrt2 / (2.0 - cbrt2)
    return SplittingScheme(
        "yoshida4", 4, (w1 / 2, (w0 + w1) / 2, (w0 + w1) / 2, w1 / 2), (w1, w0, w1),
        "Yoshida (1990) fourth-order composition of three leapfrog steps; 3 force evaluations per step.")


def _pefrl() -> SplittingScheme:
    xi, lam, chi = 0.1786178958448091, -0.2123418310626054, -0.06626458266981849
    return SplittingScheme(
        "pefrl", 4, (xi, chi, 1 - 2 * (chi + xi), chi, xi), ((1 - 2 * lam) / 2, lam, lam, (1 - 2 * lam) / 2),
        "Omelyan, Mryglod & Folk (2002) position-extended Forest-Ruth-like fourth-order scheme; 4 force "
        "evaluations per step, a wider stability interval and a far smaller error constant than Yoshida-4.")


SCHEMES = (
    SplittingScheme("symplectic_euler", 1, (0.0, 1.0), (1.0,),
                    "Symplectic Euler, the write-up's method: kick with the forces at x_n, then drift with the new "
                    "velocity. First order, 1 force evaluation per step."),
    SplittingScheme("verlet", 2, (0.0, 1.0, 0.0), (0.5, 0.5),
                    "Velocity Verlet: half kick, drift, half kick. Second order, 1 force evaluation per step (the "
                    "last kick's forces are reused by the next step's first)."),
    _yoshida4(),
    _pefrl(),
)


def kick_factors(scheme: SplittingScheme, h: float, drag: np.ndarray, mass: np.ndarray,
                 held: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per kick and node, the factors of the exact drag kick v <- decay v + gain a, and its ``travel``.

    decay = e^(-gamma c h), gain = (1 - decay) / gamma (or c h without drag), with gamma = b / m and c the
    kick coefficient. Over the kick the node travels (the integral of v) gain v + travel a, with
    travel = (c h - gain) / gamma (c^2 h^2 / 2 without drag); the ledger uses it to book the work of the
    forces and the drag loss exactly. Held nodes get decay 1, gain 0 and travel 0: their velocity never
    changes.
    """
    c = np.asarray(scheme.kick)[:, None] * h
    rate = drag / mass
    rate[rate < np.finfo(float).tiny] = 0.0   # a subnormal b/m slows nothing, and its few bits would spoil gain
    gamma = np.broadcast_to(rate[None, :], (len(scheme.kick), len(mass)))
    z = gamma * c
    # A backward kick (PEFRL's, Yoshida's) undoes drag: e^(gamma |c| h) may exceed the float range at a dt far
    # above the stability bound. The factors are then inf, and a run forced there stops at its first check.
    with np.errstate(over="ignore"):
        decay = np.exp(-z)
        safe = np.where(gamma > 0, gamma, 1.0)
        gain = np.where(gamma > 0, -np.expm1(-z) / safe, c)
        small = np.abs(z) < 1e-3
        series = c * c * (0.5 - z / 6.0 + z * z / 24.0 - z ** 3 / 120.0)  # (z + expm1(-z)) c^2 / z^2, small z
        beyond = np.where(small, 1.0, safe)   # gamma where the closed form serves; elsewhere gamma^2 may underflow
        travel = np.where(small, series, (z + np.expm1(-z)) / (beyond * beyond))
    decay[:, held] = 1.0
    gain[:, held] = 0.0
    travel[:, held] = 0.0
    return np.ascontiguousarray(decay), np.ascontiguousarray(gain), np.ascontiguousarray(travel)


# ------------------------------------------------------------------------------------------------ bundles

SplittingState = namedtuple("SplittingState", ["x", "v", "acc", "have_acc", "ledger", "spring_forces", "lost"])
"""x, v (D, N); the general stage's accelerations (D, N) and the plain stage's spring forces (2, N + 1), carried
between calls when the last kick's forces are reused (``have_acc[0]``); the ledger; the plain stage's
per-node work (N,)."""

Kicks = namedtuple("Kicks", ["drift", "kick", "decay", "gain", "travel", "reuse_force"])
"""The scheme's drift and kick coefficients and the exact drag kick's factors (stages, N) per node."""

General = namedtuple("General", ["acc_box", "exact", "free", "gamma", "v_contact", "contact_nodes", "buf", "vscratch"])
"""The general stage's scratch: the applied terms' accelerations (D, N); the exact contact kicks (on or off,
free nodes, drag rates b/m, their velocities (D, N) and node list); kick scratch; the scratch of
:func:`ropesim.integrate.velocity_kick.velocity_kick` (the kick when forces beyond the thrower's and guides'
depend on velocity)."""


class Splitting(Integrator):
    """The splitting family: any :class:`SplittingScheme`, on the general or the plain stage (see the module doc)."""

    STATE = ("acc", "have_acc", "spring_forces", "lost")

    def __init__(self, model, grid, method: SplittingScheme, specialise: bool = True):
        """``specialise=False`` keeps a plain rope on the general stage (the tests compare the two)."""
        super().__init__(model, grid, method)
        stages = len(method.kick)
        self.reuse_force = method.reuses_last_force and not model.velocity_dependent
        decay, gain, travel = kick_factors(method, grid.dt, model.drag, model.mass, model.held)
        self.kicks = Kicks(np.array(method.drift), np.array(method.kick), decay, gain, travel, self.reuse_force)
        if not specialise:
            self.switches = self.switches - {WITH_PLAIN_STAGE.name}
            self.loop = self.kernel(advance_splitting)
        plain = self.on_plain_stage
        self.plain = plain_bundle(model, decay, gain, travel) if plain else inactive_bundle(stages)
        self.acc = np.zeros_like(self.x)
        self.have_acc = np.zeros(1, dtype=np.bool_)
        self.spring_forces = np.zeros((2, model.nodes + 1) if plain else (2, 1))
        self.lost = np.zeros(model.nodes if plain else 0)
        self.general = General(np.zeros_like(self.x), model.smooth_contacts and model.applied,
                               np.ascontiguousarray(~model.held), np.where(model.held, 0.0, model.drag / model.mass),
                               np.zeros_like(self.x), np.zeros(model.nodes, dtype=np.int64), np.empty(model.nodes),
                               velocity_scratch(*self.x.shape, self.pose.shape[1]))
        self.bundle = SplittingState(self.x, self.v, self.acc, self.have_acc, self.ledger, self.spring_forces,
                                     self.lost)

    @staticmethod
    def template():
        return advance_splitting

    @classmethod
    def switches_for(cls, model, method) -> frozenset:
        """The model's switches, and the plain stage where it applies."""
        return model.switches | ({WITH_PLAIN_STAGE.name} if applies(model, method) else set())

    @property
    def on_plain_stage(self) -> bool:
        return WITH_PLAIN_STAGE.name in self.switches

    def set_exact_contacts(self, on: bool) -> None:
        """Kick nodes touching the box or a circle exactly (``on``) or plainly, whatever the edges (for the
        accuracy study; by default the kick is exact when the edges are smoothed)."""
        self.general = self.general._replace(exact=bool(on) and self.model.applied)

    @property
    def force_evaluations(self) -> int:
        # velocity-dependent forces rule out reusing the last kick's forces
        return self.step * (len(self.method.kick) - (1 if self.reuse_force else 0))

    def loop_args(self, n, frames):
        m = self.model
        return (self.bundle, self.kicks, self.plain, self.general, self.held, m.mass, m.params, self.limits,
                self.schedule(n), frames, self.bodies)


@jit.kernel
def advance_splitting(state, kicks, plain, general, held, mass, params, limits, schedule, frames, bodies):
    """Advance ``schedule.n_steps`` splitting steps in place, from global step ``schedule.step0``; ``bodies`` the
    free rigid bodies' state (pose, twist), drifted with the nodes (q <- exp(c w) q) and kicked with them.

    The contract of :mod:`ropesim.integrate.base`; returns (steps done, frames written, status, node). Each
    kick stage is the plain stage (switch ``WITH_PLAIN_STAGE``: a 2-D rope with its springs and gravity alone; see
    :mod:`ropesim.integrate.plain`) or the general one; both are written out here rather than called, because
    a helper taking arrays costs an atomic reference-count update per array and call, more than a small rope's
    whole step on the plain stage. That, and the plain stage's two copies of its kick (a flag tested inside
    the loop would stop it vectorising), is what makes this function long.
    """
    x, v, acc, have_acc, ledger, f, lost = state
    drift, kick, decay_k, gain_k, travel_k, reuse_force = kicks
    held_idx, held_x0, held_v, motion = held
    step0, n_steps, total_steps, h, save_every, check_every = schedule
    dim, n = x.shape
    stages = kick.shape[0]
    n_held = held_idx.shape[0]
    inv_mass = params.inv_mass
    g = params.gravity[0] if WITH_GRAVITY else 0.0
    k_spring, rest, closed = params.spring[0, 0], params.spring[0, 1], params.spring[0, 2] != 0.0   # one line
    px, py, vx, vy, fx, fy = x[0], x[1], v[0], v[1], f[0], f[1]   # the plain stage's rows
    inv_m = plain.bulk[0]
    n_exc = plain.exceptions.shape[0]
    if WITH_PLAIN_STAGE and not closed:
        fx[0] = fx[n] = fy[0] = fy[n] = 0.0
    held_work = ledger[HELD]   # kept in a register, stored whenever the ledger is read
    frame = np.int64(0)   # not the literal 0: Numba would compile the frame saving twice (for 0, then int64)
    next_check = step0 + check_every - step0 % check_every   # counted, not divided, per step
    next_save = step0 + save_every - step0 % save_every
    for s in range(n_steps):
        step = step0 + s
        t = step * h
        middle = t + 0.5 * h   # a path: every stage of this step on its piece (see ropesim/model/motion.py)
        if WITH_MOTION:   # the held nodes' velocities and accelerations at t, for the supports' power
            place_moving(x, v, held, t, middle)
        if drift[0] != 0.0:
            ch = drift[0] * h
            for d in range(dim):
                for i in range(n):
                    x[d, i] += ch * v[d, i]
            if WITH_BODIES:
                drift_bodies(bodies.pose, bodies.twist, ch)
                place_attachments(x, v, params.bodies, bodies.pose, bodies.twist)
            t += ch
            if WITH_MOTION:
                place_moving(x, v, held, t, middle)
            for j in range(n_held if not WITH_MOTION else 0):   # health.place_held, written out: its call cost 2.5 %
                i = held_idx[j]
                for d in range(dim):
                    x[d, i] = held_x0[d, j] + held_v[d, j] * t
        for st in range(stages):
            ch = drift[st + 1] * h
            fresh = not (st == 0 and reuse_force and have_acc[0])
            p = 0.0   # the supports' power on the rope: a held node does not accelerate, so its support pushes -m a
            if WITH_PLAIN_STAGE:
                # ---- the plain stage: spring forces into f, then the bulk kick and drift from them
                if fresh:
                    for i in range(n - 1):
                        d0 = px[i + 1] - px[i]
                        d1 = py[i + 1] - py[i]
                        r2 = d0 * d0 + d1 * d1
                        c = k_spring * (1.0 - rest / np.sqrt(r2)) if r2 > 0.0 else 0.0   # no direction, no force
                        fx[i + 1] = c * d0
                        fy[i + 1] = c * d1
                    if closed:   # an open line's f[:, 0] and f[:, N] stay 0
                        d0 = px[0] - px[n - 1]
                        d1 = py[0] - py[n - 1]
                        r2 = d0 * d0 + d1 * d1
                        c = k_spring * (1.0 - rest / np.sqrt(r2)) if r2 > 0.0 else 0.0
                        fx[0] = fx[n] = c * d0
                        fy[0] = fy[n] = c * d1
                b = BULK_FIXED + BULK_PER_STAGE * st
                decay, gain, reach = plain.bulk[b], plain.bulk[b + 1], plain.bulk[b + 2]
                for j in range(n_exc):
                    i = plain.exceptions[j]
                    plain.saved_x[0, j] = px[i]
                    plain.saved_x[1, j] = py[i]
                    plain.saved_v[0, j] = vx[i]
                    plain.saved_v[1, j] = vy[i]
                    plain.saved_lost[j] = lost[i]
                if plain.has_drag:
                    for i in range(n):
                        ax = (fx[i + 1] - fx[i]) * inv_m
                        ay = (fy[i + 1] - fy[i]) * inv_m - g
                        ux = vx[i]
                        uy = vy[i]
                        gx = gain * ax
                        gy = gain * ay
                        wx = decay * ux + gx
                        wy = decay * uy + gy
                        lost[i] += (ux + reach * ax) * gx + (uy + reach * ay) * gy
                        vx[i] = wx
                        vy[i] = wy
                        px[i] += ch * wx
                        py[i] += ch * wy
                else:
                    for i in range(n):
                        ax = (fx[i + 1] - fx[i]) * inv_m
                        ay = (fy[i + 1] - fy[i]) * inv_m - g
                        wx = decay * vx[i] + gain * ax
                        wy = decay * vy[i] + gain * ay
                        vx[i] = wx
                        vy[i] = wy
                        px[i] += ch * wx
                        py[i] += ch * wy
                for j in range(n_exc):   # the exceptions, redone from their saved state with their own factors
                    i = plain.exceptions[j]
                    e_decay = plain.exception_factors[st, 0, j]
                    e_gain = plain.exception_factors[st, 1, j]
                    e_reach = plain.exception_factors[st, 2, j]
                    ax = (fx[i + 1] - fx[i]) * inv_mass[i]
                    ay = (fy[i + 1] - fy[i]) * inv_mass[i] - g
                    ux = plain.saved_v[0, j]
                    uy = plain.saved_v[1, j]
                    gx = e_gain * ax
                    gy = e_gain * ay
                    wx = e_decay * ux + gx
                    wy = e_decay * uy + gy
                    vx[i] = wx
                    vy[i] = wy
                    px[i] = plain.saved_x[0, j] + ch * wx
                    py[i] = plain.saved_x[1, j] + ch * wy
                    lost[i] = plain.saved_lost[j]
                    if plain.has_drag:
                        lost[i] += (ux + e_reach * ax) * gx + (uy + e_reach * ay) * gy
                for j in range(n_held):   # held nodes: their power, and the velocity their bulk kick changed
                    i = held_idx[j]
                    ax = (fx[i + 1] - fx[i]) * inv_mass[i]
                    ay = (fy[i + 1] - fy[i]) * inv_mass[i] - g
                    p -= mass[i] * ax * held_v[0, j]
                    p -= mass[i] * ay * held_v[1, j]
                    vx[i] = held_v[0, j]
                    vy[i] = held_v[1, j]
            elif WITH_VELOCITY_TERMS:
                # ---- velocity-dependent forces: RK4 sub-stages at frozen positions, the ledger by the same rule
                position_accelerations(x, acc, params)
                loss, supports, box, fluid, internal, seabed = velocity_kick(x, v, acc, kick[st] * h, t, params,
                                                                             mass, general.gamma, held,
                                                                             general.vscratch, bodies)
                ledger[DRAG] += loss
                ledger[BOX] += box
                ledger[FLUID] += fluid
                ledger[INTERNAL] += internal
                ledger[SEABED] += seabed
                held_work += supports
                if ch != 0.0:
                    for d in range(dim):
                        for i in range(n):
                            x[d, i] += ch * v[d, i]
                    if WITH_BODIES:
                        drift_bodies(bodies.pose, bodies.twist, ch)
                        place_attachments(x, v, params.bodies, bodies.pose, bodies.twist)
            else:
                # ---- the general stage: every term through the term list, the kick and its ledger per node
                if fresh:
                    accelerations(x, v, acc, params, t)
                box = 0.0
                if WITH_APPLIED:
                    applied_accelerations(x, v, general.acc_box, params)
                    box = box_work(v, acc, general.acc_box, gain_k, travel_k, st, mass)   # from velocities before
                touching = 0
                if WITH_APPLIED and general.exact:
                    touching = exact_contact_kicks(x, v, acc, general.v_contact, general.contact_nodes,
                                                   kick[st] * h, general.gamma, general.free, params)
                # the kick, the loss it books and the next drift, fused; a contact kick replaces some
                # velocities first, so then the drift runs on its own
                ledger[DRAG] += kick_drift(x, v, acc, decay_k, gain_k, travel_k, st, mass,
                                           ch if touching == 0 else 0.0, general.buf)
                for j in range(touching):
                    i = general.contact_nodes[j]
                    for d in range(dim):
                        v[d, i] = general.v_contact[d, i]
                if ch != 0.0 and touching != 0:
                    for d in range(dim):
                        for i in range(n):
                            x[d, i] += ch * v[d, i]
                for j in range(n_held):   # health.held_power, written out
                    i = held_idx[j]
                    for d in range(dim):
                        p -= mass[i] * acc[d, i] * held_v[d, j]
                        if WITH_MOTION:
                            p += mass[i] * motion.accel[d, j] * held_v[d, j]
                if WITH_APPLIED:
                    for j in range(n_held):
                        i = held_idx[j]
                        for d in range(dim):
                            box += kick[st] * h * mass[i] * general.acc_box[d, i] * held_v[d, j]
                    ledger[BOX] += box
            held_work += kick[st] * h * p
            if ch != 0.0:
                t += ch
                if WITH_MOTION:
                    place_moving(x, v, held, t, middle)
                for j in range(n_held if not WITH_MOTION else 0):
                    i = held_idx[j]
                    for d in range(dim):
                        x[d, i] = held_x0[d, j] + held_v[d, j] * t
        have_acc[0] = reuse_force
        done = step + 1
        if done < next_check and done < next_save and done != total_steps:
            continue
        saving = done == next_save or done == total_steps
        if done == next_check:
            next_check += check_every
        if done == next_save:
            next_save += save_every
        ledger[HELD] = held_work
        if WITH_PLAIN_STAGE:
            settle_drag(ledger, lost, v, plain.free_mass, plain.kinetic0, plain.has_drag, held_idx, plain.terms)
            energy, stretch, worst = chain_energy(x, v, mass, k_spring, rest, closed, g, plain.lengths, plain.terms)
        else:
            energy, stretch, worst = mechanical_energy(x, v, mass, params)
        if WITH_BODIES:
            energy += bodies_energy(params, bodies.pose, bodies.twist)
        flowed, moved = flows(ledger)
        status = balance_status(energy, stretch, flowed, moved, ledger[E0], ledger[SCALE], limits[0], limits[1],
                                limits[2])
        if status != OK or not np.isfinite(energy):   # only now hand the arrays over, to name the culprit
            status, node = verdict(energy, stretch, worst, x, v, ledger, limits)
            if status != OK:
                return s + 1, frame, status, node
        if saving:
            save_frame(frame, done * h, x, v, ledger, frames.t, frames.x, frames.v, frames.ledger)
            if WITH_BODIES:
                save_bodies(frame, bodies.pose, bodies.twist, frames.body)
            frame += 1
    ledger[HELD] = held_work
    if WITH_PLAIN_STAGE:
        settle_drag(ledger, lost, v, plain.free_mass, plain.kinetic0, plain.has_drag, held_idx, plain.terms)
    return n_steps, frame, OK, -1
