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
    """string_shooter_real to t = 30 s: 1.5 million verlet steps of a contact-heavy loop, whose first 200 000
    (about 14 s of kernel time on the former kernels) the former chunking gave the kernel as one chunk. Its kernel is compiled first, so the signal finds it running."""
    assert cli("compile", "--method", "verlet", "-q")[0] == 0
    proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", "string_shooter_real", "--out", str(folder),
                             "-q", "--set", "integrator.t_end=30"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.time() + 240
    while time.time() < deadline and proc.poll() is None and not (folder / "manifest.json").exists():
        time.sleep(0.02)
    return proc


@pytest.mark.slow
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
    # The former first chunk was 20 million node-steps: 333 000 steps of 60 nodes, to t = 6.66 s, whatever it cost.
    assert manifest["status"] == "interrupted" and 0 < manifest["checkpoint"]["t"] < 6.0
    assert f"ropesim run --resume {folder}" in one_line(err)


@pytest.mark.slow
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


# ------------------------------------------------------------------ writers pointed at what is not theirs

WRITERS = {   # every command that writes, with RUN the run folder, OUT the place it is pointed at
    "export vtk": ["export", "RUN", "--to", "vtk", "--out", "OUT"],
    "export csv": ["export", "RUN", "--to", "csv", "--out", "OUT/t.csv"],
    "frames": ["frames", "RUN", "--out", "OUT/f.png"],
    "plot": ["plot", "RUN", "--out", "OUT/p.png"],
    "animate": ["animate", "RUN", "--out", "OUT/a.gif"],
    "run": ["run", str(SCENE), "--set", "integrator.t_end=0.1", "--out", "OUT"],
    "sweep": ["sweep", str(SCENE), "--set", "integrator.t_end=0.1", "--set", "drag.b=4,5", "--out", "OUT",
              "--jobs", "1"],
    "new": ["new", "OUT/scene.toml"],
}


def _args(command: str, run: Path, out: Path) -> list[str]:
    return [a.replace("RUN", str(run)).replace("OUT", str(out)) for a in WRITERS[command]]


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory) -> Path:
    return small_run(tmp_path_factory.mktemp("src") / "run")


@pytest.mark.parametrize("command", [c for c in WRITERS if c not in ("new",)])
def test_a_folder_of_the_users_is_refused_and_left_as_it_was(tmp_path, run_folder, command):
    """export --to vtk --out FOLDER emptied the folder (exit 0); every writer must refuse a folder holding
    what ropesim did not write, or write beside it, touching none of it."""
    out = tmp_path / "mine"
    (out / "sub").mkdir(parents=True)
    (out / "notes.txt").write_text("my notes")
    (out / "sub" / "data.bin").write_bytes(b"\x00\x01")
    for name in ("t.csv", "f.png", "p.png", "a.gif"):     # files of the user's at the names asked for
        (out / name).write_bytes(b"the user's own " + name.encode())
    before = snapshot(out)
    code, _, err = cli(*_args(command, run_folder, out))
    assert code == 2, err
    assert str(out) in one_line(err)
    assert snapshot(out) == before


def test_export_into_the_current_folder_is_refused_or_done_in_place(tmp_path, run_folder):
    """--out . failed with EBUSY and left a hidden folder; an empty current folder takes the series in place, a
    rerun replaces it, and a folder with the user's files in it is refused."""
    work = tmp_path / "work"
    work.mkdir()
    for _ in range(2):
        code, _, err = cli("export", str(run_folder), "--to", "vtk", "--out", ".", cwd=work)
        assert code == 0, err
    suffixes = sorted(p.suffix for p in work.iterdir())
    assert suffixes.count(".pvd") == 1 and suffixes.count(".vtu") >= Trajectory.open(run_folder).frames
    assert set(suffixes) == {".pvd", ".vtu"}
    assert not list(tmp_path.glob(".*"))
    (work / "notes.txt").write_text("mine")
    code, _, err = cli("export", str(run_folder), "--to", "vtk", "--out", ".", cwd=work)
    assert code == 2 and "notes.txt" in one_line(err)
    assert (work / "notes.txt").read_text() == "mine"


def test_a_rerun_keeps_and_names_files_the_user_added(tmp_path):
    folder = small_run(tmp_path / "run")
    (folder / "notes.md").write_text("what I saw")
    (folder / "analyse.py").write_text("print(1)")
    code, _, err = cli("run", str(SCENE), "--set", "integrator.t_end=0.1", "--out", str(folder), "-q")
    line = one_line(err)
    assert code == 2 and "analyse.py" in line and "notes.md" in line and "did not write" in line
    assert (folder / "notes.md").read_text() == "what I saw" and Trajectory.open(folder).t[-1] == 0.2


