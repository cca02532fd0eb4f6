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

``--chain`` measures the issue's target instead: the mooring chain (scenarios/mooring_chain.toml, 83 nodes,
its fairlead held at the surface) in a JONSWAP sea (Hs 6 m, Tp 10 s, 100 components, ramped over 20 s). A
converged reference (rk4 at 0.5 ms; rk4 at 1 ms is shown against it) and each candidate method and step run the
same ``--window`` seconds. The error is the fairlead tension's RMS difference from the reference over the window
after its first tenth, relative to the reference's range there: the issue's "at 1 %", as on WD0050
(scripts/bench_moorings.py). Shown too: the largest difference relative to the peak (lenient: the peak is
mostly the static pretension, 1000 kN, against a 35 kN swing) and the RMS relative to the swing's standard
deviation (strict: a seventh of the range). The speed is simulated seconds per CPU second of the run (one core;
the least of ``--repeats`` runs of the window after compiling), frames every 0.2 s and their derived arrays
(tension, support forces, the sea's) included. ``--hours H`` then runs H hours of that sea whole, with the
fastest candidate within 1 % (or with ``--step METHOD:DT[:RHO]``, skipping the ladder), and the cost per
node-step of still water and 1, 50, 200 components follows (rk4 at 1 ms, sdirk2 at 20 ms, galpha at 200 ms;
``--sweep-seconds`` long).

    python scripts/bench_waves.py --chain [--window 300] [--hours 3]
    python scripts/bench_waves.py --chain --step sdirk2:0.02 --hours 3 [--sweep-seconds 30]
    python scripts/bench_waves.py --chain --methods galpha --hours 3 --no-sweep [--galpha-rho 0,0.9]

galpha runs a ladder for each ``--galpha-rho`` value (default 0 and 0.9).
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

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


CHAIN = Path(__file__).resolve().parent.parent / "scenarios" / "mooring_chain.toml"
CANDIDATES = (("rk4", 0.001), ("rk4", 0.002), ("sdirk2", 0.01), ("sdirk2", 0.02), ("sdirk2", 0.04),
              ("sdirk2", 0.05), ("sdirk2", 0.1), ("galpha", 0.025), ("galpha", 0.05), ("galpha", 0.1),
              ("galpha", 0.2))
#: galpha's rho_inf values, each a ladder of its own (--galpha-rho): 0, the setting for a line read by its
#: tension at WD0050's touchdowns, and 0.9, the default, whose period error is a third of 0's (the sea's measure)
GALPHA = {"rho_inf": (0.0, 0.9)}
FRAME = 0.2   # s between compared frames: a whole number of every candidate's steps
REFERENCE = ("rk4", 0.0005)
TARGET = 0.01


def chain_in_a_sea(method: str, dt: float, t_end: float, components: int | None = 100, rho: float | None = None):
    """The mooring chain held at its fairlead, in the JONSWAP sea (module doc) cut into ``components`` (None:
    a [sea] without waves), as a validated Scene; galpha at ``rho`` (None: the first of --galpha-rho)."""
    import tomllib

    import tomli_w

    import ropesim

    scene = tomllib.loads(CHAIN.read_text(encoding="utf-8"))
    del scene["driven"]
    scene["pinned"] = {"nodes": [0, -1]}
    scene["sea"] = {"level": 0.0}
    if components:
        scene["waves"] = {"kind": "jonswap", "significant_height": 6.0, "peak_period": 10.0,
                          "components": components, "ramp_time": 20.0}
    scene["integrator"] = {"method": method, "dt": dt, "t_end": t_end}
    if method == "galpha":
        scene["integrator"]["rho_inf"] = GALPHA["rho_inf"][0] if rho is None else rho
    scene["output"] = {"interval": FRAME}
    return ropesim.scene_from_toml(tomli_w.dumps(scene))


def fairlead_tension(scene, repeats: int = 1):
    """(fairlead tension (F,) [N], the least CPU time of ``repeats`` runs [s], force evaluations per step).
    CPU time, not wall time: the run's own use of one core, which a shared machine's load stretches far less
    than the wall clock (the run is single-threaded)."""
    from ropesim.run import _run_in_memory
    from ropesim.integrate.grid import TimeGrid
    from ropesim.model.build import build

    best, traj = math.inf, None
    for _ in range(repeats):
        model = build(scene)
        start = time.process_time()
        traj = _run_in_memory(model, TimeGrid.of(scene), False, None, None)
        best = min(best, time.process_time() - start)
    grid = TimeGrid.of(scene)
    evaluations = getattr(traj, "force_evaluations", None) or traj.summary.get("force_evaluations", 0)
    if traj.summary.get("status") != "completed":
        raise RuntimeError(f"stopped: {traj.summary.get('status')}")
    return np.abs(np.asarray(traj.tension)[:, -1]), best, evaluations / grid.steps


def ladder(methods: tuple[str, ...] | None) -> list[tuple[str, float, float | None]]:
    """(method, dt, galpha's rho_inf or None) of every candidate, galpha once per --galpha-rho value."""
    out = []
    for method, dt in CANDIDATES:
        if methods and method not in methods:
            continue
        out += [(method, dt, rho) for rho in GALPHA["rho_inf"]] if method == "galpha" else [(method, dt, None)]
    return sorted(out, key=lambda c: (c[0], c[2] or 0.0, c[1]))


def label(method: str, rho: float | None) -> str:
    return method if rho is None else f"{method} rho {rho:g}"


def errors(tension: np.ndarray, reference: np.ndarray) -> tuple[float, float, float]:
    """The fairlead tension's error against the reference, three ways: (RMS error / the reference's range, the
    issue's measure, as WD0050's; largest error / peak; RMS error / standard deviation), the RMS and the range
    and deviation over the window after its first tenth (the waves' ramp)."""
    waves = reference[reference.size // 10:]
    rms = math.sqrt(np.mean((tension - reference)[reference.size // 10:] ** 2))
    return (rms / (waves.max() - waves.min()), np.abs(tension - reference).max() / reference.max(),
            rms / waves.std())


def chain_target(window: float, repeats: int, hours: float, step: str | None = None,
                 sweep_seconds: float = 30.0, methods: tuple[str, ...] | None = None) -> None:
    console = Console()
    if step:   # a method and step chosen already: the whole sea and the cost per node-step, without the ladder
        method, dt, *rho = step.split(":")
        rho = float(rho[0]) if rho else None
        fairlead_tension(chain_in_a_sea(method, float(dt), 1.0, rho=rho))
        t_end = 3600.0 * hours
        _, cpu, per_step = fairlead_tension(chain_in_a_sea(method, float(dt), t_end, rho=rho))
        console.print(f"{hours:g} h of the sea, whole, {label(method, rho)} at {1e3 * float(dt):g} ms: {cpu:.1f} s "
                      f"of CPU time, {t_end / cpu:.0f}x real time, {1e9 * cpu / (83 * t_end / float(dt)):.0f} ns "
                      f"per node-step, {per_step:.2f} force evaluations per step")
        if sweep_seconds > 0:
            console.print(per_node_step(repeats, sweep_seconds))
        console.print(load_note())
        return
    fairlead_tension(chain_in_a_sea("rk4", 0.001, 1.0))         # compile the loops before timing
    fairlead_tension(chain_in_a_sea("sdirk2", 0.02, 1.0))
    fairlead_tension(chain_in_a_sea("galpha", 0.1, 1.0))
    reference, ref_wall, _ = fairlead_tension(chain_in_a_sea(*REFERENCE, window))
    waves = reference[reference.size // 10:]
    table = Table(title=f"the mooring chain in a JONSWAP sea (Hs 6 m, Tp 10 s, 100 components), {window:g} s "
                        f"against {REFERENCE[0]} at {1e3 * REFERENCE[1]:g} ms (peak {reference.max() / 1e3:.0f} "
                        f"kN, range {(waves.max() - waves.min()) / 1e3:.1f} kN, std {waves.std() / 1e3:.1f} kN)")
    for column in ("method", "dt (ms)", "RMS error / range", "largest error / peak", "RMS error / std",
                   "evaluations per step", "ns per node-step", "x real time (CPU)"):
        table.add_column(column, justify="right")
    nodes = 83
    fastest = None
    for method, dt, rho in ladder(methods):
        try:
            tension, wall, per_step = fairlead_tension(chain_in_a_sea(method, dt, window, rho=rho), repeats)
        except Exception as exc:   # a step too long for the method blows up: say so and go on
            table.add_row(label(method, rho), f"{1e3 * dt:g}", f"fails: {str(exc).splitlines()[0][:40]}", "", "",
                          "", "", "")
            continue
        of_range, of_peak, of_std = errors(tension, reference)
        speed = window / wall
        table.add_row(label(method, rho), f"{1e3 * dt:g}", f"{100 * of_range:.3f} %", f"{100 * of_peak:.3f} %",
                      f"{100 * of_std:.2f} %", f"{per_step:.1f}", f"{1e9 * wall / (nodes * window / dt):.0f}",
                      f"{speed:.0f}")
        if of_range <= TARGET and (fastest is None or speed > fastest[3]):
            fastest = (method, dt, rho, speed)
    console.print(table)
    if fastest is not None:
        method, dt, rho, speed = fastest
        console.print(f"fastest within {100 * TARGET:g} % of the tension's range (RMS): {label(method, rho)} at "
                      f"{1e3 * dt:g} ms, {speed:.0f}x real time over the window")
        if hours > 0:
            t_end = 3600.0 * hours
            _, wall, per_step = fairlead_tension(chain_in_a_sea(method, dt, t_end, rho=rho))
            console.print(f"{hours:g} h of that sea, whole: {wall:.1f} s of CPU time, {t_end / wall:.0f}x real "
                          f"time, {per_step:.2f} force evaluations per step")
    if sweep_seconds > 0:
        console.print(per_node_step(repeats, sweep_seconds))
    console.print(load_note())


def per_node_step(repeats: int, seconds: float = 30.0) -> Table:
    """The whole step's cost per node [ns] on the chain, still water and 1, 50, 200 components, rk4 at 1 ms,
    sdirk2 at 20 ms and galpha at 200 ms (runs interleaved, fastest of ``repeats``)."""
    table = Table(title=f"the mooring chain under a sea, CPU ns per node-step (whole runs of {seconds:g} s)")
    table.add_column("waves", justify="right")
    runs = {"rk4": 0.001, "sdirk2": 0.02, "galpha": 0.2}
    for method, dt in runs.items():
        table.add_column(f"{method} at {1e3 * dt:g} ms", justify="right")
    counts = (None, 1, 50, 200)
    best = {(c, m): math.inf for c in counts for m in runs}
    for _ in range(repeats):
        for c in counts:
            for method, dt in runs.items():
                _, wall, _ = fairlead_tension(chain_in_a_sea(method, dt, seconds, c))
                best[c, method] = min(best[c, method], wall)
    for c in counts:
        table.add_row("still water" if c is None else f"{c} components",
                      *(f"{1e9 * best[c, m] / (83 * seconds / dt):.0f}" for m, dt in runs.items()))
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=100)
    parser.add_argument("--calls", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--chain", action="store_true", help="the issue's target: the chain in a 3-hour sea")
    parser.add_argument("--window", type=float, default=300.0, help="--chain: simulated seconds compared")
    parser.add_argument("--hours", type=float, default=0.0, help="--chain: then run this many hours whole")
    parser.add_argument("--step", default=None, help="--chain: METHOD:DT, run --hours with it, no ladder")
    parser.add_argument("--sweep-seconds", type=float, default=30.0, help="--chain: the cost runs' length")
    parser.add_argument("--galpha-rho", default="0,0.9", help="--chain: galpha's rho_inf values, comma-separated "
                        "(default 0,0.9: a ladder each)")
    parser.add_argument("--no-sweep", action="store_true", help="--chain: skip the cost per node-step")
    parser.add_argument("--methods", default=None, help="--chain: comma-separated methods of the ladder (default all)")
    args = parser.parse_args()
    GALPHA["rho_inf"] = tuple(float(r) for r in args.galpha_rho.split(","))
    if args.chain:
        chain_target(args.window, min(args.repeats, 2), args.hours, args.step,
                     0.0 if args.no_sweep else args.sweep_seconds,
                     tuple(args.methods.split(",")) if args.methods else None)
        return
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
