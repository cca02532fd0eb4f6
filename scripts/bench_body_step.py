"""Per node, the free-body system of ``bench_systems_moordyn.py`` against one line, and against another revision's
code, in one process and in CPU time.

The per-node part of ``scripts/bench_systems_moordyn.py`` times each run's wall clock, which on the shared machine
swings by more than a free body costs. Here every contender is an integrator built once and stepped by its own
``advance`` (no set-up, no output), restored to the same start before each round, interleaved round by round and
timed by the thread's CPU clock: one line of all the nodes, the three lines held at their fairleads, the three
lines on the free spar with this checkout's code, and the same with another revision's ``ropesim`` package
(extracted by ``git archive`` to a temporary folder and imported under another name, so both compile side by
side). Ratios are medians of per-round ratios; the brackets give their smallest and largest.

    python scripts/bench_body_step.py REV [--segments 20] [--steps 20000] [--rounds 9] [--methods verlet,rk4]
"""

from __future__ import annotations

import argparse
import importlib
import io
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "scripts")]   # this checkout's ropesim

from benchlib import load_note, median, median_ratio


def other_package(rev: str, folder: Path) -> str:
    """``rev``'s ropesim package extracted into ``folder`` as ``ropesim_other`` (its imports are relative);
    returns the name to import."""
    tar = subprocess.run(["git", "archive", rev, "ropesim"], cwd=ROOT, check=True, capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(tar)) as archive:
        archive.extractall(folder, filter="data")
    (folder / "ropesim").rename(folder / "ropesim_other")
    sys.path.insert(0, str(folder))
    return "ropesim_other"


def stepper(package: str, scene: dict, x0=None):
    """A warmed-up integrator of ``package`` (``ropesim`` or the other revision's) for a scene dict, its nodes
    started at x0 (D, N) when given."""
    import tomli_w

    top = importlib.import_module(package)
    build = importlib.import_module(f"{package}.model.build").build
    grid = importlib.import_module(f"{package}.integrate.grid").TimeGrid
    make = importlib.import_module(f"{package}.integrate.methods").make_integrator
    validated = top.scene_from_toml(tomli_w.dumps(scene))
    model = build(validated)
    if x0 is not None:
        model.x0[:] = x0
    out = make(model, grid.of(validated))
    out.warm_up()
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rev", help="the other revision (git)")
    parser.add_argument("--segments", type=int, default=20, help="segments per line")
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--methods", default="verlet,rk4")
    args = parser.parse_args(argv)
    import bench_systems_moordyn as bench
    from references.moordyn_systems import static_positions, system_scene_dict, to_ropesim

    lines = bench.resized_lines(args.segments)
    nodes = 3 * (args.segments + 1)
    x0 = to_ropesim(static_positions("lines", changes={"lines": lines})).T
    with tempfile.TemporaryDirectory() as folder:
        other = other_package(args.rev, Path(folder))
        print(f"| method, step | layout | CPU per node and step | / one line | / held lines | / {args.rev}'s body |")
        print("| --- | --- | --- | --- | --- | --- |")
        for method in args.methods.split(","):
            dt = bench.PER_NODE[method] * 20 / args.segments
            window = args.steps * dt
            kw = {"method": method, "dt": dt, "t_end": window, "interval": window}
            body = system_scene_dict("spar", None, changes={"lines": lines}, **kw)
            held = system_scene_dict("lines", None, start="equilibrium", changes={"lines": lines}, **kw)
            runs = {"one line": stepper("ropesim", bench.single_line(nodes - 1, method, dt, window)),
                    "three lines, held": stepper("ropesim", held),
                    f"on the free body, {args.rev}": stepper(other, body, x0),
                    "on the free body, this checkout": stepper("ropesim", body, x0)}
            starts = {name: run.state() for name, run in runs.items()}
            cpu: dict[str, list[float]] = {name: [] for name in runs}
            for _ in range(args.rounds):
                for name, run in runs.items():
                    run.restore(starts[name])
                    tick = time.thread_time()
                    done = run.advance(args.steps).done
                    cpu[name].append(time.thread_time() - tick)
                    if done != args.steps:
                        raise SystemExit(f"{name}: stopped after {done} steps")
            base = cpu[f"on the free body, {args.rev}"]
            for name, c in cpu.items():
                cells = []
                for ref in (cpu["one line"], cpu["three lines, held"], base):
                    ratios = [a / b for a, b in zip(c, ref)]
                    cells.append(f"{median_ratio(c, ref):.3f} [{min(ratios):.3f}, {max(ratios):.3f}]")
                print(f"| {method}, {dt * 1e3:.3g} ms | {name} | {1e9 * median(c) / (nodes * args.steps):.0f} ns | "
                      + " | ".join(cells) + " |", flush=True)
    print(f"\n{nodes} nodes, {args.steps} steps a run, {args.rounds} rounds; {load_note()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
