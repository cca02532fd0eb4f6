"""Time integrators: splitting schemes as data, run by one compiled loop.

A splitting (drift-kick) scheme advances one step h as

    drift(a_0 h), kick(b_0 h), drift(a_1 h), kick(b_1 h), ..., kick(b_{s-1} h), drift(a_s h)

where drift(c) moves positions, x += c v, and kick(c) moves velocities under the forces at the current
positions. Time advances in the drifts, so held nodes are put at x0 + V t with t the drift's end time and every
force sees positions of one instant.

Linear drag is integrated exactly within each kick: with gamma = b / m, the kick solves
v' = a - gamma v for a time c, v <- e^(-gamma c) v + (1 - e^(-gamma c)) / gamma a. Putting -b v into a plain
kick instead would drop every scheme to first order; done this way each keeps its order with drag on and
drag never limits the time step.

To add a scheme: give its coefficients, its order and a line of documentation in :data:`METHODS`; the
stability interval is computed from the coefficients. The name is the same in TOML, on the command line and
here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit

from .kernel import accelerations

OK, NON_FINITE = 0, 1


@dataclass(frozen=True)
class SplittingScheme:
    """A drift-kick composition: ``drift`` has one more entry than ``kick``."""

    name: str
    order: int
    drift: tuple[float, ...]
    kick: tuple[float, ...]
    doc: str

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
        return _stability_limit(self.drift, self.kick)


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


METHODS: dict[str, SplittingScheme] = {
    s.name: s for s in (
        SplittingScheme("symplectic_euler", 1, (0.0, 1.0), (1.0,),
                        "Symplectic Euler, the write-up's method: kick with the forces at x_n, then drift with "
                        "the new velocity. First order, 1 force evaluation per step."),
        SplittingScheme("verlet", 2, (0.0, 1.0, 0.0), (0.5, 0.5),
                        "Velocity Verlet: half kick, drift, half kick. Second order, 1 force evaluation per step "
                        "(the last kick's forces are reused by the next step's first)."),
        _yoshida4(),
        _pefrl(),
    )
}


def get_method(name: str) -> SplittingScheme:
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}: allowed {', '.join(METHODS)}") from None


@lru_cache(maxsize=None)
def _stability_limit(drift: tuple, kick: tuple) -> float:
    def growth(hw: float) -> float:
        m = np.eye(2)
        for k in range(len(kick)):
            m = np.array([[1.0, drift[k]], [0.0, 1.0]]) @ m       # (x, v) with h = 1, omega = hw
            m = np.array([[1.0, 0.0], [-kick[k] * hw * hw, 1.0]]) @ m
        m = np.array([[1.0, drift[-1]], [0.0, 1.0]]) @ m
        return float(np.max(np.abs(np.linalg.eigvals(m))))

    step, hw = 1e-3, 1e-3
    while hw < 10.0 and growth(hw + step) <= 1.0 + 1e-9:
        hw += step
    lo, hi = hw, hw + step
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if growth(mid) <= 1.0 + 1e-9 else (lo, mid)
    return lo


def kick_factors(scheme: SplittingScheme, h: float, drag: np.ndarray, mass: np.ndarray,
                 held: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per kick and node, the factors of the exact drag kick v <- decay v + gain a.

    decay = e^(-gamma c h), gain = (1 - decay) / gamma (or c h without drag), with gamma = b / m and c the
    kick coefficient. Held nodes get decay 1 and gain 0: their velocity never changes.
    """
    c = np.asarray(scheme.kick)[:, None] * h
    gamma = (drag / mass)[None, :]
    decay = np.exp(-gamma * c)
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = np.where(gamma > 0, -np.expm1(-gamma * c) / np.where(gamma > 0, gamma, 1.0), c)
    decay[:, held] = 1.0
    gain[:, held] = 0.0
    return np.ascontiguousarray(decay), np.ascontiguousarray(gain)


@njit(cache=True, error_model="numpy")
def _first_non_finite(x):
    dim, n = x.shape
    for i in range(n):
        for d in range(dim):
            if not math.isfinite(x[d, i]):
                return i
    return -1


@njit(cache=True, error_model="numpy")
def advance(x, v, acc, have_acc, step0, n_steps, total_steps, h, drift, kick, decay, gain, reuse_force,
            held_idx, held_x0, held_v, forces, save_every, frames_t, frames_x, frames_v, check_every):
    """Advance ``n_steps`` steps in place, from global step ``step0`` (time step0 * h).

    Saves a frame after every global step s (1-based) with s % save_every == 0 or s == total_steps, into
    ``frames_*`` (F, D, N). ``have_acc[0]`` carries the first-same-as-last forces between calls.
    Returns (steps done, frames written, status, node): status NON_FINITE names the first non-finite node.
    """
    dim, n = x.shape
    stages = kick.shape[0]
    n_held = held_idx.shape[0]
    frame = 0
    for s in range(n_steps):
        step = step0 + s
        t = step * h
        for k in range(stages + 1):
            c = drift[k]
            if c != 0.0:
                ch = c * h
                for d in range(dim):
                    for i in range(n):
                        x[d, i] += ch * v[d, i]
                t += ch
                for j in range(n_held):
                    i = held_idx[j]
                    for d in range(dim):
                        x[d, i] = held_x0[d, j] + held_v[d, j] * t
            if k == stages:
                break
            if not (k == 0 and reuse_force and have_acc[0]):
                accelerations(x, v, acc, forces)
            dk = decay[k]
            gk = gain[k]
            for d in range(dim):
                for i in range(n):
                    v[d, i] = dk[i] * v[d, i] + gk[i] * acc[d, i]
        have_acc[0] = reuse_force
        done = step + 1
        saving = done % save_every == 0 or done == total_steps
        if saving or done % check_every == 0:
            bad = _first_non_finite(x)
            if bad < 0:
                bad = _first_non_finite(v)
            if bad >= 0:
                return s + 1, frame, NON_FINITE, bad
        if saving:
            frames_t[frame] = done * h
            frames_x[frame] = x
            frames_v[frame] = v
            frame += 1
    return n_steps, frame, OK, -1
