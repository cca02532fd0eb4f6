"""Turn a validated :class:`Scene` into the arrays the compiled kernel works on.

Nothing here steps time: it lays out the initial state (shape (D, N), structure of arrays), the per-node
masses and drag coefficients, the held (pinned or driven) nodes, and the force terms' parameters and flags
(:func:`ropesim.model.terms.model_params`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import schema as S
from .terms import ModelParams, has_applied, model_params


@dataclass
class Model:
    """A scene laid out for the kernel. Arrays are float64 unless noted; positions are (D, N)."""

    scene: S.Scene
    x0: np.ndarray            # initial positions [m]
    v0: np.ndarray            # initial velocities [m/s]
    mass: np.ndarray          # (N,) [kg]
    drag: np.ndarray          # (N,) linear drag coefficients b [kg/s]
    held: np.ndarray          # (N,) bool: pinned or driven
    held_idx: np.ndarray      # (H,) int64 indices of held nodes
    held_x0: np.ndarray       # (D, H) their positions at t = 0 [m]
    held_v: np.ndarray        # (D, H) their constant velocities [m/s]
    params: ModelParams       # the force terms' parameters and flags, for the compiled code

    @property
    def dim(self) -> int:
        return self.x0.shape[0]

    @property
    def nodes(self) -> int:
        return self.x0.shape[1]

    @property
    def velocity_dependent(self) -> bool:
        """True when a force other than drag depends on velocity (the thrower and guide circles)."""
        return has_applied(self.params)

    @property
    def has_drag(self) -> bool:
        return bool(np.any(self.drag[~self.held] > 0))

    @property
    def smooth_contacts(self) -> bool:
        """True when the box's or a circle's edges are smoothed: the splitting schemes then kick the nodes they
        touch exactly (:mod:`ropesim.integrate.contact`)."""
        scene = self.scene
        return (scene.thrower is not None and scene.thrower.edge_width > 0) or any(g.edge_width > 0
                                                                                     for g in scene.guides)


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

    return Model(scene=scene, x0=x0, v0=v0, mass=mass, drag=drag, held=held, held_idx=held_idx,
                 held_x0=np.ascontiguousarray(x0[:, held_idx]), held_v=np.ascontiguousarray(held_v[:, held_idx]),
                 params=model_params(scene, mass))


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
