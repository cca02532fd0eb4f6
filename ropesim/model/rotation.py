"""Rotations as unit quaternions q = (w, x, y, z), turning a body's frame into the world's: v_world = R(q) v_body.

The scene gives an orientation as angles: in 3-D rotations about x, then y, then z (fixed axes), so
R = Rz(c) Ry(b) Rx(a), MoorDyn's roll, pitch and yaw order; in 2-D one angle about z. A rotation by the vector
phi (angle |phi| about phi / |phi|) is exp(phi) = (cos(|phi| / 2), sin(|phi| / 2) phi / |phi|); a body turning at
the world-frame rate w for a time c goes from q to exp(c w) q.

NumPy functions here serve the model's set-up and the analyses; the compiled kernels (``@jit.kernel``) serve the
integrators (:mod:`ropesim.model.bodies`).
"""

from __future__ import annotations

import math

import numpy as np

from . import jit


def quaternion_from_angles(angles_deg, dim: int = 3) -> np.ndarray:
    """The unit quaternion (4,) of the scene's orientation angles [deg]: (a, b, c) about x, then y, then z in
    3-D (R = Rz Ry Rx); (c,) about z in 2-D."""
    angles = np.radians(np.asarray(angles_deg, dtype=float))
    if dim == 2:
        angles = np.array([0.0, 0.0, angles[0]])
    q = np.array([1.0, 0.0, 0.0, 0.0])
    for axis in (0, 1, 2):   # q = qz qy qx: the rotation about x acts first
        half = 0.5 * angles[axis]
        turn = np.zeros(4)
        turn[0] = math.cos(half)
        turn[1 + axis] = math.sin(half)
        q = multiply(turn, q)
    return q


def multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The quaternion product p q (the rotation q, then p)."""
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def rotation_matrix(q: np.ndarray) -> np.ndarray:
    """R(q) (..., 3, 3) of quaternions q (..., 4), which need not be normalised exactly (they are divided by
    their norm)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1)], axis=-2)


