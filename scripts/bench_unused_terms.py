"""What a scene pays for force terms it does not declare: nothing.

Times the compiled kernel (compilation excluded, median of repeats) on each helicopter scene as it is, and on
the same scene with the shooter's thrower box, two guide circles and bending springs declared but placed or
sized so they change nothing the rope does (box and circles far away, bending springs with a tiny stiffness).
The ratio is the cost a helicopter scene would pay if the kernel evaluated every term; because each optional
term sits behind its own flag, an undeclared term costs one predictable branch per force evaluation.

    python scripts/bench_unused_terms.py [--steps 200000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

import ropesim
from ropesim.model.build import build
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator

ROOT = Path(__file__).resolve().parent.parent
UNUSED = [
    "thrower.center=[1000.0, 1000.0]", "thrower.length=1.0", "thrower.width=1.0", "thrower.v_max=5.0",
    "thrower.b_thrower=50.0",
    "guides.0.center=[-1000.0, 1000.0]", "guides.0.radius=1.0", "guides.0.omega0=60.0",
    "guides.1.center=[1000.0, -1000.0]", "guides.1.radius=1.0", "guides.1.omega0=60.0",
    "bending.stiffness=1e-9",
]


def kernel_seconds(scene, steps: int, repeats: int) -> float:
    """Median wall time of ``steps`` steps of the compiled loop."""
    model = build(scene)
    grid = TimeGrid.of(scene)
    times = []
    for _ in range(repeats + 1):
        stepper = make_integrator(model, grid, scene.integrator.method)
        stepper.warm_up()
        start = time.perf_counter()
        stepper.advance(steps)
        times.append(time.perf_counter() - start)
    return statistics.median(times[1:])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    long_run = [f"integrator.t_end={args.steps * 0.001 * 2}"]
    table = Table(title=f"Kernel time, {args.steps} steps (median of {args.repeats}), compilation excluded")
    for col in ("scene", "declared terms only", "+ unused box, circles, bending", "ratio"):
        table.add_column(col, justify="right" if col != "scene" else "left")
    for name in ("helicopter_uniform", "helicopter_mass", "helicopter_parachute"):
        path = ROOT / "scenarios" / f"{name}.toml"
        plain = kernel_seconds(ropesim.load_scene(path, long_run), args.steps, args.repeats)
        padded = kernel_seconds(ropesim.load_scene(path, long_run + UNUSED), args.steps, args.repeats)
        table.add_row(name, f"{plain * 1e3:.1f} ms", f"{padded * 1e3:.1f} ms", f"{padded / plain:.2f}x")
    Console().print(table)


if __name__ == "__main__":
    main()
