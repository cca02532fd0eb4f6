"""Water kinematics given from outside at each coupling step (MoorDyn's external wave kinematics, ``WaveKin = 1``):
:meth:`ropesim.Coupling.wave_points` and :meth:`ropesim.Coupling.set_waves`.

A riser in MoorDyn's z-up frame, from an anchor on the seabed 40 m down to a coupled point held 4 m under the
surface, in regular waves that ramp up over a period. Physics: the caller, given the node coordinates at each
coupling step, sets the waves' own velocity and acceleration there (ropesim's NumPy wave field, as another
program's wave model would); held over the coupling step, they lag the waves inside ropesim by up to a step, so
the forces on the coupled point converge to the internal-wave run's at first order in the coupling step. Held the
same way as ropesim's integrator samples them (symplectic Euler evaluates its forces once, at the step's start,
and a coupling step of one internal step), the run is the internal-wave run bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

import ropesim
from ropesim.coupling import CouplingError
from ropesim.model.waves import wave_field

RISER = """
name = "riser_in_waves"
dimension = 3
up = "z"
[line_types.hose]
diameter = 0.2
mass_per_length = 40.0
EA = 2.0e7
[[points]]
id = "anchor"
position = [-30.0, 0.0, -40.0]
[[points]]
id = "top"
kind = "coupled"
position = [0.0, 0.0, -4.0]
[[lines]]
id = "riser"
type = "hose"
start = "anchor"
end = "top"
length = 50.0
segments = 20
[gravity]
g = 9.81
[fluid]
density = 1025.0
[buoyancy]
[fluid_drag]
cd_normal = 1.2
cd_tangential = 0.1
[added_mass]
ca_normal = 1.0
[sea]
level = 0.0
[waves]
kind = "regular"
height = 2.0
period = 6.0
direction = 20.0
ramp_time = 6.0
[seabed]
height = -40.0
[integrator]
method = "symplectic_euler"
dt = 0.001
t_end = 12.0
[output]
interval = 0.1
"""


def out(w):
    """The y-up twin's vectors (N, 3) in the z-up scene: (x, y, z) -> (x, -z, y)."""
    return np.stack([w[:, 0], -w[:, 2], w[:, 1]], axis=1)


def numpy_waves(field, points, t):
    """(elevation, velocity, acceleration) of ropesim's NumPy wave field at z-up ``points`` (N, 3), time t: what
    the coupled program's own wave model would give."""
    x, height, across = points[:, 0], points[:, 2], -points[:, 1]
    eta, u, a = field.kinematics(x, height - field.level, t, across)
    return eta, out(u), out(a)


def run(coupling_dt: float, t_end: float, external: bool):
    """The coupled point's forces (K, 3) at the coupling steps' ends, the point held still."""
    coupling = ropesim.Coupling(ropesim.scene_from_toml(RISER, source="riser.toml"))
    field = wave_field(coupling.scene)
    coupling.init()
    x, v = coupling.positions(), np.zeros(3)
    forces = []
    for k in range(round(t_end / coupling_dt)):
        t = k * coupling_dt
        if external:
            eta, u, a = numpy_waves(field, coupling.wave_points(), t)
            coupling.set_waves(u, a, eta)
        forces.append(coupling.step(t, coupling_dt, x, v))
    return np.array(forces)


def test_waves_given_from_outside_converge_to_the_internal_waves_at_first_order():
    reference = run(0.01, 12.0, external=False)
    errors = []
    for dt in (0.08, 0.04, 0.02):
        forces = run(dt, 12.0, external=True)
        at = np.round(np.arange(1, len(forces) + 1) * dt / 0.01).astype(int) - 1
        errors.append(np.max(np.abs(forces - reference[at])))
    order = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((order > 0.8) & (order < 1.3)), (errors, order)
    # the waves move the riser's top: the forces swing by far more than the lag (500 N against 4 N at 0.02 s)
    assert np.ptp(reference[:, 0]) > 100 * errors[-1], (np.ptp(reference[:, 0]), errors)


def test_waves_held_as_the_integrator_samples_them_reproduce_the_internal_run_bit_for_bit():
    from ropesim.model.forces.sea import GIVEN_WAVES
    from ropesim.model.waves import NODE_ROWS, node_kinematics

    scene = ropesim.scene_from_toml(RISER, source="riser.toml", overrides=["integrator.t_end=2"])
    inside, given, calm = ropesim.Coupling(scene), ropesim.Coupling(scene), ropesim.Coupling(scene)
    for coupling in (inside, given, calm):
        coupling.init()
    calm.set_waves(np.zeros((21, 3)), np.zeros((21, 3)))      # still water given: the waves inside are not used
    sea = given.model.params.sea
    scalars, comps = sea.scalars.copy(), sea.comps.copy()     # the caller's own copy of the same waves
    scalars[GIVEN_WAVES] = 0.0
    work, kinematics = np.zeros((NODE_ROWS, given.model.nodes)), np.zeros((7, given.model.nodes))
    x, v, h = given.positions(), np.zeros(3), scene.integrator.dt
    for k in range(2000):
        t = k * h
        node_kinematics(given.integrator.x, t, scalars, comps, work, kinematics)   # the twin's frame
        given.set_waves(out(kinematics[1:4].T), out(kinematics[4:7].T), kinematics[0])
        for coupling in (inside, given, calm):
            coupling.step(t, h, x, v)
    assert np.abs(calm.integrator.x - inside.integrator.x).max() > 1e-3    # the waves move the riser
    assert np.array_equal(given.integrator.x, inside.integrator.x)
    assert np.array_equal(given.integrator.v, inside.integrator.v)


