"""ropesim against MoorDyn on equal physics: the same line, drag, buoyancy, added mass and axial damping in both,
no seabed. Prints the agreement and the speed as Markdown tables and draws the top tension of both codes over time.

The cases (tests/references/moordyn_equal_physics.py has every number and the conventions):

- current: 30 m of 16 mm chain (30 segments, a 20 kg clump on its free bottom end) hanging from a fixed point
  5 m under the surface; a uniform 1.12 m/s current is on from t = 0; 150 s, to its steady state;
- towed: the same line with its top towed at 1 m/s through still water from t = 0; 150 s, to its steady state;
- catenary: 60 m of the chain (30 segments) between a fixed anchor 50 m down and a fairlead 30 m away and 45 m
  up, released from MoorDyn's initial catenary while the fairlead moves at (0.3, 0.2, 0) m/s, 20 s; and,
  separately, its static state (MoorDyn's IC, ropesim settled) against the exact static state of the discrete line.

Both codes start from the same state at rest (MoorDyn's tight IC state of the hanging line in still water; its
initial catenary, without the IC, for the catenary). MoorDyn runs its default RK2 at dtM = 0.2 ms, ropesim
velocity Verlet at dt = 0.2 ms; each code's own step error is measured by halving its step over the first 20 s,
and MoorDyn's RK4 at the same dtM shows how much of the difference is MoorDyn's RK2.

Speed: each case's first 20 s, both codes at the step above and at their largest stable steps, ropesim also with
rk4 and the implicit sdirk2; interleaved rounds (after an untimed one), medians. Timed: MoorDyn's time loop
(its ``Step`` calls; its IC excluded) and ropesim's time loop (compile excluded), over the same simulated time.

    pip install -e ".[test]"     # moordyn, moorpy, scipy
    python scripts/compare_moordyn.py [--cases current,towed,catenary] [--repeats 3] \\
        [--figure docs/images/moordyn_equal_physics.png] [--no-speed]

About 3 to 5 minutes on a shared 2-core machine (1.5 to 2 without the speed runs).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]   # this checkout's ropesim, not an installed one

from references.moordyn_equal_physics import (  # noqa: E402
    CASES,
    DEFAULT_IC,
    TIGHT_IC,
    Case,
    Series,
    compare,
    exact_static,
    ropesim_scene,
    run_moordyn,
    run_ropesim,
)
from references.moordyn_harness import moordyn_version  # noqa: E402

FIGURE = ROOT / "docs" / "images" / "moordyn_equal_physics.png"
CHECK_WINDOW = 20.0   # s: the step-halving checks and the speed runs cover the first 20 s of each case
SDIRK_DT = 5.0e-3     # s: ropesim's implicit sdirk2 in the speed table
#: MoorDyn's largest stable RK2 step (s) per case, measured over the first 20 s against its RK4: with l = 1 m
#: segments 0.4 ms agrees to 0.2 N RMS and 0.5 ms diverges (the axial damping's rate 4 BA / (l m) = 3900 1/s alone
#: limits RK2 to 2 / 3900 = 0.51 ms); with l = 2 m (the catenary) 0.6 ms agrees to 4 N and 0.8 ms diverges.
#: MoorDyn's own default step (CFL 0.5 of a segment's axial period, no damping counted) would be 1.5 ms and 3.0 ms.
MOORDYN_DT_MAX = {"current": 4.0e-4, "towed": 4.0e-4, "catenary": 6.0e-4}


def fmt(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def pct(x: float) -> str:
    return f"{100 * x:.2g} %" if abs(x) >= 1e-4 else f"{x:.1e}"


def window(case: Case, seconds: float) -> Case:
    return case.with_(t_end=min(case.t_end, seconds))


def settle_static(case: Case, start, t_end: float = 400.0):
    """ropesim's own static state of a line between two fixed points: sdirk2 (L-stable, so large steps damp
    every mode) from ``start`` for t_end seconds. Returns (top, bottom) segment tensions (N)."""
    traj = run_ropesim(case.with_(top_velocity=None), start, method="sdirk2", dt=0.05, t_end=t_end)
    tension = np.asarray(traj.tension)
    return float(tension[-1, -1]), float(tension[-1, 0])


# ------------------------------------------------------------------------------------------------ agreement


def agreement(case: Case) -> dict:
    """Run a case in both codes and measure their differences and each code's own step error."""
    print(f"  {case.name}: MoorDyn {case.scheme} dtM = {case.dtM * 1e3:g} ms, {case.t_end:g} s ...", flush=True)
    md = run_moordyn(case)
    start = md.positions[0]
    print(f"  {case.name}: ropesim {case.method} dt = {case.dt * 1e3:g} ms ...", flush=True)
    rs = run_ropesim(case, start)
    a, b = Series.of_moordyn(md), Series.of_ropesim(rs)
    out = {"case": case, "start": start, "md": a, "rs": b, "main": compare(case, a, b)}

    short = window(case, CHECK_WINDOW)
    frames = int(round(short.t_end / case.dt_out)) + 1
    cut = Series(a.t[:frames], a.x[:frames], a.top[:frames], a.bottom[:frames], a.wall)
    cut_rs = Series(b.t[:frames], b.x[:frames], b.top[:frames], b.bottom[:frames], b.wall)
    print(f"  {case.name}: step checks over {short.t_end:g} s ...", flush=True)
    md_half = run_moordyn(short, dtM=case.dtM / 2)
    md_rk4 = run_moordyn(short, scheme="RK4")
    rs_half = run_ropesim(short, start, dt=case.dt / 2)
    out["md_ic_spread"] = float(max(np.abs(md_half.positions[0] - start).max(),
                                    np.abs(md_rk4.positions[0] - start).max()))
    out["md_step"] = compare(short, cut, Series.of_moordyn(md_half))
    out["rs_step"] = compare(short, cut_rs, Series.of_ropesim(rs_half))
    rk4 = Series.of_moordyn(md_rk4)
    out["rk4_vs_rs"] = compare(short, rk4, cut_rs)
    out["rk2_vs_rk4"] = compare(short, rk4, cut)
    out["rk4"] = rk4

    if case.clump is None and case.top_velocity is not None:   # a line between two points: its static state
        exact = exact_static(case)
        settled = settle_static(case, np.linspace(case.bottom_start(), case.top, case.segments + 1))
        default = run_moordyn(case.with_(ic=True, ic_options=DEFAULT_IC), t_end=0.0)
        tight = run_moordyn(case.with_(ic=True, ic_options=TIGHT_IC), t_end=0.0)
        out["static"] = {"exact": exact, "moordyn": (float(tight.fairlead_tension[0]), float(tight.anchor_tension[0])),
                         "moordyn_default": (float(default.fairlead_tension[0]), float(default.anchor_tension[0])),
                         "ropesim": settled}
    return out


