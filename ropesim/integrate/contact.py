"""Exact velocity kicks for nodes touching the thrower box or a guide circle.

The box's and guides' forces are linear in velocity: inside the box a_x = (b_thrower / m)(v_max - v_x) and
a_y = ... - 2 zeta omega0 v_y, in a circle a_r = ... - 2 zeta omega0 v_r. Evaluated at the velocity a kick starts
from, as a plain kick does, they make the kick an explicit Euler step of v' = a(x, v), and every splitting
scheme drops to first order on the shooter. But with x frozen, as it is during a kick, the kick's equation is
linear, v' = b - A v, with A = gamma_drag I + Gamma(x) (Gamma: the box's diag(s b_thrower / m, s c, s c), turned
with the box when it has a launch angle (s b_thrower / m e e^T + s c n n^T in x-y), plus each circle's weight
times c r_hat r_hat^T) and b = a(x, v0) + Gamma v0, so it is solved exactly:

    v(tau) = e^(-A tau) v0 + A^-1 (I - e^(-A tau)) b,

A's x-y block diagonalised in closed form (it is symmetric 2 x 2), z separately. The splitting schemes then
compose exact flows again and keep their orders (on the smoothed shooter; with sharp edges nothing converges
anyway). Used for scenes with smoothed edges (``edge_width`` > 0), so sharp-edged scenes run exactly as before.
A one-sided circle's smooth release depends on v_r nonlinearly: it is frozen at v0 (not exact).
"""

import math


from ..model.forces.thrower import box_of, smooth_step, weight_at
from ..model.terms import WITH_GUIDES, WITH_THROWER
from ..model import jit


@jit.kernel
def _phi(lam, tau):
    """(1 - e^(-lam tau)) / lam, and tau at lam = 0."""
    z = lam * tau
    if abs(z) < 1e-12:
        return tau
    return -math.expm1(-z) / lam


@jit.kernel
def contact_rates(x, v, i, inv_mass, thrower, guides, box, three_d):
    """The rates [1/s] (gxx, gxy, gyy, gzz) of the velocity-linear forces the box and the circles put on node
    ``i``: the drive's and the centring's along and across the box (rotated by the launch angle), and each
    circle's pull along its radius."""
    ca, sa = thrower[10], thrower[11]
    gxx = gxy = gyy = gzz = 0.0
    outside = 1.0
    if WITH_THROWER:
        s = weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, box)
        outside = 1.0 - s
        if s > 0.0:
            if not (sa == 0.0 and ca == 1.0):     # the drive's rate along e = (ca, sa), the centring's across it
                drive, centring = s * thrower[6] * inv_mass[i], s * thrower[8]
                gxx += drive * ca * ca + centring * sa * sa
                gxy += (drive - centring) * ca * sa
                gyy += drive * sa * sa + centring * ca * ca
                gzz += centring
            else:
                gxx += s * thrower[6] * inv_mass[i]
                gyy += s * thrower[8]
                gzz += s * thrower[8]
    if WITH_GUIDES and outside > 0.0:
        for c in range(guides.shape[0]):
            dx = x[0, i] - guides[c, 0]
            dy = x[1, i] - guides[c, 1]
            r = math.sqrt(dx * dx + dy * dy)
            weight = outside * smooth_step(guides[c, 2] - r, guides[c, 6])
            if weight == 0.0 or r == 0.0:
                continue
            ux, uy = dx / r, dy / r
            if guides[c, 5] != 0.0:
                vr = v[0, i] * ux + v[1, i] * uy
                if guides[c, 6] == 0.0:
                    if vr > 0.0:
                        continue
                else:
                    weight *= smooth_step(-vr, guides[c, 6] * math.sqrt(guides[c, 3]))
            k = weight * guides[c, 4]
            gxx += k * ux * ux
            gxy += k * ux * uy
            gyy += k * uy * uy
    return gxx, gxy, gyy, gzz


@jit.kernel
def kick_exactly(v, acc, out, i, g, gxx, gxy, gyy, gzz, tau):
    """Node ``i``'s velocity after an exact kick of length ``tau`` under dv/dt = b - A v into ``out[:, i]``:
    A = g I + the contact rates, b = acc + the rates times v (the contact forces' constant part)."""
    vx, vy = v[0, i], v[1, i]
    bx = acc[0, i] + gxx * vx + gxy * vy
    by = acc[1, i] + gxy * vx + gyy * vy
    # A's x-y block [[g + gxx, gxy], [gxy, g + gyy]] = R diag(l1, l2) R^T
    mean = g + 0.5 * (gxx + gyy)
    half = math.sqrt(0.25 * (gxx - gyy) ** 2 + gxy * gxy)
    l1, l2 = mean + half, mean - half
    theta = 0.5 * math.atan2(2.0 * gxy, gxx - gyy)
    cs, sn = math.cos(theta), math.sin(theta)
    v1 = cs * vx + sn * vy
    v2 = -sn * vx + cs * vy
    b1 = cs * bx + sn * by
    b2 = -sn * bx + cs * by
    w1 = math.exp(-l1 * tau) * v1 + _phi(l1, tau) * b1
    w2 = math.exp(-l2 * tau) * v2 + _phi(l2, tau) * b2
    out[0, i] = cs * w1 - sn * w2
    out[1, i] = sn * w1 + cs * w2
    if v.shape[0] == 3:
        lz = g + gzz
        out[2, i] = math.exp(-lz * tau) * v[2, i] + _phi(lz, tau) * (acc[2, i] + gzz * v[2, i])


@jit.kernel
def exact_contact_kicks(x, v, acc, out, nodes, tau, gamma, free, forces):
    """For every free node the box or a circle touches, its velocity after an exact kick of length ``tau``
    into ``out[:, i]``, its index into ``nodes``; returns how many. ``acc`` is a(x, v) without drag and
    ``gamma`` (N,) the drag rate b / m."""
    three_d = x.shape[0] == 3
    box = box_of(forces.thrower)
    count = 0
    for i in range(x.shape[1]):
        if not free[i]:
            continue
        gxx, gxy, gyy, gzz = contact_rates(x, v, i, forces.inv_mass, forces.thrower, forces.guides,
                                           box, three_d)
        if gxx == 0.0 and gxy == 0.0 and gyy == 0.0 and gzz == 0.0:
            continue
        kick_exactly(v, acc, out, i, gamma[i], gxx, gxy, gyy, gzz, tau)
        nodes[count] = i
        count += 1
    return count
