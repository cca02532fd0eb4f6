"""Orders of convergence of every integrator, energy conservation in a vacuum, the reference solution, the
work-precision report (`ropesim accuracy`), and the stiff integrator against explicit ones.

Order tests fit the slope of log(error) against log(dt) on a smooth scene with drag on and a driven node (the
helicopter, short t_end), against PEFRL at dt / 16. Tolerance 0.15 on the slope: over a factor-8 ladder in the
asymptotic range the next term of the error expansion shifts a fitted slope by a few hundredths (measured:
1.000, 2.000, 4.01, 4.005, 3.96, 1.999), while the nearest wrong answer is a whole order away.
"""

from __future__ import annotations

import csv
import math
import textwrap

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import ropesim
from ropesim.analysis.accuracy import accuracy_report, observed_order, run_once
from ropesim.model.build import build
from ropesim.cli.app import app
from ropesim.integrate.methods import METHODS
from ropesim.scene.loader import scene_from_toml
from ropesim.scene.schema import Integrator

from conftest import SCENARIOS

ORDER_TOLERANCE = 0.15
# Ladders in each method's asymptotic range, above the reference floor (about 1e-10 m here).
LADDERS = {
    "symplectic_euler": [0.008, 0.004, 0.002, 0.001],
    "verlet": [0.008, 0.004, 0.002, 0.001],
    "yoshida4": [0.008, 0.004, 0.002, 0.001],
    "pefrl": [0.016, 0.008, 0.004],
    "rk4": [0.016, 0.008, 0.004, 0.002],
    "sdirk2": [0.008, 0.004, 0.002, 0.001],
    "galpha": [0.008, 0.004, 0.002, 0.001],
}


def helicopter(t_end: float = 0.5):
    return ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml", [f"integrator.t_end={t_end}"])


@pytest.fixture(scope="module")
def reference():
    """PEFRL at dt = 1/16 of the smallest step of every ladder."""
    return run_once(helicopter(), "pefrl", 0.001 / 16).x


def test_one_name_per_integrator_everywhere():
    """The scene schema's choices, the code's METHODS and the CLI's --methods all list the same names."""
    choices = Integrator.__dataclass_fields__["method"].metadata["spec"].choices
    assert tuple(choices) == tuple(METHODS)
    assert {m.name for m in METHODS.values()} == set(METHODS)


@pytest.mark.parametrize("method", list(METHODS))
def test_order_of_convergence_with_drag_and_a_driven_node(method, reference):
    scene = helicopter()
    errors = []
    for dt in LADDERS[method]:
        r = run_once(scene, method, dt)
        assert r.status == "completed"
        errors.append(float(np.max(np.linalg.norm(r.x - reference, axis=0))))
    order, used = observed_order(LADDERS[method], errors, [True] * len(errors))
    assert used == len(errors)
    assert abs(order - METHODS[method].order) < ORDER_TOLERANCE, (method, order, errors)


def test_reference_has_converged(reference):
    """Two refinements of the reference agree to round-off level, far below every error measured above."""
    finer = run_once(helicopter(), "pefrl", 0.001 / 32).x
    assert np.max(np.abs(finer - reference)) < 1e-9


VACUUM = textwrap.dedent("""
    name = "pendulum_rope"
    dimension = 2
    [rope]
    nodes = 10
    segment_length = 0.1
    stiffness = 2000.0
    mass = 0.1
    [initial]
    shape = "line"
    start = [0.0, 0.0]
    end = [0.9, 0.0]
    [pinned]
    nodes = [0]
    [gravity]
    g = 9.81
    [integrator]
    dt = 0.002
    t_end = 1.0
    [output]
    interval = 0.01
""")


def energy_error(method: str, dt: float) -> np.ndarray:
    """|E(t) - E(0)| per saved frame of a rope pendulum released horizontally in a vacuum (nothing flows)."""
    from ropesim.model.energy import energy_terms

    scene = scene_from_toml(VACUUM, overrides=[f"integrator.method={method}", f"integrator.dt={dt}"])
    traj = ropesim.simulate(scene)
    assert traj.summary["status"] == "completed"
    total = energy_terms(build(scene), traj.x, traj.v)["total"]
    return np.abs(total - total[0])


