"""Solutions u(t) of the equation of motion, each a dense output with one convention.

Every solution is a callable ``sol(t) -> ndarray`` of shape ``(2,) + shape(t)``: the phase u
(rad) and its rate u̇ (rad/s) at times t (s, from the start of the motion), like scipy's
``OdeSolution``. ``closed_form`` tells whether it holds at any time (``t_end`` is then
infinite) or only on ``[0, t_end]`` (an ODE integration). The methods are derived in
docs/physics.md#the-two-methods-direct-and-table.
"""

import math

import numpy as np

from ..bodies.cycle import TWO_PI
from ..numerics.dense import dense_reader
from ..numerics.spectral import (STALL, refine_grid, spectral_antiderivative, spectral_derivative,
                       spectral_tail, upsample)
from ..numerics.tables import HermiteTable, power_coefficients, power_value

__all__ = ['LibrationSolution', 'OdeSolution', 'PhaseSolution', 'QuadratureSolution',
           'RestSolution', 'SundmanSolution', 'import_integrator']


def import_integrator():
    """Import scipy.integrate (~0.6 s) now: when a stream that will integrate is built, never
    in its first chunk, inside a real-time node's loop, where the stall drops samples."""
    import scipy.integrate  # noqa: F401


class PhaseSolution:
    """Base of the solutions: ``sol(t)`` → array (2, ...) of u (rad) and u̇ (rad/s)."""

    #: name of the solver, as reported in benchmarks ('rest', 'quadrature', ...)
    name = ''
    #: True if the solution is known in closed form at every t ≥ 0
    closed_form = True
    #: the last time (s) at which the solution is defined
    t_end = math.inf
    #: the equilibrium u* (rad) the motion oscillates about (or rests at), else None
    centre = None
    #: True if the solution holds the state (u, w) of the regular chart itself (w the angular
    #: speed about AB, finite where the body stops turning in u): :meth:`state` needs no
    #: ``turn_rate`` then, and u̇ = w/|ω_u| is only what it reports
    regular_chart = False

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        u, u_dot = self._evaluate(t.ravel())
        return np.stack([u, u_dot]).reshape((2,) + t.shape)

    def displacement(self, t):
        """Array (2, ...) of δ = u − ``centre`` (rad) and u̇ (rad/s) at times t (s).

        For a motion about an equilibrium, δ is computed as such (not as a difference of
        phases), so it keeps its relative precision however small the amplitude: u itself
        is rounded to its ulp (~1e-16 rad), δ is not.
        """
        if self.centre is None:
            raise ValueError(f'a {self.name!r} solution has no centre')
        t = np.asarray(t, dtype=float)
        delta, u_dot = self._displace(t.ravel())
        return np.stack([delta, u_dot]).reshape((2,) + t.shape)

    def forget_before(self, t):
        """Drop what the solution keeps for times before t (s), once they are no longer
        asked for: nothing here (a solution built piece by piece as time runs on frees its
        earlier pieces)."""

    def state(self, t, turn_rate=None):
        """(u, w) at times t (s): the phase (rad) and the angular speed about AB (rad/s),
        w = |ω_u|(u) u̇ with ``turn_rate(u)`` = |ω_u| (a solution in the chart (u, w) gives
        w itself and needs no ``turn_rate``)."""
        u, u_dot = self(t)
        return u, u_dot * turn_rate(u)

    def initial_energy(self, energy_turning, turn_rate):
        """E (J) of the motion: ``energy_turning(u, w)`` of the state at t = 0 (a solution
        that holds its energy gives it instead)."""
        return float(energy_turning(*(float(np.ravel(x)[0])
                                      for x in self.state(0.0, turn_rate))))

    def _evaluate(self, t):
        raise NotImplementedError

    def _displace(self, t):
        u, u_dot = self._evaluate(t)
        return u - self.centre, u_dot


