"""ropesim against MoorDyn on equal physics (tests/references/moordyn_equal_physics.py has the cases and the
conventions; scripts/compare_moordyn.py the full-size comparison behind docs/background/validation.md).

The same lumped-mass chain in both codes, from the same start: Morison drag on the velocity relative to a current,
buoyancy, added mass across and along, axial damping, tension-only segments, a clump on a free end. The fast tests
run each case small (10 segments); the slow ones at the documented size.

What the tolerances rest on (measured, MoorDyn 2.7.2): both codes solve the same equations, so what is left is each
one's time-step error, and MoorDyn's RK2 has the larger one: with MoorDyn's RK4 at the same step the difference
falls 4 to 20 times (``test_moordyn_rk2_is_what_is_left``). The tolerances sit 5 to 20 times above the measured
differences (room for another MoorDyn version's RK2, other platforms) and at least three times below what one
wrong coefficient does (``test_a_wrong_coefficient_breaks_the_agreement``: drag 2 % off, added mass 10 % off,
axial damping 50 % off, no buoyancy, ...), so a regression in ropesim's drag, buoyancy, added mass or damping fails
here. Units: SI.
"""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("moordyn")
pytestmark = pytest.mark.slow   # four MoorDyn runs and four scenes of their own parts: the slow suite

ROOT = Path(__file__).resolve().parent.parent

from references.moordyn_equal_physics import (  # noqa: E402
    CASES,
    CHAIN,
    CLUMP,
    DEFAULT_IC,
    TIGHT_IC,
    Series,
    compare,
    exact_static_line,
    run_moordyn,
    run_ropesim,
)

#: The cases at 10 segments (l = 3 m on the hanging line, 6 m on the catenary). MoorDyn's RK2 and ropesim's verlet
#: at the same step: 0.5 ms on the hanging line (0.36 of verlet's bound); 0.1 ms on the catenary, whose snap taut
#: from MoorDyn's initial shape needs it (MoorDyn's RK2 error there converges at first order only: the slack
#: segments switch on and off; at 0.5 ms it is 1 % of the tension range, at 0.2 ms 0.4 %, at 0.1 ms 0.19 %).
SMALL = {
    "current": CASES["current"].with_(segments=10, t_end=20.0, dtM=5e-4, dt=5e-4),
    "towed": CASES["towed"].with_(segments=10, t_end=20.0, dtM=5e-4, dt=5e-4),
    "catenary": CASES["catenary"].with_(segments=10, t_end=10.0, dtM=1e-4, dt=1e-4),
}

#: Largest allowed differences, ropesim - MoorDyn RK2, over frames 1..end: top and bottom tension RMS as a fraction
#: of the top tension's range, node positions RMS (m). Measured (10 segments): top 1.9e-5, 1.5e-4, 1.9e-3; bottom
#: 3.5e-6, 5.0e-5, 1.8e-4; positions 1.9e-7, 4.8e-8, 4.9e-7 m (current, towed, catenary).
TOLERANCE = {
    "current": {"top": 2e-4, "pos": 2e-6},
    "towed": {"top": 1e-3, "pos": 1e-6},
    "catenary": {"top": 1e-2, "pos": 5e-6},
}


@pytest.fixture(scope="module")
def moordyn_runs():
    """MoorDyn's RK2 run of each small case, and its start (shared by every test here)."""
    return {name: run_moordyn(case) for name, case in SMALL.items()}


def differences(name: str, md, **physics) -> dict:
    case = SMALL[name]
    rs = run_ropesim(case, md.positions[0], **physics)
    assert rs.summary["status"] == "completed", rs.summary
    return compare(case, Series.of_moordyn(md), Series.of_ropesim(rs))


def assert_agrees(name: str, d: dict) -> None:
    tol = TOLERANCE[name]
    assert d["top_rms_rel"] < tol["top"], f"top tension RMS {d['top_rms']:.3g} N of range {d['top_range']:.3g} N"
    assert d["bottom_rms"] / d["top_range"] < tol["top"], f"bottom tension RMS {d['bottom_rms']:.3g} N"
    assert d["pos_rms"] < tol["pos"], f"node positions RMS {d['pos_rms']:.3g} m"


def test_hanging_line_in_a_current(moordyn_runs):
    """A chain with a clump on its free end, hanging from a fixed point, a 1.12 m/s current on from t = 0: drag
    across and along, buoyancy, added mass, the clump's drag and added mass."""
    d = differences("current", moordyn_runs["current"])
    assert_agrees("current", d)
    assert d["top_range"] > 200.0   # the current moves the top tension by 275 N: the test is not of a still line


