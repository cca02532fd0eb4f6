"""The energy ledger: drag loss, work of held nodes and of the thrower box, and the balance's residual."""

from __future__ import annotations

import math
import textwrap
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ropesim
from ropesim.analysis.ledger import LEDGER, ledger_series
from ropesim.io.frames import read_flows
from ropesim.model.build import build
from ropesim.integrate.methods import METHODS
from ropesim.integrate.splitting import kick_factors
from ropesim.scene.loader import scene_from_toml
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.health import LEDGER_COLUMNS
from ropesim.integrate.methods import make_integrator

from conftest import SCENARIOS


def coasting_pair(b: float, v0: float, method: str, dt: float = 0.01) -> str:
    """Two nodes at rest length apart moving together at v0 with drag b, no gravity: the spring stays slack,
    each node's speed decays as v0 e^(-b t / m) and drag takes 2 * 1/2 m v0^2 (1 - e^(-2 b t / m))."""
    return textwrap.dedent(f"""
        name = "pair"
        dimension = 2
        [rope]
        nodes = 2
        segment_length = 1.0
        stiffness = 100.0
        mass = 2.0
        [initial]
        shape = "line"
        start = [0.0, 0.0]
        end = [1.0, 0.0]
        velocity = [{v0}, 0.0]
        [drag]
        b = {b}
        [integrator]
        method = "{method}"
        dt = {dt}
        t_end = 1.0
    """)


def final_ledger(scene):
    model = build(scene)
    grid = TimeGrid.of(scene)
    stepper = make_integrator(model, grid, scene.integrator.method)
    stepper.advance(grid.steps)
    return stepper


@pytest.mark.parametrize("method", ["symplectic_euler", "verlet", "yoshida4", "pefrl"])
@settings(max_examples=10, deadline=None)
@given(b=st.floats(0.01, 50.0), v0=st.floats(-20.0, 20.0))
def test_drag_loss_is_exact_in_the_splitting_schemes(method, b, v0):
    """Drag is integrated exactly in every kick, so a coasting node's loss is exact to round-off."""
    s = final_ledger(scene_from_toml(coasting_pair(b, v0, method)))
    m, t = 2.0, 1.0
    exact = 2 * 0.5 * m * v0 ** 2 * -math.expm1(-2 * b * t / m)
    assert s.ledger[0] == pytest.approx(exact, rel=1e-9, abs=1e-12)
    assert s.v[0] == pytest.approx(v0 * math.exp(-b * t / m), rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("rate", [0.0, 5e-320, 1e-200, 1e-6, 0.3, 2e3, 1e20])
def test_kick_factors_follow_the_closed_forms_at_every_drag_rate(rate):
    """decay = e^-z, gain = (1 - e^-z) / gamma and travel = (c - gain) / gamma (z = gamma c), from no drag to
    drag that stops a node in one kick, without a warning. A subnormal b/m counts as none: its few
    significant bits would spoil gain, and it changes nothing a float can hold."""
    h, mass = 1e-3, np.array([2.0, 2.0])
    scheme = METHODS["verlet"]   # two kicks of c = h / 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        decay, gain, travel = kick_factors(scheme, h, rate * mass, mass, np.array([True, False]))
    c = 0.5 * h
    gamma = rate if rate >= np.finfo(float).tiny else 0.0
    z = gamma * c
    want_gain = -math.expm1(-z) / gamma if gamma else c
    want_travel = (c - want_gain) / gamma if z > 1e-3 else c * c * sum((-z) ** n / math.factorial(n + 2)
                                                                        for n in range(12))
    assert decay[:, 1] == pytest.approx(math.exp(-z), rel=1e-15)
    assert gain[:, 1] == pytest.approx(want_gain, rel=1e-15)
    assert travel[:, 1] == pytest.approx(want_travel, rel=1e-12)
    assert (decay[:, 0], gain[:, 0], travel[:, 0]) == (pytest.approx(1.0), pytest.approx(0.0), pytest.approx(0.0))


@pytest.mark.parametrize("method", ["rk4", "sdirk2"])
def test_drag_loss_converges_at_the_methods_order(method):
    """Runge-Kutta methods book the drag power with their own weights: the loss converges at their order."""
    exact = 2 * 0.5 * 2.0 * 3.0 ** 2 * -math.expm1(-2 * 4.0 / 2.0)
    errs = [abs(final_ledger(scene_from_toml(coasting_pair(4.0, 3.0, method, dt))).ledger[0] - exact)
            for dt in (0.02, 0.01)]
    assert math.log2(errs[0] / errs[1]) == pytest.approx(METHODS[method].order, abs=0.2)


@pytest.mark.parametrize("method", list(METHODS))
def test_towed_rope_balances_and_the_residual_shrinks_at_order(method):
    """The helicopter: the driven node's work goes into drag and the rope's energy; the balance's residual is
    the integration error, a tiny fraction of the energy that flowed, shrinking as dt^order (log2 of the
    ratio on halving dt within 0.5 of the order; measured 1.00, 2.00, 4.04, 4.00, 3.73, 1.96)."""
    residuals = []
    # RK4's residual has a fifth-order part (its damping of the stiff modes) that dominates above dt = 1 ms
    for dt in ((0.001, 0.0005) if method == "rk4" else (0.004, 0.002)):
        scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml",
                                   ["integrator.t_end=1", f"integrator.dt={dt}", f"integrator.method={method}"])
        traj = ropesim.simulate(scene)
        ledger = traj.summary["energy_ledger"]
        assert ledger["held_work_J"] > 0 and ledger["drag_loss_J"] > 0 and ledger["box_work_J"] == 0
        assert ledger["relative_residual"] < 1e-3
        residuals.append(ledger["max_residual_J"])
    order = METHODS[method].order
    if residuals[1] > 1e-8:  # above round-off
        assert math.log2(residuals[0] / residuals[1]) == pytest.approx(order, abs=0.5)


