"""Linear (Airy) waves, regular or irregular, on water of a given depth: the surface and the water's kinematics.

A sea is a sum of J components, each an Airy wave of amplitude a_j [m], angular frequency w_j [rad/s], wave
number k_j [1/m], phase phi_j and direction beta_j. Heights are measured from the mean water level, d is the
water depth, y points up and x, z are horizontal; a component travels along e_j = (cos beta_j, 0, -sin beta_j),
beta measured about the vertical (y) axis from +x, so that MoorDyn's wave heading is the same angle (MoorDyn's
point (x, y, z) is ropesim's (x, z, -y)). With the phase of component j at a point,
theta_j = k_j (x cos beta_j - z sin beta_j) - w_j t + phi_j:

    eta = sum_j a_j cos theta_j                                          the surface elevation
    u   = sum_j a_j w_j   [C_j(s) cos theta_j e_j + S_j(s) sin theta_j y]    the water's velocity
    a   = sum_j a_j w_j^2 [C_j(s) sin theta_j e_j - S_j(s) cos theta_j y]    its local acceleration du/dt

C_j(s) = cosh(k_j (s + d)) / sinh(k_j d), S_j(s) = sinh(k_j (s + d)) / sinh(k_j d) (e^(k_j s) both in deep
water), evaluated at the *stretched* height s of the point: Wheeler stretching (DNV-RP-C205 3.2.3) maps the
water column from the seabed to the instantaneous surface, -d <= y <= eta, onto the mean one, s = d (y - eta) /
(d + eta) (s = y - eta in deep water), so that the kinematics at the surface are those linear theory gives at the
mean level, whether under a crest or a trough; ``stretching = "vertical"`` evaluates at s = min(y, 0) instead
(the mean level's kinematics held constant above it). Above the surface a point gets the surface's kinematics
(MoorDyn's convention); how much of them acts is the free surface's business, not this module's.
Each w_j, k_j pair satisfies the finite-depth dispersion relation w^2 = g k tanh(k d) exactly
(:func:`wave_number`, Newton's method to the last bit). A ramp r(t) = (1 - cos(pi t / T)) / 2 over the first
T = ``ramp_time`` seconds (the same ramp as a ``[flow]``'s) scales eta and u, and a = r du/dt + r' u.

Three kinds of component sets:

- regular (:func:`regular_component`): one component, a = H / 2, w = 2 pi / T;
- a spectrum (:func:`spectral_components`), JONSWAP or Pierson-Moskowitz (:func:`spectrum`: Hs, Tp, gamma), cut
  into J components **evenly spaced in wave number** over a frequency range, each carrying its bin's variance,
  a_j = sqrt(2 S(w_j) dw_j) with dw_j the bin's width in frequency, and a random phase drawn from a seed
  (NumPy's PCG64). Even wave-number spacing has two uses: the frequencies, w_j = w(k_j) by the dispersion
  relation, are incommensurate, so the record does not repeat (evenly spaced frequencies repeat every
  2 pi / dw), and the phases along the sea, k_j x = k_0 x + j dk x, follow a recurrence: the kinematics at a
  node cost two sines, two cosines and four exponentials, then a complex multiplication per component;
- a table (:func:`table_components`): the user's components (amplitude, frequency, phase, direction), any
  frequencies and directions.

:class:`WaveField` evaluates the formulas with NumPy, component by component (the reference: the tests, the
viewer's drawn surface, a body's outputs). The compiled kernels (:func:`node_kinematics`, :func:`water_at`, and
:func:`surface_at` for the saved frames' surface, the probes and the pictures) evaluate the same formulas from
the tables :func:`compiled_tables` makes.

**Cost.** The time factors e^(i (phi_j - w_j t)) are computed once per time (J sines and cosines, cached, so
every node and every Newton iteration at that time shares them: :func:`time_factors`). For a spectrum the node's
spatial factors e^(i k_j x'), e^(k_j s) and e^(-k_j (s + 2 d)) are powers of one per node, advanced by a
multiplication per component, vectorised over the nodes (:func:`node_kinematics`); nothing per node and
component calls a sine, a cosine or an exponential. A table or a regular wave evaluates each component directly.
The numbers depend only on the positions and the time, never on what was computed before: a run gives the
same trajectory however it is cut into chunks and resumed.

Compiled tables: ``comps`` (COMP_ROWS, J), one column per component (the row names below); ``scalars``
(WAVE_SCALARS,), the field's constants and the time factors' clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import jit
from .ramp import ramp, ramp_rate

BREAKING_STEEPNESS = 1.0 / 7.0   # H / L above which a wave breaks (Michell 1893; DNV-RP-C205 3.4.6)
JONSWAP_SIGMA = (0.07, 0.09)     # the peak's width below and above w_p (DNV-RP-C205 3.5.5)
DEEP = math.inf

# rows of the compiled components table (COMP_ROWS, J)
AMP, OMEGA, K, PHASE, COS_DIR, SIN_DIR, DEPTH_FACTOR, TIME_COS, TIME_SIN = range(9)
COMP_ROWS = 9
# the field's compiled scalars (WAVE_SCALARS,)
(LEVEL, DEPTH, GRAVITY, RAMP_TIME, STRETCHING, MODE, K0, DK, DIR_COS, DIR_SIN, TIME_CLOCK, TIME_VALID) = range(12)
WAVE_SCALARS = 12
DIRECT, RECURRENCE = 1, 2        # MODE: each component evaluated directly, or the even-wave-number recurrence
WHEELER, VERTICAL = 1.0, 0.0
STRETCHINGS = {"wheeler": WHEELER, "vertical": VERTICAL}


# ------------------------------------------------------------------------------ dispersion and spectra


def wave_number(omega, depth: float = DEEP, g: float = 9.80665):
    """The wave number k [1/m] of waves of angular frequency ``omega`` [rad/s] on water ``depth`` [m] deep:
    the root of w^2 = g k tanh(k d), by Newton's method from Eckart's approximation until it stops changing
    (relative residual ~1e-16). Deep water (inf): w^2 / g. Vectorised over ``omega``."""
    w = np.asarray(omega, dtype=float)
    deep = w * w / g
    if math.isinf(depth):
        return deep
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(deep * depth > 0, deep / np.sqrt(np.tanh(deep * depth)), 0.0)   # Eckart (1952), within 5 %
    for _ in range(50):
        th = np.tanh(k * depth)
        f = g * k * th - w * w
        df = g * th + g * k * depth * (1.0 - th * th)
        step = np.where(df > 0, f / np.where(df > 0, df, 1.0), 0.0)
        k = k - step
        if np.all(np.abs(step) <= 4e-16 * np.abs(k)):
            break
    return k


def angular_frequency(k, depth: float = DEEP, g: float = 9.80665):
    """w = sqrt(g k tanh(k d)) [rad/s] of wave number ``k`` [1/m] (the dispersion relation, explicitly)."""
    k = np.asarray(k, dtype=float)
    return np.sqrt(g * k) if math.isinf(depth) else np.sqrt(g * k * np.tanh(k * depth))


def dnv_gamma(hs: float, tp: float) -> float:
    """DNV-RP-C205's peak enhancement factor for a JONSWAP sea (3.5.5.5): 5 for Tp / sqrt(Hs) <= 3.6,
    exp(5.75 - 1.15 Tp / sqrt(Hs)) up to 5, 1 (Pierson-Moskowitz) beyond."""
    ratio = tp / math.sqrt(hs)
    if ratio <= 3.6:
        return 5.0
    return math.exp(5.75 - 1.15 * ratio) if ratio < 5.0 else 1.0


def _pm_shape(u):
    """Pierson-Moskowitz's shape in u = w / w_p, 5 u^-5 exp(-5/4 u^-4), whose integral over u is 1."""
    u = np.asarray(u, dtype=float)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        out = 5.0 * u ** -5 * np.exp(-1.25 * u ** -4)
    return np.where(u > 0, out, 0.0)


