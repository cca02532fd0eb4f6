"""Free rigid bodies in the stiff integrator's Newton solve (:mod:`ropesim.integrate.sdirk`).

A body's stage unknowns are its reference point r and a rotation vector phi from its orientation at the step's
start, q = exp(phi) q_n (so q is a unit quaternion to round-off whatever the Newton iterates do); its stage
twist W = (v, w) follows from them as the nodes' velocities do from their positions, W = (U - U_hat) / beta,
U = (r, phi). SDIRK2 is applied to (U, W) as to (x, v), with U' = W: the Runge-Kutta-Munthe-Kaas method with
dexp^-1_phi truncated to the identity, which keeps the order of a method of order 2 (its error, phi x w / 2 with
phi = t w + O(t^2), enters the step at O(h^3)). The body's line ends (its attachments) sit where the stage pose
puts them and move at v + w x rho (:func:`place_stage`).

The body's equation at a stage is its Newton-Euler equations (:mod:`ropesim.model.bodies`) in the nodes' form,

    R_b = -beta [M (W - W_hat) - beta F],

M its 6 x 6 mass matrix about the reference point (its own mass, inertia and added mass, its attachments' masses
and added masses at their arms) and F the right-hand side of ``move_bodies`` (its own forces and moments, its
attachments' forces, less the centripetal forces and the gyroscopic moment). It is the group's own residual in
the Schur complement (:mod:`ropesim.model.schur`); its attachments' rows hold nothing of their own (their
forces are in F). The Newton matrix's group block is then G^T J G over the attachments (the band: their masses,
the springs' stiffness beta^2 K and damping beta C at them, coupled to their lines through B) plus the body's own
block (:func:`stage_rows`):

    O = M - sum_c m_c G_c^T G_c (the plain masses the band already holds) + beta^2 (K_phi + K_s) + beta D,

K_phi = -sum [F]x [p]x the rotational geometric stiffness of the forces that turn with the body (its weight at
its centre of gravity, its buoyancy at its centre of buoyancy, each attachment's force at its arm; see
:mod:`ropesim.model.body_groups`), and D = -dF/dW: the gyroscopic moment's [w]x I - [I w]x, the centripetal
forces' -M_p ([w x p]x + [w]x [p]x) at each mass's arm p, and the drag's and rotational drag's
R diag(d) (|u| I + u u^T / |u|) R^T and a free body's linear damper diag(c) on its translation; K_s = diag(k)
its linear spring's. Under a sea (:mod:`ropesim.model.body_sea`) the drag's rate is the water's share f on the
velocity relative to the water plus the air's on the velocity relative to the wind, and K_s takes the
waterplane's heave stiffness rho g A_wp while the surface cuts the body's walls. Left out: the dependence of the centripetal and drag terms on the orientation
(O(beta^2 w^2)), which only slows Newton's convergence, never changes its solution.

Stored in :class:`BodyStage`; everything here runs behind the bodies switch.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..model import jit
from ..model.bodies import _add_mass_at, body_attachments_system, body_own_system, place_attachments
from ..model.body_groups import body_unknowns, kept_rows, set_body_arms
from ..model.body_layout import ADDED_N, ADDED_T, COB, COG, DAMPER, DRAG, DRAG_ROT, INERTIA, LIFT, MASS, SPRING
from ..model.body_sea import WITH_BODY_SEA, sea_rates
from ..model.forces.fluid import WITH_FLOW, flow_at, node_tangent
from ..model.forces.gravity import WITH_GRAVITY
from ..model.rotation import cross, matrix_of, rotate, rotate_back, turn

BodyStage = namedtuple("BodyStage", ["base", "pose", "twist", "hat_r", "hat_phi", "hat_w", "r", "phi", "step",
                                     "work", "own", "inertia", "out", "keep", "where"])
"""A stage's body state (B free bodies): base (7, B) the poses at the step's start; pose (7, B) and twist (6, B)
the stage's; hat_r, hat_phi (3, B) and hat_w (6, B) the stage's known parts; r, phi (3, B) its unknowns; step
(6, B) the last Newton update; scratch work (6, 7), own (6, 6), inertia (3, 3), out (6, B); keep (k,) int64 the
rows a scene's dimension keeps (:func:`~ropesim.model.body_groups.kept_rows`); where (2,) int64 the first body
member and the first body unknown in the groups."""


def body_stage(model, groups) -> BodyStage:
    """The scratch of the free bodies' stages for ``model`` with its Schur ``groups`` (bodies last)."""
    count = model.body_pose0.shape[1]
    k = body_unknowns(model.dim)
    bundle = model.params.bodies
    where = np.array([groups.nodes.size - bundle.nodes.size, int(groups.offset[-1]) - count * k], dtype=np.int64)
    three, six = (lambda: np.zeros((3, count))), (lambda: np.zeros((6, count)))
    return BodyStage(model.body_pose0.copy(), model.body_pose0.copy(), six(), three(), three(), six(), three(),
                     three(), six(), np.zeros((6, 7)), np.zeros((6, 6)), np.zeros((3, 3)), six(),
                     kept_rows(model.dim).astype(np.int64), where)