def test_shooter_ledger_books_the_box_and_the_drag(tmp_path):
    """The thrower pumps energy in, drag takes it out; the run folder keeps the flows in ledger.npz."""
    scene = ropesim.load_scene(SCENARIOS / "shooter_medium.toml", ["integrator.t_end=1", "integrator.method=verlet"])
    traj = ropesim.simulate(scene, tmp_path / "run")
    ledger = traj.summary["energy_ledger"]
    assert ledger["box_work_J"] > 0 and ledger["drag_loss_J"] > 0 and ledger["held_work_J"] == 0
    assert ledger["relative_residual"] < 0.01
    flows, energy0 = read_flows(tmp_path / "run")
    assert flows.shape == (traj.frames, len(LEDGER_COLUMNS)) and (tmp_path / "run" / LEDGER).is_file()
    series = ledger_series(build(scene), traj.x, traj.v, flows, energy0)
    assert series["residual"][-1] == pytest.approx(ledger["residual_J"])
    assert np.all(np.diff(series["drag_loss"]) >= 0)  # drag only ever takes energy


def test_ledger_is_identical_however_the_run_is_chunked():
    scene = ropesim.load_scene(SCENARIOS / "shooter_low.toml", ["integrator.method=pefrl"])
    model, grid = build(scene), TimeGrid.of(scene)
    whole = make_integrator(model, grid, "pefrl")
    whole.advance(600)
    pieces = make_integrator(model, grid, "pefrl")
    for n in (1, 99, 500):
        pieces.advance(n)
    assert np.array_equal(whole.ledger, pieces.ledger)


def test_plot_shows_the_ledger(tmp_path):
    from typer.testing import CliRunner

    from ropesim.cli.app import app

    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml", ["integrator.t_end=0.5"])
    ropesim.simulate(scene, tmp_path / "run")
    result = CliRunner().invoke(app, ["plot", str(tmp_path / "run"), "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 0, result.output
    assert "ledger" in result.stdout
