"""Linear wave kinematics (ropesim.model.waves) against closed forms and independent references: the dispersion
relation against scipy's root finder and its deep- and shallow-water limits, Airy's kinematics written out
here, the spectrum's variance by scipy's quadrature, a long irregular record's variance and Welch spectrum,
Wheeler stretching at the crest and the trough, the ramp against a finite difference, and the compiled kernels
against the NumPy reference."""

import math

import numpy as np
import pytest
from scipy import integrate, optimize, signal, stats

from ropesim.model import waves as W

G = 9.80665


def airy(a, omega, k, phase, beta, depth, x, z, s, t):
    """One Airy component at stretched height s written out: (eta, u (3,), du/dt (3,))."""
    theta = k * (x * math.cos(beta) - z * math.sin(beta)) - omega * t + phase
    if math.isinf(depth):
        ch = sh = math.exp(k * s)
    else:
        ch = math.cosh(k * (s + depth)) / math.sinh(k * depth)
        sh = math.sinh(k * (s + depth)) / math.sinh(k * depth)
    e = np.array([math.cos(beta), 0.0, -math.sin(beta)])
    u = a * omega * (ch * math.cos(theta) * e + sh * math.sin(theta) * np.array([0.0, 1.0, 0.0]))
    du = a * omega ** 2 * (ch * math.sin(theta) * e - sh * math.cos(theta) * np.array([0.0, 1.0, 0.0]))
    return a * math.cos(theta), u, du


# --------------------------------------------------------------------------------------------- dispersion


@pytest.mark.parametrize("depth", [0.5, 5.0, 50.0, 300.0, 4000.0])
def test_wave_number_is_the_dispersion_relations_root(depth):
    omega = np.array([0.05, 0.2, 0.6, 1.0, 2.5, 8.0])
    k = W.wave_number(omega, depth, G)
    for w, kk in zip(omega, k):
        ref = optimize.brentq(lambda q: G * q * math.tanh(q * depth) - w * w, 1e-12, 10 * w * w / G + 10 / depth,
                              xtol=1e-300, rtol=4 * np.finfo(float).eps)
        assert kk == pytest.approx(ref, rel=1e-12)
        assert G * kk * math.tanh(kk * depth) == pytest.approx(w * w, rel=1e-12)
    assert np.allclose(W.angular_frequency(k, depth, G), omega, rtol=1e-13, atol=0)


def test_wave_number_limits():
    omega = 1.3
    deep = omega ** 2 / G
    assert W.wave_number(omega, math.inf, G) == pytest.approx(deep, rel=1e-15)
    assert W.wave_number(omega, 1e4, G) == pytest.approx(deep, rel=1e-14)   # k d = 1700: tanh is 1
    # shallow water: w = k sqrt(g d) (1 - (k d)^2 / 6 + ...): the relative error of the long-wave limit is (kd)^2/6
    d = 1e-3
    k = float(W.wave_number(omega, d, G))
    kd = k * d
    assert omega / math.sqrt(G * d) == pytest.approx(k * (1 - kd * kd / 6), rel=kd ** 4)
    assert W.wave_number(0.0, 10.0, G) == 0.0


# ----------------------------------------------------------------------------------------------- spectra


@pytest.mark.parametrize("gamma", [1.0, 2.0, 3.3, 7.0])
def test_spectrum_variance_is_hs_squared_over_16(gamma):
    hs, tp = 6.0, 10.0
    wp = 2 * math.pi / tp
    var = sum(integrate.quad(lambda w: float(W.spectrum(w, hs, tp, gamma)), lo, hi, limit=200, epsabs=1e-13)[0]
              for lo, hi in [(1e-3, 0.8 * wp), (0.8 * wp, 1.2 * wp), (1.2 * wp, 10 * wp), (10 * wp, 400 * wp)])
    assert var == pytest.approx(hs * hs / 16, rel=1e-6)
    # DNV-RP-C205's approximate normalisation 1 - 0.287 ln gamma is within 2 % of the exact one up to gamma = 7
    assert W.jonswap_normalisation(gamma) == pytest.approx(1 - 0.287 * math.log(gamma), rel=0.02)
    # the peak is at w_p
    w = np.linspace(0.5 * wp, 2 * wp, 30001)
    assert w[np.argmax(W.spectrum(w, hs, tp, gamma))] == pytest.approx(wp, rel=1e-4)


