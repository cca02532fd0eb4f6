r"""The towed cable: its critical angle (closed form), the continuous cable (an ODE), and the exact steady state
of the discrete lumped-mass line (three scipy solves: a node-by-node march, a simultaneous solve over segment
tensions and angles, and one over raw node positions). No ropesim code is used.

Conventions (see ``references.conventions``; 2-D, coordinates (x, z), z up, SI units):

- Nodes 0..N, node 0 the held top (tow point), node N the free end. Segment j joins nodes j and j+1, unstretched
  length l_j, diameter d, mass per metre mu, axial stiffness EA (tension only).
- In steady state every node moves with the tow velocity V; the fluid moves with the current C. The line's
  velocity relative to the fluid is u = V - C, the same at every node. Towing at speed U in still fluid is
  u = (U, 0); a held top in a current U flowing towards -x is the same u. Work in the tow point's frame.
- Node loads: weight -mu L_i g, buoyancy +rho (pi d^2/4) L_i g (vertical), Morison drag
  -1/2 rho Cd_n d L_i |u_n| u_n - 1/2 rho Cd_t pi d L_i |u_t| u_t, linear drag -b_n L_i u_n - b_t L_i u_t, with
  u_t = (u.q_i) q_i and q_i MoorDyn's node tangent (unit(x_{i+1} - x_{i-1}) inside, the adjacent segment at the
  ends). An optional end body at node N adds its weight, buoyancy and isotropic drag -1/2 rho Cd_b A_b |u| u.
- Angles phi are measured from the downward vertical, positive when the line trails behind the tow point.

The critical angle (derivation)
-------------------------------
Take a long cable towed at speed U through still fluid, and far from its ends let it be straight at angle phi from
the vertical. Arc length s runs up the cable from the free end, and its unit tangent t = (sin phi, cos phi) points
up the cable; n = (cos phi, -sin phi) is the normal in the plane. With tension T(s) and external force per metre f,
the equilibrium of an element is d(T t)/ds + f = 0, and since dt/ds = phi' n:

    T' = -f . t                 (tangential: changes the tension)
    T phi' = -f . n             (normal: bends the cable)

Per metre, the weight in the fluid is w = (mu - rho pi d^2/4) g, acting along -z: -f.t = w cos phi, -f.n =
-w sin phi. The relative velocity u = (U, 0) has normal part (u.n) n = U cos phi n and tangential part
U sin phi t, so the drag per metre adds -f.n = +k_n U^2 cos^2 phi and -f.t = +k_t U^2 sin^2 phi, with
k_n = 1/2 rho Cd_n d and k_t = 1/2 rho Cd_t pi d. Hence (continuous towed-cable equations, cf. Pode 1951):

    dT/ds   = w cos phi + k_t U^2 sin^2 phi (+ b_t U sin phi)
    T dphi/ds = k_n U^2 cos^2 phi - w sin phi (+ b_n U cos phi)

A straight cable (phi' = 0) needs the normal loads to balance:

    w sin phi_c = 1/2 rho Cd_n d U^2 cos^2 phi_c.

With K = rho Cd_n d U^2 / (2 w) this is K sin^2 + sin - K = 0, so

    sin phi_c = (sqrt(1 + 4 K^2) - 1) / (2 K) = 2 K / (1 + sqrt(1 + 4 K^2)),

(the second form is free of cancellation at small K). Limits: K -> 0 (slow, heavy): phi_c ~ K - K^3/... ~ K,
hanging vertically; K -> infinity (fast, light): cos phi_c ~ K^(-1/2), phi_c -> 90 deg, streaming horizontally.
Equivalently sin(phi_c) / cos^2(phi_c) = K. With linear normal drag alone, tan phi_c = b_n U / w.

Tangential drag does NOT change phi_c: on a straight cable it acts along the tangent and only makes the tension
grow faster. It changes how fast a cable that is not at phi_c (below an end body, say) approaches it: linearising
the normal equation about phi_c, T d(dphi)/ds = -c dphi with c = w cos phi_c + 2 k_n U^2 sin phi_c cos phi_c, and
with T = T_0 + a s, a = w cos phi_c + k_t U^2 sin^2 phi_c,

    phi(s) - phi_c ~ (T_0 + a s)^(-c / a)        (algebraic, not exponential, decay)

so tangential drag (larger a) makes the approach slower: a finite cable's top angle differs more from phi_c.
Without tangential drag c / a = 1 + 2 tan^2 phi_c. The same holds for the discrete line: a straight line at
phi_c is an exact discrete steady state when there is no end body (every node's loads are proportional to its
L_i), whatever the tangential drag, and with an end body the discrete line approaches phi_c going up.

Crosswind: 3-D reduces to 2-D
-----------------------------
A sling under a helicopter flying at U with a side wind W sees a horizontal relative velocity u = (U, -W) (or
any horizontal vector). Gravity is vertical and every drag term lies in the plane spanned by u and the node
tangent, so a line lying in the vertical plane through u feels no force out of that plane: the 3-D steady state
is the 2-D one for |u| = sqrt(U^2 + W^2), turned by atan2(W, U) about the vertical (``crosswind_plane``). The
line trails straight downwind of the relative wind, not behind the helicopter's track.

Sources: Pode, L. (1951), "Tables for computing the equilibrium configuration of a flexible cable in a uniform
stream", DTMB Report 687 (the critical-angle tow); Casarella, M. J. & Parsons, M. (1970), "Cable systems under
hydrodynamic loading", Marine Technology Society Journal 4(4) (review of the loading functions); Chakrabarti, B. &
Hanna, J. A. (2016), "Catenaries in viscous fluid", J. Fluids Struct. 66, arXiv:1509.01282 (closed forms under
LINEAR drag, including towing); the discrete loads follow MoorDyn (Hall & Goupee 2015, Ocean Engineering 104, 590-603).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, least_squares, root

from .conventions import (
    axial_node_forces,
    gravity_buoyancy_node_forces,
    linear_drag_node_forces,
    morison_node_forces,
    node_lengths,
)

# --------------------------------------------------------------------------------------------------------------
# closed forms
# --------------------------------------------------------------------------------------------------------------


def weight_in_fluid(mu, d, rho, g):
    """w = (mu - rho pi d^2 / 4) g [N/m]: weight per metre less buoyancy."""
    return (mu - rho * math.pi * d * d / 4.0) * g


def drag_parameter(U, w, rho, cd_n, d):
    """K = rho Cd_n d U^2 / (2 w): normal drag per metre at right angles to the flow over weight per metre."""
    return rho * cd_n * d * U * U / (2.0 * w)


def critical_angle(U, w, rho, cd_n, d):
    """Critical angle phi_c [rad] from the vertical of a long cable towed at speed U [m/s] under quadratic normal
    drag: w sin phi = 1/2 rho Cd_n d U^2 cos^2 phi, i.e. sin phi_c = 2K / (1 + sqrt(1 + 4 K^2)).

    w: weight per metre in the fluid [N/m] (> 0); rho [kg/m^3]; Cd_n [-]; d: diameter [m]. Vectorised over U.
    Independent of the tangential drag (see the module docstring). Source: Pode (1951); Blevins (1984) ch. 10.
    """
    K = np.asarray(drag_parameter(np.asarray(U, dtype=float), w, rho, cd_n, d))
    s = 2.0 * K / (1.0 + np.sqrt(1.0 + 4.0 * K * K))
    # cos^2 = sin / K, and atan2 keeps full precision near 90 deg, where arcsin(s) would not
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(K > 0, np.sqrt(s / np.where(K > 0, K, 1.0)), 1.0)
    return np.arctan2(s, c)


def critical_angle_linear(U, w, b_n):
    """Critical angle [rad] under linear normal drag b_n [N s/m^2] alone: tan phi_c = b_n U / w."""
    return np.arctan2(b_n * np.asarray(U, dtype=float), w)


def critical_angle_general(U, w, rho, cd_n, d, b_n=0.0):
    """Critical angle [rad] with quadratic AND linear normal drag: w sin phi = k_n U^2 cos^2 phi + b_n U cos phi.

    The left side rises and the right side falls on [0, pi/2], so the root is unique (brentq).
    """
    kn = 0.5 * rho * cd_n * d
    U = abs(float(U))
    if U == 0.0:
        return 0.0
    f = lambda p: w * math.sin(p) - kn * U * U * math.cos(p) ** 2 - b_n * U * math.cos(p)  # noqa: E731
    return brentq(f, 0.0, 0.5 * math.pi, xtol=1e-15, rtol=4 * np.finfo(float).eps)


def crosswind_plane(forward, side):
    """(|u|, azimuth): the 2-D problem's relative speed and the angle [rad] by which its plane is turned about the
    vertical, for a tow point moving at ``forward`` [m/s] along +x with a wind of ``side`` [m/s] blowing towards
    -y (relative velocity of the line through the air (forward, side)). See the module docstring."""
    return math.hypot(forward, side), math.atan2(side, forward)


def to_3d(x2, azimuth):
    """Place a 2-D solution (x along the relative velocity, z up) in 3-D, turned by ``azimuth`` about z."""
    x2 = np.asarray(x2, dtype=float)
    c, s = math.cos(azimuth), math.sin(azimuth)
    return np.stack([x2[:, 0] * c, x2[:, 0] * s, x2[:, 1]], axis=1)


def approach_exponent(U, w, rho, cd_n, cd_t, d):
    """c / a in phi(s) - phi_c ~ (T_0 + a s)^(-c/a): the algebraic rate at which a towed cable approaches its
    critical angle going up from a disturbance (end body). Smaller with more tangential drag.

    c = w cos phi_c + 2 k_n U^2 sin phi_c cos phi_c, a = w cos phi_c + k_t U^2 sin^2 phi_c.
    """
    p = float(critical_angle(U, w, rho, cd_n, d))
    kn, kt = 0.5 * rho * cd_n * d, 0.5 * rho * cd_t * math.pi * d
    c = w * math.cos(p) + 2.0 * kn * U * U * math.sin(p) * math.cos(p)
    a = w * math.cos(p) + kt * U * U * math.sin(p) ** 2
    return c / a


# --------------------------------------------------------------------------------------------------------------
# the problem
# --------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TowedLine:
    """A towed lumped-mass line in 2-D, all parameters explicit (SI units).

    seg_lengths: unstretched segment lengths l_j, node 0 (top) to node N (free end) [m]
    mu: mass per metre [kg/m]; d: diameter [m]; EA: axial stiffness [N] (math.inf: inextensible)
    rho: fluid density [kg/m^3]; g: gravity [m/s^2]
    cd_n, cd_t: normal / tangential quadratic drag coefficients [-] (on d L_i and pi d L_i)
    b_n, b_t: linear drag per metre [N s/m^2]
    u: velocity of the line relative to the fluid, (ux, uz) [m/s] (tow velocity minus current)
    end_mass [kg], end_volume [m^3] (buoyancy), end_area A_b [m^2] and end_cd Cd_b [-]: a body at node N with
    isotropic drag -1/2 rho Cd_b A_b |u| u
    drag_length: "unstretched" or "stretched": which L_i the drag uses
    """

    seg_lengths: tuple
    mu: float
    d: float
    EA: float = math.inf
    rho: float = 1025.0
    g: float = 9.80665
    cd_n: float = 1.2
    cd_t: float = 0.0
    b_n: float = 0.0
    b_t: float = 0.0
    u: tuple = (1.0, 0.0)
    end_mass: float = 0.0
    end_volume: float = 0.0
    end_area: float = 0.0
    end_cd: float = 1.0
    drag_length: str = "unstretched"

    @classmethod
    def uniform(cls, length, segments, **kw):
        """A line of ``segments`` equal segments, total unstretched length ``length``."""
        return cls(seg_lengths=(length / segments,) * segments, **kw)

    @property
    def N(self) -> int:
        return len(self.seg_lengths)

    @property
    def w(self) -> float:
        return weight_in_fluid(self.mu, self.d, self.rho, self.g)

    def end_body_force(self) -> np.ndarray:
        """Weight, buoyancy and isotropic drag of the end body [N]."""
        u = np.asarray(self.u, dtype=float)
        f = -0.5 * self.rho * self.end_cd * self.end_area * np.linalg.norm(u) * u
        f[1] += (self.rho * self.end_volume - self.end_mass) * self.g
        return f

    def stretched(self, j: int, T: float) -> float:
        """Stretched length of segment j under tension T."""
        return self.seg_lengths[j] * (1.0 + T / self.EA) if math.isfinite(self.EA) else self.seg_lengths[j]

    def node_forces(self, x) -> np.ndarray:
        """External force on every node of the configuration x (N+1, 2), the conventions evaluated in full."""
        x = np.asarray(x, dtype=float)
        v = np.broadcast_to(np.asarray(self.u, dtype=float), x.shape)  # line relative to the fluid
        f = gravity_buoyancy_node_forces(self.seg_lengths, self.mu, self.d, self.rho, self.g, dim=2)
        f = f + morison_node_forces(x, v, self.seg_lengths, self.d, self.rho, self.cd_n, self.cd_t,
                                    drag_length=self.drag_length)
        if self.b_n or self.b_t:
            f = f + linear_drag_node_forces(x, v, self.seg_lengths, self.b_n, self.b_t,
                                            drag_length=self.drag_length)
        f[-1] += self.end_body_force()
        return f


@dataclass
class TowedSolution:
    x: np.ndarray  # (N+1, 2) node positions relative to the tow point (node 0 at the origin) [m]
    T: np.ndarray  # (N,) segment tensions [N]
    info: dict = field(default_factory=dict)

    @property
    def angles(self) -> np.ndarray:
        """Each segment's angle from the downward vertical [rad], positive trailing towards -x."""
        seg = np.diff(self.x, axis=0)  # from node j to node j+1 (downwards)
        return np.arctan2(-seg[:, 0], -seg[:, 1])


