"""A newcomer's first run: CPU seconds with an empty compile cache, this checkout against another revision.

Three measurements, each in new processes, every cold case with its own empty ``NUMBA_CACHE_DIR``:

- **first step**: ``ropesim run SCENE --set integrator.t_end=DT`` (one step, its frames and summary written)
  for every built-in scene with its own method, and helicopter_mass first. The CPU time (user + system) of the
  whole process is what a first run costs before its first step; the same command again on the cache it
  left (warm) shows what is left once nothing compiles.
- **accuracy**: ``ropesim accuracy helicopter_mass`` with every method (one repeat), cold and warm.
- **warm whole process**: ``ropesim run helicopter_uniform`` with a warm cache against a minimal Numba
  script doing the same steps (the write-up's towed rope, 3000 symplectic Euler steps, a frame every 10 saved
  to an .npz), paired: the two alternate, round by round, and the ratio is the median of the per-round ratios
  of wall time (and of CPU time, steadier on a shared machine). ``--warm-only`` measures only this.

With ``--against REV`` the first two run for that revision too (checked out in a temporary worktree),
interleaved case by case with this checkout so both see the same machine load; the tables give both and
their ratio. CPU time is kept beside wall time because the machine is shared: a loaded machine stretches wall
time far more than CPU time.

    python scripts/bench_first_run.py [--against REV] [--rounds 1] [--scenes a,b@galpha]
        [--warm-only] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

ROOT = Path(__file__).resolve().parent.parent

MINIMAL = '''
import sys
import numpy as np
from numba import njit

@njit(cache=True)
def run(x, v, steps, h, k, l0, m, g, b, vx, every, out):
    n = x.shape[1]
    f = np.zeros((2, n + 1))
    decay = np.exp(-b / m * h)
    gain = (1.0 - decay) * m / b
    frame = 0
    for s in range(steps):
        for i in range(n - 1):
            d0 = x[0, i + 1] - x[0, i]
            d1 = x[1, i + 1] - x[1, i]
            c = k * (1.0 - l0 / np.sqrt(d0 * d0 + d1 * d1))
            f[0, i + 1] = c * d0
            f[1, i + 1] = c * d1
        for i in range(1, n):
            v[0, i] = decay * v[0, i] + gain * (f[0, i + 1] - f[0, i]) / m
            v[1, i] = decay * v[1, i] + gain * ((f[1, i + 1] - f[1, i]) / m - g)
            x[0, i] += h * v[0, i]
            x[1, i] += h * v[1, i]
        x[0, 0] = vx * (s + 1) * h
        if (s + 1) % every == 0:
            out[frame] = x
            frame += 1

n, steps, every = 21, 3000, 10
x = np.zeros((2, n)); x[1] = -0.5 * np.arange(n)
v = np.zeros((2, n)); v[0] = 8.0
out = np.zeros((steps // every, 2, n))
run(x, v, steps, 0.001, 5000.0, 0.5, 5.0, 9.81, 5.0, 8.0, every, out)
np.savez(sys.argv[1], x=out)
'''


def timed(cmd: list[str], env: dict, cwd: Path) -> dict:
    """Wall and CPU seconds of one run of ``cmd`` (which must succeed)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.strip()[-2000:]}")
    return {"wall": wall, "cpu": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)}


def cold_and_warm(tree: Path, args: list[str], work: Path) -> dict:
    """``python -m ropesim ARGS`` of ``tree``'s code with a new empty cache, then again on what it left."""
    cache = tempfile.mkdtemp(prefix="cache-", dir=work)
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=cache, MPLBACKEND="Agg")
    cmd = [sys.executable, "-m", "ropesim", *args]
    return {"cold": timed(cmd, env, work), "warm": timed(cmd, env, work)}


def first_step(scene: str, out: Path) -> list[str]:
    """One step of ``scene``, or of ``NAME@METHOD``: scene NAME with ``--set integrator.method=METHOD``."""
    from ropesim import load_scene

    scene, _, method = scene.partition("@")
    dt = load_scene(scene).integrator.dt
    chosen = ["--set", f"integrator.method={method}"] if method else []
    return ["run", scene, *chosen, "--set", f"integrator.t_end={dt!r}", "--out", str(out), "--quiet", "--force"]


def accuracy(out: Path) -> list[str]:
    return ["accuracy", "helicopter_mass", "--repeats", "1", "--out", str(out)]