def test_spectrum_is_pierson_moskowitz_for_gamma_one():
    hs, tp, w = 3.0, 8.0, np.linspace(0.3, 3.0, 50)
    wp = 2 * math.pi / tp
    pm = 5 / 16 * hs ** 2 * wp ** 4 * w ** -5 * np.exp(-1.25 * (w / wp) ** -4)   # DNV-RP-C205 (3.5.5.4)
    assert np.allclose(W.spectrum(w, hs, tp, 1.0), pm, rtol=1e-14, atol=0)


def test_dnv_gamma():
    assert W.dnv_gamma(6.0, 8.0) == 5.0                                      # Tp / sqrt(Hs) = 3.27
    assert W.dnv_gamma(6.0, 10.0) == pytest.approx(math.exp(5.75 - 1.15 * 10 / math.sqrt(6)))
    assert W.dnv_gamma(1.0, 6.0) == 1.0


@pytest.mark.parametrize("gamma, kept", [(3.3, 0.990), (1.0, 0.985)])
def test_default_range_keeps_most_of_the_variance(gamma, kept):
    hs, tp = 6.0, 10.0
    lo, hi = W.default_range(tp)
    inside = integrate.quad(lambda w: float(W.spectrum(w, hs, tp, gamma)), lo, hi, limit=200)[0]
    assert inside / (hs * hs / 16) == pytest.approx(kept, abs=0.001)


def test_components_carry_their_bins_variance():
    hs, tp, gamma, depth = 6.0, 10.0, 3.3, 50.0
    lo, hi = W.default_range(tp)
    c = W.spectral_components(hs, tp, gamma, 200, (lo, hi), depth, G, seed=7, direction=0.3)
    assert c.count == 200
    assert np.allclose(np.diff(c.k), c.spacing, rtol=1e-9, atol=0)           # evenly spaced in wave number
    assert np.allclose(W.angular_frequency(c.k, depth, G), c.omega, rtol=1e-13, atol=0)
    assert c.omega[0] > lo and c.omega[-1] < hi
    inside = integrate.quad(lambda w: float(W.spectrum(w, hs, tp, gamma)), lo, hi, limit=200)[0]
    assert 0.5 * np.sum(c.amplitude ** 2) == pytest.approx(inside, rel=2e-3)   # midpoint rule over 200 bins
    assert np.all((c.phase >= 0) & (c.phase < 2 * math.pi)) and np.all(c.direction == 0.3)
    again = W.spectral_components(hs, tp, gamma, 200, (lo, hi), depth, G, seed=7, direction=0.3)
    assert np.array_equal(again.phase, c.phase)                                # the seed fixes the phases
    other = W.spectral_components(hs, tp, gamma, 200, (lo, hi), depth, G, seed=8, direction=0.3)
    assert not np.array_equal(other.phase, c.phase)


