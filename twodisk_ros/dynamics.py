"""Rolling dynamics under gravity: one degree of freedom in the cycle phase u.

With no slip at A and B the body turns about the line AB, so its motion is fixed by u(t)
(physics notes). Kinetic and potential energy (SI units):

    T = ½ m(u) u̇²,   m(u) = ω_uᵀ I_G ω_u + M |ω_u × r1|²,   V(u) = M g z_G(u),

ω_u being the angular velocity per unit u̇ (body frame, rad) and I_G the inertia about G.
Lagrange's equation: m ü + ½ m′ u̇² + V′ = 0; energy E = T + V is conserved.

Two modes: ``dynamic`` (gravity only) and ``kinematic`` (constant angular speed |ω| = Ω, so
u̇ = Ω / |ω_u(u)|). Two methods behind :func:`simulate`:

``direct``
    DOP853 (scipy ``solve_ivp``) with the geometry evaluated on the fly from the closed
    forms; ``tolerance`` is its rtol (atol = tolerance × scale).
``table``
    Periodic tables of one cycle (m, V, |ω_u| with derivatives, spectral to rounding), then:
    when u moves one way for ever (kinematic mode, or rolling over the top: E > max V),
    t(u) = ∫ du/|u̇| is a secular-plus-periodic function, tabulated once and inverted by
    bracketed Newton (no time stepping, no drift); when it oscillates in a well (E < max V),
    the same in the angle φ of V(u(φ)) = V* + (E − V*) sin²φ (see ``_Libration``). Only
    within 1e-6 M g L of the separatrix E = max V is DOP853 run on the tabulated right-hand
    side, with ``tolerance`` as its rtol.

A body exactly at an equilibrium with u̇ = 0 stays there (the exact solution).
"""

from dataclasses import dataclass, field
import math

import numpy as np
from scipy.integrate import solve_ivp

from .body import complex_step, TwoDiskBody
from .cycle import RollingCycle, TWO_PI
from .equilibria import equilibria, STABLE
from .mass_models import MassProperties
from .tables import HermiteTable, spectral_antiderivative, spectral_tail

__all__ = ['RollingDynamics', 'RollingMotion', 'simulate', 'METHODS', 'MODES']

METHODS = ('direct', 'table')
MODES = ('dynamic', 'kinematic')
#: solvers whose motion is known at any time without stepping (RollingMotion.solver)
CLOSED_FORM_SOLVERS = ('quadrature', 'libration', 'rest')

_FD_STEP = 1e-3   # rad: step of the 5-point difference of m(u), times the feature width


