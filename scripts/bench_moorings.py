"""Speed at equal accuracy on a mooring line: ropesim (verlet, rk4, sdirk2, galpha) against MoorDyn (RK2, RK4), and where
ropesim's implicit sdirk2 overtakes its explicit methods as the chain gets stiffer.

The case: MoorDyn's WD0050_Chain (tests/data/moordyn/cases/: 410 m of studless chain, 82 segments, EA = 1.674e9 N,
critical axial damping, on a seabed with friction, in 50 m of water; tests/references/moordyn_own_cases.py builds
it for both codes on equal physics, ropesim's seabed damping on MoorDyn's two-way law, ``damping_both_ways``), in
3-D, its fairlead surging 5 m at 15 s (smootherstep ramp over the first period) for ``--window`` seconds: a
sinusoidal sea state's first-order motion. Both codes start from ropesim's static solve (MoorDyn's
state is set to it, ``set_line_state``), at rest.

Accuracy: the fairlead tension (the top segment's spring plus damping: ropesim's ``tension[:, -1]``, MoorDyn's
computed from its state at the frame, as ``GetLineFairTen`` reports it from the last force evaluation, a fraction
of a step earlier: first order in the step, 1e-4 of the range between 0.33 and 0.66 ms) every 0.1 s, RMS of its
difference from the code's own converged answer over the window divided by that answer's range (max - min; the
RMS of the signal itself is 1.9 times smaller than the range here, so a fraction of the RMS is 1.9 times larger). The converged answers: each code's RK4 at a tenth of ropesim's
largest stable rk4 step, checked against twice that step; how far the two converged answers are apart is reported
(the codes' physics differ by that much, see the validation page; each code is timed against its own answer, as
"the same tension accuracy against a converged reference" asks).

The fairlead's motion: ropesim's own sinusoid (``[[driven]]`` amplitude, period, ramp_time), exact at every stage;
MoorDyn's coupled point follows the same function, handed to it at every internal step (``Step`` with dt = dtM: the
point moves along the secant inside each call, so its velocity is within a dt^2 term of the true one at the
midpoint). The Python binding's cost per ``Step`` call (a few microseconds) is measured separately and taken off
MoorDyn's times, so MoorDyn is timed as if called from C; its raw times are kept too (``raw_walls``).

Timing: each configuration's time loop alone (ropesim's ``wall_time_s``, compile excluded: every method is run once
first; MoorDyn's ``Step`` calls, its set-up excluded), every configuration in turn, ``--repeats`` rounds, the
fastest of each kept. Then for each accuracy target (1 %, 0.1 %, 0.01 % of the range) the cheapest configuration
of each method that reaches it, its wall time per simulated second and what a 3-hour sea state (10 800 s) would
take at that rate.

The stiff chain: the same case with EA from 1e8 to 1e11 N (critical axial damping kept, BA = l sqrt(EA m')), a 30 s
window, each method's cheapest configuration reaching 1 % and 0.1 % against an rk4 reference at each EA.

    pip install -e ".[bench]"      # moordyn
    python scripts/bench_moorings.py [--repeats 3] [--window 120] [--points 4] [--no-sweep] \\
        [--json docs/data/moorings_speed.json] [--figure docs/images/moorings_speed.png]

``--fluid`` instead times galpha (fixed steps and tolerances, six per decade from 0.1 to 1e-4 m, each at the
rho_inf values of ``--fluid-rho``, default 0, 0.3 and 0.5) against MoorDyn's RK2 and RK4 on the three
equal-physics fluid cases of tests/references/moordyn_equal_physics.py (current, towed, catenary; full size,
their first ``--fluid-window`` seconds, no seabed), each code against its own RK4 at a small step, the error the
top tension's RMS over its range; the cheapest configuration of each code at 1 % and 0.1 %:

    python scripts/bench_moorings.py --fluid [current,towed,catenary] [--fluid-window 20] [--repeats 2] \
        [--fluid-rho 0,0.3,0.5]

The error counts the first seconds, where the current switches on (or the tow starts, or the catenary is
released) at t = 0 and sets off axial waves. The towed line and the catenary ring at their first axial
modes (about 100 rad/s, 1 % damped) for 2 to 4 s, and following that ringing's phase at 0.1 s samples is
what sets galpha's steps there (about 1 ms); the catenary's release adds 80 to 140 us steps in its first 0.2 s.

About 6 minutes on the shared 2-core machine at load average 1 to 2, 13 at load 4 to 6 (half without the sweep).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]   # this checkout's ropesim, not an installed one

from references.moordyn_own_cases import (  # noqa: E402
    Surge,
    chain_case,
    chain_scene_dict,
    differences,
    moordyn_ba,
    run_moordyn_line,
)

FIGURE = ROOT / "docs" / "images" / "moorings_speed.png"
JSON = ROOT / "docs" / "data" / "moorings_speed.json"
SURGE = Surge(amplitude=5.0, period=15.0, ramp_time=15.0)
DT_OUT = 0.1                         # s: output (and MoorDyn's coupling at most)
TARGETS = (1e-2, 1e-3, 1e-4)         # RMS error / range of the reference
SEA_STATE = 3 * 3600.0               # s
ROPESIM_METHODS = ("verlet", "rk4", "sdirk2")
MOORDYN_SCHEMES = ("RK2", "RK4")
SWEEP_EA = (1e8, 3e8, 1e9, 3e9, 1e10, 1e11)
SWEEP_WINDOW = 30.0
#: ropesim's seabed damping: MoorDyn's two-way law (equal physics), or ropesim's own with --own-seabed
SEABED = {"both_ways": True}
#: galpha's rho_inf, from --galpha-rho: 0, the setting for a stiff line read by its tension (see the accuracy
#: page; its default, 0.9, is 20x less accurate in the fairlead tension at 0.1 s steps)
GALPHA = {"rho_inf": 0.0}


def step_of(k: int) -> float:
    """The step (s) that divides the output interval k times."""
    return DT_OUT / k


def k_at_most(dt: float) -> int:
    """The smallest k with DT_OUT / k <= dt."""
    return max(1, math.ceil(DT_OUT / dt - 1e-9))


# ------------------------------------------------------------------------------------------------ the problem


def problem(EA: float | None = None):
    """The case (WD0050 with ``EA`` and the critical damping that goes with it) and the common start: ropesim's 3-D
    static solve, as MoorDyn node positions (N+1, 3)."""
    import tomli_w

    import ropesim
    from ropesim.model.build import build

    case = chain_case("WD0050_Chain")
    if EA is not None:
        case = replace(case, EA=EA, BA=moordyn_ba(-1.0, case.length, case.segments, EA, case.mass_per_length))
    scene = ropesim.scene_from_toml(tomli_w.dumps(chain_scene_dict(case, None, dimension=3, moving=False,
                                                                   both_ways=SEABED["both_ways"],
                                                                   t_end=0.0)))
    x = build(scene).x0.T
    return case, np.ascontiguousarray(x[:, [0, 2, 1]])


def ropesim_run(case, start, method: str, dt: float, t_end: float) -> dict:
    """One run; ``method`` "galpha tol=T" is galpha with adaptive steps at tolerance T [m] (dt its output grid)."""
    import tomli_w

    import ropesim

    name, _, tol = method.partition(" tol=")
    scene = chain_scene_dict(case, start, method=name, dt=dt, t_end=t_end, interval=DT_OUT, dimension=3,
                             both_ways=SEABED["both_ways"],
                             surge=SURGE)
    if tol:
        scene["integrator"]["tolerance"] = float(tol)
    if name == "galpha" and GALPHA["rho_inf"] is not None:
        scene["integrator"]["rho_inf"] = GALPHA["rho_inf"]
    traj = ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(scene)))
    ok = traj.summary["status"] == "completed"
    return {"fairlead": np.abs(np.asarray(traj.tension)[:, -1]) if ok else None, "wall": traj.summary["wall_time_s"],
            "ok": ok, "status": traj.summary["status"]}


def moordyn_run(case, start, scheme: str, dt: float, t_end: float, coupling: float | None = None) -> dict:
    try:
        out = run_moordyn_line(case, start, SURGE.motion(case.fairlead), dt, scheme, t_end, coupling, DT_OUT)
    except RuntimeError as exc:   # MoorDyn refused or blew up in a way the harness reports
        return {"fairlead": None, "wall": float("nan"), "ok": False, "status": str(exc)}
    frames = int(round(t_end / DT_OUT)) + 1
    ok = out["ok"] and out["fairlead"].size == frames
    return {"fairlead": out["from_state"] if ok else None, "wall": out["wall"], "ok": ok,
            "status": "completed" if ok else "blew up", "calls": out["calls"]}


def run(case, start, code: str, method: str, dt: float, t_end: float) -> dict:
    return (ropesim_run if code == "ropesim" else moordyn_run)(case, start, method, dt, t_end)


def bound_of(case, start, method: str) -> float:
    """ropesim's predicted largest stable step (s) for ``method`` (inf for sdirk2)."""
    import tomli_w

    import ropesim
    from ropesim.analysis.stability import predicted_dt
    from ropesim.model.build import build

    scene = chain_scene_dict(case, start, method=method, dt=1e-3, t_end=1.0, dimension=3, surge=SURGE,
                             both_ways=SEABED["both_ways"])
    return predicted_dt(build(ropesim.scene_from_toml(tomli_w.dumps(scene))), method)


