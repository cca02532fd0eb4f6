"""Real ropes in real air and water: physical units, Morison and viscous drag, flows, buoyancy, added mass,
bodies, axial damping, tension-only segments, and the numerics that carry them.

Every physical model is checked against a reference that shares no code with ropesim: the towed line's
discrete steady state solved with scipy and its critical angle in closed form (tests/references/towed_cable.py),
terminal speeds and drop histories, neutral buoyancy, and the Morison formula evaluated directly
(tests/references/closed_forms.py, conventions.py). The integrators' orders are fitted with all of it on.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ropesim
from ropesim.analysis.accuracy import observed_order, run_once
from ropesim.integrate.health import FLUID, INTERNAL
from ropesim.integrate.methods import METHODS
from ropesim.model.build import build
from ropesim.model.terms import accelerations, solve_accelerations
from ropesim.scene.loader import SceneError

from references.closed_forms import drop_quadratic, rope_terminal_velocity
from references.conventions import morison_node_forces
from references.towed_cable import TowedLine, critical_angle, steady_state_march

G, RHO = 9.80665, 1025.0

LINE = """
name = "{name}"
dimension = {dim}
[rope]
length = {length}
segments = {segments}
mass_per_length = {mu}
diameter = {d}
EA = {EA}
[initial]
shape = "hanging"
[pinned]
nodes = [0]
[gravity]
g = 9.80665
[fluid]
density = 1025.0
[integrator]
method = "{method}"
dt = {dt}
t_end = {t_end}
[output]
interval = {interval}
"""


def line(extra: str = "", dim: int = 2, length: float = 20.0, segments: int = 20, mu: float = 2.0, d: float = 0.02,
         EA: float = 1.0e6, method: str = "sdirk2", dt: float = 0.02, t_end: float = 1.0, interval: float = 1.0,
         sets=()):
    text = LINE.format(name="line", dim=dim, length=length, segments=segments, mu=mu, d=d, EA=EA, method=method,
                       dt=dt, t_end=t_end, interval=interval) + extra
    return ropesim.scene_from_toml(text, overrides=list(sets))


# ------------------------------------------------------------------------------------- physical units


def test_physical_units_give_the_trajectory_of_the_per_node_form_they_map_to():
    """length 6 m in 12 segments, 0.8 kg/m, EA 6 kN: l = 0.5 m, k = 12 kN/m, m = 0.4 kg, the ends 0.2 kg."""
    common = """