@pytest.mark.slow
def test_pictures_and_exports_replace_their_own_files(tmp_path, run_folder):
    for command in ("export csv", "frames", "plot", "animate", "export vtk"):
        for _ in range(2):                        # the second time replaces what the first wrote
            code, _, err = cli(*_args(command, run_folder, tmp_path / command.replace(" ", "-")))
            assert code == 0, (command, err)


@pytest.mark.slow
def test_run_into_a_symlink_writes_to_its_target(tmp_path):
    """The link was replaced by a real folder, a hidden .NAME.new-* link stayed, and a stale .lock in the
    target; now the run goes where the link points."""
    target = tmp_path / "big-disk" / "run"
    target.parent.mkdir()
    link = tmp_path / "run"
    link.symlink_to(target)
    for _ in range(2):   # a new run, then a rerun over it
        code, _, err = cli("run", str(SCENE), "--set", "integrator.t_end=0.1", "--out", str(link), "-q")
        assert code == 0, err
    assert link.is_symlink() and Trajectory.open(target).summary["status"] == "completed"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big-disk", "run"]
    assert sorted(p.name for p in target.parent.iterdir()) == ["run"]
    assert not (target / ".lock").exists()
    picture = tmp_path / "p.png"
    picture.symlink_to(tmp_path / "big-disk" / "p.png")
    assert cli("plot", str(link), "--out", str(picture))[0] == 0
    assert picture.is_symlink() and (tmp_path / "big-disk" / "p.png").stat().st_size > 1000


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_output_folder_names_the_file_asked_for(tmp_path, run_folder):
    out = tmp_path / "ro"
    out.mkdir()
    out.chmod(0o555)
    try:
        code, _, err = cli("plot", str(run_folder), "--out", str(out / "p.png"))
        assert code == 4 and one_line(err).startswith(f"ropesim: {out / 'p.png'}: cannot write it")
        assert ".tmp" not in err
    finally:
        out.chmod(0o755)


def test_a_read_only_output_folder_in_process(tmp_path, run_folder, monkeypatch):
    """As root a read-only folder is writable, so the refusal of the temporary file is injected: the message
    names the file asked for, never the hidden temporary one, and the exit code is 4."""
    from typer.testing import CliRunner

    from ropesim.cli.app import app
    from ropesim.io import atomic

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied", str(tmp_path / ".p.abcdefgh.tmp.png"))

    monkeypatch.setattr(atomic.tempfile, "mkstemp", refuse)
    for command, out in (("plot", "p.png"), ("frames", "f.png"), ("animate", "a.gif")):
        result = CliRunner().invoke(app, [command, str(run_folder), "--out", str(tmp_path / out)])
        assert result.exit_code == 4, result.output
        assert one_line(result.stderr) == f"ropesim: {tmp_path / out}: cannot write it (Permission denied)"


def test_pictures_and_exports_into_a_full_disk_exit_4_naming_the_file(tmp_path, run_folder, monkeypatch):
    """They exited 2 ("bad input") and named no file; an MP4 dumped twelve lines of ffmpeg."""
    import errno

    from typer.testing import CliRunner

    from ropesim.cli.app import app
    from ropesim.io import atomic
    from ropesim.render import encode

    real_replace = atomic.os.replace

    def full(src, dst):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(atomic.os, "replace", full)
    monkeypatch.setattr(encode, "FULL_DISK_BYTES", 1 << 62)    # ffmpeg's failure looks like a full disk
    for args, out in ((["plot"], "p.png"), (["frames"], "f.png"), (["animate"], "a.gif"),
                      (["export", "--to", "csv"], "t.csv")):
        result = CliRunner().invoke(app, [args[0], str(run_folder), *args[1:], "--out", str(tmp_path / out)])
        assert result.exit_code == 4, (args, result.output)
        assert one_line(result.stderr) == f"ropesim: {tmp_path / out}: cannot write it (No space left on device)"
    monkeypatch.setattr(atomic.os, "replace", real_replace)

    def broken_pipe(*args, **kwargs):
        def gen():
            yield
            raise OSError("[Errno 32] Broken pipe\n\nFFMPEG COMMAND:\nffmpeg -y ...\n\nFFMPEG STDERR OUTPUT:\n"
                          + "error line\n" * 12)
        g = gen()
        return g

    import imageio_ffmpeg
    monkeypatch.setattr(imageio_ffmpeg, "write_frames", broken_pipe)
    result = CliRunner().invoke(app, ["animate", str(run_folder), "--out", str(tmp_path / "a.mp4")])
    assert result.exit_code == 4, result.output
    assert one_line(result.stderr) == f"ropesim: {tmp_path / 'a.mp4'}: cannot write it (No space left on device)"
    assert not (tmp_path / "a.mp4").exists() and not list(tmp_path.glob(".a.*"))


