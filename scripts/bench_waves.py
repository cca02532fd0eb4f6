"""What the wave kinematics cost per node and evaluation, for 1, 50 and 200 components.

Times ropesim.model.waves.node_kinematics (the surface, the water's velocity and acceleration at every node of a
line at one time) on a JONSWAP sea cut into J components, two ways:

- ``recurrence``: the spectrum's evenly spaced wave numbers, the spatial factors advanced by a complex
  multiplication per component (what a spectrum gets);
- ``direct``: the same components as a table, each evaluated with its own sines, cosines and exponentials
  (what a table of components gets).

Each evaluation is at a new time, so the J time factors are recomputed every time, as in a run (one time per
stage). The contenders alternate round by round on the shared machine and the fastest round of each is kept.

    python scripts/bench_waves.py [--nodes 100] [--calls 2000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from rich.console import Console
from rich.table import Table

from benchlib import load_note
from ropesim.model import waves as W

G = 9.80665


def evaluator(field: W.WaveField, nodes: int, direct: bool):
    if direct:
        c = field.components
        field = W.WaveField(W.Components(c.amplitude, c.omega, c.k, c.phase, c.direction), field.level,
                            field.depth, field.g)
    scalars, comps = W.compiled_tables(field)
    x = np.vstack([np.linspace(0.0, 400.0, nodes), np.linspace(-50.0, 0.0, nodes), np.zeros(nodes)])
    work, out = np.zeros((W.NODE_ROWS, nodes)), np.zeros((7, nodes))
    W.node_kinematics(x, 0.0, scalars, comps, work, out)   # compile / load from the cache

    def run(calls: int) -> float:
        start = time.perf_counter()
        for step in range(calls):
            W.node_kinematics(x, 0.01 * (step + 1), scalars, comps, work, out)
        return time.perf_counter() - start

    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=100)
    parser.add_argument("--calls", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    table = Table(title=f"wave kinematics, {args.nodes} nodes in 50 m of water (ns per node and evaluation)")
    for column in ("components", "recurrence", "direct", "direct / recurrence"):
        table.add_column(column, justify="right")
    for count in (1, 50, 200):
        c = W.spectral_components(6.0, 10.0, 3.3, count, W.default_range(10.0), 50.0, G, seed=0, direction=0.0)
        field = W.WaveField(c, level=0.0, depth=50.0, g=G)
        runs = {"recurrence": evaluator(field, args.nodes, False), "direct": evaluator(field, args.nodes, True)}
        best = {name: math.inf for name in runs}
        for _ in range(args.repeats):
            for name, run in runs.items():
                best[name] = min(best[name], run(args.calls))
        per = {name: best[name] / (args.calls * args.nodes) * 1e9 for name in runs}
        table.add_row(str(count), f"{per['recurrence']:.0f}", f"{per['direct']:.0f}",
                      f"{per['direct'] / per['recurrence']:.2f}")
    console = Console()
    console.print(table)
    console.print(load_note())


if __name__ == "__main__":
    main()
