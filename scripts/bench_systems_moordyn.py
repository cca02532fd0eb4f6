"""Speed of a system of lines with a free body against MoorDyn, at equal physics and accuracy, and per node
against a single line of the same size and method.

The case (tests/data/moordyn/cases/spar_free.txt, read for both codes by tests/references/moordyn_systems.py):
OC3-Hywind's three chains of lines.txt (902.2 m, 20 segments each, Morison drag, added mass, buoyancy, axial
damping, a seabed) on a free rigid body, a spar of OC3-Hywind's mass and inertia with its centre of gravity
78 m down and 0.5 m off its axis, translational and rotational drag, made 10 % too buoyant for its lines: released
from their static shape (both codes start from ropesim's static solve with the body held, MoorDyn's lines set to
it), it heaves, surges and pitches. 63 nodes and one body; nothing is driven, so MoorDyn is stepped 0.1 s per call
(the binding's cost per call is negligible against 0.1 s of its steps).

1. Against MoorDyn, per simulated second. Each code's explicit methods at steps up to the largest stable one
   (ropesim: symplectic_euler, verlet, rk4; MoorDyn: RK2, its default, and RK4), each timed on its time loop
   alone (ropesim's ``wall_time_s`` after a compiling run; MoorDyn's ``Step`` calls), the median of
   ``--repeats`` interleaved rounds (each round runs every configuration in turn; the ratio of two is the median of
   their per-round ratios). Accuracy: each run against its own code's converged answer (RK4 at 0.5 ms),
   RMS over the window as a fraction of the signal's range, the worst of the three fairlead tensions and the
   body's heave, surge and pitch. The two converged answers are reported too (how equal the physics is). Then,
   for each accuracy target, each code's cheapest run that reaches it.
2. Per node, ropesim alone: the same nodes as one line (a chain of the same segments from an anchor on the seabed
   to a fixed point), as the three lines held at their fairleads (lines.txt, the vessel still) and as the three
   lines on the free spar, at 20 segments per line (63 nodes) and at 200 (603 nodes; the segments ten times
   shorter, the step too), each method at one step, ``--steps`` steps, interleaved rounds; the wall time per node
   and step and its ratio to the single line (the median of the per-round ratios).

    pip install -e ".[bench]"     # moordyn
    python scripts/bench_systems_moordyn.py [--repeats 5] [--window 30] [--segments 20,200] [--steps 3000]

About 3 minutes on the shared 2-core machine at load 2, twice that at load 8.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "scripts")]   # this checkout's ropesim

from benchlib import interleaved, load_note, median, median_ratio
from references.moordyn_own_cases import moordyn_ba
from references.moordyn_systems import (
    from_ropesim,
    read_system,
    ropesim_fairlead_tensions,
    run_moordyn_system,
    run_system_from,
    static_positions,
    system_scene_dict,
)

CASE = "spar"
REFERENCE_DT = 0.0005
STEPS_MS = (2.0, 4.0, 5.0, 6.25, 100 / 14, 100 / 12, 10.0, 12.5, 20.0)    # each divides the 0.1 s frames
ROPESIM_METHODS = ("symplectic_euler", "verlet", "rk4")
MOORDYN_SCHEMES = ("RK2", "RK4")
TARGETS = (1e-5, 1e-6, 3e-7)
PER_NODE = {"verlet": 0.01, "rk4": 0.005}              # s: each method's step for the per-node comparison


def signals_ropesim(traj) -> np.ndarray:
    """(F, 6): the three fairlead tensions (N), the body's heave and surge (m) and pitch (rad), MoorDyn's axes."""
    from ropesim.model.rotation import rotation_matrix

    fair = ropesim_fairlead_tensions(CASE, traj, None)
    x = from_ropesim(np.asarray(traj.body_x)[:, 0])
    r = rotation_matrix(np.asarray(traj.body_q)[:, 0])
    pitch = np.arctan2(r[:, 0, 1], r[:, 0, 0])      # -(the angle about ropesim's z) = the angle about MoorDyn's y
    return np.column_stack([fair, x[:, 2], x[:, 0], pitch])


def signals_moordyn(run) -> np.ndarray:
    return np.column_stack([run.fairlead_state, run.body_r6[:, 0, 2], run.body_r6[:, 0, 0], run.body_r6[:, 0, 4]])


def error(sig: np.ndarray, ref: np.ndarray) -> float:
    """The worst signal's RMS difference over the window as a fraction of its range."""
    if sig.shape != ref.shape or not np.all(np.isfinite(sig)):
        return math.inf
    return float(max(np.sqrt(np.mean((sig[:, k] - ref[:, k]) ** 2)) / np.ptp(ref[:, k]) for k in range(ref.shape[1])))


