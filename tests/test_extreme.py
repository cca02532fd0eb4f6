"""Extreme cases: each ends in a correct result or a clean, named refusal or stop; never a hang or a silent NaN.

k = 1e8; node mass 1e-4; N = 2; a loop of 3; N = 20,000; b = 0, b = 1e4 and b = 5e9 (backward kicks overflow);
dt at 0.9x and 1.1x of the bound; coincident nodes; g = 0; t_end = 0; t_end not a multiple of dt.
"""

from __future__ import annotations

import math
import textwrap
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import ropesim
from ropesim.analysis.stability import predicted_dt
from ropesim.model.build import build
from ropesim.cli.app import app
from ropesim.integrate.methods import METHODS
from ropesim.scene.loader import scene_from_toml

from conftest import SCENARIOS

ENV = {"COLUMNS": "200"}
runner = CliRunner()
HELICOPTER = SCENARIOS / "helicopter_uniform.toml"


def helicopter(*sets: str):
    return ropesim.load_scene(HELICOPTER, list(sets))


def sane(traj) -> None:
    """Completed, every saved value finite."""
    assert traj.summary["status"] == "completed", traj.summary.get("message")
    assert np.all(np.isfinite(traj.x)) and np.all(np.isfinite(traj.v))


def test_stiff_rope_k_1e8_refused_explicitly_and_solved_implicitly(tmp_path):
    """k = 1e8 N/m: at the scene's 1 ms step every explicit method is refused, naming sdirk2; sdirk2 runs at
    10 ms and the rope barely stretches (top segment: its load over k, about 1e-5 of its length)."""
    result = runner.invoke(app, ["run", str(HELICOPTER), "--set", "rope.stiffness=1e8", "-o", str(tmp_path / "a")],
                           env=ENV)
    assert result.exit_code == 2 and "stability bound" in result.stderr and "sdirk2" in result.stderr
    traj = ropesim.simulate(helicopter("rope.stiffness=1e8", "integrator.method=sdirk2", "integrator.dt=0.01"))
    sane(traj)
    load = 21 * 5.0 * math.hypot(9.81, 8.0)  # at most the whole rope's weight and drag at tow speed
    assert 0 < traj.summary["max_spring_stretch"] < 2 * load / (1e8 * 0.5)


def test_light_node_mass_1e4_needs_a_short_step():
    """m = 1e-4 kg with k = 5000 and no drag: omega_max about 1.4e4 rad/s, so the bound drops to about
    1.4e-4 s and a run at 0.9 of it completes; sdirk2 runs the scene's own 1 ms step. With the scene's drag
    b = 5 kg/s on such light nodes (b/m = 5e4 /s) the rope is overdamped: exact drag turns each kick into a
    gradient step, stable up to h = 2 (b/m) / omega^2 = 5e-4 s, and the bound says so."""
    light = ["rope.mass=1e-4", "integrator.t_end=0.05"]
    bound = predicted_dt(build(helicopter(*light, "drag.b=0")), "verlet")
    assert bound == pytest.approx(2 / (2 * math.sqrt(5000 / 1e-4)), rel=0.01)
    sane(ropesim.simulate(helicopter(*light, "drag.b=0", f"integrator.dt={0.9 * bound}", "integrator.method=verlet")))
    sane(ropesim.simulate(helicopter(*light, "drag.b=0", "integrator.method=sdirk2")))
    overdamped = predicted_dt(build(helicopter(*light)), "verlet")
    omega2 = 4 * 5000 / 1e-4
    assert overdamped == pytest.approx(2 * 5e4 / omega2, rel=0.02)
    sane(ropesim.simulate(helicopter(*light, f"integrator.dt={0.9 * overdamped}", "integrator.method=verlet")))


TWO = textwrap.dedent("""
    name = "two"
    dimension = 2
    [rope]
    nodes = 2
    segment_length = 1.0
    stiffness = 50.0
    mass = 0.5
    [initial]
    shape = "line"
    start = [0.0, 0.0]
    end = [1.2, 0.0]
    [integrator]
    dt = 0.001
    t_end = 1.0
    [output]
    interval = 0.05
""")


# One method in the quick loop, every method in the slow suite: each family compiles its own loop for the
# two-node scene's parts.
ONE_METHOD_QUICKLY = [m if m == "symplectic_euler" else pytest.param(m, marks=pytest.mark.slow) for m in METHODS]


@pytest.mark.parametrize("method", ONE_METHOD_QUICKLY)
def test_two_nodes_oscillate_at_the_closed_form_frequency(method):
    """N = 2, stretched by 0.2 m and released: the length is 1 + 0.2 cos(sqrt(2 k / m) t) exactly."""
    traj = ropesim.simulate(scene_from_toml(TWO, overrides=[f"integrator.method={method}"]))
    sane(traj)
    length = np.linalg.norm(traj.x[:, 1] - traj.x[:, 0], axis=1)
    exact = 1.0 + 0.2 * np.cos(math.sqrt(2 * 50.0 / 0.5) * traj.t)
    assert np.max(np.abs(length - exact)) < (5e-3 if METHODS[method].order < 2 else 5e-4)
    np.testing.assert_allclose(traj.x.mean(axis=1), [[0.6, 0.0]] * traj.frames, atol=1e-12)  # momentum


