"""Free rigid bodies in generalized-alpha's Newton solve (:mod:`ropesim.integrate.galpha`).

A body's unknowns are those of SDIRK2's stages (:mod:`ropesim.integrate.sdirk_bodies`): its reference point r and
a rotation vector phi from its orientation at the step's start, q = exp(phi) q_n (a unit quaternion to round-off,
whatever the Newton iterates do: no norm drift). In that chart the body is stepped exactly as the nodes are, with
U = (r, phi) in the place of x (U_n = (r_n, 0)), its twist W = (v, w) in the place of v and its acceleration
A = W' (6, carried from step to step as the nodes' a_n):

    U_(n+1) = U_n + h W_n + h^2 ((1/2 - beta) A_n + beta A_(n+1)),   W_(n+1) = W_n + h ((1 - gam) A_n + gam A_(n+1)),
    M(U_f) A_(n+1-am) = F(t_f, U_f, W_f)   at the force point U_f = (1 - af) U_(n+1) + af U_n,

M and F the body's Newton-Euler equations (:mod:`ropesim.model.bodies`: its mass matrix with its attachments' masses
at their arms; its own forces, its attachments' forces, less the centripetal forces and the gyroscopic moment).
U_f = (r_f, phi_f) is the unknown: q_f = exp((1 - af) phi_(n+1)) q_n lies on the geodesic from q_n to q_(n+1), and the
attachments (line ends on the body) sit where the force-point pose puts them. Taking w = phi' (dexp^-1_phi truncated
to the identity, as SDIRK2 and the Runge-Kutta-Munthe-Kaas methods' low orders do) keeps the order 2: with
phi = t w + O(t^2) the neglected phi x w / 2 enters a step at O(h^3). At rho_inf = 1 the step is symmetric (the
force point is the geodesic midpoint, seen alike from either end), so a torque-free body keeps its energy and
angular momentum without drift.

With W = Wk + (U - Uk) / beta_v and U - Ua = beta_v (W - W_hat), W_hat = Wk - c2 am A_n / beta_v (Uk, Wk, Ua as the
nodes' Xk, Vk, Xa; :func:`step_start_bodies`), the body's residual is SDIRK2's stage residual with its pair of
weights (beta_v, c2 / beta_v) in the place of (beta, beta) (:func:`~ropesim.integrate.sdirk_bodies.stage_rows`):
-beta_v [M (W - W_hat) - (c2 / beta_v) F] = -[M (U - Ua) - c2 F], the nodes' scaling. Its Newton block is then
M + c2 K + (c2 / beta_v) D, the nodes' M + c2 K + (c2 / beta_v) C: both join the Schur complement of
:mod:`ropesim.model.schur` as a group, as in SDIRK2. The linear drag b of an attachment node acts on the body
(as in the Runge-Kutta methods).

The adaptive steps' error estimate covers the body's unknowns: e = h^2 |beta - 1/6 + (am - af) / 2| (A_(n+1) - A_n),
times its mass matrix, filtered through the Newton matrix with the nodes' (J^-1 M e; its attachments then carry
the body's error at their points); a body counts |e_r| + reach |e_phi| [m] against the tolerance, reach its
farthest point from the reference point (an attachment, its centres of gravity and buoyancy, at least its radius of
gyration). Dense output: r by the cubic Hermite interpolant of the step's ends (r, v), the orientation by
exp(phi(theta)) q_n with phi the Hermite interpolant of (0, w_n) and (phi_(n+1), w_(n+1)).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..model import jit
from ..model.bodies import body_attachments_system, body_own_system
from ..model.forces.gravity import WITH_GRAVITY
from ..model.rotation import turn
from ..model.terms import body_accelerations
from .sdirk_bodies import body_stage, stage_rows

BodyAlpha = namedtuple("BodyAlpha", ["stage", "acc", "known", "reach", "pose0", "twist0", "pose1", "twist1",
                                     "turned"])
"""The free bodies (B) in generalized-alpha: ``stage`` the Newton solve's :class:`~ropesim.integrate.sdirk_bodies.
BodyStage` (its pose and twist at the force point; hat_r, hat_phi = Uk - beta_v Wk; hat_w = W_hat; r, phi = U_f);
acc (6, B) the accelerations A_n (state); known (6, B) Uk; reach (B,) [m]; the adaptive steps' last step's ends
pose0, twist0 and pose1, twist1 ((7, B), (6, B)) and turned (3, B), phi_(n+1) in q_n's chart (state with a
tolerance)."""


def body_alpha(model, groups) -> BodyAlpha:
    """The bodies' arrays for ``model`` with its Schur ``groups`` (bodies last)."""
    bundle = model.params.bodies
    count = model.body_pose0.shape[1]
    reach = np.zeros(count)
    for b in range(count):
        arms = [bundle.cog[:, b], bundle.cob[:, b], *bundle.arm[:, bundle.start[b]:bundle.start[b + 1]].T]
        gyration = math.sqrt(np.trace(bundle.inertia[:, :, b]) / (2.0 * bundle.mass[b])) if bundle.mass[b] > 0 else 0.0
        reach[b] = max(gyration, *(float(np.linalg.norm(a)) for a in arms))
    pose, twist = model.body_pose0, np.zeros((6, count))
    return BodyAlpha(body_stage(model, groups), np.zeros((6, count)), np.zeros((6, count)), reach, pose.copy(),
                     twist.copy(), pose.copy(), twist.copy(), np.zeros((3, count)))


def state_names(body: BodyAlpha, adaptive: bool) -> dict[str, np.ndarray]:
    """The bodies' arrays a resumed run needs, by attribute name: A_n, and the last step's ends with a tolerance."""
    names = {"body_acc": body.acc}
    if adaptive:
        names.update(body_pose0=body.pose0, body_twist0=body.twist0, body_pose1=body.pose1,
                     body_twist1=body.twist1, body_turned=body.turned)
    return names


@jit.kernel
def start_accelerations_bodies(x, v, an, params, pose, twist, body, t):
    """A_n at (pose, twist) and time t from ``an`` holding every node's F / m - b v / m (after the points' and
    added mass's solve); the attachments' accelerations into ``an``."""
    body_accelerations(x, v, an, params, pose, twist, body.acc, t)


@jit.kernel
def step_start_bodies(body, pose, twist, co, h):
    """The step's known parts from (pose, twist) and A_n: Uk = U_n + (1 - af) (h W_n + h^2 (1/2 - beta) A_n),
    Wk = W_n + (1 - af) h (1 - gam) A_n, the stage's hat_r, hat_phi = Uk - beta_v Wk and W_hat = Wk - c2 am A_n /
    beta_v, and the predictor U_f = U_n + (1 - af) (h W_n + h^2 A_n / 2) (as the nodes', A_(n+1) = A_n)."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    c2 = (1.0 - af) * beta * h * h / (1.0 - am)
    beta_v = beta * h / gam
    stage = body.stage
    for b in range(pose.shape[1]):
        for d in range(7):
            stage.base[d, b] = pose[d, b]
        for d in range(6):
            a = body.acc[d, b]
            w = twist[d, b]
            start = pose[d, b] if d < 3 else 0.0
            uk = start + (1.0 - af) * (h * w + h * h * (0.5 - beta) * a)
            wk = w + (1.0 - af) * h * (1.0 - gam) * a
            guess = start + (1.0 - af) * (h * w + 0.5 * h * h * a)
            body.known[d, b] = uk
            stage.hat_w[d, b] = wk - c2 * am * a / beta_v
            if d < 3:
                stage.hat_r[d, b] = uk - beta_v * wk
                stage.r[d, b] = guess
            else:
                stage.hat_phi[d - 3, b] = uk - beta_v * wk
                stage.phi[d - 3, b] = guess


@jit.kernel
def rows_bodies(body, X, V, acc, c2, beta_v, t_f, nodes, params, groups, rhs):
    """The bodies' residuals and own blocks into the groups (:func:`~ropesim.integrate.sdirk_bodies.stage_rows`
    with the weights (beta_v, c2 / beta_v)), from ``acc`` holding F / m at the force point, to which the
    attachments' linear drag is added first; their attachments' rows of ``rhs`` zeroed. Returns the squared norm
    of the bodies' residuals."""
    free, mass, drag = nodes
    bodies = params.bodies
    dim = X.shape[0]
    for k in range(bodies.links.shape[0]):   # bodies.index[k]: attachment k's node
        i = bodies.index[k]
        if drag[i] != 0.0:
            for d in range(dim):
                acc[d, i] -= drag[i] * V[d, i] / mass[i]
    return stage_rows(body.stage, X, acc, beta_v, c2 / beta_v, t_f, params, groups, rhs)


@jit.kernel
def rotation_stride(body):
    """The largest displacement [m] the bodies' last Newton update of their rotation makes within their reach."""
    worst = 0.0
    for b in range(body.reach.shape[0]):
        for d in range(3):
            moved = abs(body.stage.step[3 + d, b]) * body.reach[b]
            if not moved <= worst:
                worst = moved
    return worst


@jit.kernel
def fluid_power_bodies(work, params, body, t_f):
    """The power [W] of the fluid's forces on the bodies at the solved force point (drag, added mass), from
    ``work.acc`` holding F / m there (its attachments' entries then hold their accelerations)."""
    stage = body.stage
    return body_accelerations(work.X, work.V, work.acc, params, stage.pose, stage.twist, stage.out, t_f)


@jit.kernel
def step_end_bodies(body, pose, twist, co, h):
    """From the solved force point U_f: A_(n+1) = (U_f - Uk) / ((1 - af) beta h^2), W_(n+1) = W_n + h ((1 - gam) A_n
    + gam A_(n+1)), r_(n+1) = r_n + (r_f - r_n) / (1 - af), q_(n+1) = exp(phi_f / (1 - af)) q_n (kept in
    ``turned``)."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    scale = 1.0 / ((1.0 - af) * beta * h * h)
    stage = body.stage
    for b in range(pose.shape[1]):
        for d in range(6):
            u = stage.r[d, b] if d < 3 else stage.phi[d - 3, b]
            a1 = (u - body.known[d, b]) * scale
            twist[d, b] += h * ((1.0 - gam) * body.acc[d, b] + gam * a1)
            body.acc[d, b] = a1
        for d in range(3):
            pose[d, b] += (stage.r[d, b] - pose[d, b]) / (1.0 - af)
            body.turned[d, b] = stage.phi[d, b] / (1.0 - af)
        turn(pose[3:7], b, body.turned[0, b], body.turned[1, b], body.turned[2, b])


@jit.kernel
def raw_error_bodies(body, X, acc, co, h, t_f, params, groups, rhs):
    """M e of the bodies (their mass matrices at the force point, times e = h^2 |beta - 1/6 + (am - af) / 2|
    (A_(n+1) - A_n)) into the groups' ``own_rhs``; their attachments' rows of ``rhs`` zeroed (the filter's solve
    puts the body's error there)."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    weight = h * h * abs(beta - 1.0 / 6.0 + 0.5 * (am - af))
    scale = 1.0 / ((1.0 - af) * beta * h * h)
    stage = body.stage
    bodies = params.bodies
    work, keep = stage.work, stage.keep
    k = keep.shape[0]
    dim = X.shape[0]
    g = params.gravity[0] if WITH_GRAVITY else 0.0
    for b in range(body.reach.shape[0]):
        body_own_system(work, g, params.flow, bodies, stage.pose, stage.twist, b, t_f, 0.0)
        body_attachments_system(work, X, acc, params.inv_mass, params.neighbours, bodies, stage.pose, stage.twist, b)
        for d in range(6):
            u = stage.r[d, b] if d < 3 else stage.phi[d - 3, b]
            stage.out[d, b] = weight * ((u - body.known[d, b]) * scale - body.acc[d, b])
        at = stage.where[1] + b * k
        for a in range(k):
            s = 0.0
            for c in range(k):
                s += work[keep[a], keep[c]] * stage.out[keep[c], b]
            groups.own_rhs[at + a] = s
        for c in range(bodies.index[bodies.links.shape[0] + b], bodies.index[bodies.links.shape[0] + b + 1]):
            i = bodies.index[c]
            for d in range(dim):
                rhs[i * dim + d] = 0.0


@jit.kernel
def error_ratio_bodies(body, groups, af, tol, rtol, share):
    """The bodies' filtered errors (the groups' ``du`` after the filter's solve) over their allowance: the largest
    ratio of |e_r| + reach |e_phi| to share (tol + rtol max |r|) over the bodies, and that error [m]."""
    stage = body.stage
    keep = stage.keep
    k = keep.shape[0]
    worst, worst_error = 0.0, 0.0
    for b in range(body.reach.shape[0]):
        moved2, turned2 = 0.0, 0.0
        for a in range(k):
            e = groups.du[stage.where[1] + b * k + a]
            if keep[a] < 3:
                moved2 += e * e
            else:
                turned2 += e * e
        e = math.sqrt(moved2) + body.reach[b] * math.sqrt(turned2)
        size = 0.0
        for d in range(3):
            end = stage.base[d, b] + (stage.r[d, b] - stage.base[d, b]) / (1.0 - af)
            size = max(size, abs(stage.base[d, b]), abs(end))
        ratio = e / (share * (tol + rtol * size))
        if ratio > worst:
            worst, worst_error = ratio, e
    return worst, worst_error


@jit.kernel
def keep_step_start_bodies(body):
    """The accepted step's start: (pose0, twist0) <- (pose1, twist1), before the step's end moves the latter."""
    for b in range(body.pose1.shape[1]):
        for d in range(7):
            body.pose0[d, b] = body.pose1[d, b]
        for d in range(6):
            body.twist0[d, b] = body.twist1[d, b]


@jit.kernel
def dense_output_bodies(body, clock0, clock1, t, pose, twist):
    """The bodies' pose and twist at time t in the last step [clock0, clock1]: r by the cubic Hermite interpolant
    of (r, v) at its ends, q = exp(phi(t)) q0 with phi the Hermite interpolant of (0, w0) and (phi_1, w1), and
    their derivatives."""
    span = clock1 - clock0
    th = (t - clock0) / span if span > 0.0 else 1.0
    t2 = th * th
    t3 = t2 * th
    h00, h10, h01, h11 = 2.0 * t3 - 3.0 * t2 + 1.0, t3 - 2.0 * t2 + th, 3.0 * t2 - 2.0 * t3, t3 - t2
    d00, d10, d01, d11 = 6.0 * t2 - 6.0 * th, 3.0 * t2 - 4.0 * th + 1.0, 6.0 * th - 6.0 * t2, 3.0 * t2 - 2.0 * th
    p0, w0, p1, w1 = body.pose0, body.twist0, body.pose1, body.twist1
    for b in range(pose.shape[1]):
        for d in range(3):
            pose[d, b] = h00 * p0[d, b] + h10 * span * w0[d, b] + h01 * p1[d, b] + h11 * span * w1[d, b]
            if span > 0.0:
                twist[d, b] = (d00 * p0[d, b] + d01 * p1[d, b]) / span + d10 * w0[d, b] + d11 * w1[d, b]
                twist[3 + d, b] = d01 * body.turned[d, b] / span + d10 * w0[3 + d, b] + d11 * w1[3 + d, b]
            else:
                twist[d, b] = w1[d, b]
                twist[3 + d, b] = w1[3 + d, b]
        for d in range(4):
            pose[3 + d, b] = p0[3 + d, b]
        phi0 = h10 * span * w0[3, b] + h01 * body.turned[0, b] + h11 * span * w1[3, b]
        phi1 = h10 * span * w0[4, b] + h01 * body.turned[1, b] + h11 * span * w1[4, b]
        phi2 = h10 * span * w0[5, b] + h01 * body.turned[2, b] + h11 * span * w1[5, b]
        turn(pose[3:7], b, phi0, phi1, phi2)