def warm_process(rounds: int, work: Path) -> dict:
    """Paired warm runs of `ropesim run helicopter_uniform` and the minimal script: wall and CPU per round."""
    script = work / "minimal.py"
    script.write_text(MINIMAL)
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=tempfile.mkdtemp(prefix="cache-", dir=work),
               MPLBACKEND="Agg", PYTHONPYCACHEPREFIX=str(work / "pycache"))
    env.pop("PYTHONDONTWRITEBYTECODE", None)   # warm means bytecode too, as an installed package has it
    ropesim = [sys.executable, "-m", "ropesim", "run", "helicopter_uniform", "--out", str(work / "uniform"),
               "--quiet", "--force"]
    minimal = [sys.executable, str(script), str(work / "minimal.npz")]
    timed(ropesim, env, work), timed(minimal, env, work)   # compile both
    rows = []
    for r in range(rounds):
        pair = [("ropesim", ropesim), ("minimal", minimal)]
        got = {name: timed(cmd, env, work) for name, cmd in (pair if r % 2 == 0 else pair[::-1])}
        rows.append(got)
    return {"rounds": rows, "ratio": statistics.median(r["ropesim"]["wall"] / r["minimal"]["wall"] for r in rows),
            "cpu_ratio": statistics.median(r["ropesim"]["cpu"] / r["minimal"]["cpu"] for r in rows)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", metavar="REV", help="also measure this git revision, interleaved")
    parser.add_argument("--rounds", type=int, default=1, help="cold measurements per case (the median is shown)")
    parser.add_argument("--scenes", help="comma-separated built-in scenes, NAME@METHOD for another method "
                                         "(default: all)")
    parser.add_argument("--warm-rounds", type=int, default=15, help="paired rounds of the warm whole process")
    parser.add_argument("--warm-only", action="store_true", help="only the warm whole process (no cold cases)")
    parser.add_argument("--json", metavar="FILE", help="also write every measurement to FILE")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT))
    from ropesim.scene.builtin import builtin_names

    scenes = args.scenes.split(",") if args.scenes else builtin_names()
    scenes = ["helicopter_mass"] + [s for s in scenes if s != "helicopter_mass"]
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))   # killed: still remove the temporary worktree
    results: dict = {"first_step": {}, "accuracy": {}}
    with tempfile.TemporaryDirectory(prefix="ropesim-first-run-") as tmp:
        work = Path(tmp)
        trees = {"this": ROOT}
        if args.against:
            base = work / "base"
            subprocess.run(["git", "worktree", "add", "--detach", "-q", str(base), args.against], cwd=ROOT,
                           check=True)
            trees = {args.against: base, "this": ROOT}
        try:
            cases = [("first_step", s, first_step(s, work / "run")) for s in scenes]
            cases.append(("accuracy", "helicopter_mass", accuracy(work / "accuracy")))
            for r in range(0 if args.warm_only else args.rounds):
                for kind, name, cmd in cases:
                    order = list(trees.items()) if r % 2 == 0 else list(trees.items())[::-1]
                    for who, tree in order:
                        m = cold_and_warm(tree, cmd, work)
                        results[kind].setdefault(name, {}).setdefault(who, []).append(m)
                        print(f"round {r + 1} {who:>10} {kind:<10} {name:<22} cold {m['cold']['cpu']:6.1f} s CPU "
                              f"({m['cold']['wall']:6.1f} s wall), warm {m['warm']['cpu']:5.2f} s CPU", flush=True)
            if args.warm_rounds > 0:
                results["warm_process"] = warm_process(args.warm_rounds, work)
        finally:
            if args.against:
                subprocess.run(["git", "worktree", "remove", "--force", str(trees[args.against])], cwd=ROOT,
                               check=False)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    report(results, list(trees), args.against)


def report(results: dict, trees: list[str], against: str | None) -> None:
    def med(runs: list[dict], phase: str, key: str) -> float:
        return statistics.median(m[phase][key] for m in runs)

    console = Console(width=150)
    for kind, title in (("first_step", "First step of a first run (empty cache): CPU seconds of the whole process"),
                        ("accuracy", "`ropesim accuracy helicopter_mass`, every method, --repeats 1")):
        if not results[kind]:
            continue
        table = Table(title=title)
        table.add_column("case")
        for who in trees:
            table.add_column(f"{who}\ncold CPU [s]", justify="right")
            table.add_column(f"{who}\ncold wall [s]", justify="right")
            table.add_column(f"{who}\nwarm CPU [s]", justify="right")
        if against:
            table.add_column("this / base\ncold CPU", justify="right")
        for name, by in results[kind].items():
            row = [name]
            for who in trees:
                row += [f"{med(by[who], 'cold', 'cpu'):.1f}", f"{med(by[who], 'cold', 'wall'):.1f}",
                        f"{med(by[who], 'warm', 'cpu'):.2f}"]
            if against:
                row.append(f"{med(by['this'], 'cold', 'cpu') / med(by[against], 'cold', 'cpu'):.2f}")
            table.add_row(*row)
        console.print(table)
    warm = results.get("warm_process")
    if warm is None:
        return
    table = Table(title=f"Warm whole process, helicopter_uniform: {len(warm['rounds'])} paired rounds, medians")
    for col in ("process", "wall [s]", "CPU [s]"):
        table.add_column(col, justify="left" if col == "process" else "right")
    for name in ("ropesim", "minimal"):
        table.add_row(f"{'ropesim run' if name == 'ropesim' else 'minimal Numba script'}",
                      f"{statistics.median(r[name]['wall'] for r in warm['rounds']):.2f}",
                      f"{statistics.median(r[name]['cpu'] for r in warm['rounds']):.2f}")
    table.add_row("ratio (median of rounds)", f"{warm['ratio']:.2f}", f"{warm['cpu_ratio']:.2f}")
    console.print(table)


if __name__ == "__main__":
    main()