# ------------------------------------------------------------------------------- reruns and leftovers


def test_a_rerun_stopped_before_its_first_checkpoint_keeps_the_earlier_run(tmp_path):
    """An accidental rerun killed after its swap lost the completed run; now the earlier run stays until the
    new one commits a checkpoint past t = 0."""
    folder = small_run(tmp_path / "run")
    before = snapshot(folder)
    traj = simulate(ropesim.load_scene(SCENE, ["integrator.t_end=50"]), folder,
                    stop=(lambda calls=[]: calls.append(1) or len(calls) > 3))
    assert traj.summary["status"] == "interrupted" and traj.summary["kept_earlier_run"] == str(folder)
    assert snapshot(folder) == before and sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_a_rerun_killed_before_its_first_checkpoint_keeps_the_earlier_run(tmp_path):
    folder = small_run(tmp_path / "run")
    before = snapshot(folder)
    proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", str(SCENE), "--out", str(folder), "-q",
                             "--set", "integrator.t_end=1e5"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.time() + 120
    while time.time() < deadline and not list(tmp_path.glob(".run.new-*/checkpoint/x.npy")):
        time.sleep(0.01)
    time.sleep(0.5)
    proc.kill()
    proc.wait()
    assert {k: v for k, v in snapshot(folder).items() if k != ".lock"} == before     # .lock: its own, unlocked
    small_run(folder, 0.1)                          # the next run clears the killed one's hidden folder
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_kill_9_in_the_final_write_leaves_nothing_that_resume_keeps(tmp_path):
    """A kill -9 while trajectory.npz is written left .trajectory.*.tmp.npz, which --resume never removed."""
    folder = tmp_path / "run"
    driver = (
        "import os, signal, sys, ropesim\n"
        "from ropesim.io import runfolder\n"
        "real = runfolder._write_npy\n"
        "def killed(fh, arr):\n"
        "    real(fh, arr[:len(arr) // 2]); fh.flush(); os.kill(os.getpid(), signal.SIGKILL)\n"
        "runfolder._write_npy = killed\n"
        "ropesim.simulate(ropesim.load_scene(sys.argv[1], ['integrator.t_end=1']), sys.argv[2])\n")
    proc = subprocess.run([sys.executable, "-c", driver, str(SCENE), str(folder)], capture_output=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL
    assert list(folder.glob(".trajectory.*.tmp.npz"))
    code, _, err = cli("run", "--resume", str(folder), "-q")
    assert code == 0, err
    assert not [p.name for p in folder.iterdir() if p.name.startswith(".")]
    clean = small_run(tmp_path / "clean", 1.0)
    with np.load(folder / "trajectory.npz") as a, np.load(clean / "trajectory.npz") as b:
        assert all(np.array_equal(a[k], b[k]) for k in b.files)


def test_resume_of_a_folder_that_is_no_run_leaves_no_lock(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    before = snapshot(tmp_path)
    code, _, err = cli("run", "--resume", str(tmp_path))
    assert code == 2 and "no manifest.json" in one_line(err)
    assert snapshot(tmp_path) == before and not (tmp_path / ".lock").exists()


def test_resume_with_a_t_end_before_the_checkpoint_says_so(tmp_path):
    folder = tmp_path / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=3000"]), folder,
             stop=(lambda calls=[]: calls.append(1) or len(calls) > 3))
    reached = json.loads((folder / "manifest.json").read_text())["checkpoint"]["t"]
    assert reached > 0.1
    code, _, err = cli("run", "--resume", str(folder), "--set", "integrator.t_end=0.1")
    line = one_line(err)
    assert code == 2 and "lies before the run's last checkpoint" in line and "whole number" not in line


def test_the_summary_of_an_interrupted_run_names_its_checkpoint(tmp_path):
    from ropesim.cli.report import written

    folder = tmp_path / "run"
    traj = simulate(ropesim.load_scene(SCENE, ["integrator.t_end=3000"]), folder,
                    stop=(lambda calls=[]: calls.append(1) or len(calls) > 3))
    text = written(traj.summary, folder)
    assert "checkpoint/" in text and "trajectory.npz" not in text
    assert not (folder / "trajectory.npz").exists()


def test_ctrl_c_while_the_command_line_starts_is_one_line(tmp_path):
    """Ctrl-C in the first 0.6 s printed nothing (Typer's own handling exits 130 silently). The signal goes a set
    time after ropesim's package installed its handler (seen in Python's import-time log), not after the process
    started: on a busy machine the interpreter alone can take longer than the delay, and a Ctrl-C before
    ropesim's first line is Python's, out of ropesim's reach. The run is 10^8 steps (seconds of kernel time):
    with a warm cache the former 10^6 finished before a 0.6 s signal came, and exited 0 (seen in CI)."""
    env = dict(os.environ, PYTHONPROFILEIMPORTTIME="1")
    for delay in (0.0, 0.3, 0.6):
        proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", str(SCENE), "--out", str(tmp_path / "r"),
                                 "--set", "integrator.t_end=100000", "--set", "output.interval=100"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        for line in proc.stderr:
            if line.split("|")[-1].strip() == "ropesim.io.numba_cache":   # imported after the handler went in
                break
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
        err = "\n".join(line for line in err.splitlines() if not line.startswith("import time:"))
        assert proc.returncode == 130, err
        assert "Traceback" not in err and err.strip(), (delay, out, err)


def test_ctrl_c_stays_one_line_until_main_takes_it_over():
    """The command line's modules loaded, main() still had imports and signal set-up to do before its own try:
    Ctrl-C handed back to Python at the end of ``import ropesim.cli`` landed there as a traceback (seen: a
    KeyboardInterrupt in main's import of .status). Importing the CLI keeps the one-line handler; main() gives
    Ctrl-C back to Python inside the try that reports it."""
    probe = ("import signal, sys; sys.argv[0] = 'ropesim'; import ropesim.cli; "
             "print(signal.getsignal(signal.SIGINT).__name__)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert done.stdout.strip() == "_interrupted_while_loading", done.stderr


# ----------------------------------------------------------------------------------- the compile cache


def test_a_cache_folder_planted_by_another_user_is_never_used(tmp_path, monkeypatch):
    """$TMPDIR/ropesim-kernels-<uid>, made first by another user with mode 0777 and a pickled index in it, was
    accepted: Numba would have unpickled the planted file as the user running ropesim."""
    from ropesim.io import numba_cache

    monkeypatch.setattr(sys, "platform", "linux")
    blocked = tmp_path / "a-file"
    blocked.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocked / "x"))
    monkeypatch.setattr(numba_cache.tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    planted = numba_cache.temp_cache_dir()
    fingerprint = numba_cache.source_fingerprint(blocked / "pkg")
    (planted / fingerprint).mkdir(parents=True)
    (planted / fingerprint / "kernel.index.nbi").write_bytes(b"\x80\x04cos\nsystem\n...")   # a pickle
    os.chmod(planted, 0o777)
    os.chmod(planted / fingerprint, 0o777)
    if os.geteuid() == 0:
        os.chown(planted, 4242, 4242)
        os.chown(planted / fingerprint, 4242, 4242)
    before = snapshot(planted)
    chosen = numba_cache.choose_cache_dir(blocked / "pkg", environ={})
    assert chosen is not None and not Path(chosen).is_relative_to(planted)
    st = os.stat(chosen)
    assert st.st_uid == os.getuid() and st.st_mode & 0o077 == 0
    assert snapshot(planted) == before
    for mode in (0o777, 0o775):       # the user's own folder, but writable by others: refused too
        mine = tmp_path / f"mine-{mode:o}"
        (mine / "k").mkdir(parents=True)
        os.chmod(mine, mode)
        assert numba_cache.private_folder(mine, "k")[0] is None
        assert "others can write" in numba_cache.private_folder(mine, "k")[1]


def test_the_cache_folders_ropesim_makes_are_private(tmp_path):
    from ropesim.io import numba_cache

    folder, why = numba_cache.private_folder(tmp_path / "base", "abc")
    assert why == "" and folder == tmp_path / "base" / "abc"
    for path in (tmp_path / "base", folder):
        assert os.stat(path).st_mode & 0o077 == 0


# ------------------------------------------------------------------------------------ crafted pickles


def _pickled_array() -> np.ndarray:
    return np.array([{"evil": 1}, None], dtype=object)


def _craft(tmp_path: Path, run: Path, where: str) -> Path:
    """A copy of a run folder with a pickled object array in one of its files."""
    import shutil

    folder = tmp_path / f"crafted-{where.replace('/', '-')}"
    shutil.copytree(run, folder)
    if where == "trajectory.npz":
        with np.load(run / "trajectory.npz") as npz:
            arrays = {k: npz[k] for k in npz.files}
        arrays["x"] = _pickled_array()
        np.savez(folder / "trajectory.npz", **arrays)
    elif where == "state.npz":
        np.savez(folder / "state.npz", step=_pickled_array())
    elif where == "ledger.npz":
        np.savez(folder / "ledger.npz", t=_pickled_array())
    elif where == "checkpoint/state":
        manifest = json.loads((folder / "manifest.json").read_text())
        np.savez(folder / manifest["checkpoint"]["state"], step=_pickled_array(), x=_pickled_array())
    return folder


@pytest.fixture(scope="module")
def interrupted_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("int") / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=3000"]), folder,
             stop=(lambda calls=[]: calls.append(1) or len(calls) > 3))
    return folder


