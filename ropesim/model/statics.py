"""The static shape: every force balanced at every free node, the held nodes where the scene holds them.

Solved by a damped Newton method with a line search on the potential energy. Each iteration takes the step d
of an overdamped implicit step of the dynamics (pseudo-transient continuation),

    (M / tau^2 + C / tau + K) d = F(x),

K the stiffness and C the damping of the force terms (the stiff integrator's Newton matrix, here at zero
velocity, :func:`ropesim.model.terms.newton_matrix` divided by tau^2, where the scene's method compiles it;
for an explicit method differenced from the compiled force, :mod:`ropesim.model.static_matrix`), F the net
static force (weight, buoyancy, springs, bending, the seabed's contact, drag in the flow at its full strength,
nodes at rest). With a small pseudo-time step tau this is a short gradient step (K alone is singular or indefinite for a slack chain
or at a seabed touchdown); as tau grows it becomes Newton's step. The step is then shortened until it lowers
the merit

    phi(a) = E(x + a d) - a d . F_nc(x),

E the potential energy of the conservative terms (springs, bending, gravity, buoyancy, the seabed's contact)
and F_nc the rest (drag in the flow; without a flow, a sea, a thrower or guides every other term's vanishes at
rest and F_nc is not computed), which phi holds at its value at x; its slope at a = 0 is -d . F < 0
(Armijo's condition, with a factor 1e-4). Stiff springs make the residual force a poor judge of a step (a
slack segment drawn 1 cm past its rest length gives 5e6 N on a chain) where the energy is not: the line
search takes the fraction of the step at which the segment comes taut. A full step doubles tau, a shortened
one keeps it, a failed one quarters it; no node moves more than a segment in one step (a trust region: the
Jacobian is only local). Near the solution, where the energy's changes reach its round-off, a step is also
taken when it halves the residual. The banded solves make each iteration O(N).

A system of lines is solved the same way: a free point's line ends share one unknown and its balance is the sum
of the forces on them (:func:`~ropesim.model.junctions.fold_junctions`), the step solved with each line banded
and the points' unknowns by a Schur complement (:mod:`ropesim.model.schur`; for an explicit method, whose loop
compiles none, in NumPy around the banded factor and solve, :mod:`ropesim.model.static_schur`). The pseudo-time step starts at the
stiffest line's spring period, and no node moves more than the shortest segment in one step.

A free rigid body's unknowns are its reference point's displacement and a small rotation vector (six in 3-D,
three in 2-D), in the same Schur complement; its orientation moves on the rotation group (q <- exp(phi) q) and
its line ends follow it (:class:`~ropesim.model.body_groups.StaticBodies`): its own rows are its mass matrix plus
tau^2 its rotational geometric stiffness, the merit function adds its potential energy, and its residual is its
net force and its net moment over its size. It turns by at most MAX_TURN in one step.

Drag in a flow depends on positions too, through each node's tangent (the split into normal and tangential
drag): K_t = -dF_drag/dx (:func:`ropesim.model.forces.fluid.add_fluid_tangent_stiffness`), which the
integrator's symmetric matrix leaves out. For a line hanging in a current it is as large as the springs'
sideways stiffness, and without it the iteration stalls (a 50 m line in 1 m/s of current was left 7 N out of
balance after 2000 iterations, in 2 m/s 880 N). It is not symmetric, so the step solves
(M + tau C + tau^2 (K + K_t)) d = tau^2 F by GMRES, with the banded Cholesky of the symmetric part as its
(right) preconditioner: a few Krylov vectors, O(N) each. Without drag in a flow the step is the banded solve
alone.

Converged when the largest residual force on a free node is below ``tol`` times the largest force any term
puts on a node (its weight, or its spring's pull at 1 % strain), by default 1e-10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .banded import factor as factor_newton_matrix
from .banded import solve as solve_newton_matrix
from .banded import woodbury
from .jacobian import Jacobian, band_width
from .forces.fluid import WITH_FLOW, WITH_FLUID_DRAG, WITH_VISCOUS_DRAG, add_fluid_tangent_stiffness, still_flow
from .junctions import WITH_JUNCTIONS, add_junction_added_mass_jacobian, fold_junctions
from .body_groups import StaticBodies
from .schur import model_groups, schur_factor, schur_solve
from .static_matrix import DifferencedMatrix
from .static_schur import NumpySchur
from .forces.bending import WITH_EI_BENDING
from .forces.sea import WITH_SEA
from .terms import (WITH_APPLIED, accelerations, coupling_reach, mechanical_energy, newton_matrix,
                    velocity_accelerations)
from . import jit

TOL = 1e-10
MAX_ITERATIONS = 2000
KRYLOV_TOL = 1e-10        # GMRES stops when the step's linear residual is this fraction of tau^2 |F|
KRYLOV_DIMENSION = 80     # ... or after this many Krylov vectors (the step is then inexact; the search judges it)
MAX_TURN = 0.25          # a free body turns by at most this many radians in one step
AT_REST_FORCES = {WITH_FLOW.name, WITH_SEA.name, WITH_APPLIED.name}   # non-conservative terms not 0 at v = 0
ANALYTIC_MATRIX_METHODS = ("sdirk2", "galpha")   # their loops compile newton_matrix: the static solver shares it


@dataclass(frozen=True)
class Equilibrium:
    """The static shape (D, N) [m], the largest residual force [N] and what it is relative to, iterations; the
    free bodies' poses (7, B) (reference point, unit quaternion)."""

    x: np.ndarray
    residual: float
    scale: float
    iterations: int
    converged: bool
    pose: np.ndarray = field(default_factory=lambda: np.zeros((7, 0)))


