"""Systems in the scene file: lines between points, points fixed, free, driven or on rigid bodies.

What the loader fills in (a line's material from its type, a point's kind, a body's zeros, a driven point's or
body's motion), that the resolved scene loads back to itself, every refusal in one line naming its key (a few
through ``ropesim check``: exit 2, no traceback), the new spec kinds, and random system scenes, mutated, that are
accepted or refused in one line. Pure Python: nothing here builds a model. (One rope's loader: test_loader.py.)"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from ropesim.cli.app import app
from ropesim.scene import schema as S
from ropesim.scene.loader import SceneError, load_scene, scene_from_toml
from ropesim.scene.system import ROPE_ONLY_INSTEAD, SYSTEM_ONLY_INSTEAD
from ropesim.scene.values import parse_value

from test_loader import (DELETE, FUZZ, LINE, SYSTEM_FILES, assert_one_line, keys, load, loaded_or_one_line,
                         mutated_scenes, perturbed_scenes, refused, set_items, values, variant)

SPREAD = tomllib.loads((Path(__file__).parent / "data" / "systems" / "oc3_hywind.toml").read_text())
CLUMP = tomllib.loads((Path(__file__).parent / "data" / "systems" / "clump_weight.toml").read_text())

# A 3-D system with every kind of point and body, and every key a line, point or body has.
EVERY_PART = {
    "name": "every_part", "dimension": 3,
    "line_types": {
        "chain": {"diameter": 0.1, "density": 7850.0, "EA": 1e8, "axial_damping": 1e4, "EI": 10.0,
                  "cd_normal": 2.4, "ca_normal": 0.8},
        "rope": {"diameter": 0.05, "mass_per_length": 1.5, "EA": 2e6, "compression": False},
    },
    "bodies": [
        {"id": "buoy", "position": [0.0, -5.0, 0.0], "mass": 2000.0, "inertia": [900.0, 1000.0, 1100.0, 10.0, -20.0, 5.0],
         "orientation": [0.0, 45.0, 0.0], "center_of_gravity": [0.0, -0.5, 0.0], "volume": 4.0,
         "center_of_buoyancy": [0.0, 0.2, 0.0], "cd_area": [1.0, 1.5, 1.0], "cd_rotation": [0.1, 0.1, 0.1],
         "added_mass": [1000.0, 2000.0, 1000.0], "added_inertia": [50.0, 60.0, 50.0]},
        {"id": "vessel", "kind": "driven", "position": [60.0, 0.0, 0.0], "velocity": [0.5, 0.0, 0.0],
         "angular_velocity": [0.0, 1.0, 0.0], "amplitude": [1.0, 0.5, 0.0, 2.0, 0.0, 0.0],
         "period": [10.0, 8.0, 0.0, 12.0, 0.0, 0.0], "ramp_time": 2.0,
         "path_table": [[0.0, 0, 0, 0, 0, 0, 0], [1.0, 0.1, 0, 0, 0, 0, 5.0], [2.0, 0.2, 0, 0, 0, 0, 10.0]]},
        {"id": "frame", "kind": "fixed", "position": [-30.0, -10.0, 10.0], "orientation": [0.0, 90.0, 0.0]},
    ],
    "points": [
        {"id": "anchor", "position": [0.0, -40.0, 0.0]},
        {"id": "clump", "kind": "free", "position": [20.0, -30.0, 0.0], "mass": 500.0, "volume": 0.06,
         "cd_area": 0.3, "ca": 1.0},
        {"id": "winch", "kind": "driven", "position": [20.0, 0.0, 20.0], "velocity": [0.0, 0.1, 0.0],
         "amplitude": [0.0, 0.5, 0.0], "period": [0.0, 4.0, 0.0], "phase": [0.0, 90.0, 0.0],
         "path_table": [[0.0, 0.0, 0.0, 0.0], [2.0, 0.0, -0.5, 0.0]]},
        {"id": "buoy_pad", "body": "buoy", "position": [0.0, -1.0, 0.0]},
        {"id": "fairlead", "kind": "body", "body": "vessel", "position": [-5.0, -10.0, 0.0]},
        {"id": "frame_pad", "body": "frame", "position": [0.0, 0.0, 1.0]},
    ],
    "lines": [
        {"id": "ground_chain", "type": "chain", "start": "anchor", "end": "clump", "length": 40.0, "segments": 8},
        {"id": "riser", "type": "chain", "start": "clump", "end": "buoy_pad", "length": 30.0, "segments": 6,
         "diameter": 0.12, "cd_normal": 1.2},
        {"id": "hawser", "start": "buoy_pad", "end": "fairlead", "length": 70.0, "segments": 10,
         "mass_per_length": 3.0, "diameter": 0.08, "EA": 5e6, "compression": True},
        {"id": "winch_line", "type": "rope", "start": "winch", "end": "clump", "length": 40.0, "segments": 5},
        {"id": "tether", "type": "rope", "start": "frame_pad", "end": "clump", "length": 55.0, "segments": 1},
    ],
    "initial": {"shape": "equilibrium"},
    "gravity": {}, "fluid": {"density": 1025.0}, "buoyancy": {},
    "fluid_drag": {"cd_normal": 1.1, "cd_tangential": 0.02}, "added_mass": {"ca_normal": 1.0},
    "viscous_drag": {"b_normal": 1.0, "b_tangential": 0.1},
    "flow": {"profile": "table", "heights": [-50.0, 10.0], "velocities": [[0.0, 0.0, 0.0], [0.5, 0.0, 0.1]],
             "ramp_time": 1.0},
    "seabed": {"height": -40.0, "friction": 0.5},
    "integrator": {"method": "rk4", "dt": 0.001, "t_end": 2.0},
}
# A 2-D system with a body: a free block hung from two fixed points by two legs, a driven point pulling it.
PLANE = {
    "bodies": {"id": "block", "position": [0.0, -4.0], "mass": 50.0, "inertia": 8.0, "orientation": 10.0},
    "points": [{"id": "a", "position": [-3.0, 0.0]}, {"id": "b", "position": [3.0, 0.0]},
               {"id": "pull", "kind": "driven", "position": [10.0, -4.0], "velocity": [0.2, 0.0]},
               {"id": "left", "body": "block", "position": [-0.5, 0.5]},
               {"id": "right", "body": "block", "position": [0.5, 0.5]},
               {"id": "side", "body": "block", "position": [0.5, 0.0]}],
    "lines": [{"id": "leg_a", "start": "a", "end": "left", "length": 4.5, "segments": 5, "mass_per_length": 0.5,
               "EA": 1e5},
              {"id": "leg_b", "start": "b", "end": "right", "length": 4.5, "segments": 5, "mass_per_length": 0.5,
               "EA": 1e5},
              {"id": "pull_line", "start": "side", "end": "pull", "length": 9.0, "segments": 3,
               "mass_per_length": 0.5, "EA": 1e5}],
    "gravity": {},
    "integrator": {"dt": 0.001, "t_end": 1.0},
}
SYSTEM_RAWS = [SPREAD, CLUMP, EVERY_PART, PLANE]


def by_id(items, name):
    return next(item for item in items if item.id == name)


# ------------------------------------------------------------------------------------------ resolved


def test_the_example_systems_load_as_systems():
    spread, clump = (load_scene(path) for path in sorted(SYSTEM_FILES, reverse=True))
    assert spread.is_system and clump.is_system and spread.rope is None and clump.rope is None
    assert [line.id for line in spread.lines] == ["line1", "line2", "line3"]
    assert {p.kind for p in spread.points} == {"fixed", "body"} and spread.rigid_bodies[0].kind == "driven"
    assert spread.bodies == () and spread.line_types[0][0] == "chain"
    assert isinstance(clump.initial, S.StraightLinesStart) and isinstance(spread.initial, S.SystemEquilibriumStart)
    assert by_id(clump.points, "clump").kind == "free" and by_id(clump.points, "clump").mass == 200.0
    # The anchors 853.87 m out (MoorDyn's -426.94, +-739.47 is 853.87 m too, to 0.2 mm) and 320 m down, the fairleads
    # 5.2 m out and 70 m down in the spar's frame: MoorDyn's (x, y, z) is ropesim's (x, z, -y).
    for p in spread.points:
        radius, depth = math.hypot(p.position[0], p.position[2]), -p.position[1]
        assert (radius, depth) == pytest.approx((853.87, 320.0) if p.kind == "fixed" else (5.2, 70.0), abs=3e-3)
    anchor2, fairlead2 = by_id(spread.points, "anchor2"), by_id(spread.points, "fairlead2")
    assert anchor2.position[2] < 0 and fairlead2.position[2] < 0   # MoorDyn's +y side is ropesim's -z side


def test_a_line_takes_its_types_material_and_its_own_keys_win():
    scene = load(EVERY_PART)
    ground, riser, hawser = (by_id(scene.lines, n) for n in ("ground_chain", "riser", "hawser"))
    assert ground.diameter == 0.1 and ground.EA == 1e8 and ground.axial_damping == 1e4 and ground.EI == 10.0
    assert ground.mass_per_length == pytest.approx(7850.0 * math.pi * 0.1 ** 2 / 4, rel=1e-15)
    assert riser.diameter == 0.12 and riser.mass_per_length == pytest.approx(7850.0 * math.pi * 0.12 ** 2 / 4)
    assert ground.cd_normal == 2.4 and riser.cd_normal == 1.2   # the type's, then the line's own
    assert ground.cd_tangential == riser.cd_tangential == 0.02   # neither gives it: [fluid_drag]'s
    assert ground.ca_normal == 0.8 and hawser.ca_normal == 1.0 and hawser.ca_tangential == 0.0   # [added_mass]'s
    assert hawser.type is None and hawser.compression is True and ground.compression is False
    assert hawser.density is None and hawser.axial_damping is None and hawser.EI is None   # absent stays absent
    assert ground.segment_length == 5.0 and ground.nodes == 9


def test_points_and_bodies_get_their_defaults():
    scene = load(EVERY_PART)
    kinds = {p.id: p.kind for p in scene.points}
    assert kinds == {"anchor": "fixed", "clump": "free", "winch": "driven", "buoy_pad": "body", "fairlead": "body",
                     "frame_pad": "body"}
    anchor, winch = by_id(scene.points, "anchor"), by_id(scene.points, "winch")
    assert anchor.mass is None and anchor.ramp_time is None and anchor.velocity is None   # a fixed point's: none
    assert winch.ramp_time == 0.0 and winch.phase == (0.0, 90.0, 0.0) and winch.mass is None
    frame, vessel, buoy = (by_id(scene.rigid_bodies, n) for n in ("frame", "vessel", "buoy"))
    assert frame.center_of_gravity == frame.center_of_buoyancy == frame.cd_area == frame.added_mass == (0.0,) * 3
    assert frame.cd_rotation == frame.added_inertia == (0.0,) * 3 and frame.orientation == (0.0, 90.0, 0.0)
    assert frame.inertia is None and frame.velocity is None and frame.ramp_time is None
    assert vessel.phase == (0.0,) * 6 and vessel.angular_velocity == (0.0, 1.0, 0.0) and vessel.ramp_time == 2.0
    assert buoy.inertia == (900.0, 1000.0, 1100.0, 10.0, -20.0, 5.0) and buoy.kind == "free"
    plane = load(PLANE)
    block = plane.rigid_bodies[0]
    assert block.orientation == (10.0,) and block.inertia == (8.0,) and block.cd_rotation == (0.0,)
    assert block.center_of_gravity == (0.0, 0.0) and by_id(plane.points, "pull").velocity == (0.2, 0.0)


def _system_parts(scene: S.Scene, resolved: dict):
    """(key, part, its table in the resolved TOML) for every table and entry a system's resolved scene holds."""
    for key in S.TABLES:
        if getattr(scene, key) is not None:
            yield key, getattr(scene, key), resolved[key]
    for name, line_type in scene.line_types:
        yield f"line_types.{name}", line_type, resolved["line_types"][name]
    for key in ("lines", "points"):
        for j, (item, table) in enumerate(zip(getattr(scene, key), resolved[key], strict=True)):
            yield f"{key}.{j}", item, table
    for j, (item, table) in enumerate(zip(scene.rigid_bodies, resolved.get("bodies", []), strict=True)):
        yield f"bodies.{j}", item, table


