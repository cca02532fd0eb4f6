"""The free surface (``[sea]``): water below the instantaneous surface, air above it, and what acts on the part
of each node that is submerged.

**Where the water is.** The surface is at y = level + eta(x, t), eta the waves' elevation at the node
(:mod:`ropesim.model.waves`; 0 without ``[waves]``), taken as flat across the node's share of its line. That
share is two half segments, from the node to the middle of each segment it touches (one at an open line's
end), each a straight cylinder of the line's diameter. The fraction of such a cylinder below a horizontal plane
is exact in closed form: a disc of the cylinder, at height y_c on its axis, is cut by the plane along a chord
u = (surface - y_c) / (r cos alpha) radii from its centre (alpha the axis's slope), so its submerged part is
Phi(u) = (acos(-u) + u sqrt(1 - u^2)) / pi, and along the axis u varies linearly: the half segment's fraction
is the mean of Phi over [u_0, u_1], (G(u_1) - G(u_0)) / (u_1 - u_0), G the integral of Phi
(:func:`cylinder_fraction`). A horizontal cylinder gets the exact circular segment (so a floating line rests
at Archimedes' draught), a vertical one the fraction of its axis below the surface, and everything between is
continuous, as the stiff integrator's Newton solve needs. The node's line fraction f is the mean of its half
segments' weighted by their unstretched lengths. A point body (a rope's ``[[bodies]]``, a system's free point
with a volume) is a sphere of its volume: f_b = (u + 1)^2 (2 - u) / 4, u = (surface - y) / R.
``[sea] fraction = "moordyn"`` puts MoorDyn 2's rule in place of the line's cylinders, to compare with it on
equal physics (:func:`moordyn_line_fraction`): each segment's share below the mean of its two nodes' surface
heights, measured along a diagonal of the segment; the Newton matrix keeps the cylinders' slope.

**What acts on it**, with f and f_b at the state and time of every force evaluation:

- buoyancy on the submerged part only: ``[buoyancy]`` keeps its push rho V g on the whole volume (and its
  potential energy), and this term takes away the part above the surface, -rho g (V_line (1 - f) +
  V_body (1 - f_b)), booked as the fluid's work;
- added mass on the submerged part: the node's mass matrix m I + f A_line + f_b A_body. :func:`water_state`
  rewrites the live coefficients the added-mass pass, the free points' solve and the Newton matrix read
  (``ModelParams.added_mass``, ``Junctions.added``) from their bases (this bundle's rows) at every evaluation,
  before they are read;
- the water's inertia force on the submerged part, MoorDyn's Froude-Krylov plus added-mass force (its Ap and
  Aq): f rho V_line [(b + Ca_n) a_n + (b + Ca_t) a_t] + f_b rho V_body (b + Ca) a_w, a_w the water's local
  acceleration (the waves' du/dt, and a ramping current's) split along the node tangent; b = 1 with
  ``[buoyancy]`` (the pressure gradient that accelerates the water), the Ca parts with added mass;
- drag (``[fluid_drag]``, a point body's ``cd_area``): the water's on the fraction f of the node (f_b of its
  body) on the velocity relative to the water, u_w = U_current + u_waves, and the air's on the rest, the same
  coefficients times rho_air / rho_water, on the velocity relative to the ``wind``. Air adds no buoyancy.

**Water kinematics from outside** (MoorDyn's external wave kinematics; :meth:`ropesim.Coupling.set_waves`): with
the scalar ``GIVEN_WAVES`` set, every evaluation takes each node's surface elevation, the waves' velocity and
acceleration from the rows ``GIVEN`` (what the coupled program last gave, held until it gives them again) instead
of computing the waves; a ``[flow]`` current is added on top as always.

Above the surface a node gets the surface's water kinematics (:mod:`ropesim.model.waves`), but only its
submerged part feels them. With a sea the ramping current's inertia force ([flow] ``ramp_time``) is this
term's too, on the submerged part (the :mod:`~ropesim.model.forces.flow_inertia` term is off).

:func:`water_state` computes every node's surface elevation, fractions and water kinematics for positions x at
time t into the bundle's state rows, at every force evaluation and before every Newton matrix (the time
factors of the waves are shared by every evaluation at one time, :func:`ropesim.model.waves.time_factors`).
The numbers depend on (x, t) alone, so a call at the last call's positions and time returns at once (sdirk2's
Newton matrix asks at the stage's (x, t) its residual has just asked at).

The Newton matrix (sdirk2) gets the drag's damping on both parts (fractions and tangent frozen) and the
buoyancy's vertical stiffness at the surface, -m lift df/dy (:func:`add_sea_jacobian`); the stability bound the
heave stiffness of a floating node, lift 2 / (pi r) at most (:func:`_heave_stiffness`), and the drag's rate at
the speed scale, which includes the waves' orbital speed and the wind
(:func:`ropesim.model.forces.fluid.speed_scale`).

Compiled bundle :class:`Sea` = (scalars, comps, nodes): the waves' scalars then this module's
(:data:`SCALAR_COUNT`), the wave components (:mod:`ropesim.model.waves`), and per node the rows named below.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import Term
from .added_mass import ADDED_MASS_TERM, WITH_ADDED_MASS
from .fluid import (WITH_BODY_DRAG, WITH_FLOW, WITH_FLUID_DRAG, flow_at, flow_scaled, morison_damping,
                    node_tangent)
from ..ramp import ramp_rate
from ..junctions import WITH_JUNCTIONS
from ..layout import junctions, line_volumes, lumped_bodies, per_node
from ..waves import (COMP_ROWS, LEVEL, NODE_ROWS, WAVE_SCALARS, compiled_tables, direct_kinematics,
                     recurrence, recurrence_kinematics, wave_field)
from .. import jit

WITH_SEA = jit.Switch("sea", "a free surface: water below, air above")
WITH_WAVES = jit.Switch("waves", "waves on the sea")
WITH_WAVE_RECURRENCE = jit.Switch("wave_recurrence", "a spectrum's waves: their kinematics by the recurrence over "
                                                     "evenly spaced wave numbers (ropesim.model.waves)")
WITH_MOORDYN_FRACTION = jit.Switch("moordyn_fraction", "[sea] fraction = \"moordyn\": MoorDyn 2's submerged "
                                                       "fraction of the lines")

Sea = namedtuple("Sea", ["scalars", "comps", "nodes"])

# the surface's scalars, after the waves'; GIVEN_WAVES: 1 when the waves' kinematics come from outside;
# WAVES_HELD: 1 while galpha's Newton solve holds the waves' kinematics of its step (:func:`hold_waves`), which it
# does when HOLD_WAVES is 1 (always, but for the test that measures what holding changes)
(AIR_RATIO, WIND_X, WIND_Y, WIND_Z, FRACTION_RULE, STATE_TIME, STATE_VALID,
 GIVEN_WAVES, WAVES_HELD, HOLD_WAVES) = range(WAVE_SCALARS, WAVE_SCALARS + 10)
SCALAR_COUNT = WAVE_SCALARS + 10
CYLINDERS, MOORDYN_RULE = 0.0, 1.0   # FRACTION_RULE: ``[sea] fraction``

# per-node rows of Sea.nodes: constants, then the state of the last evaluation, then scratch
(LIFT_LINE, LIFT_BODY, RADIUS, SPHERE, KN, KT, KB, AN, AT, AB, OWNED, HALF_LO, HALF_HI,
 ETA, UX, UY, UZ, AX, AY, AZ, F_LINE, F_BODY, AT_X, AT_Y, AT_Z) = range(25)
WORK = 25
GIVEN = WORK + NODE_ROWS     # 7 rows as ETA to AZ: the kinematics given from outside
NODE_STATE_ROWS = GIVEN + 7


# ------------------------------------------------------------------------------------- submerged parts


@jit.kernel(inline="always")
def _phi(u):
    """The fraction of a unit disc below a chord u radii above its centre."""
    if u <= -1.0:
        return 0.0
    if u >= 1.0:
        return 1.0
    return (math.acos(-u) + u * math.sqrt(1.0 - u * u)) / math.pi


@jit.kernel(inline="always")
def _g(u):
    """The integral of :func:`_phi` from -1 to u."""
    if u <= -1.0:
        return 0.0
    if u >= 1.0:
        return u
    w = 1.0 - u * u
    return (u * math.acos(-u) + math.sqrt(w) - w * math.sqrt(w) / 3.0) / math.pi


@jit.kernel
def cylinder_fraction(y_node, y_mid, rc, surface):
    """(fraction, its derivative by y_node) of a half segment's cylinder below the plane y = ``surface``: the
    cylinder's axis from height ``y_node`` (the node) to ``y_mid`` (its segment's middle, which moves half as
    much as the node), ``rc`` = r cos(alpha) its radius times the cosine of the axis's slope (module doc)."""
    u0 = (surface - y_node) / rc
    u1 = (surface - y_mid) / rc
    du = u1 - u0
    if abs(du) <= 1e-5:   # (G(u1) - G(u0)) / du would cancel: the mean of Phi by the midpoint rule
        mid = 0.5 * (u0 + u1)
        slope = (2.0 / math.pi) * math.sqrt(1.0 - mid * mid) if -1.0 < mid < 1.0 else 0.0
        return _phi(mid), -0.75 * slope / rc
    f = (_g(u1) - _g(u0)) / du
    return f, -((f - _phi(u0)) / du + 0.5 * (_phi(u1) - f) / du) / rc


