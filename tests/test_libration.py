"""Librations of every amplitude about a stable equilibrium, against independent references.

Issue 9: nudging the Oloid at a stable equilibrium raised, and at 7e-6 rad the table method
was 1.5 % of the amplitude off. Here both methods run from amplitude 0 (rest) to just below
the separatrix, started by a displacement at rest and by a velocity kick at the equilibrium,
for the Oloid (θ = ±π/2 stable, b² − 2a² + 2Δ² < 0) and a body of the other family
(θ = 0 and the turning points stable).

The error is measured on the displacement δ = u − u* (``sol.displacement``), relative to the
amplitude A: u itself is rounded to its ulp (1.1e-16 rad at u* = 0.85), which alone is 1e-4
of A = 1e-12. The references are written here, sharing no code with the package's solvers:

* A ≤ 1e-9 rad: the linearised motion δ = δ₀ cos ωt + (δ̇₀/ω) sin ωt, ω = √(V″/m), whose
  nonlinear correction (~ A² V‴/V″) is below 1e-9 A;
* 1e-9 < A < 1e-3: DOP853 (rtol 1e-13) on m(δ) δ̈ + ½ m′(δ) δ̇² + V′(δ) = 0 with V′ cubic and
  m quadratic in δ, the Taylor coefficients from finite differences of the closed forms
  (truncation ~ A³ relative: ≤ 1e-12 A);
* A ≥ 1e-3: DOP853 (rtol 1e-13, atol 1e-16 A) on the same equation in δ with the closed
  forms (V′ by complex step of z_G, m) through degree-160 Chebyshev interpolants over the
  whole well, m′ their derivative: the interpolants' tails are below 1e-14 and the
  rounding of V′ (~1e-16 J/rad) is below 1e-12 of V″ A there.

V″ is taken from a 7-point difference of the complex-step V′ (h = 2e-3: truncation ~1e-14,
rounding ~1e-13 relative).
"""

import functools
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from numpy.polynomial import chebyshev
from scipy.integrate import solve_ivp

from rounding import ulps
from twodisk_ros.physics import EllipseBody, RollingDynamics, simulate, simulate_phase
from twodisk_ros.physics.mass.models import laminae

MASS, GRAVITY = 1.0, 9.81
BODIES = {'oloid': (0.1, 0.1, 0.05),          # θ = ±π/2 stable
          'fat': (0.1, 0.2, 0.03)}             # b² − 2a² + 2Δ² > 0: θ = 0 stable
METHODS = ('table', 'direct')
AMPLITUDES = [0.0, 1e-12, 1e-9, 1e-7, 7e-6, 1e-4, 1e-2, 0.3]
#: energies below the barrier (× M g L) of the near-separatrix cases
BELOW_BARRIER = [1e-3, 1e-5]
#: max |δ − δ_ref| / A over three small-oscillation periods (the issue's requirement)
ERROR_MAX = 1e-9
#: the same, table method at 1e-5 M g L below the barrier (see the test)
SEPARATRIX_TABLE_ERROR_MAX = 3e-8
#: ODE tolerance passed to simulate (the table method ignores it but near the separatrix)
TOLERANCE = 1e-12
N_PERIODS, N_SAMPLES = 3, 61


@functools.lru_cache(maxsize=None)
def _dynamics(name):
    abd = BODIES[name]
    return RollingDynamics(EllipseBody(*abd), laminae(*abd, MASS), GRAVITY)


# ----------------------------------------------------------------- the test's own closed forms
def _slope(body, u):
    """V′(u) (J/rad): complex step of the closed form z_G."""
    u = np.asarray(u, dtype=float)
    return MASS * GRAVITY * np.imag(body.phase_height(u + 1e-30j)) / 1e-30


def _stencil_derivative(f, u, h):
    """f′(u) by the 7-point central difference (error ~ h⁶ f⁽⁷⁾/140)."""
    c = (1 / 60, -3 / 20, 3 / 4)
    return sum(ck * (f(u + (3 - i) * h) - f(u - (3 - i) * h)) for i, ck in enumerate(c)) / h


@functools.lru_cache(maxsize=None)
def _well(name):
    """(u*, V″, m0, taylor): u* the first stable phase, Taylor coefficients of V′ and m."""
    dyn = _dynamics(name)
    centre = min(eq.phase for eq, period in dyn.equilibria_with_periods() if period)
    body = dyn.body

    def slope(u):
        return _slope(body, u)

    def mass(u):
        return float(dyn.effective_mass(u))
    k = _stencil_derivative(slope, centre, 2e-3)
    h = 1e-2
    # Taylor coefficients to ~1e-6 relative (they multiply A² or less)
    d2v = _stencil_derivative(lambda x: _stencil_derivative(slope, x, h), centre, h)
    d3v = _stencil_derivative(lambda x: _stencil_derivative(
        lambda y: _stencil_derivative(slope, y, h), x, h), centre, h)
    m0 = mass(centre)
    m1 = _stencil_derivative(mass, centre, h)
    m2 = _stencil_derivative(lambda x: _stencil_derivative(mass, x, h), centre, h)
    return centre, k, m0, (k, d2v / 2, d3v / 6, m0, m1, m2 / 2)