@pytest.mark.parametrize("raw", SYSTEM_RAWS, ids=["spread", "clump", "every_part", "plane"])
def test_the_resolved_system_loads_back_equal_shows_every_value_and_is_a_fixed_point(raw):
    scene = load(raw)
    text = S.scene_to_toml(scene)
    again = scene_from_toml(text, source="scene.toml", default_name="another")
    assert again == scene and S.scene_to_toml(again) == text
    resolved = tomllib.loads(text)
    assert "rope" not in resolved and resolved["initial"]["shape"] in S.SYSTEM_INITIAL_SHAPES
    for key, part, table in _system_parts(scene, resolved):
        shown = {f.name for f in fields(part) if "spec" in f.metadata and getattr(part, f.name) is not None}
        assert set(table) - {"shape"} == shown, key
    fluid = ({"cd_normal", "cd_tangential"} if "fluid_drag" in raw else set()) | (
        {"ca_normal", "ca_tangential"} if "added_mass" in raw else set())
    for line in resolved["lines"]:   # every line shows its whole material, whatever its type gave
        assert {"EA", "mass_per_length", "compression", *fluid} <= set(line)


def test_a_driven_points_and_a_driven_bodys_path_csv_is_read_into_its_table(tmp_path):
    (tmp_path / "winch.csv").write_text("t,dx,dy,dz\n0,0,0,0\n1,0,-0.2,0\n2,0,-0.5,0\n")
    (tmp_path / "vessel.csv").write_text("# t, surge, heave, sway, roll, yaw, pitch\n0,0,0,0,0,0,0\n2,1,0,0,0,3,0\n")
    raw = copy.deepcopy(EVERY_PART)
    del raw["points"][2]["path_table"], raw["bodies"][1]["path_table"]
    raw["points"][2]["path"], raw["bodies"][1]["path"] = "winch.csv", "vessel.csv"
    scene = scene_from_toml(tomli_w.dumps(raw), source="t.toml", base_dir=tmp_path)
    winch, vessel = by_id(scene.points, "winch"), by_id(scene.rigid_bodies, "vessel")
    assert winch.path is None and winch.path_table == ((0, 0, 0, 0), (1, 0, -0.2, 0), (2, 0, -0.5, 0))
    assert vessel.path is None and vessel.path_table == ((0,) * 7, (2, 1, 0, 0, 0, 3, 0))
    assert load(S.scene_to_toml(scene)) == scene   # the resolved scene carries its paths

    (tmp_path / "vessel.csv").write_text("0,0,0,0\n2,1,0,0\n")   # a point's columns, not a body's
    with pytest.raises(SceneError, match=r"bodies\.1\.path: .*vessel.csv, line 1: needs 7 finite numbers "
                                         r"\(t, dx, dy, dz, rx, ry, rz\)"):
        scene_from_toml(tomli_w.dumps(raw), source="t.toml", base_dir=tmp_path)
    (tmp_path / "vessel.csv").write_text("0,0,0,0,0,0,1\n2,1,0,0,0,3,0\n")
    with pytest.raises(SceneError, match=r"bodies\.1\.path: .*the displacement at t = 0 is \[0.0, 0.0, 0.0, 0.0, "
                                         r"0.0, 1.0\], not zero \(the path moves the body from where"):
        scene_from_toml(tomli_w.dumps(raw), source="t.toml", base_dir=tmp_path)


