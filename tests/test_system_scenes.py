"""The built-in systems of issue 20 against physics worked out without ropesim:

- ``clump_weight``: the clump's static height and the wires' tension against two elastic catenaries (scipy);
- ``spread_mooring``: the chains' static pull on the spar, at rest and offset in surge, against the single-line
  elastic catenary with seabed summed over the three lines (tests/references/closed_forms.py);
- ``spread_mooring_free``: the free spar starts in static balance in the current (every force on it summed from
  the scene's numbers and the first frame's positions) and stays there; its offset, where the chains' pull
  equals the static restoring force of the same spar held at that pose, and the current's drag on it;
- ``helicopter_sling``: the container hanging still at the start, its weight shared by the four legs and its
  centre of gravity under the hook; the whole flight's energy ledger.

Each also loads, passes `ropesim check` with its own method and step, and runs briefly. The long runs are in the
slow suite.
"""

from __future__ import annotations

import math
import re
import tomllib

import numpy as np
import pytest
import tomli_w
from scipy.optimize import brentq
from typer.testing import CliRunner

import ropesim
from ropesim.cli.app import app
from ropesim.scene.builtin import builtin_folder

from references.closed_forms import elastic_catenary

SCENES = ("clump_weight", "helicopter_sling", "spread_mooring", "spread_mooring_free")
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


def raw(name: str) -> dict:
    return tomllib.loads((builtin_folder() / f"{name}.toml").read_text(encoding="utf-8"))


def scene_of(data: dict, *sets: str):
    return ropesim.scene_from_toml(tomli_w.dumps(data), overrides=list(sets))


def by_id(items, key):
    return next(item for item in items if item["id"] == key)


@pytest.mark.parametrize("name", SCENES)
def test_the_scene_loads_checks_stable_and_runs(name, tmp_path):
    s = ropesim.load_scene(name)
    assert s.is_system and s.description and s.name == name
    result = invoke("check", name)
    assert result.exit_code == 0, result.output
    mine = [line for line in result.stdout.splitlines() if "<- this scene" in line]
    assert len(mine) == 1 and s.integrator.method in mine[0] and "is stable" in mine[0], result.stdout
    short = 20 * s.integrator.dt
    run = invoke("run", name, "--set", f"integrator.t_end={short}", "--set", f"output.interval={short / 4}",
                 "-o", tmp_path / name, "-q")
    assert run.exit_code == 0, run.output
    traj = ropesim.Trajectory.open(tmp_path / name)
    assert traj.t[-1] == pytest.approx(short) and np.all(np.isfinite(traj.x)) and np.all(np.isfinite(traj.tension))
    assert list(traj.lines) == [line.id for line in s.lines]


# ------------------------------------------------------------------------------------- the clump weight


def test_clump_weight_hangs_where_two_elastic_catenaries_meet():
    """The static clump: each wire an elastic catenary from its anchor (scipy, no seabed) whose lower end pulls
    up with half the clump's weight; the depth d where that holds. Lumped into 10 segments each, ropesim's
    static clump agrees to the 0.1 mm `equilibrium` prints (measured: 0.03 mm), and the fixed points' loads to
    1e-4 (measured 4e-6: the lumped wire's weight sits where the continuous one's is, in straight segments)."""
    s = ropesim.load_scene("clump_weight")
    wire = dict(s.line_types)["wire"]
    w, EA, L = wire.mass_per_length * s.gravity.g, wire.EA, s.lines[0].length
    mg = by_id([p.__dict__ for p in s.points], "clump")["mass"] * s.gravity.g

    def lift(d):   # the wire seen from the clump (its "anchor", the line's low end) up to the fixed point
        return elastic_catenary(20.0, d, L, w, EA, seabed=False).VA - mg / 2

    depth = brentq(lift, 9.0, 11.0, xtol=1e-10)
    cat = elastic_catenary(20.0, depth, L, w, EA, seabed=False)
    result = invoke("equilibrium", "clump_weight")
    assert result.exit_code == 0, result.output
    text = " ".join(result.stdout.replace("│", " ").split())
    clump_y = float(re.search(r"point clump free at \(20, (-[\d.]+)\) m", text).group(1))
    assert clump_y == pytest.approx(-depth, abs=1e-4)
    fx, fy = (float(v) for v in re.search(r"point left fixed at \(0, 0\) m: Fx = (-?[\d.]+), Fy = (-?[\d.]+) N",
                                          text).groups())
    # the fixed point holds the wire's top end: its horizontal pull H and the vertical V at that end
    assert -fx == pytest.approx(cat.H, rel=1e-4) and fy == pytest.approx(cat.V, rel=1e-4)


