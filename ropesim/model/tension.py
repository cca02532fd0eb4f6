"""Tension and strain along the rope, per saved frame: what the run folder stores beside positions.

Segment j joins node j and node j + 1 (node 0 for a loop's last segment). Its tension [N] is the axial force
of :func:`ropesim.model.forces.springs.segment_forces` (the spring's k (r - l0), none while a slack segment
is short, plus the axial damping), positive when it pulls; its strain is r / l0 - 1.
"""

from __future__ import annotations

import numpy as np

from .forces.springs import pair_spring_stretch, segment_forces

FRAME_ARRAYS = ("tension", "strain")   # per saved frame, (F, S) each, S the number of segments


def segment_count(model) -> int:
    rope = model.scene.rope
    return rope.nodes if rope.closed else rope.nodes - 1


def frame_arrays(model, x: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """{"tension": (F, S) [N], "strain": (F, S) [-]} for frames x, v (F, N, D)."""
    rope = model.scene.rope
    return {"tension": segment_forces(model, x, v),
            "strain": pair_spring_stretch(x, rope.segment_length, 1, rope.closed)}


def end_tensions(model, tension: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tension [N] at the rope's two ends per frame: its first and last segments (a loop: segment 0 twice)."""
    return tension[..., 0], tension[..., -1]
