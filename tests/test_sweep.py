"""`ropesim sweep`: value syntax, up-front validation, the product of runs, resume, failures, plots, Dask.

The physics check: a sweep over the towed rope's drag b and tow speed V must put, in each row, the angle that
row's own parameters give in steady state, tan(theta) = b V / (m g) (uniform rope, see ropesim.analysis.towed).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import ropesim
from ropesim.cli.app import app
from ropesim.scene.loader import parse_override
from ropesim.sweep.core import TIMING_COLUMNS, read_table, run_sweep
from ropesim.sweep.plan import Point, SweepError, parse_axis, plan, toml_value
from ropesim.sweep.points import run_local

UNIFORM = Path(__file__).resolve().parent.parent / "scenarios" / "helicopter_uniform.toml"
M, G = 5.0, 9.81  # helicopter_uniform: node mass [kg], gravity [m/s^2]


@pytest.fixture(scope="module", autouse=True)
def warm_kernel_cache():
    """Compile the kernel once in this process so the sweep's worker processes load it from the cache."""
    ropesim.simulate(ropesim.load_scene(UNIFORM, ["integrator.t_end=0.01"]))


# ------------------------------------------------------------------------------------ value syntax


@given(start=st.floats(-1e3, 1e3), stop=st.floats(-1e3, 1e3), count=st.integers(1, 40))
def test_range_is_inclusive_linspace(start, stop, count):
    axis = parse_axis(f"drag.b={start!r}:{stop!r}:{count}")
    assert len(axis.values) == count
    assert axis.values[0] == start and (count == 1 or axis.values[-1] == stop)  # the ends exactly as given
    scale = max(abs(start), abs(stop), 1e-300)
    assert np.allclose(axis.values, np.linspace(start, stop, count), rtol=1e-11, atol=1e-11 * scale)
    assert all(type(v) is float for v in axis.values)


def test_range_steps_are_round_numbers():
    assert parse_axis("drag.b=0:1.5:16").values == tuple(round(0.1 * i, 10) for i in range(16))


def test_range_of_an_integer_key_gives_integers():
    assert parse_axis("rope.nodes=11:61:6").values == (11, 21, 31, 41, 51, 61)
    assert parse_axis("rope.nodes=10:20:3").values == (10, 15, 20)
    assert all(type(v) is int for v in parse_axis("rope.nodes=10:21:4").values)
    with pytest.raises(SweepError, match="repeats whole numbers"):
        parse_axis("rope.nodes=2:4:5")
    # a float key given whole-number ends still gets floats
    assert parse_axis("drag.b=0:1:3").values == (0.0, 0.5, 1.0)


@pytest.mark.parametrize("text, values", [
    ("drag.b=0.1,0.4,1.0", (0.1, 0.4, 1.0)),
    ("drag.b=0.3", (0.3,)),
    ("rope.nodes=21,41", (21, 41)),
    ("driven.0.velocity=[8,0],[4.5,0]", ([8, 0], [4.5, 0])),
    ("integrator.method=verlet,pefrl", ("verlet", "pefrl")),
    ('integrator.method="verlet"', ("verlet",)),
])
def test_lists_and_single_values(text, values):
    axis = parse_axis(text)
    assert axis.values == values
    assert axis.swept == (len(values) > 1)


@pytest.mark.parametrize("text, message", [
    ("drag.b", "expected KEY=VALUES"),
    ("drag.b=", "expected KEY=VALUES"),
    ("drag.b=0:1:0", "whole number >= 1"),
    ("drag.b=0:1:2.5", "whole number >= 1"),
])
def test_bad_value_syntax(text, message):
    with pytest.raises(SweepError, match=message):
        parse_axis(text)


values = st.recursive(st.floats(allow_nan=False, allow_infinity=False) | st.integers(-10**9, 10**9)
                      | st.booleans() | st.text(max_size=8), lambda inner: st.lists(inner, max_size=3), max_leaves=6)