def _upsample(samples, factor):
    """Samples of a periodic function on a grid ``factor`` times finer (zero-padded FFT)."""
    n = samples.shape[0]
    coeffs = np.fft.rfft(samples)
    padded = np.zeros(n * factor // 2 + 1, dtype=complex)
    padded[:n // 2] = coeffs[:n // 2]
    padded[n // 2] = 0.5 * coeffs[n // 2]    # split the Nyquist term symmetrically
    return np.fft.irfft(padded, n * factor) * factor


def _spectral_derivative(samples):
    n = samples.shape[0]
    k = np.fft.fftfreq(n, d=1.0 / n).reshape((n,) + (1,) * (samples.ndim - 1))
    return np.real(np.fft.ifft(1j * k * np.fft.fft(samples, axis=0), axis=0))


class RollingDynamics:
    """The equation of motion of one body with one mass model.

    Parameters
    ----------
    body : TwoDiskBody
    mass_properties : MassProperties
        Mass (kg) and inertia about G (kg m², body frame); the centre of mass must be G.
    gravity : float
        g (m/s²), finite and ≥ 0.
    cycle : RollingCycle, optional
        Reused if given (it holds the kinematic tables).
    """

    def __init__(self, body, mass_properties, gravity=9.81, cycle=None):
        if not isinstance(body, TwoDiskBody):
            raise TypeError(f'body must be a TwoDiskBody, got {type(body).__name__}')
        if not isinstance(mass_properties, MassProperties):
            raise TypeError('mass_properties must be a MassProperties')
        gravity = float(gravity)
        if not (math.isfinite(gravity) and gravity >= 0):
            raise ValueError(f'gravity must be finite and >= 0 m/s^2, got {gravity!r}')
        if np.max(np.abs(mass_properties.center_of_mass)) > 1e-9 * body.size:
            raise ValueError('mass_properties.center_of_mass must be G (the origin)')
        self.body = body
        self.mass = mass_properties
        self.gravity = gravity
        self.cycle = cycle if cycle is not None else RollingCycle(body)
        self._feature_width = min(1.0, body.b / body.a, body.a / body.b,
                                  2 * math.sqrt(body.delta / body.a))
        self._build_tables(4 * self.cycle.resolution)
        self._equilibria = None

    # -- closed forms (the direct method) ---------------------------------------------------
    def effective_mass(self, u):
        """m(u) (kg m²/rad²): T = ½ m(u) u̇²."""
        u = np.asarray(u, dtype=float)
        omega = self.body.phase_angular_velocity(u)
        r1 = self.body.phase_geometry(u).contact_a
        v = np.cross(omega, r1)
        inertia = self.mass.inertia
        return (np.einsum('...i,ij,...j->...', omega, inertia, omega)
                + self.mass.mass * np.sum(v * v, axis=-1))

    def angular_speed_per_phase(self, u):
        """|ω_u| (rad of body rotation per rad of u)."""
        return np.linalg.norm(self.body.phase_angular_velocity(u), axis=-1)

    def potential(self, u):
        """V(u) = M g z_G(u) (J)."""
        return self.mass.mass * self.gravity * self.body.phase_height(u)

    def potential_slope(self, u):
        """dV/du (J/rad), by complex step of the closed form."""
        return self.mass.mass * self.gravity * complex_step(self.body.phase_height, u)

    def effective_mass_slope(self, u):
        """dm/du (kg m²/rad³): 5-point difference of :meth:`effective_mass`.

        The step is 1e-3 rad times the width of the sharpest feature of the body's functions
        of u, min(1, b/a, a/b, 2√(Δ/a)) (body module docstring).
        """
        u = np.asarray(u, dtype=float)
        h = _FD_STEP * self._feature_width
        m = [self.effective_mass(u + k * h) for k in (-2, -1, 1, 2)]
        return (m[0] - 8 * m[1] + 8 * m[2] - m[3]) / (12 * h)

    # -- tables (the table method) ----------------------------------------------------------
    def _build_tables(self, n):
        u = TWO_PI * np.arange(n) / n
        m = self.effective_mass(u)
        w = self.angular_speed_per_phase(u)
        v = self.potential(u)
        dv = self.potential_slope(u)
        values = np.column_stack([m, v, w])
        first = np.column_stack([_spectral_derivative(m), dv, _spectral_derivative(w)])
        second = _spectral_derivative(first)
        close = np.concatenate
        self._table = HermiteTable(0.0, TWO_PI / n, close([values, values[:1]]),
                                   close([first, first[:1]]), close([second, second[:1]]))
        # V alone, for the level searches of oscillations (a third of the work)
        self._potential = HermiteTable(0.0, TWO_PI / n, close([v, v[:1]]),
                                       close([dv, dv[:1]]), close([second[:, 1], second[:1, 1]]))
        self._nodes = u
        self.potential_range = (float(v.min()), float(v.max()))

    def tabulated(self, u, derivative=0):
        """(m, V, |ω_u|) at phase(s) u from the tables, shape u.shape + (3,)."""
        u = np.asarray(u, dtype=float)
        return self._table(np.mod(u, TWO_PI), derivative)

    def tabulated_potential(self, u, derivative=0):
        """V(u) (J) or V′(u) (J/rad) from the tables."""
        return self._potential(np.mod(np.asarray(u, dtype=float), TWO_PI), derivative)

    # -- derived quantities -----------------------------------------------------------------
    def energy(self, u, u_dot):
        """E = ½ m(u) u̇² + V(u) (J), from the tables."""
        f = self.tabulated(u)
        return 0.5 * f[..., 0] * np.asarray(u_dot) ** 2 + f[..., 1]

    @property
    def energy_scale(self):
        """M g L (J), L = body size: the scale of relative energy drifts (g → 1 m/s² if g = 0)."""
        g = self.gravity if self.gravity > 0 else 1.0
        return self.mass.mass * g * self.body.size

    def equilibria_with_periods(self):
        """[(Equilibrium, small-oscillation period in s or None)] for all eight equilibria.

        T = 2π √(m(u*) / V″(u*)) at the stable ones (coordinate-free: both in u).
        Computed once per dynamics object.
        """
        if self._equilibria is None:
            result = []
            for eq in equilibria(self.body):
                period = None
                if eq.stability == STABLE and self.gravity > 0:
                    stiffness = self.mass.mass * self.gravity * eq.phase_curvature
                    period = TWO_PI * math.sqrt(float(self.effective_mass(eq.phase)) / stiffness)
                result.append((eq, period))
            self._equilibria = result
        return list(self._equilibria)

    def small_oscillation_periods(self):
        """[(Equilibrium, period in s)] for every stable equilibrium (T = 2π √(m / V″))."""
        return [(eq, period) for eq, period in self.equilibria_with_periods()
                if period is not None]

    def well(self, u):
        """(u*, u_low, u_high): the minimum of V in the well holding phase u, between maxima."""
        found = sorted((eq.phase, eq.stability) for eq, _ in self.equilibria_with_periods())
        maxima = np.array([p for p, kind in found if kind != STABLE])
        minima = np.array([p for p, kind in found if kind == STABLE])
        if len(maxima) == 0 or len(minima) == 0:
            raise RuntimeError('V has no wells (neutral body): no oscillation')
        base = TWO_PI * math.floor(u / TWO_PI)
        edges = np.concatenate([maxima - TWO_PI, maxima, maxima + TWO_PI]) + base
        i = np.searchsorted(edges, u, side='right')
        low, high = edges[i - 1], edges[i]
        centres = np.concatenate([minima - TWO_PI, minima, minima + TWO_PI]) + base
        inside = centres[(centres > low) & (centres < high)]
        return float(inside[0]), float(low), float(high)

    def potential_curvature(self, u):
        """d²V/du² (J/rad²) at an equilibrium phase u (spectral, as in the equilibria)."""
        for eq, _ in self.equilibria_with_periods():
            gap = abs(math.remainder(u - eq.phase, TWO_PI))
            if gap < 1e-9:
                return self.mass.mass * self.gravity * eq.phase_curvature
        raise ValueError(f'u = {u!r} rad is not an equilibrium phase')

    def is_equilibrium(self, u):
        """True if phase u (rad) is one of the equilibria (within 1e-9 rad), or V′(u) vanishes
        there to rounding (z_G constant: the neutral case)."""
        phases = np.array([eq.phase for eq, _ in self.equilibria_with_periods()])
        gap = np.abs(np.remainder(u - phases + math.pi, TWO_PI) - math.pi)
        if np.min(gap) <= 1e-9:
            return True
        return abs(float(self.potential_slope(u))) <= 1e-13 * self.energy_scale

    def initial_phase_rate(self, u0, omega0):
        """u̇₀ (rad/s) giving the body the signed angular speed ``omega0`` (rad/s) at u0."""
        return float(omega0) / float(self.angular_speed_per_phase(u0))


@dataclass
class RollingMotion:
    """A simulated motion u(t), with dense output over ``[0, t_end]``.

    Attributes
    ----------
    t : ndarray
        Sample times (s).
    phase, phase_rate : ndarray
        u (rad) and u̇ (rad/s) at ``t``.
    energy : ndarray
        E (J) at ``t``, recomputed from (u, u̇) with the tables.
    nfev : int
        Right-hand-side evaluations (0 for the quadrature path).
    """

    dynamics: RollingDynamics
    mode: str
    method: str
    t: np.ndarray
    phase: np.ndarray
    phase_rate: np.ndarray
    energy: np.ndarray
    nfev: int
    solver: str
    sol: object = field(repr=False)

    @property
    def energy_drift(self):
        """max |E − E₀| over the samples, relative to :attr:`RollingDynamics.energy_scale`.

        A conservation check in dynamic mode only: in kinematic mode the motor does work and
        E changes along the cycle by design.
        """
        return float(np.max(np.abs(self.energy - self.energy[0]))) / self.dynamics.energy_scale

    def positions(self):
        """World positions of G, A and B at the samples (m), each shape (len(t), 3)."""
        return self.dynamics.cycle.positions(self.phase)

    def states(self):
        """Full :class:`RollingState` at the samples (pose, contacts, angles)."""
        return self.dynamics.cycle.state(self.phase)


class _Quadrature:
    """u(t) for motion in one direction, from t(u) = ∫ du / |u̇| tabulated over one cycle.

    With x = s (u − u₀) ≥ 0 the distance travelled in u, τ(x) = s (G(u₀ + s x) − G(u₀)),
    G′ = 1/|u̇|, is increasing and τ(x + 2π) = τ(x) + T. Each time is reduced to one cycle,
    bracketed between two table nodes, and solved there by safeguarded Newton.
    """

    def __init__(self, dynamics, u0, direction, inverse_speed, n):
        u = TWO_PI * np.arange(n) / n
        rate = inverse_speed(u)
        if not np.all(np.isfinite(rate)) or np.any(rate <= 0):
            raise RuntimeError('the motion does not advance monotonically in u over a cycle')
        mean, periodic = spectral_antiderivative(rate)
        second = _spectral_derivative(rate)
        self._mean = mean
        self._table = HermiteTable(0.0, TWO_PI / n, np.append(periodic, 0.0),
                                   np.append(rate - mean, rate[0] - mean),
                                   np.append(second, second[0]))
        self._u0, self._s = float(u0), float(direction)
        self._g0 = self._antiderivative(self._u0)
        self.cycle_time = mean * TWO_PI
        self._x_nodes = TWO_PI * np.arange(n + 1) / n
        self._tau_nodes = self._tau(self._x_nodes)
        self._tau_nodes[0], self._tau_nodes[-1] = 0.0, self.cycle_time

    def _antiderivative(self, u):
        cycles = np.floor(np.asarray(u) / TWO_PI)
        rest = np.asarray(u) - TWO_PI * cycles
        return self._mean * u + self._table(rest)

    def _rate(self, u):
        return self._table(np.mod(u, TWO_PI), derivative=1) + self._mean

    def _tau(self, x):
        return self._s * (self._antiderivative(self._u0 + self._s * x) - self._g0)

    BLOCK = 65536   # samples solved at once (keeps the temporaries in cache)

    def __call__(self, t):
        """(u, u̇) at times t ≥ 0 (s)."""
        t = np.asarray(t, dtype=float)
        if t.size <= self.BLOCK:
            return self._solve(t)
        flat = t.ravel()
        u, u_dot = np.empty_like(flat), np.empty_like(flat)
        for start in range(0, flat.size, self.BLOCK):
            part = slice(start, start + self.BLOCK)
            u[part], u_dot[part] = self._solve(flat[part])
        return u.reshape(t.shape), u_dot.reshape(t.shape)

    def _solve(self, t):
        period = self.cycle_time
        cycles = np.floor(t / period)
        rest = np.clip(t - cycles * period, 0.0, period)
        nodes, taus = self._x_nodes, self._tau_nodes
        j = np.clip(np.searchsorted(taus, rest, side='right') - 1, 0, len(nodes) - 2)
        low, high = nodes[j], nodes[j + 1]
        x = low + (rest - taus[j]) * (high - low) / (taus[j + 1] - taus[j])
        for _ in range(30):
            step = (self._tau(x) - rest) / self._rate(self._u0 + self._s * x)
            x_new = np.clip(x - step, low, high)
            done = np.max(np.abs(x_new - x), initial=0.0) <= 1e-13
            x = x_new
            if done:
                break
        residual = np.max(np.abs(self._tau(x) - rest), initial=0.0)
        if residual > 1e-10 * period:
            raise RuntimeError(f'inverting t(u) failed: residual {residual:.3g} s')
        u = self._u0 + self._s * (x + TWO_PI * cycles)
        return u, self._s / self._rate(u)


class _Libration:
    """Oscillation in a well of V, in closed form from tables (no time stepping).

    The angle φ is defined by V(u(φ)) = V* + (E − V*) sin²φ with sign(u − u*) = sign(sin φ),
    u* the minimum of the well; then u̇ = √(2(E − V*)/m) cos φ and
    dt/dφ = √(2 m (E − V*)) sin φ / V′(u), smooth, positive and 2π-periodic
    (√(m/V″) at φ = 0, π). φ(t) comes from :class:`_Quadrature`, u(φ) from a table.
    """

    _GAUSS = np.polynomial.legendre.leggauss(20)

    def __init__(self, dynamics, u0, u_dot0, max_nodes):
        self._dynamics = dynamics
        u_min, self._u_low, self._u_high = dynamics.well(u0)
        self._u_min = u_min
        f0 = dynamics.tabulated(u0)
        rise0 = float(self._rise(np.array(u0)))
        self._depth = depth = 0.5 * f0[0] * u_dot0**2 + rise0   # E − V*, no cancellation
        self._stiffness = dynamics.potential_curvature(u_min)
        # resolve u(φ) spectrally on few nodes, then upsample ×4 for the Hermite tables
        n = 128
        while True:
            u, du_dphi, dt_dphi = self._samples(n)
            resolved = max(spectral_tail(du_dphi), spectral_tail(dt_dphi)) < 1e-13
            if resolved or 4 * n >= max_nodes:
                break
            n *= 2
        u = u_min + _upsample(u - u_min, 4)
        du_dphi, dt_dphi = _upsample(du_dphi, 4), _upsample(dt_dphi, 4)
        n *= 4
        d2u_dphi2 = _spectral_derivative(du_dphi)
        self._u = HermiteTable(0.0, TWO_PI / n, np.append(u, u[0]),
                               np.append(du_dphi, du_dphi[0]), np.append(d2u_dphi2, d2u_dphi2[0]))
        sin0 = math.copysign(math.sqrt(min(1.0, max(0.0, rise0 / depth))), u0 - u_min)
        cos0 = u_dot0 / math.sqrt(2 * depth / f0[0])
        self._phase = _Quadrature(dynamics, math.atan2(sin0, cos0), 1.0, lambda x: dt_dphi, n)
        self.period = self._phase.cycle_time

    def _samples(self, n):
        """u, du/dφ and dt/dφ at φ_j = 2πj/n."""
        dynamics, u_min, depth = self._dynamics, self._u_min, self._depth
        phi = TWO_PI * np.arange(n) / n
        sin_phi, cos_phi = np.sin(phi), np.cos(phi)
        u = self._solve_rise(depth * sin_phi**2, np.where(sin_phi >= 0, u_min, self._u_low),
                             np.where(sin_phi >= 0, self._u_high, u_min))
        centre = np.isclose(np.abs(sin_phi), 0.0, atol=1e-12)
        u = np.where(centre, u_min, u)
        m = dynamics.tabulated(u)[..., 0]
        slope = dynamics.tabulated(u, derivative=1)[..., 1]
        safe = np.where(centre, 1.0, slope)
        amplitude = math.sqrt(2 * depth / self._stiffness)
        du_dphi = np.where(centre, amplitude * cos_phi, 2 * depth * sin_phi * cos_phi / safe)
        dt_dphi = np.where(centre, math.sqrt(dynamics.tabulated(u_min)[0] / self._stiffness),
                           np.sqrt(2 * m * depth) * sin_phi / safe)
        return u, du_dphi, dt_dphi

    def _rise(self, u):
        """V(u) − V(u*) (J) as ∫ V′ from u* (20-point Gauss): no cancellation near u*."""
        nodes, weights = self._GAUSS
        half = 0.5 * (np.asarray(u) - self._u_min)
        points = self._u_min + half[..., None] * (1 + nodes)
        slopes = self._dynamics.tabulated_potential(points, derivative=1)
        return half * np.sum(weights * slopes, axis=-1)

    def _solve_rise(self, level, low, high):
        """u in [low, high] with V(u) − V* = level, V monotone there.

        Safeguarded Newton (bisection when a step leaves the bracket) on the tabulated V,
        then two Newton steps on the Gauss-integrated rise (accurate near u*).
        """
        dynamics, u_min = self._dynamics, self._u_min
        v_star = float(dynamics.tabulated_potential(u_min))
        lo, hi = np.minimum(low, high).astype(float), np.maximum(low, high).astype(float)
        orient = np.where(np.asarray(high) > u_min + 1e-15, 1.0, -1.0)   # g increasing in u
        u = 0.5 * (lo + hi)
        for _ in range(100):
            g = orient * (dynamics.tabulated_potential(u) - v_star - level)
            dg = orient * dynamics.tabulated_potential(u, derivative=1)
            lo, hi = np.where(g < 0, u, lo), np.where(g > 0, u, hi)
            newton = u - g / np.where(dg > 0, dg, 1.0)
            inside = (dg > 0) & (newton > lo) & (newton < hi)
            u_new = np.where(inside, newton, 0.5 * (lo + hi))
            done = np.max(np.abs(u_new - u), initial=0.0) <= 1e-14
            u = u_new
            if done:
                break
        for _ in range(2):
            slope = dynamics.tabulated_potential(u, derivative=1)
            step = np.where(slope == 0, 0.0, (self._rise(u) - level)
                            / np.where(slope == 0, 1.0, slope))
            u = np.clip(u - step, lo - 1e-12, hi + 1e-12)
        return u

    def __call__(self, t):
        """(u, u̇) at times t ≥ 0 (s)."""
        phi, phi_dot = self._phase(t)
        rest = np.mod(phi, TWO_PI)
        return self._u(rest), self._u(rest, derivative=1) * phi_dot


def _real(name, value, rule, allowed):
    """``value`` as a float if ``allowed(value)``, else ValueError naming ``name`` and ``rule``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} must be a number {rule}, got {value!r}') from None
    if not allowed(number):
        raise ValueError(f'{name} must be {rule}, got {value!r}')
    return number


def _check_choice(name, value, allowed):
    if value not in allowed:
        raise ValueError(f'{name} must be one of {", ".join(map(repr, allowed))}, got {value!r}')


def simulate(dynamics, t_eval, *, mode='dynamic', theta0=0.0, branch=1, omega0=0.0,
             method='table', tolerance=1e-10):
    """Simulate the rolling body from an initial state and sample it at ``t_eval``.

    Parameters
    ----------
    dynamics : RollingDynamics
    t_eval : array_like
        Sample times (s), increasing, starting at ≥ 0 (t = 0 is the initial state).
    mode : {'dynamic', 'kinematic'}
    theta0 : float
        Initial θ (rad), |theta0| ≤ θ_max.
    branch : {+1, -1}
        +1: the paper's branch (B below the plane of disk 1), −1: its mirror.
    omega0 : float
        Signed angular speed of the body (rad/s); positive: θ increasing on branch +1.
        In kinematic mode it is held constant.
    method : {'direct', 'table'}
    tolerance : float
        Relative tolerance of the ODE solver (in (0, 1)).

    Returns
    -------
    RollingMotion
    """
    _check_choice('mode', mode, MODES)
    _check_choice('method', method, METHODS)
    tolerance = _real('tolerance', tolerance, 'in (0, 1)', lambda x: 0 < x < 1)
    omega0 = _real('omega0', omega0, 'finite (rad/s)', math.isfinite)
    theta_max = dynamics.body.theta_max
    theta0 = _real('theta0', theta0, f'finite with |theta0| <= theta_max = {theta_max!r} rad',
                   lambda x: math.isfinite(x) and abs(x) <= theta_max)
    try:
        t_eval = np.asarray(t_eval, dtype=float)
    except (TypeError, ValueError):
        t_eval = np.array([np.nan])
    if (t_eval.ndim != 1 or t_eval.size == 0 or not np.all(np.isfinite(t_eval))
            or t_eval[0] < 0 or np.any(np.diff(t_eval) <= 0)):
        raise ValueError('t_eval must be a non-empty 1-d array of finite, strictly increasing '
                         'times >= 0 s')
    u0 = float(dynamics.body.phase_from_theta(theta0, branch))
    return simulate_phase(dynamics, t_eval, u0, dynamics.initial_phase_rate(u0, omega0),
                          mode=mode, method=method, tolerance=tolerance)


def simulate_phase(dynamics, t_eval, u0, u_dot0, *, mode='dynamic', method='table',
                   tolerance=1e-10):
    """As :func:`simulate`, from the phase u0 (rad) and phase rate u_dot0 (rad/s).

    In kinematic mode the angular speed held is |u_dot0|·|ω_u(u0)|.
    """
    _check_choice('mode', mode, MODES)
    _check_choice('method', method, METHODS)
    t_eval = np.asarray(t_eval, dtype=float)
    if mode == 'kinematic':
        omega = float(u_dot0) * float(dynamics.angular_speed_per_phase(u0))
        return _simulate_kinematic(dynamics, t_eval, float(u0), omega, method, tolerance)
    return _simulate_dynamic(dynamics, t_eval, float(u0), float(u_dot0), method, tolerance)


class MotionStream:
    """Samples of one motion at increasing times, for as long as asked (the node's source).

    The quadrature path is evaluated in closed form at any time; the ODE paths are
    integrated in chunks of ``chunk`` seconds, each continuing from the end of the last.
    """

    def __init__(self, dynamics, u0, u_dot0, *, mode='dynamic', method='table',
                 tolerance=1e-10, chunk=10.0):
        self.dynamics, self.mode, self.method, self.tolerance = dynamics, mode, method, tolerance
        self._chunk = float(chunk)
        self._start = 0.0
        self._motion = simulate_phase(dynamics, [0.0, self._chunk], u0, u_dot0, mode=mode,
                                      method=method, tolerance=tolerance)
        self.initial_energy = float(self._motion.energy[0])
        self._omega = abs(float(u_dot0) * float(dynamics.angular_speed_per_phase(u0)))

    def _eval(self, t):
        motion, tau = self._motion, np.asarray(t, dtype=float) - self._start
        if motion.solver in CLOSED_FORM_SOLVERS:
            return motion.sol(tau)
        y = motion.sol(tau)
        if self.mode == 'kinematic':
            speed = self.dynamics.tabulated(y[0])[..., 2]
            return y[0], np.sign(motion.phase_rate[0]) * self._omega / speed
        return y[0], y[1]

    def sample(self, t):
        """(u, u̇) at times t (s, array, increasing, not before earlier calls)."""
        t = np.asarray(t, dtype=float)
        if self._motion.solver in CLOSED_FORM_SOLVERS:
            return self._eval(t)
        pieces = []
        while True:
            end = self._start + self._chunk
            inside = t <= end
            pieces.append(self._eval(t[inside]))
            t = t[~inside]
            if not t.size:
                break
            u_end, u_dot_end = self._eval_scalar(end)
            self._start = end
            self._motion = simulate_phase(self.dynamics, [0.0, self._chunk], u_end, u_dot_end,
                                          mode=self.mode, method=self.method,
                                          tolerance=self.tolerance)
        return tuple(np.concatenate([p[i] for p in pieces]) for i in range(2))

    def _eval_scalar(self, t):
        u, u_dot = self._eval(np.array([t]))
        return u[0], u_dot[0]


def _motion(dynamics, mode, method, t, u, u_dot, nfev, solver, sol):
    return RollingMotion(dynamics=dynamics, mode=mode, method=method, t=t, phase=u,
                         phase_rate=u_dot, energy=dynamics.energy(u, u_dot), nfev=nfev,
                         solver=solver, sol=sol)


def _rest(dynamics, mode, method, t, u0):
    u = np.full_like(t, u0)
    zero = np.zeros_like(t)
    return _motion(dynamics, mode, method, t, u, zero, 0, 'rest',
                   lambda tt: (np.full_like(np.asarray(tt, float), u0), 0 * np.asarray(tt)))


def _simulate_kinematic(dynamics, t_eval, u0, omega0, method, tolerance):
    if omega0 == 0:
        return _rest(dynamics, 'kinematic', method, t_eval, u0)
    speed = abs(omega0)
    direction = math.copysign(1.0, omega0)
    if method == 'table':
        quad = _Quadrature(dynamics, u0, direction,
                           lambda u: dynamics.tabulated(u)[..., 2] / speed,
                           len(dynamics._nodes))
        u, u_dot = quad(t_eval)
        return _motion(dynamics, 'kinematic', method, t_eval, u, u_dot, 0, 'quadrature', quad)

    def rhs(t, y):
        return [direction * speed / float(dynamics.angular_speed_per_phase(y[0]))]
    result = _solve(rhs, t_eval, [u0], tolerance, 1.0)
    u = result.y[0]
    u_dot = direction * speed / dynamics.angular_speed_per_phase(u)
    return _motion(dynamics, 'kinematic', method, t_eval, u, u_dot, result.nfev, 'DOP853',
                   result.sol)


def _simulate_dynamic(dynamics, t_eval, u0, u_dot0, method, tolerance):
    if u_dot0 == 0 and dynamics.is_equilibrium(u0):
        return _rest(dynamics, 'dynamic', method, t_eval, u0)
    if method == 'table':
        f0 = dynamics.tabulated(u0)
        energy = 0.5 * f0[0] * u_dot0**2 + f0[1]
        v_max = dynamics.potential_range[1]
        margin = energy - v_max
        n = len(dynamics._nodes)
        if u_dot0 != 0 and margin > 1e-6 * dynamics.energy_scale:
            def inverse_speed(u):
                f = dynamics.tabulated(u)
                return np.sqrt(f[..., 0] / (2.0 * (energy - f[..., 1])))
            quad = _Quadrature(dynamics, u0, math.copysign(1.0, u_dot0), inverse_speed, n)
            u, u_dot = quad(t_eval)
            return _motion(dynamics, 'dynamic', method, t_eval, u, u_dot, 0, 'quadrature',
                           quad)
        if margin < -1e-6 * dynamics.energy_scale:
            libration = _Libration(dynamics, u0, u_dot0, n)
            u, u_dot = libration(t_eval)
            return _motion(dynamics, 'dynamic', method, t_eval, u, u_dot, 0, 'libration',
                           libration)

        def rhs(t, y):
            f = dynamics.tabulated(y[0])
            df = dynamics.tabulated(y[0], derivative=1)
            return [y[1], -(df[1] + 0.5 * df[0] * y[1] ** 2) / f[0]]
    else:
        def rhs(t, y):
            m = float(dynamics.effective_mass(y[0]))
            dm = float(dynamics.effective_mass_slope(y[0]))
            dv = float(dynamics.potential_slope(y[0]))
            return [y[1], -(dv + 0.5 * dm * y[1] ** 2) / m]
    rate_scale = max(abs(u_dot0), 1.0)
    result = _solve(rhs, t_eval, [u0, u_dot0], tolerance, rate_scale)
    return _motion(dynamics, 'dynamic', method, t_eval, result.y[0], result.y[1], result.nfev,
                   'DOP853', result.sol)


def _solve(rhs, t_eval, y0, tolerance, scale):
    span = (0.0, float(t_eval[-1]))
    if span[1] == 0.0:
        y = np.array(y0, dtype=float)[:, None] * np.ones((1, t_eval.size))
        return _Trivial(y)
    result = solve_ivp(rhs, span, y0, method='DOP853', t_eval=t_eval, rtol=tolerance,
                       atol=tolerance * scale, dense_output=True)
    if not result.success:
        raise RuntimeError(f'integration failed: {result.message}')
    return result


@dataclass
class _Trivial:
    y: np.ndarray
    nfev: int = 0
    sol: object = None