def test_given_waves_are_part_of_the_saved_state_and_a_restart_continues_bit_for_bit():
    scene = ropesim.scene_from_toml(RISER, source="riser.toml", overrides=["integrator.t_end=1"])
    first = ropesim.Coupling(scene)
    first.init()
    field = wave_field(first.scene)
    x, v = first.positions(), np.zeros(3)

    def step(coupling, k):
        t = 3.0 + 0.05 * k          # the waves well up
        if k % 2 == 0:                # given every other step: held in between, saved with the state
            eta, u, a = numpy_waves(field, coupling.wave_points(), t)
            coupling.set_waves(u, a, eta)
        return coupling.step(0.05 * k, 0.05, x, v)

    for k in range(3):
        step(first, k)
    saved = first.state()
    second = ropesim.Coupling(scene)
    second.restore(saved)
    for k in range(3, 8):
        assert np.array_equal(step(first, k), step(second, k))


@pytest.mark.parametrize("call, words", [
    (lambda c, n: c.set_waves(np.zeros((n, 2)), np.zeros((n, 3))), "velocity: 42 numbers of shape (21, 2); give 21 x 3"),
    (lambda c, n: c.set_waves(np.zeros((n, 3)), np.full((n, 3), np.nan)), "acceleration at node 0 is nan"),
    (lambda c, n: c.set_waves(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n + 1)), "elevation: 22 numbers"),
    (lambda c, n: c.set_waves("calm", np.zeros((n, 3))), "velocity: not an array of numbers"),
])
def test_bad_waves_are_refused_in_one_line(call, words):
    coupling = ropesim.Coupling(ropesim.scene_from_toml(RISER, source="riser.toml"))
    assert coupling.wave_points().shape == (21, 3)
    with pytest.raises(CouplingError, match="riser_in_waves: set_waves: ") as info:
        call(coupling, 21)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_a_scene_without_a_sea_has_no_waves_to_give():
    from test_coupling import coupled_scene

    coupling = ropesim.Coupling(coupled_scene())
    with pytest.raises(CouplingError, match=r"wave_points: the scene has no \[sea\]"):
        coupling.wave_points()


def test_moordyns_external_wave_calls_give_the_couplings_own_run(tmp_path):
    """The same script through MoorDyn's call shapes (ExternalWaveKinInit, GetWaveKinCoordinates, SetWaveKin):
    the line's nodes then each point, in MoorDyn's frame, which is this z-up scene's; the forces are those of
    ropesim.Coupling given the same waves, bit for bit."""
    import ropesim.compat.moordyn as moordyn

    path = tmp_path / "riser.toml"
    path.write_text(RISER.replace("t_end = 12.0", "t_end = 1.0"))
    system = moordyn.Create(str(path))
    direct = ropesim.Coupling(ropesim.scene_from_toml(path.read_text(), source=str(path)))
    field = wave_field(direct.scene)
    x, v = [0.0, 0.0, -4.0], [0.0, 0.0, 0.0]
    moordyn.Init(system, x, v)
    direct.init(x, v)
    assert moordyn.ExternalWaveKinInit(system) == 21 + 2 == moordyn.ExternalWaveKinGetN(system)
    for k in range(5):
        t = 3.0 + 0.1 * k
        points = np.array(moordyn.GetWaveKinCoordinates(system))
        assert np.array_equal(points[:21], direct.wave_points())
        assert np.array_equal(points[21:], [[-30.0, 0.0, -40.0], [0.0, 0.0, -4.0]])      # anchor, top
        _, u, a = numpy_waves(field, points, t)
        assert moordyn.SetWaveKin(system, u.tolist(), a.tolist(), t) == 0
        _, u, a = numpy_waves(field, direct.wave_points(), t)
        direct.set_waves(u, a)
        assert moordyn.Step(system, x, v, 0.1 * k, 0.1) == direct.step(0.1 * k, 0.1, x, v).tolist()
    with pytest.raises(CouplingError, match="ExternalWaveKinSet: u needs 23 x 3 numbers"):
        moordyn.ExternalWaveKinSet(system, [[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]], 0.0)
