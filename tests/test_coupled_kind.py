"""A coupled point or body (moved by a program ropesim is coupled to) in a run of the scene alone: held where the
scene puts it, exactly as a fixed one."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

import ropesim
from ropesim.scene.loader import SceneError, scene_from_dict

OC3 = tomllib.loads((Path(__file__).parent / "data" / "systems" / "oc3_hywind.toml").read_text())


def spread(body_kind: str, anchor_kind: str) -> dict:
    raw = {**OC3, "integrator": {"method": "rk4", "dt": 0.002, "t_end": 0.2}, "output": {"interval": 0.02},
           "initial": {"shape": "lines"}}
    raw["bodies"] = [{"id": "spar", "kind": body_kind, "position": [0.0, 0.0, 0.0]}]
    raw["points"] = [dict(p) for p in OC3["points"]]
    raw["points"][0]["kind"] = anchor_kind
    return raw


def test_coupled_points_and_bodies_stay_as_fixed_ones_do():
    fixed = ropesim.simulate(scene_from_dict(spread("fixed", "fixed")))
    coupled = ropesim.simulate(scene_from_dict(spread("coupled", "coupled")))
    assert np.array_equal(fixed.x, coupled.x) and np.array_equal(fixed.v, coupled.v)


def test_a_coupled_point_takes_no_free_points_keys():
    raw = spread("coupled", "coupled")
    raw["points"][0]["mass"] = 10.0
    with pytest.raises(SceneError, match=r"^t.toml: points.0.mass: only a free point carries a mass; this point is "
                                         r"'coupled': the program it is coupled to moves it"):
        scene_from_dict(raw, source="t.toml")