# ------------------------------------------------------------------------------------------------ ladders


def largest_stable(case, start, code: str, method: str, guess: float, t_end: float) -> tuple[int, list]:
    """The smallest k (largest step DT_OUT / k) from ``guess`` down by factors of ~1.1 whose run over t_end stays
    stable; returns (k, the steps tried that blew up)."""
    k, failed = k_at_most(guess), []
    for _ in range(60):
        if run(case, start, code, method, step_of(k), t_end)["ok"]:
            return k, failed
        failed.append(step_of(k))
        k = max(k + 1, int(round(k * 1.1)))
    raise RuntimeError(f"{code} {method}: no stable step found below {guess}")


def ladder(k0: int, count: int, factor: float = math.sqrt(2.0)) -> list[int]:
    """count values of k from k0, growing by ``factor`` (steps shrinking by it), distinct."""
    ks: list[int] = []
    for i in range(count):
        k = max(k0, int(round(k0 * factor ** i)))
        if ks and k <= ks[-1]:
            k = ks[-1] + 1
        ks.append(k)
    return ks


#: sdirk2's steps, DT_OUT / k: dense, because its Newton solve may fail at some steps and not at others
SDIRK_KS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32)
#: galpha's fixed steps, DT_OUT / k, and its tolerances [m] with adaptive steps (reported on the DT_OUT grid)
GALPHA_KS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32)
GALPHA_TOLERANCES = (3.0, 1.0, 0.3, 0.1, 0.03, 0.01, 0.003)


