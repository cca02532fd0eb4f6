"""Shared pieces of the benchmark scripts: the towed-rope scene, interleaved timing, medians, tables.

The machine is shared, so no absolute time is trusted on its own: every comparison times its contenders
interleaved (A, B, C, A, B, C, ...) within one process, and reports the median of each and the median of the
per-round ratios.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parent.parent
TOWED = ROOT / "scenarios" / "helicopter_uniform.toml"   # N = 21, l = 0.5 m, k = 5000 N/m, m = 5 kg, b = 5 kg/s


def towed_scene(nodes: int, method: str = "symplectic_euler", steps: int = 1000, dt: float | None = None,
                extra: list[str] | tuple[str, ...] = ()):
    """The helicopter's uniform towed rope with ``nodes`` nodes, long enough for ``steps`` steps, one frame saved.

    Segment length, stiffness, node mass and drag stay the write-up's (l = 0.5 m, k = 5000 N/m, m = 5 kg,
    b = 5 kg/s), so a longer rope is a longer rope of the same material.
    """
    import ropesim

    h = dt if dt is not None else 0.001
    t_end = steps * h
    sets = [f"rope.nodes={nodes}", f"integrator.method={method}", f"integrator.dt={h!r}",
            f"integrator.t_end={t_end!r}", f"output.interval={t_end!r}", *extra]
    return ropesim.load_scene(TOWED, sets)


def stepper_for(scene):
    """A warmed-up integrator (:mod:`ropesim.integrate.base`) for ``scene`` (its loop compiled or loaded from
    the cache)."""
    from ropesim.integrate.grid import TimeGrid
    from ropesim.integrate.methods import make_integrator
    from ropesim.model.build import build

    stepper = make_integrator(build(scene), TimeGrid.of(scene))
    stepper.warm_up()
    return stepper


def interleaved(contenders: dict[str, Callable[[], object]], repeats: int) -> dict[str, list[float]]:
    """Wall seconds of each contender, run in turn ``repeats`` times (after one untimed warm-up round)."""
    times: dict[str, list[float]] = {name: [] for name in contenders}
    for rnd in range(repeats + 1):
        for name, fn in contenders.items():
            start = time.perf_counter()
            fn()
            elapsed = time.perf_counter() - start
            if rnd:
                times[name].append(elapsed)
    return times


def median(xs) -> float:
    return statistics.median(xs)


def median_ratio(num: list[float], den: list[float]) -> float:
    """Median over rounds of num[i] / den[i] (same-round pairs see the same machine load)."""
    return statistics.median(a / b for a, b in zip(num, den))


def rate(node_steps: float, seconds: float) -> str:
    """Node-steps per second, human-readable (M/s)."""
    return f"{node_steps / seconds / 1e6:,.1f} M/s"


def seconds(s: float) -> str:
    return f"{s * 1e3:,.1f} ms" if s < 1 else f"{s:,.2f} s"


def load_note() -> str:
    """One line on how busy the machine was (1-minute load average over the core count)."""
    import os

    try:
        load = os.getloadavg()[0]
    except OSError:
        return ""
    return f"load average {load:.2f} on {os.cpu_count()} cores during the run"