@jit.kernel(inline="always")
def _half_piece(x, i, j, surface, r):
    """(fraction, d fraction / d y_i) of the half segment from node i to the middle of its segment to node j."""
    dim = x.shape[0]
    dx = 0.5 * (x[0, j] - x[0, i])
    dy = 0.5 * (x[1, j] - x[1, i])
    dz = 0.5 * (x[2, j] - x[2, i]) if dim == 3 else 0.0
    flat = math.sqrt(dx * dx + dz * dz)
    length = math.sqrt(flat * flat + dy * dy)
    rc = r * flat / length if length > 0.0 else r
    if rc < 1e-12 * r:
        rc = 1e-12 * r
    return cylinder_fraction(x[1, i], x[1, i] + dy, rc, surface)


@jit.kernel
def line_fraction(x, i, around, surface, nodes):
    """(f, df/dy_i) of node i's share of its line below ``surface`` (module doc); (1, 0) on a node without a line
    volume."""
    w_lo, w_hi = nodes[HALF_LO, i], nodes[HALF_HI, i]
    total = w_lo + w_hi
    r = nodes[RADIUS, i]
    if total == 0.0 or r == 0.0:
        return 1.0, 0.0
    f = slope = 0.0
    if w_lo > 0.0:
        a, da = _half_piece(x, i, around[0, i], surface, r)
        f += w_lo * a
        slope += w_lo * da
    if w_hi > 0.0:
        b, db = _half_piece(x, i, around[1, i], surface, r)
        f += w_hi * b
        slope += w_hi * db
    return f / total, slope / total