def configurations(case, start, t_end: float, points: int, sdirk_ks=SDIRK_KS,
                   moordyn: bool = True) -> tuple[list, dict]:
    """Every (code, method, k) to time, from each method's largest stable step down, and notes of what blew up."""
    notes: dict = {}
    configs = []
    short = min(t_end, 40.0)
    for method in ("verlet", "rk4"):
        bound = bound_of(case, start, method)
        k0, failed = largest_stable(case, start, "ropesim", method, 1.6 * bound, short)
        notes[f"ropesim {method}"] = {"bound_s": bound, "largest_stable_s": step_of(k0), "blew_up_at_s": failed}
        configs += [("ropesim", method, k) for k in ladder(k0, points)]
    configs += [("ropesim", "sdirk2", k) for k in sdirk_ks]
    configs += [("ropesim", "galpha", k) for k in GALPHA_KS]
    configs += [("ropesim", f"galpha tol={tol:g}", 1) for tol in GALPHA_TOLERANCES]
    rk4_bound = notes["ropesim rk4"]["bound_s"]
    for scheme, guess in (("RK2", rk4_bound), ("RK4", 1.5 * rk4_bound)) if moordyn else ():
        k0, failed = largest_stable(case, start, "MoorDyn", scheme, guess, short)
        notes[f"MoorDyn {scheme}"] = {"largest_stable_s": step_of(k0), "blew_up_at_s": failed}
        configs += [("MoorDyn", scheme, k) for k in ladder(k0, points)]
    return configs, notes


