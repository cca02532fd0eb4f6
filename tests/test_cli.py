"""The command line end to end: `ropesim run` on every built-in scene (short t_end), the run folder it writes,
determinism from the resolved scene, errors as one line with exit code 2, `check`, `--help`, and a real
subprocess run of `python -m ropesim` and of the `ropesim` console script."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ropesim
from typer.testing import CliRunner

from ropesim.model.build import build
from ropesim.cli.app import app
from ropesim.integrate.methods import METHODS
from ropesim.analysis.towed import towed_end
from ropesim.scene.loader import load_scene

from conftest import ROOT, SCENARIOS

T_END, DT, INTERVAL = 0.05, 0.001, 0.01  # every scene is run for 50 ms, saving every 10 ms; most step 1 ms
SHORT = f"integrator.t_end={T_END}"
SHORT_RUN = (SHORT, f"output.interval={INTERVAL}")   # each scene keeps its own dt
SCENES = sorted(p.stem for p in SCENARIOS.glob("*.toml"))
ENV = {"COLUMNS": "200"}  # wide rich tables, so printed figures are not wrapped
TIMING_KEYS = {"wall_time_s", "compile_time_s", "steps_per_second", "node_steps_per_second"}

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(app, [str(a) for a in args], env=ENV)


def read_npz(folder: Path) -> dict[str, np.ndarray]:
    with np.load(folder / "trajectory.npz") as data:
        return {k: data[k] for k in data.files}


def read_summary(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


def assert_one_line_error(result, *fragments: str) -> str:
    """Exit code 2, nothing on stdout, one line on stderr that contains every fragment, and no traceback."""
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr
    assert lines[0].startswith("ropesim: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


class _Runs(dict):
    """Scenarios run through the CLI with t_end = 0.05 s, each the first time a test asks for it:
    {name: (result, run folder)}."""

    def __init__(self, base: Path):
        super().__init__()
        self.base = base

    def __missing__(self, name: str) -> tuple:
        folder = self.base / name
        sets = [a for key in SHORT_RUN for a in ("--set", key)]
        self[name] = (invoke("run", SCENARIOS / f"{name}.toml", *sets, "--out", folder), folder)
        return self[name]


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> _Runs:
    return _Runs(tmp_path_factory.mktemp("runs"))


# buoy_tether's sdirk2 loop with five fluid terms compiles for 20 s of CPU, alone a tenth of the quick loop: it
# runs in the slow suite, every other scene in both.
EVERY_SCENE = [pytest.param(n, marks=pytest.mark.slow) if n == "buoy_tether" else n for n in SCENES]


# ------------------------------------------------------------------------------- run on every scene


@pytest.mark.parametrize("name", EVERY_SCENE)
def test_run_writes_exactly_the_run_folder(runs, name):
    result, folder = runs[name]
    assert result.exit_code == 0, (result.output, result.exception)
    assert result.stderr == ""
    assert f"{name}: completed" in result.stdout and str(folder) in result.stdout
    names = {p.name for p in folder.iterdir()}
    assert names == {"scene.toml", "summary.json", "trajectory.npz", "ledger.npz", "manifest.json", "state.npz"}
    # atomic writes leave no temporary files, checkpoint streams or lock behind
    assert not [n for n in names if n.startswith(".") or n.endswith(".tmp")], names


@pytest.mark.parametrize("name", EVERY_SCENE)
def test_trajectory_covers_zero_to_t_end(runs, name):
    _, folder = runs[name]
    scene = load_scene(SCENARIOS / f"{name}.toml", list(SHORT_RUN))
    model = build(scene)
    arrays = read_npz(folder)
    t, x, v = arrays["t"], arrays["x"], arrays["v"]
    frames = round(T_END / INTERVAL) + 1
    n, d = model.nodes, scene.dimension   # a system's nodes: every line's, line after line
    assert t.shape == (frames,) and x.shape == (frames, n, d) and v.shape == (frames, n, d)
    assert t.dtype == x.dtype == v.dtype == np.float64
    np.testing.assert_allclose(t, np.linspace(0.0, T_END, frames), rtol=0, atol=1e-14)
    assert t[0] == 0.0
    if scene.rigid_bodies:
        # a body's line ends: placed at t = 0 by the compiled code from its pose, x0 by NumPy (round-off apart)
        scale = np.abs(model.x0).max()
        np.testing.assert_allclose(x[0], model.x0.T, rtol=0, atol=4e-16 * scale)
        np.testing.assert_allclose(v[0], model.v0.T, rtol=0, atol=4e-16 * max(np.abs(model.v0).max(), 1.0))
    else:
        np.testing.assert_array_equal(x[0], model.x0.T)
        np.testing.assert_array_equal(v[0], model.v0.T)
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(v))
    for drive in scene.driven:  # driven nodes sit on x0 + V t (+ their ramped sinusoid) at every saved frame
        assert drive.path_table is None, "teach this test the path"
        # the ramp r = 10 s^3 - 15 s^4 + 6 s^5, s = t / ramp_time (smootherstep), and its rate
        s = np.minimum(t / drive.ramp_time, 1.0) if drive.ramp_time > 0 else np.ones_like(t)
        ramp = s ** 3 * (10 - 15 * s + 6 * s ** 2)
        dramp = 30 * s ** 2 * (1 - s) ** 2 / drive.ramp_time if drive.ramp_time > 0 else np.zeros_like(t)
        wave, dwave = np.zeros((frames, d)), np.zeros((frames, d))
        for axis in range(d) if drive.amplitude is not None else ():
            a, phase = drive.amplitude[axis], math.radians(drive.phase[axis])
            if a != 0.0:
                omega = 2 * math.pi / drive.period[axis]
                wave[:, axis] = a * (np.sin(omega * t + phase) - math.sin(phase))
                dwave[:, axis] = a * omega * np.cos(omega * t + phase)
        for i in drive.nodes:
            i = scene.node(i)
            expected = model.x0[:, i] + np.outer(t, drive.velocity) + ramp[:, None] * wave
            np.testing.assert_allclose(x[:, i], expected, rtol=0, atol=1e-12)
            speed = np.broadcast_to(drive.velocity, (frames, d)) + dramp[:, None] * wave + ramp[:, None] * dwave
            np.testing.assert_allclose(v[:, i], speed, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", EVERY_SCENE)
def test_summary_figures_agree_with_the_trajectory(runs, name):
    """The summary's figures, recomputed independently from trajectory.npz and the scene."""
    _, folder = runs[name]
    scene = load_scene(folder / "scene.toml")
    model = build(scene)
    arrays = read_npz(folder)
    x, v = arrays["x"], arrays["v"]
    s = read_summary(folder)

    assert s["scene"] == name and s["status"] == "completed" and s["method"] == scene.integrator.method
    dt = scene.integrator.dt   # 1 ms, but 20 us for string_shooter_real's light, stiff string
    assert s["t_end"] == pytest.approx(T_END, abs=1e-15) and s["dt"] == pytest.approx(dt, rel=1e-12)
    assert s["steps"] == round(T_END / dt) and s["frames"] == len(arrays["t"]) and s["nodes"] == model.nodes
    assert "dt_requested" not in s
    assert s["wall_time_s"] >= 0 and s["compile_time_s"] >= 0
    wall, rate = s["wall_time_s"], s["steps_per_second"]
    if wall > 1e-6:  # wall_time_s is rounded to the microsecond, steps_per_second to 0.1 /s
        assert s["steps"] / (wall + 5e-7) - 0.1 <= rate <= s["steps"] / (wall - 5e-7) + 0.1

    energy = s["final_energy_J"]
    kinetic = 0.5 * np.sum(model.mass[:, None] * v[-1] ** 2)
    assert energy["kinetic"] == pytest.approx(kinetic, rel=1e-12)
    if scene.gravity is not None:
        assert energy["gravity"] == pytest.approx(scene.gravity.g * model.mass @ x[-1, :, 1], rel=1e-12, abs=1e-9)
    assert energy["total"] == pytest.approx(sum(val for k, val in energy.items() if k != "total"), rel=1e-12)

    stretches = []   # each line's segments (a rope: the one line), line after line
    for line in model.lines:
        nodes = x[:, line.first:line.first + line.nodes]
        closing = nodes[:, :1] if line.closed else nodes[:, :0]
        segments = np.diff(np.concatenate([nodes, closing], axis=1), axis=1)
        stretches.append(np.linalg.norm(segments, axis=2) / line.segment_length - 1)
    stretch = np.concatenate(stretches, axis=1)
    assert s["max_spring_stretch"] == pytest.approx(stretch.max(), rel=1e-9)
    assert s["max_spring_stretch_t"] == pytest.approx(arrays["t"][np.unravel_index(stretch.argmax(),
                                                                                   stretch.shape)[0]])

    if towed_end(scene) is not None:
        towed = s["towed"]
        seg = np.diff(x[-1], axis=0)  # from the helicopter down; it flies towards +x, so trailing is -x
        angles = np.degrees(np.arctan2(-seg[:, 0], -seg[:, 1]))
        assert towed["top_angle_deg"] == pytest.approx(angles[0], abs=1e-4)
        assert towed["bottom_angle_deg"] == pytest.approx(angles[-1], abs=1e-4)
        assert towed["shape"] in ("straight", "steeper at the bottom", "flatter at the bottom")
        assert "shooter" not in s
    elif scene.thrower is not None:
        shooter = s["shooter"]
        d = x[-1].mean(axis=0) - np.asarray(scene.thrower.center)
        assert shooter["loop_inclination_deg"] == pytest.approx(math.degrees(math.atan2(d[0], -d[1])), abs=1e-3)
        assert "towed" not in s
    else:
        assert "towed" not in s and "shooter" not in s


