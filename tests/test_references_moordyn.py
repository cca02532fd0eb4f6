"""MoorDyn as a reference: the harness (tests/references/moordyn_harness.py), the conventions written down in
tests/references/MOORDYN_CONVENTIONS.md (each formula there is recomputed here from MoorDyn's own node states and
compared with what the installed MoorDyn reports), and the stored reference runs in tests/data/moordyn/.

Units: SI (m, s, kg, N). Needs the ``moordyn`` package (the ``bench`` extra); MoorPy (``test`` extra) for one check.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("moordyn")

from references.catenary_closed_form import seabed_catenary, suspended_catenary  # noqa: E402
from references.moordyn_harness import (  # noqa: E402
    MOORDYN_DEFAULT_G,
    Environment,
    LineProps,
    Solver,
    line_system,
    moordyn_system,
    run_input_file,
    run_line,
    set_options,
    sinusoidal_motion,
)

DATA = Path(__file__).parent / "data" / "moordyn"
CASES = DATA / "cases"

#: The studless chain of MoorDyn's own tests/Mooring/WD0050_Chain.txt (and WD0200, WD0600).
CHAIN = dict(diameter=0.252, mass_per_length=390.0, EA=1.674e9, BA=-1.0, Cd=1.37, Ca=1.0, CdAx=0.64, CaAx=0.0)
RHO_W = 1025.0
G = MOORDYN_DEFAULT_G
CHAIN_W = (CHAIN["mass_per_length"] - RHO_W * math.pi / 4 * CHAIN["diameter"] ** 2) * G  # submerged N/m

#: A light line for the force-formula checks: every coefficient non-zero and different, so a swapped or dropped
#: term shows. Explicit Euler at dtM = 1e-4 s is stable for it (axial omega dt = 0.02; zeta = 0.8). The probes start
#: from MoorDyn's initial catenary without the IC solve (the formulas hold in any state; the IC would cost seconds).
PROBE = LineProps(length=120.0, n_segments=20, diameter=0.1, mass_per_length=50.0, EA=1.0e8, BA=-0.8,
                  Cd=1.2, Ca=0.9, CdAx=0.3, CaAx=0.2)
EULER = Solver(dtM=1.0e-4, scheme="Euler", ic=False)

#: Relative tolerance for a formula recomputed in numpy from the same doubles MoorDyn used: both sides do the
#: same dozen floating-point operations in a different order, so they agree to ~1e-13 (the tension's
#: (l_stretched - l) loses ~3 digits at strain 1e-3); 1e-9 leaves room and still catches any wrong factor.
EXACT = 1e-9


# ------------------------------------------------------------------------------------------------ helpers


def node_state(md, line):
    """Node positions and velocities (N+1, 3) of a MoorDyn line, m and m/s."""
    n = md.GetLineN(line)
    pos = np.array([md.GetLineNodePos(line, i) for i in range(n + 1)])
    vel = np.array([md.GetLineNodeVel(line, i) for i in range(n + 1)])
    return pos, vel


def node_vectors(md, line, getter):
    """A per-node 3-vector getter of the bindings (e.g. md.GetLineNodeDrag) for every node, (N+1, 3), N."""
    return np.array([getter(line, i) for i in range(md.GetLineN(line) + 1)])


def euler_probe(md, system, line, fairlead, velocity, t_drive, dt_drive=0.05):
    """Drive the coupled fairlead from ``fairlead`` (m) at constant ``velocity`` (m/s) for ``t_drive`` s, then take
    one more explicit-Euler step of exactly dtM (the system must use tScheme Euler).

    Euler evaluates the forces at the state at the start of its step, so after the probe step every force MoorDyn
    reports belongs to the returned state: node positions (m) and velocities (m/s), (N+1, 3), with the fairlead
    node at the prescribed position and velocity. Returns (pos, vel)."""
    import cmoordyn

    x, v, t = np.array(fairlead, float), np.array(velocity, float), 0.0
    for _ in range(round(t_drive / dt_drive)):
        md.Step(system, list(x), list(v), t, dt_drive)
        x, t = x + v * dt_drive, t + dt_drive
    pos, vel = node_state(md, line)
    np.testing.assert_allclose(pos[-1], x, rtol=0, atol=1e-9)  # the point moved exactly as prescribed
    md.Step(system, list(x), list(v), t, cmoordyn.get_dt(system))
    vel[-1] = v
    return pos, vel


def geometry(pos):
    """Segment lengths (N,) m, segment unit vectors qs (N, 3) and MoorDyn's node tangents q (N+1, 3): the
    chord through the two neighbours for inner nodes, the end segment's direction at the ends (no EI end
    clamping)."""
    seg = np.diff(pos, axis=0)
    lstr = np.linalg.norm(seg, axis=1)
    qs = seg / lstr[:, None]
    chord = pos[2:] - pos[:-2]
    q = np.vstack([qs[:1], chord / np.linalg.norm(chord, axis=1)[:, None], qs[-1:]])
    return lstr, qs, q


def node_lengths(line: LineProps):
    """Unstretched length lumped at each node (N+1,) m: half a segment at each end, a whole one inside."""
    lengths = np.full(line.n_segments + 1, line.length / line.n_segments)
    lengths[[0, -1]] *= 0.5
    return lengths


def segment_forces(line: LineProps, pos, vel):
    """MoorDyn's segment stiffness and damping forces T, Td (N, 3) N, along qs (pulling node i towards i+1):
    T = EA (l_s - l) / l only in tension; Td = BA (qs . (v_i+1 - v_i)) / l, in tension and compression, with
    BA = zeta (L/N) sqrt(EA m') when the input BA is -zeta."""
    lstr, qs, _ = geometry(pos)
    l0 = line.length / line.n_segments
    ba = -line.BA * l0 * math.sqrt(line.EA * line.mass_per_length) if line.BA < 0 else line.BA
    t = np.where(lstr > l0, line.EA * (lstr - l0) / l0, 0.0)[:, None] * qs
    strain_rate = np.einsum("ij,ij->i", qs, np.diff(vel, axis=0)) / l0
    return t, (ba * strain_rate)[:, None] * qs


# ----------------------------------------------------------------------------- the harness: tests (a)-(c)


def test_static_suspended_catenary_matches_closed_form():
    """(a) A chain hanging clear of the seabed: MoorDyn's static state (its IC solve) against the elastic catenary.

    Tolerances. Vertical forces and tension, 0.1 %: the lumped-mass chain converges to the catenary as (L/N)^2
    (fairlead V error 1.2e-3, 3.2e-4, 9.6e-5 at N = 10, 20, 40 with a tight IC) and MoorDyn's IC at threshIC = 1e-3
    stops with a residual worth 1e-4 more. Horizontal force, 0.5 %: H is small here (a steep line) and the IC leaves
    a slow in-plane sway that drag hardly damps; after the IC, H at either end wanders by +-0.4 % over 200 s while V
    stays within 1e-4 (measured). Sea water of 1000 instead of 1025 kg/m^3 moves V_F by 0.4 %, a lost half-segment
    end weight by 0.7 %: both fail."""
    line = LineProps(length=120.0, n_segments=40, **CHAIN)
    run = run_line(line, Environment(depth=200.0), anchor=(60.0, 0.0, -90.0), fairlead=(0.0, 0.0, -10.0))
    ref = suspended_catenary(60.0, 80.0, 120.0, CHAIN["EA"], CHAIN_W)
    fair, anchor = run.fairlead_force[0], run.anchor_force[0]  # force of the line on its end nodes
    assert -fair[2] == pytest.approx(ref.V_F, rel=1e-3)
    assert np.linalg.norm(fair) == pytest.approx(ref.fairlead_tension, rel=1e-3)
    assert anchor[2] - ref.V_A == pytest.approx(0.0, abs=1e-3 * CHAIN_W * 120.0)  # V_A is small: vs the weight
    assert fair[0] == pytest.approx(ref.H, rel=5e-3)
    assert -anchor[0] == pytest.approx(ref.H, rel=5e-3)


def test_static_chain_on_seabed_matches_closed_form():
    """(a) The 50 m chain of MoorDyn's WD0050 case on a stiff seabed, 164 segments, against the elastic catenary on
    a rigid frictionless seabed (MoorDyn's IC solve ignores friction).

    Tolerance 0.2 %: MoorDyn's touchdown discretisation converges as measured H errors of -0.62 %, -0.079 %,
    -0.044 % at N = 82, 164, 328; the seabed spring (kBot = 3e6 Pa/m) lets the grounded chain sink
    w / (kBot d) = 4.4 mm, worth +0.03 %. At MoorDyn's own kBot = 1e5 the sink is 0.13 m and worth +0.8 %, which is
    why this test uses a stiff seabed."""
    line = LineProps(length=410.0, n_segments=164, **CHAIN)
    env = Environment(depth=55.0, kbot=3.0e6, cbot=1.0e4)
    run = run_line(line, env, anchor=(400.0, 0.0, -55.0), fairlead=(0.0, 0.0, -5.0), solver=Solver(dtM=4e-4))
    ref = seabed_catenary(400.0, 50.0, 410.0, CHAIN["EA"], CHAIN_W)
    fair = run.fairlead_force[0]
    assert fair[0] == pytest.approx(ref.H, rel=2e-3)
    assert -fair[2] == pytest.approx(ref.V_F, rel=2e-3)
    assert np.linalg.norm(fair) == pytest.approx(ref.fairlead_tension, rel=2e-3)
    assert run.anchor_tension[0] == pytest.approx(ref.H, rel=2e-3)  # the grounded chain carries H to the anchor
    grounded = run.positions[0][:, 2] < -55.0 + 0.01
    assert grounded.sum() * 410.0 / 164 == pytest.approx(ref.grounded, abs=2 * 410.0 / 164)


def test_closed_form_catenary_matches_moorpy():
    """The closed form against MoorPy's independent catenary solver, for the three chain geometries of MoorDyn's
    WD0050/0200/0600 cases: both solve the same equations, to 1e-10 relative or better."""
    catenary = pytest.importorskip("moorpy.Catenary").catenary
    for xf, zf, length in [(400.0, 50.0, 410.0), (700.0, 200.0, 760.0), (1500.0, 600.0, 1700.0)]:
        ours = seabed_catenary(xf, zf, length, CHAIN["EA"], CHAIN_W)
        f_ah, f_av, f_bh, f_bv, _ = catenary(xf, zf, length, CHAIN["EA"], CHAIN_W, CB=0, Tol=1e-12, MaxIter=200)
        assert ours.H == pytest.approx(-f_bh, rel=1e-9)
        assert ours.V_F == pytest.approx(-f_bv, rel=1e-9)  # MoorPy gives the forces the line puts on its ends
        assert ours.anchor_tension == pytest.approx(math.hypot(f_ah, f_av), rel=1e-9)


def test_still_line_stays_static():
    """(b) The 50 m chain after MoorDyn's IC, fairlead held, no current, 30 s: nothing moves.

    Tolerances: nodes within 2 cm, fairlead tension within 0.1 %, anchor tension within 0.3 %: MoorDyn's IC stops at
    threshIC = 1e-3 and ignores seabed friction, and the residual then rings along the grounded chain (measured:
    nodes settle by 4 mm, the fairlead tension by 0.02 %, the anchor tension oscillates by +-0.15 %); the fairlead
    stays exactly where it was put."""
    line = LineProps(length=410.0, n_segments=82, **CHAIN)
    env = Environment(depth=55.0, kbot=1.0e5, cbot=1.0e4, friction=0.5)
    run = run_line(line, env, anchor=(400.0, 0.0, -55.0), fairlead=(0.0, 0.0, -5.0), t_end=30.0, dt_out=0.5)
    assert np.abs(run.positions - run.positions[0]).max() < 0.02
    np.testing.assert_array_equal(run.positions[:, -1], np.tile([0.0, 0.0, -5.0], (len(run.t), 1)))
    np.testing.assert_allclose(run.fairlead_tension, run.fairlead_tension[0], rtol=1e-3)
    np.testing.assert_allclose(run.anchor_tension, run.anchor_tension[0], rtol=3e-3)


def test_reruns_are_identical():
    """(c) The same run twice (IC, then 10 s of surge): bit-identical output, so stored references are exact."""
    line = LineProps(length=410.0, n_segments=82, **CHAIN)
    env = Environment(depth=55.0, kbot=1.0e5, cbot=1.0e4, friction=0.5)
    kwargs = dict(anchor=(400.0, 0.0, -55.0), fairlead=(0.0, 0.0, -5.0), t_end=10.0, dt_out=0.1,
                  motion=sinusoidal_motion((0.0, 0.0, -5.0), 3.0, 10.0, ramp_periods=0.5))
    a, b = run_line(line, env, **kwargs), run_line(line, env, **kwargs)
    for name in ("positions", "fairlead_tension", "anchor_tension", "fairlead_force", "anchor_force"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.fairlead_tension.max() > 1.1 * a.fairlead_tension[0]  # the surge did load the line


# ----------------------------------------------------------------------------- harness details


def test_set_options_replaces_and_adds():
    """set_options rewrites an existing option row (any case) and adds a missing one under the header."""
    text = "x\n---- OPTIONS ----\n0.001 dtM  step\n2 writeLog\n---- need this ----\n"
    out = set_options(text, {"DTM": 0.5, "disableOutput": 1})
    assert out == "x\n---- OPTIONS ----\n1 disableOutput\n0.5 dtM\n2 writeLog\n---- need this ----\n"
    with pytest.raises(ValueError):
        set_options("no options here\n", {"dtM": 1})


def test_sinusoidal_motion_ramp():
    """The ramped sinusoid: at rest at t = 0 (position and slope), the full amplitude after the ramp (m, s)."""
    path = sinusoidal_motion((1.0, 2.0, 3.0), amplitude=5.0, period=10.0, axis=0, ramp_periods=1.0)
    np.testing.assert_array_equal(path(0.0), [1.0, 2.0, 3.0])
    assert abs(path(1e-3)[0] - 1.0) < 1e-9
    assert path(12.5)[0] == pytest.approx(6.0)
    assert path(17.5)[0] == pytest.approx(-4.0)
    assert path(7.5)[1:].tolist() == [2.0, 3.0]


def test_coupled_point_moves_linearly_within_a_coupling_step():
    """MoorDyn moves a coupled point as x + v s through a whole Step of dt (many internal steps), whatever x it had
    before: the harness's secant velocity therefore lands the fairlead exactly on the path at each output time."""
    with line_system(PROBE, Environment(depth=200.0), (100.0, 0.0, -60.0), (0.0, 0.0, -5.0)) as (md, system, line):
        md.Step(system, [0.0, 0.0, -5.0], [1.0, -2.0, 0.5], 0.0, 0.1)
        point = md.GetPoint(system, 2)
        np.testing.assert_allclose(md.GetPointPos(point), [0.1, -0.2, -4.95], rtol=0, atol=1e-12)
        np.testing.assert_allclose(md.GetLineNodePos(line, PROBE.n_segments), [0.1, -0.2, -4.95], atol=1e-12)


# ----------------------------------------------------------------------------- MoorDyn's conventions, pinned


def test_mass_matrix_weight_and_buoyancy():
    """Node mass matrix M_i = m_i I + rho V_i (Ca (I - q q^T) + CaAx q q^T) and weight W_i = -g (m_i - rho V_i) e_z,
    with m_i = m' l_i, V_i = (pi d^2 / 4) l_i and l_i half a segment at the ends; exact to rounding."""
    env = Environment(depth=200.0, g=9.7, rho_w=1010.0)
    with line_system(PROBE, env, (100.0, 0.0, -60.0), (0.0, 0.0, -5.0), EULER) as (md, system, line):
        pos, vel = euler_probe(md, system, line, (0.0, 0.0, -5.0), (0.4, 0.3, -0.2), t_drive=0.5)
        mass = np.array([md.GetLineNodeM(line, i) for i in range(PROBE.n_segments + 1)])
        weight = node_vectors(md, line, md.GetLineNodeWeight)
    _, _, q = geometry(pos)
    li = node_lengths(PROBE)
    m, v = PROBE.mass_per_length * li, math.pi / 4 * PROBE.diameter**2 * li
    qq = np.einsum("ij,ik->ijk", q, q)
    eye = np.eye(3)
    expected = m[:, None, None] * eye + (env.rho_w * v)[:, None, None] * (PROBE.Ca * (eye - qq) + PROBE.CaAx * qq)
    np.testing.assert_allclose(mass, expected, rtol=EXACT, atol=EXACT * m.max())
    np.testing.assert_allclose(weight[:, 2], -env.g * (m - env.rho_w * v), rtol=EXACT)
    np.testing.assert_array_equal(weight[:, :2], 0.0)


def test_default_gravity_is_9_80665():
    """MoorDyn's default g (no ``g`` option, as in its WD0050 case) is 9.80665 m/s^2, not the documented 9.81."""
    text = set_options((CASES / "WD0050_Chain.txt").read_text(encoding="utf-8"), {"writeLog": 0, "TmaxIC": 0.0})
    with moordyn_system(text, (0.0, 0.0, 0.0)) as (md, system):
        line = md.GetLine(system, 1)
        md.Step(system, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0, 0.01)
        weight = md.GetLineNodeWeight(line, 40)[2]  # a node on the seabed, fully submerged
    seg = 410.0 / 82
    submerged_mass = seg * (390.0 - 1025.0 * math.pi / 4 * 0.252**2)
    assert -weight / submerged_mass == pytest.approx(9.80665, rel=1e-12)


def test_tension_damping_and_reported_tensions():
    """Segment tension EA strain (tension only) plus damping BA strain-rate, BA = zeta (L/N) sqrt(EA m') from a
    negative BA input; GetLineNodeTen is that at the end segments and the mean of the two neighbours inside;
    GetLineFairTen is |GetLineNodeTen(N)|; the end node's net force is -T - Td of its segment plus the node's own
    weight, drag, Froude-Krylov and seabed terms. All exact to rounding."""
    with line_system(PROBE, Environment(depth=200.0), (100.0, 0.0, -60.0), (0.0, 0.0, -5.0), EULER) as (
        md, system, line,
    ):
        pos, vel = euler_probe(md, system, line, (0.0, 0.0, -5.0), (-0.8, 0.2, 0.3), t_drive=1.0)
        n = PROBE.n_segments
        ten = node_vectors(md, line, md.GetLineNodeTen)
        fair_ten = md.GetLineFairTen(line)
        fnet = node_vectors(md, line, md.GetLineNodeForce)
        parts = sum(node_vectors(md, line, getter) for getter in (
            md.GetLineNodeWeight, md.GetLineNodeDrag, md.GetLineNodeFroudeKrilov, md.GetLineNodeSeabedForce))
    t, td = segment_forces(PROBE, pos, vel)
    assert np.abs(td).max() > 1e-3 * np.abs(t).max()  # the damping term is really exercised
    expected = np.vstack([t[:1] + td[:1], 0.5 * (t[1:] + t[:-1] + td[1:] + td[:-1]), t[-1:] + td[-1:]])
    np.testing.assert_allclose(ten, expected, rtol=EXACT, atol=EXACT * np.abs(t).max())
    assert fair_ten == pytest.approx(np.linalg.norm(t[-1] + td[-1]), rel=EXACT)
    inner = np.diff(t + td, axis=0)  # T_i - T_i-1 + Td_i - Td_i-1 at nodes 1..N-1
    np.testing.assert_allclose(fnet[1:n], inner + parts[1:n], rtol=EXACT, atol=EXACT * np.abs(t).max())
    np.testing.assert_allclose(fnet[n], -(t[-1] + td[-1]) + parts[n], rtol=EXACT, atol=EXACT * np.abs(t).max())
    np.testing.assert_allclose(fnet[0], t[0] + td[0] + parts[0], rtol=EXACT, atol=EXACT * np.abs(t).max())


def test_compressed_segments_carry_damping_but_no_stiffness():
    """A slack vertical line (segments 1 m for 2 m unstretched, started straight without IC): zero stiffness force
    in compression, but the internal damping term still acts."""
    line = LineProps(length=10.0, n_segments=5, diameter=0.1, mass_per_length=50.0, EA=1.0e7, BA=-1.0)
    solver = Solver(dtM=1.0e-4, scheme="Euler", ic=False)
    with line_system(line, Environment(depth=100.0), (0.0, 0.0, -20.0), (0.0, 0.0, -15.0), solver) as (
        md, system, handle,
    ):
        pos, vel = euler_probe(md, system, handle, (0.0, 0.0, -15.0), (0.0, 0.0, 0.0), t_drive=0.2)
        ten = node_vectors(md, handle, md.GetLineNodeTen)
    lstr, _, _ = geometry(pos)
    assert (lstr < 2.0).all()
    t, td = segment_forces(line, pos, vel)
    np.testing.assert_array_equal(t, 0.0)
    assert np.abs(td).max() > 1.0  # newtons: the falling nodes stretch-rate the segments
    np.testing.assert_allclose(ten[0], td[0], rtol=EXACT)
    np.testing.assert_allclose(ten[-1], td[-1], rtol=EXACT)


def test_morison_drag_with_current():
    """Drag per node: Dp = 1/2 rho Cd d l_i |vp| vp (transverse) and Dq = 1/2 rho CdAx pi d l_i |vq| vq
    (tangential), v = U - r_dot split along MoorDyn's node tangent q; exact to rounding."""
    env = Environment(depth=200.0, current=(0.3, 0.7, -0.1))
    with line_system(PROBE, env, (100.0, 0.0, -60.0), (0.0, 0.0, -5.0), EULER) as (md, system, line):
        pos, vel = euler_probe(md, system, line, (0.0, 0.0, -5.0), (0.5, -0.4, 0.1), t_drive=1.0)
        drag = node_vectors(md, line, md.GetLineNodeDrag)
    _, _, q = geometry(pos)
    rel = np.asarray(env.current) - vel
    vq = np.einsum("ij,ij->i", rel, q)[:, None] * q
    vp = rel - vq
    li = node_lengths(PROBE)
    dp = 0.5 * env.rho_w * PROBE.Cd * PROBE.diameter * li[:, None] * np.linalg.norm(vp, axis=1)[:, None] * vp
    dq = 0.5 * env.rho_w * PROBE.CdAx * math.pi * PROBE.diameter * li[:, None] * np.linalg.norm(vq, axis=1)[:, None]
    dq = dq * vq
    np.testing.assert_allclose(drag, dp + dq, rtol=EXACT, atol=EXACT * np.abs(drag).max())
    assert np.abs(dq).max() > 1e-3 * np.abs(dp).max()  # the tangential term is really exercised


def test_current_is_ignored_by_the_initial_condition_solve():
    """MoorDyn 2.7.2 applies currents only after its IC solve: the static state is the same with and without one."""
    env = Environment(depth=200.0)
    kwargs = dict(anchor=(100.0, 0.0, -60.0), fairlead=(0.0, 0.0, -5.0))
    still = run_line(PROBE, env, **kwargs)
    flowing = run_line(PROBE, Environment(depth=200.0, current=(0.0, 1.0, 0.0)), t_end=1.0, **kwargs)
    np.testing.assert_array_equal(still.positions[0], flowing.positions[0])
    assert np.abs(flowing.positions[-1, :, 1]).max() > 0.01  # afterwards the current does push the line


@pytest.mark.parametrize("stat_dyn", [1.0, 3.0])
def test_seabed_contact_and_friction(stat_dyn):
    """Seabed force on a node below z = -depth: B_z = ((-depth - z) kBot - v_z cBot) d l_i; horizontal friction
    -min(mu FricDamp |v_h|, mu |B_z|) v_h/|v_h|, except that MoorDyn compares with StatDynFricScale mu |B_z| before
    capping at mu |B_z| (so with StatDynFricScale > 1 the force jumps down at the cap). Exact to rounding."""
    env = Environment(depth=50.0, kbot=1.0e5, cbot=2.0e4, friction=0.6, fric_damp=1.0e5,
                      stat_dyn_fric_scale=stat_dyn)
    solver = Solver(dtM=1.0e-4, scheme="Euler")  # from the IC (cheap here): the chain lies on the bed, at rest
    with line_system(PROBE, env, (100.0, 0.0, -50.0), (0.0, 0.0, -5.0), solver) as (md, system, line):
        pos, vel = euler_probe(md, system, line, (0.0, 0.0, -5.0), (-1.5, 1.0, 0.0), t_drive=1.0)
        bed = node_vectors(md, line, md.GetLineNodeSeabedForce)  # B + bending force, and EI = 0 here
    li = node_lengths(PROBE)
    depth_below = -env.depth - pos[:, 2]
    contact = depth_below > 0
    assert contact.sum() >= 5
    bz = np.where(contact, (depth_below * env.kbot - vel[:, 2] * env.cbot) * PROBE.diameter * li, 0.0)
    speed = np.hypot(vel[:, 0], vel[:, 1])
    cap = np.abs(bz) * env.friction
    ff = speed * env.friction * env.fric_damp
    ff = np.where(ff > env.stat_dyn_fric_scale * cap, cap, ff)
    with np.errstate(invalid="ignore", divide="ignore"):
        fxy = np.where(contact[:, None] & (speed[:, None] > 0), -ff[:, None] * vel[:, :2] / speed[:, None], 0.0)
    np.testing.assert_allclose(bed[:, 2], bz, rtol=EXACT, atol=EXACT * np.abs(bz).max())
    np.testing.assert_allclose(bed[:, :2], fxy, rtol=EXACT, atol=EXACT * np.abs(bz).max())
    # both regimes occur: friction proportional to the sliding speed, and capped at mu |B_z|; with
    # StatDynFricScale = 3 the proportional law runs on past mu |B_z| (up to 3 mu |B_z|) before the cap applies
    ff, cap = ff[contact], cap[contact]
    assert (ff < cap).any()
    if stat_dyn == 1.0:
        assert (ff == cap).any()
    else:
        assert ((ff > cap) & (ff <= stat_dyn * cap)).any()


def test_bending_curvature_and_forces():
    """Bending: curvature K_i = 4 / (l_i-1 + l_i) sqrt((1 - qs_i-1 . qs_i) / 2) at inner nodes (0 at pinned ends);
    with p = unit(qs_i-1 x qs_i), node i-1 gets (qs_i-1 x p) K EI / l_i-1, node i+1 gets (qs_i x p) K EI / l_i and
    node i the opposite of both (l: stretched lengths). GetLineNodeSeabedForce reports B + this bending force."""
    jumper = LineProps(length=170.0, n_segments=34, diameter=0.396, mass_per_length=165.0, EA=5.0e8, BA=-0.5,
                       EI=120.8e3, Cd=1.0, Ca=1.0)
    solver = Solver(dtM=1.0e-4, scheme="Euler", ic=False)  # from MoorDyn's initial catenary: curved enough
    with line_system(jumper, Environment(depth=100.0, rho_w=1000.0), (-100.0, 0.0, -55.0), (0.0, 0.0, -5.0),
                     solver) as (md, system, line):
        pos, _ = euler_probe(md, system, line, (0.0, 0.0, -5.0), (0.5, 0.0, 0.2), t_drive=0.2)
        curv = np.array([md.GetLineNodeCurv(line, i) for i in range(jumper.n_segments + 1)])
        bend = node_vectors(md, line, md.GetLineNodeBendStiff)
        bed = node_vectors(md, line, md.GetLineNodeSeabedForce)
    lstr, qs, _ = geometry(pos)
    dots = np.einsum("ij,ij->i", qs[:-1], qs[1:])
    inner = np.where(dots > 1.0, 0.0, 4.0 / (lstr[:-1] + lstr[1:]) * np.sqrt(0.5 * (1 - dots)))
    k = np.concatenate([[0.0], inner, [0.0]])
    assert k.max() > 0.01  # 1/m: a bent line, so the check is not vacuous
    np.testing.assert_allclose(curv, k, rtol=EXACT, atol=EXACT * k.max())
    p = np.cross(qs[:-1], qs[1:])
    p /= np.linalg.norm(p, axis=1)[:, None]
    f_prev = np.cross(qs[:-1], p) * (k[1:-1] * jumper.EI / lstr[:-1])[:, None]
    f_next = np.cross(qs[1:], p) * (k[1:-1] * jumper.EI / lstr[1:])[:, None]
    expected = np.zeros_like(pos)
    expected[:-2] += f_prev
    expected[2:] += f_next
    expected[1:-1] -= f_prev + f_next
    np.testing.assert_allclose(bend, expected, rtol=EXACT, atol=EXACT * np.abs(expected).max())
    np.testing.assert_allclose(bed, bend, rtol=EXACT, atol=EXACT * np.abs(expected).max())  # clear of the bed


def test_cfl_time_step():
    """With a CFL option instead of dtM (MoorDyn's WD0600 case), dtM = CFL 2 pi sqrt(m' l / (EA / l)), the period of
    one segment's axial spring carrying the segment's mass (no added mass)."""
    import cmoordyn

    text = set_options((CASES / "WD0600_Chain.txt").read_text(encoding="utf-8"), {"writeLog": 0, "TmaxIC": 0.0})
    with moordyn_system(text, (0.0, 0.0, 0.0)) as (md, system):
        dt = cmoordyn.get_dt(system)
    seg = 1700.0 / 170
    assert dt == pytest.approx(0.1 * 2 * math.pi * math.sqrt(390.0 * seg / (1.674e9 / seg)), rel=1e-12)


# ----------------------------------------------------------------------------- stored references


def stored_cases():
    """The stored reference cases: names of tests/data/moordyn/<case>.json (not own_cases.json and own_systems.json,
    the further runs of scripts/compare_moordyn_cases.py and compare_moordyn_systems.py, in their own layouts)."""
    return sorted(p.stem for p in DATA.glob("*.json") if p.stem not in ("own_cases", "own_systems"))


def test_stored_references_exist_and_are_small():
    """The references the brief asks for are there, each with its inputs and wall times, and under 2 MB in all."""
    names = stored_cases()
    assert {"WD0050_Chain", "WD0200_Chain", "WD0600_Chain", "BeamCantilevered", "lowe_and_langley_2006"} <= set(names)
    total = sum(p.stat().st_size for p in DATA.rglob("*") if p.is_file())
    assert total < 2_000_000
    for name in names:
        meta = json.loads((DATA / f"{name}.json").read_text())
        data = np.load(DATA / f"{name}.npz")
        assert meta["moordyn_version"] and meta["dynamic"]["wall_time_s"] > 0
        assert data["t"].shape == data["fairlead_tension"].shape == data["anchor_tension"].shape
        assert data["node_positions"].shape == (len(data["t"]), len(data["node_index"]), 3)


def test_stored_static_tensions_reproduce():
    """The static fairlead tension stored for each chain case is what MoorDyn's IC gives now (deterministic: to
    1e-9, the tolerance only absorbs the JSON's decimal round trip)."""
    for name in ("WD0050_Chain", "WD0200_Chain", "WD0600_Chain"):
        meta = json.loads((DATA / f"{name}.json").read_text())
        run = run_input_file(CASES / meta["input_file"])
        assert run.fairlead_tension[0] == pytest.approx(meta["static"]["fairlead_tension_N"], rel=1e-9)
        assert run.anchor_tension[0] == pytest.approx(meta["static"]["anchor_tension_N"], rel=1e-9)


@pytest.fixture(scope="module")
def reference_script():
    """scripts/moordyn_reference.py, imported as a module (it is not a package)."""
    import importlib.util
    import sys

    path = Path(__file__).parent.parent / "scripts" / "moordyn_reference.py"
    spec = importlib.util.spec_from_file_location("moordyn_reference", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up there
    spec.loader.exec_module(module)
    yield module
    del sys.modules[spec.name]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["WD0050_Chain", "WD0200_Chain", "WD0600_Chain", "lowe_and_langley_2006",
                                  "BeamCantilevered"])
def test_stored_dynamic_runs_reproduce(name, reference_script):
    """Each stored dynamic run regenerates from scripts/moordyn_reference.py's recipe to 1e-9 (the same binary
    gives bit-identical runs; the tolerance allows another CPU's libm)."""
    data = np.load(DATA / f"{name}.npz")
    fresh = reference_script.dynamic_run(reference_script.CASES[name])
    np.testing.assert_allclose(fresh.fairlead_tension, data["fairlead_tension"], rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(fresh.positions[:, data["node_index"]], data["node_positions"], rtol=1e-9, atol=1e-9)
