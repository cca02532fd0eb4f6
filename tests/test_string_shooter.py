"""The built-in scene string_shooter_real: a light string loop thrown by two wheels in air.

Fast: it loads as its comments say (a physical rope, the nip turned by 30 degrees with both wheels), it is
stable at its step by `ropesim check`'s bound with room to spare, and a short run completes; the takeoff
study's pieces. Slow: the regimes of docs/background/string-shooter.md, each over the scene's 3 s: at its 25 m/s
the loop stands steadily out in front of the wheels; at 12 m/s thrown level (from the study's start, hanging round
the lower wheel) it hangs below them; without tangential drag (Cd_t = 0) it never settles into a steady lifted
loop at 25 m/s.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import replace

import numpy as np
import pytest

import ropesim
from ropesim.analysis.stability import predicted_dt
from ropesim.model.build import build

from conftest import ROOT
from references.closed_forms import string_loop_takeoff_speeds

SCENE = "string_shooter_real"
STABLE_FRACTION = 0.5   # slack (tension-only) segments near the bound have blown up at 90 % of it


def study():
    spec = importlib.util.spec_from_file_location("string_shooter_takeoff",
                                                  ROOT / "scripts" / "string_shooter_takeoff.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_scene_is_what_its_comments_say():
    scene = ropesim.load_scene(SCENE)
    rope = scene.rope
    assert rope.physical and rope.closed and rope.nodes == 60 and not rope.compression
    assert rope.segment_length == pytest.approx(0.025) and rope.mass == pytest.approx(0.0016 * 0.025)
    assert rope.stiffness == pytest.approx(500.0 / 0.025)
    assert (scene.fluid.density, scene.fluid_drag.cd_normal, scene.fluid_drag.cd_tangential) == (1.225, 1.2, 0.02)
    t = scene.thrower
    assert (t.angle, t.v_max, t.edge_width) == (30.0, 25.0, 0.002)
    # the wheels touch at the nip, each R along the nip's normal (-sin a, cos a): turned with the box
    normal = np.array([-math.sin(math.radians(t.angle)), math.cos(math.radians(t.angle))])
    lower, upper = scene.guides
    assert lower.radius == upper.radius == 0.025
    np.testing.assert_allclose(upper.center, 0.025 * normal, atol=1e-6)
    np.testing.assert_allclose(lower.center, -0.025 * normal, atol=1e-6)
    # the study script turns them the same way
    same = ropesim.load_scene(SCENE, study().overrides(1.5, 30.0, 25.0, 0.02, 3.0))
    for mine, its in zip(same.guides, scene.guides):   # the file's centres are rounded to the micrometre
        np.testing.assert_allclose(mine.center, its.center, atol=1e-6)
    assert replace(same, guides=scene.guides) == scene


def test_the_step_is_at_most_half_the_stable_bound():
    scene = ropesim.load_scene(SCENE)
    model = build(scene)
    bound = predicted_dt(model, scene.integrator.method)
    assert scene.integrator.dt <= STABLE_FRACTION * bound
    # the study's other lengths keep the segment length, so the same step
    for length in (1.0, 2.0):
        other = ropesim.load_scene(SCENE, [f"rope.length={length}", f"rope.segments={round(length / 0.025)}"])
        assert other.integrator.dt <= STABLE_FRACTION * predicted_dt(build(other), "verlet")


def test_the_study_uses_the_closed_form_terminal_speeds():
    mod = study()
    for cd_t in (0.005, 0.02, 0.05):
        want = string_loop_takeoff_speeds(mod.MU, mod.DIAMETER, mod.RHO, mod.G, mod.CD_N, cd_t)
        got = mod.terminal_speeds(cd_t)
        # the closed form takes buoyancy off the weight (rho pi d^2 / 4 = 0.14 % of the string's mass per metre);
        # the scene declares no [buoyancy], so the study leaves it out
        assert got["tangential"] == pytest.approx(want["tangential"], rel=1e-3)
        assert got["normal"] == pytest.approx(want["normal"], rel=1e-3)
    assert mod.terminal_speeds(0.02)["tangential"] == pytest.approx(16.5, abs=0.1)


def test_the_takeoff_is_where_the_loop_stays_steady_and_lifted():
    mod = study()
    rows = [mod.classify({"v_max": v, "angle": 30.0, "inclination_deg": i, "height_sd_over_length": sd,
                          "status": "completed", "string_speed_m_s": v})
            for v, i, sd in ((8, 100, 0.05), (12, 30, 0.001), (16, 40, 0.001), (20, 70, 0.001), (24, 80, 0.001))]
    assert rows[0]["lifted 45 deg"] is False          # lifted on average but flapping: not the lifted state
    assert mod.crossing(rows, "45 deg") == (16, 20) and mod.crossing(rows, "halfway") == (16, 20)
    assert mod.takeoff_speed(rows, "45 deg")["v_takeoff"] == pytest.approx(16 + 4 * 5 / 30)
    assert mod.takeoff_speed(rows, "halfway")["v_takeoff"] == pytest.approx(16 + 4 * 20 / 30)   # at 60 degrees
    assert mod.crossing(rows[:-2], "45 deg") is None
    assert math.isnan(mod.crossing(rows[3:], "45 deg")[0])
    rows[2] = mod.classify({**rows[2], "height_sd_over_length": 0.05})   # flapping below: the bracket's middle
    assert mod.takeoff_speed(rows, "45 deg")["v_takeoff"] == pytest.approx(18)


def test_a_short_run_completes_with_the_shooter_figures():
    scene = ropesim.load_scene(SCENE, ["integrator.t_end=0.1"])
    traj = ropesim.simulate(scene)
    assert traj.summary["status"] == "completed"
    shooter = traj.summary["shooter"]
    assert shooter["drive_speed_m_s"] == 25.0 and shooter["nodes_in_thrower"] >= 1
    assert {"centroid_height_m", "mean_centroid_height_m"} <= set(shooter)
    assert np.all(np.isfinite(traj.x))


def loop_state(*sets: str) -> dict:
    mod = study()
    scene = ropesim.load_scene(SCENE, list(sets))
    traj = ropesim.simulate(scene)
    assert traj.summary["status"] == "completed"
    figures = mod.measure(traj.t, traj.x, traj.v, scene.rope.length)
    figures["summary"] = traj.summary["shooter"]
    return figures


@pytest.mark.slow
def test_at_its_speed_the_loop_stands_steadily_in_front_of_the_wheels():
    state = loop_state()
    assert state["inclination_deg"] > 80 and state["height_over_length"] > -0.02
    assert state["height_sd_over_length"] < 0.01                  # steady
    assert state["string_speed_m_s"] == pytest.approx(25.0, rel=0.05)
    assert state["summary"]["mean_loop_inclination_deg"] > 80


@pytest.mark.slow
def test_slow_and_level_the_loop_hangs_below_the_wheels():
    sets = study().study_overrides(1.5, 0.0, 12.0, 0.02, 3.0)   # from the loop hanging round the lower wheel
    state = loop_state(*sets)
    assert abs(state["inclination_deg"]) < 30 and state["height_over_length"] < -0.1


@pytest.mark.slow
def test_without_tangential_drag_the_loop_does_not_stand_up():
    state = loop_state("fluid_drag.cd_tangential=0")
    assert not (state["inclination_deg"] > 45 and state["height_sd_over_length"] < 0.01)


@pytest.mark.slow
def test_the_study_script_runs_and_writes_its_tables_and_figures(tmp_path):
    import subprocess
    import sys

    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "string_shooter_takeoff.py"), "--quick",
                             "--jobs", "1", "--out", str(tmp_path / "out"), "--figures", str(tmp_path / "fig")],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert "2 runs in" in result.stdout
    for name in ("runs.csv", "takeoff.csv", "takeoff.md", "shapes.npz"):
        assert (tmp_path / "out" / name).is_file(), name
    assert len(list((tmp_path / "out" / "cases").glob("*.npz"))) == 2    # the cache a rerun picks up
    for name in ("string_shooter_takeoff.png", "string_shooter_cdt.png", "string_shooter_shapes.png"):
        assert (tmp_path / "fig" / name).stat().st_size > 10_000, name
