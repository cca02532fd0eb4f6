"""A system's results per object (ropesim.analysis.objects, ropesim.analysis.rotation): each line's, point's and
rigid body's arrays slice the right nodes and segments, its end forces and a body's force and moment follow
their definitions, the orientations agree with scipy's Rotation, and a free point's line forces obey Newton's
second law in a real run."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import ropesim
from ropesim.analysis.rotation import angles_from_quaternion, continuous_angles, rotation_matrix
from ropesim.model.rotation import quaternion_from_angles
from ropesim.model.layout import line_layouts
from ropesim.model.tension import line_segments

from conftest import ROOT as REPO
from synthetic_system import body_rotations, plate_scene, turning_body_run

SYSTEMS = REPO / "tests" / "data" / "systems"
G = 9.81


@pytest.fixture(scope="module")
def spar_run():
    return turning_body_run(ropesim.load_scene(SYSTEMS / "oc3_hywind.toml"))


@pytest.fixture(scope="module")
def plate_run():
    return turning_body_run(plate_scene(), rate=1.3)


# ------------------------------------------------------------------------------------------ rotations


def test_rotations_agree_with_scipy():
    rng = np.random.default_rng(7)
    angles = rng.uniform(-180.0, 180.0, (500, 3))
    angles[:, 1] /= 2.0                                 # b in [-90, 90], where the angles are unique
    reference = Rotation.from_euler("xyz", angles, degrees=True)   # about fixed x, then y, then z: Rz Ry Rx
    q = np.array([quaternion_from_angles(a) for a in angles])
    assert np.allclose(np.abs(np.sum(q * reference.as_quat(scalar_first=True), axis=1)), 1.0, atol=1e-12)
    assert np.allclose(rotation_matrix(q), reference.as_matrix(), atol=1e-12)
    assert np.allclose(angles_from_quaternion(reference.as_quat(scalar_first=True)), angles, atol=1e-9)
    scaled = 3.0 * reference.as_quat(scalar_first=True)          # not normalised: divided by its norm first
    assert np.allclose(rotation_matrix(scaled), reference.as_matrix(), atol=1e-12)
    # the lock at b = +-90 deg: some angles that give the same rotation
    for locked in ([30.0, 90.0, 10.0], [-50.0, -90.0, 40.0]):
        back = angles_from_quaternion(quaternion_from_angles(locked))
        assert abs(back[1]) == pytest.approx(90.0, abs=1e-9)
        assert np.allclose(Rotation.from_euler("xyz", back, degrees=True).as_matrix(),
                           Rotation.from_euler("xyz", locked, degrees=True).as_matrix(), atol=1e-9)


def test_two_d_rotations_are_about_z():
    turn = np.array([[170.0], [-100.0], [181.0], [540.0]])
    q = np.array([quaternion_from_angles(a, dim=2) for a in turn])
    assert np.allclose(q[:, 1:3], 0.0)
    assert np.allclose(angles_from_quaternion(q, dim=2)[:, 0], [170.0, -100.0, -179.0, 180.0])
    assert np.allclose(rotation_matrix(q, dim=2),
                       Rotation.from_euler("z", turn, degrees=True).as_matrix()[:, :2, :2], atol=1e-12)
    assert np.allclose(continuous_angles(np.array([170.0, -175.0, -160.0, 179.0])), [170.0, 185.0, 200.0, 179.0])


# ------------------------------------------------------------------------------------------ lines


@pytest.mark.parametrize("which", ["spar_run", "plate_run"])
def test_each_line_slices_its_own_nodes_and_segments(which, request):
    traj = request.getfixturevalue(which)
    layouts = line_layouts(traj.scene)
    first_segment = 0
    assert list(traj.lines) == [line.id for line in traj.scene.lines]
    for layout, line in zip(layouts, traj.scene.lines):
        result = traj.line(line.id)
        assert (result.first, result.nodes, result.start, result.end) == (layout.first, layout.nodes, line.start,
                                                                          line.end)
        assert np.array_equal(result.positions, traj.x[:, layout.first:layout.end])
        assert np.array_equal(result.velocities, traj.v[:, layout.first:layout.end])
        segments = slice(first_segment, first_segment + line.segments)
        assert np.array_equal(result.tension, traj.tension[:, segments])
        assert np.array_equal(result.strain, traj.strain[:, segments])
        assert np.array_equal(result.start_tension, traj.tension[:, first_segment])
        assert np.array_equal(result.end_tension, traj.tension[:, first_segment + line.segments - 1])
        first_segment += line.segments
    assert first_segment == traj.tension.shape[1]


def test_a_line_end_pulls_what_it_holds_along_its_end_segment(plate_run):
    traj = plate_run
    for line in traj.scene.lines:
        result = traj.line(line.id)
        x = np.asarray(result.positions)
        for force, tension, end, neighbour in ((result.start_force, result.start_tension, x[:, 0], x[:, 1]),
                                               (result.end_force, result.end_tension, x[:, -1], x[:, -2])):
            along = (neighbour - end) / np.linalg.norm(neighbour - end, axis=1, keepdims=True)
            assert np.allclose(np.linalg.norm(force, axis=1), np.abs(tension), rtol=1e-12)
            assert np.allclose(force, tension[:, None] * along, rtol=1e-12, atol=1e-9)


def test_unknown_ids_name_what_the_run_has(spar_run):
    with pytest.raises(KeyError, match="no line 'line9' in this run; its lines: 'line1', 'line2', 'line3'"):
        spar_run.line("line9")
    with pytest.raises(KeyError, match="its points: 'anchor1'"):
        spar_run.point("fairled1")
    with pytest.raises(KeyError, match="no body 'hull'.*'spar'"):
        spar_run.body("hull")


def test_a_rope_is_the_line_rope():
    scene = ropesim.load_scene(REPO / "scenarios" / "helicopter_mass.toml", ["integrator.t_end=0.05"])
    traj = ropesim.simulate(scene)
    rope = traj.line("rope")
    assert list(traj.lines) == ["rope"] and traj.points == {} and traj.bodies == {}
    assert np.array_equal(rope.positions, traj.x) and np.array_equal(rope.tension, traj.tension)
    assert rope.start is None and rope.start_force.shape == (traj.frames, 2)


# ------------------------------------------------------------------------------------------ points


def test_points_are_their_line_ends(spar_run):
    ends = {p.id: [] for p in spar_run.scene.points}
    for line, layout in zip(spar_run.scene.lines, line_layouts(spar_run.scene)):
        ends[line.start].append(layout.first)
        ends[line.end].append(layout.end - 1)
    for point in spar_run.scene.points:
        result = spar_run.point(point.id)
        assert result.nodes == tuple(ends[point.id])
        assert np.array_equal(result.position, spar_run.x[:, ends[point.id][0]])
        assert np.array_equal(result.velocity, spar_run.v[:, ends[point.id][0]])
    anchor = spar_run.point("anchor2")
    assert anchor.kind == "fixed" and anchor.ends == (("line2", "start"),)
    assert np.array_equal(anchor.force, spar_run.line("line2").start_force)
    assert list(anchor.line_forces) == ["line2"]


# ------------------------------------------------------------------------------------------ bodies


@pytest.mark.parametrize("which", ["spar_run", "plate_run"])
def test_a_body_reports_its_pose_against_scipy(which, request):
    traj = request.getfixturevalue(which)
    dim = traj.scene.dimension
    rate = 0.7 if which == "spar_run" else 1.3
    axis = (0.3, 0.9, 0.2) if dim == 3 else (0.0, 0.0, 1.0)
    (turning,) = body_rotations(traj.scene, traj.t, axis, rate)
    body = traj.body(traj.scene.rigid_bodies[0].id)
    assert np.array_equal(body.position, traj.body_x[:, 0]) and np.array_equal(body.velocity, traj.body_v[:, 0])
    assert np.array_equal(body.quaternion, traj.body_q[:, 0])
    assert body.rotation.shape == (traj.frames, dim, dim)
    assert np.allclose(body.rotation, turning.as_matrix()[:, :dim, :dim], atol=1e-12)
    reference = turning.as_euler("xyz", degrees=True)
    if dim == 2:
        reference = reference[:, 2:]
    turned = (body.angles - reference + 180.0) % 360.0 - 180.0        # equal up to whole turns
    assert np.allclose(turned, 0.0, atol=1e-8)
    assert np.all(np.abs(np.diff(body.angles, axis=0)) < 90.0)          # continuous from frame to frame
    if dim == 2:   # a steady turn about z reads as a steady ramp of the angle: 1.3 rad/s for 6 s is 447 deg
        assert np.allclose(body.angles[:, 0], 20.0 + np.degrees(rate * traj.t), atol=1e-8)
        assert np.allclose(body.angular_velocity, rate)
    else:
        assert np.allclose(body.angular_velocity, rate * np.array(axis) / np.linalg.norm(axis))


@pytest.mark.parametrize("which", ["spar_run", "plate_run"])
def test_a_body_takes_the_force_and_moment_of_each_line_on_its_points(which, request):
    """Each line end on a body point pulls it with its end segment's tension; the moments are about the
    body's reference point, which the points ride with (x_point = x_b + R p, checked through scipy)."""
    traj = request.getfixturevalue(which)
    dim = traj.scene.dimension
    scene = traj.scene
    body_id = scene.rigid_bodies[0].id
    body = traj.body(body_id)
    rotation = Rotation.from_quat(np.asarray(traj.body_q[:, 0]), scalar_first=True)
    force, turn, per_line = np.zeros((traj.frames, dim)), np.zeros((traj.frames, 3)), {}
    for point in (p for p in scene.points if p.kind == "body"):
        local = np.zeros(3)
        local[:dim] = point.position
        at = np.asarray(traj.body_x[:, 0]) + rotation.apply(local)[:, :dim]
        for line in scene.lines:
            for which_end, node in (("start", 0), ("end", -1)):
                if getattr(line, which_end) != point.id:
                    continue
                x = np.asarray(traj.line(line.id).positions)
                assert np.allclose(x[:, node], at, atol=1e-12)
                neighbour = x[:, 1] if node == 0 else x[:, -2]
                along = (neighbour - at) / np.linalg.norm(neighbour - at, axis=1, keepdims=True)
                tension = traj.line(line.id).start_tension if node == 0 else traj.line(line.id).end_tension
                f = tension[:, None] * along
                arm = np.zeros((traj.frames, 3))
                arm[:, :dim] = at - np.asarray(traj.body_x[:, 0])
                f3 = np.zeros((traj.frames, 3))
                f3[:, :dim] = f
                force += f
                turn += np.cross(arm, f3)
                per_line[line.id] = f
    assert body.points == tuple(p.id for p in scene.points if p.kind == "body")
    assert set(body.line_forces) == set(per_line)
    for line, f in per_line.items():
        assert np.allclose(body.line_forces[line], f, rtol=1e-12, atol=1e-9)
    assert np.allclose(body.force, force, rtol=1e-12, atol=1e-9)
    expected = turn if dim == 3 else turn[:, 2:]
    assert body.moment.shape == expected.shape
    assert np.allclose(body.moment, expected, rtol=1e-12, atol=1e-6)
    assert np.allclose(sum(body.line_moments.values()), body.moment, rtol=1e-12, atol=1e-6)