# ------------------------------------------------------------------------------------- the spread mooring


def _chain_weight_in_water(s) -> float:
    chain = dict(s.line_types)["chain"]
    return (chain.mass_per_length - s.fluid.density * math.pi * chain.diameter ** 2 / 4) * s.gravity.g


def _catenary_pull(s, offset: float) -> np.ndarray:
    """The three chains' pull on the spar [N] (x, y, z) with the spar moved ``offset`` m in x: each line the
    elastic catenary with seabed from its anchor to its fairlead, pulling the fairlead towards its anchor with H
    and down with V (the fairlead's half segment left out, as ropesim's line-end force leaves it)."""
    w, total = _chain_weight_in_water(s), np.zeros(3)
    points = {p.id: p for p in s.points}
    for line in s.lines:
        anchor, fair = np.asarray(points[line.start].position), np.asarray(points[line.end].position, dtype=float)
        fair = fair + [offset, 0.0, 0.0]   # the driven spar's frame is the world's, shifted
        horizontal = np.array([anchor[0] - fair[0], anchor[2] - fair[2]])
        X, Z = float(np.hypot(*horizontal)), fair[1] - anchor[1]
        cat = elastic_catenary(X, Z, line.length, w, dict(s.line_types)["chain"].EA)
        u = horizontal / X
        half = w * line.segment_length / 2   # the fairlead node's weight in water, on the body, not in the pull
        total += [cat.H * u[0], -(cat.V - half), cat.H * u[1]]
    return total


def _static_pull(data: dict, offset: float, angles=None) -> np.ndarray:
    """ropesim's static pull of the chains on the spar held ``offset`` m along x (the equilibrium start, the
    spar fixed there), from a run of one step."""
    data = {**data, "bodies": [dict(data["bodies"][0])], "initial": {"shape": "equilibrium"}}
    body = data["bodies"][0]
    for key in ("amplitude", "period", "ramp_time", "mass", "inertia", "center_of_gravity", "volume",
                "center_of_buoyancy", "cd_area", "cd_rotation", "added_mass", "added_inertia"):
        body.pop(key, None)
    body["kind"] = "fixed"
    body["position"] = [body["position"][0] + offset, *body["position"][1:]]
    if angles is not None:
        body["orientation"] = list(angles)
    dt = data["integrator"]["dt"]
    traj = ropesim.simulate(scene_of(data, f"integrator.t_end={dt}", f"output.interval={dt}"))
    return traj.body("spar").force[0]


@pytest.mark.parametrize("offset", [0.0, 10.0, -10.0])
def test_spread_mooring_static_pull_is_three_elastic_catenaries(offset):
    """The static restoring force of the three-line spread mooring against offset: ropesim's static shape (20
    segments of 45 m per line, on the scene's soft seabed, where the chain sinks 2.6 mm) against the elastic
    catenary with a rigid frictionless seabed, summed over the lines. Measured: within 0.08 % of the largest
    component (the vertical) in each, the restoring force in x within 0.2 % of itself at +-10 m (the lumped
    line's discretisation); so 0.3 % and 0.5 %."""
    data = raw("spread_mooring")
    s = scene_of(data)
    expected = _catenary_pull(s, offset)
    got = _static_pull(data, offset)
    scale = np.max(np.abs(expected))
    assert np.max(np.abs(got - expected)) < 3e-3 * scale, (got, expected)
    if offset != 0.0:
        assert got[0] == pytest.approx(expected[0], rel=5e-3)
    if offset == 0.0:   # the scene's claim: buoyancy less weight of the free spar is what the chains hold down
        free = ropesim.load_scene("spread_mooring_free")
        spar = free.rigid_bodies[0]
        lift = (free.fluid.density * spar.volume - spar.mass) * free.gravity.g
        half_segments = 3 * _chain_weight_in_water(s) * s.lines[0].segment_length / 2
        assert -got[1] + half_segments == pytest.approx(lift, rel=2e-3)


