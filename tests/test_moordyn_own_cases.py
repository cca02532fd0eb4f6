"""ropesim against MoorDyn on MoorDyn's own test cases: three studless chains on a seabed (WD0050, WD0200, WD0600:
seabed spring and dashpot, friction, drag, added mass, buoyancy, a surging fairlead) and the cantilevered beam (EI,
a clamped end). tests/references/moordyn_own_cases.py builds each case from MoorDyn's own input file and holds the
conventions; scripts/compare_moordyn_cases.py the full comparison behind docs/background/validation.md.

Everything here runs on MoorDyn 2.7.2's stored runs (tests/data/moordyn/: ``<case>.npz`` from
scripts/moordyn_reference.py, ``own_cases.npz`` from ``scripts/compare_moordyn_cases.py --regenerate``): MoorDyn is
not needed at test time.

What the tolerances rest on (measured; the issue asks for 0.5 % static and 2 % RMS dynamic):

- static: ropesim's static solve is within 3.3e-5 (fairlead) and 1.1e-5 (anchor) of MoorDyn's IC run tight, and
  within 5.8e-4 of the IC its file sets up (threshIC 1e-3, 1e-2 for WD0600); the tolerances are 1e-4 and 1e-3;
- dynamic: ropesim's rk4 at MoorDyn's step along the same path differs from MoorDyn's RK2 run by 4.8e-4 to 7.4e-4
  of the fairlead tension's range RMS (1.4e-3 of its RMS at most), 1.5e-3 of the range at most; the anchor tension
  by 5.4e-5 to 1.6e-4. Most of it is ropesim's first-order error at the path's rows (``test_..._first_order``: it
  halves with ropesim's step, to 8.7e-5 at dt/8), not a difference in physics. Tolerances: 3e-3 of the range for
  the fairlead (RMS and max), 4e-4 for the anchor, i.e. 2 to 4 times the measured values and 7 times below the
  issue's 2 %;
- one wrong seabed or fluid coefficient breaks the anchor's agreement at least threefold (measured on WD0050: kBot
  doubled 14x, no cBot 27x, a Coulomb friction (v_reg = 1 cm/s, ropesim's default) 400x, Cd 10 % high 100x, the
  footprint twice as wide 33x; friction switched off entirely moves it by 1.2x only: MoorDyn's friction is a
  weak drag);
- the beam: its tip within 7.6e-5 of its range of MoorDyn's over 6 s after a straight release, the three mode
  frequencies to 1e-5, the static tip deflection to 1.1e-4 of the deflection MoorDyn's release oscillates about.
Units: SI.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from references.moordyn_own_cases import (
    BEAM,
    CHAINS,
    DATA,
    anchor_tension,
    beam_case,
    beam_static_tip,
    catenary_start,
    chain_case,
    chain_scene_dict,
    differences,
    fairlead_tension,
    fit_oscillation,
    load_reference,
    path_rows,
    read_input,
    ropesim_static,
    run_beam,
    run_chain,
    segment_tension,
    static_tensions,
)

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def stored():
    with np.load(DATA / "own_cases.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    return arrays, json.loads((DATA / "own_cases.json").read_text(encoding="utf-8"))


# ------------------------------------------------------------------------------------------------ the input files


def test_the_cases_are_read_from_moordyns_own_files():
    """Every number of the ropesim scenes comes from MoorDyn's input files and its 2.7.2 defaults, as the README of
    tests/data/moordyn/cases lists them."""
    c = chain_case("WD0050_Chain")
    assert (c.length, c.segments, c.diameter, c.mass_per_length, c.EA) == (410.0, 82, 0.252, 390.0, 1.674e9)
    assert (c.Cd, c.Ca, c.CdAx, c.CaAx) == (1.37, 1.0, 0.64, 0.0)
    assert c.anchor == (400.0, 0.0, -50.0) and c.fairlead == (0.0, 0.0, 0.0) and c.depth == 50.0
    assert (c.kbot, c.cbot, c.friction, c.fric_damp, c.rho_w, c.g) == (1e5, 1e4, 0.5, 200.0, 1025.0, 9.80665)
    assert c.BA == pytest.approx(4.04e6, rel=1e-3)                  # zeta = 1: (L/N) sqrt(EA m')
    assert c.wet_weight == pytest.approx(3323.2, abs=0.1)
    assert c.friction_speed == pytest.approx(83.08, abs=0.01)     # w l / FricDamp
    assert [chain_case(n).BA for n in CHAINS[1:]] == pytest.approx([7.49e6, 8.08e6], rel=1e-3)
    assert chain_case("WD0600_Chain").dtM == pytest.approx(3.0327e-3, rel=1e-4)   # from its CFL = 0.1
    b = beam_case()
    assert (b.length, b.segments, b.EI, b.mass_per_length) == (10.0, 19, 1e7, 100.0)
    assert b.clamp == (0.0, 0.0, 10.0) and b.axis == (1.0, 0.0, 0.0)
    assert b.BA == pytest.approx(2.04e5, rel=1e-3)
    assert read_input(DATA / "cases" / "BeamCantilevered.txt").points[0]["type"] == "Free"


def test_the_fairlead_follows_the_stored_path_and_the_tension_is_moordyns():
    """ropesim's path_table is the stored fairlead path at every coupling instant (MoorDyn joins the same points by
    straight lines); the tension from a frame's state equals ropesim's own ``tension`` when taken with the frame's
    own fairlead velocity."""
    c = chain_case("WD0050_Chain")
    ref, _ = load_reference(c.name)
    rows = np.asarray(path_rows(c))
    assert rows.shape == (751, 3)
    assert np.array_equal(rows[:, 0], ref["t"])
    assert np.abs(rows[:, 1] - ref["fairlead_path"][:, 0]).max() == 0.0
    assert np.abs(rows[:, 2]).max() == 0.0
    traj = run_chain(c, ref["static_positions"], t_end=2.0)
    own = segment_tension(c, traj.x, traj.v, c.segments - 1)
    assert np.allclose(own, np.asarray(traj.tension)[:, -1], rtol=1e-12, atol=1e-6)
    assert np.abs(fairlead_tension(c, traj)[1:] - np.abs(own[1:])).max() > 1e3   # N: the velocity jumps
    # frame 0: MoorDyn's fairlead rests during its IC (ropesim's already moves on the path's first piece)
    assert fairlead_tension(c, traj)[0] == pytest.approx(static_tensions(c, np.asarray(traj.x)[0])[0], rel=1e-12)


# ------------------------------------------------------------------------------------------------ static


@pytest.mark.parametrize("name", CHAINS)
def test_static_chain_tensions_agree_with_moordyns_ic(name, stored):
    """ropesim's static solve against MoorDyn's IC: within 1e-4 of its IC run tight (measured 3.3e-5, 1.1e-5,
    5e-6 at the fairlead) and 1e-3 of the IC its file sets up (measured 2.8e-4, 1.9e-4, 5.8e-4)."""
    c = chain_case(name)
    ref, _ = load_reference(name)
    arrays, record = stored
    x, fair, anchor = ropesim_static(c)
    tight = record["chains"][name]["tight_ic"]
    assert fair == pytest.approx(tight["fairlead_tension_N"], rel=1e-4)
    assert anchor == pytest.approx(tight["anchor_tension_N"], rel=1e-4)
    assert fair == pytest.approx(ref["fairlead_tension"][0], rel=1e-3)
    assert anchor == pytest.approx(ref["anchor_tension"][0], rel=1e-3)
    tight_x = arrays[f"{name}_tight_ic_positions"][:, [0, 2]]
    assert np.abs(x - tight_x).max() < 2e-3           # m; measured 0.14, 0.06, 0.6 mm
    grounded = x[:, 1] < -c.depth
    assert grounded.sum() > c.segments // 4            # the seabed carries a good part of the chain
    sink = -c.depth - x[grounded, 1]
    assert sink.max() == pytest.approx(c.wet_weight / (c.kbot * c.diameter), rel=2e-3)   # w / (kBot d) = 0.13 m


@pytest.mark.slow
@pytest.mark.parametrize("name", CHAINS)
def test_a_settled_dynamic_run_ends_at_the_static_solve(name):
    """The chain dropped from a straight line between its ends (every segment slack), the fairlead held, 600 s of
    sdirk2 at 6.25 ms: it ends within 2e-4 of the static solve's tensions (measured: 3e-6 to 6.5e-5; its slowest
    sway is still dying out, nodes at 0.3 to 7 mm/s). sdirk2 at 12.5 ms fails its Newton solve on WD0600's fall."""
    c = chain_case(name)
    _, fair, anchor = ropesim_static(c)
    traj = run_chain(c, catenary_start(c), method="sdirk2", dt=0.00625, t_end=600.0, moving=False, interval=50.0)
    assert traj.summary["status"] == "completed", traj.summary.get("message")
    f, a = static_tensions(c, np.asarray(traj.x)[-1])
    assert f == pytest.approx(fair, rel=2e-4)
    assert a == pytest.approx(anchor, rel=2e-4)


