"""ropesim.Coupling: another program moves the coupled points and bodies, ropesim returns their lines' forces.

OC3-Hywind's three chains (tests/data/systems/oc3_hywind.toml) with the spar coupled instead of driven. Physics:
driven through the coupling with the driven twin's own prescribed surge, sampled at the coupling steps, the
forces on the spar converge to the driven run's as the coupling step shrinks, at first order (the fairleads
move at the step's initial velocity for the whole step, MoorDyn's rule, so their velocity at the step's end is
off by the surge acceleration times the step, and the chains' axial damping feels it). A restart from a
checkpoint continues bit for bit; bad calls are refused in one line.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.coupling import CouplingError

SCENE = Path(__file__).parent / "data" / "systems" / "oc3_hywind.toml"
DRIVEN = SCENE.read_text()
COUPLED = re.sub(r'kind = "driven"\n(position = [^\n]*\n)amplitude = [^\n]*\nperiod = [^\n]*\nramp_time = [^\n]*\n',
                 r'kind = "coupled"\n\1', DRIVEN)
FAST = ["integrator.method=verlet", "integrator.dt=0.001", "initial.shape=lines", "output.interval=0.1"]


def coupled_scene(more=()):
    return ropesim.scene_from_toml(COUPLED, source="oc3_coupled.toml", overrides=[*FAST, *more])


def test_the_coupled_spar_is_a_coupled_body_with_six_degrees_of_freedom():
    coupling = ropesim.Coupling(coupled_scene())
    assert coupling.dofs == 6
    assert coupling.layout() == "spar: x y z rx ry rz"
    assert np.array_equal(coupling.positions(), np.zeros(6))


@pytest.fixture(scope="module")
def driven_run():
    scene = ropesim.scene_from_toml(DRIVEN, source="oc3.toml", overrides=[*FAST, "integrator.t_end=16",
                                                                          "output.interval=0.05"])
    return ropesim.simulate(scene)


def spar_force(traj) -> np.ndarray:
    """The net force on the spar's three fairleads without their inertia (F, 3), from the run's held_force."""
    return sum(traj.point(f"fairlead{k}").held_force for k in (1, 2, 3))


def coupled_forces(dt: float, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, forces on the spar (K, 6)) of the coupled twin driven with the driven scene's surge."""
    from ropesim.model.bodies import driven_pose
    from ropesim.model.build import build

    driven = build(ropesim.scene_from_toml(DRIVEN, source="oc3.toml", overrides=FAST), solve=False)
    body = driven.scene.rigid_bodies[0]
    coupling = ropesim.Coupling(coupled_scene())
    coupling.init(statics=False)
    steps = round(t_end / dt)
    times = np.arange(steps + 1) * dt
    position, _, velocity, _ = driven_pose(driven, body, times)
    out = np.zeros((steps, 6))
    for k in range(steps):
        x = np.concatenate([position[k], np.zeros(3)])
        v = np.concatenate([velocity[k], np.zeros(3)])
        out[k] = coupling.step(times[k], dt, x, v)
    return times[1:], out


def test_forces_converge_to_the_driven_runs_at_first_order_in_the_coupling_step(driven_run):
    reference = spar_force(driven_run)
    errors = []
    for dt in (0.2, 0.1, 0.05):
        times, forces = coupled_forces(dt, 16.0)
        frames = np.round(times / 0.05).astype(int)
        errors.append(np.max(np.abs(forces[:, :3] - reference[frames])))
    order = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((order > 0.8) & (order < 1.3)), (errors, order)
    # the leading error: three chains' damping BA / l on the velocity lag a dt, a the surge's acceleration
    # (5 m at 60 s: 0.055 m/s^2, more while the ramp runs)
    lag = 3 * 6.2358e6 / (902.2 / 20) * 5 * (2 * np.pi / 60) ** 2 * 0.05
    assert errors[-1] < 4 * lag, (errors, lag)