# ------------------------------------------------------------------------------------------ refusals

REFUSALS = [   # (base, changes, key, fragments): each a one-line refusal naming the key
    # a line attached to a missing point; its start equal to its end; an unknown type
    (CLUMP, {"lines__0__start": "lft"}, "lines.0.start", ("no point 'lft' in [[points]]", "did you mean 'left'?",
                                                         "points: left, right, clump")),
    (CLUMP, {"lines__1__end": "nowhere"}, "lines.1.end", ("no point 'nowhere'",)),
    (CLUMP, {"lines__0__end": "left"}, "lines.0.end", ("is also its start, 'left'", "two different points")),
    (CLUMP, {"lines__0__type": "wyre"}, "lines.0.type", ("no line type 'wyre' in [line_types]",
                                                        "did you mean 'wire'?")),
    # duplicate ids, within lines, points and bodies
    (CLUMP, {"lines__1__id": "left_wire"}, "lines.1.id", ("'left_wire' is already the id of lines.0",)),
    (CLUMP, {"points__2__id": "left"}, "points.2.id", ("'left' is already the id of points.0",)),
    (EVERY_PART, {"bodies__2__id": "buoy"}, "bodies.2.id", ("'buoy' is already the id of bodies.0",)),
    # a point on a missing body, kind = body without a body, a body with another kind
    (EVERY_PART, {"points__3__body": "bouy"}, "points.3.body", ("no body 'bouy' in [[bodies]]", "did you mean 'buoy'?",
                                                              "bodies: buoy, vessel, frame")),
    (CLUMP, {"points__0__kind": "body"}, "points.0.body", ("missing: a point of kind 'body' sits on a rigid body",)),
    (EVERY_PART, {"points__3__kind": "free"}, "points.3.body", ("the point's kind is 'free'",
                                                              "only a point of kind 'body'")),
    (EVERY_PART, {"points__4__kind": "fixed"}, "points.4.body", ("the point's kind is 'fixed'",)),
    # inertia: not positive definite, not positive; negative masses
    (EVERY_PART, {"bodies__0__inertia": [1.0, 1.0, 1.0, 2.0, 0.0, 0.0]}, "bodies.0.inertia",
     ("is not positive definite", "principal moments -1, 1, 3 [kg m^2]; all must be > 0")),
    (EVERY_PART, {"bodies__0__inertia": [100.0, 100.0, 100.0, 60.0, 60.0, -60.0]}, "bodies.0.inertia",
     ("is not positive definite", "principal moments -20, 160, 160")),
    (EVERY_PART, {"bodies__0__inertia": [900.0, 0.0, 1100.0]}, "bodies.0.inertia",
     ("moments of inertia Ixx, Iyy, Izz of at least 1e-12 [kg m^2]",)),
    (EVERY_PART, {"bodies__0__inertia": [900.0, -5.0, 1100.0, 0.0, 0.0, 0.0]}, "bodies.0.inertia", ("at least 1e-12",)),
    (PLANE, {"bodies__inertia": -8.0}, "bodies.0.inertia", ("must be at least 1e-12 [kg m^2], got -8.0",)),
    (PLANE, {"bodies__inertia": [8.0, 8.0, 8.0]}, "bodies.0.inertia",
     ("must be a list of 1 finite number (the moment of inertia Izz about the axis out of the plane: dimension = 2)",
      "(3 numbers)")),
    (EVERY_PART, {"bodies__0__inertia": [1.0, 2.0]}, "bodies.0.inertia",
     ("3 principal moments (Ixx, Iyy, Izz) or the tensor's 6 entries",)),
    (EVERY_PART, {"bodies__0__mass": -1.0}, "bodies.0.mass", ("must be a number >= 0 [kg], got -1.0",)),
    (EVERY_PART, {"points__1__mass": -500.0}, "points.1.mass", ("must be a number >= 0 [kg]",)),
    (CLUMP, {"line_types__wire__mass_per_length": -0.4}, "line_types.wire.mass_per_length", ("> 0 [kg/m]",)),
    # a free point with no mass and no line; a point no line uses
    (CLUMP, {"points__3": {"id": "loose", "kind": "free", "position": [5.0, -5.0]}}, "points.3",
     ("'loose' is a free point with no mass and no line",)),
    (CLUMP, {"points__3": {"id": "spare", "position": [5.0, -5.0]}}, "points.3", ("no line starts or ends at 'spare'",)),
    (CLUMP, {"points__3": {"id": "ball", "kind": "free", "mass": 3.0, "position": [5.0, -5.0]}}, "points.3",
     ("no line starts or ends at 'ball'",)),
    # a free point's keys on a point that is not free
    (CLUMP, {"points__0__mass": 10.0}, "points.0.mass", ("only a free point carries a mass", "this point is 'fixed'")),
    (CLUMP, {"points__0__volume": 0.0}, "points.0.volume", ("only a free point carries a volume",)),
    (EVERY_PART, {"points__2__cd_area": 1.0}, "points.2.cd_area", ("this point is 'driven'",)),
    (EVERY_PART, {"points__3__ca": 1.0}, "points.3.ca", ("this point is 'body'", "give the body its mass")),
    (EVERY_PART, {"points__1__volume": 0.0}, "points.1.ca", ("an added-mass coefficient needs the point's volume",)),
    # a free body with no mass or no inertia
    (EVERY_PART, {"bodies__0__mass": DELETE}, "bodies.0.mass", ("missing: a free body needs its mass",)),
    (EVERY_PART, {"bodies__0__inertia": DELETE}, "bodies.0.inertia", ("missing: a free body needs its moments",)),
    (PLANE, {"bodies__inertia": DELETE}, "bodies.0.inertia", ("(Izz)",)),
    # a body-fixed attachment in the wrong number of dimensions
    (SPREAD, {"points__3__position": [5.2, -70.0]}, "points.3.position",
     ("must be a list of 3 finite numbers (dimension = 3) [m], got [5.2, -70.0] (2 numbers)",
      "a point on body 'spar' is placed in the body's frame, in the scene's 3 dimensions")),
    (PLANE, {"points__3__position": [-0.5, 0.5, 0.0]}, "points.3.position",
     ("must be a list of 2 finite numbers (dimension = 2)", "(3 numbers)", "on body 'block'")),
    (SPREAD, {"points__0__position": [853.87, -320.0]}, "points.0.position", ("(2 numbers)",)),
    (SPREAD, {"bodies__0__orientation": [0.0, 1.0]}, "bodies.0.orientation",
     ("must be a list of 3 finite numbers (one angle per axis of rotation, x, y, z: dimension = 3) [deg]",)),
    (SPREAD, {"bodies__0__amplitude": [5.0, 0.0, 0.0]}, "bodies.0.amplitude",
     ("must be a list of 6 finite numbers (one per degree of freedom, dx, dy, dz, rx, ry, rz",)),
    # motion keys on a point or body that is not driven
    (CLUMP, {"points__0__velocity": [1.0, 0.0]}, "points.0.velocity", ("is a driven point's motion",
                                                                     "set kind = 'driven'")),
    (CLUMP, {"points__2__ramp_time": 1.0}, "points.2.ramp_time", ("this point is 'free'",)),
    (SPREAD, {"points__3__amplitude": [1.0, 0.0, 0.0]}, "points.3.amplitude", ("drive its body instead",)),
    (EVERY_PART, {"bodies__2__velocity": [1.0, 0.0, 0.0]}, "bodies.2.velocity", ("is a driven body's motion",
                                                                               "this body is 'fixed'")),
    (EVERY_PART, {"bodies__0__path_table": [[0, 0, 0, 0, 0, 0, 0], [3, 0, 0, 0, 0, 0, 0]]}, "bodies.0.path_table",
     ("this body is 'free'",)),
    # a driven point's and body's motion, checked as [[driven]]'s
    (EVERY_PART, {"points__2__period": DELETE}, "points.2.period", ("missing: a sinusoid needs its period per axis",)),
    (EVERY_PART, {"bodies__1__period": [10.0, 0.0, 0.0, 12.0, 0.0, 0.0]}, "bodies.1.period",
     ("must be > 0 on every degree of freedom that moves",)),
    (EVERY_PART, {"points__2__amplitude": DELETE}, "points.2.period", ("is used only with amplitude",)),
    (EVERY_PART, {"bodies__1__path_table": [[0, 0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 0, 0]]}, "bodies.1.path_table",
     ("covers t = 0 to 1 s, but the run goes from 0 to 2 s",)),
    (EVERY_PART, {"bodies__1__path_table": [[0, 0, 0, 0], [2, 0, 0, 0]]}, "bodies.1.path_table",
     ("each 7 finite numbers (t, then one per degree of freedom)",)),
    (EVERY_PART, {"points__2__path": "winch.csv"}, "points.2.path_table", ("not both",)),
    # a line's material incomplete or contradictory
    (CLUMP, {"line_types__wire__EA": DELETE}, "lines.0.EA", ("missing: the line's axial stiffness EA [N] (on the "
                                                            "line or its line type 'wire')",)),
    (CLUMP, {"line_types__wire__mass_per_length": DELETE}, "lines.0.mass_per_length",
     ("missing: give mass_per_length, or diameter and density",)),
    (CLUMP, {"lines__0__density": 7850.0}, "lines.0.mass_per_length",
     ("0.4 kg/m contradicts density x pi d^2 / 4 = 0.616538 kg/m",)),
    (EVERY_PART, {"line_types__chain__diameter": DELETE}, "lines.0.diameter",
     ("missing: with density, the mass per metre is density x pi d^2 / 4 (on the line or its line type 'chain')",)),
    (PLANE, {"lines__0__length": 1e-9, "lines__0__segments": 10_000}, "lines.0.length",
     ("gives segment_length = length / segments = 1e-13 [m], outside 1e-12",)),
    (PLANE, {"lines__0__EA": 1e12, "lines__0__length": 0.5}, "lines.0.EA", ("gives stiffness = EA / l = 1e+13 [N/m]",)),
    # a line's fluid coefficients without the table they refine
    (CLUMP, {"lines__0__cd_normal": 1.2}, "lines.0.cd_normal", ("is used only with [fluid_drag]",)),
    (CLUMP, {"line_types__wire__ca_tangential": 0.1}, "line_types.wire.ca_tangential", ("only with [added_mass]",)),
    # a line with no diameter under fluid terms; fluid terms without [fluid]; buoyancy without gravity
    (EVERY_PART, {"lines__2__diameter": DELETE}, "lines.2.diameter", ("missing: [fluid_drag] acts on each line's "
                                                                     "diameter",)),
    (SPREAD, {"line_types__chain__diameter": DELETE}, "lines.0.diameter", ("[fluid_drag]",)),
    (SPREAD, {"fluid": DELETE}, "fluid_drag", ("needs a [fluid] table",)),
    (PLANE, {"points__0__kind": "free", "points__0__cd_area": 0.5}, "points.0.cd_area", ("needs a [fluid] table",)),
    (PLANE, {"bodies__volume": 0.5}, "bodies.0.volume", ("needs a [fluid] table",)),
    (PLANE, {"bodies__cd_rotation": [0.2]}, "bodies.0.cd_rotation", ("needs a [fluid] table",)),
    (SPREAD, {"gravity": DELETE}, "buoyancy", ("needs [gravity]",)),
    # a flow with nothing to push
    (PLANE, {"flow": {"velocity": [1.0, 0.0]}}, "flow", ("moves the system only through drag",
                                                         "[viscous_drag] or a point or body with cd_area")),
    # a flow table that does not cover the system's start
    (EVERY_PART, {"flow__heights": [-30.0, 10.0]}, "flow.heights", ("cover y = -30 to 10 m, but the system's points "
                                                                    "and bodies start at y = -40 to 0 m",)),
    # a held point below the seabed; a seabed with no footprint
    (SPREAD, {"seabed__height": -319.0}, "seabed.height", ("puts the seabed 1 m above fixed point 'anchor1' "
                                                           "(points.0, at y = -320 m)",)),
    (EVERY_PART, {"points__2__position": [20.0, -45.0, 20.0]}, "seabed.height", ("driven point 'winch'",)),
    (PLANE, {"seabed": {"height": -10.0}}, "seabed.contact_width", ("give it, or every line's diameter (lines.0 has "
                                                                    "none)",)),
    # names and ids: printable, bounded, fit for a folder or file name
    (CLUMP, {"lines__0__id": "a/b"}, "lines.0.id", ("must be a plain name (it names the line in outputs)",
                                                    "without / or \\")),
    (CLUMP, {"points__0__id": "tab\there"}, "points.0.id", ("printable",)),
    (EVERY_PART, {"bodies__0__id": ".."}, "bodies.0.id", ("not '.' or '..'",)),
    (CLUMP, {"lines__0__id": "x" * 201}, "lines.0.id", ("at most 200 bytes in UTF-8",)),
    (CLUMP, {"name": "a/b"}, "name", ("plain folder name",)),
    # the start
    (CLUMP, {"initial": {"shape": "hanging"}}, "initial.shape", ("'hanging' starts one rope; a system starts as "
                                                                 "'lines', 'equilibrium'",)),
    (CLUMP, {"initial": {"shape": "lines", "top": [0, 0]}}, "initial.top", ("allowed: shape",)),
    (CLUMP, {"initial": {"shape": "equlibrium"}}, "initial.shape", ("did you mean 'equilibrium'?",)),
    # nothing free; an idle body; the tables a system needs
    (CLUMP, {"points__2__kind": "fixed", "points__2__mass": DELETE, "lines__0__segments": 1, "lines__1__segments": 1},
     "lines", ("nothing is free to move",)),
    (EVERY_PART, {"points__5__body": "vessel"}, "bodies.2", ("'frame' is fixed and no point sits on it",)),
    (CLUMP, {"lines": []}, "lines", ("has no entries",)),
    (CLUMP, {"points": DELETE}, "points", ("missing",)),
    (CLUMP, {"integrator": DELETE}, "integrator", ("missing: every scene needs a [integrator] table",)),
    (CLUMP, {"lines__0__segments": 0}, "lines.0.segments", ("must be an integer >= 1",)),
    (CLUMP, {"line_types__wire__EA": math.inf}, "line_types.wire.EA", ("finite",)),
    (CLUMP, {"lines__0__speed": 1.0}, "lines.0.speed", ("unknown key", "allowed: id, start, end, length")),
    (CLUMP, {"line_types": {"a.b": {"EA": 1.0}}}, "line_types.a.b", ("must not contain '.'",)),
    (CLUMP, {"line_types": 5}, "line_types", ("must be a table of named tables ([line_types.NAME])",)),
    # one-rope parts in a system, a system's parts in one rope
    (CLUMP, {"bodies": [{"node": 0, "mass": 1.0}]}, "bodies.0.node", ("a body on a node belongs to a one-rope "
                                                                      "scene",)),
    (LINE, {"bodies": [{"id": "box", "position": [0, 0], "mass": 1.0}]}, "bodies.0.id",
     ("a rigid body (an entry with an id) belongs to a system",)),
    (LINE, {"points": [{"id": "a", "position": [0, 0]}]}, "points", ("[[points]] join a system's lines",
                                                                     "needs [[lines]]")),
    (LINE, {"line_types": {"wire": {"EA": 1.0}}}, "line_types", ("[line_types] name the materials",)),
]