def _enhancement(u, gamma: float):
    sigma = np.where(np.asarray(u) <= 1.0, JONSWAP_SIGMA[0], JONSWAP_SIGMA[1])
    return gamma ** np.exp(-0.5 * ((np.asarray(u) - 1.0) / sigma) ** 2)


def jonswap_normalisation(gamma: float) -> float:
    """The factor A that makes A S_PM(w) gamma^r(w) integrate to S_PM's variance exactly (DNV's approximation
    1 - 0.287 ln gamma is within 2 % of it for gamma up to 7): 1 / (1 + integral of S_PM (gamma^r - 1)), the
    correction computed by Simpson's rule over the peak, where gamma^r - 1 is above 1e-20."""
    if gamma == 1.0:
        return 1.0
    u = np.linspace(0.05, 1.95, 38001)
    f = _pm_shape(u) * (_enhancement(u, gamma) - 1.0)
    h = u[1] - u[0]
    extra = h / 3.0 * (f[0] + f[-1] + 4.0 * f[1:-1:2].sum() + 2.0 * f[2:-1:2].sum())
    return 1.0 / (1.0 + extra)


def spectrum(omega, hs: float, tp: float, gamma: float = 1.0):
    """The one-sided wave spectrum S(w) [m^2 s / rad] at ``omega`` [rad/s]: JONSWAP with peak enhancement
    ``gamma`` (1: Pierson-Moskowitz), significant height ``hs`` [m] and peak period ``tp`` [s] (DNV-RP-C205
    3.5.5), normalised so that its variance, the integral of S over all frequencies, is hs^2 / 16 exactly."""
    wp = 2.0 * math.pi / tp
    u = np.asarray(omega, dtype=float) / wp
    return hs * hs / 16.0 / wp * _pm_shape(u) * _enhancement(u, gamma) * jonswap_normalisation(gamma)


