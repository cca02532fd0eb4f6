"""Fluid forces on the velocity relative to an ambient flow: Morison-type quadratic drag, linear anisotropic
drag, point bodies' drag, and the flow's push on the linear [drag] b.

The flow U(y, t) (``[flow]``) is uniform, a power law over height above a datum, or a table over height
interpolated linearly (held at its end rows beyond them), times a smooth ramp (1 - cos(pi t / T)) / 2 over
the first T = ``ramp_time`` seconds. With u = v - U the relative velocity of node i, split along the node
tangent q_i (the unit chord through its two neighbours, x_(i+1) - x_(i-1); at an open line's ends the end
segment's direction; MoorDyn's convention) into u_t = (u . q) q and u_n = u - u_t:

- quadratic drag (``[fluid_drag]``): F = -c_n L |u_n| u_n - c_t L |u_t| u_t, c_n = rho Cd_n d / 2 on the
  projected area, c_t = rho Cd_t pi d / 2 on the skin (MoorDyn's Cd and CdAx), L the node's share of
  unstretched length (half of each adjacent segment);
- linear drag (``[viscous_drag]``): F = -b_n L u_n - b_t L u_t;
- a body (``[[bodies]]`` with cd_area): F = -(rho CdA / 2) |u| u;
- the linear [drag] b in a flow: F = -b (v - U), of which the kick integrates -b v exactly; the push + b U is
  added here.

Lumping: every coefficient acts on the node's share L of *unstretched* length, as MoorDyn does (stretching
changes neither mass nor drag area). A node whose two neighbours coincide has no tangent: all of u counts as
normal. All of it is work of the fluid, booked in the energy ledger's ``fluid_work``.

Parameters: ``fluid_drag`` (2, N) c_n and c_t per node [kg/m^2] (each line's own), ``viscous_drag`` [b_n, b_t] [N s/m^2], ``body_drag`` (N,)
rho CdA / 2 [kg/m], ``flow_push`` (N,) b / m [1/s], ``flow`` = (scalars [profile, ramp_time, datum,
reference_height, exponent, Ux, Uy, Uz], table (K, 4) [y, Ux, Uy, Uz]), and the model's ``node_length`` (N,).
"""

from __future__ import annotations

import math

import numpy as np

from . import Term
from ..layout import lumped_bodies, per_node
from .. import jit
from ..ramp import ramp

WITH_FLUID_DRAG = jit.Switch("fluid_drag", "Morison quadratic drag")
WITH_VISCOUS_DRAG = jit.Switch("viscous_drag", "linear anisotropic drag")
WITH_BODY_DRAG = jit.Switch("body_drag", "point bodies' drag")
WITH_FLOW = jit.Switch("flow", "an ambient flow")
WITH_FLOW_PUSH = jit.Switch("flow_push", "a flow's push on the linear drag")
UNIFORM, POWER_LAW, TABLE = 0, 1, 2
PROFILES = {"uniform": UNIFORM, "power_law": POWER_LAW, "table": TABLE}
FLOW_PARAMS = 8


@jit.kernel
def flow_at(y, t, flow, table):
    """The flow velocity (Ux, Uy, Uz) [m/s] at height y [m] and time t [s] (see the module doc)."""
    return flow_scaled(y, ramp(t, flow[1]), flow, table)


def still_flow(flow: tuple) -> tuple:
    """``flow`` (the parameters above) with no speed anywhere: the same profile and table heights, every
    velocity 0, the same types (so a kernel compiled for the flow runs on it as it is)."""
    scalars, table = flow
    still_scalars, still_table = scalars.copy(), table.copy()
    still_scalars[5:8] = 0.0
    still_table[:, 1:] = 0.0
    return still_scalars, still_table


