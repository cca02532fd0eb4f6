"""Free rigid bodies under a sea (ropesim/model/body_sea.py) against closed forms.

- The loads on a body held in a regular Airy wave (3-D, 30 m of water, the wave at 30 degrees, the body turned
  about all three axes): its weight, buoyancy f rho V g at its centre of buoyancy, the Morison drag
  1/2 rho R diag(CdA) R^T |u| u and the inertia force (f rho V + R diag(a) R^T) a_w, with u and a_w the
  closed-form Airy velocity and acceleration at the reference point (Wheeler-stretched; the wave number solved
  here by scipy's brentq, independently of ropesim's Newton solve). Compiled kernel against the formulas: to
  1e-12 of the largest load.
- A fully submerged body's buoyancy is rho V g whatever the waves do above it (crest and trough pass); under
  MoorDyn's rule (``fraction = "moordyn"``) a body crossing the surface keeps its full buoyancy and feels no
  water acceleration, as MoorDyn's body does.
- A floating box (V = 8 m^3, height 2 m, so A_wp = 4 m^2; m = 4100 kg, heave added mass 1000 kg) released 0.3 m
  above its draught: Archimedes' draught f = m / (rho V) = 1/2 (its centre of buoyancy at the mean level) and
  heave y = 0.3 cos(w t), w^2 = rho g A_wp / (m + a) (exact: the waterplane is linear in heave while it cuts
  the walls; the amplitude keeps it inside them). verlet at 1 ms (w dt = 0.0028: phase error (w dt)^2 / 24 per
  radian, 4e-6 of the amplitude over 6 s) to 2e-5 of the amplitude, and the energy ledger (the buoyancy lost
  above the surface booked as the fluid's work) to 1e-5 of the energy exchanged. sdirk2 at 10 ms (slow suite:
  its error (w dt)^2 / 12 per radian ~ 7e-5 per radian, 1e-3 of the amplitude over 13 radians).
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import ropesim

RHO, G = 1025.0, 9.80665

LOADS = """
name = "held_body"
dimension = 3
[[bodies]]
id = "can"
position = [3.0, Y0, 2.0]
orientation = [10.0, 20.0, 30.0]
mass = 2000.0
center_of_gravity = [0.1, -0.3, 0.05]
inertia = [800.0, 900.0, 1000.0]
volume = 3.0
center_of_buoyancy = [0.0, 0.2, -0.1]
height = 1.5
cd_area = [2.0, 3.0, 1.5]
added_mass = [1500.0, 2500.0, 1200.0]
[[points]]
id = "anchor"
position = [8.0, Y0, 2.0]
[[points]]
id = "eye"
body = "can"
position = [0.0, 0.0, 0.0]
[[lines]]
id = "slack"
start = "anchor"
end = "eye"
length = 10.0
segments = 2
mass_per_length = 1.0e-6
EA = 1.0
[gravity]
g = 9.80665
[fluid]
density = 1025.0
[sea]
level = 0.0
depth = 30.0
fraction = "FRACTION"
[waves]
kind = "regular"
height = 2.0
period = 8.0
direction = 30.0
phase = 40.0
[integrator]
method = "rk4"
dt = 0.001
t_end = 0.01
"""

FLOAT = """
name = "floating_box"
dimension = 3
[[bodies]]
id = "box"
position = [0.0, 0.3, 0.0]
mass = 4100.0
inertia = [1000.0, 1000.0, 1000.0]
volume = 8.0
height = 2.0
added_mass = [0.0, 1000.0, 0.0]
[[points]]
id = "anchor"
position = [5.0, 0.0, 0.0]
[[points]]
id = "eye"
body = "box"
position = [0.0, 0.0, 0.0]
[[lines]]
id = "slack"
start = "anchor"
end = "eye"
length = 10.0
segments = 2
mass_per_length = 1.0e-6
EA = 1.0
[gravity]
g = 9.80665
[fluid]
density = 1025.0
[sea]
level = 0.0
[integrator]
method = "METHOD"
dt = DT
t_end = 6.0
[output]
interval = 0.01
"""


def airy(x, y, z, t, height=2.0, period=8.0, depth=30.0, direction=30.0, phase=40.0):
    """The closed-form regular Airy wave at (x, y, z) and t: eta, velocity (3), local acceleration (3), Wheeler
    stretched, the wave number from the dispersion relation by brentq."""
    from scipy.optimize import brentq

    w, a, d = 2 * math.pi / period, 0.5 * height, depth
    k = brentq(lambda k: G * k * math.tanh(k * d) - w * w, 1e-9, 10.0, xtol=1e-15, rtol=1e-15)
    beta = math.radians(direction)
    theta = k * (x * math.cos(beta) - z * math.sin(beta)) - w * t + math.radians(phase)
    eta = a * math.cos(theta)
    s = min(d * (y - eta) / (d + eta), 0.0)
    ch, sh = math.cosh(k * (s + d)) / math.sinh(k * d), math.sinh(k * (s + d)) / math.sinh(k * d)
    e = np.array([math.cos(beta), 0.0, -math.sin(beta)])
    u = a * w * (ch * math.cos(theta) * e + sh * math.sin(theta) * np.array([0.0, 1.0, 0.0]))
    du = a * w * w * (ch * math.sin(theta) * e - sh * math.cos(theta) * np.array([0.0, 1.0, 0.0]))
    return eta, u, du


def rotation(angles_deg):
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("xyz", angles_deg, degrees=True).as_matrix()


def expected_loads(y0, t, rule):
    """Force and moment (world axes, about the reference point) on the held body of LOADS at rest, at time t."""
    r = rotation([10.0, 20.0, 30.0])
    ref = np.array([3.0, y0, 2.0])
    cog, cob = r @ np.array([0.1, -0.3, 0.05]), r @ np.array([0.0, 0.2, -0.1])
    volume, mass = 3.0, 2000.0
    eta, u, du = airy(ref[0], ref[1], ref[2], t)
    f = 1.0 if rule == "moordyn" else min(max((eta - (ref[1] + cob[1])) / 1.5 + 0.5, 0.0), 1.0)
    up = np.array([0.0, 1.0, 0.0])
    weight, buoyancy = -mass * G * up, f * RHO * volume * G * up
    drag = 0.5 * RHO * f * r @ np.diag([2.0, 3.0, 1.5]) @ r.T @ u * np.linalg.norm(u)
    inertia = np.zeros(3) if rule == "moordyn" else (f * RHO * volume * np.eye(3)
                                                     + r @ np.diag([1500.0, 2500.0, 1200.0]) @ r.T) @ du
    force = weight + buoyancy + drag + inertia
    moment = np.cross(cog, weight) + np.cross(cob, buoyancy)
    return force, moment, f


def own_loads(scene, times):
    """The compiled own loads (force, moment: world axes) of the scene's one free body at rest at its start."""
    from ropesim.model.body_groups import own_parts
    from ropesim.model.build import build

    model = build(scene)
    own = model.kernel(own_parts)
    pose, twist = model.body_pose0.copy(), np.zeros((6, 1))
    out = np.zeros((1, 6, 7))
    loads = []
    for t in times:
        own(model.params, pose, twist, float(t), out)
        loads.append(out[0, :, 6].copy())
    return np.array(loads)


