"""The initial shapes a scene can start from, as node positions."""

from __future__ import annotations

import numpy as np

from . import schema as S


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