def test_the_beams_static_tip_agrees_with_moordyns_release(stored):
    """The cantilever's static tip deflection: ropesim's static solve against the deflection MoorDyn's straight
    release oscillates about (fitted, modes 1-3) to 1e-3 (measured 1.1e-4) and the Euler-Bernoulli beam to the
    discretisation's 0.26 % (19 segments); MoorDyn's own IC stalls at 0.0705 m."""
    b = beam_case()
    _, record = stored
    tip = beam_static_tip(b)
    md = b.clamp[2] - record["beam_straight"]["fit"]["offset"]
    assert tip == pytest.approx(md, rel=1e-3)
    assert tip == pytest.approx(b.analytic_tip, rel=4e-3)
    assert tip > b.analytic_tip


# ------------------------------------------------------------------------------------------------ dynamic

#: Largest allowed differences, ropesim rk4 at MoorDyn's step against MoorDyn's stored RK2 run, as fractions of the
#: MoorDyn signal's range: fairlead RMS and max, anchor RMS. Measured (WD0050, WD0200, WD0600): fairlead RMS 7.4e-4,
#: 4.8e-4, 6.2e-4; max 1.5e-3, 9.8e-4, 1.5e-3; anchor RMS 1.6e-4, 5.4e-5, 1.6e-4.
DYNAMIC_TOL = {"fair_rms": 3e-3, "fair_max": 3e-3, "anchor_rms": 4e-4}