def against_moordyn(start: np.ndarray, window: float, repeats: int) -> list[dict]:
    """Every configuration of both codes: wall time per simulated second (fastest round) and error."""
    def ropesim_run(method, dt):
        return run_system_from(CASE, start, method=method, dt=dt, t_end=window, interval=0.1)

    def moordyn_run(scheme, dt):
        return run_moordyn_system(CASE, None, window, 0.1, start=start, options={"tScheme": scheme, "dtM": dt})

    print(f"  converged answers (RK4 at {REFERENCE_DT * 1e3:g} ms) ...", flush=True)
    ref_rs = signals_ropesim(ropesim_run("rk4", REFERENCE_DT))
    ref_md = signals_moordyn(moordyn_run("RK4", REFERENCE_DT))
    apart = error(ref_rs, ref_md)
    rows = []
    print("  each configuration, until it is unstable ...", flush=True)
    for method in ROPESIM_METHODS:
        for ms in STEPS_MS:
            traj = ropesim_run(method, ms / 1e3)
            if traj.summary["status"] != "completed":
                rows.append({"code": "ropesim", "method": method, "dt_ms": ms, "stable": False})
                break
            rows.append({"code": "ropesim", "method": method, "dt_ms": ms, "stable": True,
                         "error": error(signals_ropesim(traj), ref_rs), "walls": []})
    for scheme in MOORDYN_SCHEMES:
        for ms in STEPS_MS:
            try:
                run = moordyn_run(scheme, ms / 1e3)
            except RuntimeError:      # "MoorDyn reported an error integrating": it diverged
                rows.append({"code": "MoorDyn", "method": scheme, "dt_ms": ms, "stable": False})
                break
            rows.append({"code": "MoorDyn", "method": scheme, "dt_ms": ms, "stable": True,
                         "error": error(signals_moordyn(run), ref_md), "walls": []})
    stable = [r for r in rows if r["stable"]]
    print(f"  timing {len(stable)} configurations, {repeats} rounds ...", flush=True)
    for _ in range(repeats):
        for r in stable:
            if r["code"] == "ropesim":
                r["walls"].append(float(ropesim_run(r["method"], r["dt_ms"] / 1e3).summary["wall_time_s"]))
            else:
                r["walls"].append(moordyn_run(r["method"], r["dt_ms"] / 1e3).wall)
    for r in stable:
        r["per_second"] = median(r["walls"]) / window
    return rows, apart


def resized_lines(segments: int) -> list[dict]:
    """lines.txt's three lines, each of ``segments`` segments (the damping ratio kept: BA for the new length)."""
    s = read_system("lines")
    t = s.types["main"]
    lines = system_scene_dict("lines", None)["lines"]
    return [{**ln, "segments": segments, "axial_damping": moordyn_ba(t.BA, ln["length"], segments, t.EA, t.w)}
            for ln in lines]


def single_line(segments: int, method: str, dt: float, t_end: float) -> dict:
    """One chain of ``segments`` segments (a scene dict) from an anchor on the seabed to a point held 250 m above it,
    in the same water as the spread's lines and of their segments' length, so of their stable step."""
    scene = system_scene_dict("lines", None, method=method, dt=dt, t_end=t_end, interval=t_end, start="equilibrium")
    per = resized_lines(round((segments - 2) / 3))[0]
    length = segments * per["length"] / per["segments"]
    scene["points"] = [{"id": "anchor", "kind": "fixed", "position": [0.0, -320.0, 0.0]},
                       {"id": "top", "kind": "fixed", "position": [0.92 * length, -70.0, 0.0]}]
    scene["lines"] = [{**per, "start": "anchor", "end": "top", "length": length, "segments": segments}]
    return scene


