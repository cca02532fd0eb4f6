"""The static solver on free rigid bodies (ropesim/model/statics.py with ropesim/model/body_groups.py): a body's
six unknowns (three in 2-D) in the Schur complement beside each line's band, its pose found in all its degrees of
freedom, against references written separately (tests/references/line_systems.py):

- a body on a symmetric V of two elastic lines in the massless limit: its depth in closed form;
- an asymmetric body on three elastic lines in 3-D, its centre of gravity off its reference point: its pose from
  scipy on the body's own six equations;
- a free spar on a symmetric three-line spread mooring, pushed by a current on its drag area: its offset, heave
  and pitch, and the restoring force at the offset, from the single-line elastic catenary with seabed summed
  over the lines.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from references.line_systems import SeabedCatenaries, StraightElasticLines, body_balance
from ropesim.analysis.statics import equilibrium
from ropesim.model.build import build
from ropesim.scene.loader import scene_from_toml

G = 9.81


def v_scene(segments: int = 4) -> str:
    """A 1000 kg block on two 10 m elastic lines (EA 200 kN, 0.1 g/m: the massless limit) from anchors 20 m
    apart to eyes 2 m apart and 0.5 m above its reference point; started off centre and turned."""
    return f"""
name = "v"
dimension = 2
[[bodies]]
id = "block"
position = [0.5, -6.0]
orientation = 10.0
mass = 1000.0
inertia = 300.0
[[points]]
id = "left_anchor"
position = [-10.0, 0.0]
[[points]]
id = "right_anchor"
position = [10.0, 0.0]
[[points]]
id = "left_eye"
body = "block"
position = [-1.0, 0.5]
[[points]]
id = "right_eye"
body = "block"
position = [1.0, 0.5]
[[lines]]
id = "left"
start = "left_anchor"
end = "left_eye"
length = 10.0
segments = {segments}
mass_per_length = 1.0e-4
EA = 2.0e5
[[lines]]
id = "right"
start = "right_eye"
end = "right_anchor"
length = 10.0
segments = {segments}
mass_per_length = 1.0e-4
EA = 2.0e5
[gravity]
g = {G}
[integrator]
dt = 1.0e-3
t_end = 1.0
"""


def test_a_body_on_a_symmetric_v_of_elastic_lines_hangs_where_the_closed_form_puts_it():
    """Each straight line of stretched length L = sqrt((D - a)^2 + h^2) pulls T = EA (L - L0) / L0, and the two
    carry the weight: 2 T h / L = m g, one equation for the eyes' depth h. The lines weigh 1e-6 of the block,
    so the lumped lines' own sag moves the block by about that fraction: 1e-6 of the depth, and their pulls
    are equal to round-off, the body level and on the axis."""
    EA, L0, m, D, a = 2e5, 10.0, 1000.0, 10.0, 1.0

    def excess(h):
        L = math.hypot(D - a, h)
        return 2.0 * EA * (L - L0) / L0 * h / L - m * G

    h = brentq(excess, 1e-3, 20.0, xtol=1e-14)
    shape = equilibrium(scene_from_toml(v_scene()))
    assert shape.converged
    body = shape.bodies[0]
    assert body.position[0] == pytest.approx(0.0, abs=1e-9)
    assert body.angles[0] == pytest.approx(0.0, abs=1e-8)
    assert body.position[1] == pytest.approx(-h - 0.5, rel=1e-6)
    left, right = body.line_forces["left"], body.line_forces["right"]
    assert np.allclose(left * [-1.0, 1.0], right, rtol=1e-9)
    length = math.hypot(D - a, h)
    assert np.linalg.norm(left) == pytest.approx(EA * (length - L0) / L0, rel=1e-6)
    assert left[1] + right[1] == pytest.approx(m * G, rel=1e-6)


TRIPOD = dict(anchors=[(-8.0, 0.0, -3.0), (7.0, 1.0, -4.0), (1.0, 0.5, 8.0)],
              eyes=[(-1.0, 0.4, -0.5), (1.2, 0.3, -0.6), (0.1, 0.5, 1.0)],
              lengths=[8.0, 8.5, 9.0], EA=[2.0e5, 3.0e5, 1.5e5])


def tripod_scene() -> str:
    """A 500 kg body, its centre of gravity off its reference point, on three elastic lines of different lengths
    and stiffnesses (0.1 g/m: the massless limit) from anchors at different heights; started level."""
    out = ['name = "tripod"\ndimension = 3\n',
           '[[bodies]]\nid = "body"\nposition = [0.0, -5.0, 0.0]\nmass = 500.0\ninertia = [60.0, 80.0, 70.0]\n'
           'center_of_gravity = [0.2, -0.3, 0.1]\n']
    for k, (anchor, eye, length, ea) in enumerate(zip(*TRIPOD.values())):
        out.append(f'[[points]]\nid = "anchor{k}"\nposition = {list(anchor)}\n')
        out.append(f'[[points]]\nid = "eye{k}"\nbody = "body"\nposition = {list(eye)}\n')
        start, end = (f"anchor{k}", f"eye{k}") if k != 1 else (f"eye{k}", f"anchor{k}")
        out.append(f'[[lines]]\nid = "line{k}"\nstart = "{start}"\nend = "{end}"\nlength = {length}\nsegments = 3\n'
                   f'mass_per_length = 1.0e-4\nEA = {ea}\n')
    out.append(f"[gravity]\ng = {G}\n[integrator]\ndt = 1.0e-3\nt_end = 1.0\n")
    return "\n".join(out)


def test_an_asymmetric_body_on_three_elastic_lines_takes_the_pose_of_its_own_equations():
    """All six degrees of freedom: the body's reference point and orientation against scipy's solve of its net
    force and moment (straight massless lines, pulling T = EA (L - L0) / L0 towards their anchors, its weight at
    its centre of gravity); within 1e-6 (the lines weigh 1e-6 of the body), and each line's force on it."""
    lines = StraightElasticLines(TRIPOD["anchors"], TRIPOD["eyes"], TRIPOD["lengths"], TRIPOD["EA"])
    r, R = body_balance(lines, np.eye(3), np.array([0.0, -5.0, 0.0]), 500.0 * G, (0.2, -0.3, 0.1))
    shape = equilibrium(scene_from_toml(tripod_scene()))
    assert shape.converged
    body = shape.bodies[0]
    ours = Rotation.from_quat(np.r_[body.quaternion[1:], body.quaternion[0]]).as_matrix()
    turned = Rotation.from_matrix(ours @ R.T).magnitude()
    assert turned < 1e-6, turned
    assert np.abs(body.position - r).max() < 1e-6 * np.linalg.norm(r)
    assert math.degrees(Rotation.from_matrix(R).magnitude()) > 3.0     # it did turn, well away from its start
    pulls = lines(r + np.array(TRIPOD["eyes"]) @ R.T)
    for k in range(3):
        assert body.line_forces[f"line{k}"] == pytest.approx(pulls[k], rel=1e-5, abs=1e-5 * np.abs(pulls).max())


