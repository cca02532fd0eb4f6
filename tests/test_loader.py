"""The strict scene loader: what it accepts, how it refuses, --set overrides, the resolved-scene round trip,
and property-based attacks on it. (The scene reference's agreement with the schema: tests/test_docs.py.)"""

from __future__ import annotations

import copy
import math
import tomllib
import warnings
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ropesim.scene import schema as S
from ropesim.model.build import EquilibriumError, build
from ropesim.scene.loader import SceneError, apply_override, load_scene, parse_override, scene_from_toml
from ropesim.analysis.stability import time_step_verdict
from ropesim.integrate.methods import METHODS
from ropesim.integrate.grid import TimeGrid
from ropesim.integrate.methods import make_integrator
from ropesim.run import BLEW_UP, COMPLETED, simulate

from conftest import SCENARIOS

SOURCE = "t.toml"
SCENARIO_FILES = sorted(SCENARIOS.glob("*.toml"))
SYSTEM_FILES = sorted((Path(__file__).parent / "data" / "systems").glob("*.toml"))   # lines, points and bodies

# A small valid open rope, and a small valid loop with a thrower; the refusal tests change one thing at a time.
LINE = {
    "rope": {"nodes": 5, "segment_length": 1.0, "stiffness": 100.0, "mass": 1.0},
    "initial": {"shape": "hanging"},
    "integrator": {"dt": 0.001, "t_end": 0.1},
}
LOOP = {
    "rope": {"nodes": 8, "segment_length": 1.0, "stiffness": 100.0, "mass": 1.0, "closed": True},
    "initial": {"shape": "square_loop"},
    "thrower": {"center": [0.0, 0.0], "length": 2.0, "width": 1.0, "v_max": 1.0, "b_thrower": 5.0},
    "guides": [{"center": [-1.0, 0.0], "radius": 0.5}, {"center": [1.0, 0.0], "radius": 0.5}],
    "integrator": {"dt": 0.001, "t_end": 0.1},
}
TOWED_3D = {   # a towed rope with an end mass, in 3-D
    "dimension": 3,
    "rope": {"nodes": 12, "segment_length": 0.5, "stiffness": 5000.0, "mass": 5.0},
    "initial": {"shape": "hanging", "top": [0.0, 0.0, 0.0], "velocity": [8.0, 0.0, 1.0]},
    "driven": [{"nodes": [0], "velocity": [8.0, 0.0, 1.0]}],
    "gravity": {"g": 9.81},
    "drag": {"b": 5.0},
    "overrides": [{"index": -1, "mass": 100.0}],
    "integrator": {"dt": 0.001, "t_end": 0.1},
}
SHOOTER_3D = {**LOOP, "dimension": 3, "thrower": {**LOOP["thrower"], "center": [0.0, 0.0, 0.0]},
              "guides": [{"center": [-1.0, 0.0, 0.0], "radius": 0.5}, {"center": [1.0, 0.0, 0.0], "radius": 0.5}],
              "initial": {"shape": "square_loop", "velocity": [0.0, 0.0, 0.5]}, "bending": {"stiffness": 10.0},
              "drag": {"b": 0.1}, "gravity": {"g": 9.81}}
DELETE = object()


def variant(base: dict, **changes) -> dict:
    """``base`` with dotted keys (``__`` for ``.``) set, or removed when the value is DELETE."""
    raw = copy.deepcopy(base)
    for dotted, value in changes.items():
        *path, last = dotted.split("__")
        node = raw
        for part in path:
            node = node[int(part)] if isinstance(node, list) else node.setdefault(part, {})
        if isinstance(node, list):   # an entry of an array of tables: changed, removed, or added at the end
            last = int(last)
            if last == len(node):
                node.append(None)
        if value is DELETE:
            del node[last]
        else:
            node[last] = value
    return raw


def load(raw: dict | str, source: str = SOURCE, sets=()) -> S.Scene:
    text = raw if isinstance(raw, str) else tomli_w.dumps(raw)
    return scene_from_toml(text, source=source, default_name="t", overrides=sets)


def assert_one_line(exc: SceneError, source: str = SOURCE) -> str:
    text = str(exc)
    assert "\n" not in text and "\r" not in text, text
    assert text.startswith(f"{source}: ") or text.startswith(f"{source} (with --set"), text
    return text


def refused(raw, key: str, *fragments: str, source: str = SOURCE, sets=()) -> str:
    """Assert that loading fails with one line naming the source, ``key`` and every fragment; return it."""
    with pytest.raises(SceneError) as info:
        load(raw, source, sets)
    text = assert_one_line(info.value, source)
    assert info.value.key == key, text
    assert f": {key}: " in text, text
    for fragment in fragments:
        assert fragment in text, f"{fragment!r} not in {text!r}"
    return text


# ------------------------------------------------------------------------------------ accepted scenes


def test_minimal_scenes_get_every_default():
    line = load(LINE)
    assert line.name == "t" and line.dimension == 2 and line.description == ""
    assert line.rope.closed is False
    assert line.initial == S.HangingStart(top=(0.0, 0.0), velocity=(0.0, 0.0))
    assert line.integrator.method == "symplectic_euler"
    assert line.output.interval == 0.01
    assert line.gravity is None and line.drag is None and line.bending is None and line.thrower is None
    assert line.guides == () and line.driven == () and line.overrides == () and line.pinned is None

    loop = load(LOOP)
    assert loop.initial.top_center == (0.0, 0.0)  # the thrower's centre
    assert loop.thrower.omega0 == pytest.approx(4 * math.pi * 1.0 / 2.0)  # 2 (2 pi v_max / L)
    assert [g.omega0 for g in loop.guides] == [loop.thrower.omega0] * 2
    assert [g.one_sided for g in loop.guides] == [False, False]
    assert load(variant(LINE, gravity={})).gravity.g == 9.81


