"""What one galpha step costs on WD0050 (bench_moorings' case, MoorDyn's seabed law), part by part, against
MoorDyn's RK2 step.

    python scripts/bench_galpha_step.py [--tolerance 1] [--dt 0.1] [--window 30] [--calls 2000] [--rho-inf R]
        [--own-seabed]
    python scripts/bench_galpha_step.py --seabed-effect 0.0025   # the two-way damping's regularisation
    python scripts/bench_galpha_step.py --cpu 0.1 0.00625 --window 120   # CPU time against MoorDyn's RK2

Times each compiled part of a step on the case's state at rest (the force evaluation with its residual, the
matrix's assembly and factorisation, a solve with the factored matrix), then runs the case with adaptive steps
at ``--tolerance`` and with fixed steps of ``--dt``, and breaks the run's time into those parts from its counts
(steps, rejections, Newton iterations, factorisations). MoorDyn's RK2 step is two force evaluations of its own
(its ns per node and evaluation from bench_moorings' term costs).

``--cpu DT ...`` instead times whole runs in CPU time (``time.process_time``, less disturbed by other processes
than wall time): ``ropesim.simulate`` with galpha at each fixed step DT (frames every 0.1 s, their derived arrays
and the summary included) against MoorDyn's RK2 at ``--moordyn-dt`` (its largest stable step on WD0050, from
bench_moorings' ladder) with a ``Step`` every 0.1 s, the fastest of ``--rounds`` interleaved rounds, and a galpha
step's cost in MoorDyn force evaluations (two per RK2 step).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "scripts"), str(ROOT / "tests")]


def main() -> int:
    import tomli_w

    import ropesim
    from bench_moorings import DT_OUT, SEABED, SURGE, problem
    from references.moordyn_own_cases import chain_scene_dict
    from ropesim.integrate import galpha as G
    from ropesim.integrate.grid import TimeGrid
    from ropesim.integrate.methods import make_integrator
    from ropesim.model.banded import solve
    from ropesim.model.build import build

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tolerance", type=float, default=1.0)
    parser.add_argument("--dt", type=float, default=0.1)
    parser.add_argument("--window", type=float, default=30.0)
    parser.add_argument("--calls", type=int, default=2000)
    parser.add_argument("--rho-inf", type=float, default=0.0, help="galpha's rho_inf (0: the setting for moorings)")
    parser.add_argument("--own-seabed", action="store_true",
                        help="ropesim's own seabed damping (into the plane only, ramped in) instead of MoorDyn's")
    parser.add_argument("--seabed-effect", type=float, metavar="DT",
                        help="instead: the fairlead tension of galpha at fixed steps DT with MoorDyn's two-way "
                             "damping grown in (galpha's) and as MoorDyn has it, against each other and rk4")
    parser.add_argument("--cpu", type=float, nargs="+", metavar="DT",
                        help="instead: CPU time of galpha at these fixed steps against MoorDyn's RK2")
    parser.add_argument("--moordyn-dt", type=float, default=0.1 / 45, help="MoorDyn RK2's step for --cpu [s]")
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds for --cpu (the fastest counts)")
    args = parser.parse_args()
    if args.cpu:
        return cpu_times(args.cpu, args.moordyn_dt, args.window, args.rounds, args.rho_inf)
    if args.seabed_effect:
        return seabed_effect(args.seabed_effect, args.window, args.rho_inf)
    SEABED["both_ways"] = not args.own_seabed
    case, start = problem()

    def integrator(dt, tol=None):
        scene = chain_scene_dict(case, start, method="galpha", dt=dt, t_end=args.window, interval=DT_OUT,
                                 dimension=3, both_ways=SEABED["both_ways"], surge=SURGE)
        if tol is not None:
            scene["integrator"]["tolerance"] = tol
        if args.rho_inf is not None:
            scene["integrator"]["rho_inf"] = args.rho_inf
        s = ropesim.scene_from_toml(tomli_w.dumps(scene))
        model, grid = build(s), TimeGrid.of(s)
        return make_integrator(model, grid), grid

    it, grid = integrator(args.dt)
    it.warm_up()
    k, w, co, h = it.kernel, it.work, it.coefficients, args.dt
    am, af, gam, beta = co
    c2, bv = (1 - af) * beta * h * h / (1 - am), beta * h / gam
    k(G.step_start)(it.x, it.v, it.acc_n, w, co, h)
    nw, p = it.newton, it.model.params
    parts = {}
    for name, call in (
            ("force evaluation + residual", lambda: k(G.residual)(w, nw.rhs, c2, bv, 0.5 * h, it.held, it.nodes, p,
                                                                  nw.body, nw.groups)),
            ("assembly + factorisation", lambda: k(G.factor_matrix)(w, nw, c2, bv, 0.5 * h, it.nodes, p)),
            ("solve (factored)", lambda: k(solve)(nw.jac.band, nw.jac.corner, nw.cyclic, nw.jac.band.shape[0] - 1,
                                                  nw.rhs, nw.wood))):
        call()
        tick = time.perf_counter()
        for _ in range(args.calls):
            call()
        parts[name] = (time.perf_counter() - tick) / args.calls
    nodes = it.model.nodes
    print(f"WD0050, {nodes} nodes, 3-D; per call (Python call overhead included, about 1 us):")
    for name, sec in parts.items():
        print(f"  {name:30s} {sec * 1e6:8.1f} us  ({sec * 1e9 / nodes:6.0f} ns per node)")
    for label, (dt, tol) in (("adaptive", (DT_OUT, args.tolerance)), ("fixed", (args.dt, None))):
        it, grid = integrator(dt, tol)
        it.warm_up()
        tick = time.perf_counter()
        result = it.advance(grid.steps)
        wall = time.perf_counter() - tick
        report = it.step_report() or {"steps_taken": int(it.stats[G.STEPS]), "steps_rejected": 0}
        its, fac = int(it.stats[G.ITERATIONS]), int(it.stats[G.FACTORISATIONS])
        steps = report["steps_taken"] + report["steps_rejected"]
        model_cost = (its * (parts["force evaluation + residual"] + parts["solve (factored)"])
                      + fac * parts["assembly + factorisation"])
        print(f"\n{label} ({'tolerance %g m' % tol if tol else 'dt %g s' % dt}), {args.window:g} s: status "
              f"{result.status}, {wall:.3f} s ({wall / args.window * 1e3:.2f} ms per simulated s); steps taken "
              f"{report['steps_taken']}, rejected {report['steps_rejected']}; Newton iterations {its} "
              f"({its / max(steps, 1):.2f} per attempted step), factorisations {fac} ({fac / max(steps, 1):.2f} per "
              f"step); the parts above account for {model_cost:.3f} s: iterations {its * parts['force evaluation + residual']:.3f} s, "
              f"solves {its * parts['solve (factored)']:.3f} s, factorisations {fac * parts['assembly + factorisation']:.3f} s")
        if report["steps_taken"]:
            print(f"  mean step {args.window / report['steps_taken'] * 1e3:.2f} ms")
    return 0


def cpu_times(steps: list[float], moordyn_dt: float, window: float, rounds: int, rho_inf: float) -> int:
    """galpha at each of ``steps`` against MoorDyn's RK2 at ``moordyn_dt`` over ``window`` s: CPU seconds, the
    fastest of ``rounds`` interleaved rounds, and one galpha step's cost in MoorDyn force evaluations."""
    import os

    import tomli_w

    import ropesim
    from bench_moorings import DT_OUT, SURGE, moordyn_run, problem
    from references.moordyn_own_cases import chain_scene_dict

    case, start = problem()
    scenes = {}
    for dt in steps:
        scene = chain_scene_dict(case, start, method="galpha", dt=dt, t_end=window, interval=DT_OUT, dimension=3,
                                 both_ways=True, surge=SURGE)
        scene["integrator"]["rho_inf"] = rho_inf
        scenes[dt] = ropesim.scene_from_toml(tomli_w.dumps(scene))
        ropesim.simulate(scenes[dt])   # compiled before the clock starts
    moordyn_run(case, start, "RK2", moordyn_dt, 1.0, DT_OUT)
    best = {}
    for _ in range(rounds):
        tick = time.process_time()
        out = moordyn_run(case, start, "RK2", moordyn_dt, window, DT_OUT)
        best["moordyn"] = min(best.get("moordyn", np.inf), time.process_time() - tick)
        if not out["ok"]:
            print(f"MoorDyn RK2 at {moordyn_dt:g} s: {out['status']}")
            return 1
        for dt, scene in scenes.items():
            tick = time.process_time()
            traj = ropesim.simulate(scene)
            best[dt] = min(best.get(dt, np.inf), time.process_time() - tick)
            if traj.summary["status"] != "completed":
                print(f"galpha at {dt:g} s: {traj.summary['status']}")
                return 1
    evaluation = best["moordyn"] / (2 * window / moordyn_dt)
    print(f"WD0050, {window:g} s, CPU seconds (fastest of {rounds} rounds, load {os.getloadavg()[0]:.1f}):")
    print(f"  MoorDyn RK2 at {moordyn_dt * 1e3:.3g} ms: {best['moordyn']:.3f} s, {evaluation * 1e6:.2f} us per force "
          f"evaluation")
    for dt in steps:
        step = best[dt] / (window / dt)
        spent = 2 * dt / moordyn_dt   # MoorDyn's evaluations in the same simulated time
        print(f"  galpha at {dt * 1e3:.3g} ms: {best[dt]:.3f} s, {step * 1e6:.1f} us a step = "
              f"{step / evaluation:.1f} MoorDyn evaluations against its {spent:.1f}: "
              f"{best['moordyn'] / best[dt]:.2f}x")
    return 0