# --------------------------------------------------------------------------------------------------------------
# method 1: march from the free end, one scalar root per node
# --------------------------------------------------------------------------------------------------------------


def _node_force(line: TowedLine, i: int, q: np.ndarray, Ldrag: float) -> np.ndarray:
    """External force on node i given its tangent q and drag length Ldrag (written out, 2-D)."""
    u = np.asarray(line.u, dtype=float)
    L0 = (line.seg_lengths[i - 1] if i > 0 else 0.0) + (line.seg_lengths[i] if i < line.N else 0.0)
    L0 *= 0.5
    f = np.array([0.0, (line.rho * math.pi * line.d ** 2 / 4.0 - line.mu) * L0 * line.g])
    ut = (u @ q) * q
    un = u - ut
    f -= 0.5 * line.rho * line.cd_n * line.d * Ldrag * math.hypot(*un) * un
    f -= 0.5 * line.rho * line.cd_t * math.pi * line.d * Ldrag * math.hypot(*ut) * ut
    f -= line.b_n * Ldrag * un + line.b_t * Ldrag * ut
    if i == line.N:
        f += line.end_body_force()
    return f


def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def steady_state_march(line: TowedLine, tol: float = 1e-14) -> TowedSolution:
    """The exact discrete steady state by marching from the free end up to the tow point.

    At node i the segment above (i-1, i) must carry everything below: T_{i-1} e + S_i = 0, with
    S_i = sum_{k >= i} F_k and e the unit vector from node i to node i-1. F_i depends on e through node i's
    tangent q_i (and, with drag_length="stretched", through the stretched length), so for each node solve ONE
    scalar equation for e's angle theta: g(theta) = angle(-S_i(theta)) - theta = 0 (brentq), with the tension
    T = |S_i| and the stretched length l (1 + T/EA) found by a fixed point inside. Of several roots the stable one
    (g decreasing) nearest the previous segment's direction is taken.
    """
    N, ls = line.N, line.seg_lengths
    x = [None] * (N + 1)
    T = np.zeros(N)
    x[N] = np.zeros(2)
    S_below = np.zeros(2)
    prev_theta = None

    for i in range(N, 0, -1):
        def solve_inner(theta, i=i):
            e = np.array([math.cos(theta), math.sin(theta)])
            Tg = T[i] if i < N else 0.0  # first guess of this segment's tension
            for _ in range(100):
                lam = line.stretched(i - 1, Tg)
                xa = x[i] + lam * e  # node i-1
                if i == N:
                    q = -e
                    Ld = 0.5 * (lam if line.drag_length == "stretched" else ls[i - 1])
                else:
                    q = x[i + 1] - xa
                    q = q / math.hypot(*q)
                    if line.drag_length == "stretched":
                        Ld = 0.5 * (lam + math.hypot(*(x[i + 1] - x[i])))
                    else:
                        Ld = 0.5 * (ls[i - 1] + ls[i])
                S = S_below + _node_force(line, i, q, Ld)
                Tn = math.hypot(*S)
                if abs(Tn - Tg) <= 1e-15 * max(Tn, 1.0) or not math.isfinite(line.EA):
                    Tg = Tn
                    break
                Tg = Tn
            return S, Tg, lam

        def g(theta):
            S, _, _ = solve_inner(theta)
            return _wrap(math.atan2(-S[1], -S[0]) - theta)

        if prev_theta is None:
            # the free end: scan all directions for stable roots (g falling through zero)
            grid = np.linspace(-math.pi, math.pi, 721)
            vals = np.array([g(t) for t in grid])
            S_iso = S_below + _node_force(line, i, np.array([0.0, 1.0]), 0.0)  # no drag: weight + end body
            ref = math.atan2(-S_iso[1], -S_iso[0])
            cands = []
            for a, b, ga, gb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
                if ga > 0 >= gb and ga - gb < math.pi:
                    cands.append(brentq(g, a, b, xtol=tol))
            if not cands:
                raise RuntimeError("no stable direction for the end segment")
            theta = min(cands, key=lambda t: abs(_wrap(t - ref)))
        else:
            # expand a bracket round the segment below's direction until g falls through zero
            delta, theta = 1e-4, None
            while delta <= math.pi:
                a, b = prev_theta - delta, prev_theta + delta
                ga, gb = g(a), g(b)
                if ga > 0 >= gb:
                    theta = brentq(g, a, b, xtol=tol)
                    break
                delta *= 2.0
            if theta is None:
                raise RuntimeError(f"no bracket for the direction of segment {i - 1}")
        S, Ti, lam = solve_inner(theta)
        e = np.array([math.cos(theta), math.sin(theta)])
        T[i - 1] = Ti
        x[i - 1] = x[i] + lam * e
        S_below = S
        prev_theta = theta

    X = np.array(x)
    X -= X[0]
    return TowedSolution(x=X, T=T, info={"method": "march"})


