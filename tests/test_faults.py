"""Fault injection on real runs: signals at random points, a full disk, concurrent writers, damaged files.

After every case the run folder is either a finished run identical to a clean one, or an unfinished run whose
frames equal a clean run's up to its last checkpoint; ``--resume`` then finishes it bit for bit as the clean
run. The fast suite runs a handful of representative cases; ``-m slow`` runs several dozen integer-seeded ones.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.io import runfolder
from ropesim.io.runfolder import RunFolderBusy, RunFolderError
from ropesim.io.trajectory import Trajectory
from ropesim.run import resume, simulate

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenarios" / "helicopter_mass.toml"
WALL_KEYS = {"wall_time_s", "compile_time_s", "steps_per_second", "node_steps_per_second"}
T_END = {"symplectic_euler": 1500.0, "verlet": 1200.0, "pefrl": 300.0, "rk4": 40.0}

# A real run in its own process: the library's simulate with frequent checkpoints, exit code as the CLI's.
DRIVER = """
import sys, ropesim
from ropesim.run import EXIT_CODES, simulate
scene = ropesim.load_scene(sys.argv[1], sys.argv[3:])
traj = simulate(scene, sys.argv[2], checkpoint_seconds=0.05)
sys.exit(EXIT_CODES.get(traj.summary.get("stopped_by", ""), 0))
"""


def _sets(method: str, t_end: float | None = None) -> list[str]:
    return [f"integrator.method={method}", f"integrator.t_end={t_end or T_END[method]}", "output.interval=0.05"]


_CLEAN: dict = {}


def clean_run(method: str, tmp_root: Path) -> Path:
    """One uninterrupted run per method, the reference every faulty run is compared with."""
    if method not in _CLEAN or not (_CLEAN[method] / "trajectory.npz").is_file():
        folder = tmp_root / f"clean-{method}"
        simulate(ropesim.load_scene(SCENE, _sets(method)), folder)
        _CLEAN[method] = folder
    return _CLEAN[method]


@pytest.fixture(scope="module")
def clean_root(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("clean")


def assert_identical(folder: Path, clean: Path) -> None:
    """Frames, ledger, tension and the summary (but for wall times) equal the clean run's bit for bit."""
    for name in ("trajectory.npz", "ledger.npz"):
        with np.load(folder / name) as a, np.load(clean / name) as b:
            assert a.files == b.files
            for key in a.files:
                assert np.array_equal(a[key], b[key]), (name, key)
    sa, sb = (json.loads((f / "summary.json").read_text()) for f in (folder, clean))
    assert {k: v for k, v in sa.items() if k not in WALL_KEYS} == {k: v for k, v in sb.items() if k not in WALL_KEYS}
    assert json.loads((folder / "manifest.json").read_text())["status"] == "completed"
    assert not (folder / "checkpoint").exists() and not (folder / ".lock").exists()


FINISHED_FILES = {"trajectory.npz", "ledger.npz", "summary.json", "state.npz", "manifest.json", "scene.toml"}


def assert_killed_after_the_commit(folder: Path, clean: Path) -> None:
    """A kill -9 in the milliseconds between a run's completing commit and its lock's removal: the run is whole,
    what is left beside it (.lock, perhaps the streams) is nobody's, and the next writer of the folder removes
    it. (Nothing runs after a SIGKILL, so no writer can promise to have cleaned up by then.)"""
    assert set(os.listdir(folder)) - FINISHED_FILES <= {".lock", "checkpoint"}
    assert runfolder.holder(folder) is None               # a stale lock is not taken for a live writer
    assert Trajectory.open(folder).summary["status"] == "completed"
    with pytest.raises(RunFolderError, match="already completed"):
        resume(folder)                                    # not blocked by it, and it cleans up
    assert_identical(folder, clean)


def assert_prefix(folder: Path, clean: Path) -> int:
    """The unfinished run's frames are the clean run's first frames, exactly; returns how many."""
    traj = Trajectory.open(folder)
    ref = Trajectory.open(clean)
    k = traj.frames
    assert 1 <= k <= ref.frames
    for name in ("t", "x", "v", "tension", "strain", "ledger"):
        assert np.array_equal(getattr(traj, name), getattr(ref, name)[:k]), name
    return k


