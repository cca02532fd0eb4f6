#!/usr/bin/env bash
# Regenerate the figures and tables of the docs' "Accuracy and stability" page (a few minutes on 2 cores):
#   docs/images/accuracy_helicopter.png   work-precision, smooth towed rope (orders 1, 2, 4, 4, 4, 2)
#   docs/images/accuracy_stiff.png        work-precision, k = 1e8 N/m over 10 s: where the stiff integrator wins
#   docs/images/stability_helicopter.png  stable/unstable map against the predicted bounds, k = 5e3 .. 5e7
#   docs/images/stability_shooter.png     the same on the string shooter (contacts, explicit damping)
#   docs/images/accuracy_shooter_order.png  what limits the order on the shooter (scripts/shooter_order.py)
# Tables (CSV) go to runs/figures/ (OUT=... to change).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-runs/figures}
images=docs/images
mkdir -p "$out" "$images"

ropesim accuracy scenarios/helicopter_uniform.toml --set integrator.t_end=1 \
  --dts 0.008,0.004,0.002,0.001,0.0005,0.00025 --out "$out/accuracy-helicopter"
cp "$out/accuracy-helicopter/accuracy.png" "$images/accuracy_helicopter.png"

ropesim accuracy scenarios/helicopter_uniform.toml --set rope.stiffness=1e8 --set integrator.t_end=10 \
  --methods verlet,pefrl,rk4,sdirk2 --dts 0.05,0.02,0.01,0.005,0.0002,0.0001,0.00005 --repeats 1 \
  --out "$out/accuracy-stiff"
cp "$out/accuracy-stiff/accuracy.png" "$images/accuracy_stiff.png"

ropesim stability scenarios/helicopter_uniform.toml --k 5000,500000,50000000 --out "$out/stability-helicopter"
cp "$out/stability-helicopter/stability.png" "$images/stability_helicopter.png"

ropesim stability scenarios/shooter_medium.toml --out "$out/stability-shooter"
cp "$out/stability-shooter/stability.png" "$images/stability_shooter.png"

python scripts/shooter_order.py --out "$images/accuracy_shooter_order.png"
mv "$images/accuracy_shooter_order.csv" "$out/shooter_order.csv"