def test_a_coupled_spar_held_still_pulls_as_the_run_that_holds_it():
    scene = coupled_scene(["integrator.t_end=2"])
    run = ropesim.simulate(scene)
    coupling = ropesim.Coupling(scene)
    first = coupling.init(statics=False)
    assert np.allclose(first[:3], spar_force(run)[0], rtol=1e-12, atol=1e-6)
    for k in range(10):
        forces = coupling.step(0.2 * k, 0.2, np.zeros(6), np.zeros(6))
    assert np.allclose(forces[:3], spar_force(run)[-1], rtol=1e-9, atol=1e-3)


def test_a_restart_from_a_checkpoint_continues_bit_for_bit(tmp_path):
    scene = coupled_scene()
    rng = np.random.default_rng(7)
    motion = [(rng.normal(size=6) * [1, 0.2, 1, 0.01, 0.01, 0.01], rng.normal(size=6) * 0.1) for _ in range(20)]
    coupling = ropesim.Coupling(scene, tmp_path / "run")
    coupling.init(statics=False)
    for k in range(10):
        coupling.step(coupling.t, 0.05, *motion[k])
    coupling.checkpoint()
    straight = [coupling.step(coupling.t, 0.05, *motion[k]) for k in range(10, 20)]
    straight_state = coupling.state()
    coupling.writer.close()          # the process dies here: nothing after the checkpoint was committed
    coupling.writer = None

    again = ropesim.Coupling.resume(tmp_path / "run")
    resumed = [again.step(again.t, 0.05, *motion[k]) for k in range(10, 20)]
    assert all(np.array_equal(a, b) for a, b in zip(straight, resumed))
    for name, value in straight_state.items():
        assert np.array_equal(value, again.state()[name]), name
    again.close()

    traj = ropesim.Trajectory.open(tmp_path / "run")
    assert traj.t[-1] == pytest.approx(1.0, abs=1e-12) and len(traj.t) == 11
    assert traj.summary["status"] == "completed" and traj.summary["coupled"] == ["spar"]
    assert np.allclose(spar_force(traj)[-1], resumed[-1][:3], rtol=1e-12, atol=1e-6)


def test_the_first_coupling_step_shrinks_the_internal_step_to_fit_as_moordyn_does():
    coupling = ropesim.Coupling(coupled_scene())
    coupling.init(statics=False)
    coupling.step(0.0, 0.0025, np.zeros(6), np.zeros(6))      # 0.0025 / 0.001: three steps of 0.000833 s
    assert coupling.dt == pytest.approx(0.0025 / 3, rel=1e-15)
    coupling.step(coupling.t, 0.0025 / 3 * 2, np.zeros(6), np.zeros(6))
    with pytest.raises(CouplingError, match="not a whole number of internal steps"):
        coupling.step(coupling.t, 0.001, np.zeros(6), np.zeros(6))


@pytest.mark.parametrize("positions, velocities, t, dt, words", [
    (np.zeros(5), np.zeros(6), 0.0, 0.1, "5 numbers of shape (5,); the coupled objects have 6 degrees of freedom"),
    (np.zeros((2, 3)), np.zeros(6), 0.0, 0.1, "6 numbers of shape (2, 3)"),
    ([0, 0, np.nan, 0, 0, 0], np.zeros(6), 0.0, 0.1, "positions[2] = nan (spar z)"),
    (np.zeros(6), [0, 0, 0, 0, np.inf, 0], 0.0, 0.1, "velocities[4] = inf (spar ry)"),
    (np.zeros(6), np.zeros(6), 1.0, 0.1, "t = 1.0 s, but the coupling stands at t = 0.0 s"),
    (np.zeros(6), np.zeros(6), 0.0, -0.1, "dt = -0.1"),
    (np.zeros(6), np.zeros(6), 0.0, float("nan"), "dt = nan"),
    ("spar", np.zeros(6), 0.0, 0.1, "positions: not an array of numbers"),
])
def test_a_bad_coupling_call_is_refused_in_one_line(positions, velocities, t, dt, words):
    coupling = ropesim.Coupling(coupled_scene())
    with pytest.raises(CouplingError, match="init"):
        coupling.step(0.0, 0.1, np.zeros(6), np.zeros(6))
    coupling.init(statics=False)
    with pytest.raises(CouplingError) as refused:
        coupling.step(t, dt, positions, velocities)
    message = str(refused.value)
    assert words in message and "\n" not in message