LOOP3 = textwrap.dedent("""
    name = "triangle"
    dimension = 2
    [rope]
    nodes = 3
    segment_length = 1.0
    stiffness = 100.0
    mass = 1.0
    closed = true
    [initial]
    shape = "points"
    points = [[0.0, 0.0], [1.1, 0.0], [0.55, 0.9526279441628825]]
    [integrator]
    dt = 0.001
    t_end = 1.0
    [output]
    interval = 0.05
""")


@pytest.mark.parametrize("method", ONE_METHOD_QUICKLY)
def test_loop_of_three_breathes_at_the_closed_form_frequency(method):
    """A closed loop of 3, an equilateral triangle of side 1.1 released: it breathes symmetrically; each side
    is 1 + 0.1 cos(sqrt(3 k / m) t) (the breathing mode of a triangle of springs: omega^2 = 3 k / m)."""
    traj = ropesim.simulate(scene_from_toml(LOOP3, overrides=[f"integrator.method={method}"]))
    sane(traj)
    side = np.linalg.norm(traj.x[:, 1] - traj.x[:, 0], axis=1)
    exact = 1.0 + 0.1 * np.cos(math.sqrt(3 * 100.0) * traj.t)
    assert np.max(np.abs(side - exact)) < (3e-3 if METHODS[method].order < 2 else 3e-4)


@pytest.mark.parametrize("method", ["verlet", pytest.param("sdirk2", marks=pytest.mark.slow)])
def test_twenty_thousand_nodes(method):
    """N = 20,000 (a 2 km rope, pinned at the top, hanging straight): it stays hanging, stretched by its own
    weight, the bound falls back to Gershgorin (no dense eigenvalues), and nothing is lost."""
    text = textwrap.dedent(f"""
        name = "long"
        dimension = 2
        [rope]
        nodes = 20000
        segment_length = 0.1
        stiffness = 1e6
        mass = 0.01
        [initial]
        shape = "hanging"
        top = [0.0, 0.0]
        [pinned]
        nodes = [0]
        [gravity]
        [integrator]
        method = "{method}"
        dt = 1e-4
        t_end = 0.01
        [output]
        interval = 0.01
    """)
    traj = ropesim.simulate(scene_from_toml(text))
    sane(traj)
    assert traj.x.shape == (2, 20000, 2)
    assert np.all(np.abs(traj.x[-1, :, 0]) < 1e-9)  # straight down
    assert traj.x[-1, 0, 1] == 0.0


def test_no_drag_and_huge_drag():
    """b = 0 (a vacuum) runs and conserves energy; b = 1e4 kg/s on 5 kg nodes (gamma = 2000 /s): drag is exact
    in the splitting schemes' kicks, so it only widens their bound (overdamped); rk4's bound shrinks to
    2.785/gamma; and a free rope falls at exactly the terminal speed m g / b."""
    vacuum = ropesim.simulate(helicopter("drag.b=0", "driven.0.velocity=[0.0, 0.0]", "initial.velocity=[0.0, 0.0]",
                                         "integrator.method=pefrl", "integrator.t_end=1"))
    sane(vacuum)
    assert vacuum.summary["energy_ledger"]["max_residual_J"] < 1e-6
    scene = helicopter("drag.b=1e4")
    assert predicted_dt(build(scene), "verlet") > predicted_dt(build(helicopter()), "verlet")
    assert predicted_dt(build(scene), "rk4") == pytest.approx(2.785 / 2000, rel=2e-3)
    free = textwrap.dedent("""
        name = "falling"
        dimension = 2
        [rope]
        nodes = 5
        segment_length = 0.5
        stiffness = 5000.0
        mass = 5.0
        [initial]
        shape = "hanging"
        top = [0.0, 0.0]
        [gravity]
        g = 9.81
        [drag]
        b = 1e4
        [integrator]
        method = "verlet"
        dt = 0.001
        t_end = 0.2
    """)
    for method in ("verlet", "sdirk2"):
        traj = ropesim.simulate(scene_from_toml(free, overrides=[f"integrator.method={method}"]))
        sane(traj)
        np.testing.assert_allclose(traj.v[-1, :, 1], -5.0 * 9.81 / 1e4, rtol=1e-6)


@pytest.mark.parametrize("method", ["yoshida4", "pefrl"])
def test_backward_kicks_under_drag_beyond_the_float_range(tmp_path, method):
    """b = 5e9 kg/s: a backward kick's drag factor e^(gamma |c| h) overflows at dt = 1 ms. The bound says so (a
    finite dt, not a traceback), the run is refused, and forced it stops at its first check without a warning."""
    bound = predicted_dt(build(helicopter("drag.b=5e9")), method)
    assert 0.0 < bound < 1e-6
    args = ["run", str(HELICOPTER), "-q", "-o", str(tmp_path / "run")]
    for s in ("drag.b=5e9", f"integrator.method={method}", "integrator.t_end=0.5"):
        args += ["--set", s]
    refused = runner.invoke(app, args, env=ENV)
    assert refused.exit_code == 2 and "stability bound" in refused.stderr, refused.output
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        forced = runner.invoke(app, [*args, "--force"], env=ENV)
    assert forced.exit_code == 3 and "blew up at t =" in forced.stderr, (forced.output, forced.exception)


