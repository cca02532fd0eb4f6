"""The run loop: determinism, chunking, clean stops (interrupt, blow-up), the time grid, the run folder."""

import json
import os
import signal
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest

import ropesim
from ropesim.model.build import build
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.run import BLEW_UP, INTERRUPTED, integrate
from ropesim.io.trajectory import FrameStore, Trajectory


@pytest.mark.parametrize("name, method", [("helicopter_mass", "verlet"), ("shooter_low", "symplectic_euler"),
                                          ("helicopter_parachute", "yoshida4"), ("shooter_high", "pefrl")])
def test_chunking_never_changes_the_numbers(scenarios, name, method):
    """1000 steps at once, or in uneven pieces, give bit-identical states (forces reused across chunks)."""
    scene = ropesim.load_scene(scenarios / f"{name}.toml", [f"integrator.method={method}"])
    model = build(scene)
    grid = TimeGrid.of(scene)
    whole = make_integrator(model, grid, method)
    whole.advance(1000)
    pieces = make_integrator(model, grid, method)
    for n in (1, 7, 92, 400, 500):
        pieces.advance(n)
    assert np.array_equal(whole.x, pieces.x) and np.array_equal(whole.v, pieces.v)


def test_same_input_same_output(scenarios):
    scene = ropesim.load_scene(scenarios / "shooter_medium.toml", ["integrator.t_end=0.5"])
    a, b = ropesim.simulate(scene), ropesim.simulate(scene)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.v, b.v) and np.array_equal(a.t, b.t)


def test_held_nodes_follow_their_path_exactly(scenarios):
    """The helicopter's node is at x0 + V t at every saved frame, to round-off."""
    scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml", ["integrator.method=pefrl"])
    traj = ropesim.simulate(scene)
    np.testing.assert_allclose(traj.x[:, 0, 0], 8.0 * traj.t, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(traj.x[:, 0, 1], 0.0)
    np.testing.assert_array_equal(traj.v[:, 0], np.tile([8.0, 0.0], (traj.frames, 1)))


@pytest.mark.parametrize("dt, t_end, interval, steps, frames", [
    (0.001, 3.0, 0.01, 3000, 301),
    (0.003, 0.01, 0.003, 4, 5),        # 0.01 / 0.003 is not whole: 4 steps of 0.0025 s, a frame each
    (0.001, 0.0, 0.01, 0, 1),          # t_end = 0: just the initial frame
    (0.001, 0.0155, 0.01, 16, 3),      # frames at 0, 10 steps and the last step
])
def test_time_grid(scenarios, dt, t_end, interval, steps, frames):
    scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml",
                               [f"integrator.dt={dt}", f"integrator.t_end={t_end}", f"output.interval={interval}"])
    grid = TimeGrid.of(scene)
    assert (grid.steps, grid.frames) == (steps, frames)
    assert grid.dt <= dt and (grid.steps * grid.dt == pytest.approx(t_end))
    traj = ropesim.simulate(scene)
    assert traj.frames == frames and traj.t[0] == 0.0 and traj.t[-1] == pytest.approx(t_end, abs=1e-15)
    assert np.all(np.diff(traj.t) > 0)


def test_blow_up_stops_cleanly_and_keeps_frames(scenarios, tmp_path):
    """Above the stability bound (0.0316 s here) the run stops, names the node and a stable dt, keeps frames."""
    scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml",
                               ["integrator.dt=0.05", "integrator.t_end=60", "output.interval=0.05"])
    traj = ropesim.simulate(scene, tmp_path / "run")
    s = traj.summary
    assert s["status"] == BLEW_UP
    assert "node" in s["message"] and "would be stable" in s["message"]
    assert 0 < s["steps"] < 1200 and traj.frames >= 1
    assert np.all(np.isfinite(traj.x)), "only frames from before the blow-up are kept"
    stable = float(s["message"].split("time step of ")[1].split(" s")[0])
    rerun = ropesim.simulate(ropesim.load_scene(scenarios / "helicopter_uniform.toml",
                                                [f"integrator.dt={stable}", "integrator.t_end=5"]))
    assert rerun.summary["status"] == "completed"



@pytest.mark.parametrize("method, code", [("galpha", "NEWTON_FAILED"), ("sdirk2", "NEWTON_FAILED"),
                                          ("verlet", "NEWTON_FAILED"), ("verlet", "NON_FINITE")])
