"""Orientations of rigid bodies: unit quaternions, rotation matrices and the scene's angles, in NumPy.

A body's orientation is the unit quaternion q = (w, x, y, z) that turns its frame into the world's:
v_world = R(q) v_body. The scene writes an orientation as angles [deg]: in 3-D rotations about x, then y, then z,
about the fixed axes, so R = Rz(c) Ry(b) Rx(a) (MoorDyn's roll, pitch, yaw order; scipy's
``Rotation.from_euler("xyz", ...)``); in 2-D one angle about z. q and -q are the same orientation.

Every function takes stacked arrays (a run's frames, its bodies) on the leading axes.
"""

from __future__ import annotations

import numpy as np


def quaternion_from_angles(angles_deg, dim: int = 3) -> np.ndarray:
    """The unit quaternions (..., 4) of the scene's angles [deg] (..., 3) in 3-D (about x, then y, then z) or
    (..., 1) in 2-D (about z)."""
    angles = np.radians(np.asarray(angles_deg, dtype=float))
    if dim == 2:
        zero = np.zeros(angles.shape[:-1])
        a, b, c = zero, zero, angles[..., 0]
    else:
        a, b, c = np.moveaxis(angles, -1, 0)
    ca, sa, cb, sb, cc, sc = (f(v / 2) for v in (a, b, c) for f in (np.cos, np.sin))
    # q = qz qy qx, the product written out
    return np.stack([cc * cb * ca + sc * sb * sa, cc * cb * sa - sc * sb * ca,
                     cc * sb * ca + sc * cb * sa, sc * cb * ca - cc * sb * sa], axis=-1)


def rotation_matrix(q, dim: int = 3) -> np.ndarray:
    """R(q) (..., 3, 3) of quaternions q (..., 4), each divided by its norm first; with ``dim`` 2 its upper-left
    (..., 2, 2) block (a 2-D body turns about z)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    r = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1)], axis=-2)
    return r[..., :dim, :dim]


def angles_from_quaternion(q, dim: int = 3) -> np.ndarray:
    """The scene's angles [deg] of quaternions q (..., 4): (..., 3) in 3-D, a about x, b about y, c about z with
    R = Rz(c) Ry(b) Rx(a), a and c in (-180, 180], b in [-90, 90] (at b = +-90 deg, where only a - c or a + c is
    defined, a is 0); (..., 1) in 2-D, the angle about z in (-180, 180]."""
    q = np.asarray(q, dtype=float)
    if dim == 2:
        turn = 2.0 * np.arctan2(q[..., 3], q[..., 0])
        return np.degrees(np.arctan2(np.sin(turn), np.cos(turn)))[..., None]
    r = rotation_matrix(q)
    cos_b = np.hypot(r[..., 2, 1], r[..., 2, 2])
    b = np.arctan2(-r[..., 2, 0], cos_b)
    locked = cos_b < 1e-9
    a = np.where(locked, 0.0, np.arctan2(r[..., 2, 1], r[..., 2, 2]))
    # at the lock, a = 0 leaves R = Rz(c) Ry(+-90 deg), whose entries (0, 1) and (1, 1) are -sin c and cos c
    c = np.where(locked, np.arctan2(-r[..., 0, 1], r[..., 1, 1]), np.arctan2(r[..., 1, 0], r[..., 0, 0]))
    return np.degrees(np.stack([a, b, c], axis=-1))


def continuous_angles(angles_deg: np.ndarray, axis: int = 0) -> np.ndarray:
    """Angles [deg] along ``axis`` (a run's frames) without the jumps of 360 deg where they pass +-180: a body
    that turns a full turn reads 360."""
    return np.degrees(np.unwrap(np.radians(np.asarray(angles_deg, dtype=float)), axis=axis))
