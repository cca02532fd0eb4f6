"""What every saved frame of a scene with a ``[sea]`` stores about the sea: each node's submerged fraction, each
line's, and the surface's elevation at the wave probes.

- ``submerged`` (F, N): the fraction of each node's share of its line below the instantaneous surface, the same
  f the forces use (:func:`ropesim.model.forces.sea.line_fraction`: two half segments, each a cylinder of the
  line's diameter cut by the surface at the node's elevation). A line without a diameter has no volume: its node
  counts 1 below the surface and 0 above.
- ``line_submerged`` (F, L): each line's submerged fraction of its unstretched length, the nodes' fractions
  weighted by their shares of it (a rope is one line).
- ``probe_elevation`` (F, P) [m]: the surface's height above the mean level at each ``[sea] probes`` position,
  the waves' ramp included (0 without ``[waves]``).

They depend on the frame's positions and time alone, so they are computed as the frames are stored, stream to
the run folder with them and resume with them (:mod:`ropesim.io.runfolder`).
"""

from __future__ import annotations

import numpy as np

from .forces.sea import HALF_HI, HALF_LO, RADIUS, line_fraction
from .waves import SURFACE_ROWS, WAVE_SCALARS, compiled_tables, surface_at, wave_field
from . import jit


def sea_shapes(model) -> dict[str, tuple]:
    """The sea's per-frame arrays' shapes (frame axis left out); none without a ``[sea]``."""
    sea = model.scene.sea
    if sea is None:
        return {}
    shapes = {"submerged": (len(model.params.inv_mass),), "line_submerged": (len(model.lines),)}
    if sea.probes:
        shapes["probe_elevation"] = (len(sea.probes),)
    return shapes


def elevation(scene, t: np.ndarray, x: np.ndarray, z: np.ndarray | float = 0.0) -> np.ndarray:
    """The surface's height above the mean level [m] at horizontal positions (x, z) and times t (broadcast
    together): :func:`surface` of the scene's waves; zeros without ``[waves]``."""
    field = wave_field(scene)
    return surface(None if field is None else compiled_tables(field), t, x, z)


def surface(tables, t: np.ndarray, x: np.ndarray, z: np.ndarray | float = 0.0) -> np.ndarray:
    """The surface's height above the mean level [m] of the waves whose compiled ``tables`` (scalars, comps) are
    given (:func:`ropesim.model.waves.compiled_tables`; None: no waves, zeros) at horizontal positions (x, z) and
    times t (broadcast together): the surface the forces see, by their own arithmetic
    (:func:`ropesim.model.waves.surface_at`). The tables' time factors are scratch."""
    t, x, z = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float)) for a in (t, x, z)))
    out = np.zeros(t.shape)
    if tables is None or out.size == 0:
        return out
    surface_at(*(np.ascontiguousarray(a).reshape(-1) for a in (t, x, z)), *tables,
               np.empty((SURFACE_ROWS, out.size)), out.reshape(-1))
    return out


def model_tables(model):
    """A copy of the model's own compiled wave tables (its sea's), or None without ``[waves]``: the frames'
    surface without rebuilding the spectrum for every chunk of frames."""
    if model.scene.sea is None or model.scene.waves is None:
        return None
    sea = model.params.sea
    return sea.scalars[:WAVE_SCALARS].copy(), sea.comps.copy()


def probe_elevation(scene, t: np.ndarray) -> np.ndarray:
    """(F, P) the surface's elevation [m] at the scene's probes (in the y-up frame the model computes in) at
    times t (F,)."""
    probes = np.asarray(scene.sea.probes, dtype=float)
    x = probes[:, 0]
    z = probes[:, 1] if probes.shape[1] > 1 else np.zeros(len(probes))
    return elevation(scene, np.asarray(t, float)[:, None], x[None, :], z[None, :])


def sea_frames(model, t: np.ndarray, x: np.ndarray) -> dict[str, np.ndarray]:
    """The sea's per-frame arrays (module doc) for frames at times t (F,) with positions x (F, N, D) [m], y up."""
    scene = model.scene
    if scene.sea is None:
        return {}
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    z = x[..., 2] if x.shape[2] == 3 else 0.0
    level = scene.sea.level + surface(model_tables(model), t[:, None], x[..., 0], z)
    nodes = model.params.sea.nodes
    submerged = np.empty(x.shape[:2])
    node_fractions(np.ascontiguousarray(np.swapaxes(x, 1, 2)), level, model.params.neighbours, nodes, submerged)
    weight = nodes[HALF_LO] + nodes[HALF_HI]
    lines = np.empty((len(t), len(model.lines)))
    for k, line in enumerate(model.lines):
        w = weight[line.first:line.end]
        share = submerged[:, line.first:line.end]
        # row by row (not a matrix product, whose summation order follows the chunk's frame count): a
        # resumed run's frames are its uninterrupted twin's bit for bit
        lines[:, k] = (share * w).sum(axis=1) / w.sum() if w.sum() > 0 else share.mean(axis=1)
    out = {"submerged": submerged, "line_submerged": lines}
    if scene.sea.probes:
        out["probe_elevation"] = probe_elevation(scene, t)
    return out


@jit.kernel
def node_fractions(x, surface, around, nodes, out):
    """Each frame's nodes' submerged fractions (F, N) into ``out``: x (F, D, N) positions, ``surface`` (F, N)
    the surface's height over each node."""
    frames, _, n = x.shape
    for f in range(frames):
        for i in range(n):
            if nodes[RADIUS, i] > 0.0 and nodes[HALF_LO, i] + nodes[HALF_HI, i] > 0.0:
                out[f, i] = line_fraction(x[f], i, around, surface[f, i], nodes)[0]
            else:
                out[f, i] = 1.0 if x[f, 1, i] < surface[f, i] else 0.0