# --------------------------------------------------------------------------------------- the components


@dataclass(frozen=True)
class Components:
    """A sea's components (J,): amplitude [m], angular frequency [rad/s], wave number [1/m], phase [rad],
    direction [rad]; ``spacing`` the wave-number step dk of a spectrum's evenly spaced components (their k_j
    are k_0 + j dk exactly), None for any other set."""

    amplitude: np.ndarray
    omega: np.ndarray
    k: np.ndarray
    phase: np.ndarray
    direction: np.ndarray
    spacing: float | None = None

    @property
    def count(self) -> int:
        return len(self.amplitude)


def default_range(tp: float) -> tuple[float, float]:
    """A spectrum's default frequency range [rad/s]: half to three times the peak frequency (a JONSWAP sea
    with gamma = 3.3 keeps 99.0 % of its variance there, a Pierson-Moskowitz one 98.5 %)."""
    wp = 2.0 * math.pi / tp
    return 0.5 * wp, 3.0 * wp


def spectral_components(hs: float, tp: float, gamma: float, count: int, frequency_range, depth: float, g: float,
                        seed: int, direction: float) -> Components:
    """``count`` components of the spectrum, evenly spaced in wave number over ``frequency_range`` [rad/s]
    (see the module doc), with phases from ``seed`` and one ``direction`` [rad]."""
    lo, hi = frequency_range
    k_lo, k_hi = (float(k) for k in wave_number(np.array([lo, hi]), depth, g))
    dk = (k_hi - k_lo) / count
    k0 = k_lo + 0.5 * dk
    k = k0 + dk * np.arange(count)
    omega = angular_frequency(k, depth, g)
    edges = angular_frequency(k_lo + dk * np.arange(count + 1), depth, g)
    width = np.diff(edges)
    amplitude = np.sqrt(2.0 * spectrum(omega, hs, tp, gamma) * width)
    phase = np.random.default_rng(seed).uniform(0.0, 2.0 * math.pi, count)
    return Components(amplitude, omega, k, phase, np.full(count, direction), dk)