def test_a_scene_without_coupled_objects_is_refused():
    scene = ropesim.scene_from_toml(DRIVEN, source="oc3.toml", overrides=FAST)
    with pytest.raises(CouplingError, match="no point or body has kind = 'coupled'"):
        ropesim.Coupling(scene)


def test_held_force_is_minus_the_support_on_a_fixed_anchor(driven_run):
    anchor = driven_run.point("anchor1")
    row = np.flatnonzero([np.allclose(s, -anchor.held_force) for s in np.swapaxes(driven_run.support, 0, 1)])
    assert row.size == 1
    fairlead = driven_run.point("fairlead1")
    assert fairlead.held_force is not None and np.all(np.isfinite(fairlead.held_force))


PLANAR = """
name = "planar_chain"
dimension = 2
[[points]]
id = "anchor"
position = [0.0, -20.0]
[[points]]
id = "top"
kind = "coupled"
position = [15.0, 0.0]
[[lines]]
id = "chain"
start = "anchor"
end = "top"
length = 30.0
segments = 12
mass_per_length = 2.0
EA = 1.0e5
axial_damping = 200.0
[gravity]
g = 9.81
[integrator]
method = "verlet"
dt = 0.001
t_end = 1.0
[output]
interval = 0.1
"""


def test_a_planar_coupled_point_held_still_pulls_as_the_run_that_holds_it():
    scene = ropesim.scene_from_toml(PLANAR, source="planar.toml")
    run = ropesim.simulate(scene)
    coupling = ropesim.Coupling(scene)
    assert coupling.layout() == "top: x y"
    coupling.init(statics=False)
    for k in range(10):
        forces = coupling.step(0.1 * k, 0.1, [15.0, 0.0], [0.0, 0.0])
    held = run.point("top").held_force[-1]
    assert np.allclose(forces, held, rtol=1e-9, atol=1e-9)
    assert np.allclose(run.x[-1], coupling.integrator.x.T, rtol=0, atol=1e-12)
    assert held[1] < 0 and held[0] < 0        # the chain hangs down towards its anchor, below and to the left


def test_rk4_reports_its_last_stages_forces_within_its_step_error_of_the_end_states():
    """rk4's last stage is at the step's end time, its held nodes where they end: the forces a coupling step returns
    come from it (as MoorDyn reports its last evaluation's), not from one more evaluation at the end state. Its free
    nodes sit at y + h K3, whose velocities differ from the end state's by O(h^2) (what the chains' axial damping
    feels), so the forces differ from the end state's by far less than the coupling's own first-order lag (3 BA / l
    a dt, 2e-3 of the force here). Measured, the spar surging 2 m and turning 0.02 rad about z from its static shape: forces
    7.4e-6, moments 4.4e-5 (1.2e-6 on MoorDyn's lines.txt, tests/test_compat_moordyn.py). How they are reported
    changes no trajectory."""
    scene = coupled_scene(["integrator.method=rk4", "integrator.dt=0.002"])
    reported, evaluated = ropesim.Coupling(scene), ropesim.Coupling(scene)
    reported.init()
    evaluated.init()
    evaluated._loop_acc = None        # the other way: one more evaluation at the end state
    assert reported._loop_acc is reported.integrator.scratch.acc
    worst = np.zeros(2)
    for k in range(100):
        t = 0.01 * k
        x = np.array([2.0 * np.sin(0.5 * t), 0, 0, 0, 0, 0.02 * np.sin(0.5 * t)])
        v = np.array([1.0 * np.cos(0.5 * t), 0, 0, 0, 0, 0.01 * np.cos(0.5 * t)])
        ours, end = reported.step(t, 0.01, x, v), evaluated.step(t, 0.01, x, v)
        for part, what in enumerate((slice(0, 3), slice(3, 6))):
            worst[part] = max(worst[part], np.linalg.norm(ours[what] - end[what]) / np.linalg.norm(end[what]))
        assert np.array_equal(reported.integrator.x, evaluated.integrator.x)
    assert np.all(worst < 1e-4), worst
    assert evaluated._end_forces() == pytest.approx(reported._end_forces(), rel=1e-15)