def test_integers_are_numbers_and_single_values_are_lists():
    scene = load(variant(LINE, rope__mass=2, pinned={"nodes": -1}, guides={"center": [0, 3], "radius": 1,
                                                                             "omega0": 2}))
    assert scene.rope.mass == 2.0 and isinstance(scene.rope.mass, float)
    assert scene.pinned.nodes == (-1,) and scene.node(-1) == 4
    assert len(scene.guides) == 1 and scene.guides[0].center == (0.0, 3.0)


def test_every_part_together_in_3d():
    raw = {
        "name": "all", "description": "every part", "dimension": 3,
        "rope": {"nodes": 6, "segment_length": 0.5, "stiffness": 1e3, "mass": 0.2},
        "bending": {"stiffness": 10.0},
        "initial": {"shape": "line", "start": [0, 0, 0], "end": [2.5, 0, 0], "velocity": [0, 0, 1]},
        "gravity": {"g": 9.8}, "drag": {"b": 0.1},
        "pinned": {"nodes": [0]},
        "driven": [{"nodes": [-1], "velocity": [1, 0, 0]}],
        "overrides": [{"index": -2, "mass": 3.0}, {"index": 2, "drag": 0.0}],
        "integrator": {"method": "yoshida4", "dt": 1e-4, "t_end": 0.5},
        "output": {"interval": 0.05},
    }
    scene = load(raw)
    assert scene.dimension == 3 and scene.initial.end == (2.5, 0.0, 0.0)
    model = build(scene)
    assert model.x0.shape == (3, 6) and model.mass[4] == 3.0 and model.drag[2] == 0.0 and model.drag[3] == 0.1
    assert list(model.held_idx) == [0, 5]


def test_points_and_explicit_top_center():
    pts = [[0, 0], [1, 0], [1, -1], [0, -1]]
    scene = load(variant(LINE, rope__nodes=4, rope__closed=True, initial={"shape": "points", "points": pts}))
    assert scene.initial.points == tuple(tuple(float(c) for c in p) for p in pts)
    loop = load(variant(LOOP, initial__top_center=[3, 4]))
    assert loop.initial.top_center == (3.0, 4.0)


# ---------------------------------------------------------------------------------------- refusals

UNKNOWN_KEYS = [
    ("ropes", "rope"), ("integrater", "integrator"), ("gravty", "gravity"), ("overide", "overrides"),
    ("rope__mas", "mass"), ("rope__closd", "closed"), ("integrator__tend", "t_end"),
    ("integrator__methd", "method"), ("output__intervall", "interval"), ("initial__tpo", "top"),
]


@pytest.mark.parametrize("dotted,near", UNKNOWN_KEYS)
def test_misspelt_key_suggests_the_nearest(dotted, near):
    refused(variant(LINE, **{dotted: 1}), dotted.replace("__", "."), f"did you mean '{near}'?", "allowed:")


@pytest.mark.parametrize("dotted,near", [
    ("thrower__vmax", "v_max"), ("thrower__omega", "omega0"), ("guides__1__raduis", "radius"),
    ("guides__0__onesided", "one_sided"), ("bending__stifness", "stiffness"),
])
def test_misspelt_key_in_the_shooter_parts(dotted, near):
    raw = variant(LOOP, bending={"stiffness": 1.0}, **{dotted: 1})
    refused(raw, dotted.replace("__", "."), f"did you mean '{near}'?")


@pytest.mark.parametrize("dotted,near,extra", [
    ("driven__0__velocty", "velocity", {"driven": [{"nodes": [0], "velocity": [1, 0]}]}),
    ("overrides__0__mas", "mass", {"overrides": [{"index": -1, "mass": 2.0}]}),
    ("pinned__node", "nodes", {"pinned": {"nodes": [0]}}),
    ("drag__bb", "b", {"drag": {"b": 1.0}}),
    ("gravity__gg", "g", {"gravity": {"g": 1.0}}),
])
def test_misspelt_key_in_the_held_and_force_parts(dotted, near, extra):
    refused(variant(variant(LINE, **extra), **{dotted: 1}), dotted.replace("__", "."), f"did you mean '{near}'?")


def test_unknown_key_without_a_near_one_lists_what_is_allowed():
    text = refused(variant(LINE, zzzz=1), "zzzz", "allowed: name, description, dimension, up, rope, initial")
    assert "did you mean" not in text
    refused(variant(LINE, rope__qqqq=1), "rope.qqqq", "allowed: nodes, segment_length, stiffness, mass, closed")


@pytest.mark.parametrize("shape,extra,key,allowed", [
    ("hanging", {"start": [0, 0]}, "initial.start", "allowed: shape, top, velocity"),
    ("line", {"start": [0, 0], "end": [0, -4], "top": [0, 0]}, "initial.top", "allowed: shape, start, end, velocity"),
    ("points", {"points": [[0, 0], [0, -1], [0, -2], [0, -3], [0, -4]], "top_center": [0, 0]},
     "initial.top_center", "allowed: shape, points, velocity"),
])
def test_keys_of_another_initial_shape_are_refused(shape, extra, key, allowed):
    refused(variant(LINE, initial={"shape": shape, **extra}), key, f"with shape = '{shape}'", allowed)


def test_square_loop_refuses_points():
    refused(variant(LOOP, initial__points=[[0, 0]]), "initial.points", "with shape = 'square_loop'",
            "allowed: shape, top_center, velocity")


