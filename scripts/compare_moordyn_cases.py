"""ropesim against MoorDyn on MoorDyn's own test cases: three chains on a seabed (WD0050, WD0200, WD0600) and the
cantilevered beam. Prints the agreement as Markdown tables and draws docs/images/moordyn_own_cases.png.

tests/references/moordyn_own_cases.py builds each case for ropesim from MoorDyn's own input file and sets out the
conventions (friction, the fairlead's velocity jumps, the beam's straight start). Compared:

- static: ropesim's static solve (``initial.shape = "equilibrium"``) and the end of a settled dynamic run (from a
  straight line between the ends, every segment slack, 600 s of sdirk2 at 6.25 ms with the fairlead held) against
  MoorDyn's IC state as its file sets it up (stored) and run tight (its stationary solver to threshIC 1e-6, stored
  in tests/data/moordyn/own_cases.json); for the beam the tip deflection against Euler-Bernoulli and against the
  deflection MoorDyn's release oscillates about;
- dynamic: MoorDyn's stored run (RK2, its own dtM, the fairlead surging along the stored path) against ropesim's rk4
  at the same step from MoorDyn's IC state, along the same path: the fairlead tension (MoorDyn's ``GetLineFairTen``
  definition, see the module) and the anchor tension; for the beam the tip's height after a straight release;
- where the difference comes from: both codes against MoorDyn's converged answer (RK4 at dtM/2, stored), ropesim's
  step halved three times, friction off, ropesim's own (one-way) seabed damping instead of MoorDyn's two-way law
  (``seabed.damping_both_ways``, which the cases set), MoorDyn's reported tension against the one from its state.

    pip install -e ".[test]"     # moordyn, scipy
    python scripts/compare_moordyn_cases.py [--cases WD0050_Chain,...,BeamCantilevered] [--figure PATH]
    python scripts/compare_moordyn_cases.py --regenerate      # rerun MoorDyn for tests/data/moordyn/own_cases.*

About 8 minutes on a shared 2-core machine at load 4 to 6; --regenerate adds about 5 minutes of MoorDyn runs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]   # this checkout's ropesim, not an installed one

from references.moordyn_own_cases import (  # noqa: E402
    BEAM,
    CHAINS,
    DATA,
    anchor_tension,
    beam_case,
    beam_static_tip,
    catenary_start,
    chain_case,
    differences,
    fairlead_tension,
    fit_oscillation,
    fitting_step,
    load_reference,
    ropesim_static,
    run_beam,
    run_chain,
    run_moordyn_beam_straight,
    run_moordyn_chain,
    static_tensions,
    to_ropesim,
)

FIGURE = ROOT / "docs" / "images" / "moordyn_own_cases.png"
STORED = DATA / "own_cases"          # own_cases.npz and own_cases.json
TIGHT_IC = {"threshIC": 1e-6, "TmaxIC": 4000}
BEAM_DT = 5.0e-5                     # s: ropesim's rk4 on the beam (1e-4 blows up: EA on 0.53 m segments)
SETTLE = {"t_end": 600.0, "dt": 0.00625}   # sdirk2 at 12.5 ms fails its Newton solve on WD0600's fall


def pct(x: float) -> str:
    return f"{100 * x:+.4f} %"


def rel(x: float) -> str:
    return f"{x:.2e}"


# ------------------------------------------------------------------------------------------------ MoorDyn data


def regenerate(names: list[str]) -> None:
    """Run MoorDyn for the data the tests and this script read beyond the stored runs: its IC run tight, its
    converged answer on the stored motion (RK4 at dtM/2, tension from its state), the beam's straight release."""
    from references.moordyn_harness import moordyn_version

    record: dict = {"moordyn_version": moordyn_version(),
                    "made_by": "scripts/compare_moordyn_cases.py --regenerate",
                    "tight_ic_options": TIGHT_IC, "chains": {}}
    arrays: dict[str, np.ndarray] = {}
    for name in names:
        if name == BEAM:
            continue
        case = chain_case(name)
        print(f"  {name}: MoorDyn's IC run tight {TIGHT_IC} ...", flush=True)
        tic = time.perf_counter()
        tight = run_moordyn_chain(case, TIGHT_IC, t_end=0.0)
        ic_wall = time.perf_counter() - tic
        print(f"  {name}: MoorDyn RK4 at dtM / 2 over the stored motion ...", flush=True)
        conv = run_moordyn_chain(case, {"tScheme": "RK4", "dtM": case.dtM / 2}, positions=False)
        rk2 = run_moordyn_chain(case, positions=False)
        record["chains"][name] = {
            "tight_ic": {"fairlead_tension_N": float(tight.reported[0]), "anchor_tension_N": float(tight.anchor[0]),
                         "wall_s": ic_wall},
            "converged": {"scheme": conv.scheme, "dtM_s": conv.dtM},
        }
        arrays[f"{name}_tight_ic_positions"] = tight.positions[0]
        arrays[f"{name}_converged_fairlead"] = conv.from_state
        arrays[f"{name}_converged_anchor"] = conv.anchor
        arrays[f"{name}_rk2_fairlead_from_state"] = rk2.from_state
    if BEAM in names:
        print("  BeamCantilevered: MoorDyn's straight release ...", flush=True)
        beam = beam_case()
        run = run_moordyn_beam_straight(beam)
        nodes = np.unique(np.round(np.linspace(0, beam.segments, 5)).astype(int))
        arrays["beam_straight_t"] = run["t"]
        arrays["beam_straight_nodes"] = nodes
        arrays["beam_straight_positions"] = run["positions"][:, nodes]
        record["beam_straight"] = {"dtM_s": beam.dtM, "dt_out_s": beam.dt_out, "t_end_s": beam.t_end,
                                   "wall_s": run["wall"], "fit": fit_oscillation(run["t"], run["positions"][:, -1, 2])}
    record["fields"] = {
        "<case>_tight_ic_positions": "m, (N+1, 3): MoorDyn's IC state with tight_ic_options",
        "<case>_converged_fairlead": "N, (F,): top segment |T + Td| from MoorDyn's state at each frame (RK4, dtM/2), "
                                     "the fairlead at the secant velocity of the interval ending there",
        "<case>_converged_anchor": "N, (F,): GetLineNodeTen(0) of the same run",
        "<case>_rk2_fairlead_from_state": "N, (F,): as converged_fairlead, for the stored RK2 run (dtM)",
        "beam_straight_t": "s, (F,)", "beam_straight_nodes": "(k,): node indices stored",
        "beam_straight_positions": "m, (F, k, 3): MoorDyn's beam released straight and at rest (MoorDyn frame)",
    }
    np.savez_compressed(f"{STORED}.npz", **arrays)
    Path(f"{STORED}.json").write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {STORED}.npz, {STORED}.json")