@pytest.mark.parametrize("base,changes,key,fragments", REFUSALS, ids=[f"{i}-{r[2]}" for i, r in enumerate(REFUSALS)])
def test_bad_systems_are_refused_in_one_line_naming_the_key(base, changes, key, fragments):
    refused(variant(base, **changes), key, *fragments)


@pytest.mark.parametrize("table", S.ROPE_ONLY_TABLES)
def test_each_one_rope_table_is_refused_in_a_system_saying_what_to_use(table):
    raw = {**copy.deepcopy(CLUMP), table: {} if table not in S.ARRAYS_OF_TABLES else [{}]}
    text = refused(raw, table, ROPE_ONLY_INSTEAD[table])
    assert len(text) < 300
    assert set(ROPE_ONLY_INSTEAD) == set(S.ROPE_ONLY_TABLES) and set(SYSTEM_ONLY_INSTEAD) == set(S.SYSTEM_ONLY_TABLES)


@pytest.mark.parametrize("table,instead", [("pinned", "a fixed point"), ("drag", "[viscous_drag]"),
                                           ("drag", "[fluid_drag]"), ("driven", "a driven point"),
                                           ("overrides", "a free point with mass"), ("bending", "EI"),
                                           ("rope", "[line_types]")])
def test_the_one_rope_tables_name_their_replacement(table, instead):
    assert instead in ROPE_ONLY_INSTEAD[table]