@jit.kernel
def start_step(body, pose, twist):
    """The step's first stage: U_hat = (r_n, 0), W_hat = w_n, from the state ``pose``, ``twist``."""
    for b in range(pose.shape[1]):
        for d in range(7):
            body.base[d, b] = pose[d, b]
        for d in range(3):
            body.hat_r[d, b] = pose[d, b]
            body.hat_phi[d, b] = 0.0
        for d in range(6):
            body.hat_w[d, b] = twist[d, b]


@jit.kernel
def next_stage(body, twist, h, gamma):
    """The second stage's known part from the first's W: U_hat = U_n + (1 - gamma) h W, W_hat = w_n + (1 - gamma) /
    gamma (W - w_n) (as the nodes')."""
    ratio = (1.0 - gamma) / gamma
    for b in range(twist.shape[1]):
        for d in range(3):
            body.hat_r[d, b] = body.base[d, b] + (1.0 - gamma) * h * body.twist[d, b]
            body.hat_phi[d, b] = (1.0 - gamma) * h * body.twist[3 + d, b]
        for d in range(6):
            body.hat_w[d, b] = twist[d, b] + ratio * (body.twist[d, b] - twist[d, b])


@jit.kernel
def guess_stage(body, beta):
    """The Newton iteration's start: U = U_hat + beta W_hat."""
    for b in range(body.r.shape[1]):
        for d in range(3):
            body.r[d, b] = body.hat_r[d, b] + beta * body.hat_w[d, b]
            body.phi[d, b] = body.hat_phi[d, b] + beta * body.hat_w[3 + d, b]


@jit.kernel
def place_stage(body, X, V, beta, bodies, arm):
    """The stage's pose (r, exp(phi) q_n) and twist ((U - U_hat) / beta), its attachments in ``X`` and ``V`` where
    it holds them and their arms into the groups' ``arm``."""
    for b in range(body.r.shape[1]):
        for d in range(3):
            body.pose[d, b] = body.r[d, b]
            body.twist[d, b] = (body.r[d, b] - body.hat_r[d, b]) / beta
            body.twist[3 + d, b] = (body.phi[d, b] - body.hat_phi[d, b]) / beta
        for d in range(4):
            body.pose[3 + d, b] = body.base[3 + d, b]
        turn(body.pose[3:7], b, body.phi[0, b], body.phi[1, b], body.phi[2, b])
    place_attachments(X, V, bodies, body.pose, body.twist)
    set_body_arms(arm, body.where[0], bodies, body.pose)