def test_a_long_irregular_record_has_the_spectrums_variance_and_shape():
    """A 3-hour JONSWAP record sampled at 2 Hz at one place: its variance is sum a_j^2 / 2 (the spectrum's
    integral over the range, 99.0 % of Hs^2 / 16) within the record's statistical error, and Welch's estimate
    of its spectrum lies within the estimator's 99.9 % confidence band of the target in most bins."""
    hs, tp, gamma = 6.0, 10.0, 3.3
    lo, hi = W.default_range(tp)
    c = W.spectral_components(hs, tp, gamma, 400, (lo, hi), math.inf, G, seed=3, direction=0.0)
    field = W.WaveField(c, level=0.0, depth=math.inf, g=G)
    fs, duration = 2.0, 3 * 3600.0
    t = np.arange(0.0, duration, 1 / fs)
    eta = field.elevation(0.0, t)
    target = 0.5 * np.sum(c.amplitude ** 2)
    assert target == pytest.approx(hs * hs / 16 * 0.990, rel=2e-3)
    # the variance of a record of length T of a Gaussian sea has the relative standard error sqrt(2 T_c / T),
    # T_c = integral of rho(t)^2 dt = pi m(S^2) / m(S)^2 its correlation time (7.7 s here): 3.8 %. The
    # components' amplitudes are fixed (only the phases are random), so the record is closer than that.
    m0 = integrate.quad(lambda w: float(W.spectrum(w, hs, tp, gamma)), lo, hi, limit=200)[0]
    m2 = integrate.quad(lambda w: float(W.spectrum(w, hs, tp, gamma)) ** 2, lo, hi, limit=200)[0]
    error = math.sqrt(2 * math.pi * m2 / m0 ** 2 / duration)
    assert np.var(eta) == pytest.approx(target, rel=3 * error)
    assert 4 * math.sqrt(np.var(eta)) == pytest.approx(hs, rel=0.03)
    f, pxx = signal.welch(eta, fs=fs, nperseg=2048)              # one-sided, per Hz
    omega, s_est = 2 * math.pi * f, pxx / (2 * math.pi)            # per rad/s
    band = (omega > 1.1 * lo) & (omega < 0.9 * hi)
    segments = 2 * len(t) // 2048 - 1                             # Hann windows overlapping by half
    dof = 2 * segments * 0.9                                      # about: overlapping segments are correlated
    low, high = stats.chi2.ppf([0.0005, 0.9995], dof) / dof
    ratio = s_est[band] / W.spectrum(omega[band], hs, tp, gamma)
    assert np.mean((ratio > low) & (ratio < high)) > 0.95
    assert np.median(ratio) == pytest.approx(1.0, abs=0.05)


def test_steepest_component():
    c = W.table_components([(0.5, 1.0, 0, 0), (1.0, 2.0, 0, 0)], 20.0, G)
    steep, j = W.steepest(c)
    assert j == 1 and steep == pytest.approx(2 * 1.0 * c.k[1] / (2 * math.pi))


# ------------------------------------------------------------------------------------------- kinematics


@pytest.mark.parametrize("depth", [3.0, 20.0, 200.0, math.inf])
def test_regular_airy_kinematics_match_the_closed_form(depth):
    c = W.regular_component(1.2, 7.0, phase=0.4, direction=0.5, depth=depth, g=G)
    field = W.WaveField(c, level=0.0, depth=depth, g=G, stretching="vertical")
    rng = np.random.default_rng(1)
    for _ in range(20):
        x, z, t = rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(0, 30)
        y = -rng.uniform(0.6, min(depth, 40.0))                  # under the trough: s = y
        eta, u, du = field.kinematics(x, y, t, z)
        e_ref, u_ref, du_ref = airy(0.6, c.omega[0], c.k[0], 0.4, 0.5, depth, x, z, y, t)
        scale = 0.6 * c.omega[0] / math.tanh(c.k[0] * depth) if not math.isinf(depth) else 0.6 * c.omega[0]
        assert eta == pytest.approx(e_ref, abs=1e-14)
        assert np.allclose(u, u_ref, rtol=0, atol=1e-13 * scale)
        assert np.allclose(du, du_ref, rtol=0, atol=1e-13 * scale * c.omega[0])


def test_shallow_water_velocity_is_uniform_in_depth():
    """Long waves (k d << 1): u = eta sqrt(g / d) at every depth, the vertical velocity linear in height."""
    d = 2.0
    c = W.regular_component(0.02, 60.0, 0.0, 0.0, d, G)
    field = W.WaveField(c, level=0.0, depth=d, g=G, stretching="vertical")
    kd = c.k[0] * d
    for y in (-0.1, -1.0, -1.9):
        eta, u, _ = field.kinematics(3.0, y, 0.0)
        assert u[0] == pytest.approx(eta * math.sqrt(G / d), rel=kd ** 2)