def forces_on_free_nodes(acceleration, x, v, acc, p, t, mass, free, out, junctions=None):
    """The net static force [N] on every free node (0 on held nodes) into ``out`` (flat, node-major), a free
    point's on its first node (the sum over its line ends, the others 0); returns its largest component (inf if
    any is not a number). ``acceleration`` is the scene's compiled term list
    (:func:`~ropesim.model.terms.accelerations`), the loop's own: the static solver compiles no copy of it."""
    acceleration(x, v, acc, p, t)
    dim, n = x.shape
    np.multiply(acc, mass, out=out.reshape(n, dim).T)
    out.reshape(n, dim)[~free] = 0.0
    if junctions is not None:
        fold_junctions(out, junctions, dim)
    worst = float(np.abs(out).max(initial=0.0))
    return np.inf if worst != worst else worst


def solve_equilibrium(model, x: np.ndarray | None = None, tol: float = TOL,
                      max_iterations: int = MAX_ITERATIONS, pose: np.ndarray | None = None) -> Equilibrium:
    """The static shape of ``model`` from the guess ``x`` (D, N) (default: its initial positions) and the free
    bodies' poses ``pose`` (7, B) (default: their initial poses).

    The Newton matrix is differenced from the scene's compiled force (:mod:`ropesim.model.static_matrix`) unless
    the scene's method compiles the analytic one anyway (:data:`ANALYTIC_MATRIX_METHODS`) or declares EI
    bending (a beam's soft modes are below the differences' round-off). Should the differenced iteration stall
    (its pseudo-time step shrunk to nothing) or not converge in the full ``MAX_ITERATIONS``, the solve starts
    again from the same guess with the analytic matrix: no scene converges with it that did before (a free body
    imported from MoorDyn and a floating box under a sea need it). :func:`warm_up` prepares both."""
    differenced = _differences(model)
    result, stalled = _solve(model, x, tol, max_iterations, pose, differenced)
    if differenced and not result.converged and (stalled or max_iterations >= MAX_ITERATIONS):
        result, _ = _solve(model, x, tol, max_iterations, pose, False)
    return result