WRONG_TYPES = [
    ({"rope__nodes": 5.0}, "rope.nodes", "must be an integer >= 2"),
    ({"rope__nodes": "5"}, "rope.nodes", "got '5'"),
    ({"rope__nodes": True}, "rope.nodes", "must be an integer"),
    ({"rope__mass": "heavy"}, "rope.mass", "must be a number > 0 [kg], got 'heavy'"),
    ({"rope__mass": True}, "rope.mass", "must be a number"),
    ({"rope__mass": [1.0]}, "rope.mass", "must be a number"),
    ({"rope__closed": 1}, "rope.closed", "must be true or false"),
    ({"rope__closed": "yes"}, "rope.closed", "must be true or false"),
    ({"initial__top": [0]}, "initial.top", "must be a list of 2 finite numbers (dimension = 2) [m]"),
    ({"initial__top": [0, 0, 0]}, "initial.top", "list of 2 finite numbers"),
    ({"initial__top": [0, "1"]}, "initial.top", "list of 2 finite numbers"),
    ({"initial__velocity": "fast"}, "initial.velocity", "list of 2 finite numbers"),
    ({"initial__shape": 3}, "initial.shape", "must be one of 'hanging', 'line', 'square_loop', 'points'"),
    ({"initial__shape": "hangin"}, "initial.shape", "did you mean 'hanging'?"),
    ({"integrator__method": "verlett"}, "integrator.method", "did you mean 'verlet'?"),
    ({"integrator__method": 3}, "integrator.method", "must be one of 'symplectic_euler', 'verlet'"),
    ({"integrator__dt": "0.001"}, "integrator.dt", "must be a number > 0 [s]"),
    ({"dimension": 4}, "dimension", "must be one of 2, 3"),
    ({"dimension": "3"}, "dimension", "must be one of 2, 3"),
    ({"dimension": 2.0}, "dimension", "must be one of 2, 3"),
    ({"name": 5}, "name", "must be a string"),
    ({"description": ["a"]}, "description", "must be a string"),
    ({"pinned": {"nodes": [1.5]}}, "pinned.nodes", "non-empty list of node indices"),
    ({"pinned": {"nodes": []}}, "pinned.nodes", "non-empty list of node indices"),
    ({"pinned": {"nodes": [True]}}, "pinned.nodes", "non-empty list of node indices"),
    ({"rope": 5}, "rope", "must be a table, got 5"),
    ({"initial": "hanging"}, "initial", "must be a table"),
    ({"gravity": [1, 2]}, "gravity", "must be a table"),
    ({"guides": 5}, "guides", "must be an array of tables ([[guides]])"),
    ({"overrides": [5]}, "overrides.0", "must be a table"),
    ({"rope__mass": math.nan}, "rope.mass", "must be a finite number"),
    ({"rope__mass": math.inf}, "rope.mass", "must be a finite number"),
    ({"rope__mass": 10 ** 400}, "rope.mass", "must be a finite number"),
    ({"initial__top": [0, math.inf]}, "initial.top", "finite numbers"),
    ({"initial__top": [0, 10 ** 400]}, "initial.top", "finite numbers"),
]


@pytest.mark.parametrize("changes,key,fragment", WRONG_TYPES)
def test_wrong_types(changes, key, fragment):
    refused(variant(LINE, **changes), key, fragment)


OUT_OF_RANGE = [
    ({"rope__mass": 0}, "rope.mass", "must be a number > 0 [kg], got 0.0"),
    ({"rope__mass": -1}, "rope.mass", "> 0"),
    ({"rope__nodes": 1}, "rope.nodes", "must be an integer >= 2"),
    ({"rope__nodes": 10 ** 7}, "rope.nodes", "<= 1e+06"),
    ({"rope__segment_length": 0.0}, "rope.segment_length", "> 0 [m]"),
    ({"rope__stiffness": -5}, "rope.stiffness", "> 0 [N/m]"),
    ({"integrator__dt": 0}, "integrator.dt", "must be a number > 0 [s]"),
    ({"integrator__dt": -0.001}, "integrator.dt", "> 0"),
    ({"integrator__t_end": -1}, "integrator.t_end", "must be a number >= 0 [s]"),
    ({"drag": {"b": -0.1}}, "drag.b", "must be a number >= 0 [kg/s]"),
    ({"gravity": {"g": -9.81}}, "gravity.g", ">= 0"),
    ({"bending": {"stiffness": 0}}, "bending.stiffness", "> 0 [N/m]"),
    ({"output": {"interval": 0}}, "output.interval", "> 0 [s]"),
    ({"overrides": [{"index": 0, "mass": 0}]}, "overrides.0.mass", "> 0 [kg]"),
    ({"overrides": [{"index": 0, "drag": -1}]}, "overrides.0.drag", ">= 0 [kg/s]"),
    ({"overrides": [{"index": 5, "mass": 1}]}, "overrides.0.index", "past the rope's end: allowed -5 to 4"),
    ({"overrides": [{"index": -6, "mass": 1}]}, "overrides.0.index", "allowed -5 to 4"),
    ({"pinned": {"nodes": [0, 7]}}, "pinned.nodes[1]", "node index 7 is past the rope's end"),
    ({"driven": [{"nodes": [-6], "velocity": [1, 0]}]}, "driven.0.nodes[0]", "past the rope's end"),
    ({"integrator__t_end": 1e300}, "integrator.t_end", "at most 1e+12"),
    # finite, in range, yet their products or ratios overflow (k / m, omega r, ...): refused by magnitude
    ({"rope__mass": 1e-310}, "rope.mass", "must be at least 1e-12 [kg] (smaller ones make ratios such as k / m "
                                          "overflow), got 1e-310"),
    ({"rope__stiffness": 1e300}, "rope.stiffness", "must be at most 1e+12 in magnitude [N/m]"),
    ({"overrides": [{"index": -1, "mass": 1e-13}]}, "overrides.0.mass", "at least 1e-12 [kg]"),
    ({"drag": {"b": 1e308}}, "drag.b", "at most 1e+12 in magnitude [kg/s]"),
    ({"initial__top": [0, -1e13]}, "initial.top",
     "at most 1e+12 in magnitude [m] (larger numbers overflow in products), got [0, -10000000000000.0]"),
    ({"integrator__dt": 1e-300}, "integrator.dt", "at least 1e-12 [s]"),
]


@pytest.mark.parametrize("changes,key,fragment", OUT_OF_RANGE)
def test_out_of_range(changes, key, fragment):
    refused(variant(LINE, **changes), key, fragment)