@jit.kernel(inline="always")
def moordyn_segment_fraction(x, i, j, surface, r):
    """MoorDyn 2's submerged fraction of the segment from node i to node j (i < j) under the plane y =
    ``surface`` (its ``Line::calcSubSeg``, branch for branch): 1 or 0 with both ends below or above, 1/2 with
    the ends at opposite heights, else the share below the surface of the diagonal from the lower end's
    underside to the upper end's top side, each end moved by r cos(alpha) across the axis."""
    dim = x.shape[0]
    z_i, z_j = x[1, i] - surface, x[1, j] - surface
    if z_i <= 0.0 and z_j < 0.0:
        return 1.0
    if z_i > 0.0 and z_j > 0.0:
        return 0.0
    if z_i == -z_j:
        return 0.5
    lower, upper = (z_i, z_j) if z_i < 0.0 else (z_j, z_i)
    dx = x[0, j] - x[0, i]
    dy = x[1, j] - x[1, i]
    dz = x[2, j] - x[2, i] if dim == 3 else 0.0
    flat = math.sqrt(dx * dx + dz * dz)
    length = math.sqrt(flat * flat + dy * dy)
    shift = r * flat / length if length > 0.0 else 0.0   # the vertical part of r times the up-most normal
    lower -= shift
    upper += shift
    return abs(lower) / (abs(lower) + upper)


