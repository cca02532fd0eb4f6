r"""Closed forms (and small scipy solves of closed-form equations) for validating ropesim's real-rope physics.

Nothing here imports ropesim. SI units throughout. Conventions (the team's; see ``references.conventions``):

- Lumped-mass line: nodes 0..N, segment j joins nodes j and j+1 with unstretched length l_j, diameter d, mass per
  metre mu; node share of length L_i = half of each adjacent segment; node mass mu L_i.
- Node tangent q_i: unit(x_{i+1} - x_{i-1}) inside, the single adjacent segment at the ends (MoorDyn).
- Relative velocity u = v - U_flow, u_t = (u.q) q, u_n = u - u_t.
- Quadratic drag F = -1/2 rho Cd_n d L |u_n| u_n - 1/2 rho Cd_t pi d L |u_t| u_t (normal drag on the projected
  area d L, tangential on the skin pi d L); linear drag F = -b_n L u_n - b_t L u_t.
- Buoyancy +rho (pi d^2/4) L g upward; weight in the fluid per metre w = (mu - rho pi d^2/4) g.
- The last coordinate is vertical, positive up.

Contents: terminal velocities and drop histories; neutral buoyancy; the Morison drag of one segment; the elastic
catenary with seabed touchdown and friction; the Euler-Bernoulli cantilever (continuous and discrete); the block
on an incline with Coulomb friction; the hanging chain's normal modes (continuous and discrete).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh_tridiagonal
from scipy.optimize import brentq, fsolve
from scipy.special import jn_zeros

# ==============================================================================================================
# terminal velocity and drop histories
# ==============================================================================================================


def terminal_velocity_quadratic(weight, rho, cd, area):
    """Terminal speed [m/s] of a body with net downward force ``weight`` [N] (weight less buoyancy) under
    quadratic drag 1/2 rho Cd A v^2: v_t = sqrt(2 W / (rho Cd A)).

    Source: any fluid-mechanics text, e.g. White, "Fluid Mechanics", 7th ed., sec. 7.6.
    """
    return math.sqrt(2.0 * weight / (rho * cd * area))


def terminal_velocity_linear(weight, b):
    """Terminal speed [m/s] under linear drag b v (b in N s/m): v_t = W / b."""
    return weight / b


def rope_terminal_velocity(mu, d, rho, g, cd_n=1.2, cd_t=0.0, b_n=0.0, b_t=0.0, orientation="broadside"):
    """Terminal speed [m/s] of a straight rope falling broadside (axis horizontal) or end-on (axis vertical).

    Per metre of rope the weight in the fluid w = (mu - rho pi d^2/4) g balances the drag per metre; the length
    cancels, so a lumped-mass line of any length or segmentation falls at the same speed (each node's loads scale
    with its L_i). Broadside only normal drag acts: w = 1/2 rho Cd_n d v^2 + b_n v; end-on only tangential drag:
    w = 1/2 rho Cd_t pi d v^2 + b_t v. Solves the quadratic a v^2 + b v - w = 0 for v >= 0 (either drag may be
    zero, not both).
    """
    w = (mu - rho * math.pi * d * d / 4.0) * g
    if orientation == "broadside":
        a, b = 0.5 * rho * cd_n * d, b_n
    elif orientation == "end-on":
        a, b = 0.5 * rho * cd_t * math.pi * d, b_t
    else:
        raise ValueError("orientation is 'broadside' or 'end-on'")
    sign = 1.0 if w >= 0 else -1.0  # a buoyant rope rises: same speed, upward
    w = abs(w)
    if a == 0.0:
        return sign * w / b
    return sign * 2.0 * w / (b + math.sqrt(b * b + 4.0 * a * w))  # the stable root, no cancellation


def string_loop_takeoff_speeds(mu, d, rho=1.225, g=9.80665, cd_n=1.2, cd_t=0.02):
    """Two drag-weight balance speeds [m/s] for a string of mass per metre mu [kg/m], diameter d [m] in air, as
    candidate estimates of the string shooter's takeoff speed (see STRING_SHOOTER_LITERATURE.md; these are
    derived here, not taken from the papers):

    - "tangential": skin drag per metre equals weight per metre, 1/2 rho Cd_t pi d U^2 = w: the string's end-on
      terminal speed. In a steady loop every element moves along its own tangent, so in still air only this drag
      acts; above this speed even a vertically falling branch gains tension along its motion.
    - "normal": 1/2 rho Cd_n d U^2 = w, the broadside terminal speed (the scale of the transient, sideways motions).

    Neither depends on the loop's length or launch angle (Abello et al. 2024 report that the takeoff speed does
    not). Returns dict(tangential=..., normal=...).
    """
    return dict(tangential=rope_terminal_velocity(mu, d, rho, g, cd_n, cd_t, orientation="end-on"),
                normal=rope_terminal_velocity(mu, d, rho, g, cd_n, cd_t, orientation="broadside"))


def drop_quadratic(t, weight, mass, rho, cd, area):
    """Speed v(t) [m/s] and distance x(t) [m] fallen by a body released from rest under quadratic drag.

    m dv/dt = W - c v^2, c = 1/2 rho Cd A:  v = v_t tanh(t / tau),  x = v_t tau ln cosh(t / tau),
    v_t = sqrt(W / c), tau = m v_t / W = m / (c v_t). ``mass`` is the inertial mass (include the added mass for a
    body in water: a cylinder broadside has Ca = 1, i.e. rho pi d^2/4 per metre).
    """
    t = np.asarray(t, dtype=float)
    c = 0.5 * rho * cd * area
    vt = math.sqrt(weight / c)
    tau = mass * vt / weight
    r = np.abs(t / tau)
    log_cosh = r + np.log1p(np.exp(-2.0 * r)) - math.log(2.0)  # log cosh without overflow at large t
    return vt * np.tanh(t / tau), vt * tau * log_cosh


def drop_linear(t, weight, mass, b):
    """Speed v(t) and distance x(t) for a body released from rest under linear drag b v:
    v = v_t (1 - exp(-t/tau)), x = v_t (t - tau (1 - exp(-t/tau))), v_t = W / b, tau = m / b."""
    t = np.asarray(t, dtype=float)
    vt, tau = weight / b, mass / b
    return vt * (1.0 - np.exp(-t / tau)), vt * (t - tau * (-np.expm1(-t / tau)))


# ==============================================================================================================
# neutral buoyancy
# ==============================================================================================================


def net_vertical_force_per_node(seg_lengths, mu, d, rho, g):
    """Net vertical force on each node of a line at rest [N]: (rho pi d^2/4 - mu) g L_i (buoyancy minus weight).

    Zero at every node when the line is neutrally buoyant, mu = rho pi d^2/4: such a line, at rest in still fluid,
    feels no force at all (drag is zero at zero velocity, the springs are unstretched) and stays put, in any shape.
    """
    seg = np.asarray(seg_lengths, dtype=float)
    L = np.zeros(seg.size + 1)
    L[:-1] += 0.5 * seg
    L[1:] += 0.5 * seg
    return (rho * math.pi * d * d / 4.0 - mu) * g * L


def neutral_mass_per_metre(d, rho):
    """mu [kg/m] at which a rope of diameter d [m] is neutrally buoyant in a fluid of density rho."""
    return rho * math.pi * d * d / 4.0


def neutral_diameter(mu, rho):
    """d [m] at which a rope of mass per metre mu is neutrally buoyant: sqrt(4 mu / (pi rho))."""
    return math.sqrt(4.0 * mu / (math.pi * rho))


# ==============================================================================================================
# Morison drag of one segment
# ==============================================================================================================


def segment_morison_drag(x0, x1, v0, v1, d, rho, cd_n, cd_t, flow=(0.0, 0.0, 0.0), length=None):
    """Quadratic drag on the two nodes of a single-segment line [N], from the formula, written out scalar by scalar.

    Both nodes are end nodes, so both take the segment's direction as tangent, q = (x1 - x0) / |x1 - x0|, and half
    the segment's length, L = length / 2 (``length`` defaults to the current |x1 - x0|; pass the unstretched length
    to use that). For node k: u = v_k - flow, u_t = (u.q) q, u_n = u - u_t,
    F_k = -1/2 rho Cd_n d L |u_n| u_n - 1/2 rho Cd_t pi d L |u_t| u_t.
    Works in 2-D or 3-D (``flow`` is trimmed to the dimension). Returns (F0, F1) as numpy arrays.
    """
    dim = len(x0)
    q = [x1[k] - x0[k] for k in range(dim)]
    norm = math.sqrt(sum(c * c for c in q))
    q = [c / norm for c in q]
    L = 0.5 * (norm if length is None else length)
    out = []
    for v in (v0, v1):
        u = [v[k] - flow[k] for k in range(dim)]
        ut_mag = sum(u[k] * q[k] for k in range(dim))  # signed
        ut = [ut_mag * q[k] for k in range(dim)]
        un = [u[k] - ut[k] for k in range(dim)]
        un_mag = math.sqrt(sum(c * c for c in un))
        F = [-0.5 * rho * cd_n * d * L * un_mag * un[k] - 0.5 * rho * cd_t * math.pi * d * L * abs(ut_mag) * ut[k]
             for k in range(dim)]
        out.append(np.array(F))
    return out[0], out[1]


# ==============================================================================================================
# elastic catenary with seabed touchdown (and seabed friction)
# ==============================================================================================================


@dataclass
class CatenaryResult:
    """The elastic catenary's solution: the tension components at each end of the line [N].

    H, V: horizontal and vertical tension components at the fairlead (V upward on the fairlead's support)
    HA, VA: horizontal and vertical tension components at the anchor (VA = 0 with touchdown)
    LB: unstretched length lying on the seabed [m]; x_touchdown: horizontal distance anchor -> touchdown [m]
    regime: "suspended", "touchdown", or "slack" (X too short: the line lies partly slack on the seabed, H = 0)
    """

    H: float
    V: float
    HA: float
    VA: float
    LB: float
    x_touchdown: float
    regime: str

    @property
    def T_fairlead(self) -> float:
        return math.hypot(self.H, self.V)

    @property
    def T_anchor(self) -> float:
        return math.hypot(self.HA, self.VA)


def catenary_suspended_xz(H, V, L, w, EA):
    """Fairlead offsets (X, Z) from the anchor of a fully suspended elastic catenary with fairlead tension
    components H, V (Irvine 1981, ch. 2; Jonkman 2007, sec. 4.2):

    X = (H/w) [asinh(V/H) - asinh((V - wL)/H)] + H L / EA
    Z = (H/w) [sqrt(1 + (V/H)^2) - sqrt(1 + ((V - wL)/H)^2)] + (V L - w L^2 / 2) / EA
    """
    VA = V - w * L
    X = (H / w) * (math.asinh(V / H) - math.asinh(VA / H)) + H * L / EA
    Z = (H / w) * (math.sqrt(1 + (V / H) ** 2) - math.sqrt(1 + (VA / H) ** 2)) + (V * L - 0.5 * w * L * L) / EA
    return X, Z


def catenary_touchdown_xz(H, V, L, w, EA, CB=0.0):
    """(X, Z) of an elastic catenary whose anchor end lies on a flat seabed (Jonkman 2007, sec. 4.2; the MAP++
    theory manual):

    LB = L - V/w (length on the seabed),
    X = LB + (H/w) asinh(V/H) + H L / EA + (CB w / (2 EA)) [-LB^2 + (LB - H/(CB w)) max(LB - H/(CB w), 0)]
    Z = (H/w) [sqrt(1 + (V/H)^2) - 1] + V^2 / (2 EA w)
    The friction term: the seabed portion's tension falls from H at touchdown by CB w per metre towards the anchor.
    """
    LB = L - V / w
    X = LB + (H / w) * math.asinh(V / H) + H * L / EA
    if CB > 0:
        a = LB - H / (CB * w)
        X += (CB * w / (2 * EA)) * (-LB * LB + a * max(a, 0.0))
    Z = (H / w) * (math.sqrt(1 + (V / H) ** 2) - 1.0) + V * V / (2 * EA * w)
    return X, Z


def elastic_catenary(X, Z, L, w, EA, CB=0.0, seabed=True, tol=1e-12) -> CatenaryResult:
    """Solve the 2-D elastic catenary: anchor at (0, 0) on a flat seabed, fairlead at (X, Z), Z > 0 above it.

    X, Z [m]; L unstretched length [m]; w weight per metre in water [N/m] (> 0); EA [N]; CB seabed friction
    coefficient [-] (0: frictionless); seabed=False: no seabed, the line may hang below the anchor.

    Method: with touchdown, for a given H the Z equation fixes V (monotone, brentq) and then X(H) is monotone in H
    (brentq). If that gives V > wL (no line left on the seabed), or there is no seabed, solve the two suspended
    equations for (H, V) with fsolve from several starts and keep the exact root. The anchor tension with touchdown
    is HA = max(H - CB w LB, 0), VA = 0; suspended, HA = H and VA = V - w L.

    Sources: Irvine, H. M., "Cable Structures" (MIT Press 1981), ch. 2; Jonkman, J. M., "Dynamics Modeling and
    Loads Analysis of an Offshore Floating Wind Turbine", NREL/TP-500-41958 (2007), sec. 4.2; Masciola et al., MAP++
    documentation (NREL), "the seabed friction model"; Faltinsen, "Sea Loads on Ships and Offshore Structures"
    (1990), ch. 8 (inextensible limit).
    """
    if not (Z > 0 and X > 0 and L > 0 and w > 0 and EA > 0):
        raise ValueError("need X, Z, L, w, EA > 0")

    if seabed:
        # smallest X reachable with touchdown: H -> 0, the line hangs straight up from the seabed
        V0 = _vertical_hang_V(Z, w, EA)
        if V0 < w * L:
            X_min = (L - V0 / w)  # as H -> 0 (the seabed part is unstretched, and the hanging part has no X)
            if X <= X_min:
                return CatenaryResult(0.0, V0, 0.0, 0.0, L - V0 / w, X, "slack")

            def V_of_H(H):
                f = lambda V: catenary_touchdown_xz(H, V, L, w, EA, CB)[1] - Z  # noqa: E731
                hi = max(w * L, 1.0)
                while f(hi) < 0:
                    hi *= 2.0
                return brentq(f, 0.0, hi, xtol=1e-300, rtol=1e-15, maxiter=500)

            def rX(H):
                return catenary_touchdown_xz(H, V_of_H(H), L, w, EA, CB)[0] - X

            lo, hi = 1e-9 * w * max(L, Z), w * max(L, Z)
            while rX(hi) < 0:
                hi *= 2.0
                if hi > 1e6 * EA:
                    break
            if rX(hi) >= 0 and rX(lo) < 0:
                H = brentq(rX, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=500)
                V = V_of_H(H)
                if V <= w * L:
                    LB = L - V / w
                    HA = max(H - CB * w * LB, 0.0)
                    if CB > 0 and H < CB * w * LB:
                        stretch = H * H / (2 * CB * w * EA)
                    else:
                        stretch = (H * LB - 0.5 * CB * w * LB * LB) / EA
                    return CatenaryResult(H, V, HA, 0.0, LB, LB + stretch, "touchdown")

    # fully suspended
    def F(p):
        H, V = math.exp(p[0]), p[1]
        x, z = catenary_suspended_xz(H, V, L, w, EA)
        return [(x - X) / L, (z - Z) / L]

    best = None
    chord = math.hypot(X, Z)
    for lam0 in (math.sqrt(3.0 * ((L * L - Z * Z) / (X * X) - 1.0)) if L > chord else 0.2, 0.2, 1.0, 5.0, 0.05):
        lam0 = max(lam0, 1e-3)
        H0 = abs(w * X / (2.0 * lam0))
        V0 = 0.5 * w * (Z / math.tanh(lam0) + L)
        p, info, ier, _ = fsolve(F, [math.log(H0), V0], full_output=True, xtol=1e-14)
        res = max(abs(r) for r in F(p))
        if best is None or res < best[1]:
            best = (p, res)
        if res < tol:
            break
    H, V = math.exp(best[0][0]), best[0][1]
    if best[1] > 1e-8:
        raise RuntimeError(f"catenary did not converge (residual {best[1]:.2e})")
    if seabed and V - w * L < -1e-9 * w * L:
        raise RuntimeError("suspended solution dips below the anchor although the seabed is on")
    return CatenaryResult(H, V, H, V - w * L, 0.0, 0.0, "suspended")


def _vertical_hang_V(Z, w, EA):
    """V at the top of a vertical elastic hanging part of height Z (H -> 0): Z = V/w + V^2/(2 EA w)."""
    # V^2/(2 EA) + V - w Z = 0
    return 2.0 * w * Z / (1.0 + math.sqrt(1.0 + 2.0 * w * Z / EA))


def inextensible_touchdown(H, Z, L, w):
    """The textbook inextensible catenary with touchdown (Faltinsen 1990, ch. 8; Irvine 1981, ch. 1): given the
    horizontal tension H and the fairlead height Z, with a = H / w:

    suspended length l_s = sqrt(Z^2 + 2 Z a), V = w l_s, X = L - l_s + a asinh(l_s / a), T_fairlead = H + w Z.
    Returns dict(l_s, V, X, T_fairlead, LB).
    """
    a = H / w
    ls = math.sqrt(Z * Z + 2.0 * Z * a)
    return dict(l_s=ls, V=w * ls, X=L - ls + a * math.asinh(ls / a), T_fairlead=H + w * Z, LB=L - ls)


# ==============================================================================================================
# Euler-Bernoulli cantilever
# ==============================================================================================================

BETA_L = (1.8751040687119611, 4.6940911329741746, 7.8547574382376126)  # roots of cos x cosh x = -1


def cantilever_tip_deflection_uniform_load(w, L, EI):
    """Tip deflection [m] of a clamped-free beam under a uniform load w [N/m] (its own weight): w L^4 / (8 EI).
    Source: Gere & Timoshenko, "Mechanics of Materials", table of beam deflections (Appendix G)."""
    return w * L ** 4 / (8.0 * EI)


def cantilever_tip_deflection_point_load(P, L, EI):
    """Tip deflection [m] under a tip load P [N]: P L^3 / (3 EI). Source: Gere & Timoshenko, Appendix G."""
    return P * L ** 3 / (3.0 * EI)


def cantilever_root_eq(x):
    """cos x cosh x + 1: its roots are beta_n L for the clamped-free beam."""
    return math.cos(x) * math.cosh(x) + 1.0


def cantilever_beta_L(n_modes=3):
    """beta_n L, n = 1..n_modes, solved with brentq near (2n - 1) pi / 2 (to machine precision).
    The equation is rescaled, cos x + 1/cosh x = 0, which has the same roots and no overflow."""
    out = []
    for n in range(1, n_modes + 1):
        c = (2 * n - 1) * math.pi / 2
        f = lambda x: math.cos(x) + 1.0 / math.cosh(x)  # noqa: E731
        out.append(brentq(f, c - 1.0 if n == 1 else c - 0.5, c + 0.5, xtol=1e-15, rtol=1e-15))
    return np.array(out)


def cantilever_frequencies(EI, mu, L, n_modes=3):
    """Natural angular frequencies [rad/s] of a uniform clamped-free Euler-Bernoulli beam:
    omega_n = (beta_n L)^2 sqrt(EI / (mu L^4)). Source: Blevins, "Formulas for Natural Frequency and Mode Shape"
    (1979), table 8-1; Rao, "Mechanical Vibrations", sec. 8.5."""
    return cantilever_beta_L(n_modes) ** 2 * math.sqrt(EI / (mu * L ** 4))


def discrete_cantilever_tip_deflection(joint_x, joint_k, node_x, node_force, tip_x=None):
    """Small-deflection tip deflection of a chain of rigid links joined by rotational springs (a discrete beam).

    joint_x: positions along the beam of the rotational springs (the clamp's spring at joint_x[0] if the clamp is
    compliant) [m]; joint_k: their stiffnesses [N m/rad]; node_x, node_force: transverse forces on the nodes and
    their positions [m, N]; tip_x: where to measure (default: the last node).

    Exact to first order: joint j turns by M_j / k_j with M_j = sum over nodes beyond it of F (x - x_j), and a
    rotation at x_j moves a point at x by (x - x_j) times it, so delta_tip = sum_j M_j (x_tip - x_j) / k_j.
    For N equal links of length l, bending springs k = EI / l at x_j = j l (j = 0..N-1) and a tip load P this is
    P l^3 N (N+1)(2N+1) / (6 EI) = P L^3/(3 EI) (1 + 3/(2N) + 1/(2N^2)): first-order convergence to the beam.
    """
    joint_x = np.asarray(joint_x, dtype=float)
    joint_k = np.asarray(joint_k, dtype=float)
    node_x = np.asarray(node_x, dtype=float)
    node_force = np.asarray(node_force, dtype=float)
    tip = node_x[-1] if tip_x is None else tip_x
    out = 0.0
    for xj, kj in zip(joint_x, joint_k):
        beyond = node_x > xj
        M = np.sum(node_force[beyond] * (node_x[beyond] - xj))
        out += M * (tip - xj) / kj
    return out


# ==============================================================================================================
# block (or line) on an incline with Coulomb friction
# ==============================================================================================================


def incline_critical_angle(mu_s):
    """The slope [rad] above which a block (or a line lying straight down the slope, any buoyancy) starts to slide:
    atan(mu_s). Weight and buoyancy scale the normal force and the driving force alike, so neither matters."""
    return math.atan(mu_s)


def incline_acceleration(alpha, mu_s, mu_k=None, g=9.80665, weight_fraction=1.0, inertia_fraction=1.0):
    """Acceleration [m/s^2] down a slope of angle alpha [rad] from rest:
    a = g (w/m g) (sin alpha - mu_k cos alpha) when tan alpha > mu_s, else 0 (it stays).

    weight_fraction = (weight in the fluid) / (weight in air), e.g. 1 - rho_fluid/rho_body; inertia_fraction =
    (mass + added mass) / mass. In air with no added mass a = g (sin alpha - mu_k cos alpha).
    Source: any mechanics text (e.g. Meriam & Kraige, "Engineering Mechanics: Dynamics", ch. 3).
    """
    mu_k = mu_s if mu_k is None else mu_k
    if math.tan(alpha) <= mu_s:
        return 0.0
    return g * weight_fraction / inertia_fraction * (math.sin(alpha) - mu_k * math.cos(alpha))


# ==============================================================================================================
# hanging chain: normal modes
# ==============================================================================================================


def hanging_chain_frequencies(L, g=9.80665, n_modes=5):
    """Angular frequencies [rad/s] of small swinging of a uniform heavy chain hanging from a fixed point:
    omega_n = (j_{0,n} / 2) sqrt(g / L), j_{0,n} the zeros of the Bessel function J0 (Bernoulli 1732, Euler).
    Sources: D. Bernoulli (1732) and Euler for the J0 mode shapes; Rayleigh, "The Theory of Sound", vol. 1 (the
    hanging chain); Fetter & Walecka, "Theoretical Mechanics of Particles and Continua" (hanging-chain problem).
    """
    return 0.5 * jn_zeros(0, n_modes) * math.sqrt(g / L)


def discrete_hanging_chain_frequencies(masses, lengths, g=9.80665):
    """Angular frequencies [rad/s] of small in-plane swinging of point masses on massless inextensible links
    hanging from a fixed point (node 0). masses[k] is node k+1's mass [kg], lengths[k] the link from node k to
    node k+1 [m].

    Link j (above node j+1) carries the weight below it, T_j = g sum_{k > j} m_k. For horizontal displacements
    y_i (y_0 = 0): m_i y_i'' = T_i (y_{i+1} - y_i) / l_i - T_{i-1} (y_i - y_{i-1}) / l_{i-1}, i.e. K y = omega^2 M y
    with K tridiagonal; symmetrised with M^(-1/2) and solved by scipy.linalg.eigh_tridiagonal.
    The team's lumped line (inner nodes mu l, end node mu l/2) is the case masses = mu * L_i[1:].
    """
    m = np.asarray(masses, dtype=float)
    l = np.asarray(lengths, dtype=float)
    n = m.size
    T = g * np.cumsum(m[::-1])[::-1]  # T[j]: link j (above node j+1) carries masses j..n-1 (0-based)
    k = T / l  # stiffness of link j
    diag = k.copy()
    diag[:-1] += k[1:]
    off = -k[1:]
    s = 1.0 / np.sqrt(m)
    w2 = eigh_tridiagonal(diag * s * s, off * s[:-1] * s[1:], eigvals_only=True)
    return np.sqrt(w2)


def lumped_chain_masses(L, N, mu=1.0):
    """Node masses (nodes 1..N) and link lengths of the team's lumped line of N equal segments hanging from node 0:
    inner nodes mu L/N, the free end mu L/(2N). (Node 0's half segment sits on the support.)"""
    l = L / N
    m = np.full(N, mu * l)
    m[-1] *= 0.5
    return m, np.full(N, l)