def seabed_effect(dt: float, window: float, rho_inf: float | None) -> int:
    """The regularisation's effect on the answer: WD0050 with galpha at fixed ``dt``, MoorDyn's two-way seabed
    damping grown in over delta_d (what galpha runs) and at full strength from first contact (MoorDyn's law,
    which every other method runs), RMS of their fairlead tensions' difference over the range of rk4's."""
    import tomli_w

    import ropesim
    from bench_moorings import DT_OUT, SURGE, problem, reference
    from references.moordyn_own_cases import chain_scene_dict, differences
    from ropesim.model.forces import seabed

    case, start = problem()
    own = seabed.SEABED_TERM.params

    def moordyns(scene, layout):   # the both-ways flag 1 (MoorDyn's law) where galpha's would be 2
        bed, area = own(scene, layout)
        bed = bed.copy()
        bed[10] = min(bed[10], 1.0)
        return bed, area

    def fairlead(law):
        object.__setattr__(seabed.SEABED_TERM, "params", law)
        try:
            scene = chain_scene_dict(case, start, method="galpha", dt=dt, t_end=window, interval=DT_OUT,
                                     dimension=3, both_ways=True, surge=SURGE)
            if rho_inf is not None:
                scene["integrator"]["rho_inf"] = rho_inf
            traj = ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(scene)))
        finally:
            object.__setattr__(seabed.SEABED_TERM, "params", own)
        if traj.summary["status"] != "completed":
            return None
        import numpy as np

        return np.abs(np.asarray(traj.tension)[:, -1])

    ref, info = reference(case, start, window)
    grown, full = fairlead(own), fairlead(moordyns)
    print(f"WD0050, galpha at {dt:g} s (rho_inf {rho_inf}), {window:g} s; reference {info}")
    for name, run in (("grown in (galpha's)", grown), ("MoorDyn's, full from contact", full)):
        print(f"  {name:30s} " + (f"{differences(ref, run)['rms_of_range']:.2e} of the range from rk4"
                                  if run is not None else "Newton failed"))
    if grown is not None and full is not None:
        print(f"  the two laws apart: {differences(full, grown)['rms_of_range']:.2e} of the range")
    return 0


if __name__ == "__main__":
    sys.exit(main())
