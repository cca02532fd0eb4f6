"""A scene may say which axis is up: ``up = "z"`` (MoorDyn's and OrcaFlex's frame) beside ropesim's y.

The loader turns a z-up scene into its y-up twin (:mod:`ropesim.scene.frame`) and every output is turned back.
What must hold: a z-up scene and its y-up twin give the same trajectories up to the axis permutation
(x, y, z)_z-up = (x, -z, y)_y-up, to round-off (1e-12 relative). The z-up scene here is written from the y-up one
by this file's own table of what each key means, with scipy turning the body's orientation (independent of the
loader's P R P^T and its angles). The system: OC3-Hywind's spar, free, on its three chains over the seabed, one
anchor a driven point, a current across, the spar tilted about all three axes, a full inertia tensor."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ropesim import simulate
from ropesim.io.trajectory import Trajectory
from ropesim.scene import schema as S
from ropesim.scene.frame import GEOMETRIC_KINDS, TURNS
from ropesim.scene.loader import SceneError, load_scene, scene_from_dict, scene_from_toml

ROOT = Path(__file__).resolve().parents[1]
P = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])      # z-up coordinates -> y-up


def y_up_scene() -> dict:
    """spread_mooring_free, short and coarse, with a driven anchor, a tilted spar and a full inertia tensor."""
    raw = tomllib.loads((ROOT / "ropesim" / "scenarios" / "spread_mooring_free.toml").read_text())
    raw.pop("initial", None)   # the pose and twist given below, not the static solve's (an iterative solve would
    # carry the orientation's round-off of 1e-16 into its own stopping point)
    for line in raw["lines"]:
        line["segments"] = 8
    spar = raw["bodies"][0]
    spar.update(orientation=[3.0, 5.0, 7.0], inertia=[1.89e10, 1.9e8, 1.89e10, 1.0e8, -2.0e8, 3.0e7],
                velocity=[0.1, 0.05, -0.2], angular_velocity=[0.5, 1.0, 0.2])
    raw["points"][0].update(kind="driven", amplitude=[2.0, 0.5, 1.0], period=[5.0, 6.0, 7.0], phase=[0.0, 20.0, 30.0],
                            path_table=[[0.0, 0.0, 0.0, 0.0], [10.0, 1.0, 0.5, -2.0]])
    raw["flow"] = {"velocity": [1.0, 0.0, 0.4], "ramp_time": 0.5}
    raw["integrator"].update(t_end=0.6)
    raw["output"] = {"interval": 0.1}
    raw["name"] = "twin"
    return raw


def out(v):
    """A y-up vector in the z-up frame: (x, y, z) -> (x, -z, y)."""
    return [v[0], -v[2] + 0.0, v[1]]


def swap(v):
    return [v[0], v[2], v[1]]


def to_z_up(raw: dict) -> dict:
    """The z-up scene of a y-up one, by this test's own reading of each key."""
    z = copy.deepcopy(raw)
    z["up"] = "z"
    z["flow"]["velocity"] = out(z["flow"]["velocity"])
    for p in z["points"]:
        p["position"] = out(p["position"])
        for key in ("amplitude",):
            if key in p:
                p[key] = out(p[key])
        for key in ("period", "phase"):
            if key in p:
                p[key] = swap(p[key])
        if "path_table" in p:
            p["path_table"] = [[r[0], *out(r[1:])] for r in p["path_table"]]
    for b in z["bodies"]:
        for key in ("position", "center_of_gravity", "center_of_buoyancy", "velocity", "angular_velocity"):
            b[key] = out(b[key])
        for key in ("cd_area", "cd_rotation", "added_mass", "added_inertia"):
            b[key] = swap(b[key])
        xx, yy, zz, xy, xz, yz = b["inertia"]
        tensor = P.T @ np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) @ P
        b["inertia"] = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]
        turn = Rotation.from_matrix(P.T @ Rotation.from_euler("xyz", b["orientation"], degrees=True).as_matrix() @ P)
        b["orientation"] = turn.as_euler("xyz", degrees=True).tolist()     # R = Rz Ry Rx, ropesim's angles
    return z


