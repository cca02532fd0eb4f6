"""The string shooter's takeoff speed in air: sweep the wheels' speed for two loop lengths and two launch angles,
then vary the tangential drag coefficient Cd_t. Draws the figures and the table of
docs/background/string-shooter.md.

Every run is the built-in scene string_shooter_real (a cotton string loop, d = 1.5 mm, 1.6 g/m, in air) with
the loop length, the launch angle (the nip and both wheels turned together), the wheels' speed v_max and Cd_t
set, run for T_END = 3 s from rest, the loop hanging round the lower wheel like a belt on a pulley (a narrow
stadium turned with the nip: :func:`pulley_start`; the scene's own square start can wind a long slow loop
round the lower wheel instead); the figures are means over the last second.

- The loop's inclination: the direction of its centroid seen from the nip, measured from straight down (0: the
  loop hangs below the wheels, the "pulley" state; 90: it stands straight out in front; more: above).
- Takeoff: the loop is *lifted* when its mean inclination is at least 45 degrees (its centroid more in front
  of the wheels than below them). The takeoff speed is where the inclination crosses 45 degrees for the last
  time on the way up the sweep (above it every run is lifted): interpolated linearly between the two runs
  that bracket it, after BISECTIONS bisection runs have narrowed the bracket.
- Steady: the centroid's height varies by less than STEADY_FRACTION of the loop's length (one standard
  deviation) over the last second; otherwise the loop flaps.

    python scripts/string_shooter_takeoff.py [--jobs 2] [--out runs/string-shooter-takeoff]
                                              [--figures docs/images] [--quick]

69 runs of 3 s; 9 minutes with --jobs 2 on two cores (measured: 539 s) (a run takes 8 to 25 s of one core: 40 to 80 nodes at
dt = 2e-5 s). --quick runs two speeds of one series at T_END = 0.05 s, to check the script.
Writes runs.csv (one row per run), takeoff.csv and takeoff.md (the takeoff table) in --out, shapes.npz (each
run's last frames), and the figures string_shooter_takeoff.png, string_shooter_cdt.png and
string_shooter_shapes.png in --figures.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

SCENE = "string_shooter_real"
SEGMENT = 0.025              # m, the scene's segment length, kept for every loop length
WHEEL_RADIUS = 0.025         # m, the scene's guides
T_END = 3.0                  # s
WINDOW = 1.0                 # s, the figures are means over the last WINDOW seconds
LIFTED_DEG = 45.0
STEADY_FRACTION = 0.01
BISECTIONS = 3
SPEEDS = (8.0, 12.0, 15.0, 18.0, 21.0, 24.0, 28.0)    # m/s, the length-and-angle sweep
LENGTHS = (1.0, 2.0)         # m
ANGLES = (0.0, 30.0)         # deg
CDT_LENGTH, CDT_ANGLE = 1.5, 30.0
CDTS = (0.0, 0.005, 0.02, 0.05)
CDT_FACTORS = (0.7, 0.9, 1.1, 1.3, 1.6)   # speeds U_t x these for Cd_t > 0
CDT_ZERO_SPEEDS = (12.0, 18.0, 25.0, 32.0)

# The string, as in the scene (checked by tests/test_string_shooter.py)
MU, DIAMETER, RHO, CD_N, G = 0.0016, 0.0015, 1.225, 1.2, 9.81


def terminal_speeds(cd_t: float) -> dict:
    """The two drag-weight balances [m/s] of tests/references/closed_forms.string_loop_takeoff_speeds: end-on
    (skin drag 1/2 rho Cd_t pi d U^2 = weight per metre) and broadside (1/2 rho Cd_n d U^2 = weight)."""
    w = MU * G
    return {"tangential": math.sqrt(2 * w / (RHO * cd_t * math.pi * DIAMETER)) if cd_t > 0 else math.inf,
            "normal": math.sqrt(2 * w / (RHO * CD_N * DIAMETER))}


def overrides(length: float, angle: float, v_max: float, cd_t: float, t_end: float) -> list[str]:
    """The scene keys of one run: the nip turned by ``angle`` and the wheels with it (the scene's own start)."""
    a = math.radians(angle)
    s, c = WHEEL_RADIUS * math.sin(a), WHEEL_RADIUS * math.cos(a)
    return [f"rope.length={length!r}", f"rope.segments={round(length / SEGMENT)}", f"thrower.angle={angle!r}",
            f"thrower.v_max={v_max!r}", f"fluid_drag.cd_tangential={cd_t!r}", f"integrator.t_end={t_end!r}",
            f"guides.0.center=[{s!r}, {-c!r}]", f"guides.1.center=[{-s!r}, {c!r}]"]


def pulley_start(length: float, nodes: int, angle: float) -> np.ndarray:
    """Node positions (nodes, 2) [m] of the loop hanging round the lower wheel like a belt on a pulley: the
    wheel's rim (radius R, centre (0, -R)) from its top, the nip, clockwise down its front, a straight strand
    down, a half circle of radius R at the bottom, a strand back up and the rim's back quarter to the nip; the
    whole turned by ``angle`` about the nip, nodes evenly spaced along it."""
    r = WHEEL_RADIUS
    drop = (length - 2 * math.pi * r) / 2
    quarter = math.pi * r / 2
    points = []
    for s in np.arange(nodes) * length / nodes:
        if s < quarter:
            a = s / r
            points.append((r * math.sin(a), r * (math.cos(a) - 1)))
        elif s < quarter + drop:
            points.append((r, -r - (s - quarter)))
        elif s < 3 * quarter + drop:
            a = (s - quarter - drop) / r
            points.append((r * math.cos(a), -r - drop - r * math.sin(a)))
        elif s < 3 * quarter + 2 * drop:
            points.append((-r, -r - drop + (s - 3 * quarter - drop)))
        else:
            a = (s - 3 * quarter - 2 * drop) / r
            points.append((-r * math.cos(a), r * (math.sin(a) - 1)))
    a = math.radians(angle)
    turn = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return np.array(points) @ turn.T


def study_overrides(length: float, angle: float, v_max: float, cd_t: float, t_end: float) -> list[str]:
    """:func:`overrides` and the pulley start."""
    points = pulley_start(length, round(length / SEGMENT), angle)
    shown = ", ".join(f"[{float(x)!r}, {float(y)!r}]" for x, y in points)
    return overrides(length, angle, v_max, cd_t, t_end) + ["initial.shape=points", f"initial.points=[{shown}]"]


def measure(t: np.ndarray, x: np.ndarray, v: np.ndarray, length: float, window: float = WINDOW) -> dict:
    """The loop's figures over the last ``window`` seconds of frames x, v (F, N, 2), the nip at the origin."""
    from ropesim.analysis.shooter import circulation_speed

    last = t >= t[-1] - window
    centroid = x[last].mean(axis=1)
    incl = np.degrees(np.arctan2(centroid[:, 0], -centroid[:, 1]))
    return {"inclination_deg": float(incl.mean()),
            "height_over_length": float(centroid[:, 1].mean() / length),
            "height_sd_over_length": float(centroid[:, 1].std() / length),
            "lowest_over_length": float(x[last][:, :, 1].min(axis=1).mean() / length),
            "string_speed_m_s": float(np.mean([circulation_speed(a, b) for a, b in zip(x[last], v[last])]))}


CRITERIA = {   # name: the inclination [deg] a steady loop must reach to count as lifted, from its launch angle
    "45 deg": lambda angle: LIFTED_DEG,
    "halfway": lambda angle: (90.0 + angle) / 2,
}


def case_name(case: dict) -> str:
    return (f"L{case['length']:g}_a{case['angle']:g}_cdt{case['cd_t']:g}_v{case['v_max']:g}"
            f"_t{case['t_end']:g}")


def run_one(case: dict) -> dict:
    import ropesim

    scene = ropesim.load_scene(SCENE, study_overrides(case["length"], case["angle"], case["v_max"], case["cd_t"],
                                                      case["t_end"]))
    start = time.perf_counter()
    traj = ropesim.simulate(scene)
    wall = time.perf_counter() - start
    row = {**case, "status": traj.summary["status"], "wall_s": round(wall, 1)}
    row.update(measure(traj.t, traj.x, traj.v, case["length"], min(WINDOW, case["t_end"] / 3)))
    row["frames"] = traj.x[-21::5].copy()     # the last 0.2 s, every 50 ms, for the shape figure
    return row


def classify(row: dict) -> dict:
    """Steady, and lifted by each criterion (a lifted loop is a steady one)."""
    row["steady"] = row["status"] == "completed" and row["height_sd_over_length"] < STEADY_FRACTION
    for name, threshold in CRITERIA.items():
        row[f"lifted {name}"] = row["steady"] and row["inclination_deg"] >= threshold(row["angle"])
    return row


def series_key(row: dict) -> tuple:
    return row["length"], row["angle"], row["cd_t"]


def crossing(rows: list[dict], criterion: str = "45 deg") -> tuple[float, float] | None:
    """The bracket (v_below, v_above) of one series' takeoff by ``criterion``: the fastest run not lifted and
    the next faster run (above it every run is lifted); None when the fastest run is not lifted (no takeoff in
    the range), (nan, slowest) when every run is lifted."""
    rows = sorted(rows, key=lambda r: r["v_max"])
    lifted = f"lifted {criterion}"
    if not rows[-1][lifted]:
        return None
    for below, above in zip(rows[-2::-1], rows[::-1]):
        if not below[lifted]:
            return below["v_max"], above["v_max"]
    return math.nan, rows[0]["v_max"]


def takeoff_speed(rows: list[dict], criterion: str = "45 deg") -> dict:
    """The takeoff speed of one series by ``criterion``, as v_max and as the measured string speed: interpolated
    where the inclination reaches the criterion's threshold when the run below the bracket is steady (its
    inclination then means something), else the bracket's middle."""
    bracket = crossing(rows, criterion)
    if bracket is None or math.isnan(bracket[0]):
        return {"v_takeoff": math.nan, "u_takeoff": math.nan, "bracket": bracket}
    lo, hi = (next(r for r in rows if r["v_max"] == v) for v in bracket)
    f = 0.5
    if lo["steady"]:
        threshold = CRITERIA[criterion](lo["angle"])
        f = min(1.0, max(0.0, (threshold - lo["inclination_deg"]) / (hi["inclination_deg"] - lo["inclination_deg"])))
    return {"v_takeoff": lo["v_max"] + f * (hi["v_max"] - lo["v_max"]),
            "u_takeoff": lo["string_speed_m_s"] + f * (hi["string_speed_m_s"] - lo["string_speed_m_s"]),
            "bracket": bracket}


def run_all(cases: list[dict], jobs: int, done: list[dict], cache: Path) -> None:
    """Run ``cases`` (those not already in ``cache``, a folder of one .npz per run) and add their rows to
    ``done``."""
    cache.mkdir(parents=True, exist_ok=True)
    todo = []
    for case in cases:
        file = cache / f"{case_name(case)}.npz"
        if file.is_file():
            with np.load(file, allow_pickle=False) as data:
                row = {k: data[k].item() for k in data.files if k != "frames"}
                row["frames"] = data["frames"]
            done.append(classify(row))
        else:
            todo.append(case)
    if not todo:
        return
    with ProcessPoolExecutor(jobs) as pool:
        for row in pool.map(run_one, todo):
            np.savez(cache / f"{case_name(row)}.npz", **row)
            done.append(classify(row))
            print(f"L = {row['length']:g} m, angle {row['angle']:g} deg, Cd_t {row['cd_t']:g}, v_max "
                  f"{row['v_max']:.4g} m/s: {row['status']}, inclination {row['inclination_deg']:.1f} deg, "
                  f"height {row['height_over_length']:+.3f} L, {'steady' if row['steady'] else 'flapping'} "
                  f"({row['wall_s']:.0f} s)", flush=True)


def bisect(rows: list[dict], jobs: int, t_end: float, steps: int, cache: Path) -> None:
    """Narrow every series' takeoff brackets (by each criterion) by ``steps`` bisection runs."""
    for _ in range(steps):
        cases = {}
        for key in sorted({series_key(r) for r in rows}):
            series = [r for r in rows if series_key(r) == key]
            for criterion in CRITERIA:
                bracket = crossing(series, criterion)
                if bracket is None or math.isnan(bracket[0]):
                    continue
                length, angle, cd_t = key
                case = dict(length=length, angle=angle, cd_t=cd_t, v_max=round(sum(bracket) / 2, 4), t_end=t_end)
                cases[case_name(case)] = case
        if cases:
            run_all(list(cases.values()), jobs, rows, cache)


def write_tables(rows: list[dict], out: Path) -> list[dict]:
    fields = ["length", "angle", "cd_t", "v_max", "status", "string_speed_m_s", "inclination_deg",
              "height_over_length", "height_sd_over_length", "lowest_over_length", "steady",
              *(f"lifted {c}" for c in CRITERIA), "wall_s"]
    with open(out / "runs.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fields, extrasaction="ignore")
        writer.writeheader()
        for r in sorted(rows, key=lambda r: (series_key(r), r["v_max"])):
            writer.writerow({k: round(v, 4) if isinstance(v, float) else v for k, v in r.items()})
    table = []
    for key in sorted({series_key(r) for r in rows}):
        length, angle, cd_t = key
        series = [r for r in rows if series_key(r) == key]
        ut = terminal_speeds(cd_t)["tangential"]
        entry = {"length_m": length, "angle_deg": angle, "cd_t": cd_t, "runs": len(series),
                 "end_on_terminal_m_s": ut,
                 "flapping_at": " ".join(f"{v:g}" for v in sorted(r["v_max"] for r in series if not r["steady"]))}
        for criterion in CRITERIA:
            found = takeoff_speed(series, criterion)
            entry[f"v_takeoff {criterion}"] = found["v_takeoff"]
            entry[f"u_takeoff {criterion}"] = found["u_takeoff"]
            entry[f"u_over_ut {criterion}"] = found["u_takeoff"] / ut
            entry[f"bracket {criterion}"] = found["bracket"]
        table.append(entry)
    with open(out / "takeoff.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, list(table[0]))
        writer.writeheader()
        writer.writerows(table)

    def shown(entry, criterion):
        bracket = entry[f"bracket {criterion}"]
        if bracket is None:
            return "none up to the top speed", "–", "–"
        if math.isnan(bracket[0]):
            return f"below {bracket[1]:g}", "–", "–"
        return (f"{entry[f'v_takeoff {criterion}']:.1f} ({bracket[0]:g} – {bracket[1]:g})",
                f"{entry[f'u_takeoff {criterion}']:.1f}", f"{entry[f'u_over_ut {criterion}']:.2f}")

    lines = ["| L [m] | launch angle [deg] | Cd_t | U_t [m/s] | takeoff v_max, 45° [m/s] (bracket) | U*/U_t, 45° | "
             "takeoff v_max, halfway [m/s] (bracket) | U*/U_t, halfway | flapping at v_max [m/s] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        a, _, a_ratio = shown(r, "45 deg")
        b, _, b_ratio = shown(r, "halfway")
        ut = f"{r['end_on_terminal_m_s']:.1f}" if math.isfinite(r["end_on_terminal_m_s"]) else "∞"
        lines.append(f"| {r['length_m']:g} | {r['angle_deg']:g} | {r['cd_t']:g} | {ut} | {a} | {a_ratio} | {b} | "
                     f"{b_ratio} | {r['flapping_at'] or '–'} |")
    (out / "takeoff.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return table


def figures(rows: list[dict], table: list[dict], folder: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    takeoffs = {(r["length_m"], r["angle_deg"], r["cd_t"]): r for r in table}
    present = {series_key(r) for r in rows}

    def fraction(r):   # 0: hanging straight down, 1: along the launch direction
        return r["inclination_deg"] / (90.0 + r["angle"])

    def plot_series(ax, key, x_of, y_of, **style):
        series = sorted((r for r in rows if series_key(r) == key), key=lambda r: r["v_max"])
        line, = ax.plot([x_of(r) for r in series], [y_of(r) for r in series], **{"linestyle": "-", **style})
        for steady, face in ((True, line.get_color()), (False, "white")):
            pick = [r for r in series if r["steady"] == steady]
            ax.plot([x_of(r) for r in pick], [y_of(r) for r in pick], "o", mfc=face, color=line.get_color(), ms=4.5)
        return line

    def speed_over_ut(r):
        return r["string_speed_m_s"] / terminal_speeds(r["cd_t"])["tangential"]

    def takeoff_label(key, criterion):
        v = takeoffs[key][f"v_takeoff {criterion}"]
        return f"{v:.1f} m/s" if math.isfinite(v) else "none"

    # 1. length and angle, Cd_t = 0.02
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.9))
    keys = [k for k in [(length, angle, 0.02) for length in LENGTHS for angle in ANGLES]
            + [(CDT_LENGTH, CDT_ANGLE, 0.02)] if k in present]
    for key in keys:
        style = {"linestyle": "--" if key[1] == 0 else "-"}
        label = (f"L = {key[0]:g} m, {key[1]:g}°: takeoff {takeoff_label(key, '45 deg')} (45°), "
                 f"{takeoff_label(key, 'halfway')} (halfway)")
        line = plot_series(axes[0], key, lambda r: r["v_max"], lambda r: r["inclination_deg"], label=label, **style)
        plot_series(axes[1], key, speed_over_ut, fraction, color=line.get_color(), **style)
    speeds = terminal_speeds(0.02)
    axes[0].axhline(LIFTED_DEG, color="0.3", lw=0.8, ls=":")
    axes[0].axhline(CRITERIA["halfway"](30.0), color="0.6", lw=0.8, ls=":")
    axes[0].axvline(speeds["tangential"], color="k", lw=1.0, ls="-.",
                    label=f"end-on terminal speed U_t = {speeds['tangential']:.1f} m/s")
    axes[0].axvline(speeds["normal"], color="0.5", lw=1.0, ls="-.",
                    label=f"broadside terminal speed {speeds['normal']:.1f} m/s")
    axes[0].set_xlabel("wheel speed v_max [m/s]")
    axes[0].set_ylabel("loop inclination [deg]: 0 hanging, 90 straight out")
    axes[0].set_title("Cd_t = 0.02; dotted: 45° and 60° (halfway at 30°)\nfilled: steady loop, open: flapping",
                      fontsize=9)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=3, frameon=False)
    axes[1].axhline(0.5, color="0.3", lw=0.8, ls=":")
    axes[1].axvline(1.0, color="k", lw=1.0, ls="-.")
    axes[1].set_xlabel("string speed / end-on terminal speed, U / U_t")
    axes[1].set_ylabel("inclination / (90° + launch angle)")
    axes[1].set_title("the same, as the fraction of the way from hanging to the launch direction", fontsize=9)
    fig.tight_layout(rect=(0, 0.13, 1, 1))
    fig.savefig(folder / "string_shooter_takeoff.png", dpi=110)
    plt.close(fig)

    # 2. Cd_t
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.0))
    for cd_t in CDTS:
        key = (CDT_LENGTH, CDT_ANGLE, cd_t)
        if key not in present:
            continue
        label = f"Cd_t = {cd_t:g}: takeoff {takeoff_label(key, '45 deg')} (45°)" if cd_t > 0 else \
            "Cd_t = 0: never steady"
        line = plot_series(axes[0], key, lambda r: r["v_max"], lambda r: r["inclination_deg"], label=label)
        if cd_t > 0:
            plot_series(axes[1], key, speed_over_ut, lambda r: r["inclination_deg"], color=line.get_color(),
                        label=f"Cd_t = {cd_t:g}, U_t = {terminal_speeds(cd_t)['tangential']:.1f} m/s")
    for ax in axes:
        ax.axhline(LIFTED_DEG, color="0.3", lw=0.8, ls=":")
        ax.set_ylabel("loop inclination [deg]")
        ax.legend(fontsize=7, loc="lower right")
    axes[1].axvline(1.0, color="k", lw=1.0, ls="-.")
    axes[0].set_xlabel("wheel speed v_max [m/s]")
    axes[1].set_xlabel("string speed / end-on terminal speed, U / U_t")
    axes[0].set_title(f"L = {CDT_LENGTH:g} m, launch angle {CDT_ANGLE:g}°; filled: steady, open: flapping",
                      fontsize=9)
    axes[1].set_title("against U / U_t, U_t = sqrt(2 mu g / (rho Cd_t pi d)): one curve", fontsize=9)
    fig.tight_layout()
    fig.savefig(folder / "string_shooter_cdt.png", dpi=110)
    plt.close(fig)

    # 3. shapes: Cd_t = 0.02 across the takeoff, and Cd_t = 0
    panels = []
    for cd_t in (0.02, 0.0):
        series = sorted((r for r in rows if series_key(r) == (CDT_LENGTH, CDT_ANGLE, cd_t)), key=lambda r: r["v_max"])
        if len(series) > 6:
            series = [series[i] for i in np.linspace(0, len(series) - 1, 6).round().astype(int)]
        if series:
            panels.append(series)
    if not panels:
        return
    columns = max(len(p) for p in panels)
    fig, axes = plt.subplots(len(panels), columns, figsize=(2.2 * columns, 2.7 * len(panels)), sharex=True,
                             sharey=True, squeeze=False)
    a = math.radians(CDT_ANGLE)
    for row_axes, series in zip(axes, panels):
        for ax in row_axes[len(series):]:
            ax.axis("off")
        for ax, r in zip(row_axes, series):
            for k, frame in enumerate(r["frames"]):
                p = np.vstack([frame, frame[:1]])
                ax.plot(p[:, 0], p[:, 1], "-", lw=0.9, color="C0" if r["cd_t"] else "C3",
                        alpha=0.25 + 0.75 * k / max(1, len(r["frames"]) - 1))
            for sign in (1, -1):
                centre = sign * WHEEL_RADIUS * np.array([-math.sin(a), math.cos(a)])
                ax.add_patch(plt.Circle(centre, WHEEL_RADIUS, fill=False, color="0.4", lw=0.7))
            ax.set_aspect("equal")
            ax.set_title(f"Cd_t = {r['cd_t']:g}, v_max = {r['v_max']:.3g} m/s\n{r['inclination_deg']:.0f}°, "
                         f"{'steady' if r['steady'] else 'flapping'}", fontsize=7)
            ax.tick_params(labelsize=6)
    for ax in axes[-1]:
        ax.set_xlabel("x [m]", fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("y [m]", fontsize=7)
    fig.suptitle(f"L = {CDT_LENGTH:g} m, launch angle {CDT_ANGLE:g}°: the last 0.2 s of each run, every 50 ms "
                 "(older paler)", fontsize=8)
    fig.tight_layout()
    fig.savefig(folder / "string_shooter_shapes.png", dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("runs/string-shooter-takeoff"))
    parser.add_argument("--figures", type=Path, default=Path("docs/images"))
    parser.add_argument("--quick", action="store_true", help="two short runs of one series: a smoke test")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    rows: list[dict] = []
    if args.quick:
        t_end = 0.05
        cases = [dict(length=CDT_LENGTH, angle=CDT_ANGLE, cd_t=0.02, v_max=v, t_end=t_end) for v in (8.0, 24.0)]
        steps = 0
    else:
        t_end = T_END
        cases = [dict(length=length, angle=angle, cd_t=0.02, v_max=v, t_end=t_end)
                 for length in LENGTHS for angle in ANGLES for v in SPEEDS]
        for cd_t in CDTS:
            speeds = CDT_ZERO_SPEEDS if cd_t == 0 else [round(terminal_speeds(cd_t)["tangential"] * f, 2)
                                                        for f in CDT_FACTORS]
            cases += [dict(length=CDT_LENGTH, angle=CDT_ANGLE, cd_t=cd_t, v_max=v, t_end=t_end) for v in speeds]
        steps = BISECTIONS
    cases.sort(key=lambda c: -c["length"])   # the longest loops (the slowest runs) first: the pool ends evenly
    cache = args.out / "cases"
    run_all(cases, args.jobs, rows, cache)
    bisect(rows, args.jobs, t_end, steps, cache)
    table = write_tables(rows, args.out)
    np.savez_compressed(args.out / "shapes.npz", **{
        f"L{r['length']:g}_a{r['angle']:g}_cdt{r['cd_t']:g}_v{r['v_max']:g}": r["frames"] for r in rows})
    figures(rows, table, args.figures)
    print(f"{len(rows)} runs in {time.perf_counter() - start:.0f} s; tables in {args.out}/, figures in "
          f"{args.figures}/")


if __name__ == "__main__":
    main()