@jit.kernel
def flow_scaled(y, s, flow, table):
    """The flow's full profile at height y [m] times s: its velocity with s the ramp's factor, its local
    acceleration with s the ramp's rate."""
    kind = int(flow[0])
    if kind == TABLE:
        k = table.shape[0]
        if y <= table[0, 0]:
            return s * table[0, 1], s * table[0, 2], s * table[0, 3]
        if y >= table[k - 1, 0]:
            return s * table[k - 1, 1], s * table[k - 1, 2], s * table[k - 1, 3]
        lo, hi = 0, k - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if table[mid, 0] <= y:
                lo = mid
            else:
                hi = mid
        w = (y - table[lo, 0]) / (table[hi, 0] - table[lo, 0])
        return (s * (table[lo, 1] + w * (table[hi, 1] - table[lo, 1])),
                s * (table[lo, 2] + w * (table[hi, 2] - table[lo, 2])),
                s * (table[lo, 3] + w * (table[hi, 3] - table[lo, 3])))
    if kind == POWER_LAW:
        above = y - flow[2]
        s = s * (above / flow[3]) ** flow[4] if above > 0.0 else 0.0
    return s * flow[5], s * flow[6], s * flow[7]


def neighbours(first: int, nodes: int, closed: bool) -> np.ndarray:
    """The nodes (2, nodes) whose chord gives each node's tangent, for a line of ``nodes`` nodes from node
    ``first``: its two neighbours; at an open line's end itself and its one neighbour (the end segment's
    direction); round a loop the wrapped ones. A node on no line (a free point) is its own neighbour both ways,
    so it has no tangent. ``ModelParams.neighbours`` holds them for every node."""
    i = np.arange(nodes)
    lo, hi = i - 1, i + 1
    lo[0] = nodes - 1 if closed else 0
    hi[-1] = 0 if closed else nodes - 1
    return np.stack([lo, hi]).astype(np.int64) + first


@jit.kernel(inline="always")
def node_tangent(x, i, around):
    """The unit tangent (qx, qy, qz) of node i (see the module doc), along the chord between its neighbours
    ``around[:, i]`` (:func:`neighbours`); (0, 0, 0) when it has none."""
    dim = x.shape[0]
    lo, hi = around[0, i], around[1, i]
    qx = x[0, hi] - x[0, lo]
    qy = x[1, hi] - x[1, lo]
    qz = x[2, hi] - x[2, lo] if dim == 3 else 0.0
    r = math.sqrt(qx * qx + qy * qy + qz * qz)
    if r == 0.0:
        return 0.0, 0.0, 0.0
    return qx / r, qy / r, qz / r


@jit.kernel
def add_fluid_forces(x, v, acc, p, t):
    """Add the fluid forces (see the module doc) of every free-or-held node as accelerations [m/s^2]; returns
    their power [W] on the rope (held nodes included: their supports take it)."""
    dim, n = x.shape
    c_n, c_t = p.fluid_drag[0], p.fluid_drag[1]   # per node
    b_n, b_t = p.viscous_drag[0], p.viscous_drag[1]
    flow, table = p.flow
    power = 0.0
    for i in range(n):
        ux = uy = uz = 0.0
        if WITH_FLOW:
            ux, uy, uz = flow_at(x[1, i], t, flow, table)
        rx = v[0, i] - ux
        ry = v[1, i] - uy
        rz = v[2, i] - uz if dim == 3 else 0.0
        fx = fy = fz = 0.0
        if WITH_FLUID_DRAG or WITH_VISCOUS_DRAG:
            qx, qy, qz = node_tangent(x, i, p.neighbours)
            along = rx * qx + ry * qy + rz * qz
            tx, ty, tz = along * qx, along * qy, along * qz
            nx, ny, nz = rx - tx, ry - ty, rz - tz
            length = p.node_length[i]
            if WITH_FLUID_DRAG:
                cn = c_n[i] * length * math.sqrt(nx * nx + ny * ny + nz * nz)
                ct = c_t[i] * length * abs(along)
                fx -= cn * nx + ct * tx
                fy -= cn * ny + ct * ty
                fz -= cn * nz + ct * tz
            if WITH_VISCOUS_DRAG:
                fx -= length * (b_n * nx + b_t * tx)
                fy -= length * (b_n * ny + b_t * ty)
                fz -= length * (b_n * nz + b_t * tz)
        if WITH_BODY_DRAG and p.body_drag[i] > 0.0:
            cb = p.body_drag[i] * math.sqrt(rx * rx + ry * ry + rz * rz)
            fx -= cb * rx
            fy -= cb * ry
            fz -= cb * rz
        inv_m = p.inv_mass[i]
        if WITH_FLOW_PUSH:   # + b U, as an acceleration (b / m) U
            fx += p.flow_push[i] * ux / inv_m
            fy += p.flow_push[i] * uy / inv_m
            fz += p.flow_push[i] * uz / inv_m
        acc[0, i] += fx * inv_m
        acc[1, i] += fy * inv_m
        power += fx * v[0, i] + fy * v[1, i]
        if dim == 3:
            acc[2, i] += fz * inv_m
            power += fz * v[2, i]
    return power



