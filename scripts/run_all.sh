#!/usr/bin/env bash
# Run, then animate, every built-in scenario: runs/<name>/ (trajectory.npz, scene.toml, summary.json, <name>.gif).
#
# Usage: scripts/run_all.sh [SCENE.toml ...]          (default: every scenarios/*.toml)
# Environment:
#   RUNS_DIR=runs     where the run folders go
#   T_END=0.1         override every scene's end time [s] (a quick check); unset: each scene's own t_end
#   NO_ANIMATE=1      run only, no animations
set -euo pipefail

prog=$(basename "$0")
die() { echo "$prog: $*" >&2; exit 1; }
root=$(cd "$(dirname "$0")/.." && pwd)
runs_dir=${RUNS_DIR:-runs}
animate=1
[[ ${NO_ANIMATE:-} == 1 ]] && animate=0

command -v ropesim >/dev/null || die "ropesim is not installed (not on PATH); install it with: pip install -e $root"
if (( animate )) && ! ropesim animate --help >/dev/null 2>&1; then
    die "this ropesim has no 'animate' command; update ropesim, or set NO_ANIMATE=1 to only run the scenes"
fi

if (( $# )); then
    scenes=("$@")
else
    shopt -s nullglob
    scenes=("$root"/scenarios/*.toml)
    (( ${#scenes[@]} )) || die "no scene files in $root/scenarios/"
fi
for scene in "${scenes[@]}"; do
    [[ -f $scene ]] || die "scene file $scene not found"
done

extra=()
[[ -n ${T_END:-} ]] && extra=(--set "integrator.t_end=$T_END")

n=${#scenes[@]}
i=0
start=$SECONDS
for scene in "${scenes[@]}"; do
    i=$((i + 1))
    name=$(basename "$scene" .toml)
    out="$runs_dir/$name"
    echo "[$i/$n] $name: run -> $out/"
    status=0
    ropesim run "$scene" --out "$out" --quiet "${extra[@]+"${extra[@]}"}" || status=$?
    (( status == 0 )) || die "ropesim run $scene failed (exit $status); what it computed is in $out/"
    if (( animate )); then
        echo "[$i/$n] $name: animate -> $out/$name.gif"
        ropesim animate "$out" --out "$out/$name.gif" || die "ropesim animate $out failed (exit $?)"
    fi
done
echo "$prog: $n scenes in $runs_dir/ ($((SECONDS - start)) s)"