@pytest.mark.parametrize("where", ["trajectory.npz", "ledger.npz", "state.npz", "checkpoint/state"])
def test_crafted_pickles_are_refused_in_one_line(tmp_path, run_folder, interrupted_run, where):
    """No loader of files from others unpickles: animate, plot, export and --resume refuse each crafted
    folder in one line (exit 2), and a scene's from_run start does too."""
    source = interrupted_run if where == "checkpoint/state" else run_folder
    folder = _craft(tmp_path, source, where)
    commands = [["run", "--resume", str(folder)]]
    if where == "trajectory.npz":
        commands += [["animate", str(folder), "--out", str(tmp_path / "a.gif")],
                     ["plot", str(folder), "--out", str(tmp_path / "p.png")],
                     ["export", str(folder), "--to", "csv", "--out", str(tmp_path / "t.csv")]]
    for args in commands:
        code, _, err = cli(*args)
        if where == "state.npz" and args[0] == "run":
            assert code == 2 and "already completed" in one_line(err)   # a completed run is not reopened
            continue
        assert code == 2, (args, err)
        one_line(err)
    if where == "trajectory.npz":
        scene = tmp_path / "from_run.toml"
        text = SCENE.read_text().split("[initial]")[0]
        scene.write_text(f'name = "from_run"\n{text}\n[initial]\nshape = "from_run"\nrun = "{folder}"\n'
                         f'[integrator]\ndt = 0.001\nt_end = 0.1\n')
        code, _, err = cli("check", str(scene))
        assert code == 2, err
        one_line(err)