def test_wheeler_stretching_at_crest_trough_and_seabed():
    """Under Wheeler stretching the velocity at the instantaneous surface is linear theory's at the mean level,
    under a crest as under a trough, and at the seabed it is linear theory's at the seabed."""
    depth, a = 30.0, 1.5
    c = W.regular_component(2 * a, 9.0, 0.0, 0.0, depth, G)
    w, k = c.omega[0], c.k[0]
    field = W.WaveField(c, level=0.0, depth=depth, g=G)
    for t, sign in ((0.0, 1.0), (math.pi / w, -1.0)):             # crest at x = 0, then a trough
        eta, u, du = field.kinematics(0.0, sign * a, t)
        assert eta == pytest.approx(sign * a, rel=1e-14)
        assert u[0] == pytest.approx(sign * a * w / math.tanh(k * depth), rel=1e-13)   # the mean level's
        assert u[1] == pytest.approx(0.0, abs=1e-13)
        assert du[1] == pytest.approx(-sign * a * w * w, rel=1e-13)
        _, u_bed, _ = field.kinematics(0.0, -depth, t)
        assert u_bed[0] == pytest.approx(sign * a * w / math.sinh(k * depth), rel=1e-13)
        assert u_bed[1] == pytest.approx(0.0, abs=1e-13)
        # halfway between the seabed and the surface: linear theory's at half the depth
        _, u_mid, _ = field.kinematics(0.0, 0.5 * (sign * a - depth), t)
        assert u_mid[0] == pytest.approx(sign * a * w * math.cosh(k * depth / 2) / math.sinh(k * depth), rel=1e-13)
    # above the surface: the surface's kinematics
    assert np.allclose(field.kinematics(0.0, a + 3.0, 0.0)[1], field.kinematics(0.0, a, 0.0)[1], rtol=1e-15)
    # vertical stretching: the mean level's kinematics held above it
    vertical = W.WaveField(c, level=0.0, depth=depth, g=G, stretching="vertical")
    assert vertical.kinematics(0.0, a, 0.0)[1][0] == pytest.approx(a * w / math.tanh(k * depth), rel=1e-13)


def test_irregular_kinematics_are_the_sum_of_their_components():
    """Three components in three directions, summed here one by one at the stretched height of the total
    surface."""
    rows = [(0.4, 0.6, 30.0, 0.0), (0.3, 0.9, 100.0, 40.0), (0.2, 1.4, 250.0, -75.0)]
    depth = 25.0
    c = W.table_components(rows, depth, G)
    field = W.WaveField(c, level=0.0, depth=depth, g=G)
    rng = np.random.default_rng(5)
    for _ in range(20):
        x, z, t, y = rng.uniform(-40, 40), rng.uniform(-40, 40), rng.uniform(0, 60), rng.uniform(-25, 1.0)
        parts = [airy(a, w, k, math.radians(ph), math.radians(b), depth, x, z, 0.0, t)
                 for (a, w, ph, b), k in zip(rows, c.k)]
        eta_ref = sum(p[0] for p in parts)
        s = min(depth * (y - eta_ref) / (depth + eta_ref), 0.0)
        parts = [airy(a, w, k, math.radians(ph), math.radians(b), depth, x, z, s, t)
                 for (a, w, ph, b), k in zip(rows, c.k)]
        eta, u, du = field.kinematics(x, y, t, z)
        assert eta == pytest.approx(eta_ref, abs=1e-14)
        assert np.allclose(u, sum(p[1] for p in parts), rtol=0, atol=1e-13)
        assert np.allclose(du, sum(p[2] for p in parts), rtol=0, atol=1e-13)