def reference(case, start, t_end: float, code: str = "ropesim") -> tuple[np.ndarray, dict]:
    """A code's converged answer: its RK4 at a tenth of ropesim's rk4 bound, and its difference from twice that
    step (RMS / range)."""
    k = k_at_most(0.1 * bound_of(case, start, "rk4"))
    method = "rk4" if code == "ropesim" else "RK4"
    fine = run(case, start, code, method, step_of(k), t_end)
    half = run(case, start, code, method, step_of(max(1, k // 2)), t_end)
    if not (fine["ok"] and half["ok"]):
        raise RuntimeError(f"{code}'s reference run did not complete")
    return fine["fairlead"], {"code": code, "method": method, "dt_s": step_of(k), "check_dt_s": step_of(max(1, k // 2)),
                              "check_rms_of_range": differences(fine["fairlead"], half["fairlead"])["rms_of_range"]}


def measure(case, start, configs: list, refs: dict, t_end: float, repeats: int, per_call: float = 0.0) -> list[dict]:
    """Each configuration once per round, ``repeats`` rounds (after one run of each method to compile); the fastest
    wall time of each, the error of its first run (runs are deterministic) against its code's converged answer
    (``refs[code]``); MoorDyn's net of ``per_call`` seconds per Step call."""
    for code, method in {(c, m) for c, m, _ in configs}:
        run(case, start, code, method, step_of(200), 0.2)   # compile / warm up
    rows = [{"code": c, "method": m, "dt_s": step_of(k), "walls": [], "ok": True} for c, m, k in configs]
    for rnd in range(repeats):
        print(f"    round {rnd + 1}/{repeats} ...", flush=True)
        for row in rows:
            if not row["ok"]:
                continue
            out = run(case, start, row["code"], row["method"], row["dt_s"], t_end)
            if not out["ok"]:
                row.update(ok=False, status=out["status"])
                continue
            row["walls"].append(out["wall"] - per_call * out.get("calls", 0))
            row["raw_walls"] = row.get("raw_walls", []) + [out["wall"]]
            if "error" not in row:
                d = differences(refs[row["code"]], out["fairlead"])
                row["error"], row["error_of_rms"] = d["rms_of_range"], d["rms_of_rms"]
    for row in rows:
        if row["ok"]:
            row["wall_per_s"] = min(row["walls"]) / t_end
            row["real_time_factor"] = 1.0 / row["wall_per_s"]
    return rows


def cheapest(rows: list[dict], targets=TARGETS) -> dict:
    """Per target and per method, the measured configuration reaching it with the least wall time."""
    out: dict = {}
    for target in targets:
        best: dict = {}
        for row in rows:
            if not row["ok"] or row["error"] > target:
                continue
            key = f"{row['code']} {row['method'].split(' tol=')[0]}" + (" adaptive" if " tol=" in row["method"] else "")
            if key not in best or row["wall_per_s"] < best[key]["wall_per_s"]:
                best[key] = {"dt_s": row["dt_s"], "method": row["method"], "wall_per_s": row["wall_per_s"], "error": row["error"],
                             "sea_state_wall_s": row["wall_per_s"] * SEA_STATE,
                             "real_time_factor": row["real_time_factor"]}
        out[f"{target:g}"] = best
    return out


def call_overhead(case, start, t_end: float, repeats: int = 1) -> dict:
    """MoorDyn's RK2 at 1 ms coupled every step against coupled every 0.1 s: the binding's cost per Step call
    (the fastest of ``repeats`` interleaved rounds of each: one round on a loaded machine once put it at 27 us,
    38 % of MoorDyn's time, and took that much off every MoorDyn time)."""
    each, coarse = None, None
    for _ in range(max(1, repeats)):
        e = moordyn_run(case, start, "RK2", 1e-3, t_end)
        c = moordyn_run(case, start, "RK2", 1e-3, t_end, coupling=DT_OUT)
        each = e if each is None or e["wall"] < each["wall"] else each
        coarse = c if coarse is None or c["wall"] < coarse["wall"] else coarse
    calls = each["calls"] - coarse["calls"]
    return {"dtM_s": 1e-3, "wall_coupled_every_step_s": each["wall"], "wall_coupled_every_0.1s_s": coarse["wall"],
            "per_call_us": 1e6 * (each["wall"] - coarse["wall"]) / calls,
            "share_of_time_at_1ms": (each["wall"] - coarse["wall"]) / each["wall"]}


def term_costs(case, start, repeats: int, t_end: float = 20.0, dt: float = 2.0e-3) -> dict:
    """What one force evaluation costs per node, ropesim's rk4 at 2 ms with terms left out one at a time, and
    MoorDyn's RK2 at 1 ms coupled every 0.1 s (its binding's per-call cost spread thin), interleaved rounds, the
    fastest of each: ns per node and evaluation (4 per rk4 step, 2 per RK2 step)."""
    import tomli_w

    import ropesim

    variants = {
        "all terms": lambda d: None,
        "without added mass": lambda d: d.pop("added_mass"),
        "without fluid drag": lambda d: d.pop("fluid_drag"),
        "without axial damping": lambda d: d["rope"].update(axial_damping=0.0),
        "without the seabed": lambda d: d.pop("seabed"),
        "springs, gravity, buoyancy only": lambda d: (d.pop("added_mass"), d.pop("fluid_drag"), d.pop("seabed"),
                                                      d["rope"].update(axial_damping=0.0)),
    }
    scenes = {}
    for name, change in variants.items():
        d = chain_scene_dict(case, start, method="rk4", dt=dt, t_end=t_end, interval=DT_OUT, dimension=3,
                             both_ways=SEABED["both_ways"],
                             surge=SURGE)
        change(d)
        scenes[name] = ropesim.scene_from_toml(tomli_w.dumps(d))
    best = {name: math.inf for name in [*scenes, "MoorDyn RK2"]}
    for rnd in range(repeats + 1):
        for name, scene in scenes.items():
            wall = ropesim.simulate(scene).summary["wall_time_s"]
            best[name] = min(best[name], wall) if rnd else best[name]
        wall = moordyn_run(case, start, "RK2", 1e-3, t_end, coupling=DT_OUT)["wall"]
        best["MoorDyn RK2"] = min(best["MoorDyn RK2"], wall) if rnd else best["MoorDyn RK2"]
    nodes = case.segments + 1
    out = {name: 1e9 * wall / (t_end / dt * 4 * nodes) for name, wall in best.items() if name != "MoorDyn RK2"}
    out["MoorDyn RK2"] = 1e9 * best["MoorDyn RK2"] / (t_end / 1e-3 * 2 * nodes)
    return out


def crossover(sweep: list[dict], target: str) -> float | None:
    """The EA (N) where sdirk2's cheapest configuration costs the same as the best explicit ropesim method's,
    interpolated in log EA between the swept values (None if it never crosses)."""
    pts = []
    for s in sweep:
        per = s["cheapest"][target]
        explicit = [per[k]["wall_per_s"] for k in ("ropesim verlet", "ropesim rk4") if k in per]
        if explicit and "ropesim sdirk2" in per:
            pts.append((math.log(s["EA"]), math.log(per["ropesim sdirk2"]["wall_per_s"] / min(explicit))))
    for (a, ra), (b, rb) in zip(pts, pts[1:]):
        if ra > 0.0 >= rb:
            return math.exp(a + (b - a) * ra / (ra - rb))
    return None


# ------------------------------------------------------------------------------------------------ tables


def speed_table(rows: list[dict]) -> str:
    lines = ["| code | method | step | wall time per simulated second | real-time factor | fairlead tension error "
             "(RMS / range) | (RMS / RMS) |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        if not r["ok"]:
            lines.append(f"| {r['code']} | {r['method']} | {r['dt_s'] * 1e3:.4g} ms | {r.get('status')} | | | |")
            continue
        step = r["method"].split(" tol=")[1] + " m tolerance" if " tol=" in r["method"] else f"{r['dt_s'] * 1e3:.4g} ms"
        lines.append(f"| {r['code']} | {r['method'].split(' tol=')[0]} | {step} | {r['wall_per_s'] * 1e3:.2f} ms | "
                     f"{r['real_time_factor']:.0f} | {r['error']:.2e} | {r['error_of_rms']:.2e} |")
    return "\n".join(lines)


def target_table(best: dict) -> str:
    keys = ["ropesim verlet", "ropesim rk4", "ropesim sdirk2", "ropesim galpha", "ropesim galpha adaptive",
            "MoorDyn RK2", "MoorDyn RK4"]
    keys = [k for k in keys if any(k in per for per in best.values())]
    lines = ["| accuracy (RMS / range) | " + " | ".join(keys) + " | best ropesim / best MoorDyn |",
             "| --- |" + " --- |" * (len(keys) + 1)]
    for target, per in best.items():
        cells = []
        for k in keys:
            b = per.get(k)
            cells.append(f"{b['wall_per_s'] * 1e3:.2f} ms/s at {b['dt_s'] * 1e3:.3g} ms: 3 h in "
                         f"{b['sea_state_wall_s']:.0f} s ({b['real_time_factor']:.0f}x real time)" if b else "not reached")
        rs = [per[k]["wall_per_s"] for k in keys if k in per and k.startswith("ropesim")]
        md = [per[k]["wall_per_s"] for k in keys if k in per and k.startswith("MoorDyn")]
        ratio = f"{min(md) / min(rs):.2f}x faster" if rs and md else ""
        lines.append(f"| {float(target) * 100:g} % | " + " | ".join(cells) + f" | {ratio} |")
    return "\n".join(lines)


def config_label(best: dict) -> str:
    """A cheapest configuration's step (``0.1 ms``) or tolerance (``tol=0.01``)."""
    return best["method"].partition(" ")[2] or f"{best['dt_s'] * 1e3:.3g} ms"


def sweep_table(sweep: list[dict]) -> str:
    keys = ["ropesim verlet", "ropesim rk4", "ropesim sdirk2", "ropesim galpha", "ropesim galpha adaptive"]
    lines = ["| EA (N) | accuracy | " + " | ".join(keys) + " | sdirk2 / best explicit ropesim |",
             "| --- | --- |" + " --- |" * (len(keys) + 1)]
    for s in sweep:
        for target, per in s["cheapest"].items():
            cells = [f"{per[k]['wall_per_s'] * 1e3:.2f} ms/s ({config_label(per[k])})" if k in per else "—"
                     for k in keys]
            explicit = [per[k]["wall_per_s"] for k in keys[:2] if k in per]
            ratio = (f"{per['ropesim sdirk2']['wall_per_s'] / min(explicit):.2f}"
                     if explicit and "ropesim sdirk2" in per else "")
            lines.append(f"| {s['EA']:.0e} | {float(target) * 100:g} % | " + " | ".join(cells) + f" | {ratio} |")
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------------ figure


STYLE = {"ropesim verlet": ("C2", "o"), "ropesim rk4": ("C3", "s"), "ropesim sdirk2": ("C1", "D"),
         "MoorDyn RK2": ("C0", "^"), "MoorDyn RK4": ("C9", "v")}


def draw(rows: list[dict], sweep: list[dict], floor: float, path: Path, window: float) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = 2 if sweep else 1
    fig, axes = plt.subplots(1, panels, figsize=(6.2 * panels, 4.6), layout="constrained", squeeze=False)
    ax = axes[0, 0]
    for key, (color, marker) in STYLE.items():
        pts = sorted((r["wall_per_s"], r["error"]) for r in rows if r["ok"] and f"{r['code']} {r['method']}" == key)
        if pts:
            w, e = zip(*pts)
            ax.loglog(np.array(w) * 1e3, e, marker=marker, color=color, lw=1.2, ms=5, label=key)
    for target in TARGETS:
        ax.axhline(target, color="0.6", lw=0.6, ls=":")
    ax.axhline(floor, color="C0", lw=0.6, ls="--", label="the two codes' converged answers apart")
    ax.axvline(10.0, color="k", lw=0.8, ls="--", label="100x faster than real time")
    ax.set_xlabel("wall time per simulated second [ms]")
    ax.set_ylabel("fairlead tension error (RMS / range)")
    ax.set_title(f"WD0050 chain (83 nodes, 3-D), fairlead surging 5 m at 15 s, {window:g} s;\n"
                 "each code against its own converged answer", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    if sweep:
        ax = axes[0, 1]
        target = f"{TARGETS[0]:g}"
        for key in ("ropesim verlet", "ropesim rk4", "ropesim sdirk2"):
            color, marker = STYLE[key]
            pts = [(s["EA"], s["cheapest"][target][key]["wall_per_s"]) for s in sweep if key in s["cheapest"][target]]
            if pts:
                ea, w = zip(*pts)
                ax.loglog(ea, np.array(w) * 1e3, marker=marker, color=color, lw=1.2, ms=5, label=key)
        ax.axvline(1.674e9, color="0.5", lw=0.6, ls=":", label="WD0050's chain")
        ax.set_xlabel("EA [N]")
        ax.set_ylabel(f"wall time per simulated second at {float(target) * 100:g} % [ms]")
        ax.set_title(f"the same chain stiffer: cheapest step reaching {float(target) * 100:g} % "
                     f"({SWEEP_WINDOW:g} s)", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    from ropesim.io.atomic import atomic_output

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ fluid cases

#: galpha's configurations on the equal-physics fluid cases: fixed steps DT_OUT / k and tolerances [m], six per
#: decade (1, 1.5, 2, 3, 5, 7): with one per decade the cheapest tolerance reaching 1 % was up to 3x tighter than
#: it needed to be (the cost grows about as tol^(-1/2)), each at every rho_inf of ``--fluid-rho``
FLUID_GALPHA_KS = (1, 2, 4, 8, 16, 32)
FLUID_GALPHA_TOLERANCES = tuple(m * 10.0 ** e for e in (-2, -3, -4) for m in (7, 5, 3, 2, 1.5, 1)) + (1e-1,)
#: rho_inf tried on the fluid cases. 0 is the moorings' setting (the steady current needs it: at 0.5 its top
#: tension is 2.8 % off at tol 1e-2 against 0.11 %). The towed line and the catenary ring after their start, and
#: their steps are set by following that ringing's phase: a smaller error constant |beta - 1/6 + (am - af) / 2|
#: (0.33 at rho_inf 0, 0.16 at 0.3, 0.11 at 0.5) takes fewer steps at the same tension error (the towed line:
#: 1886 steps at 0.3 against 2594 at 0, 0.96 and 1.0 %), until af grows the rejections (0.7 and 0.9: 3 to 8 times
#: more on the towed line)
FLUID_RHO = (0.0, 0.3, 0.5)
#: MoorDyn's steps tried from the largest down (s); its largest stable RK2 step is 0.4 ms on the hanging line and
#: 0.6 ms on the catenary (scripts/compare_moordyn.py), RK4's a little larger
FLUID_MOORDYN_DTS = (8.0e-4, 6.0e-4, 5.0e-4, 4.0e-4, 3.0e-4, 2.0e-4)


def galpha_label(rho: float, tol: float | None = None) -> str:
    """A galpha configuration's method label: "galpha rho=R" (fixed steps) or "galpha rho=R tol=T"."""
    return f"galpha rho={rho:g}" + ("" if tol is None else f" tol={tol:g}")


def galpha_config(method: str) -> tuple[str, float | None, float | None]:
    """(scheme, rho_inf or None, tolerance or None) of a method label (:func:`galpha_label`, or a plain name)."""
    scheme, _, tol = method.partition(" tol=")
    scheme, _, rho = scheme.partition(" rho=")
    return scheme, (float(rho) if rho else None), (float(tol) if tol else None)


def fluid_runs(name: str, window: float):
    """The equal-physics case ``name`` (tests/references/moordyn_equal_physics.py, full size) cut to ``window``
    seconds, its shared start (MoorDyn's initial state) and a runner (code, method, dt) -> (top tension (F,) or
    None, wall time of the time loop [s])."""
    import tomli_w

    import ropesim
    from references.moordyn_equal_physics import CASES, Series, ropesim_scene_dict, run_moordyn

    case = CASES[name].with_(t_end=min(CASES[name].t_end, window))
    start = run_moordyn(case, t_end=case.dt_out).positions[0]

    def runner(code: str, method: str, dt: float):
        if code == "MoorDyn":
            try:
                out = Series.of_moordyn(run_moordyn(case, dtM=dt, scheme=method))
            except RuntimeError:
                return None, math.nan
            frames = int(round(case.t_end / case.dt_out)) + 1
            ok = out.top.size == frames and np.all(np.isfinite(out.top)) and np.all(np.isfinite(out.x))
            ok = ok and float(np.abs(out.x).max()) < 1e3
            return (out.top if ok else None), out.wall
        scheme, rho, tol = galpha_config(method)
        d = ropesim_scene_dict(case, start, method=scheme, dt=dt)
        if scheme == "galpha":
            d["integrator"]["rho_inf"] = GALPHA["rho_inf"] if rho is None else rho
            if tol is not None:
                d["integrator"]["tolerance"] = tol
        traj = ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(d)))
        if traj.summary["status"] != "completed":
            return None, math.nan
        return Series.of_ropesim(traj).top, traj.summary["wall_time_s"]

    return case, start, runner


def fluid_case(name: str, window: float, repeats: int, rhos=FLUID_RHO) -> dict:
    """galpha against MoorDyn on one equal-physics case: each code's converged answer (its RK4 at a small step,
    checked against twice that step), every configuration timed ``repeats`` rounds (the fastest kept), the top
    tension's RMS error over the reference's range, and the cheapest configuration of each reaching 1 % and 0.1 %."""
    from ropesim.analysis.stability import predicted_dt
    from ropesim.model.build import build
    from references.moordyn_equal_physics import ropesim_scene

    case, start, runner = fluid_runs(name, window)
    rk4_bound = predicted_dt(build(ropesim_scene(case, start, method="rk4", dt=1e-4)), "rk4")
    k = k_at_most(0.1 * rk4_bound)
    refs, ref_info = {}, {}
    for code, method, dt, check in (("ropesim", "rk4", step_of(k), step_of(max(1, k // 2))),
                                    ("MoorDyn", "RK4", 5.0e-5, 1.0e-4)):
        fine, _ = runner(code, method, dt)
        half, _ = runner(code, method, check)
        if fine is None or half is None:
            raise RuntimeError(f"{name}: {code}'s reference run did not complete")
        refs[code] = fine
        ref_info[code] = {"method": method, "dt_s": dt, "check_dt_s": check, "check_rms_of_range":
                          float(np.sqrt(np.mean((fine[1:] - half[1:]) ** 2)) / np.ptp(fine[1:]))}
    configs = [("ropesim", galpha_label(rho), step_of(k)) for rho in rhos for k in FLUID_GALPHA_KS]
    configs += [("ropesim", galpha_label(rho, tol), DT_OUT) for rho in rhos for tol in FLUID_GALPHA_TOLERANCES]
    for scheme in MOORDYN_SCHEMES:   # from the largest step that stays finite down
        stable = [dt for dt in FLUID_MOORDYN_DTS if runner("MoorDyn", scheme, dt)[0] is not None]
        configs += [("MoorDyn", scheme, dt) for dt in stable[:3]]
    rows = [{"code": c, "method": m, "dt_s": dt, "walls": [], "ok": True} for c, m, dt in configs]
    for _ in range(repeats):
        for row in rows:
            if not row["ok"]:
                continue
            top, wall = runner(row["code"], row["method"], row["dt_s"])
            if top is None:
                row.update(ok=False)
                continue
            row["walls"].append(wall)
            ref = refs[row["code"]]
            row["error"] = float(np.sqrt(np.mean((top[1:] - ref[1:]) ** 2)) / np.ptp(ref[1:]))
    for row in rows:
        if row["ok"]:
            row["wall_per_s"] = min(row["walls"]) / case.t_end
            row["real_time_factor"] = 1.0 / row["wall_per_s"]
    best = cheapest(rows, TARGETS[:2])
    ratios = {}
    for target, per in best.items():
        moordyn = [v["wall_per_s"] for key, v in per.items() if key.startswith("MoorDyn")]
        galpha = [v["wall_per_s"] for key, v in per.items() if key.startswith("ropesim galpha")]
        ratios[target] = min(moordyn) / min(galpha) if moordyn and galpha else None
    return {"case": name, "window_s": case.t_end, "nodes": case.segments + 1, "references": ref_info,
            "rows": rows, "cheapest": best, "moordyn_over_galpha": ratios}


def fluid_table(results: list[dict]) -> str:
    lines = ["| case | accuracy | galpha (cheapest) | MoorDyn (cheapest) | MoorDyn / galpha |", "|---|---|---|---|---|"]
    for r in results:
        for target, per in r["cheapest"].items():
            def cell(prefix):
                rows = [(v["wall_per_s"], v) for key, v in per.items() if key.startswith(prefix)]
                if not rows:
                    return "not reached"
                _, v = min(rows, key=lambda p: p[0])
                return f"{1e3 * v['wall_per_s']:.2f} ms/s ({v['method']}, {1e3 * v['dt_s']:g} ms; {100 * v['error']:.2g} %)"
            ratio = r["moordyn_over_galpha"][target]
            lines.append(f"| {r['case']} ({r['nodes']} nodes, {r['window_s']:g} s) | {float(target) * 100:g} % | "
                         f"{cell('ropesim galpha')} | {cell('MoorDyn')} | "
                         f"{'-' if ratio is None else f'{ratio:.1f}x'} |")
    return "\n".join(lines)


def fluid_main(args) -> int:
    """``--fluid``: the three equal-physics fluid cases, galpha against MoorDyn (the issue's >= 5x at 1 %)."""
    from references.moordyn_harness import moordyn_version

    started = time.perf_counter()
    rhos = args.fluid_rho
    results = []
    for name in args.fluid.split(","):
        print(f"{name}, {args.fluid_window:g} s ...", flush=True)
        results.append(fluid_case(name, args.fluid_window, args.repeats, rhos))
    try:
        load = os.getloadavg()
    except OSError:
        load = None
    out = {"made_by": "scripts/bench_moorings.py --fluid", "moordyn_version": moordyn_version(),
           "galpha_rho_inf": list(rhos), "load_average_after": load,
           "accuracy": "RMS of the top tension's difference from the code's own converged answer over the window, "
                       "divided by that answer's range", "cases": results}
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
    for r in results:
        print(f"\n{r['case']}: references {r['references']}")
        for row in r["rows"]:
            err = f"{100 * row['error']:.3g} %" if row["ok"] else "failed"
            wall = f"{1e3 * row['wall_per_s']:.2f} ms/s" if row["ok"] else ""
            print(f"  {row['code']} {row['method']} {1e3 * row['dt_s']:g} ms: {err} {wall}")
    print("\n" + fluid_table(results))
    print(f"\nwrote {args.json}; load average {load}; total {time.perf_counter() - started:.0f} s")
    return 0


# ------------------------------------------------------------------------------------------------ main


def stiff_sweep(args) -> list[dict]:
    """The EA sweep (ropesim only, each EA against its own rk4 reference); ``--only`` keeps those methods."""
    sweep = []
    for EA in (float(e) for e in args.sweep_ea.split(",")):
        print(f"EA = {EA:.0e} N, {SWEEP_WINDOW:g} s ...", flush=True)
        c, s0 = problem(EA)
        r, r_info = reference(c, s0, SWEEP_WINDOW)
        cfg, n = configurations(c, s0, SWEEP_WINDOW, 4, moordyn=False)
        if args.only:
            keep = set(args.only.split(","))
            cfg = [x for x in cfg if x[1].split(" tol=")[0] in keep]
        sweep_rows = measure(c, s0, cfg, {"ropesim": r}, SWEEP_WINDOW, max(1, args.repeats - 1))
        sweep.append({"EA": EA, "BA": c.BA, "reference": r_info, "notes": n, "rows": sweep_rows,
                      "cheapest": cheapest(sweep_rows, TARGETS[:2])})
    return sweep


def sweep_main(args, started: float) -> int:
    """``--sweep-only``: the stiff chains alone, printed and written to ``--json``."""
    sweep = stiff_sweep(args)
    for s in sweep:
        print(f"\nEA {s['EA']:.0e} N: reference {s['reference']}")
        for row in s["rows"]:
            err = f"{100 * row['error']:.3g} %" if row["ok"] else f"failed ({row.get('status', '')})"
            wall = f"{1e3 * row['wall_per_s']:.2f} ms/s" if row["ok"] else ""
            print(f"  {row['method']} {1e3 * row['dt_s']:.3g} ms: {err} {wall}")
    print(f"\n## Stiffer chains ({SWEEP_WINDOW:g} s)\n")
    print(sweep_table(sweep))
    load = os.getloadavg()
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps({"made_by": "scripts/bench_moorings.py --sweep-only", "galpha_rho_inf":
                                     GALPHA["rho_inf"], "sweep": sweep, "sweep_window_s": SWEEP_WINDOW,
                                     "load_average_after": load}, indent=1) + "\n", encoding="utf-8")
    print(f"\nwrote {args.json}; load average {load}; total {time.perf_counter() - started:.0f} s")
    return 0


def rho_values(text: str) -> tuple[float, ...]:
    """``--fluid-rho``'s comma-separated rho_inf values, each in [0, 1]."""
    try:
        values = tuple(float(r) for r in text.split(","))
    except ValueError:
        values = ()
    if not values or not all(0.0 <= r <= 1.0 for r in values):
        raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated numbers in [0, 1], e.g. 0,0.3,0.5")
    return values


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="timed rounds (the fastest of each is kept)")
    parser.add_argument("--window", type=float, default=120.0, help="simulated seconds of the main comparison")
    parser.add_argument("--points", type=int, default=4, help="steps per explicit method's ladder")
    parser.add_argument("--no-sweep", action="store_true", help="skip the EA sweep")
    parser.add_argument("--sweep-only", action="store_true", help="only the EA sweep (no MoorDyn, no WD0050 window)")
    parser.add_argument("--only", help="comma-separated ropesim methods to time (default: all; MoorDyn always)")
    parser.add_argument("--galpha-rho", type=float, default=0.0,
                        help="galpha's rho_inf (default 0, the setting for moorings; galpha's own default is 0.9); "
                             "--fluid tries those of --fluid-rho instead")
    parser.add_argument("--own-seabed", action="store_true",
                        help="ropesim's own seabed damping (into the plane only) instead of MoorDyn's two-way law")
    parser.add_argument("--sweep-ea", default=",".join(f"{e:g}" for e in SWEEP_EA), help="EA values (N) to sweep")
    parser.add_argument("--json", type=Path, default=JSON, help="where the results go")
    parser.add_argument("--figure", type=Path, default=FIGURE, help="PNG of error against cost, and the sweep")
    parser.add_argument("--fluid", nargs="?", const="current,towed,catenary", default=None,
                        help="instead: galpha against MoorDyn on the equal-physics fluid cases (comma-separated)")
    parser.add_argument("--fluid-window", type=float, default=20.0, help="--fluid: simulated seconds per case")
    parser.add_argument("--fluid-rho", type=rho_values, default=FLUID_RHO,
                        help="--fluid: galpha's rho_inf values to try (comma-separated, each in [0, 1]; each with "
                             "every step and tolerance; default " + ",".join(f"{r:g}" for r in FLUID_RHO) + ")")
    args = parser.parse_args(argv)
    SEABED["both_ways"] = not args.own_seabed
    GALPHA["rho_inf"] = args.galpha_rho
    if args.fluid:
        if args.json == JSON:
            args.json = JSON.with_name("moorings_fluid_speed.json")
        return fluid_main(args)

    from references.moordyn_harness import moordyn_version

    import ropesim

    started = time.perf_counter()
    print(f"MoorDyn {moordyn_version()}, ropesim {ropesim.__version__}", flush=True)
    if args.sweep_only:
        return sweep_main(args, started)
    case, start = problem()
    print(f"reference (rk4), {args.window:g} s ...", flush=True)
    ref, ref_info = reference(case, start, args.window)
    print(f"reference (MoorDyn RK4), {args.window:g} s ...", flush=True)
    md_ref, md_ref_info = reference(case, start, args.window, "MoorDyn")
    floor = differences(ref, md_ref)["rms_of_range"]
    overhead = call_overhead(case, start, 20.0, args.repeats)
    print("ladders (largest stable steps) ...", flush=True)
    configs, notes = configurations(case, start, args.window, args.points)
    if args.only:
        keep = set(args.only.split(","))
        configs = [c for c in configs if c[0] == "MoorDyn" or c[1].split(" tol=")[0] in keep]
    print(f"timing {len(configs)} configurations, {args.repeats} rounds ...", flush=True)
    rows = measure(case, start, configs, {"ropesim": ref, "MoorDyn": md_ref}, args.window, args.repeats,
                   overhead["per_call_us"] * 1e-6)
    best = cheapest(rows)
    print("cost per force evaluation ...", flush=True)
    per_eval = term_costs(case, start, args.repeats)

    sweep = [] if args.no_sweep else stiff_sweep(args)

    try:
        load = os.getloadavg()
    except OSError:
        load = None
    result = {
        "made_by": "scripts/bench_moorings.py", "moordyn_version": moordyn_version(),
        "ropesim_version": ropesim.__version__, "machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                                                            "load_average_after": load},
        "case": {"seabed_damping_both_ways": SEABED["both_ways"], "name": case.name, "nodes": case.segments + 1, "dimension": 3, "EA_N": case.EA, "BA_Ns": case.BA,
                 "surge": {"amplitude_m": SURGE.amplitude, "period_s": SURGE.period, "ramp_time_s": SURGE.ramp_time},
                 "window_s": args.window, "output_s": DT_OUT},
        "accuracy": "RMS over the window of the fairlead tension's difference from the reference, divided by the "
                    "reference's range (error) or by its RMS (error_of_rms)",
        "reference": ref_info, "reference_range_N": float(np.ptp(ref[1:])), "reference_rms_N":
            float(np.sqrt(np.mean(ref[1:] ** 2))),
        "moordyn_reference": md_ref_info, "converged_answers_apart_rms_of_range": floor,
        "largest_steps": notes, "moordyn_call_overhead": overhead, "repeats": args.repeats,
        "ns_per_node_evaluation": per_eval,
        "rows": [{k: v for k, v in r.items()} for r in rows], "cheapest": best, "sea_state_s": SEA_STATE,
        "sweep": sweep, "sweep_window_s": SWEEP_WINDOW,
        "crossover_EA_N": {f"{t:g}": crossover(sweep, f"{t:g}") for t in TARGETS[:2]} if sweep else None,
    }
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    draw(rows, sweep, floor, args.figure, args.window)

    print(f"\n## Every configuration ({args.window:g} s; reference: {ref_info})\n")
    print(speed_table(rows))
    print(f"\n## Cheapest configuration per accuracy (3 h = {SEA_STATE:g} s)\n")
    print(target_table(best))
    print(f"\nMoorDyn's converged answer ({md_ref_info}) against ropesim's: {floor:.2e} of the range; "
          f"MoorDyn's Step call costs {overhead['per_call_us']:.1f} us in the binding "
          f"({100 * overhead['share_of_time_at_1ms']:.0f} % of its time at 1 ms); largest stable steps: "
          + "; ".join(f"{k} {v['largest_stable_s'] * 1e3:.3g} ms" for k, v in notes.items()))
    print("\nns per node and force evaluation: " + ", ".join(f"{k} {v:.0f}" for k, v in per_eval.items()))
    if sweep:
        print(f"\n## Stiffer chains ({SWEEP_WINDOW:g} s)\n")
        print(sweep_table(sweep))
        print(f"\nsdirk2 as cheap as the best explicit method at EA = {result['crossover_EA_N']} N")
    print(f"\nwrote {args.json}, {args.figure}; load average {load}; total {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
