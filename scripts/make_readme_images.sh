#!/usr/bin/env bash
# Regenerate the docs' pictures of the built-in scenarios (docs/images/scenarios/) with ropesim's own
# commands: the towed ropes as overlaid frames seen from the helicopter, run long enough to reach their steady
# shapes (plus the plot of the one with the end mass), the string shooters as small GIFs of their default runs
# (the real one, string_shooter_real, slowed down, with a frame sheet), the moorings and the beam (frames,
# the chain's swing as a GIF, and each one's plot with its tensions), and the systems of lines (each one's
# frames, an animation and its plot), and the sea's scenes (the chain in waves, the floating hose).
#
#     scripts/make_readme_images.sh        # about three minutes on two cores; prints the pictures' total size
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
# the real string shooter: 25 m/s, so slowed down four times over its first 1.5 s, and a frame sheet to 3 s
ropesim run string_shooter_real -o "$runs/string_shooter_real" -q
ropesim animate "$runs/string_shooter_real" --fps 20 --speed 0.25 --end 1.5 --size 320 \
    -o "$out/string_shooter_real.gif" -q
ropesim frames "$runs/string_shooter_real" --times 0,0.03,0.06,0.1,0.2,0.5,1,3 --columns 4 --width 760 \
    -o "$out/string_shooter_real_frames.png" -q

# the mooring chain: one wave period overlaid, two periods animated at twice the speed, and its tensions
ropesim run mooring_chain -o "$runs/mooring_chain" -q
ropesim frames "$runs/mooring_chain" --overlay --times 60,62,64,66,68 --width 760 -o "$out/mooring_chain.png" -q
ropesim animate "$runs/mooring_chain" --start 50 --end 70 --speed 2 --fps 10 --size 480 \
    -o "$out/mooring_chain.gif" -q
ropesim plot "$runs/mooring_chain" -o "$out/mooring_chain_plot.png" -q
# the float drawn down as the current comes in, and the beam's first half swing
ropesim run buoy_tether -o "$runs/buoy_tether" -q
ropesim frames "$runs/buoy_tether" --overlay --times 0,30,45,60,75,90,120,360 --width 480 \
    -o "$out/buoy_tether.png" -q
ropesim plot "$runs/buoy_tether" -o "$out/buoy_tether_plot.png" -q
ropesim run cantilever_beam -o "$runs/cantilever_beam" -q
ropesim frames "$runs/cantilever_beam" --overlay --times 0,0.1,0.2,0.3,0.44 --width 760 \
    -o "$out/cantilever_beam.png" -q
ropesim plot "$runs/cantilever_beam" -o "$out/cantilever_beam_plot.png" -q

# the systems of lines: the clump weight's drop and bounce, the driven spar (seen from the side, where the chains
# lift and lay down), the free spar held still by the current from its static start, and the sling load's swing (from the side) and turn (in 3-D)
ropesim run clump_weight -o "$runs/clump_weight" -q
ropesim frames "$runs/clump_weight" --overlay --times 0,0.2,0.4,0.6,0.8,1.0 --width 640 -o "$out/clump_weight.png" -q
ropesim animate "$runs/clump_weight" --speed 0.5 --end 2 --fps 20 --size 400 -o "$out/clump_weight.gif" -q
ropesim plot "$runs/clump_weight" -o "$out/clump_weight_plot.png" -q
ropesim run spread_mooring -o "$runs/spread_mooring" -q
ropesim frames "$runs/spread_mooring" --times 60 --width 760 -o "$out/spread_mooring.png" -q
ropesim animate "$runs/spread_mooring" --view xy --speed 10 --fps 10 --size 400 -o "$out/spread_mooring.gif" -q
ropesim plot "$runs/spread_mooring" -o "$out/spread_mooring_plot.png" -q
ropesim run spread_mooring_free -o "$runs/spread_mooring_free" -q
ropesim frames "$runs/spread_mooring_free" --overlay --view xy --times 0,600 --width 760 \
    -o "$out/spread_mooring_free.png" -q
ropesim animate "$runs/spread_mooring_free" --view xy --speed 60 --fps 5 --size 400 \
    -o "$out/spread_mooring_free.gif" -q
ropesim plot "$runs/spread_mooring_free" -o "$out/spread_mooring_free_plot.png" -q
ropesim run helicopter_sling -o "$runs/helicopter_sling" -q
ropesim frames "$runs/helicopter_sling" --follow --overlay --view xy --times 0,5,10,15,20,25,30 --width 640 \
    -o "$out/helicopter_sling.png" -q
ropesim animate "$runs/helicopter_sling" --follow --end 48 --speed 4 --fps 5 --size 360 \
    -o "$out/helicopter_sling.gif" -q
ropesim plot "$runs/helicopter_sling" -o "$out/helicopter_sling_plot.png" -q

# the sea: the chain in an irregular sea (a frame sheet over one peak period, a minute animated, its tensions),
# and the floating hose riding its waves (over one period, two periods animated)
ropesim run mooring_chain_waves -o "$runs/mooring_chain_waves" -q
ropesim frames "$runs/mooring_chain_waves" --times 100,102.5,105,107.5 --columns 2 --width 760 \
    -o "$out/mooring_chain_waves.png" -q
ropesim animate "$runs/mooring_chain_waves" --start 60 --end 100 --speed 4 --fps 10 --size 480 \
    -o "$out/mooring_chain_waves.gif" -q
ropesim plot "$runs/mooring_chain_waves" -o "$out/mooring_chain_waves_plot.png" -q
ropesim run floating_hose -o "$runs/floating_hose" -q
ropesim frames "$runs/floating_hose" --times 40,42,44,46 --columns 2 --width 760 -o "$out/floating_hose.png" -q
ropesim animate "$runs/floating_hose" --start 40 --end 56 --speed 2 --fps 10 --size 480 \
    -o "$out/floating_hose.gif" -q
ropesim plot "$runs/floating_hose" -o "$out/floating_hose_plot.png" -q
du -ch "$out"/* | tail -1