def test_ramp_scales_the_waves_and_adds_its_rate():
    """Within the ramp the acceleration is r du/dt + r' u: against a central difference of u in time at a
    point below the troughs (where the stretched height is the point's own)."""
    c = W.regular_component(1.0, 6.0, 0.0, 0.0, 40.0, G)
    field = W.WaveField(c, level=0.0, depth=40.0, g=G, ramp_time=20.0, stretching="vertical")
    x, y = 3.0, -4.0
    for t in (0.5, 7.3, 15.0, 19.9):
        h = 1e-4
        fd = (field.kinematics(x, y, t + h)[1] - field.kinematics(x, y, t - h)[1]) / (2 * h)
        assert np.allclose(field.kinematics(x, y, t)[2], fd, rtol=0, atol=1e-7)
    r = 0.5 * (1 - math.cos(math.pi * 5.0 / 20.0))
    still = W.WaveField(c, level=0.0, depth=40.0, g=G, stretching="vertical")
    assert field.elevation(x, 5.0) == pytest.approx(r * still.elevation(x, 5.0), rel=1e-14)
    assert field.kinematics(x, y, 0.0)[1] == pytest.approx(np.zeros(3))
    assert np.array_equal(field.kinematics(x, y, 25.0)[1], still.kinematics(x, y, 25.0)[1])


# -------------------------------------------------------------------------------------- compiled kernels


def _compiled(field, x, t):
    scalars, comps = W.compiled_tables(field)
    out = np.zeros((7, x.shape[1]))
    W.node_kinematics(x, t, scalars, comps, np.zeros((W.NODE_ROWS, x.shape[1])), out)
    return out, scalars


@pytest.mark.parametrize("kind", ["spectrum", "spectrum_deep", "table"])
@pytest.mark.parametrize("dim", [2, 3])
def test_compiled_kinematics_match_the_reference(kind, dim):
    level = 2.0
    if kind == "table":
        c = W.table_components([(0.4, 0.6, 30.0, 0.0), (0.3, 0.9, 100.0, 0.0 if dim == 2 else 40.0),
                                (0.2, 1.4, 250.0, 180.0)], 25.0, G)
        depth = 25.0
    else:
        depth = math.inf if kind == "spectrum_deep" else 25.0
        c = W.spectral_components(4.0, 9.0, 3.3, 200, W.default_range(9.0), depth, G, seed=2,
                                  direction=0.0 if dim == 2 else 0.7)
    field = W.WaveField(c, level=level, depth=depth, g=G, ramp_time=10.0)
    rng = np.random.default_rng(0)
    n = 64
    x = np.vstack([rng.uniform(-100, 100, n), level + rng.uniform(-24, 4, n)]
                  + ([rng.uniform(-100, 100, n)] if dim == 3 else []))
    for t in (0.0, 3.7, 250.0):
        out, scalars = _compiled(field, x, t)
        assert scalars[W.MODE] == (W.DIRECT if kind == "table" else W.RECURRENCE)
        z = x[2] if dim == 3 else 0.0
        eta, u, du = field.kinematics(x[0], x[1] - level, t, z)
        speed = np.abs(u).max() + 1e-300
        assert np.allclose(out[0], eta, rtol=0, atol=1e-11)
        assert np.allclose(out[1:4].T, u, rtol=0, atol=1e-11 * speed)
        assert np.allclose(out[4:7].T, du, rtol=0, atol=1e-11 * np.abs(du).max() + 1e-300)