def test_blow_up_advice_claims_stability_only_from_the_bound(scenarios, method, code):
    """Only an explicit method stepping above its stability bound is told a step "would be stable" (half the
    bound); a Newton failure, or a blow-up below the bound, is told to try a quarter of its step, which no bound
    backs. Nothing compiles: the message is built from the model and the stopped integrator's clock."""
    from types import SimpleNamespace

    from ropesim import run
    from ropesim.analysis.stability import predicted_dt

    scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml", [f"integrator.method={method}"])
    model = build(scene)
    bound = predicted_dt(model, method)
    dt = 2.0 * bound if np.isfinite(bound) else 0.05
    stopped = SimpleNamespace(grid=SimpleNamespace(dt=dt), t=1.5, step=30, limits=(4.0,))
    stable_dt, message = run._blow_up_message(model, stopped, getattr(run, code), 7)
    assert message.startswith("blew up at t = 1.5 s (step 30): ") and "node 7" in message
    if method == "verlet" and code == "NON_FINITE":
        assert stable_dt == pytest.approx(0.5 * bound) and message.endswith("or less would be stable")
    else:
        assert stable_dt == pytest.approx(0.25 * dt) and "would be stable" not in message
        assert f"try a time step of {stable_dt:.3g} s (a quarter of this one)" in message
        assert ("integrator.tolerance" in message) == (method == "galpha")

def test_interrupt_keeps_what_was_computed(scenarios, tmp_path):
    scene = ropesim.load_scene(scenarios / "helicopter_uniform.toml", ["integrator.t_end=5000"])
    model = build(scene)
    store = FrameStore(TimeGrid.of(scene).frames, model.nodes, model.dim)
    calls = []
    outcome = integrate(model, store, stop=lambda: calls.append(1) or len(calls) > 3, target_chunk_seconds=1e-4)
    assert outcome.status == INTERRUPTED and "interrupted at t =" in outcome.message
    assert 0 < outcome.steps < 5_000_000
    assert store.count == 1 + outcome.steps // 10  # every frame up to the stop, nothing after
    calls.clear()
    traj = ropesim.simulate(scene, tmp_path / "run", stop=lambda: calls.append(1) or len(calls) > 3)
    assert traj.summary["status"] == INTERRUPTED and traj.frames == 1 + traj.summary["steps"] // 10
    assert (tmp_path / "run" / "checkpoint" / "x.npy").is_file() and not (tmp_path / "run" / "trajectory.npz").exists()
    assert np.load(tmp_path / "run" / "checkpoint" / "x.npy").shape == (traj.frames, 21, 2)  # plain .npy files


def test_ctrl_c_in_a_real_run(scenarios, tmp_path):
    """SIGINT to `ropesim run`: exit 130, one line saying where it stopped, the run folder holds the frames."""
    out = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "ropesim", "run", str(scenarios / "helicopter_uniform.toml"),
                             "--out", str(out), "--set", "integrator.t_end=1000000", "--set", "output.interval=50"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    x = out / "checkpoint" / "x.npy"
    while time.time() < deadline and not (x.is_file() and x.stat().st_size > 256 + 2 * 21 * 2 * 8):
        time.sleep(0.05)  # until frames past the first are being written: the kernel is compiled and running
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted at t =" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    traj = Trajectory.open(out)
    assert traj.summary["status"] == INTERRUPTED and 1 < traj.frames < 20001
    assert (out / "manifest.json").is_file() and not (out / ".lock").exists()


def test_run_folder_is_plain_npz_and_reads_lazily(scenarios, tmp_path):
    scene = ropesim.load_scene(scenarios / "shooter_low.toml", ["integrator.t_end=0.2"])
    traj = ropesim.simulate(scene, tmp_path)
    assert sorted(os.listdir(tmp_path)) == ["ledger.npz", "manifest.json", "scene.toml", "state.npz", "summary.json",
                                            "trajectory.npz"]
    mask = os.umask(0)
    os.umask(mask)
    for name in os.listdir(tmp_path):  # readable like any new file, not mkstemp's private 0600
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o666 & ~mask
    with zipfile.ZipFile(tmp_path / "trajectory.npz") as zf:
        assert all(i.compress_type == zipfile.ZIP_STORED for i in zf.infolist())
    with np.load(tmp_path / "trajectory.npz") as npz:
        assert np.array_equal(npz["x"], traj.x) and np.array_equal(npz["t"], traj.t)
    assert isinstance(traj.x, np.memmap)
    again = ropesim.simulate(ropesim.load_scene(tmp_path / "scene.toml"))
    assert np.array_equal(again.x, traj.x)
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "completed"


def test_corrupt_run_folder_is_one_clear_line(tmp_path):
    (tmp_path / "scene.toml").write_text("[rope]\nnodes = 3\n")
    (tmp_path / "trajectory.npz").write_bytes(b"not a zip")
    with pytest.raises(ropesim.RunFolderError) as err:
        Trajectory.open(tmp_path)
    assert "scene.toml is not valid" in str(err.value) and "\n" not in str(err.value)