RHO, G_SEA = 1025.0, 9.80665
CHAIN_W = (77.7 - RHO * math.pi * 0.09 ** 2 / 4.0) * G_SEA     # submerged weight [N/m]
SPREAD_ANCHORS = [(300.0 * math.cos(2 * math.pi * k / 3), -100.0, 300.0 * math.sin(2 * math.pi * k / 3))
                  for k in range(3)]
SPREAD_FAIRLEADS = [(5.0 * math.cos(2 * math.pi * k / 3), -20.0, 5.0 * math.sin(2 * math.pi * k / 3))
                    for k in range(3)]
SPAR = dict(mass=5.0e5, volume=515.0, cog=(0.0, -30.0, 0.0), cob=(0.0, -15.0, 0.0), cd_area=50.0)


def spread_scene(segments: int, current: float) -> str:
    """A free spar (500 t, 515 m^3, its centre of buoyancy 15 m above its centre of gravity) on three 320 m chains
    (77.7 kg/m, 90 mm, EA 384 MN) from anchors 120 degrees apart on the seabed 100 m down at 300 m from its axis
    to fairleads on it 20 m down at 5 m; a current along x pushes on its 50 m^2 drag area (the chains have no drag),
    a stiff seabed (3e9 N/m^3: its chains sink 3e-6 m into it)."""
    out = ['name = "spread"\ndimension = 3\n[line_types.chain]\ndiameter = 0.09\nmass_per_length = 77.7\n'
           'EA = 3.84e8\n',
           f'[[bodies]]\nid = "spar"\nposition = [0.0, 0.0, 0.0]\nmass = {SPAR["mass"]}\n'
           f'inertia = [1.0e8, 1.0e6, 1.0e8]\ncenter_of_gravity = {list(SPAR["cog"])}\nvolume = {SPAR["volume"]}\n'
           f'center_of_buoyancy = {list(SPAR["cob"])}\ncd_area = {[SPAR["cd_area"]] * 3}\n']
    for k, (anchor, fairlead) in enumerate(zip(SPREAD_ANCHORS, SPREAD_FAIRLEADS)):
        out.append(f'[[points]]\nid = "anchor{k}"\nposition = {list(anchor)}\n')
        out.append(f'[[points]]\nid = "fairlead{k}"\nbody = "spar"\nposition = {list(fairlead)}\n')
        out.append(f'[[lines]]\nid = "line{k}"\ntype = "chain"\nstart = "anchor{k}"\nend = "fairlead{k}"\n'
                   f'length = 320.0\nsegments = {segments}\n')
    out.append(f'[gravity]\ng = {G_SEA}\n[fluid]\ndensity = {RHO}\n[buoyancy]\n[flow]\nvelocity = [{current}, 0.0, 0.0]\n'
               '[seabed]\nheight = -100.0\nstiffness = 3.0e9\n[integrator]\ndt = 0.01\nt_end = 1.0\n')
    return "\n".join(out)


