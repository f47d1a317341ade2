"""Solutions u(t) of the equation of motion, each a dense output with one convention.

Every solution is a callable ``sol(t) -> ndarray`` of shape ``(2,) + shape(t)``: the phase u
(rad) and its rate u̇ (rad/s) at times t (s, from the start of the motion), like scipy's
``OdeSolution``. ``closed_form`` tells whether it holds at any time (``t_end`` is then
infinite) or only on ``[0, t_end]`` (an ODE integration). The methods are derived in
docs/physics.md#the-two-methods-direct-and-table.
"""

import math

import numpy as np

from .cycle import TWO_PI
from .spectral import (refine_grid, spectral_antiderivative, spectral_derivative,
                       spectral_tail, upsample)
from .tables import HermiteTable

__all__ = ['LibrationSolution', 'OdeSolution', 'PhaseSolution', 'QuadratureSolution',
           'RestSolution']


class PhaseSolution:
    """Base of the solutions: ``sol(t)`` → array (2, ...) of u (rad) and u̇ (rad/s)."""

    #: name of the solver, as reported in benchmarks ('rest', 'quadrature', ...)
    name = ''
    #: True if the solution is known in closed form at every t ≥ 0
    closed_form = True
    #: the last time (s) at which the solution is defined
    t_end = math.inf

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        u, u_dot = self._evaluate(t.ravel())
        return np.stack([u, u_dot]).reshape((2,) + t.shape)

    def _evaluate(self, t):
        raise NotImplementedError


class RestSolution(PhaseSolution):
    """A body at rest at an equilibrium phase u0 (rad): the exact solution u(t) = u0."""

    name = 'rest'

    def __init__(self, u0):
        self.u0 = float(u0)

    def _evaluate(self, t):
        return np.full_like(t, self.u0), np.zeros_like(t)


class OdeSolution(PhaseSolution):
    """Dense output of a DOP853 integration over [0, t_end] (scipy's ``OdeSolution``).

    Parameters
    ----------
    dense : callable or None
        scipy's ``sol``: y(t) with y = (u, u̇), or y = (u,) when ``rate`` is given; None for a
        span of zero length (the initial state ``y0`` holds).
    y0 : sequence of float
        The initial state.
    t_end : float
        End of the span (s).
    rate : callable, optional
        u̇ as a function of u (kinematic mode, where only u is integrated).
    """

    name = 'DOP853'
    closed_form = False

    def __init__(self, dense, y0, t_end, rate=None):
        self._dense, self._y0, self._rate = dense, np.asarray(y0, dtype=float), rate
        self.t_end = float(t_end)

    def _evaluate(self, t):
        if t.size == 0:
            return np.zeros(0), np.zeros(0)
        if self._dense is None:
            y = self._y0[:, None] * np.ones((1, t.size))
        else:
            y = np.asarray(self._dense(t)).reshape(len(self._y0), t.size)
        if self._rate is not None:
            return y[0], self._rate(y[0])
        return y[0], y[1]


class QuadratureSolution(PhaseSolution):
    """u(t) for motion in one direction, from t(u) = ∫ du / |u̇| tabulated over one cycle.

    With x = s (u − u₀) ≥ 0 the distance travelled in u, τ(x) = s (G(u₀ + s x) − G(u₀)),
    G′ = 1/|u̇|, is increasing and τ(x + 2π) = τ(x) + T. Each time is reduced to one cycle,
    bracketed between two table nodes, and solved there by safeguarded Newton.

    Parameters
    ----------
    u0 : float
        Initial phase (rad).
    direction : {+1.0, -1.0}
        Sign of u̇.
    inverse_speed : callable
        1/|u̇| (s/rad) as a function of u, positive and 2π-periodic.
    n : int
        Nodes of the table over one cycle.
    """

    name = 'quadrature'
    BLOCK = 65536   # samples solved at once (keeps the temporaries in cache)

    def __init__(self, u0, direction, inverse_speed, n):
        u = TWO_PI * np.arange(n) / n
        rate = inverse_speed(u)
        if not np.all(np.isfinite(rate)) or np.any(rate <= 0):
            raise RuntimeError('the motion does not advance monotonically in u over a cycle')
        mean, periodic = spectral_antiderivative(rate)
        self._mean = mean
        self._table = HermiteTable.periodic(periodic, rate - mean, spectral_derivative(rate))
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

    def _evaluate(self, t):
        u, u_dot = np.empty_like(t), np.empty_like(t)
        for start in range(0, t.size, self.BLOCK):
            part = slice(start, start + self.BLOCK)
            u[part], u_dot[part] = self._solve(t[part])
        return u, u_dot

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


class LibrationSolution(PhaseSolution):
    """Oscillation in a well of V, in closed form from tables (no time stepping).

    The angle φ is defined by V(u(φ)) = V* + (E − V*) sin²φ with sign(u − u*) = sign(sin φ),
    u* the minimum of the well; then u̇ = √(2(E − V*)/m) cos φ and
    dt/dφ = √(2 m (E − V*)) sin φ / V′(u), smooth, positive and 2π-periodic
    (√(m/V″) at φ = 0, π). φ(t) comes from :class:`QuadratureSolution`, u(φ) from a table.

    Parameters
    ----------
    dynamics : RollingDynamics
    u0, u_dot0 : float
        Initial phase (rad) and rate (rad/s), inside a well of V.
    max_nodes : int
        Largest number of nodes of the tables in φ.
    """

    name = 'libration'
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
        def sample(n):
            u, du_dphi, dt_dphi = self._samples(n)
            return max(spectral_tail(du_dphi), spectral_tail(dt_dphi)), (u, du_dphi, dt_dphi)
        n, (u, du_dphi, dt_dphi) = refine_grid(sample, 128, max(128, max_nodes // 4))
        u = u_min + upsample(u - u_min, 4)
        du_dphi, dt_dphi = upsample(du_dphi, 4), upsample(dt_dphi, 4)
        n *= 4
        self._u = HermiteTable.periodic(u, du_dphi, spectral_derivative(du_dphi))
        sin0 = math.copysign(math.sqrt(min(1.0, max(0.0, rise0 / depth))), u0 - u_min)
        cos0 = u_dot0 / math.sqrt(2 * depth / f0[0])
        self._phase = QuadratureSolution(math.atan2(sin0, cos0), 1.0, lambda x: dt_dphi, n)
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

    def _evaluate(self, t):
        phi, phi_dot = self._phase(t)
        rest = np.mod(phi, TWO_PI)
        return self._u(rest), self._u(rest, derivative=1) * phi_dot