@jit.kernel(inline="always")
def moordyn_line_fraction(x, i, around, level, nodes):
    """Node i's submerged fraction by MoorDyn 2's rule: its half segments weighted by their unstretched lengths,
    each segment's fraction (:func:`moordyn_segment_fraction`) under the mean of its two nodes' surface heights
    (MoorDyn's ``Line::getStateDeriv``); 1 on a node without a line volume."""
    w_lo, w_hi = nodes[HALF_LO, i], nodes[HALF_HI, i]
    total = w_lo + w_hi
    r = nodes[RADIUS, i]
    if total == 0.0 or r == 0.0:
        return 1.0
    f = 0.0
    for side in range(2):
        w = w_lo if side == 0 else w_hi
        if w > 0.0:
            j = around[side, i]
            surface = level + 0.5 * (nodes[ETA, i] + nodes[ETA, j])
            f += w * moordyn_segment_fraction(x, min(i, j), max(i, j), surface, r)
    return f / total


@jit.kernel(inline="always")
def sphere_fraction(y, surface, radius):
    """(fraction, its derivative by y) of a sphere of ``radius`` centred at height y below ``surface``."""
    u = (surface - y) / radius
    if u <= -1.0:
        return 0.0, 0.0
    if u >= 1.0:
        return 1.0, 0.0
    return (u + 1.0) * (u + 1.0) * (2.0 - u) / 4.0, -0.75 * (1.0 - u * u) / radius


# --------------------------------------------------------------------------------------- the state


@jit.kernel(inline="always")
def _state_holds(x, t, scalars, nodes):
    """True when the state rows already hold positions x at time t (the last call's, stored in AT_X..AT_Z)."""
    if scalars[STATE_VALID] != 1.0 or scalars[STATE_TIME] != t:
        return False
    dim, n = x.shape
    for i in range(n):
        for a in range(dim):
            if nodes[AT_X + a, i] != x[a, i]:
                return False
    return True


@jit.kernel
def water_state(x, p, t):
    """Every node's surface elevation, submerged fractions, the water's velocity and acceleration at positions x
    (D, N) and time t [s] into the sea's state rows (module doc). A call at the positions and time of the last
    returns at once: they depend on (x, t) alone, and sdirk2 asks for them at the same (x, t) for a stage's
    residual and for its Newton matrix."""
    sea = p.sea
    scalars, nodes = sea.scalars, sea.nodes
    dim, n = x.shape
    if _state_holds(x, t, scalars, nodes):
        return
    # within galpha's Newton solve of one step, the kinematics (and a current's) of its first iterate
    keep = scalars[WAVES_HELD] == 1.0 and scalars[STATE_VALID] == 1.0 and scalars[STATE_TIME] == t
    if keep:
        pass
    elif scalars[GIVEN_WAVES] != 0.0:
        for r in range(7):
            for i in range(n):
                nodes[ETA + r, i] = nodes[GIVEN + r, i]
    elif WITH_WAVES:   # only the evaluation the scene's waves take is compiled
        if WITH_WAVE_RECURRENCE:
            recurrence_kinematics(x, t, scalars, sea.comps, nodes[WORK:WORK + NODE_ROWS], nodes[ETA:AZ + 1])
        else:
            direct_kinematics(x, t, scalars, sea.comps, nodes[ETA:AZ + 1])
    else:
        for r in range(ETA, AZ + 1):
            for i in range(n):
                nodes[r, i] = 0.0
    if WITH_FLOW and not keep:
        flow, table = p.flow
        rate = ramp_rate(t, flow[1])
        for i in range(n):
            u0, u1, u2 = flow_at(x[1, i], t, flow, table)
            nodes[UX, i] += u0
            nodes[UY, i] += u1
            nodes[UZ, i] += u2
            if rate != 0.0:
                a0, a1, a2 = flow_scaled(x[1, i], rate, flow, table)
                nodes[AX, i] += a0
                nodes[AY, i] += a1
                nodes[AZ, i] += a2
    level = scalars[LEVEL]
    for i in range(n):
        surface = level + nodes[ETA, i]
        if WITH_MOORDYN_FRACTION:
            nodes[F_LINE, i] = moordyn_line_fraction(x, i, p.neighbours, level, nodes)
        else:
            nodes[F_LINE, i] = line_fraction(x, i, p.neighbours, surface, nodes)[0]
        nodes[F_BODY, i] = sphere_fraction(x[1, i], surface, nodes[SPHERE, i])[0] if nodes[SPHERE, i] > 0.0 else 1.0
    if WITH_ADDED_MASS:
        for i in range(n):
            if nodes[OWNED, i] == 0.0:
                _live_added(p.added_mass, i, i, nodes)
        if WITH_JUNCTIONS:
            points = p.junctions
            for k in range(points.nodes.shape[0]):
                _live_added(points.added, k, points.nodes[k], nodes)
    for i in range(n):
        for a in range(dim):
            nodes[AT_X + a, i] = x[a, i]
    scalars[STATE_TIME] = t
    scalars[STATE_VALID] = 1.0