def _differences(model) -> bool:
    """Whether the static solve differences its Newton matrix (see :func:`solve_equilibrium`)."""
    return not (model.scene.integrator.method in ANALYTIC_MATRIX_METHODS or WITH_EI_BENDING.name in model.switches)


def warm_up(model, x: np.ndarray) -> Equilibrium:
    """One iteration from ``x`` with each Newton matrix :func:`solve_equilibrium` may take for ``model`` (the
    differenced one and its analytic fallback), so that `ropesim compile` prepares whatever a solve compiles;
    returns the first one's result."""
    differenced = _differences(model)
    result, _ = _solve(model, x, TOL, 1, None, differenced)
    if differenced:
        _solve(model, x, TOL, 1, None, False)
    return result


def _solve(model, x: np.ndarray | None, tol: float, max_iterations: int, pose: np.ndarray | None,
           differenced: bool) -> tuple[Equilibrium, bool]:
    """:func:`solve_equilibrium` with the differenced (or the analytic) Newton matrix; and whether it stalled."""
    x = np.array(model.x0 if x is None else x, dtype=float)
    pose = np.array(model.body_pose0 if pose is None else pose, dtype=float)
    dim, n = x.shape
    scene, p = model.scene, model.params
    acceleration, energy_of, factor, solve = (model.kernel(f) for f in (
        accelerations, mechanical_energy, factor_newton_matrix, solve_newton_matrix))
    free = np.ascontiguousarray(~model.held)
    mass = model.mass
    v = np.zeros_like(x)
    acc = np.zeros_like(x)
    t = _steady_time(scene)
    w, cyclic = band_width(any(line.closed for line in model.lines), n, coupling_reach(scene))
    nt, m = dim * n, w * dim
    jac = Jacobian(np.zeros(((w + 1) * dim, nt)), np.zeros((m, m)), np.zeros((dim, dim)), w)
    wood = woodbury(nt, m)
    nodes = (free, mass, np.where(model.held, 0.0, model.drag))
    # the drag's tangent stiffness: zero at rest without a flow (u = v - U = 0), neither compiled nor applied then
    dragged = bool({WITH_FLUID_DRAG.name, WITH_VISCOUS_DRAG.name} & model.switches) and WITH_FLOW.name in model.switches
    if not differenced or (cyclic and n < 2 * w + 1):
        differenced, jacobian, tangent_stiffness = None, model.kernel(newton_matrix), \
            model.kernel(add_fluid_tangent_stiffness)
    else:   # an explicit method's loop compiles no Newton matrix: differenced from the loop's own force
        differenced = DifferencedMatrix(model, acceleration, w, cyclic, free, mass, nodes[2], t,
                                        model.velocity_dependent)
    groups = model_groups(model, w, arms=differenced is None)   # else placed by StaticBodies, in NumPy
    bodies = StaticBodies(model, groups, t, differenced is None) if p.bodies is not None else None
    junctions = p.junctions
    if groups.nodes.size:   # a system's free points and bodies: each line banded, they by a Schur complement
        # an explicit method's loop links no Schur solver: the groups' part in NumPy around the banded one
        schur = NumpySchur(groups, dim, factor, solve, jac.corner, wood) if differenced is not None else None

        def factored() -> bool:
            if junctions is not None:
                add_junction_added_mass_jacobian(x, jac.band, junctions, p.neighbours)
            if bodies is not None:
                bodies.fill(tau)
            if schur is not None:
                return schur.factor(jac.band)
            return schur_factor(jac.band, w, p.lines, groups)

        def inverse(z: np.ndarray) -> np.ndarray | None:
            if schur is not None:
                schur.solve(z)
            else:
                schur_solve(jac.band, w, p.lines, groups, z)
            return bodies.step() if bodies is not None else None   # the bodies' unknowns

        def homogeneous(z: np.ndarray) -> np.ndarray | None:
            """inverse without the bodies' own right-hand side"""
            own = groups.own_rhs.copy()
            groups.own_rhs[:] = 0.0
            try:
                return inverse(z)
            finally:
                groups.own_rhs[:] = own

        def folded(z: np.ndarray) -> np.ndarray:
            if junctions is not None:
                fold_junctions(z, junctions, dim)
            return z
    else:
        def factored() -> bool:
            return factor(jac.band, jac.corner, cyclic, jac.band.shape[0] - 1, wood)

        def inverse(z: np.ndarray) -> None:
            solve(jac.band, jac.corner, cyclic, jac.band.shape[0] - 1, z, wood)

        homogeneous = None

        def folded(z: np.ndarray) -> np.ndarray:
            return z

    def balance(x: np.ndarray, pose: np.ndarray, out: np.ndarray) -> tuple[float, float, float]:
        """The net forces into ``out``; (the largest left on a free node or body, the residual's norm [N], the
        potential energy [J]). A body's line ends carry their lines' pull: its residual is its net force and
        moment (over its size)."""
        if bodies is not None:
            bodies.place(x, pose)
        worst = forces_on_free_nodes(acceleration, x, v, acc, p, t, mass, free, out, junctions)
        energy = float(energy_of(x, v, mass, p)[0])
        if bodies is None:
            return worst, float(np.linalg.norm(out)), energy
        bodies.evaluate(pose, out)
        loose = out.reshape(n, dim)[~bodies.attached]
        worst = max(float(np.abs(loose).max(initial=0.0)) if np.all(np.isfinite(loose)) else np.inf, bodies.worst())
        return worst, math.hypot(float(np.linalg.norm(loose)), bodies.norm()), energy + bodies.energy(pose)

    force, trial, other = np.zeros(nt), np.zeros(nt), np.zeros(nt)
    moving_fluid = bool(AT_REST_FORCES & model.switches)   # otherwise F_nc = 0 at rest: nothing to compile
    if moving_fluid:   # once before the first step too, so that `ropesim compile`'s one-iteration warm-up has it
        nonconservative = _nonconservative(model, acceleration, v, acc, t, free, junctions)
        nonconservative(x, other)
    scale = _force_scale(model)
    worst, norm, energy = balance(x, pose, force)
    stiffest = max(line.stiffness for line in model.lines)
    tau = math.sqrt(float(mass[free].min()) / max(stiffest, 1e-300))   # one spring's period
    reach = min(line.segment_length for line in model.lines)
    blocks = np.zeros((n, 3, dim, dim)) if dragged and differenced is None else None
    stalled = False
    for iteration in range(1, max_iterations + 1):
        if worst <= tol * scale:
            return Equilibrium(x, worst, scale, iteration - 1, True, pose), False
        extra = None           # the matrix's part the banded solve leaves out: by GMRES
        if differenced is not None:
            rest = differenced.fill(x, jac, tau)   # M + tau b + tau^2 K + tau C, so the step is tau^2 F
            if dragged:   # the drag's tangent stiffness in a flow
                extra = lambda z, rest=rest: folded(differenced.apply(rest, z))
        else:
            jacobian(x, v, jac, tau, nodes, p, t)
            if blocks is not None:
                blocks[:] = 0.0
                tangent_stiffness(x, v, blocks, free, p, t)
                if blocks.any():
                    extra = lambda z, s=tau * tau: s * folded(_apply_blocks(blocks, z, free))
        if not factored():
            tau *= 0.25
            continue
        step = force * tau * tau
        if extra is None:
            du = inverse(step)
        else:
            step, du = _krylov_step(step, inverse, extra, homogeneous)
        largest = float(np.abs(step).max())
        shorten = reach / largest if largest > reach else 1.0
        if du is not None:     # a body turns by at most MAX_TURN in one step
            turns = np.abs(du[:, dim:]).max(initial=0.0)
            shorten = min(shorten, MAX_TURN / turns if turns > MAX_TURN else 1.0)
            du *= shorten
        step *= shorten
        slope = -float(step @ force)
        if du is not None:
            own, own_drag = bodies.rates(du)
            slope -= own
        if not slope < 0.0:          # not downhill (a non-conservative force turned it): a shorter pseudo-step
            tau *= 0.25
            if tau < 1e-30:
                stalled = True
                break
            continue
        if moving_fluid:
            nonconservative(x, other)
        drift = float(step @ other) + (own_drag if du is not None else 0.0)
        fraction, accepted = 1.0, False
        while fraction > 1e-6:
            candidate = x + fraction * step.reshape(n, dim).T
            moved = bodies.moved(pose, du, fraction) if du is not None else pose
            better, new_norm, trial_energy = balance(candidate, moved, trial)
            change = trial_energy - energy - fraction * drift
            if change <= 1e-4 * fraction * slope or (
                    abs(change) <= 1e-12 * max(abs(energy), 1.0) and new_norm <= 0.5 * norm):
                accepted = True
                break
            fraction *= 0.5
        if not accepted:
            tau *= 0.25
            if tau < 1e-30:
                stalled = True
                break
            if bodies is not None:
                balance(x, pose, force)   # the bodies' figures back at x
            continue
        if fraction == 1.0:
            tau = min(2.0 * tau, 1e12)
        x, pose, worst, norm, force, trial, energy = candidate, moved, better, new_norm, trial, force, trial_energy
    if bodies is not None:
        bodies.place(x, pose)
    return Equilibrium(x, worst, scale, max_iterations, worst <= tol * scale, pose), stalled