@pytest.mark.parametrize("dotted,key,fragment", [
    ("thrower__length", "thrower.length", "> 0 [m]"),
    ("thrower__width", "thrower.width", "> 0 [m]"),
    ("thrower__b_thrower", "thrower.b_thrower", ">= 0 [kg/s]"),
    ("thrower__omega0", "thrower.omega0", "> 0 [rad/s]"),
    ("thrower__damping_ratio", "thrower.damping_ratio", ">= 0"),
    ("guides__1__radius", "guides.1.radius", "> 0 [m]"),
    ("guides__0__omega0", "guides.0.omega0", "> 0 [rad/s]"),
])
def test_out_of_range_in_the_shooter_parts(dotted, key, fragment):
    refused(variant(LOOP, **{dotted: -1}), key, fragment)


MISSING_PARTS = [
    (variant(LINE, rope=DELETE), "rope", "missing: every scene needs a [rope] table"),
    (variant(LINE, initial=DELETE), "initial", "missing: every scene needs a [initial] table"),
    (variant(LINE, integrator=DELETE), "integrator", "missing"),
    (variant(LINE, rope__mass=DELETE), "rope.mass", "missing: mass m of each node [kg]"),
    (variant(LINE, rope__nodes=DELETE), "rope.nodes", "missing"),
    (variant(LINE, integrator__dt=DELETE), "integrator.dt", "missing: time step [s]"),
    (variant(LINE, integrator__t_end=DELETE), "integrator.t_end", "missing"),
    (variant(LINE, initial__shape=DELETE), "initial.shape", "missing: one of 'hanging', 'line'"),
    (variant(LINE, initial={"shape": "line", "start": [0, 0]}), "initial.end", "missing"),
    (variant(LINE, initial={"shape": "points"}), "initial.points", "missing: one position per node"),
    (variant(LINE, drag={}), "drag.b", "missing"),
    (variant(LINE, bending={}), "bending.stiffness", "missing"),
    (variant(LINE, pinned={}), "pinned.nodes", "missing"),
    (variant(LINE, driven=[{"velocity": [1.0, 0.0]}]), "driven.0.nodes", "missing: indices of the driven nodes"),
    (variant(LINE, driven=[{"nodes": [0], "amplitude": [1.0, 0.0]}]), "driven.0.period", "missing"),
    (variant(LINE, overrides=[{"mass": 2.0}]), "overrides.0.index", "missing"),
    (variant(LOOP, thrower__center=DELETE), "thrower.center", "missing"),
    (variant(LOOP, thrower__v_max=DELETE), "thrower.v_max", "missing"),
    (variant(LOOP, guides__1__radius=DELETE), "guides.1.radius", "missing"),
]


@pytest.mark.parametrize("raw,key,fragment", MISSING_PARTS)
def test_missing_tables_and_keys(raw, key, fragment):
    refused(raw, key, fragment)


CROSS_FIELD = [
    (variant(LINE, pinned={"nodes": [0]}, driven=[{"nodes": [-5], "velocity": [1, 0]}]), "driven.0.nodes[0]",
     "node 0 is already held by pinned.nodes[0]; a node is pinned or driven, not both"),
    (variant(LINE, driven=[{"nodes": [1], "velocity": [1, 0]}, {"nodes": [1], "velocity": [0, 1]}]),
     "driven.1.nodes[0]", "already held by driven.0.nodes[0]"),
    (variant(LINE, pinned={"nodes": [4, -1]}), "pinned.nodes[1]", "node 4 is listed twice (also pinned.nodes[0])"),
    (variant(LINE, pinned={"nodes": [0, 1, 2, 3, 4]}), "pinned", "every node is held"),
    (variant(LINE, overrides=[{"index": 4, "mass": 2}, {"index": -1, "drag": 2}]), "overrides.1.index",
     "node 4 is already overridden by overrides.0; give each node one entry"),
    (variant(LINE, overrides=[{"index": 1}]), "overrides.0", "sets neither mass nor drag"),
    (variant(LINE, initial={"shape": "square_loop", "top_center": [0, 0]}), "initial.shape",
     "'square_loop' needs a closed loop (rope.closed = true)"),
    (variant(LINE, rope__closed=True), "initial.shape", "'hanging' makes an open line"),
    (variant(LINE, rope__closed=True, initial={"shape": "line", "start": [0, 0], "end": [1, 0]}), "initial.shape",
     "'line' makes an open line"),
    (variant(LINE, rope__nodes=2, rope__closed=True, initial={"shape": "points", "points": [[0, 0], [1, 0]]}),
     "rope.nodes", "a closed loop needs at least 3 nodes, got 2"),
    (variant(LOOP, thrower=DELETE, guides=DELETE), "initial.top_center",
     "missing: needed when there is no [thrower]"),
    (variant(LOOP, thrower=DELETE, initial__top_center=[0, 0]), "guides.0.omega0",
     "missing: needed when there is no [thrower]"),
    (variant(LINE, initial={"shape": "points", "points": [[0, 0], [0, 1], [0, 2]]}), "initial.points",
     "has 3 points but rope.nodes is 5; give one per node"),
    (variant(LINE, initial={"shape": "points", "points": [[0, 0], [0, 1], [0, 1], [0, 3], [0, 4]]}),
     "initial.points", "nodes 1 and 2 coincide"),
    (variant(LINE, rope__closed=True, initial={"shape": "points", "points": [[0, 0], [1, 0], [1, 1], [0, 1],
                                                                             [0, 0]]}),
     "initial.points", "nodes 4 and 0 coincide"),
    (variant(LINE, initial={"shape": "points", "points": [[0, 0], [0, 1], [0, 2], [0, 3], [0, 4, 5]]}),
     "initial.points[4]", "list of 2 finite numbers"),
    (variant(LINE, initial={"shape": "line", "start": [1, 2], "end": [1, 2]}), "initial.end",
     "equals initial.start"),
    (variant(LOOP, rope__nodes=4, bending={"stiffness": 1.0}), "bending",
     "bending springs on a loop need at least 5 nodes"),
    (variant(LINE, rope__nodes=2, bending={"stiffness": 1.0}), "bending", "need at least 3 nodes on a line, got 2"),
    (variant(LOOP, thrower__v_max=0), "thrower.omega0", "default 4 pi |v_max| / length is 0 rad/s"),
    (variant(LINE, integrator__dt=1e-9, integrator__t_end=1e4), "integrator.t_end", "t_end / dt = 1e+13 steps"),
    (variant(LINE, name=""), "name", "must be a plain folder name"),
    (variant(LINE, name="../elsewhere"), "name", "without / or \\"),
    (variant(LINE, name=".."), "name", "not '.' or '..'"),
    (variant(LINE, name="a\u0000b"), "name", "printable"),
]