@given(value=values)
def test_values_pass_to_runs_exactly(value):
    """Each run's --set carries its value exactly: floats as their shortest repr, round-tripping bit for bit."""
    assert parse_override(f"k={toml_value(value)}")[1] == value


# ------------------------------------------------------------------------------------- planning


def test_plan_is_the_product_in_order_with_deterministic_names():
    sets = ["drag.b=5,10", "integrator.t_end=1", "driven.0.velocity=[8,0],[4,0],[2,0]"]
    base, axes, points = plan(UNIFORM, sets)
    assert base.integrator.t_end == 1.0
    assert [p.params for p in points] == [{"drag.b": b, "driven.0.velocity": v} for b in (5, 10)
                                          for v in ([8, 0], [4, 0], [2, 0])]
    assert points[0].name == "drag.b=5_driven.0.velocity=8,0"
    assert [p.name for p in plan(UNIFORM, sets)[2]] == [p.name for p in points]
    scene = ropesim.scene_from_toml(points[-1].scene_toml)
    assert scene.drag.b == 10.0 and scene.driven[0].velocity == (2.0, 0.0) and scene.integrator.t_end == 1.0
    assert ropesim.scene_to_toml(scene) == points[-1].scene_toml  # the resolved scene round-trips exactly


def test_close_values_get_exact_names():
    points = plan(UNIFORM, ["drag.b=1.0000001,1.0000002"])[2]
    assert [p.name for p in points] == ["drag.b=1.0000001", "drag.b=1.0000002"]
    assert plan(UNIFORM, ["drag.b=0.25,1.0000001"])[2][1].name == "drag.b=1"


@pytest.mark.parametrize("sets, words", [
    (["drag.b=1,-1"], ["drag.b", ">= 0", "-1"]),
    (["drag.bb=1,2"], ["drag.bb", "unknown key"]),
    (["rope.nodes=21,2.5"], ["rope.nodes", "integer"]),
    (["drag.b=1,2", "drag.b=3"], ["drag.b", "given twice"]),
    (["integrator.method=verlet,pefr"], ["integrator.method", "did you mean"]),
])
def test_a_bad_combination_fails_the_sweep_before_any_run(tmp_path, sets, words):
    out = tmp_path / "sweep"
    args = ["sweep", str(UNIFORM), "--out", str(out)]
    for item in sets:
        args += ["--set", item]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    line = result.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    assert all(w in line for w in words), line
    assert not out.exists()


def test_missing_scene_file(tmp_path):
    result = CliRunner().invoke(app, ["sweep", str(tmp_path / "nope.toml"), "--set", "drag.b=1,2"])
    assert result.exit_code == 2 and "nope.toml: no such scene file" in result.stderr


# ---------------------------------------------------------------------------- running and resume


@pytest.fixture(scope="module")
def towed_sweep(tmp_path_factory):
    """drag.b x tow speed on the uniform towed rope, long enough to settle (slowest mode decays as e^(-bt/2m))."""
    out = tmp_path_factory.mktemp("towed") / "sweep"
    sets = ["drag.b=5:15:3", "driven.0.velocity=[8.0,0.0],[4.0,0.0]", "integrator.t_end=20",
            "initial.velocity=[0.0,0.0]", "output.interval=0.5"]
    result = run_sweep(UNIFORM, sets, out=out, jobs=2, plots=["towed.top_angle_deg"], quiet=True)
    return sets, out, result


