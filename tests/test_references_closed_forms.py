"""Tests of the independent references in tests/references/ (closed forms and separate scipy solves).

These check the references against themselves by a second route (another method, a limit, a known number, or
MoorPy), so that ropesim can later be checked against them. Nothing here imports ropesim.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_bvp, solve_ivp
from scipy.linalg import eigh
from scipy.special import jn_zeros

from references import closed_forms as cf
from references.conventions import (
    gravity_buoyancy_node_forces,
    linear_drag_node_forces,
    morison_node_forces,
    node_lengths,
    node_tangents,
)
from references.towed_cable import (
    TowedLine,
    approach_exponent,
    continuous_cable,
    critical_angle,
    crosswind_plane,
    critical_angle_general,
    critical_angle_linear,
    drag_parameter,
    residual,
    steady_state_full,
    steady_state_march,
    steady_state_positions,
    to_3d,
    weight_in_fluid,
    with_,
)

RHO_W, G = 1025.0, 9.80665

# ==============================================================================================================
# conventions
# ==============================================================================================================


def test_node_lengths_and_tangents_follow_the_stated_convention():
    L = node_lengths([1.0, 2.0, 3.0])
    np.testing.assert_allclose(L, [0.5, 1.5, 2.5, 1.5])
    x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 3.0]])
    q = node_tangents(x)
    s = math.sqrt(0.5)
    np.testing.assert_allclose(q, [[1, 0], [s, s], [0, 1], [0, 1]], atol=1e-15)


# ==============================================================================================================
# towed cable: critical angle
# ==============================================================================================================


@given(K=st.floats(1e-6, 1e6))
def test_critical_angle_solves_its_defining_balance(K):
    # w = 1, rho Cd d / 2 = 1: then U^2 = K
    phi = float(critical_angle(math.sqrt(K), 1.0, 2.0, 1.0, 1.0))
    assert 0.0 <= phi < math.pi / 2
    # sin(phi) = K cos^2(phi). Evaluating cos(phi) near 90 deg has absolute error ~eps, so K cos^2 carries
    # ~2 eps K cos(phi) = 2 eps sqrt(K): the bound is round-off of the check itself, not of the closed form
    assert abs(math.sin(phi) - K * math.cos(phi) ** 2) <= 1e-15 * (4.0 + 8.0 * math.sqrt(K))


def test_critical_angle_limits():
    # K -> 0: phi ~ K (sin phi = K cos^2 phi = K (1 - K^2 + ...), so phi = K - K^3/... : relative error ~ K^2)
    for K in (1e-3, 1e-5):
        phi = float(critical_angle(math.sqrt(K), 1.0, 2.0, 1.0, 1.0))
        assert phi == pytest.approx(K, rel=2 * K * K)
    # K -> infinity: cos phi ~ K^-1/2 (cos^2 = sin / K, sin -> 1), relative error O(1/K)
    for K in (1e4, 1e8):
        phi = float(critical_angle(math.sqrt(K), 1.0, 2.0, 1.0, 1.0))
        assert math.cos(phi) == pytest.approx(K ** -0.5, rel=1.0 / K)
    # no drag, no flow: straight down
    assert float(critical_angle(0.0, 1.0, 1.0, 1.0, 1.0)) == 0.0


def test_critical_angle_known_number():
    # chain-free example by hand: w = 16.4554 N/m (mu = 2 kg/m, d = 20 mm in sea water), Cd_n = 1.2, U = 1.5 m/s:
    # K = 1025 * 1.2 * 0.02 * 2.25 / (2 * 16.4554) = 1.681816; sin phi = (sqrt(1 + 4K^2) - 1) / (2K) = 0.745857
    w = weight_in_fluid(2.0, 0.02, RHO_W, G)
    assert w == pytest.approx((2.0 - RHO_W * math.pi * 1e-4) * G, rel=1e-15)
    K = drag_parameter(1.5, w, RHO_W, 1.2, 0.02)
    assert K == pytest.approx(1.681816, rel=1e-6)
    phi = float(critical_angle(1.5, w, RHO_W, 1.2, 0.02))
    assert math.sin(phi) == pytest.approx((math.sqrt(1 + 4 * K * K) - 1) / (2 * K), rel=1e-14)
    assert math.degrees(phi) == pytest.approx(48.2416, abs=1e-4)


def test_general_critical_angle_reduces_to_each_drag_law():
    w = 10.0
    for U in (0.1, 1.0, 7.0):
        assert critical_angle_general(U, w, RHO_W, 1.2, 0.03) == pytest.approx(
            float(critical_angle(U, w, RHO_W, 1.2, 0.03)), abs=1e-14)
        assert critical_angle_general(U, w, RHO_W, 0.0, 0.03, b_n=4.0) == pytest.approx(
            float(critical_angle_linear(U, w, 4.0)), abs=1e-14)


# ==============================================================================================================
# towed cable: discrete steady state, two methods
# ==============================================================================================================

BASE = dict(mu=2.0, d=0.02, EA=1e6, rho=RHO_W, g=G, cd_n=1.2, u=(1.5, 0.0))

CASES = {
    "normal drag only": dict(),
    "tangential drag": dict(cd_t=0.05),
    "end mass": dict(end_mass=20.0, cd_t=0.01),
    "end drogue (drag body)": dict(end_area=0.5, cd_t=0.01),
    "linear drag too": dict(b_n=3.0, b_t=1.0, cd_t=0.02, end_mass=5.0),
    "stretched drag length, soft": dict(EA=2e4, cd_t=0.02, end_mass=10.0, drag_length="stretched"),
    "current with an upward part": dict(u=(1.2, -0.3), cd_t=0.02, end_mass=10.0),
    "light line in air, crosswind": dict(mu=0.3, d=0.012, rho=1.225, cd_n=1.2, cd_t=0.01, EA=5e5, u=(8.0, 0.0),
                                         end_mass=2.0, end_area=0.3, end_cd=1.0),
}


@pytest.mark.parametrize("name", list(CASES))
def test_march_and_full_solve_agree(name):
    line = TowedLine.uniform(60.0, 30, **{**BASE, **CASES[name]})
    m = steady_state_march(line)
    f = steady_state_full(line)
    # two exact solutions of the same discrete equations by different methods (node-by-node scalar roots vs one
    # simultaneous solve): measured agreement ~1e-14 m; 1e-10 of the line's length leaves room for conditioning
    np.testing.assert_allclose(m.x, f.x, rtol=0, atol=1e-10 * 60)
    np.testing.assert_allclose(m.T, f.T, rtol=1e-10, atol=1e-12 * abs(line.w) * 60)
    assert f.info["residual"] < 1e-10 * max(m.T.max(), 1.0)
    # and the march satisfies every node's balance by itself. Recomputing T = EA (|dx|/l - 1) from positions
    # loses ~EA * eps relative: the bound scales with EA
    F = np.abs(residual(line, m.x)).max()
    assert F < 1e-13 * line.EA + 1e-12 * m.T.max()


@pytest.mark.parametrize("cd_t", [0.0, 0.05, 0.5])
def test_without_an_end_body_the_discrete_line_is_straight_at_the_critical_angle(cd_t):
    """Every node's loads are proportional to its L_i, so the straight line at phi_c is exact, at any N and any
    tangential drag (tangential drag only changes the tension)."""
    line = TowedLine.uniform(100.0, 20, **{**BASE, "cd_t": cd_t})
    m = steady_state_march(line)
    pc = float(critical_angle(1.5, line.w, RHO_W, 1.2, 0.02))
    np.testing.assert_allclose(m.angles, pc, atol=1e-12)
    # tension grows up the line by (w cos phi + k_t U^2 sin^2 phi) per metre of line
    kt = 0.5 * RHO_W * cd_t * math.pi * 0.02
    grad = line.w * math.cos(pc) + kt * 1.5 ** 2 * math.sin(pc) ** 2
    expected = grad * (100.0 - 5.0 * np.arange(20) - 2.5)  # segment j carries nodes j+1..N: length below - l/2
    np.testing.assert_allclose(m.T, expected, rtol=1e-12)


@pytest.mark.parametrize("name", ["end mass", "light line in air, crosswind"])
def test_march_agrees_with_a_raw_node_position_solve(name):
    """A third method: scipy root over the raw node positions (springs in the Jacobian) for soft lines."""
    line = TowedLine.uniform(30.0, 15, **{**BASE, **CASES[name]})
    m = steady_state_march(line)
    p = steady_state_positions(line)
    # conditioning ~ EA / (w l) ~ 1e5 on top of round-off: 1e-9 of the length
    np.testing.assert_allclose(m.x, p.x, rtol=0, atol=1e-9 * 30)


def test_inextensible_line():
    line = TowedLine.uniform(40.0, 20, **{**BASE, "EA": math.inf, "end_mass": 10.0, "cd_t": 0.02})
    m = steady_state_march(line)
    np.testing.assert_allclose(m.x, steady_state_full(line).x, atol=1e-12)
    seg = np.linalg.norm(np.diff(m.x, axis=0), axis=1)
    np.testing.assert_allclose(seg, 2.0, rtol=1e-14)
    # a very stiff line differs by its stretch, T / EA ~ 1e-9 relative at EA = 1e12: positions within 1e-7 m
    stiff = steady_state_march(with_(line, EA=1e12))
    np.testing.assert_allclose(stiff.x, m.x, atol=1e-7)
    assert np.abs(stiff.x - m.x).max() > 0  # and it does stretch


def test_end_body_drag_uses_cd_times_area():
    a = steady_state_march(TowedLine.uniform(30.0, 10, **{**BASE, "end_area": 0.25, "end_cd": 2.0}))
    b = steady_state_march(TowedLine.uniform(30.0, 10, **{**BASE, "end_area": 0.5, "end_cd": 1.0}))
    np.testing.assert_allclose(a.x, b.x, atol=1e-12)
    # a drogue pulls the bottom flatter than phi_c, a weight steeper
    pc = float(critical_angle(1.5, weight_in_fluid(2.0, 0.02, RHO_W, G), RHO_W, 1.2, 0.02))
    assert a.angles[-1] > pc
    assert steady_state_march(TowedLine.uniform(30.0, 10, **{**BASE, "end_mass": 5.0})).angles[-1] < pc


def test_the_free_end_settles_in_the_stable_direction():
    """A single heavy node on one segment in a current: its segment lies along its total load."""
    line = TowedLine.uniform(1.0, 1, mu=1.0, d=0.01, rho=1000.0, g=9.81, cd_n=1.0, cd_t=0.0, u=(2.0, 0.0))
    m = steady_state_march(line)
    # node 1: L = 0.5 m, weight (1 - 1000 pi 0.01^2 / 4) 0.5 g, normal drag only, balance gives phi_c exactly
    pc = float(critical_angle(2.0, line.w, 1000.0, 1.0, 0.01))
    assert m.angles[0] == pytest.approx(pc, abs=1e-13)


def test_long_line_converges_to_the_critical_angle_and_tangential_drag_slows_the_approach():
    """Below a heavy end body the line starts steep and bends towards phi_c going up. Without tangential drag
    its top reaches phi_c; with it, the limit is the same but the approach is slower (the algebraic exponent
    c/a falls from 1 + 2 tan^2 phi_c), so at the same length the top is further from phi_c."""
    tops = {}
    for cd_t in (0.0, 0.1):
        line = TowedLine.uniform(600.0, 300, **{**BASE, "cd_t": cd_t, "end_mass": 20.0})
        m = steady_state_march(line)
        pc = float(critical_angle(1.5, line.w, RHO_W, 1.2, 0.02))
        dev = np.abs(m.angles - pc)
        assert dev[-1] > 0.5  # the bottom segment hangs far from phi_c (rad)
        assert np.all(np.diff(dev[::-1][5:]) < 0)  # the deviation falls monotonically going up
        tops[cd_t] = dev[0]
    assert tops[0.0] < 1e-4  # within 0.006 deg at the top of 600 m
    assert tops[0.1] > 3 * tops[0.0]


def test_crosswind_steady_state_is_the_2d_one_turned_about_the_vertical():
    """Helicopter sling: forward 20 m/s, side wind 5 m/s. Build the 2-D solution for |u|, turn it into 3-D and
    evaluate the 3-D loads (the conventions work in any dimension): every node balances, out of plane too."""
    U, az = crosswind_plane(20.0, 5.0)
    assert U == pytest.approx(math.hypot(20, 5)) and az == pytest.approx(math.atan2(5, 20))
    line = TowedLine.uniform(20.0, 20, mu=0.13, d=0.016, EA=5e6, rho=1.225, g=G, cd_n=1.2, cd_t=0.02, u=(U, 0.0),
                             end_mass=25.0, end_cd=1.0, end_area=0.05)
    m = steady_state_march(line)
    x3 = to_3d(m.x, az)
    u3 = np.array([20.0, 5.0, 0.0])  # the line's velocity through the air
    f = morison_node_forces(x3, np.broadcast_to(u3, x3.shape), line.seg_lengths, line.d, line.rho, line.cd_n,
                            line.cd_t)
    f[:, 2] += gravity_buoyancy_node_forces(line.seg_lengths, line.mu, line.d, line.rho, G, dim=3)[:, 2]
    f[-1] += -0.5 * line.rho * 0.05 * np.linalg.norm(u3) * u3 + np.array([0, 0, -25.0 * G])
    seg = np.diff(x3, axis=0)
    e = seg / np.linalg.norm(seg, axis=1, keepdims=True)
    f[:-1] += m.T[:, None] * e
    f[1:] -= m.T[:, None] * e
    # balances to round-off of the tensions (~270 N at the top)
    assert np.abs(f[1:]).max() < 1e-10 * m.T.max()
    # the line trails straight downwind of the relative wind: every node at -(cos az, sin az) * s horizontally
    horiz = x3[:, :2]
    cross = horiz[:, 0] * math.sin(az) - horiz[:, 1] * math.cos(az)
    assert np.abs(cross).max() < 1e-12


def test_continuous_cable_approaches_the_critical_angle_at_the_predicted_algebraic_rate():
    w = weight_in_fluid(2.0, 0.02, RHO_W, G)
    pc = float(critical_angle(1.5, w, RHO_W, 1.2, 0.02))
    for cd_t in (0.0, 0.1):
        s, xy, T, phi = continuous_cable(2000.0, w, RHO_W, 0.02, (1.5, 0.0), 1.2, cd_t,
                                         end_force=(0.0, -20 * G), n_out=2001)
        sel = slice(1000, 2001)
        slope = np.polyfit(np.log(T[sel]), np.log(np.abs(phi[sel] - pc)), 1)[0]
        # the linearised law holds once |phi - phi_c| ~ 1e-5 rad: the fitted exponent agrees to 1e-5 relative
        assert -slope == pytest.approx(approach_exponent(1.5, w, RHO_W, 1.2, cd_t, 0.02), rel=1e-5)
    assert approach_exponent(1.5, w, RHO_W, 1.2, 0.0, 0.02) == pytest.approx(1 + 2 * math.tan(pc) ** 2, rel=1e-14)


def test_discrete_line_converges_to_the_continuous_cable():
    base = {**BASE, "cd_t": 0.02, "end_mass": 20.0}
    one = TowedLine.uniform(100.0, 1, **base)
    s, xy, T, phi = continuous_cable(100.0, one.w, RHO_W, 0.02, (1.5, 0.0), 1.2, 0.02, EA=1e6,
                                     end_force=one.end_body_force())
    errs = []
    for N in (50, 100, 200):
        m = steady_state_march(TowedLine.uniform(100.0, N, **base))
        errs.append(np.linalg.norm(m.x[-1] - xy[0]))
    # the free end's position converges at second order in 1/N once N >~ 50 (measured error 0.091, 0.026,
    # 0.0070 m: ratios 3.4 and 3.7, tending to 4)
    assert errs[2] < 0.01  # m, on a 100 m line at N = 200
    assert errs[0] / errs[1] > 3.0 and errs[1] / errs[2] > 3.0


# ==============================================================================================================
# terminal velocity and drops
# ==============================================================================================================


@pytest.mark.parametrize("orientation", ["broadside", "end-on"])
def test_rope_terminal_velocity_zeroes_the_node_loads_of_the_convention(orientation):
    mu, d, cd_n, cd_t = 0.5, 0.02, 1.2, 0.008
    vt = cf.rope_terminal_velocity(mu, d, RHO_W, G, cd_n, cd_t, orientation=orientation)
    N, l = 7, 0.3
    s = np.arange(N + 1) * l
    x = np.stack([s, np.zeros_like(s)], 1) if orientation == "broadside" else np.stack([np.zeros_like(s), s], 1)
    v = np.array([0.0, -vt])
    f = morison_node_forces(x, v, [l] * N, d, RHO_W, cd_n, cd_t) + gravity_buoyancy_node_forces([l] * N, mu, d,
                                                                                                 RHO_W, G)
    assert np.abs(f).max() < 1e-13 * mu * l * G


def test_terminal_velocity_with_both_drag_laws():
    mu, d = 0.5, 0.02
    w = (mu - RHO_W * math.pi * d * d / 4) * G
    v = cf.rope_terminal_velocity(mu, d, RHO_W, G, 1.2, b_n=2.0)
    assert 0.5 * RHO_W * 1.2 * d * v * v + 2.0 * v == pytest.approx(w, rel=1e-14)
    assert cf.rope_terminal_velocity(mu, d, RHO_W, G, 0.0, b_n=2.0) == pytest.approx(w / 2.0, rel=1e-15)
    f = linear_drag_node_forces(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([0.0, -w / 2.0]), [1.0], 2.0, 0.0)
    np.testing.assert_allclose(f[:, 1], 0.5 * w, rtol=1e-15)  # each node L = 0.5: drag = its share of the weight


def test_string_takeoff_estimates_are_terminal_speeds_and_ignore_loop_length():
    v = cf.string_loop_takeoff_speeds(1.6e-3, 1.5e-3, cd_n=1.2, cd_t=0.02)
    w = (1.6e-3 - 1.225 * math.pi * 1.5e-3 ** 2 / 4) * 9.80665
    assert 0.5 * 1.225 * 0.02 * math.pi * 1.5e-3 * v["tangential"] ** 2 == pytest.approx(w, rel=1e-14)
    assert 0.5 * 1.225 * 1.2 * 1.5e-3 * v["normal"] ** 2 == pytest.approx(w, rel=1e-14)
    # the numbers quoted in STRING_SHOOTER_LITERATURE.md (cotton string, 1.5 mm, 1.6 g/m)
    assert v["normal"] == pytest.approx(3.77, abs=0.01)
    assert v["tangential"] == pytest.approx(16.5, abs=0.05)


def test_drop_histories_solve_their_equations_of_motion():
    W, m, rho, cd, A, b = 9.0, 1.5, 1.2, 0.47, 0.05, 0.7
    t = np.linspace(0, 10, 101)
    vq, xq = cf.drop_quadratic(t, W, m, rho, cd, A)
    sol = solve_ivp(lambda _, y: [y[1], (W - 0.5 * rho * cd * A * y[1] ** 2) / m], (0, 10), [0, 0], t_eval=t,
                    rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(vq, sol.y[1], atol=1e-9)
    np.testing.assert_allclose(xq, sol.y[0], atol=1e-8)
    vl, xl = cf.drop_linear(t, W, m, b)
    sol = solve_ivp(lambda _, y: [y[1], (W - b * y[1]) / m], (0, 10), [0, 0], t_eval=t, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(vl, sol.y[1], atol=1e-9)
    np.testing.assert_allclose(xl, sol.y[0], atol=1e-8)
    # limits: free fall at first, terminal speed at last
    vq0, _ = cf.drop_quadratic(1e-4, W, m, rho, cd, A)
    assert vq0 == pytest.approx(W / m * 1e-4, rel=1e-6)
    vq_inf, _ = cf.drop_quadratic(1e4, W, m, rho, cd, A)
    assert vq_inf == pytest.approx(cf.terminal_velocity_quadratic(W, rho, cd, A), rel=1e-15)
    vl_inf, _ = cf.drop_linear(1e4, W, m, b)
    assert vl_inf == pytest.approx(cf.terminal_velocity_linear(W, b), rel=1e-15)


# ==============================================================================================================
# neutral buoyancy
# ==============================================================================================================


@given(d=st.floats(1e-3, 0.5), rho=st.floats(1.0, 2000.0),
       segs=st.lists(st.floats(0.01, 10.0), min_size=1, max_size=20))
def test_a_neutrally_buoyant_line_feels_no_net_vertical_force(d, rho, segs):
    mu = cf.neutral_mass_per_metre(d, rho)
    f = cf.net_vertical_force_per_node(segs, mu, d, rho, G)
    assert np.abs(f).max() <= 1e-15 * mu * G * max(segs) * 4
    assert cf.neutral_diameter(mu, rho) == pytest.approx(d, rel=1e-14)
    # and the conventions module agrees node by node
    np.testing.assert_allclose(gravity_buoyancy_node_forces(segs, mu, d, rho, G)[:, -1], f, atol=1e-12 * mu)


def test_a_heavier_line_sinks_node_by_node_in_proportion_to_length():
    f = cf.net_vertical_force_per_node([1.0, 3.0], 2.0, 0.02, RHO_W, G)
    w = weight_in_fluid(2.0, 0.02, RHO_W, G)
    np.testing.assert_allclose(f, [-0.5 * w, -2.0 * w, -1.5 * w], rtol=1e-14)


# ==============================================================================================================
# Morison drag on one segment
# ==============================================================================================================

vec3 = st.tuples(*[st.floats(-10, 10)] * 3)


@settings(max_examples=200)
@given(x0=vec3, x1=vec3, v0=vec3, v1=vec3, flow=vec3)
def test_segment_drag_formula_matches_the_vectorised_convention(x0, x1, v0, v1, flow):
    if np.linalg.norm(np.subtract(x1, x0)) < 1e-3:
        return
    d, rho, cdn, cdt = 0.03, RHO_W, 1.2, 0.01
    F0, F1 = cf.segment_morison_drag(x0, x1, v0, v1, d, rho, cdn, cdt, flow=flow)
    x = np.array([x0, x1])
    f = morison_node_forces(x, np.array([v0, v1]), [np.linalg.norm(x[1] - x[0])], d, rho, cdn, cdt, flow=flow,
                            drag_length="unstretched")
    scale = 0.5 * rho * cdn * d * np.linalg.norm(x[1] - x[0]) * (30.0 ** 2)
    np.testing.assert_allclose(np.array([F0, F1]), f, atol=1e-13 * scale)
    # drag never feeds energy in: F . u <= 0 for each node
    for F, v in ((F0, v0), (F1, v1)):
        assert np.dot(F, np.subtract(v, flow)) <= 1e-12 * scale


def test_segment_drag_known_cases():
    d, rho, cdn, cdt, l = 0.02, 1000.0, 1.2, 0.01, 2.0
    # broadside at 3 m/s: each node gets 1/2 rho Cd_n d (l/2) 9 = 108 N against the motion
    F0, F1 = cf.segment_morison_drag((0, 0, 0), (l, 0, 0), (0, 3, 0), (0, 3, 0), d, rho, cdn, cdt)
    np.testing.assert_allclose(F0, [0, -0.5 * rho * cdn * d * 1.0 * 9, 0], rtol=1e-15)
    np.testing.assert_allclose(F1, F0, rtol=1e-15)
    # end-on: skin drag 1/2 rho Cd_t pi d (l/2) 9
    F0, _ = cf.segment_morison_drag((0, 0, 0), (l, 0, 0), (3, 0, 0), (3, 0, 0), d, rho, cdn, cdt)
    np.testing.assert_allclose(F0, [-0.5 * rho * cdt * math.pi * d * 9, 0, 0], rtol=1e-15)
    # at 45 degrees: the parts act separately on their own components, |u_n| = |u_t| = 3 / sqrt 2
    F0, _ = cf.segment_morison_drag((0, 0), (l, 0), (3 / math.sqrt(2), 3 / math.sqrt(2)), (0, 0), d, rho, cdn, cdt)
    c = 4.5  # |u_t| u_t = |u_n| u_n = (3 / sqrt 2)^2
    np.testing.assert_allclose(F0, [-0.5 * rho * cdt * math.pi * d * c, -0.5 * rho * cdn * d * c], rtol=1e-14)
    # a still body in a current towards -y is dragged along with it, as if it moved at +3 m/s in still water
    F0, _ = cf.segment_morison_drag((0, 0), (l, 0), (0, 0), (0, 0), d, rho, cdn, cdt, flow=(0, -3))
    np.testing.assert_allclose(F0, [0, -0.5 * rho * cdn * d * 9], rtol=1e-15)


# ==============================================================================================================
# elastic catenary
# ==============================================================================================================

moorpy_catenary = pytest.importorskip("moorpy.Catenary").catenary

CAT_CASES = [
    # X, Z, L, w, EA, CB, seabed
    (400, 140, 500, 1000, 1e8, 0.0, True),  # touchdown
    (400, 140, 500, 1000, 1e8, 0.5, True),  # touchdown, friction takes all of H before the anchor
    (400, 140, 500, 1000, 1e8, 0.05, True),  # touchdown, friction takes part of H
    (300, 200, 400, 800, 5e7, 0.0, True),
    (600, 300, 700, 500, 4e8, 0.0, True),
    (200, 150, 260, 700, 1e7, 0.0, True),  # soft: most of the slack is stretch
    (848.67, 250, 902.2, 698.094, 384.243e6, 0.0, True),  # OC3-Hywind line properties, touchdown
    (300, 200, 370, 800, 5e7, 0.0, True),  # fully suspended
    (300, 200, 355, 800, 5e7, 0.0, True),  # taut: chord longer than the line
    (200, 50, 300, 1000, 1e9, 0.0, False),  # no seabed: the line dips below the anchor
]


@pytest.mark.parametrize("X, Z, L, w, EA, CB, seabed", CAT_CASES)
def test_catenary_matches_moorpy(X, Z, L, w, EA, CB, seabed):
    r = cf.elastic_catenary(X, Z, L, w, EA, CB, seabed=seabed)
    fAH, fAV, fBH, fBV, info = moorpy_catenary(X, Z, L, EA, w, CB=CB if seabed else -1e4)
    # MoorPy iterates to a displacement tolerance of 1e-6 m (its Tol): relative force agreement ~1e-7 is all
    # it can give; our solve is at round-off (checked below by substitution)
    assert r.H == pytest.approx(-fBH, rel=2e-7)
    assert r.V == pytest.approx(-fBV, rel=2e-7)
    assert r.HA == pytest.approx(fAH, rel=2e-7, abs=1e-6 * w * L)
    assert r.VA == pytest.approx(fAV, rel=2e-7, abs=1e-6 * w * L)
    assert r.LB == pytest.approx(info["LBot"], rel=1e-7, abs=1e-5)  # MoorPy's Tol = 1e-6 m, amplified
    xz = (cf.catenary_touchdown_xz(r.H, r.V, L, w, EA, CB) if r.regime == "touchdown"
          else cf.catenary_suspended_xz(r.H, r.V, L, w, EA))
    np.testing.assert_allclose(xz, (X, Z), rtol=1e-12)


def test_catenary_elastic_tension_identity():
    """dT/dz = w / (1 + T/EA) along the suspended part, so (T_F - T_0) + (T_F^2 - T_0^2) / (2 EA) = w Z, with T_0
    the tension at the lower end of the suspended part (the anchor, or H at touchdown, frictionless)."""
    for X, Z, L, w, EA in [(400, 140, 500, 1000, 1e6), (300, 200, 370, 800, 5e6), (300, 200, 355, 800, 5e7)]:
        r = cf.elastic_catenary(X, Z, L, w, EA)
        T0 = r.H if r.regime == "touchdown" else r.T_anchor
        lhs = (r.T_fairlead - T0) + (r.T_fairlead ** 2 - T0 ** 2) / (2 * EA)
        assert lhs == pytest.approx(w * Z, rel=1e-11)


def test_catenary_textbook_inextensible_touchdown():
    """Faltinsen (1990) sec. 8: a = H/w, l_s = sqrt(Z^2 + 2 Z a), T_fairlead = H + w Z. By hand: w = 1 kN/m,
    Z = 100 m, H = 100 kN: a = 100 m, l_s = 100 sqrt 3 = 173.205 m, V = 173.205 kN, T_F = 200 kN exactly,
    X = L - l_s + a asinh(sqrt 3) = L - 41.50929 m."""
    tb = cf.inextensible_touchdown(1e5, 100.0, 500.0, 1000.0)
    assert tb["l_s"] == pytest.approx(100 * math.sqrt(3), rel=1e-15)
    assert tb["X"] == pytest.approx(500 - 100 * math.sqrt(3) + 100 * math.asinh(math.sqrt(3)), rel=1e-15)
    assert tb["X"] == pytest.approx(458.49071, abs=1e-5)
    assert tb["T_fairlead"] == 2e5
    # the elastic solver in the inextensible limit (EA = 1e15: stretch 1e-10 relative) reproduces it
    r = cf.elastic_catenary(tb["X"], 100.0, 500.0, 1000.0, 1e15)
    assert r.regime == "touchdown"
    assert r.H == pytest.approx(1e5, rel=1e-7)
    assert r.V == pytest.approx(tb["V"], rel=1e-7)
    assert r.T_fairlead == pytest.approx(2e5, rel=1e-7)
    assert r.LB == pytest.approx(tb["LB"], rel=1e-7)


def test_catenary_regimes_meet_continuously():
    """At the X where the line just leaves the seabed (V = w L, V_A = 0) touchdown and suspended solutions agree."""
    L, w, EA, H = 500.0, 1000.0, 1e8, 5e4
    Xc, Zc = cf.catenary_suspended_xz(H, w * L, L, w, EA)
    lo = cf.elastic_catenary(Xc - 1e-6, Zc, L, w, EA)
    hi = cf.elastic_catenary(Xc + 1e-6, Zc, L, w, EA)
    assert lo.regime == "touchdown" and hi.regime == "suspended"
    assert lo.H == pytest.approx(H, rel=1e-5) and hi.H == pytest.approx(H, rel=1e-5)
    assert lo.LB < 1e-3


def test_catenary_friction_lowers_the_anchor_load_but_keeps_the_fairlead_tension_close():
    X, Z, L, w, EA = 400.0, 140.0, 500.0, 1000.0, 1e7
    r0 = cf.elastic_catenary(X, Z, L, w, EA, CB=0.0)
    r1 = cf.elastic_catenary(X, Z, L, w, EA, CB=0.05)
    r2 = cf.elastic_catenary(X, Z, L, w, EA, CB=1.0)
    assert r0.HA == r0.H
    assert r1.HA == pytest.approx(r1.H - 0.05 * w * r1.LB, rel=1e-12)
    assert r2.HA == 0.0
    # friction only changes the seabed part's stretch: the fairlead tension moves by less than H L_B / EA terms
    assert abs(r1.H - r0.H) / r0.H < 0.05


def test_catenary_slack_line_lies_on_the_seabed():
    r = cf.elastic_catenary(100.0, 50.0, 300.0, 1000.0, 1e9)
    assert r.regime == "slack" and r.H == 0.0
    assert r.V == pytest.approx(1000.0 * 50.0, rel=1e-4)  # the vertical part's weight (stretch 2.5e-5)


# ==============================================================================================================
# cantilever
# ==============================================================================================================


def test_cantilever_beta_L_roots():
    b = cf.cantilever_beta_L(3)
    # the brief's 9-digit values
    np.testing.assert_allclose(b, [1.87510407, 4.69409113, 7.85475744], atol=6e-9)
    # and the stored constants, to round-off; each is a root of cos x cosh x + 1 (relative to cosh x)
    np.testing.assert_allclose(b, cf.BETA_L, rtol=1e-15)
    for x in b:
        assert abs(cf.cantilever_root_eq(x)) < 1e-12 * math.cosh(x)
    # higher modes approach (2n - 1) pi / 2
    assert cf.cantilever_beta_L(8)[-1] == pytest.approx(15 * math.pi / 2, abs=1e-6)


def _beam_fe_frequencies(EI, mu, L, n_el=40, n_modes=3):
    """Independent check: cubic Hermite beam finite elements (consistent mass), clamped at x = 0."""
    h = L / n_el
    k = EI / h ** 3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
    m = mu * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                                 [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    n = 2 * (n_el + 1)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(n_el):
        i = slice(2 * e, 2 * e + 4)
        K[i, i] += k
        M[i, i] += m
    w2 = eigh(K[2:, 2:], M[2:, 2:], eigvals_only=True)
    return np.sqrt(w2[:n_modes])


def test_cantilever_frequencies_match_finite_elements():
    EI, mu, L = 250.0, 0.8, 3.0
    om = cf.cantilever_frequencies(EI, mu, L)
    np.testing.assert_allclose(om, np.array(cf.BETA_L) ** 2 * math.sqrt(EI / (mu * L ** 4)), rtol=1e-14)
    # Hermite elements converge as h^4 in frequency: 40 elements gave 1e-6 on the third mode, so 100 give ~3e-8
    np.testing.assert_allclose(_beam_fe_frequencies(EI, mu, L, n_el=100), om, rtol=1e-7)


def test_cantilever_deflections_match_the_beam_equation():
    """Solve EI y'''' = q(x) with y(0) = y'(0) = 0, y''(L) = 0, EI y'''(L) = -P independently (solve_bvp)."""
    EI, L, w, P = 120.0, 2.0, 3.0, 5.0

    def tip(q, P):
        sol = solve_bvp(lambda x, y: np.vstack([y[1], y[2], y[3], np.full_like(x, q / EI)]),
                        lambda a, b: np.array([a[0], a[1], b[2], b[3] - P / EI]),  # P downward at the tip
                        np.linspace(0, L, 50), np.zeros((4, 50)), tol=1e-10)
        return sol.sol(L)[0]

    # downward loads give y < 0: compare magnitudes; solve_bvp's tolerance 1e-10 bounds the error
    assert -tip(-w, 0.0) == pytest.approx(cf.cantilever_tip_deflection_uniform_load(w, L, EI), rel=1e-8)
    assert -tip(0.0, P) == pytest.approx(cf.cantilever_tip_deflection_point_load(P, L, EI), rel=1e-8)


def test_discrete_cantilever_converges_to_the_beam():
    EI, L, P, w = 50.0, 1.0, 2.0, 3.0
    prev = None
    for N in (4, 16, 64, 256):
        l = L / N
        joints = np.arange(N) * l  # springs at the clamp and at each inner node
        k = np.full(N, EI / l)
        nodes = np.arange(1, N + 1) * l
        tip_P = cf.discrete_cantilever_tip_deflection(joints, k, nodes, np.r_[np.zeros(N - 1), P])
        # closed form of the same discrete model
        assert tip_P == pytest.approx(P * l ** 3 * N * (N + 1) * (2 * N + 1) / (6 * EI), rel=1e-13)
        exact = cf.cantilever_tip_deflection_point_load(P, L, EI)
        assert tip_P / exact - 1 == pytest.approx(1.5 / N + 0.5 / N ** 2, rel=1e-9)
        # own weight lumped on the nodes (end node half): first-order convergence too
        f = np.full(N, w * l)
        f[-1] *= 0.5
        tip_w = cf.discrete_cantilever_tip_deflection(joints, k, nodes, f)
        err = abs(tip_w / cf.cantilever_tip_deflection_uniform_load(w, L, EI) - 1)
        if prev is not None:
            assert err < prev / 3.0  # O(1/N): x4 in N, error / 4 (allow / 3)
        prev = err
    assert prev < 0.01


# ==============================================================================================================
# incline
# ==============================================================================================================


def test_incline_critical_angle_and_acceleration():
    mu = 0.6
    ac = cf.incline_critical_angle(mu)
    assert math.tan(ac) == pytest.approx(mu, rel=1e-15)
    assert cf.incline_acceleration(ac - 1e-9, mu) == 0.0
    assert cf.incline_acceleration(ac + 1e-3, mu) > 0.0
    a = math.radians(40)
    assert cf.incline_acceleration(a, 0.5, 0.4, g=9.81) == pytest.approx(9.81 * (math.sin(a) - 0.4 * math.cos(a)),
                                                                          rel=1e-15)


@given(alpha=st.floats(0.01, 1.5), mu=st.floats(0.0, 2.0), frac=st.floats(0.05, 1.0))
def test_incline_vector_balance(alpha, mu, frac):
    """Build the forces as vectors: weight in fluid, normal reaction, kinetic friction opposing sliding."""
    m, g = 2.0, 9.81
    W = np.array([0.0, -frac * m * g])
    n = np.array([-math.sin(alpha), math.cos(alpha)])  # slope normal, out of the slope
    t = np.array([-math.cos(alpha), -math.sin(alpha)])  # down the slope
    N = -W @ n
    a = cf.incline_acceleration(alpha, mu, g=g, weight_fraction=frac)
    if W @ t > mu * N:  # sliding
        F = W + N * n - mu * N * t
        assert a == pytest.approx((F @ t) / m, rel=1e-12, abs=1e-12)
        assert abs(F @ n) < 1e-12 * m * g
    else:
        assert a == 0.0
    # the critical angle does not depend on the weight fraction (buoyancy)
    assert (alpha > cf.incline_critical_angle(mu)) == (a > 0) or abs(math.tan(alpha) - mu) < 1e-12


# ==============================================================================================================
# hanging chain
# ==============================================================================================================


def test_hanging_chain_continuous_frequencies():
    om = cf.hanging_chain_frequencies(2.0, 9.81, 3)
    np.testing.assert_allclose(om / math.sqrt(9.81 / 2.0), jn_zeros(0, 3) / 2, rtol=1e-15)
    assert om[0] / math.sqrt(9.81 / 2.0) == pytest.approx(1.2024, abs=1e-4)  # j_01 / 2 = 1.20241


def test_discrete_hanging_chain_small_cases():
    g, l = 9.81, 0.7
    # one mass: the simple pendulum
    assert cf.discrete_hanging_chain_frequencies([2.0], [l], g)[0] == pytest.approx(math.sqrt(g / l), rel=1e-15)
    # two equal masses on equal links: omega^2 = (g/l)(2 -+ sqrt 2)
    om = cf.discrete_hanging_chain_frequencies([1.0, 1.0], [l, l], g)
    np.testing.assert_allclose(om ** 2, g / l * np.array([2 - math.sqrt(2), 2 + math.sqrt(2)]), rtol=1e-14)


def test_discrete_hanging_chain_converges_to_bessel():
    L, g = 3.0, 9.81
    exact = cf.hanging_chain_frequencies(L, g, 3)
    errs = []
    for N in (10, 40, 160):
        m, l = cf.lumped_chain_masses(L, N)
        errs.append(np.abs(cf.discrete_hanging_chain_frequencies(m, l, g)[:3] / exact - 1).max())
    # the lumped line (half mass at the free end) converges at second order: error / 16 per x4 in N
    # (measured: third mode 1.0e-1, 9.7e-3, 5.9e-4)
    assert errs[-1] < 1e-3
    assert errs[0] / errs[1] > 10 and errs[1] / errs[2] > 10
    # equal masses on every node (no half mass at the end) converge only at first order
    m = np.full(160, L / 160)
    err_equal = abs(cf.discrete_hanging_chain_frequencies(m, np.full(160, L / 160), g)[0] / exact[0] - 1)
    assert err_equal > 100 * abs(cf.discrete_hanging_chain_frequencies(*cf.lumped_chain_masses(L, 160), g)[0]
                                 / exact[0] - 1)
