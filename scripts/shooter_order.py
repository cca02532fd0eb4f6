"""What limits the order of convergence on the string shooter: measure it and draw docs/images/accuracy_shooter_order.png.

Three versions of shooter_medium over 0.5 s, each method over a ladder of dt, errors against RK4 at dt_min / 16
(checked against dt_min / 8):

1. as shipped: the box's and guides' forces switch on and off sharply as nodes cross their edges;
2. smoothed (thrower.edge_width = guides[].edge_width = W: the forces fade in over W metres), but with the
   contacts' velocity-dependent forces evaluated in the splitting schemes' kicks at the starting velocity;
3. smoothed, with the nodes touching the box or a circle kicked exactly (ropesim.contact; the default for
   smoothed scenes).

    python scripts/shooter_order.py [--width 0.2] [--out docs/images/accuracy_shooter_order.png]

Prints each method's fitted order per version and writes a CSV beside the figure.
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

import ropesim
from ropesim.analysis.accuracy import observed_order, run_once

METHODS = ("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2")
DTS = (0.004, 0.002, 0.001, 0.0005, 0.00025)


def versions(width: float) -> dict[str, tuple[list[str], bool | None]]:
    smooth = [f"thrower.edge_width={width}", f"guides.0.edge_width={width}", f"guides.1.edge_width={width}"]
    return {"sharp edges (as shipped)": ([], None),
            f"edges smoothed over {width:g} m, contact damping in plain kicks": (smooth, False),
            f"edges smoothed over {width:g} m, touching nodes kicked exactly": (smooth, True)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=float, default=0.2)
    parser.add_argument("--t-end", type=float, default=0.5)
    parser.add_argument("--out", type=Path, default=Path("docs/images/accuracy_shooter_order.png"))
    args = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = []
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharey=True, constrained_layout=True)
    for ax, (title, (sets, exact)) in zip(axes, versions(args.width).items()):
        scene = ropesim.load_scene(Path(__file__).resolve().parent.parent / "scenarios/shooter_medium.toml",
                                   [f"integrator.t_end={args.t_end}", *sets])
        ref = run_once(scene, "rk4", min(DTS) / 16)
        check = run_once(scene, "rk4", min(DTS) / 8)
        ref_diff = float(np.max(np.linalg.norm(ref.x - check.x, axis=0)))
        print(f"{title}: reference refinements differ by {ref_diff:.2e} m")
        for method in METHODS:
            errs = []
            for dt in DTS:
                r = run_once(scene, method, dt, exact_contacts=exact)
                err = float(np.max(np.linalg.norm(r.x - ref.x, axis=0))) if r.status == "completed" else np.nan
                errs.append(err)
                rows.append({"version": title, "method": method, "dt": dt, "status": r.status, "error_max_m": err,
                             "reference_difference_m": ref_diff})
            order, used = observed_order(DTS, errs, [np.isfinite(e) for e in errs])
            finite = [e for e in errs if np.isfinite(e)]
            converges = len(finite) >= 2 and finite[-1] < finite[0] / 4
            label = f"{method} ({order:.2f})" if converges else f"{method} (no convergence)"
            print(f"  {method:17s} order {order:5.2f}  errors " + " ".join(f"{e:.2e}" for e in errs))
            ok = [(d, e) for d, e in zip(DTS, errs) if np.isfinite(e)]
            if ok:
                ax.loglog(*zip(*ok), "o-", label=label)
        ax.axhline(ref_diff, color="grey", ls=":", lw=1)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("dt [s]")
        ax.set_xticks(DTS, [f"{d:g}" for d in DTS])
        ax.minorticks_off()
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, title="method (fitted order)", title_fontsize=7)
    axes[0].set_ylabel(f"largest node position error at t = {args.t_end:g} s [m]")
    fig.suptitle("shooter_medium: what limits the order (dotted: the reference's own uncertainty)")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=100)
    with open(args.out.with_suffix(".csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"written: {args.out} and {args.out.with_suffix('.csv')}")


if __name__ == "__main__":
    main()