@jit.kernel
def _add_centripetal(own, m00, m01, m02, m11, m12, m22, p0, p1, p2, w0, w1, w2, scale):
    """Add scale times -d/dw of a mass M's centripetal force -M w x (w x p) at arm p, and of its moment, to
    ``own``'s rotation columns: f = -M ([w x p]x + [w]x [p]x) into the force rows, p x f into the moment rows
    ([w]x [p]x = p w^T - (w . p) I)."""
    e0, e1, e2 = cross(w0, w1, w2, p0, p1, p2)
    wp = w0 * p0 + w1 * p1 + w2 * p2
    mm = ((m00, m01, m02), (m01, m11, m12), (m02, m12, m22))
    ex = ((0.0, -e2, e1), (e2, 0.0, -e0), (-e1, e0, 0.0))
    p = (p0, p1, p2)
    w = (w0, w1, w2)
    for j in range(3):
        d0 = ex[0][j] + p[0] * w[j] - (wp if j == 0 else 0.0)
        d1 = ex[1][j] + p[1] * w[j] - (wp if j == 1 else 0.0)
        d2 = ex[2][j] + p[2] * w[j] - (wp if j == 2 else 0.0)
        f0 = -(mm[0][0] * d0 + mm[0][1] * d1 + mm[0][2] * d2)
        f1 = -(mm[1][0] * d0 + mm[1][1] * d1 + mm[1][2] * d2)
        f2 = -(mm[2][0] * d0 + mm[2][1] * d1 + mm[2][2] * d2)
        own[0, 3 + j] += scale * f0
        own[1, 3 + j] += scale * f1
        own[2, 3 + j] += scale * f2
        t0, t1, t2 = cross(p0, p1, p2, f0, f1, f2)
        own[3, 3 + j] += scale * t0
        own[4, 3 + j] += scale * t1
        own[5, 3 + j] += scale * t2


@jit.kernel
def _add_turning_force(own, f0, f1, f2, p0, p1, p2, scale):
    """Add scale times K_phi = (F . p) I - p F^T of a force F at arm p that turns with the body (rotation block)."""
    fp = f0 * p0 + f1 * p1 + f2 * p2
    f = (f0, f1, f2)
    p = (p0, p1, p2)
    for i in range(3):
        for j in range(3):
            own[3 + i, 3 + j] += scale * ((fp if i == j else 0.0) - p[i] * f[j])


@jit.kernel(literal_integers=False)
def _add_drag_rate(own, row, r, d0, d1, d2, u0, u1, u2, scale):
    """Add scale times R diag(d) (|u| I + u u^T / |u|) R^T (u in body axes) to the 3 x 3 block at (row, row)."""
    speed = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    if speed == 0.0:
        return
    u = (u0, u1, u2)
    dd = (d0, d1, d2)
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                for l in range(3):
                    body = dd[k] * ((speed if k == l else 0.0) + u[k] * u[l] / speed)
                    s += r[3 * i + k] * body * r[3 * j + l]
            own[row + i, row + j] += scale * s


