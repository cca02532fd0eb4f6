"""The cost of a coupling step of one internal step against an internal step inside a plain run (target: at
most 1.5x), in one process, so that the ratio does not depend on how busy the machine is.

OC3-Hywind's three chains (tests/data/systems/oc3_hywind.toml, 63 nodes, rk4) with the spar coupled. Both are
timed on the same coupling's integrator, alternating, best of --repeat batches of --steps steps:
  - plain: ``integrator.advance(n)``, n internal steps in one compiled call, as ``ropesim run`` takes them;
  - coupled: n calls of ``Coupling.step(t, dt, x, v)`` with dt the internal step (one internal step each:
    the arrays checked, the coupled objects moved, the step, the forces on them), the spar surging. The
    caller's positions are computed before the batch: the caller's own arithmetic (x + v t, 0.7 us a step
    with NumPy) is not the coupling's cost.

Many short batches, because on a shared machine another process's burst slows the coupled batches (Python
and three compiled calls per step, more memory touched) far more than the plain ones: the best of many short
batches is each one's cost when nothing else runs, and the ratio of the two the overhead.

    python scripts/bench_coupling.py              # best of 200 batches of 100 steps
    python scripts/bench_coupling.py --method verlet --dt 0.001
"""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "tests" / "data" / "systems" / "oc3_hywind.toml"


def coupled_scene(method: str, dt: float):
    """OC3-Hywind with its spar coupled instead of driven."""
    import ropesim

    text = SCENE.read_text()
    text = re.sub(r'kind = "driven"\n(position = [^\n]*\n)amplitude = [^\n]*\nperiod = [^\n]*\nramp_time = [^\n]*\n',
                  r'kind = "coupled"\n\1', text)
    return ropesim.scene_from_toml(text, source=str(SCENE), overrides=[f"integrator.method={method}",
                                   f"integrator.dt={dt}", "initial.shape=lines"])


def main() -> None:
    import ropesim

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=200)
    ap.add_argument("--method", default="rk4")
    ap.add_argument("--dt", type=float, default=0.002)
    args = ap.parse_args()

    coupling = ropesim.Coupling(coupled_scene(args.method, args.dt))
    coupling.init(statics=False)
    integrator, h = coupling.integrator, coupling.dt
    x0 = coupling.positions()
    v = np.zeros(coupling.dofs)
    v[0] = 0.1                                     # surging at 0.1 m/s

    def plain() -> float:
        tick = time.perf_counter()
        integrator.advance(args.steps)
        return time.perf_counter() - tick

    def coupled() -> float:
        first = coupling.integrator.step
        times = [(first + k) * h for k in range(args.steps)]
        positions = [x0 + v * t for t in times]
        tick = time.perf_counter()
        for t, x in zip(times, positions):
            coupling.step(t, h, x, v)
        return time.perf_counter() - tick

    coupled()                                       # compiled and warm
    plain_best, coupled_best = float("inf"), float("inf")
    for _ in range(args.repeat):
        plain_best = min(plain_best, plain())
        coupled_best = min(coupled_best, coupled())
    per_plain, per_coupled = plain_best / args.steps * 1e6, coupled_best / args.steps * 1e6
    print(f"{SCENE.name}: {integrator.x.shape[1]} nodes, {args.method}, dt = {h:g} s, best of {args.repeat} x "
          f"{args.steps} steps")
    print(f"  internal step in a plain run : {per_plain:8.2f} us")
    print(f"  coupling step of one step    : {per_coupled:8.2f} us")
    print(f"  ratio                        : {per_coupled / per_plain:8.2f}  (target <= 1.5)")


if __name__ == "__main__":
    main()
