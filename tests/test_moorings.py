"""Moorings, tethers and beams against independent references: the elastic catenary with seabed touchdown, the
Euler-Bernoulli cantilever (static deflection and first frequency), Coulomb friction on a slope, prescribed
motion and the force on its support, the static solver as a command, and one-line refusals of bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from typer.testing import CliRunner

import ropesim
from ropesim.analysis.statics import equilibrium
from ropesim.cli.app import app
from ropesim.model.build import build
from ropesim.run import resume, simulate
from ropesim.scene.loader import SceneError

from references.closed_forms import (cantilever_frequencies, cantilever_tip_deflection_uniform_load,
                                     elastic_catenary, incline_acceleration)

RHO, G = 1025.0, 9.81

# ------------------------------------------------------------------------------------------ the catenary

# A chain-like line, 100 m, anchored on a flat seabed at the origin, its fairlead 80 m along and 40 m up; weight
# in water w = (m - rho pi d^2 / 4) g per metre.
MU, D, EA, L = 50.0, 0.1, 5.0e8, 100.0
W = (MU - RHO * math.pi * D * D / 4.0) * G


def catenary_scene(segments: int, extra: str = "", fairlead: str = "pinned") -> ropesim.Scene:
    """The line from the anchor (node 0) to the fairlead (the last node), pinned, or driven by ``fairlead``."""
    held = ("[pinned]\nnodes = [0, -1]" if fairlead == "pinned"
            else f"[pinned]\nnodes = [0]\n[[driven]]\nnodes = [-1]\n{fairlead}")
    return ropesim.scene_from_toml(f"""