def regular_component(height: float, period: float, phase: float, direction: float, depth: float,
                      g: float) -> Components:
    """An Airy wave of ``height`` H [m] and ``period`` [s]: one component of amplitude H / 2."""
    omega = np.array([2.0 * math.pi / period])
    return Components(np.array([0.5 * height]), omega, wave_number(omega, depth, g), np.array([phase]),
                      np.array([direction]))


def table_components(rows, depth: float, g: float) -> Components:
    """The user's components: rows (amplitude [m], angular frequency [rad/s], phase [deg], direction [deg])."""
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    return Components(rows[:, 0].copy(), rows[:, 1].copy(), wave_number(rows[:, 1], depth, g),
                      np.radians(rows[:, 2]), np.radians(rows[:, 3]))


def components_of(waves, depth: float, g: float) -> Components:
    """The components of a scene's ``[waves]`` (a resolved :class:`ropesim.scene.schema.Waves`) on water ``depth``
    [m] deep under gravity ``g`` [m/s^2]."""
    direction = math.radians(waves.direction)
    if waves.kind == "regular":
        return regular_component(waves.height, waves.period, math.radians(waves.phase), direction, depth, g)
    if waves.kind == "table":
        return table_components(waves.table, depth, g)
    gamma = waves.gamma if waves.kind == "jonswap" else 1.0
    return spectral_components(waves.significant_height, waves.peak_period, gamma, waves.components,
                               waves.frequency_range, depth, g, waves.seed, direction)


def water_depth(scene) -> float:
    """The depth [m] a scene's waves feel: ``sea.depth``, else the mean level above the seabed, else deep water
    (inf)."""
    sea = scene.sea
    if sea.depth is not None:
        return sea.depth
    if scene.seabed is not None:
        return sea.level - scene.seabed.height
    return DEEP


def wave_field(scene) -> "WaveField | None":
    """A scene's waves (None without ``[sea]`` and ``[waves]``)."""
    if scene.sea is None or scene.waves is None:
        return None
    depth, g = water_depth(scene), scene.gravity.g
    return WaveField(components_of(scene.waves, depth, g), scene.sea.level, depth, g, scene.waves.ramp_time,
                     scene.waves.stretching)


def steepest(components: Components) -> tuple[float, int]:
    """(largest H / L = 2 a k / (2 pi) of any component, its index)."""
    steep = components.amplitude * components.k / math.pi
    j = int(np.argmax(steep))
    return float(steep[j]), j


# ---------------------------------------------------------------------------- NumPy: the reference