def test_line_with_its_top_towed(moordyn_runs):
    """The same line with its top towed at 1 m/s through still water from t = 0: the jerk rings the axial modes
    (axial damping, added mass), then the line trails back."""
    d = differences("towed", moordyn_runs["towed"])
    assert_agrees("towed", d)


def test_catenary_snapping_taut_while_its_fairlead_moves(moordyn_runs):
    """A catenary between an anchor and a fairlead released from MoorDyn's initial shape (some segments slack) while
    the fairlead moves at 0.36 m/s: tension-only segments snapping taut, then a line being stretched."""
    md = moordyn_runs["catenary"]
    case = SMALL["catenary"]
    strain = np.linalg.norm(np.diff(md.positions[0], axis=0), axis=1) / (case.length / case.segments) - 1.0
    assert strain.min() < -1e-4   # the test covers slack segments
    d = differences("catenary", md)
    assert_agrees("catenary", d)


def test_static_catenary_against_the_exact_discrete_line():
    """The catenary's static state: the exact discrete line (solved independently, see ``exact_static``), ropesim
    started there and held (it must not move: its weight, buoyancy and EA balance), and MoorDyn's IC."""
    case = SMALL["catenary"].with_(top_velocity=None, t_end=2.0)
    start, tension = exact_static_line(case)
    top, bottom = tension[-1], tension[0]
    assert np.abs(start[-1] - case.top).max() < 1e-9   # the exact line closes on the fairlead
    rs = run_ropesim(case, start)
    tension = np.asarray(rs.tension)
    assert tension[-1, -1] == pytest.approx(top, rel=1e-6)
    assert tension[-1, 0] == pytest.approx(bottom, rel=1e-6)
    assert np.abs(np.asarray(rs.x)[-1] - np.asarray(rs.x)[0]).max() < 1e-6
    # MoorDyn's IC, at dtM = 0.5 ms: its default (stationary) solver stops at once at dtM = 0.1 ms with this line,
    # 18 % short (MOORDYN_CONVENTIONS.md, section 12)
    ic = case.with_(ic=True, dtM=5e-4)
    tight = run_moordyn(ic.with_(ic_options=TIGHT_IC), t_end=0.0)
    assert tight.fairlead_tension[0] == pytest.approx(top, rel=1e-4)
    assert tight.anchor_tension[0] == pytest.approx(bottom, rel=1e-3)
    default = run_moordyn(ic.with_(ic_options=DEFAULT_IC), t_end=0.0)
    assert default.fairlead_tension[0] == pytest.approx(top, rel=1e-3)   # measured: 1.5e-4 short


@pytest.mark.parametrize("name", ["towed", "catenary"])
def test_moordyn_rk2_is_what_is_left(name):
    """With MoorDyn's RK4 at the same step the difference to ropesim (PEFRL, 4th order, so its own step error is
    small) shrinks at least fourfold: the physics is the same, MoorDyn's RK2 is what differs."""
    case = SMALL[name].with_(t_end=5.0)
    rk2, rk4 = run_moordyn(case), run_moordyn(case, scheme="RK4")
    rs = Series.of_ropesim(run_ropesim(case, rk2.positions[0], method="pefrl"))
    with_rk2 = compare(case, Series.of_moordyn(rk2), rs)
    with_rk4 = compare(case, Series.of_moordyn(rk4), rs)
    assert with_rk4["top_rms"] < 0.25 * with_rk2["top_rms"]


#: One coefficient wrong in ropesim's input (MoorDyn keeps the right one), and what it does on the towed line
#: (10 segments) to the measured differences, in multiples of their tolerance (the largest one):
REGRESSIONS = {
    "drag across 2 % high": dict(Cd=CHAIN.Cd * 1.02),                     # positions 37 000x, top 8x
    "drag along 2 % high": dict(CdAx=CHAIN.CdAx * 1.02),                  # positions 570x, top 16x
    "added mass across 10 % low": dict(Ca=CHAIN.Ca * 0.9),                # positions 1200x
    "added mass along 0.1, not 0": dict(CaAx=0.1),                        # positions 9x, top 6x
    "axial damping 50 % high": dict(BA=CHAIN.BA * 1.5),                   # top 6x (25 % high: 3.5x)
    "no buoyancy": dict(buoyancy=False),                                  # positions 270 000x
    "clump drag 10 % high": dict(clump=replace(CLUMP, cd_area=CLUMP.cd_area * 1.1)),   # positions 2700x
    "clump added mass 0": dict(clump=replace(CLUMP, ca=0.0)),             # positions 2000x, top 20x
}
FAST_REGRESSIONS = ("drag across 2 % high", "added mass across 10 % low", "axial damping 50 % high")


