"""The stiff integrator's cost per step grows linearly with N (banded Newton solve), open line and closed loop.

    python scripts/bench_stiff.py

Times sdirk2 (and verlet, for the ratio) on a hanging rope and a closed loop with bending, N = 100 .. 10,000,
and prints microseconds per node-step and Newton iterations per step. Ratios within one run are what count.
"""

from __future__ import annotations

import textwrap
import time

from ropesim.model.build import build
from ropesim.scene.loader import scene_from_toml
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator


def scene(n: int, closed: bool, method: str, steps: int):
    extra = "closed = true\n[bending]\nstiffness = 1e4" if closed else ""
    shape = ('shape = "square_loop"\ntop_center = [0.0, 0.0]' if closed else 'shape = "hanging"\ntop = [0.0, 0.0]')
    return scene_from_toml(textwrap.dedent(f"""
        name = "bench"
        dimension = 2
        [rope]
        nodes = {n}
        segment_length = 0.1
        stiffness = 1e6
        mass = 0.01
        {extra}
        [initial]
        {shape}
        velocity = [1.0, 0.0]
        [gravity]
        [drag]
        b = 0.01
        [integrator]
        method = "{method}"
        dt = 1e-3
        t_end = {steps * 1e-3}
        [output]
        interval = {steps * 1e-3}
    """).replace("        ", ""))


def per_node_step(n: int, closed: bool, method: str, steps: int = 50) -> tuple[float, float]:
    sc = scene(n, closed, method, steps)
    model, grid = build(sc), TimeGrid.of(sc)
    best, iters = float("inf"), 0.0
    for _ in range(3):
        st = make_integrator(model, grid, method)
        st.warm_up()
        t = time.perf_counter()
        st.advance(grid.steps)
        best = min(best, time.perf_counter() - t)
        iters = st.force_evaluations / grid.steps
    return best / (n * grid.steps) * 1e6, iters


def main() -> None:
    print(f"{'shape':6s} {'N':>6s} {'sdirk2 us/node-step':>20s} {'Newton its/step':>16s}")
    for closed in (False, True):
        for n in (100, 1000, 10000):
            us, its = per_node_step(n, closed, "sdirk2")
            print(f"{'loop' if closed else 'line':6s} {n:6d} {us:20.3f} {its:16.1f}")


if __name__ == "__main__":
    main()
