"""What a scene pays for force terms it does not declare: nothing.

Times the compiled loop (compilation excluded) on built-in scenes as they are, and on the same scene with
every optional term it does not use declared but placed or sized so that it changes (next to) nothing the
rope does:

- the seed's helicopter scenes (per-node rope, linear drag): the shooter's thrower box and two guide circles
  far away, bending springs with a tiny stiffness, and a seabed a kilometre below;
- helicopter_crosswind (a rope in physical units with quadratic drag in a wind): a seabed a kilometre below,
  bending stiffness EI, anisotropic linear drag, buoyancy and added mass of a near-weightless fluid's worth
  (which also brings in the flow's inertia force, its wind being ramped), and a body of negligible drag area.

An undeclared term is not compiled at all (its compile-time switch is off, see ropesim/model/jit.py), so it
costs nothing; the ratio (padded / as declared) is what a scene would pay if the kernel evaluated every term.
The two variants alternate, repeat by repeat, so both see the same machine load, and the fastest call of each
is kept (load only ever adds time).

    python scripts/bench_unused_terms.py [--steps 100000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

import ropesim
from ropesim.analysis.stability import predicted_dt
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build

ROOT = Path(__file__).resolve().parent.parent
SEED_UNUSED = [
    "thrower.center=[1000.0, 1000.0]", "thrower.length=1.0", "thrower.width=1.0", "thrower.v_max=5.0",
    "thrower.b_thrower=50.0",
    "guides.0.center=[-1000.0, 1000.0]", "guides.0.radius=1.0", "guides.0.omega0=60.0",
    "guides.1.center=[1000.0, -1000.0]", "guides.1.radius=1.0", "guides.1.omega0=60.0",
    "bending.stiffness=1e-9",
    "seabed.height=-1000.0", "seabed.contact_width=0.01", "seabed.friction=0.5",
]
PHYSICAL_UNUSED = [
    "seabed.height=-1000.0", "seabed.friction=0.5",
    "rope.EI=1e-9",
    "viscous_drag.b_normal=1e-9", "viscous_drag.b_tangential=1e-9",
    "buoyancy={}", "added_mass.ca_normal=1e-9",
    "bodies.1.node=10", "bodies.1.cd_area=1e-12",
]
CASES = {   # label: (scene, method, terms declared but inert)
    "helicopter_uniform symplectic_euler": ("helicopter_uniform", "symplectic_euler", SEED_UNUSED),
    "helicopter_mass rk4": ("helicopter_mass", "rk4", SEED_UNUSED),
    "helicopter_parachute verlet": ("helicopter_parachute", "verlet", SEED_UNUSED),
    "helicopter_crosswind rk4": ("helicopter_crosswind", "rk4", PHYSICAL_UNUSED),
    "helicopter_crosswind sdirk2": ("helicopter_crosswind", "sdirk2", PHYSICAL_UNUSED),
}


def integrator(scene_name: str, method: str, sets: list[str], steps: int, repeats: int):
    """A warmed-up integrator of the built-in scene with ``sets`` applied, long enough for every timed call."""
    as_filed = ropesim.load_scene(ROOT / "scenarios" / f"{scene_name}.toml")
    dt = as_filed.integrator.dt
    if method != "sdirk2":   # the explicit methods at half their largest stable step, and at most the scene's
        dt = min(dt, 0.5 * predicted_dt(build(as_filed), method))
    scene = ropesim.load_scene(ROOT / "scenarios" / f"{scene_name}.toml",
                               sets + [f"integrator.method={method}", f"integrator.dt={dt!r}",
                                       f"integrator.t_end={dt * steps * (repeats + 2)!r}"])
    stepper = make_integrator(build(scene), TimeGrid.of(scene), method)
    stepper.warm_up()
    return stepper


def fastest_call(pair, steps: int, repeats: int) -> list[float]:
    """The fastest of ``repeats`` timed calls of ``steps`` steps for each integrator, the two alternating."""
    best = [float("inf")] * len(pair)
    for _ in range(repeats):
        for k, stepper in enumerate(pair):
            start = time.perf_counter()
            stepper.advance(steps)
            best[k] = min(best[k], time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000, help="steps per timed call (sdirk2: a tenth)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    table = Table(title=f"Time per step, fastest of {args.repeats} alternating calls, compilation excluded")
    for col in ("scene and method", "declared terms only", "+ unused terms, inert", "ratio"):
        table.add_column(col, justify="right" if col != "scene and method" else "left")
    for label, (name, method, unused) in CASES.items():
        steps = args.steps // 10 if method == "sdirk2" else args.steps
        pair = [integrator(name, method, sets, steps, args.repeats) for sets in ([], unused)]
        plain, padded = fastest_call(pair, steps, args.repeats)
        table.add_row(label, f"{plain / steps * 1e6:.2f} us", f"{padded / steps * 1e6:.2f} us",
                      f"{padded / plain:.2f}x")
    Console(width=100).print(table)


if __name__ == "__main__":
    main()