def turned_out(a):
    """A y-up run's vectors (..., 3) as the z-up run stores them."""
    return np.stack([a[..., 0], -a[..., 2], a[..., 1]], axis=-1)


def assert_close(z_up, y_up, what):
    scale = np.max(np.abs(y_up))
    assert np.max(np.abs(z_up - y_up)) <= 1e-12 * scale, what


@pytest.fixture(scope="module")
def twins():
    y_raw = y_up_scene()
    y_scene, z_scene = scene_from_dict(y_raw), scene_from_dict(to_z_up(y_raw))
    return y_scene, z_scene, simulate(y_scene), simulate(z_scene)


def test_the_z_up_scene_and_its_y_up_twin_give_the_same_trajectories(twins):
    _, _, ty, tz = twins
    assert tz.summary["status"] == ty.summary["status"] == "completed"
    assert len(tz.t) == len(ty.t) == 7
    for name in ("x", "v", "support", "held_force", "body_x", "body_v", "body_w"):
        assert_close(getattr(tz, name), turned_out(getattr(ty, name)), name)
    for name in ("tension", "strain"):
        assert_close(getattr(tz, name), getattr(ty, name), name)
    rz = tz.body("spar").rotation
    assert_close(rz, P.T @ ty.body("spar").rotation @ P, "the spar's rotation: P^T R P")
    assert_close(tz.body("spar").moment, turned_out(ty.body("spar").moment), "the lines' moment on the spar")
    energy_y, energy_z = ty.summary["final_energy_J"], tz.summary["final_energy_J"]
    assert energy_y.keys() == energy_z.keys()
    for key in energy_y:
        assert abs(energy_z[key] - energy_y[key]) <= 1e-12 * max(abs(v) for v in energy_y.values()), key
    # the run moved: the chains hang from the spar, which rises (z up) while they fall into their catenaries
    assert tz.body_x[-1, 0, 2] > tz.body_x[0, 0, 2]
    assert np.all(tz.x[..., 2] > -320.0 - 0.05)                      # nothing sinks into the seabed (z)


def test_a_z_up_scene_is_its_y_up_twin_inside_and_writes_back_its_own_frame(twins):
    y_scene, z_scene, _, _ = twins
    assert z_scene.up == "z" and y_scene.up == "y"
    spar_y, spar_z = y_scene.rigid_bodies[0], z_scene.rigid_bodies[0]
    assert spar_z.position == spar_y.position and spar_z.inertia == spar_y.inertia
    np.testing.assert_allclose(spar_z.orientation, spar_y.orientation, rtol=0, atol=1e-12)
    written = S.scene_to_dict(z_scene)
    given = to_z_up(y_up_scene())
    assert written["up"] == "z"
    assert written["bodies"][0]["orientation"] == given["bodies"][0]["orientation"]     # as the file gave it
    assert written["bodies"][0]["position"] == given["bodies"][0]["position"]
    assert written["points"][0]["path_table"] == given["points"][0]["path_table"]
    again = scene_from_toml(S.scene_to_toml(z_scene))
    assert again == z_scene                       # the resolved scene loads back to the same twin, bit for bit
    assert S.scene_to_dict(y_scene)["up"] == "y"     # a y-up scene's resolved file says so, its keys as before


def test_a_z_up_run_folder_exports_and_plots_heights_from_z(twins, tmp_path):
    from ropesim.io.export import export
    from ropesim.render.plots import run_figure

    _, z_scene, _, _ = twins
    traj = simulate(z_scene, tmp_path / "run")
    opened = Trajectory.open(tmp_path / "run")
    assert opened.scene == z_scene
    assert tomllib.loads((tmp_path / "run" / "scene.toml").read_text())["up"] == "z"
    np.testing.assert_array_equal(np.load(tmp_path / "run" / "trajectory.npz")["x"], traj.x)
    assert np.all(traj.x[-1, :, 2] < 1.0) and np.ptp(traj.x[-1, :, 2]) > 250    # heights: z, seabed to surface
    export(opened, "csv", tmp_path / "run.csv")
    text = (tmp_path / "run.csv").read_text().splitlines()
    header = text[0].split(",")
    rows = np.array([[float(c) for c in (row.split(",")[:1] + row.split(",")[2:])] for row in text[1:]])
    z_column = header.index(next(h for h in header if h.startswith("z ")))
    np.testing.assert_array_equal(rows[:, z_column - 1], opened.x[:, :, 2].ravel())     # the CSV's z: heights
    fig, _ = run_figure(opened)
    labels = [(ax.get_xlabel(), ax.get_ylabel(), getattr(ax, "get_zlabel", lambda: "")()) for ax in fig.axes]
    assert ("x [m]", "y [m]", "z [m]") in labels                    # the 3-D shape: z up, labelled so
    internal = opened.internal
    np.testing.assert_array_equal(internal.x[..., 1], opened.x[..., 2])   # the model's height is the scene's z
    from ropesim.viewer.content import run_content

    assert run_content(opened).axes == ("x", "z", "-y")     # the viewer draws y-up, its triad names the scene's axes