def per_node(segments: int, steps: int, repeats: int) -> dict:
    """ropesim's wall time per node and step, ``segments`` per line: one line of all the nodes, the three lines
    held at their fairleads, the three lines on the free body; each method at its step of PER_NODE scaled to the
    segments' length, ``steps`` steps, interleaved rounds."""
    import tomli_w

    import ropesim

    lines = resized_lines(segments)
    nodes = 3 * (segments + 1)
    start = static_positions("lines", changes={"lines": lines})
    out = {}
    for method, dt20 in PER_NODE.items():
        dt = dt20 * 20 / segments
        window = steps * dt
        kw = {"method": method, "dt": dt, "t_end": window, "interval": window}
        scenes = {"one line": single_line(nodes - 1, method, dt, window),
                  "three lines, held at the fairleads": system_scene_dict("lines", None, start="equilibrium",
                                                                          changes={"lines": lines}, **kw)}
        scenes = {k: ropesim.scene_from_toml(tomli_w.dumps(v)) for k, v in scenes.items()}
        walls: dict[str, list[float]] = {k: [] for k in (*scenes, "three lines on the free body")}

        def timed(name, scene=None, walls=walls, kw=kw):
            def run():
                traj = (ropesim.simulate(scene) if scene is not None else
                        run_system_from(CASE, start, changes={"lines": lines}, **kw))
                walls[name].append(float(traj.summary["wall_time_s"]))
            return run

        contenders = {name: timed(name, scene) for name, scene in scenes.items()}
        contenders["three lines on the free body"] = timed("three lines on the free body")
        interleaved(contenders, repeats)           # its own timer includes set-up; the loop's time is kept
        walls = {name: w[1:] for name, w in walls.items()}    # the warm-up round compiled
        out[method] = {"dt": dt, "nodes": nodes,
                       "rows": {name: {"ns_per_node_step": 1e9 * median(w) / (nodes * steps),
                                       "ratio": median_ratio(w, walls["one line"])}
                                for name, w in walls.items()}}
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--window", type=float, default=30.0, help="simulated seconds per run against MoorDyn")
    parser.add_argument("--segments", type=lambda v: [int(x) for x in v.split(",")], default=[20, 200],
                        help="segments per line in the per-node comparison (comma-separated)")
    parser.add_argument("--steps", type=int, default=3000, help="steps per run in the per-node comparison")
    args = parser.parse_args(argv)
    started = time.perf_counter()
    from references.moordyn_harness import moordyn_version

    start = static_positions("lines")
    print(f"MoorDyn {moordyn_version()} against ropesim, {args.window:g} s of the free spar on three chains:",
          flush=True)
    rows, apart = against_moordyn(start, args.window, args.repeats)
    print(f"\nThe two converged answers (RK4 at {REFERENCE_DT * 1e3:g} ms) apart by {apart:.1e} of the range "
          f"(worst signal, RMS).\n")
    print("| code | method | step | wall time per simulated second | error against its own converged answer |")
    print("| --- | --- | --- | --- | --- |")
    for r in rows:
        if r["stable"]:
            print(f"| {r['code']} | {r['method']} | {r['dt_ms']:.3g} ms | {r['per_second'] * 1e3:.2f} ms | "
                  f"{r['error']:.1e} |")
        else:
            print(f"| {r['code']} | {r['method']} | {r['dt_ms']:.3g} ms | unstable | |")
    print("\n| accuracy target | ropesim's cheapest | MoorDyn's cheapest | MoorDyn's time / ropesim's |")
    print("| --- | --- | --- | --- |")
    for target in TARGETS:
        best = {}
        for code in ("ropesim", "MoorDyn"):
            fits = [r for r in rows if r["code"] == code and r["stable"] and r["error"] <= target]
            best[code] = min(fits, key=lambda r: r["per_second"]) if fits else None
        cells = [f"{b['method']} at {b['dt_ms']:.3g} ms: {b['per_second'] * 1e3:.2f} ms per s" if b else "none"
                 for b in best.values()]
        ratio = (f"{median_ratio(best['MoorDyn']['walls'], best['ropesim']['walls']):.2f}"
                 if all(best.values()) else "")
        print(f"| {target:g} | {cells[0]} | {cells[1]} | {ratio} |")
    print("\nPer node, ropesim alone (median of rounds; ratio: median of per-round ratios):\n")
    print("| nodes | method, step | layout | wall time per node and step | / one line |")
    print("| --- | --- | --- | --- | --- |")
    for segments in args.segments:
        for method, res in per_node(segments, args.steps, args.repeats).items():
            for name, row in res["rows"].items():
                print(f"| {res['nodes']} | {method}, {res['dt'] * 1e3:.3g} ms | {name} | "
                      f"{row['ns_per_node_step']:.0f} ns | {row['ratio']:.2f} |")
    print(f"\n{load_note()}; total {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
