"""Tension figures of a run: at both ends of the rope over time, and the largest anywhere, with where and when.

Segment j joins node j and node j + 1; "start" is segment 0 (at node 0) and "end" the last segment (at the
last node; for a loop, the one closing it). Tensions come from the run folder's per-frame ``tension`` array
(:mod:`ropesim.model.tension`), read in blocks, so a memory-mapped trajectory of any size is fine.
"""

from __future__ import annotations

import numpy as np

def tension_figures(t: np.ndarray, tension: np.ndarray, block: int) -> dict:
    """{start_N, end_N (at the last frame), start/end min and max over the run, max_N, max_segment, max_t_s},
    reading ``block`` frames at a time."""
    t = np.asarray(t)
    best, where, when = -np.inf, 0, 0
    start_range, end_range = [np.inf, -np.inf], [np.inf, -np.inf]
    for s in range(0, len(t), block):
        block_values = np.asarray(tension[s:s + block])
        k, j = np.unravel_index(int(np.nanargmax(block_values)), block_values.shape)
        if block_values[k, j] > best:
            best, where, when = float(block_values[k, j]), int(j), s + int(k)
        for column, bounds in ((block_values[:, 0], start_range), (block_values[:, -1], end_range)):
            bounds[0] = min(bounds[0], float(np.nanmin(column)))
            bounds[1] = max(bounds[1], float(np.nanmax(column)))
    last = np.asarray(tension[-1])
    return {
        "start_N": float(last[0]), "end_N": float(last[-1]),
        "start_min_N": start_range[0], "start_max_N": start_range[1],
        "end_min_N": end_range[0], "end_max_N": end_range[1],
        "max_N": best, "max_segment": where, "max_t_s": float(f"{float(t[when]):.12g}"),
    }
