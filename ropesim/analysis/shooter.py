"""The string shooter's loop: its inclination, its height and how fast the string goes round.

Inclination is the direction of the loop's centroid seen from the thrower's centre, measured from straight
down, positive towards the throw (+x): 0 degrees is a loop hanging vertically below the thrower (the vacuum
picture), 90 degrees a loop standing straight out in front of it (the in-air picture), above 90 a loop lifted
above the thrower. It is measured from the vertical whatever the thrower's launch angle (``thrower.angle``, at
most 90 degrees either way, so the throw always goes towards +x): hanging and lifted are about gravity, and
loops thrown at different angles compare directly. The centroid's height above the thrower's centre [m] says
the same in length units (negative: the loop hangs below the wheels).
"""

from __future__ import annotations

import numpy as np

from ..model.build import Model

AVERAGE_WINDOW_S = 1.0  # the mean inclination is over the last second (or the last 20 % of a shorter run)


def loop_inclination(model: Model, x: np.ndarray) -> np.ndarray:
    """Inclination [deg] of the loop for one frame (N, D) or many (F, N, D)."""
    centre = np.asarray(model.scene.thrower.center)
    d = np.asarray(x).mean(axis=-2) - centre
    return np.degrees(np.arctan2(d[..., 0], -d[..., 1]))


def centroid_height(model: Model, x: np.ndarray) -> np.ndarray:
    """Height [m] of the loop's centroid above the thrower's centre for one frame (N, D) or many (F, N, D)."""
    return np.asarray(x)[..., :, 1].mean(axis=-1) - model.scene.thrower.center[1]


def circulation_speed(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Mean speed [m/s] of the string along itself (positive from node i towards node i+1), per frame."""
    x, v = np.asarray(x), np.asarray(v)
    tangent = np.roll(x, -1, axis=-2) - np.roll(x, 1, axis=-2)
    norm = np.linalg.norm(tangent, axis=-1, keepdims=True)
    tangent = tangent / np.where(norm > 0, norm, 1.0)
    return np.einsum("...nd,...nd->...", v, tangent) / x.shape[-2]


def shooter_figures(model: Model, t: np.ndarray, x: np.ndarray, v: np.ndarray) -> dict:
    """The shooter's summary: inclination and centroid height at the end and averaged at the end, and the
    circulation speed."""
    window = min(AVERAGE_WINDOW_S, 0.2 * float(t[-1]))
    last = np.flatnonzero(t >= t[-1] - window)
    incl = loop_inclination(model, x[last])
    height = centroid_height(model, x[last])
    return {
        "loop_inclination_deg": round(float(incl[-1]), 3),
        "mean_loop_inclination_deg": round(float(incl.mean()), 3),
        "centroid_height_m": round(float(height[-1]), 6),
        "mean_centroid_height_m": round(float(height.mean()), 6),
        "averaged_over_s": round(float(t[-1] - t[last[0]]), 6),
        "circulation_speed_m_s": round(float(circulation_speed(x[-1], v[-1])), 4),
        "drive_speed_m_s": model.scene.thrower.v_max,
        "nodes_in_thrower": nodes_in_thrower(model, x[-1]),
    }


def nodes_in_thrower(model: Model, x: np.ndarray) -> int:
    """How many nodes of one frame (N, D) are inside the thrower box: 0 means the loop has fallen out."""
    from ..model.forces.thrower import inside_box

    xdn = np.ascontiguousarray(np.asarray(x).T)
    box = model.params.thrower
    return int(sum(inside_box(xdn, i, box) for i in range(xdn.shape[1])))