def test_free_spar_starts_in_static_balance_and_stays_put():
    """The free spar's equilibrium start in the steady 1 m/s current. At t = 0 every force on the spar and its
    three fairlead nodes (which the body carries), summed here from the scene's numbers and the first frame's
    positions, balances: weight at the centre of gravity, buoyancy at the centre of buoyancy, the hull's drag
    1/2 rho R diag(CdA) R^T |U| U, each chain's end segment pulling with EA (r / l0 - 1), and each fairlead's half
    segment's weight in water and Morison drag. The static solve stops when no force on a node or the body is
    above 1e-10 of its force scale (3.8e-4 N here), so the net force must be below 1e-3 N (measured 1e-5 N, on
    a spar weighing 79 MN) and the net moment about the reference point below 1e-3 N times its 16 m size. Left
    alone (no waves, no drive) it then stays put: a residual force dF on the chains' soft heave stiffness
    (12 kN/m) moves it dF / k ~ 3e-8 m; over 150 s (more than a surge and a heave period) the spar moves less
    than 1 um and turns less than 1e-9 rad (measured 3.2e-8 m and 5e-13 rad), and the fairlead tensions change
    by less than 1e-6 of themselves (measured 3e-10). Where it starts is the header's figures."""
    s = ropesim.load_scene("spread_mooring_free", ["integrator.t_end=150"])
    traj = ropesim.simulate(s)
    spar, body = traj.body("spar"), s.rigid_bodies[0]
    rho, g, U = s.fluid.density, s.gravity.g, np.asarray(s.flow.velocity, dtype=float)
    chain = dict(s.line_types)["chain"]
    R, ref = spar.rotation[0], spar.position[0]
    forces = [(np.array([0.0, -body.mass * g, 0.0]), R @ np.asarray(body.center_of_gravity)),
              (np.array([0.0, rho * body.volume * g, 0.0]), R @ np.asarray(body.center_of_buoyancy)),
              (0.5 * rho * R @ (np.asarray(body.cd_area) * (R.T @ U)) * np.linalg.norm(U), np.zeros(3))]
    d = chain.diameter
    for line in s.lines:
        x = traj.line(line.id).positions[0]
        l0, toward = line.segment_length, x[-2] - x[-1]
        r = float(np.linalg.norm(toward))
        q = -toward / r                                   # the fairlead node's tangent, its end segment
        u = -U                                            # the flow relative to the node at rest
        ut = (u @ q) * q
        un = u - ut
        half = l0 / 2
        weight = (chain.mass_per_length - rho * math.pi * d * d / 4) * g * half
        drag = (-0.5 * rho * s.fluid_drag.cd_normal * d * half * np.linalg.norm(un) * un
                - 0.5 * rho * s.fluid_drag.cd_tangential * math.pi * d * half * np.linalg.norm(ut) * ut)
        pull = chain.EA * (r / l0 - 1.0) * toward / r
        forces.append((pull + drag + np.array([0.0, -weight, 0.0]), x[-1] - ref))
    net = sum(f for f, _ in forces)
    turning = sum(np.cross(arm, f) for f, arm in forces)
    assert np.max(np.abs(net)) < 1e-3, net
    assert np.max(np.abs(turning)) < 1e-3 * 16.0, turning
    assert spar.position[0, 0] == pytest.approx(10.02, abs=0.01)          # the header's offset,
    assert spar.position[0, 1] == pytest.approx(-62.07 - 2.59, abs=0.01)   # sinking 2.59 m,
    assert spar.angles[0, 2] == pytest.approx(-0.089, abs=0.001)          # pitched 0.089 degrees
    assert np.max(np.abs(spar.position - spar.position[0])) < 1e-6
    assert np.max(np.abs(np.radians(spar.angles - spar.angles[0]))) < 1e-9
    for line in s.lines:
        tension = traj.line(line.id).end_tension
        assert np.max(np.abs(tension - tension[0])) < 1e-6 * tension[0]


@pytest.mark.slow
def test_free_spar_settles_where_the_chains_static_pull_balances_the_current(tmp_path):
    """The free spar started the other way, from straight chains with the current ramping in over 100 s (the scene
    before its static start), after 600 s: it has settled (moving less than 1 mm/s; measured 0.09 mm/s) at the pose
    the scene's static start solves for (the free body's six degrees of freedom in the equilibrium solver): within
    1 cm and 0.002 degrees (measured 0.9 mm in surge, 6.2 mm in heave, which is soft, lightly damped and still
    ringing, 5e-4 degrees in pitch). The chains' pull on it equals the static pull of the same chains with the
    spar held at its final pose in the same current (the equilibrium solver without a free body) within 1e-4
    (measured 1.3e-5, in x too); in x that pull balances the current's drag on the hull, 1/2 rho CdA U^2, plus the
    drag on the fairleads' half segments, which the body carries (measured 0.9 % more than the hull's; within 2 %)."""
    from ropesim.model.build import build

    s = ropesim.load_scene("spread_mooring_free", ["initial.shape=lines", "flow.ramp_time=100"])
    traj = ropesim.simulate(s, tmp_path / "free")
    spar = traj.body("spar")
    assert np.max(np.abs(spar.velocity[-1])) < 1e-3
    offset = spar.position[-1, 0]
    assert 9.5 < offset < 10.5   # the header's 10.0 m
    balanced = ropesim.simulate(ropesim.load_scene("spread_mooring_free", ["integrator.t_end=0.002"])).body("spar")
    assert np.max(np.abs(spar.position[-1] - balanced.position[0])) < 1e-2
    assert np.max(np.abs(spar.angles[-1] - balanced.angles[0])) < 2e-3
    data = raw("spread_mooring_free")
    data["bodies"][0]["position"] = [0.0, float(spar.position[-1, 1]), 0.0]
    static = _static_pull(data, offset, angles=spar.angles[-1])
    pull = spar.force[-1]
    assert np.max(np.abs(pull - static)) < 1e-4 * np.max(np.abs(static)), (pull, static)
    assert pull[0] == pytest.approx(static[0], rel=1e-4)
    body = s.rigid_bodies[0]
    drag = 0.5 * s.fluid.density * body.cd_area[0] * 1.0 ** 2
    assert drag < -pull[0] < 1.02 * drag   # the fairleads' half segments are dragged too


