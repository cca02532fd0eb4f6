"""Free rigid bodies: a spar, a buoy, a container moving in 6 degrees of freedom (3 in 2-D) under its lines.

State, per free body b (world frame, SI units): ``pose`` (7, B) its reference point r (3) and orientation q (4, a
unit quaternion, body frame to world, :mod:`ropesim.model.rotation`); ``twist`` (6, B) the velocity of the
reference point v and the angular velocity w, in world axes. Not nodes: the integrators carry it beside x and v.

Line ends on a body's points (its *attachments*) are line nodes slaved to the body: node i at arm s_i (body
frame) sits at x_i = r + R s_i and moves at v_i = v + w x rho_i, rho_i = R s_i (:func:`place_attachments`, called
whenever the body's state changes). The forces of every term on an attachment node (F_i = m_i acc_i, its springs,
weight, drag, ...) act on the body, and the node's mass m_i and added mass A_i (its line's, along the node's
tangent) join the body's; so the node keeps its line's lumping, and the body takes what the node carries, as
MoorDyn's body takes its points' net forces and masses (``Point::getNetForceAndMass``).

Newton-Euler about the reference point, in world axes, with a and alpha the reference point's and the body's
accelerations (:func:`move_bodies`):

    sum over masses mu (the body's own m at its centre of gravity c = R c_b, each attachment's m_i I + A_i at rho_i):
        mu a - mu [rho]x alpha                = F_rho - mu w x (w x rho)
        [rho]x mu a - [rho]x mu [rho]x alpha  = rho x (F_rho - mu w x (w x rho))
    plus the body's inertia about its centre of gravity I = R I_b R^T: I alpha + w x (I w) on the moment's side,
    and its own added mass A_t = R diag(a_b) R^T (on a) and added inertia A_r = R diag(j_b) R^T (on alpha).

The body's own forces: its weight -m g y at c; buoyancy rho V g y at its centre of buoyancy R c_B; drag on the
velocity u = U(r) - v of the flow relative to the reference point, F = 1/2 rho R diag(CdA) R^T u |u|, and the
rotational drag moment -1/2 rho R diag(Cd_r) R^T w |w| (MoorDyn's body drag, ``Body::doRHS``). Under a ``[sea]``
:mod:`ropesim.model.body_sea` takes the drag's place: the buoyancy lost above the surface, the water's drag on
the wet part (on the waves' velocity too) and the air's on the dry part, and the water's inertia force. The added mass
acts on the accelerations alone: the velocity-dependent forces of potential flow on a body (the Munk moment) are
left out, as MoorDyn leaves them out. The 6 x 6 matrix is symmetric positive definite (a body's own mass or inertia
may be zero when its attachments carry it); in 2-D the body moves in x, y and turns about z, and the solve keeps
those three degrees of freedom.

The explicit methods solve these equations in the body's axes (:func:`move_bodies`), where the matrix is constant
(its own mass, inertia and added mass, and each attachment's isotropic m_i + a_n at its fixed arm s_i) but for the
attachments' added mass along their lines, (a_t - a_n) q q^T at s_i: a rank-one term u u^T, u = (q, s_i x q), q the
line's tangent in body axes. The constant part is inverted once when the model is built; a body whose
lines have a_t != a_n adds its rank-one terms and factors its 6 x 6 per evaluation (a few hundred flops). Only the
right-hand side is rotated in and the accelerations out. The stiff integrator's Newton solve and the static solver
assemble the same equations in world axes (:func:`body_own_system`, :func:`body_attachments_system`).

The power of the fluid's forces on the body (drag, and the added mass's inertial force -A a) is booked as fluid
work, as for a node. Gravity and buoyancy are conservative: the body's mechanical energy is
1/2 m |v + w x c|^2 + 1/2 w . I w + m g (r + c)_y - rho V g (r + R c_B)_y (:func:`body_energy`).

Parameters, :class:`~ropesim.model.body_layout.Bodies` (B free bodies, K attachments), packed into four arrays so
that a compiled call carries few (:mod:`ropesim.model.body_layout` names the columns): per body a record in
``table`` (B, BODY_COLUMNS) with its mass [kg], rho V g [N], centre of gravity and of buoyancy in the body frame
[m], 1/2 rho CdA [kg/m], 1/2 rho Cd_r [kg m^2], added mass [kg] and inertia [kg m^2] on the body axes, its spring,
damper and rest point, and its inertia (3 x 3) about the centre of gravity in body axes [kg m^2]; per attachment a
record in ``links`` (K, LINK_COLUMNS) with its arm (body frame) [m], its line's added-mass coefficients a_n, a_t
[kg] (the per-node added-mass pass leaves them to this one), its node's mass [kg] and, as scratch, its chord d
along its line in body axes (the tangent q = d / |d|) and (a_t - a_n) / |d|^2; ``matrices`` (B, 3, 6, 7) each
body's constant mass matrix in body axes, its inverse, and its solve's scratch, on the kept rows (6 in 3-D; x, y
and the turn about z in 2-D); ``index`` the attachments' nodes, then each body's first attachment. A body
*varies* when its attachments have a_t != a_n.
"""

from __future__ import annotations

import math

import numpy as np

from . import jit
from .body_layout import (ADDED, ADDED_N, ADDED_ROT, ADDED_T, ARM, BODY_COLUMNS, CHORD, CHORD_SCALE, COB, COG,
                          CONSTANT, DAMPER, DRAG, DRAG_ROT, INERTIA, INVERSE, LIFT, LINK_COLUMNS, MASS, NODE_MASS,
                          REST, SCRATCH, SPRING, VARIES, Bodies)
from .body_sea import WITH_BODY_SEA, sea_loads
from .forces.added_mass import WITH_ADDED_MASS
from .forces.fluid import WITH_FLOW, flow_at, node_tangent
from ..scene.schema import STILL_KINDS
from .rotation import cross, matrix_of, quaternion_from_angles, rotate, rotate_back, turn

WITH_BODIES = jit.Switch("bodies", "free rigid bodies")

POSE, TWIST = 7, 6   # rows of the pose (r, q) and twist (v, w) arrays
STATE_ROWS = POSE + TWIST   # a saved frame's rows per body


def free_bodies(scene) -> tuple:
    """The scene's free rigid bodies, in scene order (fixed and driven bodies hold their points instead)."""
    return tuple(b for b in scene.rigid_bodies if b.kind == "free")