@dataclass(frozen=True)
class WaveField:
    """A sea's waves for NumPy: its components, the mean level [m], depth [m] (inf: deep), g, ramp time [s]
    and stretching ("wheeler" or "vertical"). The tests, the viewer's surface and a body's outputs evaluate
    it; the compiled kernels evaluate the same formulas (module doc)."""

    components: Components
    level: float
    depth: float
    g: float
    ramp_time: float = 0.0
    stretching: str = "wheeler"

    def _ramp(self, t):
        t = np.asarray(t, dtype=float)
        T = self.ramp_time
        if T <= 0.0:
            return np.ones_like(t), np.zeros_like(t)
        inside = (t > 0) & (t < T)
        r = np.where(t >= T, 1.0, np.where(inside, 0.5 * (1.0 - np.cos(np.pi * t / T)), 0.0))
        rate = np.where(inside, 0.5 * np.pi / T * np.sin(np.pi * t / T), 0.0)
        return r, rate

    def _phases(self, x, z, t):
        c = self.components
        x, z, t = (np.asarray(a, dtype=float)[..., None] for a in (x, z, t))
        return c.k * (x * np.cos(c.direction) - z * np.sin(c.direction)) - c.omega * t + c.phase

    def elevation(self, x, t, z=0.0):
        """The surface's height above the mean level [m] at horizontal positions (x, z) [m] and times t [s]
        (broadcast together), the ramp included."""
        theta = self._phases(x, z, t)
        return self._ramp(t)[0] * (self.components.amplitude * np.cos(theta)).sum(axis=-1)

    def stretched(self, y, eta):
        """The height s [m] below the mean level at which a point at height y (above the mean level) is
        evaluated when the surface is at eta (see the module doc); at most 0, at least -d."""
        y, eta = np.asarray(y, dtype=float), np.asarray(eta, dtype=float)
        if self.stretching == "vertical":
            s = y
        elif math.isinf(self.depth):
            s = y - eta
        else:
            s = self.depth * (y - eta) / (self.depth + eta)
        return np.clip(s, -self.depth, 0.0)

    def kinematics(self, x, y, t, z=0.0):
        """(eta (...,), velocity (..., 3), acceleration (..., 3)) at points (x, y, z) [m] (y measured from the
        mean level) and times t [s], broadcast together, the ramp included; the module doc's formulas."""
        c = self.components
        theta = self._phases(x, z, t)
        r, rate = self._ramp(t)
        eta = r * (c.amplitude * np.cos(theta)).sum(axis=-1)
        s = self.stretched(y, eta)[..., None]
        if math.isinf(self.depth):
            C = S = np.exp(c.k * s)
        else:
            e1, e2 = np.exp(c.k * s), np.exp(-c.k * (s + 2.0 * self.depth))
            scale = -1.0 / np.expm1(-2.0 * c.k * self.depth)
            C, S = (e1 + e2) * scale, (e1 - e2) * scale
        aw = c.amplitude * c.omega
        cos, sin = np.cos(theta), np.sin(theta)
        ex, ez = np.cos(c.direction), -np.sin(c.direction)
        u = np.stack([(aw * C * cos * ex).sum(axis=-1), (aw * S * sin).sum(axis=-1),
                      (aw * C * cos * ez).sum(axis=-1)], axis=-1)
        du = np.stack([(aw * c.omega * C * sin * ex).sum(axis=-1), -(aw * c.omega * S * cos).sum(axis=-1),
                       (aw * c.omega * C * sin * ez).sum(axis=-1)], axis=-1)
        return eta, u * r[..., None], du * r[..., None] + u * rate[..., None]


def orbital_speed(field: WaveField) -> float:
    """The water's largest speed [m/s] under the waves, at the mean level: sum_j a_j w_j coth(k_j d), or for many
    components four times its standard deviation (a 3-hour sea's largest, about), whichever is smaller."""
    c = field.components
    speed = c.amplitude * c.omega / (1.0 if math.isinf(field.depth) else np.tanh(c.k * field.depth))
    return float(min(speed.sum(), 4.0 * math.sqrt(0.5 * float((speed * speed).sum()))))


def recurrence(components: Components) -> bool:
    """Whether the compiled kernels evaluate ``components`` by the recurrence (a spectrum's evenly spaced wave
    numbers, one direction) rather than each component directly (module doc)."""
    c = components
    return c.spacing is not None and c.count > 0 and bool(np.all(c.direction == c.direction[0]))


def compiled_tables(field: WaveField) -> tuple[np.ndarray, np.ndarray]:
    """The compiled kernels' tables of ``field``: its scalars (WAVE_SCALARS,) and its components (COMP_ROWS, J)
    (module doc). A spectrum's evenly spaced wave numbers select the recurrence, any other set direct
    evaluation."""
    c = field.components
    out = np.zeros(WAVE_SCALARS)
    out[LEVEL], out[DEPTH], out[GRAVITY] = field.level, field.depth, field.g
    out[RAMP_TIME] = field.ramp_time
    out[STRETCHING] = STRETCHINGS[field.stretching]
    uniform = recurrence(c)
    out[MODE] = RECURRENCE if uniform else DIRECT
    k = c.k
    if uniform:
        out[K0], out[DK] = c.k[0], c.spacing
        out[DIR_COS], out[DIR_SIN] = math.cos(c.direction[0]), math.sin(c.direction[0])
        k = c.k[0] + c.spacing * np.arange(c.count)   # exactly what the recurrence computes
    comps = np.zeros((COMP_ROWS, c.count))
    comps[AMP], comps[OMEGA], comps[K], comps[PHASE] = c.amplitude, c.omega, k, c.phase
    comps[COS_DIR], comps[SIN_DIR] = np.cos(c.direction), np.sin(c.direction)
    comps[DEPTH_FACTOR] = 1.0 if math.isinf(field.depth) else -1.0 / np.expm1(-2.0 * k * field.depth)
    return out, comps