@pytest.mark.parametrize("raw,key,fragment", CROSS_FIELD)
def test_rules_across_keys(raw, key, fragment):
    refused(raw, key, fragment)


def test_invalid_toml_is_one_line():
    with pytest.raises(SceneError) as info:
        load("[rope]\nnodes = \n", source="bad.toml")
    assert "not valid TOML" in assert_one_line(info.value, "bad.toml")
    with pytest.raises(SceneError) as info:
        load('name = "a"\nname = "b"\n', source="dup.toml")
    assert "not valid TOML" in assert_one_line(info.value, "dup.toml")


def test_a_byte_order_mark_is_ignored(tmp_path):
    """Notepad and some Windows editors start a UTF-8 file with a byte-order mark: the scene, and a path CSV."""
    scene = tmp_path / "bom.toml"
    scene.write_bytes(b"\xef\xbb\xbf" + tomli_w.dumps(LINE).encode())
    assert load_scene(scene).rope.nodes == LINE["rope"]["nodes"]
    (tmp_path / "path.csv").write_bytes(b"\xef\xbb\xbf0,0,0\n1000,1,0\n")
    driven = {**LINE, "driven": [{"nodes": [0], "path": "path.csv"}]}
    scene.write_bytes(b"\xef\xbb\xbf" + tomli_w.dumps(driven).encode())
    assert load_scene(scene).driven[0].path_table[-1] == (1000.0, 1.0, 0.0)


def test_text_and_path_sizes_are_capped(tmp_path):
    """A 50 MB description took `check` minutes; a 1e300 path displacement passed (TOML numbers stop at 1e12)."""
    with pytest.raises(SceneError) as info:
        load({**LINE, "description": "x" * 50_000})
    assert "at most 1000 characters" in assert_one_line(info.value)
    with pytest.raises(SceneError) as info:
        load({**LINE, "name": "n" * 300})
    assert "at most 200 bytes" in assert_one_line(info.value)
    (tmp_path / "path.csv").write_text("0,0,0\n1,1e300,0\n")
    scene = tmp_path / "s.toml"
    scene.write_text(tomli_w.dumps({**LINE, "driven": [{"nodes": [0], "path": "path.csv"}]}))
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    assert "at most 1e+12 in magnitude" in assert_one_line(info.value, str(scene))
    with pytest.raises(SceneError) as info:
        load({**LINE, "driven": [{"nodes": [0], "path_table": [[0, 0, 0], [1, 1e300, 0]]}]})
    assert "at most 1e+12" in assert_one_line(info.value)


def test_file_problems(tmp_path):
    for path, fragment in [(tmp_path / "nope.toml", "no such scene file"), (tmp_path, "is a folder")]:
        with pytest.raises(SceneError) as info:
            load_scene(path)
        assert fragment in assert_one_line(info.value, str(path))
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00rope")
    with pytest.raises(SceneError) as info:
        load_scene(binary)
    assert "cannot be read" in assert_one_line(info.value, str(binary))
    good = tmp_path / "good_name.toml"
    good.write_text(tomli_w.dumps(LINE))
    assert load_scene(good).name == "good_name"  # the file's stem when the scene has no name


# ------------------------------------------------------------------------------------ --set overrides


@pytest.mark.parametrize("item,path,value", [
    ("integrator.dt=0.002", ["integrator", "dt"], 0.002),
    ("rope.nodes=61", ["rope", "nodes"], 61),
    ("rope.closed=true", ["rope", "closed"], True),
    ("initial.top=[1, -2.5]", ["initial", "top"], [1, -2.5]),
    ("integrator.method=verlet", ["integrator", "method"], "verlet"),
    ('name="two words"', ["name"], "two words"),
    ("description = a sentence, unquoted ", ["description"], "a sentence, unquoted"),
    ("gravity.g=1e1", ["gravity", "g"], 10.0),
    ("guides.1.one_sided=false", ["guides", "1", "one_sided"], False),
    ("integrator.dt=", ["integrator", "dt"], ""),
])
def test_parse_override_types_values_like_toml(item, path, value):
    parts, parsed = parse_override(item)
    assert parts == path and parsed == value and type(parsed) is type(value)


def test_set_reaches_into_arrays_of_tables_and_adds_entries():
    scene = load(LOOP, sets=["guides.1.one_sided=true", "guides.0.radius=0.25", "rope.nodes=12",
                             "overrides.0.index=-1", "overrides.0.mass=3", "overrides.1.index=0",
                             "overrides.1.drag=0.5", "gravity.g=9.8", "guides.0.center.1=0.5"])
    assert [g.one_sided for g in scene.guides] == [False, True]
    assert scene.guides[0].radius == 0.25 and scene.guides[0].center == (-1.0, 0.5)
    assert scene.rope.nodes == 12 and scene.gravity.g == 9.8
    assert scene.overrides == (S.NodeOverride(index=-1, mass=3.0), S.NodeOverride(index=0, drag=0.5))
    scene = load(LOOP, sets=["guides.2.center=[0, 5]", "guides.2.radius=1"])
    assert len(scene.guides) == 3 and scene.guides[2].center == (0.0, 5.0)