name = "catenary"
[rope]
length = {L}
segments = {segments}
mass_per_length = {MU}
diameter = {D}
EA = {EA}
[initial]
shape = "equilibrium"
start = [0.0, 0.0]
end = [80.0, 40.0]
{held}
[gravity]
g = {G}
[fluid]
density = {RHO}
[buoyancy]
[seabed]
height = 0.0
{extra}
[integrator]
method = "sdirk2"
dt = 0.01
t_end = 1.0
""")


@pytest.fixture(scope="module")
def catenary_reference():
    return elastic_catenary(80.0, 40.0, L, W, EA)


def test_the_catenary_with_touchdown_agrees_with_the_elastic_catenary(catenary_reference):
    """The static fairlead load (the support's force on the top node) and the length on the seabed, against the
    elastic catenary with a frictionless touchdown solved separately (Irvine; Jonkman 2007), at 50, 100 and 200
    segments. The lumped line's touchdown falls on a node, so its grounded length is within a segment of the
    continuous one and its loads do not converge smoothly: measured 2e-5 to 2e-4 off (the contact spring's give,
    w / (kBot d) = 1.4 mm, is smaller still)."""
    ref = catenary_reference
    assert ref.regime == "touchdown"
    for segments in (50, 100, 200):
        shape = equilibrium(catenary_scene(segments))
        assert shape.converged and shape.residual <= 1e-10 * shape.scale
        fairlead = np.flatnonzero(shape.held == segments)[0]
        h, v = shape.supports[fairlead]
        assert h == pytest.approx(ref.H, rel=3e-4) and v == pytest.approx(ref.V, rel=3e-4), (segments, h, v)
        assert abs(shape.grounded_length - ref.LB) <= L / segments, (segments, shape.grounded_length)


def test_the_anchor_carries_what_the_seabed_does_not(catenary_reference):
    """Frictionless: the grounded part is straight and carries H to the anchor, with no vertical load."""
    shape = equilibrium(catenary_scene(100))
    anchor = np.flatnonzero(shape.held == 0)[0]
    h, v = shape.supports[anchor]
    assert h == pytest.approx(-catenary_reference.H, rel=3e-4)
    # vertically the anchor carries its own half segment's weight in water, and the pull of the first segment,
    # which slopes down to the next node sunk w / (kBot d) into the seabed: H times that slope
    sink = W / (3.0e6 * D)
    assert v == pytest.approx(W * 0.5 + catenary_reference.H * sink / 1.0, rel=2e-2)
    assert shape.touchdown is not None and 0 < shape.touchdown < 100
    # the grounded nodes all lie on (just in) the seabed, the suspended ones above it
    assert np.all(shape.x[shape.grounded, 1] < 0.0) and np.all(shape.x[shape.grounded, 1] > -0.01)


def test_the_equilibrium_command_prints_the_loads_and_writes_a_runnable_scene(tmp_path, catenary_reference):
    scene_file = tmp_path / "catenary.toml"
    scene_file.write_text(ropesim.scene_to_toml(catenary_scene(100)))
    out = tmp_path / "static.toml"
    result = CliRunner().invoke(app, ["equilibrium", str(scene_file), "-o", str(out)], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    assert "static shape found in" in result.stdout and "support, node 100" in result.stdout
    assert "nodes rest on it" in result.stdout and "touchdown at node" in result.stdout
    assert f"written: {out}" in result.stdout
    static = ropesim.load_scene(out)
    assert static.initial.shape == "points"
    traj = simulate(static)   # starts at rest in balance: nothing moves
    assert np.abs(np.asarray(traj.v)).max() < 1e-6
    again = CliRunner().invoke(app, ["equilibrium", str(scene_file), "-o", str(out)])
    assert again.exit_code == 2 and "exists" in again.stderr and "--force" in again.stderr


def test_a_static_solve_that_cannot_converge_is_one_line_and_exit_1(tmp_path):
    """A free line on a sloping seabed has no static shape (at rest friction holds nothing, so it slides
    forever): the solver stops, the command prints what it reached and says so; a run that starts from that
    shape stops before it begins, in one line."""
    text = ropesim.scene_to_toml(slope_scene(10.0, 0.5, 0.1)).replace('shape = "points"', 'shape = "equilibrium"')
    text = text[:text.index("points = [")] + "start = [0.0, 0.0]\nend = [0.98, 0.17]\n" + text[text.index("\n[", text.index("points = [")):]
    scene_file = tmp_path / "sliding.toml"
    scene_file.write_text(text)
    result = CliRunner().invoke(app, ["equilibrium", str(scene_file)], env={"COLUMNS": "200"})
    assert result.exit_code == 1, result.output
    assert "NOT converged" in result.stdout
    assert "did not converge" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    run = CliRunner().invoke(app, ["run", str(scene_file), "-o", str(tmp_path / "r"), "-q"])
    assert run.exit_code == 1 and "did not converge" in run.stderr and "Traceback" not in run.stderr


# ---------------------------------------------------------------------------------------- the cantilever

EI, MU_BEAM, L_BEAM = 1000.0, 1.0, 1.0


def cantilever(segments: int, method: str = "sdirk2", t_end: float = 0.0, shape: str = "equilibrium") -> str:
    start = 'start = [0.0, 0.0]\nend = [1.0, 0.0]' if shape in ("equilibrium", "line") else ""
    return f"""
name = "cantilever"
[rope]
length = {L_BEAM}
segments = {segments}
mass_per_length = {MU_BEAM}
diameter = 0.01
EA = 1.0e9
EI = {EI}
compression = true
[initial]
shape = "{shape}"
{start}
[pinned]
nodes = [0]
clamped = [0]
[gravity]
g = {G}
[integrator]
method = "{method}"
dt = 0.0002
t_end = {t_end}
[output]
interval = 0.0002
"""


def test_a_cantilevers_static_tip_deflection_converges_to_euler_bernoulli():
    """w L^4 / (8 EI) = 1.23 mm (0.12 % of the length, so geometric nonlinearity is 1e-6): the lumped beam's
    error falls at second order in the segment length."""
    exact = cantilever_tip_deflection_uniform_load(MU_BEAM * G, L_BEAM, EI)
    errors = []
    for segments in (10, 20, 40):
        model = build(ropesim.scene_from_toml(cantilever(segments)))
        errors.append(abs(-model.x0[1, -1] - exact) / exact)
    assert errors[-1] < 2e-3, errors
    assert 3.0 < errors[0] / errors[1] < 5.0 and 3.0 < errors[1] / errors[2] < 5.0, errors


# slow: an sdirk2 loop of a bent beam no other quick test compiles (6 s of a cold run); the beam's static
# deflection stays quick (above), its release against MoorDyn too (tests/test_moordyn_own_cases.py)
@pytest.mark.slow
def test_a_cantilever_released_straight_swings_at_its_first_euler_bernoulli_frequency():
    """Released straight, the beam oscillates about its static shape mostly in its first mode: the tip's
    period from zero crossings of its offset from the static deflection, against 2 pi / omega_1 with
    omega_1 = 1.875^2 sqrt(EI / (mu L^4)) = 111.2 rad/s. sdirk2 at T / 280 and 40 segments: within 0.5 %."""
    omega1 = cantilever_frequencies(EI, MU_BEAM, L_BEAM, 1)[0]
    static = build(ropesim.scene_from_toml(cantilever(40))).x0[1, -1]
    traj = simulate(ropesim.scene_from_toml(cantilever(40, t_end=0.3, shape="line")))
    t, tip = np.asarray(traj.t), np.asarray(traj.x[:, -1, 1]) - static
    rising = np.flatnonzero((tip[:-1] < 0.0) & (tip[1:] >= 0.0))
    crossings = t[rising] - tip[rising] * (t[rising + 1] - t[rising]) / (tip[rising + 1] - tip[rising])
    period = float(np.mean(np.diff(crossings)))
    assert len(crossings) >= 4
    assert period == pytest.approx(2.0 * math.pi / omega1, rel=5e-3)


# --------------------------------------------------------------------------------------- friction on a slope

def slope_scene(angle_deg: float, mu: float, t_end: float) -> ropesim.Scene:
    """A 1 m rope of 5 nodes lying straight down a slope (rising towards +x), sunk to its contact equilibrium."""
    a = math.radians(angle_deg)
    mass, d, k = 0.2, 0.01, 3.0e6
    sink = mass * G * math.cos(a) / (k * d)          # N = m g cos a = k delta A with A = d L per metre
    points = [[float(s * math.cos(a) + sink * math.sin(a)), float(s * math.sin(a) - sink * math.cos(a))]
              for s in np.linspace(0.0, 1.0, 5)]
    return ropesim.scene_from_toml(f"""
[rope]
length = 1.0
segments = 4
mass_per_length = {mass}
diameter = {d}
EA = 1.0e4
compression = true
[initial]
shape = "points"
points = {points}
[gravity]
g = {G}
[seabed]
height = 0.0
slope = {angle_deg}
stiffness = {k}
friction = {mu}
friction_speed = 0.01
[integrator]
method = "rk4"
dt = 2e-5
t_end = {t_end}
[output]
interval = 0.01
""")


def _speed_down(traj, angle_deg):
    a = math.radians(angle_deg)
    return -(np.asarray(traj.v)[:, :, 0].mean(axis=1) * math.cos(a) + np.asarray(traj.v)[:, :, 1].mean(axis=1)
             * math.sin(a))


def test_friction_holds_a_line_below_its_critical_angle_but_for_the_regularised_creep():
    """tan 10 deg = 0.18 < mu = 0.5: the line holds, creeping at the regularisation's speed
    v_reg r / sqrt(1 - r^2), r = tan(a) / mu, where mu N v / sqrt(v^2 + v_reg^2) balances m g sin a."""
    traj = simulate(slope_scene(10.0, 0.5, 0.5))
    r = math.tan(math.radians(10.0)) / 0.5
    creep = 0.01 * r / math.sqrt(1.0 - r * r)
    assert _speed_down(traj, 10.0)[-10:] == pytest.approx(np.full(10, creep), rel=1e-3)


def test_friction_lets_a_line_slide_above_its_critical_angle_at_coulombs_rate():
    """tan 35 deg = 0.70 > mu = 0.5: the line accelerates at g (sin a - mu cos a) = 1.61 m/s^2, friction at its
    full mu N once the speed is well above v_reg (the regularisation's shortfall mu N (1 - v / sqrt(v^2 +
    v_reg^2)) is below 1e-4 of it from 0.5 s on)."""
    traj = simulate(slope_scene(35.0, 0.5, 1.5))
    t, speed = np.asarray(traj.t), _speed_down(traj, 35.0)
    late = t >= 0.5
    rate = np.polyfit(t[late], speed[late], 1)[0]
    assert rate == pytest.approx(incline_acceleration(math.radians(35.0), 0.5, g=G), rel=1e-3)


# ------------------------------------------------------------------------------------- prescribed motion

HANGING = """
name = "swung"
dimension = 3
[rope]
length = 4.0
segments = 8
mass_per_length = 0.5
diameter = 0.01
EA = 1.0e4
axial_damping = 20.0
[initial]
shape = "hanging"
[[driven]]
nodes = [0]
{drive}
[gravity]
g = 9.81
[integrator]
method = "rk4"
dt = 2e-4
t_end = 3.0
[output]
interval = 2e-4
"""


def test_a_driven_node_follows_its_sinusoid_and_its_support_force_is_the_ropes_momentum_balance():
    """The held node sits on x0 + r(t) (A sin(2 pi t / T + phi) - A sin(phi)) at every frame, to round-off (r the
    smootherstep ramp); and
    the support's force equals d/dt of the rope's momentum minus its weight (central differences of the saved
    frames at every step: their O((omega h)^2) error on the stretch's oscillation, omega = 280 rad/s, is below
    1e-3 of the weight)."""
    drive = "amplitude = [0.3, 0.1, 0.0]\nperiod = [1.5, 0.75, 1.0]\nphase = [0.0, 90.0, 0.0]\nramp_time = 1.0"
    scene = ropesim.scene_from_toml(HANGING.format(drive=drive))
    traj = simulate(scene)
    t = np.asarray(traj.t)
    u = np.minimum(t / 1.0, 1.0)
    ramp = u ** 3 * (10.0 - 15.0 * u + 6.0 * u * u)
    amp, period, phase = np.array([0.3, 0.1, 0.0]), np.array([1.5, 0.75, 1.0]), np.radians([0.0, 90.0, 0.0])
    path = ramp[:, None] * (amp * np.sin(2 * np.pi * t[:, None] / period + phase) - amp * np.sin(phase))
    np.testing.assert_allclose(traj.x[:, 0], path, rtol=0, atol=1e-13)

    model = build(scene)
    momentum = np.einsum("n,fnd->fd", model.mass, np.asarray(traj.v))
    rate = (momentum[2:] - momentum[:-2]) / (t[2:, None] - t[:-2, None])
    weight = np.array([0.0, -model.mass.sum() * 9.81, 0.0])
    support = np.asarray(traj.support)[1:-1, 0]
    scale = model.mass.sum() * 9.81
    assert np.abs(rate - weight - support).max() < 1e-3 * scale


def test_a_csv_path_and_the_same_inline_path_give_the_same_run(tmp_path):
    """The loader reads the CSV into path_table, so the two forms are the same scene, and the held node is on the
    piecewise-linear path at every frame."""
    rows = [(0.0, 0.0, 0.0, 0.0), (1.0, 0.5, 0.0, 0.0), (2.0, 0.5, 0.3, 0.0), (3.5, 0.0, 0.0, 0.2)]
    (tmp_path / "path.csv").write_text("t, dx, dy, dz\n" + "\n".join(",".join(map(str, r)) for r in rows) + "\n")
    from_file = tmp_path / "a.toml"
    from_file.write_text(HANGING.format(drive='path = "path.csv"'))
    inline = HANGING.format(drive=f"path_table = {[list(r) for r in rows]}")
    a, b = ropesim.load_scene(from_file), ropesim.scene_from_toml(inline)
    assert a == b
    traj = simulate(a)
    t = np.asarray(traj.t)
    table = np.array(rows)
    for axis in range(3):
        np.testing.assert_allclose(traj.x[:, 0, axis], np.interp(t, table[:, 0], table[:, axis + 1]), rtol=0,
                                   atol=1e-13)


@pytest.mark.parametrize("friction", [0.0, 0.6])
def test_the_stiff_method_takes_a_chain_slamming_on_the_seabed_in_large_steps(friction):
    """A 30-segment chain under a fairlead surging 2 m and heaving 1 m every 8 s, its touchdown nodes landing at
    up to 3 m/s: sdirk2 at dt = 20 ms (Verlet needs dt < 0.96 ms here) completes 30 s, its stages converging
    in a few Newton iterations. With MoorDyn's contact law (damping that also holds a node leaving the seabed,
    switched on at once) its Newton solve stalled at dt = 5 ms: see the seabed's module doc."""
    scene = catenary_scene(30, extra=f"friction = {friction}", fairlead="amplitude = [2.0, 1.0]\nperiod = [8.0, 8.0]"
                                                                       "\nramp_time = 2.0")
    scene = ropesim.scene_from_toml(ropesim.scene_to_toml(scene), overrides=[
        "integrator.t_end=30", "integrator.dt=0.02", "output.interval=0.1"])
    traj = simulate(scene)
    assert traj.summary["status"] == "completed", traj.summary.get("message")
    assert traj.summary["force_evaluations"] < 12 * 2 * 1500   # at most 12 Newton iterations a stage on average
    assert traj.summary["energy_ledger"]["seabed_work_J"] < 0.0   # the seabed only takes energy out


