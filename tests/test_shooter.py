"""The string shooter: the write-up's qualitative results on the built-in scenes."""

import numpy as np
import pytest

import ropesim
from ropesim.analysis.shooter import circulation_speed, loop_inclination, nodes_in_thrower
from ropesim.model.build import build

SCENES = ["shooter_vacuum", "shooter_low", "shooter_medium", "shooter_high"]


@pytest.fixture(scope="module")
def runs():
    out = {}
    for name in SCENES + ["shooter_low_one_sided"]:
        scene = ropesim.load_scene(f"scenarios/{name}.toml")
        out[name] = (build(scene), ropesim.simulate(scene))
    return out


@pytest.mark.parametrize("name", SCENES + ["shooter_low_one_sided"])
def test_loop_stays_in_the_shooter_and_circulates(runs, name):
    """The thrower keeps driving the loop for the whole run: string stays in the box, moving near v_max."""
    model, traj = runs[name]
    in_box = traj.summary["shooter"]["nodes_in_thrower"]
    assert in_box == nodes_in_thrower(model, traj.x[-1])
    assert in_box >= 3  # the box is 8 m long and l = 1 m: string still fed through it, not fallen out
    speed = circulation_speed(traj.x[-1], traj.v[-1])
    # round the loop in the drive's direction; well above half the drive speed, below it (drag and weight)
    assert 0.5 * 5.0 < speed < 5.0
    # a 30 m hanging strand stretches its top spring by ~6 %; the drop from the initial square adds a few times
    # that. Beyond 50 % the wheels or the guides would be tearing the string apart.
    assert traj.summary["max_spring_stretch"] < 0.5


def test_higher_air_resistance_higher_inclination(runs):
    """The write-up's claim: the loop leans further forward the stronger the drag (vacuum: it hangs back)."""
    means = [runs[name][1].summary["shooter"]["mean_loop_inclination_deg"] for name in SCENES]
    assert means == sorted(means), means
    assert means[0] < -20.0 < means[1]  # the vacuum loop hangs well behind; any air brings it forward
    assert means[-1] > 0.0


def test_inclination_summary_is_the_centroid_angle(runs):
    model, traj = runs["shooter_medium"]
    centroid = traj.x[-1].mean(axis=0) - np.array([0.0, 0.0])
    expected = np.degrees(np.arctan2(centroid[0], -centroid[1]))
    assert loop_inclination(model, traj.x[-1]) == pytest.approx(expected)
    assert traj.summary["shooter"]["loop_inclination_deg"] == pytest.approx(expected, abs=1e-3)


def test_one_sided_circles_let_go_of_outgoing_string(runs):
    """The write-up's remedy: with a one-sided exit circle the thrown string no longer wraps round it.

    Measured as string near the exit circle (within 0.5 m of its rim, outside the box), summed over frames.
    """
    def near_exit_circle(model, traj):
        guide = model.scene.guides[1]
        r = np.linalg.norm(traj.x - np.array(guide.center), axis=-1)
        return int(np.sum((r < guide.radius + 0.5) & (traj.x[..., 0] > 4.0)))

    held = near_exit_circle(*runs["shooter_low"])
    released = near_exit_circle(*runs["shooter_low_one_sided"])
    assert released < 0.35 * held, (released, held)  # measured 244 against 2372