@jit.kernel
def hold_waves(p, on):
    """Hold the water's kinematics (``on``) through generalized-alpha's Newton solve of one step, or let them go.

    While held, an evaluation at the time of the last one keeps that one's surface elevation, wave and current
    velocity and acceleration at each node instead of recomputing them at the new iterate (the submerged
    fractions, the added mass and the forces are recomputed from them as always). The first iterate is the step's
    predictor X_p = x + (1 - af) (h v + h^2 a_n / 2), within (1 - af) beta h^2 (a_(n+1) - a_n) = O(h^3) of the
    solution: the forces' error, |grad u| O(h^3) ~ k u O(h^3), moves the step's positions by O(h^5), two orders
    below the scheme's own local error, and the solve costs one wave evaluation a step instead of one per
    iteration (100 components on 83 nodes: ~20 us of a ~30 us force evaluation). Both calls invalidate the
    state: what is held is the solve's own first evaluation, and nothing after the solve (the ledger, the
    frames, the health check) sees kinematics held at another position.
    """
    scalars = p.sea.scalars
    scalars[WAVES_HELD] = scalars[HOLD_WAVES] if on else 0.0
    scalars[STATE_VALID] = 0.0


@jit.kernel(inline="always")
def _live_added(added, k, i, nodes):
    """Column k of the live added-mass coefficients (2, K) from node i's bases and submerged fractions."""
    fl, fb = nodes[F_LINE, i], nodes[F_BODY, i]
    added[0, k] = nodes[AN, i] * fl + nodes[AB, i] * fb
    added[1, k] = nodes[AT, i] * fl + nodes[AB, i] * fb


# -------------------------------------------------------------------------------------------- forces