def _apply_blocks(blocks: np.ndarray, z: np.ndarray, free: np.ndarray) -> np.ndarray:
    """K_t z for node-local blocks (N, 3, D, D) on each node's neighbours before, itself and after (``blocks`` of
    :func:`add_fluid_tangent_stiffness`); held nodes' entries of z are left out (they do not move)."""
    n, _, dim, _ = blocks.shape
    zz = z.reshape(n, dim) * free[:, None]
    out = np.einsum("nab,nb->na", blocks[:, 1], zz)
    out += np.einsum("nab,nb->na", blocks[:, 0], np.roll(zz, 1, axis=0))
    out += np.einsum("nab,nb->na", blocks[:, 2], np.roll(zz, -1, axis=0))
    return out.reshape(-1)


def _krylov_step(rhs: np.ndarray, inverse, extra, homogeneous=None) -> tuple[np.ndarray, np.ndarray | None]:
    """Solve (A + E) d = rhs by GMRES, right-preconditioned by A: ``inverse(z)`` overwrites z with A^-1 z (the
    factored banded matrix) and returns the free bodies' unknowns of it (or None), ``extra(z)`` returns E z. From
    d = 0; stops at KRYLOV_TOL or KRYLOV_DIMENSION vectors, returning the best d so far and its bodies' unknowns.

    With free bodies, ``inverse`` also solves for the bodies' own right-hand side r_b (their rows of the system,
    on which E does not act) and ``homogeneous(z)`` without it: d = d_b + A^-1 (y, 0) with d_b = A^-1 (0, r_b),
    and GMRES solves y + E A^-1 (y, 0) = rhs - E d_b. (r_b stays at its scale while the Krylov vectors are unit:
    taken out of A^-1 (v, r_b) - d_b, v's part would drown in the round-off of d_b.)"""
    offset, offset_unknowns = np.zeros_like(rhs), None
    if homogeneous is None:                  # a rope: no own right-hand side
        homogeneous = inverse
    else:
        offset_unknowns = inverse(offset)    # d_b (None without free bodies)
    if offset_unknowns is not None:
        rhs = rhs - extra(offset)
    beta = float(np.linalg.norm(rhs))
    if beta == 0.0:
        return offset, offset_unknowns
    basis, preconditioned, unknowns = [rhs / beta], [], []
    hessenberg = np.zeros((KRYLOV_DIMENSION + 1, KRYLOV_DIMENSION))
    coefficients = np.zeros(1)
    for k in range(KRYLOV_DIMENSION):
        z = basis[k].copy()
        unknowns.append(homogeneous(z))
        preconditioned.append(z)
        w = basis[k] + extra(z)                  # (A + E) A^-1 v
        for _ in range(2):                       # Gram-Schmidt twice: orthogonal to round-off
            for j in range(k + 1):
                h = float(basis[j] @ w)
                hessenberg[j, k] += h
                w -= h * basis[j]
        hessenberg[k + 1, k] = float(np.linalg.norm(w))
        target = np.zeros(k + 2)
        target[0] = beta
        coefficients, *_ = np.linalg.lstsq(hessenberg[:k + 2, :k + 1], target, rcond=None)
        residual = float(np.linalg.norm(hessenberg[:k + 2, :k + 1] @ coefficients - target))
        if residual <= KRYLOV_TOL * beta or hessenberg[k + 1, k] <= 1e-300:
            break
        basis.append(w / hessenberg[k + 1, k])
    step = offset + sum(c * z for c, z in zip(coefficients, preconditioned))
    if offset_unknowns is None:
        return step, None
    return step, offset_unknowns + sum(c * u for c, u in zip(coefficients, unknowns))