def test_every_geometric_key_of_the_schema_says_how_it_turns():
    classes = [cls for cls in vars(S).values() if isinstance(cls, type) and hasattr(cls, "__dataclass_fields__")]
    for cls in classes:
        for name, f in cls.__dataclass_fields__.items():
            spec = f.metadata.get("spec")
            if spec is not None and spec.kind in GEOMETRIC_KINDS:
                assert name in TURNS, f"{cls.__name__}.{name}"


@pytest.mark.parametrize("change, key, words", [
    (lambda raw: raw.update(dimension=2), "up", "3-D"),
    (lambda raw: raw.update(up="x"), "up", "one of 'y', 'z'"),
    (lambda raw: raw["bodies"][0].update(kind="driven", angular_velocity=[0.0, 1.0, 0.0],
                                         orientation=[0.0, 0.0, 5.0]), "bodies.0", "at most one of y and z"),
    (lambda raw: raw["seabed"].update(height=-300.0), "seabed.height", "at z = -320 m"),   # checked on the twin
])
def test_bad_up_is_refused_in_one_line(change, key, words):
    raw = to_z_up(y_up_scene())
    for b in raw["bodies"]:
        b["orientation"] = [0.0, 0.0, 0.0]
    change(raw)
    if raw.get("dimension") == 2:
        raw = {"name": "flat", "dimension": 2, "up": "z", "rope": {"nodes": 3, "segment_length": 1.0,
                                                                     "stiffness": 10.0, "mass": 1.0},
               "initial": {"shape": "hanging"}, "integrator": {"dt": 0.01, "t_end": 0.1}}
    if raw.get("bodies", [{}])[0].get("kind") == "driven":
        for k in ("mass", "inertia", "volume", "cd_area", "cd_rotation", "added_mass", "added_inertia", "velocity",
                  "center_of_gravity", "center_of_buoyancy"):
            raw["bodies"][0].pop(k, None)
        raw.pop("buoyancy")
    with pytest.raises(SceneError) as exc:
        scene_from_dict(raw, source="scene.toml")
    message = str(exc.value)
    assert "\n" not in message and message.startswith(f"scene.toml: {key}") and words in message, message


def test_bad_up_exits_2_in_one_line_from_the_command_line(tmp_path):
    import subprocess
    import sys

    scene = tmp_path / "flat.toml"
    scene.write_text('up = "z"\n[rope]\nnodes = 3\nsegment_length = 1.0\nstiffness = 10.0\nmass = 1.0\n'
                     '[initial]\nshape = "hanging"\n[integrator]\ndt = 0.01\nt_end = 0.1\n')
    done = subprocess.run([sys.executable, "-m", "ropesim", "check", str(scene)], capture_output=True, text=True)
    assert done.returncode == 2
    lines = [line for line in (done.stderr + done.stdout).splitlines() if line.strip()]
    assert len(lines) == 1 and "up" in lines[0] and "3-D" in lines[0] and "Traceback" not in done.stderr, lines


