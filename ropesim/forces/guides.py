"""Guide circles (cylinders along z in 3-D) that the shooter's loop wraps around.

A node inside a circle of radius R (distance r from its centre in the x-y plane) and outside the thrower box
is pushed out to the rim by a damped radial spring, a_r = -omega0^2 (r - R) - 2 zeta omega0 v_r, and its
weight is cancelled (a_y += g, once even inside two circles). A one-sided circle lets go of nodes moving
outward (v_r > 0).

Parameters: one row per circle, float64 (M, 6): cx, cy, R, omega0^2, 2 zeta omega0, one_sided (0 or 1).
"""

import numpy as np
from numba import njit

from .thrower import inside_box

GUIDE_PARAMS = 6


@njit(cache=True, error_model="numpy")
def add_guides(x, v, acc, circles, box, has_box, g):
    """Add the guide circles' accelerations [m/s^2]; ``box`` is the thrower's parameters if ``has_box``."""
    n = x.shape[1]
    for i in range(n):
        if has_box and inside_box(x, i, box):
            continue
        lifted = False
        for c in range(circles.shape[0]):
            dx = x[0, i] - circles[c, 0]
            dy = x[1, i] - circles[c, 1]
            r = np.sqrt(dx * dx + dy * dy)
            radius = circles[c, 2]
            if r >= radius:
                continue
            if r > 0.0:
                vr = (v[0, i] * dx + v[1, i] * dy) / r
                if circles[c, 5] != 0.0 and vr > 0.0:
                    continue
                ar = -circles[c, 3] * (r - radius) - circles[c, 4] * vr
                acc[0, i] += ar * dx / r
                acc[1, i] += ar * dy / r
            if not lifted:
                acc[1, i] += g
                lifted = True