def _nonconservative(model, acceleration, v: np.ndarray, acc: np.ndarray, t: float, free: np.ndarray, junctions):
    """F_nc at rest as ``forces(x, out)``: the non-conservative terms' force [N] on every free node into ``out``
    (flat, node-major), a free point's on its first node.

    With a flow the only such term (no sea, thrower or guides) it is the flow's drag on nodes at rest: the net
    force in the flow less the net force in still water (:func:`~ropesim.model.forces.fluid.still_flow`), both
    by the loop's own compiled term list, so nothing more is compiled (:func:`nonconservative_forces` was 0.7 s
    of CPU of a first run). The difference is the drag to the round-off of the net force. Otherwise
    :func:`nonconservative_forces`."""
    p, mass = model.params, model.mass
    if AT_REST_FORCES & model.switches != {WITH_FLOW.name}:
        kernel = model.kernel(nonconservative_forces)
        return lambda x, out: kernel(x, v, acc, p, t, mass, free, out)
    still = p._replace(flow=still_flow(p.flow))
    at_rest = np.zeros(v.size)

    def forces(x: np.ndarray, out: np.ndarray) -> None:
        forces_on_free_nodes(acceleration, x, v, acc, p, t, mass, free, out, junctions)
        forces_on_free_nodes(acceleration, x, v, acc, still, t, mass, free, at_rest, junctions)
        out -= at_rest
    return forces


@jit.kernel
def nonconservative_forces(x, v, acc, p, t, mass, free, out):
    """The force [N] of the terms that are not conservative (drag in the flow; the others vanish at rest) on
    every free node into ``out`` (flat, node-major), a free point's on its first node."""
    dim, n = x.shape
    for i in range(n):
        for d in range(dim):
            acc[d, i] = 0.0
    velocity_accelerations(x, v, acc, p, t)
    for i in range(n):
        for d in range(dim):
            out[i * dim + d] = mass[i] * acc[d, i] if free[i] else 0.0
    if WITH_JUNCTIONS:
        fold_junctions(out, p.junctions, dim)


def _steady_time(scene) -> float:
    """A time at which every ramp (a flow's) has finished: the static shape is for the steady flow."""
    return (scene.flow.ramp_time if scene.flow is not None else 0.0) + 1.0


def _force_scale(model) -> float:
    """The largest force [N] a term puts on a node: its weight (g or 1 m/s^2 times its mass), or a segment's
    pull at 1 % strain (the stiffest line's)."""
    scene = model.scene
    g = scene.gravity.g if scene.gravity is not None else 1.0
    return max(float(model.mass.max()) * g, 0.01 * max(line.stiffness * line.segment_length for line in model.lines))