def test_a_one_rope_scene_is_as_it_was():
    """A rope scene's parts are those of one rope; every system part is left empty."""
    scene = load(LINE)
    assert not scene.is_system and scene.lines == scene.points == scene.rigid_bodies == scene.line_types == ()


@pytest.mark.parametrize("base,changes,fragment", [
    (CLUMP, {"lines__0__start": "lft"}, "no point 'lft'"),
    (SPREAD, {"points__3__position": [5.2, -70.0]}, "placed in the body's frame"),
    (EVERY_PART, {"bodies__0__inertia": [1.0, 1.0, 1.0, 2.0, 0.0, 0.0]}, "not positive definite"),
    (CLUMP, {"pinned": {"nodes": [0]}}, "a fixed point"),
])
def test_ropesim_check_refuses_a_bad_system_with_exit_2_and_one_line(tmp_path, base, changes, fragment):
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(variant(base, **changes)))
    result = CliRunner().invoke(app, ["check", str(path)], env={"COLUMNS": "200"})
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    assert result.stdout == "" and "Traceback" not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("ropesim: ") and str(path) in lines[0] and fragment in lines[0]


# ------------------------------------------------------------------------------------------ spec kinds


def _spec(kind, unit="deg"):
    return S.Spec(kind, "test", unit, required=False)


