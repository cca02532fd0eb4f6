"""Kernel speed before and after a change, in one run: this checkout against another git revision.

The other revision is checked out into a temporary git worktree; each round runs the same timing probe once in
each tree (a fresh process each, alternating, so both see the same machine load). A probe times a few calls of
each case and keeps the fastest (load only ever adds time); the table shows the median over rounds of each
tree's time and the median of the per-round ratios. Compilation is excluded (each probe warms its
integrator up first; each tree has its own Numba cache). The probe speaks both the integrator contract
(``ropesim.integrate.methods.make_integrator``) and the older ``ropesim.run.Stepper``.

    python scripts/bench_compare.py BASE_REV [--rounds 5] [--cases towed21,towed1000,shooter]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from rich.console import Console
from rich.table import Table

ROOT = Path(__file__).resolve().parent.parent

PROBE = r"""
import json, sys, time
import ropesim
from ropesim.model.build import build
try:
    from ropesim.integrate.grid import TimeGrid
    from ropesim.integrate.methods import make_integrator
except ImportError:   # before the integrator contract
    from ropesim.run import Stepper, TimeGrid
    def make_integrator(model, grid, name):
        return Stepper(model, name, grid)

cases = json.loads(sys.argv[1])
out = {}
for key, (scene_file, sets, method, steps, repeats) in cases.items():
    dt = ropesim.load_scene(scene_file, sets).integrator.dt   # the grid must hold every timed call
    scene = ropesim.load_scene(scene_file, sets + [f"integrator.method={method}",
                                                   f"integrator.t_end={steps * (repeats + 2) * dt!r}"])
    model, grid = build(scene), TimeGrid.of(scene)
    it = make_integrator(model, grid, method)
    it.warm_up()
    it.advance(steps)
    best = []
    for _ in range(repeats):
        start = time.perf_counter()
        it.advance(steps)
        best.append(time.perf_counter() - start)
    out[key] = min(best) / steps   # the least disturbed call: on a shared machine load only ever adds time
print(json.dumps(out))
"""

SCEN = str(ROOT / "scenarios")
CASES = {   # name: (scene, --set, method, steps per timed call, timed calls)
    "towed N=21 symplectic_euler": (f"{SCEN}/helicopter_uniform.toml", [], "symplectic_euler", 200_000, 9),
    "towed N=60 symplectic_euler": (f"{SCEN}/helicopter_uniform.toml", ["rope.nodes=60"], "symplectic_euler",
                                    100_000, 9),
    "towed N=1000 symplectic_euler": (f"{SCEN}/helicopter_uniform.toml", ["rope.nodes=1000"], "symplectic_euler",
                                      5_000, 9),
    "helicopter_mass pefrl": (f"{SCEN}/helicopter_mass.toml", [], "pefrl", 50_000, 9),
    "helicopter_mass rk4": (f"{SCEN}/helicopter_mass.toml", [], "rk4", 20_000, 9),
    "helicopter_mass sdirk2": (f"{SCEN}/helicopter_mass.toml", [], "sdirk2", 2_000, 9),
    # sdirk2: 11 calls of 400 steps stay inside the 4.86 s its Newton solve survives the box's sharp edges
    **{f"shooter_high {m}": (f"{SCEN}/shooter_high.toml", [], m, 400 if m == "sdirk2" else 20_000, 9)
       for m in ("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2")},
    # the sea's scenes: the free surface's fractions, the waves' kinematics, the Newton matrix's sea blocks
    "mooring_chain_waves sdirk2": (f"{SCEN}/mooring_chain_waves.toml", [], "sdirk2", 400, 9),
    "floating_hose sdirk2": (f"{SCEN}/floating_hose.toml", [], "sdirk2", 1_000, 9),
}


def probe(tree: Path, cache: str, cases: dict) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=cache)
    proc = subprocess.run([sys.executable, "-c", PROBE, json.dumps(cases)], capture_output=True, text=True, env=env,
                          cwd=tree, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", help="the git revision to compare with (e.g. HEAD~3, a tag)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--cases", default="", help="comma-separated substrings of case names (default: all)")
    args = parser.parse_args()
    wanted = [c for c in args.cases.split(",") if c]
    cases = {k: v for k, v in CASES.items() if not wanted or any(w in k for w in wanted)}
    with tempfile.TemporaryDirectory(prefix="ropesim-bench-") as tmp:
        base = Path(tmp) / "base"
        subprocess.run(["git", "worktree", "add", "--detach", "-q", str(base), args.base], cwd=ROOT, check=True)
        try:
            caches = {"base": tempfile.mkdtemp(dir=tmp), "this": tempfile.mkdtemp(dir=tmp)}
            times: dict[str, dict[str, list]] = {"base": {k: [] for k in cases}, "this": {k: [] for k in cases}}
            for _ in range(args.rounds):
                for who, tree in (("base", base), ("this", ROOT)):
                    for k, t in probe(tree, caches[who], cases).items():
                        times[who][k].append(t)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=ROOT, check=False)
    table = Table(title=f"Time per step, median of {args.rounds} alternating rounds: {args.base} against this "
                        f"checkout")
    for col in ("case", f"{args.base} [us]", "this [us]", "this / base"):
        table.add_column(col, justify="left" if col == "case" else "right")
    for k in cases:
        b, t = times["base"][k], times["this"][k]
        ratio = statistics.median(x / y for x, y in zip(t, b))
        table.add_row(k, f"{statistics.median(b) * 1e6:.3f}", f"{statistics.median(t) * 1e6:.3f}", f"{ratio:.3f}")
    Console(width=120).print(table)


if __name__ == "__main__":
    main()
