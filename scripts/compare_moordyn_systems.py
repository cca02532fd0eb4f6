"""ropesim against MoorDyn on MoorDyn's own system cases: OC3-Hywind's three chains on a surging vessel
(``lines.txt``), a free rigid body turned by a line (``body_tests/rotatingBody.txt``) and a mass dropped onto its
slack line (``lifting.txt``); and a free body in water, the speed benchmark's spar on lines.txt's chains
(``spar_free.txt``, ours). Prints the agreement as Markdown tables and draws docs/images/moordyn_systems.png.

tests/references/moordyn_systems.py builds each case for ropesim from MoorDyn's own input file and sets out the
conventions (the frame, MoorDyn's Euler angles, the coupled points' velocity jumps, what MoorDyn's body leaves
out). Compared:

- static: ropesim's static solve (``initial.shape = "equilibrium"``) against MoorDyn's initial-condition (IC) state
  as its file sets it up, without its saved ``.ic`` state, and run tight; lifting's against its closed form;
- dynamic: MoorDyn's stored run (its file's scheme and dtM) against ropesim's rk4 at the same step from the same
  state, the coupled points along the same path: each line's fairlead tension (MoorDyn's ``GetLineFairTen``,
  from the state at the frame), the anchor tensions, the body's pose, the free point's position;
- where the differences come from: both against MoorDyn run with RK4 at half its step (stored), ropesim's step
  halved, and for lifting MoorDyn against itself started 1 nm off (the snapping line is chaotic).

    pip install -e ".[test]"     # moordyn, scipy
    python scripts/compare_moordyn_systems.py [--cases lines,rotatingBody,lifting,spar] [--figure PATH]
    python scripts/compare_moordyn_systems.py --regenerate      # rerun MoorDyn for tests/data/moordyn/own_systems.*
                                                  # (--cases: only those cases' runs; the others' are kept)

About 3 minutes on a shared 2-core machine (most of it compiling); --regenerate adds about a minute.
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

from references.moordyn_systems import (
    EULER_CHECK,
    LIFTING_RUN,
    LINES_SURGE,
    SPAR_RUN,
    STORED,
    SYSTEMS,
    body_rotations_moordyn,
    differences,
    drive_of,
    from_ropesim,
    gyroscopic_share,
    lifting_closed_form,
    load_stored,
    moordyn_centripetal_excess,
    moordyn_euler_check,
    moordyn_ic,
    read_system,
    ropesim_anchor_state,
    ropesim_fairlead_tensions,
    rotation_angle_between,
    run_moordyn_system,
    run_system,
    run_system_from,
    spar_changes,
    start_positions,
    static_positions,
    static_tensions,
    to_ropesim,
)

FIGURE = ROOT / "docs" / "images" / "moordyn_systems.png"
TIGHT_IC = {"threshIC": 1e-8, "TmaxIC": 4000}
POSITIONS_EVERY = {"lines": 50, "lifting": 30, "spar": 50}   # every node stored every this many frames (5, 0.3, 5 s)
PERTURBATION = 1e-9      # m: lifting's start moved this far (one node, along the line) for MoorDyn against itself


def rel(x: float) -> str:
    return f"{x:.2e}"


def pct(x: float) -> str:
    return f"{100 * x:+.4f} %"


# ------------------------------------------------------------------------------------------------ MoorDyn data


def regenerate(names) -> None:
    """Run MoorDyn for the stored arrays of the cases ``names`` (the others' are kept): the IC states of lines.txt
    and lifting.txt, and each case's dynamic run with the file's scheme and step and with RK4 at half the step,
    from the start ropesim's scene gives."""
    from references.moordyn_harness import moordyn_version

    arrays, record = load_stored() if Path(f"{STORED}.json").exists() else ({}, {"cases": {}})
    for name in names:
        for key in [k for k in arrays if k.startswith(name + "_")]:
            del arrays[key]
    record |= {"moordyn_version": moordyn_version(), "made_by": "scripts/compare_moordyn_systems.py --regenerate",
               "tight_ic_options": TIGHT_IC, "euler_check": {**EULER_CHECK,
                                                             "moordyn_position_m": moordyn_euler_check()}}
    for name in names:
        print(f"  {name} ...", flush=True)
        record["cases"][name] = REGENERATE[name](arrays)
    record["fields"] = FIELDS
    np.savez_compressed(f"{STORED}.npz", **arrays)
    Path(f"{STORED}.json").write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {STORED}.npz, {STORED}.json")


def regenerate_lines(arrays: dict) -> dict:
    s = read_system("lines")
    # lines: its IC as filed, without its saved .ic state, and tight; then the surge from ropesim's static state
    print("  lines: MoorDyn's IC (as filed, by dynamic relaxation, without its .ic, tight) ...", flush=True)
    ics = {"filed": moordyn_ic("lines"), "relaxation": moordyn_ic("lines", {"ICgenDynamic": 1}),
           "no_ic_file": moordyn_ic("lines", ic_file=False), "tight": moordyn_ic("lines", TIGHT_IC)}
    start = static_positions("lines")
    drive = drive_of("lines")
    print("  lines: the surge (RK2 at dtM, RK4 at dtM / 2) ...", flush=True)
    rk2 = run_moordyn_system("lines", drive, drive.t_end, drive.dt_out, start=start)
    rk4 = run_moordyn_system("lines", drive, drive.t_end, drive.dt_out, start=start,
                             options={"tScheme": "RK4", "dtM": s.file.dtM / 2})
    arrays["lines_start"] = start
    for k, ic in ics.items():
        arrays[f"lines_ic_{k}_positions"] = ic["positions"]
    _store_run(arrays, "lines", rk2, rk4, every_positions=POSITIONS_EVERY["lines"])
    return {"ic": {k: {"fairlead_tension_N": ic["fairlead"].tolist(), "anchor_tension_N": ic["anchor"].tolist(),
                       "init_wall_s": ic["init_wall"]} for k, ic in ics.items()},
            "dynamic": _run_record(rk2, rk4, drive), "surge": LINES_SURGE}


def regenerate_rotating(arrays: dict) -> dict:
    """rotatingBody: MoorDyn's own drive from the file's layout."""
    s = read_system("rotatingBody")
    drive = drive_of("rotatingBody")
    rk2 = run_moordyn_system("rotatingBody", drive, drive.t_end, drive.dt_out)
    rk4 = run_moordyn_system("rotatingBody", drive, drive.t_end, drive.dt_out,
                             options={"tScheme": "RK4", "dtM": s.file.dtM / 2})
    _store_run(arrays, "rotatingBody", rk2, rk4)
    return {"dynamic": _run_record(rk2, rk4, drive)}


def regenerate_lifting(arrays: dict) -> dict:
    """lifting: its IC as filed and run long (it stalls); the drop from ropesim's start, and 1 nm off it."""
    s = read_system("lifting")
    ics = {"filed": moordyn_ic("lifting"), "long": moordyn_ic("lifting", {"TmaxIC": 1000, "threshIC": 1e-7,
                                                                          "dtIC": 10.0})}
    start = start_positions("lifting")
    t_end, dt_out = LIFTING_RUN["t_end"], LIFTING_RUN["dt_out"]
    rk4 = run_moordyn_system("lifting", None, t_end, dt_out, start=start)
    nudged = start.copy()
    nudged[10, 2] += PERTURBATION
    off = run_moordyn_system("lifting", None, t_end, dt_out, start=nudged)
    half = run_moordyn_system("lifting", None, t_end, dt_out, start=start, options={"dtM": s.file.dtM / 2})
    arrays["lifting_start"] = start
    for k, ic in ics.items():
        arrays[f"lifting_ic_{k}_positions"] = ic["positions"]
    _store_run(arrays, "lifting", rk4, half, every_positions=POSITIONS_EVERY["lifting"])
    arrays["lifting_perturbed_points"] = off.points
    arrays["lifting_perturbed_fairlead"] = off.fairlead_state
    return {
        "ic": {k: {"fairlead_tension_N": ic["fairlead"].tolist(), "point_m": ic["points"].tolist(),
                   "init_wall_s": ic["init_wall"]} for k, ic in ics.items()},
        "ic_long_options": {"TmaxIC": 1000, "threshIC": 1e-7, "dtIC": 10.0},
        "dynamic": _run_record(rk4, half, None), "perturbation_m": PERTURBATION,
        "perturbed_node": 10}


def regenerate_spar(arrays: dict) -> dict:
    """spar (the speed benchmark's case): released from the lines' static shape, RK4 at dtM and at dtM / 2, and
    RK4 at dtM with the body's Ca = SPAR_RUN["ca"] (MoorDyn's added mass in its centripetal force)."""
    s = read_system("spar")
    start = static_positions("lines")
    t_end, dt_out = SPAR_RUN["t_end"], SPAR_RUN["dt_out"]
    rk4 = run_moordyn_system("spar", None, t_end, dt_out, start=start, options={"tScheme": "RK4"})
    half = run_moordyn_system("spar", None, t_end, dt_out, start=start,
                              options={"tScheme": "RK4", "dtM": s.file.dtM / 2})
    added = run_moordyn_system("spar", None, t_end, dt_out, start=start, options={"tScheme": "RK4"},
                               body_ca=SPAR_RUN["ca"])
    _store_run(arrays, "spar", rk4, half, every_positions=POSITIONS_EVERY["spar"])
    arrays["spar_added_mass_body_r6"] = added.body_r6
    arrays["spar_added_mass_fairlead"] = added.fairlead_state
    return {"dynamic": _run_record(rk4, half, None), "run": SPAR_RUN}


REGENERATE = {"lines": regenerate_lines, "rotatingBody": regenerate_rotating, "lifting": regenerate_lifting,
              "spar": regenerate_spar}

FIELDS = {
    "<case>_t": "s, (F,): the frames, every coupling instant",
    "<case>_fairlead": "N, (F, L): each line's end-B segment |T + Td| from MoorDyn's state at the frame, a coupled "
                       "end at the secant velocity of the interval ending there (the file's scheme and dtM)",
    "<case>_fairlead_reported": "N, (F, L): GetLineFairTen of the same run (its last force evaluation)",
    "<case>_anchor": "N, (F, L): each line's end-A segment |T + Td| from the state",
    "<case>_points": "m, (F, P, 3): every point's position (MoorDyn frame), where a point is free",
    "<case>_body_r6": "m, rad, (F, B, 6): each body's position and angles (R = Rx Ry Rz)",
    "<case>_body_v6": "m/s, rad/s, (F, B, 6): its velocity and angular velocity",
    "<case>_positions": "m, (F', nodes, 3): every node, line after line, every POSITIONS_EVERY-th frame",
    "<case>_converged_*": "the same from MoorDyn's RK4 at half the file's step (lifting: the file's RK4 at half "
                          "its step)",
    "lines_start, lifting_start": "m, (nodes, 3): the state both codes start from (ropesim's static shape for "
                                  "lines, its straight start for lifting), MoorDyn frame",
    "<case>_ic_<kind>_positions": "m, (nodes, 3): MoorDyn's IC state",
    "lifting_perturbed_*": "MoorDyn's lifting run started with node 10 moved 1 nm down",
    "spar_added_mass_*": "MoorDyn's spar run with the body's Ca set to 1 (its file's is 0)",
}


def _store_run(arrays: dict, name: str, run, converged, every_positions: int = 1) -> None:
    arrays[f"{name}_t"] = run.t
    for key, value in (("fairlead", run.fairlead_state), ("fairlead_reported", run.fairlead),
                       ("anchor", run.anchor_state)):
        arrays[f"{name}_{key}"] = value
    if run.body_r6.shape[1]:
        arrays[f"{name}_body_r6"], arrays[f"{name}_body_v6"] = run.body_r6, run.body_v6
        arrays[f"{name}_converged_body_r6"] = converged.body_r6
    if any(p.kind == "free" for p in read_system(name).points):
        arrays[f"{name}_points"], arrays[f"{name}_converged_points"] = run.points, converged.points
    arrays[f"{name}_positions"] = run.positions[::every_positions]
    arrays[f"{name}_converged_fairlead"] = converged.fairlead_state
    arrays[f"{name}_converged_anchor"] = converged.anchor_state


def _run_record(run, converged, drive) -> dict:
    return {"scheme": run.scheme, "dtM_s": run.dtM, "wall_time_s": run.wall,
            "converged": {"scheme": converged.scheme, "dtM_s": converged.dtM},
            "t_end_s": float(run.t[-1]), "dt_out_s": float(run.t[1] - run.t[0])}


# ------------------------------------------------------------------------------------------------ the cases


def lines_results(arrays: dict, record: dict) -> dict:
    s = read_system("lines")
    rec = record["cases"]["lines"]
    print("  lines: static solve ...", flush=True)
    x = static_positions("lines")
    fair, anchor = static_tensions("lines", x)
    static = {"ropesim": (fair, anchor), "start_moved": float(np.abs(x - arrays["lines_start"]).max()),
              "positions_tight": float(np.abs(x - arrays["lines_ic_tight_positions"]).max())}
    for k, ic in rec["ic"].items():
        static[k] = (np.array(ic["fairlead_tension_N"]), np.array(ic["anchor_tension_N"]))
    drive = drive_of("lines")
    dt = s.file.dtM
    print(f"  lines: dynamic runs (rk4 at {dt * 1e3:g} ms and {dt * 500:g} ms) ...", flush=True)
    runs = {}
    for k in (1, 2):
        traj = run_system("lines", drive, start="equilibrium", dt=dt / k)
        runs[k] = (ropesim_fairlead_tensions("lines", traj, drive), ropesim_anchor_state("lines", traj),
                   float(traj.summary["wall_time_s"]), traj)
    fair_rs, anch_rs, wall, traj = runs[1]
    md_f, md_a, conv_f = arrays["lines_fairlead"], arrays["lines_anchor"], arrays["lines_converged_fairlead"]
    pos = from_ropesim(np.asarray(traj.x))[::POSITIONS_EVERY["lines"]]
    dyn = {"dt": dt, "wall": wall, "md_wall": rec["dynamic"]["wall_time_s"],
           "fair": [differences(md_f[:, i], fair_rs[:, i]) for i in range(3)],
           "anchor": [differences(md_a[:, i], anch_rs[:, i]) for i in range(3)],
           "ladder": {k: [differences(conv_f[:, i], f[:, i]) for i in range(3)] for k, (f, *_) in runs.items()},
           "md_rk2": [differences(conv_f[:, i], md_f[:, i]) for i in range(3)],
           "md_reported": [differences(md_f[:, i], arrays["lines_fairlead_reported"][:, i]) for i in range(3)],
           "positions": float(np.abs(pos - arrays["lines_positions"]).max()),
           "positions_every_s": POSITIONS_EVERY["lines"] * drive.dt_out,
           "series": (arrays["lines_t"], md_f[:, :2], fair_rs[:, :2])}
    return {"static": static, "dynamic": dyn}


def rotating_results(arrays: dict, record: dict) -> dict:
    from ropesim.model.rotation import rotation_matrix

    s = read_system("rotatingBody")
    rec = record["cases"]["rotatingBody"]
    drive = drive_of("rotatingBody")
    dt = s.file.dtM
    print(f"  rotatingBody: rk4 at {dt * 1e3:g} and {dt * 500:g} ms, verlet at {dt * 1e3:g} ms ...", flush=True)
    runs = {}
    for method, k in (("rk4", 1), ("rk4", 2), ("verlet", 1)):
        traj = run_system("rotatingBody", drive, method=method, dt=dt / k)
        runs[(method, k)] = traj
    md_r = body_rotations_moordyn(arrays["rotatingBody_body_r6"][:, 0])
    conv_r = body_rotations_moordyn(arrays["rotatingBody_converged_body_r6"][:, 0])
    md_f, conv_f = arrays["rotatingBody_fairlead"], arrays["rotatingBody_converged_fairlead"]
    out = {"dt": dt, "md_wall": rec["dynamic"]["wall_time_s"], "turned": rotation_angle_between(md_r[0], md_r)}
    for key, traj in runs.items():
        f = ropesim_fairlead_tensions("rotatingBody", traj, drive)
        r = rotation_matrix(np.asarray(traj.body_q)[:, 0])
        out[key] = {"line7": differences(md_f[:, 6], f[:, 6]), "line7_conv": differences(conv_f[:, 6], f[:, 6]),
                    "springs": max(differences(md_f[:, i], f[:, i])["rms_of_range"] for i in range(6)),
                    "angle": rotation_angle_between(md_r, r), "angle_conv": rotation_angle_between(conv_r, r),
                    "position": float(np.abs(to_ropesim(arrays["rotatingBody_body_r6"][:, 0, :3])
                                             - np.asarray(traj.body_x)[:, 0]).max()),
                    "wall": float(traj.summary["wall_time_s"]), "tension": f[:, 6]}
    out["md_rk2_line7"] = differences(conv_f[:, 6], md_f[:, 6])
    out["md_rk2_angle"] = rotation_angle_between(conv_r, md_r)
    out["gyroscopic"] = gyroscopic_share("rotatingBody", runs[("rk4", 1)])
    out["translation"] = np.ptp(arrays["rotatingBody_body_r6"][:, 0, :3], axis=0)
    out["series"] = (arrays["rotatingBody_t"], md_f[:, 6])
    return out


def lifting_results(arrays: dict, record: dict) -> dict:
    s = read_system("lifting")
    rec = record["cases"]["lifting"]
    print("  lifting: static solve, the drop (rk4 at the file's step and half) ...", flush=True)
    x = static_positions("lifting")
    exact = lifting_closed_form()
    static = {"ropesim_point": float(x[-1, 2]), "ropesim_tension": static_tensions("lifting", x)[0][0],
              "exact": exact, "md": rec["ic"]}
    dt = s.file.dtM
    t_end = LIFTING_RUN["t_end"]
    runs = {k: run_system("lifting", None, dt=dt / k, t_end=t_end, interval=LIFTING_RUN["dt_out"]) for k in (1, 2)}
    md_z, off_z = arrays["lifting_points"][:, 1, 2], arrays["lifting_perturbed_points"][:, 1, 2]
    md_f, off_f = arrays["lifting_fairlead"][:, 0], arrays["lifting_perturbed_fairlead"][:, 0]
    t = arrays["lifting_t"]
    out = {"static": static, "dt": dt, "t": t, "md_wall": rec["dynamic"]["wall_time_s"]}
    for k, traj in runs.items():
        z = from_ropesim(np.asarray(traj.x))[:, -1, 2]
        f = ropesim_fairlead_tensions("lifting", traj, None)[:, 0]
        out[k] = {"dz": np.abs(z - md_z), "df": np.abs(f - md_f), "z": z, "f": f,
                  "wall": float(traj.summary["wall_time_s"])}
    out["md_self_dz"], out["md_self_df"] = np.abs(off_z - md_z), np.abs(off_f - md_f)
    out["md_half_dz"] = np.abs(arrays["lifting_converged_points"][:, 1, 2] - md_z)
    out["md_z"], out["md_f"] = md_z, md_f
    return out


def spar_signals(traj) -> np.ndarray:
    """ropesim's spar run as (F, 6): the three fairlead tensions (N), the body's heave and surge (m), its pitch
    (rad, about MoorDyn's y), MoorDyn's axes."""
    from ropesim.model.rotation import rotation_matrix

    fair = ropesim_fairlead_tensions("spar", traj, None)
    x = from_ropesim(np.asarray(traj.body_x)[:, 0])
    r = rotation_matrix(np.asarray(traj.body_q)[:, 0])
    return np.column_stack([fair, x[:, 2], x[:, 0], np.arctan2(r[:, 0, 1], r[:, 0, 0])])


def spar_moordyn_signals(fairlead, r6) -> np.ndarray:
    return np.column_stack([fairlead, r6[:, 0, 2], r6[:, 0, 0], r6[:, 0, 4]])


SPAR_SIGNALS = ("line 1 fairlead tension", "line 2 fairlead tension", "line 3 fairlead tension", "body heave",
                "body surge", "body pitch")


def spar_results(arrays: dict, record: dict) -> dict:
    s = read_system("spar")
    dt = s.file.dtM
    start = static_positions("lines")
    kw = {"t_end": SPAR_RUN["t_end"], "interval": SPAR_RUN["dt_out"]}
    print(f"  spar: rk4 at {dt * 1e3:g} and {dt * 500:g} ms, and with the body's Ca = {SPAR_RUN['ca']:g} ...",
          flush=True)
    runs = {k: run_system_from("spar", start, dt=dt / k, **kw) for k in (1, 2)}
    added = run_system_from("spar", start, dt=dt, changes=spar_changes(SPAR_RUN["ca"]), **kw)
    md = spar_moordyn_signals(arrays["spar_fairlead"], arrays["spar_body_r6"])
    conv = spar_moordyn_signals(arrays["spar_converged_fairlead"], arrays["spar_converged_body_r6"])
    md_added = spar_moordyn_signals(arrays["spar_added_mass_fairlead"], arrays["spar_added_mass_body_r6"])
    rs = {k: spar_signals(traj) for k, traj in runs.items()}
    rs_added = spar_signals(added)
    t = np.asarray(runs[1].t)
    return {"dt": dt, "t": t, "md": md, "rs": rs[1], "md_added": md_added, "rs_added": rs_added,
            "rows": [differences(md[:, k], rs[1][:, k]) for k in range(6)],
            "half": [differences(conv[:, k], rs[2][:, k]) for k in range(6)],
            "md_step": [differences(conv[:, k], md[:, k]) for k in range(6)],
            "added_rows": [differences(md_added[:, k], rs_added[:, k]) for k in range(6)],
            "excess": moordyn_centripetal_excess(added, SPAR_RUN["ca"]),
            "wall": float(runs[1].summary["wall_time_s"]), "md_wall": record["cases"]["spar"]["dynamic"]["wall_time_s"]}


def first_time_above(t, err, level) -> float:
    """The first time (s) at which err exceeds level (inf if never)."""
    hit = np.flatnonzero(np.asarray(err) > level)
    return float(t[hit[0]]) if hit.size else float("inf")


# ------------------------------------------------------------------------------------------------ tables


def static_table(lines: dict | None, lifting: dict | None) -> str:
    rows = [("| case | quantity | MoorDyn IC as filed | the same by dynamic relaxation | MoorDyn IC without its .ic | "
             "MoorDyn IC run tight | ropesim static solve | solve − tight IC | solve − IC as filed |"),
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    if lines:
        st = lines["static"]
        for k, label in ((0, "fairlead tension"), (1, "anchor tension")):
            for i in (0, 1):
                rs = st["ropesim"][k][i]
                rows.append(f"| lines, line {i + 1} | {label} | {st['filed'][k][i] / 1e3:.3f} kN | "
                            f"{st['relaxation'][k][i] / 1e3:.3f} kN | {st['no_ic_file'][k][i] / 1e3:.3f} kN | {st['tight'][k][i] / 1e3:.3f} kN | "
                            f"{rs / 1e3:.3f} kN | {rel(rs / st['tight'][k][i] - 1)} | "
                            f"{pct(rs / st['filed'][k][i] - 1)} |")
    if lifting:
        st = lifting["static"]
        ex = st["exact"]
        md = st["md"]
        rows.append(f"| lifting | mass height (closed form {ex['point_z']:.6f} m) | "
                    f"{md['filed']['point_m'][1][2]:.6f} m (stalled) | | | {md['long']['point_m'][1][2]:.6f} m "
                    f"(1000 s, stalled) | {st['ropesim_point']:.6f} m | | |")
        rows.append(f"| lifting | tension next to the mass (closed form {ex['tension_b']:.5f} N) | "
                    f"{md['filed']['fairlead_tension_N'][0]:.5f} N | | | {md['long']['fairlead_tension_N'][0]:.5f} N | "
                    f"{st['ropesim_tension']:.5f} N | | |")
    return "\n".join(rows)


def dynamic_table(lines: dict | None, rotating: dict | None, lifting: dict | None) -> str:
    rows = [("| case | signal | range | ropesim − MoorDyn: RMS (max) | RMS / range | MoorDyn's own step error "
             "(RK2 − converged), RMS / range |"), "| --- | --- | --- | --- | --- | --- |"]
    if lines:
        d = lines["dynamic"]
        for i in range(3):
            x = d["fair"][i]
            rows.append(f"| lines | line {i + 1} fairlead tension | {x['range'] / 1e3:.1f} kN | {x['rms']:.2f} N "
                        f"({x['max']:.2f} N) | {rel(x['rms_of_range'])} | {rel(d['md_rk2'][i]['rms_of_range'])} |")
        x = d["anchor"][0]
        rows.append(f"| lines | line 1 anchor tension | {x['range'] / 1e3:.1f} kN | {x['rms']:.2f} N ({x['max']:.2f} N)"
                    f" | {rel(x['rms_of_range'])} | |")
        rows.append(f"| lines | every node, every {d['positions_every_s']:g} s | | largest {d['positions'] * 1e3:.3f} mm | | |")
    if rotating:
        r, k = rotating, ("rk4", 1)
        x = r[k]["line7"]
        rows.append(f"| rotatingBody | line 7 (the dragging line) tension | {x['range']:.1f} N | {x['rms']:.3f} N "
                    f"({x['max']:.3f} N) | {rel(x['rms_of_range'])} | {rel(r['md_rk2_line7']['rms_of_range'])} |")
        rows.append(f"| rotatingBody | the six springs' tensions (largest) | | | {rel(r[k]['springs'])} | |")
        ang = r[k]["angle"]
        rows.append(f"| rotatingBody | body orientation (turns {np.degrees(r['turned'].max()):.0f} deg) | | "
                    f"{np.sqrt(np.mean(ang ** 2)):.2e} rad ({ang.max():.2e} rad) | "
                    f"{rel(np.sqrt(np.mean(ang ** 2)) / r['turned'].max())} | "
                    f"{rel(np.sqrt(np.mean(r['md_rk2_angle'] ** 2)) / r['turned'].max())} |")
        rows.append(f"| rotatingBody | body position (moves {r['translation'].max() * 1e3:.1f} mm) | | "
                    f"largest {r[k]['position'] * 1e6:.2f} µm | | |")
    if lifting:
        li = lifting
        t = li["t"]
        window = t <= 0.6
        dz = li[1]["dz"]
        df = li[1]["df"]
        rows.append(f"| lifting | mass height, 0-0.6 s (drop and first snap) | {np.ptp(li['md_z'][window]):.3f} m | "
                    f"largest {dz[window].max():.1e} m | | |")
        rows.append(f"| lifting | tension next to the mass, 0-0.6 s | {np.ptp(li['md_f'][window]) / 1e3:.0f} kN | "
                    f"largest {df[window].max():.1e} N | {rel(df[window].max() / np.ptp(li['md_f'][window]))} | |")
    return "\n".join(rows)


def spar_table(spar: dict) -> str:
    rows = [("| signal | range | ropesim − MoorDyn: RMS (max) | RMS / range | at dt / 2 against MoorDyn at dtM / 2 | "
            f"the body's Ca = {SPAR_RUN['ca']:g}: RMS / range |"), "| --- | --- | --- | --- | --- | --- |"]
    for k, name in enumerate(SPAR_SIGNALS):
        x, h, a = spar["rows"][k], spar["half"][k], spar["added_rows"][k]
        unit, scale = (("kN", 1e-3) if k < 3 else ("m", 1.0) if k < 5 else ("mrad", 1e3))
        rows.append(f"| {name} | {x['range'] * scale:.4g} {unit} | {x['rms'] * scale:.2e} {unit} "
                    f"({x['max'] * scale:.2e} {unit}) | {rel(x['rms_of_range'])} | {rel(h['rms_of_range'])} | "
                    f"{rel(a['rms_of_range'])} |")
    heave = spar["md_added"][:, 3] - spar["rs_added"][:, 3]
    rows.append("")
    rows.append(f"With the body's Ca = {SPAR_RUN['ca']:g}, MoorDyn's heave − ropesim's at {spar['t'][-1]:g} s: "
                f"{heave[-1] * 1e3:.3f} mm; MoorDyn's added mass in its centripetal force predicts "
                f"{spar['excess'][-1] * 1e3:.3f} mm (moordyn_centripetal_excess). Wall time: ropesim "
                f"{spar['wall']:.2f} s, MoorDyn {spar['md_wall']:.2f} s (RK4, {spar['dt'] * 1e3:g} ms).")
    return "\n".join(rows)


def explanation_rows(lines: dict | None, rotating: dict | None, lifting: dict | None) -> str:
    out = []
    if lines:
        d = lines["dynamic"]
        out.append("lines, fairlead tension RMS / range against MoorDyn's RK4 at dtM / 2, ropesim rk4 at dt, dt/2: "
                   + "; ".join(f"line {i + 1}: " + ", ".join(rel(d['ladder'][k][i]['rms_of_range']) for k in (1, 2))
                               for i in range(3))
                   + "; MoorDyn's reported GetLineFairTen against the one from its state: "
                   + ", ".join(rel(d['md_reported'][i]['rms_of_range']) for i in range(3))
                   + f". Wall time: ropesim {d['wall']:.2f} s, MoorDyn {d['md_wall']:.2f} s.")
    if rotating:
        r = rotating
        parts = []
        for key in (("rk4", 1), ("rk4", 2), ("verlet", 1)):
            x = r[key]
            parts.append(f"{key[0]} at dt/{key[1]}: line 7 {rel(x['line7_conv']['rms_of_range'])} of its range, "
                         f"orientation {np.sqrt(np.mean(x['angle_conv'] ** 2)):.2e} rad RMS")
        g = r["gyroscopic"]["body1"]
        out.append("rotatingBody against MoorDyn's RK4 at dtM / 2: " + "; ".join(parts)
                   + f". Gyroscopic moment on ropesim's run: largest {g['gyroscopic_max_Nm']:.1e} N m against "
                     f"{g['moment_rms_Nm']:.1f} N m RMS of the lines' moment.")
    if lifting:
        li = lifting
        t = li["t"]
        for level in (1e-9, 1e-6, 1e-3):
            out.append(f"lifting: mass height apart by more than {level:g} m first at: ropesim rk4 − MoorDyn "
                       f"{first_time_above(t, li[1]['dz'], level):.2f} s; at half the step "
                       f"{first_time_above(t, li[2]['dz'], level):.2f} s; MoorDyn − MoorDyn started 1 nm off "
                       f"{first_time_above(t, li['md_self_dz'], level):.2f} s; MoorDyn − MoorDyn at half its step "
                       f"{first_time_above(t, li['md_half_dz'], level):.2f} s")
    return "\n\n".join(out)


# ------------------------------------------------------------------------------------------------ figure


def draw(lines: dict | None, rotating: dict | None, lifting: dict | None, path: Path, spar: dict | None = None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = [c for c in (("lines", lines), ("rotatingBody", rotating), ("lifting", lifting), ("spar", spar))
            if c[1] is not None]
    fig, axes = plt.subplots(2, len(cols), figsize=(4.0 * len(cols), 5.6), layout="constrained", squeeze=False,
                             sharex="col", height_ratios=(2, 1))
    for col, (name, r) in enumerate(cols):
        top, bottom = axes[0, col], axes[1, col]
        if name == "lines":
            t, md, rs = r["dynamic"]["series"]
            for i, c in ((0, "C0"), (1, "C2")):
                top.plot(t, md[:, i] / 1e3, color=c, lw=2.4, alpha=0.5, label=f"line {i + 1}, MoorDyn (RK2, 2 ms)")
                top.plot(t, rs[:, i] / 1e3, color="C3", lw=0.8, ls="--",
                         label="ropesim (rk4, 2 ms)" if i == 0 else None)
                bottom.plot(t[1:], rs[1:, i] - md[1:, i], color=c, lw=0.8, label=f"line {i + 1}")
            top.set_title("lines.txt: OC3-Hywind's chains, vessel surging 5 m", fontsize=9)
            top.set_ylabel("fairlead tension [kN]")
            bottom.set_ylabel("ropesim − MoorDyn [N]")
        elif name == "rotatingBody":
            t, md = r["series"]
            rs = r[("rk4", 1)]["tension"]
            top.plot(t, md, color="C0", lw=2.4, alpha=0.5, label="line 7, MoorDyn (RK2, 0.5 ms)")
            top.plot(t, rs, color="C3", lw=0.8, ls="--", label="ropesim (rk4, 0.5 ms)")
            ax2 = top.twinx()
            ax2.plot(t, np.degrees(r["turned"]), color="k", lw=0.7, ls=":")
            ax2.set_ylabel("body turned from its start [deg] (dotted)", fontsize=8)
            top.set_title("rotatingBody: a free body turned by a line", fontsize=9)
            top.set_ylabel("tension [N]")
            bottom.plot(t[1:], rs[1:] - md[1:], color="C3", lw=0.8, label="line 7 tension [N]")
            bottom.plot(t, 1e4 * r[("rk4", 1)]["angle"], color="C1", lw=0.8, label="orientation [1e-4 rad]")
            bottom.set_ylabel("ropesim − MoorDyn")
        elif name == "spar":
            t = r["t"]
            top.plot(t, r["md"][:, 3], color="C0", lw=2.4, alpha=0.5, label="heave, MoorDyn (RK4, 2 ms)")
            top.plot(t, r["rs"][:, 3], color="C3", lw=0.8, ls="--", label="ropesim (rk4, 2 ms)")
            top.plot(t, 100 * r["md"][:, 5], color="C2", lw=2.4, alpha=0.5, label="pitch [10 mrad], MoorDyn")
            top.plot(t, 100 * r["rs"][:, 5], color="C3", lw=0.8, ls="--")
            top.set_title("a free spar on lines.txt's chains, released", fontsize=9)
            top.set_ylabel("heave [m]")
            bottom.plot(t, 1e3 * (r["rs"][:, 3] - r["md"][:, 3]), color="C3", lw=0.8, label="ropesim − MoorDyn")
            bottom.plot(t, 1e3 * (r["rs_added"][:, 3] - r["md_added"][:, 3]), color="C1", lw=0.8,
                        label=f"the same, body Ca = {SPAR_RUN['ca']:g}")
            bottom.plot(t, -1e3 * r["excess"], color="k", lw=0.8, ls=":",
                        label="MoorDyn's added-mass\ncentripetal force, integrated")
            bottom.set_ylabel("heave difference [mm]")
        else:
            t = r["t"]
            top.plot(t, -r["md_z"] - 100.0, color="C0", lw=2.4, alpha=0.5, label="MoorDyn (RK4, 0.1 ms)")
            top.plot(t, -r[1]["z"] - 100.0, color="C3", lw=0.8, ls="--", label="ropesim (rk4, 0.1 ms)")
            top.set_title("lifting.txt: 1 t dropped onto its slack line", fontsize=9)
            top.set_ylabel("mass below 100 m [m]")
            bottom.semilogy(t[1:], np.maximum(r[1]["dz"][1:], 1e-16), color="C3", lw=0.8, label="ropesim − MoorDyn")
            bottom.semilogy(t[1:], np.maximum(r["md_self_dz"][1:], 1e-16), color="C0", lw=0.8,
                            label="MoorDyn − MoorDyn 1 nm off")
            bottom.set_ylabel("|mass height difference| [m]")
        bottom.set_xlabel("t [s]")
        for ax in (top, bottom):
            ax.grid(True, alpha=0.3)
        top.legend(fontsize=7, loc="best")
        bottom.legend(fontsize=7, loc="best")
    from ropesim.io.atomic import atomic_output

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ main


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(SYSTEMS), help="comma-separated: " + ", ".join(SYSTEMS))
    parser.add_argument("--figure", type=Path, default=FIGURE, help="PNG of the comparison")
    parser.add_argument("--regenerate", action="store_true",
                        help="rerun MoorDyn for tests/data/moordyn/own_systems.* (needs moordyn) before comparing")
    args = parser.parse_args(argv)
    names = [n.strip() for n in args.cases.split(",") if n.strip()]
    unknown = [n for n in names if n not in SYSTEMS]
    if unknown:
        parser.error(f"unknown case(s) {unknown}; choose from {list(SYSTEMS)}")

    import ropesim

    started = time.perf_counter()
    if args.regenerate:
        print("MoorDyn runs:", flush=True)
        regenerate(names)
    arrays, record = load_stored()
    print(f"MoorDyn {record['moordyn_version']} (stored), ropesim {ropesim.__version__}:", flush=True)
    lines = lines_results(arrays, record) if "lines" in names else None
    rotating = rotating_results(arrays, record) if "rotatingBody" in names else None
    lifting = lifting_results(arrays, record) if "lifting" in names else None
    spar = spar_results(arrays, record) if "spar" in names else None
    if lines or lifting:
        print("\n## Static\n")
        print(static_table(lines, lifting))
    if lines or rotating or lifting:
        print("\n## Dynamic\n")
        print(dynamic_table(lines, rotating, lifting))
    if spar:
        print("\n## A free spar (RK4 at equal steps)\n")
        print(spar_table(spar))
    if lines or rotating or lifting:
        print("\n## Where the differences come from\n")
        print(explanation_rows(lines, rotating, lifting))
    draw(lines, rotating, lifting, args.figure, spar)
    print(f"\nwrote {args.figure}")
    print(f"total {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