@pytest.mark.parametrize("kind,dim,value,expected", [
    ("angles", 3, [1, 2, 3], (1.0, 2.0, 3.0)),
    ("angles", 2, [30], (30.0,)),
    ("angles", 2, 30, (30.0,)),   # one angle may be written bare
    ("dofs", 3, [1, 2, 3, 4, 5, 6], (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)),
    ("dofs", 2, [1, 2, 3], (1.0, 2.0, 3.0)),
    ("dof_rows", 2, [[0, 0, 0, 0], [1, 1, 2, 3]], ((0.0,) * 4, (1.0, 1.0, 2.0, 3.0))),
    ("dof_rows", 3, [[0, 0, 0, 0, 0, 0, 0]], ((0.0,) * 7,)),
    ("inertia", 3, [1, 2, 3], (1.0, 2.0, 3.0)),
    ("inertia", 3, [2, 2, 2, -1, 0, 0], (2.0, 2.0, 2.0, -1.0, 0.0, 0.0)),
    ("inertia", 2, 5, (5.0,)),
    ("inertia", 2, [5], (5.0,)),
])
def test_the_new_spec_kinds_accept(kind, dim, value, expected):
    assert parse_value(value, _spec(kind), "k", "t.toml", dim) == expected


@pytest.mark.parametrize("kind,dim,value,fragment", [
    ("angles", 3, [1, 2], "must be a list of 3 finite numbers (one angle per axis of rotation, x, y, z"),
    ("angles", 2, [1, 2], "must be a list of 1 finite number (one angle per axis of rotation, z"),
    ("angles", 3, [1, 2, math.nan], "finite"),
    ("angles", 3, [1, 2, True], "finite numbers"),
    ("angles", 2, True, "finite number"),
    ("angles", 3, [0, 0, 1e13], "at most 1e+12 in magnitude [deg]"),
    ("dofs", 3, [1, 2, 3], "must be a list of 6 finite numbers (one per degree of freedom, dx, dy, dz, rx, ry, rz"),
    ("dofs", 2, [1, 2, 3, 4, 5, 6], "must be a list of 3 finite numbers (one per degree of freedom, dx, dy, rz"),
    ("dofs", 3, "surge", "got 'surge'"),
    ("dof_rows", 3, [[0, 0, 0, 0]], "each 7 finite numbers (t, then one per degree of freedom)"),
    ("dof_rows", 2, [[0, 0, 0, math.inf]], "each 4 finite numbers"),
    ("dof_rows", 2, [], "must be a list of rows"),
    ("dof_rows", 2, [[0, 0, 0, 1e13]], "at most 1e+12 in magnitude"),
    ("dof_rows", 2, [[0, 0, 0, 0]] * 100_001, "at most 100,000 rows"),
    ("inertia", 3, [1, 2, 3, 4], "3 principal moments (Ixx, Iyy, Izz) or the tensor's 6 entries"),
    ("inertia", 3, 5, "3 principal moments"),
    ("inertia", 3, [1, 2, "3"], "finite numbers (Ixx, Iyy, Izz)"),
    ("inertia", 3, [1, 2, 3, 0, 0, math.nan], "finite numbers (Ixx, Iyy, Izz, Ixy, Ixz, Iyz)"),
    ("inertia", 3, [1, 1e-13, 1], "at least 1e-12"),
    ("inertia", 3, [1, 1, 1e13], "at most 1e+12 in magnitude"),
    ("inertia", 3, [1, 1, 1, 1, 0, 0], "not positive definite"),   # a singular tensor: one principal moment 0
    ("inertia", 2, [1, 2], "must be a list of 1 finite number"),
    ("inertia", 2, 0, "must be at least 1e-12"),
])
def test_the_new_spec_kinds_refuse(kind, dim, value, fragment):
    with pytest.raises(SceneError) as info:
        parse_value(value, _spec(kind), "bodies.0.k", "t.toml", dim)
    text = assert_one_line(info.value, "t.toml")
    assert info.value.key == "bodies.0.k" and fragment in text, text


