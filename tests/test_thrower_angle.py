"""The thrower's launch angle (``thrower.angle``): the box and its drive turned in the x-y plane.

Checked on the kernels themselves, in a frame test: with gravity off, a node in the turned box feels the turned
force of the same node in the unturned box (positions and velocities turned about the box's centre, sharp and
smooth edges, 2-D and 3-D); with gravity on, the weight is still cancelled along y. The stiff integrator's
Jacobian block and the exact contact kick are checked against the kernel (finite differences, a matrix
exponential). Unturned scenes keep their numbers bit for bit: tests/test_bit_identity.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from ropesim.model.build import build
from ropesim.model.forces.thrower import add_thrower, add_thrower_jacobian, box_weight
from ropesim.scene.loader import SceneError, scene_from_dict

CENTRE = (0.3, -0.2)


def thrower_model(angle=0.0, dim=2, edge_width=0.0, g=0.0, guides=False):
    z = [0.0] * (dim - 2)
    raw = {
        "dimension": dim,
        "rope": {"nodes": 4, "segment_length": 0.1, "stiffness": 100.0, "mass": 0.02, "closed": True},
        "initial": {"shape": "points", "points": [[0.0, 0.0] + z, [0.1, 0.0] + z, [0.1, -0.1] + z,
                                                  [0.0, -0.1] + z]},
        "thrower": {"center": [*CENTRE] + z, "length": 0.4, "width": 0.1, "v_max": 6.0, "b_thrower": 0.5,
                    "omega0": 40.0, "damping_ratio": 0.7, "edge_width": edge_width, "angle": angle},
        "integrator": {"dt": 1e-4, "t_end": 0.01},
    }
    if g:
        raw["gravity"] = {"g": g}
    if guides:
        raw["guides"] = [{"center": [0.5, -0.15], "radius": 0.1, "edge_width": edge_width}]
    return build(scene_from_dict(raw))


def rotation(angle: float, dim: int) -> np.ndarray:
    a = math.radians(angle)
    r = np.eye(dim)
    r[:2, :2] = [[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]
    return r


def kernel_acc(model, x, v, g=0.0):
    """The thrower's acceleration (D, N) on nodes at x, v (D, N), mass 0.02 kg each."""
    acc = np.zeros_like(x)
    inv_mass = np.full(x.shape[1], 1.0 / 0.02)
    add_thrower(np.ascontiguousarray(x), np.ascontiguousarray(v), acc, inv_mass, model.params.thrower, g)
    return acc


def random_nodes(rng, dim, n=400):
    """Positions around the unturned box (inside, across the edges, outside) and velocities, (D, n) each."""
    local = rng.uniform(-1, 1, (dim, n)) * np.array([0.3, 0.08, 0.08][:dim])[:, None]
    return local, rng.normal(0, 4, (dim, n))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("edge_width", [0.0, 0.01])
@pytest.mark.parametrize("angle", [30.0, -55.0, 90.0])
def test_a_turned_box_gives_the_turned_force_of_the_unturned_one(angle, edge_width, dim):
    rng = np.random.default_rng(7)
    local, v = random_nodes(rng, dim)
    centre = np.array([*CENTRE, 0.0][:dim])[:, None]
    rot = rotation(angle, dim)
    flat = kernel_acc(thrower_model(0.0, dim, edge_width), local + centre, v)
    turned = kernel_acc(thrower_model(angle, dim, edge_width), rot @ local + centre, rot @ v)
    assert np.count_nonzero(flat[0]) > 100      # many nodes are inside, some outside
    np.testing.assert_allclose(turned, rot @ flat, rtol=1e-9, atol=1e-9 * np.abs(flat).max())


@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_the_turned_box_pushes_along_its_axis_and_still_cancels_the_weight(angle):
    model = thrower_model(angle, g=9.81)
    centre = np.array(CENTRE)[:, None]
    a = kernel_acc(model, centre.copy(), np.zeros((2, 1)), g=9.81)[:, 0]
    drive = 0.5 / 0.02 * 6.0
    alpha = math.radians(angle)
    np.testing.assert_allclose(a, [drive * math.cos(alpha), drive * math.sin(alpha) + 9.81], rtol=1e-12)
    # a node just across the turned box (above its centre line along its normal n): pulled back along -n
    n = np.array([-math.sin(alpha), math.cos(alpha)])
    a = kernel_acc(model, centre + 0.01 * n[:, None], np.zeros((2, 1)), g=9.81)[:, 0]
    np.testing.assert_allclose(a - [0.0, 9.81], drive * np.array([math.cos(alpha), math.sin(alpha)])
                               - 40.0 ** 2 * 0.01 * n, rtol=1e-12)


