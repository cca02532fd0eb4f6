"""How long `ropesim animate` takes to encode a 150-frame GIF and MP4 of a 60-node run (target: under 5 s).

Runs the scene once (not timed), then times, best / median of --repeat:
  - the library call ropesim.render.animate.animate(...) (layout, drawing, encoding, writing), in this process;
  - the whole command `python -m ropesim animate ...` in a fresh process (start-up and imports included).
150 frames: --fps 50 (a GIF rate, 2/100 s a frame) from t = 0 to 2.98 s. Beside each wall time, the CPU time
(user + system, ffmpeg's included) it used: on a shared machine a short job's wall time is stretched by whoever
else is running, its CPU time much less.

    python scripts/bench_animation.py                     # scenarios/shooter_medium.toml, 60 nodes
    python scripts/bench_animation.py --frames 300 --repeat 5
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FPS = 50.0


def cpu_seconds() -> float:
    """User + system CPU time of this process and its finished children [s]."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def timed(fn) -> tuple[float, float]:
    """(wall, CPU) seconds of ``fn()``."""
    wall, cpu = time.perf_counter(), cpu_seconds()
    fn()
    return time.perf_counter() - wall, cpu_seconds() - cpu


def best_and_median(samples: list[tuple[float, float]]) -> str:
    wall = sorted(w for w, _ in samples)
    cpu = sorted(c for _, c in samples)
    return f"{wall[0]:.2f} / {statistics.median(wall):.2f} s (CPU {cpu[0]:.2f} / {statistics.median(cpu):.2f} s)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=ROOT / "scenarios" / "shooter_medium.toml")
    parser.add_argument("--frames", type=int, default=150)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--size", type=int, default=640, help="the picture's longer side [px]")
    args = parser.parse_args()

    import ropesim
    from ropesim.render.animate import animate

    end = (args.frames - 1) / FPS
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        scene = ropesim.load_scene(args.scene, [f"integrator.t_end={max(end, 0.01):.6g}"])
        ropesim.simulate(scene, tmp / "run")
        traj = ropesim.Trajectory.open(tmp / "run")
        print(f"{scene.name}: {traj.nodes} nodes, {traj.frames} saved frames; {args.frames} video frames at "
              f"{FPS:g} fps, longer side {args.size} px, best / median of {args.repeat}")
        for suffix in (".gif", ".mp4"):
            out = tmp / f"bench{suffix}"
            result = animate(traj, out, fps=FPS, end=end, size=args.size)
            assert result.frames == args.frames, result
            call = [timed(lambda: animate(traj, out, fps=FPS, end=end, size=args.size)) for _ in range(args.repeat)]
            command = [sys.executable, "-m", "ropesim", "animate", str(tmp / "run"), "-o", str(out), "--fps",
                       str(FPS), "--end", repr(end), "--size", str(args.size), "-q"]
            whole = [timed(lambda: subprocess.run(command, check=True, cwd=ROOT)) for _ in range(args.repeat)]
            print(f"  {suffix[1:].upper()} {result.size[0]}x{result.size[1]} px, {out.stat().st_size / 1e6:.2f} MB\n"
                  f"    animate() in this process  {best_and_median(call)}\n"
                  f"    whole command              {best_and_median(whole)}")


if __name__ == "__main__":
    main()