def test_a_positive_definite_tensor_is_told_from_one_that_is_not_by_its_eigenvalues():
    """A random rotation of positive principal moments is accepted; shift one moment below zero and it is not."""
    rng = np.random.default_rng(20)
    for _ in range(50):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        moments = rng.uniform(1.0, 100.0, 3)
        for shift, ok in ((0.0, True), (-moments.min() - 1e-3 * moments.max(), False)):
            tensor = q @ np.diag(moments + shift) @ q.T
            six = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]
            if min(six[:3]) < 1e-12:
                continue   # refused for a non-positive diagonal first
            try:
                parse_value([float(v) for v in six], _spec("inertia", "kg m^2"), "k", "t.toml", 3)
                assert ok, six
            except SceneError as exc:
                assert not ok and "not positive definite" in str(exc), (six, str(exc))


# ------------------------------------------------------------------------------------------ fuzzing


def _accepted_or_one_line(text: str, sets=()):
    """Loaded, a system's resolved scene loads back to itself; refused, the refusal is one line."""
    scene = loaded_or_one_line(text, sets)
    if scene is None:
        return None
    assert scene_from_toml(S.scene_to_toml(scene), source="again.toml") == scene
    if scene.is_system:
        assert scene.rope is None and all(line.EA and line.mass_per_length for line in scene.lines)
    return scene


