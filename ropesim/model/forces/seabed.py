"""The seabed (or ground): a plane that pushes nodes out of it, damps them, and rubs them with friction.

The plane is y = height + tan(a) x (a = ``slope``), with the unit normal n = (-sin a, cos a[, 0]) pointing out
of it. A node at distance s = n . (x - (0, height[, 0])) from it is in contact while s < 0, sunk a depth
delta = -s. On its footprint A = contact_width x L (L its share of unstretched length; MoorDyn's d l) it feels

- the contact spring k delta A along n (``stiffness`` k per unit area, MoorDyn's kBot): conservative, energy
  k delta^2 A / 2, a position-only term;
- the contact damping c |v . n| A f(delta) along n while the node moves into the plane (``damping`` c,
  MoorDyn's cBot), none while it moves out: the seabed resists being pressed but never holds a node back
  (MoorDyn damps both ways, which makes its seabed sticky: a node lifting off at 0.1 m/s is held by c A v, for
  a 10 cm chain's 3 m node 10 kN, while it rises through its millimetre of sink). f = min(1, delta / delta_d)
  grows it over the first delta_d = 1e-3 times the footprint's width of penetration (the widest line's in a
  system; 0.1 mm for a 10 cm chain, less than what it sinks under its own weight), so that the contact force has no jump where a moving
  node touches the plane. Both choices keep the normal force continuous and growing with depth, which the
  stiff method's Newton solve needs (a force that jumps may leave a stage equation without a root). With
  ``damping_both_ways`` (for equal physics with MoorDyn) the damping is MoorDyn's instead: -c (v . n) A along
  n, in both directions, at full strength from the first contact; except with the ``galpha`` integrator, whose
  Newton solve meets that jump at every landing and lift-off (c A |v . n|, 1.3 kN for WD0050's chain landing at
  0.1 m/s: at 0.1 s steps it failed at most touchdowns): there it grows in over the same delta_d,
  -c (v . n) A f (the regularisation; its effect on WD0050's fairlead tension is measured on the accuracy page,
  "Moorings at the sea's time scale"). ropesim's own law has a kink at rest instead, where the damping switches
  on (v . n < 0) and off: a resting node's Newton iterates flipped between damped and free, and galpha failed
  Newton at the thrown spar's second 0.1 s step. For galpha its min(v . n, 0) is C1 over v_reg
  (``friction_speed``): -v_reg (2 u^2 - u^3), u = -v . n / v_reg, for -v_reg < v . n < 0 (:func:`inward`;
  monotone, never pulling a node in; exact outside);
- friction against its sliding velocity v_s = v - (v . n) n, split along the rope (the node tangent projected
  on the plane, t_s) and across it: F = -N (mu_axial (v_s . t_s) t_s + mu (v_s - (v_s . t_s) t_s)) /
  sqrt(|v_s|^2 + v_reg^2), N = k delta A the spring's normal load. Well above v_reg (``friction_speed``) this
  is Coulomb's mu N against the motion; below it, a steep linear drag (the regularisation: friction stays a
  smooth function of the state, which explicit and implicit methods both need).

The damping and friction depend on velocity; their work is the energy ledger's ``seabed_work``.

Parameters: ``seabed`` = (scalars [height, tan a, cos a, sin a, k, c, mu, mu_axial, v_reg, delta_d,
both ways (1), both ways grown in over delta_d (2, galpha's), into the plane only (0) or so with its switch
smoothed over v_reg (-1, galpha's)], footprint (N,) [m^2]).
"""

from __future__ import annotations

import math

import numpy as np

from . import Term
from ..layout import per_node
from .fluid import node_tangent
from .. import jit

WITH_SEABED = jit.Switch("seabed", "the seabed's contact and friction")
SEABED_PARAMS = 11
DAMPING_DEPTH = 1e-3   # delta_d / the footprint's width: the depth over which the contact damping grows


@jit.kernel(inline="always")
def depth(px, py, bed):
    """How far a point is sunk below the plane along its normal [m] (negative above it)."""
    return (bed[0] + bed[1] * px - py) * bed[2]


@jit.kernel(inline="always")
def inward(vn, scale):
    """min(v_n, 0) made C1 over -scale < v_n < 0 [m/s]: -scale (2 u^2 - u^3), u = -v_n / scale, there (exact
    outside, rising monotonically: slope u (4 - 3 u) in 0..4/3, 0 at rest); galpha's one-way damping switch."""
    if vn >= 0.0:
        return 0.0
    if vn <= -scale:
        return vn
    u = -vn / scale
    return -scale * u * u * (2.0 - u)


