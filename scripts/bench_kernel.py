"""Kernel throughput: ropesim's compiled loop against a minimal hand-written Numba loop and a NumPy step.

The physics is the towed rope (scenarios/helicopter_uniform.toml: a 2-D open line of N nodes, node 0 driven
at 8 m/s, Hookean springs, gravity, linear drag integrated exactly in the kick, symplectic Euler, dt = 1 ms).

1. The yardstick, written below in the plainest fast form: structure-of-arrays rows, one loop computing each
   spring's force into a buffer, one loop kicking and drifting every free node, `error_model="numpy"`. Both
   loops vectorise. It knows nothing but this scene: no held-node list, no energy ledger, no blow-up checks.
2. The same step written with vectorised NumPy array operations (buffers preallocated).
3. ropesim's own compiled loop (its splitting integrator, here on its plain stage :mod:`ropesim.integrate.plain`),
   everything included: per-node masses and drag, held nodes, the energy ledger, the blow-up check every
   64 steps.

All three start from the same state, run the same steps and end at the same positions (checked). They run
interleaved in one process; the table shows the median rates and the median of the per-round ratios.
Then node-steps per second for every integrator from N = 21 to N = 10^6, and the cost of a step of every
integrator on `shooter_high` (N = 60, the general loop with bending, thrower and guide circles).

    python scripts/bench_kernel.py [--repeats 7] [--work 2e7] [--sizes 21,60,1000] [--skip-methods]
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from numba import njit
from rich.console import Console
from rich.table import Table

from benchlib import ROOT, interleaved, load_note, median, median_ratio, rate, stepper_for, towed_scene

L0, K, M, B, G, V = 0.5, 5000.0, 5.0, 5.0, 9.81, 8.0   # helicopter_uniform's rope, drag and tow speed


@njit(error_model="numpy")
def yardstick(x, v, f, steps, h, k, rest, inv_m, g, decay, gain, x0, vx, t0):
    """``steps`` symplectic Euler steps of the towed rope; ``f`` (2, N + 1) holds the spring forces / m."""
    n = x.shape[1]
    px, py, vv, vw, fx, fy = x[0], x[1], v[0], v[1], f[0], f[1]
    km = k * inv_m
    for s in range(steps):
        for i in range(n - 1):           # spring (i, i + 1), force on node i per unit mass, into f[:, i + 1]
            dx = px[i + 1] - px[i]
            dy = py[i + 1] - py[i]
            c = km * (1.0 - rest / np.sqrt(dx * dx + dy * dy))
            fx[i + 1] = c * dx
            fy[i + 1] = c * dy
        fx[n] = 0.0
        fy[n] = 0.0
        for i in range(1, n):            # kick (drag exact) then drift, free nodes
            u = decay * vv[i] + gain * (fx[i + 1] - fx[i])
            w = decay * vw[i] + gain * (fy[i + 1] - fy[i] - g)
            vv[i] = u
            vw[i] = w
            px[i] += h * u
            py[i] += h * w
        t = t0 + (s + 1) * h             # the driven node
        px[0] = x0[0] + vx * t
        py[0] = x0[1]



def drag_factors(h: float) -> tuple[float, float]:
    """(decay, gain) of the exact drag kick over a step h [s]: v <- decay v + gain a, with gamma = b / m."""
    gamma = B / M
    return math.exp(-gamma * h), -math.expm1(-gamma * h) / gamma

class NumpyStep:
    """The same step with whole-array NumPy operations on (2, N) arrays."""

    def __init__(self, x, v):
        self.x, self.v = x, v
        n = x.shape[1]
        self.d = np.empty((2, n - 1))
        self.r = np.empty(n - 1)
        self.a = np.empty((2, n))
        self.x0 = x[:, 0].copy()
        self.step = 0

    def run(self, steps, h, decay, gain):
        x, v, d, r, a = self.x, self.v, self.d, self.r, self.a
        for _ in range(steps):
            np.subtract(x[:, 1:], x[:, :-1], out=d)
            np.sqrt(np.einsum("ij,ij->j", d, d), out=r)
            d *= K / M * (1.0 - L0 / r)
            a[:] = 0.0
            a[1] -= G
            a[:, :-1] += d
            a[:, 1:] -= d
            v[:, 1:] *= decay
            v[:, 1:] += gain * a[:, 1:]
            x += h * v
            self.step += 1
            x[:, 0] = self.x0
            x[0, 0] += V * self.step * h


def compare(n: int, repeats: int, work: float) -> tuple:
    """(rates, ratios, max position difference) of the three contenders at N = n."""
    steps = max(10, int(work / n))
    scene = towed_scene(n, "symplectic_euler", steps * (repeats + 2))
    stepper = stepper_for(scene)
    h = stepper.grid.dt
    decay, gain = drag_factors(h)
    xy, vy = stepper.x.copy(), stepper.v.copy()
    f = np.zeros((2, n + 1))
    yardstick(xy.copy(), vy.copy(), f, 1, h, K, L0, 1.0 / M, G, decay, gain, xy[:, 0].copy(), V, 0.0)  # compile
    x0 = xy[:, 0].copy()
    done = {"yard": 0}

    def run_yard():
        yardstick(xy, vy, f, steps, h, K, L0, 1.0 / M, G, decay, gain, x0, V, done["yard"] * h)
        done["yard"] += steps

    npstep = NumpyStep(stepper.x.copy(), stepper.v.copy())
    np_steps = max(3, steps // 50)   # NumPy is far slower: time fewer steps, compare rates

    times = interleaved({"yardstick": run_yard,
                         "numpy": lambda: npstep.run(np_steps, h, decay, gain),
                         "ropesim": lambda: stepper.advance(steps)}, repeats)
    per_step = {"yardstick": [t / steps for t in times["yardstick"]],
                "numpy": [t / np_steps for t in times["numpy"]],
                "ropesim": [t / steps for t in times["ropesim"]]}
    rates = {k: n / median(ts) for k, ts in per_step.items()}
    ratios = {"of yardstick": median_ratio(per_step["yardstick"], per_step["ropesim"]),
              "x numpy": median_ratio(per_step["numpy"], per_step["ropesim"])}
    return rates, ratios, same_physics(n, 2000)


def same_physics(n: int, steps: int) -> float:
    """Largest difference [m] between the three contenders' positions after ``steps`` steps from rest."""
    stepper = stepper_for(towed_scene(n, "symplectic_euler", steps))
    h = stepper.grid.dt
    decay, gain = drag_factors(h)
    x, v = stepper.x.copy(), stepper.v.copy()
    npstep = NumpyStep(stepper.x.copy(), stepper.v.copy())
    yardstick(x, v, np.zeros((2, n + 1)), steps, h, K, L0, 1.0 / M, G, decay, gain, x[:, 0].copy(), V, 0.0)
    npstep.run(steps, h, decay, gain)
    stepper.advance(steps)
    return float(max(np.abs(stepper.x - x).max(), np.abs(stepper.x - npstep.x).max()))


