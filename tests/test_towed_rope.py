"""The helicopter's towed rope and the hanging chain against closed forms.

Steady state (see ropesim.analysis.towed): segment i carries the weight and drag of every node below it, so the
exact discrete steady state is known node by node. The write-up's t_f = 3 s is not steady (the uniform rope
still trails at about 46 degrees then; an end mass of 100 kg with b = 5 relaxes on a time scale M / b = 20 s),
so these runs are long; the kernel makes them cheap (21 nodes, a few hundred thousand steps).
"""

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.special

import ropesim
from ropesim.analysis.towed import exact_steady_state, segment_angles, shape_verdict
from ropesim.model.build import build


def final_shape(model, traj):
    """Final node positions relative to the held node (node 0 in these scenes)."""
    return traj.x[-1] - traj.x[-1][0]


def run(scenarios, name, *sets):
    scene = ropesim.load_scene(scenarios / f"{name}.toml", list(sets))
    return build(scene), ropesim.simulate(scene)


def test_writeup_t_final_is_not_yet_steady(scenarios):
    model, traj = run(scenarios, "helicopter_uniform")
    top = segment_angles(model, traj.x[-1])[0]
    assert 44.0 < top < 48.0  # the "about 46 degrees" at t = 3 s; steady is 39.2


def test_uniform_rope_becomes_a_straight_line_at_the_drag_angle(scenarios):
    """tan(theta) = b v / (m g) = 5 * 8 / (5 * 9.81) for every segment."""
    model, traj = run(scenarios, "helicopter_uniform", "integrator.t_end=60", "output.interval=1")
    angles = segment_angles(model, traj.x[-1])
    expected = math.degrees(math.atan2(5.0 * 8.0, 5.0 * 9.81))
    # the slowest mode decays at about b / m = 1 /s: after 60 s its amplitude is e^-60 of the initial one
    np.testing.assert_allclose(angles, expected, atol=1e-8)
    assert traj.summary["towed"]["shape"] == "straight"


@pytest.mark.parametrize("name, t_end, tol", [
    # slowest decay rates: end mass ~ b_total / M_total-like pendulum mode, measured e-fold < 25 s
    ("helicopter_mass", 600, 1e-6),
    ("helicopter_parachute", 120, 1e-6),
])
def test_steady_state_matches_exact_discrete_solution_node_by_node(scenarios, name, t_end, tol):
    model, traj = run(scenarios, name, f"integrator.t_end={t_end}", "output.interval=1")
    exact = exact_steady_state(model)
    got = final_shape(model, traj)
    # positions are metres on a ~12 m rope; tol is far above round-off and far below any modelling error
    np.testing.assert_allclose(got, exact, atol=tol)


def test_end_mass_is_steeper_at_the_bottom_and_parachute_flatter(scenarios):
    for name, verdict in [("helicopter_mass", "steeper at the bottom"),
                          ("helicopter_parachute", "flatter at the bottom"),
                          ("helicopter_uniform", "straight")]:
        model, traj = run(scenarios, name, "integrator.t_end=200", "output.interval=1")
        angles = segment_angles(model, traj.x[-1])
        assert shape_verdict(angles) == verdict
        assert traj.summary["towed"]["shape"] == verdict
        if verdict != "straight":
            # the angle changes monotonically down the rope
            steps = np.diff(angles)
            assert np.all(steps < 0) if verdict.startswith("steeper") else np.all(steps > 0)


def test_exact_steady_state_angles_by_hand():
    """The end-mass rope's bottom and top angles from the tension sums, written out."""
    scene = ropesim.load_scene("scenarios/helicopter_mass.toml")
    model = build(scene)
    angles = segment_angles(model, exact_steady_state(model))
    g, v, m, b, big_m = 9.81, 8.0, 5.0, 5.0, 100.0
    bottom = math.degrees(math.atan2(b * v, big_m * g))
    top = math.degrees(math.atan2(20 * b * v, (19 * m + big_m) * g))
    assert angles[-1] == pytest.approx(bottom, abs=1e-10)
    assert angles[0] == pytest.approx(top, abs=1e-10)


def hanging_chain_scene(n, k, m, l, g, amplitude_shape, method="verlet", dt=2e-4, t_end=20.0):
    """A chain pinned at node 0, at rest in its stretched equilibrium, displaced sideways by ``amplitude_shape``."""
    below = m * g * (n - 1 - np.arange(n - 1))  # tension in segment i (nodes below it)
    lengths = l + below / k
    y = -np.concatenate([[0.0], np.cumsum(lengths)])
    points = [[float(a), float(yy)] for a, yy in zip(amplitude_shape, y)]
    text = f"""
[rope]
nodes = {n}
segment_length = {l}
stiffness = {k}
mass = {m}
[initial]
shape = "points"
points = {points}
[pinned]
nodes = [0]
[gravity]
g = {g}
[integrator]
method = "{method}"
dt = {dt}
t_end = {t_end}
[output]
interval = {dt * 10}
"""
    return ropesim.scene_from_toml(text), below, lengths