def agreement_table(results: list[dict]) -> str:
    rows = ["| case | quantity | MoorDyn | ropesim | ropesim − MoorDyn | MoorDyn's own step error |",
            "| --- | --- | --- | --- | --- | --- |"]
    for r in results:
        case, m, s = r["case"], r["main"], r["md_step"]
        name = f"{case.name}: {case.title}"
        if "static" in r:
            st = r["static"]
            for k, label in ((0, "static top tension"), (1, "static bottom tension")):
                md_v, rs_v, ex = st["moordyn"][k], st["ropesim"][k], st["exact"][k]
                rows.append(f"| {name} | {label} (exact: {ex:.2f} N) | {md_v:.2f} N | {rs_v:.2f} N | "
                            f"{pct((rs_v - md_v) / md_v)} | IC: {pct((md_v - ex) / ex)} from exact "
                            f"({pct((st['moordyn_default'][k] - ex) / ex)} with MoorDyn's default IC) |")
        if case.steady > 0:
            for key, label in (("top", "steady top tension"), ("bottom", "steady bottom tension")):
                rows.append(f"| {name} | {label} (last {case.steady:g} s) | {m[f'steady_{key}_a']:.2f} N | "
                            f"{m[f'steady_{key}_b']:.2f} N | {pct(m[f'steady_{key}_rel'])} | |")
        rows.append(f"| {name} | top tension over 0–{case.t_end:g} s, RMS (max) | range "
                    f"{m['top_range']:.1f} N | | {fmt(m['top_rms'], 2)} N ({fmt(m['top_max'], 2)} N) = "
                    f"{pct(m['top_rms_rel'])} of the range | {fmt(s['top_rms'], 2)} N over 0–{CHECK_WINDOW:g} s |")
        rows.append(f"| {name} | bottom tension over 0–{case.t_end:g} s, RMS (max) | range "
                    f"{m['bottom_range']:.1f} N | | {fmt(m['bottom_rms'], 2)} N ({fmt(m['bottom_max'], 2)} N) = "
                    f"{pct(m['bottom_rms'] / m['bottom_range'])} of the range | {fmt(s['bottom_rms'], 2)} N |")
        rows.append(f"| {name} | node positions, RMS (max) | | | {m['pos_rms']:.1e} m ({m['pos_max']:.1e} m) | "
                    f"{s['pos_rms']:.1e} m |")
    return "\n".join(rows)


