"""ropesim against MoorDyn in waves: the chain of MoorDyn's tests/Mooring/wavekin_wave_1.txt, its fairlead held at
the mean water level, in a regular wave (H 6 m, T 10 s) and a JONSWAP sea (Hs 6 m, Tp 10 s, gamma 3.3, 50
components), 60 s each. Prints the fairlead tension's agreement as a Markdown table and draws
docs/images/moordyn_waves.png.

Equal physics is set out in tests/references/moordyn_waves.py: MoorDyn sums the same Airy components at its nodes
(WaveKin = 7, Wheeler-stretched), and ropesim runs with ``[sea] fraction = "moordyn"``, MoorDyn's submerged-fraction
rule. The rows with ropesim's own rule (``"cylinders"``) show what that rule changes.

    pip install -e ".[test]"     # moordyn
    python scripts/compare_moordyn_waves.py [--cases regular,jonswap] [--t-end 60] [--figure PATH]

About 2 minutes on a shared 2-core machine (MoorDyn's RK2 at 1 ms takes most of it), plus compiling.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]   # this checkout's ropesim, not an installed one

from references.moordyn_waves import CASES, agreement, chain, run_moordyn, run_ropesim  # noqa: E402

FIGURE = ROOT / "docs" / "images" / "moordyn_waves.png"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--t-end", type=float, default=None, help="simulated time (s), default each case's")
    parser.add_argument("--figure", type=Path, default=FIGURE)
    args = parser.parse_args()
    names = [n for n in args.cases.split(",") if n]
    line = chain()
    print("| waves | ropesim's fraction rule | RMS difference (N) | of the mean tension | of its std | "
          "largest (N) |")
    print("|---|---|---:|---:|---:|---:|")
    curves = {}
    for name in names:
        case = CASES[name]
        md = run_moordyn(line, case, args.t_end)
        start = md.positions[0]
        for rule in ("moordyn", "cylinders"):
            _, tension = run_ropesim(line, start, case, args.t_end, fraction=rule)
            a = agreement(md.tension, tension)
            print(f"| {name} | {rule} | {a['rms']:.3g} | {100 * a['rms_of_mean']:.2g} % | "
                  f"{100 * a['rms_of_std']:.2g} % | {a['max']:.3g} |")
            curves[name, rule] = tension
        curves[name, "MoorDyn"] = md.tension
        curves[name, "t"] = md.t
        print(f"|  | (MoorDyn: mean {md.tension.mean() / 1e6:.4f} MN, std {md.tension.std() / 1e3:.2f} kN; "
              f"its reported GetLineFairTen against its state: RMS "
              f"{np.sqrt(np.mean((md.reported - md.tension) ** 2)):.3g} N) | | | | |")
    if args.figure:
        draw(names, curves, args.figure)
        print(f"\nfigure: {args.figure.relative_to(ROOT) if args.figure.is_relative_to(ROOT) else args.figure}")


def draw(names, curves, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(names), figsize=(5.5 * len(names), 5.5), sharex=True, squeeze=False)
    for c, name in enumerate(names):
        t, md = curves[name, "t"], curves[name, "MoorDyn"]
        top, bottom = axes[0, c], axes[1, c]
        top.plot(t, md / 1e6, color="black", lw=2.2, label="MoorDyn 2.7 (WaveKin 7, RK2)")
        top.plot(t, curves[name, "moordyn"] / 1e6, color="tab:orange", lw=1.0, label="ropesim, MoorDyn's fraction")
        top.set_title(f"{name}: fairlead tension")
        top.set_ylabel("MN")
        for rule, color in (("moordyn", "tab:orange"), ("cylinders", "tab:blue")):
            bottom.plot(t, (curves[name, rule] - md) / 1e3, color=color, lw=1.0,
                        label=f"ropesim ({rule}) - MoorDyn")
        bottom.set_ylabel("kN")
        bottom.set_xlabel("t (s)")
        top.legend(fontsize=8, loc="lower right")
        bottom.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)


if __name__ == "__main__":
    main()