SYSTEM_FUZZ = settings(FUZZ, max_examples=400)   # loading alone is quick: a few ms a scene


@SYSTEM_FUZZ
@given(mutated_scenes(SYSTEM_RAWS))
def test_mutated_systems_are_accepted_or_refused_in_one_line(raw):
    _accepted_or_one_line(tomli_w.dumps(raw))


@SYSTEM_FUZZ
@given(perturbed_scenes(SYSTEM_RAWS))
def test_systems_with_edge_numbers_are_accepted_or_refused_in_one_line(raw):
    _accepted_or_one_line(tomli_w.dumps(raw))


SYSTEM_KEYS = st.sampled_from(sorted({"lines", "points", "bodies", "line_types", "0", "1", "2", "chain", "wire",
                                      *(f.name for cls in (S.Line, S.Point, S.RigidBody, S.LineType)
                                        for f in fields(cls))}))


@SYSTEM_FUZZ
@given(st.sampled_from(SYSTEM_RAWS), st.lists(st.tuples(st.lists(st.one_of(SYSTEM_KEYS, keys), min_size=1,
                                                                  max_size=4), values), min_size=1, max_size=3))
def test_random_set_overrides_on_systems_are_accepted_or_refused_in_one_line(raw, items):
    _accepted_or_one_line(tomli_w.dumps(raw), set_items(items))


def test_a_sweep_knows_a_systems_keys():
    """`ropesim sweep` reads a key's kind and unit from the schema: a line type's key, a rigid body's, a line's."""
    from ropesim.sweep.plan import key_spec, parse_axis

    assert key_spec("line_types.chain.EA").unit == "N" and key_spec("bodies.0.inertia").kind == "inertia"
    assert key_spec("points.2.mass").unit == "kg" and key_spec("bodies.1.node").kind == "int"
    assert parse_axis("lines.0.segments=10:40:4").values == (10, 20, 30, 40)   # integers, not 10.0 ...