def explanation_table(results: list[dict]) -> str:
    rows = [f"| case (first {CHECK_WINDOW:g} s) | top tension RMS: ropesim − MoorDyn RK2 | MoorDyn RK2 − RK4 "
            "| ropesim − MoorDyn RK4 | ropesim's own step error | positions: ropesim − MoorDyn RK4 |",
            "| --- | --- | --- | --- | --- | --- |"]
    for r in results:
        rk2_rk4, rs_rk4, rs_step = r["rk2_vs_rk4"], r["rk4_vs_rs"], r["rs_step"]
        rs_rk2 = compare(window(r["case"], CHECK_WINDOW), _cut(r["md"], r["case"]), _cut(r["rs"], r["case"]))
        rows.append(f"| {r['case'].name} | {fmt(rs_rk2['top_rms'], 2)} N | {fmt(rk2_rk4['top_rms'], 2)} N | "
                    f"{fmt(rs_rk4['top_rms'], 2)} N | {fmt(rs_step['top_rms'], 2)} N | {rs_rk4['pos_rms']:.1e} m |")
    return "\n".join(rows)


def _cut(series: Series, case: Case) -> Series:
    frames = int(round(min(case.t_end, CHECK_WINDOW) / case.dt_out)) + 1
    return Series(series.t[:frames], series.x[:frames], series.top[:frames], series.bottom[:frames], series.wall)


# ------------------------------------------------------------------------------------------------ speed


def ropesim_bound(case: Case, start, method: str) -> float:
    from ropesim.analysis.stability import predicted_dt
    from ropesim.model.build import build

    return predicted_dt(build(ropesim_scene(case, start, method=method, dt=case.dt)), method)


def fitting_step(dt_out: float, dt_max: float) -> float:
    """The largest step below dt_max that divides dt_out."""
    return dt_out / math.ceil(dt_out / dt_max - 1e-9)


def speed(case: Case, start, reference: Series, repeats: int) -> list[dict]:
    """Interleaved timing of each configuration over the case's first CHECK_WINDOW seconds."""
    short = window(case, CHECK_WINDOW)
    rk4_dt = fitting_step(case.dt_out, 0.9 * ropesim_bound(case, start, "rk4"))
    verlet_max = fitting_step(case.dt_out, 0.9 * ropesim_bound(case, start, "verlet"))
    configs = [
        ("MoorDyn", f"RK2, dtM = {case.dtM * 1e3:g} ms", lambda: Series.of_moordyn(run_moordyn(short))),
        ("MoorDyn", f"RK2, dtM = {MOORDYN_DT_MAX[case.name] * 1e3:g} ms (largest stable)",
         lambda: Series.of_moordyn(run_moordyn(short, dtM=MOORDYN_DT_MAX[case.name]))),
        ("ropesim", f"verlet, dt = {case.dt * 1e3:g} ms", lambda: Series.of_ropesim(run_ropesim(short, start))),
        ("ropesim", f"verlet, dt = {verlet_max * 1e3:.3g} ms (0.9 x bound)",
         lambda: Series.of_ropesim(run_ropesim(short, start, dt=verlet_max))),
        ("ropesim", f"rk4, dt = {rk4_dt * 1e3:.3g} ms (0.9 x bound)",
         lambda: Series.of_ropesim(run_ropesim(short, start, method="rk4", dt=rk4_dt))),
        ("ropesim", f"sdirk2, dt = {SDIRK_DT * 1e3:g} ms",
         lambda: Series.of_ropesim(run_ropesim(short, start, method="sdirk2", dt=SDIRK_DT))),
    ]
    walls: list[list[float]] = [[] for _ in configs]
    last: list[Series | None] = [None] * len(configs)
    for rnd in range(repeats + 1):
        for i, (_, _, fn) in enumerate(configs):
            series = fn()
            last[i] = series
            if rnd:
                walls[i].append(series.wall)
    out = []
    for (code, label, _), w, series in zip(configs, walls, last):
        out.append({"code": code, "label": label, "wall": statistics.median(w), "walls": w,
                    "per_second": statistics.median(w) / short.t_end,
                    "vs_reference": compare(short, reference, series)})
    return out