@pytest.mark.parametrize("method", ["symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4"])
def test_dt_at_0_9_and_1_1_of_the_bound(tmp_path, method):
    """0.9x the bound: runs to the end. 1.1x: refused without --force; with --force it blows up within a
    bounded number of steps, exits 3 naming the time, the node and a stable dt, and keeps the frames."""
    bound = predicted_dt(build(helicopter()), method)
    common = [f"integrator.method={method}", "integrator.t_end=60", "output.interval=0.5"]
    sane(ropesim.simulate(helicopter(*common, f"integrator.dt={0.9 * bound}")))
    args = ["run", str(HELICOPTER), "-q", "-o", str(tmp_path / "run")]
    for s in [*common, f"integrator.dt={1.1 * bound}"]:
        args += ["--set", s]
    assert runner.invoke(app, args, env=ENV).exit_code == 2
    forced = runner.invoke(app, [*args, "--force"], env=ENV)
    assert forced.exit_code == 3, forced.output
    line = forced.stderr.strip()
    assert "blew up at t =" in line and "node" in line and "would be stable" in line
    traj = ropesim.Trajectory.open(tmp_path / "run")
    assert traj.summary["status"] == "blew_up" and traj.summary["steps"] < 2000
    assert traj.t[-1] < 60 and np.all(np.isfinite(traj.x[:-1]))


COINCIDENT = textwrap.dedent("""
    name = "coincident"
    dimension = 2
    [rope]
    nodes = 4
    segment_length = 0.5
    stiffness = 500.0
    mass = 1.0
    [initial]
    shape = "points"
    points = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.0], [1.0, 0.0]]
    [pinned]
    nodes = [0]
    [gravity]
    [integrator]
    dt = 0.001
    t_end = 0.5
""")


def test_coincident_nodes_in_a_scene_file_are_refused_by_name():
    with pytest.raises(ropesim.SceneError, match="initial.points: nodes 1 and 2 coincide"):
        scene_from_toml(COINCIDENT)


@pytest.mark.parametrize("method", list(METHODS))
def test_nodes_that_come_to_coincide_are_integrated_without_nan(method):
    """A zero-length segment during a run (made here by moving node 2 onto node 1 after loading): that spring
    has no direction and pushes nothing until the neighbours pull the nodes apart; no NaN anywhere."""
    from ropesim.integrate.grid import TimeGrid
    from ropesim.integrate.methods import make_integrator

    scene = scene_from_toml(COINCIDENT.replace("[0.5, 0.0], [1.0, 0.0]]", "[0.75, 0.0], [1.0, 0.0]]"),
                            overrides=[f"integrator.method={method}"])
    model = build(scene)
    model.x0[:, 2] = model.x0[:, 1]
    grid = TimeGrid.of(scene)
    stepper = make_integrator(model, grid, method)
    done, _, status, _ = stepper.advance(grid.steps)
    assert status == 0 and done == grid.steps
    assert np.all(np.isfinite(stepper.x)) and np.all(np.isfinite(stepper.v))
    assert np.linalg.norm(stepper.x[:, 2] - stepper.x[:, 1]) > 0.05  # pulled apart by gravity and the end node


def test_zero_gravity_rope_at_rest_stays_at_rest_and_never_trips_the_checks():
    """g = 0, no drag, nothing moving: nothing happens, exactly, for every method (the energy scale has a
    floor, so a zero-energy system does not look like a runaway)."""
    for method in METHODS:
        traj = ropesim.simulate(helicopter("gravity.g=0", "drag.b=0", "driven.0.velocity=[0.0, 0.0]",
                                           "initial.velocity=[0.0, 0.0]", f"integrator.method={method}",
                                           "integrator.t_end=0.2", "initial.top=[0.0, 0.0]"))
        sane(traj)
        assert np.max(np.abs(traj.x[-1] - traj.x[0])) < 1e-12


@pytest.mark.parametrize("method", list(METHODS))
def test_t_end_zero_and_t_end_not_a_multiple_of_dt(method):
    """t_end = 0: one frame, the initial state, a zero ledger. t_end = 0.0105 with dt = 0.001: the step shrinks
    to 0.0105/11 and the last frame lands exactly on t_end, the driven node exactly at V t_end."""
    zero = ropesim.simulate(helicopter("integrator.t_end=0", f"integrator.method={method}"))
    assert zero.frames == 1 and zero.summary["status"] == "completed"
    assert zero.summary["energy_ledger"]["residual_J"] == 0.0
    odd = ropesim.simulate(helicopter("integrator.t_end=0.0105", f"integrator.method={method}"))
    sane(odd)
    assert odd.t[-1] == pytest.approx(0.0105, abs=1e-15) and odd.summary["dt"] == pytest.approx(0.0105 / 11)
    assert odd.x[-1, 0, 0] == pytest.approx(8.0 * 0.0105, abs=1e-14)
