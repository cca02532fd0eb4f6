"""The seabed's contact damping: ropesim's own law (into the plane only, grown in over 1e-3 footprint widths of
depth) and MoorDyn's (``seabed.damping_both_ways``: -c (v . n) A both ways, at full strength from first contact),
on one node sunk in the plane, and the key's round trip through the loader; and galpha's forms of both (without
a jump or a kink for its Newton solve), with their Newton blocks against finite differences."""

import numpy as np
import pytest
import tomli_w

import ropesim
from ropesim.model.build import build
from ropesim.model.forces.seabed import add_seabed_friction, add_seabed_jacobian

K, C, WIDTH = 1.0e5, 1.0e4, 0.2


def sunk_rope(both_ways: bool, sink: float, method: str = "rk4"):
    """A 3-node, 2 m rope lying level with its nodes ``sink`` below a level seabed at y = 0."""
    scene = ropesim.scene_from_toml(tomli_w.dumps({
        "name": "sunk", "dimension": 2,
        "rope": {"length": 2.0, "segments": 2, "mass_per_length": 10.0, "diameter": WIDTH, "EA": 1e6},
        "initial": {"shape": "points", "points": [[0.0, -sink], [1.0, -sink], [2.0, -sink]]},
        "integrator": {"method": method, "dt": 1e-4, "t_end": 1e-3},
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


V_REG = 0.01   # the seabed's friction_speed default [m/s]: galpha smooths the one-way switch over it


def test_galpha_smooths_the_one_way_switch_at_rest_and_keeps_the_law_elsewhere():
    """galpha's one-way law: exact for |v . n| >= v_reg and lifting off, and between, min(v . n, 0) replaced by
    -v_reg (2 u^2 - u^3), u = -v_n / v_reg: continuous with a continuous slope (0 at rest, 1 at -v_reg), never
    pulling a node in (the damping's power stays a loss). Without it Newton flipped resting nodes between damped
    and free and failed at the thrown spar's second 0.1 s step (scripts/bench_galpha_bodies.py)."""
    _, model = sunk_rope(False, 1e-3, "galpha")
    area = WIDTH * 1.0
    assert damping_force(model, 0.1) == 0.0
    assert damping_force(model, 1e-4) == 0.0
    for vn in (-0.1, -V_REG):
        assert damping_force(model, vn) == pytest.approx(-C * area * vn, rel=1e-12)
    assert damping_force(model, -0.5 * V_REG) == pytest.approx(C * area * V_REG * 0.375, rel=1e-12)
    speeds = np.linspace(-2 * V_REG, V_REG, 601)
    force = np.array([damping_force(model, vn) for vn in speeds])
    slope = -np.gradient(force, speeds) / (C * area)
    assert np.all(np.diff(force) <= 1e-12) and np.all(force >= 0.0)   # monotone, pushing out only
    assert np.abs(np.diff(slope)).max() < 0.03   # no kink: the slope moves by at most 4/3 / 50 a sample
    assert slope[speeds < -V_REG * 1.01].min() == pytest.approx(1.0)


@pytest.mark.parametrize("both_ways", [False, True])
@pytest.mark.parametrize("sink", [1e-3, 2e-5])   # past, and within, the growth depth 2e-4 m
@pytest.mark.parametrize("vn", [-0.05, -0.004, 0.003])
def test_galphas_newton_block_is_the_forces_derivative(both_ways, sink, vn):
    """The seabed's normal entry of galpha's Newton matrix, -(s^2 dF/dy + s dF/dv) with s the assembly's weight,
    is the finite-difference derivative of the normal force (depth and speed), for both laws in galpha's forms
    (but for the two-way growth's negative stiffness, which the matrix leaves out)."""
    _, model = sunk_rope(both_ways, sink, "galpha")
    s, dim = 0.05, 2

    def force(dy, dv):
        x = model.x0.copy()
        x[1, 1] += dy
        v = np.zeros_like(x)
        v[1, 1] = vn + dv
        acc = np.zeros_like(x)
        add_seabed_friction(x, v, acc, 1.0 / model.mass, model.params.seabed, model.params.neighbours)
        return acc[1, 1] * model.mass[1]

    hy, hv = 1e-9, 1e-7
    dfdy = (force(hy, 0.0) - force(-hy, 0.0)) / (2 * hy)
    dfdv = (force(0.0, hv) - force(0.0, -hv)) / (2 * hv)
    band = np.zeros((2 * dim, dim * 3))
    v = np.zeros_like(model.x0)
    v[1, 1] = vn
    add_seabed_jacobian(model.x0, v, band, s, np.ones(3, dtype=np.bool_), model.params.seabed, False)
    spring = s * s * K * WIDTH * 1.0   # the contact spring's part, k A
    expected = -(s * s * dfdy + s * dfdv)
    if both_ways and vn > 0.0 and sink < 1e-3 * WIDTH:   # lifting off inside the growth depth: the growth's
        expected = -s * dfdv   # stiffness is negative there, and is left out of the matrix (kept positive)
    assert band[0, 1 * dim + 1] - spring == pytest.approx(expected, rel=1e-5, abs=1e-6 * spring)
