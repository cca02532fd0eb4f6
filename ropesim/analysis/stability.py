"""Stability before running: bounds on the fastest natural frequency and each method's largest stable step.

The linearised rope obeys M x'' = -K x - C x' (plus drag). A spring of stiffness k between nodes i and j
contributes k [u u^T + (1 - l/r) (I - u u^T)] to K: at most k in any direction while it is stretched (r >= l),
so K <= (L (x) I_D) with L the spring graph's Laplacian weighted by k (held nodes removed: they do not move).
The thrower's and guides' centring springs add their omega0^2 to the nodes they can hold. Two bounds on
omega_max, the square root of the largest eigenvalue of M^-1/2 L M^-1/2 (+ omega0^2):

- ``gershgorin``: the largest row sum of |M^-1/2 L M^-1/2|. For a uniform chain 2 sqrt(k/m): its zig-zag mode,
  twice a single spring's sqrt(k/m) (the write-up's dt < 2 sqrt(m/k) is the one-spring limit).
- ``spectral``: that largest eigenvalue itself (dense symmetric eigenvalues up to SPECTRAL_MAX_NODES nodes;
  Gershgorin above). Exact for a straight, stretched rope; never above Gershgorin.

A method's largest stable step is then the h at which its one-step map of the damped oscillator
x'' = -omega^2 x - gamma x' stops being bounded (:func:`ropesim.integrators.stable_step`), with gamma the
explicit velocity damping the method sees: the thrower's drive b_thrower / m and centring damping 2 zeta omega0,
the guides' 2 zeta omega0, and, for Runge-Kutta (which does not integrate drag exactly), the drag b / m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..build import Model, spring_count
from ..integrators import METHODS, get_method, stable_step

SPECTRAL_MAX_NODES = 800
WARN_FRACTION = 0.8       # `ropesim run` warns above this fraction of the bound, refuses above the bound


def _laplacian_rows(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, k) of every spring between two free nodes, and the diagonal (N,) of L."""
    scene = model.scene
    n = model.nodes
    diag = np.zeros(n)
    ii, jj, kk = [], [], []
    pairs = [(1, scene.rope.stiffness)]
    if scene.bending is not None:
        pairs.append((2, scene.bending.stiffness))
    for stride, k in pairs:
        i = np.arange(spring_count(n, stride, scene.rope.closed))
        j = (i + stride) % n
        keep = i != j
        i, j = i[keep], j[keep]
        np.add.at(diag, i, k)
        np.add.at(diag, j, k)
        both = ~model.held[i] & ~model.held[j]
        ii.append(i[both])
        jj.append(j[both])
        kk.append(np.full(both.sum(), k))
    return np.concatenate(ii), np.concatenate(jj), np.concatenate(kk), diag


def contact_stiffness(model: Model) -> float:
    """The largest omega0^2 [1/s^2] of the thrower's and guides' centring springs (0 without them)."""
    scene = model.scene
    w0 = scene.thrower.resolved_omega0 if scene.thrower is not None else 0.0
    extra = w0 * w0  # inf, not OverflowError, when absurdly large
    for guide in scene.guides:
        w = guide.omega0 if guide.omega0 is not None else (
            scene.thrower.resolved_omega0 if scene.thrower is not None else 0.0)
        extra = max(extra, w * w)
    return extra


def explicit_damping(model: Model) -> float:
    """The largest velocity-damping rate [1/s] a method evaluates explicitly (thrower and guides)."""
    scene = model.scene
    rate = 0.0
    if scene.thrower is not None:
        t = scene.thrower
        free_mass = model.mass[~model.held] if (~model.held).any() else model.mass
        rate = max(t.b_thrower / float(free_mass.min()), 2 * t.damping_ratio * t.resolved_omega0)
    for guide in scene.guides:
        w = guide.omega0 if guide.omega0 is not None else (
            scene.thrower.resolved_omega0 if scene.thrower is not None else 0.0)
        rate = max(rate, 2 * guide.damping_ratio * w)
    return rate


def gershgorin_frequency(model: Model) -> float:
    """Gershgorin bound [rad/s] on omega_max (see the module doc); 0 when no node is free."""
    free = ~model.held
    if not free.any():
        return 0.0
    i, j, k, diag = _laplacian_rows(model)
    inv_sqrt_m = 1.0 / np.sqrt(model.mass)
    row = diag / model.mass
    coupling = k * inv_sqrt_m[i] * inv_sqrt_m[j]
    np.add.at(row, i, coupling)
    np.add.at(row, j, coupling)
    return float(math.sqrt(row[free].max() + contact_stiffness(model)))


def spectral_frequency(model: Model) -> float:
    """omega_max [rad/s] of the bound matrix itself (Gershgorin's bound above SPECTRAL_MAX_NODES nodes)."""
    free = np.flatnonzero(~model.held)
    if free.size == 0:
        return 0.0
    if model.nodes > SPECTRAL_MAX_NODES:
        return gershgorin_frequency(model)
    i, j, k, diag = _laplacian_rows(model)
    lap = np.diag(diag)
    np.add.at(lap, (i, j), -k)
    np.add.at(lap, (j, i), -k)
    inv_sqrt_m = 1.0 / np.sqrt(model.mass)
    sym = lap * inv_sqrt_m[:, None] * inv_sqrt_m[None, :]
    sym = sym[np.ix_(free, free)]
    top = float(np.linalg.eigvalsh(sym)[-1])
    return math.sqrt(max(top, 0.0) + contact_stiffness(model))


def drag_rates(model: Model) -> tuple[float, float]:
    """(smallest, largest) drag rate b / m [1/s] over the free nodes."""
    free = ~model.held
    if not free.any():
        return 0.0, 0.0
    rate = model.drag[free] / model.mass[free]
    return float(rate.min()), float(rate.max())


def predicted_dt(model: Model, method: str, omega: float | None = None) -> float:
    """Largest stable time step [s] for ``method`` on this scene (inf for the stiff integrator).

    Uses the spectral bound on omega_max unless ``omega`` is given. Splitting schemes integrate drag exactly,
    so they are bounded with the least drag (the worst case); Runge-Kutta sees drag explicitly, bounded with
    the most.
    """
    scheme = get_method(method)
    omega = spectral_frequency(model) if omega is None else omega
    low, high = drag_rates(model)
    damping = explicit_damping(model)
    if scheme.kind == "rk":
        return stable_step(scheme, omega, damping, high)
    return stable_step(scheme, omega, damping, low)


@dataclass(frozen=True)
class Bound:
    method: str
    h_omega: float             # the method's stability interval on the undamped oscillator
    dt_gershgorin: float       # largest stable dt with the Gershgorin bound [s]
    dt_spectral: float         # ... with the spectral bound [s]; the one `ropesim run` enforces


def bounds(model: Model, methods=None) -> tuple[float, float, list[Bound]]:
    """(Gershgorin omega_max, spectral omega_max, every method's bounds)."""
    g, s = gershgorin_frequency(model), spectral_frequency(model)
    rows = []
    for name in methods or METHODS:
        scheme = get_method(name)
        rows.append(Bound(name, scheme.stability_limit, predicted_dt(model, name, g), predicted_dt(model, name, s)))
    return g, s, rows


def time_step_verdict(model: Model, method: str, dt: float) -> tuple[str, float]:
    """('ok' | 'warn' | 'refuse', bound [s]): refuse above the bound, warn above WARN_FRACTION of it."""
    bound = predicted_dt(model, method)
    if dt > bound:
        return "refuse", bound
    if dt > WARN_FRACTION * bound:
        return "warn", bound
    return "ok", bound