def body_of_points(scene) -> dict[str, str]:
    """Each point on a rigid body: point id -> body id."""
    return {p.id: p.body for p in scene.points if p.kind == "body"}


def attachments(scene, ends: dict[str, list[int]]) -> dict[str, list[tuple[int, np.ndarray]]]:
    """Each rigid body's line end nodes and their arms in the body frame (3,) [m], by body id, from the line ends
    on each point (:func:`ropesim.model.layout.point_ends`)."""
    out: dict[str, list] = {b.id: [] for b in scene.rigid_bodies}
    for point in scene.points:
        if point.kind == "body":
            arm = np.zeros(3)
            arm[:scene.dimension] = point.position
            out[point.body].extend((node, arm) for node in ends[point.id])
    return out


def vector3(values, dim: int) -> np.ndarray:
    """A scene vector (dim,) as (3,) (0 along z in 2-D)."""
    out = np.zeros(3)
    out[:dim] = values
    return out


def turns3(values, dim: int) -> np.ndarray:
    """A scene's per-rotation-axis values (3 in 3-D, about z alone in 2-D) as (3,)."""
    out = np.zeros(3)
    if dim == 2:
        out[2] = values[0]
    else:
        out[:] = values
    return out


def inertia_tensor(values, dim: int) -> np.ndarray:
    """The inertia (3, 3) [kg m^2] of a scene's moments: Ixx Iyy Izz [Ixy Ixz Iyz] in 3-D, Izz in 2-D (whose x and
    y moments, which a planar motion never uses, are set to Izz to keep the tensor invertible)."""
    if dim == 2:
        return np.eye(3) * values[0]
    ixx, iyy, izz = values[:3]
    ixy, ixz, iyz = values[3:] if len(values) == 6 else (0.0, 0.0, 0.0)
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def initial_pose(body, dim: int) -> np.ndarray:
    """A body's pose (7,) at t = 0: its reference point and orientation."""
    return np.concatenate([vector3(body.position, dim), quaternion_from_angles(body.orientation, dim)])


def bodies_bundle(scene, ends: dict[str, list[int]], added: np.ndarray, node_mass: np.ndarray) -> Bodies:
    """The compiled description of the scene's free bodies (see the module doc), their attachments' masses from
    ``node_mass`` (N,) [kg]; their attachments' added-mass coefficients are taken out of ``added`` (2, N), which the
    per-node pass then skips."""
    dim = scene.dimension
    bodies = free_bodies(scene)
    rho = scene.fluid.density if scene.fluid is not None else 0.0
    g = scene.gravity.g if scene.gravity is not None else 0.0
    count = len(bodies)
    on_body = attachments(scene, ends)
    table = np.zeros((count, BODY_COLUMNS))
    nodes, arms, start = [], [], [0]
    for b, body in enumerate(bodies):
        record = table[b]
        record[MASS] = body.mass
        record[LIFT] = rho * body.volume * g
        record[INERTIA:INERTIA + 9] = inertia_tensor(body.inertia, dim).ravel()
        for column, values in ((COG, vector3(body.center_of_gravity, dim)),
                               (COB, vector3(body.center_of_buoyancy, dim)),
                               (DRAG, 0.5 * rho * vector3(body.cd_area, dim)),
                               (DRAG_ROT, 0.5 * rho * turns3(body.cd_rotation, dim)),
                               (ADDED, vector3(body.added_mass, dim)), (ADDED_ROT, turns3(body.added_inertia, dim)),
                               (SPRING, vector3(body.stiffness or (0.0,) * dim, dim)),
                               (DAMPER, vector3(body.damping or (0.0,) * dim, dim)),
                               (REST, vector3(body.position, dim))):
            record[column:column + 3] = values
        for node, arm in on_body[body.id]:
            nodes.append(node)
            arms.append(arm)
        start.append(len(nodes))
    node_index = np.array(nodes, dtype=np.int64)
    links = np.zeros((len(nodes), LINK_COLUMNS))
    if arms:
        links[:, ARM:ARM + 3] = arms
    if added.size and len(nodes):
        links[:, ADDED_N:ADDED_N + 2] = added[:, node_index].T
        added[:, node_index] = 0.0
    links[:, NODE_MASS] = 1.0 / (1.0 / node_mass[node_index])   # as the compiled code has m from 1 / m
    bundle = Bodies(table, links, np.zeros((count, 3, 6, 7)), np.concatenate([node_index, start]).astype(np.int64))
    rows = np.arange(6) if dim == 3 else np.array([0, 1, 5])
    n = len(rows)
    for b in range(count):
        k0, k1 = start[b], start[b + 1]
        own = constant_mass(table[b, MASS], bundle.cog[:, b], bundle.inertia[:, :, b], bundle.added[:, b],
                            bundle.added_rot[:, b], node_mass[node_index[k0:k1]] + links[k0:k1, ADDED_N],
                            links[k0:k1, ARM:ARM + 3].T)
        bundle.matrices[b, CONSTANT, :n, :n] = own[np.ix_(rows, rows)]
        bundle.matrices[b, INVERSE, :n, :n] = np.linalg.inv(own[np.ix_(rows, rows)])
        table[b, VARIES] = float(np.any(links[k0:k1, ADDED_T] != links[k0:k1, ADDED_N]))
    return bundle


