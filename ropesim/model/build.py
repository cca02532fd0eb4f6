"""Turn a validated :class:`Scene` into the arrays the compiled kernel works on.

Nothing here steps time: it lays out the initial state (shape (D, N), structure of arrays), the per-node
masses and drag coefficients, the held (pinned or driven) nodes, and one parameter array plus an on/off flag
per optional force term.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import schema as S
from .forces.guides import GUIDE_PARAMS
from .forces.thrower import THROWER_PARAMS
from .terms import BENDING, GRAVITY, GUIDES, N_FLAGS, THROWER


@dataclass
class Model:
    """A scene laid out for the kernel. Arrays are float64 unless noted; positions are (D, N)."""

    scene: S.Scene
    x0: np.ndarray            # initial positions [m]
    v0: np.ndarray            # initial velocities [m/s]
    mass: np.ndarray          # (N,) [kg]
    drag: np.ndarray          # (N,) drag coefficients b [kg/s]
    held: np.ndarray          # (N,) bool: pinned or driven
    held_idx: np.ndarray      # (H,) int64 indices of held nodes
    held_x0: np.ndarray       # (D, H) their positions at t = 0 [m]
    held_v: np.ndarray        # (D, H) their constant velocities [m/s]
    forces: tuple             # (inv_mass, flags, spring, bending, gravity, thrower, guides) for the kernel

    @property
    def dim(self) -> int:
        return self.x0.shape[0]

    @property
    def nodes(self) -> int:
        return self.x0.shape[1]

    @property
    def velocity_dependent(self) -> bool:
        """True when a force other than drag depends on velocity (the thrower and guide circles)."""
        flags = self.forces[1]
        return bool(flags[THROWER] or flags[GUIDES])

    @property
    def has_drag(self) -> bool:
        return bool(np.any(self.drag[~self.held] > 0))


def build(scene: S.Scene) -> Model:
    """Lay out ``scene`` for the kernel."""
    n, dim = scene.rope.nodes, scene.dimension
    x0 = initial_positions(scene)
    v0 = np.empty((dim, n))
    v0[:] = np.asarray(scene.initial.velocity, dtype=float)[:, None]

    mass = np.full(n, scene.rope.mass)
    drag = np.full(n, scene.drag.b if scene.drag is not None else 0.0)
    for o in scene.overrides:
        i = scene.node(o.index)
        if o.mass is not None:
            mass[i] = o.mass
        if o.drag is not None:
            drag[i] = o.drag

    held_v = np.zeros((dim, n))
    held = np.zeros(n, dtype=bool)
    if scene.pinned is not None:
        held[[scene.node(i) for i in scene.pinned.nodes]] = True
    for drive in scene.driven:
        idx = [scene.node(i) for i in drive.nodes]
        held[idx] = True
        held_v[:, idx] = np.asarray(drive.velocity)[:, None]
    held_idx = np.flatnonzero(held).astype(np.int64)
    v0[:, held_idx] = held_v[:, held_idx]

    flags = np.zeros(N_FLAGS, dtype=np.uint8)
    rope = scene.rope
    spring = np.array([rope.stiffness, rope.segment_length, 1.0 if rope.closed else 0.0])
    bending = np.zeros(2)
    if scene.bending is not None:
        flags[BENDING] = 1
        bending = np.array([scene.bending.stiffness, 2.0 * rope.segment_length])
    gravity = np.zeros(1)
    if scene.gravity is not None:
        flags[GRAVITY] = 1
        gravity[0] = scene.gravity.g
    thrower = np.zeros(THROWER_PARAMS)
    if scene.thrower is not None:
        flags[THROWER] = 1
        t = scene.thrower
        centre = list(t.center) + [0.0] * (3 - dim)
        w = t.omega0
        thrower = np.array([*centre, t.length / 2, t.width / 2, t.v_max, t.b_thrower, w * w,
                            2 * t.damping_ratio * w, t.edge_width])
    guides = np.zeros((0, GUIDE_PARAMS))
    if scene.guides:
        flags[GUIDES] = 1
        guides = np.array([[c.center[0], c.center[1], c.radius, c.omega0 * c.omega0, 2 * c.damping_ratio * c.omega0,
                            1.0 if c.one_sided else 0.0, c.edge_width] for c in scene.guides])

    forces = (1.0 / mass, flags, spring, bending, gravity, thrower, guides)
    return Model(scene=scene, x0=x0, v0=v0, mass=mass, drag=drag, held=held, held_idx=held_idx,
                 held_x0=np.ascontiguousarray(x0[:, held_idx]), held_v=np.ascontiguousarray(held_v[:, held_idx]),
                 forces=forces)


def initial_positions(scene: S.Scene) -> np.ndarray:
    """Node positions at t = 0, shape (D, N) [m]."""
    n, dim, l = scene.rope.nodes, scene.dimension, scene.rope.segment_length
    init = scene.initial
    if isinstance(init, S.HangingStart):
        x = np.zeros((dim, n))
        x[:] = np.asarray(init.top)[:, None]
        x[1] -= l * np.arange(n)
    elif isinstance(init, S.LineStart):
        s = np.linspace(0.0, 1.0, n)
        start, end = np.asarray(init.start), np.asarray(init.end)
        x = (start[:, None] + (end - start)[:, None] * s[None, :])
    elif isinstance(init, S.SquareLoopStart):
        x = _square_loop(n, l, np.asarray(init.top_center), dim)
    elif isinstance(init, S.PointsStart):
        x = np.asarray(init.points, dtype=float).T
    else:  # pragma: no cover - the loader admits only the shapes above
        raise TypeError(type(init))
    return np.ascontiguousarray(x, dtype=float)


def _square_loop(n: int, l: float, top_center: np.ndarray, dim: int) -> np.ndarray:
    """n nodes l apart along a square of perimeter n l hanging below its top edge (clockwise from top-left)."""
    side = n * l / 4.0
    corners = np.array([[-side / 2, 0.0], [side / 2, 0.0], [side / 2, -side], [-side / 2, -side]])
    s = l * np.arange(n)
    edge = np.minimum((s // side).astype(int), 3)
    frac = (s - edge * side) / side
    start = corners[edge]
    end = corners[(edge + 1) % 4]
    xy = start + (end - start) * frac[:, None]
    x = np.zeros((dim, n))
    x[0] = top_center[0] + xy[:, 0]
    x[1] = top_center[1] + xy[:, 1]
    if dim == 3:
        x[2] = top_center[2]
    return x


def spring_count(n: int, stride: int, closed: bool) -> int:
    return n if closed else max(n - stride, 0)