@pytest.mark.parametrize("name", EVERY_SCENE)
def test_rerun_from_the_resolved_scene_is_bit_identical(runs, name, tmp_path):
    _, folder = runs[name]
    resolved = folder / "scene.toml"
    assert load_scene(resolved) == load_scene(SCENARIOS / f"{name}.toml", list(SHORT_RUN))
    result = invoke("run", resolved, "--out", tmp_path / "again", "--quiet")
    assert result.exit_code == 0 and result.stdout == "" and result.stderr == ""
    first, second = read_npz(folder), read_npz(tmp_path / "again")
    for key in ("t", "x", "v"):
        assert np.array_equal(first[key], second[key]), key
    assert (tmp_path / "again" / "scene.toml").read_text() == resolved.read_text()
    a, b = read_summary(folder), read_summary(tmp_path / "again")
    assert {k: val for k, val in a.items() if k not in TIMING_KEYS} == {k: val for k, val in b.items()
                                                                        if k not in TIMING_KEYS}


# -------------------------------------------------------------------------------- the time grid


def test_t_end_not_a_multiple_of_dt_shrinks_dt(tmp_path):
    result = invoke("run", SCENARIOS / "helicopter_uniform.toml", "--set", "integrator.t_end=0.0505",
                    "--out", tmp_path)
    assert result.exit_code == 0, result.output
    assert "shortened" in result.stdout
    s = read_summary(tmp_path)
    steps = 51  # the fewest steps no longer than the requested 1 ms
    assert s["steps"] == steps and s["dt_requested"] == DT
    assert s["dt"] == pytest.approx(0.0505 / steps, rel=1e-14) and s["dt"] < DT
    t = read_npz(tmp_path)["t"]
    # every 10th step (10 h = 9.9 ms rounds to the 10 ms interval) and the last one
    np.testing.assert_allclose(t, [*(10 * k * s["dt"] for k in range(6)), 0.0505], rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", ["helicopter_mass", "shooter_low"])
def test_t_end_zero_gives_the_initial_frame_alone(name, tmp_path):
    result = invoke("run", SCENARIOS / f"{name}.toml", "--set", "integrator.t_end=0", "--out", tmp_path, "-q")
    assert result.exit_code == 0, (result.output, result.exception)
    arrays = read_npz(tmp_path)
    model = build(load_scene(tmp_path / "scene.toml"))
    assert arrays["t"].tolist() == [0.0]
    np.testing.assert_array_equal(arrays["x"][0], model.x0.T)
    s = read_summary(tmp_path)
    assert s["steps"] == 0 and s["frames"] == 1 and s["status"] == "completed"


def test_t_end_far_below_dt_is_one_step(tmp_path):
    scene = SCENARIOS / "helicopter_uniform.toml"
    assert invoke("check", scene, "--set", "integrator.t_end=1e-320").exit_code == 0
    result = invoke("run", scene, "--set", "integrator.t_end=1e-320", "--out", tmp_path, "-q")
    assert result.exit_code == 0, (result.output, result.exception)
    assert read_npz(tmp_path)["t"].tolist() == [0.0, 1e-320]


# ---------------------------------------------------------------------------------------- errors


def _bad_scene(tmp_path: Path) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text((SCENARIOS / "helicopter_uniform.toml").read_text().replace("mass = 5.0", "mas = 5.0"))
    return path


@pytest.mark.parametrize("command", ["run", "check"])
def test_bad_scene_is_one_line_and_exit_2(command, tmp_path):
    path = _bad_scene(tmp_path)
    args = ["--out", tmp_path / "out"] if command == "run" else []
    assert_one_line_error(invoke(command, path, *args), f"{path}: rope.mas: unknown key", "did you mean 'mass'?")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", ["run", "check"])
@pytest.mark.parametrize("item,fragments", [
    ("rope.nodes=1", ["(with --set rope.nodes=1): rope.nodes: must be an integer >= 2"]),
    ("integrator.dt=-1", ["integrator.dt: must be a number > 0 [s], got -1"]),
    ("rope.nodes", ["--set: expected KEY=VALUE"]),
    ("guides.x.radius=1", ["guides.x: is a list"]),
    ("integratr.dt=0.1", ["integratr: unknown key", "did you mean 'integrator'?"]),
])
def test_bad_set_is_one_line_and_exit_2(command, item, fragments, tmp_path):
    scene = SCENARIOS / "shooter_low.toml"
    args = ["--out", tmp_path / "out"] if command == "run" else []
    assert_one_line_error(invoke(command, scene, "--set", item, *args), str(scene), *fragments)


@pytest.mark.parametrize("command", ["run", "check"])
def test_missing_or_invalid_file(command, tmp_path):
    assert_one_line_error(invoke(command, tmp_path / "nope.toml"), f"{tmp_path / 'nope.toml'}: no such scene file")
    broken = tmp_path / "broken.toml"
    broken.write_text("[rope\nnodes = 3\n")
    assert_one_line_error(invoke(command, broken), f"{broken}: not valid TOML")


def test_out_that_cannot_be_a_folder(tmp_path):
    scene = SCENARIOS / "helicopter_uniform.toml"
    a_file = tmp_path / "taken"
    a_file.write_text("")
    assert_one_line_error(invoke("run", scene, "--set", SHORT, "--out", a_file), "exists and is not a folder")
    assert_one_line_error(invoke("run", scene, "--set", SHORT, "--out", a_file / "sub"),
                          "cannot write the run folder")


# ------------------------------------------------------------------------------- check and help


def test_check_prints_the_stability_bound():
    """helicopter_uniform: every free node is a chain node of mass m with two springs k, so the Gershgorin
    bound on the fastest mode is 2 sqrt(k/m) = 63.25 rad/s, and symplectic Euler is stable for dt <= 2/omega."""
    k, m = 5000.0, 5.0
    omega = 2 * math.sqrt(k / m)
    result = invoke("check", SCENARIOS / "helicopter_uniform.toml")
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "valid scene 'helicopter_uniform'" in out and "21 nodes, open line, 2-D" in out
    assert f"{omega:.4g} rad/s" in out
    bound = f"{2 / omega:.4g} s"

    def this_scene(text: str) -> str:
        lines = [line for line in text.splitlines() if "<- this scene" in line]
        assert len(lines) == 1 and "symplectic_euler" in lines[0] and bound in lines[0], text
        return lines[0]

    assert "is stable" in this_scene(out)
    for method in METHODS:  # a line for every method, and an A-stable one says so rather than "dt <= inf"
        assert any(line.strip("│ ").startswith(method) for line in out.splitlines()), method
    assert not re.search(r"\binf\b", out)
    unstable = invoke("check", SCENARIOS / "helicopter_uniform.toml", "--set", "integrator.dt=0.05",
                      "--set", "output.interval=0.1")
    assert unstable.exit_code == 0 and "is UNSTABLE" in this_scene(unstable.stdout)


def test_check_lists_the_parts_of_a_shooter():
    result = invoke("check", SCENARIOS / "shooter_low_one_sided.toml", "--set", "integrator.method=verlet")
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "60 nodes, closed loop" in out and "bending (k2 = 500 N/m)" in out and "2 guide circles" in out
    assert "thrower (v_max = 5 m/s)" in out and "verlet, dt = 0.001 s, t_end = 5 s (5000 steps, 501 frames)" in out


@pytest.mark.parametrize("args,fragments", [
    (["--help"], ["run", "check", "scenarios", "new", "ropesim run helicopter_mass", "--version"]),
    (["-h"], ["run", "check"]),
    (["run", "--help"], ["SCENE", "built-in scene", "--out", "runs/<scene name>/", "--set", "KEY=VALUE",
                         "integrator.dt=0.002", "--quiet", "trajectory.npz"]),
    (["check", "--help"], ["SCENE", "--set", "KEY=VALUE", "stability bound"]),
    (["export", "--help"], ["pip install 'pyropesim[export]'", "(t [s], node, x [m]", "NetCDF is not offered"]),
])
def test_help(args, fragments):
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    for fragment in fragments:
        assert fragment in result.stdout, fragment


def _commands() -> list[str]:
    from typer.main import get_command

    return sorted(get_command(app).commands)


@pytest.mark.parametrize("columns", ["80", "200"])
def test_every_help_shows_flags_without_a_type_and_paragraphs_unbroken(columns):
    """A flag takes no value, so help shows no `<bool>` after it; a docstring's paragraph is wrapped to the
    terminal, never broken where its source lines ended (a line shorter than the width, then more words)."""
    for args in [["--help"]] + [[name, "--help"] for name in _commands()]:
        result = runner.invoke(app, args, env={"COLUMNS": columns})
        assert result.exit_code == 0, (args, result.output)
        assert "<bool>" not in result.stdout, args
        assert re.search(r"--help\s+-h\s+Show this message", result.stdout), args
    wide = runner.invoke(app, ["plot", "--help"], env={"COLUMNS": "200"}).stdout
    assert "against the exact steady state; a string shooter's loop inclination over time." in wide


def test_version():
    for flag in ("--version", "-V"):
        result = invoke(flag)
        assert result.exit_code == 0 and result.stdout == f"ropesim {ropesim.__version__}\n"


# ---------------------------------------------------------------------------- real processes


def _ropesim_script() -> str:
    found = shutil.which("ropesim") or str(Path(sys.executable).parent / "ropesim")
    assert Path(found).exists(), "the ropesim console script is not installed (pip install -e .)"
    return found


def _proc(*args, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=ROOT, timeout=300,
                          env={**os.environ, **ENV}, **kw)


def test_python_m_ropesim_runs_a_scene_like_the_in_process_cli(runs, tmp_path):
    proc = _proc(sys.executable, "-m", "ropesim", "run", "scenarios/helicopter_mass.toml", "--set", SHORT,
                 "--out", tmp_path, "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == ""
    first, second = read_npz(runs["helicopter_mass"][1]), read_npz(tmp_path)
    for key in ("t", "x", "v"):
        assert np.array_equal(first[key], second[key]), key


def test_console_script_checks_and_refuses():
    script = _ropesim_script()
    ok = _proc(script, "check", "scenarios/shooter_low.toml")
    assert ok.returncode == 0 and "valid scene 'shooter_low'" in ok.stdout, ok.stderr
    bad = _proc(script, "run", "scenarios/shooter_low.toml", "--set", "rope.mass=0")
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.splitlines() == [
        "ropesim: scenarios/shooter_low.toml (with --set rope.mass=0): rope.mass: must be a number > 0 [kg], "
        "got 0.0"]


def test_help_does_not_load_numba_or_matplotlib():
    code = ("import sys; from typer.testing import CliRunner; from ropesim.cli import app; "
            "r = CliRunner().invoke(app, ['run', '--help']); assert r.exit_code == 0, r.output; "
            "print(sorted(m for m in ('numba', 'matplotlib') if m in sys.modules))")
    proc = _proc(sys.executable, "-c", code)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