def _wait_for_frames(folder: Path, proc: subprocess.Popen, timeout: float = 120.0) -> None:
    """Until the kernel runs (frames past the first are being written), or the process has ended."""
    x = folder / "checkpoint" / "x.npy"
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        try:
            if x.stat().st_size > runfolder.HEADER_BYTES + 2 * 21 * 2 * 8:
                return
        except FileNotFoundError:
            pass
        time.sleep(0.01)


def fault_case(tmp_path: Path, clean_root: Path, method: str, sig: int, delay: float) -> None:
    clean = clean_run(method, clean_root)
    folder = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-c", DRIVER, str(SCENE), str(folder), *_sets(method)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_frames(folder, proc)
    time.sleep(delay)
    if proc.poll() is None:
        proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    manifest = json.loads((folder / "manifest.json").read_text())
    if manifest["status"] == "completed" and proc.returncode == -signal.SIGKILL:
        assert_killed_after_the_commit(folder, clean)
        return
    if manifest["status"] == "completed":       # it finished before the signal came
        assert_identical(folder, clean)
        return
    assert "Traceback" not in err, err
    if sig == signal.SIGKILL:
        assert proc.returncode == -signal.SIGKILL
        assert manifest["status"] == "incomplete"
    else:
        assert proc.returncode == {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGHUP: 129}[sig], err
        assert manifest["status"] == "interrupted"
        assert json.loads((folder / "summary.json").read_text())["status"] == "interrupted"
    k = assert_prefix(folder, clean)
    assert k == manifest["checkpoint"]["frames"]
    traj = resume(folder)
    assert traj.summary["status"] == "completed"
    assert_identical(folder, clean)


# ------------------------------------------------------------------------------------ signals, fast


def test_kill_9_then_resume_is_bit_identical(tmp_path, clean_root):
    fault_case(tmp_path, clean_root, "symplectic_euler", signal.SIGKILL, 0.3)


def test_sigterm_and_sighup_to_ropesim_run(tmp_path, clean_root):
    """The command line: SIGTERM exits 143, SIGHUP 129, one line naming where it stopped and how to go on;
    `ropesim run --resume` finishes bit for bit."""
    clean = clean_run("symplectic_euler", clean_root)
    for sig, code in ((signal.SIGTERM, 143), (signal.SIGHUP, 129)):
        folder = tmp_path / f"run-{code}"
        proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", str(SCENE), "--out", str(folder), "-q",
                                 *[a for s in _sets("symplectic_euler", 1e5) for a in ("--set", s)]],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        _wait_for_frames(folder, proc)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == code, err
        assert len(err.strip().splitlines()) == 1 and f"by {signal.Signals(sig).name}" in err
        assert f"ropesim run --resume {folder}" in err
        traj = Trajectory.open(folder)
        assert traj.summary["status"] == "interrupted" and traj.summary["stopped_by"] == signal.Signals(sig).name
        ref = Trajectory.open(clean)      # the same scene but t_end: the same steps up to the stop
        k = min(traj.frames, ref.frames)
        assert np.array_equal(traj.x[:k], ref.x[:k]) and np.array_equal(traj.ledger[:k], ref.ledger[:k])


# ------------------------------------------------------------------------------------ signals, slow


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(36))
def test_random_signals_on_real_runs(tmp_path, clean_root, seed):
    """Integer-seeded: SIGINT, SIGTERM, SIGHUP or SIGKILL at a random point of a real run of a random method."""
    rng = random.Random(seed)
    method = rng.choice(sorted(T_END))
    sig = rng.choice([signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL, signal.SIGKILL])
    fault_case(tmp_path, clean_root, method, sig, rng.uniform(0.0, 1.2))


# A real run killed (SIGKILL) at one point after its completing commit: the manifest's rename ("commit"), the
# streams' removal ("streams"), or the start of the folder's last fsync ("flush").
KILLED_AFTER_THE_COMMIT = """
import os, signal, sys, ropesim
from ropesim.io import runfolder
point, committed = sys.argv[3], []
write_json_durable, remove_tree, fsync_path = runfolder.write_json_durable, runfolder._remove_tree, runfolder.fsync_path
def kill_at(here):
    if here == point and committed:
        os.kill(os.getpid(), signal.SIGKILL)
def commit(path, data):
    write_json_durable(path, data)
    if data["status"] == "completed":
        committed.append(path)
    kill_at("commit")
def remove(path):
    remove_tree(path)
    kill_at("streams")
def flush(path):
    kill_at("flush")
    fsync_path(path)
runfolder.write_json_durable, runfolder._remove_tree, runfolder.fsync_path = commit, remove, flush
ropesim.simulate(ropesim.load_scene(sys.argv[1], sys.argv[4:]), sys.argv[2])
"""