def _twin_motion(angles, rates):
    """The y-up twin's angles and angle rates of a z-up body's (R = Rz Ry Rx in each frame's axes), by scipy:
    R' = P R P^T, the angular velocity w = c' e_z + b' Rz(c) e_y + a' Rz(c) Ry(b) e_x turned by P, and the twin's
    rates that give it."""
    from scipy.spatial.transform import Rotation

    def columns(a):
        rz, ry = Rotation.from_euler("z", a[2]).as_matrix(), Rotation.from_euler("y", a[1]).as_matrix()
        return np.column_stack([rz @ ry @ [1.0, 0, 0], rz @ [0, 1.0, 0], [0, 0, 1.0]])

    R = Rotation.from_euler("xyz", angles).as_matrix()
    twin = Rotation.from_matrix(P_TURN @ R @ P_TURN.T).as_euler("xyz")
    w = P_TURN @ columns(angles) @ rates
    return twin, np.linalg.solve(columns(twin), w)


P_TURN = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])      # z-up coordinates -> the y-up twin's


def test_a_z_up_coupling_gives_its_y_up_twins_forces_in_its_own_frame():
    """The same spar, coupled in a z-up scene (MoorDyn's frame) and in its y-up twin, with the same motion (the
    twin's turned by P, its angles and rates by scipy): the forces and moments, and the mass matrix, are the same
    up to the axis permutation (x, y, z)_z-up = (x, -z, y)_y-up, to 1e-12 of their largest value."""
    from dataclasses import replace

    from ropesim.scene.schema import scene_to_toml

    y_scene = coupled_scene()
    z_scene = ropesim.scene_from_toml(scene_to_toml(replace(y_scene, up="z")), source="oc3_z_up.toml")
    assert z_scene.up == "z" and replace(z_scene, up="y", given_orientations=()) == y_scene
    z, y = ropesim.Coupling(z_scene), ropesim.Coupling(y_scene)
    x0 = np.array([0.5, -0.3, 0.2, 0.02, -0.03, 0.04])
    v = np.array([0.3, -0.2, 0.1, 0.01, 0.02, -0.015])

    def twin(t):
        x = x0 + v * t
        angles, rates = _twin_motion(x[3:], v[3:])
        return np.concatenate([P_TURN @ x[:3], angles]), np.concatenate([P_TURN @ v[:3], rates])

    def out(f):
        return np.concatenate([P_TURN.T @ f[:3], P_TURN.T @ f[3:]])

    pairs = [(z.init(x0, v), out(y.init(*twin(0.0))))]
    for k in range(20):
        t = 0.01 * k
        pairs.append((z.step(t, 0.01, x0 + v * t, v), out(y.step(t, 0.01, *twin(t)))))
    ours, theirs = np.array(pairs).transpose(1, 0, 2)
    for part in (slice(0, 3), slice(3, 6)):
        assert np.max(np.abs(ours[:, part] - theirs[:, part])) <= 1e-12 * np.max(np.abs(theirs[:, part]))
    assert np.abs(theirs[:, :3]).max() > 1e6           # the chains pull (the comparison is not of zeros)
    turn = np.kron(np.eye(2), P_TURN)
    assert np.allclose(z.mass(), turn.T @ y.mass() @ turn, rtol=0, atol=1e-12 * np.abs(y.mass()).max())
    with pytest.raises(CouplingError, match=r"positions\[4\] = nan \(spar ry\)"):
        z.step(z.t, 0.01, np.array([0, 0, 0, 0, np.nan, 0]), v)