def quaternion_from_matrix(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternions (..., 4), w >= 0, of rotation matrices (..., 3, 3) (Shepperd's method: from the
    largest of the four squared components, so it stays accurate at every angle)."""
    m = np.asarray(rotation, dtype=float)
    trace = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    squares = np.stack([1.0 + trace, 1.0 + 2.0 * m[..., 0, 0] - trace, 1.0 + 2.0 * m[..., 1, 1] - trace,
                        1.0 + 2.0 * m[..., 2, 2] - trace], axis=-1)   # 4 w^2, 4 x^2, 4 y^2, 4 z^2
    pick = np.argmax(squares, axis=-1)
    big = 0.5 * np.sqrt(np.take_along_axis(squares, pick[..., None], axis=-1)[..., 0])   # the largest component
    four = 4.0 * big
    w = np.choose(pick, [big, (m[..., 2, 1] - m[..., 1, 2]) / four, (m[..., 0, 2] - m[..., 2, 0]) / four,
                         (m[..., 1, 0] - m[..., 0, 1]) / four])
    x = np.choose(pick, [(m[..., 2, 1] - m[..., 1, 2]) / four, big, (m[..., 0, 1] + m[..., 1, 0]) / four,
                         (m[..., 0, 2] + m[..., 2, 0]) / four])
    y = np.choose(pick, [(m[..., 0, 2] - m[..., 2, 0]) / four, (m[..., 0, 1] + m[..., 1, 0]) / four, big,
                         (m[..., 1, 2] + m[..., 2, 1]) / four])
    z = np.choose(pick, [(m[..., 1, 0] - m[..., 0, 1]) / four, (m[..., 0, 2] + m[..., 2, 0]) / four,
                         (m[..., 1, 2] + m[..., 2, 1]) / four, big])
    q = np.stack([w, x, y, z], axis=-1)
    return q * np.where(q[..., :1] < 0, -1.0, 1.0)


def exp_map(phi: np.ndarray) -> np.ndarray:
    """exp(phi) (4,): the rotation by the vector phi (3,) [rad]."""
    phi = np.asarray(phi, dtype=float)
    angle = float(np.linalg.norm(phi))
    if angle == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[math.cos(0.5 * angle)], math.sin(0.5 * angle) / angle * phi])


# ------------------------------------------------------------------------------------------ compiled


@jit.kernel(inline="always")
def matrix_of(q, b):
    """R of quaternion ``q[:, b]`` (assumed unit), as its nine entries row by row."""
    w, x, y, z = q[0, b], q[1, b], q[2, b], q[3, b]
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


@jit.kernel
def rotate(r, v0, v1, v2):
    """R v, ``r`` R's nine entries row by row (:func:`matrix_of`)."""
    return (r[0] * v0 + r[1] * v1 + r[2] * v2, r[3] * v0 + r[4] * v1 + r[5] * v2, r[6] * v0 + r[7] * v1 + r[8] * v2)


@jit.kernel
def rotate_back(r, v0, v1, v2):
    """R^T v: a world vector in the body's axes."""
    return (r[0] * v0 + r[3] * v1 + r[6] * v2, r[1] * v0 + r[4] * v1 + r[7] * v2, r[2] * v0 + r[5] * v1 + r[8] * v2)


@jit.kernel
def cross(a0, a1, a2, b0, b1, b2):
    """a x b."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


#: Below this squared angle [rad^2] (|p| < 0.1) the rotation's half-angle functions are their Taylor series to
#: a^8: the first term left out is below 1e-19 of the sum, so the series equals the trigonometric form to within
#: rounding, without cos, sin, tan or sqrt (a step's rotation is far below it but for a body spun very fast).
SERIES_BELOW = 1e-2


@jit.kernel(inline="always")
def half_turn(a2):
    """cos(a / 2) and sin(a / 2) / a of the angle a [rad] whose square is ``a2``: exp(p)'s scalar part and the
    factor of p in its vector part."""
    if a2 < SERIES_BELOW:
        return (1.0 + a2 * (-1.0 / 8.0 + a2 * (1.0 / 384.0 + a2 * (-1.0 / 46080.0 + a2 / 10321920.0))),
                0.5 + a2 * (-1.0 / 48.0 + a2 * (1.0 / 3840.0 + a2 * (-1.0 / 645120.0 + a2 / 185794560.0))))
    angle = math.sqrt(a2)
    return math.cos(0.5 * angle), math.sin(0.5 * angle) / angle


@jit.kernel(inline="always")
def unit_scale(n2):
    """1 / sqrt(n2) for a quaternion's squared norm n2: 3/2 - n2/2 (Newton's step from 1) when n2 is within
    1e-8 of 1, as a product of two unit quaternions is to within rounding (the error, 3/8 (n2 - 1)^2, is below
    half a unit in the last place), so renormalising each turn takes no square root and no division."""
    if abs(n2 - 1.0) < 1e-8:
        return 1.5 - 0.5 * n2
    return 1.0 / math.sqrt(n2)


@jit.kernel
def turn(q, b, p0, p1, p2):
    """q[:, b] <- exp(p) q[:, b], normalised: the orientation turned by the world-frame rotation vector p [rad]."""
    c, s = half_turn(p0 * p0 + p1 * p1 + p2 * p2)
    e0, e1, e2, e3 = c, s * p0, s * p1, s * p2
    w, x, y, z = q[0, b], q[1, b], q[2, b], q[3, b]
    n0 = e0 * w - e1 * x - e2 * y - e3 * z
    n1 = e0 * x + e1 * w + e2 * z - e3 * y
    n2 = e0 * y - e1 * z + e2 * w + e3 * x
    n3 = e0 * z + e1 * y - e2 * x + e3 * w
    scale = unit_scale(n0 * n0 + n1 * n1 + n2 * n2 + n3 * n3)
    q[0, b] = n0 * scale
    q[1, b] = n1 * scale
    q[2, b] = n2 * scale
    q[3, b] = n3 * scale


@jit.kernel(inline="always")
def dexp_inverse(p0, p1, p2, w0, w1, w2):
    """dexp^-1_p(w): the rate of the rotation vector p of q = exp(p) q0 when the body turns at the world-frame rate
    w, p' = w - p x w / 2 + (1 - (a / 2) cot(a / 2)) / a^2 p x (p x w), a = |p|."""
    a2 = p0 * p0 + p1 * p1 + p2 * p2
    if a2 < SERIES_BELOW:   # the series to a^8 (see SERIES_BELOW)
        k = 1.0 / 12.0 + a2 * (1.0 / 720.0 + a2 * (1.0 / 30240.0 + a2 * (1.0 / 1209600.0 + a2 / 47900160.0)))
    else:
        a = math.sqrt(a2)
        k = (1.0 - 0.5 * a / math.tan(0.5 * a)) / a2
    c0 = p1 * w2 - p2 * w1
    c1 = p2 * w0 - p0 * w2
    c2 = p0 * w1 - p1 * w0
    d0 = p1 * c2 - p2 * c1
    d1 = p2 * c0 - p0 * c2
    d2 = p0 * c1 - p1 * c0
    return w0 - 0.5 * c0 + k * d0, w1 - 0.5 * c1 + k * d1, w2 - 0.5 * c2 + k * d2