@jit.kernel
def add_sea_forces(x, v, acc, p):
    """Add the buoyancy lost above the surface and the water's inertia force on the submerged part (module doc)
    as accelerations [m/s^2], from the state :func:`water_state` left; returns their power [W]."""
    nodes = p.sea.nodes
    dim, n = x.shape
    power = 0.0
    for i in range(n):
        fl, fb = nodes[F_LINE, i], nodes[F_BODY, i]
        lift = nodes[LIFT_LINE, i] * (1.0 - fl) + nodes[LIFT_BODY, i] * (1.0 - fb)
        a0 = a1 = a2 = 0.0
        if nodes[KN, i] != 0.0 or nodes[KT, i] != 0.0 or nodes[KB, i] != 0.0:
            w0, w1, w2 = nodes[AX, i], nodes[AY, i], nodes[AZ, i] if dim == 3 else 0.0
            q0, q1, q2 = node_tangent(x, i, p.neighbours)
            along = w0 * q0 + w1 * q1 + w2 * q2
            kn, kt, kb = fl * nodes[KN, i], fl * nodes[KT, i], fb * nodes[KB, i]
            a0 = kn * (w0 - along * q0) + kt * along * q0 + kb * w0
            a1 = kn * (w1 - along * q1) + kt * along * q1 + kb * w1
            a2 = kn * (w2 - along * q2) + kt * along * q2 + kb * w2
        a1 -= lift
        acc[0, i] += a0
        acc[1, i] += a1
        power += (a0 * v[0, i] + a1 * v[1, i]) / p.inv_mass[i]
        if dim == 3:
            acc[2, i] += a2
            power += a2 * v[2, i] / p.inv_mass[i]
    return power


@jit.kernel(inline="always")
def _relative(v, i, nodes, scalars, water):
    """Node i's velocity relative to the water (``water``) or to the wind."""
    dim = v.shape[0]
    v2 = v[2, i] if dim == 3 else 0.0
    if water:
        return v[0, i] - nodes[UX, i], v[1, i] - nodes[UY, i], v2 - (nodes[UZ, i] if dim == 3 else 0.0)
    return v[0, i] - scalars[WIND_X], v[1, i] - scalars[WIND_Y], v2 - (scalars[WIND_Z] if dim == 3 else 0.0)


@jit.kernel
def add_sea_drag(x, v, acc, p):
    """Add the drag of the water on each node's submerged part and of the air on the rest (module doc) as
    accelerations [m/s^2]; returns its power [W]."""
    sea = p.sea
    nodes, scalars = sea.nodes, sea.scalars
    ratio = scalars[AIR_RATIO]
    c_n, c_t = p.fluid_drag[0], p.fluid_drag[1]
    dim, n = x.shape
    power = 0.0
    for i in range(n):
        fl, fb = nodes[F_LINE, i], nodes[F_BODY, i]
        f0 = f1 = f2 = 0.0
        q0 = q1 = q2 = 0.0
        if WITH_FLUID_DRAG:
            q0, q1, q2 = node_tangent(x, i, p.neighbours)
        for part in range(2):
            water = part == 0
            r0, r1, r2 = _relative(v, i, nodes, scalars, water)
            if WITH_FLUID_DRAG:
                share = fl if water else ratio * (1.0 - fl)
                if share > 0.0:
                    along = r0 * q0 + r1 * q1 + r2 * q2
                    n0, n1, n2 = r0 - along * q0, r1 - along * q1, r2 - along * q2
                    cn = share * c_n[i] * p.node_length[i] * math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
                    ct = share * c_t[i] * p.node_length[i] * abs(along)
                    f0 -= cn * n0 + ct * along * q0
                    f1 -= cn * n1 + ct * along * q1
                    f2 -= cn * n2 + ct * along * q2
            if WITH_BODY_DRAG:
                share = fb if water else ratio * (1.0 - fb)
                if share > 0.0 and p.body_drag[i] > 0.0:
                    cb = share * p.body_drag[i] * math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
                    f0 -= cb * r0
                    f1 -= cb * r1
                    f2 -= cb * r2
        inv_m = p.inv_mass[i]
        acc[0, i] += f0 * inv_m
        acc[1, i] += f1 * inv_m
        power += f0 * v[0, i] + f1 * v[1, i]
        if dim == 3:
            acc[2, i] += f2 * inv_m
            power += f2 * v[2, i]
    return power