@jit.kernel(inline="always")
def inward_slope(vn, scale):
    """d inward / d v_n."""
    if vn >= 0.0:
        return 0.0
    if vn <= -scale:
        return 1.0
    u = -vn / scale
    return u * (4.0 - 3.0 * u)


@jit.kernel
def add_seabed_contact(x, acc, inv_mass, seabed):
    """Add the contact spring's acceleration k delta A n / m [m/s^2] of every node in contact."""
    bed, area = seabed
    dim, n = x.shape
    nx, ny = -bed[3], bed[2]
    for i in range(n):
        sunk = depth(x[0, i], x[1, i], bed)
        if sunk > 0.0:
            f = bed[4] * sunk * area[i] * inv_mass[i]
            acc[0, i] += f * nx
            acc[1, i] += f * ny


@jit.kernel
def add_seabed_friction(x, v, acc, inv_mass, seabed, around):
    """Add the contact damping and friction (see the module doc) as accelerations; returns their power [W]."""
    bed, area = seabed
    dim, n = x.shape
    nx, ny = -bed[3], bed[2]
    k, c, mu, mu_axial, v_reg = bed[4], bed[5], bed[6], bed[7], bed[8]
    power = 0.0
    for i in range(n):
        sunk = depth(x[0, i], x[1, i], bed)
        if sunk <= 0.0:
            continue
        vz = v[2, i] if dim == 3 else 0.0
        vn = v[0, i] * nx + v[1, i] * ny
        if bed[10] > 0.0:
            damp = c * area[i] * vn   # MoorDyn's: both ways, at full strength
            if bed[10] > 1.0:   # galpha's: both ways, grown in over delta_d
                damp *= min(1.0, sunk / bed[9])
        elif bed[10] < 0.0:   # galpha's: into the plane only, the switch at v . n = 0 smoothed over v_reg
            damp = c * area[i] * min(1.0, sunk / bed[9]) * inward(vn, v_reg)
        else:
            damp = c * area[i] * min(1.0, sunk / bed[9]) * min(vn, 0.0)   # resists motion into the plane only
        fx = -damp * nx
        fy = -damp * ny
        fz = 0.0
        if mu > 0.0 or mu_axial > 0.0:
            sx, sy, sz = v[0, i] - vn * nx, v[1, i] - vn * ny, vz   # sliding velocity, in the plane
            qx, qy, qz = node_tangent(x, i, around)
            qn = qx * nx + qy * ny
            tx, ty, tz = qx - qn * nx, qy - qn * ny, qz
            tl = math.sqrt(tx * tx + ty * ty + tz * tz)
            along = 0.0
            if tl > 0.0:
                tx, ty, tz = tx / tl, ty / tl, tz / tl
                along = sx * tx + sy * ty + sz * tz
            scale = k * sunk * area[i] / math.sqrt(sx * sx + sy * sy + sz * sz + v_reg * v_reg)
            ax, ay, az = along * tx, along * ty, along * tz
            fx -= scale * (mu_axial * ax + mu * (sx - ax))
            fy -= scale * (mu_axial * ay + mu * (sy - ay))
            fz -= scale * (mu_axial * az + mu * (sz - az))
        acc[0, i] += fx * inv_mass[i]
        acc[1, i] += fy * inv_mass[i]
        power += fx * v[0, i] + fy * v[1, i]
        if dim == 3:
            acc[2, i] += fz * inv_mass[i]
            power += fz * v[2, i]
    return power


@jit.kernel
def seabed_energy(x, seabed):
    """The contact springs' energy, sum of k delta^2 A / 2 [J]."""
    bed, area = seabed
    e = 0.0
    for i in range(x.shape[1]):
        sunk = depth(x[0, i], x[1, i], bed)
        if sunk > 0.0:
            e += 0.5 * bed[4] * sunk * sunk * area[i]
    return e