def spread_reference(current: float):
    """The spar's pose (r, R) from the catenaries summed over the lines, and the catenaries."""
    lines = SeabedCatenaries(SPREAD_ANCHORS, SPREAD_FAIRLEADS, 320.0, 3.84e8, CHAIN_W)
    push = 0.5 * RHO * SPAR["cd_area"] * current * current
    r, R = body_balance(lines, np.eye(3), np.zeros(3), SPAR["mass"] * G_SEA, SPAR["cog"],
                        RHO * SPAR["volume"] * G_SEA, SPAR["cob"], (push, 0.0, 0.0))
    return r, R, lines, push


def spar_pose(shape) -> tuple[np.ndarray, np.ndarray]:
    body = shape.bodies[0]
    return body.position, Rotation.from_quat(np.r_[body.quaternion[1:], body.quaternion[0]]).as_matrix()


@pytest.mark.parametrize("current", [0.0, 1.0, 2.0])
def test_a_spread_moored_spar_is_held_where_the_catenaries_summed_over_its_lines_hold_it(current):
    """The spar's offset, heave and pitch under the current's push (0, 26 and 103 kN), and the restoring force the
    catenaries put on it at the pose ropesim found, against the push. The lumped lines (40 segments of 8 m)
    differ from the continuous catenary by O((l / L)^2) = 6e-4 of a line's tension, and where the touchdown
    falls between two nodes by as much again, irregularly: the restoring force is held to 1e-3 of the three lines'
    pretension (3 x 111 kN; measured 1.8e-4 at 1 m/s, 3.3e-4 at 2 m/s), the offset and the pitch to 1 % (measured
    0.13 % and 0.16 %), the heave to 1 % of its depth. With no current the spar stays on the axis to round-off."""
    r, R, lines, push = spread_reference(current)
    shape = equilibrium(scene_from_toml(spread_scene(40, current)))
    assert shape.converged
    position, turned = spar_pose(shape)
    assert position[1] == pytest.approx(r[1], rel=1e-2)
    assert abs(position[2]) < 1e-9
    pretension = sum(line.fairlead_tension for line in spread_reference(0.0)[2].last)
    restoring = lines(position + np.array(SPREAD_FAIRLEADS) @ turned.T).sum(axis=0)
    assert abs(restoring[0] + push) < 1e-3 * pretension
    if current == 0.0:
        assert abs(position[0]) < 1e-9 and Rotation.from_matrix(turned).magnitude() < 1e-12
        return
    assert position[0] == pytest.approx(r[0], rel=1e-2)
    pitch, reference_pitch = (Rotation.from_matrix(m).as_rotvec()[2] for m in (turned, R))
    assert pitch == pytest.approx(reference_pitch, rel=1e-2)


