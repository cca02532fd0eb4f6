"""Memory: peak resident memory of a big run and of reading its run folder back.

The run is the towed rope with N = 10^5 nodes (a 50 km rope of the write-up's material), 10^4 steps of 1 ms
and 100 saved frames: each frame is 10^5 x 2 positions and as many velocities, so the trajectory is
about 320 MB on disk. Each command runs as its own process and its peak resident set size (what the
operating system reports for that process alone, file pages it mapped included) is shown beside the size
of the data it handles. Target: the run stays under 1 GiB; reading commands read frames lazily.

    python scripts/bench_memory.py [--nodes 100000] [--steps 10000] [--frames 100] [--skip-pictures]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

from benchlib import TOWED, load_note

GIB = 1024 ** 3


def peak_rss(cmd: list[str]) -> tuple[float, float]:
    """(peak resident set size [bytes], wall seconds) of one run of ``cmd``, which must succeed."""
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    err = proc.stderr.read().decode()
    proc.stderr.close()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}): {err.strip()}")
    return usage.ru_maxrss * 1024.0, time.perf_counter() - start   # ru_maxrss is in KiB on Linux


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=100_000)
    parser.add_argument("--steps", type=int, default=10_000)
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--skip-pictures", action="store_true", help="only the run and the plot")
    args = parser.parse_args()
    dt = 0.001
    t_end = args.steps * dt
    sets = [f"rope.nodes={args.nodes}", f"integrator.t_end={t_end!r}", f"output.interval={t_end / args.frames!r}"]
    ropesim = [sys.executable, "-m", "ropesim"]
    frame_bytes = args.nodes * 2 * 8
    data = (args.frames + 1) * frame_bytes * 2
    table = Table(title=f"Peak resident memory, N = {args.nodes:,}, {args.steps:,} steps, {args.frames} frames "
                        f"(trajectory {data / 1e6:,.0f} MB)")
    for col in ("command", "peak RSS", "wall", "target"):
        table.add_column(col, justify="left" if col == "command" else "right")
    tmp = Path(tempfile.mkdtemp(prefix="ropesim-mem-"))
    try:
        folder = tmp / "run"
        cmds = [("ropesim run", [*ropesim, "run", str(TOWED), "-o", str(folder), "-q",
                                 *sum((["--set", s] for s in sets), [])], "< 1 GiB")]
        cmds.append(("ropesim plot", [*ropesim, "plot", str(folder), "-o", str(tmp / "plot.png")], ""))
        if not args.skip_pictures:
            cmds.append(("ropesim frames", [*ropesim, "frames", str(folder), "-o", str(tmp / "frames.png")], ""))
            cmds.append(("ropesim animate", [*ropesim, "animate", str(folder), "-o", str(tmp / "anim.gif")], ""))
        for label, cmd, target in cmds:
            try:
                rss, wall = peak_rss(cmd)
            except RuntimeError as exc:
                table.add_row(label, "failed", "", target)
                Console(stderr=True).print(f"{label}: {exc}")
                continue
            table.add_row(label, f"{rss / 2**20:,.0f} MiB", f"{wall:,.1f} s", target)
        base, _ = peak_rss([sys.executable, "-c", "import numpy, numba, matplotlib.pyplot"])
        table.add_row("(python + numpy + numba + matplotlib imported, nothing else)", f"{base / 2**20:,.0f} MiB",
                      "", "")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    Console().print(table)
    Console().print(load_note())


if __name__ == "__main__":
    main()