# --------------------------------------------------------------------------------------------------------------
# method 2: all node positions at once
# --------------------------------------------------------------------------------------------------------------


def residual(line: TowedLine, x: np.ndarray, tension_only: bool = True) -> np.ndarray:
    """Net force on nodes 1..N (node 0 held) for a configuration x (N+1, 2), flattened [N]."""
    return (axial_node_forces(x, line.seg_lengths, line.EA, tension_only) + line.node_forces(x))[1:].ravel()


def _hanging_guess(line: TowedLine) -> np.ndarray:
    """The line hanging straight (down, or up if it floats) under its weight, buoyancy and end body alone, each
    segment stretched by the load it carries: the exact state at zero relative velocity."""
    fz = gravity_buoyancy_node_forces(line.seg_lengths, line.mu, line.d, line.rho, line.g)[:, 1].copy()
    fz[-1] += (line.rho * line.end_volume - line.end_mass) * line.g
    below = np.cumsum(fz[::-1])[::-1][1:]  # segment j carries nodes j+1..N
    sign = -1.0 if below[0] <= 0 else 1.0
    seg = np.asarray(line.seg_lengths) * (1.0 + np.abs(below) / line.EA)
    z = np.concatenate([[0.0], np.cumsum(sign * seg)])
    return np.stack([np.zeros_like(z), z], axis=1)


