"""Generalized-alpha under waves: the water's kinematics held through one step's Newton solve
(ropesim/model/forces/sea.py ``hold_waves``).

Within a step, galpha's Newton iterates evaluate the waves once, at the first iterate (the predictor), instead of
at every iterate. References: the sea's own state kernel evaluated fresh (what is held, what is recomputed, and
that letting go leaves nothing held behind), and galpha evaluating the waves at every iterate, against rk4 at a
small step: the predictor is within O(h^3) of the solution, so holding moves the answer far less than the
scheme's own error.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build
from ropesim.model.forces import sea as S
from ropesim.scene.loader import scene_from_toml

# a 60 m line of 12 segments hanging between two points 10 m under the surface, 50 m apart, in 30 m of water,
# under a 20-component sea (Hs 3 m, Tp 6 s): drag and the water's inertia force drive it, nothing touches a seabed
LINE = """
name = "line_in_waves"
dimension = 2
[rope]
length = 60.0
segments = 12
mass_per_length = 60.0
diameter = 0.2
EA = 2.0e6
[initial]
shape = "equilibrium"
start = [0.0, -10.0]
end = [50.0, -10.0]
[pinned]
nodes = [0, -1]
[gravity]
g = 9.80665
[fluid]
density = 1025.0
[buoyancy]
[fluid_drag]
cd_normal = 1.2
cd_tangential = 0.2
[added_mass]
ca_normal = 1.0
[sea]
level = 0.0
depth = 30.0
[waves]
kind = "jonswap"
significant_height = 3.0
peak_period = 6.0
components = 20
ramp_time = 2.0
[integrator]
method = "galpha"
dt = 0.01
t_end = 6.0
[output]
interval = 0.2
"""


def run(method: str, dt: float, rho_inf: float | None = None, hold: bool = True):
    scene = scene_from_toml(LINE)
    scene = replace(scene, integrator=replace(scene.integrator, method=method, dt=dt, rho_inf=rho_inf))
    model, grid = build(scene), TimeGrid.of(scene)
    model.params.sea.scalars[S.HOLD_WAVES] = 1.0 if hold else 0.0
    it = make_integrator(model, grid)
    assert it.advance(grid.steps).status == 0
    return it, model


def test_held_kinematics_are_the_first_iterates_and_let_go_after_the_step():
    """Held: an evaluation at the same time and other positions keeps the waves' rows (eta, u, a) of the first,
    and recomputes the submerged fractions; at another time it evaluates afresh. Let go: the state is invalid,
    and the next evaluation is exactly a fresh one."""
    _, model = run("galpha", 0.2)
    water_state, hold = model.kernel(S.water_state), model.kernel(S.hold_waves)
    p = model.params
    nodes = p.sea.nodes
    x0 = model.x0.copy()
    x1 = x0 + np.array([[3.0], [9.9]])   # 3 m along and 9.9 m up: the middle nodes reach the surface
    rows = slice(S.ETA, S.AZ + 1)

    def fresh(x, t):
        hold(p, False)
        water_state(x, p, t)
        return nodes[rows].copy(), nodes[S.F_LINE].copy()

    at_x0, fraction_x0 = fresh(x0, 4.0)
    assert np.all(fraction_x0 == 1.0)   # 10 m down, under the 3 m sea
    at_x1, fraction_x1 = fresh(x1, 4.0)
    assert not np.allclose(at_x0, at_x1)
    hold(p, True)                                             # the cache holds x1 at 4 s: not what is held
    water_state(x0, p, 4.0)
    water_state(x1, p, 4.0)
    assert np.array_equal(nodes[rows], at_x0)                 # the waves held at the first iterate's positions
    assert np.min(nodes[S.F_LINE]) < 0.9 and np.min(fraction_x1) < 0.9   # the fractions at x1, recomputed
    later, _ = fresh(x1, 4.5)
    hold(p, True)
    water_state(x1, p, 4.5)
    assert np.array_equal(nodes[rows], later)                 # another time: evaluated afresh
    hold(p, True)
    water_state(x0, p, 4.0)
    hold(p, False)
    assert p.sea.scalars[S.STATE_VALID] == 0.0
    water_state(x1, p, 4.0)
    assert np.array_equal(nodes[rows], at_x1)                 # nothing held behind after the solve
    assert np.array_equal(nodes[S.F_LINE], fraction_x1)


@pytest.mark.parametrize("rho", [0.0, 0.9])
def test_holding_the_waves_moves_the_answer_far_less_than_the_scheme_errs(rho):
    """galpha at 0.1 s with the waves held through each Newton solve, and evaluated at every iterate (the sea's
    HOLD_WAVES off): the positions at t = 6 s differ by less than 1e-3 of either's error against rk4 at 1 ms (its
    own error 1e-10 m). The predictor is within O(h^3) of the solution, so holding moves a step by O(h^5)."""
    reference, _ = run("rk4", 0.001)
    held, _ = run("galpha", 0.1, rho)
    fresh, _ = run("galpha", 0.1, rho, hold=False)
    error = np.max(np.abs(fresh.x - reference.x))
    assert error > 1e-4
    assert np.max(np.abs(held.x - fresh.x)) < 1e-3 * error
    assert held.force_evaluations <= fresh.force_evaluations + 5


def test_the_sea_benchmarks_measure_is_the_rms_error_over_the_tensions_range():
    """scripts/bench_waves.py --chain's error measures on a made-up record: a 1000 kN pull swinging by 10 kN
    (range 20 kN, deviation 10 / sqrt 2), and a candidate 200 N off throughout: 1 % of the range (RMS), 0.02 %
    of the peak, 2.8 % of the deviation. The first tenth (the waves' ramp) is left out of the RMS and the range,
    not of the largest error."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scripts"))
    from bench_waves import errors

    t = np.linspace(0.0, 300.0, 15001)
    reference = 1.0e6 + 1.0e4 * np.sin(2 * np.pi * t / 10.0)
    reference[:100] = 0.0   # within the first tenth: not the waves' swing
    of_range, of_peak, of_std = errors(reference + 200.0, reference)
    assert of_range == pytest.approx(0.01, rel=1e-3)
    assert of_peak == pytest.approx(200.0 / 1.01e6, rel=1e-3)
    assert of_std == pytest.approx(200.0 / (1.0e4 / np.sqrt(2.0)), rel=1e-3)


@pytest.mark.slow
def test_the_sea_benchmark_runs():
    """scripts/bench_waves.py --chain over a 6 s window, galpha at rho_inf 0.9 alone: its ladder, the measure's
    three columns and the fastest candidate within 1 % of the range."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parent.parent / "scripts" / "bench_waves.py"
    result = subprocess.run([sys.executable, str(script), "--chain", "--window", "6", "--methods", "galpha",
                             "--galpha-rho", "0.9", "--no-sweep"], capture_output=True, text=True, timeout=1800,
                            env={**os.environ, "COLUMNS": "200"})
    assert result.returncode == 0, result.stderr[-2000:]
    out = result.stdout
    assert "RMS error / range" in out and "largest error / peak" in out and "RMS error / std" in out
    assert out.count("galpha rho 0.9") >= 4
    assert "fastest within 1 % of the tension's range (RMS): galpha rho 0.9" in out