@pytest.mark.parametrize("method", list(METHODS))
def test_energy_error_in_a_vacuum_shrinks_at_the_methods_order(method):
    """No drag, a pinned (not moving) node: energy is conserved, and its error shrinks as dt^order.

    Halving dt twice must divide the largest energy error over the run by about 2^order each time (log2 of
    the ratio within 0.35 of the order: the swinging rope's error is not yet in its asymptotic regime at
    the largest step). The symplectic schemes' error also stays bounded: its largest value in the second
    half of the run is no more than 3 times that in the first half (no drift). RK4 and SDIRK2 are probed at
    smaller steps: at larger ones their damping of the stiff spring modes dominates the energy error (RK4
    loses (h omega)^6 / 72 of a mode's energy per step, a fifth-order term that hides the fourth-order one
    until h omega is small).
    """
    dts = {"pefrl": [0.004, 0.002, 0.001], "rk4": [5e-4, 2.5e-4, 1.25e-4], "sdirk2": [5e-4, 2.5e-4, 1.25e-4],
            "galpha": [5e-4, 2.5e-4, 1.25e-4]}.get(
        method, [0.002, 0.001, 0.0005])
    errs = [energy_error(method, dt) for dt in dts]
    peaks = [e.max() for e in errs]
    slopes = np.log2(np.array(peaks[:-1]) / np.array(peaks[1:]))
    assert np.all(np.abs(slopes - METHODS[method].order) < 0.35), (method, peaks, slopes)
    if METHODS[method].kind == "splitting":
        half = len(errs[-1]) // 2
        assert errs[-1][half:].max() < 3 * errs[-1][:half].max()


def test_observed_order_fit():
    dts = np.array([0.1, 0.05, 0.025, 0.0125])
    assert observed_order(dts, 3 * dts ** 2, [True] * 4) == pytest.approx((2.0, 4))
    assert math.isnan(observed_order(dts, 3 * dts, [True, False, False, False])[0])


def test_accuracy_report_and_command(tmp_path):
    """The CLI writes the table and the work-precision plot and prints each method's observed order."""
    out = tmp_path / "acc"
    result = CliRunner().invoke(app, ["accuracy", str(SCENARIOS / "helicopter_uniform.toml"), "--methods",
                                      "verlet,rk4", "--dts", "0.004,0.002,0.001", "--repeats", "1", "--set",
                                      "integrator.t_end=0.3", "--out", str(out)], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader((out / "accuracy.csv").open()))
    assert [r["method"] for r in rows] == ["verlet"] * 3 + ["rk4"] * 3
    assert {"error_max_m", "error_rms_m", "energy_error_J", "wall_time_s", "force_evaluations"} <= set(rows[0])
    evals = {r["dt"]: int(r["force_evaluations"]) for r in rows if r["method"] == "rk4"}
    assert evals["0.001"] == 4 * 300  # four evaluations per step
    assert (out / "accuracy.png").stat().st_size > 10_000
    assert "observed order of verlet: 2.0" in result.stdout
    assert "observed order of rk4: 4.0" in result.stdout or "observed order of rk4: 3.9" in result.stdout


def test_accuracy_command_refuses_unknown_methods(tmp_path):
    result = CliRunner().invoke(app, ["accuracy", str(SCENARIOS / "helicopter_uniform.toml"), "--methods",
                                      "verlet,leapfrog"])
    assert result.exit_code == 2 and "unknown integrator leapfrog" in result.output


# ------------------------------------------------------------------------------- the stiff integrator


def test_stiff_integrator_is_accurate_far_beyond_the_explicit_bound():
    """k = 1e8 N/m: explicit methods need dt < 2e-4 s; sdirk2 at dt = 0.01 s (45x the bound) follows the
    PEFRL solution at 5e-5 s to within a millimetre after 1 s of towing."""
    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml", ["rope.stiffness=1e8", "integrator.t_end=1"])
    model = build(scene)
    from ropesim.analysis.stability import predicted_dt

    assert predicted_dt(model, "verlet") < 2.3e-4
    stiff = run_once(scene, "sdirk2", 0.01)
    ref = run_once(scene, "pefrl", 5e-5)
    assert stiff.status == ref.status == "completed"
    assert np.max(np.linalg.norm(stiff.x - ref.x, axis=0)) < 1e-3
    assert stiff.force_evaluations < 100 * 10  # a handful of Newton iterations per step


