"""Stability before and while running: each method's stability interval, the bounds on the fastest mode,
predicted against measured blow-up time steps, `check`, `run` (warn, refuse, --force) and `stability`."""

from __future__ import annotations

import csv
import math
import textwrap

import numpy as np
import pytest
from typer.testing import CliRunner

import ropesim
from ropesim.analysis.stability import (gershgorin_frequency, measured_dt, predicted_dt, spectral_frequency,
                                        stability_sweep)
from ropesim.model.build import build
from ropesim.cli.app import app
from ropesim.integrate.base import stable_step
from ropesim.integrate.methods import METHODS
from ropesim.scene.loader import scene_from_toml

from conftest import SCENARIOS

ENV = {"COLUMNS": "200"}
runner = CliRunner()


@pytest.mark.parametrize("method, limit", [("symplectic_euler", 2.0), ("verlet", 2.0),
                                           ("yoshida4", 1.5734), ("pefrl", 2.9894), ("rk4", 2 * math.sqrt(2))])
def test_stability_interval_of_each_method(method, limit):
    """Largest stable h omega on x'' = -omega^2 x: 2 for leapfrog-type schemes, 2 sqrt(2) for RK4 (its
    stability polynomial on the imaginary axis), 1.5734 for Yoshida-4 and 2.9894 for PEFRL (their
    compositions' known intervals)."""
    assert METHODS[method].stability_limit == pytest.approx(limit, abs=2e-4)


def test_stiff_integrator_has_no_limit_and_damps_stiff_modes():
    """sdirk2 is L-stable: bounded for any h omega and any damping, and a mode far faster than 1/h dies."""
    m = METHODS["sdirk2"]
    assert math.isinf(m.stability_limit) and math.isinf(stable_step(m, 1e6, 1e6, 1e6))
    for h_omega in (0.1, 3.0, 100.0, 1e6):
        assert max(abs(np.linalg.eigvals(m.amplification(h_omega, 1.0)))) <= 1.0
    assert max(abs(np.linalg.eigvals(m.amplification(1e6, 1.0)))) < 1e-3


def test_explicit_damping_shortens_explicit_steps():
    """A velocity force evaluated explicitly (the thrower's) limits symplectic Euler to h gamma < 2 even without
    springs; exact drag does not limit the splitting schemes at all."""
    euler = METHODS["symplectic_euler"]
    assert stable_step(euler, 0.0, 100.0) == pytest.approx(0.02, rel=1e-3)
    assert math.isinf(stable_step(euler, 0.0, 0.0, 1e4))
    assert stable_step(METHODS["rk4"], 0.0, 0.0, 1000.0) == pytest.approx(2.785 / 1000, rel=1e-3)


def chain(nodes: int, pinned: str = "", closed: bool = False, mass: float = 2.0, k: float = 800.0) -> str:
    return textwrap.dedent(f"""
        name = "chain"
        dimension = 2
        [rope]
        nodes = {nodes}
        segment_length = 0.5
        stiffness = {k}
        mass = {mass}
        closed = {'true' if closed else 'false'}
        [initial]
        shape = "line"
        start = [0.0, 0.0]
        end = [{0.5 * (nodes - 1)}, 0.0]
        {pinned}
        [integrator]
        dt = 0.001
        t_end = 1.0
    """)


@pytest.mark.parametrize("nodes", [2, 3, 10, 61])
def test_spectral_bound_is_the_free_chains_fastest_mode(nodes):
    """A free chain of N equal masses: omega_max^2 = 2 k/m (1 + cos(pi/N)) exactly; Gershgorin 2 sqrt(k/m)
    (reached only as N grows), never below it. The write-up's dt < 2 sqrt(m/k) is the one-spring limit: the
    chain's fastest mode is up to twice as fast."""
    k, m = 800.0, 2.0
    model = build(scene_from_toml(chain(nodes)))
    exact = math.sqrt(2 * k / m * (1 + math.cos(math.pi / nodes)))
    assert spectral_frequency(model) == pytest.approx(exact, rel=1e-9)
    assert gershgorin_frequency(model) >= exact * (1 - 1e-12)
    ends_only = nodes == 2  # both nodes are ends, with one spring each
    assert gershgorin_frequency(model) == pytest.approx(math.sqrt((2 if ends_only else 4) * k / m), rel=1e-12)


def test_a_held_neighbour_does_not_count_as_a_moving_one():
    """Two nodes, one pinned: a single mass on a spring, omega = sqrt(k/m) exactly (counting the pinned node's
    coupling, as a plain Gershgorin sum over all nodes would, gives sqrt(2 k/m))."""
    k, m = 800.0, 2.0
    model = build(scene_from_toml(chain(2, "[pinned]\nnodes = [0]")))
    assert gershgorin_frequency(model) == pytest.approx(math.sqrt(k / m), rel=1e-12)
    assert spectral_frequency(model) == pytest.approx(math.sqrt(k / m), rel=1e-12)


