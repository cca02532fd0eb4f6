#!/usr/bin/env bash
# The string shooter's loop inclination against air drag b: a `ropesim sweep` over drag.b, collected into
# OUT/inclination_vs_b.csv (b, t_end, mean inclination over the last second [deg], status) and plotted in
# OUT/shooter.mean_loop_inclination_deg_vs_drag.b.png.
#
# Usage: scripts/sweep_air_resistance.sh [SCENE.toml]  (default: scenarios/shooter_medium.toml)
# Environment:
#   B_MIN=0 B_MAX=1.5 COUNT=16   the drag values, evenly spaced, ends included [kg/s]
#   T_END=40                     end time [s]; a list such as 5,40 runs each b for each t_end (one line each)
#   JOBS=2                       runs at once
#   OUT=runs/sweep-air-resistance
# Inclination: the loop centroid's direction from the thrower centre, from straight down, positive forward (+x).
set -euo pipefail

prog=$(basename "$0")
die() { echo "$prog: $*" >&2; exit 1; }
root=$(cd "$(dirname "$0")/.." && pwd)
scene=${1:-$root/scenarios/shooter_medium.toml}
b_min=${B_MIN:-0} b_max=${B_MAX:-1.5} count=${COUNT:-16} t_end=${T_END:-40} jobs=${JOBS:-2}
out=${OUT:-runs/sweep-air-resistance}
figure=shooter.mean_loop_inclination_deg

command -v ropesim >/dev/null || die "ropesim is not installed (not on PATH); install it with: pip install -e $root"
command -v python3 >/dev/null || die "python3 not found"
[[ -f $scene ]] || die "scene file $scene not found"

echo "$prog: drag.b = $b_min..$b_max ($count values), t_end = $t_end s, $jobs at once: $scene -> $out/"
ropesim sweep "$scene" --set "drag.b=$b_min:$b_max:$count" --set "integrator.t_end=$t_end" \
    --jobs "$jobs" --out "$out" --plot "$figure" \
    || die "ropesim sweep failed (exit $?; its message is above)"

python3 - "$out/results.csv" "$out/inclination_vs_b.csv" "$figure" <<'PY' || die "cannot collect $figure from $out/results.csv"
import csv, os, sys

source, target, figure = sys.argv[1:]
with open(source, newline="") as fh:
    rows = list(csv.DictReader(fh))
if not rows or figure not in rows[0] or "drag.b" not in rows[0]:
    sys.exit(f"{source}: no drag.b or {figure} column (is the scene a string shooter with [drag]?)")
keep = {"drag.b": "b_kg_per_s", "integrator.t_end": "t_end_s", figure: "mean_inclination_deg", "status": "status"}
with open(target + ".tmp", "w", newline="") as fh:
    writer = csv.writer(fh, lineterminator="\n")
    columns = [k for k in keep if k in rows[0]]
    writer.writerow([keep[k] for k in columns])
    for row in rows:
        writer.writerow([row[k] for k in columns])
        print("  " + "  ".join(f"{keep[k]} = {row[k]}" for k in columns))
os.replace(target + ".tmp", target)
PY
echo "$prog: wrote $out/inclination_vs_b.csv and $out/$figure""_vs_drag.b.png"
