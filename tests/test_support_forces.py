"""A support's force includes the drag on its own held node, relative to the flow, whatever drag law gives it.

A held node in a flow feels the linear [drag] -b (v - U) like any other: its support takes it. The support
force once used -b v (0 for a pin in a 1 m/s flow, where -b U is right), while [viscous_drag] and
[fluid_drag] were right. Checked against the isotropic [viscous_drag] that is the same law (b_n = b_t = b / L),
over a run (the flow ramped in) and in the static solve.
"""

from __future__ import annotations

import numpy as np
import pytest
import tomli_w

import ropesim
from ropesim.analysis.statics import equilibrium
from ropesim.model.ramp import ramp


def pinned_line(law: str, current=(1.0, 0.0), ramp_time: float = 0.0) -> ropesim.Scene:
    """Four nodes 1 m apart, the first three pinned, in a flow: node 1's springs stay at their rest length, so
    its support holds it against the drag alone (node 0's too for the linear drag; node 3 swings free)."""
    scene = {"name": "pinned_in_a_flow", "dimension": len(current),
             "rope": {"nodes": 4, "segment_length": 1.0, "stiffness": 100.0, "mass": 2.0},
             "initial": {"shape": "line", "start": [0.0] * len(current), "end": [0.0, -3.0, *[0.0] * (len(current) - 2)]},
             "pinned": {"nodes": [0, 1, 2]}, "flow": {"velocity": list(current), "ramp_time": ramp_time},
             "integrator": {"dt": 0.01, "t_end": 1.0}, "output": {"interval": 0.25}}
    if law == "drag":
        scene["drag"] = {"b": 3.0}
    else:   # the same law: b = b_n L on the middle node (L = 1 m), b_n L / 2 on the ends
        scene["viscous_drag"] = {"b_normal": 3.0, "b_tangential": 3.0}
        scene["fluid"] = {"density": 1.0}
    return ropesim.scene_from_toml(tomli_w.dumps(scene))


@pytest.mark.slow
@pytest.mark.parametrize("current", [(1.0, 0.0), (0.6, -0.3, 0.8)])
def test_a_pinned_node_in_a_flow_is_held_against_b_times_the_flow(current):
    traj = ropesim.simulate(pinned_line("drag", current, ramp_time=0.5))
    U = np.asarray(current)
    for k, t in enumerate(traj.t):
        expected = -3.0 * ramp(float(t), 0.5) * U        # each node: -b U, the flow ramped in
        assert np.allclose(traj.support[k, :2], expected[None, :], rtol=1e-12, atol=1e-12), (t, traj.support[k])
    assert np.allclose(equilibrium(pinned_line("drag", current)).supports[:2], -3.0 * U[None, :], rtol=1e-12)


@pytest.mark.slow
def test_the_linear_drag_and_the_same_viscous_drag_give_the_same_support():
    linear, viscous = (ropesim.simulate(pinned_line(law)) for law in ("drag", "viscous"))
    middle = 1   # the viscous law acts on each node's length: the middle node's is the whole metre
    assert np.allclose(linear.support[:, middle], viscous.support[:, middle], rtol=1e-12)
    assert np.allclose(linear.support[-1, middle], [-3.0, 0.0])
