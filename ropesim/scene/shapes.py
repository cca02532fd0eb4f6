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
    elif isinstance(init, S.EquilibriumStart):
        x = sagging_line(np.asarray(init.start), np.asarray(init.end), n, l * (n - 1), scene.seabed)
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


def sagging_line(start: np.ndarray, end: np.ndarray, n: int, length: float, seabed=None) -> np.ndarray:
    """n nodes from ``start`` to ``end`` spaced evenly along a curve of the rope's ``length`` [m]: the straight
    line if the rope is no longer than the distance, else a parabola sagging below the chord, deep enough for
    the length (and held above ``seabed``'s plane). The static solver's first guess; (D, n) [m]."""
    dim = len(start)
    chord = end - start
    if length <= np.linalg.norm(chord) * (1.0 + 1e-12):
        return start[:, None] + chord[:, None] * np.linspace(0.0, 1.0, n)[None, :]
    s = np.linspace(0.0, 1.0, 2001)
    down = np.zeros(dim)
    down[1] = -1.0

    def curve(sag):
        return start[:, None] + chord[:, None] * s[None, :] + down[:, None] * (4.0 * sag * s * (1.0 - s))[None, :]

    def arc(sag):
        return float(np.sum(np.linalg.norm(np.diff(curve(sag), axis=1), axis=0)))

    lo, hi = 0.0, length
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if arc(mid) < length else (lo, mid)
    path = curve(lo)
    if seabed is not None:   # not through the seabed: lift what sinks below it onto it
        slope = np.tan(np.radians(seabed.slope))
        path[1] = np.maximum(path[1], seabed.height + slope * path[0])
        path[:, 0], path[:, -1] = start, end   # the ends stay where the scene puts them (an anchor may be buried)
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=1), axis=0))])
    where = np.linspace(0.0, along[-1], n)
    return np.stack([np.interp(where, along, path[d]) for d in range(dim)])