def test_a_run_without_body_states_says_so():
    scene = ropesim.load_scene(SYSTEMS / "oc3_hywind.toml")
    traj = turning_body_run(scene)
    from dataclasses import replace

    with pytest.raises(ValueError, match="holds no rigid-body states"):
        replace(traj, body_x=None).body("spar")


# ------------------------------------------------------------------------------------------ physics


def test_a_free_point_moves_as_its_lines_pull_it():
    """The clump weight and its two line ends move as one (200 kg plus two half segments): its momentum changes
    by the impulse of the lines' end forces plus its weight. The impulse is integrated by the trapezoidal rule
    over the saved frames, so the balance closes as (frame interval)^2: 2.4 N s of 420 N s at 1 ms, 0.37 N s at
    0.4 ms (the snap loads are the sharpest part)."""
    errors = {}
    for interval in (1e-3, 4e-4):
        scene = ropesim.load_scene(SYSTEMS / "clump_weight.toml", ["integrator.t_end=2",
                                                                     f"output.interval={interval}"])
        traj = ropesim.simulate(scene)
        clump = traj.point("clump")
        mass = 200.0 + 2 * 0.4 * 2.25 / 2
        force = clump.force + mass * np.array([0.0, -G])
        v, t = np.asarray(clump.velocity), traj.t
        impulse = np.concatenate([np.zeros((1, 2)),
                                  np.cumsum(0.5 * (force[1:] + force[:-1]) * np.diff(t)[:, None], axis=0)])
        momentum = mass * (v - v[0])
        errors[interval] = np.abs(momentum - impulse).max()
        assert errors[interval] < 0.01 * np.abs(momentum).max()
    assert errors[1e-3] / errors[4e-4] > 0.8 * (1e-3 / 4e-4) ** 2     # second order in the frame interval