def test_each_row_holds_its_own_steady_angle(towed_sweep):
    sets, out, result = towed_sweep
    assert not result.failed and result.ran == 6 and result.skipped == 0
    rows = read_table(out / "results.csv")
    assert [(float(r["drag.b"]), r["driven.0.velocity"]) for r in rows] == [
        (b, v) for b in (5.0, 10.0, 15.0) for v in ("[8.0, 0.0]", "[4.0, 0.0]")]
    for row in rows:
        b, speed = float(row["drag.b"]), json.loads(row["driven.0.velocity"])[0]
        expected = math.degrees(math.atan(b * speed / (M * G)))
        # 20 s is at least 10 decay times 2m/b: what is left of a ~60 deg start is below 0.01 deg
        assert float(row["towed.top_angle_deg"]) == pytest.approx(expected, abs=0.01)
        assert float(row["towed.bottom_angle_deg"]) == pytest.approx(expected, abs=0.01)
        assert row["status"] == "completed" and row["error"] == ""
        assert float(row["t_end"]) == 20.0
    folder = out / rows[0]["run"]
    assert json.loads((folder / "summary.json").read_text())["status"] == "completed"
    assert ropesim.load_scene(folder / "scene.toml").drag.b == 5.0


def test_plot_is_written_next_to_the_table(towed_sweep):
    import matplotlib.image

    _, out, result = towed_sweep
    assert result.plots == [out / "towed.top_angle_deg_vs_drag.b.png"]
    image = matplotlib.image.imread(result.plots[0])
    assert image.shape[0] > 300 and image.shape[1] > 500


def test_plot_of_an_unknown_column_names_the_choices(towed_sweep):
    sets, out, _ = towed_sweep
    args = ["sweep", str(UNIFORM), "--out", str(out), "--plot", "towed.top_angle"]
    for item in sets:
        args += ["--set", item]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert "--plot towed.top_angle: not a numeric column" in result.stderr
    assert "towed.top_angle_deg" in result.stderr


def test_rerun_resumes_only_what_is_unfinished(towed_sweep):
    sets, out, first = towed_sweep
    rows_before = (out / "results.csv").read_text()
    again = run_sweep(UNIFORM, sets, out=out, jobs=2, quiet=True)
    assert again.ran == 0 and again.skipped == 6
    assert (out / "results.csv").read_text() == rows_before  # kept runs are read back as they were

    names = [p["run"] for p in first.rows]
    kept = {n: os.stat(out / n / "trajectory.npz").st_mtime_ns for n in names}
    interrupted, crashed, other = names[1], names[2], names[3]
    summary = json.loads((out / interrupted / "summary.json").read_text())
    (out / interrupted / "summary.json").write_text(json.dumps({**summary, "status": "interrupted"}))
    (out / crashed / "summary.json").unlink()
    (out / other / "scene.toml").write_text((out / other / "scene.toml").read_text().replace("t_end = 20.0",
                                                                                             "t_end = 19.0"))
    resumed = run_sweep(UNIFORM, sets, out=out, jobs=2, quiet=True)
    assert resumed.ran == 3 and resumed.skipped == 3 and not resumed.failed
    rerun = {n for n in names if os.stat(out / n / "trajectory.npz").st_mtime_ns != kept[n]}
    assert rerun == {interrupted, crashed, other}
    strip = [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in read_table(out / "results.csv")]
    assert strip == [{k: v for k, v in r.items() if k not in TIMING_COLUMNS}
                     for r in _csv_rows(rows_before)]


def _csv_rows(text: str) -> list[dict]:
    import csv
    import io

    return list(csv.DictReader(io.StringIO(text)))