def _taylor_rhs(taylor):
    k, v2, v3, m0, m1, m2 = taylor

    def rhs(t, y):
        d, r = y
        m = m0 + m1 * d + m2 * d * d
        dm = m1 + 2 * m2 * d
        return [r, -(k * d + v2 * d * d + v3 * d**3 + 0.5 * dm * r * r) / m]
    return rhs


@functools.lru_cache(maxsize=None)
def _closed_rhs(name):
    """The equation in δ with m and V′ from the closed forms, through Chebyshev interpolants
    (degree 160, first-kind points) over the whole well, built here: the closed forms are
    analytic there, so the interpolants match them to rounding (tail checked)."""
    dyn = _dynamics(name)
    centre, low, high = dyn.well(_well(name)[0])
    lo, hi = low - centre, high - centre
    x = np.cos((2 * np.arange(161) + 1) * math.pi / 322)
    delta = 0.5 * (hi + lo) + 0.5 * (hi - lo) * x
    slope = chebyshev.chebfit(x, _slope(dyn.body, centre + delta), 160)
    mass = chebyshev.chebfit(x, dyn.effective_mass(centre + delta), 160)
    assert np.max(np.abs(slope[-20:])) < 1e-14 * np.max(np.abs(slope))
    assert np.max(np.abs(mass[-20:])) < 1e-14 * np.max(np.abs(mass))
    dmass = chebyshev.chebder(mass) * 2 / (hi - lo)
    # the three series as the columns of one array, evaluated as T_k(ξ) = cos(k arccos ξ)
    # (one vector operation instead of three 160-step recurrences per right-hand side): the
    # argument's rounding, ≤ k · 4e-16 rad, moves the sums by ≤ 4e-16 Σ k |c_k| ~ 4e-16 of
    # max |dV′/dξ| — 1e-15 V″, below the 1e-12 V″ A budget above by 300× at A = 1e-3
    series = np.stack([mass, np.append(dmass, 0.0), slope], axis=1)
    order = np.arange(161.0)

    def rhs(t, y):
        xi = (2 * y[0] - (hi + lo)) / (hi - lo)
        m, dm, dv = np.cos(order * math.acos(min(1.0, max(-1.0, xi)))) @ series
        return [y[1], -(dv + 0.5 * dm * y[1] ** 2) / m]
    return rhs


@functools.lru_cache(maxsize=None)
def _reference(name, delta0, rate0, t_end, n):
    """(t, δ_ref, δ̇_ref, A): the test's reference displacement from (δ₀, δ̇₀) at u*."""
    centre, k, m0, taylor = _well(name)
    omega = math.sqrt(k / m0)
    t = np.linspace(0.0, t_end, n)
    amplitude = math.hypot(delta0, rate0 / omega)
    if amplitude <= 1e-9:
        return (t, delta0 * np.cos(omega * t) + rate0 / omega * np.sin(omega * t),
                -delta0 * omega * np.sin(omega * t) + rate0 * np.cos(omega * t), amplitude)
    rhs = _taylor_rhs(taylor) if amplitude < 1e-3 else _closed_rhs(name)
    result = solve_ivp(rhs, (0.0, t_end), [delta0, rate0], method='DOP853', rtol=1e-13,
                       atol=[1e-16 * amplitude, 1e-16 * amplitude * omega], t_eval=t)
    assert result.success
    delta = result.y[0]
    return t, delta, result.y[1], float(np.max(np.abs(delta)))


def _barrier_start(name, below):
    """δ₀ > 0 at rest with V(u* + δ₀) = V_barrier − below · M g L (bisection on closed z_G)."""
    dyn = _dynamics(name)
    centre, low, high = dyn.well(_well(name)[0])
    body = dyn.body
    target = body.phase_height(high) - below * body.size
    lo, hi = centre, high
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if body.phase_height(mid) < target else (lo, mid)
    return lo - centre


def _start(name, amplitude, kind):
    """(u0, u̇0, δ₀, δ̇₀): a displacement at rest or a kick at u* of the given amplitude."""
    centre, k, m0, _ = _well(name)
    if kind == 'displacement':
        u0 = centre + amplitude
        return u0, 0.0, u0 - centre, 0.0
    return centre, amplitude * math.sqrt(k / m0), 0.0, amplitude * math.sqrt(k / m0)