@jit.kernel
def add_sea_jacobian(x, v, band, beta, free, p):
    """Add beta C + beta^2 K of the sea to the Newton matrix's node blocks, from the state :func:`water_state`
    left: the drag's damping on the wet and the dry part (fractions and tangent frozen, as
    :func:`ropesim.model.forces.fluid.add_fluid_jacobian` does), and the buoyancy's vertical stiffness at the
    surface, -m lift df/dy >= 0 (the neighbours held)."""
    sea = p.sea
    nodes, scalars = sea.nodes, sea.scalars
    ratio = scalars[AIR_RATIO]
    level = scalars[LEVEL]
    c_n, c_t = p.fluid_drag[0], p.fluid_drag[1]
    dim, n = x.shape
    for i in range(n):
        if not free[i]:
            continue
        fl, fb = nodes[F_LINE, i], nodes[F_BODY, i]
        m = 1.0 / p.inv_mass[i]
        surface = level + nodes[ETA, i]
        stiffness = 0.0
        if nodes[LIFT_LINE, i] != 0.0 and 0.0 < fl < 1.0:
            stiffness -= m * nodes[LIFT_LINE, i] * line_fraction(x, i, p.neighbours, surface, nodes)[1]
        if nodes[LIFT_BODY, i] != 0.0 and 0.0 < fb < 1.0:
            stiffness -= m * nodes[LIFT_BODY, i] * sphere_fraction(x[1, i], surface, nodes[SPHERE, i])[1]
        band[0, i * dim + 1] += beta * beta * stiffness
        q = (0.0, 0.0, 0.0)
        if WITH_FLUID_DRAG:
            q = node_tangent(x, i, p.neighbours)
        for part in range(2):
            water = part == 0
            r = _relative(v, i, nodes, scalars, water)
            share_line = fl if water else ratio * (1.0 - fl)
            share_body = fb if water else ratio * (1.0 - fb)
            along = r[0] * q[0] + r[1] * q[1] + r[2] * q[2]
            nv = (r[0] - along * q[0], r[1] - along * q[1], r[2] - along * q[2])
            speed_n = math.sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2])
            cn = share_line * c_n[i] * p.node_length[i] if WITH_FLUID_DRAG else 0.0
            ct = share_line * c_t[i] * p.node_length[i] if WITH_FLUID_DRAG else 0.0
            c_b = share_body * p.body_drag[i] if WITH_BODY_DRAG else 0.0
            speed = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) if c_b > 0.0 else 0.0
            for a in range(dim):
                for b in range(a + 1):
                    c = 0.0
                    if cn > 0.0 or ct > 0.0:
                        c += morison_damping(a, b, q, nv, speed_n, along, cn, ct)
                    if speed > 0.0:
                        c += c_b * (speed * (1.0 if a == b else 0.0) + r[a] * r[b] / speed)
                    band[a - b, i * dim + b] += beta * c


# ------------------------------------------------------------------------------------------- Python


def sea_nodes(scene, layout) -> np.ndarray:
    """The constant per-node rows of :class:`Sea` (module doc): the lift of the line and of the body, their
    radii, the inertia force's factors, the added masses' bases (and which nodes' the free points' solve owns)
    and each node's unstretched half segments."""
    n = len(layout.mass)
    nodes = np.zeros((NODE_STATE_ROWS, n))
    rho = scene.fluid.density
    line_volume = line_volumes(layout.lines, layout.node_length)
    body_volume, body_ca = np.zeros(n), np.zeros(n)
    for body in lumped_bodies(scene, layout.lines):
        body_volume[body.node] += body.volume
        body_ca[body.node] = body.ca
    if scene.buoyancy is not None:
        g = scene.gravity.g
        nodes[LIFT_LINE] = rho * g * line_volume / layout.mass
        nodes[LIFT_BODY] = rho * g * body_volume / layout.mass
    froude = 1.0 if scene.buoyancy is not None else 0.0   # the pressure field's dynamic side, with buoyancy
    lines = scene.added_mass is not None   # as the added-mass term lumps them
    ca_n = per_node(layout.lines, n, [line.ca_normal for line in layout.lines]) if lines else np.zeros(n)
    ca_t = per_node(layout.lines, n, [line.ca_tangential for line in layout.lines]) if lines else np.zeros(n)
    ca_b = body_ca if ADDED_MASS_TERM.declared(scene) else np.zeros(n)
    free = ~layout.held
    nodes[KN] = np.where(free, rho * line_volume * (froude + ca_n) / layout.mass, 0.0)
    nodes[KT] = np.where(free, rho * line_volume * (froude + ca_t) / layout.mass, 0.0)
    nodes[KB] = np.where(free, rho * body_volume * (froude + ca_b) / layout.mass, 0.0)
    nodes[AN] = np.where(free, rho * line_volume * ca_n, 0.0)
    nodes[AT] = np.where(free, rho * line_volume * ca_t, 0.0)
    nodes[AB] = np.where(free, rho * body_volume * ca_b, 0.0)
    owned = [i for group in junctions(scene, layout.lines) for i in group]
    nodes[OWNED, owned] = 1.0
    nodes[RADIUS] = per_node(layout.lines, n, [0.5 * (line.diameter or 0.0) for line in layout.lines])
    nodes[SPHERE] = np.cbrt(3.0 * body_volume / (4.0 * math.pi))
    for line in layout.lines:
        half = 0.5 * line.segment_length
        nodes[HALF_LO, line.first:line.end] = half
        nodes[HALF_HI, line.first:line.end] = half
        if not line.closed:
            nodes[HALF_LO, line.first] = 0.0
            nodes[HALF_HI, line.end - 1] = 0.0
    return nodes