# ------------------------------------------------------------------------------------- the helicopter sling


def test_the_sling_load_hangs_still_its_legs_sharing_its_weight():
    """The helicopter held where it starts (its path removed), 2 s: the container stays within 1 mm and 0.01
    degrees of where the scene starts it; over those 2 s (frames every 10 ms, the time average of what the legs'
    stiff bounce leaves) the four legs' pull on it balances its weight and the leg ends' half segments (within
    1e-4; measured 1e-5) with no moment about its centre of gravity (within 1e-3 of m g times its half length),
    its centre of gravity stays under the hook (within 1 mm), and the pendant carries everything below it
    (within 1e-4)."""
    data = raw("helicopter_sling")
    by_id(data["points"], "helicopter").pop("path_table")
    s = scene_of(data, "integrator.t_end=2.0", "output.interval=0.01")
    traj = ropesim.simulate(s)
    box, body, g = traj.body("container"), s.rigid_bodies[0], s.gravity.g
    assert np.max(np.abs(box.position - box.position[0])) < 1e-3
    assert np.max(np.abs(box.angles - box.angles[0])) < 1e-2

    def mean(values):
        return np.trapezoid(values, traj.t, axis=0) / traj.t[-1]

    mg = body.mass * g
    leg = dict(s.line_types)["leg"]
    ends = 4 * leg.mass_per_length * s.lines[1].segment_length / 2 * g   # the leg end nodes move with the body
    force = mean(box.force)
    assert force[1] == pytest.approx(mg + ends, rel=1e-4)
    assert abs(force[0]) < 1e-4 * mg and abs(force[2]) < 1e-4 * mg
    cog = np.einsum("fij,j->fi", box.rotation, np.asarray(body.center_of_gravity))
    about_cog = mean(box.moment - np.cross(cog, box.force))
    assert np.max(np.abs(about_cog)) < 1e-3 * mg * 3.03
    hook = traj.point("hook").position
    assert np.max(np.hypot(*(box.position + cog - hook)[:, [0, 2]].T)) < 1e-3
    pendant = mean(traj.line("pendant").end_force)   # on the hook: up with everything the hook carries
    pendant_end = dict(s.line_types)["pendant"].mass_per_length * s.lines[0].segment_length / 2 * g
    carried = (mg + 4 * leg.mass_per_length * s.lines[1].length * g + by_id(data["points"], "hook")["mass"] * g
               + pendant_end)
    assert pendant[1] == pytest.approx(carried, rel=1e-4)


@pytest.mark.slow
def test_the_sling_flight_keeps_its_energy_ledger_and_the_load_swings_and_turns(tmp_path):
    """The whole flight: the energy ledger balances to 1e-6 of the energy that flowed (the helicopter's work
    against the drag, the axial damping and the kinetic and potential energy), the load ends near the helicopter
    after the 200 m, and turns about the vertical by more than 45 degrees (the header's 78) as it swings."""
    traj = ropesim.simulate(ropesim.load_scene("helicopter_sling"), tmp_path / "sling")
    ledger = traj.summary["energy_ledger"]
    assert ledger["relative_residual"] < 1e-6   # measured 5e-10
    assert ledger["held_work_J"] > 1e5 and ledger["fluid_work_J"] < -1e5   # the helicopter's work, the air's
    box = traj.body("container")
    rotation = box.rotation
    heading = np.degrees(np.unwrap(np.arctan2(-rotation[:, 0, 2], rotation[:, 0, 0])))
    assert abs(heading[-1] - heading[0]) > 45.0
    assert abs(box.position[-1, 0] - 200.0) < 3.0
