"""galpha on systems with free rigid bodies (ropesim/integrate/galpha_bodies.py): the body's six unknowns (three in
2-D) stepped as the nodes are, on the rotation group, through the Schur complement.

References: the invariants of a torque-free rigid body (its kinetic energy and its angular momentum in world axes
are constant); a floating box's heave at its waterplane period in closed form; rk4 and verlet at steps 8-30 times smaller than the smallest tried (their own difference far
below the errors fitted); sdirk2's tests (tests/test_sdirk_bodies.py) for the scenes.
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np
import pytest

from synthetic_system import BODY_2D
from test_sdirk_bodies import tumbling_tripod
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build
from ropesim.model.rotation import rotation_matrix
from ropesim.scene.builtin import builtin_path
from ropesim.scene.loader import scene_from_toml

# A box (inertia 1, 2, 3 kg m^2 about its centre of gravity, its reference point) spun at 1.76 rad/s mostly about
# its intermediate axis (the tennis racket's: the spin flips over and back, a hard test of the rotation), no
# gravity, nothing attached: a torque-free body. The string beside it is there because a system has a line.
TUMBLING_BOX = """
name = "tumbling_box"
dimension = 3
[[bodies]]
id = "box"
position = [0.0, 0.0, 0.0]
mass = 10.0
inertia = [1.0, 2.0, 3.0]
angular_velocity = [10.0, 100.0, 10.0]
[[points]]
id = "a"
position = [5.0, 0.0, 0.0]
[[points]]
id = "b"
position = [7.0, 0.0, 0.0]
[[lines]]
id = "string"
start = "a"
end = "b"
length = 2.0
segments = 2
mass_per_length = 0.1
EA = 1000.0
[integrator]
method = "galpha"
dt = 0.01
t_end = 20.0
"""
BOX_INERTIA = np.diag([1.0, 2.0, 3.0])


def integrator(scene, method: str, dt: float, t_end: float, **keys):
    scene = replace(scene, integrator=replace(scene.integrator, method=method, dt=dt, t_end=t_end, **keys))
    return make_integrator(build(scene), TimeGrid.of(scene))


def advance(scene, method: str, dt: float, t_end: float, **keys):
    """The integrator after running ``scene`` with ``method`` at ``dt`` to ``t_end`` (galpha's keys in ``keys``)."""
    it = integrator(scene, method, dt, t_end, **keys)
    result = it.advance(TimeGrid.of(it.model.scene).steps)
    assert result.status == 0, result
    return it


def invariants(pose, twist) -> tuple[float, np.ndarray]:
    """A torque-free body's kinetic energy [J] and angular momentum in world axes [kg m^2/s]."""
    r = rotation_matrix(pose[3:7, 0])
    inertia = r @ BOX_INERTIA @ r.T
    w = twist[3:, 0]
    return 0.5 * w @ inertia @ w, inertia @ w


def box_errors(dt: float, rho_inf: float) -> tuple[float, float, float, float]:
    """The largest relative errors of the box's energy and angular momentum over the first and the second half of
    20 s at ``dt`` (sampled each second): (energy first, energy second, momentum first, momentum second)."""
    it = integrator(scene_from_toml(TUMBLING_BOX), "galpha", dt, 20.0, rho_inf=rho_inf)
    e0, l0 = invariants(it.pose, it.twist)
    energy, momentum = [], []
    for _ in range(20):
        assert it.advance(round(1.0 / dt)).status == 0
        e, angular = invariants(it.pose, it.twist)
        energy.append(abs(e / e0 - 1.0))
        momentum.append(np.linalg.norm(angular - l0) / np.linalg.norm(l0))
        assert abs(np.linalg.norm(it.pose[3:7, 0]) - 1.0) < 1e-15   # on the group: no norm drift
    return max(energy[:10]), max(energy[10:]), max(momentum[:10]), max(momentum[10:])


@pytest.mark.parametrize("rho_inf", [1.0, 0.9])
def test_a_torque_free_body_keeps_its_energy_and_angular_momentum_to_second_order(rho_inf):
    """Over 20 s (35 turns, the spin flipping about the unstable intermediate axis) at 20, 10 and 5 ms: the
    energy's largest error 5.1e-5, 1.3e-5, 3.3e-6 and the angular momentum's 3.0e-4, 7.6e-5, 1.8e-5 (rho_inf 1;
    0.9 within 3 % of them), each halving of dt dividing them by 3.9 to 4.2 (asserted above 3.6). At rho_inf = 1
    nothing drifts: the energy's error over the second 10 s is no larger than over the first (5.00e-5 against
    5.06e-5 at 20 ms); the momentum's grows slowly (the precession's phase error, second order too)."""
    runs = [box_errors(dt, rho_inf) for dt in (0.02, 0.01, 0.005)]
    for k in range(2):
        for column in (0, 2):
            assert runs[k][column] / runs[k + 1][column] > 3.6, runs
    assert runs[0][0] < 1e-4 and runs[0][2] < 5e-4, runs
    if rho_inf == 1.0:
        for energy_first, energy_second, _, _ in runs:
            assert energy_second <= 1.05 * energy_first, runs


def errors_against(scene, reference, steps, t_end: float, **keys) -> list[tuple[float, float]]:
    """galpha's largest errors at ``t_end`` at each dt: (the bodies' reference points and every node [m], the
    bodies' quaternions)."""
    out = []
    for dt in steps:
        it = advance(scene, "galpha", dt, t_end, **keys)
        out.append((max(np.abs(it.pose[:3] - reference.pose[:3]).max(), np.abs(it.x - reference.x).max()),
                    np.abs(it.pose[3:] - reference.pose[3:]).max()))
    return out


@functools.cache
def tripod_reference():
    """The tumbling tripod run by rk4 at 10 us to 0.1 s: the reference of the tests below (computed once)."""
    return advance(scene_from_toml(tumbling_tripod()), "rk4", 1e-5, 0.1)


def test_galpha_on_a_tumbling_body_on_lines_converges_at_second_order_and_agrees_with_verlet():
    """The tripod of tests/test_sdirk_bodies.py (a 500 kg body, thrown and spinning on three elastic lines), to
    0.1 s, against rk4 at 10 us (verlet at 10 us is 2e-11 m from it on the body, 2e-9 m on the nodes): errors
    4.9e-6, 1.2e-6, 3.1e-7 m at 312, 156, 78 us (an interior line node's; the body's reference point 1.5e-8,
    3.8e-9, 9.5e-10 m, its quaternion 2.2e-8, 5.6e-9, 1.3e-9), each halving of dt dividing them by 4.0 (asserted
    above 3.6; the quaternion's above 3.5). At 78 us the body agrees with verlet within 2e-9 m and 2e-9 in its
    quaternion, a unit one to round-off."""
    scene, reference = scene_from_toml(tumbling_tripod()), tripod_reference()
    errors = errors_against(scene, reference, (3.125e-4, 1.5625e-4, 7.8125e-5), 0.1)
    for k in range(2):
        assert errors[k][0] / errors[k + 1][0] > 3.6, errors
        assert errors[k][1] / errors[k + 1][1] > 3.5, errors
    fine, verlet = advance(scene, "galpha", 7.8125e-5, 0.1), advance(scene, "verlet", 1e-5, 0.1)
    assert np.abs(fine.pose[:3] - verlet.pose[:3]).max() < 2e-9
    assert np.abs(fine.pose[3:] - verlet.pose[3:]).max() < 2e-9
    assert abs(np.linalg.norm(fine.pose[3:, 0]) - 1.0) < 1e-15


def test_galpha_on_a_plate_in_2d_converges_at_second_order():
    """The 2-D plate of tests/test_sdirk_bodies.py (three planar unknowns), to 0.5 s, against rk4 at 20 us, 1 ->
    0.5 -> 0.25 ms: errors 6.7e-5, 1.7e-5, 4.2e-6 m, each halving dividing them by 4.00 (asserted above 3.8)."""
    scene = scene_from_toml(BODY_2D.replace("EA = 1.0e6", "EA = 1.0e4\ncompression = true"))
    reference = advance(scene, "rk4", 2e-5, 0.5)
    errors = errors_against(scene, reference, (1e-3, 5e-4, 2.5e-4), 0.5)
    assert errors[0][0] / errors[1][0] > 3.8 and errors[1][0] / errors[2][0] > 3.8, errors


@pytest.mark.parametrize("tol", [1e-3, 1e-4, 1e-5])
def test_the_tolerance_covers_the_bodies(tol):
    """Adaptive steps on the tumbling tripod to 0.1 s (reported every 10 ms): the true error (body and nodes,
    against rk4 at 10 us) is within the tolerance (measured 0.57, 0.67, 0.69 of it at 1e-3, 1e-4, 1e-5 m) and
    the steps shrink with it (29, 91, 286 steps)."""
    scene, reference = scene_from_toml(tumbling_tripod()), tripod_reference()
    it = advance(scene, "galpha", 0.01, 0.1, tolerance=tol)
    error = max(np.abs(it.pose[:3] - reference.pose[:3]).max(), np.abs(it.x - reference.x).max())
    assert 0.1 * tol < error < tol, error
    assert it.step_report()["steps_taken"] > 20 * (1e-3 / tol) ** 0.5


def test_an_adaptive_run_with_a_body_gives_the_same_numbers_however_it_is_cut():
    """Cut into calls of 3 grid steps, or stopped and restored from its state halfway, the adaptive run of the
    tumbling tripod retraces the uninterrupted one bit for bit (the bodies' accelerations and the last step's ends
    are state); the reported frames lie on the dense output, between the steps."""
    scene = scene_from_toml(tumbling_tripod())
    keys = {"tolerance": 1e-4}
    whole = advance(scene, "galpha", 0.005, 0.05, **keys)
    cut = integrator(scene, "galpha", 0.005, 0.05, **keys)
    while cut.step < 10:
        cut.advance(min(3, 10 - cut.step))
    first = integrator(scene, "galpha", 0.005, 0.05, **keys)
    first.advance(5)
    second = integrator(scene, "galpha", 0.005, 0.05, **keys)
    second.restore(first.state())
    second.advance(5)
    for other in (cut, second):
        np.testing.assert_array_equal(other.x, whole.x)
        np.testing.assert_array_equal(other.pose, whole.pose)
        np.testing.assert_array_equal(other.twist, whole.twist)
    assert whole.step_report()["steps_taken"] > 10   # the grid's points are read off inside the steps


def moving_spar() -> str:
    """spread_mooring_free with its spar thrown at 0.5 m/s downstream and 0.2 m/s across, yawing at 0.3 deg/s."""
    text = builtin_path("spread_mooring_free").read_text()
    return text.replace('kind = "free"\n', 'kind = "free"\nvelocity = [0.5, 0.0, 0.2]\n'
                                           'angular_velocity = [0.0, 0.3, 0.0]\n', 1)


@pytest.mark.slow
def test_the_free_spar_with_galpha_agrees_with_rk4():
    """The OC3 spar on its three chains (spread_mooring_free), thrown from its balance, over 30 s: galpha with a
    tolerance of 1e-2 m lands within 1e-2 m of rk4 at 1 ms (on the spar and on every chain node)."""
    scene = scene_from_toml(moving_spar())
    reference = advance(scene, "rk4", 1e-3, 30.0)
    it = advance(scene, "galpha", 0.5, 30.0, tolerance=1e-2)
    assert np.abs(it.pose[:3] - reference.pose[:3]).max() < 1e-2
    assert np.abs(it.x - reference.x).max() < 1e-2
    assert np.abs(reference.pose[:3] - it.model.body_pose0[:3]).max() > 1.0   # it did move


@pytest.mark.slow   # galpha's fixed-step loop with a body and a seabed: compiled by no fast test
def test_the_free_spar_takes_fixed_steps_to_half_a_second():
    """The thrown spar at fixed steps. At rho_inf = 0 (the moorings' setting) every step from 0.05 to 0.5 s runs
    its 30 s, within 5 mm of rk4 at 1 ms at 0.5 s and 0.5 mm at 0.1 s (measured 3.2e-3 and 1.9e-4 m on the
    nodes, 7.8e-4 and 2.4e-5 on the spar). At the default 0.9, 0.05 and 0.1 s steps get past the start, where
    Newton failed at the second step before the seabed's one-way damping switch was smoothed for galpha (its
    resting nodes flipped between damped and free from one iterate to the next)."""
    scene = scene_from_toml(moving_spar())
    reference = advance(scene, "rk4", 1e-3, 30.0)
    for dt, bound in ((0.5, 5e-3), (0.1, 5e-4)):
        it = advance(scene, "galpha", dt, 30.0, rho_inf=0.0)
        assert np.abs(it.x - reference.x).max() < bound
        assert np.abs(it.pose[:3] - reference.pose[:3]).max() < bound
    for dt in (0.1, 0.05):
        advance(scene, "galpha", dt, 2.0)


@pytest.mark.slow   # a loop of galpha, a body and a sea that no other test compiles (33 s in CI's quick suite)
def test_galpha_floats_a_box_under_a_sea_at_second_order():
    """The floating box of tests/test_body_sea.py (its waterplane's heave stiffness, added mass and the sea's
    buoyancy, issue 22), released 0.3 m high: its heave against the closed form 0.3 cos(w t) over 6 s at 10, 5
    and 2.5 ms is off by 3.1e-4, 7.6e-5, 1.9e-5 m (each halving dividing it by 4.0, asserted above 3.6), and the
    energy ledger closes to 3e-6 of the energy exchanged (asserted 1e-5)."""
    from test_body_sea import G, RHO, _float_run

    w = math.sqrt(RHO * G * 4.0 / (4100.0 + 1000.0))
    errors = []
    for dt in (0.01, 0.005, 0.0025):
        run = _float_run("galpha", dt)
        errors.append(np.abs(run.body("box").position[:, 1] - 0.3 * np.cos(w * run.t)).max())
        ledger = run.summary["energy_ledger"]
        assert abs(ledger["residual_J"]) < 1e-5 * ledger["energy_flowed_J"], ledger
    assert errors[0] / errors[1] > 3.6 and errors[1] / errors[2] > 3.6, errors
    assert errors[-1] < 3e-5, errors
