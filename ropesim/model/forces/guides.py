"""Guide circles (cylinders along z in 3-D) that the shooter's loop wraps around.

A node inside a circle of radius R (distance r from its centre in the x-y plane) and outside the thrower box
is pushed out to the rim by a damped radial spring, a_r = -omega0^2 (r - R) - 2 zeta omega0 v_r, and its
weight is cancelled (a_y += g, once even inside two circles). A one-sided circle lets go of nodes moving
outward (v_r > 0).

With an edge width w > 0 (``edge_width`` of the circle) the rim is smoothed: the circle's forces (spring,
damping and lift) are weighted by S(R - r), S the thrower's smooth step of width w, times 1 - the box's weight,
and a one-sided circle lets go smoothly, by S(-v_r) over a speed width w omega0. With w = 0 (the default) all
are sharp, as above.

Parameters: one row per circle, float64 (M, 7): cx, cy, R, omega0^2, 2 zeta omega0, one_sided (0 or 1), w.
"""

import numpy as np

from . import Term

from .thrower import box_of, smooth_step, weight_at
from .. import jit

WITH_GUIDES = jit.Switch("guides", "guide circles")
GUIDE_PARAMS = 7


@jit.kernel
def add_guides(x, v, acc, circles, box, has_box, g):
    """Add the guide circles' accelerations [m/s^2]; ``box`` is the thrower's parameters if ``has_box``."""
    n = x.shape[1]
    three_d = x.shape[0] == 3
    cube = box_of(box)
    for i in range(n):
        outside = 1.0 - weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, cube) if has_box else 1.0
        if outside == 0.0:
            continue
        lift = 0.0
        for c in range(circles.shape[0]):
            dx = x[0, i] - circles[c, 0]
            dy = x[1, i] - circles[c, 1]
            r = np.sqrt(dx * dx + dy * dy)
            radius = circles[c, 2]
            w = circles[c, 6]
            weight = smooth_step(radius - r, w)
            if weight == 0.0:
                continue
            if r > 0.0:
                vr = (v[0, i] * dx + v[1, i] * dy) / r
                if circles[c, 5] != 0.0:
                    if w == 0.0:
                        if vr > 0.0:
                            continue
                    else:
                        weight *= smooth_step(-vr, w * np.sqrt(circles[c, 3]))
                ar = outside * weight * (-circles[c, 3] * (r - radius) - circles[c, 4] * vr)
                acc[0, i] += ar * dx / r
                acc[1, i] += ar * dy / r
            lift = max(lift, weight)
        if lift > 0.0:
            acc[1, i] += outside * lift * g



@jit.kernel
def add_guides_jacobian(x, v, band, beta, mass, free, circles, box, has_box):
    """Add the circles' node blocks to the stiff integrator's Newton matrix (see :mod:`ropesim.model.jacobian`).

    A node in a circle (weight s) gets s m [(beta^2 omega0^2 + beta 2 zeta omega0) r_hat r_hat^T
    + beta^2 max(0, -a_r / r) (I - r_hat r_hat^T)] in the x-y plane: the radial spring and damping, and the
    tangential stiffness of a radial force turning with the node (left out when it would be negative).
    """
    dim, n = x.shape
    three_d = dim == 3
    cube = box_of(box)
    b2 = beta * beta
    for i in range(n):
        if not free[i]:
            continue
        outside = 1.0 - weight_at(x[0, i], x[1, i], x[2, i] if three_d else 0.0, three_d, cube) if has_box else 1.0
        if not outside > 0.0:
            continue
        m = mass[i]
        for c in range(circles.shape[0]):
            dx = x[0, i] - circles[c, 0]
            dy = x[1, i] - circles[c, 1]
            r = np.sqrt(dx * dx + dy * dy)
            radius = circles[c, 2]
            weight = outside * smooth_step(radius - r, circles[c, 6])
            if weight == 0.0 or r == 0.0:
                continue
            ux, uy = dx / r, dy / r
            vr = v[0, i] * ux + v[1, i] * uy
            if circles[c, 5] != 0.0:
                if circles[c, 6] == 0.0:
                    if vr > 0.0:
                        continue
                else:
                    weight *= smooth_step(-vr, circles[c, 6] * np.sqrt(circles[c, 3]))
            ar = -circles[c, 3] * (r - radius) - circles[c, 4] * vr
            radial = weight * (b2 * circles[c, 3] + beta * circles[c, 4])
            tangential = weight * b2 * max(0.0, -ar / r)
            u = (ux, uy)
            for a in range(2):
                for b in range(a + 1):
                    band[a - b, i * dim + b] += m * (radial * u[a] * u[b]
                                                      + tangential * ((1.0 if a == b else 0.0) - u[a] * u[b]))

def _params(scene, mass) -> np.ndarray:
    return np.array([[c.center[0], c.center[1], c.radius, c.omega0 * c.omega0, 2 * c.damping_ratio * c.omega0,
                      1.0 if c.one_sided else 0.0, c.edge_width] for c in scene.guides])


def _omega0(model, guide) -> float:
    scene = model.scene
    return guide.omega0 if guide.omega0 is not None else (
        scene.thrower.resolved_omega0 if scene.thrower is not None else 0.0)


GUIDES = Term("guides", WITH_GUIDES, _params, lambda: np.zeros((0, GUIDE_PARAMS)),
              node_stiffness=lambda model: max(_omega0(model, g) * _omega0(model, g) for g in model.scene.guides),
              damping=lambda model: max(2 * g.damping_ratio * _omega0(model, g) for g in model.scene.guides),
              ledger="box")