@pytest.mark.slow
def test_stiff_integrator_order_on_a_closed_loop_with_bending():
    """The wrap-around (Woodbury) correction: sdirk2 is second order on a pinned loop with bending springs."""
    text = textwrap.dedent("""
        name = "loop"
        dimension = 2
        [rope]
        nodes = 16
        segment_length = 0.25
        stiffness = 2000.0
        mass = 0.1
        closed = true
        [bending]
        stiffness = 100.0
        [initial]
        shape = "square_loop"
        top_center = [0.0, 0.0]
        velocity = [0.5, 0.0]
        [gravity]
        [drag]
        b = 0.05
        [pinned]
        nodes = [0]
        [integrator]
        dt = 0.001
        t_end = 0.5
    """)
    scene = scene_from_toml(text)
    ref = run_once(scene, "pefrl", 2.5e-5).x
    dts = [0.002, 0.001, 0.0005]
    errs = [np.max(np.linalg.norm(run_once(scene, "sdirk2", dt).x - ref, axis=0)) for dt in dts]
    order, _ = observed_order(dts, errs, [True] * 3)
    assert abs(order - 2.0) < ORDER_TOLERANCE, errs


def test_stiff_integrator_report_shows_where_it_wins():
    """At k = 1e7 and a 2 cm error budget sdirk2 needs fewer force evaluations than any explicit method."""
    scene = ropesim.load_scene(SCENARIOS / "helicopter_uniform.toml", ["rope.stiffness=1e7", "integrator.t_end=1"])
    report = accuracy_report(scene, ["verlet", "sdirk2"], [0.02, 0.01, 6e-4, 3e-4], repeats=1)
    best = {}
    for r in report.rows:
        if r.status == "completed" and r.error_max < 0.02:
            best[r.method] = min(best.get(r.method, math.inf), r.force_evaluations)
    assert best["sdirk2"] < best["verlet"]


# ------------------------------------------------------------------ the shooter: what limits the order


def shooter(*sets: str):
    width = ["thrower.edge_width=0.2", "guides.0.edge_width=0.2", "guides.1.edge_width=0.2"]
    return ropesim.load_scene(SCENARIOS / "shooter_medium.toml", ["integrator.t_end=0.3", *width, *sets])


@pytest.mark.slow
def test_smoothed_edges_restore_the_order_of_rk4_and_sdirk2_on_the_shooter():
    """With the box's and guides' edges smoothed (edge_width = 0.2 m) the forces are smooth in x and RK4 is
    fourth order again, SDIRK2 second order (its Newton solve converges); with sharp edges neither converges
    (scripts/shooter_order.py: errors of metres at every dt)."""
    scene = shooter()
    ref = run_once(scene, "rk4", 0.001 / 16).x
    dts = [0.004, 0.002, 0.001]
    for method, expected in (("rk4", 4.0), ("sdirk2", 2.0)):
        errs = [np.max(np.linalg.norm(run_once(scene, method, dt).x - ref, axis=0)) for dt in dts]
        order, _ = observed_order(dts, errs, [True] * 3)
        assert abs(order - expected) < 0.25, (method, errs)


@pytest.mark.slow
def test_exact_contact_kicks_restore_the_splitting_schemes_orders_on_the_smoothed_shooter():
    """The drive b_thrower (v_max - v_x) and the contact damping depend on v. A plain kick evaluates them at the
    velocity it starts from (an explicit Euler step of v' = a(x, v)): Verlet and PEFRL fall to first order.
    Kicking the touching nodes exactly (ropesim.contact, on by default with smoothed edges) gives 2 and 4 back,
    with PEFRL far the most accurate."""
    dts = [0.002, 0.001, 0.0005]
    scene = shooter()
    ref = run_once(scene, "rk4", 0.0005 / 16).x
    for exact, expected in ((False, {"verlet": 1.0, "pefrl": 1.0}), (True, {"verlet": 2.0, "pefrl": 4.0})):
        for method, order_expected in expected.items():
            errs = [np.max(np.linalg.norm(run_once(scene, method, dt, exact_contacts=exact).x - ref, axis=0))
                    for dt in dts]
            order, _ = observed_order(dts, errs, [True] * 3)
            assert abs(order - order_expected) < 0.25, (method, exact, errs)