# ------------------------------------------------------------------------------------------ compiled


@jit.kernel
def time_factors(scalars, comps, t):
    """Each component's e^(i (phi_j - w_j t)) into comps' TIME_COS and TIME_SIN rows, unless they hold time t
    already (the cache's clock is in ``scalars``): J sines and cosines per time, shared by every node."""
    if scalars[TIME_VALID] == 1.0 and scalars[TIME_CLOCK] == t:
        return
    for j in range(comps.shape[1]):
        psi = comps[PHASE, j] - comps[OMEGA, j] * t
        comps[TIME_COS, j] = math.cos(psi)
        comps[TIME_SIN, j] = math.sin(psi)
    scalars[TIME_CLOCK] = t
    scalars[TIME_VALID] = 1.0


@jit.kernel(inline="always")
def stretched_height(y, eta, scalars):
    """The height s at which a point y above the mean level is evaluated (module doc), in [-d, 0]."""
    d = scalars[DEPTH]
    if scalars[STRETCHING] == WHEELER:
        s = y - eta if d == DEEP else d * (y - eta) / (d + eta)
    else:
        s = y
    if s > 0.0:
        s = 0.0
    if s < -d:
        s = -d
    return s


@jit.kernel
def water_at(px, py, pz, t, scalars, comps):
    """The waves at one point (px, py, pz) [m] (py the height, from the origin) and time t [s]: (eta, ux, uy,
    uz, ax, ay, az), the surface elevation above the mean level [m], the water's velocity [m/s] and its
    acceleration [m/s^2], the ramp included (module doc). Each component evaluated directly."""
    time_factors(scalars, comps, t)
    d = scalars[DEPTH]
    eta = 0.0
    for j in range(comps.shape[1]):
        xp = px * comps[COS_DIR, j] - pz * comps[SIN_DIR, j]
        theta = comps[K, j] * xp
        eta += comps[AMP, j] * (math.cos(theta) * comps[TIME_COS, j] - math.sin(theta) * comps[TIME_SIN, j])
    r = ramp(t, scalars[RAMP_TIME])
    rate = ramp_rate(t, scalars[RAMP_TIME])
    eta *= r
    s = stretched_height(py - scalars[LEVEL], eta, scalars)
    uh0 = uh2 = uy = ah0 = ah2 = ay = 0.0
    for j in range(comps.shape[1]):
        k = comps[K, j]
        theta = k * (px * comps[COS_DIR, j] - pz * comps[SIN_DIR, j])
        c, sn = math.cos(theta), math.sin(theta)
        co = c * comps[TIME_COS, j] - sn * comps[TIME_SIN, j]
        si = sn * comps[TIME_COS, j] + c * comps[TIME_SIN, j]
        e1 = math.exp(k * s)
        e2 = 0.0 if d == DEEP else math.exp(-k * (s + 2.0 * d))
        big_c = (e1 + e2) * comps[DEPTH_FACTOR, j]
        big_s = (e1 - e2) * comps[DEPTH_FACTOR, j]
        aw = comps[AMP, j] * comps[OMEGA, j]
        aww = aw * comps[OMEGA, j]
        h = aw * big_c * co
        g = aww * big_c * si
        uh0 += h * comps[COS_DIR, j]
        uh2 -= h * comps[SIN_DIR, j]
        ah0 += g * comps[COS_DIR, j]
        ah2 -= g * comps[SIN_DIR, j]
        uy += aw * big_s * si
        ay -= aww * big_s * co
    return (eta, r * uh0, r * uy, r * uh2, r * ah0 + rate * uh0, r * ay + rate * uy, r * ah2 + rate * uh2)


