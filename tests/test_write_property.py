"""A property of every command that writes: whatever folder state it meets, it never changes a file that ropesim
did not write (issue 26).

Hypothesis draws a writing command (run, sweep, export to VTK or CSV, frames, plot, animate, new, equilibrium,
accuracy, stability) with its output pointed at a place in a fresh workspace, and a state for that place: missing,
an empty folder, a folder of the user's files, a file of the user's, a link to either, a ropesim run folder with or
without the user's files in it. Afterwards every file and link the user made is byte-identical, and the command
ended with an exit code of the CLI reference (0, 1, 2, 3 or 4) and without a traceback. Replacing the user's
own scene file with ``new --force`` / ``equilibrium --force`` is a request to do so, so --force is not drawn.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from typer.testing import CliRunner

import ropesim
from ropesim.cli.app import app
from ropesim.run import simulate

from test_faults_hostile import snapshot

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenarios" / "helicopter_mass.toml"
QUICK = ["--set", "integrator.t_end=0.1"]

# command -> (arguments with RUN for a run folder to read and OUT for the output, what OUT is: a folder or a file)
COMMANDS = {
    "run": (["run", str(SCENE), *QUICK, "--out", "OUT", "-q"], "folder"),
    "sweep": (["sweep", str(SCENE), *QUICK, "--set", "drag.b=4,5", "--out", "OUT", "--jobs", "1", "-q"], "folder"),
    "export vtk": (["export", "RUN", "--to", "vtk", "--out", "OUT", "-q"], "folder"),
    "export csv": (["export", "RUN", "--to", "csv", "--out", "OUT", "-q"], "file.csv"),
    "frames": (["frames", "RUN", "--out", "OUT", "-q"], "file.png"),
    "plot": (["plot", "RUN", "--out", "OUT", "-q"], "file.png"),
    "animate": (["animate", "RUN", "--out", "OUT", "--end", "0.05", "--size", "320", "-q"], "file.gif"),
    "new": (["new", "OUT"], "file.toml"),
    "view": (["view", "RUN", "--out", "OUT", "--no-open"], "file.html"),
    "equilibrium": (["equilibrium", "cantilever_beam", "--out", "OUT"], "file.toml"),
    "accuracy": (["accuracy", str(SCENE), *QUICK, "--methods", "symplectic_euler", "--dts", "0.01",
                  "--repeats", "1", "--out", "OUT"], "folder"),
    "stability": (["stability", str(SCENE), *QUICK, "--methods", "symplectic_euler", "--fractions", "0.5",
                   "--steps", "10", "--out", "OUT"], "folder"),
}
STATES = ("missing", "empty folder", "user folder", "user file", "link to user folder", "link to user file",
          "dangling link", "run folder", "run folder with user files")
CODES = {0, 1, 2, 3, 4}


@pytest.fixture(scope="module")
def source_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("source") / "run"
    simulate(ropesim.load_scene(SCENE, ["integrator.t_end=0.2"]), folder)
    return folder


def _user_files(folder: Path) -> None:
    (folder / "sub").mkdir(parents=True, exist_ok=True)
    (folder / "notes.txt").write_text("the user's notes")
    (folder / "sub" / "data.bin").write_bytes(bytes(range(256)))
    for name in ("x.csv", "x.png", "x.gif", "x.toml", "x.html", "results.csv", "accuracy.csv", "stability.png"):
        (folder / name).write_bytes(b"the user's " + name.encode())


def make_state(work: Path, state: str, kind: str, source: Path) -> Path:
    """Lay out ``state`` at ``work/out`` and return the path to give the command (``out`` itself for a folder
    output, a file in or at it for a file output)."""
    out = work / "out"
    elsewhere = work / "elsewhere"
    elsewhere.mkdir()
    if state == "empty folder":
        out.mkdir()
    elif state == "user folder":
        _user_files(out)
    elif state == "user file":
        out.write_bytes(b"the user's file")
    elif state == "link to user folder":
        _user_files(elsewhere)
        out.symlink_to(elsewhere)
    elif state == "link to user file":
        (elsewhere / "file").write_bytes(b"the user's linked file")
        out.symlink_to(elsewhere / "file")
    elif state == "dangling link":
        out.symlink_to(work / "nowhere" / "at-all")
    elif state.startswith("run folder"):
        shutil.copytree(source, out)
        if state.endswith("user files"):
            _user_files(out)
    if kind == "folder" or state in ("user file", "link to user file", "dangling link"):
        return out
    return out / f"x{kind[4:]}"         # a file inside the place: x.csv, x.png, ... (the user's own, if there)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(command=st.sampled_from(sorted(COMMANDS)), state=st.sampled_from(STATES))
def test_no_writing_command_changes_a_file_ropesim_did_not_write(source_run, command, state):
    args, kind = COMMANDS[command]
    work = Path(tempfile.mkdtemp(prefix="ropesim-property-"))
    try:
        target = make_state(work, state, kind, source_run)
        user = snapshot(work)                     # everything here now is the user's (the run copy too: as made)
        if state.startswith("run folder"):
            user = {k: v for k, v in user.items() if not k.startswith("out/") or k.split("/")[1] in (
                "notes.txt", "sub", "x.csv", "x.png", "x.gif", "x.toml", "x.html", "results.csv", "accuracy.csv",
                "stability.png")}
        line = [a.replace("RUN", str(source_run)).replace("OUT", str(target)) for a in args]
        result = CliRunner().invoke(app, line)
        assert result.exit_code in CODES, (line, result.output)
        assert result.exception is None or isinstance(result.exception, SystemExit), (line, result.output)
        assert "Traceback" not in result.output
        after = snapshot(work)
        changed = {k for k, v in user.items() if after.get(k) != v}
        assert not changed, (line, state, sorted(changed), result.output)
    finally:
        shutil.rmtree(work, ignore_errors=True)