def test_exact_contact_kick_solves_the_linear_kick_equation():
    """One node in the box and a circle's overlap, frozen x: the exact kick equals a fine RK4 integration of
    v' = a(x, v) - gamma v (a linear in v) over the kick, also for a negative (backward) kick."""
    from ropesim.integrate.contact import exact_contact_kicks
    from ropesim.model.terms import accelerations

    model = build(shooter())
    x = model.x0.copy()
    x[:, 10] = [3.9, 0.3]  # near the box's right edge, inside the right circle: both weights between 0 and 1
    v = np.zeros_like(x)
    v[:, 10] = [2.0, -1.5]
    gamma = np.full(model.nodes, 0.7)
    free = np.ones(model.nodes, dtype=np.bool_)

    def rhs(vel):
        acc = np.zeros_like(x)
        model.kernel(accelerations)(x, vel, acc, model.params, 0.0)
        return acc - gamma * vel

    for tau in (0.01, -0.004):
        out, nodes = np.zeros_like(x), np.zeros(model.nodes, dtype=np.int64)
        acc = np.zeros_like(x)
        model.kernel(accelerations)(x, v, acc, model.params, 0.0)
        count = model.kernel(exact_contact_kicks)(x, v, acc, out, nodes, tau, gamma, free, model.params)
        assert 10 in nodes[:count]
        w, steps = v.copy(), 2000
        h = tau / steps
        for _ in range(steps):
            k1 = rhs(w)
            k2 = rhs(w + h / 2 * k1)
            k3 = rhs(w + h / 2 * k2)
            k4 = rhs(w + h * k3)
            w = w + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        np.testing.assert_allclose(out[:, 10], w[:, 10], rtol=1e-10, atol=1e-12)


def test_smooth_step_and_box_weight():
    from ropesim.model.forces.thrower import box_weight, smooth_step

    assert smooth_step(0.0, 0.1) == 0.5 and smooth_step(1e-9, 0.0) == 1.0 and smooth_step(0.0, 0.0) == 0.0
    assert smooth_step(2.0, 0.1) == 1.0 and smooth_step(-2.0, 0.1) == 0.0  # exactly, beyond 20 widths
    p = build(shooter("thrower.edge_width=0.05")).params.thrower
    xs = np.linspace(0.0, 8.0, 80001)  # from the box's centre across its right edge at x = 4, in 0.1 mm steps
    w = np.array([box_weight(np.array([[x], [0.0]]), 0, p) for x in xs])
    assert w[0] == 1.0 and w[-1] == 0.0 and np.all(np.diff(w) <= 0)
    assert np.max(np.abs(np.diff(w))) < 1.1e-3  # no jump: the steepest slope is 1 / (2 w) = 10 per metre
    assert np.interp(4.0, xs, w) == pytest.approx(0.5, abs=1e-6)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(2, 14), dim=st.sampled_from([2, 3]), bending=st.booleans(), closed=st.booleans(),
       seed=st.integers(0, 2 ** 31))
def test_banded_newton_solver_matches_a_dense_solve(n, dim, bending, closed, seed):
    """The stiff integrator's linear solver (banded Cholesky, Woodbury correction for a loop's wrap-around)
    solves a random positive definite rope matrix, with springs between neighbours and second neighbours, as
    a dense solve does, to round-off."""
    from ropesim.model import jit
    from ropesim.model.banded import WITH_WRAP_AROUND, factor, solve, woodbury
    from ropesim.model.build import spring_count
    from ropesim.model.jacobian import Jacobian, add_pair, band_width

    if closed and bending and n < 5:
        return  # the loader refuses bending on loops of fewer than 5 nodes
    rng = np.random.default_rng(seed)
    w, cyclic = band_width(closed, n, 2 if bending else 1)
    jac = Jacobian(np.zeros(((w + 1) * dim, n * dim)), np.zeros((w * dim, w * dim)), np.zeros((dim, dim)), w)
    wood = woodbury(n * dim, w * dim)
    band, corner = jac.band, jac.corner
    dense = np.zeros((n * dim, n * dim))
    for stride in (1, 2) if bending else (1,):
        for i in range(spring_count(n, stride, closed)):
            j = (i + stride) % n
            if i == j:
                continue
            u = rng.standard_normal((dim, dim))
            blk = u @ u.T  # a random symmetric positive semi-definite spring block
            jac.blk[:] = blk
            add_pair(jac, n, i, j, True, True)
            for a, b in ((i, i), (j, j)):
                dense[a * dim:(a + 1) * dim, b * dim:(b + 1) * dim] += blk
            dense[i * dim:(i + 1) * dim, j * dim:(j + 1) * dim] -= blk
            dense[j * dim:(j + 1) * dim, i * dim:(i + 1) * dim] -= blk
    mass = rng.uniform(0.1, 2.0, n * dim)
    band[0] += mass
    dense[np.diag_indices(n * dim)] += mass
    rhs = rng.standard_normal(n * dim)
    p = band.shape[0] - 1
    switches = frozenset({WITH_WRAP_AROUND.name} if closed else ())   # as a scene's switches
    factor, solve = jit.specialise(factor, switches), jit.specialise(solve, switches)
    assert factor(band, corner, cyclic, p, wood)
    x = rhs.copy()
    solve(band, corner, cyclic, p, x, wood)
    expected = np.linalg.solve(dense, rhs)
    assert np.allclose(x, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