@pytest.mark.parametrize("point", ["commit", "streams", "flush"])
def test_kill_9_after_the_final_commit(tmp_path, point):
    """CI's seed 11 of the random signals: a SIGKILL landed after the run's completing commit and after its
    streams went, while the folder was flushed, and left .lock beside the completed run. The lock now goes with
    the streams, before that flush; a kill before it leaves a lock nobody holds, which blocks nothing and which
    the next writer removes with any streams left."""
    sets = _sets("verlet", 20.0)
    clean = tmp_path / "clean"
    simulate(ropesim.load_scene(SCENE, sets), clean)
    folder = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-c", KILLED_AFTER_THE_COMMIT, str(SCENE), str(folder), point, *sets],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    assert json.loads((folder / "manifest.json").read_text())["status"] == "completed"
    if point == "flush":
        assert_identical(folder, clean)                   # nothing left behind: no .lock, no streams
    else:
        assert_killed_after_the_commit(folder, clean)


# ------------------------------------------------------------------------------------ full disk


def _enospc_after(monkeypatch, budget: int) -> None:
    """The write layer raises ENOSPC once ``budget`` more bytes have gone to the frame streams."""
    real = runfolder.os.write
    left = {"bytes": budget}

    def write(fd, data):
        n = len(memoryview(data).cast("B"))
        if left["bytes"] < n:
            raise OSError(errno.ENOSPC, "No space left on device")
        left["bytes"] -= n
        return real(fd, data)

    monkeypatch.setattr(runfolder.os, "write", write)


def test_full_disk_while_frames_stream(tmp_path, monkeypatch):
    scene = ropesim.load_scene(SCENE, [*_sets("verlet", 400.0), "output.interval=0.01"])   # 44 MB of frames
    clean = tmp_path / "clean"
    simulate(scene, clean)
    _enospc_after(monkeypatch, 35_000_000)     # the first chunk (at most 16 MB of x and v) fits, a later one not
    with pytest.raises(runfolder.DiskFull) as err:
        simulate(scene, tmp_path / "run", checkpoint_seconds=0.0)
    message = str(err.value)
    assert "\n" not in message and "the disk is full" in message and "is free" in message and "--resume" in message
    monkeypatch.undo()
    k = assert_prefix(tmp_path / "run", clean)
    assert k > 1 and json.loads((tmp_path / "run" / "manifest.json").read_text())["status"] == "incomplete"
    resume(tmp_path / "run")
    assert_identical(tmp_path / "run", clean)


def test_full_disk_at_the_final_write_keeps_every_frame(tmp_path, clean_root, monkeypatch):
    clean = clean_run("verlet", clean_root)
    scene = ropesim.load_scene(SCENE, _sets("verlet"))

    def full(path, arrays):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(runfolder, "write_npz_atomic", full)
    with pytest.raises(runfolder.DiskFull, match="trajectory.npz and ledger.npz"):
        simulate(scene, tmp_path / "run")
    monkeypatch.undo()
    assert assert_prefix(tmp_path / "run", clean) == Trajectory.open(clean).frames   # every frame kept
    resume(tmp_path / "run")                                                          # finishes the folder
    assert_identical(tmp_path / "run", clean)


def test_full_disk_on_a_real_tmpfs(tmp_path):
    """A 200 kB tmpfs as --out: one line (exit 4), no SIGBUS, the folder holds its checkpoint."""
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(mnt)],
                      capture_output=True).returncode != 0:
        pytest.skip("cannot mount a tmpfs here (needs root or a user namespace); the injected ENOSPC covers it")
    try:
        proc = subprocess.run([sys.executable, "-m", "ropesim", "run", str(SCENE), "--out", str(mnt), "--force",
                               "-q"], capture_output=True, text=True, timeout=300)
        assert proc.returncode == 4, proc.stderr
        assert len(proc.stderr.strip().splitlines()) == 1 and "the disk is full" in proc.stderr
        assert json.loads((mnt / "manifest.json").read_text())["status"] == "incomplete"
        assert Trajectory.open(mnt).frames >= 1
        refused = subprocess.run([sys.executable, "-m", "ropesim", "run", str(SCENE), "--out", str(mnt), "-q"],
                                 capture_output=True, text=True, timeout=300)
        assert refused.returncode == 2 and "free" in refused.stderr and "--force" in refused.stderr
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


