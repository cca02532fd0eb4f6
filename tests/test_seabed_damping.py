"""The seabed's contact damping: ropesim's own law (into the plane only, grown in over 1e-3 footprint widths of
depth) and MoorDyn's (``seabed.damping_both_ways``: -c (v . n) A both ways, at full strength from first contact),
on one node sunk in the plane, and the key's round trip through the loader."""

import numpy as np
import pytest
import tomli_w

import ropesim
from ropesim.model.build import build
from ropesim.model.forces.seabed import add_seabed_friction

K, C, WIDTH = 1.0e5, 1.0e4, 0.2


def sunk_rope(both_ways: bool, sink: float):
    """A 3-node, 2 m rope lying level with its nodes ``sink`` below a level seabed at y = 0."""
    scene = ropesim.scene_from_toml(tomli_w.dumps({
        "name": "sunk", "dimension": 2,
        "rope": {"length": 2.0, "segments": 2, "mass_per_length": 10.0, "diameter": WIDTH, "EA": 1e6},
        "initial": {"shape": "points", "points": [[0.0, -sink], [1.0, -sink], [2.0, -sink]]},
        "integrator": {"method": "rk4", "dt": 1e-4, "t_end": 1e-3},
        "seabed": {"height": 0.0, "stiffness": K, "damping": C, "damping_both_ways": both_ways},
    }))
    return scene, build(scene)


def damping_force(model, vn: float) -> float:
    """The normal force (N) on the middle node moving at vn along the plane's normal (out of it for vn > 0)."""
    x = model.x0.copy()
    v = np.zeros_like(x)
    v[1, 1] = vn
    acc = np.zeros_like(x)
    add_seabed_friction(x, v, acc, 1.0 / model.mass, model.params.seabed, model.params.neighbours)
    return acc[1, 1] * model.mass[1]


@pytest.mark.parametrize("sink", [1e-3, 1e-5])   # well past, and within, the growth depth 1e-3 x 0.2 m
def test_moordyns_law_damps_both_ways_at_full_strength(sink):
    _, model = sunk_rope(True, sink)
    area = WIDTH * 1.0
    for vn in (0.1, -0.1):
        assert damping_force(model, vn) == pytest.approx(-C * area * vn, rel=1e-12)


def test_ropesims_law_holds_no_node_back_and_grows_in_with_depth():
    _, deep = sunk_rope(False, 1e-3)
    _, shallow = sunk_rope(False, 1e-5)
    area = WIDTH * 1.0
    assert damping_force(deep, 0.1) == 0.0                                    # lifting off: free
    assert damping_force(deep, -0.1) == pytest.approx(C * area * 0.1, rel=1e-12)
    assert damping_force(shallow, -0.1) == pytest.approx(C * area * 0.1 * 1e-5 / (1e-3 * WIDTH), rel=1e-12)


def test_the_key_defaults_off_and_shows_in_the_resolved_scene():
    off, _ = sunk_rope(False, 1e-3)
    on, _ = sunk_rope(True, 1e-3)
    assert off.seabed.damping_both_ways is False and on.seabed.damping_both_ways is True
    assert "damping_both_ways = true" in ropesim.scene_to_toml(on)