def stored() -> tuple[dict, dict]:
    with np.load(f"{STORED}.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    return arrays, json.loads(Path(f"{STORED}.json").read_text(encoding="utf-8"))


# ------------------------------------------------------------------------------------------------ the chains


def chain_results(name: str, arrays: dict, record: dict) -> dict:
    case = chain_case(name)
    ref, rec = load_reference(name)
    out: dict = {"case": case, "ref": ref, "rec": rec}
    print(f"  {name}: static solve, settled run ...", flush=True)
    x, fair, anch = ropesim_static(case)
    settled = run_chain(case, catenary_start(case), method="sdirk2", moving=False, interval=10.0, **SETTLE)
    sx, sv = np.asarray(settled.x), np.asarray(settled.v)
    s_fair, s_anch = static_tensions(case, sx[-1])
    tight = record["chains"][name]["tight_ic"]
    out["static"] = {
        "moordyn": (float(ref["fairlead_tension"][0]), float(ref["anchor_tension"][0])),
        "tight": (tight["fairlead_tension_N"], tight["anchor_tension_N"]),
        "equilibrium": (fair, anch), "settled": (s_fair, s_anch),
        "settled_speed": float(np.abs(sv[-1]).max()), "settled_status": settled.summary["status"],
        "catenary": rec["comparison"]["elastic_catenary_rigid_frictionless_seabed"]["fairlead_tension_N"],
        "positions": float(np.abs(x - to_ropesim(arrays[f"{name}_tight_ic_positions"])).max()),
    }
    start, dt = ref["static_positions"], fitting_step(case.dt_out, case.dtM)
    print(f"  {name}: dynamic runs (rk4 at {dt * 1e3:.4g} ms and its halvings) ...", flush=True)
    runs = {}
    for k in (1, 2, 4, 8):
        traj = run_chain(case, start, method="rk4", dt=dt / k)
        runs[k] = (fairlead_tension(case, traj), anchor_tension(traj), float(traj.summary["wall_time_s"]))
    nofric = run_chain(case, start, method="rk4", dt=dt, friction=False)
    one_way = run_chain(case, start, method="rk4", dt=dt, both_ways=False)   # ropesim's own seabed damping
    fair_rs, anch_rs, wall = runs[1]
    conv_fair, conv_anch = arrays[f"{name}_converged_fairlead"], arrays[f"{name}_converged_anchor"]
    out["dynamic"] = {
        "dt": dt, "wall": wall, "md_wall": rec["dynamic"]["wall_time_s"],
        "fair": differences(ref["fairlead_tension"], fair_rs),
        "anchor": differences(ref["anchor_tension"], anch_rs),
        "ladder": {k: differences(conv_fair, f) for k, (f, a, w) in runs.items()},
        "ladder_anchor": {k: differences(conv_anch, a) for k, (f, a, w) in runs.items()},
        "md_rk2": differences(conv_fair, arrays[f"{name}_rk2_fairlead_from_state"]),
        "md_reported": differences(conv_fair, ref["fairlead_tension"]),
        "friction": differences(fair_rs, fairlead_tension(case, nofric)),
        "one_way_fair": differences(ref["fairlead_tension"], fairlead_tension(case, one_way)),
        "one_way_anchor": differences(ref["anchor_tension"], anchor_tension(one_way)),
        "series": (ref["t"], ref["fairlead_tension"], fair_rs),
    }
    return out


# ------------------------------------------------------------------------------------------------ the beam


def beam_results(arrays: dict, record: dict) -> dict:
    case = beam_case()
    ref, rec = load_reference(BEAM)
    print("  BeamCantilevered: static solve and release ...", flush=True)
    tip = beam_static_tip(case)
    traj = run_beam(case, dt=BEAM_DT)
    y = np.asarray(traj.x)[:, -1, 1]
    md_t, md_tip = arrays["beam_straight_t"], arrays["beam_straight_positions"][:, -1, 2]
    md_fit, rs_fit = fit_oscillation(md_t, md_tip), fit_oscillation(np.asarray(traj.t), y)
    level = case.clamp[2]
    return {"case": case, "tip_equilibrium": tip, "tip_analytic": case.analytic_tip,
            "tip_md_ic": level - float(ref["static_positions"][-1, 2]),
            "tip_md_fit": level - md_fit["offset"], "tip_rs_fit": level - rs_fit["offset"],
            "md_freq": md_fit["frequencies"], "rs_freq": rs_fit["frequencies"],
            "analytic_freq": [case.analytic_frequency(k) for k in (1, 2, 3)],
            "release": differences(md_tip, y), "wall": float(traj.summary["wall_time_s"]),
            "md_wall": record["beam_straight"]["wall_s"], "series": (md_t, md_tip, y)}


# ------------------------------------------------------------------------------------------------ tables


def static_table(chains: list[dict], beam: dict | None) -> str:
    rows = ["| case | quantity | MoorDyn IC (its file's options) | MoorDyn IC run tight | ropesim static solve | "
            "ropesim settled run | static solve − tight IC | static solve − file's IC |",
            "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in chains:
        s = r["static"]
        for k, label in ((0, "fairlead tension"), (1, "anchor tension")):
            md, tight, eq, st = s["moordyn"][k], s["tight"][k], s["equilibrium"][k], s["settled"][k]
            rows.append(f"| {r['case'].name} | {label} | {md / 1e3:.2f} kN | {tight / 1e3:.2f} kN | {eq / 1e3:.2f} kN "
                        f"| {st / 1e3:.2f} kN ({pct(st / eq - 1)} from the solve) | {pct(eq / tight - 1)} | "
                        f"{pct(eq / md - 1)} |")
    if beam:
        b = beam
        rows.append(f"| BeamCantilevered | tip deflection (Euler-Bernoulli {b['tip_analytic']:.5f} m) | "
                    f"{b['tip_md_ic']:.5f} m (stalled) | release oscillates about {b['tip_md_fit']:.6f} m | "
                    f"{b['tip_equilibrium']:.6f} m | release about {b['tip_rs_fit']:.6f} m | "
                    f"{pct(b['tip_equilibrium'] / b['tip_md_fit'] - 1)} (from MoorDyn's release) | |")
    return "\n".join(rows)


def dynamic_table(chains: list[dict], beam: dict | None) -> str:
    rows = ["| case | signal | range | RMS | ropesim − MoorDyn: RMS (max) | RMS / range | RMS / RMS of the signal |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in chains:
        d = r["dynamic"]
        for key, label in (("fair", "fairlead tension"), ("anchor", "anchor tension")):
            x = d[key]
            rows.append(f"| {r['case'].name} | {label} | {x['range'] / 1e3:.0f} kN | {x['signal_rms'] / 1e3:.0f} kN | "
                        f"{x['rms'] / 1e3:.2f} kN ({x['max'] / 1e3:.2f} kN) | {rel(x['rms_of_range'])} | "
                        f"{rel(x['rms_of_rms'])} |")
    if beam:
        x = beam["release"]
        rows.append(f"| BeamCantilevered | tip height after a straight release | {x['range'] * 1e3:.1f} mm | | "
                    f"{x['rms'] * 1e3:.4f} mm ({x['max'] * 1e3:.4f} mm) | {rel(x['rms_of_range'])} | |")
    return "\n".join(rows)


def explanation_table(chains: list[dict]) -> str:
    rows = ["| case | ropesim rk4 at dt, dt/2, dt/4, dt/8 − MoorDyn converged (fairlead, RMS / range) | "
            "anchor at dt | MoorDyn RK2 at dtM − converged | MoorDyn reported − from its state | friction's effect | "
            "ropesim's one-way seabed damping − MoorDyn: fairlead RMS (max), anchor RMS |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in chains:
        d = r["dynamic"]
        ladder = ", ".join(rel(d["ladder"][k]["rms_of_range"]) for k in (1, 2, 4, 8))
        rows.append(f"| {r['case'].name} (dt = {d['dt'] * 1e3:.4g} ms) | {ladder} | "
                    f"{rel(d['ladder_anchor'][1]['rms_of_range'])} | {rel(d['md_rk2']['rms_of_range'])} | "
                    f"{rel(d['md_reported']['rms_of_range'])} | {rel(d['friction']['rms_of_range'])} | "
                    f"{rel(d['one_way_fair']['rms_of_range'])} ({rel(d['one_way_fair']['max_of_range'])}), "
                    f"{rel(d['one_way_anchor']['rms_of_range'])} |")
    return "\n".join(rows)


# ------------------------------------------------------------------------------------------------ figure


def draw(chains: list[dict], beam: dict | None, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = len(chains) + (1 if beam else 0)
    fig, axes = plt.subplots(2, cols, figsize=(4.0 * cols, 5.4), layout="constrained", sharex="col",
                             squeeze=False, height_ratios=(2, 1))
    for col, r in enumerate(chains):
        t, md, rs = r["dynamic"]["series"]
        top, bottom = axes[0, col], axes[1, col]
        top.plot(t, md / 1e6, color="C0", lw=2.4, alpha=0.55, label=f"MoorDyn (RK2, {r['case'].dtM * 1e3:.3g} ms)")
        top.plot(t, rs / 1e6, color="C3", lw=0.9, ls="--",
                 label=f"ropesim (rk4, {r['dynamic']['dt'] * 1e3:.3g} ms)")
        top.set_title(f"{r['case'].name}: fairlead surging {r['case'].amplitude:g} m", fontsize=9)
        top.set_ylabel("fairlead tension [MN]")
        bottom.plot(t[1:], (rs[1:] - md[1:]) / 1e3, color="C3", lw=0.8, label="ropesim − MoorDyn")
        bottom.set_ylabel("difference [kN]")
        bottom.set_xlabel("t [s]")
        for ax in (top, bottom):
            ax.grid(True, alpha=0.3)
        if col == 0:
            top.legend(fontsize=7, loc="upper left")
            bottom.legend(fontsize=7, loc="upper left")
    if beam:
        t, md, rs = beam["series"]
        level = beam["case"].clamp[2]
        top, bottom = axes[0, -1], axes[1, -1]
        top.plot(t, (md - level) * 1e3, color="C0", lw=2.4, alpha=0.55, label="MoorDyn (RK2, 0.01 ms)")
        top.plot(t, (rs - level) * 1e3, color="C3", lw=0.9, ls="--", label=f"ropesim (rk4, {BEAM_DT * 1e3:g} ms)")
        top.axhline(-beam["tip_analytic"] * 1e3, color="k", lw=0.6, ls=":", label="Euler-Bernoulli static")
        top.set_title("BeamCantilevered: tip after a straight release", fontsize=9)
        top.set_ylabel("tip height [mm]")
        top.legend(fontsize=7, loc="lower right")
        bottom.plot(t[1:], (rs[1:] - md[1:]) * 1e3, color="C3", lw=0.8)
        bottom.set_ylabel("difference [mm]")
        bottom.set_xlabel("t [s]")
        for ax in (top, bottom):
            ax.grid(True, alpha=0.3)
    from ropesim.io.atomic import atomic_output

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ main


def main(argv: list[str] | None = None) -> int:
    names_all = [*CHAINS, BEAM]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(names_all), help="comma-separated: " + ", ".join(names_all))
    parser.add_argument("--figure", type=Path, default=FIGURE, help="PNG of the tensions over time")
    parser.add_argument("--regenerate", action="store_true",
                        help="rerun MoorDyn for tests/data/moordyn/own_cases.* (needs moordyn) before comparing")
    args = parser.parse_args(argv)
    names = [n.strip() for n in args.cases.split(",") if n.strip()]
    unknown = [n for n in names if n not in names_all]
    if unknown:
        parser.error(f"unknown case(s) {unknown}; choose from {names_all}")

    import ropesim

    started = time.perf_counter()
    if args.regenerate:
        print("MoorDyn runs:", flush=True)
        regenerate(names_all)
    arrays, record = stored()
    print(f"MoorDyn {record['moordyn_version']} (stored), ropesim {ropesim.__version__}:", flush=True)
    chains = [chain_results(n, arrays, record) for n in names if n != BEAM]
    beam = beam_results(arrays, record) if BEAM in names else None
    print("\n## Static\n")
    print(static_table(chains, beam))
    print("\n## Dynamic\n")
    print(dynamic_table(chains, beam))
    if chains:
        print("\n## Where the differences come from (fairlead tension RMS / range; MoorDyn converged: RK4 at "
              "dtM / 2)\n")
        print(explanation_table(chains))
        for r in chains:
            s = r["static"]
            print(f"\n({r['case'].name}: settled run {s['settled_status']}, its nodes still moving at up to "
                  f"{s['settled_speed'] * 1e3:.2g} mm/s; static solve within {s['positions'] * 1e3:.2g} mm of "
                  f"MoorDyn's tight IC; elastic catenary on a rigid frictionless bed {s['catenary'] / 1e3:.2f} kN; "
                  f"wall time of the dynamic run: ropesim {r['dynamic']['wall']:.2f} s, MoorDyn "
                  f"{r['dynamic']['md_wall']:.2f} s)")
    if beam:
        print(f"\n(BeamCantilevered: mode frequencies MoorDyn {np.round(beam['md_freq'], 4).tolist()} Hz, ropesim "
              f"{np.round(beam['rs_freq'], 4).tolist()} Hz, Euler-Bernoulli {np.round(beam['analytic_freq'], 4).tolist()}"
              f" Hz; wall time ropesim {beam['wall']:.2f} s, MoorDyn {beam['md_wall']:.2f} s)")
    draw(chains, beam, args.figure)
    print(f"\nwrote {args.figure}")
    print(f"total {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