def test_size_estimate_refuses_what_the_disk_cannot_hold(tmp_path):
    from typer.testing import CliRunner

    from ropesim.cli.app import app

    result = CliRunner().invoke(app, ["run", str(SCENE), "--out", str(tmp_path / "r"),
                                      "--set", "integrator.t_end=1e7"])
    assert result.exit_code == 2 and "TB of frames" in result.stderr and "--force" in result.stderr
    assert not (tmp_path / "r").exists()
    check = CliRunner().invoke(app, ["check", str(SCENE), "--set", "integrator.t_end=1e7"])
    assert check.exit_code == 0 and "output: about" in check.stdout and "cannot hold" in check.stderr


# ------------------------------------------------------------------------------------ one writer


def test_a_second_writer_is_refused_naming_the_first(tmp_path):
    folder = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", str(SCENE), "--out", str(folder), "-q",
                             "--set", "integrator.t_end=1e6", "--set", "output.interval=100"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        _wait_for_frames(folder, proc)
        scene = ropesim.load_scene(SCENE, ["integrator.t_end=1"])
        with pytest.raises(RunFolderBusy) as err:
            simulate(scene, folder)
        assert f"pid {proc.pid}" in str(err.value) and "ropesim" in str(err.value) and "\n" not in str(err.value)
        with pytest.raises(RunFolderBusy):
            resume(folder)
    finally:
        proc.kill()
        proc.wait()
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=1"]), folder)   # the dead holder's lock is gone
    assert Trajectory.open(folder).summary["status"] == "completed"


def test_a_reader_asking_who_writes_never_refuses_the_next_writer(tmp_path):
    """holder() (a reader: `ropesim view` of an unfinished run, a replacement clearing leftovers) takes the lock
    shared for an instant. A writer starting in that instant was refused, "another ropesim is writing", naming
    whoever the stale .lock last recorded: here a run killed long ago."""
    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.1"]), folder)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (folder / ".lock").write_text(json.dumps({"pid": dead.pid, "command": "ropesim run (killed)", "since": "then"}))
    assert runfolder.holder(folder) is None               # stale: nobody holds it
    probe = os.open(folder / ".lock", os.O_RDONLY)
    fcntl.flock(probe, fcntl.LOCK_SH)                     # the reader's instant, caught
    threading.Timer(0.05, os.close, [probe]).start()
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.2"]), folder)   # waits the reader out
    assert Trajectory.open(folder).t[-1] == 0.2 and not (folder / ".lock").exists()

    writer = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT)   # a writer holds it: refused at once, named
    fcntl.flock(writer, fcntl.LOCK_EX)
    os.write(writer, json.dumps({"pid": os.getpid(), "command": "ropesim run x", "since": "now"}).encode())
    try:
        started = time.monotonic()
        with pytest.raises(RunFolderBusy, match=f"pid {os.getpid()}, `ropesim run x`"):
            resume(folder)
        assert time.monotonic() - started < runfolder.READERS_WAIT
    finally:
        os.close(writer)


def test_a_rerun_replaces_the_whole_folder(tmp_path):
    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=1"]), folder)
    (folder / "frames.png").write_bytes(b"stale picture")
    (folder / ".frames-abc123").mkdir()                   # a killed run of an older ropesim
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.5"]), folder)
    assert not (folder / "frames.png").exists() and not (folder / ".frames-abc123").exists()
    assert Trajectory.open(folder).t[-1] == 0.5
    assert not list(tmp_path.glob(".run.new-*")), "no hidden sibling left behind"


def test_a_folder_that_is_not_a_run_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(RunFolderError, match="is not a run folder"):
        simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.1"]), tmp_path)
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_leftovers_of_a_killed_replacement_are_removed(tmp_path):
    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.1"]), folder)
    shutil.copytree(folder, tmp_path / ".run.new-dead1234")   # a replacement killed after its swap
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.1"]), folder)
    assert not (tmp_path / ".run.new-dead1234").exists()


def test_simulate_leaves_no_signal_handler_behind(tmp_path):
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.1"]), tmp_path / "run")
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.1"]))
    assert {s: signal.getsignal(s) for s in before} == before


# ------------------------------------------------------------------------------------ resume rules