def test_a_driven_body_turning_about_z_alone_turns_angle_by_angle():
    """A z-up driven body yawing (about z) and rolling: its twin turns about y and x, the same motion."""
    raw = {"name": "yaw", "dimension": 3, "up": "z",
           "bodies": [{"id": "vessel", "kind": "driven", "position": [0.0, 0.0, 0.0], "orientation": [2.0, 0.0, 30.0],
                       "angular_velocity": [0.0, 0.0, 3.0], "amplitude": [0.0, 0.0, 0.5, 4.0, 0.0, 6.0],
                       "period": [0.0, 0.0, 5.0, 7.0, 0.0, 9.0]}],
           "points": [{"id": "fairlead", "body": "vessel", "position": [10.0, 2.0, -1.0]},
                      {"id": "anchor", "position": [60.0, 0.0, -30.0]}],
           "line_types": {"rope": {"diameter": 0.05, "mass_per_length": 2.0, "EA": 1e6}},
           "lines": [{"id": "line", "type": "rope", "start": "anchor", "end": "fairlead", "length": 70.0,
                      "segments": 4}],
           "gravity": {}, "integrator": {"dt": 0.001, "t_end": 0.4, "method": "rk4"}, "output": {"interval": 0.1}}
    traj = simulate(scene_from_dict(raw))
    t = traj.t
    yaw = 30.0 + 3.0 * t + 6.0 * np.sin(2 * np.pi * t / 9.0)
    roll = 2.0 + 4.0 * np.sin(2 * np.pi * t / 7.0)
    expected = Rotation.from_euler("xyz", np.stack([roll, 0 * t, yaw], axis=-1), degrees=True).as_matrix()
    np.testing.assert_allclose(traj.body("vessel").rotation, expected, rtol=0, atol=1e-12)
    fairlead = traj.x[:, -1]                        # the line's last node sits on the fairlead
    heave = 0.5 * np.sin(2 * np.pi * t / 5.0)
    np.testing.assert_allclose(fairlead, expected @ np.array([10.0, 2.0, -1.0]) + np.stack(
        [0 * t, 0 * t, heave], axis=-1), rtol=0, atol=1e-9)


def test_load_scene_reads_up_from_a_file(tmp_path):
    import tomli_w

    path = tmp_path / "z.toml"
    path.write_text(tomli_w.dumps(to_z_up(y_up_scene())))
    assert load_scene(path).up == "z"


def test_a_moordyn_import_as_it_is_is_the_importers_y_up_form_inside():
    """MoorDyn's file imported as it is (up = "z", the default) and as the importer turns it into ropesim's y-up
    frame (``y_up=True``, its own rotation of every key) are the same scene inside: every key equal, the body's
    angles but for the importer's rounding to 12 decimals (a free body turned by roll, pitch and yaw on one line
    to an anchor over the seabed). (Their runs start from the static solve, which leaves the nodes resting on the
    frictionless seabed free to lie anywhere along it: the rounding moves them by up to 9 mm, so the run comparison
    is the twin test above.)"""
    from dataclasses import replace

    from ropesim.scene.moordyn import read_moordyn
    from test_moordyn_import import BODY

    z_scene, y_scene = (scene_from_dict({"name": "body", **read_moordyn(BODY, "body.txt", y_up=y_up).scene})
                        for y_up in (False, True))
    assert z_scene.up == "z" and y_scene.up == "y"
    z_body, y_body = z_scene.rigid_bodies[0], y_scene.rigid_bodies[0]
    np.testing.assert_allclose(z_body.orientation, y_body.orientation, rtol=0, atol=1e-11)
    assert replace(z_scene, up="y", rigid_bodies=(replace(z_body, orientation=y_body.orientation),)) == y_scene
    assert S.scene_to_dict(z_scene)["points"] == read_moordyn(BODY, "body.txt").scene["points"]   # written back as given


