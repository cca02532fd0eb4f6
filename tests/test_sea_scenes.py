"""The sea's built-in scenes and outputs, against physics: the floating hose rests at Archimedes' draught and
heaves with the surface at long periods; the chain's fairlead tension range grows with Hs; the probes record
the Airy surface in closed form; the run folder, the export and the pictures carry the sea."""

import csv
import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy import optimize

import ropesim

ROOT = Path(__file__).resolve().parent.parent
G, RHO = 9.80665, 1025.0


def hose(*sets):
    return ropesim.load_scene("floating_hose", list(sets))


def airy(height, period, depth, x, t, ramp):
    """The Airy surface H/2 cos(k x - w t), k from w^2 = g k tanh(k d) (scipy), times the half-cosine ramp."""
    w = 2 * math.pi / period
    k = optimize.brentq(lambda k: G * k * math.tanh(k * depth) - w * w, 1e-9, 10.0, xtol=1e-15)
    r = np.where(t >= ramp, 1.0, 0.5 * (1 - np.cos(np.pi * np.clip(t, 0, ramp) / ramp)))
    return 0.5 * height * r * np.cos(k * x - w * t)


def test_the_hose_rests_at_archimedes_draught():
    """Without waves the hose stays where it starts, at rest, and its submerged fraction is m' / (rho A) (the
    circular segment the header solved), node by node and for the line."""
    scene = hose("integrator.t_end=2.0")
    run = ropesim.simulate(replace(scene, waves=None))
    share = 100.0 / (RHO * math.pi * 0.25 ** 2)
    assert np.max(np.abs(run.x[:, :, 1] - run.x[0, :, 1])) < 1e-6     # [m]
    assert np.max(np.abs(run.v)) < 1e-5
    assert np.allclose(run.line_submerged[:, 0], share, atol=1e-6, rtol=0)
    assert np.allclose(run.submerged, share, atol=1e-5, rtol=0)


def test_the_hose_heaves_with_the_surface_at_long_periods_and_the_probes_hold_airy():
    """In 20 s waves (326 m long, 5.4 hose lengths) the middle node's heave is the surface's elevation under it:
    standard deviation within 2 %, correlation above 0.999; the probes record the closed-form Airy surface."""
    run = ropesim.simulate(hose("waves.period=20.0", "waves.ramp_time=20.0", "integrator.t_end=60.0",
                                "integrator.dt=0.02"))
    after = run.t >= 25.0
    mid = 15
    eta = airy(1.0, 20.0, 30.0, run.x[after][:, mid, 0], run.t[after], 20.0)
    heave = run.x[after][:, mid, 1] - run.x[0, mid, 1]
    assert abs(heave.std() / eta.std() - 1) < 0.02
    assert np.corrcoef(heave, eta)[0, 1] > 0.999
    for k, x in enumerate((0.0, 30.0, 60.0)):
        assert np.allclose(run.probe_elevation[:, k], airy(1.0, 20.0, 30.0, x, run.t, 20.0), atol=1e-12)
    assert np.all((run.line_submerged > 0.45) & (run.line_submerged < 0.55))
    rope = run.line("rope")       # the same, by line
    assert np.array_equal(rope.submerged_total, run.line_submerged[:, 0])
    assert rope.submerged.shape == (len(run.t), 31)


# slow: its held-fairlead chain in waves is a loop no other quick test compiles (7 s of a cold run)
@pytest.mark.slow
def test_the_chain_fairlead_tension_range_grows_with_hs():
    """Only the waves load the chain (its fairlead held): the fairlead tension's swing about its mean grows with
    Hs (drag, quadratic in the orbital velocity, and the inertia force, linear: between 2 and 4 times from 3 m to
    6 m; measured 3.5, 0.99 and 3.50 kN) and vanishes in still water (5e-5 N)."""
    swings = {}
    for hs in (0.0, 3.0, 6.0):
        sets = ["integrator.t_end=60.0", "output.interval=0.2", "waves.components=50"]
        scene = ropesim.load_scene("mooring_chain_waves", sets + ([] if hs == 0 else
                                                                  [f"waves.significant_height={hs}"]))
        if hs == 0:
            scene = replace(scene, waves=None)
        run = ropesim.simulate(scene)
        top = np.linalg.norm(np.asarray(run.support)[run.t >= 20.0, -1], axis=1)
        swings[hs] = top.std()
    assert swings[0.0] < 0.05 * swings[3.0]
    assert 2.0 < swings[6.0] / swings[3.0] < 4.0