def test_the_box_weight_is_measured_along_and_across_the_turned_box():
    model = thrower_model(30.0, edge_width=0.0)
    e = np.array([math.cos(math.radians(30)), math.sin(math.radians(30))])
    n = np.array([-e[1], e[0]])
    c = np.array(CENTRE)
    inside = [c + 0.19 * e, c - 0.19 * e, c + 0.049 * n, c + 0.19 * e + 0.049 * n]
    outside = [c + 0.21 * e, c + 0.051 * n, c + np.array([0.19, -0.04])]   # the last: inside the unturned box
    for p in inside:
        assert box_weight(p.reshape(2, 1), 0, model.params.thrower) == 1.0
    for p in outside:
        assert box_weight(p.reshape(2, 1), 0, model.params.thrower) == 0.0


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("angle", [0.0, 30.0, -70.0])
def test_the_jacobian_block_matches_finite_differences_of_the_kernel(angle, dim):
    """beta^2 H + beta C_v for a node deep inside the box (weight exactly 1, so the weight's own gradient,
    which the block leaves out, is zero): H = -dF/dx, C_v = -dF/dv, F = m a."""
    model = thrower_model(angle, dim, edge_width=0.001)
    rng = np.random.default_rng(3)
    rot = rotation(angle, dim)
    centre = np.array([*CENTRE, 0.0][:dim])
    x0 = centre + rot @ np.array([0.05, 0.01, -0.01][:dim])
    v0 = rng.normal(0, 3, dim)
    m, beta, eps = 0.02, 1.7e-3, 1e-6

    def force(x, v):
        return m * kernel_acc(model, x.reshape(dim, 1), v.reshape(dim, 1))[:, 0]

    dfdx = np.array([(force(x0 + eps * d, v0) - force(x0 - eps * d, v0)) / (2 * eps) for d in np.eye(dim)]).T
    dfdv = np.array([(force(x0, v0 + eps * d) - force(x0, v0 - eps * d)) / (2 * eps) for d in np.eye(dim)]).T
    want = -(beta * beta * dfdx + beta * dfdv)
    band = np.zeros((dim, dim))
    add_thrower_jacobian(x0.reshape(dim, 1).copy(), band, beta, np.array([m]), np.array([True]),
                         model.params.thrower)
    got = np.zeros((dim, dim))
    for q in range(dim):                       # band[q, c] = A[c + q, c], the lower triangle
        for c in range(dim - q):
            got[c + q, c] = got[c, c + q] = band[q, c]
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-9 * np.abs(want).max())


@pytest.mark.parametrize("angle", [0.0, 40.0])
def test_the_exact_contact_kick_solves_the_turned_box_exactly(angle):
    """v(tau) = e^(-A tau) v0 + A^-1 (I - e^(-A tau)) b for a node in the box (A = gamma I + Gamma, Gamma the
    kernel's -d a / d v by finite differences, b = a(v0) + Gamma v0), against the kick's closed form."""
    from ropesim.integrate.contact import exact_contact_kicks

    model = thrower_model(angle, edge_width=0.01, g=9.81)
    rot = rotation(angle, 2)
    x = (np.array(CENTRE) + rot @ np.array([0.17, 0.03])).reshape(2, 1)   # in the smoothed edge: 0 < s < 1
    v = np.array([[1.5], [-2.0]])
    gamma, tau = 3.0, 0.004
    acc = kernel_acc(model, x, v, g=9.81) + np.array([[0.0], [-9.81]])
    eps = 1e-6
    big = np.array([-(kernel_acc(model, x, v + eps * d[:, None], 9.81) - kernel_acc(model, x, v - eps * d[:, None],
                                                                                      9.81))[:, 0] / (2 * eps)
                    for d in np.eye(2)]).T
    assert 0.0 < box_weight(x, 0, model.params.thrower) < 1.0
    a_mat = gamma * np.eye(2) + big
    b = acc[:, 0] + big @ v[:, 0]
    decay = scipy.linalg.expm(-a_mat * tau)
    want = decay @ v[:, 0] + np.linalg.solve(a_mat, (np.eye(2) - decay) @ b)
    out, nodes = np.zeros((2, 1)), np.zeros(1, dtype=np.int64)
    params = model.params._replace(inv_mass=np.array([1.0 / 0.02]))
    kick = model.kernel(exact_contact_kicks)
    count = kick(x, v, acc, out, nodes, tau, np.array([gamma]), np.array([True]), params)
    assert count == 1
    np.testing.assert_allclose(out[:, 0], want, rtol=1e-9)


def test_angle_zero_is_exactly_unturned_and_the_angle_is_bounded():
    model = thrower_model(0.0)
    p = model.params.thrower
    assert p[10] == 1.0 and p[11] == 0.0            # the kernels then take the unturned arithmetic
    assert model.scene.thrower.direction == (1.0, 0.0)
    for bad in (91.0, -90.5):
        with pytest.raises(SceneError, match="thrower.angle"):
            thrower_model(bad)


def test_guides_see_the_turned_box():
    """The guides act only outside the box: outside the turned box's corner, inside the unturned one's."""
    from ropesim.model.forces.guides import add_guides

    for angle, expect_guide in ((0.0, False), (45.0, True)):
        model = thrower_model(angle, guides=True)
        x = np.array([[0.45], [-0.17]])       # in the circle (centre (0.5, -0.15), R 0.1)
        acc = np.zeros((2, 1))
        add_guides(x, np.zeros((2, 1)), acc, model.params.guides, model.params.thrower, True, 0.0)
        inside_box = box_weight(x, 0, model.params.thrower) > 0
        assert inside_box != expect_guide
        assert (np.abs(acc).max() > 0) == expect_guide


def test_the_outline_draws_the_turned_box():
    from ropesim.render.framing import Box, outline, outline_extent, projection

    model = thrower_model(30.0)
    box = outline(model, projection("xy", 2))[0]
    assert isinstance(box, Box) and box.angle == 30.0 and box.half == (0.2, 0.05)
    lo, hi = outline_extent([box])
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(hi - np.array(CENTRE), [0.2 * c + 0.05 * s, 0.2 * s + 0.05 * c])
    np.testing.assert_allclose(np.array(CENTRE) - lo, [0.2 * c + 0.05 * s, 0.2 * s + 0.05 * c])
    flat = outline(thrower_model(0.0), projection("xy", 2))[0]
    assert flat == Box(CENTRE, (0.2, 0.05))
    top = outline(thrower_model(30.0, dim=3), projection("xz", 3))[0]   # from above: the turned box's extent
    assert top.angle == 0.0
    np.testing.assert_allclose(top.half, [0.2 * c + 0.05 * s, 0.05])
