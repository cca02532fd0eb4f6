"""The elastic catenary in closed form (Irvine, *Cable Structures*, 1981, ch. 2), solved with scipy: the static
reference for a uniform line of submerged weight w per unstretched metre and axial stiffness EA, with no drag, no
bending and, on the seabed, a rigid frictionless floor. Units: m, N, N/m.

Coordinates: the anchor (end A) at the origin, the fairlead (end B) at (XF, ZF) with XF > 0 the horizontal span and
ZF the height of the fairlead above the anchor. H is the horizontal tension (the same all along the line); V_A and
V_F are the vertical components of the tension at the anchor and at the fairlead, positive when the line rises
towards the fairlead there, so V_F = V_A + w L; V_A < 0 means the line dips below the anchor. The fairlead pulls
the line up with V_F; the anchor pulls it down with V_A (up with -V_A).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, root


@dataclass(frozen=True)
class CatenaryForces:
    """H: horizontal tension (N); V_A, V_F: vertical tension components at the anchor and the fairlead (N, see the
    module docstring); grounded: unstretched length resting on the seabed (m, 0 when fully suspended)."""

    H: float
    V_A: float
    V_F: float
    grounded: float

    @property
    def fairlead_tension(self) -> float:
        """Tension at the fairlead (N)."""
        return float(np.hypot(self.H, self.V_F))

    @property
    def anchor_tension(self) -> float:
        """Tension at the anchor (N)."""
        return float(np.hypot(self.H, self.V_A))


def _suspended_xz(H: float, V_A: float, s: float, EA: float, w: float) -> tuple[float, float]:
    """Position (m) at unstretched arc length s (m) from the anchor of a fully suspended elastic catenary."""
    a, b = V_A / H, (V_A + w * s) / H
    x = H / w * (np.arcsinh(b) - np.arcsinh(a)) + H * s / EA
    z = H / w * (np.hypot(1.0, b) - np.hypot(1.0, a)) + (V_A * s + 0.5 * w * s * s) / EA
    return x, z


def _solve(residual, guess):
    """scipy's hybrid Powell solve of the two closure equations (dimensionless, in units of L); the answer is
    accepted when both close to 1e-11 L whatever the solver's own step-size verdict."""
    sol = root(residual, guess, method="hybr", options={"xtol": 1e-13})
    if np.max(np.abs(residual(sol.x))) > 1e-11:
        raise RuntimeError(f"the catenary did not close: {sol.message}")
    return sol


def suspended_catenary(XF: float, ZF: float, L: float, EA: float, w: float) -> CatenaryForces:
    """Elastic catenary hanging freely between the anchor and the fairlead (it may dip below the anchor).

    XF, ZF: fairlead offset (m); L: unstretched length (m, longer than the chord); EA (N); w: weight per metre (N/m).
    """
    if L <= np.hypot(XF, ZF):
        raise ValueError("the line must be longer than the chord for this initial guess")

    def vertical_error(V_A: float, H: float) -> float:
        return _suspended_xz(H, V_A, L, np.inf, w)[1] - ZF

    def inextensible_vertical(H: float) -> float:  # V_A that closes the vertical gap of the inextensible line
        return brentq(vertical_error, -w * L - 1e3 * H, 1e3 * H + w * L, args=(H,), xtol=1e-12)

    # The inextensible line: sqrt(L^2 - ZF^2) = 2 H / w sinh(w XF / 2H) fixes H (monotonic), then V_A from ZF.
    chord = np.sqrt(L * L - ZF * ZF)
    with np.errstate(over="ignore"):  # sinh overflows to inf at the bracket's low end, which brentq handles
        H0 = brentq(lambda H: 2.0 * H / w * np.sinh(w * XF / (2.0 * H)) - chord, 1e-6 * w * L, 1e6 * w * L)
    guess = np.array([np.log(H0), inextensible_vertical(H0) / (w * L)])

    def residual(p):
        H, V_A = np.exp(p[0]), p[1] * w * L
        x, z = _suspended_xz(H, V_A, L, EA, w)
        return [(x - XF) / L, (z - ZF) / L]

    sol = _solve(residual, guess)
    H, V_A = float(np.exp(sol.x[0])), float(sol.x[1] * w * L)
    return CatenaryForces(H=H, V_A=V_A, V_F=V_A + w * L, grounded=0.0)


def seabed_catenary(XF: float, ZF: float, L: float, EA: float, w: float) -> CatenaryForces:
    """Elastic catenary with part of its length on a rigid frictionless seabed through the anchor (z = 0).

    The grounded part (length L - S) is straight and carries H (stretching by H/EA); the suspended part (length S)
    leaves the seabed horizontally, so V_A = 0 and V_F = w S. Raises ValueError when the line does not reach the
    seabed (use :func:`suspended_catenary`).
    """

    def residual(p):
        H, S = np.exp(p[0]), L / (1.0 + np.exp(-p[1]))  # H > 0, 0 < S < L
        x_s, z_s = _suspended_xz(H, 0.0, S, EA, w)
        return [((L - S) * (1.0 + H / EA) + x_s - XF) / L, (z_s - ZF) / L]

    # Inextensible guess: S = sqrt(ZF^2 + 2 ZF H / w), and the span L - S + H/w asinh(w S / H) grows with H.
    def span(H):
        S = np.sqrt(ZF * ZF + 2.0 * ZF * H / w)
        return L - S + H / w * np.arcsinh(w * S / H) - XF

    H0 = brentq(span, 1e-9 * w * L, 1e6 * w * L)
    S0 = np.sqrt(ZF * ZF + 2.0 * ZF * H0 / w)
    if S0 >= L:
        raise ValueError("the line does not touch the seabed")
    sol = _solve(residual, [np.log(H0), np.log(S0 / (L - S0))])
    H, S = float(np.exp(sol.x[0])), float(L / (1.0 + np.exp(-sol.x[1])))
    return CatenaryForces(H=H, V_A=0.0, V_F=w * S, grounded=L - S)