def test_the_run_folder_holds_the_sea_and_export_writes_it(tmp_path):
    """A run folder's sea arrays read back as they were computed; the CSV export gets a submerged column and a sea
    table."""
    sets = ["--set", "integrator.t_end=0.5", "--set", "output.interval=0.1"]
    folder = tmp_path / "run"
    done = subprocess.run([sys.executable, "-m", "ropesim", "run", "floating_hose", "-o", str(folder), "-q", *sets],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    run = ropesim.Trajectory.open(folder)
    memory = ropesim.simulate(hose("integrator.t_end=0.5", "output.interval=0.1"))
    for name in ("submerged", "line_submerged", "probe_elevation"):
        assert np.array_equal(np.asarray(getattr(run, name)), getattr(memory, name)), name
    run.export("csv", tmp_path / "out.csv")
    with open(tmp_path / "out_sea.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t [s]", "submerged rope [-]", "eta at x = 0 [m]", "eta at x = 30 [m]", "eta at x = 60 [m]"]
    assert np.allclose(np.array(rows[1:], dtype=float)[:, 2:], memory.probe_elevation, atol=0, rtol=0)
    with open(tmp_path / "out.csv") as fh:
        header = fh.readline().strip().split(",")
    assert header[-1] == "submerged [-]"


def test_a_probe_on_dry_land_is_refused(tmp_path):
    """The probes' domain is the water: a probe beyond the shoreline of a sloping seabed, one line, exit 2."""
    done = subprocess.run([sys.executable, "-m", "ropesim", "run", "floating_hose", "-o", str(tmp_path / "r"),
                           "--set", "seabed.height=-30", "--set", "seabed.slope=5", "--set", "sea.probes=[400.0]"],
                          capture_output=True, text=True)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "sea.probes[0]" in lines[0] and "shoreline x = 342.9" in lines[0], lines


def test_the_side_view_draws_the_surface_at_the_frames_time():
    """The side view's profile is the mean level plus the waves' elevation along the view, at the frame's
    time; a view from above draws no surface."""
    from matplotlib.figure import Figure

    from ropesim.render.framing import Projection
    from ropesim.render.sea_artist import SeaProfile

    scene = hose()
    ax = Figure().add_subplot()
    ax.set_xlim(-10.0, 70.0)
    ax.set_ylim(-3.0, 3.0)
    profile = SeaProfile(ax, scene, Projection((0, 1)))
    profile.show(12.5, np.zeros((31, 2)))
    u, v = profile.surface.get_data()
    assert np.allclose(v, airy(1.0, 8.0, 30.0, u, np.full_like(u, 12.5), 8.0), atol=1e-12)
    offset = np.array([-4.0, 0.25])     # a followed view: drawn minus the followed node's position
    profile.show(12.5, np.zeros((31, 2)), offset)
    u, v = profile.surface.get_data()
    assert np.allclose(v - offset[1], airy(1.0, 8.0, 30.0, u - offset[0], np.full_like(u, 12.5), 8.0), atol=1e-12)
    assert not SeaProfile(ax, scene, Projection((0, 2))).active


def test_the_3d_view_draws_the_surface_as_a_wireframe_at_the_frames_time():
    """The 3-D view's wireframe heights are the mean level plus the waves' elevation over the box, at the frame's
    time and shifted with a followed view."""
    from matplotlib.figure import Figure

    from ropesim.render.sea_artist import SeaWireframe
    from ropesim.render.view3d import axes_3d

    scene = ropesim.load_scene("floating_hose", ["dimension=3", "initial.start=[0.0, 0.0, 0.0]",
                                                 "initial.end=[60.0, 0.0, 0.0]", "sea.probes=[[30.0, 0.0]]"])
    box = np.array([[-5.0, 65.0], [-3.0, 3.0], [-10.0, 10.0]])
    ax = axes_3d(Figure(), [0, 0, 1, 1], box, False)
    shift = np.array([2.0, 0.5, -1.0])
    wire = SeaWireframe(ax, scene, box)
    wire.show(9.0, shift)
    for segment in wire.mesh.get_segments()[:3]:
        X, Y, Z = np.asarray(segment).T      # matplotlib's (x, -z, y)
        want = airy(1.0, 8.0, 30.0, X + shift[0], np.full_like(X, 9.0), 8.0) - shift[1]
        assert np.allclose(Z, want, atol=1e-12)


def test_an_interrupted_run_keeps_the_sea_and_resumes_it_bit_for_bit(tmp_path):
    """SIGTERM mid-run: the folder holds the sea's arrays up to its checkpoint, and `--resume` finishes them
    exactly as an uninterrupted run writes them."""
    import signal
    import time

    sets = [a for s in ("integrator.t_end=30.0", "output.interval=0.05") for a in ("--set", s)]
    clean, folder = tmp_path / "clean", tmp_path / "run"
    command = [sys.executable, "-m", "ropesim", "run", "floating_hose", "-q", *sets]
    assert subprocess.run(command + ["-o", str(clean)], capture_output=True).returncode == 0
    proc = subprocess.Popen(command + ["-o", str(folder)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    stream = folder / "checkpoint" / "submerged.npy"
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if stream.exists() and stream.stat().st_size > 256 + 4 * 31 * 8:
            break
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=120)
    want = ropesim.Trajectory.open(clean)
    if proc.returncode == 143:        # (else it finished before the signal came)
        cut = ropesim.Trajectory.open(folder)
        assert cut.summary["status"] == "interrupted" and 1 <= cut.frames < want.frames
        assert np.array_equal(cut.probe_elevation, want.probe_elevation[:cut.frames])
        done = subprocess.run([sys.executable, "-m", "ropesim", "run", "--resume", str(folder), "-q"],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
    got = ropesim.Trajectory.open(folder)
    for name in ("x", "submerged", "line_submerged", "probe_elevation"):
        assert np.array_equal(getattr(got, name), getattr(want, name)), name