@jit.kernel
def add_seabed_jacobian(x, v, band, beta, free, seabed, friction):
    """Add each contact's node block to the Newton matrix (:mod:`ropesim.model.jacobian`): beta^2 k A n n^T;
    on a node moving in, the damping's beta c A f n n^T and, where it grows with depth (delta < delta_d), the
    stiffness that growth adds, beta^2 c A |v . n| / delta_d n n^T; and with ``friction``
    beta mu N / sqrt(|v_s|^2 + v_reg^2) across the normal (the friction's damping at low speed, its
    direction's turning left out)."""
    bed, area = seabed
    dim, n = x.shape
    normal = (-bed[3], bed[2], 0.0)
    mu = max(bed[6], bed[7])
    for i in range(n):
        if not free[i]:
            continue
        sunk = depth(x[0, i], x[1, i], bed)
        if sunk <= 0.0:
            continue
        vn = v[0, i] * normal[0] + v[1, i] * normal[1]
        along_n = beta * beta * bed[4] * area[i]
        if bed[10] > 1.0:
            along_n += beta * bed[5] * area[i] * min(1.0, sunk / bed[9])
            if sunk < bed[9] and vn < 0.0:   # its growth's stiffness, where positive
                along_n -= beta * beta * bed[5] * area[i] * vn / bed[9]
        elif bed[10] > 0.0:
            along_n += beta * bed[5] * area[i]
        elif bed[10] < 0.0:
            along_n += beta * bed[5] * area[i] * min(1.0, sunk / bed[9]) * inward_slope(vn, bed[8])
            if sunk < bed[9]:
                along_n -= beta * beta * bed[5] * area[i] * inward(vn, bed[8]) / bed[9]
        elif vn < 0.0:
            along_n += beta * bed[5] * area[i] * min(1.0, sunk / bed[9])
            if sunk < bed[9]:
                along_n -= beta * beta * bed[5] * area[i] * vn / bed[9]
        slide = 0.0
        if friction and mu > 0.0:
            vz = v[2, i] if dim == 3 else 0.0
            sx, sy = v[0, i] - vn * normal[0], v[1, i] - vn * normal[1]
            slide = beta * mu * bed[4] * sunk * area[i] / math.sqrt(sx * sx + sy * sy + vz * vz + bed[8] * bed[8])
        for a in range(dim):
            for b in range(a + 1):
                nn = normal[a] * normal[b]
                band[a - b, i * dim + b] += along_n * nn + slide * ((1.0 if a == b else 0.0) - nn)


def _params(scene, layout) -> tuple:
    bed = scene.seabed
    a = math.radians(bed.slope)
    n = len(layout.mass)
    width = (np.full(n, bed.contact_width) if bed.contact_width is not None
             else per_node(layout.lines, n, [line.diameter or 0.0 for line in layout.lines]))
    scalars = np.array([bed.height, math.tan(a), math.cos(a), math.sin(a), bed.stiffness, bed.damping, bed.friction,
                        bed.friction if bed.friction_axial is None else bed.friction_axial, bed.friction_speed,
                        DAMPING_DEPTH * float(width.max(initial=0.0)), 1.0 if bed.damping_both_ways else 0.0])
    if scene.integrator.method == "galpha":   # forces without a jump or a kink in v . n for its Newton solve:
        scalars[10] = 2.0 if bed.damping_both_ways else -1.0   # MoorDyn's law grown in over delta_d; the one-way
        # law's switch at rest smoothed over v_reg
    return scalars, width * layout.node_length


def _energy(model, x: np.ndarray) -> np.ndarray:
    """k delta^2 A / 2 summed over the nodes [J], for frames x (..., N, D)."""
    bed, area = model.params.seabed
    x = np.asarray(x)
    sunk = np.maximum((bed[0] + bed[1] * x[..., 0] - x[..., 1]) * bed[2], 0.0)
    return 0.5 * bed[4] * np.einsum("...n,n->...", sunk * sunk, area)


def _stiffness(model) -> float:
    """The contact spring's omega^2 on the lightest-loaded node, k A / m [1/s^2]."""
    bed, area = model.params.seabed
    return float(np.max(bed[4] * area / model.mass, initial=0.0))


def _damping(model) -> float:
    """The contact's damping rate c A / m, and the friction's low-speed rate mu g / v_reg (N ~ m g) [1/s]."""
    bed, area = model.params.seabed
    g = model.scene.gravity.g if model.scene.gravity is not None else 9.81
    return float(np.max(bed[5] * area / model.mass, initial=0.0)) + max(bed[6], bed[7]) * g / bed[8]


SEABED_TERM = Term("seabed", WITH_SEABED, _params, lambda: (np.zeros(SEABED_PARAMS), np.zeros(0)), energy=_energy,
                   node_stiffness=_stiffness, damping=_damping, ledger="seabed", velocity=True, label="seabed")
"""The seabed: its contact spring (conservative: ``energy``) in the positions-only part of the term list, its
damping and friction (booked as ``seabed_work``) in the velocity part."""
