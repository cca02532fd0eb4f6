"""The free surface ([sea]) and waves in the forces: buoyancy on the submerged part alone (a line piercing the
surface, a floating line at Archimedes' draught, both in closed form), drag split between water and air, the
water's inertia force (a neutrally buoyant line rides the Airy orbit), and the bad input the loader refuses."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import optimize

import ropesim
from ropesim.model.build import build
from ropesim.model.terms import accelerations, switches

RHO, G = 1025.0, 9.81
ROOT = Path(__file__).resolve().parent.parent


def scene_of(text: str, sets=()):
    return ropesim.scene_from_toml(text, overrides=list(sets))


def hose(mass_per_length: float, diameter: float = 0.1, extra: str = "", y: float = 0.0, nodes: int = 21) -> str:
    return f"""
name = "hose"
dimension = 2
[rope]
length = 20.0
segments = {nodes - 1}
mass_per_length = {mass_per_length}
diameter = {diameter}
EA = 1.0e6
[initial]
shape = "line"
start = [0.0, {y}]
end = [20.0, {y}]
[gravity]
g = {G}
[fluid]
density = {RHO}
[buoyancy]
[sea]
level = 0.0
[integrator]
method = "sdirk2"
dt = 0.01
t_end = 1.0
{extra}
"""


def net_force(model, x, v=None, t=0.0):
    """Every node's force m a [N] (D, N) from the compiled term list."""
    acc = np.zeros_like(x)
    model.kernel(accelerations)(x, np.zeros_like(x) if v is None else v, acc, model.params, t)
    return acc * model.mass


def wet_area(yc: float, r: float) -> float:
    """The wetted cross-section [m^2] of a horizontal cylinder of radius r, its axis at height yc, the surface at
    0: a circular segment."""
    u = min(max(-yc / r, -1.0), 1.0)
    return r * r * (math.acos(-u) + u * math.sqrt(1 - u * u))


def draught_centre(mass_per_length: float, r: float) -> float:
    """The height of a floating cylinder's axis by Archimedes: rho A_wet(yc) = m'."""
    return optimize.brentq(lambda yc: RHO * wet_area(yc, r) - mass_per_length, -r, r, xtol=1e-15)


def test_a_rope_scene_compiles_none_of_the_sea():
    """A scene without [sea] switches none of it on (so its kernels compile none of it), and its bundle is empty;
    with [sea] and no [waves], the waves stay off."""
    scene = ropesim.load_scene(ROOT / "scenarios" / "buoy_tether.toml")
    on = switches(scene)
    assert "sea" not in on and "waves" not in on
    assert build(scene).params.sea.nodes.shape[1] == 0
    still = switches(scene_of(hose(4.0)))
    assert "sea" in still and "waves" not in still


