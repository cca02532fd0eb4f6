"""Trajectories of systems with rigid bodies, made up in closed form for the tests of what is drawn, exported
and reported: each body turns at a constant rate about a fixed axis while its reference point drifts, each line
runs from its start point to its end point with a sag, and its segments carry made-up tensions."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

import ropesim
from ropesim.io.trajectory import Trajectory
from ropesim.model.layout import line_layouts

BODY_2D = """
name = "plate_2d"
dimension = 2
[[bodies]]
id = "plate"
position = [0.0, -5.0]
orientation = 20.0
mass = 100.0
inertia = 50.0
[[points]]
id = "left_anchor"
position = [-10.0, 0.0]
[[points]]
id = "right_anchor"
position = [10.0, 0.0]
[[points]]
id = "left_eye"
body = "plate"
position = [-1.5, 0.5]
[[points]]
id = "right_eye"
body = "plate"
position = [1.5, 0.5]
[[lines]]
id = "left_leg"
start = "left_anchor"
end = "left_eye"
length = 11.0
segments = 6
mass_per_length = 1.0
EA = 1.0e6
[[lines]]
id = "right_leg"
start = "right_eye"
end = "right_anchor"
length = 11.0
segments = 4
mass_per_length = 1.0
EA = 1.0e6
[gravity]
[integrator]
dt = 1.0e-3
t_end = 1.0
"""


def body_rotations(scene, t: np.ndarray, axis, rate: float) -> list[Rotation]:
    """Each body's orientation over time: its scene orientation, then turned at ``rate`` [rad/s] about the world
    axis ``axis`` (about z in 2-D)."""
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    out = []
    for body in scene.rigid_bodies:
        angles = np.asarray(body.orientation, dtype=float)
        start = Rotation.from_euler("xyz", angles if scene.dimension == 3 else [0.0, 0.0, angles[0]], degrees=True)
        out.append(Rotation.from_rotvec(rate * t[:, None] * axis) * start)
    return out


def turning_body_run(scene, frames: int = 25, axis=(0.3, 0.9, 0.2), rate: float = 0.7, drift=None,
                     sag: float = 0.4) -> Trajectory:
    """A Trajectory of ``scene`` (a system with rigid bodies) in memory, made up as the module says."""
    dim = scene.dimension
    t = np.linspace(0.0, 6.0, frames)
    if dim == 2:
        axis = (0.0, 0.0, 1.0)
    drift = np.asarray(drift if drift is not None else (0.4, -0.1, 0.25)[:dim], dtype=float)
    turns = body_rotations(scene, t, axis, rate)
    body_x = np.stack([np.asarray(b.position, dtype=float) + t[:, None] * drift for b in scene.rigid_bodies], axis=1)
    body_v = np.broadcast_to(drift, body_x.shape).copy()
    body_q = np.stack([r.as_quat(scalar_first=True) for r in turns], axis=1)
    w = np.asarray(axis, dtype=float) / np.linalg.norm(axis) * rate
    body_w = np.broadcast_to(w, (frames, len(turns), 3)).copy()
    bodies = {b.id: k for k, b in enumerate(scene.rigid_bodies)}

    def where(point) -> np.ndarray:
        if point.kind != "body":
            return np.broadcast_to(np.asarray(point.position, dtype=float), (frames, dim))
        k = bodies[point.body]
        local = np.zeros(3)
        local[:dim] = point.position
        return body_x[:, k] + turns[k].apply(local)[:, :dim]

    points = {p.id: p for p in scene.points}
    layouts = line_layouts(scene)
    n = sum(line.nodes for line in layouts)
    x = np.zeros((frames, n, dim))
    tension = []
    for k, (line, layout) in enumerate(zip(scene.lines, layouts)):
        a, b = where(points[line.start]), where(points[line.end])
        s = np.linspace(0.0, 1.0, layout.nodes)
        shape = a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]
        shape[:, :, 1] -= sag * np.sin(np.pi * s)[None, :]
        x[:, layout.first:layout.end] = shape
        tension.append(1000.0 * (k + 1) + 10.0 * np.arange(layout.segments)[None, :]
                       + 50.0 * np.sin(t)[:, None])
    tension = np.concatenate(tension, axis=1)
    return Trajectory(t=t, x=x, v=np.zeros_like(x), scene=scene, tension=tension, strain=tension / 1e7,
                      body_x=body_x, body_v=body_v, body_q=body_q, body_w=body_w)


def plate_scene():
    return ropesim.scene_from_toml(BODY_2D)