@pytest.mark.parametrize("kind", ["spectrum", "table"])
@pytest.mark.parametrize("dim", [2, 3])
def test_the_frames_surface_is_the_forces_own(kind, dim):
    """The saved frames' surface (sea_frames.surface, W.surface_at) is, bit for bit, the eta the compiled forces
    computed at the same nodes and time, and within rounding of the NumPy reference, ramp included, at any mix of
    times and positions, frames in any order."""
    from ropesim.model.sea_frames import surface

    if kind == "table":   # evaluated component by component (two directions in 3-D)
        c = W.table_components([(0.4, 0.6, 30.0, 0.0), (0.3, 0.9, 100.0, 0.0 if dim == 2 else 40.0)], 25.0, G)
    else:
        c = W.spectral_components(4.0, 9.0, 3.3, 200, W.default_range(9.0), 25.0, G, seed=2,
                                  direction=0.0 if dim == 2 else 0.7)
    field = W.WaveField(c, level=0.0, depth=25.0, g=G, ramp_time=10.0)
    rng = np.random.default_rng(3)
    n = 40
    x = np.vstack([rng.uniform(-100, 100, n), rng.uniform(-24, 1, n)] + ([rng.uniform(-100, 100, n)] if dim == 3
                                                                      else []))
    z = x[2] if dim == 3 else np.zeros(n)
    times = np.array([250.0, 0.0, 3.7, 3.7, 11.0])   # frames in any order, one twice
    scalars, comps = W.compiled_tables(field)
    got = np.empty(times.size * n)
    W.surface_at(np.repeat(times, n), np.tile(x[0], times.size), np.tile(z, times.size), scalars, comps,
                 np.empty((W.SURFACE_ROWS, got.size)), got)
    got = got.reshape(times.size, n)
    for k, t in enumerate(times):
        forces, _ = _compiled(field, x, t)
        assert np.array_equal(got[k], forces[0])
        assert np.allclose(got[k], field.elevation(x[0], t, z), rtol=0, atol=1e-12)

    framed = surface(W.compiled_tables(field), times[:, None], x[0][None, :], z[None, :])   # (frames, nodes)
    assert np.array_equal(framed, got)


def test_compiled_time_factors_are_shared_and_exact_after_a_jump():
    """The cached time factors hold one time: a later call at another time recomputes them, and going back gives
    bit for bit what the first call gave (the numbers depend on (x, t) alone)."""
    c = W.spectral_components(2.0, 8.0, 2.0, 50, W.default_range(8.0), 30.0, G, seed=1, direction=0.0)
    field = W.WaveField(c, level=0.0, depth=30.0, g=G)
    x = np.array([[0.0, 10.0, 20.0], [-1.0, -5.0, 0.5]])
    scalars, comps = W.compiled_tables(field)
    work = np.zeros((W.NODE_ROWS, 3))
    first, again, later = np.zeros((7, 3)), np.zeros((7, 3)), np.zeros((7, 3))
    W.node_kinematics(x, 1.5, scalars, comps, work, first)
    W.node_kinematics(x, 9.0, scalars, comps, work, later)
    W.node_kinematics(x, 1.5, scalars, comps, work, again)
    assert np.array_equal(first, again) and not np.array_equal(first, later)
    fresh, _ = _compiled(field, x, 9.0)
    assert np.array_equal(fresh, later)


def test_water_at_one_point_matches_the_reference():
    c = W.regular_component(2.0, 8.0, 0.3, 0.2, 40.0, G)
    field = W.WaveField(c, level=-1.0, depth=40.0, g=G)
    scalars, comps = W.compiled_tables(field)
    got = W.water_at(5.0, -3.0, 2.0, 4.0, scalars, comps)
    eta, u, du = field.kinematics(5.0, -2.0, 4.0, 2.0)
    assert np.allclose(got, np.concatenate([[eta], u, du]), rtol=1e-12, atol=1e-14)


def test_orbital_speed_bounds_the_velocity():
    c = W.regular_component(2.0, 8.0, 0.0, 0.0, 15.0, G)
    field = W.WaveField(c, level=0.0, depth=15.0, g=G)
    t = np.linspace(0, 8, 801)
    peak = np.abs(field.kinematics(0.0, 0.0, t)[1][:, 0]).max()
    assert W.orbital_speed(field) == pytest.approx(peak, rel=1e-4)