# ------------------------------------------------------------------------------------------ full disks


def _tmpfs(path: Path, size: str) -> bool:
    path.mkdir()
    return subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)],
                          capture_output=True).returncode == 0


def test_run_force_on_a_disk_too_small_keeps_what_fitted(tmp_path):
    """run --force into a 300 kB disk computed the whole run as one chunk and kept only t = 0; now every chunk
    is a checkpoint on a nearly full disk, and what fitted stays."""
    mnt = tmp_path / "mnt"
    if not _tmpfs(mnt, "300k"):
        pytest.skip("cannot mount a tmpfs here (needs root or a user namespace)")
    try:
        code, _, err = cli("run", str(SCENE), "--out", str(mnt / "run"), "--force", "-q",
                           "--set", "integrator.t_end=100")
        assert code == 4 and "the disk is full" in one_line(err)
        traj = Trajectory.open(mnt / "run")
        assert traj.frames > 50, traj.frames
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def test_sweep_into_a_full_disk_is_one_line_and_leaves_no_lock_only_folders(tmp_path):
    mnt = tmp_path / "mnt"
    if not _tmpfs(mnt, "100k"):
        pytest.skip("cannot mount a tmpfs here (needs root or a user namespace)")
    try:
        code, _, err = cli("sweep", str(SCENE), "--set", "integrator.t_end=100", "--set", "drag.b=4,5,6",
                           "--out", str(mnt / "sweep"), "--jobs", "1", "-q")
        assert code in (3, 4), err
        one_line(err)
        for folder in (mnt / "sweep").iterdir() if (mnt / "sweep").exists() else ():
            if folder.is_dir():
                assert set(os.listdir(folder)) != {".lock"}, folder
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


# --------------------------------------------------------------------------------- nesting and size bombs


