"""A free body's solve per force evaluation (``ropesim.model.bodies.move_bodies``): this checkout's against another
revision's, in one process.

The other revision's ropesim/model/bodies.py is loaded beside this checkout's (it must import against this
checkout's package: its helpers, rotation and fluid modules, unchanged since); each version is called in a
compiled loop on the same model, state and node forces (each with its own revision's parameter bundle), interleaved
rounds, timed in CPU time (steadier than wall time on the shared machine); the table shows each one's median time
per call and the median of the per-round ratios. Scenes: spread_mooring_free (three chains whose tangential
added mass differs from their normal one, in a current) and helicopter_sling (a container on four legs in air).

    python scripts/bench_move_bodies.py a3e4949 [--rounds 7] [--calls 200000]
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "scripts")]   # this checkout's ropesim

from benchlib import load_note, median, median_ratio

SCENES = {"spread_mooring_free": ["initial.shape=lines"], "helicopter_sling": []}


def other_bodies(rev: str, folder: Path):
    """The module ropesim/model/bodies.py of ``rev``, imported as a sibling of this checkout's."""
    source = subprocess.run(["git", "show", f"{rev}:ropesim/model/bodies.py"], cwd=ROOT, check=True,
                            capture_output=True, text=True).stdout
    path = folder / "bodies_other.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("ropesim.model.bodies_other", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def loop_of(move):
    """A compiled loop calling ``move`` (a move_bodies specialised for the scene) n times (with ``moved`` True,
    where the revision's move_bodies takes it)."""
    import numba

    if move.py_func.__code__.co_argcount == 13:
        @numba.njit(_nrt=False)
        def loop(n, x, v, acc, inv_mass, around, flow, bodies, pose, twist, out):
            s = 0.0
            for _ in range(n):
                s += move(x, v, acc, inv_mass, around, 9.81, flow, bodies, pose, twist, out, 0.5, True)
            return s
    else:
        @numba.njit(_nrt=False)
        def loop(n, x, v, acc, inv_mass, around, flow, bodies, pose, twist, out):
            s = 0.0
            for _ in range(n):
                s += move(x, v, acc, inv_mass, around, 9.81, flow, bodies, pose, twist, out, 0.5)
            return s
    return loop


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rev", help="the other revision (git)")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--calls", type=int, default=200000)
    args = parser.parse_args(argv)
    import ropesim
    from ropesim.model import jit, terms
    from ropesim.model.bodies import bodies_bundle, move_bodies
    from ropesim.model.build import build

    with tempfile.TemporaryDirectory() as folder:
        other = other_bodies(args.rev, Path(folder))
        print(f"| scene | {args.rev} | this checkout | {args.rev} / this (median of per-round ratios) |")
        print("| --- | --- | --- | --- |")
        for name, sets in SCENES.items():
            model = build(ropesim.load_scene(name, sets))
            terms.bodies_bundle = other.bodies_bundle   # the other revision's bundle, for its move_bodies
            try:
                theirs = build(ropesim.load_scene(name, sets)).params.bodies
            finally:
                terms.bodies_bundle = bodies_bundle
            p = model.params
            bundles = {"other": theirs, "this": p.bodies}
            rng = np.random.default_rng(1)
            x = model.x0.copy()
            v, acc = rng.normal(size=x.shape) * 0.1, rng.normal(size=x.shape)
            pose, twist = model.body_pose0.copy(), np.full((6, model.body_pose0.shape[1]), 0.01)
            out = np.zeros((6, pose.shape[1]))
            loops = {"other": loop_of(jit.specialise(other.move_bodies, model.switches)),
                     "this": loop_of(jit.specialise(move_bodies, model.switches))}
            walls: dict[str, list[float]] = {k: [] for k in loops}
            for key, loop in loops.items():   # compile
                loop(10, x, v, acc.copy(), p.inv_mass, p.neighbours, p.flow, bundles[key], pose, twist, out)
            for _ in range(args.rounds):
                for key, loop in loops.items():
                    started = time.thread_time()
                    loop(args.calls, x, v, acc.copy(), p.inv_mass, p.neighbours, p.flow, bundles[key], pose, twist,
                         out)
                    walls[key].append((time.thread_time() - started) / args.calls)
            print(f"| {name} | {median(walls['other']) * 1e9:.0f} ns | {median(walls['this']) * 1e9:.0f} ns | "
                  f"{median_ratio(walls['other'], walls['this']):.2f} |", flush=True)
    print(f"\n{load_note()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
