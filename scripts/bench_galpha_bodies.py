"""galpha on a free rigid body against rk4 at equal accuracy: the OC3 spar on its three chains.

spread_mooring_free with its spar thrown from its balance (0.5 m/s downstream, 0.2 m/s across, turning at
0.3 deg/s about its axis), over 30 s: the error at the end (the spar's reference point, every chain node)
against rk4 at 1 ms, and the CPU seconds of each loop (compiled or loaded before the clock starts), all in one
process: compare the ratios. galpha at its default rho_inf (0.9) and at 0 (the moorings' setting), with its Newton
iterations and factorisations (whole run). ``--no-seabed-damping`` switches the seabed's contact damping off (what
limits galpha's fixed steps on this scene at rho_inf 0.9; the body does not).

    python scripts/bench_galpha_bodies.py [--t-end 30] [--no-seabed-damping]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build
from ropesim.scene.builtin import builtin_path
from ropesim.scene.loader import scene_from_toml


def thrown_spar(seabed_damping: bool):
    text = builtin_path("spread_mooring_free").read_text()
    text = text.replace('kind = "free"\n', 'kind = "free"\nvelocity = [0.5, 0.0, 0.2]\n'
                                           'angular_velocity = [0.0, 0.3, 0.0]\n', 1)
    return scene_from_toml(text if seabed_damping else text.replace("damping = 3.0e5", "damping = 0.0"))


def run(scene, t_end: float, method: str, dt: float, **keys):
    """(integrator, status, CPU seconds of the loop) of ``scene`` to ``t_end``."""
    scene = replace(scene, integrator=replace(scene.integrator, method=method, dt=dt, t_end=t_end, **keys))
    it = make_integrator(build(scene), TimeGrid.of(scene))
    it.advance(1)   # compile or load
    start = time.process_time()
    result = it.advance(TimeGrid.of(scene).steps - 1)
    return it, result, time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--no-seabed-damping", action="store_true")
    args = parser.parse_args()
    scene = thrown_spar(not args.no_seabed_damping)
    reference = run(scene, args.t_end, "rk4", 1e-3)[0]
    cases = [("rk4", 0.004, {}), ("rk4", 0.002, {})]
    for rho in (None, 0.0):   # galpha's default rho_inf (0.9), and 0 (the moorings' setting)
        keys = {} if rho is None else {"rho_inf": rho}
        cases += [("galpha", dt, keys) for dt in (0.5, 0.2, 0.1, 0.05)]
        cases += [("galpha", 0.5, {"tolerance": tol, **keys}) for tol in (1e-1, 1e-2, 1e-3)]
    print("| method | rho_inf | dt [s] | tolerance [m] | CPU [s] | error spar [m] | error nodes [m] | steps | "
          "Newton iterations | factorisations |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for method, dt, keys in cases:
        it, result, cpu = run(scene, args.t_end, method, dt, **keys)
        report = it.step_report() if method == "galpha" else None
        steps = report["steps_taken"] if report else it.step
        rho = f"{it.rho_inf:g}" if method == "galpha" else "-"
        head = f"| {method} | {rho} | {dt:g} | {keys.get('tolerance', '-')} |"
        if result.status:
            print(f"{head} - | Newton failed at t = {it.t:.4g} s | | | | |", flush=True)
            continue
        spar = np.abs(it.pose[:3] - reference.pose[:3]).max()
        nodes = np.abs(it.x - reference.x).max()
        newton = f"{it.stats[0]} | {it.stats[1]}" if method == "galpha" else "- | -"
        print(f"{head} {cpu:.3f} | {spar:.2e} | {nodes:.2e} | {steps} | {newton} |", flush=True)


if __name__ == "__main__":
    main()
