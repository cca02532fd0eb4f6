"""Which saved frames a picture shows: an animation's frames at a given rate, or a few chosen times.

Times are simulated seconds. An animation plays ``speed`` simulated seconds per second of video, so video
frame k shows the saved frame nearest to t = start + k speed / fps. A run that saved frames further apart
than speed / fps cannot fill that rate: then every saved frame in the range is shown once, at the rate the
run supports (speed / saved interval), and :attr:`FramePlan.note` says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import RenderError

RELATIVE_SLACK = 1e-9  # requested times may miss the saved ones by this fraction of the run (rounding)
MIN_FPS = 0.1          # a video frame shows for at most 10 s (a GIF's delay field holds at most 655 s; players
                       # and ffmpeg refuse far slower rates)


@dataclass(frozen=True)
class FramePlan:
    """The saved-frame indices to show, in order, and the video rate [frames/s] that plays them."""

    indices: np.ndarray
    fps: float
    note: str | None = None


def run_span(t: np.ndarray) -> str:
    return f"t = {t[0]:.6g} .. {t[-1]:.6g} s"


def _slack(t: np.ndarray) -> float:
    return RELATIVE_SLACK * max(1.0, abs(float(t[-1])), abs(float(t[0])))


def check_time(t: np.ndarray, value: float, option: str) -> float:
    """``value`` [s] if it lies within the saved run ``t``; else a RenderError naming ``option``."""
    if not math.isfinite(value) or value < t[0] - _slack(t) or value > t[-1] + _slack(t):
        raise RenderError(f"{option} {value:g}: outside the run ({run_span(t)})")
    return float(value)


def nearest_frames(t: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Index of the saved frame nearest to each of ``times`` (``t`` increasing)."""
    times = np.asarray(times, dtype=float)
    if len(t) == 1:
        return np.zeros(len(times), dtype=np.int64)
    right = np.clip(np.searchsorted(t, times), 1, len(t) - 1)
    left = right - 1
    return np.where(times - t[left] <= t[right] - times, left, right).astype(np.int64)


def saved_interval(t: np.ndarray) -> float:
    """The run's time between saved frames [s] (the median, since the last interval may be shorter)."""
    return float(np.median(np.diff(t))) if len(t) > 1 else math.inf


def animation_plan(t: np.ndarray, fps: float, speed: float = 1.0, start: float | None = None,
                   end: float | None = None) -> FramePlan:
    """The frames of an animation of saved times ``t`` [s] from ``start`` to ``end`` (default: the whole run)."""
    t = np.asarray(t, dtype=float)
    if not (math.isfinite(fps) and fps > 0):
        raise RenderError(f"--fps {fps:g}: must be a positive number of frames per second")
    if not (math.isfinite(speed) and speed > 0):
        raise RenderError(f"--speed {speed:g}: must be positive (simulated seconds per second of video)")
    start = check_time(t, float(t[0]) if start is None else start, "--start")
    end = check_time(t, float(t[-1]) if end is None else end, "--end")
    if end < start:
        raise RenderError(f"--end {end:g} is before --start {start:g}")
    step = speed / fps
    interval = saved_interval(t)
    if interval > step * (1 + 1e-6) and len(t) > 1:
        inside = np.flatnonzero((t >= start - _slack(t)) & (t <= end + _slack(t)))
        rate = speed / interval
        if rate < MIN_FPS:
            raise RenderError(f"--speed {speed:g}: each saved frame (every {interval:.3g} s) would show for "
                              f"{1 / rate:.3g} s; at most {1 / MIN_FPS:g} s: use --speed {MIN_FPS * interval:.3g} "
                              f"or more")
        note = (f"the run saved a frame every {interval:.3g} s, too few for {fps:g} fps at speed {speed:g} "
                f"(one every {step:.3g} s): using its {len(inside)} saved frames at {rate:.3g} fps "
                f"(save more with --set output.interval={step:.3g})")
        return FramePlan(indices=inside, fps=rate, note=note)
    count = int(math.floor((end - start) / step + 1e-9)) + 1
    indices = nearest_frames(t, start + step * np.arange(count))
    # With step >= interval, two targets share a nearest frame only at a tie (a target halfway between two
    # frames): the later one takes the next frame, just as near. Past the last frame, repeats are dropped.
    k = np.arange(count)
    indices = np.minimum(np.maximum.accumulate(indices - k) + k, len(t) - 1)
    keep = np.r_[True, np.diff(indices) != 0]
    return FramePlan(indices=indices[keep], fps=fps)


def parse_times(text: str, option: str = "--times") -> list[float]:
    """Comma-separated times in seconds, e.g. "0,0.5,1"."""
    values = []
    for part in text.split(","):
        try:
            value = float(part.strip())
        except ValueError:
            raise RenderError(f"{option} {text}: {part.strip()!r} is not a number; give times in seconds, "
                              f"e.g. {option} 0,0.5,1") from None
        if not math.isfinite(value):
            raise RenderError(f"{option} {text}: {part.strip()!r} is not a finite time")
        values.append(value)
    return values


DEFAULT_COUNT = 6


def chosen_frames(t: np.ndarray, times: list[float] | None = None, count: int | None = None) -> np.ndarray:
    """Saved-frame indices for a frame sheet: the frames nearest to ``times``, or ``count`` (default 6) evenly
    spaced frames from the first to the last (both included); a run with fewer saved frames shows them all."""
    t = np.asarray(t, dtype=float)
    if times is not None and count is not None:
        raise RenderError("--times and --count: give one or the other")
    if times is not None:
        return nearest_frames(t, [check_time(t, s, "--times") for s in times])
    count = DEFAULT_COUNT if count is None else count
    if count < 1:
        raise RenderError(f"--count {count}: must be at least 1")
    if count >= len(t):
        return np.arange(len(t))
    return nearest_frames(t, np.linspace(t[0], t[-1], count))