def test_apply_override_edits_the_raw_dict():
    raw = copy.deepcopy(LOOP)
    apply_override(raw, "guides.0.omega0=7")
    apply_override(raw, "driven.0.nodes=[0]")
    assert raw["guides"][0]["omega0"] == 7 and raw["driven"] == [{"nodes": [0]}]


SET_REFUSALS = [
    ("rope.nodes", "--set", "expected KEY=VALUE"),
    ("=5", "--set", "expected KEY=VALUE"),
    ("rope.mass.x=1", "rope.mass", "is a value, not a table"),
    ("guides.x.radius=1", "guides.x", "is a list; address its entries by number"),
    ("guides.5.radius=1", "guides.5", "has 2 entries; --set can change guides.0 to guides.1 or add guides.2"),
    ("overrides.5.mass=1", "overrides.5", "has no entries; --set can add overrides.0"),
    ("driven.3.nodes=[0]", "driven.3", "has no entries; --set can add driven.0"),
    ("guides.²=1", "guides.²", "is a list"),
    ("rope.nodes=1", "rope.nodes", "must be an integer >= 2"),
    ("rope.node=5", "rope.node", "did you mean 'nodes'?"),
    ("integrator.dt=fast", "integrator.dt", "must be a number > 0 [s], got 'fast'"),
    ("integrator.dt=", "integrator.dt", "got ''"),
    ("guides.0=5", "guides.0", "must be a table"),
    ("rope=5", "rope", "must be a table"),
    ("overrides.1.mass=2", "overrides.1", "has no entries; --set can add overrides.0"),
    ("overrides.0.mass=2", "overrides.0.index", "missing"),
]


@pytest.mark.parametrize("item,key,fragment", SET_REFUSALS)
def test_bad_set_is_one_line(item, key, fragment):
    with pytest.raises(SceneError) as info:
        load(LOOP, sets=[item])
    text = assert_one_line(info.value)
    assert info.value.key == key, text
    assert fragment in text, text
    assert text.startswith(SOURCE), text


# -------------------------------------------------------------------------------- resolved scene.toml


@pytest.mark.parametrize("path", SCENARIO_FILES + SYSTEM_FILES, ids=lambda p: p.stem)
def test_resolved_scene_loads_back_equal_and_is_a_fixed_point(path):
    scene = load_scene(path)
    text = S.scene_to_toml(scene)
    again = scene_from_toml(text, source="scene.toml", default_name="another_name")
    assert again == scene
    assert S.scene_to_toml(again) == text


@pytest.mark.parametrize("path", SCENARIO_FILES, ids=lambda p: p.stem)
def test_resolved_scene_shows_every_key_of_its_parts(path):
    """Every key that has a value in a declared part is written out, defaults included; only keys left unset
    on purpose stay out (a per-node override's other value, the physical form of a rope given per node)."""
    scene = load_scene(path)
    resolved = tomllib.loads(S.scene_to_toml(scene))
    assert set(S.TOP_LEVEL_SCALARS) - {"description"} <= set(resolved)
    for key, cls in {**S.TABLES, **S.ARRAYS_OF_TABLES}.items():
        if key not in resolved:
            continue
        parts = getattr(scene, key)
        parts = parts if isinstance(parts, tuple) else (parts,)
        tables = resolved[key] if isinstance(resolved[key], list) else [resolved[key]]
        for part, table in zip(parts, tables):
            expected = {f.name for f in fields(part) if getattr(part, f.name) is not None}
            assert set(table) == expected, key
    if scene.is_system:   # each line's length and segments, and its type's material, written out
        assert all({"id", "start", "end", "length", "segments"} <= set(line) for line in resolved["lines"])
    else:
        assert {"nodes", "segment_length", "stiffness", "mass", "closed", "compression"} <= set(resolved["rope"])


def test_round_trip_of_the_shapes_not_in_scenarios():
    for raw in (LINE, LOOP, variant(LINE, dimension=3, initial={"shape": "line", "start": [0, 0, 0],
                                                                 "end": [1, 1, 1]}),
                variant(LINE, initial={"shape": "points", "points": [[0, 0], [0, 1], [0, 2], [0, 3], [1e-9, 4]]},
                        overrides=[{"index": -1, "mass": 2.0}], pinned={"nodes": 0})):
        scene = load(raw)
        assert load(S.scene_to_toml(scene)) == scene


# ------------------------------------------------------------------------------ property-based tests

VALID_RAWS = [tomllib.loads(p.read_text()) for p in SCENARIO_FILES] + [LINE, LOOP, TOWED_3D, SHOOTER_3D]


def test_the_fuzz_tests_start_from_valid_scenes():
    for raw in VALID_RAWS:
        assert load(raw) is not None
KEY_WORDS = sorted({*S.TOP_LEVEL_SCALARS, *S.TABLES, *S.ARRAYS_OF_TABLES, *S.NAMED_TABLES, "shape",
                    *(f.name for cls in [*S.TABLES.values(), *S.ARRAYS_OF_TABLES.values(), *S.INITIAL_SHAPES.values(),
                                         *S.NAMED_TABLES.values(), *S.SYSTEM_VARIANTS.values()]
                      if cls is not None for f in fields(cls))})
EDGE_NUMBERS = [0, -1, 1, 2, 3, 4, 2 ** 63 - 1, -(2 ** 63), 10 ** 30, 10 ** 400, -(10 ** 400), 1_000_001,
                0.0, -0.0, 1e-300, 5e-324, 1e300, 1e308, -1e308, math.nan, math.inf, -math.inf, 1e-9, 0.5, -2.5]

numbers = st.one_of(st.sampled_from(EDGE_NUMBERS), st.integers(-10, 100), st.floats())
scalars = st.one_of(numbers, st.booleans(), st.text(max_size=8), st.sampled_from(list(S.INITIAL_SHAPES)))
keys = st.one_of(st.sampled_from(KEY_WORDS), st.text(min_size=1, max_size=8),
                 st.sampled_from(["0", "1", "2", "-1", "01", "\u00b2", "\uff11", "", " "]))
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(keys, inner, max_size=3)),
    max_leaves=8,
)