@jit.kernel(inline="always")
def morison_damping(a, b, q, nv, speed_n, along, cn, ct):
    """Entry (a, b) of the Morison drag's damping -dF/dv at a relative velocity of normal part ``nv`` (its
    magnitude ``speed_n``) and tangential part ``along`` q, the tangent q frozen: c_n L (|u_n| P + u_n u_n^T /
    |u_n|) + 2 c_t L |u . q| q q^T (P = I - q q^T); cn = c_n L, ct = c_t L."""
    qq = q[a] * q[b]
    c = cn * speed_n * ((1.0 if a == b else 0.0) - qq) + 2.0 * ct * abs(along) * qq
    if speed_n > 0.0:
        c += cn * nv[a] * nv[b] / speed_n
    return c


@jit.kernel
def add_fluid_jacobian(x, v, band, beta, free, p, t):
    """Add beta C to the Newton matrix's node blocks (see :mod:`ropesim.model.jacobian`), C = -dF/dv the fluid
    forces' damping at the current state, with the tangent frozen (its dependence on positions is left out):

    quadratic c_n L (|u_n| P + |u_n| n n^T) + 2 c_t L |u . q| q q^T (P = I - q q^T, n = u_n / |u_n|); linear
    L (b_n P + b_t q q^T); a body c_b (|u| I + |u| r r^T) (r = u / |u|). All positive semi-definite.
    """
    dim, n = x.shape
    flow, table = p.flow
    c_n, c_t = p.fluid_drag[0], p.fluid_drag[1]   # per node
    b_n, b_t = p.viscous_drag[0], p.viscous_drag[1]
    for i in range(n):
        if not free[i]:
            continue
        ux = uy = uz = 0.0
        if WITH_FLOW:
            ux, uy, uz = flow_at(x[1, i], t, flow, table)
        r = (v[0, i] - ux, v[1, i] - uy, v[2, i] - uz if dim == 3 else 0.0)
        q = (0.0, 0.0, 0.0)
        nv = (0.0, 0.0, 0.0)
        along = speed_n = length = 0.0
        if WITH_FLUID_DRAG or WITH_VISCOUS_DRAG:
            q = node_tangent(x, i, p.neighbours)
            along = r[0] * q[0] + r[1] * q[1] + r[2] * q[2]
            nv = (r[0] - along * q[0], r[1] - along * q[1], r[2] - along * q[2])
            speed_n = math.sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2])
            length = p.node_length[i]
        c_b = p.body_drag[i] if WITH_BODY_DRAG else 0.0
        speed = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) if c_b > 0.0 else 0.0
        for a in range(dim):
            for b in range(a + 1):
                unit = 1.0 if a == b else 0.0
                qq = q[a] * q[b]
                c = 0.0
                if WITH_FLUID_DRAG:
                    c += morison_damping(a, b, q, nv, speed_n, along, c_n[i] * length, c_t[i] * length)
                if WITH_VISCOUS_DRAG:
                    c += length * (b_n * (unit - qq) + b_t * qq)
                if speed > 0.0:
                    c += c_b * (speed * unit + r[a] * r[b] / speed)
                band[a - b, i * dim + b] += beta * c