def dynamic_differences(name: str, t_end: float | None = None, **physics) -> tuple[dict, dict]:
    c = chain_case(name)
    ref, _ = load_reference(name)
    traj = run_chain(c, ref["static_positions"], t_end=t_end, **physics)
    assert traj.summary["status"] == "completed", traj.summary.get("message")
    frames = len(traj.t)
    return (differences(ref["fairlead_tension"][:frames], fairlead_tension(c, traj)),
            differences(ref["anchor_tension"][:frames], anchor_tension(traj)))


def assert_dynamic_agreement(fair: dict, anchor: dict) -> None:
    assert fair["rms_of_range"] < DYNAMIC_TOL["fair_rms"], fair
    assert fair["max_of_range"] < DYNAMIC_TOL["fair_max"], fair
    assert fair["rms_of_rms"] < 0.02, fair   # the 2 %, on the stricter of the two measures
    assert anchor["rms_of_range"] < DYNAMIC_TOL["anchor_rms"], anchor


def test_wd0050_surging_agrees_with_moordyn():
    """WD0050's fairlead surging 5 m at 15 s for 75 s (tension 0.28 to 3.39 MN around 1.0 MN static: the far
    excursion nearly straightens the chain), from MoorDyn's IC state, rk4 at 1 ms."""
    fair, anchor = dynamic_differences("WD0050_Chain")
    assert_dynamic_agreement(fair, anchor)
    assert fair["range"] > 3.0e6


