"""Defects found by trying ropesim as a new user would (issue 24), each pinned down by a test that failed before
its fix: a pinned chain is not a towed rope; the summary's times carry no float noise and its stretch says what
it is; `ropesim check` describes a drive held still in words and counts compiling in its run-time estimate."""

from __future__ import annotations

import json

import numpy as np
import tomli_w
from typer.testing import CliRunner

import ropesim
from ropesim.cli.app import app

runner = CliRunner()

FALLING_CHAIN = {   # docs/tutorials/your-own-rope.md's first scene
    "name": "falling_chain", "rope": {"nodes": 21, "segment_length": 0.5, "stiffness": 5000.0, "mass": 5.0},
    "initial": {"shape": "line", "start": [0.0, 0.0], "end": [10.0, 0.0]}, "pinned": {"nodes": [0]},
    "gravity": {}, "integrator": {"dt": 0.001, "t_end": 0.5}, "output": {"interval": 0.1},
}


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


def test_a_chain_only_pinned_is_not_plotted_or_summarised_as_a_towed_rope(tmp_path):
    scene = tmp_path / "falling_chain.toml"
    scene.write_text(tomli_w.dumps(FALLING_CHAIN))
    run = invoke("run", scene, "-o", tmp_path / "run")
    assert run.exit_code == 0, run.output
    assert "steeper at the bottom" not in run.stdout and "rope angle" not in run.stdout
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert "towed" not in summary
    plot = invoke("plot", tmp_path / "run")
    assert plot.exit_code == 0 and "towed" not in plot.stdout, plot.stdout
    # the helicopter, a tow at constant velocity, still gets its panel
    towed = ropesim.load_scene("helicopter_mass", ["integrator.t_end=0.2"])
    assert "towed" in ropesim.simulate(towed).summary


def test_summary_times_have_no_float_noise_and_the_stretch_says_its_unit(tmp_path):
    scene = dict(FALLING_CHAIN, integrator={"dt": 0.001, "t_end": 20.9}, output={"interval": 0.1})
    scene["rope"] = dict(scene["rope"], nodes=5)
    path = tmp_path / "chain.toml"
    path.write_text(tomli_w.dumps(scene))
    run = invoke("run", path, "-o", tmp_path / "run")
    assert run.exit_code == 0, run.output
    text = (tmp_path / "run" / "summary.json").read_text()
    assert "00000000" not in text and "99999999" not in text, text      # 20.900000000000002 and the like
    summary = json.loads(text)
    assert summary["t_end"] == 20.9
    traj = ropesim.Trajectory.open(tmp_path / "run")
    assert summary["max_spring_stretch_t"] in [float(f"{t:.12g}") for t in traj.t]
    percent = 100 * summary["max_spring_stretch"]
    assert f"{percent:.3g} % of the rest length" in run.stdout and "over the saved frames" in run.stdout


def test_check_says_a_drive_held_still_in_words(tmp_path):
    scene = dict(FALLING_CHAIN, pinned=None)
    del scene["pinned"]
    scene["driven"] = [{"nodes": [0], "amplitude": [0.0, 0.0], "period": [10.0, 10.0], "ramp_time": 27.0}]
    path = tmp_path / "still.toml"
    path.write_text(tomli_w.dumps(scene))
    result = invoke("check", path)
    assert result.exit_code == 0, result.output
    assert "sinusoid ," not in result.stdout and "ramped in" not in result.stdout
    assert "held still (every amplitude is 0)" in result.stdout


def test_checks_run_time_counts_compiling_until_the_kernel_is_cached(tmp_path, monkeypatch):
    from ropesim import kernels

    scene = ropesim.load_scene("helicopter_mass", ["integrator.t_end=0.01", "integrator.method=rk4"])
    ropesim.simulate(scene)
    assert kernels.loop_cached(scene) is True                     # a run compiled it, or loaded it
    result = invoke("check", "helicopter_mass", "--set", "integrator.method=rk4")
    assert "rk4's kernel is in the cache: no compiling" in result.stdout
    monkeypatch.setattr(kernels, "loop_cached", lambda scene: False)   # as on a first run
    result = invoke("check", "helicopter_mass", "--set", "integrator.method=rk4")
    low, high = kernels.FIRST_COMPILE_SECONDS
    assert f"after compiling rk4's kernel once ({low} to {high} s; `ropesim compile` does it ahead)" in result.stdout
