"""The kernel's cost per node and step [ns] of each integrator: what ``run.NS_PER_NODE_STEP`` holds (the run-time
estimate of `ropesim run` and `ropesim check`).

helicopter_mass at 21 and 201 nodes (its own dt, 1 ms), each method warmed up (compiled or loaded) first, then
timed in CPU seconds over the same simulated time, all in one process; the larger of the two sizes is the figure.
Machines and loads differ: compare the ratios between methods, measured in one run, before the absolute numbers.

    python scripts/bench_node_step.py [--steps 2000] [--methods galpha,sdirk2,rk4]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import METHODS, make_integrator
from ropesim.model.build import build
from ropesim.run import NS_PER_NODE_STEP
from ropesim.scene.builtin import builtin_path
from ropesim.scene.loader import load_scene


def cost(method: str, nodes: int, steps: int) -> float:
    """CPU ns per node and step of ``method`` on helicopter_mass with ``nodes`` nodes over ``steps`` steps."""
    scene = load_scene(builtin_path("helicopter_mass"), [f"rope.nodes={nodes}", f"integrator.method={method}"])
    scene = replace(scene, integrator=replace(scene.integrator, t_end=steps * scene.integrator.dt))
    it = make_integrator(build(scene), TimeGrid.of(scene))
    it.advance(1)   # compile or load, and the start
    start = time.process_time()
    result = it.advance(steps - 1)
    elapsed = time.process_time() - start
    assert result.status == 0, (method, nodes, result)
    return 1e9 * elapsed / (nodes * (steps - 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--methods", default=",".join(METHODS))
    args = parser.parse_args()
    print("| method | ns per node and step, 21 nodes | 201 nodes | run.NS_PER_NODE_STEP |")
    print("|---|---|---|---|")
    for method in args.methods.split(","):
        small, large = cost(method, 21, args.steps), cost(method, 201, args.steps)
        print(f"| {method} | {small:.1f} | {large:.1f} | {NS_PER_NODE_STEP.get(method, '-')} |", flush=True)


if __name__ == "__main__":
    main()