@jit.kernel
def add_fluid_tangent_stiffness(x, v, blocks, free, p, t):
    """Add the drag's stiffness through the node tangent, K = -dF_i/dx_j, to ``blocks`` (N, 3, D, D): node i's
    block for its neighbour before it (round a loop), itself and the one after. :func:`add_fluid_jacobian`
    freezes the tangent q; for the static solver this is the missing part of Newton's matrix, and for a line
    hanging in a current it is as large as the springs' own sideways stiffness (:mod:`ropesim.model.statics`).

    With u = v - U, a = u . q, u_n = u - a q and W = q u^T + a I (= d(a q)/dq):
    dF/dq = c_n L (|u_n| W + a u_n u_n^T / |u_n|) - c_t L (2 |a| q u^T + |a| a I) + L (b_n - b_t) W, and
    q = (x_hi - x_lo) / r gives dF/dx_hi = -dF/dx_lo = dF/dq (I - q q^T) / r. Not symmetric: the static
    solver applies it beside the banded matrix rather than in it. Held rows are skipped; the caller leaves out
    held columns.
    """
    dim, n = x.shape
    flow, table = p.flow
    c_n, c_t = p.fluid_drag[0], p.fluid_drag[1]   # per node
    b_n, b_t = p.viscous_drag[0], p.viscous_drag[1]
    for i in range(n):
        if not free[i]:
            continue
        lo, hi = p.neighbours[0, i], p.neighbours[1, i]
        e0, e1 = x[0, hi] - x[0, lo], x[1, hi] - x[1, lo]
        e2 = x[2, hi] - x[2, lo] if dim == 3 else 0.0
        r = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        if r == 0.0:
            continue
        q = (e0 / r, e1 / r, e2 / r)
        ux = uy = uz = 0.0
        if WITH_FLOW:
            ux, uy, uz = flow_at(x[1, i], t, flow, table)
        u = (v[0, i] - ux, v[1, i] - uy, v[2, i] - uz if dim == 3 else 0.0)
        a = u[0] * q[0] + u[1] * q[1] + u[2] * q[2]
        un = (u[0] - a * q[0], u[1] - a * q[1], u[2] - a * q[2])
        sn = math.sqrt(un[0] * un[0] + un[1] * un[1] + un[2] * un[2])
        cn = c_n[i] * p.node_length[i] if WITH_FLUID_DRAG else 0.0
        ct = c_t[i] * p.node_length[i] if WITH_FLUID_DRAG else 0.0
        lin = p.node_length[i] * (b_n - b_t) if WITH_VISCOUS_DRAG else 0.0
        before = 0 if lo != i else 1
        after = 2 if hi != i else 1
        for j in range(dim):
            mq = 0.0
            for k in range(3):
                mq += _drag_by_tangent(j, k, q, u, a, un, sn, cn, ct, lin) * q[k]
            for k in range(dim):
                stiffness = (_drag_by_tangent(j, k, q, u, a, un, sn, cn, ct, lin) - mq * q[k]) / r   # dF_j/dx_hi,k
                blocks[i, after, j, k] -= stiffness
                blocks[i, before, j, k] += stiffness


@jit.kernel(inline="always")
def _drag_by_tangent(j, k, q, u, a, un, sn, cn, ct, lin):
    """dF_j/dq_k of a node's drag (see :func:`add_fluid_tangent_stiffness`); cn = c_n L, ct = c_t L, lin =
    L (b_n - b_t)."""
    w = q[j] * u[k] + (a if j == k else 0.0)
    m = cn * sn * w + lin * w
    if sn > 0.0:
        m += cn * a * un[j] * un[k] / sn
    return m - ct * (2.0 * abs(a) * q[j] * u[k] + (abs(a) * a if j == k else 0.0))


def speed_scale(model) -> float:
    """A speed [m/s] the run's relative velocities stay near: twice the largest of the initial and held node
    speeds, the flow's largest speed, the thrower's v_max, and with a sea the wind's speed and the waves' orbital
    speed at the surface (for the stability bound of velocity-dependent drag, which grows with speed)."""
    scene = model.scene
    speeds = [float(np.abs(model.v0).max(initial=0.0)), float(np.abs(model.held_v).max(initial=0.0))]
    if scene.flow is not None:
        rows = [scene.flow.velocity] if scene.flow.velocity is not None else list(scene.flow.velocities)
        speeds.append(max(math.hypot(*row) for row in rows))
    if scene.thrower is not None:
        speeds.append(abs(scene.thrower.v_max))
    if scene.sea is not None:
        from ..waves import orbital_speed, wave_field

        if scene.sea.wind is not None:
            speeds.append(math.hypot(*scene.sea.wind))
        if scene.waves is not None:
            speeds.append(orbital_speed(wave_field(scene)))
    return 2.0 * max(speeds + [1.0])