SURFACE_ROWS = 4
"""Scratch rows per point of :func:`surface_at`."""


@jit.kernel
def surface_at(t, px, pz, scalars, comps, work, out):
    """The surface's elevation above the mean level [m], the ramp included, at points (px, pz) [m] and times t
    [s] (three 1-D arrays of one length P) into ``out``; ``work`` (SURFACE_ROWS, P) is scratch. The surface the
    forces see, by the same arithmetic (:func:`recurrence_kinematics`' first loop for a spectrum, vectorised over
    each run of points at one time, as there over the nodes; :func:`water_at`'s for any other set), so a
    frame's surface is bit for bit the one its forces were computed under. A run of points at one time shares
    that time's factors (:func:`time_factors`)."""
    recur = scalars[MODE] == RECURRENCE
    k0, dk, cb, sb = scalars[K0], scalars[DK], scalars[DIR_COS], scalars[DIR_SIN]
    c, s, cr, sr = work[0], work[1], work[2], work[3]
    total = t.shape[0]
    first = 0
    while first < total:
        now = t[first]
        end = first + 1
        while end < total and t[end] == now:
            end += 1
        time_factors(scalars, comps, now)
        r = ramp(now, scalars[RAMP_TIME])
        if recur:
            for p in range(first, end):
                xp = px[p] * cb - pz[p] * sb
                c[p], s[p] = math.cos(k0 * xp), math.sin(k0 * xp)
                cr[p], sr[p] = math.cos(dk * xp), math.sin(dk * xp)
                out[p] = 0.0
            for j in range(comps.shape[1]):
                amp, tc, ts = comps[AMP, j], comps[TIME_COS, j], comps[TIME_SIN, j]
                for p in range(first, end):
                    cp, sp = c[p], s[p]
                    out[p] += amp * (cp * tc - sp * ts)
                    c[p] = cp * cr[p] - sp * sr[p]
                    s[p] = cp * sr[p] + sp * cr[p]
        else:
            for p in range(first, end):
                eta = 0.0
                for j in range(comps.shape[1]):
                    theta = comps[K, j] * (px[p] * comps[COS_DIR, j] - pz[p] * comps[SIN_DIR, j])
                    eta += comps[AMP, j] * (math.cos(theta) * comps[TIME_COS, j]
                                            - math.sin(theta) * comps[TIME_SIN, j])
                out[p] = eta
        for p in range(first, end):
            out[p] *= r
        first = end


NODE_ROWS = 13
"""Scratch rows per node of :func:`node_kinematics` (see there)."""
(W_C, W_S, W_CR, W_SR, W_E1, W_R1, W_E2, W_R2, W_UH, W_UY, W_AH, W_AY, W_XP) = range(NODE_ROWS)


@jit.kernel
def node_kinematics(x, t, scalars, comps, work, out):
    """The waves at every node of ``x`` (D, N) at time t [s] into ``out`` (7, N): rows eta, u (3), a (3), as
    :func:`water_at` gives them for one point; ``work`` (NODE_ROWS, N) is scratch. A spectrum's evenly spaced
    wave numbers (scalars' MODE) take the recurrence (:func:`recurrence_kinematics`), any other set each
    component directly (:func:`direct_kinematics`). The free surface's kernel calls the one its scene's waves
    take (compiling only that one); this one chooses at run time."""
    if scalars[MODE] != RECURRENCE:
        direct_kinematics(x, t, scalars, comps, out)
    else:
        recurrence_kinematics(x, t, scalars, comps, work, out)


@jit.kernel
def direct_kinematics(x, t, scalars, comps, out):
    """:func:`node_kinematics` with each component evaluated directly, node by node (:func:`water_at`)."""
    dim, n = x.shape
    for i in range(n):
        z = x[2, i] if dim == 3 else 0.0
        e, u0, u1, u2, a0, a1, a2 = water_at(x[0, i], x[1, i], z, t, scalars, comps)
        out[0, i] = e
        out[1, i] = u0
        out[2, i] = u1
        out[3, i] = u2
        out[4, i] = a0
        out[5, i] = a1
        out[6, i] = a2


