"""The static shape: every force balanced at every free node, the held nodes where the scene holds them.

Solved by pseudo-transient continuation (a damped Newton method): each iteration solves

    (M / tau^2 + C / tau + K) dx = F(x),

K the stiffness and C the damping of the force terms (the stiff integrator's Newton matrix, here at zero
velocity, :func:`ropesim.model.terms.newton_matrix` divided by tau^2), F the net static force (weight,
buoyancy, springs, bending, the seabed's contact, drag in the flow at its full strength, nodes at rest). With
a small pseudo-time step tau this is an overdamped implicit step of the dynamics, which a slack chain or a
seabed touchdown needs (K alone is singular or indefinite there). Each accepted step doubles tau, so the steps
grow into Newton's (tau -> infinity) as the shape settles; a step that makes the residual norm grow tenfold
(contact found deep inside the seabed, a segment overstretched) is undone and tau quartered; and no node moves
more than a quarter of a segment in one step (a trust region: the Jacobian is only local). The banded solves
make each iteration O(N).

Converged when the largest residual force on a free node is below ``tol`` times the largest force any term
puts on a node (its weight, or its spring's pull), by default 1e-10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .banded import factor, solve, woodbury
from .jacobian import Jacobian, band_width
from .terms import accelerations, coupling_reach, newton_matrix
from .jit import kernel

TOL = 1e-10
MAX_ITERATIONS = 2000


@dataclass(frozen=True)
class Equilibrium:
    """The static shape (D, N) [m], the largest residual force [N] and what it is relative to, iterations."""

    x: np.ndarray
    residual: float
    scale: float
    iterations: int
    converged: bool


@kernel
def _forces(x, v, acc, p, t, mass, free, out):
    """The net static force [N] on every free node (0 on held nodes) into ``out`` (flat, node-major); returns
    its largest component."""
    accelerations(x, v, acc, p, t)
    dim, n = x.shape
    worst = 0.0
    for i in range(n):
        for d in range(dim):
            f = mass[i] * acc[d, i] if free[i] else 0.0
            out[i * dim + d] = f
            if abs(f) > worst or not f == f:
                worst = abs(f) if f == f else np.inf
    return worst


def solve_equilibrium(model, x: np.ndarray | None = None, tol: float = TOL,
                      max_iterations: int = MAX_ITERATIONS) -> Equilibrium:
    """The static shape of ``model`` from the guess ``x`` (D, N) (default: its initial positions)."""
    x = np.array(model.x0 if x is None else x, dtype=float)
    dim, n = x.shape
    scene, p = model.scene, model.params
    free = np.ascontiguousarray(~model.held)
    v = np.zeros_like(x)
    acc = np.zeros_like(x)
    t = _steady_time(scene)
    w, cyclic = band_width(scene.rope.closed, n, coupling_reach(scene))
    nt, m = dim * n, w * dim
    jac = Jacobian(np.zeros(((w + 1) * dim, nt)), np.zeros((m, m)), np.zeros((dim, dim)), w)
    wood = woodbury(nt, m)
    nodes = (free, model.mass, np.where(model.held, 0.0, model.drag))
    force, trial = np.zeros(nt), np.zeros(nt)
    scale = _force_scale(model)
    worst = _forces(x, v, acc, p, t, model.mass, free, force)
    norm = float(np.linalg.norm(force))
    tau = math.sqrt(float(model.mass[free].min()) / max(scene.rope.stiffness, 1e-300))   # one spring's period
    reach = 0.25 * scene.rope.segment_length
    for iteration in range(1, max_iterations + 1):
        if worst <= tol * scale:
            return Equilibrium(x, worst, scale, iteration - 1, True)
        newton_matrix(x, v, jac, tau, nodes, p, t)   # M + tau b + tau^2 K + tau C, so the step is tau^2 F
        if not factor(jac.band, jac.corner, cyclic, jac.band.shape[0] - 1, wood):
            tau *= 0.25
            continue
        step = force * tau * tau
        solve(jac.band, jac.corner, cyclic, jac.band.shape[0] - 1, step, wood)
        largest = float(np.abs(step).max())
        if largest > reach:
            step *= reach / largest
        candidate = x + step.reshape(n, dim).T
        better = _forces(candidate, v, acc, p, t, model.mass, free, trial)
        new_norm = float(np.linalg.norm(trial))
        if not new_norm <= 10.0 * norm:
            tau *= 0.25
            if tau < 1e-30:
                break
            continue
        tau = min(2.0 * tau, 1e12)
        x, worst, norm, force, trial = candidate, better, new_norm, trial, force
    return Equilibrium(x, worst, scale, max_iterations, worst <= tol * scale)


def _steady_time(scene) -> float:
    """A time at which every ramp (a flow's) has finished: the static shape is for the steady flow."""
    return (scene.flow.ramp_time if scene.flow is not None else 0.0) + 1.0


def _force_scale(model) -> float:
    """The largest force [N] a term puts on a node: its weight (g or 1 m/s^2 times its mass), or a segment's
    pull at 1 % strain."""
    scene = model.scene
    g = scene.gravity.g if scene.gravity is not None else 1.0
    return max(float(model.mass.max()) * g, 0.01 * scene.rope.stiffness * scene.rope.segment_length)
