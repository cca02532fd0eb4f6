"""Time integrators, chosen by name: splitting schemes as data, a Butcher-table loop, and a stiff solver.

Every method advances the state (x, v), each of shape (D, N), by uniform steps h, keeps held (pinned or driven)
nodes exactly on x0 + V t at every stage, keeps its order with linear drag on, and books the energy ledger
(see :mod:`ropesim.health`). :data:`METHODS` maps each name to its method; the name is the same in TOML
(``integrator.method``), on the command line and here.

Splitting (drift-kick) schemes advance one step h as

    drift(a_0 h), kick(b_0 h), drift(a_1 h), kick(b_1 h), ..., kick(b_{s-1} h), drift(a_s h)

where drift(c) moves positions, x += c v, and kick(c) moves velocities under the forces at the current
positions. Time advances in the drifts, so held nodes are put at x0 + V t with t the drift's end time and every
force sees positions of one instant. Linear drag is integrated exactly within each kick: with gamma = b / m,
the kick solves v' = a - gamma v for a time c, v <- e^(-gamma c) v + (1 - e^(-gamma c)) / gamma a. Putting
-b v into a plain kick instead would drop every scheme to first order; done this way each keeps its order
with drag on and drag never limits the time step. The thrower's and guides' forces are linear in velocity too:
with their edges smoothed (``edge_width`` > 0) the nodes they touch get the exact kick of :mod:`ropesim.contact`;
with sharp edges they stay in the plain kick (an explicit Euler step in v: first order, as before).

:func:`advance` below runs every splitting scheme on every scene. A 2-D rope with nothing but its own springs,
gravity and drag (the towed ropes) runs instead on :func:`ropesim.chain.advance_chain`, the same steps written
for that scene alone, with bit-identical trajectories.

To add a method: give a splitting scheme's coefficients (or a Runge-Kutta method's Butcher table, see
:mod:`ropesim.rk`), its order and a line of documentation, and list it in :data:`METHODS`; its stability
interval is computed from the coefficients by :func:`stable_step`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit

from .health import BOX, DRAG, HELD, NON_FINITE, OK, end_step, held_power, place_held  # noqa: F401
from .contact import exact_contact_kicks
from ..model.forces.guides import add_guides
from ..model.forces.springs import add_pair_springs, set_chain_springs
from ..model.forces.thrower import add_thrower
from ..model.terms import BENDING, GRAVITY, GUIDES, THROWER, box_accelerations
from .kick import box_work, kick_drift


@dataclass(frozen=True)
class SplittingScheme:
    """A drift-kick composition: ``drift`` has one more entry than ``kick``."""

    name: str
    order: int
    drift: tuple[float, ...]
    kick: tuple[float, ...]
    doc: str
    kind: str = "splitting"

    @property
    def evaluations(self) -> int:
        """Force evaluations per step (first-same-as-last reuse counted when the scheme allows it)."""
        return len(self.kick) - (1 if self.reuses_last_force else 0)

    @property
    def reuses_last_force(self) -> bool:
        """True when a step ends with a kick at the positions the next step starts kicking from."""
        return len(self.kick) > 1 and self.drift[0] == 0.0 and self.drift[-1] == 0.0

    @property
    def stability_limit(self) -> float:
        """Largest h omega for which the scheme stays bounded on a harmonic oscillator x'' = -omega^2 x."""
        return stable_step(self, 1.0)

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


def _stable(method, h: float, omega: float, gamma_force: float, gamma_drag: float) -> bool:
    try:
        m = method.amplification(h, omega, gamma_force, gamma_drag)
    except OverflowError:   # a backward kick's e^(gamma |c| h) beyond the float range: the kernel's factor is inf
        return False
    if not np.all(np.isfinite(m)):
        return False
    return bool(np.max(np.abs(np.linalg.eigvals(m))) <= 1.0 + 1e-9)


@lru_cache(maxsize=4096)
def stable_step(method, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0) -> float:
    """Largest step h [s] for which ``method`` stays bounded on x'' = -omega^2 x - (gamma_force + gamma_drag) x'.

    ``gamma_force`` [1/s] is damping the method evaluates explicitly (the thrower's and guides'), ``gamma_drag``
    [1/s] the scene's linear drag (exact inside the splitting schemes' kicks, explicit in Runge-Kutta).
    Infinite for an unconditionally stable method or when nothing oscillates or damps.
    """
    if getattr(method, "unconditionally_stable", False):
        return math.inf
    rate = max(omega, gamma_force + (gamma_drag if method.kind == "rk" else 0.0))
    if rate <= 0.0:
        return math.inf
    backward = method.kind == "splitting" and min(method.kick) < 0.0   # its backward kicks amplify by drag
    h, factor = 1e-3 / max(rate, gamma_drag if backward else 0.0), 1.01
    while h * rate < 20.0 and _stable(method, h * factor, omega, gamma_force, gamma_drag):
        h *= factor
    lo, hi = h, h * factor
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _stable(method, mid, omega, gamma_force, gamma_drag) else (lo, mid)
    return lo


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


def _methods() -> dict:
    from .sdirk import SDIRK2
    from .rk import RK4

    schemes = (
        SplittingScheme("symplectic_euler", 1, (0.0, 1.0), (1.0,),
                        "Symplectic Euler, the write-up's method: kick with the forces at x_n, then drift with "
                        "the new velocity. First order, 1 force evaluation per step."),
        SplittingScheme("verlet", 2, (0.0, 1.0, 0.0), (0.5, 0.5),
                        "Velocity Verlet: half kick, drift, half kick. Second order, 1 force evaluation per step "
                        "(the last kick's forces are reused by the next step's first)."),
        _yoshida4(),
        _pefrl(),
        RK4,
        SDIRK2,
    )
    return {s.name: s for s in schemes}


METHODS: dict = _methods()


def get_method(name: str):
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}: allowed {', '.join(METHODS)}") from None


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


@njit(cache=True, error_model="numpy")
def advance(x, v, acc, acc_box, have_acc, ledger, step0, n_steps, total_steps, h, drift, kick, decay, gain, travel,
            reuse_force, held, mass, forces, limits, save_every, frames, check_every, contacts):
    """Advance ``n_steps`` splitting steps in place, from global step ``step0`` (time step0 * h).

    ``held`` = (indices, x0 (D, H), V (D, H)); ``frames`` = (t (F,), x (F, D, N), v (F, D, N), ledger (F, 3)).
    Saves a frame after every global step s (1-based) with s % save_every == 0 or s == total_steps.
    ``have_acc[0]`` carries the first-same-as-last forces between calls. ``contacts`` = (exact, free (N,) bool,
    drag rate b/m (N,), scratch (D, N), scratch (N,) int64): with ``exact`` the nodes touching the box or a
    circle get the exact kick of :mod:`ropesim.contact`. Returns (steps done, frames written, status, node):
    see :func:`ropesim.health.check_health`.
    """
    dim, n = x.shape
    stages = kick.shape[0]
    held_idx, held_x0, held_v = held
    inv_mass, flags, spring, bending, gravity, thrower, guides = forces
    closed = spring[2] != 0.0
    g = gravity[0] if flags[GRAVITY] else 0.0
    stiffness, rest = spring[0], spring[1]
    has_bending = flags[BENDING] != 0
    has_thrower = flags[THROWER] != 0
    has_guides = flags[GUIDES] != 0
    has_box = has_thrower or has_guides
    exact, free, gamma, v_contact, contact_nodes = contacts
    exact = exact and has_box
    n_held = held_idx.shape[0]
    buf = np.empty(n)   # kick_drift's per-node losses
    frame = 0
    for s in range(n_steps):
        step = step0 + s
        t = step * h
        if drift[0] != 0.0:
            ch = drift[0] * h
            for d in range(dim):
                for i in range(n):
                    x[d, i] += ch * v[d, i]
            t += ch
            place_held(x, held_idx, held_x0, held_v, t)
        for k in range(stages):
            if not (k == 0 and reuse_force and have_acc[0]):   # accelerations(), its force tuple unpacked once
                set_chain_springs(x, acc, inv_mass, stiffness, rest, closed, g)
                if has_bending:
                    add_pair_springs(x, acc, inv_mass, bending[0], bending[1], 2, closed)
                if has_thrower:
                    add_thrower(x, v, acc, inv_mass, thrower, g)
                if has_guides:
                    add_guides(x, v, acc, guides, thrower, has_thrower, g)
            box = 0.0
            if has_box:
                box_accelerations(x, v, acc_box, forces)
                box = box_work(v, acc, acc_box, gain, travel, k, mass)   # from the velocities before the kick
            touching = 0
            if exact:
                touching = exact_contact_kicks(x, v, acc, v_contact, contact_nodes, kick[k] * h, gamma, free, forces)
            drifting = drift[k + 1] != 0.0
            ch = drift[k + 1] * h
            # the kick, the loss it books (from the velocities before it) and the next drift, fused; a contact
            # kick replaces some velocities first, so then the drift runs on its own
            lost = kick_drift(x, v, acc, decay, gain, travel, k, mass, ch if drifting and touching == 0 else 0.0,
                              buf)
            for j in range(touching):
                i = contact_nodes[j]
                for d in range(dim):
                    v[d, i] = v_contact[d, i]
            if drifting and touching != 0:
                for d in range(dim):
                    for i in range(n):
                        x[d, i] += ch * v[d, i]
            ck = kick[k] * h
            ledger[DRAG] += lost
            p = 0.0   # held_power(): the supports' power on the rope
            for j in range(n_held):
                i = held_idx[j]
                for d in range(dim):
                    p -= mass[i] * acc[d, i] * held_v[d, j]
            ledger[HELD] += ck * p
            if has_box:
                for j in range(n_held):
                    i = held_idx[j]
                    for d in range(dim):
                        box += ck * mass[i] * acc_box[d, i] * held_v[d, j]
                ledger[BOX] += box
            if drifting:
                t += ch
                place_held(x, held_idx, held_x0, held_v, t)
        have_acc[0] = reuse_force
        done = step + 1
        if done % check_every and done % save_every and done != total_steps:
            continue  # nothing due: skip the call, whose array arguments cost more than a small rope's step
        status, node, frame = end_step(done, total_steps, save_every, check_every, h, x, v, mass, forces, ledger,
                                       limits, frames, frame)
        if status != OK:
            return s + 1, frame, status, node
    return n_steps, frame, OK, -1