def test_a_mooring_run_with_a_moving_fairlead_extends_bit_for_bit(tmp_path):
    """Seabed contact and friction, a fairlead moving on a ramped sinusoid, sdirk2: run to 2 s, then extended to
    4 s from its checkpoint (the integrator restored mid-motion), it equals one run straight to 4 s."""
    scene = catenary_scene(30, extra="friction = 0.6", fairlead="amplitude = [2.0, 1.0]\nperiod = [8.0, 8.0]\n"
                                                                  "ramp_time = 2.0")
    text = ropesim.scene_to_toml(scene)
    short = ropesim.scene_from_toml(text, overrides=["integrator.t_end=2.0", "integrator.dt=0.002",
                                                     "output.interval=0.1"])
    long = ropesim.scene_from_toml(text, overrides=["integrator.t_end=4.0", "integrator.dt=0.002",
                                                    "output.interval=0.1"])
    simulate(short, tmp_path / "extended")
    done = resume(tmp_path / "extended", t_end=4.0)
    clean = simulate(long, tmp_path / "clean")
    assert done.summary["status"] == clean.summary["status"] == "completed"
    assert done.frames == clean.frames == 41
    for name in ("t", "x", "v", "tension", "support"):
        np.testing.assert_array_equal(getattr(done, name), getattr(clean, name))