def _check(name, method, u0, rate0, delta0, d_rate0, error_max=ERROR_MAX):
    centre, k, m0, _ = _well(name)
    period = 2 * math.pi * math.sqrt(m0 / k)
    t = np.linspace(0.0, N_PERIODS * period, N_SAMPLES)
    motion = simulate_phase(_dynamics(name), t, u0, rate0, method=method, tolerance=TOLERANCE)
    assert motion.sol.centre == centre
    delta, rate = motion.sol.displacement(t)
    if delta0 == 0 and d_rate0 == 0:
        assert motion.solver == 'rest'
        assert np.all(delta == 0) and np.all(rate == 0) and np.all(motion.phase == centre)
        return motion, 0.0
    _, delta_ref, rate_ref, amplitude = _reference(name, delta0, d_rate0, t[-1], len(t))
    error = float(np.max(np.abs(delta - delta_ref))) / amplitude
    rate_error = float(np.max(np.abs(rate - rate_ref))) / (amplitude * 2 * math.pi / period)
    assert error <= error_max, (method, amplitude, error)
    assert rate_error <= 10 * error_max, (method, amplitude, rate_error)
    # u itself is centre + δ, to its rounding (16 ulps of |u|)
    assert np.max(np.abs(motion.phase - (centre + delta))) <= ulps(16, max(1.0, abs(centre)))
    return motion, error


# ------------------------------------------------------------------------------------ tests
def _cases():
    """(name, kind, amplitude, method); direct above the local model's range is DOP853 on
    the closed forms (~4 s a run), so there it runs for one start per body only."""
    for method in METHODS:
        for amplitude in AMPLITUDES:
            for name in BODIES:
                for kind in ('displacement', 'kick'):
                    costly = method == 'direct' and amplitude >= 0.3
                    if not costly or kind == ('displacement' if name == 'oloid' else 'kick'):
                        yield name, kind, amplitude, method


@pytest.mark.parametrize('name, kind, amplitude, method', list(_cases()))
def test_libration_matches_reference(name, kind, amplitude, method):
    u0, rate0, delta0, d_rate0 = _start(name, amplitude, kind)
    motion, _ = _check(name, method, u0, rate0, delta0, d_rate0)
    if amplitude >= 1e-3:
        assert motion.energy_drift <= 1e-11


@pytest.mark.parametrize('name, below, method',
                         [(name, below, 'table') for name in BODIES for below in BELOW_BARRIER]
                         + [('oloid', 1e-3, 'direct'), ('fat', 1e-5, 'direct')])
def test_libration_near_separatrix(name, below, method):
    # At 1e-5 M g L below the barrier the table method integrates the tabulated equation
    # (DOP853, rtol TOLERANCE): the motion near the barrier amplifies both the ODE error and
    # the tables' absolute error of V. Oloid: 1.2e-8 A at rtol 1e-12, 3e-9 A at 1e-13 (the
    # tables' part); direct measures 7.8e-9 A at 1e-12, 8e-11 A at 1e-13. Fat body: ≤ 9e-11 A.
    error_max = SEPARATRIX_TABLE_ERROR_MAX if (method, below) == ('table', 1e-5) else ERROR_MAX
    centre = _well(name)[0]
    delta0 = _barrier_start(name, below)
    motion, _ = _check(name, method, centre + delta0, 0.0, delta0, 0.0, error_max)
    assert motion.energy_drift <= 1e-11
    _, low, high = _dynamics(name).well(centre)
    assert np.all((motion.phase > low) & (motion.phase < high))


@pytest.mark.parametrize('name, method', [('oloid', 'table'), ('fat', 'table'),
                                          ('oloid', 'direct')])
@pytest.mark.parametrize('below', [1e-7, 0.0, -1e-7])
def test_separatrix_band_never_raises(name, method, below):
    # within 1e-6 M g L of the barrier: the ODE branch (table) or DOP853 (direct)
    centre = _well(name)[0]
    delta0 = _barrier_start(name, below) if below > 0 else _dynamics(name).well(centre)[2] \
        - centre
    rate0 = 0.0 if below >= 0 else math.sqrt(2e-7 * _dynamics(name).energy_scale
                                              / _well(name)[2])
    t = np.linspace(0.0, 1.5, 31)
    motion = simulate_phase(_dynamics(name), t, centre + delta0, rate0, method=method)
    assert np.all(np.isfinite(motion.phase)) and motion.energy_drift <= 1e-9