def _slots(obj, path=()):
    """Every (container, key or index) inside a raw scene, depth first."""
    items = obj.items() if isinstance(obj, dict) else enumerate(obj)
    for k, v in items:
        yield obj, k
        if isinstance(v, (dict, list)):
            yield from _slots(v, path + (k,))


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _numbers_changed(draw, change, raws=VALID_RAWS):
    """A valid scene (one of ``raws``) with one to three of its numbers replaced by ``change(draw, old value)``."""
    raw = copy.deepcopy(draw(st.sampled_from(raws)))
    numeric = [(box, k) for box, k in _slots(raw) if _is_number(box[k])]
    for _ in range(draw(st.integers(1, 3))):
        box, k = draw(st.sampled_from(numeric))
        box[k] = change(draw, box[k])
    return raw


@st.composite
def perturbed_scenes(draw, raws=VALID_RAWS):
    """A valid scene with one to three of its numbers replaced by edge values (zero, negative, huge, nan...)."""
    return _numbers_changed(draw, lambda draw, old: draw(numbers), raws)


SCALES = [-1.0, 0.0, 1e-12, 1e-9, 1e-3, 0.1, 10.0, 1e3, 1e9, 1e12]


@st.composite
def rescaled_scenes(draw):
    """A valid scene with one to three of its numbers scaled by 0, -1 or 10^-12 ... 10^12 (counts: -3 to 60),
    run by any of the integrators."""
    raw = _numbers_changed(draw, lambda draw, old: draw(st.integers(-3, 60)) if isinstance(old, int)
                           else old * draw(st.sampled_from(SCALES)))
    raw.setdefault("integrator", {})["method"] = draw(st.sampled_from(sorted(METHODS)))
    return raw


@st.composite
def mutated_scenes(draw, raws=VALID_RAWS):
    """A valid scene (one of ``raws``) with one to four random edits: delete, retype, renumber, add unknown keys,
    nest."""
    raw = copy.deepcopy(draw(st.sampled_from(raws)))
    for _ in range(draw(st.integers(1, 4))):
        slots = list(_slots(raw))
        action = draw(st.sampled_from(["delete", "replace", "number", "number", "add", "nest"]))
        box, k = draw(st.sampled_from(slots)) if slots else (raw, None)
        if action == "add" or k is None:
            target = box[k] if k is not None and isinstance(box[k], (dict, list)) else box
            if isinstance(target, dict):
                target[draw(keys)] = draw(values)
            else:
                target.append(draw(values))
        elif action == "delete":
            del box[k]
        elif action == "replace":
            box[k] = draw(values)
        elif action == "number":
            box[k] = draw(numbers)
        else:  # wrap the value in a list or a table
            box[k] = draw(st.sampled_from([lambda v: [v], lambda v: {"x": v}, lambda v: {str(k): v}]))(box[k])
    return raw


def loaded_or_one_line(text: str, sets=()) -> S.Scene | None:
    """The scene ``text`` holds, or None when it is refused, in one line."""
    try:
        return scene_from_toml(text, source="fuzz.toml", default_name="fuzz", overrides=sets)
    except SceneError as exc:
        assert_one_line(exc, "fuzz.toml")
        return None


def _accepted_or_one_line(text: str, sets=(), solve: bool = True):
    """The scene ``text`` holds, set up (laid out, its time step checked, its integrator made) without a warning,
    or None when it is refused in one line. With ``solve``, a static start is solved first (which compiles the
    static solver for the scene's terms, as many as there are term sets among the examples): it converges or
    says in one line that it did not."""
    scene = loaded_or_one_line(text, sets)
    if scene is None:
        return None
    with warnings.catch_warnings():   # an accepted scene sets up without overflow or invalid-value warnings
        warnings.simplefilter("error")
        try:
            model = build(scene, solve=solve)
        except EquilibriumError as exc:   # a static start may have no static shape (a 252 000 km chain floats
            assert isinstance(scene.initial, (S.EquilibriumStart, S.SystemEquilibriumStart))   # off, or a driven
            # spar is moved 1000 km from its anchors): one named line too, exit 1 in the CLI
            assert "\n" not in str(exc) and "did not converge" in str(exc)
            return None
        assert model.x0.shape == (scene.dimension, model.nodes)
        grid = TimeGrid.of(scene)
        time_step_verdict(model, scene.integrator.method, scene.integrator.dt)
        make_integrator(model, grid, scene.integrator.method)
    assert scene_from_toml(S.scene_to_toml(scene), source="again.toml") == scene
    return scene