def transverse_modes(n, m, below, lengths):
    """Eigenfrequencies of the linearised transverse motion: node j is pulled towards its neighbours with
    stiffness T / L of each segment (scipy as an independent eigen-solver)."""
    free = n - 1
    stiff = np.zeros((free, free))
    for seg, (t, length) in enumerate(zip(below, lengths)):
        c = t / length
        lo, hi = seg - 1, seg  # segment seg joins node seg (free index seg-1) and node seg+1 (free index seg)
        stiff[hi, hi] += c
        if lo >= 0:
            stiff[lo, lo] += c
            stiff[lo, hi] -= c
            stiff[hi, lo] -= c
    w2, vecs = scipy.linalg.eigh(stiff, m * np.eye(free))
    return np.sqrt(w2), vecs


def test_hanging_chain_frequency_matches_linear_theory():
    """Small sideways swings of a hanging chain oscillate at the discrete chain's eigenfrequencies."""
    n, k, m, l, g = 20, 1e5, 0.1, 0.1, 9.81
    below = m * g * (n - 1 - np.arange(n - 1))
    omegas, vecs = transverse_modes(n, m, below, l + below / k)
    for mode in (0, 1):
        shape = np.concatenate([[0.0], 1e-4 * vecs[:, mode] / np.abs(vecs[:, mode]).max()])
        period = 2 * np.pi / omegas[mode]
        scene, _, _ = hanging_chain_scene(n, k, m, l, g, shape, t_end=6 * period)
        traj = ropesim.simulate(scene)
        # project the motion on the mode shape and count its zero crossings (linear interpolation)
        signal = traj.x[:, 1:, 0] @ vecs[:, mode]
        s0, s1 = signal[:-1], signal[1:]
        idx = np.flatnonzero(np.sign(s0) != np.sign(s1))
        crossings = traj.t[idx] - s0[idx] * (traj.t[idx + 1] - traj.t[idx]) / (s1[idx] - s0[idx])
        measured = 2 * np.pi / (2 * np.mean(np.diff(crossings)))
        # Verlet's phase error (h w)^2 / 24 ~ 1e-7 and the amplitude nonlinearity ~ (1e-4 / 1 m)^2: 1e-4 is ample
        assert measured == pytest.approx(omegas[mode], rel=1e-4)


def test_discrete_chain_approaches_the_continuous_bessel_modes():
    """As N grows the discrete chain's frequencies tend to omega_n = (j_0,n / 2) sqrt(g / L) of the uniform
    inextensible chain (Bernoulli, Euler); the discrete error shrinks like 1 / N."""
    g, length = 9.81, 2.0
    errors = []
    for n in (41, 81, 161):
        m, l, k = 1.0 / n, length / (n - 1), 1e9
        below = m * g * (n - 1 - np.arange(n - 1))
        omegas, _ = transverse_modes(n, m, below, l + below / k)
        # the discrete chain hangs its mass at the nodes; the continuous chain's length L = (n - 1) l
        bessel = scipy.special.jn_zeros(0, 2) / 2 * math.sqrt(g / length)
        errors.append(abs(omegas[0] / bessel[0] - 1))
    assert errors[0] < 0.02
    assert errors[1] < errors[0] * 0.6 and errors[2] < errors[1] * 0.6


def test_a_rope_with_bending_stiffness_is_no_towed_rope(scenarios):
    """The towed rope's steady state balances weight and drag alone: a rope with EI (a cantilever holds a shape
    of its own) gets no towed-rope figures in its summary or plot, as a rope with [bending] gets none."""
    from ropesim.analysis.towed import towed_end

    assert towed_end(ropesim.load_scene(scenarios / "helicopter_mass.toml")) == 0
    assert towed_end(ropesim.load_scene(scenarios / "helicopter_mass.toml", ["rope.EI=10.0"])) is None
    cantilever = ropesim.scene_from_toml(
        'dimension = 2\n[rope]\nlength = 2.0\nsegments = 4\nmass_per_length = 1.0\nEA = 1e4\nEI = 5.0\n'
        '[initial]\nshape = "line"\nstart = [0.0, 0.0]\nend = [2.0, 0.0]\n[pinned]\nnodes = [0]\nclamped = [0]\n'
        '[gravity]\n[integrator]\ndt = 0.001\nt_end = 0.01\n')
    assert towed_end(cantilever) is None
    summary = ropesim.simulate(cantilever).summary
    assert "towed" not in summary