@pytest.mark.slow
@pytest.mark.parametrize("name", CHAINS[1:])
def test_deeper_chains_surging_agree_with_moordyn(name):
    """WD0200 and WD0600 surging 10 m at 20 s for 100 s."""
    fair, anchor = dynamic_differences(name)
    assert_dynamic_agreement(fair, anchor)


@pytest.mark.slow
def test_ropesims_own_seabed_damping_is_not_moordyns():
    """With ropesim's default seabed damping (into the plane only, grown in with depth) instead of MoorDyn's
    (``damping_both_ways``), WD0050's anchor tension moves 7.5 times as far from MoorDyn's (1.2e-3 of the range,
    measured), the fairlead's largest difference 4.5 times (6.7e-3): still inside the issue's 2 %, outside these
    tolerances, which is why the cases use MoorDyn's law."""
    fair, anchor = dynamic_differences("WD0050_Chain", both_ways=False)
    assert anchor["rms_of_range"] > 2 * DYNAMIC_TOL["anchor_rms"], anchor
    assert fair["max_of_range"] > 1.5 * DYNAMIC_TOL["fair_max"], fair
    assert fair["rms_of_rms"] < 0.02, fair


#: One coefficient wrong in ropesim (MoorDyn keeps the right one): what it does to WD0050's anchor tension RMS
#: over 75 s, in multiples of the measured 1.6e-4 of the range.
REGRESSIONS = {
    "seabed stiffness doubled": lambda d: d["seabed"].update(stiffness=2 * d["seabed"]["stiffness"]),   # 14x
    "no seabed damping": lambda d: d["seabed"].update(damping=0.0),                                        # 27x
    "Coulomb friction (v_reg 1 cm/s)": lambda d: d["seabed"].update(friction_speed=0.01),                  # 400x
    "footprint twice as wide": lambda d: d["seabed"].update(contact_width=2 * d["rope"]["diameter"]),      # 33x
    "normal drag 10 % high": lambda d: d["fluid_drag"].update(cd_normal=1.1 * d["fluid_drag"]["cd_normal"]),  # 100x
    "normal added mass 10 % low": lambda d: d["added_mass"].update(ca_normal=0.9),                         # 8x
}
FAST_REGRESSIONS = ("Coulomb friction (v_reg 1 cm/s)",)


@pytest.mark.parametrize("regression", [
    pytest.param(name, marks=() if name in FAST_REGRESSIONS else pytest.mark.slow) for name in REGRESSIONS])
def test_a_wrong_coefficient_breaks_the_agreement(regression):
    """Each takes the anchor tension's RMS difference to at least three times its tolerance, over the first 30 s
    (the fast one) or all 75 s."""
    import tomli_w

    import ropesim

    c = chain_case("WD0050_Chain")
    ref, _ = load_reference(c.name)
    t_end = 30.0 if regression in FAST_REGRESSIONS else None
    scene = chain_scene_dict(c, ref["static_positions"], t_end=t_end)
    REGRESSIONS[regression](scene)
    traj = ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(scene)))
    anchor = differences(ref["anchor_tension"][:len(traj.t)], anchor_tension(traj))
    assert anchor["rms_of_range"] > 3 * DYNAMIC_TOL["anchor_rms"], anchor


