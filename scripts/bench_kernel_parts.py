"""Where the plain stage's time goes against the yardstick: the splitting loop with the blow-up check and the drag-loss
work term each switched off.

Same towed rope and yardstick as ``scripts/bench_kernel.py``. ropesim's loop (:func:`ropesim.integrate.splitting.advance_splitting` on its plain stage)
is called directly three ways, interleaved with the yardstick in one process:

- as run (blow-up check every 64 steps, the drag loss booked in every kick);
- without the blow-up check (and so without forming the drag loss for it);
- without the check and without the kick's work term (the loop a scene without drag runs).

The switched-off variants are for measuring only: without the work term the ledger's drag loss is not kept.

    python scripts/bench_kernel_parts.py [--sizes 21,60,1000] [--repeats 7] [--work 2e7]
"""

from __future__ import annotations

import argparse

import numpy as np
from rich.console import Console
from rich.table import Table

from bench_kernel import G, K, L0, M, V, drag_factors, yardstick
from benchlib import interleaved, load_note, median, stepper_for, towed_scene

NEVER = 2 ** 62   # a check or frame interval no run reaches


def contenders(n: int, steps: int) -> dict:
    """name -> a call that advances its own copy of the towed rope ``steps`` steps."""
    out = {}
    scene = towed_scene(n, "symplectic_euler", steps * 100)
    ref = stepper_for(scene)
    h = ref.grid.dt
    decay, gain = drag_factors(h)
    x, v, f = ref.x.copy(), ref.v.copy(), np.zeros((2, n + 1))
    x0, done = x[:, 0].copy(), [0]

    def yard():
        yardstick(x, v, f, steps, h, K, L0, 1.0 / M, G, decay, gain, x0, V, done[0] * h)
        done[0] += steps

    out["yardstick"] = yard
    from ropesim.integrate.base import Schedule

    for name, check_every, work in (("ropesim as run", 64, True), ("no blow-up check", NEVER, True),
                                    ("no check, no work term", NEVER, False)):
        st = stepper_for(scene)
        plain, m = st.plain._replace(has_drag=work), st.model

        def run(st=st, plain=plain, m=m, check_every=check_every):
            st.loop(st.bundle, st.kicks, plain, st.general, st.held, m.mass, m.params, st.limits,
                    Schedule(st.step, steps, NEVER, h, NEVER, check_every), st.new_frames(0), st.bodies)
            st.step += steps

        run()   # compile this flag combination
        out[name] = run
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="21,60,1000")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--work", type=float, default=2e7, help="node-steps per timed call (default 2e7)")
    args = parser.parse_args()
    table = Table(title=f"Towed rope, symplectic Euler: ns per step (median of {args.repeats} interleaved rounds)")
    table.add_column("N", justify="right")
    names = None
    rows = []
    for n in (int(s) for s in args.sizes.split(",")):
        steps = max(10, int(args.work / n))
        calls = contenders(n, steps)
        times = interleaved(calls, args.repeats)
        names = list(calls)
        yard = median(times["yardstick"]) / steps
        rows.append([str(n)] + [f"{median(times[k]) / steps * 1e9:,.1f} ({yard / (median(times[k]) / steps):.0%})"
                                for k in names])
    for name in names:
        table.add_column(name + " (of yardstick)", justify="right")
    for row in rows:
        table.add_row(*row)
    Console().print(table)
    Console().print(load_note())


if __name__ == "__main__":
    main()