@pytest.mark.parametrize("bomb", ["table", "array", "description", "size"])
def test_toml_bombs_are_one_line_and_exit_2(tmp_path, bomb):
    scene = tmp_path / "bomb.toml"
    if bomb == "table":
        scene.write_text("a = " + "{b = " * 5000 + "1" + "}" * 5000 + "\n")
    elif bomb == "array":
        scene.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    elif bomb == "description":
        scene.write_text(f'description = "{"x" * 5_000_000}"\n' + SCENE.read_text().replace("description", "#"))
    else:
        scene.write_text("# " + "x" * (17 * 2 ** 20) + "\n" + SCENE.read_text())
    started = time.monotonic()
    code, _, err = cli("check", str(scene))
    assert code == 2 and str(scene) in one_line(err)
    assert time.monotonic() - started < 60


def test_set_and_sweep_nesting_bombs_are_one_line(tmp_path):
    deep = "[" * 5000 + "]" * 5000
    for args in (["check", str(SCENE), "--set", f"rope.nodes={deep}"],
                 ["sweep", str(SCENE), "--set", f"drag.b={deep}", "--out", str(tmp_path / "s")]):
        code, _, err = cli(*args)
        assert code == 2, err
        one_line(err)


def test_csv_bombs_are_one_line(tmp_path):
    (tmp_path / "huge.csv").write_text("0,0,0\n" + "".join(f"{i},{i * 1e-3},0\n" for i in range(1, 100_002)))
    (tmp_path / "far.csv").write_text("0,0,0\n1000,1e300,0\n")
    for name, fragment in (("huge.csv", "more than 100,000 rows"), ("far.csv", "at most 1e+12")):
        scene = tmp_path / f"{name}.toml"
        scene.write_text(SCENE.read_text() + f'\n[[driven]]\nnodes = [3]\npath = "{name}"\n')
        code, _, err = cli("check", str(scene))
        assert code == 2 and fragment in one_line(err), err


# ------------------------------------------------------------------------------------------------ sweeps


@pytest.mark.slow
def test_a_sweep_of_10_000_runs_stopped_by_ctrl_c(tmp_path):
    """It left 9,919 empty run folders, listed the runs never started as "error" and reported "10000 runs
    (10000 run now, 0 kept)"."""
    out = tmp_path / "sweep"
    proc = subprocess.Popen([sys.executable, "-m", "ropesim", "sweep", str(SCENE), "--set", "drag.b=1:10:100",
                             "--set", "integrator.t_end=0.1:0.2:100", "--out", str(out), "--jobs", "1", "--yes"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 240
    while time.time() < deadline and len(list(out.glob("*/summary.json"))) < 3 and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, err = proc.communicate(timeout=240)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and err.splitlines()[0] == f"ropesim: sweep: 10,000 runs into {out}/"
    from ropesim.sweep.core import read_table

    rows = read_table(out / "results.csv")
    assert len(rows) == 10_000
    statuses = {s: sum(r["status"] == s for r in rows) for s in {r["status"] for r in rows}}
    folders = [p for p in out.iterdir() if p.is_dir()]
    ran = len(rows) - statuses["not_run"]
    assert set(statuses) <= {"completed", "interrupted", "not_run"} and 3 <= ran < 100, statuses
    assert len(folders) == ran                                 # no folder for a run that never started
    assert f"({ran} run now, 0 kept, {statuses['not_run']} not started)" in stdout


def test_a_large_sweep_asks_first(tmp_path):
    code, _, err = cli("sweep", str(SCENE), "--set", "drag.b=1:10:2000", "--out", str(tmp_path / "s"))
    assert code == 2 and "2,000 runs" in one_line(err) and "--yes" in err
    assert not (tmp_path / "s").exists()
    code, _, err = cli("sweep", str(SCENE), "--set", "drag.b=1:10:1000", "--set", "rope.nodes=3:1002:1000",
                       "--out", str(tmp_path / "s"))
    assert code == 2 and "1,000,000 combinations" in one_line(err)


def test_sweep_plot_is_checked_before_the_runs(tmp_path):
    out = tmp_path / "s"
    code, _, err = cli("sweep", str(SCENE), "--set", "drag.b=4,5", "--set", "integrator.t_end=0.1",
                       "--out", str(out), "--plot", "no.such_figure", "--jobs", "1")
    assert code == 2 and "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith("ropesim: --plot no.such_figure: not a numeric column")
    assert not out.exists() or not [p for p in out.iterdir() if p.is_dir()]       # no run started