@pytest.mark.parametrize("method", ["symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4"])
def test_predicted_bound_matches_measured_blow_up_on_the_helicopter(method):
    """The towed rope (drag, a driven node, a heavy-free uniform chain): the predicted bound is safe (runs at
    it survive) and tight (a run 1 % above it blows up): measured within 0.4 % for every explicit method."""
    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml")
    bound = predicted_dt(build(scene), method)
    stable, unstable = measured_dt(scene, method, bound)
    assert bound <= stable * (1 + 1e-9)
    assert unstable <= 1.01 * bound


@pytest.mark.slow
@pytest.mark.parametrize("name", ["shooter_medium", "helicopter_mass", "helicopter_parachute"])
@pytest.mark.parametrize("method", ["symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4"])
def test_predicted_bound_is_safe_on_every_scene(name, method):
    """Everywhere the bound is below the measured blow-up. On the shooter it is 12-30 % conservative: the
    contact springs and the thrower's explicit damping are charged to every node, not only those inside."""
    scene = ropesim.load_scene(SCENARIOS / f"{name}.toml")
    bound = predicted_dt(build(scene), method)
    stable, unstable = measured_dt(scene, method, bound)
    assert bound <= stable * (1 + 1e-9)
    assert unstable <= 1.5 * bound


def test_sweep_maps_stable_and_unstable_steps():
    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml")
    result = stability_sweep(scene, ["verlet", "sdirk2"], [0.5, 0.9, 1.1, 3.0], [5000.0, 5e5], steps=1000)
    table = {(r["method"], r["stiffness"], r["dt_over_ref"]): r["stable"] for r in result.rows}
    for k in (5000.0, 5e5):
        assert [table[("verlet", k, f)] for f in (0.5, 0.9, 1.1, 3.0)] == [True, True, False, False]
        assert all(table[("sdirk2", k, f)] for f in (0.5, 0.9, 1.1, 3.0))


# ------------------------------------------------------------------------------------- command line


def test_check_prints_both_bounds_for_every_method():
    result = runner.invoke(app, ["check", str(SCENARIOS / "shooter_medium.toml")], env=ENV)
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "Gershgorin bound 160 rad/s" in out and "omega_max <= 153.6 rad/s" in out
    for name in METHODS:
        assert f"  {name}" in out
    assert "stable at any dt" in out and "velocity damping" in out


def test_run_warns_above_80_percent_and_refuses_above_the_bound(tmp_path):
    scene = SCENARIOS / "helicopter_uniform.toml"
    bound = predicted_dt(build(ropesim.load_scene(scene)), "symplectic_euler")
    def common(dt):  # ten whole steps, so dt is not shortened to fit t_end
        return ["--set", f"integrator.dt={dt}", "--set", f"integrator.t_end={10 * dt}", "--set",
                f"output.interval={dt}"]

    warn = runner.invoke(app, ["run", str(scene), "-o", str(tmp_path / "a"), *common(0.9 * bound)], env=ENV)
    assert warn.exit_code == 0 and "warning" in warn.stderr and "is 90% of symplectic_euler's" in warn.stderr
    refused = runner.invoke(app, ["run", str(scene), "-o", str(tmp_path / "b"), *common(1.1 * bound)], env=ENV)
    assert refused.exit_code == 2 and "--force" in refused.stderr and len(refused.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "b").exists()
    calm = runner.invoke(app, ["run", str(scene), "-o", str(tmp_path / "c"), *common(0.5 * bound)], env=ENV)
    assert calm.exit_code == 0 and calm.stderr == ""


def test_stability_command_writes_table_and_plot(tmp_path):
    result = runner.invoke(app, ["stability", str(SCENARIOS / "helicopter_uniform.toml"), "--methods",
                                 "verlet,rk4", "--fractions", "0.5,1.5", "--steps", "500", "-o", str(tmp_path)],
                           env=ENV)
    assert result.exit_code == 0, result.output
    bounds = list(csv.DictReader((tmp_path / "bounds.csv").open()))
    assert [b["method"] for b in bounds] == ["verlet", "rk4"]
    for b in bounds:
        assert float(b["predicted_dt_spectral"]) <= float(b["measured_stable_dt"]) * 1.0001
    assert (tmp_path / "stability.png").stat().st_size > 5000
    assert "measured blow-up" in result.stdout