@pytest.mark.parametrize("regression", [
    pytest.param(name, marks=() if name in FAST_REGRESSIONS else pytest.mark.slow) for name in REGRESSIONS])
def test_a_wrong_coefficient_breaks_the_agreement(moordyn_runs, regression):
    """Each regression takes at least one measured difference to three times its tolerance or more."""
    d = differences("towed", moordyn_runs["towed"], **REGRESSIONS[regression])
    tol = TOLERANCE["towed"]
    worst = max(d["top_rms_rel"] / tol["top"], d["bottom_rms"] / d["top_range"] / tol["top"],
                d["pos_rms"] / tol["pos"])
    assert worst > 3.0, d


# ------------------------------------------------------------------------------------------------ full size


@pytest.mark.parametrize("name", list(CASES))
def test_full_size_agreement_as_documented(name):
    """The documented comparison (docs/background/validation.md, scripts/compare_moordyn.py), case by case:
    steady tensions to 1e-8, the top and bottom tensions over time to 2e-5 (current), 3e-4 (towed) and 2e-3
    (catenary) of the top tension's range, node positions to 1e-7 m (1e-5 m on the catenary). Measured: steady
    2e-10; 2.6e-6, 1.1e-4, 9.6e-4 of the range; positions 1.3e-8, 1.0e-8, 1.1e-6 m RMS."""
    case = CASES[name]
    md = run_moordyn(case)
    d = compare(case, Series.of_moordyn(md), Series.of_ropesim(run_ropesim(case, md.positions[0])))
    top_tol, pos_tol = {"current": (2e-5, 1e-7), "towed": (3e-4, 1e-7), "catenary": (2e-3, 1e-5)}[name]
    assert d["top_rms_rel"] < top_tol
    assert d["bottom_rms"] / d["top_range"] < top_tol
    assert d["pos_rms"] < pos_tol
    if case.steady:
        assert abs(d["steady_top_rel"]) < 1e-8
        assert abs(d["steady_bottom_rel"]) < 1e-8
    assert math.isfinite(d["top_max"])


def test_the_comparison_script_runs(tmp_path):
    """scripts/compare_moordyn.py on one case, agreement only: its tables and its figure."""
    figure = tmp_path / "figure.png"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "compare_moordyn.py"), "--cases", "catenary",
                             "--no-speed", "--figure", str(figure)], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert "| catenary: catenary, fairlead moved | static top tension" in result.stdout
    assert "| catenary | " in result.stdout   # the table of where the differences come from
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ----------------------------------------------------------------------------------------- accelerating water


def test_a_ramped_flow_carries_a_neutrally_buoyant_rope_along():
    """Morison's equation in an accelerating uniform flow U(t): a rope as dense as the water, started with it at
    rest, moves exactly with it (relative velocity 0, so no drag; the water's pressure gradient rho V dU/dt plus
    the added mass's Ca rho V dU/dt accelerate the rope's m + Ca rho V = (1 + Ca) rho V at dU/dt), as in
    MoorDyn's Line.cpp (Ap, Aq). Without the inertia term the rope, moved by drag alone, lagged by 0.22 m/s of
    1 m/s at t = 4 s."""
    import ropesim

    rho, d = 1025.0, 0.05
    scene = ropesim.scene_from_toml(f"""
dimension = 3
[rope]
length = 2.0
segments = 2
diameter = {d}
density = {rho}
EA = 1e5
[initial]
shape = "line"
start = [0.0, 0.0, 0.0]
end = [0.0, 2.0, 0.0]
[integrator]
method = "verlet"
dt = 1e-3
t_end = 4.0
[output]
interval = 0.1
[gravity]
g = 9.81
[fluid]
density = {rho}
[flow]
velocity = [1.0, 0.0, 0.0]
ramp_time = 4.0
[fluid_drag]
cd_normal = 1.2
[buoyancy]
[added_mass]
ca_normal = 1.0
""")
    traj = ropesim.simulate(scene)
    t = np.asarray(traj.t)
    water = 0.5 * (1.0 - np.cos(np.pi * np.minimum(t, 4.0) / 4.0))
    lag = water[:, None] - np.asarray(traj.v)[:, :, 0]
    assert np.abs(lag).max() < 1e-6   # verlet's kick error: 5e-8 measured (rk4 1e-15, symplectic Euler 2e-4)