class RestSolution(PhaseSolution):
    """A body at rest at an equilibrium phase u0 (rad): the exact solution u(t) = u0."""

    name = 'rest'

    def __init__(self, u0):
        self.u0 = self.centre = float(u0)

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
    centre : float, optional
        If given, the integrated variable is the displacement δ = u − centre (an oscillation
        about the equilibrium ``centre``), and u = centre + δ.
    """

    name = 'DOP853'
    closed_form = False

    def __init__(self, dense, y0, t_end, rate=None, centre=None):
        import_integrator()
        self._dense = None if dense is None else dense_reader(dense)
        self._y0, self._rate = np.asarray(y0, dtype=float), rate
        self.t_end = float(t_end)
        self.centre = None if centre is None else float(centre)

    def _evaluate(self, t):
        y0, y1 = self._integrated(t)
        return (y0 if self.centre is None else self.centre + y0), y1

    def _displace(self, t):
        if self.centre is None:
            return super()._displace(t)
        return self._integrated(t)

    def _integrated(self, t):
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
    bracketed between two table nodes, and solved there by safeguarded Newton; a call of at
    least n + 1 times reads x from the inverse x(τ) instead, interpolated between the same
    nodes, if it reproduces Newton to :attr:`INVERSE_TOLERANCE`;
    docs/physics.md#the-two-methods-direct-and-table.

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
    BLOCK = 4096   # samples solved at once (keeps the temporaries in cache)
    #: largest |x(τ) − Newton| (rad) at which the inverse table replaces Newton
    INVERSE_TOLERANCE = 1e-13

    def __init__(self, u0, direction, inverse_speed, n):
        u = TWO_PI * np.arange(n) / n
        rate = inverse_speed(u)
        # 1/|u̇| may vanish at isolated phases (a body that does not turn in u there:
        # u̇ is infinite for an instant, t(u) still increases)
        if not np.all(np.isfinite(rate)) or np.any(rate < 0) or not np.mean(rate) > 0:
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
        #: x(τ) over one cycle (a table instead of Newton): False until a call of at least
        #: as many samples as the table has nodes builds it, None if refused
        self._inverse = False

    def _antiderivative(self, u):
        cycles = np.floor(np.asarray(u) / TWO_PI)
        rest = np.asarray(u) - TWO_PI * cycles
        return self._mean * u + self._table(rest)

    def _rate(self, u):
        return self._table(np.mod(u, TWO_PI), derivative=1) + self._mean

    def _tau(self, x):
        return self._s * (self._antiderivative(self._u0 + self._s * x) - self._g0)

    def _evaluate(self, t):
        # the inverse's build costs about as much as Newton on half its nodes' count of
        # samples: calls that large use it (built on the first), smaller ones (a node's
        # blocks) solve by Newton
        large = t.size >= len(self._x_nodes)
        if large and self._inverse is False:
            self._inverse = self._build_inverse()
        inverse = large and self._inverse is not None
        u, u_dot = np.empty_like(t), np.empty_like(t)
        for start in range(0, t.size, self.BLOCK):
            part = slice(start, start + self.BLOCK)
            u[part], u_dot[part] = self._solve(t[part], inverse)
        return u, u_dot

    def _build_inverse(self):
        """The power-basis coefficients of x(τ) on the intervals [τ_i, τ_i+1] of the table's own
        nodes (x_i, τ_i), a quintic Hermite from dx/dτ = 1/τ′ and d²x/dτ² = −τ″/τ′³ there (no
        solving); kept only if τ(x(τ)) − τ, divided by τ′, is within ``INVERSE_TOLERANCE`` at
        the midpoint of every interval (where the interpolant's error peaks); else None."""
        x, taus = self._x_nodes, self._tau_nodes
        width = np.diff(taus)
        u = self._u0 + self._s * x
        rate = self._rate(u)
        if not (np.all(rate > 0) and np.all(width > 0)):
            return None           # u̇ infinite somewhere: x(τ) has no bounded slope there
        slope = 1.0 / rate
        curvature = -self._s * self._table.jet(np.mod(u, TWO_PI))[2] * slope**3
        self._inverse = power_coefficients(
            x[:-1], width * slope[:-1], width**2 * curvature[:-1],
            x[1:], width * slope[1:], width**2 * curvature[1:])
        middle = taus[:-1] + 0.5 * width
        x_middle = self._invert(middle)
        error = np.abs(self._tau(x_middle) - middle) / self._rate(self._u0 + self._s * x_middle)
        return self._inverse if np.max(error) <= self.INVERSE_TOLERANCE else None

    def _invert(self, rest):
        """x(τ) at times rest (s, in [0, T]) from the inverse's coefficients."""
        taus = self._tau_nodes
        j = np.clip(np.searchsorted(taus, rest, side='right') - 1, 0, len(taus) - 2)
        return power_value(self._inverse.take(j, axis=0),
                           (rest - taus[j]) / (taus[j + 1] - taus[j]))

    def _solve(self, t, inverse):
        period = self.cycle_time
        cycles = np.floor(t / period)
        rest = np.clip(t - cycles * period, 0.0, period)
        x = np.clip(self._invert(rest), 0.0, TWO_PI) if inverse else self._newton(rest)
        u = self._u0 + self._s * (x + TWO_PI * cycles)
        with np.errstate(divide='ignore'):
            return u, self._s / self._rate(u)

    def _newton(self, rest):
        """x ∈ [0, 2π] with τ(x) = rest (s, in [0, T]): bracketed, safeguarded Newton."""
        period = self.cycle_time
        nodes, taus = self._x_nodes, self._tau_nodes
        j = np.clip(np.searchsorted(taus, rest, side='right') - 1, 0, len(nodes) - 2)
        low, high = nodes[j], nodes[j + 1]
        x = low + (rest - taus[j]) * (high - low) / (taus[j + 1] - taus[j])
        below, above = low, high       # the bracket, for where 1/|u̇| vanishes
        for _ in range(30):
            g = self._tau(x) - rest
            below, above = np.where(g < 0, x, below), np.where(g > 0, x, above)
            with np.errstate(divide='ignore', invalid='ignore'):
                step = g / self._rate(self._u0 + self._s * x)
            x_new = np.clip(x - step, low, high)
            x_new = np.where(np.isfinite(step), x_new, 0.5 * (below + above))
            done = np.max(np.abs(x_new - x), initial=0.0) <= 1e-13
            x = x_new
            if done:
                break
        residual = np.max(np.abs(self._tau(x) - rest), initial=0.0)
        if residual > 1e-10 * period:
            raise RuntimeError(f'inverting t(u) failed: residual {residual:.3g} s')
        return x


class LibrationSolution(PhaseSolution):
    """Oscillation in a well of V, in closed form (no time stepping), in the displacement.

    With δ = u − u* from the well's minimum u* and depth D = E − V*, the angle φ is defined by
    V(u* + δ(φ)) − V* = D sin²φ with sign(δ) = sign(sin φ); then u̇ = √(2D/m) cos φ and
    dt/dφ = √(2 m D) sin φ / V′, smooth, positive and 2π-periodic (√(m/V″) at φ = 0, π).
    φ(t) comes from :class:`QuadratureSolution`, δ(φ) from a table.

    Everything is computed in x = δ/s, s the linear amplitude estimate √(δ₀² + m u̇₀²/V″),
    from the well's ``ratio(δ)`` = V′/δ (``physics.wells``): V′ = s x ratio(s x) and
    V − V* = s² x² ∫₀¹ τ ratio(s x τ) dτ (20-point Gauss), so every quantity keeps its
    relative precision at any amplitude, 1e-300 rad as well as 1 rad. The level equation is
    solved by safeguarded Newton in |x| with a relative tolerance.

    Parameters
    ----------
    well : LocalWell or TabulatedWell
        Centre u* (rad), bounds ``low`` < 0 < ``high`` of δ (rad), ``stiffness`` V″(u*),
        ``ratio(δ)`` and ``mass(δ)``.
    delta0, u_dot0 : float
        Initial displacement u0 − u* (rad) and rate (rad/s), not both zero.
    max_nodes : int
        Largest number of nodes of the tables in φ.
    """

    name = 'libration'
    #: spectral tail at which u(φ) and t(φ) count as resolved: above the noise plateau of
    #: the tabulated V′ (~1e-13 of its peak), far below any truncation that matters
    TAIL = 1e-11
    #: tails below this that stop shrinking under doubling are the noise of the tabulated V′
    #: (~5e-11 for b/a = 0.01, Δ/a = 1e-3, whose 2¹⁸-node tables carry more rounding), not
    #: missing resolution: refining further cost seconds and changed u(t) by < 1e-12 rad
    NOISE = 1e-8
    _NODES, _WEIGHTS = np.polynomial.legendre.leggauss(20)

    def __init__(self, well, delta0, u_dot0, max_nodes):
        self._well = well
        self.centre = well.centre
        delta0, u_dot0 = float(delta0), float(u_dot0)
        m0, k = float(well.mass(delta0)), well.stiffness
        self._scale = s = math.hypot(delta0, u_dot0 * math.sqrt(m0 / k))
        if not s > 0:
            raise ValueError('a libration needs a displacement or a rate (else: rest)')
        x0, v0 = delta0 / s, u_dot0 / s
        rise0 = float(self._rise(np.array(x0)))
        self._depth = depth = 0.5 * m0 * v0**2 + rise0     # (E − V*) / s², no cancellation
        self._bounds = (well.low / s, well.high / s)

        tails = []

        def sample(n):
            x, dx_dphi, dt_dphi = self._samples(n)
            tails.append(max(spectral_tail(dx_dphi), spectral_tail(dt_dphi)))
            return tails[-1], (x, dx_dphi, dt_dphi)
        n, (x, dx_dphi, dt_dphi) = refine_grid(sample, 128, max(128, max_nodes),
                                           tolerance=self.TAIL, floor=self.NOISE)
        #: the spectral tail of the tables in φ; ``resolved``: below TAIL or at the noise
        #: floor of the tabulated V′ (False: the grid reached ``max_nodes`` still converging)
        self.tail = tails[-1]
        self.resolved = self.tail < self.TAIL or (
            len(tails) > 1 and self.tail <= self.NOISE and self.tail > STALL * tails[-2])
        x, dx_dphi, dt_dphi = (upsample(f, 4) for f in (x, dx_dphi, dt_dphi))
        n *= 4
        self._x = HermiteTable.periodic(x, dx_dphi, spectral_derivative(dx_dphi))
        sin0 = math.copysign(math.sqrt(min(1.0, max(0.0, rise0 / depth))), x0)
        cos0 = v0 / math.sqrt(2 * depth / m0)
        self._phase = QuadratureSolution(math.atan2(sin0, cos0), 1.0, lambda _: dt_dphi, n)
        self.period = self._phase.cycle_time
        #: the turning displacements (rad): δ at φ = −π/2 and π/2
        self.turning_points = tuple(s * float(self._x(p)) for p in (1.5 * math.pi, 0.5 * math.pi))

    def _slope(self, x):
        """V′(u* + s x) / s (J/rad)."""
        return x * self._well.ratio(self._scale * x)

    def _rise(self, x):
        """(V(u* + s x) − V*) / s² (J) = x² ∫₀¹ τ ratio(s x τ) dτ: no cancellation near u*."""
        tau = 0.5 * (1 + self._NODES)
        ratio = self._well.ratio(self._scale * np.asarray(x)[..., None] * tau)
        return np.asarray(x) ** 2 * np.sum(0.5 * self._WEIGHTS * tau * ratio, axis=-1)

    def _samples(self, n):
        """x, dx/dφ and dt/dφ at φ_j = 2πj/n."""
        depth, k = self._depth, self._well.stiffness
        phi = TWO_PI * np.arange(n) / n
        sin_phi, cos_phi = np.sin(phi), np.cos(phi)
        side = np.where(sin_phi >= 0, 1.0, -1.0)
        centre = np.abs(sin_phi) < 1e-12
        x = side * self._solve_level(depth * sin_phi**2, side, centre)
        m = self._well.mass(self._scale * x)
        slope = np.where(centre, 1.0, self._slope(x))
        dx_dphi = np.where(centre, math.sqrt(2 * depth / k) * cos_phi,
                           2 * depth * sin_phi * cos_phi / slope)
        dt_dphi = np.where(centre, math.sqrt(float(self._well.mass(0.0)) / k),
                           np.sqrt(2 * m * depth) * sin_phi / slope)
        return x, dx_dphi, dt_dphi

    def _solve_level(self, level, side, centre):
        """y = |x| ≥ 0 with rise(side·y) = level (rise increases with y on each side).

        Safeguarded Newton from the linear guess √(2 level / V″), bisection when a step
        leaves the bracket; converged when each step is below 1e-15 y or the residual below
        4e-15 of the level (its rounding). 0 at ``centre``.
        """
        level, side = np.asarray(level, dtype=float), np.asarray(side, dtype=float)
        y = np.zeros_like(level)
        todo = np.nonzero(~np.asarray(centre))[0]          # points still iterating
        lev, sid = level[todo], side[todo]
        low = np.zeros_like(lev)
        high = np.where(sid > 0, self._bounds[1], -self._bounds[0])
        guess = np.minimum(np.sqrt(2 * lev / self._well.stiffness), 0.5 * high)
        for _ in range(200):
            if todo.size == 0:
                break
            g = self._rise(sid * guess) - lev
            dg = sid * self._slope(sid * guess)
            low, high = np.where(g < 0, guess, low), np.where(g > 0, guess, high)
            newton = guess - g / np.where(dg > 0, dg, 1.0)
            inside = (dg > 0) & (newton >= low) & (newton <= high)
            new = np.where(inside, newton, 0.5 * (low + high))
            done = ((np.abs(new - guess) <= 1e-15 * new) | (high - low <= 1e-15 * new)
                    | (np.abs(g) <= 4e-15 * lev))
            y[todo] = new
            keep = ~done
            todo, lev, sid, low, high, guess = (a[keep] for a in
                                                (todo, lev, sid, low, high, new))
        return y

    def _evaluate(self, t):
        delta, rate = self._displace(t)
        return self.centre + delta, rate

    def _displace(self, t):
        phi, phi_dot = self._phase(t)
        rest = np.mod(phi, TWO_PI)
        s = self._scale
        return s * self._x(rest), s * self._x(rest, derivative=1) * phi_dot


class SundmanSolution(PhaseSolution):
    """Dense output of DOP853 in the regularised time τ of a body that may stop turning in u.

    Where |ω_u| vanishes (m(u) = 0) the equation m ü + ½ m′ u̇² + V′ = 0 is singular and u̇
    infinite for an instant. With w = |ω_u| u̇ the body's angular speed about the contact line
    AB, J = m/|ω_u|² its moment of inertia about AB (positive everywhere) and dt/dτ = |ω_u|:

        du/dτ = w,   dw/dτ = −(½ J′ w² + V′)/J,   dt/dτ = |ω_u(u)|,

    all regular (derivatives in u; derived from Lagrange's equation,
    docs/physics.md#bodies-that-stop-turning-in-u). In kinematic mode w = ±Ω is constant.

    Parameters
    ----------
    dense : callable or None
        scipy's ``sol`` of y(τ) = (u, w, t); None for a span of zero length.
    y0 : sequence of float
        (u0, w0, 0).
    tau_end : float
        End of the span in τ.
    rotation_rate : callable
        |ω_u|(u) (rad per rad of u), to report u̇ = w/|ω_u| (inf where it vanishes).
    """

    regular_chart = True
    name = 'DOP853'
    closed_form = False

    def __init__(self, dense, y0, tau_end, rotation_rate):
        import_integrator()
        self._dense = None if dense is None else dense_reader(dense)
        self._y0, self._rotation_rate = np.asarray(y0, dtype=float), rotation_rate
        self._tau_end = float(tau_end)
        self.t_end = float(dense(self._tau_end)[2]) if dense is not None else 0.0

    def state(self, t, turn_rate=None):
        """(u, w) at times t (s): the phase and the body's angular speed about AB (rad/s)."""
        t = np.asarray(t, dtype=float).ravel()
        if self._dense is None or t.size == 0:
            return np.full(t.shape, self._y0[0]), np.full(t.shape, self._y0[1])
        low, high = np.zeros(t.size), np.full(t.size, self._tau_end)
        for _ in range(64):                     # t(τ) is non-decreasing: bisection
            mid = 0.5 * (low + high)
            later = np.asarray(self._dense(mid))[2] >= t
            low, high = np.where(later, low, mid), np.where(later, mid, high)
            if np.all(high - low <= 1e-15 * max(1.0, self._tau_end)):
                break
        y = np.asarray(self._dense(0.5 * (low + high))).reshape(3, t.size)
        return y[0], y[1]

    def _evaluate(self, t):
        u, w = self.state(t)
        with np.errstate(divide='ignore', invalid='ignore'):
            return u, w / self._rotation_rate(u)
