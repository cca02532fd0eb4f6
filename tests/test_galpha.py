"""Generalized-alpha (ropesim/integrate/galpha.py): its linear stability, its order on ropes and on systems of
lines meeting at free points, its energy at rho_inf = 1, and its Newton solve at a mooring's large steps.

References: the closed-form spectral radius of the scheme (Chung & Hulbert 1993: rho_inf as h omega -> infinity,
at most 1 everywhere); rk4 at steps 20-100 times smaller (its own error far below the errors fitted); the energy
of a rope pendulum in a vacuum (nothing flows in or out).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.integrate.galpha import GALPHA, NEWTON_SHARE, coefficients
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.build import build
from ropesim.scene.loader import load_scene, scene_from_toml

from conftest import SCENARIOS
from test_accuracy import VACUUM

DATA = Path(__file__).parent / "data" / "systems"


def advance(scene, method: str, dt: float, t_end: float, rho_inf: float | None = None):
    """Run ``scene`` with ``method`` at ``dt`` to ``t_end`` (galpha with ``rho_inf``); returns the integrator."""
    integrator = replace(scene.integrator, method=method, dt=dt, t_end=t_end, rho_inf=rho_inf)
    scene = replace(scene, integrator=integrator)
    model, grid = build(scene), TimeGrid.of(scene)
    it = make_integrator(model, grid)
    result = it.advance(grid.steps)
    assert result.status == 0, result
    return it


@pytest.mark.parametrize("rho", [0.0, 0.5, 0.9, 1.0])
def test_spectral_radius_is_rho_inf_at_infinite_steps_and_never_above_one(rho):
    """The undamped oscillator's one-step map (x, v, a): spectral radius <= 1 at every h omega (unconditional
    stability), rho_inf as h omega -> infinity, and 1 - O((h omega)^4) dissipation at small h omega (a second-
    order scheme damps the resolved modes only at third order in h omega or beyond)."""
    radius = [max(abs(np.linalg.eigvals(GALPHA.amplification(h, 1.0, rho_inf=rho)))) for h in np.logspace(-3, 4, 60)]
    assert max(radius) <= 1.0 + 1e-8   # eigenvalues of a (nearly) repeated root: accurate to ~sqrt(eps)
    far = max(abs(np.linalg.eigvals(GALPHA.amplification(1e7, 1.0, rho_inf=rho))))
    assert far == pytest.approx(rho, abs=1e-3)
    assert 1.0 - radius[0] < 1e-9   # h omega = 1e-3


def test_coefficients_are_chung_and_hulberts():
    """gamma = 1/2 - am + af (second order), beta = (1 - am + af)^2 / 4; rho_inf = 1 is the trapezoidal rule."""
    assert coefficients(1.0) == pytest.approx((0.5, 0.5, 0.5, 0.25))
    assert coefficients(0.0) == pytest.approx((-1.0, 0.0, 1.5, 1.0))


def test_without_numerical_dissipation_an_undamped_chain_keeps_its_energy_at_second_order():
    """rho_inf = 1, the rope pendulum released in a vacuum (test_accuracy's VACUUM): its largest energy error over
    1 s shrinks 4 times per halving of dt (log2 of the ratio within 0.1 of 2; measured 2.00, 2.00), and it does
    not drift: the largest error in the second half of the run is within 3 times that of the first."""
    from ropesim.model.energy import energy_terms

    peaks = []
    for dt in (0.002, 0.001, 0.0005):
        scene = scene_from_toml(VACUUM, overrides=["integrator.method=galpha", f"integrator.dt={dt}",
                                                    "integrator.rho_inf=1"])
        traj = ropesim.simulate(scene)
        total = energy_terms(build(scene), traj.x, traj.v)["total"]
        error = np.abs(total - total[0])
        peaks.append(error.max())
        half = len(error) // 2
        assert error[half:].max() < 3 * error[:half].max()
    slopes = np.log2(np.array(peaks[:-1]) / np.array(peaks[1:]))
    assert np.all(np.abs(slopes - 2.0) < 0.1), (peaks, slopes)


# slow: galpha's loop of a free point between two lines is compiled for this test alone (10 s of a cold quick run);
# galpha on a system stays quick in tests/test_galpha_bodies.py (the tripod's body on three lines)
@pytest.mark.slow
def test_on_a_system_the_free_point_moves_as_one_and_the_order_is_two():
    """The clump weight on two wires (a free point joining two lines, solved by the Schur complement), the wires
    taking compression (a smooth problem): galpha at dt = 1, 0.5, 0.25 ms against rk4 at 10 us converges at
    second order (fitted slope within 0.05 of 2), with rho_inf 0.9 (the default) and 0.5."""
    base = load_scene(DATA / "clump_weight.toml")
    scene = replace(base, lines=tuple(replace(line, compression=True) for line in base.lines))
    reference = advance(scene, "rk4", 1e-5, 0.5).x
    steps = (1e-3, 5e-4, 2.5e-4)
    for rho in (None, 0.5):
        errors = [np.abs(advance(scene, "galpha", dt, 0.5, rho).x - reference).max() for dt in steps]
        order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
        assert order == pytest.approx(2.0, abs=0.05), (rho, errors)


@pytest.mark.parametrize("name", ["helicopter_uniform", "helicopter_mass", "helicopter_parachute"])
def test_the_fitted_order_on_the_seeds_scenes_is_two_within_five_hundredths(name):
    """The seed's towed ropes (drag, a driven node; the accuracy page's scenes) to 0.5 s against PEFRL at 1/16 of
    the smallest step: the fitted order within 0.05 of 2 at the default rho_inf (0.9) on steps of 8 to 1 ms
    (measured 1.984, 1.985, 1.998; at rho_inf = 1 the same), and at rho_inf = 0 on 4 to 0.5 ms (its larger error
    constant puts 8 ms outside the asymptotic range: 1.948, 1.978, 1.925 from 8 ms; error ratios 3.40, 3.95,
    4.02 on helicopter_parachute)."""
    from ropesim.analysis.accuracy import observed_order, run_once

    scene = ropesim.load_scene(SCENARIOS / f"{name}.toml", ["integrator.t_end=0.5"])
    reference = run_once(scene, "pefrl", 0.0005 / 16).x
    for rho, steps in ((None, [0.008, 0.004, 0.002, 0.001]), (0.0, [0.004, 0.002, 0.001, 0.0005])):
        s = replace(scene, integrator=replace(scene.integrator, rho_inf=rho))
        errors = [float(np.max(np.linalg.norm(run_once(s, "galpha", dt).x - reference, axis=0))) for dt in steps]
        order, used = observed_order(steps, errors, [True] * len(steps))
        assert used == len(steps)
        assert order == pytest.approx(2.0, abs=0.05), (rho, errors)


# slow: galpha's loop of mooring_chain is compiled for this test alone (8 s of a cold quick run)
@pytest.mark.slow
def test_mooring_chain_at_a_tenth_of_a_second():
    """mooring_chain (seabed contact and friction, fluid drag, added mass, a surging fairlead) at dt = 0.1 s, 40
    times rk4's stable step: Newton converges at every step, to 30 s (about 10 iterations and 2.5
    factorisations a step, measured: the sliding seabed nodes make the matrix go stale within a step; asserted
    below 4), and the chain stays within 0.1 m of rk4 at 2 ms. Without the friction's exact slope
    (galpha.friction_slope) Newton stalled at t = 20 s."""
    scene = ropesim.load_scene(SCENARIOS / "mooring_chain.toml")
    it = advance(scene, "galpha", 0.1, 30.0)
    assert it.factorisations < 4 * 300
    reference = advance(scene, "rk4", 0.002, 30.0).x
    assert np.abs(it.x - reference).max() < 0.1


def test_modified_newton_reuses_the_matrix_on_a_smooth_scene():
    """The helicopter (drag, a driven node) at dt = 4 ms: the matrix is factored on fewer than one step in
    four, about two Newton iterations a step."""
    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml")
    it = advance(scene, "galpha", 0.004, 0.5)
    steps = math.ceil(0.5 / 0.004)
    assert it.factorisations < steps / 4
    assert it.force_evaluations < 4 * steps


@pytest.mark.parametrize("rho", [0.0, 0.9])
def test_newtons_stopping_test_keeps_to_its_share_of_the_steps_error(rho):
    """With fixed steps Newton stops once its remaining error is below NEWTON_SHARE (a tenth) of the step's own
    truncation estimate. On the helicopter at 8 ms (1 s, drag and a driven node), that solve's answer differs from
    a solve to NEWTON_TOL (the strain of 1e-9 it used before; ``loosest`` 0 turns the share off) by at most that
    share of the scheme's own error against PEFRL at 1/16 of the step (measured: 0.7 % of it at rho_inf = 0, 0.3 %
    at 0.9), with fewer Newton iterations (measured: 251 force evaluations instead of 450 and 334)."""
    from ropesim.analysis.accuracy import run_once

    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml", ["integrator.t_end=1.0"])
    reference = run_once(scene, "pefrl", 0.008 / 16).x

    def solve(share: bool):
        integrator = replace(scene.integrator, method="galpha", dt=0.008, rho_inf=rho)
        s = replace(scene, integrator=integrator)
        model, grid = build(s), TimeGrid.of(s)
        it = make_integrator(model, grid)
        if not share:
            it.newton = it.newton._replace(loosest=0.0)
        assert it.advance(grid.steps).status == 0
        return it

    loose, tight = solve(True), solve(False)
    scheme = np.abs(tight.x - reference).max()
    assert np.abs(loose.x - tight.x).max() <= NEWTON_SHARE * scheme
    assert loose.force_evaluations < tight.force_evaluations


# ------------------------------------------------------------------------------------------ adaptive steps


def adaptive(scene, tol: float, dt: float, t_end: float, rho_inf: float | None = None):
    integrator = replace(scene.integrator, method="galpha", dt=dt, t_end=t_end, tolerance=tol, rho_inf=rho_inf)
    scene = replace(scene, integrator=integrator)
    model, grid = build(scene), TimeGrid.of(scene)
    it = make_integrator(model, grid)
    assert it.advance(grid.steps).status == 0
    return it


def shooter():
    width = ["thrower.edge_width=0.2", "guides.0.edge_width=0.2", "guides.1.edge_width=0.2"]
    return ropesim.load_scene(SCENARIOS / "shooter_medium.toml", width)


@pytest.mark.parametrize("case", ["helicopter", "shooter"])
def test_the_tolerance_means_what_it_says(case):
    """The true error at t_end, against a converged reference, is at most 3 times the tolerance and not
    wastefully far below it (above a tenth). Measured (true / tolerance at 1e-2, 1e-3, 1e-4 m): the helicopter
    over 2 s 0.16, 0.38, 0.37 (pefrl at 0.2 ms, its own error below 1e-9 m); the smoothed shooter over 1 s
    0.62, 0.64, 0.64 (rk4 at 62.5 us: 5e-11 m); mooring_chain in the slow test below."""
    from ropesim.analysis.accuracy import run_once

    if case == "helicopter":
        scene, t_end, reference = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml"), 2.0, ("pefrl", 2e-4)
    else:
        scene, t_end, reference = shooter(), 1.0, ("rk4", 0.001 / 16)
    ref = run_once(replace(scene, integrator=replace(scene.integrator, t_end=t_end)), *reference).x
    for tol in (1e-2, 1e-4):
        it = adaptive(scene, tol, 0.01, t_end)
        ratio = np.max(np.linalg.norm(it.x - ref, axis=0)) / tol
        assert 0.1 < ratio < 3.0, (case, tol, ratio)
        report = it.step_report()
        assert report["estimated_error_m"] <= tol * 1.0001   # the steps' allowances add up to the tolerance


@pytest.mark.slow
def test_the_tolerance_means_what_it_says_on_the_mooring_chain():
    """mooring_chain over 30 s (seabed contact and friction, drag, added mass, a surging fairlead), tolerance
    1e-1 and 1e-2 m: the true error against rk4 at 1 ms (its own, by 0.5 ms: 1.5e-7 m) lands at 0.14 and 0.18 of
    the tolerance (measured), asserted within 3 times it."""
    from ropesim.analysis.accuracy import run_once

    scene = ropesim.load_scene(SCENARIOS / "mooring_chain.toml", ["integrator.t_end=30"])
    ref = run_once(scene, "rk4", 0.001).x
    for tol in (1e-1, 1e-2):
        it = adaptive(scene, tol, 0.1, 30.0)
        assert np.max(np.linalg.norm(it.x - ref, axis=0)) < 3 * tol


def test_frames_on_the_grid_by_dense_output_and_the_summary_reports_the_steps(tmp_path):
    """The helicopter at tolerance 1e-4 m with a 1 ms grid: the frames sit on the output grid, every frame (not
    only the last) within 3 times the tolerance of pefrl's, with several grid points per step (the steps are the
    scheme's); summary.json reports the steps taken and rejected and the estimated error."""
    import json

    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml",
                               ["integrator.method=galpha", "integrator.tolerance=1e-4", "integrator.t_end=1",
                                "output.interval=0.01"])
    traj = ropesim.simulate(scene, tmp_path / "run")
    np.testing.assert_allclose(traj.t, np.arange(101) * 0.01, atol=1e-12)
    ref = ropesim.simulate(replace(scene, integrator=replace(scene.integrator, method="pefrl", dt=2e-4,
                                                             tolerance=None)))
    assert np.max(np.linalg.norm(traj.x - ref.x, axis=-1)) < 3e-4
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    steps = summary["adaptive_steps"]
    assert steps["tolerance_m"] == 1e-4 and 0 < steps["estimated_error_m"] <= 1e-4 * 1.0001
    assert 0 < steps["steps_taken"] < summary["steps"] / 2 and steps["steps_rejected"] >= 0
    assert steps["smallest_step_s"] <= steps["largest_step_s"]