def test_resume_refuses_an_edited_scene_and_another_grid(tmp_path):
    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=1"]), folder, stop=lambda: True)   # stops at t = 0
    assert Trajectory.open(folder).summary["status"] == "interrupted"
    text = (folder / "scene.toml").read_text()
    (folder / "scene.toml").write_text(text.replace("b = 5.0", "b = 6.0"))
    with pytest.raises(RunFolderError, match="changed since the run began"):
        resume(folder)
    (folder / "scene.toml").write_text(text)
    with pytest.raises(RunFolderError, match="changes the run's time grid"):
        resume(folder, t_end=1.0005)         # 1000.5 steps of 0.001 s: dt would shrink
    resume(folder)
    with pytest.raises(RunFolderError, match="already completed"):
        resume(folder)


def test_extending_a_finished_run_equals_the_longer_run(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=2.005", "output.interval=0.01"]), a)  # off-grid end
    resume(a, t_end=3.0)
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=3.0", "output.interval=0.01"]), b)
    assert_identical(a, b)


# ------------------------------------------------------------------------------------ damaged files


def _flip(path: Path, offset: int) -> None:
    data = bytearray(path.read_bytes())
    data[offset] ^= 0xFF
    path.write_bytes(bytes(data))


def test_damaged_frames_are_refused_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from ropesim.cli.app import app

    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=1"]), folder)
    size = (folder / "trajectory.npz").stat().st_size
    _flip(folder / "trajectory.npz", size // 2)
    with pytest.raises(RunFolderError, match="CRC-32"):
        Trajectory.open(folder)
    for command in ("plot", "frames", "animate"):
        result = CliRunner().invoke(app, [command, str(folder), "-o", str(tmp_path / f"p.{'gif' if command == 'animate' else 'png'}")])
        assert result.exit_code == 2 and "damaged" in result.stderr and len(result.stderr.splitlines()) == 1
    with open(folder / "trajectory.npz", "r+b") as fh:      # truncated
        fh.truncate(size // 3)
    with pytest.raises(RunFolderError):
        Trajectory.open(folder)


def test_damaged_checkpoint_is_refused(tmp_path):
    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=3000"]), folder,
             stop=(lambda calls=[]: calls.append(1) or len(calls) > 2))
    x = folder / "checkpoint" / "x.npy"
    _flip(x, runfolder.HEADER_BYTES + 40)
    with pytest.raises(RunFolderError, match="damaged"):
        Trajectory.open(folder)
    with pytest.raises(RunFolderError, match="damaged"):
        resume(folder)


@pytest.mark.slow
def test_a_torn_tail_past_the_checkpoint_is_ignored_and_cut(tmp_path, clean_root):
    folder = tmp_path / "run"
    scene = ropesim.load_scene(SCENE, ["integrator.t_end=3000"])
    simulate(scene, folder, stop=(lambda calls=[]: calls.append(1) or len(calls) > 2))
    frames = Trajectory.open(folder).frames
    for npy in (folder / "checkpoint").glob("*.npy"):        # half a frame written after the commit
        with open(npy, "ab") as fh:
            fh.write(b"\x00" * 13)
    assert Trajectory.open(folder).frames == frames
    resume(folder)
    simulate(scene, tmp_path / "clean")
    assert_identical(folder, tmp_path / "clean")


def test_picture_options_are_bounded(tmp_path):
    from typer.testing import CliRunner

    from ropesim.cli.app import app

    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.2"]), folder)
    for args in (["animate", "--size", "100000"], ["animate", "--size", "0"], ["frames", "--width", "99999"],
                 ["frames", "--count", "100000"], ["frames", "--columns", "0"], ["animate", "--fps", "1e9"],
                 ["animate", "--speed", "0"]):
        result = CliRunner().invoke(app, [args[0], str(folder), *args[1:]])
        assert result.exit_code == 2, (args, result.output)
        assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output


@pytest.mark.slow
def test_a_sweep_point_resumes_its_unfinished_run(tmp_path):
    from ropesim.scene.schema import scene_to_toml
    from ropesim.sweep.points import run_point

    scene = ropesim.load_scene(SCENE, ["integrator.t_end=3000"])
    folder = tmp_path / "point"
    simulate(scene, folder, stop=(lambda calls=[]: calls.append(1) or len(calls) > 2))
    assert json.loads((folder / "manifest.json").read_text())["status"] == "interrupted"
    assert run_point(scene_to_toml(scene), str(folder))["status"] == "completed"
    simulate(scene, tmp_path / "clean")
    assert_identical(folder, tmp_path / "clean")
