"""The run folder's costs: fsync latency on this disk, the frame store's formats, and a run's throughput.

    python scripts/bench_runfolder.py                 # all three
    python scripts/bench_runfolder.py --main DIR      # also the same run with the ropesim checked out in DIR

1. fsync: median latency of fsync after writing 0 B, 4 kB, 1 MB and 8 MB (what one checkpoint costs).
2. formats, for the frames of `helicopter_mass --set integrator.t_end=300` (30001 frames of 21 nodes):
   append-only .npy streams with write() (the checkpoint format), the same with an fsync per chunk, the former
   memory-mapped .npy files, one .npz per chunk (segments), and the final uncompressed trajectory.npz:
   seconds to write, bytes on disk, and whether numpy.load reads the result.
3. throughput: `ropesim run helicopter_mass --set integrator.t_end=300`, five times: the summary's steps per
   second (the loop's wall time, frames written included) and the whole command's wall time.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np


def fsync_latency(folder: Path) -> None:
    path = folder / "fsync.bin"
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    block = b"x" * 2 ** 20
    for size in (0, 4096, 2 ** 20, 8 * 2 ** 20):
        times = []
        for _ in range(11):
            left = size
            while left > 0:
                left -= os.write(fd, block[:min(left, len(block))])
            tick = time.perf_counter()
            os.fsync(fd)
            times.append(time.perf_counter() - tick)
        print(f"fsync after {size:>8} B: median {statistics.median(times) * 1e3:.2f} ms, max {max(times) * 1e3:.2f} ms")
    os.close(fd)
    path.unlink()


def formats(folder: Path) -> None:
    from ropesim.io.runfolder import Stream, write_npz_atomic

    frames, chunk = 30001, 2500
    rng = np.random.default_rng(0)
    arrays = {"t": rng.random(frames), "x": rng.random((frames, 21, 2)), "v": rng.random((frames, 21, 2)),
              "tension": rng.random((frames, 20)), "strain": rng.random((frames, 20)), "ledger": rng.random((frames, 6))}

    def streams(sync: bool) -> tuple[float, int]:
        d = Path(tempfile.mkdtemp(dir=folder))
        tick = time.perf_counter()
        s = {n: Stream(d / f"{n}.npy", a.shape[1:]) for n, a in arrays.items()}
        for start in range(0, frames, chunk):
            for n, a in arrays.items():
                s[n].append(a[start:start + chunk])
            if sync:
                for st in s.values():
                    st.sync()
        for st in s.values():
            st.sync()
            st.close()
        took = time.perf_counter() - tick
        assert np.array_equal(np.load(d / "x.npy"), arrays["x"])
        return took, sum(p.stat().st_size for p in d.iterdir())

    def memmaps() -> tuple[float, int]:
        d = Path(tempfile.mkdtemp(dir=folder))
        tick = time.perf_counter()
        mm = {n: np.lib.format.open_memmap(d / f"{n}.npy", mode="w+", shape=a.shape) for n, a in arrays.items()}
        for start in range(0, frames, chunk):
            for n, a in arrays.items():
                mm[n][start:start + chunk] = a[start:start + chunk]
        for m in mm.values():
            m.flush()
            os.fsync(os.open(m.filename, os.O_RDONLY))
        took = time.perf_counter() - tick
        return took, sum(p.stat().st_size for p in d.iterdir())

    def segments() -> tuple[float, int]:
        d = Path(tempfile.mkdtemp(dir=folder))
        tick = time.perf_counter()
        for start in range(0, frames, chunk):
            write_npz_atomic(d / f"seg-{start:09d}.npz", {n: a[start:start + chunk] for n, a in arrays.items()})
        took = time.perf_counter() - tick
        return took, sum(p.stat().st_size for p in d.iterdir())

    def final_npz() -> tuple[float, int]:
        d = Path(tempfile.mkdtemp(dir=folder))
        tick = time.perf_counter()
        write_npz_atomic(d / "trajectory.npz", arrays)
        took = time.perf_counter() - tick
        with zipfile.ZipFile(d / "trajectory.npz") as zf:
            assert zf.testzip() is None
        return took, (d / "trajectory.npz").stat().st_size

    raw = sum(a.nbytes for a in arrays.values())
    print(f"frames: {raw / 1e6:.1f} MB of float64 in {frames} frames, {frames // chunk + 1} chunks")
    for name, fn in (("streams, write(), one fsync per checkpoint", lambda: streams(False)),
                     ("streams, write(), fsync every chunk", lambda: streams(True)),
                     ("memory-mapped .npy (the former store)", memmaps),
                     ("one .npz per chunk (segments)", segments),
                     ("trajectory.npz (the finished run)", final_npz)):
        times = [fn() for _ in range(3)]
        took = statistics.median(t for t, _ in times)
        print(f"{name:<45} {took * 1e3:7.1f} ms  {raw / took / 1e6:7.0f} MB/s  {times[0][1] / 1e6:6.2f} MB")


def throughput(root: Path, folder: Path, label: str) -> None:
    env = {**os.environ, "PYTHONPATH": str(root)}
    out = folder / f"run-{label}"
    cmd = [sys.executable, "-m", "ropesim", "run", "helicopter_mass", "--set", "integrator.t_end=300", "-q",
           "--out", str(out)]
    subprocess.run(cmd, env=env, check=True, cwd=folder)   # compile (or load) the kernel first
    rates, walls = [], []
    for _ in range(5):
        tick = time.perf_counter()
        subprocess.run(cmd, env=env, check=True, cwd=folder)
        walls.append(time.perf_counter() - tick)
        rates.append(json.loads((out / "summary.json").read_text())["steps_per_second"])
    print(f"{label:<8} steps/s median {statistics.median(rates) / 1e6:.2f} M (min {min(rates) / 1e6:.2f}, max "
          f"{max(rates) / 1e6:.2f}); command {statistics.median(walls):.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--main", type=Path, help="a checkout of another ropesim to compare the run with")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(dir=Path.cwd(), prefix=".bench-runfolder-") as tmp:
        folder = Path(tmp)
        fsync_latency(folder)
        formats(folder)
        throughput(Path(__file__).resolve().parent.parent, folder, "this")
        if args.main is not None:
            throughput(args.main.resolve(), folder, "main")


if __name__ == "__main__":
    main()
