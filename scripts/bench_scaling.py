"""How cost grows with N: per step O(N); for a rope of fixed length and material, total cost O(N^2) explicit.

1. Per-step cost: the towed rope of the write-up's material per node (l = 0.5 m, 5 kg, k = 5000 N/m) at
   N = 10^2 ... 10^6, symplectic Euler and the stiff integrator (sdirk2), time per step and per node-step.
   O(N) per step means a flat time per node-step.
2. Fixed rope, finer and finer: a 100 m rope of 500 kg with EA = 2.5 MN and drag 1 kg/(s m) split into N
   nodes (l = 100 / (N - 1) m, m = 500 / N kg, k = EA / l, b = 100 / N kg/s), towed for 10 s. Its fastest
   mode's frequency grows as N, so an explicit method's stable step shrinks as 1/N: dt = 0.9 times the
   method's own bound (ropesim.analysis.stability.predicted_dt), and the total cost, N nodes times N steps, grows as
   N^2. The stiff integrator has no stability bound: it keeps dt = 10 ms at every N and grows as N. The
   fitted exponents of wall time against N are printed.

Compilation is excluded (every stepper is warmed up first); each time is the median of --repeats runs.

    python scripts/bench_scaling.py [--repeats 3] [--max-nodes 1000000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from rich.console import Console
from rich.table import Table

from benchlib import load_note, median, stepper_for, towed_scene

LENGTH, MASS, EA, DRAG_PER_M, T_END = 100.0, 500.0, 2.5e6, 1.0, 10.0
STIFF_DT = 0.01   # the stiff integrator's step at every N [s]


def per_step(n: int, method: str, repeats: int) -> float:
    """Median seconds per step of ``method`` on the write-up's towed rope with ``n`` nodes."""
    work = 2e7 if method != "sdirk2" else 1e6
    steps = max(3, int(work / n))
    times = []
    for _ in range(repeats):
        stepper = stepper_for(towed_scene(n, method, steps))
        start = time.perf_counter()
        stepper.advance(steps)
        times.append((time.perf_counter() - start) / steps)
    return median(times)


def fixed_rope(n: int, method: str, dt: float | None):
    """The fixed 100 m rope in ``n`` nodes; ``dt`` None: 0.9 of the method's stability bound."""
    seg = LENGTH / (n - 1)
    material = [f"rope.segment_length={seg!r}", f"rope.mass={MASS / n!r}", f"rope.stiffness={EA / seg!r}",
                f"drag.b={DRAG_PER_M * LENGTH / n!r}"]
    if dt is None:
        from ropesim.analysis.stability import predicted_dt
        from ropesim.model.build import build

        probe = towed_scene(n, method, 1, extra=material)
        dt = 0.9 * predicted_dt(build(probe), method)
    steps = max(1, round(T_END / dt))
    return towed_scene(n, method, steps, dt=T_END / steps, extra=material), steps


def total_time(n: int, method: str, dt: float | None, repeats: int) -> tuple[float, int, float]:
    """(median wall seconds, steps, dt) of the fixed rope towed for T_END."""
    times = []
    for _ in range(repeats):
        scene, steps = fixed_rope(n, method, dt)
        stepper = stepper_for(scene)
        start = time.perf_counter()
        stepper.advance(steps)
        times.append(time.perf_counter() - start)
    return median(times), steps, scene.integrator.dt


def slope(ns, ts) -> float:
    return float(np.polyfit(np.log(ns), np.log(ts), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--max-nodes", type=int, default=1_000_000)
    args = parser.parse_args()
    console = Console()

    sizes = [n for n in (100, 1_000, 10_000, 100_000, 1_000_000) if n <= args.max_nodes]
    table = Table(title="Cost of one step, towed rope (median)")
    for col in ("N", "symplectic Euler / step", "per node-step", "sdirk2 / step", "per node-step"):
        table.add_column(col, justify="right")
    for n in sizes:
        e, s = per_step(n, "symplectic_euler", args.repeats), per_step(n, "sdirk2", args.repeats)
        table.add_row(f"{n:,}", f"{e * 1e6:,.1f} us", f"{e / n * 1e9:.2f} ns", f"{s * 1e6:,.1f} us",
                      f"{s / n * 1e9:.1f} ns")
    console.print(table)

    ladder = [21, 42, 84, 168, 336, 672, 1344]
    table = Table(title=f"A {LENGTH:g} m rope of fixed material towed for {T_END:g} s, in N nodes: total kernel time")
    stiff_col = f"sdirk2 (dt = {STIFF_DT * 1e3:g} ms)"
    for col in ("N", "explicit dt", "steps", "symplectic Euler", stiff_col, "sdirk2 steps"):
        table.add_column(col, justify="right")
    explicit, stiff = [], []
    for n in ladder:
        te, steps, dt = total_time(n, "symplectic_euler", None, args.repeats)
        ts, ssteps, _ = total_time(n, "sdirk2", STIFF_DT, args.repeats)
        explicit.append(te)
        stiff.append(ts)
        table.add_row(str(n), f"{dt:.3g} s", f"{steps:,}", f"{te * 1e3:,.1f} ms", f"{ts * 1e3:,.1f} ms", f"{ssteps:,}")
    console.print(table)
    console.print(f"fitted exponent of total time vs N: symplectic Euler {slope(ladder, explicit):.2f} (expected 2), "
                  f"sdirk2 {slope(ladder, stiff):.2f} (expected 1); over N = 84 ... 1344 (overheads weigh less): "
                  f"{slope(ladder[2:], explicit[2:]):.2f} and {slope(ladder[2:], stiff[2:]):.2f}")
    console.print(load_note())


if __name__ == "__main__":
    main()
