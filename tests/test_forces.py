"""Force terms against an independent energy: F = -grad E by finite differences, and Newton's third law.

The reference energy is written here from scratch with an explicit list of spring pairs, so the kernel's
index handling (the ends of a line, the wrap of a loop, second neighbours) is checked, not just its algebra.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ropesim.model.build import build
from ropesim.model.terms import accelerations
from ropesim.scene.loader import scene_from_dict


def scene_dict(n, closed, dim, bending=None, gravity=None, k=5000.0, l=0.5):
    raw = {
        "dimension": dim,
        "rope": {"nodes": n, "segment_length": l, "stiffness": k, "mass": 1.0, "closed": closed},
        "initial": {"shape": "points", "points": [[float(i), 0.0] + [0.0] * (dim - 2) for i in range(n)]},
        "integrator": {"dt": 1e-3, "t_end": 1.0},
    }
    if bending is not None:
        raw["bending"] = {"stiffness": bending}
    if gravity is not None:
        raw["gravity"] = {"g": gravity}
    return raw


def reference_pairs(n, closed, stride):
    """Spring pairs written out by hand: (i, i + stride) on a line, wrapping on a loop."""
    if closed:
        return [(i, (i + stride) % n) for i in range(n)]
    return [(i, i + stride) for i in range(n - stride)]


def reference_energy(x, n, closed, k, l, k2, g, mass):
    """x: (N, D). Springs, bending springs of rest length 2 l, and gravity m g y."""
    e = 0.0
    for i, j in reference_pairs(n, closed, 1):
        e += 0.5 * k * (np.linalg.norm(x[j] - x[i]) - l) ** 2
    if k2:
        for i, j in reference_pairs(n, closed, 2):
            e += 0.5 * k2 * (np.linalg.norm(x[j] - x[i]) - 2 * l) ** 2
    if g:
        e += g * np.sum(mass * x[:, 1])
    return e


def kernel_force(model, x_nd):
    acc = np.zeros((model.dim, model.nodes))
    x = np.ascontiguousarray(x_nd.T)
    model.kernel(accelerations)(x, np.zeros_like(x), acc, model.params, 0.0)
    return (acc * model.mass).T  # (N, D) newtons


def numeric_force(energy, x, h=1e-6):
    f = np.zeros_like(x)
    for idx in np.ndindex(x.shape):
        xp, xm = x.copy(), x.copy()
        xp[idx] += h
        xm[idx] -= h
        f[idx] = -(energy(xp) - energy(xm)) / (2 * h)
    return f


CASES = [
    # (nodes, closed, dim, bending)
    (2, False, 2, None),
    (3, False, 2, 500.0),
    (7, False, 2, 500.0),
    (5, True, 2, 500.0),
    (8, True, 3, 300.0),
    (6, False, 3, None),
]


@pytest.mark.parametrize("n, closed, dim, k2", CASES)
def test_force_is_minus_energy_gradient(n, closed, dim, k2):
    rng = np.random.default_rng(n * 10 + dim)
    model = build(scene_from_dict(scene_dict(n, closed, dim, bending=k2, gravity=9.81)))
    x = rng.normal(scale=0.6, size=(n, dim))
    energy = lambda y: reference_energy(y, n, closed, 5000.0, 0.5, k2 or 0.0, 9.81, model.mass)  # noqa: E731
    f_kernel = kernel_force(model, x)
    f_numeric = numeric_force(energy, x)
    # central differences: truncation ~h^2 E''' and round-off ~eps E / h, both far below 1e-5 of the force scale
    scale = np.abs(f_numeric).max()
    np.testing.assert_allclose(f_kernel, f_numeric, atol=1e-5 * scale)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(5, 30), closed=st.booleans(), dim=st.sampled_from([2, 3]), seed=st.integers(0, 2**32 - 1))
def test_internal_forces_sum_to_zero(n, closed, dim, seed):
    """Springs and bending springs are internal: total force and total torque vanish (Newton's third law)."""
    model = build(scene_from_dict(scene_dict(n, closed, dim, bending=400.0)))
    x = np.random.default_rng(seed).normal(scale=2.0, size=(n, dim))
    f = kernel_force(model, x)
    scale = np.abs(f).max() + 1e-300
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12 * scale * n)
    if dim == 2:
        torque = np.sum(x[:, 0] * f[:, 1] - x[:, 1] * f[:, 0])
    else:
        torque = np.cross(x, f).sum(axis=0)
    np.testing.assert_allclose(torque, 0.0, atol=1e-11 * scale * n * np.abs(x).max())


def test_bending_at_the_ends_of_a_line():
    """On a straight line at rest length nothing pulls; bending one end node loads only its neighbours."""
    n, l = 6, 0.5
    model = build(scene_from_dict(scene_dict(n, False, 2, bending=500.0, l=l)))
    x = np.stack([l * np.arange(n), np.zeros(n)], axis=1)
    np.testing.assert_allclose(kernel_force(model, x), 0.0, atol=1e-9)
    # Rotate the first segment about node 1 (first spring keeps its length): only the bending spring (0, 2)
    # is strained, so forces appear on nodes 0 and 2 alone, equal and opposite, along x2 - x0.
    x[0] = x[1] + l * np.array([-np.cos(0.3), np.sin(0.3)])
    f = kernel_force(model, x)
    assert np.allclose(f[[1, 3, 4, 5]], 0.0, atol=1e-9)
    np.testing.assert_allclose(f[0], -f[2], atol=1e-9)
    d = x[2] - x[0]
    expected = 500.0 * (np.linalg.norm(d) - 2 * l) * d / np.linalg.norm(d)
    np.testing.assert_allclose(f[0], expected, rtol=1e-12)


