"""The helicopter claim as a picture: the rope's angle along its length in steady state, simulated vs exact.

    python scripts/plot_towed_angles.py RUN_DIR [RUN_DIR ...] --out docs/images/claims_helicopter_angles.png

For each towed-rope run folder (made by `ropesim run`; see scripts/make_claim_figures.sh) it draws the angle from
vertical of every segment, from the helicopter down: at the run's last frame (markers), in the exact discrete
steady state of ropesim.analysis.towed (line), and at the write-up's t_f = 3 s if the run passed it (dotted).
Reads the run folders only; never re-runs a scene.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from ropesim.model.build import build
from ropesim.io.runfolder import RunFolderError
from ropesim.io.trajectory import Trajectory
from ropesim.analysis.towed import exact_steady_state, segment_angles, towed_end

WRITE_UP_T_END = 3.0  # s: the write-up's t_f for the helicopter


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="towed-rope run folders")
    parser.add_argument("--out", type=Path, required=True, help="PNG to write")
    args = parser.parse_args(argv)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 4.8), layout="constrained")
    for run, colour in zip(args.runs, plt.rcParams["axes.prop_cycle"].by_key()["color"]):
        try:
            traj = Trajectory.open(run)
        except RunFolderError as exc:
            sys.exit(f"plot_towed_angles.py: {exc}")
        model = build(traj.scene)
        if towed_end(traj.scene) is None:
            sys.exit(f"plot_towed_angles.py: {run}: not a towed rope (an open line held at one end)")
        steady = exact_steady_state(model)
        if towed_end(traj.scene) != 0:
            steady = steady[::-1]
        exact = segment_angles(model, steady)
        s = (np.arange(len(exact)) + 0.5) * traj.scene.rope.segment_length  # rest length from the top [m]
        t_end = float(traj.t[-1])
        ax.plot(s, exact, color=colour, lw=1.5, label=f"{traj.scene.name}: exact steady state")
        ax.plot(s, segment_angles(model, np.asarray(traj.x[-1])), "o", color=colour, ms=4,
                label=f"{traj.scene.name}: simulated, t = {t_end:g} s")
        if t_end > WRITE_UP_T_END:
            k = int(np.argmin(np.abs(np.asarray(traj.t) - WRITE_UP_T_END)))
            ax.plot(s, segment_angles(model, np.asarray(traj.x[k])), ":", color=colour, lw=1.2,
                    label=f"{traj.scene.name}: t = {float(traj.t[k]):g} s (write-up's t_f)")
    ax.set_xlabel("position along the rope from the helicopter (rest length) [m]")
    ax.set_ylabel("segment angle from vertical, trailing [deg]")
    ax.set_title("Towed rope: angle along its length in steady state", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{args.out.name}.", suffix=".tmp", dir=args.out.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, format="png", dpi=120)
        os.replace(tmp, args.out)
    finally:
        Path(tmp).unlink(missing_ok=True)
    print(f"plot_towed_angles.py: wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
