"""Orientations of rigid bodies for the analyses and pictures: rotation matrices and the scene's angles of
quaternions, stacked over a run's frames and bodies, in NumPy.

A body's orientation is the unit quaternion q = (w, x, y, z) that turns its frame into the world's:
v_world = R(q) v_body (:mod:`ropesim.model.rotation`, which also turns the scene's angles into quaternions). The
scene writes an orientation as angles [deg]: in 3-D rotations about x, then y, then z, about the fixed axes, so
R = Rz(c) Ry(b) Rx(a) (MoorDyn's roll, pitch, yaw order; scipy's ``Rotation.from_euler("xyz", ...)``); in 2-D one
angle about z. q and -q are the same orientation.
"""

from __future__ import annotations

import numpy as np

from ..model.rotation import rotation_matrix as _matrix


def rotation_matrix(q, dim: int = 3) -> np.ndarray:
    """R(q) (..., 3, 3) of quaternions q (..., 4), each divided by its norm first; with ``dim`` 2 its upper-left
    (..., 2, 2) block (a 2-D body turns about z)."""
    return _matrix(q)[..., :dim, :dim]


def angles_from_quaternion(q, dim: int = 3) -> np.ndarray:
    """The scene's angles [deg] of quaternions q (..., 4): (..., 3) in 3-D, a about x, b about y, c about z with
    R = Rz(c) Ry(b) Rx(a), a and c in (-180, 180], b in [-90, 90] (at b = +-90 deg, where only a - c or a + c is
    defined, a is 0); (..., 1) in 2-D, the angle about z in (-180, 180]."""
    q = np.asarray(q, dtype=float)
    if dim == 2:
        turn = 2.0 * np.arctan2(q[..., 3], q[..., 0])
        return np.degrees(np.arctan2(np.sin(turn), np.cos(turn)))[..., None]
    r = _matrix(q)
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