# -------------------------------------------------------------------------------------------- bad input

def _refused(text: str, key: str, *fragments: str, base=None) -> None:
    with pytest.raises(SceneError) as info:
        ropesim.scene_from_toml(text, base_dir=base)
    message = str(info.value)
    assert info.value.key == key and "\n" not in message, message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_a_seabed_above_the_anchor_is_refused():
    _refused(ropesim.scene_to_toml(catenary_scene(20)).replace("height = 0.0", "height = 1.5"), "seabed.height",
             "1.5 m above held node 0", "an anchor sits on the seabed or above it")


def test_a_negative_friction_is_refused():
    _refused(ropesim.scene_to_toml(catenary_scene(20)).replace("friction = 0.0", "friction = -0.2"),
             "seabed.friction", ">= 0")


@pytest.mark.parametrize("csv, fragments", [
    ("t,dx,dy,dz\n0,0,0,0\n2,1,0,0\n1,0,0,0\n4,0,0,0\n", ("times must increase", "1 s follows 2 s")),
    ("0,0,0\n4,1,0\n", ("line 1", "needs 4 finite numbers (t, dx, dy, dz)")),
    ("0,0,0,0\n2,1,0,0\n", ("covers t = 0 to 2 s", "the run goes from 0 to 3 s")),
    ("0,0.5,0,0\n4,1,0,0\n", ("the displacement at t = 0 is [0.5, 0.0, 0.0], not zero",)),
    ("t,dx,dy,dz\n0,0,0,0\n1,0,x,0\n", ("line 3", "not numbers")),
])
def test_a_bad_path_csv_is_refused_in_one_line(tmp_path, csv, fragments):
    (tmp_path / "path.csv").write_text(csv)
    _refused(HANGING.format(drive='path = "path.csv"'), "driven.0.path", *fragments, base=tmp_path)


def test_a_missing_path_file_and_both_path_forms_are_refused(tmp_path):
    _refused(HANGING.format(drive='path = "nowhere.csv"'), "driven.0.path", "cannot read", base=tmp_path)
    (tmp_path / "p.csv").write_text("0,0,0,0\n4,0,0,0\n")
    _refused(HANGING.format(drive='path = "p.csv"\npath_table = [[0, 0, 0, 0], [4, 0, 0, 0]]'),
             "driven.0.path_table", "not both", base=tmp_path)
    _refused(HANGING.format(drive="path_table = [[0, 0, 0], [4, 0, 0]]"), "driven.0.path_table",
             "rows, each 4 finite numbers")