def method_rates(sizes: list[int], work: float, repeats: int) -> dict:
    """Median node-steps per second of every integrator at every size."""
    from ropesim.integrate.methods import METHODS

    out = {}
    for name, method in METHODS.items():
        slow = 20.0 if method.kind == "implicit" else 1.0   # the stiff solver does a Newton solve per stage
        for n in sizes:
            steps = max(3, int(work / n / method.evaluations / slow))
            stepper = stepper_for(towed_scene(n, name, steps * (repeats + 2)))
            t = interleaved({"run": lambda: stepper.advance(steps)}, repeats)["run"]
            out[name, n] = n * steps / median(t)
    return out


def shooter_step_times(repeats: int) -> dict:
    """Median wall time [s] of one step of every integrator on scenarios/shooter_high.toml."""
    import ropesim
    from ropesim.integrate.methods import METHODS

    out = {}
    for name, method in METHODS.items():
        steps = 200 if method.kind == "implicit" else 5000
        scene = ropesim.load_scene(ROOT / "scenarios" / "shooter_high.toml",
                                   [f"integrator.method={name}", f"integrator.t_end={steps * (repeats + 2) * 1e-3!r}"])
        stepper = stepper_for(scene)
        out[name] = median(interleaved({"run": lambda: stepper.advance(steps)}, repeats)["run"]) / steps
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--work", type=float, default=2e7, help="node-steps per timed call (default 2e7)")
    parser.add_argument("--sizes", default="21,60,1000")
    parser.add_argument("--method-sizes", default="21,100,1000,10000,100000,1000000")
    parser.add_argument("--skip-methods", action="store_true", help="only the yardstick comparison")
    args = parser.parse_args()
    console = Console()

    table = Table(title="Towed rope, symplectic Euler: node-steps per second (median of "
                        f"{args.repeats} interleaved rounds)")
    for col in ("N", "yardstick loop", "NumPy step", "ropesim", "ropesim / yardstick", "ropesim / NumPy",
                "max |x diff| [m]"):
        table.add_column(col, justify="right")
    for n in (int(s) for s in args.sizes.split(",")):
        rates, ratios, diff = compare(n, args.repeats, args.work)
        table.add_row(str(n), rate(rates["yardstick"], 1), rate(rates["numpy"], 1), rate(rates["ropesim"], 1),
                      f"{ratios['of yardstick']:.0%}", f"{ratios['x numpy']:.0f}x", f"{diff:.1e}")
    console.print(table)
    console.print("targets: ropesim >= 90 % of the yardstick and >= 30x NumPy at N = 21, 60 and 1000; "
                  + load_note())
    if args.skip_methods:
        return

    sizes = [int(s) for s in args.method_sizes.split(",")]
    rates = method_rates(sizes, args.work, max(3, args.repeats // 2))
    table = Table(title="Every integrator, towed rope: node-steps per second (median), compilation excluded")
    table.add_column("method")
    for n in sizes:
        table.add_column(f"N = {n:,}", justify="right")
    from ropesim.integrate.methods import METHODS

    for name in METHODS:
        table.add_row(name, *(rate(rates[name, n], 1) for n in sizes))
    console.print(table)
    table = Table(title="Every integrator, shooter_high (N = 60, general loop): one step (median)")
    table.add_column("method")
    table.add_column("per step", justify="right")
    for name, t in shooter_step_times(max(3, args.repeats // 2)).items():
        table.add_row(name, f"{t * 1e6:,.1f} µs")
    console.print(table)
    console.print(load_note())


if __name__ == "__main__":
    main()