@jit.kernel
def stage_rows(body, X, acc, beta, damp, t, p, groups, rhs):
    """Every body's stage residual R_b = -beta [M (W - W_hat) - damp F] into the groups' ``own_rhs`` and its own
    block O (the module doc's, with beta^2 -> beta damp on the stiffness and beta -> damp on the damping) into
    ``own``, from ``acc`` holding every node's F / m at the stage; its attachments' rows of ``rhs`` zeroed.
    SDIRK2 passes damp = beta; generalized-alpha its own pair (:mod:`ropesim.integrate.galpha_bodies`). Returns
    the squared norm of the bodies' residuals."""
    dim = X.shape[0]
    bodies = p.bodies
    g = p.gravity[0] if WITH_GRAVITY else 0.0
    work, own, inertia, keep = body.work, body.own, body.inertia, body.keep
    k = keep.shape[0]
    first = body.where[1]
    attached = bodies.links.shape[0]   # bodies.index[attached + b]: body b's first attachment
    norm = 0.0
    for b in range(body.r.shape[1]):
        pose, twist = body.pose, body.twist
        body_own_system(work, g, p.flow, bodies, pose, twist, b, t, 0.0)
        body_attachments_system(work, X, acc, p.inv_mass, p.neighbours, bodies, pose, twist, b)
        r = matrix_of(pose[3:7], b)
        w0, w1, w2 = twist[3, b], twist[4, b], twist[5, b]
        for i in range(6):
            s = 0.0
            for j in range(6):
                s += work[i, j] * (twist[j, b] - body.hat_w[j, b])
                own[i, j] = work[i, j]
            work[i, 6] = -beta * (s - damp * work[i, 6])
        # the plain attachment masses the band holds; the turning forces; the centripetal and drag rates
        record = bodies.table[b]
        m = record[MASS]
        c0, c1, c2 = rotate(r, record[COG], record[COG + 1], record[COG + 2])
        _add_turning_force(own, 0.0, -m * g, 0.0, c0, c1, c2, beta * damp)
        _add_centripetal(own, m, 0.0, 0.0, m, 0.0, m, c0, c1, c2, w0, w1, w2, damp)
        lift = record[LIFT]
        if lift != 0.0:
            k0, k1, k2 = rotate(r, record[COB], record[COB + 1], record[COB + 2])
            _add_turning_force(own, 0.0, lift, 0.0, k0, k1, k2, beta * damp)
        for c in range(bodies.index[attached + b], bodies.index[attached + b + 1]):
            i = bodies.index[c]
            mi = 1.0 / p.inv_mass[i]
            p0 = groups.arm[0, body.where[0] + c]
            p1 = groups.arm[1, body.where[0] + c]
            p2 = groups.arm[2, body.where[0] + c]
            _add_mass_at(own, -mi, 0.0, 0.0, -mi, 0.0, -mi, p0, p1, p2)
            a2 = acc[2, i] if dim == 3 else 0.0
            _add_turning_force(own, mi * acc[0, i], mi * acc[1, i], mi * a2, p0, p1, p2, beta * damp)
            a_n, a_t = bodies.links[c, ADDED_N], bodies.links[c, ADDED_T]
            q0, q1, q2 = node_tangent(X, i, p.neighbours)
            extra = a_t - a_n
            _add_centripetal(own, mi + a_n + extra * q0 * q0, extra * q0 * q1, extra * q0 * q2,
                             mi + a_n + extra * q1 * q1, extra * q1 * q2, mi + a_n + extra * q2 * q2,
                             p0, p1, p2, w0, w1, w2, damp)
        # the gyroscopic moment: [w]x I - [I w]x, I = R I_b R^T
        for i in range(3):
            for j in range(3):
                s = 0.0
                for a in range(3):
                    for c in range(3):
                        s += r[3 * i + a] * record[INERTIA + 3 * a + c] * r[3 * j + c]
                inertia[i, j] = s
        i0 = inertia[0, 0] * w0 + inertia[0, 1] * w1 + inertia[0, 2] * w2
        i1 = inertia[1, 0] * w0 + inertia[1, 1] * w1 + inertia[1, 2] * w2
        i2 = inertia[2, 0] * w0 + inertia[2, 1] * w1 + inertia[2, 2] * w2
        for j in range(3):
            e0, e1, e2 = cross(w0, w1, w2, inertia[0, j], inertia[1, j], inertia[2, j])
            own[3, 3 + j] += damp * e0
            own[4, 3 + j] += damp * e1
            own[5, 3 + j] += damp * e2
        own[3, 4] += damp * i2     # - [I w]x
        own[3, 5] -= damp * i1
        own[4, 3] -= damp * i2
        own[4, 5] += damp * i0
        own[5, 3] += damp * i1
        own[5, 4] -= damp * i0
        # drag on the flow relative to the reference point, and the rotational drag
        if WITH_BODY_SEA:   # under a sea: the water's share and the air's, and the waterplane's heave stiffness
            heave, wet, dry, u0, u1, u2, air0, air1, air2 = sea_rates(p.flow, bodies, pose, twist, b, t, r)
            own[1, 1] += beta * damp * heave
            ub = rotate_back(r, u0, u1, u2)
            _add_drag_rate(own, 0, r, record[DRAG], record[DRAG + 1], record[DRAG + 2], ub[0], ub[1], ub[2],
                           damp * wet)
            ub = rotate_back(r, air0, air1, air2)
            _add_drag_rate(own, 0, r, record[DRAG], record[DRAG + 1], record[DRAG + 2], ub[0], ub[1], ub[2],
                           damp * dry)
            wb = rotate_back(r, w0, w1, w2)
            _add_drag_rate(own, 3, r, record[DRAG_ROT], record[DRAG_ROT + 1], record[DRAG_ROT + 2], wb[0], wb[1],
                           wb[2], damp * (wet + dry))
        else:
            u0, u1, u2 = -twist[0, b], -twist[1, b], -twist[2, b]
            if WITH_FLOW:
                U0, U1, U2 = flow_at(pose[1, b], t, p.flow[0], p.flow[1])
                u0 += U0
                u1 += U1
                u2 += U2
            ub = rotate_back(r, u0, u1, u2)
            _add_drag_rate(own, 0, r, record[DRAG], record[DRAG + 1], record[DRAG + 2], ub[0], ub[1], ub[2], damp)
            wb = rotate_back(r, w0, w1, w2)
            _add_drag_rate(own, 3, r, record[DRAG_ROT], record[DRAG_ROT + 1], record[DRAG_ROT + 2], wb[0], wb[1],
                           wb[2], damp)
        # the linear spring and damper on the reference point: beta^2 k + beta c on its translation
        for a in range(3):
            if record[SPRING + a] != 0.0 or record[DAMPER + a] != 0.0:
                own[a, a] += beta * damp * record[SPRING + a] + damp * record[DAMPER + a]
        at = first + b * k
        for a in range(k):
            groups.own_rhs[at + a] = work[keep[a], 6]
            norm += work[keep[a], 6] * work[keep[a], 6]
            for c in range(k):
                groups.own[at + a, at + c] = own[keep[a], keep[c]]
        for c in range(bodies.index[attached + b], bodies.index[attached + b + 1]):
            i = bodies.index[c]
            for d in range(dim):
                rhs[i * dim + d] = 0.0
    return norm