def test_the_beam_released_straight_swings_as_in_moordyn(stored):
    """The beam released straight and at rest under gravity, rk4 at 0.05 ms, against MoorDyn's release (its state
    set straight, see ``run_moordyn_beam_straight``): the tip's height over the first 1.5 s within 2e-4 of its
    range (measured 3.4e-5; 7.6e-5 over all 6 s)."""
    arrays, _ = stored
    b = beam_case()
    traj = run_beam(b, dt=5e-5, t_end=1.5)
    md = arrays["beam_straight_positions"][:len(traj.t)]
    nodes = arrays["beam_straight_nodes"]
    y = np.asarray(traj.x)[:, nodes, 1]
    tip = differences(md[:, -1, 2], y[:, -1])
    assert tip["range"] > 0.2
    assert tip["rms_of_range"] < 2e-4, tip
    assert np.abs(y - md[:, :, 2]).max() < 1e-4   # m, every stored node


@pytest.mark.slow
def test_the_beams_release_over_six_seconds(stored):
    """All 6 s: the tip within 2e-4 of its range RMS (measured 7.6e-5), the three modes' frequencies within 1e-4
    of MoorDyn's (measured 1e-5: 1.7656, 10.959, 30.292 Hz; Euler-Bernoulli's 1.7696, 11.090, 31.05 Hz)."""
    arrays, record = stored
    b = beam_case()
    traj = run_beam(b, dt=5e-5)
    y = np.asarray(traj.x)[:, -1, 1]
    tip = differences(arrays["beam_straight_positions"][:, -1, 2], y)
    assert tip["rms_of_range"] < 2e-4, tip
    ours = fit_oscillation(np.asarray(traj.t), y)["frequencies"]
    assert ours == pytest.approx(record["beam_straight"]["fit"]["frequencies"], rel=1e-4)


# ------------------------------------------------------------------------------------------------ what is left


@pytest.mark.parametrize("method,order", [("rk4", 4)] + [pytest.param(m, k, marks=pytest.mark.slow) for m, k in (
    ("symplectic_euler", 1), ("verlet", 2), ("yoshida4", 4), ("pefrl", 4), ("sdirk2", 2))])
def test_steps_ending_on_the_paths_rows_keep_each_methods_order(method, order):
    """A 4-segment line, heavily damped axially, its end driven along a sinusoid sampled every 0.1 s (a
    piecewise-linear path): with steps that divide 0.1 s every method converges at its own order, as within
    each piece, because every stage of a step moves the node on that step's piece (ropesim/model/motion.py).
    Once a stage on a row took the next piece's velocity, and every method fell to first order (rk4: halving
    the step from 12.5 ms shrank the error 1.7 times, not 16). MoorDyn moves a coupled point on one piece for
    the whole coupling step too."""
    import tomli_w

    import ropesim

    def run(dt):
        rows = [[t, 0.3 * np.sin(np.pi * t), 0.0] for t in np.round(np.arange(0.0, 4.0001, 0.1), 10)]
        scene = {"dimension": 2, "rope": {"length": 4.0, "segments": 4, "mass_per_length": 2.0, "EA": 4000.0,
                                          "axial_damping": 100.0, "compression": False},
                 "initial": {"shape": "line", "start": [0.0, 0.0], "end": [4.0, 0.0]},
                 "integrator": {"method": method, "dt": dt, "t_end": 4.0}, "output": {"interval": 0.1},
                 "gravity": {"g": 9.81}, "pinned": {"nodes": [0]}, "driven": [{"nodes": [-1], "path_table": rows}]}
        return np.asarray(ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(scene))).x)

    reference = run(0.1 / 512)
    coarse, fine = (np.abs(run(0.1 / k) - reference).max() for k in (16, 32))
    assert coarse / fine > 2.0 ** (order - 0.5), (coarse, fine, coarse / fine)   # 1.4, 2.8, 11.3 for 1, 2, 4


