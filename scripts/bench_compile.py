"""First-run compile time of each integrator: one fresh process and one empty Numba cache per method, one scene.

For each method, ``python -m ropesim run SCENE --set integrator.method=M`` runs twice: with an empty
``NUMBA_CACHE_DIR`` (cold: everything the run needs compiles) and again with the cache that left (warm:
everything loads). Both are whole processes, Python's start-up included; the table gives their wall and CPU
times, the difference (what compiling costs a first run) and the summary's ``compile_time_s`` (the cold run's
"compile or cache load" of the integrator's loop, as `ropesim run` prints it). The scene runs a short end time
so that compiling dominates; every method runs the same scene.

The machine is shared, so a wall time alone is not trusted: the CPU time (user + system) of the process is
given beside it, and with ``--against REV`` the same measurements run for another git revision (checked out
in a temporary worktree) interleaved with this checkout's, method by method and round by round, so both see
the same load; the last column is this checkout's first-run compile CPU time over REV's (median over rounds).

    python scripts/bench_compile.py [--scene helicopter_mass] [--methods rk4,sdirk2] [--rounds 1] [--against REV]
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
METHODS = ("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2")


def timed_run(tree: Path, scene: str, method: str, t_end: float, cache: str, out: str) -> dict:
    """One `ropesim run` of ``tree``'s code in a new process: wall and CPU seconds, and its summary's
    compile_time_s."""
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=cache)
    cmd = [sys.executable, "-m", "ropesim", "run", scene, "--set", f"integrator.method={method}", "--set",
           f"integrator.t_end={t_end!r}", "--out", out, "--quiet", "--force"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    summary = json.loads((Path(out) / "summary.json").read_text())
    return {"wall": wall, "cpu": cpu, "compile": summary["compile_time_s"]}


def measure(tree: Path, scene: str, method: str, t_end: float, work: Path) -> dict:
    """Cold then warm run of ``method`` with a new, empty cache."""
    cache = tempfile.mkdtemp(prefix="cache-", dir=work)
    out = str(work / "run")
    cold = timed_run(tree, scene, method, t_end, cache, out)
    warm = timed_run(tree, scene, method, t_end, cache, out)
    return {"cold": cold, "warm": warm, "first_wall": cold["wall"] - warm["wall"],
            "first_cpu": cold["cpu"] - warm["cpu"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="helicopter_mass", help="a built-in scene's name or a scene file")
    parser.add_argument("--methods", default=",".join(METHODS), help="comma-separated (default: all)")
    parser.add_argument("--t-end", type=float, default=0.05, help="the runs' end time [s] (default 0.05)")
    parser.add_argument("--rounds", type=int, default=1, help="measurements per method (the median is shown)")
    parser.add_argument("--against", metavar="REV", help="also measure this git revision, interleaved")
    parser.add_argument("--json", metavar="FILE", help="also write every measurement to FILE")
    args = parser.parse_args()
    methods = [m for m in args.methods.split(",") if m]
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))   # killed: still remove the temporary worktree
    results: dict[str, dict[str, list[dict]]] = {}
    with tempfile.TemporaryDirectory(prefix="ropesim-compile-") as tmp:
        work = Path(tmp)
        trees = {"this": ROOT}
        if args.against:
            base = work / "base"
            subprocess.run(["git", "worktree", "add", "--detach", "-q", str(base), args.against], cwd=ROOT,
                           check=True)
            trees = {args.against: base, "this": ROOT}
        try:
            for r in range(args.rounds):
                for method in methods:
                    order = list(trees.items()) if r % 2 == 0 else list(trees.items())[::-1]
                    for who, tree in order:
                        m = measure(tree, args.scene, method, args.t_end, work)
                        results.setdefault(who, {}).setdefault(method, []).append(m)
                        print(f"round {r + 1} {who:>10} {method:<16} cold {m['cold']['wall']:6.1f} s wall "
                              f"{m['cold']['cpu']:6.1f} s CPU, warm {m['warm']['wall']:5.2f} s wall", flush=True)
        finally:
            if args.against:
                subprocess.run(["git", "worktree", "remove", "--force", str(trees[args.against])], cwd=ROOT,
                               check=False)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))

    def med(who: str, method: str, *keys: str) -> float:
        values = []
        for m in results[who][method]:
            for k in keys:
                m = m[k]
            values.append(m)
        return statistics.median(values)

    for who in trees:
        table = Table(title=f"First run of {args.scene} (t_end = {args.t_end:g} s), {who}: median of {args.rounds}")
        for col in ("method", "cold wall [s]", "cold CPU [s]", "warm wall [s]", "first-run compile\nwall [s]",
                    "first-run compile\nCPU [s]", "compile_time_s\n(summary)"):
            table.add_column(col, justify="left" if col == "method" else "right")
        for method in methods:
            table.add_row(method, *(f"{med(who, method, *k):.2f}" for k in (
                ("cold", "wall"), ("cold", "cpu"), ("warm", "wall"), ("first_wall",), ("first_cpu",),
                ("cold", "compile"))))
        Console(width=140).print(table)
    if args.against:
        table = Table(title=f"First-run compile CPU time: this checkout against {args.against}")
        for col in ("method", f"{args.against} [s]", "this [s]", "this / base"):
            table.add_column(col, justify="left" if col == "method" else "right")
        for method in methods:
            base, this = results[args.against][method], results["this"][method]
            ratio = statistics.median(t["first_cpu"] / b["first_cpu"] for t, b in zip(this, base))
            table.add_row(method, f"{med(args.against, method, 'first_cpu'):.2f}",
                          f"{med('this', method, 'first_cpu'):.2f}", f"{ratio:.2f}")
        Console(width=140).print(table)


if __name__ == "__main__":
    main()
