"""The browser viewer's size and speed on a large 3-D run: a 20 m rope of 2000 nodes whirled by its top end
(1000 saved frames over 10 s), as `ropesim view` writes it and headless Chromium shows it.

    python scripts/bench_viewer.py                  # about a minute on two cores (the run, then 3 page loads)
    python scripts/bench_viewer.py --run DIR        # reuse a run folder made before (by this script: --keep)

Measures: the page's size; the time `ropesim view RUN --no-open` takes (a fresh process, Python's start-up and
imports included) and the time write_page takes in a running Python; the time from navigation to the first
frame on the screen (the median of 3 loads, each in a new tab); and the frames per second while it plays, with
the playback speed set so that every screen refresh needs a new frame (the fps the page's own counter shows).
Needs Debian's chromium and the playwright package (the test extra). Goals (issue 25): at most 20 MB, the
first frame within 2 s, at least 30 fps, the page written within 2 s.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = """\
name = "whirl"
description = "A 20 m rope of 2000 nodes whirled by its top end in a horizontal circle (3-D)"
dimension = 3
[rope]
nodes = 2000
segment_length = 0.01
stiffness = 1.0e6
mass = 0.01
[initial]
shape = "hanging"
top = [0.0, 0.0, 0.0]
[[driven]]
nodes = [0]
amplitude = [2.0, 0.0, 2.0]
period = [2.0, 2.0, 2.0]
phase = [90.0, 0.0, 0.0]
ramp_time = 2.0
[gravity]
g = 9.81
[drag]
b = 0.002
[integrator]
method = "symplectic_euler"
dt = 5e-5
t_end = 9.99
[output]
interval = 0.01
"""
LOADS = 3
PLAY_SECONDS = 5.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, help="a run folder of the whirl scene, made before")
    parser.add_argument("--keep", type=Path, help="run the scene into this folder and keep it")
    parser.add_argument("--json", type=Path, help="also write the figures to this JSON file")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="ropesim-bench-viewer-") as tmp:
        run = args.run or args.keep or Path(tmp) / "whirl"
        if args.run is None:
            (Path(tmp) / "whirl.toml").write_text(SCENE)
            subprocess.run([sys.executable, "-m", "ropesim", "run", str(Path(tmp) / "whirl.toml"), "-o", str(run),
                            "-q"], check=True)
        figures = measure(run, Path(tmp) / "whirl.html")
    print(json.dumps(figures, indent=2))
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")
    return 0


def measure(run: Path, page_path: Path) -> dict:
    sys.path.insert(0, str(ROOT))
    from ropesim.io.trajectory import Trajectory
    from ropesim.viewer import headless
    from ropesim.viewer.page import write_page

    traj = Trajectory.open(run)
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "ropesim", "view", str(run), "-o", str(page_path), "--no-open", "-q"],
                   check=True)
    command_s = time.perf_counter() - started
    started = time.perf_counter()
    page = write_page(traj, page_path)
    write_s = time.perf_counter() - started
    first_frames, decodes = [], []
    with headless.browser() as browser:
        for _ in range(LOADS):
            opened = browser.open(page_path, viewport=(1280, 800))
            if opened.errors or opened.requests:
                raise SystemExit(f"the page failed: {opened.errors or opened.requests}")
            state = opened.state()
            first_frames.append(state["firstFrameMs"] / 1000)
            decodes.append(state["decodeMs"] / 1000)
            last = opened
        interval = float(traj.t[1] - traj.t[0])
        page_ = last.page
        page_.evaluate(f"window.ropesim.setSpeed({2 * 60 * interval}); window.ropesim.play()")   # 2 frames a refresh
        page_.wait_for_timeout(500)
        before = page_.evaluate("[window.ropesim.state().renders, window.ropesim.state().frame, performance.now()]")
        page_.wait_for_timeout(1000 * PLAY_SECONDS)
        after = page_.evaluate("[window.ropesim.state().renders, window.ropesim.state().frame, performance.now()]")
        if after[1] < before[1]:
            raise SystemExit("the run ended while fps was measured: lower the playback speed")
        seconds = (after[2] - before[2]) / 1000
        fps = (after[0] - before[0]) / seconds
        shown = (after[1] - before[1]) / seconds
    return {
        "run": {"frames": traj.frames, "nodes": traj.nodes, "dimension": traj.scene.dimension,
                "trajectory_npz_MB": round((run / "trajectory.npz").stat().st_size / 1e6, 1)},
        "page_MB": round(page.nbytes / 1e6, 2),
        "write_page_s": round(write_s, 2),
        "view_command_s": round(command_s, 2),
        "first_frame_s": round(statistics.median(first_frames), 2),
        "first_frame_s_all": [round(v, 2) for v in first_frames],
        "decode_s": round(statistics.median(decodes), 2),
        "fps": round(fps, 1),
        "saved_frames_shown_per_s": round(shown, 1),
    }


if __name__ == "__main__":
    sys.exit(main())