def test_a_failed_run_is_recorded_and_the_sweep_goes_on(tmp_path):
    """dt = 0.05 s is past symplectic Euler's stability bound (0.032 s) for this rope: it overflows in 30 s."""
    out = tmp_path / "sweep"
    args = ["sweep", str(UNIFORM), "--out", str(out), "-j", "2", "--set", "integrator.dt=0.05,0.001",
            "--set", "output.interval=0.05", "--set", "integrator.t_end=30"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 3, result.output
    assert "1 of 2 runs did not complete" in result.stderr
    blew, fine = read_table(out / "results.csv")
    assert blew["status"] == "blew_up" and "blew up at t =" in blew["error"] and "dt = 0.05 s" in blew["error"]
    assert fine["status"] == "completed" and fine["error"] == "" and float(fine["t_end"]) == 30.0


def test_a_run_that_raises_is_recorded_with_its_error(tmp_path):
    bad = Point(name="bad", params={}, sets=(), scene_toml="[rope]\nnodes = 1\n")
    ((point, summary, error),) = list(run_local([(bad, tmp_path / "bad")], jobs=1))
    assert point is bad and summary is None
    assert error.startswith("SceneError: ") and "every scene needs a [initial] table" in error


@pytest.mark.slow
def test_a_method_several_runs_use_compiles_once_before_the_workers_start(monkeypatch, tmp_path):
    """Workers would each compile the same loop at the same time; the sweep compiles (or loads) it once itself.
    A method used by one run alone compiles in its worker, alongside the others."""
    import ropesim.kernels

    warmed = []
    monkeypatch.setattr(ropesim.kernels, "warm_up", lambda scene: warmed.append(scene.integrator.method))
    short = ["integrator.t_end=0.01"]
    run_sweep(UNIFORM, ["integrator.method=verlet,pefrl", "drag.b=1,2", *short], out=tmp_path / "a", jobs=2,
              quiet=True)
    assert sorted(warmed) == ["pefrl", "verlet"]
    warmed.clear()
    run_sweep(UNIFORM, ["integrator.method=verlet,pefrl", *short], out=tmp_path / "b", jobs=2, quiet=True)
    run_sweep(UNIFORM, ["drag.b=1,2", *short], out=tmp_path / "c", jobs=1, quiet=True)
    assert warmed == []


# ------------------------------------------------------------------------------------------- dask


def test_dask_cluster_gives_the_local_results_bit_for_bit(towed_sweep, tmp_path):
    distributed = pytest.importorskip("distributed", reason='the dask extra is not installed: '
                                                            'pip install -e ".[dask]"')
    sets, local_out, local = towed_sweep
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, protocol="tcp",
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        remote = run_sweep(UNIFORM, sets, out=out, scheduler=cluster.scheduler_address, quiet=True)
    assert remote.ran == 6 and not remote.failed

    def figures(folder):
        return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in read_table(folder / "results.csv")]

    assert figures(out) == figures(local_out)
    for row in local.rows:
        a, b = ropesim.Trajectory.open(local_out / row["run"]), ropesim.Trajectory.open(out / row["run"])
        for name in ("t", "x", "v"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), (row["run"], name)
        assert (local_out / row["run"] / "scene.toml").read_text() == (out / row["run"] / "scene.toml").read_text()