def test_a_vertical_line_piercing_the_surface_is_buoyed_by_its_submerged_part_alone():
    """A vertical line from y = -7.3 to 2.7 m: the net buoyancy is rho g A (7.3 m) exactly, whichever node the
    surface crosses, and the weight is the whole line's."""
    d, mu = 0.2, 10.0
    for top in (2.7, 3.0, 0.05):
        text = hose(mu, d).replace("end = [20.0, 0.0]", f"end = [0.0, {top}]").replace(
            "start = [0.0, 0.0]", f"start = [0.0, {top - 10.0}]").replace("length = 20.0", "length = 10.0")
        model = build(scene_of(text))
        x = model.x0.copy()
        f = net_force(model, x)
        area = math.pi * d * d / 4
        wet = 10.0 - top
        assert f[1].sum() == pytest.approx(RHO * G * area * wet - mu * 10.0 * G, rel=1e-12, abs=1e-9)
        assert np.allclose(f[0], 0.0, atol=1e-9)
        # node by node: rho g A times the length of its two half segments below the surface (without
        # [buoyancy] the same scene's forces are the weight and the springs')
        dry = build(scene_of(text.replace("[buoyancy]\n", "")))
        lift = (f - net_force(dry, x))[1]
        y = x[1]
        lo = np.concatenate([[y[0]], 0.5 * (y[:-1] + y[1:])])     # each node's share, from the middle below
        hi = np.concatenate([0.5 * (y[:-1] + y[1:]), [y[-1]]])    # to the middle above
        wet_share = np.clip(np.minimum(hi, 0.0) - lo, 0.0, None) * (10.0 / (y[-1] - y[0]))
        assert np.allclose(lift, RHO * G * area * wet_share, rtol=0, atol=1e-9)
        assert (wet_share == 0).sum() == int(top // 0.5)   # the nodes wholly in air


def test_a_floating_line_rests_at_archimedes_draught():
    """A horizontal hose lighter than water: at the draught where rho A_wet = m' (a circular segment) every
    node's force vanishes; lifted or lowered by a tenth of the radius it is pushed back by rho g times the
    change of the circular segment, per metre."""
    d, r = 0.1, 0.05
    for mu in (2.0, 4.0, 7.5):
        yc = draught_centre(mu, r)
        model = build(scene_of(hose(mu, d, y=yc)))
        f = net_force(model, model.x0)
        assert np.abs(f).max() < 1e-9 * mu * G
        for dy in (0.1 * r, -0.1 * r):
            x = model.x0.copy()
            x[1] += dy
            f = net_force(model, x)
            expect = RHO * G * (wet_area(yc + dy, r) - wet_area(yc, r))   # per metre
            assert expect * dy < 0
            assert f[1].sum() / 20.0 == pytest.approx(expect, rel=1e-9)
            assert np.allclose(f[1] / model.params.node_length, expect, rtol=1e-9, atol=0)   # node by node


def test_drag_in_air_above_the_surface_and_in_water_below():
    """A held line 5 m above the water, in a wind blowing up at 10 m/s, moving up at 0.5 m/s: each metre feels
    the air's drag, rho_air Cd d / 2 |v - w| (v - w); 5 m below the surface, the water's on its own velocity; in
    a floating position, half under, half of each."""
    extra = "[fluid_drag]\ncd_normal = 1.2\ncd_tangential = 0.0\n[pinned]\nnodes = [0, -1]\n"
    text = hose(4.0, 0.1, extra=extra).replace("[sea]\nlevel = 0.0", "[sea]\nlevel = 0.0\nwind = [0.0, 10.0]")
    air, water = 1.225 * 1.2 * 0.1 / 2, RHO * 1.2 * 0.1 / 2
    for y, per_metre in ((5.0, air * 9.5 * 9.5 - air * 10.0 * 10.0), (-5.0, -water * 0.5 * 0.5),
                         (0.0, 0.5 * (-water * 0.5 * 0.5) + 0.5 * (air * 9.5 * 9.5 - air * 10.0 * 10.0))):
        model = build(scene_of(text.replace("start = [0.0, 0.0]", f"start = [0.0, {y}]").replace(
            "end = [20.0, 0.0]", f"end = [20.0, {y}]")))
        v = np.zeros_like(model.x0)
        v[1] = 0.5
        drag = net_force(model, model.x0, v) - net_force(model, model.x0)   # what the velocity changes
        assert np.allclose(drag[1, 1:-1], per_metre, rtol=1e-12, atol=0)    # 1 m per interior node
        assert np.allclose(drag[0], 0.0, atol=1e-12)


def test_a_neutrally_buoyant_line_rides_the_water():
    """A short line of the water's own density under a regular wave, no drag: Froude-Krylov alone, rho V du/dt
    (Ca = 0), accelerates each node as the water's local acceleration there. Started with the water's velocity,
    its centre of mass (the springs' forces cancel in it; the line is 0.1 mm long, so the field's curvature
    across it is (k gap)^2 ~ 1e-9) follows x'' = du/dt(x, t) (scipy's solve_ivp on the NumPy wave field) and,
    over its first period, the circular orbit of radius R = a e^(k y) of deep water to first order in the
    steepness. (The local acceleration, MoorDyn's too, lacks the convective part u . grad u, so the line sinks
    by k R^2 w^2 t^2 / 2 relative to a water particle: 2.7 mm after the first period.)"""
    from scipy.integrate import solve_ivp

    from ropesim.model.waves import wave_field

    d = 0.1
    mu = RHO * math.pi * d * d / 4
    a, period, y0, gap = 0.05, 4.0, -3.0, 1e-4
    omega = 2 * math.pi / period
    k = omega ** 2 / G
    text = f"""
name = "neutral"
dimension = 2
[rope]
length = {gap}
segments = 1
mass_per_length = {mu!r}
diameter = {d}
EA = 1e-4
[initial]
shape = "points"
points = [[0.0, {y0}], [{gap}, {y0}]]
velocities = VELOCITIES
[gravity]
g = {G}
[fluid]
density = {RHO}
[buoyancy]
[sea]
level = 0.0
[waves]
kind = "regular"
height = {2 * a}
period = {period}
stretching = "vertical"
[integrator]
method = "rk4"
dt = 0.002
t_end = {2 * period}
[output]
interval = 0.5
"""
    field = wave_field(scene_of(text.replace("VELOCITIES", "[[0.0, 0.0], [0.0, 0.0]]")))
    u0 = [[float(c) for c in field.kinematics(x, y0, 0.0)[1][:2]] for x in (0.0, gap)]
    scene = scene_of(text.replace("VELOCITIES", f"[[{u0[0][0]!r}, {u0[0][1]!r}], [{u0[1][0]!r}, {u0[1][1]!r}]]"))
    traj = ropesim.simulate(scene)

    def rhs(t, s):
        du = field.kinematics(s[0], s[1], t)[2]
        return [s[2], s[3], du[0], du[1]]

    start = [0.5 * gap, y0, *field.kinematics(0.5 * gap, y0, 0.0)[1][:2]]
    ref = solve_ivp(rhs, (0, 2 * period), start, t_eval=traj.t, rtol=1e-11, atol=1e-13)
    centre = traj.x.mean(axis=1)
    assert np.abs(centre[:, 0] - ref.y[0]).max() < 1e-7
    assert np.abs(centre[:, 1] - ref.y[1]).max() < 1e-7
    radius = a * math.exp(k * y0)
    circle = np.stack([radius * np.sin(omega * traj.t), y0 + radius * (np.cos(omega * traj.t) - 1)], axis=1)
    first = traj.t <= period
    assert np.abs(centre[first] - circle[first]).max() < 0.5 * k * (radius * omega * period) ** 2
    assert np.ptp(centre[first, 0]) == pytest.approx(2 * radius, rel=0.02)


def test_sea_and_waves_keys_refused_with_one_line(tmp_path):
    """Bad input: each refused in one line naming the file and the key, exit 2."""
    base = hose(4.0)
    cases = {
        "[waves]\nkind = \"jonswap\"\nsignificant_height = -1.0\npeak_period = 10.0\n": "waves.significant_height",
        "[waves]\nkind = \"regular\"\nheight = 1.0\nperiod = -2.0\n": "waves.period",
        "[waves]\nkind = \"regular\"\nheight = 5.0\nperiod = 2.0\n": "waves.height",         # H/L = 0.8
        "[waves]\nkind = \"table\"\ntable_file = \"comps.csv\"\n": "waves.table_file",
        "[waves]\nkind = \"regular\"\nheight = 1.0\nperiod = 5.0\nseed = 3\n": "waves.seed",
        "[waves]\nkind = \"swell\"\n": "waves.kind",
        "[viscous_drag]\nb_normal = 1.0\nb_tangential = 0.1\n": "viscous_drag",
        "[drag]\nb = 0.1\n": "drag",
        "[waves]\nkind = \"jonswap\"\nsignificant_height = 2.0\npeak_period = -8.0\n": "waves.peak_period",
        "[waves]\nkind = \"jonswap\"\nsignificant_height = 12.0\npeak_period = 3.0\n": "waves.significant_height",
        "[waves]\nkind = \"table\"\ntable = [[0.5, 1.0, 0.0]]\n": "waves.table",
        "[waves]\nkind = \"regular\"\nheight = 1.0\nperiod = 5.0\nstretching = \"linear\"\n": "waves.stretching",
    }
    (tmp_path / "comps.csv").write_text("amplitude,frequency,phase\n0.5,1.0,0\n")
    for extra, key in cases.items():
        path = tmp_path / "s.toml"
        path.write_text(base + extra)
        out = subprocess.run([sys.executable, "-m", "ropesim", "check", str(path)], capture_output=True, text=True)
        assert out.returncode == 2, (extra, out.stdout, out.stderr)
        lines = out.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in out.stderr, out.stderr
        assert key in lines[0] and "s.toml" in lines[0], lines[0]
        if key == "waves.table_file":
            assert "no 'direction' column" in lines[0]


# slow, every case: each is a loop of a scene with a [sea] above it that no other test compiles (buoy_tether's
# sdirk2 with the sea: 19 s of a cold quick run); the sea's forces per node stay quick (below)
@pytest.mark.parametrize("name, sets", [
    pytest.param("buoy_tether", ["integrator.t_end=10.0", "output.interval=1.0"], marks=pytest.mark.slow),
    pytest.param("buoy_tether", ["integrator.method=rk4", "integrator.dt=5e-4", "integrator.t_end=2.0",
                                 "output.interval=0.5"], marks=pytest.mark.slow),
    pytest.param("spread_mooring", ["integrator.t_end=10.0", "output.interval=1.0"], marks=pytest.mark.slow),
])
def test_a_surface_above_everything_changes_nothing(name, sets):
    """A scene wholly under water runs the same with a [sea] above it as without: the buoyancy, the drag in the
    current, the added mass (a line's, a body's; rewritten from the submerged fractions at every evaluation)
    and the ramping current's inertia force all on the whole of every node (to round-off: the sea's term
    evaluates the same forces in another order)."""
    scene = ropesim.load_scene(ROOT / "scenarios" / f"{name}.toml", sets)
    from dataclasses import replace

    from ropesim.scene.schema import Sea

    wet = replace(scene, sea=Sea(level=10.0))
    assert "sea" in switches(wet) and "flow_inertia" not in switches(wet)
    dry, sea = ropesim.simulate(scene), ropesim.simulate(wet)
    assert np.ptp(dry.x[:, :, 0]) > 1e-3   # it moves
    assert np.abs(sea.x - dry.x).max() < 1e-9
    assert np.abs(sea.v - dry.v).max() < 1e-8


@pytest.mark.parametrize("ca", [0.0, 1.0])
def test_a_floating_line_heaves_at_its_natural_period(ca):
    """A hose of half the water's density floats half under (its axis at the surface). Lifted by 1 % of its
    radius and let go (no drag), it heaves at omega^2 = rho g 2 r / (m' + f rho A Ca), f = 1/2 of its added
    mass in the water: 4 g / (pi r) without added mass, 2 g / (pi r) with Ca = 1 (rk4; the period from the
    zero crossings, to 0.2 %: the amplitude's nonlinearity is of order 1e-4)."""
    r = 0.05
    area = math.pi * r * r
    mu = 0.5 * RHO * area
    text = hose(mu, 2 * r, y=0.01 * r).replace("EA = 1.0e6", "EA = 1.0e4").replace(
        'method = "sdirk2"\ndt = 0.01\nt_end = 1.0', 'method = "rk4"\ndt = 0.002\nt_end = 3.0')
    if ca:
        text += f"[added_mass]\nca_normal = {ca}\n"
    traj = ropesim.simulate(scene_of(text, ["output.interval=0.002"]))
    y = traj.x[:, 10, 1]
    down = np.nonzero((y[:-1] > 0) & (y[1:] <= 0))[0]
    crossings = traj.t[down] + y[down] / (y[down] - y[down + 1]) * 0.002   # interpolated linearly
    period = np.diff(crossings).mean()
    omega2 = RHO * G * 2 * r / (mu + 0.5 * RHO * area * ca)
    assert len(crossings) >= 3
    assert period == pytest.approx(2 * math.pi / math.sqrt(omega2), rel=2e-3)


def test_the_viewer_draws_the_sea():
    """A run's page shows the sea: in 2-D its mean level, in 3-D with waves a grid that moves with them, each
    frame's heights the waves' elevation there (the page itself is tested by tests/test_viewer_browser.py)."""
    from ropesim.model.waves import wave_field
    from ropesim.viewer.content import run_content

    flat = run_content(ropesim.simulate(scene_of(hose(4.0), ["integrator.t_end=0.05", "output.interval=0.01"])))
    assert flat.water.height == 0.0 and flat.water.heights is None
    text = hose(4.0).replace("dimension = 2", "dimension = 3").replace("[0.0, 0.0]", "[0.0, 0.0, 0.0]").replace(
        "[20.0, 0.0]", "[20.0, 0.0, 0.0]").replace("level = 0.0", "level = -1.0")
    text += '[waves]\nkind = "regular"\nheight = 0.5\nperiod = 6.0\ndirection = 30.0\n'
    scene = scene_of(text, ["integrator.t_end=0.3", "output.interval=0.1"])
    content = run_content(ropesim.simulate(scene))
    water = content.water
    assert water.heights.shape == (4, 33, 33)
    assert water.x[0] < 0.0 and water.x[-1] > 20.0
    field = wave_field(scene)
    for frame in (0, 3):
        expect = -1.0 + field.elevation(water.x[:, None], content.t[frame], water.z[None, :])
        assert np.allclose(water.heights[[frame]][0], expect, rtol=0, atol=1e-12)
    assert np.ptp(water.heights[[3]]) > 0.4


def test_check_names_the_sea_and_its_waves(tmp_path):
    """`ropesim check` lists the sea among the force terms: level, depth, air, the waves' kind and figures (the
    regular wave's length from the dispersion relation), stretching and ramp."""
    path = tmp_path / "s.toml"
    path.write_text(hose(4.0, extra="[waves]\nkind = \"regular\"\nheight = 1.0\nperiod = 5.0\nramp_time = 10.0\n"))
    out = subprocess.run([sys.executable, "-m", "ropesim", "check", str(path)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    text = " ".join(out.stdout.replace("│", " ").split())
    length = 2 * math.pi * G / (2 * math.pi / 5.0) ** 2   # deep water: the hose's sea has no seabed
    assert "sea (level y = 0 m, deep water, air 1.225 kg/m^3)" in text
    assert f"regular waves H = 1 m, T = 5 s (L = {length:.4g} m), wheeler stretching, ramped over 10 s" in text


def test_the_run_time_estimate_counts_the_waves():
    """The estimate adds the sea's cost per node and evaluation, and each component's: a table of 200 is
    evaluated directly, a spectrum of 200 by the recurrence (scripts/bench_waves.py measures both)."""
    from ropesim.run import estimate

    base = ropesim.scene_from_toml(hose(4.0))
    table = "\n".join(f"  [0.01, {0.5 + 0.01 * j}, 0.0, 0.0]," for j in range(200))
    direct = ropesim.scene_from_toml(hose(4.0, extra=f"[waves]\nkind = \"table\"\ntable = [\n{table}\n]\n"))
    spectrum = ropesim.scene_from_toml(hose(4.0, extra="[waves]\nkind = \"jonswap\"\nsignificant_height = 1.0\n"
                                                       "peak_period = 8.0\ncomponents = 200\n"))
    still, slow, fast = (estimate(s).seconds for s in (base, direct, spectrum))
    assert still < fast < slow
    assert (slow - still) / (fast - still) == pytest.approx(36 / 2)   # the hose's [sea] is in all three


def _moordyn_calc_sub_seg(a, b, surface, d):
    """MoorDyn 2.7's Line::calcSubSeg transcribed in its own frame (z up) with its vector algebra, for
    :func:`test_moordyn_fraction_rule_is_moordyns`."""
    a, b = np.array(a, float), np.array(b, float)
    za, zb = a[2] - surface, b[2] - surface
    if za <= 0 and zb < 0:
        return 1.0
    if za > 0 and zb > 0:
        return 0.0
    if za == -zb:
        return 0.5
    lower, upper = (a.copy(), b.copy()) if za < 0 else (b.copy(), a.copy())
    lower[2] -= surface
    upper[2] -= surface
    axis = upper - lower
    up = np.array([0.0, 0.0, 1.0])
    normal = np.cross(axis, np.cross(up, axis))
    if np.linalg.norm(normal) > 0:
        normal = normal / np.linalg.norm(normal) * d / 2
    lower, upper = lower - normal, upper + normal
    return abs(lower[2]) / (abs(lower[2]) + upper[2])


def test_moordyn_fraction_rule_is_moordyns():
    """``[sea] fraction = "moordyn"``: each segment's fraction as MoorDyn's calcSubSeg computes it (transcribed
    above with its cross products, in its z-up frame), for segments of every slope and heading across a
    surface, wholly in and out of the water, and vertical, to round-off."""
    from ropesim.model.forces.sea import moordyn_segment_fraction

    rng = np.random.default_rng(7)
    d, surface = 0.3, 0.4
    for _ in range(400):
        a = rng.uniform(-2, 2, 3)
        b = a + rng.normal(size=3) * rng.choice([0.1, 1.0, 3.0])
        if rng.random() < 0.1:
            b[:2] = a[:2]                         # vertical
        x = np.array([[a[0], b[0]], [a[2], b[2]], [-a[1], -b[1]]])   # MoorDyn (x, y, z) -> ropesim (x, z, -y)
        ours = moordyn_segment_fraction(x, 0, 1, surface, d / 2)
        assert ours == pytest.approx(_moordyn_calc_sub_seg(a, b, surface, d), abs=1e-12)
