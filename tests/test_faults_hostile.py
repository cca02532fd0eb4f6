"""Fault injection, the hostile pass (issue 26): signals inside one long chunk, kill -9 in the final write,
writers pointed at folders and files that are not ropesim's (non-run folders, symlinks, read-only folders, full
disks), a compile cache planted by another user, crafted pickles, nesting and size bombs, and a sweep of 10^4
runs stopped by Ctrl-C.

In every case: no traceback, one line naming the file, the exit code of the CLI reference (2 bad input, 4 a
write that failed, 130/143/129 a stop), and no byte changed outside ropesim's own files.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.io.trajectory import Trajectory
from ropesim.run import resume, simulate

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenarios" / "helicopter_mass.toml"


def cli(*args: str, cwd: Path | None = None, timeout: float = 300, env: dict | None = None):
    """`ropesim ARGS` in a process of its own (as a user types it): (exit code, stdout, stderr)."""
    proc = subprocess.run([sys.executable, "-m", "ropesim", *args], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd, env=env)
    return proc.returncode, proc.stdout, proc.stderr


def one_line(err: str) -> str:
    assert "Traceback" not in err, err
    lines = [line for line in err.strip().splitlines() if line.startswith("ropesim:")]
    assert lines and len(err.strip().splitlines()) == len(lines), err
    return lines[-1]


def snapshot(root: Path) -> dict[str, str]:
    """Every file and link under ``root``: its bytes' hash (or its link target)."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in filenames + [d for d in dirnames if os.path.islink(os.path.join(dirpath, d))]:
            path = Path(dirpath) / name
            rel = str(path.relative_to(root))
            if path.is_symlink():
                out[rel] = "-> " + os.readlink(path)
            else:
                out[rel] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def small_run(folder: Path, t_end: float = 0.2) -> Path:
    simulate(ropesim.load_scene(SCENE, [f"integrator.t_end={t_end}"]), folder)
    return folder


# ------------------------------------------------------------------------- signals inside one long chunk


def _start_long_run(folder: Path) -> subprocess.Popen:
    """string_shooter_real: 150 000 verlet steps of a contact-heavy loop, about 14 s of kernel time, which the
    former chunking gave the kernel as one chunk. Its kernel is compiled first, so the signal finds it running."""
    assert cli("compile", "--method", "verlet", "-q")[0] == 0
    proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", "string_shooter_real", "--out", str(folder),
                             "-q"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 240
    while time.time() < deadline and proc.poll() is None and not (folder / "manifest.json").exists():
        time.sleep(0.02)
    return proc


def test_ctrl_c_inside_what_was_one_long_chunk_is_honoured_at_once(tmp_path):
    folder = tmp_path / "run"
    proc = _start_long_run(folder)
    time.sleep(2.0)
    assert proc.poll() is None, proc.communicate()
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    waited = time.monotonic() - sent
    assert proc.returncode == 130, err
    assert waited < 5.0, f"the stop took {waited:.1f} s"     # a chunk is about 0.1 s of wall time
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["status"] == "interrupted" and 0 < manifest["checkpoint"]["t"] < 3.0
    assert f"ropesim run --resume {folder}" in one_line(err)


def test_kill_9_keeps_a_checkpoint_no_older_than_the_interval(tmp_path):
    """kill -9 seven seconds in: a checkpoint is written at least every 5 s (CHECKPOINT_SECONDS), so frames past
    t = 0 survive (the former single chunk kept only the t = 0 frame)."""
    folder = tmp_path / "run"
    proc = _start_long_run(folder)
    time.sleep(7.0)
    if proc.poll() is None:
        proc.kill()
    proc.communicate(timeout=120)
    manifest = json.loads((folder / "manifest.json").read_text())
    if manifest["status"] == "completed":
        pytest.skip("the run finished within 7 s on this machine")
    assert manifest["checkpoint"]["t"] > 0 and Trajectory.open(folder).frames > 1
