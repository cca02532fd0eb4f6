"""The string shooter's drive box (the write-up's thrower).

A node inside the box |x - cx| < L/2, |y - cy| < W/2 (and |z - cz| < W/2 in 3-D) is driven along +x
towards v_max, F_x = b_thrower (v_max - v_x), and held to the centre line by a damped spring that also
cancels its weight: a_y = g - omega0^2 (y - cy) - 2 zeta omega0 v_y (likewise in z, without g).

A launch angle alpha (``thrower.angle``) turns the box and its drive about its centre in the x-y plane, positive
counter-clockwise (launching upward for a throw towards +x): with e = (cos alpha, sin alpha) along the box and
n = (-sin alpha, cos alpha) across it, u = e.(x - c) and q = n.(x - c) replace x - cx and y - cy above, the drive
acts along e, a_e = (b_thrower / m)(v_max - v.e), and the centring spring across it, a_n = -omega0^2 q -
2 zeta omega0 v.n; the weight is cancelled as before (a_y += g, whatever the angle), and z is unchanged. At
alpha = 0 (the default) the kernels run the unrotated arithmetic itself, so unrotated scenes give the same
numbers bit for bit.

With an edge width w > 0 (``thrower.edge_width``) the box's edges are smoothed: each force is weighted by
S(L/2 - |x - cx|) S(W/2 - |y - cy|) [S(W/2 - |z - cz|)], with S(d) = (1 + tanh(d / w)) / 2, a smooth step of
width w instead of the sharp in-or-out (w = 0, the default). Smooth forces let higher-order integrators keep
their order and the stiff integrator's Newton solve converge; see the README's "Accuracy and stability".

Parameters, packed in one float64 array: cx, cy, cz, L/2, W/2, v_max, b_thrower, omega0^2, 2 zeta omega0, w,
cos alpha, sin alpha.
"""

import math

import numpy as np

from . import Term
from .. import jit

WITH_THROWER = jit.Switch("thrower", "the string shooter's drive box")
THROWER_PARAMS = 12
SMOOTH_CUTOFF = 20.0  # beyond 20 widths tanh is 1 to double precision: the weight is exactly 0 or 1


@jit.kernel
def smooth_step(d, w):
    """The indicator of d > 0, smoothed over a width w: (1 + tanh(d / w)) / 2; the sharp step when w = 0."""
    if w == 0.0:
        return 1.0 if d > 0.0 else 0.0
    z = d / w
    if z > SMOOTH_CUTOFF:
        return 1.0
    if z < -SMOOTH_CUTOFF:
        return 0.0
    return 0.5 * (1.0 + math.tanh(z))


@jit.kernel
def box_of(p):
    """The box's centre, half-length, half-width, edge width and direction (cx, cy, cz, L/2, W/2, w, cos alpha,
    sin alpha), a tuple of floats.

    The per-node weight takes this tuple and the node's coordinates, all passed by value: a helper taking
    arrays costs an atomic reference-count update per array and call, which made a shooter step six times
    slower (12.9 us against 2.0 at N = 60).
    """
    return p[0], p[1], p[2], p[3], p[4], p[9], p[10], p[11]


@jit.kernel
def weight_at(px, py, pz, three_d, box):
    """How much a node at (px, py[, pz]) is inside the box ``box`` (see :func:`box_of`), 0 to 1 (exactly 0 or 1
    with sharp edges); ``pz`` is ignored unless ``three_d``."""
    cx, cy, cz, half_length, half_width, w, ca, sa = box
    if sa == 0.0 and ca == 1.0:     # unrotated: the original arithmetic, bit for bit
        along, across = abs(px - cx), abs(py - cy)
    else:
        dx, dy = px - cx, py - cy
        along, across = abs(ca * dx + sa * dy), abs(ca * dy - sa * dx)
    if w == 0.0:
        if along >= half_length or across >= half_width:
            return 0.0
        if three_d and abs(pz - cz) >= half_width:
            return 0.0
        return 1.0
    s = smooth_step(half_length - along, w) * smooth_step(half_width - across, w)
    if three_d:
        s *= smooth_step(half_width - abs(pz - cz), w)
    return s


@jit.kernel
def box_weight(x, i, p):
    """How much node i is inside the box, 0 to 1 (exactly 0 or 1 with sharp edges)."""
    three_d = x.shape[0] == 3
    return weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, box_of(p))