# The same examples at every run (derandomize): a failure is reproduced by running the test again, and the
# kernels the examples compile are the same ones, loaded from the cache by a second run on unchanged sources.
FUZZ = settings(max_examples=150, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
# The quick suite sets up each accepted scene with its static start's first guess; the slow suite solves it
# too (the static solver compiled for each example's term set: 40 s of CPU for these examples).
SOLVE = pytest.mark.parametrize("solve", [False, pytest.param(True, marks=pytest.mark.slow)],
                                ids=["set_up", "solved"])


@SOLVE
@FUZZ
@given(raw=mutated_scenes())
def test_mutated_scenes_are_accepted_or_refused_in_one_line(raw, solve):
    _accepted_or_one_line(tomli_w.dumps(raw), solve=solve)


@SOLVE
@FUZZ
@given(raw=perturbed_scenes())
def test_scenes_with_edge_numbers_are_accepted_or_refused_in_one_line(raw, solve):
    _accepted_or_one_line(tomli_w.dumps(raw), solve=solve)


@SOLVE
@FUZZ
@given(raw=st.sampled_from(VALID_RAWS), items=st.lists(st.tuples(st.lists(keys, min_size=1, max_size=4), values),
                                                       min_size=1, max_size=3))
def test_random_set_overrides_are_accepted_or_refused_in_one_line(raw, items, solve):
    _accepted_or_one_line(tomli_w.dumps(raw), set_items(items), solve=solve)


def set_items(items) -> list[str]:
    """``--set`` strings from (key path, value) pairs: KEY=VALUE, the value written as TOML (a table as {})."""
    sets = []
    for path, value in items:
        text = tomli_w.dumps({"v": value}).partition("=")[2].strip() if not isinstance(value, dict) else "{}"
        sets.append(".".join(path) + "=" + text)
    return sets


@pytest.mark.slow
@FUZZ
@given(rescaled_scenes())
def test_rescaled_scenes_are_refused_in_one_line_or_run_cleanly(raw):
    """Accepted, a scene runs 30 steps to 'completed' (every saved value finite) or 'blew_up' (named), with no
    warning or exception on the way: setup, kernel, blow-up check, analyses."""
    scene = _accepted_or_one_line(tomli_w.dumps(raw))
    if scene is None:
        return
    dt = scene.integrator.dt
    scene = replace(scene, integrator=replace(scene.integrator, t_end=30 * dt), output=replace(scene.output,
                                                                                               interval=10 * dt))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        traj = simulate(scene)
    status = traj.summary["status"]
    assert status in (COMPLETED, BLEW_UP), status
    if status == COMPLETED:
        assert np.all(np.isfinite(traj.x)) and np.all(np.isfinite(traj.v))
    else:
        assert traj.summary["message"]


@FUZZ
@given(st.lists(st.text(max_size=6), max_size=3))
def test_random_set_strings_never_crash(sets):
    _accepted_or_one_line(tomli_w.dumps(LINE), sets)


toml_lines = st.one_of(
    st.builds(lambda k: f"[{k}]", st.sampled_from(KEY_WORDS)),
    st.builds(lambda k: f"[[{k}]]", st.sampled_from(KEY_WORDS)),
    st.builds(lambda k, v: f"{k} = {v}", st.sampled_from(KEY_WORDS),
              st.sampled_from(["1", "-3", "0.5", "nan", "inf", "1e400", "true", '"hanging"', '"square_loop"',
                               "[0, 0]", "[1, 2, 3]", "[[0, 0], [1, 0]]", "{}", "{ a = 1 }", "'x'", "[]", "1979-05-27",
                               "99999999999999999999999999"])),
    st.text(max_size=20),
)


@FUZZ
@given(st.lists(toml_lines, max_size=12))
def test_random_toml_ish_text_never_crashes(lines):
    _accepted_or_one_line("\n".join(lines))


def test_a_scene_error_survives_pickling():
    """A sweep's worker process raises it in another process: the message must arrive whole."""
    import pickle

    error = SceneError("a.toml", "rope.mass", "must be a number > 0, got -1")
    again = pickle.loads(pickle.dumps(error))
    assert isinstance(again, SceneError) and str(again) == str(error) == "a.toml: rope.mass: must be a number > 0, got -1"
    assert (again.source, again.key, again.message) == (error.source, error.key, error.message)


@pytest.mark.parametrize("rope, key, fragment", [
    ({"length": 2e-12, "segments": 40, "mass_per_length": 0.13, "EA": 1e-3}, "rope.length",
     "gives segment_length = length / segments = 5e-14 [m], outside 1e-12"),
    ({"length": 2e-8, "segments": 40, "mass_per_length": 0.13, "EA": 5e6}, "rope.EA",
     "gives stiffness = EA / l = 1e+16 [N/m]"),
    ({"length": 20.0, "segments": 40, "mass_per_length": 0.13, "EA": 1e12}, "rope.EA",
     "gives stiffness = EA / l = 2e+12 [N/m], outside 1e-12 to 1e+12"),
    ({"length": 20.0, "segments": 40, "mass_per_length": 1e-12, "EA": 5e6}, "rope.mass_per_length",
     "gives mass = mass_per_length x l = 5e-13 [kg]"),
])
def test_a_physical_rope_whose_per_node_values_would_overflow_is_refused(rope, key, fragment):
    """The per-node values derived from the physical form obey the per-node keys' limits, so a resolved scene
    always loads again."""
    refused(variant(LINE, rope=rope), key, fragment)


CHAIN_ON_A_SEABED = """
dimension = 2
[rope]
length = 120.0
segments = 24
mass_per_length = 50.0
diameter = 0.1
EA = 1e8
[initial]
shape = "equilibrium"
start = [0.0, -30.0]
end = [100.0, 0.0]
[pinned]
nodes = [0, -1]
[gravity]
[seabed]
height = -30.0
[integrator]
dt = 0.001
t_end = 0.01
"""


def test_an_equilibrium_start_keeps_its_ends_where_the_scene_puts_them():
    """The static solver's first guess, a sagging curve, is lifted onto the seabed where it would pass through
    it, but its ends are held nodes and stay where the scene puts them; so the loader's check that no held node
    starts below the seabed sees a buried anchor where it really is. (The guess used to lift a buried anchor
    onto the seabed: the scene loaded with its anchor silently moved.)"""
    from ropesim.scene.shapes import initial_positions

    scene = scene_from_toml(CHAIN_ON_A_SEABED)
    x = initial_positions(scene)
    assert tuple(x[:, 0]) == (0.0, -30.0) and tuple(x[:, -1]) == (100.0, 0.0)
    assert np.all(x[1] >= -30.0) and np.any(x[1, 1:-1] == -30.0)   # the sag lies on the seabed
    model = build(scene)
    assert tuple(model.x0[:, 0]) == (0.0, -30.0) and tuple(model.x0[:, -1]) == (100.0, 0.0)
    buried = CHAIN_ON_A_SEABED.replace("start = [0.0, -30.0]", "start = [0.0, -30.5]")
    with pytest.raises(SceneError, match=r"seabed.height: puts the seabed 0.5 m above held node 0 \(at y = -30.5 m\)"):
        scene_from_toml(buried)