def mass_at(mass: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The 6 x 6 mass matrix about the reference point of a 3 x 3 mass matrix at arm p [m]:
    [[M, -M [p]x], [[p]x M, -[p]x M [p]x]]."""
    px = np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])
    return np.block([[mass, -mass @ px], [px @ mass, -px @ mass @ px]])


def constant_mass(m, cog, inertia, added, added_rot, masses, arms) -> np.ndarray:
    """A body's mass matrix (6, 6) about its reference point in its own axes, all of it that is constant there:
    its mass m [kg] at its centre of gravity ``cog`` (3,) [m], its inertia (3, 3) [kg m^2], added mass and added
    inertia (3,) on its axes, and its attachments' isotropic masses (K,) [kg] (each node's m_i + a_n) at ``arms``
    (3, K) [m]. What is left is each attachment's (a_t - a_n) q q^T along its line's tangent q."""
    out = mass_at(m * np.eye(3), cog)
    out[3:, 3:] += inertia
    out += np.diag(np.concatenate([added, added_rot]))
    for mk, arm in zip(masses, arms.T):
        out += mass_at(mk * np.eye(3), arm)
    return out


def no_bodies() -> None:
    """What a scene without free bodies has in their place: None, so that the parameter bundle every compiled
    function receives (by value, each array in it reference-counted at every call) carries nothing of bodies and
    compiles nothing of them (its fields are read only behind :data:`WITH_BODIES`)."""
    return None


def body_energy_numpy(bundle: Bodies, pose: np.ndarray, twist: np.ndarray, g: float) -> dict[str, np.ndarray]:
    """The free bodies' kinetic, gravitational and buoyancy energy [J] for poses (..., 7, B) and twists
    (..., 6, B), as :func:`body_energy` computes it compiled (see the module doc)."""
    from .rotation import rotation_matrix

    pose, twist = np.asarray(pose), np.asarray(twist)
    rot = rotation_matrix(np.moveaxis(pose[..., 3:7, :], -2, -1))            # (..., B, 3, 3)
    c = np.einsum("...bij,jb->...bi", rot, bundle.cog)
    cb = np.einsum("...bij,jb->...bi", rot, bundle.cob)
    w = np.moveaxis(twist[..., 3:6, :], -2, -1)                               # (..., B, 3)
    v_g = np.moveaxis(twist[..., 0:3, :], -2, -1) + np.cross(w, c)
    inertia = np.einsum("...bij,jkb,...blk->...bil", rot, bundle.inertia, rot)
    kinetic = 0.5 * (bundle.mass * np.einsum("...bi,...bi->...b", v_g, v_g)
                     + np.einsum("...bi,...bij,...bj->...b", w, inertia, w))
    y = pose[..., 1, :]
    stretch = pose[..., 0:3, :] - bundle.rest
    out = {"body spring": 0.5 * (bundle.spring * stretch * stretch).sum(axis=(-2, -1))} if np.any(bundle.spring) else {}
    return {**out, "body kinetic": kinetic.sum(axis=-1),
            "body gravity": (bundle.mass * g * (y + c[..., 1])).sum(axis=-1),
            "body buoyancy": (-bundle.lift * (y + cb[..., 1])).sum(axis=-1)}


# ------------------------------------------------------------------------------------------ compiled


@jit.kernel
def place_attachments(x, v, bodies, pose, twist):
    """Put every attachment node where its body holds it: x_i = r + R s_i, v_i = v + w x R s_i."""
    dim = x.shape[0]
    links, index = bodies.links, bodies.index
    first = links.shape[0]   # index[first + b]: body b's first attachment
    for b in range(pose.shape[1]):
        r = matrix_of(pose[3:7], b)
        w0, w1, w2 = twist[3, b], twist[4, b], twist[5, b]
        for k in range(index[first + b], index[first + b + 1]):
            i = index[k]
            p0, p1, p2 = rotate(r, links[k, ARM], links[k, ARM + 1], links[k, ARM + 2])
            e0, e1, e2 = cross(w0, w1, w2, p0, p1, p2)
            x[0, i] = pose[0, b] + p0
            x[1, i] = pose[1, b] + p1
            v[0, i] = twist[0, b] + e0
            v[1, i] = twist[1, b] + e1
            if dim == 3:
                x[2, i] = pose[2, b] + p2
                v[2, i] = twist[2, b] + e2


@jit.kernel
def drift_bodies(pose, twist, c):
    """Move every body for a time c [s] at its current velocities: r += c v, q <- exp(c w) q (exact for a constant
    twist: the splitting schemes' drift)."""
    for b in range(pose.shape[1]):
        for d in range(3):
            pose[d, b] += c * twist[d, b]
        turn(pose[3:7], b, c * twist[3, b], c * twist[4, b], c * twist[5, b])


@jit.kernel(inline="always")
def _add_mass_at(work, m00, m01, m02, m11, m12, m22, p0, p1, p2):
    """Add a mass matrix M (symmetric, its six entries) sitting at arm p from the reference point to the 6 x 6
    matrix in ``work``: [[M, -M [p]x], [[p]x M, -[p]x M [p]x]]."""
    mm = ((m00, m01, m02), (m01, m11, m12), (m02, m12, m22))
    px = ((0.0, -p2, p1), (p2, 0.0, -p0), (-p1, p0, 0.0))
    for i in range(3):
        for j in range(3):
            work[i, j] += mm[i][j]
            mp = 0.0   # (M [p]x)[i, j]
            pm = 0.0   # ([p]x M)[i, j]
            for k in range(3):
                mp += mm[i][k] * px[k][j]
                pm += px[i][k] * mm[k][j]
            work[i, 3 + j] -= mp
            work[3 + i, j] += pm
    for i in range(3):
        for j in range(3):
            pmp = 0.0   # ([p]x M [p]x)[i, j]
            for k in range(3):
                pm = 0.0
                for l in range(3):
                    pm += px[i][l] * mm[l][k]
                pmp += pm * px[k][j]
            work[3 + i, 3 + j] -= pmp


@jit.kernel(inline="always")
def _add_rotated(work, row, col, r, d0, d1, d2):
    """Add R diag(d) R^T to the 3 x 3 block of ``work`` at (row, col); ``r`` R's nine entries."""
    for i in range(3):
        for j in range(3):
            work[row + i, col + j] += d0 * r[3 * i] * r[3 * j] + d1 * r[3 * i + 1] * r[3 * j + 1] + \
                d2 * r[3 * i + 2] * r[3 * j + 2]


@jit.kernel(inline="always")
def _ldl_factor(a, n):
    """A = L D L^T in place in a (n, n) symmetric positive definite matrix (its lower triangle read): L's strict
    lower part and D on the diagonal."""
    for j in range(n):
        d = a[j, j]
        for k in range(j):
            d -= a[j, k] * a[j, k] * a[k, k]
        a[j, j] = d
        inverse = 1.0 / d
        for i in range(j + 1, n):
            s = a[i, j]
            for k in range(j):
                s -= a[i, k] * a[j, k] * a[k, k]
            a[i, j] = s * inverse


@jit.kernel(inline="always")
def _varying_mass(work, constant, n, links, k0, k1):
    """A body's mass matrix in its axes into ``work``'s lower triangle: its constant part ``constant`` plus each
    attachment k0 <= k < k1's rank-one term c d d^T at its arm s, u = (d, s x d) on the n kept rows (``links``:
    the chords d and the factors c)."""
    for i in range(n):
        for j in range(i + 1):
            work[i, j] = constant[i, j]
    for k in range(k0, k1):
        c = links[k, CHORD_SCALE]
        if c != 0.0:
            d0, d1, d2 = links[k, CHORD], links[k, CHORD + 1], links[k, CHORD + 2]
            t0, t1, t2 = cross(links[k, ARM], links[k, ARM + 1], links[k, ARM + 2], d0, d1, d2)
            work[0, 6], work[1, 6] = d0, d1
            if n == 3:
                work[2, 6] = t2
            else:
                work[2, 6], work[3, 6], work[4, 6], work[5, 6] = d2, t0, t1, t2
            for i in range(n):
                ci = c * work[i, 6]
                for j in range(i + 1):
                    work[i, j] += ci * work[j, 6]


@jit.kernel(inline="always")
def _ldl_solve(f, n, work):
    """Solve (L D L^T) y = work[:n, 6] in place, ``f`` holding L and D (:func:`_ldl_factor`)."""
    for i in range(n):
        s = work[i, 6]
        for k in range(i):
            s -= f[i, k] * work[k, 6]
        work[i, 6] = s
    for i in range(n):
        work[i, 6] /= f[i, i]
    for i in range(n - 1, -1, -1):
        s = work[i, 6]
        for k in range(i + 1, n):
            s -= f[k, i] * work[k, 6]
        work[i, 6] = s


@jit.kernel(inline="always")
def _times_inverse(inverse, n, work):
    """work[:n, 0] = inverse work[:n, 6]: a body's constant mass matrix's inverse (n, n) applied to its right-hand
    side (n independent dot products, where the L D L^T's triangular solves are two chains of dependent steps)."""
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += inverse[i, j] * work[j, 6]
        work[i, 0] = s


@jit.kernel(inline="always")
def _factor6(work, constant, links, k0, k1):
    """A 3-D body's mass matrix in its axes, factored: :func:`_varying_mass` then :func:`_ldl_factor` (the same
    operations in the same order, so the same numbers) written out in scalars, L and D into ``work``. The loops
    keep the matrix in memory and reload it after every store (the compiler cannot tell the column of u from the
    entries it updates): 90 ns a call against 34 in a compiled loop."""
    a00 = constant[0, 0]
    a10, a11 = constant[1, 0], constant[1, 1]
    a20, a21, a22 = constant[2, 0], constant[2, 1], constant[2, 2]
    a30, a31, a32, a33 = constant[3, 0], constant[3, 1], constant[3, 2], constant[3, 3]
    a40, a41, a42, a43, a44 = constant[4, 0], constant[4, 1], constant[4, 2], constant[4, 3], constant[4, 4]
    a50, a51, a52, a53, a54, a55 = (constant[5, 0], constant[5, 1], constant[5, 2], constant[5, 3],
                                    constant[5, 4], constant[5, 5])
    for k in range(k0, k1):
        c = links[k, CHORD_SCALE]
        if c != 0.0:
            u0, u1, u2 = links[k, CHORD], links[k, CHORD + 1], links[k, CHORD + 2]
            u3, u4, u5 = cross(links[k, ARM], links[k, ARM + 1], links[k, ARM + 2], u0, u1, u2)
            c0 = c * u0
            a00 = a00 + c0 * u0
            c1 = c * u1
            a10, a11 = a10 + c1 * u0, a11 + c1 * u1
            c2 = c * u2
            a20, a21, a22 = a20 + c2 * u0, a21 + c2 * u1, a22 + c2 * u2
            c3 = c * u3
            a30, a31, a32, a33 = a30 + c3 * u0, a31 + c3 * u1, a32 + c3 * u2, a33 + c3 * u3
            c4 = c * u4
            a40, a41, a42, a43, a44 = a40 + c4 * u0, a41 + c4 * u1, a42 + c4 * u2, a43 + c4 * u3, a44 + c4 * u4
            c5 = c * u5
            a50, a51, a52 = a50 + c5 * u0, a51 + c5 * u1, a52 + c5 * u2
            a53, a54, a55 = a53 + c5 * u3, a54 + c5 * u4, a55 + c5 * u5
    d0 = a00
    inv0 = 1.0 / d0
    l10 = a10 * inv0
    l20 = a20 * inv0
    l30 = a30 * inv0
    l40 = a40 * inv0
    l50 = a50 * inv0
    d1 = a11 - l10 * l10 * d0
    inv1 = 1.0 / d1
    l21 = (a21 - l20 * l10 * d0) * inv1
    l31 = (a31 - l30 * l10 * d0) * inv1
    l41 = (a41 - l40 * l10 * d0) * inv1
    l51 = (a51 - l50 * l10 * d0) * inv1
    d2 = a22 - l20 * l20 * d0 - l21 * l21 * d1
    inv2 = 1.0 / d2
    l32 = (a32 - l30 * l20 * d0 - l31 * l21 * d1) * inv2
    l42 = (a42 - l40 * l20 * d0 - l41 * l21 * d1) * inv2
    l52 = (a52 - l50 * l20 * d0 - l51 * l21 * d1) * inv2
    d3 = a33 - l30 * l30 * d0 - l31 * l31 * d1 - l32 * l32 * d2
    inv3 = 1.0 / d3
    l43 = (a43 - l40 * l30 * d0 - l41 * l31 * d1 - l42 * l32 * d2) * inv3
    l53 = (a53 - l50 * l30 * d0 - l51 * l31 * d1 - l52 * l32 * d2) * inv3
    d4 = a44 - l40 * l40 * d0 - l41 * l41 * d1 - l42 * l42 * d2 - l43 * l43 * d3
    inv4 = 1.0 / d4
    l54 = (a54 - l50 * l40 * d0 - l51 * l41 * d1 - l52 * l42 * d2 - l53 * l43 * d3) * inv4
    d5 = a55 - l50 * l50 * d0 - l51 * l51 * d1 - l52 * l52 * d2 - l53 * l53 * d3 - l54 * l54 * d4
    work[0, 0] = d0
    work[1, 0], work[1, 1] = l10, d1
    work[2, 0], work[2, 1], work[2, 2] = l20, l21, d2
    work[3, 0], work[3, 1], work[3, 2], work[3, 3] = l30, l31, l32, d3
    work[4, 0], work[4, 1], work[4, 2], work[4, 3], work[4, 4] = l40, l41, l42, l43, d4
    work[5, 0], work[5, 1], work[5, 2], work[5, 3], work[5, 4] = l50, l51, l52, l53, l54
    work[5, 5] = d5


@jit.kernel(inline="always")
def _solve6(work, r0, r1, r2, r3, r4, r5):
    """:func:`_ldl_solve` of a 3-D body's factor in ``work`` for the right-hand side r, written out in scalars as
    :func:`_factor6` (the same operations in the same order; 28 against 10 ns): returns the solution."""
    d0, d1, d2, d3, d4, d5 = work[0, 0], work[1, 1], work[2, 2], work[3, 3], work[4, 4], work[5, 5]
    l10, l20, l30, l40, l50 = work[1, 0], work[2, 0], work[3, 0], work[4, 0], work[5, 0]
    l21, l31, l41, l51 = work[2, 1], work[3, 1], work[4, 1], work[5, 1]
    l32, l42, l52, l43, l53, l54 = work[3, 2], work[4, 2], work[5, 2], work[4, 3], work[5, 3], work[5, 4]
    y0 = r0
    y1 = r1 - l10 * y0
    y2 = r2 - l20 * y0 - l21 * y1
    y3 = r3 - l30 * y0 - l31 * y1 - l32 * y2
    y4 = r4 - l40 * y0 - l41 * y1 - l42 * y2 - l43 * y3
    y5 = r5 - l50 * y0 - l51 * y1 - l52 * y2 - l53 * y3 - l54 * y4
    z0 = y0 / d0
    z1 = y1 / d1
    z2 = y2 / d2
    z3 = y3 / d3
    z4 = y4 / d4
    z5 = y5 / d5
    x5 = z5
    x4 = z4 - l54 * x5
    x3 = z3 - l43 * x4 - l53 * x5
    x2 = z2 - l32 * x3 - l42 * x4 - l52 * x5
    x1 = z1 - l21 * x2 - l31 * x3 - l41 * x4 - l51 * x5
    x0 = z0 - l10 * x1 - l20 * x2 - l30 * x3 - l40 * x4 - l50 * x5
    return x0, x1, x2, x3, x4, x5


@jit.kernel
def own_load(gravity, flow, bodies, pose, twist, b, t, r):
    """Body b's own force [N] and moment [N m] about its reference point, in its axes (R^T of the world's): its
    weight and centripetal force at its centre of gravity, the gyroscopic moment -w x (I w), its buoyancy at its
    centre of buoyancy, its drag and rotational drag, its linear spring and damper (see the module doc); and the
    power [W] of the drag and the damper, as (f0, f1, f2, m0, m1, m2, power). ``r``: R's nine entries."""
    body = bodies.table[b]
    wb0, wb1, wb2 = rotate_back(r, twist[3, b], twist[4, b], twist[5, b])
    vb0, vb1, vb2 = rotate_back(r, twist[0, b], twist[1, b], twist[2, b])
    up0, up1, up2 = r[3], r[4], r[5]   # the world's up, R^T y, in body axes
    m = body[MASS]
    c0, c1, c2 = body[COG], body[COG + 1], body[COG + 2]
    e0, e1, e2 = cross(wb0, wb1, wb2, c0, c1, c2)
    n0, n1, n2 = cross(wb0, wb1, wb2, e0, e1, e2)   # w x (w x c)
    mg = m * gravity
    f0, f1, f2 = -m * n0 - mg * up0, -m * n1 - mg * up1, -m * n2 - mg * up2
    j0 = body[INERTIA] * wb0 + body[INERTIA + 1] * wb1 + body[INERTIA + 2] * wb2   # I_b w
    j1 = body[INERTIA + 3] * wb0 + body[INERTIA + 4] * wb1 + body[INERTIA + 5] * wb2
    j2 = body[INERTIA + 6] * wb0 + body[INERTIA + 7] * wb1 + body[INERTIA + 8] * wb2
    g0, g1, g2 = cross(wb0, wb1, wb2, j0, j1, j2)
    m0, m1, m2 = cross(c0, c1, c2, f0, f1, f2)
    m0, m1, m2 = m0 - g0, m1 - g1, m2 - g2
    lift = body[LIFT]
    if lift != 0.0:
        l0, l1, l2 = lift * up0, lift * up1, lift * up2
        k0, k1, k2 = cross(body[COB], body[COB + 1], body[COB + 2], l0, l1, l2)
        f0, f1, f2 = f0 + l0, f1 + l1, f2 + l2
        m0, m1, m2 = m0 + k0, m1 + k1, m2 + k2
    if WITH_BODY_SEA:   # under a free surface: water and air, the lost buoyancy, the water's inertia
        k0, k1, k2, n0, n1, n2, power = sea_loads(flow, bodies, pose, twist, b, t, r)
        f0, f1, f2, m0, m1, m2 = f0 + k0, f1 + k1, f2 + k2, m0 + n0, m1 + n1, m2 + n2
    else:
        # drag on the flow relative to the reference point, and the rotational drag
        u0, u1, u2 = -twist[0, b], -twist[1, b], -twist[2, b]
        if WITH_FLOW:
            U0, U1, U2 = flow_at(pose[1, b], t, flow[0], flow[1])
            u0 += U0
            u1 += U1
            u2 += U2
        speed = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
        spin = math.sqrt(wb0 * wb0 + wb1 * wb1 + wb2 * wb2)
        ub0, ub1, ub2 = rotate_back(r, u0, u1, u2)
        d0, d1, d2 = body[DRAG] * speed * ub0, body[DRAG + 1] * speed * ub1, body[DRAG + 2] * speed * ub2
        s0 = -body[DRAG_ROT] * spin * wb0
        s1 = -body[DRAG_ROT + 1] * spin * wb1
        s2 = -body[DRAG_ROT + 2] * spin * wb2
        power = d0 * vb0 + d1 * vb1 + d2 * vb2 + s0 * wb0 + s1 * wb1 + s2 * wb2
        f0, f1, f2, m0, m1, m2 = f0 + d0, f1 + d1, f2 + d2, m0 + s0, m1 + s1, m2 + s2
    # the linear spring and damper on the reference point (world axes; no moment about it); the damper's power is
    # the fluid's
    h0, h1, h2 = 0.0, 0.0, 0.0
    for k in range(3):
        if body[SPRING + k] != 0.0 or body[DAMPER + k] != 0.0:
            damping = body[DAMPER + k] * twist[k, b]
            pull = -(body[SPRING + k] * (pose[k, b] - body[REST + k]) + damping)
            power -= damping * twist[k, b]
            if k == 0:
                h0 = pull
            elif k == 1:
                h1 = pull
            else:
                h2 = pull
    if h0 != 0.0 or h1 != 0.0 or h2 != 0.0:
        hb0, hb1, hb2 = rotate_back(r, h0, h1, h2)
        f0, f1, f2 = f0 + hb0, f1 + hb1, f2 + hb2
    return f0, f1, f2, m0, m1, m2, power


@jit.kernel
def body_own_system(work, gravity, flow, bodies, pose, twist, b, t, power):
    """Body b's own part of its Newton-Euler equations (see the module doc) into ``work`` (6, 7), zeroed first, in
    world axes: its mass at its centre of gravity, inertia and added mass (the matrix), its own force and moment
    (:func:`own_load`, the right-hand side); returns ``power`` [W] plus the drag's and the damper's."""
    body = bodies.table[b]
    r = matrix_of(pose[3:7], b)
    for i in range(6):
        for j in range(7):
            work[i, j] = 0.0
    m = body[MASS]
    c0, c1, c2 = rotate(r, body[COG], body[COG + 1], body[COG + 2])
    _add_mass_at(work, m, 0.0, 0.0, m, 0.0, m, c0, c1, c2)
    for i in range(3):   # R I_b R^T
        for j in range(3):
            s = 0.0
            for k in range(3):
                for l in range(3):
                    s += r[3 * i + k] * body[INERTIA + 3 * k + l] * r[3 * j + l]
            work[3 + i, 3 + j] += s
    _add_rotated(work, 0, 0, r, body[ADDED], body[ADDED + 1], body[ADDED + 2])
    _add_rotated(work, 3, 3, r, body[ADDED_ROT], body[ADDED_ROT + 1], body[ADDED_ROT + 2])
    f0, f1, f2, m0, m1, m2, own = own_load(gravity, flow, bodies, pose, twist, b, t, r)
    work[0, 6], work[1, 6], work[2, 6] = rotate(r, f0, f1, f2)
    work[3, 6], work[4, 6], work[5, 6] = rotate(r, m0, m1, m2)
    return power + own


@jit.kernel
def body_attachments_system(work, x, acc, inv_mass, around, bodies, pose, twist, b):
    """Add body b's attachments to its Newton-Euler equations in ``work`` (6, 7), world axes: each node's mass and
    added mass at its arm, and its force m_i acc_i less its centripetal part (``acc`` holding each node's
    F_i / m_i)."""
    dim = x.shape[0]
    links, index = bodies.links, bodies.index
    first = links.shape[0]
    r = matrix_of(pose[3:7], b)
    w0, w1, w2 = twist[3, b], twist[4, b], twist[5, b]
    for k in range(index[first + b], index[first + b + 1]):
        i = index[k]
        p0, p1, p2 = rotate(r, links[k, ARM], links[k, ARM + 1], links[k, ARM + 2])
        mi = 1.0 / inv_mass[i]
        a_n, a_t = links[k, ADDED_N], links[k, ADDED_T]
        q0, q1, q2 = node_tangent(x, i, around)
        extra = a_t - a_n   # m I + a_n (I - q q^T) + a_t q q^T
        m00 = mi + a_n + extra * q0 * q0
        m01 = extra * q0 * q1
        m02 = extra * q0 * q2
        m11 = mi + a_n + extra * q1 * q1
        m12 = extra * q1 * q2
        m22 = mi + a_n + extra * q2 * q2
        _add_mass_at(work, m00, m01, m02, m11, m12, m22, p0, p1, p2)
        e0, e1, e2 = cross(w0, w1, w2, p0, p1, p2)
        n0, n1, n2 = cross(w0, w1, w2, e0, e1, e2)   # w x (w x rho)
        g0 = mi * acc[0, i] - (m00 * n0 + m01 * n1 + m02 * n2)
        g1 = mi * acc[1, i] - (m01 * n0 + m11 * n1 + m12 * n2)
        g2 = (mi * acc[2, i] if dim == 3 else 0.0) - (m02 * n0 + m12 * n1 + m22 * n2)
        m0, m1, m2 = cross(p0, p1, p2, g0, g1, g2)
        work[0, 6] += g0
        work[1, 6] += g1
        work[2, 6] += g2
        work[3, 6] += m0
        work[4, 6] += m1
        work[5, 6] += m2


@jit.kernel
def move_bodies(x, v, acc, inv_mass, around, gravity, flow, bodies, pose, twist, out, t, moved):
    """The free bodies' accelerations (see the module doc) into ``out`` (6, B) (a, then alpha), from ``acc``
    holding each attachment node's F_i / m_i, and every attachment's acceleration a + alpha x rho + w x (w x rho)
    into ``acc``; returns the power [W] of the fluid's forces on the bodies (drag and added mass).

    Solved in the body's axes, where its mass matrix is constant but for its attachments' added mass along their
    lines' tangents, (a_t - a_n) q q^T at each arm, a rank-one term u u^T with u = (q, s x q): the constant part
    is inverted once (:func:`bodies_bundle`), and a body with such terms adds them to it and factors its 6 x 6
    (3 x 3 in 2-D) matrix per evaluation; with ``moved`` False (the nodes and the bodies' poses where they were at
    the last call: the sub-stages of a velocity kick) it reuses that call's chords and factor. The stiff
    integrator's Newton solve assembles the same equations in world axes (:func:`body_own_system`,
    :func:`body_attachments_system`)."""
    dim = x.shape[0]
    links, index = bodies.links, bodies.index
    first = links.shape[0]   # index[first + b]: body b's first attachment
    n = 6 if dim == 3 else 3
    power = 0.0
    for b in range(pose.shape[1]):
        r = matrix_of(pose[3:7], b)
        w0, w1, w2 = twist[3, b], twist[4, b], twist[5, b]
        wb0, wb1, wb2 = rotate_back(r, w0, w1, w2)
        body = bodies.table[b]
        work = bodies.matrices[b, SCRATCH]
        varies = body[VARIES] != 0.0
        k_first, k_end = index[first + b], index[first + b + 1]
        f0, f1, f2, m0, m1, m2, own = own_load(gravity, flow, bodies, pose, twist, b, t, r)
        power += own
        for k in range(k_first, k_end):   # each attachment's force less its centripetal part
            link = links[k]
            i = index[k]
            s0, s1, s2 = link[ARM], link[ARM + 1], link[ARM + 2]
            mi = link[NODE_MASS]
            a_n, a_t = link[ADDED_N], link[ADDED_T]
            g0, g1, g2 = rotate_back(r, mi * acc[0, i], mi * acc[1, i], mi * acc[2, i] if dim == 3 else 0.0)
            e0, e1, e2 = cross(wb0, wb1, wb2, s0, s1, s2)
            n0, n1, n2 = cross(wb0, wb1, wb2, e0, e1, e2)   # w x (w x s)
            mn = mi + a_n
            g0, g1, g2 = g0 - mn * n0, g1 - mn * n1, g2 - mn * n2
            if WITH_ADDED_MASS and a_t != a_n:   # (a_t - a_n) q q^T = c d d^T, d the chord along the line,
                if moved:                          # c = (a_t - a_n) / |d|^2
                    lo, hi = around[0, i], around[1, i]
                    d0, d1, d2 = rotate_back(r, x[0, hi] - x[0, lo], x[1, hi] - x[1, lo],
                                             x[2, hi] - x[2, lo] if dim == 3 else 0.0)
                    chord = d0 * d0 + d1 * d1 + d2 * d2
                    c = (a_t - a_n) / chord if chord > 0.0 else 0.0
                    link[CHORD], link[CHORD + 1], link[CHORD + 2], link[CHORD_SCALE] = d0, d1, d2, c
                else:
                    d0, d1, d2, c = link[CHORD], link[CHORD + 1], link[CHORD + 2], link[CHORD_SCALE]
                along = c * (d0 * n0 + d1 * n1 + d2 * n2)
                g0, g1, g2 = g0 - along * d0, g1 - along * d1, g2 - along * d2
            h0, h1, h2 = cross(s0, s1, s2, g0, g1, g2)
            f0, f1, f2, m0, m1, m2 = f0 + g0, f1 + g1, f2 + g2, m0 + h0, m1 + h1, m2 + h2
        solved = False   # a body's mass matrix varies only with its attachments' added mass (compiled only then)
        if WITH_ADDED_MASS:
            if moved and varies:
                if n == 6:   # 3-D: written out in scalars, the same numbers (_factor6)
                    _factor6(work, bodies.matrices[b, CONSTANT], links, k_first, k_end)
                else:
                    _varying_mass(work, bodies.matrices[b, CONSTANT], n, links, k_first, k_end)
                    _ldl_factor(work, n)
            if varies and n == 6:
                ab0, ab1, ab2, alb0, alb1, alb2 = _solve6(work, f0, f1, f2, m0, m1, m2)
                solved = True
        if not solved:
            work[0, 6], work[1, 6] = f0, f1   # the kept rows' right-hand side: x, y and the turn about z in 2-D
            if n == 3:
                work[2, 6] = m2
            else:
                work[2, 6], work[3, 6], work[4, 6], work[5, 6] = f2, m0, m1, m2
            at = 0
            if WITH_ADDED_MASS:
                if varies:
                    _ldl_solve(work, n, work)
                    at = 6
            if at == 0:   # the constant matrix's inverse times the right-hand side, into the unused first column
                _times_inverse(bodies.matrices[b, INVERSE], n, work)
            if n == 3:   # 2-D: x, y and the turn about z
                ab0, ab1, ab2, alb0, alb1, alb2 = work[0, at], work[1, at], 0.0, 0.0, 0.0, work[2, at]
            else:
                ab0, ab1, ab2, alb0, alb1, alb2 = work[0, at], work[1, at], work[2, at], work[3, at], work[4, at], \
                    work[5, at]
        out[0, b], out[1, b], out[2, b] = rotate(r, ab0, ab1, ab2)
        out[3, b], out[4, b], out[5, b] = rotate(r, alb0, alb1, alb2)
        # the fluid's inertial force on the body's own added mass: -A_t a . v - A_r alpha . w
        vb0, vb1, vb2 = rotate_back(r, twist[0, b], twist[1, b], twist[2, b])
        power -= body[ADDED] * ab0 * vb0 + body[ADDED + 1] * ab1 * vb1 + body[ADDED + 2] * ab2 * vb2
        power -= body[ADDED_ROT] * alb0 * wb0 + body[ADDED_ROT + 1] * alb1 * wb1 + body[ADDED_ROT + 2] * alb2 * wb2
        for k in range(k_first, k_end):   # each attachment's acceleration a + alpha x s + w x (w x s)
            link = links[k]
            i = index[k]
            s0, s1, s2 = link[ARM], link[ARM + 1], link[ARM + 2]
            e0, e1, e2 = cross(wb0, wb1, wb2, s0, s1, s2)
            t0, t1, t2 = cross(alb0, alb1, alb2, s0, s1, s2)
            n0, n1, n2 = cross(wb0, wb1, wb2, e0, e1, e2)
            kb0, kb1, kb2 = ab0 + t0 + n0, ab1 + t1 + n1, ab2 + t2 + n2
            k0, k1, k2 = rotate(r, kb0, kb1, kb2)
            acc[0, i] = k0
            acc[1, i] = k1
            if dim == 3:
                acc[2, i] = k2
            a_n, a_t = link[ADDED_N], link[ADDED_T]
            if WITH_ADDED_MASS and (a_n != 0.0 or a_t != 0.0):   # the fluid's inertial force -A_i a_i on the
                # node, at its velocity
                h0, h1, h2 = a_n * kb0, a_n * kb1, a_n * kb2   # in body axes, with the chord kept above
                if a_t != a_n:
                    d0, d1, d2 = link[CHORD], link[CHORD + 1], link[CHORD + 2]
                    along = link[CHORD_SCALE] * (kb0 * d0 + kb1 * d1 + kb2 * d2)
                    h0, h1, h2 = h0 + along * d0, h1 + along * d1, h2 + along * d2
                u0, u1, u2 = rotate_back(r, v[0, i], v[1, i], v[2, i] if dim == 3 else 0.0)
                power -= h0 * u0 + h1 * u1 + h2 * u2
    return power


@jit.kernel
def body_energy(bodies, pose, twist, gravity):
    """The free bodies' mechanical energy [J]: kinetic, gravitational and buoyancy (see the module doc)."""
    e = 0.0
    for b in range(pose.shape[1]):
        body = bodies.table[b]
        r = matrix_of(pose[3:7], b)
        w0, w1, w2 = twist[3, b], twist[4, b], twist[5, b]
        c0, c1, c2 = rotate(r, body[COG], body[COG + 1], body[COG + 2])
        e0, e1, e2 = cross(w0, w1, w2, c0, c1, c2)
        g0, g1, g2 = twist[0, b] + e0, twist[1, b] + e1, twist[2, b] + e2
        wb = rotate_back(r, w0, w1, w2)
        spin = 0.0   # w . I w = (R^T w) . I_b (R^T w)
        for k in range(3):
            for l in range(3):
                spin += wb[k] * body[INERTIA + 3 * k + l] * wb[l]
        m = body[MASS]
        k1 = rotate(r, body[COB], body[COB + 1], body[COB + 2])[1]
        e += 0.5 * m * (g0 * g0 + g1 * g1 + g2 * g2) + 0.5 * spin + m * gravity * (pose[1, b] + c1)
        e -= body[LIFT] * (pose[1, b] + k1)
        for k in range(3):
            stretch = pose[k, b] - body[REST + k]
            e += 0.5 * body[SPRING + k] * stretch * stretch
    return e


@jit.kernel
def save_bodies(frame, pose, twist, frames_body):
    """Copy the bodies' state into saved frame ``frame`` of ``frames_body`` (F, 13, B): pose rows, then twist."""
    for b in range(pose.shape[1]):
        for d in range(POSE):
            frames_body[frame, d, b] = pose[d, b]
        for d in range(TWIST):
            frames_body[frame, POSE + d, b] = twist[d, b]


def initial_state(scene) -> tuple[np.ndarray, np.ndarray]:
    """The free bodies' pose (7, B) and twist (6, B) at t = 0: where the scene puts them, with its ``velocity`` and
    ``angular_velocity`` [deg/s] (world axes)."""
    bodies = free_bodies(scene)
    dim = scene.dimension
    pose, twist = np.zeros((POSE, len(bodies))), np.zeros((TWIST, len(bodies)))
    for b, body in enumerate(bodies):
        pose[:, b] = initial_pose(body, dim)
        twist[:3, b] = vector3(body.velocity, dim)
        twist[3:, b] = np.radians(turns3(body.angular_velocity, dim))
    return pose, twist


# ------------------------------------------------------------------------------------- saved frames


def body_shapes(model) -> dict[str, tuple]:
    """The rigid bodies' per-frame arrays and their shapes (none without rigid bodies): every body of the scene,
    free, fixed or driven, in scene order."""
    count = len(model.scene.rigid_bodies)
    if not count:
        return {}
    dim = model.dim
    return {"body_x": (count, dim), "body_q": (count, 4), "body_v": (count, dim), "body_w": (count, 3)}


def body_frames(model, t: np.ndarray, state: np.ndarray | None) -> dict[str, np.ndarray]:
    """Every rigid body's ``body_x`` (F, B, D) [m], ``body_q`` (F, B, 4), ``body_v`` (F, B, D) [m/s] and ``body_w``
    (F, B, 3) [rad/s] at times t (F,): a free body's from the integrator's saved state (F, 13, B_free), a fixed
    body's where the scene puts it, a driven body's from its prescribed motion."""
    scene, dim = model.scene, model.dim
    frames = len(t)
    count = len(scene.rigid_bodies)
    out = {"body_x": np.zeros((frames, count, dim)), "body_q": np.zeros((frames, count, 4)),
           "body_v": np.zeros((frames, count, dim)), "body_w": np.zeros((frames, count, 3))}
    free = 0
    for b, body in enumerate(scene.rigid_bodies):
        if body.kind == "free":
            rows = np.asarray(state)[:, :, free]
            free += 1
            out["body_x"][:, b] = rows[:, 0:dim]
            out["body_q"][:, b] = rows[:, 3:7]
            out["body_v"][:, b] = rows[:, POSE:POSE + dim]
            out["body_w"][:, b] = rows[:, POSE + 3:POSE + 6]
        elif body.kind in STILL_KINDS:
            pose = initial_pose(body, dim)
            out["body_x"][:, b] = pose[:dim]
            out["body_q"][:, b] = pose[3:]
        else:
            position, q, velocity, spin = driven_pose(model, body, np.asarray(t, dtype=float))
            out["body_x"][:, b] = position[:, :dim]
            out["body_q"][:, b] = q
            out["body_v"][:, b] = velocity[:, :dim]
            out["body_w"][:, b] = spin
    return out


def driven_pose(model, body, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A driven body's reference point (F, 3) [m], orientation (F, 4), velocity (F, 3) [m/s] and angular velocity
    (F, 3) [rad/s] at times t (F,), from its prescribed motion (:func:`ropesim.model.motion.rigid_state`)."""
    from .motion import rigid_state
    from .rotation import quaternion_from_matrix

    driven = [b for b in model.scene.rigid_bodies if b.kind in ("driven", "coupled")]
    index = driven.index(body)
    motions = model.motion.bodies
    state = np.array([rigid_state(motions, index, float(tk), float(tk)) for tk in t]).reshape(len(t), 24)
    q = quaternion_from_matrix(state[:, 9:18].reshape(-1, 3, 3))
    return state[:, 0:3], q, state[:, 3:6], state[:, 18:21]


def free_body_state(model, frames, part: slice = slice(None)) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The free bodies' poses (F, 7, B) and twists (F, 6, B) in frames ``part`` of ``frames`` (anything with the
    per-frame arrays body_x, body_q, body_v and body_w: a Trajectory, or a dict of them), for
    :func:`ropesim.model.energy.energy_terms`; (None, None) without free bodies."""
    which = [b for b, body in enumerate(model.scene.rigid_bodies) if body.kind == "free"]
    if not which:
        return None, None
    get = frames.get if isinstance(frames, dict) else lambda name: getattr(frames, name)
    x, q, v, w = (np.asarray(get(name)[part])[:, which] for name in ("body_x", "body_q", "body_v", "body_w"))
    count, dim = x.shape[0], model.dim
    pose, twist = np.zeros((count, POSE, len(which))), np.zeros((count, TWIST, len(which)))
    pose[:, :dim] = np.swapaxes(x, 1, 2)
    pose[:, 3:] = np.swapaxes(q, 1, 2)
    twist[:, :dim] = np.swapaxes(v, 1, 2)
    twist[:, 3:] = np.swapaxes(w, 1, 2)
    return pose, twist