def sea_switches(scene) -> set[str]:
    """The switches of a scene's sea beyond :data:`WITH_SEA`: its waves, the evaluation they take and the
    lines' fraction rule (none without ``[sea]``)."""
    if scene.sea is None:
        return set()
    on = {WITH_MOORDYN_FRACTION.name} if scene.sea.fraction == "moordyn" else set()
    field = wave_field(scene)
    if field is not None:
        on.add(WITH_WAVES.name)
        if recurrence(field.components):
            on.add(WITH_WAVE_RECURRENCE.name)
    return on


def _params(scene, layout) -> Sea:
    field = wave_field(scene)
    scalars = np.zeros(SCALAR_COUNT)
    if field is not None:
        scalars[:WAVE_SCALARS], comps = compiled_tables(field)
    else:
        comps = np.zeros((COMP_ROWS, 0))
        scalars[LEVEL] = scene.sea.level
    scalars[AIR_RATIO] = scene.sea.air_density / scene.fluid.density
    if scene.sea.wind is not None:
        scalars[WIND_X:WIND_X + scene.dimension] = scene.sea.wind
    scalars[FRACTION_RULE] = MOORDYN_RULE if scene.sea.fraction == "moordyn" else CYLINDERS
    scalars[HOLD_WAVES] = 1.0
    return Sea(scalars, comps, sea_nodes(scene, layout))


def no_sea() -> Sea:
    """What a scene without a ``[sea]`` gets: the same types, nothing in them."""
    return Sea(np.zeros(SCALAR_COUNT), np.zeros((COMP_ROWS, 0)), np.zeros((NODE_STATE_ROWS, 0)))


def _heave_stiffness(model) -> float:
    """The largest omega^2 [1/s^2] of a node heaving at the surface: m lift (df/dy) / m, at most lift 2 / (pi r)
    for a line (a horizontal cylinder half under) and lift 3 / (4 R) for a point body's sphere."""
    nodes = model.params.sea.nodes
    free = ~model.held
    with np.errstate(divide="ignore", invalid="ignore"):
        line = np.where(nodes[RADIUS] > 0, nodes[LIFT_LINE] * 2.0 / (math.pi * nodes[RADIUS]), 0.0)
        body = np.where(nodes[SPHERE] > 0, nodes[LIFT_BODY] * 0.75 / nodes[SPHERE], 0.0)
    return float(np.max((line + body)[free], initial=0.0))


SEA_TERM = Term("sea", WITH_SEA, _params, no_sea, ledger="fluid", velocity=True, node_stiffness=_heave_stiffness)
"""The free surface: the buoyancy above it taken away, the water's inertia force on each node's submerged part
and the drag split between water and air (the waves' kinematics within)."""