@pytest.mark.slow
def test_the_comparison_script_runs(tmp_path):
    """scripts/compare_moordyn_cases.py on the beam (stored MoorDyn data only): its tables and its figure."""
    figure = tmp_path / "figure.png"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "compare_moordyn_cases.py"), "--cases", BEAM,
                             "--figure", str(figure)], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert "| BeamCantilevered | tip deflection" in result.stdout
    assert "| BeamCantilevered | tip height after a straight release |" in result.stdout
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_the_fluid_case_benchmark_runs(tmp_path):
    """scripts/bench_moorings.py --fluid on the catenary's first 2 s (needs MoorDyn): both codes against their own
    converged answers (which agree with their check runs), galpha's and MoorDyn's configurations timed, the
    cheapest per accuracy in the JSON."""
    pytest.importorskip("moordyn")
    out = tmp_path / "fluid.json"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "bench_moorings.py"), "--fluid", "catenary",
                             "--fluid-window", "2", "--repeats", "1", "--json", str(out)],
                            capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr
    assert "| catenary (31 nodes, 2 s) | 1 % |" in result.stdout
    case = json.loads(out.read_text())["cases"][0]
    assert all(ref["check_rms_of_range"] < 1e-3 for ref in case["references"].values())
    codes = {(row["code"], row["method"].split(" tol=")[0]) for row in case["rows"] if row["ok"]}
    assert codes == {("ropesim", "galpha rho=0"), ("ropesim", "galpha rho=0.3"), ("ropesim", "galpha rho=0.5"),
                     ("MoorDyn", "RK2"), ("MoorDyn", "RK4")}
    tolerances = {row["method"].partition(" tol=")[2] for row in case["rows"] if " tol=" in row["method"]}
    assert {"0.001", "0.0015", "0.002", "0.003", "0.005", "0.007"} <= tolerances   # six per decade
    assert set(case["cheapest"]) == {"0.01", "0.001"}
    for target, per in case["cheapest"].items():   # each code's cheapest configuration reaches the target
        assert all(v["error"] <= float(target) for v in per.values())


@pytest.mark.slow
def test_the_stiff_chain_sweep_runs_alone(tmp_path):
    """scripts/bench_moorings.py --sweep-only at one EA with --only galpha: only galpha's configurations (fixed
    and adaptive) are timed, against the EA's own rk4 reference, and its columns fill the sweep table."""
    pytest.importorskip("moordyn")
    out = tmp_path / "sweep.json"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "bench_moorings.py"), "--sweep-only",
                             "--sweep-ea", "1e8", "--only", "galpha", "--repeats", "1", "--json", str(out)],
                            capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr
    sweep = json.loads(out.read_text())["sweep"]
    assert [s["EA"] for s in sweep] == [1e8]
    assert {row["method"].split(" tol=")[0] for row in sweep[0]["rows"]} == {"galpha"}
    assert {"ropesim galpha", "ropesim galpha adaptive"} <= set(sweep[0]["cheapest"]["0.01"])
    assert "| 1e+08 | 1 % | — | — | — | " in result.stdout


@pytest.mark.slow
def test_the_speed_benchmark_runs(tmp_path):
    """scripts/bench_moorings.py on a 4 s window without the EA sweep (needs MoorDyn): every method timed against
    its code's converged answer, its tables, JSON and figure; MoorDyn's state set to ropesim's static shape."""
    pytest.importorskip("moordyn")
    out, figure = tmp_path / "speed.json", tmp_path / "speed.png"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "bench_moorings.py"), "--window", "4",
                             "--repeats", "1", "--points", "2", "--no-sweep", "--json", str(out),
                             "--figure", str(figure)], capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr
    assert "## Cheapest configuration per accuracy" in result.stdout
    record = json.loads(out.read_text())
    codes = {(r["code"], r["method"]) for r in record["rows"] if r["ok"]}
    methods = {(code, method.split(" tol=")[0]) for code, method in codes}     # galpha's adaptive runs by tolerance
    assert methods == {("ropesim", "verlet"), ("ropesim", "rk4"), ("ropesim", "sdirk2"), ("ropesim", "galpha"),
                       ("MoorDyn", "RK2"), ("MoorDyn", "RK4")}
    assert record["case"]["seabed_damping_both_ways"] is True
    assert record["converged_answers_apart_rms_of_range"] < 1e-3   # equal physics: the two answers agree
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
