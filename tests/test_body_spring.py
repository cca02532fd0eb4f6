"""A free rigid body's linear spring and damper (``stiffness``, ``damping`` on [[bodies]]) against the damped
oscillator's closed form: m y'' = -k y - c y', y(0) = 0, y'(0) = v0 gives y = v0 / w_d e^(-zeta w t) sin(w_d t).

The body (1000 kg, k = 4000 N/m, c = 400 N s/m: w = 2 rad/s, zeta = 0.1) hangs on nothing: its one line is slack
and nearly massless (1e-6 kg/m) and there is no gravity, so only its spring and damper act. verlet at dt = 1 ms
(w dt = 0.002: a phase error of (w dt)^2 / 24 per radian, 2e-6 over the run) must match to 1e-5 of the amplitude;
the energy balance (the spring's energy in the ledger, the damper's loss booked as fluid work) to 1e-6 of it.
"""

import math

import numpy as np
import pytest

import ropesim

SCENE = """
name = "spring_body"
dimension = 3
[[bodies]]
id = "buoy"
position = [0.0, 0.0, 0.0]
mass = 1000.0
inertia = [100.0, 100.0, 100.0]
stiffness = [0.0, 4000.0, 0.0]
damping = [0.0, 400.0, 0.0]
velocity = [0.0, 1.0, 0.0]
[[points]]
id = "anchor"
position = [5.0, 0.0, 0.0]
[[points]]
id = "eye"
body = "buoy"
position = [0.0, 0.0, 0.0]
[[lines]]
id = "slack"
start = "anchor"
end = "eye"
length = 10.0
segments = 2
mass_per_length = 1.0e-6
EA = 1.0
[integrator]
method = "verlet"
dt = 0.001
t_end = 10.0
[output]
interval = 0.05
"""


@pytest.fixture(scope="module")
def run():
    return ropesim.simulate(ropesim.scene_from_toml(SCENE, source="spring_body.toml"))


def test_a_free_body_on_its_spring_and_damper_rings_down_as_the_damped_oscillator(run):
    w, zeta, v0 = 2.0, 0.1, 1.0
    wd = w * math.sqrt(1 - zeta ** 2)
    t = run.t
    exact = v0 / wd * np.exp(-zeta * w * t) * np.sin(wd * t)
    heave = run.body("buoy").position[:, 1]
    assert np.max(np.abs(heave - exact)) < 1e-5 * v0 / wd
    assert np.max(np.abs(run.body("buoy").position[:, [0, 2]])) < 1e-6   # the slack line all but lets it be


def test_the_spring_is_in_the_energy_and_the_damper_in_the_fluid_work(run):
    ledger = run.summary["energy_ledger"]
    kinetic0 = 0.5 * 1000.0 * 1.0 ** 2
    assert ledger["energy0_J"] == pytest.approx(kinetic0, rel=1e-6)
    assert abs(ledger["residual_J"]) < 1e-6 * kinetic0
    assert ledger["fluid_work_J"] == pytest.approx(ledger["energy_J"] - ledger["energy0_J"], rel=1e-5)


def test_a_spring_on_a_body_that_is_not_free_is_refused():
    text = SCENE.replace('position = [0.0, 0.0, 0.0]\nmass = 1000.0', 'position = [0.0, 0.0, 0.0]\nkind = "fixed"', 1)
    with pytest.raises(ropesim.SceneError, match="bodies.0.stiffness: acts on a free body"):
        ropesim.scene_from_toml(text.replace("inertia = [100.0, 100.0, 100.0]\n", "").replace(
            "velocity = [0.0, 1.0, 0.0]\n", ""), source="s.toml")


def test_the_static_solve_balances_a_free_bodys_weight_on_its_spring():
    """With gravity and an equilibrium start, the spring holds the body m g / k below where it rests (its slack,
    nearly massless line adds 1e-4 N to 9810 N): the static solve counts the spring's force, its energy in the
    merit function and its stiffness in the Newton block."""
    from ropesim.model.build import build

    at_rest = SCENE.replace("velocity = [0.0, 1.0, 0.0]\n", "")
    text = at_rest + '\n[gravity]\ng = 9.81\n[initial]\nshape = "equilibrium"\n'
    model = build(ropesim.scene_from_toml(text, source="spring_body.toml"))
    assert model.body_pose0[1, 0] == pytest.approx(-1000.0 * 9.81 / 4000.0, rel=1e-6)
