"""Static references for systems of lines meeting at a free point, independent of ropesim.

1. The continuous elastic catenary (Irvine, *Cable Structures*, 1981, ch. 2): n identical lines hanging from
   anchors at one height, spread evenly round a vertical axis at horizontal distance R from it, meet at a free
   point of weight W on the axis. By symmetry each line carries W / n of the point's weight at its lower end
   and the same horizontal tension H; the line's span R and its unstretched length L fix H, and its rise fixes
   how far below the anchors the point hangs. Units: m, N, N/m.
2. The lumped system itself (nodes, springs, node weights) solved for its static balance by scipy, written from
   its energy alone: E = sum 1/2 k (r - l0)^2 over springs (none while a tension-only spring is short) +
   sum m g y over nodes, the free point's line ends one node.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, least_squares


@dataclass(frozen=True)
class HangingPoint:
    """The point's depth below the anchors [m], and each line's horizontal tension H, vertical tension at the point
    V_point and at its anchor V_anchor [N]."""

    depth: float
    H: float
    V_point: float
    V_anchor: float

    @property
    def anchor_tension(self) -> float:
        return float(np.hypot(self.H, self.V_anchor))

    @property
    def point_tension(self) -> float:
        return float(np.hypot(self.H, self.V_point))


def _span_and_rise(H: float, V: float, L, EA: float, w: float) -> tuple[float, float]:
    """The horizontal span and the rise [m] of an elastic catenary from its lower end, where its tension is (H, V)
    (V > 0: the line rises there), to the unstretched arc length L [m] along it (a number or an array)."""
    a, b = V / H, (V + w * L) / H
    x = H / w * (np.arcsinh(b) - np.arcsinh(a)) + H * L / EA
    z = H / w * (np.hypot(1.0, b) - np.hypot(1.0, a)) + (V * L + 0.5 * w * L * L) / EA
    return x, z


def point_on_catenaries(n: int, R: float, L: float, EA: float, w: float, W: float) -> HangingPoint:
    """A free point of weight W [N] hanging from n identical elastic catenaries (length L [m], axial stiffness EA
    [N], weight w [N/m]) whose anchors sit at horizontal distance R [m] from it, all at one height."""
    V = W / n
    H = brentq(lambda h: _span_and_rise(h, V, L, EA, w)[0] - R, 1e-9 * (w * L + W), 1e9 * (w * L + W),
               xtol=1e-14 * (w * L + W), rtol=1e-15)
    return HangingPoint(_span_and_rise(H, V, L, EA, w)[1], H, V, V + w * L)


def catenary_shape(point: HangingPoint, s, EA: float, w: float) -> tuple[np.ndarray, np.ndarray]:
    """Where the arc length s [m] (unstretched, from the point) of one of :func:`point_on_catenaries`' lines lies:
    its horizontal distance from the point towards the anchor and its height above the point [m]."""
    return _span_and_rise(point.H, point.V_point, np.asarray(s, dtype=float), EA, w)


def lumped_statics(x0: np.ndarray, springs: list[tuple[int, int, float, float, bool]], mass: np.ndarray,
                   held: np.ndarray, g: float) -> np.ndarray:
    """The static balance of a lumped system: node positions (N, D) with y up, springs (i, j, k [N/m], rest
    length [m], tension-only), node masses [kg], held nodes (bool) kept where ``x0`` puts them. Solved by
    scipy's least squares on the net force of the free nodes, from ``x0``; returns the positions."""
    x0 = np.asarray(x0, dtype=float)
    dim = x0.shape[1]
    free = np.flatnonzero(~held)

    def positions(z):
        x = x0.copy()
        x[free] = z.reshape(-1, dim)
        return x

    def force(z):
        x = positions(z)
        f = np.zeros_like(x)
        f[:, 1] -= mass * g
        for i, j, k, rest, slack in springs:
            d = x[j] - x[i]
            r = np.linalg.norm(d)
            if slack and r < rest:
                continue
            pull = k * (r - rest) * d / r
            f[i] += pull
            f[j] -= pull
        return f[free].ravel()

    def stiffness(z):
        x = positions(z)
        n = len(x)
        jac = np.zeros((n * dim, n * dim))
        for i, j, k, rest, slack in springs:
            d = x[j] - x[i]
            r = np.linalg.norm(d)
            if slack and r < rest:
                continue
            u = d / r
            blk = k * ((1.0 - rest / r) * np.eye(dim) + rest / r * np.outer(u, u))   # d(pull on i)/d x_j
            a, b = slice(i * dim, (i + 1) * dim), slice(j * dim, (j + 1) * dim)
            jac[a, a] -= blk
            jac[b, b] -= blk
            jac[a, b] += blk
            jac[b, a] += blk
        cols = (free[:, None] * dim + np.arange(dim)).ravel()
        return jac[np.ix_(cols, cols)]

    sol = least_squares(force, x0[free].ravel(), jac=stiffness, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm")
    if not np.abs(force(sol.x)).max() <= 1e-9 * mass.sum() * g:
        raise RuntimeError(f"the lumped system did not balance: {sol.message}")
    return positions(sol.x)


# ------------------------------------------------------------------------------------------ rigid bodies
#
# 3. A rigid body held by lines, its static pose solved by scipy from its own equations: the net force and the
#    net moment about its reference point vanish. Its pose: the reference point r and a rotation vector phi with
#    R = exp(phi) R0 (scipy's Rotation). A force at the body-frame point s acts at r + R s. y is up.


def _pose_matrix(phi, R0: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(phi).as_matrix() @ R0


def body_balance(line_pull, R0: np.ndarray, guess_r, weight: float, cog, lift: float = 0.0, cob=(0.0, 0.0, 0.0),
                 push=(0.0, 0.0, 0.0), planar: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The static pose (r (3,), R (3, 3)) of a rigid body of weight ``weight`` [N] at its centre of gravity ``cog``
    (body frame), buoyancy ``lift`` [N] at ``cob``, a constant force ``push`` (3,) [N] at its reference point, and
    lines: ``line_pull(eyes)`` returns the forces (K, 3) [N] of its lines on their eyes at world positions
    ``eyes`` (K, 3) (its ``eyes`` attribute gives their body-frame positions (K, 3)). ``planar``: the body stays in
    the x-y plane, turning about z alone (3 unknowns). Solved by least squares to round-off from ``guess_r`` and
    R0."""
    from scipy.optimize import least_squares

    eyes, cog, cob, push = (np.asarray(a, dtype=float) for a in (line_pull.eyes, cog, cob, push))

    def unpack(z):
        if planar:
            return np.array([z[0], z[1], 0.0]), np.array([0.0, 0.0, z[2]])
        return z[:3], z[3:]

    def residual(z):
        r, phi = unpack(z)
        R = _pose_matrix(phi, R0)
        arms = eyes @ R.T
        pulls = line_pull(r + arms)
        c, cb = R @ cog, R @ cob
        down, up = np.array([0.0, -weight, 0.0]), np.array([0.0, lift, 0.0])
        force = pulls.sum(axis=0) + down + up + push
        moment = np.cross(arms, pulls).sum(axis=0) + np.cross(c, down) + np.cross(cb, up)
        out = np.concatenate([force, moment])
        return out[[0, 1, 5]] if planar else out

    z0 = np.concatenate([guess_r[:2], [0.0]]) if planar else np.concatenate([guess_r, np.zeros(3)])
    sol = least_squares(residual, z0, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm")
    if not np.abs(residual(sol.x)).max() <= 1e-9 * max(weight, 1.0):
        raise RuntimeError(f"the body did not balance: {sol.message}")
    r, phi = unpack(sol.x)
    return r, _pose_matrix(phi, R0)


class StraightElasticLines:
    """Massless elastic lines that pull only when stretched: line k from ``anchors[k]`` to the body-frame eye
    ``eyes[k]``, unstretched length ``lengths[k]`` [m], axial stiffness ``EA[k]`` [N]; called with the eyes' world
    positions, returns each line's force on its eye, T = EA (L - L0) / L0 towards its anchor."""

    def __init__(self, anchors, eyes, lengths, EA):
        self.anchors, self.eyes = np.asarray(anchors, dtype=float), np.asarray(eyes, dtype=float)
        self.lengths, self.EA = np.asarray(lengths, dtype=float), np.asarray(EA, dtype=float)

    def __call__(self, at: np.ndarray) -> np.ndarray:
        d = self.anchors - at
        length = np.linalg.norm(d, axis=1)
        tension = np.maximum(self.EA * (length - self.lengths) / self.lengths, 0.0)
        return (tension / length)[:, None] * d


class SeabedCatenaries:
    """Elastic catenaries from anchors on a rigid frictionless seabed through them (Irvine; tests/references/
    catenary_closed_form.py, grounded or fully suspended as the geometry asks): line k from ``anchors[k]`` to the
    body-frame fairlead ``eyes[k]``, unstretched length ``length`` [m], axial stiffness ``EA`` [N], submerged
    weight ``w`` [N/m]; called with the fairleads' world positions, returns each line's force on its fairlead:
    H horizontally towards its anchor, V_F down. ``last`` keeps the catenaries of the last call."""

    def __init__(self, anchors, eyes, length: float, EA: float, w: float):
        self.anchors, self.eyes = np.asarray(anchors, dtype=float), np.asarray(eyes, dtype=float)
        self.length, self.EA, self.w = length, EA, w
        self.last = []

    def __call__(self, at: np.ndarray) -> np.ndarray:
        from references.catenary_closed_form import seabed_catenary, suspended_catenary

        out, self.last = np.zeros((len(at), 3)), []
        for k, (anchor, fairlead) in enumerate(zip(self.anchors, at)):
            towards = anchor - fairlead
            towards[1] = 0.0
            span, rise = float(np.linalg.norm(towards)), float(fairlead[1] - anchor[1])
            try:
                line = seabed_catenary(span, rise, self.length, self.EA, self.w)
            except ValueError:
                line = suspended_catenary(span, rise, self.length, self.EA, self.w)
            self.last.append(line)
            out[k] = line.H * towards / span
            out[k, 1] = -line.V_F
        return out