[initial]
shape = "line"
start = [0.0, 0.0]
end = [4.0, -4.0]
[pinned]
nodes = [0]
[gravity]
g = 9.81
[drag]
b = 0.3
[integrator]
method = "verlet"
dt = 0.0005
t_end = 0.5
"""
    physical = ropesim.scene_from_toml("[rope]\nlength = 6.0\nsegments = 12\nmass_per_length = 0.8\nEA = 6000.0\n"
                                       "compression = true\n" + common)
    per_node = ropesim.scene_from_toml("[rope]\nnodes = 13\nsegment_length = 0.5\nstiffness = 12000.0\nmass = 0.4\n"
                                       + common + "[[overrides]]\nindex = 0\nmass = 0.2\n"
                                                  "[[overrides]]\nindex = -1\nmass = 0.2\n")
    assert physical.rope.nodes == 13 and physical.rope.stiffness == 12000.0 and physical.rope.mass == 0.4
    a, b = ropesim.simulate(physical), ropesim.simulate(per_node)
    assert a.summary["status"] == b.summary["status"] == "completed"
    assert np.array_equal(a.x, b.x) and np.array_equal(a.v, b.v)


def test_a_resolved_physical_rope_shows_both_forms_and_loads_again():
    scene = line(dim=3)
    text = ropesim.scene_to_toml(scene)
    for key in ("length", "segments", "mass_per_length", "EA", "nodes", "segment_length", "stiffness", "mass",
                "compression"):
        assert f"\n{key} = " in text, key
    assert ropesim.scene_from_toml(text) == scene
    assert scene.rope.compression is False   # a real rope goes slack


def test_diameter_and_density_give_the_mass_per_metre():
    rope = ropesim.scene_from_toml(LINE.format(name="x", dim=2, length=10.0, segments=10, mu=1.0, d=0.02, EA=1e5,
                                               method="verlet", dt=0.001, t_end=0.1, interval=0.1)
                                   .replace("mass_per_length = 1.0\n", "density = 1140.0\n")).rope
    assert rope.mass_per_length == pytest.approx(1140.0 * math.pi * 0.02 ** 2 / 4, rel=1e-15)
    assert rope.mass == pytest.approx(rope.mass_per_length, rel=1e-15)   # l = 1 m


@pytest.mark.parametrize("change, key, fragment", [
    ({"EA": None}, "rope.EA", "missing: a rope in physical units needs length, EA"),
    ({"segments": None}, "rope.segments", "missing: how many segments"),
    ({"mass_per_length": None}, "rope.mass_per_length", "missing: give mass_per_length, or diameter and density"),
    ({"nodes": 7}, "rope.nodes", "7 nodes contradict segments = 20"),
    ({"stiffness": 1.0}, "rope.stiffness", "contradicts the physical form, which gives 1e+06"),
    ({"mass_per_length": None, "density": 1000.0, "diameter": None}, "rope.diameter", "missing: with density"),
    ({"density": 1000.0}, "rope.mass_per_length", "contradicts density x pi d^2 / 4"),
    ({"segments": 2, "closed": True}, "rope.segments", "a closed loop needs at least 3"),
])
def test_contradictory_or_incomplete_physical_ropes_are_refused_in_one_line(change, key, fragment):
    rope = {"length": 20.0, "segments": 20, "mass_per_length": 2.0, "diameter": 0.02, "EA": 1.0e6}
    for k, v in change.items():
        if v is None:
            rope.pop(k)
        else:
            rope[k] = v
    text = "[rope]\n" + "".join(f"{k} = {str(v).lower() if isinstance(v, bool) else v}\n" for k, v in rope.items())
    text += '[initial]\nshape = "hanging"\n[integrator]\ndt = 0.001\nt_end = 0.1\n'
    if rope.get("closed"):
        text = text.replace('shape = "hanging"', 'shape = "points"\npoints = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]')
    with pytest.raises(SceneError) as info:
        ropesim.scene_from_toml(text, source="t.toml")
    message = str(info.value)
    assert "\n" not in message and f"t.toml: {key}: " in message and fragment in message, message


# ------------------------------------------------------------------------------- bad fluid input


@pytest.mark.parametrize("extra, key, fragment", [
    ("[fluid_drag]\ncd_normal = -1.0\n", "fluid_drag.cd_normal", "must be a number >= 0"),
    ("[fluid_drag]\ncd_tangential = 0.1\n", "fluid_drag.cd_normal", "missing"),
    ("[added_mass]\nca_normal = -0.5\n", "added_mass.ca_normal", "must be a number >= 0"),
    ("[viscous_drag]\nb_normal = 1.0\n", "viscous_drag.b_tangential", "missing"),
    ("[flow]\nvelocity = [1.0, 0.0]\n", "flow", "moves the rope only through drag"),
    ("[fluid_drag]\ncd_normal = 1.2\n[flow]\nprofile = \"power_law\"\nvelocity = [1.0, 0.0]\nexponent = 0.14\n",
     "flow.reference_height", "missing: profile = 'power_law' needs velocity, reference_height, exponent"),
    ("[fluid_drag]\ncd_normal = 1.2\n[flow]\nprofile = \"table\"\nheights = [-30.0, 0.0]\n"
     "velocities = [[1.0, 0.0]]\n", "flow.velocities", "has 1 rows but flow.heights has 2"),
    ("[fluid_drag]\ncd_normal = 1.2\n[flow]\nprofile = \"table\"\nheights = [0.0, -30.0]\n"
     "velocities = [[1.0, 0.0], [0.0, 0.0]]\n", "flow.heights", "must increase strictly"),
    ("[fluid_drag]\ncd_normal = 1.2\n[flow]\nprofile = \"table\"\nheights = [-10.0, 0.0]\n"
     "velocities = [[1.0, 0.0], [0.0, 0.0]]\n", "flow.heights", "the rope starts at y = -20 to 0 m"),
    ("[fluid_drag]\ncd_normal = 1.2\n[flow]\nvelocity = [1.0, 0.0]\nexponent = 0.14\n", "flow.exponent",
     "is not used by profile = 'uniform'"),
    ("[[bodies]]\nnode = 40\nmass = 1.0\n", "bodies.0.node", "node index 40 is past the rope's end"),
    ("[[bodies]]\nnode = 3\n", "bodies.0", "has no mass, volume or cd_area"),
    ("[[bodies]]\nnode = 3\nmass = 1.0\nca = 1.0\n", "bodies.0.ca", "needs the body's volume"),
    ("[[bodies]]\nnode = 3\nmass = 1.0\n[[bodies]]\nnode = 3\nmass = 2.0\n", "bodies.1.node",
     "node 3 already carries bodies.0"),
])
def test_bad_fluid_input_is_one_line_naming_the_key(extra, key, fragment):
    with pytest.raises(SceneError) as info:
        line(extra)
    message = str(info.value)
    assert "\n" not in message and f": {key}: " in message and fragment in message, message


def test_fluid_terms_need_a_fluid_and_a_diameter():
    no_fluid = LINE.format(name="x", dim=2, length=10.0, segments=10, mu=1.0, d=0.02, EA=1e5, method="verlet",
                           dt=0.001, t_end=0.1, interval=0.1).replace("[fluid]\ndensity = 1025.0\n", "")
    with pytest.raises(SceneError, match="fluid_drag: needs a \\[fluid\\] table"):
        ropesim.scene_from_toml(no_fluid + "[fluid_drag]\ncd_normal = 1.0\n")
    no_diameter = LINE.format(name="x", dim=2, length=10.0, segments=10, mu=1.0, d=0.02, EA=1e5, method="verlet",
                              dt=0.001, t_end=0.1, interval=0.1).replace("diameter = 0.02\n", "")
    with pytest.raises(SceneError, match="rope.diameter: missing: \\[buoyancy\\] acts on the rope's diameter"):
        ropesim.scene_from_toml(no_diameter + "[buoyancy]\n")


# ------------------------------------------------------------------------ forces against the formulas


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2 ** 31), dim=st.sampled_from([2, 3]), n=st.integers(2, 9),
       cd_n=st.floats(0.0, 2.0), cd_t=st.floats(0.0, 0.2))
def test_morison_drag_is_the_formula_evaluated_directly(seed, dim, n, cd_n, cd_t):
    """Random positions, velocities and a uniform flow: the kernel's drag force on every node equals the
    conventions' plain-numpy Morison formula (tangent = chord through the neighbours, unstretched L_i)."""
    rng = np.random.default_rng(seed)
    l0, d, rho = 0.7, 0.02, 1025.0
    flow = rng.normal(size=dim)
    text = (f"dimension = {dim}\n[rope]\nlength = {l0 * (n - 1)}\nsegments = {n - 1}\nmass_per_length = 1.5\n"
            f"diameter = {d}\nEA = 1e5\n[initial]\nshape = \"hanging\"\n[fluid]\ndensity = {rho}\n"
            f"[fluid_drag]\ncd_normal = {cd_n!r}\ncd_tangential = {cd_t!r}\n[flow]\nvelocity = {[float(f) for f in flow]}\n"
            f"[integrator]\ndt = 0.001\nt_end = 0.1\n")
    model = build(ropesim.scene_from_toml(text))
    x = rng.normal(scale=2.0, size=(dim, n))
    v = rng.normal(size=(dim, n))
    total = np.zeros((dim, n))
    model.kernel(accelerations)(x, v, total, model.params, 0.0)
    springs = np.zeros((dim, n))
    model.kernel(accelerations)(x, flow[:, None] + 0.0 * v, springs, model.params, 0.0)   # at zero relative velocity: no drag
    got = (total - springs) * model.mass
    want = morison_node_forces(x.T, v.T, [l0] * (n - 1), d, rho, cd_n, cd_t, flow=flow).T
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * (1.0 + np.abs(want).max()))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2 ** 31), dim=st.sampled_from([2, 3]))
def test_added_mass_solves_the_mass_matrix_equation(seed, dim):
    """a = M^-1 F with M = m I + rho V (Ca_n (I - q q^T) + Ca_t q q^T): check M a = F node by node, and the
    power returned is that of the fluid's inertial force m a - F."""
    rng = np.random.default_rng(seed)
    n = 6
    text = (f"dimension = {dim}\n[rope]\nlength = 5.0\nsegments = {n - 1}\nmass_per_length = 1.5\ndiameter = 0.05\n"
            f"EA = 1e5\n[initial]\nshape = \"hanging\"\n[fluid]\ndensity = 1025.0\n[added_mass]\n"
            f"ca_normal = 1.0\nca_tangential = 0.3\n[integrator]\ndt = 0.001\nt_end = 0.1\n")
    model = build(ropesim.scene_from_toml(text))
    x = rng.normal(size=(dim, n))
    v = rng.normal(size=(dim, n))
    force = rng.normal(size=(dim, n))
    acc = force / model.mass
    power = model.kernel(solve_accelerations)(x, v, acc, model.params)
    volume = math.pi * 0.05 ** 2 / 4 * np.where(np.arange(n) % (n - 1) == 0, 0.5, 1.0)
    for i in range(n):
        lo, hi = max(i - 1, 0), min(i + 1, n - 1)
        q = (x[:, hi] - x[:, lo]) / np.linalg.norm(x[:, hi] - x[:, lo])
        mass_matrix = model.mass[i] * np.eye(dim) + 1025.0 * volume[i] * (1.0 * (np.eye(dim) - np.outer(q, q))
                                                                           + 0.3 * np.outer(q, q))
        np.testing.assert_allclose(mass_matrix @ acc[:, i], force[:, i], rtol=1e-12, atol=1e-12)
    assert power == pytest.approx(np.sum((model.mass * acc - force) * v), rel=1e-12, abs=1e-12)


# ---------------------------------------------------------------------------- physics against references


def test_a_towed_line_settles_on_the_independently_solved_discrete_steady_state():
    """A 20 m line in a 1.5 m/s current with normal and tangential drag, buoyancy, stretch and an end body
    (10 kg, 2 l, CdA 0.05 m^2): its steady state is references.towed_cable.steady_state_march's, a scipy march
    from the free end that shares no code with ropesim, to 1e-9 m and 1e-9 of the tension (both are exact
    discrete steady states; what is left is the transient, decayed to round-off by t = 300 s)."""
    body = "[[bodies]]\nnode = -1\nmass = 10.0\nvolume = 0.002\ncd_area = 0.05\n"
    extra = ("[flow]\nvelocity = [-1.5, 0.0]\n[fluid_drag]\ncd_normal = 1.2\ncd_tangential = 0.02\n[buoyancy]\n"
             + body)
    traj = ropesim.simulate(line(extra, t_end=300.0, interval=300.0))
    reference = steady_state_march(TowedLine.uniform(20.0, 20, mu=2.0, d=0.02, EA=1e6, rho=RHO, g=G, cd_n=1.2,
                                                     cd_t=0.02, u=(1.5, 0.0), end_mass=10.0, end_volume=0.002,
                                                     end_area=0.05, end_cd=1.0))
    np.testing.assert_allclose(traj.x[-1], reference.x, atol=1e-9)
    np.testing.assert_allclose(traj.tension[-1], reference.T, rtol=1e-9)
    assert traj.summary["tension"]["start_N"] == pytest.approx(reference.T[0], rel=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("cd_t", [0.0, 0.05])
def test_without_an_end_body_a_towed_line_streams_straight_at_the_critical_angle(cd_t):
    """sin(phi_c) / cos^2(phi_c) = rho Cd_n d U^2 / (2 w) (references.towed_cable.critical_angle); tangential
    drag only raises the tension, it does not turn the line."""
    extra = f"[flow]\nvelocity = [-1.0, 0.0]\n[fluid_drag]\ncd_normal = 1.2\ncd_tangential = {cd_t}\n[buoyancy]\n"
    traj = ropesim.simulate(line(extra, t_end=300.0, interval=300.0))
    segments = np.diff(traj.x[-1], axis=0)
    angles = np.arctan2(-segments[:, 0], -segments[:, 1])
    w = (2.0 - RHO * math.pi * 0.02 ** 2 / 4) * G
    np.testing.assert_allclose(angles, critical_angle(1.0, w, RHO, 1.2, 0.02), rtol=1e-9)


@pytest.mark.slow
def test_a_rope_falling_broadside_reaches_the_terminal_speed():
    """A horizontal rope (free) falls at sqrt(w / (rho Cd_n d / 2)), its length and segmentation irrelevant."""
    text = ("[rope]\nlength = 4.0\nsegments = 8\nmass_per_length = 0.6\ndiameter = 0.01\nEA = 1e5\n[initial]\n"
            "shape = \"line\"\nstart = [0.0, 0.0]\nend = [4.0, 0.0]\n[gravity]\ng = 9.80665\n[fluid]\n"
            "density = 1025.0\n[fluid_drag]\ncd_normal = 1.1\n[buoyancy]\n[integrator]\nmethod = \"verlet\"\n"
            "dt = 0.001\nt_end = 20.0\n[output]\ninterval = 20.0\n")
    traj = ropesim.simulate(ropesim.scene_from_toml(text))
    expected = rope_terminal_velocity(0.6, 0.01, RHO, G, cd_n=1.1)
    np.testing.assert_allclose(-traj.v[-1][:, 1], expected, rtol=1e-6)
    np.testing.assert_allclose(traj.v[-1][:, 0], 0.0, atol=1e-9)


@pytest.mark.slow
def test_a_body_dropped_in_water_follows_the_tanh_history_with_its_added_mass():
    """Two 2 kg bodies (1 l, CdA 0.01 m^2, Ca 0.5 each) on a nearly massless 1 cm rope, falling side by side:
    v(t) = v_t tanh(t / tau) with the inertial mass m + rho Ca V and the weight less buoyancy
    (references.closed_forms.drop_quadratic)."""
    text = ("[rope]\nlength = 0.01\nsegments = 1\nmass_per_length = 1e-4\ndiameter = 1e-4\nEA = 100.0\n"
            "[initial]\nshape = \"line\"\nstart = [0.0, 0.0]\nend = [0.01, 0.0]\n[gravity]\ng = 9.80665\n"
            "[fluid]\ndensity = 1025.0\n[buoyancy]\n[[bodies]]\nnode = 0\nmass = 2.0\nvolume = 0.001\n"
            "cd_area = 0.01\nca = 0.5\n[[bodies]]\nnode = 1\nmass = 2.0\nvolume = 0.001\ncd_area = 0.01\nca = 0.5\n"
            "[integrator]\nmethod = \"pefrl\"\ndt = 0.0002\nt_end = 2.0\n[output]\ninterval = 0.25\n")
    traj = ropesim.simulate(ropesim.scene_from_toml(text))
    mass = 2.0 + 5e-7 + RHO * 0.5 * 0.001           # body, half the rope, added mass
    weight = (2.0 + 5e-7 - RHO * (0.001 + math.pi * 1e-8 / 4 * 0.005)) * G
    speed, _ = drop_quadratic(traj.t, weight, mass, RHO, 1.0, 0.01)
    np.testing.assert_allclose(-traj.v[:, 0, 1], speed, rtol=2e-4)   # the rope's tiny drag and rounding


@pytest.mark.parametrize("method", [m if m == "rk4" else pytest.param(m, marks=pytest.mark.slow) for m in METHODS])
def test_a_neutrally_buoyant_rope_stays_put(method):
    """mu = rho pi d^2 / 4: weight and buoyancy cancel on every node, drag and springs are zero at rest."""
    mu = RHO * math.pi * 0.02 ** 2 / 4
    text = ("[rope]\nlength = 6.0\nsegments = 6\n" f"mass_per_length = {mu!r}\n" "diameter = 0.02\nEA = 1e5\n"
            "[initial]\nshape = \"points\"\npoints = [[0, 0], [1, 0], [1, -1], [2, -1], [2, -2], [3, -2], "
            "[3.5, -2.8]]\n[gravity]\ng = 9.80665\n[fluid]\ndensity = 1025.0\n[fluid_drag]\ncd_normal = 1.2\n"
            "[buoyancy]\n[added_mass]\nca_normal = 1.0\n[integrator]\n" f"method = \"{method}\"\n"
            "dt = 0.001\nt_end = 2.0\n")
    traj = ropesim.simulate(ropesim.scene_from_toml(text))   # every segment at rest length but a slack last one
    assert traj.summary["status"] == "completed" and traj.frames == 201
    assert np.abs(traj.x[-1] - traj.x[0]).max() < 1e-12 and np.abs(traj.v).max() < 1e-12


ACCELERATING = """
dimension = 3
[rope]
length = 2.0
segments = 4
diameter = 0.05
density = 2050.0
EA = 1e5
[initial]
shape = "line"
start = [0.0, 0.0, 0.0]
end = [1.0, 1.0, 0.0]
[integrator]
method = "rk4"
dt = 1e-3
t_end = 3.0
[output]
interval = 0.1
[gravity]
g = 9.81
[fluid]
density = 1025.0
[flow]
velocity = [1.0, 0.0, 0.5]
ramp_time = 3.0
[added_mass]
ca_normal = 1.0
ca_tangential = 0.3
"""


@pytest.mark.slow
@pytest.mark.parametrize("buoyancy", [True, False])
def test_a_rope_in_accelerating_water_follows_morisons_inertia_term(buoyancy):
    """A straight free rope twice as dense as the water, no drag, in a flow ramping in, U r(t): every node has the
    same mass, volume and added mass per length, so the rope translates rigidly and each node's velocity is, split
    along the rope's direction q (normal n, tangential t),

        v(t) = sum over n, t of P [(rho V b - m) g t y + (b + Ca) rho V U r(t)] / (m + Ca rho V),

    b = 1 with [buoyancy] (its weight's share and the pressure gradient rho V dU/dt), 0 without (the added
    mass's part alone). rk4 integrates this to round-off."""
    scene = ropesim.scene_from_toml(ACCELERATING + ("[buoyancy]\n" if buoyancy else ""))
    traj = ropesim.simulate(scene)
    t = np.asarray(traj.t)
    b, rho, g = (1.0 if buoyancy else 0.0), 1025.0, 9.81
    q = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
    along, normal = np.outer(q, q), np.eye(3) - np.outer(q, q)
    ramp = 0.5 * (1.0 - np.cos(np.pi * t / 3.0))
    expected = np.zeros((len(t), 3))
    for proj, ca in ((normal, 1.0), (along, 0.3)):   # per unit volume: m = 2 rho, Ca rho, (b + Ca) rho
        push = np.outer(t, (b * rho - 2.0 * rho) * g * np.array([0.0, 1.0, 0.0])) + np.outer(
            ramp, (b + ca) * rho * np.array([1.0, 0.0, 0.5]))
        expected += push @ proj.T / (2.0 * rho + ca * rho)
    np.testing.assert_allclose(traj.v, np.broadcast_to(expected[:, None, :], traj.v.shape), rtol=0, atol=1e-11)
    ledger = traj.summary["energy_ledger"]   # the fluid's work (the push, the added mass against the sinking)
    assert ledger["relative_residual"] < 1e-12 and ledger["fluid_work_J"] != 0.0   # closes the balance


def test_the_water_pushes_only_while_it_accelerates():
    """After the ramp (and in a steady flow) the inertia term is zero: the same rope keeps the velocity it had at
    the ramp's end, its sinking aside."""
    scene = ropesim.scene_from_toml(ACCELERATING + "[buoyancy]\n", overrides=["integrator.t_end=5.0",
                                                                               "gravity.g=0.0"])
    traj = ropesim.simulate(scene)
    after = np.asarray(traj.t) >= 3.0
    np.testing.assert_allclose(traj.v[after], np.broadcast_to(traj.v[np.argmax(after)], traj.v[after].shape),
                               rtol=0, atol=1e-13)
    assert np.abs(traj.v[np.argmax(after)]).max() > 0.5


# ----------------------------------------------------------------------------------------- the numerics

FLUID_ORDER = """
dimension = 3
[rope]
length = 10.0
segments = 10
mass_per_length = 1.0
diameter = 0.03
EA = 4.0e4
axial_damping = 50.0
compression = true
[initial]
shape = "line"
start = [0.0, 0.0, 0.0]
end = [6.0, -8.0, 0.0]
velocity = [0.0, 0.0, 0.3]
[pinned]
nodes = [0]
[gravity]
g = 9.81
[fluid]
density = 1025.0
[flow]
velocity = [0.8, 0.0, 0.4]
ramp_time = 1.0
[fluid_drag]
cd_normal = 1.2
cd_tangential = 0.05
[buoyancy]
[added_mass]
ca_normal = 1.0
ca_tangential = 0.2
[[bodies]]
node = -1
mass = 2.0
volume = 0.001
cd_area = 0.05
ca = 0.5
[integrator]
dt = 0.001
t_end = 0.5
"""
FLUID_LADDERS = {"symplectic_euler": [0.004, 0.002, 0.001, 0.0005], "verlet": [0.004, 0.002, 0.001, 0.0005],
                 "yoshida4": [0.004, 0.002, 0.001], "pefrl": [0.008, 0.004, 0.002], "rk4": [0.004, 0.002, 0.001],
                 "sdirk2": [0.004, 0.002, 0.001, 0.0005], "galpha": [0.004, 0.002, 0.001, 0.0005]}


@pytest.fixture(scope="module")
def fluid_reference():
    scene = ropesim.scene_from_toml(FLUID_ORDER)
    return scene, run_once(scene, "pefrl", 0.0005 / 16).x


@pytest.mark.slow
@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_keeps_its_order_with_fluid_forces_a_ramped_flow_and_added_mass(method, fluid_reference):
    """Quadratic drag (normal and tangential) on the velocity relative to a flow that ramps up through the run,
    buoyancy, added mass (normal and axial), axial damping, an end body, in 3-D: the fitted order of the final
    positions' error is the method's. (Smooth forces: a slack segment's kink, or a ramp ending inside the run,
    would cap the fourth-order methods near 3.) Tolerance 0.3: rk4's fit is 4.2 on this ladder."""
    scene, reference = fluid_reference
    errors = [float(np.max(np.linalg.norm(run_once(scene, method, dt).x - reference, axis=0)))
              for dt in FLUID_LADDERS[method]]
    order, _ = observed_order(FLUID_LADDERS[method], errors, [True] * len(errors))
    assert abs(order - METHODS[method].order) < 0.3, (method, order, errors)


@pytest.mark.slow
@pytest.mark.parametrize("method", list(METHODS))
def test_the_ledger_books_the_fluid_and_the_damping(method):
    """The fluid's work (drag against the current, added mass) and the axial damping's balance the energy:
    the residual is the integration error, a small fraction of what flowed; damping only takes energy out."""
    scene = ropesim.scene_from_toml(FLUID_ORDER, overrides=[f"integrator.method={method}", "integrator.dt=0.0005",
                                                            "integrator.t_end=2.0"])
    traj = ropesim.simulate(scene)
    assert traj.summary["status"] == "completed"
    ledger = traj.summary["energy_ledger"]
    assert ledger["fluid_work_J"] != 0.0 and ledger["internal_work_J"] < 0.0
    assert ledger["relative_residual"] < (2e-3 if METHODS[method].order < 2 else 1e-4), ledger


@pytest.mark.slow
def test_the_stability_bound_holds_with_fluid_forces():
    """Just below the predicted bound a run in water stays sane, well above it blows up (verlet)."""
    from ropesim.analysis.stability import predicted_dt

    extra = "[flow]\nvelocity = [-1.5, 0.0]\n[fluid_drag]\ncd_normal = 1.2\ncd_tangential = 0.02\n[buoyancy]\n"
    scene = line(extra + "[added_mass]\nca_normal = 1.0\n", method="verlet", t_end=10.0, interval=10.0)
    bound = predicted_dt(build(scene), "verlet")
    below = ropesim.simulate(dataclasses.replace(scene, integrator=dataclasses.replace(scene.integrator,
                                                                                        dt=0.9 * bound)))
    above = ropesim.simulate(dataclasses.replace(scene, integrator=dataclasses.replace(scene.integrator,
                                                                                        dt=1.2 * bound)))
    assert below.summary["status"] == "completed" and above.summary["status"] == "blew_up"


def test_undeclared_fluid_terms_leave_the_ledger_columns_at_zero():
    traj = ropesim.simulate(ropesim.load_scene("helicopter_mass", ["integrator.t_end=0.2"]))
    ledger = traj.summary["energy_ledger"]
    assert ledger["fluid_work_J"] == ledger["internal_work_J"] == ledger["seabed_work_J"] == 0.0
    assert FLUID == 3 and INTERNAL == 4   # the columns' places in ledger.npz and in saved frames


# ------------------------------------------------------------------------------------- built-in scenes


def test_helicopter_crosswind_settles_on_the_towed_line_turned_into_the_relative_wind():
    """The sling trails in the vertical plane through the relative wind (20, 0, -5) m/s, turned 14.04 degrees
    from the track (references.towed_cable.crosswind_plane), with the 2-D steady state of steady_state_march in
    that plane: top tension, the hook's position and azimuth within 1e-3 after 300 s (the swing decayed)."""
    from references.towed_cable import crosswind_plane

    speed, azimuth = crosswind_plane(20.0, 5.0)
    reference = steady_state_march(TowedLine.uniform(20.0, 40, mu=0.13, d=0.016, EA=5e6, rho=1.225, g=9.81,
                                                     cd_n=1.2, cd_t=0.015, u=(speed, 0.0), end_mass=25.0,
                                                     end_area=0.05, end_cd=1.0))
    traj = ropesim.simulate(ropesim.load_scene("helicopter_crosswind", ["integrator.t_end=300", "integrator.dt=0.01",
                                                                       "output.interval=300"]))
    assert traj.summary["status"] == "completed"
    hook = traj.x[-1][-1] - traj.x[-1][0]
    trailing = math.hypot(hook[0], hook[2])
    assert math.atan2(hook[2], -hook[0]) == pytest.approx(azimuth, rel=1e-3)
    assert trailing == pytest.approx(-reference.x[-1][0], rel=1e-3)
    assert hook[1] == pytest.approx(reference.x[-1][1], rel=1e-4)
    assert traj.tension[-1][0] == pytest.approx(reference.T[0], rel=1e-3)