def _positions_from_segments(line: TowedLine, T, theta) -> np.ndarray:
    """Node positions from segment tensions and directions: x_{j+1} = x_j + l_j (1 + T_j/EA) (cos th, sin th)."""
    lam = np.asarray(line.seg_lengths) * (1.0 + (np.asarray(T) / line.EA if math.isfinite(line.EA) else 0.0))
    steps = lam[:, None] * np.stack([np.cos(theta), np.sin(theta)], axis=1)
    return np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])


def steady_state_full(line: TowedLine, steps: int = 6) -> TowedSolution:
    """The discrete steady state by solving every node's force balance simultaneously (scipy.optimize.root).

    Unknowns: every segment's tension T_j and direction angle theta_j (2N numbers, which fix every node position
    through x_{j+1} = x_j + l_j (1 + T_j/EA) e_j). Equations: the net force on each node 1..N,
    T_j e_j - T_{j-1} e_{j-1} + F_i(x) = 0 (T_N = 0), with F_i the full conventions evaluated on the whole line.
    Continuation in the relative velocity from the exact hanging state (u = 0) to u in ``steps`` stages; hybr,
    then a Levenberg-Marquardt polish. Any EA, including math.inf. Unlike the march, nothing is solved node by node:
    all tangents, drags and tensions are coupled in one Newton-type solve.
    """
    N = line.N
    scale = max(abs(line.w) * sum(line.seg_lengths), float(np.linalg.norm(line.end_body_force())), 1e-12)
    x_h = _hanging_guess(replace(line, EA=line.EA if math.isfinite(line.EA) else 1e300))
    fz = line.node_forces(x_h)[:, 1]  # at u = 0 only weight, buoyancy, end body
    T0 = np.abs(np.cumsum(fz[::-1])[::-1][1:])
    th0 = np.full(N, -0.5 * math.pi if x_h[-1, 1] <= 0 else 0.5 * math.pi)
    z = np.concatenate([T0 / scale, th0])

    def unpack(z):
        return z[:N] * scale, z[N:]

    def fun(z, ln):
        T, th = unpack(z)
        x = _positions_from_segments(ln, T, th)
        Te = T[:, None] * np.stack([np.cos(th), np.sin(th)], axis=1)
        f = ln.node_forces(x)
        f[:-1] += Te
        f[1:] -= Te
        return f[1:].ravel() / scale

    u = np.asarray(line.u, dtype=float)
    for lam in np.linspace(0.0, 1.0, steps + 1)[1:]:
        ln = replace(line, u=tuple(lam * u))
        z = root(fun, z, args=(ln,), method="hybr", options={"xtol": 1e-15}).x
    z = least_squares(fun, z, args=(line,), xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm").x
    T, th = unpack(z)
    x = _positions_from_segments(line, T, th)
    res = float(np.max(np.abs(fun(z, line)))) * scale
    if np.any(T < 0):
        raise RuntimeError("full solve ended with a compressed segment")
    return TowedSolution(x=x, T=T, info={"method": "full", "residual": res})


def steady_state_positions(line: TowedLine, x0=None, steps: int = 8) -> TowedSolution:
    """The discrete steady state by solving every node's force balance at once for all node positions.

    Continuation in the relative velocity: start from the exact hanging state at u = 0 (or from ``x0``), raise u
    to its value in ``steps`` stages, and at each solve all 2N equations with scipy.optimize.root (hybr), then
    polish with least_squares (Levenberg-Marquardt). The springs are solved with the two-sided law (compression
    allowed) so the Jacobian stays smooth; the solution is then checked to have every segment in tension.

    The unknowns are the raw node positions, so the spring forces (EA / l per metre of stretch) dominate the
    Jacobian: fine for soft lines (EA / (w l) up to ~1e5), ill-conditioned for stiff ones, where
    ``steady_state_full`` (same equations, unknowns per segment) is the one to use.

    Needs a finite EA. Shares with the march only the statement of the loads (``TowedLine.node_forces``, which
    evaluates ``references.conventions`` on the whole line), not the method.
    """
    if not math.isfinite(line.EA):
        raise ValueError("the full solve needs a finite EA")
    N = line.N
    scale = max(abs(line.w) * sum(line.seg_lengths), float(np.linalg.norm(line.end_body_force())), 1e-12)

    def solve(ln, z0, polish):
        def fun(z):
            x = np.vstack([np.zeros(2), z.reshape(N, 2)])
            return residual(ln, x, tension_only=False) / scale

        z = root(fun, z0, method="hybr", options={"xtol": 1e-14}).x
        if polish:
            z = least_squares(fun, z, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm").x
        return z, float(np.max(np.abs(fun(z)))) * scale

    if x0 is None:
        z = _hanging_guess(line)[1:].ravel()
        lams = np.linspace(0.0, 1.0, steps + 1)[1:]
    else:
        z = np.asarray(x0, dtype=float)[1:].ravel()
        lams = [1.0]
    u = np.asarray(line.u, dtype=float)
    for lam in lams:
        z, res = solve(replace(line, u=tuple(lam * u)), z, polish=lam == 1.0)
    x = np.vstack([np.zeros(2), z.reshape(N, 2)])
    seg = np.linalg.norm(np.diff(x, axis=0), axis=1)
    T = line.EA * (seg / np.asarray(line.seg_lengths) - 1.0)
    if np.any(T < 0):
        raise RuntimeError("full solve ended with a compressed segment")
    return TowedSolution(x=x, T=T, info={"method": "positions", "residual": res})


# --------------------------------------------------------------------------------------------------------------
# method 3: the continuous cable (ODE), the N -> infinity limit
# --------------------------------------------------------------------------------------------------------------


def continuous_cable(line_length, w, rho, d, u, cd_n, cd_t=0.0, b_n=0.0, b_t=0.0, EA=math.inf,
                     end_force=(0.0, 0.0), n_out=201, rtol=1e-12, atol=1e-12):
    """The continuous towed cable: integrate dT/ds = -f.t, T dphi/ds = -f.n up from the free end (s = 0) to the
    tow point (s = line_length, unstretched arc length), with positions dx/ds = (1 + T/EA) t.

    w: weight per metre in the fluid [N/m]; u: line velocity relative to the fluid (ux, uz) [m/s];
    end_force: external force on the free end (end body) [N]. With no end force the free end starts at phi_c
    when the drag has a normal part (it then stays there: the straight solution).
    Returns (s, x (n, 2) relative to the tow point, T, phi).
    """
    u = np.asarray(u, dtype=float)
    kn, kt = 0.5 * rho * cd_n * d, 0.5 * rho * cd_t * math.pi * d

    def f_ext(phi):
        t = np.array([math.sin(phi), math.cos(phi)])
        ut = (u @ t) * t
        un = u - ut
        f = np.array([0.0, -w])
        f -= kn * np.linalg.norm(un) * un + kt * np.linalg.norm(ut) * ut
        f -= b_n * un + b_t * ut
        return f, t, np.array([math.cos(phi), -math.sin(phi)])

    F0 = np.asarray(end_force, dtype=float)
    T0 = float(np.linalg.norm(F0))
    if T0 > 0:
        phi0 = math.atan2(-F0[0], -F0[1])  # t(0) = -F0 / |F0|: the line pulls the body against its load
    else:
        U = float(np.linalg.norm(u))
        phi0 = critical_angle_general(U, w, rho, cd_n, d, b_n) if u[1] == 0 and u[0] > 0 else 0.0

    def rhs(s, y):
        T, phi = y[0], y[1]
        f, t, n = f_ext(phi)
        stretch = 1.0 + (T / EA if math.isfinite(EA) else 0.0)
        dphi = (-f @ n) / T if T > 0 else 0.0
        return [-f @ t, dphi, stretch * t[0], stretch * t[1]]

    s = np.linspace(0.0, line_length, n_out)
    sol = solve_ivp(rhs, (0.0, line_length), [T0, phi0, 0.0, 0.0], t_eval=s, method="DOP853",
                    rtol=rtol, atol=atol)
    T, phi, x, z = sol.y
    xy = np.stack([x - x[-1], z - z[-1]], axis=1)
    return s, xy, T, phi


def with_(line: TowedLine, **changes) -> TowedLine:
    """A copy of ``line`` with some parameters changed."""
    return replace(line, **changes)


__all__ = [
    "weight_in_fluid", "drag_parameter", "critical_angle", "critical_angle_linear", "critical_angle_general",
    "approach_exponent", "crosswind_plane", "to_3d", "TowedLine", "TowedSolution", "steady_state_march", "steady_state_full",
    "steady_state_positions", "residual",
    "continuous_cable", "with_", "node_lengths",
]