def test_bending_around_a_loop_prefers_a_circle():
    """On a regular polygon with sides at rest length only bending acts, the same on every node (the wrap
    included): radial, outward, since second neighbours sit closer than 2 l."""
    n, l = 12, 1.0
    radius = l / (2 * np.sin(np.pi / n))  # first neighbours exactly at rest length
    angles = 2 * np.pi * np.arange(n) / n
    x = radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    plain = kernel_force(build(scene_from_dict(scene_dict(n, True, 2, l=l))), x)
    np.testing.assert_allclose(plain, 0.0, atol=1e-9)
    f = kernel_force(build(scene_from_dict(scene_dict(n, True, 2, bending=500.0, l=l))), x)
    radial = np.sum(f * x, axis=1) / radius
    tangential = f[:, 0] * -np.sin(angles) + f[:, 1] * np.cos(angles)
    np.testing.assert_allclose(tangential, 0.0, atol=1e-9)
    # chord to the second neighbour is 2 R sin(2 pi / n) < 2 l: the compressed spring pushes each node outward
    chord = 2 * radius * np.sin(2 * np.pi / n)
    # each node has two second neighbours; each pushes along the chord, whose radial component is sin(2 pi / n)
    expected = 2 * 500.0 * (2 * l - chord) * np.sin(2 * np.pi / n)
    np.testing.assert_allclose(radial, expected, rtol=1e-10)


def test_coincident_nodes_exert_no_force_and_no_nan():
    model = build(scene_from_dict(scene_dict(3, False, 2)))
    x = np.array([[0.0, 0.0], [0.0, 0.0], [0.5, 0.0]])
    f = kernel_force(model, x)
    assert np.all(np.isfinite(f))
    np.testing.assert_allclose(f[0], 0.0)  # its only spring has no direction


def shooter_model(**thrower):
    raw = scene_dict(4, True, 2, gravity=9.8)
    raw["initial"] = {"shape": "points", "points": [[0.0, 0.0], [1.0, 0.0], [1.0, -1.0], [0.0, -1.0]]}
    raw["thrower"] = {"center": [0.0, 0.0], "length": 8.0, "width": 2.0, "v_max": 5.0, "b_thrower": 10.0,
                      **thrower}
    raw["guides"] = [{"center": [4.0, 0.0], "radius": 1.0, "omega0": 20.0}]
    return build(scene_from_dict(raw))


def single_node_acc(model, pos, vel):
    """Acceleration of node 0 at ``pos``/``vel`` with the springs switched off (k -> 0 via a far-away rope)."""
    from ropesim.model.forces.guides import add_guides
    from ropesim.model.forces.thrower import add_thrower

    x = np.array(pos, dtype=float).reshape(2, 1)
    v = np.array(vel, dtype=float).reshape(2, 1)
    acc = np.zeros((2, 1))
    p = model.params
    inv_mass, gravity, thrower, guides = p.inv_mass, p.gravity, p.thrower, p.guides
    acc[1, 0] -= gravity[0]
    add_thrower(x, v, acc, inv_mass[:1], thrower, gravity[0])
    add_guides(x, v, acc, guides, thrower, True, gravity[0])
    return acc[:, 0]


def test_thrower_box_follows_the_writeup():
    """Inside the box: a_x = b_thrower / m (v_max - v_x); a_y = -omega0^2 y - 2 omega0 v_y (weight cancelled)."""
    model = shooter_model()
    w = 2 * (2 * np.pi * 5.0 / 8.0)
    a = single_node_acc(model, [1.0, 0.3], [2.0, -0.5])
    np.testing.assert_allclose(a, [10.0 * (5.0 - 2.0), -w * w * 0.3 - 2 * w * -0.5], rtol=1e-12)
    outside = single_node_acc(model, [1.0, 1.5], [2.0, -0.5])  # above the box: only gravity
    np.testing.assert_allclose(outside, [0.0, -9.8])


def test_guide_circle_pushes_out_and_one_sided_lets_go():
    model = shooter_model()
    # inside the circle, outside the box (x > 4), at r = 0.5 from its centre, moving inward
    a = single_node_acc(model, [4.5, 0.0], [-1.0, 0.0])
    expected_r = -400.0 * (0.5 - 1.0) - 40.0 * -1.0
    np.testing.assert_allclose(a, [expected_r, 0.0], atol=1e-12)  # weight cancelled
    raw_scene = model.scene
    from dataclasses import replace

    one_sided = build(replace(raw_scene, guides=(replace(raw_scene.guides[0], one_sided=True),)))
    np.testing.assert_allclose(single_node_acc(one_sided, [4.5, 0.0], [1.0, 0.0]), [0.0, -9.8])
    np.testing.assert_allclose(single_node_acc(one_sided, [4.5, 0.0], [-1.0, 0.0]), a)