def test_a_z_up_rope_hangs_along_z_and_starts_again_from_its_own_run(tmp_path):
    """A 3-D rope of a z-up scene hangs along -z from its pinned top and swings in x; another z-up scene starts from
    its last frame (initial.shape = "from_run" reads the run's frames, which are in the scene's frame); a y-up scene
    starting from it is refused in one line."""
    import tomli_w

    rope = {"name": "hang", "dimension": 3, "up": "z",
            "rope": {"nodes": 5, "segment_length": 0.5, "stiffness": 2000.0, "mass": 0.1},
            "initial": {"shape": "hanging", "top": [0.0, 1.0, 3.0], "velocity": [0.5, 0.0, 0.0]},
            "pinned": {"nodes": [0]}, "gravity": {},
            "integrator": {"dt": 1e-4, "t_end": 0.2, "method": "verlet"}, "output": {"interval": 0.1}}
    traj = simulate(scene_from_dict(rope), tmp_path / "hang")
    np.testing.assert_allclose(traj.x[0, :, 2], 3.0 - 0.5 * np.arange(5), rtol=0, atol=1e-12)   # down along z
    np.testing.assert_array_equal(traj.x[0, :, 1], 1.0)
    assert traj.x[-1, -1, 0] > 0.0 and traj.x[-1, -1, 2] < traj.x[-1, 0, 2]
    again = dict(rope, initial={"shape": "from_run", "run": "hang"})
    path = tmp_path / "again.toml"
    path.write_text(tomli_w.dumps(again))
    scene = load_scene(path)
    written = S.scene_to_dict(scene)
    np.testing.assert_array_equal(np.array(written["initial"]["points"]), traj.x[-1])    # the frame, in z up
    path.write_text(tomli_w.dumps({k: v for k, v in again.items() if k != "up"}))
    with pytest.raises(SceneError, match="initial.run: .*up = 'z' and this scene has up = 'y'"):
        load_scene(path)


SEA_TWIN = """
name = "sea_twin"
dimension = 3
{up}
[rope]
length = 14.0
segments = 12
mass_per_length = 2.0
diameter = 0.1
EA = 1.0e6
[initial]
shape = "line"
start = {start}
end = {end}
[gravity]
[fluid]
density = 1025.0
[buoyancy]
[fluid_drag]
cd_normal = 1.2
cd_tangential = 0.1
[added_mass]
ca_normal = 1.0
[sea]
level = 0.0
wind = {wind}
probes = {probes}
[waves]
kind = "regular"
height = 1.0
period = 5.0
direction = 30.0
[integrator]
method = "rk4"
dt = 1.0e-3
t_end = 1.0
[output]
interval = 0.1
"""


def test_a_line_through_the_surface_in_oblique_waves_and_wind_is_its_y_up_twin():
    """The sea in a z-up scene: the mean level is a height along z, the wind a vector, and ``direction`` an angle
    about the vertical from +x towards +y (towards -z in the y-up twin, where the waves run along
    (cos b, 0, -sin b)): a rope crossing the surface, in waves 30 degrees off x and a wind across, gives the same
    run either way up."""
    start, end, wind = [0.0, -6.0, 0.0], [10.0, 3.0, 4.0], [5.0, 0.5, 2.0]
    fmt = lambda v: "[" + ", ".join(repr(float(c)) for c in v) + "]"    # noqa: E731
    y_up = scene_from_toml(SEA_TWIN.format(up="", start=fmt(start), end=fmt(end), wind=fmt(wind),
                                           probes="[[3.0, -2.0], [0.0, 0.0]]"))    # (x, z)
    z_up = scene_from_toml(SEA_TWIN.format(up='up = "z"', start=fmt(out(start)), end=fmt(out(end)),
                                           wind=fmt(out(wind)), probes="[[3.0, 2.0], [0.0, 0.0]]"))   # (x, y)
    y_run, z_run = simulate(y_up), simulate(z_up)
    assert np.ptp(y_run.x[..., 1], axis=0).max() > 0.01          # the waves and the weight move it
    for name in ("x", "v"):
        assert_close(getattr(z_run, name), turned_out(getattr(y_run, name)), name)
    np.testing.assert_allclose(z_run.tension, y_run.tension, rtol=1e-12, atol=1e-12 * np.max(y_run.tension))
    # the sea's records are scalars: the same numbers either way up (a probe at the twin's (x, z) = (x, -y))
    assert np.ptp(y_run.probe_elevation[:, 0]) > 0.1
    np.testing.assert_array_equal(z_run.probe_elevation, y_run.probe_elevation)
    np.testing.assert_allclose(z_run.submerged, y_run.submerged, rtol=0, atol=1e-9)
    assert 0.0 < y_run.line_submerged.min() and y_run.line_submerged.max() < 1.0   # it crosses the surface