TIMES = np.linspace(0.0, 8.0, 9)


@pytest.fixture(scope="module")
def loads():
    """(y0, rule) -> compiled loads at TIMES, one compile for all."""
    out = {}
    for y0, rule in ((-6.0, "cylinders"), (0.2, "cylinders"), (0.2, "moordyn")):
        text = LOADS.replace("Y0", str(y0)).replace("FRACTION", rule)
        out[y0, rule] = own_loads(ropesim.scene_from_toml(text, source="held_body.toml"), TIMES)
    return out


@pytest.mark.parametrize("y0, rule", [(-6.0, "cylinders"), (0.2, "cylinders"), (0.2, "moordyn")])
def test_a_held_body_feels_morison_drag_and_inertia_of_the_airy_wave_at_its_point(loads, y0, rule):
    got = loads[y0, rule]
    fractions = []
    for t, row in zip(TIMES, got):
        force, moment, f = expected_loads(y0, t, rule)
        scale = np.abs(force).max()
        np.testing.assert_allclose(row[:3], force, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(row[3:], moment, rtol=0, atol=1e-12 * scale)
        fractions.append(f)
    if y0 < -2.0 or rule == "moordyn":
        assert fractions == [1.0] * len(TIMES)      # wholly submerged whatever the wave: full rho V g
    else:
        assert min(fractions) < 0.5 < max(fractions)   # the wave washes up and down the walls, and past them
        assert sum(0.0 < f < 1.0 for f in fractions) >= 4


def test_a_submerged_bodys_buoyancy_does_not_feel_the_waves(loads):
    """Without drag and inertia the vertical load is rho V g - m g at every phase: the waves take nothing."""
    got = loads[-6.0, "cylinders"]
    for t, row in zip(TIMES, got):
        force, _, _ = expected_loads(-6.0, t, "cylinders")
        _, u, du = airy(3.0, -6.0, 2.0, t)
        r = rotation([10.0, 20.0, 30.0])
        drag = 0.5 * RHO * r @ np.diag([2.0, 3.0, 1.5]) @ r.T @ u * np.linalg.norm(u)
        inertia = (RHO * 3.0 * np.eye(3) + r @ np.diag([1500.0, 2500.0, 1200.0]) @ r.T) @ du
        assert row[1] - drag[1] - inertia[1] == pytest.approx(RHO * 3.0 * G - 2000.0 * G, rel=1e-13)


def _float_run(method, dt):
    text = FLOAT.replace("METHOD", method).replace("DT", str(dt))
    return ropesim.simulate(ropesim.scene_from_toml(text, source="floating_box.toml"))


def _check_floating(run, tolerance):
    w = math.sqrt(RHO * G * 4.0 / (4100.0 + 1000.0))   # rho g A_wp / (m + a), A_wp = V / h
    heave = run.body("box").position[:, 1]
    assert 4100.0 / (RHO * 8.0) == pytest.approx(0.5)   # Archimedes: half under, its centre at the mean level
    np.testing.assert_allclose(heave, 0.3 * np.cos(w * run.t), rtol=0, atol=tolerance * 0.3)
    assert np.abs(run.body("box").position[:, [0, 2]]).max() < 1e-6
    # the submerged fraction reported per frame: 1/2 - heave / h, between 0.35 and 0.65
    np.testing.assert_allclose(run.body("box").submerged, 0.5 - 0.3 * np.cos(w * run.t) / 2.0, rtol=0,
                               atol=tolerance * 0.3 / 2.0)
    ledger = run.summary["energy_ledger"]
    assert abs(ledger["residual_J"]) < 1e-5 * ledger["energy_flowed_J"]


def test_a_floating_box_rests_at_archimedes_draught_and_heaves_at_its_waterplane_period():
    _check_floating(_float_run("verlet", 0.001), 2e-5)


@pytest.mark.slow
def test_sdirk2_floats_the_box_alike():
    _check_floating(_float_run("sdirk2", 0.01), 1e-3)


def test_under_moordyns_rule_the_reported_fraction_is_whole():
    text = FLOAT.replace("METHOD", "verlet").replace("DT", "0.001").replace("t_end = 6.0", "t_end = 0.5")
    run = ropesim.simulate(ropesim.scene_from_toml(text.replace("level = 0.0\n", 'level = 0.0\nfraction = "moordyn"\n'),
                                                   source="floating_box.toml"))
    assert np.array_equal(run.body("box").submerged, np.ones(len(run.t)))
    assert run.body("box").position[-1, 1] > 0.3   # whole buoyancy, twice its weight: it rises


def test_only_scenes_with_free_bodies_in_a_sea_compile_the_bodies_sea():
    from ropesim.model.terms import switches

    def on(text):
        return "body_sea" in switches(ropesim.scene_from_toml(text, source="s.toml"))

    floating = FLOAT.replace("METHOD", "rk4").replace("DT", "0.001")
    assert on(floating)
    assert not on(floating.replace("[sea]\nlevel = 0.0\n", "").replace("height = 2.0\n", ""))


@pytest.mark.parametrize("change, key, words", [
    (lambda s: s.replace("height = 2.0\n", ""), "bodies.0.height", "missing: free body 'box' under a [sea]"),
    (lambda s: s.replace("[sea]\nlevel = 0.0\n", ""), "bodies.0.height", "it needs a [sea]"),
    (lambda s: s.replace("mass = 4100.0\n", 'kind = "fixed"\n').replace("inertia = [1000.0, 1000.0, 1000.0]\n",
                                                                         ""), "bodies.0.height", "this body is 'fixed'"),
    (lambda s: s.replace("height = 2.0", "height = 0.0"), "bodies.0.height", ""),
])
def test_bad_body_sea_input_is_refused_in_one_line(change, key, words):
    text = change(FLOAT.replace("METHOD", "rk4").replace("DT", "0.001"))
    with pytest.raises(ropesim.SceneError) as exc:
        ropesim.scene_from_toml(text, source="scene.toml")
    message = str(exc.value)
    assert "\n" not in message and message.startswith(f"scene.toml: {key}") and words in message, message


def test_moordyns_rule_needs_no_height():
    text = FLOAT.replace("METHOD", "rk4").replace("DT", "0.001").replace("height = 2.0\n", "")
    ropesim.scene_from_toml(text.replace("level = 0.0\n", 'level = 0.0\nfraction = "moordyn"\n'), source="s.toml")


def test_a_missing_height_exits_2_in_one_line_from_the_command_line(tmp_path):
    scene = tmp_path / "box.toml"
    scene.write_text(FLOAT.replace("METHOD", "rk4").replace("DT", "0.001").replace("height = 2.0\n", ""))
    done = subprocess.run([sys.executable, "-m", "ropesim", "check", str(scene)], capture_output=True, text=True)
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1 and "bodies.0.height" in done.stderr, done.stderr


def test_the_static_solver_floats_the_box_where_the_dynamics_keep_it():
    """initial.shape = "equilibrium" with a 10 m chain of 2 kg/m hanging from the box to an anchor 8 m down: the
    static solve (the waterplane's heave stiffness in its step matrix) finds the balance that verlet then holds
    to 1e-9 m over 2 s, the box sunk below its free draught by part of the chain's wet weight (at most all of
    it over rho g A_wp)."""
    text = FLOAT.replace("METHOD", "verlet").replace("DT", "0.001").replace("t_end = 6.0", "t_end = 2.0")
    text = text.replace("[gravity]", '[initial]\nshape = "equilibrium"\n[gravity]')
    text = text.replace("position = [5.0, 0.0, 0.0]", "position = [6.0, -8.0, 0.0]").replace(
        "mass_per_length = 1.0e-6\nEA = 1.0", "mass_per_length = 2.0\ndiameter = 0.02\nEA = 1.0e5")
    run = ropesim.simulate(ropesim.scene_from_toml(text, source="floating_box.toml"))
    p = run.body("box").position
    assert np.abs(p - p[0]).max() < 1e-9
    wet_weight = 10.0 * (2.0 - RHO * math.pi * 0.01 ** 2)           # kg: the whole chain's, in water
    assert -wet_weight / (RHO * 4.0) < p[0, 1] < -0.2 * wet_weight / (RHO * 4.0)


def test_waves_given_from_outside_are_refused_with_a_free_body():
    """A coupled program's wave kinematics come at the lines' nodes; a free body's reference point is not one."""
    from ropesim.coupling import CouplingError

    text = FLOAT.replace("METHOD", "rk4").replace("DT", "0.001")
    text = text.replace('id = "anchor"\n', 'id = "anchor"\nkind = "coupled"\n')   # the program moves the anchor
    coupling = ropesim.Coupling(ropesim.scene_from_toml(text, source="floating_box.toml"))
    n = coupling.wave_points().shape[0]
    with pytest.raises(CouplingError, match="floating_box: set_waves: a free rigid body") as info:
        coupling.set_waves(np.zeros((n, 3)), np.zeros((n, 3)))
    assert "\n" not in str(info.value)
