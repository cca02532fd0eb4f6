#!/usr/bin/env bash
# Regenerate the docs' pictures of the built-in scenarios (docs/images/scenarios/) with ropesim's own
# commands: the towed ropes as overlaid frames seen from the helicopter, run long enough to reach their steady
# shapes (plus the plot of the one with the end mass), the string shooters as small GIFs of their default runs.
#
#     scripts/make_readme_images.sh        # about a minute on two cores; prints the pictures' total size
set -euo pipefail
cd "$(dirname "$0")/.."
out=docs/images/scenarios
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
mkdir -p "$out"
ropesim() { python -m ropesim "$@"; }

for scene in helicopter_uniform helicopter_mass helicopter_parachute; do
    ropesim run "scenarios/$scene.toml" --set integrator.t_end=60 --set output.interval=0.05 -o "$runs/$scene" -q
    ropesim frames "$runs/$scene" --follow --overlay --times 0,1,2,4,8,15,60 --width 360 -o "$out/$scene.png" -q
done
ropesim plot "$runs/helicopter_mass" -o "$out/helicopter_mass_plot.png" -q

# the sling in a side wind (3-D): seen from above (x-z) and from the side (x-y), and its tension plot
ropesim run helicopter_crosswind -o "$runs/helicopter_crosswind" -q
ropesim frames "$runs/helicopter_crosswind" --follow --overlay --times 0,1,2,4,8,15,60 --view xz --width 360 \
    -o "$out/helicopter_crosswind_above.png" -q
ropesim frames "$runs/helicopter_crosswind" --follow --overlay --times 0,1,2,4,8,15,60 --view xy --width 360 \
    -o "$out/helicopter_crosswind_side.png" -q
ropesim plot "$runs/helicopter_crosswind" -o "$out/helicopter_crosswind_plot.png" -q

for scene in shooter_vacuum shooter_low shooter_low_one_sided shooter_medium shooter_high; do
    ropesim run "scenarios/$scene.toml" -o "$runs/$scene" -q
    ropesim animate "$runs/$scene" --fps 10 --size 320 -o "$out/$scene.gif" -q
done
du -ch "$out"/* | tail -1