@jit.kernel
def inside_box(x, i, p):
    """True when node i lies inside the box described by ``p`` (its sharp edges, whatever the edge width)."""
    three_d = x.shape[0] == 3
    cx, cy, cz, half_length, half_width, _, ca, sa = box_of(p)
    sharp = (cx, cy, cz, half_length, half_width, 0.0, ca, sa)
    return weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, sharp) > 0.0


@jit.kernel
def add_thrower(x, v, acc, inv_mass, p, g):
    """Add the box's drive and centring accelerations [m/s^2] to every node inside it."""
    n = x.shape[1]
    w2 = p[7]
    c = p[8]
    box = box_of(p)
    three_d = x.shape[0] == 3
    ca, sa = p[10], p[11]
    if sa == 0.0 and ca == 1.0:     # unrotated: the original arithmetic, bit for bit
        for i in range(n):
            s = weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, box)
            if s == 0.0:
                continue
            acc[0, i] += s * (p[6] * inv_mass[i] * (p[5] - v[0, i]))
            acc[1, i] += s * (g - w2 * (x[1, i] - p[1]) - c * v[1, i])
            if x.shape[0] == 3:
                acc[2, i] += s * (-w2 * (x[2, i] - p[2]) - c * v[2, i])
        return
    for i in range(n):
        s = weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, box)
        if s == 0.0:
            continue
        across = ca * (x[1, i] - p[1]) - sa * (x[0, i] - p[0])
        a_e = p[6] * inv_mass[i] * (p[5] - (ca * v[0, i] + sa * v[1, i]))
        a_n = -w2 * across - c * (ca * v[1, i] - sa * v[0, i])
        acc[0, i] += s * (ca * a_e - sa * a_n)
        acc[1, i] += s * (sa * a_e + ca * a_n + g)
        if three_d:
            acc[2, i] += s * (-w2 * (x[2, i] - p[2]) - c * v[2, i])



@jit.kernel
def add_thrower_jacobian(x, band, beta, mass, free, p):
    """Add the box's node blocks to the stiff integrator's Newton matrix (see :mod:`ropesim.model.jacobian`).

    For a node inside the box (weight s): beta s b_thrower e e^T (the drive's damping along the box's direction
    e, beta times -d force / d v) and s m (beta^2 omega0^2 + beta 2 zeta omega0) across it (n n^T, and along z:
    the centring spring and its damping). Unrotated, e is x and these are the diagonal's entries.
    """
    dim, n = x.shape
    three_d = dim == 3
    box = box_of(p)
    b2 = beta * beta
    ca, sa = p[10], p[11]
    rotated = not (sa == 0.0 and ca == 1.0)
    for i in range(n):
        if not free[i]:
            continue
        sb = weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, box)
        if sb > 0.0:
            drive = sb * beta * p[6]
            centring = sb * mass[i] * (b2 * p[7] + beta * p[8])
            if rotated:
                band[0, i * dim] += drive * ca * ca + centring * sa * sa
                band[1, i * dim] += (drive - centring) * ca * sa
                band[0, i * dim + 1] += drive * sa * sa + centring * ca * ca
                if three_d:
                    band[0, i * dim + 2] += centring
            else:
                band[0, i * dim] += drive
                for d in range(1, dim):
                    band[0, i * dim + d] += centring

def _params(scene, mass) -> np.ndarray:
    t = scene.thrower
    centre = list(t.center) + [0.0] * (3 - scene.dimension)
    w = t.omega0
    return np.array([*centre, t.length / 2, t.width / 2, t.v_max, t.b_thrower, w * w, 2 * t.damping_ratio * w,
                     t.edge_width, *t.direction])    # angle 0: (1.0, 0.0) exactly


def _damping(model) -> float:
    """The drive's b_thrower / m on the lightest free node, or the centring spring's 2 zeta omega0 [1/s]."""
    t = model.scene.thrower
    free_mass = model.mass[~model.held] if (~model.held).any() else model.mass
    return max(t.b_thrower / float(free_mass.min()), 2 * t.damping_ratio * t.resolved_omega0)


def _empty() -> np.ndarray:
    p = np.zeros(THROWER_PARAMS)
    p[10] = 1.0   # unrotated
    return p


THROWER = Term("thrower", WITH_THROWER, _params, _empty,
               node_stiffness=lambda model: model.scene.thrower.resolved_omega0 * model.scene.thrower.resolved_omega0, damping=_damping, ledger="box")