def test_a_free_body_moves_and_turns_as_its_lines_pull_it(tmp_path):
    """A 100 kg plate (Izz = 50 kg m^2) falling onto two slack legs and swinging on them, in a real run: the
    rigid assembly (the plate and the two line ends it carries, half a segment each) changes its momentum by the
    impulse of the lines' end forces and its weight, and its angular momentum about the origin by the angular
    impulse of r_b x F + the body's line moment (about its reference point) and the weights. The impulses are
    integrated over frames every 0.5 ms by the trapezoidal rule, with verlet at dt = 0.25 ms: the balances close
    to 1e-4 and 3e-4 of what moved (a first-order method leaves an O(dt) remainder of its own: 0.4 % at this dt)."""
    from synthetic_system import BODY_2D

    path = tmp_path / "plate.toml"
    path.write_text(BODY_2D)
    scene = ropesim.load_scene(path, ["integrator.t_end=2", "output.interval=5e-4", "integrator.dt=2.5e-4",
                                      "integrator.method=verlet"])
    traj = ropesim.simulate(scene)
    body, t = traj.body("plate"), traj.t
    ends = [traj.line("left_leg").node_at("end"), traj.line("right_leg").node_at("start")]
    end_mass = np.array([11.0 / 6 / 2, 11.0 / 4 / 2])        # 1 kg/m, half a segment each
    mass, inertia, weight = 100.0, 50.0, np.array([0.0, -G])
    x_end, v_end = np.asarray(traj.x)[:, ends], np.asarray(traj.v)[:, ends]

    def impulse(rate):
        return np.concatenate([np.zeros((1,) + rate.shape[1:]),
                               np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t).reshape(-1, *[1] * (rate.ndim - 1)),
                                         axis=0)])

    def cross(r, f):
        return r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]

    x_b, v_b = np.asarray(body.position), np.asarray(body.velocity)
    momentum = mass * v_b + np.einsum("k,fkd->fd", end_mass, v_end)
    change = momentum - momentum[0]
    pushed = impulse(body.force + (mass + end_mass.sum()) * weight)
    assert np.abs(change - pushed).max() < 2e-4 * np.abs(change).max()
    spin = (inertia * body.angular_velocity[:, 0] + mass * cross(x_b, v_b)
            + np.einsum("k,fk->f", end_mass, cross(x_end, v_end)))
    torque = (cross(x_b, body.force) + body.moment[:, 0] + cross(x_b, mass * weight)
              + np.einsum("k,fk->f", end_mass, cross(x_end, np.broadcast_to(weight, x_end.shape))))
    assert np.abs(spin - spin[0] - impulse(torque)).max() < 6e-4 * np.abs(spin - spin[0]).max()
    assert np.abs(body.angles[-1, 0] - body.angles[0, 0]) > 1.0       # it did turn