def test_the_spread_moored_spars_offset_converges_with_the_segment_length():
    """At 2 m/s of current, from 20 to 40 segments per line the offset's error falls at least 3-fold (measured
    6-fold: second order, the touchdown's quantisation on top)."""
    r = spread_reference(2.0)[0]
    errors = [np.linalg.norm(spar_pose(equilibrium(scene_from_toml(spread_scene(n, 2.0))))[0] - r) for n in (20, 40)]
    assert errors[1] < errors[0] / 3.0, errors


def test_equilibrium_reports_each_bodys_pose_and_each_lines_force_and_moment_on_it(tmp_path):
    """`ropesim equilibrium` on the V: the body's row (where it rests, how it is turned) and each line's force
    and moment about its reference point, in the table and the JSON; the two moments cancel by symmetry."""
    from typer.testing import CliRunner

    from ropesim.cli.app import app

    path = tmp_path / "v.toml"
    path.write_text(v_scene())
    runner = CliRunner()
    result = runner.invoke(app, ["equilibrium", str(path)])
    assert result.exit_code == 0, result.output
    for text in ("body block", "free at (", "line left on it", "line right on it", "about its reference point"):
        assert text in result.output
    data = json.loads(runner.invoke(app, ["equilibrium", str(path), "--json"]).output)
    (body,) = data["bodies"]
    assert body["id"] == "block" and body["kind"] == "free" and len(body["quaternion"]) == 4
    lines = {line["id"]: line for line in body["lines"]}
    assert lines["left"]["moment_Nm"][0] == pytest.approx(-lines["right"]["moment_Nm"][0], rel=1e-9)
    assert lines["left"]["force_N"][1] + lines["right"]["force_N"][1] == pytest.approx(1000.0 * G, rel=1e-6)


def test_a_scene_with_a_free_body_started_in_its_static_shape_stays_at_rest():
    """initial.shape = "equilibrium" on the tripod: the body starts at its static pose (the solver's, not the
    scene's), and over 0.2 s of verlet it and its lines stay there: the body moves less than 1e-6 m, the
    line nodes likewise (the stiffest mode's period is 1 ms; a start off balance by the solver's tolerance moves
    nothing measurable)."""
    import ropesim

    scene = scene_from_toml(tripod_scene().replace("[gravity]", '[initial]\nshape = "equilibrium"\n[gravity]')
                            .replace("t_end = 1.0", "t_end = 0.2").replace("dt = 1.0e-3", "dt = 1.0e-5"))
    model = build(scene)
    static = equilibrium(scene_from_toml(tripod_scene()))
    assert np.allclose(model.body_pose0[:3, 0], static.bodies[0].position, atol=1e-9)
    traj = ropesim.simulate(scene)
    assert np.abs(traj.body_x - traj.body_x[0]).max() < 1e-6
    assert np.abs(traj.x - traj.x[0]).max() < 1e-6
