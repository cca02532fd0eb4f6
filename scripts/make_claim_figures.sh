#!/usr/bin/env bash
# The write-up's two claims, measured; writes docs/images/claims_helicopter_angles.png and
# docs/images/claims_shooter_inclination.png.
#
# 1. Helicopter: the three towed-rope scenes run to HELI_T_END (default 300 s: the end mass relaxes on
#    M / b = 20 s), then each segment's angle against the exact steady state (scripts/plot_towed_angles.py).
# 2. Shooter: scripts/sweep_air_resistance.sh over b in [0, 1.5] (16 values), each b at the write-up's
#    t_f = 5 s and longer, to see whether the inclination has settled: SHOOTER_T_END (default
#    5,40,120: one line each).
#
# Environment: RUNS_DIR=runs/claims, IMAGES=docs/images, HELI_T_END=300, SHOOTER_T_END=5,40,120, COUNT=16, JOBS=2
set -euo pipefail

prog=$(basename "$0")
die() { echo "$prog: $*" >&2; exit 1; }
root=$(cd "$(dirname "$0")/.." && pwd)
runs_dir=${RUNS_DIR:-runs/claims}
images=${IMAGES:-$root/docs/images}
heli_t_end=${HELI_T_END:-300}

command -v ropesim >/dev/null || die "ropesim is not installed (not on PATH); install it with: pip install -e $root"
mkdir -p "$images"

runs=()
for name in helicopter_uniform helicopter_mass helicopter_parachute; do
    scene="$root/scenarios/$name.toml"
    [[ -f $scene ]] || die "scene file $scene not found"
    echo "$prog: $name to t = $heli_t_end s -> $runs_dir/$name/"
    ropesim run "$scene" --out "$runs_dir/$name" --quiet --set "integrator.t_end=$heli_t_end" \
        --set output.interval=0.1 || die "ropesim run $scene failed (exit $?)"
    runs+=("$runs_dir/$name")
done
python3 "$root/scripts/plot_towed_angles.py" "${runs[@]}" --out "$images/claims_helicopter_angles.png" \
    || die "plotting the helicopter figure failed"

T_END=${SHOOTER_T_END:-5,40,120} COUNT=${COUNT:-16} OUT="$runs_dir/shooter" JOBS=${JOBS:-2} \
    "$root/scripts/sweep_air_resistance.sh" "$root/scenarios/shooter_medium.toml"
cp "$runs_dir/shooter/shooter.mean_loop_inclination_deg_vs_drag.b.png" "$images/claims_shooter_inclination.png"
echo "$prog: wrote $images/claims_helicopter_angles.png and $images/claims_shooter_inclination.png"
