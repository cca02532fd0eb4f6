"""Axial damping as a damping ratio (MoorDyn's negative BA): the coefficient MoorDyn computes, and the damping a
segment then has."""

import math

import numpy as np
import pytest

import ropesim
from ropesim.scene.loader import SceneError, scene_from_toml
from ropesim.scene.schema import scene_to_toml

OC3 = {"d": 0.09, "w": 77.7066, "EA": 384.243e6, "BA": -0.8, "length": 902.2, "segments": 20}  # MoorDyn's lines.txt

SYSTEM = """
dimension = 3
[integrator]
dt = 1e-3
t_end = 0.01
[gravity]
[line_types.main]
diameter = 0.09
mass_per_length = 77.7066
EA = 384.243e6
{type_key}
[[points]]
id = "anchor"
position = [0.0, 0.0, 0.0]
[[points]]
id = "fairlead"
position = [850.0, 250.0, 0.0]
[[lines]]
id = "one"
type = "main"
start = "anchor"
end = "fairlead"
length = 902.2
segments = {segments}
{line_key}
"""


def moordyn_ba(BAin, d, w, EA, UnstrLen, N):
    """Line.cpp (Line::setup), as written there: A = pi/4 d^2, rho = w / A, BA = -BAin UnstrLen / N sqrt(EA rho A)."""
    A = math.pi / 4.0 * d * d
    rho = w / A
    return -BAin * UnstrLen / N * math.sqrt(EA * rho * A)


def test_a_line_types_ratio_gives_moordyns_coefficient_for_each_lines_segment():
    for segments in (20, 7):
        scene = scene_from_toml(SYSTEM.format(type_key="axial_damping_ratio = 0.8", segments=segments, line_key=""))
        expected = moordyn_ba(OC3["BA"], OC3["d"], OC3["w"], OC3["EA"], OC3["length"], segments)
        assert scene.lines[0].axial_damping == pytest.approx(expected, rel=1e-14)
    # MoorDyn 2 (pip) logs "Line 1 damping set to 9.80212e+08 Pa-s = 6.23584e+06 Ns, based on input of -0.8" for
    # its tests/Mooring/lines.txt (20 segments): the same 6 digits
    oc3 = scene_from_toml(SYSTEM.format(type_key="axial_damping_ratio = 0.8", segments=20, line_key=""))
    assert f"{oc3.lines[0].axial_damping:.6g}" == "6.23584e+06"


def test_the_resolved_scene_keeps_the_ratio_and_loads_back_to_itself():
    scene = scene_from_toml(SYSTEM.format(type_key="axial_damping_ratio = 0.8", segments=20, line_key=""))
    again = scene_from_toml(scene_to_toml(scene))
    assert again.lines[0] == scene.lines[0] and again.lines[0].axial_damping_ratio == 0.8


def test_a_lines_own_key_wins_over_its_types():
    own = scene_from_toml(SYSTEM.format(type_key="axial_damping_ratio = 0.8", segments=20,
                                        line_key="axial_damping = 1000.0"))
    assert own.lines[0].axial_damping == 1000.0 and own.lines[0].axial_damping_ratio is None
    ratio = scene_from_toml(SYSTEM.format(type_key="axial_damping = 1000.0", segments=20,
                                          line_key="axial_damping_ratio = 0.5"))
    assert ratio.lines[0].axial_damping == pytest.approx(0.5 / 0.8 * 6.235836932772354e6, rel=1e-12)


def test_a_coefficient_and_a_ratio_that_disagree_are_refused_in_one_line():
    with pytest.raises(SceneError) as exc:
        scene_from_toml(SYSTEM.format(type_key="axial_damping_ratio = 0.8\naxial_damping = 1.0", segments=20,
                                      line_key=""), source="t.toml")
    assert str(exc.value).startswith("t.toml: line_types.main.axial_damping: 1 N s contradicts axial_damping_ratio")
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("zeta", [0.05, 0.2])
def test_one_free_segment_rings_down_at_the_ratio_of_critical(zeta):
    """Two free nodes of mass m on one spring k: the stretch s obeys (m/2) s'' + c s' + k s = 0, c = BA / l, so
    its damping ratio is c / (2 sqrt(k m / 2)); with BA = zeta l sqrt(EA m') (m = m' l / 2 at each end, EA = k l)
    that is zeta. The stretch's log decrement over one damped period is 2 pi zeta / sqrt(1 - zeta^2)."""
    k, m, l0 = 1.0e4, 0.5, 1.0
    scene = scene_from_toml(f"""
dimension = 2
[rope]
length = {l0}
segments = 1
mass_per_length = {2 * m / l0}
EA = {k * l0}
compression = true
axial_damping_ratio = {zeta}
[initial]
shape = "points"
points = [[0.0, 0.0], [{l0 * 1.01}, 0.0]]
[integrator]
method = "rk4"
dt = 1e-5
t_end = 0.2
[output]
interval = 1e-5
""")
    traj = ropesim.simulate(scene)
    stretch = np.linalg.norm(traj.x[:, 1] - traj.x[:, 0], axis=1) - l0
    peaks = [i for i in range(1, len(stretch) - 1) if stretch[i - 1] < stretch[i] >= stretch[i + 1] and stretch[i] > 0]
    assert len(peaks) >= 2
    decrement = math.log(stretch[peaks[0]] / stretch[peaks[1]])
    assert decrement == pytest.approx(2 * math.pi * zeta / math.sqrt(1 - zeta ** 2), rel=2e-3)
