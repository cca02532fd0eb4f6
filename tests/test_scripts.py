"""The batch shell scripts in scripts/, run for real with tiny end times: outputs, progress, loud failures."""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCRIPTS = ROOT / "scripts"
SCENARIOS = ROOT / "scenarios"


@pytest.fixture(scope="module", autouse=True)
def warm_kernel_cache():
    """Compile the kernel once here: the scripts' ropesim processes (and a sweep's workers, in parallel) then
    load it from this session's cache instead of each compiling it."""
    import ropesim

    ropesim.simulate(ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml", ["integrator.t_end=0.01"]))


def has_animate() -> bool:
    result = subprocess.run(["ropesim", "animate", "--help"], capture_output=True)
    return result.returncode == 0


def run(script: str, *args: str, env: dict | None = None, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", str(SCRIPTS / script), *args], capture_output=True, text=True, cwd=cwd,
                          env={**os.environ, **(env or {})}, timeout=600)


@pytest.mark.slow
def test_run_all_runs_and_animates_each_scene(tmp_path):
    scenes = [SCENARIOS / "helicopter_parachute.toml", SCENARIOS / "shooter_high.toml"]  # an open line, a loop
    animate = has_animate()  # `ropesim animate` (issue 3) may not be in this checkout yet
    env = {"T_END": "0.05", "RUNS_DIR": "out"} | ({} if animate else {"NO_ANIMATE": "1"})
    result = run("run_all.sh", *map(str, scenes), env=env, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    for i, scene in enumerate(scenes, 1):
        name = scene.stem
        folder = tmp_path / "out" / name
        summary = json.loads((folder / "summary.json").read_text())
        assert summary["status"] == "completed" and summary["t_end"] == pytest.approx(0.05)
        assert f"[{i}/2] {name}: run -> out/{name}/" in result.stdout
        if animate:
            gif = folder / f"{name}.gif"
            assert gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")
    assert "2 scenes in out/" in result.stdout


@pytest.mark.slow
def test_run_all_takes_every_scenario_by_default(tmp_path):
    result = run("run_all.sh", env={"T_END": "0.02", "RUNS_DIR": "out", "NO_ANIMATE": "1"}, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    names = sorted(p.stem for p in SCENARIOS.glob("*.toml"))
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == names
    for name in names:
        assert json.loads((tmp_path / "out" / name / "summary.json").read_text())["status"] == "completed"


def test_run_all_stops_loudly_on_a_missing_scene(tmp_path):
    result = run("run_all.sh", str(SCENARIOS / "helicopter_mass.toml"), "nope.toml", env={"NO_ANIMATE": "1"},
                 cwd=tmp_path)
    assert result.returncode != 0
    assert result.stderr.strip() == "run_all.sh: scene file nope.toml not found"
    assert not (tmp_path / "runs").exists()  # checked before anything runs


def test_run_all_stops_loudly_when_a_run_fails(tmp_path):
    """A run that fails (dt far past the stability bound: refused) stops the script with the run's exit code."""
    bad = tmp_path / "unstable.toml"
    text = (SCENARIOS / "helicopter_uniform.toml").read_text()
    bad.write_text(text.replace("dt = 0.001", "dt = 0.2").replace("interval = 0.01", "interval = 0.2")
                   .replace("t_end = 3.0", "t_end = 100.0"))
    result = run("run_all.sh", str(bad), env={"NO_ANIMATE": "1"}, cwd=tmp_path)
    assert result.returncode != 0
    assert "stability bound" in result.stderr
    assert f"run_all.sh: ropesim run {bad} failed (exit 2)" in result.stderr


@pytest.mark.parametrize("script", ["run_all.sh", "sweep_air_resistance.sh"])
def test_scripts_say_when_ropesim_is_missing(tmp_path, script):
    bash = shutil.which("bash")
    path = os.pathsep.join(str(Path(p).parent) for p in (bash, shutil.which("dirname"), shutil.which("basename")))
    assert shutil.which("ropesim", path=path) is None
    result = run(script, env={"PATH": path}, cwd=tmp_path)
    assert result.returncode != 0
    assert "ropesim is not installed (not on PATH)" in result.stderr


@pytest.mark.slow
def test_sweep_air_resistance_collects_inclination_against_b(tmp_path):
    env = {"T_END": "0.3", "COUNT": "3", "B_MAX": "1.0", "OUT": "air", "JOBS": "2"}
    result = run("sweep_air_resistance.sh", env=env, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    with open(tmp_path / "air" / "inclination_vs_b.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["b_kg_per_s"]) for r in rows] == [0.0, 0.5, 1.0]
    sweep = list(csv.DictReader(open(tmp_path / "air" / "results.csv", newline="")))
    for row, full in zip(rows, sweep):
        assert row["status"] == "completed"
        # the table carries the run's own summary figure, and the figure is an angle
        assert float(row["mean_inclination_deg"]) == float(full["shooter.mean_loop_inclination_deg"])
        assert -180.0 <= float(row["mean_inclination_deg"]) <= 180.0
        folder = tmp_path / "air" / full["run"]
        summary = json.loads((folder / "summary.json").read_text())
        assert summary["shooter"]["mean_loop_inclination_deg"] == float(row["mean_inclination_deg"])
    assert (tmp_path / "air" / "shooter.mean_loop_inclination_deg_vs_drag.b.png").stat().st_size > 10_000
    assert "drag.b = 0..1.0 (3 values)" in result.stdout


def test_sweep_air_resistance_fails_loudly(tmp_path):
    missing = run("sweep_air_resistance.sh", "nope.toml", cwd=tmp_path)
    assert missing.returncode != 0
    assert missing.stderr.strip() == "sweep_air_resistance.sh: scene file nope.toml not found"
    # a towed rope has no loop inclination: the runs complete, the plot of the inclination refuses
    bad = run("sweep_air_resistance.sh", str(SCENARIOS / "helicopter_uniform.toml"), env={"T_END": "0.01",
                                                                                         "COUNT": "2"}, cwd=tmp_path)
    assert bad.returncode != 0
    assert "ropesim: --plot shooter.mean_loop_inclination_deg: not a numeric column" in bad.stderr
    assert "sweep_air_resistance.sh: ropesim sweep failed (exit 2" in bad.stderr