def test_an_adaptive_run_gives_the_same_numbers_however_it_is_cut():
    """Cut into calls of 7 grid steps, or stopped and restored from its state halfway, the adaptive run retraces
    the uninterrupted one bit for bit (the steps' ends, the next step and the factored matrix are state)."""
    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml",
                               ["integrator.method=galpha", "integrator.tolerance=1e-4", "integrator.t_end=0.5",
                                "integrator.dt=0.01"])
    model, grid = build(scene), TimeGrid.of(scene)
    whole = make_integrator(model, grid)
    whole.advance(grid.steps)
    cut = make_integrator(model, grid)
    while cut.step < grid.steps:
        cut.advance(min(7, grid.steps - cut.step))
    np.testing.assert_array_equal(cut.x, whole.x)
    first = make_integrator(model, grid)
    first.advance(grid.steps // 2)
    second = make_integrator(model, grid)
    second.restore(first.state())
    second.advance(grid.steps - second.step)
    np.testing.assert_array_equal(second.x, whole.x)
    np.testing.assert_array_equal(second.v, whole.v)


@pytest.mark.parametrize("sets, message", [
    (["integrator.tolerance=1e-3"], "integrator.tolerance: is generalized-alpha's"),
    (["integrator.method=galpha", "integrator.relative_tolerance=1e-3"],
     "integrator.relative_tolerance: needs integrator.tolerance"),
    (["integrator.method=galpha", "integrator.tolerance=0"], "integrator.tolerance: must be a number > 0"),
    (["integrator.method=galpha", "integrator.rho_inf=1.5"], "integrator.rho_inf: must be a number >= 0 and <= 1"),
])
def test_bad_integrator_keys_are_refused_in_one_line(sets, message):
    import subprocess
    import sys

    args = [sys.executable, "-m", "ropesim", "check", str(SCENARIOS / "helicopter_uniform.toml")]
    for item in sets:
        args += ["--set", item]
    done = subprocess.run(args, capture_output=True, text=True)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr
