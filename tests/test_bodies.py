"""Rigid bodies in systems: their rotation, their pendulum modes, fixed and driven bodies, and their state.

References are independent of the model: the torque-free rotation of an axisymmetric body in closed form
(precession about the angular momentum at |L| / I1 and spin about the symmetry axis at w3 (I1 - I3) / I1), and
the two small-angle modes of a body on a string from the Lagrangian's 2 x 2 mass and stiffness matrices, solved
by scipy.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.spatial.transform import Rotation

import ropesim
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.model.bodies import free_body_state
from ropesim.model.build import build
from ropesim.model.energy import energy_terms
from ropesim.model.rotation import quaternion_from_angles, quaternion_from_matrix, rotation_matrix
from ropesim.scene.loader import scene_from_toml

# ------------------------------------------------------------------------------ torque-free rotation

I1, I3 = 2.0, 5.0
SPIN_ANGLES = [20.0, -35.0, 50.0]
SPIN_RATE = np.radians([40.0, 0.0, 90.0])   # world axes, at t = 0


def spinning_top(method: str, dt: float, t_end: float = 5.0) -> str:
    """An axisymmetric body (I1 = I2 != I3) spinning in zero gravity; its one line, slack and attached at its centre
    of gravity, puts neither force nor moment on it."""
    rates = ", ".join(repr(float(r)) for r in np.degrees(SPIN_RATE))
    return f"""
name = "spinning_top"
dimension = 3
[line_types.thread]
mass_per_length = 0.01
EA = 100.0
[[points]]
id = "anchor"
position = [-1.0, 0.0, 0.0]
[[points]]
id = "pivot"
body = "top"
position = [0.0, 0.0, 0.0]
[[bodies]]
id = "top"
position = [0.0, 0.0, 0.0]
orientation = {SPIN_ANGLES}
mass = 3.0
inertia = [{I1}, {I1}, {I3}]
angular_velocity = [{rates}]
[[lines]]
id = "slack"
type = "thread"
start = "anchor"
end = "pivot"
length = 3.0
segments = 3
[integrator]
method = "{method}"
dt = {dt}
t_end = {t_end}
"""


def torque_free_orientation(t: float) -> np.ndarray:
    """R(t) = exp(t |L| / I1 [L^]x) R0 exp(t w3 (I1 - I3) / I1 [e3]x), w3 the body-axis spin at t = 0."""
    r0 = rotation_matrix(quaternion_from_angles(SPIN_ANGLES))
    body_inertia = np.diag([I1, I1, I3])
    momentum = r0 @ body_inertia @ r0.T @ SPIN_RATE
    w3 = (r0.T @ SPIN_RATE)[2]
    precession = Rotation.from_rotvec(t / I1 * momentum).as_matrix()
    spin = Rotation.from_rotvec(t * w3 * (I1 - I3) / I1 * np.array([0.0, 0.0, 1.0])).as_matrix()
    return precession @ r0 @ spin


def angular_momentum_and_energy(traj) -> tuple[np.ndarray, np.ndarray]:
    r = rotation_matrix(traj.body_q[:, 0])
    inertia = np.einsum("fij,jk,flk->fil", r, np.diag([I1, I1, I3]), r)
    w = traj.body_w[:, 0]
    momentum = np.einsum("fij,fj->fi", inertia, w)
    return momentum, 0.5 * np.einsum("fi,fi->f", w, momentum)


@pytest.mark.parametrize("method, order", [("verlet", 2), ("rk4", 4), ("yoshida4", 4)])
def test_torque_free_rotation_against_its_closed_form_at_the_methods_order(method, order):
    """The orientation after 5 s (about 1.3 turns) against the closed form: the error falls at the method's order
    when dt halves; kinetic energy and angular momentum are kept to the method's order; the quaternion stays a unit
    quaternion to round-off and the body does not move off its place."""
    errors, drifts = [], []
    for dt in (0.02, 0.01):
        traj = ropesim.simulate(scene_from_toml(spinning_top(method, dt)))
        errors.append(np.abs(rotation_matrix(traj.body_q[-1, 0]) - torque_free_orientation(traj.t[-1])).max())
        momentum, energy = angular_momentum_and_energy(traj)
        drifts.append(np.abs(momentum - momentum[0]).max())
        assert np.abs(energy - energy[0]).max() < 1e-6 * energy[0]
        assert np.abs(np.linalg.norm(traj.body_q[:, 0], axis=1) - 1.0).max() < 1e-15
        assert np.abs(traj.body_x).max() == 0.0 and np.abs(traj.body_v).max() == 0.0
    observed = math.log2(errors[0] / errors[1])
    assert abs(observed - order) < 0.15, (errors, observed)
    assert errors[1] < (5e-5 if order == 2 else 3e-8)
    assert drifts[1] < drifts[0] / 2 ** (order - 0.5)


# ------------------------------------------------------------------------------ pendulum modes

def body_on_a_string(mode: int, method: str = "verlet") -> tuple[str, float]:
    """A 100 kg body hanging 0.5 m below its hook on a 2 m string, in 2-D, started in small-angle mode ``mode`` of
    the closed form; (its scene, that mode's angular frequency [rad/s])."""
    mass, inertia, arm, length, g = 100.0, 10.0, 0.5, 2.0, 9.81
    mass_matrix = np.array([[mass * length ** 2, mass * length * arm], [mass * length * arm, mass * arm ** 2 + inertia]])
    stiffness = np.array([[mass * g * length, 0.0], [0.0, mass * g * arm]])
    w2, shapes = eigh(stiffness, mass_matrix)
    string_angle, body_angle = shapes[:, mode] / np.abs(shapes[:, mode]).max() * math.radians(1.0)
    hook = length * np.array([math.sin(string_angle), -math.cos(string_angle)])
    cog = hook + arm * np.array([math.sin(body_angle), -math.cos(body_angle)])
    unstretched = length * (1.0 - mass * g / 1.0e7)   # the string's length under the body's weight is 2 m
    scene = f"""
name = "body_on_a_string"
dimension = 2
[line_types.string]
mass_per_length = 0.05
EA = 1.0e7
compression = true
[[points]]
id = "top"
position = [0.0, 0.0]
[[points]]
id = "hook"
body = "bob"
position = [0.0, {arm}]
[[bodies]]
id = "bob"
position = [{float(cog[0])!r}, {float(cog[1])!r}]
orientation = [{math.degrees(body_angle)!r}]
mass = {mass}
inertia = [{inertia}]
[[lines]]
id = "string"
type = "string"
start = "top"
end = "hook"
length = {unstretched!r}
segments = 2
[gravity]
g = {g}
[integrator]
method = "{method}"
dt = 2.0e-5
t_end = 12.0
[output]
interval = 2.0e-4
"""
    return scene, math.sqrt(w2[mode])


def test_the_summarys_final_energy_is_the_bodys_at_the_last_frame():
    """summary.json's final energy takes the free body's state at the run's last frame (it took its initial pose and
    twist): a quarter period after starting at rest at the swing's end, its kinetic energy is 1/2 m v^2 + 1/2 I w^2
    of the last frame's velocity and angular velocity, and its potential energy m g y of the last frame's place."""
    text, omega = body_on_a_string(0)
    quarter = 0.5 * math.pi / omega
    text = text.replace("t_end = 12.0", f"t_end = {quarter!r}").replace("interval = 2.0e-4", "interval = 2.0e-2")
    traj = ropesim.simulate(scene_from_toml(text))
    final = traj.summary["final_energy_J"]
    v, w = traj.body_v[-1, 0], traj.body_w[-1, 0]
    kinetic = 0.5 * 100.0 * float(v @ v) + 0.5 * 10.0 * float(w[2] ** 2)
    assert kinetic > 1e-3 and final["body kinetic"] == pytest.approx(kinetic, rel=1e-12)
    assert final["body gravity"] == pytest.approx(100.0 * 9.81 * float(traj.body_x[-1, 0, 1]), rel=1e-12)


@pytest.mark.parametrize("mode", [0, 1])
def test_a_body_on_a_string_swings_in_both_small_angle_modes_of_the_closed_form(mode):
    """Started in one mode, the string swings at that mode's frequency: within 0.2 % (the string's 0.1 kg, which
    the two-degree-of-freedom closed form leaves out, lowers the second mode by 0.08 %)."""
    text, omega = body_on_a_string(mode)
    traj = ropesim.simulate(scene_from_toml(text))
    assert traj.summary["status"] == "completed"
    hook = traj.x[:, -1]
    angle = np.arctan2(hook[:, 0], -hook[:, 1])
    sign = np.sign(angle)
    k = np.flatnonzero(sign[1:] != sign[:-1])
    crossings = traj.t[k] - angle[k] * (traj.t[k + 1] - traj.t[k]) / (angle[k + 1] - angle[k])
    measured = math.pi / np.mean(np.diff(crossings))
    assert len(crossings) >= 6
    assert abs(measured / omega - 1.0) < 2e-3, (measured, omega)


# ------------------------------------------------------------------------------ fixed and driven bodies

FRAME = """
name = "frames"
dimension = 3
[line_types.rope]
mass_per_length = 0.5
EA = 1.0e5
[[bodies]]
id = "deck"
kind = "KIND"
position = [0.0, 0.0, 0.0]
orientation = [10.0, 20.0, 30.0]
MOTION
[[points]]
id = "bollard"
body = "deck"
position = [2.0, 1.0, -1.0]
[[points]]
id = "weight"
kind = "free"
mass = 20.0
position = [2.0, -6.0, -1.0]
[[lines]]
id = "hanging"
type = "rope"
start = "bollard"
end = "weight"
length = 6.0
segments = 6
[gravity]
[integrator]
method = "rk4"
dt = 1.0e-3
t_end = 2.0
"""


def test_a_fixed_body_holds_its_points_where_its_pose_puts_them():
    scene = scene_from_toml(FRAME.replace("KIND", "fixed").replace("MOTION", ""))
    traj = ropesim.simulate(scene)
    r0 = rotation_matrix(quaternion_from_angles([10.0, 20.0, 30.0]))
    expected = r0 @ np.array([2.0, 1.0, -1.0])
    assert np.array_equal(traj.x[:, 0], np.broadcast_to(traj.x[0, 0], traj.x[:, 0].shape))
    assert np.allclose(traj.x[0, 0], expected, rtol=0, atol=1e-14)
    assert np.allclose(traj.body_q, quaternion_from_angles([10.0, 20.0, 30.0]), rtol=0, atol=1e-15)
    assert np.abs(traj.body_v).max() == 0.0 and np.abs(traj.body_w).max() == 0.0


def test_a_driven_body_moves_its_points_rigidly_as_its_six_degrees_of_freedom_say():
    """Surge at 0.5 m/s, a sinusoid in heave and one in the angle about y: the bollard's node is at r(t) + R(t) s
    with R = Rz Ry Rx of the angles at t, at every saved frame; the body's own frames give the same pose, and its
    angular velocity is the angles' rates turned into world axes (here the second angle's alone, about the y axis
    turned by the third rotation: w = b' Rz e_y)."""
    motion = ("velocity = [0.5, 0.0, 0.0]\namplitude = [0.0, 0.3, 0.0, 0.0, 15.0, 0.0]\n"
              "period = [1.0, 2.0, 1.0, 1.0, 1.5, 1.0]")
    scene = scene_from_toml(FRAME.replace("KIND", "driven").replace("MOTION", motion))
    traj = ropesim.simulate(scene)
    t = traj.t
    heave = 0.3 * np.sin(2 * np.pi * t / 2.0)
    yaw = 20.0 + 15.0 * np.sin(2 * np.pi * t / 1.5)
    position = np.stack([0.5 * t, heave, 0.0 * t], axis=1)
    rotation = Rotation.from_euler("xyz", np.stack([np.full_like(t, 10.0), yaw, np.full_like(t, 30.0)], axis=1),
                                   degrees=True).as_matrix()
    bollard = position + rotation @ np.array([2.0, 1.0, -1.0])
    assert np.allclose(traj.x[:, 0], bollard, rtol=0, atol=1e-12)
    assert np.allclose(traj.body_x[:, 0], position, rtol=0, atol=1e-12)
    assert np.allclose(rotation_matrix(traj.body_q[:, 0]), rotation, rtol=0, atol=1e-12)
    yaw_rate = np.radians(15.0 * 2 * np.pi / 1.5 * np.cos(2 * np.pi * t / 1.5))
    axis = Rotation.from_euler("z", 30.0, degrees=True).as_matrix() @ np.array([0.0, 1.0, 0.0])
    assert np.allclose(traj.body_w[:, 0], yaw_rate[:, None] * axis, rtol=0, atol=1e-12)
    assert traj.summary["status"] == "completed"


def test_quaternions_from_matrices_round_trip():
    rotations = Rotation.random(500, random_state=7)
    q = quaternion_from_matrix(rotations.as_matrix())
    assert np.allclose(rotation_matrix(q), rotations.as_matrix(), rtol=0, atol=1e-14)
    assert np.all(q[:, 0] >= 0)


# ------------------------------------------------------------------------------ state and energy

def test_a_free_bodys_run_cut_into_pieces_or_saved_and_restored_continues_bit_for_bit():
    scene = scene_from_toml(spinning_top("verlet", 0.01).replace("[integrator]", "[gravity]\n[integrator]"))
    model = build(scene)
    grid = TimeGrid.of(scene)
    whole = make_integrator(model, grid)
    whole.advance(300)
    pieces = make_integrator(model, grid)
    pieces.advance(113)
    saved = pieces.state()
    assert {"pose", "twist"} <= set(saved)
    restored = make_integrator(model, grid)
    restored.restore(saved)
    restored.advance(187)
    for name in ("x", "v", "pose", "twist", "ledger"):
        assert np.array_equal(getattr(whole, name), getattr(restored, name)), name


def test_a_body_in_water_books_drag_and_added_mass_as_fluid_work():
    """A buoyant body on a chain, in water with drag and added mass, swinging from a sideways start: the energy
    balance E(t) - E(0) - fluid work stays within 0.5 % of the energy that flowed (the run's own integration
    error), and the fluid took energy out."""
    text = """
name = "buoy"
dimension = 3
[line_types.chain]
diameter = 0.05
mass_per_length = 20.0
EA = 2.0e7
[[points]]
id = "anchor"
position = [0.0, -20.0, 0.0]
[[points]]
id = "eye"
body = "float"
position = [0.0, -0.5, 0.0]
[[bodies]]
id = "float"
position = [6.0, -2.0, 0.0]
mass = 500.0
inertia = [80.0, 80.0, 80.0]
volume = 2.0
center_of_buoyancy = [0.0, 0.1, 0.0]
cd_area = [1.5, 1.5, 1.5]
cd_rotation = [3.0, 3.0, 3.0]
added_mass = [400.0, 400.0, 400.0]
added_inertia = [20.0, 20.0, 20.0]
[[lines]]
id = "chain"
type = "chain"
start = "anchor"
end = "eye"
length = 18.0
segments = 12
[fluid]
density = 1025.0
[fluid_drag]
cd_normal = 1.2
cd_tangential = 0.2
[added_mass]
ca_normal = 1.0
ca_tangential = 0.0
[gravity]
[integrator]
method = "rk4"
dt = 2.0e-4
t_end = 6.0
"""
    traj = ropesim.simulate(scene_from_toml(text))
    assert traj.summary["status"] == "completed"
    ledger = traj.summary["energy_ledger"]
    assert ledger["fluid_work_J"] < -100.0
    assert abs(ledger["relative_residual"]) < 5e-3, ledger
    model = build(traj.scene)
    pose, twist = free_body_state(model, traj)
    terms = energy_terms(model, traj.x, traj.v, pose, twist)
    assert {"body kinetic", "body gravity", "body buoyancy"} <= set(terms)


# ------------------------------------------------------------------------- the body-axes solve


def _world_axes_accelerations(model, x, v, acc, pose, twist, t):
    """The free bodies' accelerations (6, B) from their Newton-Euler equations assembled in world axes (the stiff
    integrator's :func:`~ropesim.model.bodies.body_own_system` and :func:`~ropesim.model.bodies.body_attachments_system`)
    and solved by numpy: what :func:`~ropesim.model.bodies.move_bodies` must give from its body-axes factorisation."""
    from ropesim.model import jit
    from ropesim.model.bodies import body_attachments_system, body_own_system

    p = model.params
    own = jit.specialise(body_own_system, model.switches)
    keep = [0, 1, 5] if model.dim == 2 else list(range(6))
    out = np.zeros((6, pose.shape[1]))
    for b in range(pose.shape[1]):
        work = np.zeros((6, 7))
        own(work, 9.81, p.flow, p.bodies, pose, twist, b, t, 0.0)
        body_attachments_system(work, x, acc, p.inv_mass, p.neighbours, p.bodies, pose, twist, b)
        out[keep, b] = np.linalg.solve(work[np.ix_(keep, keep)], work[keep, 6])
    return out


@pytest.mark.parametrize("case", ["spread_mooring_free", "helicopter_sling", "plate_2d", "tripod_in_water"])
def test_the_body_axes_solve_equals_the_world_axes_equations(case):
    """move_bodies solves each body's equations in its own axes, with the constant part of its mass matrix
    factored once and its attachments' tangential added mass ((a_t - a_n) q q^T, the spar's chains and the tripod's
    lines in water) added per evaluation: at a tilted, turning pose with arbitrary node forces its accelerations
    equal the world-axes assembly solved by numpy to round-off (1e-12 of their size), again with the factor reused
    at the same positions (a velocity kick's sub-stages), and the attachment nodes get a + alpha x rho +
    w x (w x rho)."""
    from test_sdirk_bodies import tumbling_tripod
    from synthetic_system import BODY_2D
    from ropesim.model import jit
    from ropesim.model.bodies import move_bodies
    from ropesim.model.rotation import quaternion_from_angles, rotation_matrix

    text = {"plate_2d": BODY_2D, "tripod_in_water": tumbling_tripod(water=True)}.get(case)
    scene = scene_from_toml(text) if text else ropesim.load_scene(case, ["initial.shape=lines"])
    model = build(scene)
    rng = np.random.default_rng(7)
    x, v = model.x0.copy(), rng.normal(size=model.x0.shape)
    acc = rng.normal(size=x.shape) * 50.0
    pose, twist = model.body_pose0.copy(), rng.normal(size=(6, model.body_pose0.shape[1])) * 0.3
    if model.dim == 2:
        twist[[2, 3, 4]] = 0.0
        pose[3:] = quaternion_from_angles([25.0], 2)[:, None]
    else:
        pose[3:] = quaternion_from_angles([10.0, -30.0, 15.0], 3)[:, None]
    want = _world_axes_accelerations(model, x, v, acc, pose, twist, 0.5)
    got, node_acc = np.zeros_like(want), acc.copy()
    p = model.params
    mover = jit.specialise(move_bodies, model.switches)
    mover(x, v, node_acc, p.inv_mass, p.neighbours, 9.81, p.flow, p.bodies, pose, twist, got, 0.5, True)
    for d in range(2):   # forces and moments: each to 1e-12 of its largest
        assert np.abs(got[3 * d:3 * d + 3] - want[3 * d:3 * d + 3]).max() <= 1e-12 * np.abs(want[3 * d:3 * d + 3]).max()
    # a velocity kick's next sub-stage: the same positions and pose, other node forces and twist; the matrix
    # factored above is reused (moved=False), and the answer is still the world-axes solve's
    acc2, twist2 = rng.normal(size=x.shape) * 50.0, rng.normal(size=twist.shape) * 0.3
    if model.dim == 2:
        twist2[[2, 3, 4]] = 0.0
    again = np.zeros_like(want)
    mover(x, v, acc2.copy(), p.inv_mass, p.neighbours, 9.81, p.flow, p.bodies, pose, twist2, again, 0.5, False)
    want2 = _world_axes_accelerations(model, x, v, acc2, pose, twist2, 0.5)
    for d in range(2):
        assert np.abs(again[3 * d:3 * d + 3] - want2[3 * d:3 * d + 3]).max() <= \
            1e-12 * np.abs(want2[3 * d:3 * d + 3]).max()
    bundle = p.bodies
    for b in range(pose.shape[1]):
        r = rotation_matrix(pose[3:, b])
        a, alpha, w = want[:3, b], want[3:, b], twist[3:, b]
        for k in range(bundle.start[b], bundle.start[b + 1]):
            rho = r @ bundle.arm[:, k]
            expect = a + np.cross(alpha, rho) + np.cross(w, np.cross(w, rho))
            node = bundle.nodes[k]
            assert np.allclose(node_acc[:, node], expect[:model.dim], rtol=1e-10, atol=1e-10 * np.abs(expect).max())