def _free_min_mass(model) -> float:
    free = ~model.held
    return float(model.mass[free].min()) if free.any() else float(model.mass.min())


def _quadratic_rate(model) -> float:
    """Largest d(drag force)/d(speed) / mass [1/s] of the quadratic drag at the speed scale: 2 c L U / m."""
    p, free = model.params, ~model.held
    c = np.maximum(p.fluid_drag[0], p.fluid_drag[1])
    return float(np.max(2.0 * c[free] * p.node_length[free] * speed_scale(model) / model.mass[free], initial=0.0))


def _fluid_drag(scene, layout) -> np.ndarray:
    """(2, N): c_n = rho Cd_n d / 2 and c_t = rho Cd_t pi d / 2 of each node's line [kg/m^2] (0 off the lines)."""
    rho, n = scene.fluid.density, len(layout.mass)
    return np.stack([per_node(layout.lines, n, [0.5 * rho * line.cd_normal * line.diameter for line in layout.lines]),
                     per_node(layout.lines, n, [0.5 * rho * line.cd_tangential * math.pi * line.diameter
                                                for line in layout.lines])])


def _body_drag(scene, layout) -> np.ndarray:
    out = np.zeros(len(layout.mass))
    for body in lumped_bodies(scene, layout.lines):
        out[body.node] = 0.5 * scene.fluid.density * body.cd_area if body.cd_area > 0 else 0.0
    return out


def _flow(scene, layout) -> tuple:
    f = scene.flow
    scalars = np.zeros(FLOW_PARAMS)
    scalars[0], scalars[1], scalars[2] = PROFILES[f.profile], f.ramp_time, f.datum
    if f.profile == "power_law":
        scalars[3], scalars[4] = f.reference_height, f.exponent
    if f.velocity is not None:
        scalars[5:5 + len(f.velocity)] = f.velocity
    table = np.zeros((0, 4))
    if f.profile == "table":
        table = np.zeros((len(f.heights), 4))
        table[:, 0] = f.heights
        table[:, 1:1 + scene.dimension] = np.asarray(f.velocities)
    return scalars, table


def _flow_push(scene, layout) -> np.ndarray:
    b = np.full(len(layout.mass), scene.drag.b)
    for o in scene.overrides:
        if o.drag is not None:
            b[scene.node(o.index)] = o.drag
    return np.where(layout.held, 0.0, b / layout.mass)


FLUID_DRAG_TERM = Term("fluid_drag", WITH_FLUID_DRAG, _fluid_drag, lambda: np.zeros((2, 0)), damping=_quadratic_rate,
                       ledger="fluid", velocity=True)
VISCOUS_DRAG_TERM = Term(
    "viscous_drag", WITH_VISCOUS_DRAG, lambda scene, layout: np.array([scene.viscous_drag.b_normal,
                                                                  scene.viscous_drag.b_tangential]),
    lambda: np.zeros(2), ledger="fluid", velocity=True,
    damping=lambda model: float(np.max(max(model.params.viscous_drag) * model.params.node_length[~model.held]
                                       / model.mass[~model.held], initial=0.0)))
BODY_DRAG_TERM = Term(
    "bodies", WITH_BODY_DRAG, _body_drag, lambda: np.zeros(0), ledger="fluid", velocity=True,
    active=lambda scene: any(b.cd_area > 0 for b in lumped_bodies(scene)),
    damping=lambda model: float(np.max(2.0 * model.params.body_drag * speed_scale(model) / model.mass,
                                       initial=0.0)))
FLOW_TERM = Term("flow", WITH_FLOW, _flow, lambda: (np.zeros(FLOW_PARAMS), np.zeros((0, 4))))
"""The flow field itself: no force of its own (the drag terms act on the velocity relative to it)."""
FLOW_PUSH_TERM = Term("drag", WITH_FLOW_PUSH, _flow_push, lambda: np.zeros(0), ledger="fluid", velocity=True,
                      active=lambda scene: scene.flow is not None and scene.drag is not None)
"""The flow's push on the linear [drag]: + b U per node."""
