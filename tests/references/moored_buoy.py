r"""The static shape of a taut-moored buoy's tether in a current that varies with height: the continuous elastic
cable, integrated with scipy from the buoy down to the anchor. No ropesim code is used.

Conventions (see ``references.conventions``; 2-D, coordinates (x, z), z up, SI units): the anchor is held at
(x_a, z_a); the tether, of unstretched length L, diameter d, mass per metre mu and axial stiffness EA, rises from
it to a buoy of mass M, volume V, drag area CdA (isotropic) at its top; the current U(z) flows along +x. Everything
is at rest, so the velocity relative to the water is -U.

The equations
-------------
Arc length s is unstretched length measured from the buoy (s = 0) down the tether (s = L at the anchor). T(s) is
the force that the part of the tether below s exerts on the part above it; it points down the tether, along the
unit tangent t = T / |T|. An element ds feels T(s + ds) from below, -T(s) from above and the distributed load
f ds, so

    dT/ds = -f,        dr/ds = (1 + |T| / EA) t,

with f per unstretched metre: the weight in water (0, -(mu - rho pi d^2 / 4) g) plus Morison drag on the current,
its normal part 1/2 rho Cd_n d |U_n| U_n and its tangential part 1/2 rho Cd_t pi d |U_t| U_t (U_t = (U . t) t,
U_n = U - U_t). Drag and buoyancy act on unstretched length, as in MoorDyn and ropesim. At the buoy the tether
holds the buoy's net force: T(0) = -(0, (rho V - M) g) - 1/2 rho CdA |U| U at the buoy's height.

Given the buoy's height z_b the equations integrate to the anchor's end; z_b is found (brentq) so that the end
lands at z_a, and the buoy's x then follows from where the end lands: the current depends on z only, so moving
the whole tether sideways changes nothing.

The one approximation against a lumped-mass line is the continuum itself: a line of N segments converges to
this at O(1/N^2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


@dataclass
class TetherShape:
    """The static tether: s (unstretched length from the buoy), r (x, z) and T (Tx, Tz) along it, (n,) and (n, 2)."""

    s: np.ndarray
    r: np.ndarray
    T: np.ndarray

    @property
    def buoy(self) -> np.ndarray:
        return self.r[0]

    @property
    def top_tension(self) -> float:
        return float(np.linalg.norm(self.T[0]))

    @property
    def anchor_tension(self) -> float:
        return float(np.linalg.norm(self.T[-1]))

    def angle_from_vertical(self, s: float) -> float:
        """The tether's angle from the vertical [deg] at unstretched length s from the buoy, positive leaning
        downstream (+x) going up."""
        T = np.array([np.interp(s, self.s, self.T[:, 0]), np.interp(s, self.s, self.T[:, 1])])
        return math.degrees(math.atan2(-T[0], -T[1]))


def power_law_current(U_ref: float, z_ref: float, alpha: float, datum: float):
    """U(z) = U_ref ((z - datum) / z_ref)^alpha above the datum (the seabed), 0 below it (DNV-RP-C205, sec. 4.1.3:
    the tidal current, alpha = 1/7)."""
    def U(z):
        h = z - datum
        return U_ref * (h / z_ref) ** alpha if h > 0 else 0.0
    return U


def moored_buoy(anchor, L, d, mu, EA, buoy_mass, buoy_volume, buoy_cda, current, rho=1025.0, g=9.81, cd_n=1.2,
                cd_t=0.0, points=401, rtol=1e-11, atol=1e-11) -> TetherShape:
    """The static tether from the buoy to the anchor (see the module doc); ``current`` is U(z) [m/s] along +x."""
    xa, za = anchor
    w = (mu - rho * math.pi * d * d / 4.0) * g
    kn, kt = 0.5 * rho * cd_n * d, 0.5 * rho * cd_t * math.pi * d
    net_up = (rho * buoy_volume - buoy_mass) * g
    if net_up <= 0:
        raise ValueError("the buoy must float: rho V > M")

    def rhs(s, y):
        x, z, Tx, Tz = y
        T = math.hypot(Tx, Tz)
        tx, tz = Tx / T, Tz / T
        U = current(z)
        ut = U * tx                         # U . t, U = (U, 0)
        Utx, Utz = ut * tx, ut * tz
        Unx, Unz = U - Utx, -Utz
        un = math.hypot(Unx, Unz)
        fx = kn * un * Unx + kt * abs(ut) * Utx
        fz = kn * un * Unz + kt * abs(ut) * Utz - w
        stretch = 1.0 + T / EA
        return [stretch * tx, stretch * tz, -fx, -fz]

    def shoot(zb, dense=False):
        Ub = current(zb)
        T0 = [-0.5 * rho * buoy_cda * abs(Ub) * Ub, -net_up]
        return solve_ivp(rhs, (0.0, L), [0.0, zb, *T0], method="DOP853", rtol=rtol, atol=atol,
                         t_eval=np.linspace(0.0, L, points) if dense else None)

    def miss(zb):
        return shoot(zb).y[1, -1] - za

    lo, hi = za + 0.05 * L, za + L * (1.0 + 2.0 * (net_up + w * L) / EA)   # a tether leaning far over .. straight up
    zb = brentq(miss, lo, hi, xtol=1e-13, rtol=1e-15, maxiter=200)
    sol = shoot(zb, dense=True)
    r = sol.y[:2].T.copy()
    r[:, 0] += xa - r[-1, 0]
    return TetherShape(sol.t, r, sol.y[2:].T.copy())
