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


KILO = 1e3


def force_unit(largest: float) -> tuple[str, float]:
    """("kN", 1000) where forces reach kilonewtons (``largest`` [N] at least 1000), else ("N", 1)."""
    return ("kN", KILO) if abs(largest) >= KILO else ("N", 1.0)


def frame_window(t: np.ndarray, start: float | None = None, stop: float | None = None) -> slice:
    """The frames with start <= t <= stop (either end open when None), as a slice; ValueError (one line naming
    --from/--to and the run's span) when none is left."""
    t = np.asarray(t)
    lo = 0 if start is None else int(np.searchsorted(t, start - 1e-9 * max(1.0, abs(start)), side="left"))
    hi = len(t) if stop is None else int(np.searchsorted(t, stop + 1e-9 * max(1.0, abs(stop)), side="right"))
    if (start is not None and stop is not None and stop < start) or hi <= lo:
        raise ValueError(f"--from {start if start is not None else t[0]:g} --to {stop if stop is not None else t[-1]:g}: "
                         f"no saved frame in that window; the run has frames from t = {float(t[0]):g} to "
                         f"{float(t[-1]):g} s")
    return slice(lo, hi)


def window_statistics(values, frames: slice, block: int = 256) -> dict[str, np.ndarray]:
    """min, max, mean and std (population) over the frames ``frames`` of ``values`` (F, ...) per entry, read
    ``block`` frames at a time (a memory-mapped run of any length): two passes, the second about the mean."""
    lo, hi = frames.start, frames.stop
    count = hi - lo
    low = high = total = None
    for s in range(lo, hi, block):
        part = np.asarray(values[s:min(hi, s + block)], dtype=float)
        low = part.min(axis=0) if low is None else np.minimum(low, part.min(axis=0))
        high = part.max(axis=0) if high is None else np.maximum(high, part.max(axis=0))
        total = part.sum(axis=0) if total is None else total + part.sum(axis=0)
    mean = total / count
    spread = np.zeros_like(mean)
    for s in range(lo, hi, block):
        part = np.asarray(values[s:min(hi, s + block)], dtype=float)
        spread += ((part - mean) ** 2).sum(axis=0)
    return {"min": low, "max": high, "mean": mean, "std": np.sqrt(spread / count)}


def windowed_figures(traj, start: float | None = None, stop: float | None = None) -> dict:
    """The tension and support figures of a run over the window [start, stop] [s] (the whole run by default):
    per segment min / max / mean / std of tension [N], the two end tensions' and each support force
    magnitude's, the largest tension with where and when, and the unit to print them in. A rope's are at the
    top level; a system's per line, under ``lines`` by line id (its segments numbered from its start), with
    ``support_labels`` naming each support by its point and line end."""
    from ..model.layout import line_layouts

    frames = frame_window(traj.t, start, stop)
    t = np.asarray(traj.t[frames])
    out = {"from_s": float(f"{float(t[0]):.12g}"), "to_s": float(f"{float(t[-1]):.12g}"), "frames": int(len(t))}
    lines, first = {}, 0
    for line in line_layouts(traj.scene):
        lines[line.id] = _line_window(traj.tension[:, first:first + line.segments], t, frames)
        first += line.segments
    if traj.scene.is_system:
        out["lines"] = lines
    else:
        out.update(lines["rope"])
    largest = max(float(np.max(np.abs(figures["segments"]["max"]))) for figures in lines.values())
    if traj.support is not None:
        magnitude = np.linalg.norm(np.asarray(traj.support[frames]), axis=2)
        stats = window_statistics(magnitude, slice(0, len(t)))
        out["supports"] = [{name: float(values[h]) for name, values in stats.items()} for h in range(magnitude.shape[1])]
        if traj.scene.is_system:
            from ..model.build import build

            out["support_labels"] = support_labels(traj.scene, build(traj.scene, solve=False).held_idx)
        largest = max(largest, float(stats["max"].max()))
    out["unit"] = force_unit(largest)[0]
    return out


def _line_window(tension, t: np.ndarray, frames: slice) -> dict:
    """One line's figures over ``frames``: per segment statistics, its two ends', the largest with where and
    when (``tension`` (F, S) [N], all frames; ``t`` the window's times)."""
    along = window_statistics(tension, frames)
    k, j = np.unravel_index(int(np.argmax(np.asarray(tension[frames]))), (len(t), tension.shape[1]))
    return {"segments": {name: values.tolist() for name, values in along.items()},
            "start": {name: float(values[0]) for name, values in along.items()},
            "end": {name: float(values[-1]) for name, values in along.items()},
            "max_N": float(tension[frames.start + k, j]), "max_segment": int(j),
            "max_t_s": float(f"{float(t[k]):.12g}")}


def end_columns(model) -> list[tuple[str, int]]:
    """(label, column in the frames' tension array) of every line end: a rope's "segment 0 (at node 0)" and its
    last segment's; a system's "LINE start (POINT)" and "LINE end (POINT)"."""
    from ..model.tension import line_segments

    if not model.scene.is_system:
        last = sum(line.segments for line in model.lines) - 1
        return [("segment 0 (at node 0)", 0)] + ([(f"segment {last} (the other end)", last)] if last > 0 else [])
    out = []
    for line, part in zip(model.scene.lines, line_segments(model)):
        out += [(f"{line.id} start ({line.start})", part.start), (f"{line.id} end ({line.end})", part.stop - 1)]
    return out


def support_labels(scene, held) -> list[str]:
    """A system's supports, its held nodes ``held`` (in node order: a fixed or driven point's line ends, and
    those on a fixed or driven body's points), each by the point that holds it and the line end there:
    "anchor1 (line1's start)"."""
    from ..model.layout import line_layouts

    ends = {}
    for line, layout in zip(scene.lines, line_layouts(scene)):
        ends[layout.first] = f"{line.start} ({line.id}'s start)"
        ends[layout.end - 1] = f"{line.end} ({line.id}'s end)"
    return [ends.get(int(node), f"node {int(node)}") for node in held]
