"""The string shooter's drive box (the write-up's thrower).

A node inside the box |x - cx| < L/2, |y - cy| < W/2 (and |z - cz| < W/2 in 3-D) is driven along +x
towards v_max, F_x = b_thrower (v_max - v_x), and held to the centre line by a damped spring that also
cancels its weight: a_y = g - omega0^2 (y - cy) - 2 zeta omega0 v_y (likewise in z, without g).

Parameters, packed in one float64 array: cx, cy, cz, L/2, W/2, v_max, b_thrower, omega0^2, 2 zeta omega0.
"""

from numba import njit

THROWER_PARAMS = 9


@njit(cache=True, error_model="numpy")
def inside_box(x, i, p):
    """True when node i lies inside the box described by ``p``."""
    if abs(x[0, i] - p[0]) >= p[3] or abs(x[1, i] - p[1]) >= p[4]:
        return False
    if x.shape[0] == 3 and abs(x[2, i] - p[2]) >= p[4]:
        return False
    return True


@njit(cache=True, error_model="numpy")
def add_thrower(x, v, acc, inv_mass, p, g):
    """Add the box's drive and centring accelerations [m/s^2] to every node inside it."""
    n = x.shape[1]
    w2 = p[7]
    c = p[8]
    for i in range(n):
        if not inside_box(x, i, p):
            continue
        acc[0, i] += p[6] * inv_mass[i] * (p[5] - v[0, i])
        acc[1, i] += g - w2 * (x[1, i] - p[1]) - c * v[1, i]
        if x.shape[0] == 3:
            acc[2, i] += -w2 * (x[2, i] - p[2]) - c * v[2, i]
