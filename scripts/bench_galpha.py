"""galpha against sdirk2 on mooring_chain: error, Newton iterations, factorisations and kernel time per step size.

    python scripts/bench_galpha.py [--t-end 30] [--methods galpha,sdirk2] [--dts 0.2,0.1,0.05,0.025,0.0125]

Each run's final positions are compared with rk4 at 0.5 ms (the largest node distance [m]); the kernel time is
one warmed-up run's (compilation excluded). The measurement behind the choice of generalized-alpha
(docs/background/accuracy.md, "Moorings at the sea's time scale").
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import ropesim
from ropesim.analysis.accuracy import run_once

SCENE = Path(__file__).resolve().parent.parent / "scenarios" / "mooring_chain.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=30.0)
    parser.add_argument("--methods", default="galpha,sdirk2")
    parser.add_argument("--dts", default="0.2,0.1,0.05,0.025,0.0125")
    args = parser.parse_args()
    scene = ropesim.load_scene(SCENE, [f"integrator.t_end={args.t_end:g}"])
    reference = run_once(scene, "rk4", 0.0005).x
    print(f"{'method':8} {'dt [s]':>8} {'status':>10} {'max error [m]':>14} {'Newton its':>11} {'kernel [s]':>10}")
    for method in args.methods.split(","):
        for dt in (float(d) for d in args.dts.split(",")):
            r = run_once(scene, method, dt)
            ok = r.status == "completed"
            err = float(np.max(np.linalg.norm(r.x - reference, axis=0))) if ok else float("nan")
            print(f"{method:8} {dt:8.4g} {r.status[:10]:>10} {err:14.3e} {r.force_evaluations:11d} "
                  f"{min(r.wall_times):10.3f}")


if __name__ == "__main__":
    main()