@pytest.mark.parametrize('name', BODIES)
@pytest.mark.parametrize('method', METHODS)
def test_small_amplitude_period(name, method):
    # T → 2π √(m/V″) as A → 0; the shift is O(A²) (~1e-14 at A = 1e-7)
    centre, k, m0, _ = _well(name)
    expected = 2 * math.pi * math.sqrt(m0 / k)
    for amplitude in (1e-12, 1e-7):
        motion = simulate_phase(_dynamics(name), [0.0, 1.0], centre + amplitude, 0.0,
                                method=method)
        assert abs(motion.sol.period / expected - 1) <= 1e-11
    listed = [p for eq, p in _dynamics(name).equilibria_with_periods()
              if p and abs(eq.phase - centre) < 1e-12]
    assert abs(listed[0] / expected - 1) <= 1e-11


@pytest.mark.parametrize('name', BODIES)
@pytest.mark.parametrize('amplitude', [1e-12, 1e-9, 7e-6, 1e-4])
def test_small_libration_conserves_energy(name, amplitude):
    # E − V* from the test's Taylor model, relative to the depth (absolute E is rounding)
    centre, k, m0, (_, v2, v3, _, m1, m2) = _well(name)
    t = np.linspace(0.0, 10.0, 201)
    motion = simulate_phase(_dynamics(name), t, centre + amplitude, 0.0)
    d, r = motion.sol.displacement(t)
    depth = 0.5 * (m0 + m1 * d + m2 * d * d) * r * r + k * d * d / 2 + v2 * d**3 / 3 \
        + v3 * d**4 / 4
    assert np.max(np.abs(depth / depth[0] - 1)) <= 1e-9


@pytest.mark.parametrize('method', METHODS)
@pytest.mark.parametrize('start', [dict(theta0=math.pi / 2, omega0=1e-6),
                                   dict(theta0=1.5707963267948966, omega0=0.0),
                                   dict(theta0=math.pi / 2 - 1e-7, omega0=0.0)])
def test_issue_9_nudged_oloid(method, start):
    dyn = _dynamics('oloid')
    t = np.linspace(0.0, 10.0, 101)
    motion = simulate(dyn, t, method=method, **start)
    assert np.all(np.isfinite(motion.phase))
    centre = dyn.well(motion.phase[0])[0]
    assert np.max(np.abs(motion.phase - centre)) < 1e-5


@pytest.mark.parametrize('method', METHODS)
@pytest.mark.parametrize('omega0', [1e-12, 1e-6, 2.0])
def test_two_circle_roller_rolls_on_at_any_speed(method, omega0):
    abd = (0.1, 0.1, 0.1 / math.sqrt(2.0))
    dyn = RollingDynamics(EllipseBody(*abd), laminae(*abd, MASS), GRAVITY)
    # 4 s: at 2 rad/s the phase advances 6.5 rad, one whole turn of m(u) (a cycle of the body)
    t = np.linspace(0.0, 4.0, 41)
    motion = simulate(dyn, t, omega0=omega0, method=method)
    assert np.all(np.diff(motion.phase) > 0)
    kinetic = 0.5 * dyn.effective_mass(motion.phase) * motion.phase_rate**2
    assert np.max(np.abs(kinetic / kinetic[0] - 1)) <= 1e-9


@settings(max_examples=30, deadline=None)
@given(log_amplitude=st.floats(-14.0, 0.0), sign=st.sampled_from([-1.0, 1.0]),
       kind=st.sampled_from(['displacement', 'kick']), method=st.sampled_from(METHODS),
       name=st.sampled_from(sorted(BODIES)))
def test_any_amplitude_stays_in_the_well(log_amplitude, sign, kind, method, name):
    dyn = _dynamics(name)
    centre, k, m0, _ = _well(name)
    _, low, high = dyn.well(centre)
    if kind == 'displacement':
        reach = (high - centre) if sign > 0 else (centre - low)
        u0, rate0 = centre + sign * min(10.0**log_amplitude, 0.99 * reach), 0.0
        amplitude = abs(u0 - centre)      # exact: u0 is rounded to its ulp
    else:   # below the barrier: ½ m0 u̇² < V_barrier − V*
        barrier = MASS * GRAVITY * (dyn.body.phase_height(high) - dyn.body.phase_height(centre))
        rate0 = sign * min(10.0**log_amplitude * math.sqrt(k / m0),
                           0.99 * math.sqrt(2 * barrier / m0))
        u0 = centre
    t = np.linspace(0.0, 1.5, 31)
    motion = simulate_phase(dyn, t, u0, rate0, method=method)
    assert np.all(np.isfinite(motion.phase)) and np.all(np.isfinite(motion.phase_rate))
    assert np.all((motion.phase >= low) & (motion.phase <= high))
    delta, _ = motion.sol.displacement(t)
    assert np.all(np.isfinite(delta))
    if kind == 'displacement':   # starts at a turning point: never goes beyond it
        assert np.max(sign * delta) <= amplitude * (1 + 1e-9)