def speed_table(rows_by_case: dict[str, list[dict]], nodes: dict[str, int]) -> str:
    lines = ["| case | code | integrator and step | wall time per simulated second | MoorDyn (largest stable step) / "
             "this | top tension RMS from the reference |", "| --- | --- | --- | --- | --- | --- |"]
    for name, rows in rows_by_case.items():
        md_fast = rows[1]["wall"]
        for r in rows:
            rel = r["vs_reference"]["top_rms_rel"]
            lines.append(f"| {name} ({nodes[name]} nodes) | {r['code']} | {r['label']} | "
                         f"{r['per_second'] * 1e3:.1f} ms | {md_fast / r['wall']:.2f} | "
                         f"{fmt(r['vs_reference']['top_rms'], 2)} N ({pct(rel)} of the range) |")
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------------ figure


def draw(results: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(results), figsize=(4.2 * len(results), 5.6), layout="constrained",
                             sharex="col", squeeze=False, height_ratios=(2, 1))
    for col, r in enumerate(results):
        case, a, b, rk4 = r["case"], r["md"], r["rs"], r["rk4"]
        top, bottom = axes[0, col], axes[1, col]
        first = 0 if case.ic else 1   # without MoorDyn's IC, it reports no tension at t = 0 (nothing computed yet)
        top.plot(a.t[first:], a.top[first:] / 1e3, color="C0", lw=2.4, alpha=0.55,
                 label=f"MoorDyn ({case.scheme}, {case.dtM * 1e3:g} ms)")
        top.plot(b.t, b.top / 1e3, color="C3", lw=0.9, ls="--", label=f"ropesim ({case.method}, {case.dt * 1e3:g} ms)")
        top.set_title(f"{case.name}: {case.title}", fontsize=9)
        top.set_ylabel("top tension [kN]")
        top.grid(True, alpha=0.3)
        n = len(rk4.t)
        bottom.plot(a.t[1:], b.top[1:] - a.top[1:], color="C3", lw=0.8, label="ropesim − MoorDyn RK2")
        bottom.plot(rk4.t[1:], a.top[1:n] - rk4.top[1:], color="C0", lw=0.8, ls=":",
                    label=f"MoorDyn RK2 − RK4 (first {CHECK_WINDOW:g} s)")
        bottom.set_ylabel("difference [N]")
        bottom.set_xlabel("t [s]")
        bottom.grid(True, alpha=0.3)
        if col == 0:
            top.legend(fontsize=7, loc="lower right")
            bottom.legend(fontsize=7, loc="upper right")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, format="png", dpi=110)
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ main


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated: " + ", ".join(CASES))
    parser.add_argument("--repeats", type=int, default=3, help="timed rounds of the speed runs")
    parser.add_argument("--figure", type=Path, default=FIGURE, help="PNG of the top tension over time")
    parser.add_argument("--no-speed", action="store_true", help="skip the timed runs")
    args = parser.parse_args(argv)
    names = [n.strip() for n in args.cases.split(",") if n.strip()]
    unknown = [n for n in names if n not in CASES]
    if unknown:
        parser.error(f"unknown case(s) {unknown}; choose from {list(CASES)}")

    import ropesim

    started = time.perf_counter()
    print(f"MoorDyn {moordyn_version()}, ropesim {ropesim.__version__}; agreement runs:", flush=True)
    results = [agreement(CASES[n]) for n in names]
    print("\n## Agreement\n")
    print(agreement_table(results))
    print("\n## Where the differences come from\n")
    print(explanation_table(results))
    for r in results:
        print(f"\n({r['case'].name}: MoorDyn's IC state moved by {r['md_ic_spread']:.1e} m between its step and "
              f"scheme variants)")
    draw(results, args.figure)
    print(f"\nwrote {args.figure}")

    if not args.no_speed:
        print(f"\nspeed runs: first {CHECK_WINDOW:g} s of each case, {args.repeats} timed rounds ...", flush=True)
        speeds, nodes = {}, {}
        for r in results:
            speeds[r["case"].name] = speed(r["case"], r["start"], r["rk4"], args.repeats)
            nodes[r["case"].name] = r["case"].segments + 1
        print(f"\n## Speed (reference: MoorDyn RK4 at dtM = 0.2 ms; medians of {args.repeats} rounds)\n")
        print(speed_table(speeds, nodes))
        try:
            load = os.getloadavg()[0]
            print(f"\nload average {load:.2f} on {os.cpu_count()} cores")
        except OSError:
            pass
    print(f"\ntotal {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