@jit.kernel
def take_body_update(body, groups):
    """U += the bodies' Newton update (the groups' du), kept in ``step``. Returns its largest translation [m]."""
    keep = body.keep
    k = keep.shape[0]
    first = body.where[1]
    worst = 0.0
    for b in range(body.r.shape[1]):
        for d in range(6):
            body.step[d, b] = 0.0
        for a in range(k):
            body.step[keep[a], b] = groups.du[first + b * k + a]
        for d in range(3):
            body.r[d, b] += body.step[d, b]
            body.phi[d, b] += body.step[3 + d, b]
            if not abs(body.step[d, b]) <= worst:
                worst = abs(body.step[d, b])
    return worst


@jit.kernel
def take_back_half_bodies(body):
    """Halve the bodies' last update and take that half back."""
    for b in range(body.r.shape[1]):
        for d in range(3):
            body.step[d, b] *= 0.5
            body.step[3 + d, b] *= 0.5
            body.r[d, b] -= body.step[d, b]
            body.phi[d, b] -= body.step[3 + d, b]


@jit.kernel
def end_step_bodies(body, pose, twist):
    """The step's end (stiffly accurate): the state takes the last stage's pose and twist."""
    for b in range(pose.shape[1]):
        for d in range(7):
            pose[d, b] = body.pose[d, b]
        for d in range(6):
            twist[d, b] = body.twist[d, b]