def test_unreachable_scheduler_is_one_line(tmp_path, monkeypatch):
    pytest.importorskip("distributed", reason='the dask extra is not installed: pip install -e ".[dask]"')
    from ropesim.sweep import dask as sweep_dask

    monkeypatch.setattr(sweep_dask, "CONNECT_TIMEOUT", "1s")
    args = ["sweep", str(UNIFORM), "--out", str(tmp_path / "s"), "--set", "drag.b=1,2",
            "--set", "integrator.t_end=0.01", "--scheduler", "tcp://127.0.0.1:9"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert "--scheduler tcp://127.0.0.1:9: cannot connect" in result.stderr


@settings(max_examples=5, deadline=None)
@given(count=st.integers(2, 5))
def test_range_count_is_the_number_of_runs(count):
    """The count in start:stop:count is how many runs a swept key contributes."""
    axis = parse_axis(f"drag.b=0.1:1.5:{count}")
    assert len(axis.values) == count and axis.swept


@pytest.mark.slow
def test_ctrl_c_stops_the_runs_cleanly_and_the_table_says_so(tmp_path):
    """Ctrl-C (SIGINT to the terminal's process group): runs stop at their next chunk, keep their frames, and
    the table marks them interrupted, so a rerun would run them again; exit code 130."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "sweep"
    cmd = [sys.executable, "-m", "ropesim", "sweep", str(UNIFORM), "--out", str(out), "-j", "2",
           "--set", "drag.b=4,6", "--set", "integrator.t_end=1e6", "--set", "output.interval=10"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 180
        while sum(f.stat().st_size > 4096 for f in out.glob("*/checkpoint/x.npy")) < 2:  # both are integrating
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.2)
        time.sleep(0.5)
        os.killpg(proc.pid, signal.SIGINT)
        _, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, stderr
    assert "sweep interrupted; rerun the same command to finish it" in stderr
    rows = read_table(out / "results.csv")
    assert [r["status"] for r in rows] == ["interrupted", "interrupted"]
    for row in rows:
        assert row["error"].startswith("interrupted at t = ")
        traj = ropesim.Trajectory.open(out / row["run"])
        assert traj.t[-1] < 1e6 and np.all(np.isfinite(traj.x))  # the frames up to the stop, kept
        assert (out / row["run"] / "checkpoint").is_dir()  # kept for the rerun to resume


def _children(pid: int) -> list[int]:
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _workers(pid: int) -> list[int]:
    """The sweep's worker processes (its children but multiprocessing's resource tracker)."""
    def cmdline(child: int) -> bytes:
        try:
            return Path(f"/proc/{child}/cmdline").read_bytes()
        except OSError:
            return b""

    return [child for child in _children(pid) if b"spawn_main" in cmdline(child)]


@pytest.mark.slow
@pytest.mark.parametrize("signals", [["SIGTERM"], ["SIGTERM", "SIGTERM", "SIGHUP", "SIGINT"]],
                         ids=["once", "again-while-it-stops"])
def test_sigterm_stops_the_sweep_writes_the_table_and_leaves_no_process(tmp_path, signals):
    """SIGTERM to the sweep alone (as `timeout` or a batch scheduler sends it): exit 143; every run that started
    stops at its next chunk keeping its checkpoint and its row says interrupted; every run not started says
    not_run and has no folder; no run starts after the signal; results.csv is whole; no worker is left behind.

    The signal goes once both workers integrate a run of 10^6 s (their frames stream), a state that lasts: no
    third run can start before it. More signals while the sweep stops (an impatient user, a scheduler's
    second notice) change nothing: one used to cut the pool's shutdown short, so the table was written before
    the stopped runs' summaries (all four rows said not_run) and the sweep never exited."""
    import signal
    import subprocess
    import sys
    import time

    from ropesim.io.runfolder import holder

    out = tmp_path / "sweep"
    cmd = [sys.executable, "-m", "ropesim", "sweep", str(UNIFORM), "--out", str(out), "-j", "2",
           "--set", "drag.b=4,5,6,7", "--set", "integrator.t_end=1e6", "--set", "output.interval=10"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 180
        while len(running := {f.parent.parent.name for f in out.glob("*/checkpoint/x.npy")
                              if f.stat().st_size > 4096}) < 2:
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.2)
        workers = _workers(proc.pid)
        started = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        for name in signals[1:]:     # while the workers still stop, so inside the sweep's stop for sure
            time.sleep(0.01)
            if any(_alive(pid) for pid in workers):
                proc.send_signal(getattr(signal, name))
        _, stderr = proc.communicate(timeout=120)
        took = time.monotonic() - started
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 143, stderr
    assert "sweep interrupted by SIGTERM" in stderr and took < 30
    assert len(workers) == 2 and not [pid for pid in workers if _alive(pid)], "worker processes left behind"
    rows = read_table(out / "results.csv")
    assert [r["run"] for r in rows] == [f"drag.b={b}" for b in (4, 5, 6, 7)]
    assert sorted(p.name for p in out.iterdir()) == sorted([*running, "results.csv"])   # none started after
    for row in rows:
        folder = out / row["run"]
        if row["run"] in running:
            assert row["status"] == "interrupted" and row["error"].startswith("interrupted at t = "), row
            assert json.loads((folder / "summary.json").read_text())["status"] == "interrupted"
            assert json.loads((folder / "manifest.json").read_text())["status"] == "interrupted"
            assert (folder / "checkpoint").is_dir() and holder(folder) is None   # kept to resume, not locked
        else:
            assert row["status"] == "not_run" and row["error"] == "", row