@jit.kernel
def recurrence_kinematics(x, t, scalars, comps, work, out):
    """:func:`node_kinematics` for a spectrum's evenly spaced wave numbers: the recurrence of the module doc,
    vectorised over the nodes: per node two sines, two cosines and four exponentials, per node and component a
    complex multiplication."""
    dim, n = x.shape
    time_factors(scalars, comps, t)
    k0, dk, d = scalars[K0], scalars[DK], scalars[DEPTH]
    cb, sb = scalars[DIR_COS], scalars[DIR_SIN]
    r = ramp(t, scalars[RAMP_TIME])
    rate = ramp_rate(t, scalars[RAMP_TIME])
    c, s, cr, sr = work[W_C], work[W_S], work[W_CR], work[W_SR]
    e1, r1, e2, r2 = work[W_E1], work[W_R1], work[W_E2], work[W_R2]
    uh, uy, ah, ay, xp = work[W_UH], work[W_UY], work[W_AH], work[W_AY], work[W_XP]
    eta = out[0]
    for i in range(n):
        xp[i] = x[0, i] * cb - (x[2, i] * sb if dim == 3 else 0.0)
        c[i] = math.cos(k0 * xp[i])
        s[i] = math.sin(k0 * xp[i])
        cr[i] = math.cos(dk * xp[i])
        sr[i] = math.sin(dk * xp[i])
        eta[i] = 0.0
    for j in range(comps.shape[1]):   # the surface: sum_j a_j cos(k_j x' + psi_j)
        amp, tc, ts = comps[AMP, j], comps[TIME_COS, j], comps[TIME_SIN, j]
        for i in range(n):
            ci, si = c[i], s[i]
            eta[i] += amp * (ci * tc - si * ts)
            c[i] = ci * cr[i] - si * sr[i]
            s[i] = ci * sr[i] + si * cr[i]
    level = scalars[LEVEL]
    deep = d == DEEP
    for i in range(n):
        eta[i] *= r
        h = stretched_height(x[1, i] - level, eta[i], scalars)
        c[i] = math.cos(k0 * xp[i])
        s[i] = math.sin(k0 * xp[i])
        e1[i] = math.exp(k0 * h)
        r1[i] = math.exp(dk * h)
        e2[i] = 0.0 if deep else math.exp(-k0 * (h + 2.0 * d))
        r2[i] = 1.0 if deep else math.exp(-dk * (h + 2.0 * d))
        uh[i] = uy[i] = ah[i] = ay[i] = 0.0
    for j in range(comps.shape[1]):   # the kinematics, the spatial factors advanced by one component
        aw = comps[AMP, j] * comps[OMEGA, j]
        aww = aw * comps[OMEGA, j]
        tc, ts, depth_factor = comps[TIME_COS, j], comps[TIME_SIN, j], comps[DEPTH_FACTOR, j]
        for i in range(n):
            ci, si, p, q = c[i], s[i], e1[i], e2[i]
            co = ci * tc - si * ts
            sn = si * tc + ci * ts
            big_c = (p + q) * depth_factor
            big_s = (p - q) * depth_factor
            uh[i] += aw * big_c * co
            uy[i] += aw * big_s * sn
            ah[i] += aww * big_c * sn
            ay[i] -= aww * big_s * co
            c[i] = ci * cr[i] - si * sr[i]
            s[i] = ci * sr[i] + si * cr[i]
            e1[i] = p * r1[i]
            e2[i] = q * r2[i]
    ex, ez = cb, -sb
    for i in range(n):
        out[1, i] = r * uh[i] * ex
        out[2, i] = r * uy[i]
        out[3, i] = r * uh[i] * ez
        out[4, i] = r * ah[i] * ex + rate * uh[i] * ex
        out[5, i] = r * ay[i] + rate * uy[i]
        out[6, i] = r * ah[i] * ez + rate * uh[i] * ez
