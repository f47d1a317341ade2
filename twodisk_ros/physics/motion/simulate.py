"""Simulated motions u(t): the public API (:func:`simulate`) and the node's stream.

Two modes: ``dynamic`` (gravity only) and ``kinematic`` (constant angular speed |ω| = Ω, so
u̇ = Ω / |ω_u(u)|). Two methods (docs/physics.md#the-two-methods-direct-and-table):

``direct``
    DOP853 (scipy ``solve_ivp``) with the geometry evaluated on the fly from the closed
    forms; ``tolerance`` is its rtol (atol = tolerance × scale).
``table``
    Periodic tables of one cycle (m, V, |ω_u| with derivatives, spectral to rounding), then:
    when u moves one way for ever (kinematic mode, or rolling over the top: E > max V),
    t(u) = ∫ du/|u̇| is a secular-plus-periodic function, tabulated once and inverted by
    bracketed Newton (no time stepping, no drift); when it oscillates in a well (E < max V),
    the same in the angle φ of V(u* + δ(φ)) = V* + (E − V*) sin²φ, in the displacement δ.
    Only near the separatrix E = max V (LIBRATION_MARGIN below to ROLLING_MARGIN above) is
    DOP853 run on the tabulated right-hand side, with ``tolerance`` as its rtol.

Small oscillations (amplitude ≤ LOCAL_FRACTION of the equilibrium's LocalWell radius) use
the same closed-form LibrationSolution with the local well model in both methods; above it,
the direct method integrates δ = u − u* inside a well. A body exactly at an equilibrium with
u̇ = 0 stays there (the exact solution); at a stable one, any other start oscillates. If V is
flat (g = 0 or z_G constant) ½ m u̇² is conserved and V′ is not evaluated. Every motion
carries its solution as ``sol``, a :class:`~twodisk_ros.physics.motion.solvers.PhaseSolution`.
"""

from dataclasses import dataclass, field
from functools import partial
import math

import numpy as np

from ..bodies.cycle import TWO_PI
from .dynamics import RollingDynamics
from .sundman import SundmanSolution, general_closed_form, sundman, turning_state
from .solvers import (LibrationSolution, OdeSolution, QuadratureSolution, RestSolution)
from ..numerics.spectral import STALL, spectral_tail
from .turning import TurningPointSolution, turning_points

__all__ = ['CLOSED_FORM_SOLVERS', 'METHODS', 'MODES', 'MotionStream', 'RollingMotion',
           'simulate', 'simulate_phase']

METHODS = ('direct', 'table')
#: The table method's closed-form solutions need E away from the separatrix E = max V,
#: where t(u) is logarithmically singular: below max V by more than LIBRATION_MARGIN
#: (× M g L) the libration tables (closer, their grid in φ would need > 10⁴ nodes), above
#: it by more than ROLLING_MARGIN the quadrature (closer, 1/|u̇| is not resolved by the
#: table grid: energy drift 2e-7 M g L at 1e-4 above); in between, DOP853 on the tables.
LIBRATION_MARGIN = 3e-4
ROLLING_MARGIN = 1e-3
#: inside that band a libration is tried on at most this many nodes in φ (a failed try
#: costs ~0.1 s) and kept only if its tables converge (LibrationSolution.resolved)
BAND_NODES = 16384
#: and a rolling motion uses the quadrature if 1/|u̇| is resolved to this on half its grid
HALF_GRID_TAIL = 1e-11
#: or if it is at the noise floor of its samples below this (see _resolved)
ROLLING_NOISE = 1e-9
#: amplitudes up to this fraction of the local well's radius use the local well model
LOCAL_FRACTION = 0.5
MODES = ('dynamic', 'kinematic')
#: names of the solvers whose motion is known at any time without stepping (for reports)
CLOSED_FORM_SOLVERS = tuple(kind.name for kind in (QuadratureSolution, LibrationSolution,
                                                   RestSolution, TurningPointSolution))


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
    solver : str
        Name of the solver used: 'quadrature', 'libration', 'oscillation' (over several wells), 'rest' or 'DOP853'.
    sol : PhaseSolution
        Dense output: ``sol(t)`` is an array (2, ...) of u (rad) and u̇ (rad/s) at times t
        (s), for every method, like scipy's ``OdeSolution``.
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
    if dynamics.general:       # u̇₀ is infinite where the body does not turn in u
        return simulate_phase(dynamics, t_eval, u0, None, mode=mode, method=method,
                              tolerance=tolerance, angular_speed=omega0)
    return simulate_phase(dynamics, t_eval, u0, dynamics.initial_phase_rate(u0, omega0),
                          mode=mode, method=method, tolerance=tolerance)


def simulate_phase(dynamics, t_eval, u0, u_dot0, *, mode='dynamic', method='table',
                   tolerance=1e-10, angular_speed=None):
    """As :func:`simulate`, from the phase u0 (rad) and phase rate u_dot0 (rad/s).

    In kinematic mode the angular speed held is |u_dot0|·|ω_u(u0)|. For a body other than the
    ellipse the start may instead be given as ``angular_speed`` w0 = |ω_u(u0)| u̇0 (rad/s,
    signed; u_dot0 is then ignored): the one form that holds where the body does not turn in
    u (|ω_u(u0)| = 0, u̇0 infinite).
    """
    _check_choice('mode', mode, MODES)
    _check_choice('method', method, METHODS)
    t_eval = np.asarray(t_eval, dtype=float)
    if dynamics.general:
        u0 = float(u0)
        w0 = (float(angular_speed) if angular_speed is not None
              else float(u_dot0) * float(dynamics.angular_speed_per_phase(u0)))
        closed = general_closed_form(dynamics, mode, method, u0, w0, _REGULAR_FORMS)
        if closed is not None:
            return _motion(dynamics, mode, method, t_eval, closed)
        sol, nfev = sundman(dynamics, mode, method, float(t_eval[-1]), u0, w0, tolerance)
        return _motion(dynamics, mode, method, t_eval, sol, nfev)
    u0, u_dot0 = float(u0), float(u_dot0)
    closed = _closed_form(dynamics, mode, method, u0, u_dot0)
    if closed is not None:
        return _motion(dynamics, mode, method, t_eval, closed)
    sol, nfev = _ode(dynamics, mode, method, float(t_eval[-1]), u0, u_dot0, tolerance)
    return _motion(dynamics, mode, method, t_eval, sol, nfev)


class MotionStream:
    """Samples of one motion at increasing times, for as long as asked (the node's source).

    A closed-form solution is evaluated at any time. Otherwise DOP853 is run lazily, in
    segments that cover the times asked for and at least ``lookahead`` seconds beyond the
    last segment, at most ``chunk`` seconds each, each continued from the end state of the
    one before: the first samples cost only the integration up to them (a 10 s segment
    through the sharp features of a thin body cost ~30 s of CPU), and the choice between
    closed form and ODE is made once.
    """

    def __init__(self, dynamics, u0, u_dot0, *, mode='dynamic', method='table',
                 tolerance=1e-10, chunk=10.0, lookahead=0.5, angular_speed=None):
        _check_choice('mode', mode, MODES)
        _check_choice('method', method, METHODS)
        self.dynamics, self.mode, self.method, self.tolerance = dynamics, mode, method, tolerance
        self._chunk, self._lookahead = float(chunk), min(float(lookahead), float(chunk))
        self._start = 0.0
        u0 = float(u0)
        if dynamics.general:     # the state is (u, w), w = |ω_u| u̇ (simulate_phase)
            w0 = (float(angular_speed) if angular_speed is not None
                  else float(u_dot0) * float(dynamics.angular_speed_per_phase(u0)))
            closed = general_closed_form(dynamics, mode, method, u0, w0, _REGULAR_FORMS)
            self._end_state = (u0, w0)
            self._speed = abs(w0)
            self.initial_energy = float(0.5 * dynamics.tabulated_inertia(u0) * w0**2
                                        + dynamics.tabulated(u0)[1])
            self._sol = closed if closed is not None else SundmanSolution(
                None, [u0, w0, 0.0], 0.0, dynamics.angular_speed_per_phase)
        else:
            u_dot0 = float(u_dot0)
            closed = _closed_form(dynamics, mode, method, u0, u_dot0)
            #: the solution from ``_start`` on: closed form, or the ODE's segment so far
            self._sol = closed if closed is not None else OdeSolution(None, [u0, u_dot0], 0.0)
            self._end_state = (u0, u_dot0)
            self._speed = abs(u_dot0 * float(dynamics.angular_speed_per_phase(u0)))
            self.initial_energy = float(dynamics.energy(u0, u_dot0))
        #: right-hand-side evaluations of the ODE segments so far (0 for a closed form)
        self.nfev = 0

    @property
    def solver(self):
        """Name of the solver: 'quadrature', 'libration', 'rest' or 'DOP853'."""
        return self._sol.name if self._sol.closed_form else 'DOP853'

    def sample(self, t):
        """(u, u̇) at times t (s, array, increasing, not before earlier calls)."""
        return self._sample(t, False)

    def sample_with_speed(self, t):
        """(u, u̇, w) at times t (s, increasing, not before earlier calls): w = |ω_u| u̇ the
        angular speed about AB (rad/s, signed as u̇), finite also where the body stops
        turning in u (:func:`~twodisk_ros.physics.motion.sundman.turning_state`)."""
        return self._sample(t, True)

    def _sample(self, t, with_speed):
        t = np.asarray(t, dtype=float)
        pieces = []
        while True:
            end = self._start + self._sol.t_end
            inside = t <= end
            local = t[inside] - self._start
            pieces.append(np.stack(turning_state(self.dynamics, self._sol, local, self.mode,
                                                 self.initial_energy, self._speed)
                                   if with_speed else self._sol(local)))
            t = t[~inside]
            if not t.size:
                break
            general = self.dynamics.general
            if self._sol.t_end > 0:
                state = (self._sol.state(self._sol.t_end) if general
                         else self._sol(self._sol.t_end))
                self._end_state = tuple(float(np.ravel(x)[0]) for x in state)
            self._start = end
            span = min(self._chunk, max(float(t[-1]) - end, self._lookahead))
            self._sol, nfev = (sundman if general else _ode)(
                self.dynamics, self.mode, self.method, span, *self._end_state, self.tolerance)
            self.nfev += nfev
        joined = np.concatenate(pieces, axis=1)
        return tuple(joined)


def _motion(dynamics, mode, method, t, sol, nfev=0):
    u, u_dot = sol(t)
    return RollingMotion(dynamics=dynamics, mode=mode, method=method, t=t, phase=u,
                         phase_rate=u_dot, energy=dynamics.energy(u, u_dot), nfev=nfev,
                         solver=sol.name, sol=sol)


def _closed_form(dynamics, mode, method, u0, u_dot0):
    """The solution of this motion known at any time, or None (then :func:`_ode`)."""
    if mode == 'kinematic':
        omega = u_dot0 * float(dynamics.angular_speed_per_phase(u0))
        if omega == 0:
            return RestSolution(u0)
        if method != 'table':
            return None
        speed = abs(omega)
        return QuadratureSolution(u0, math.copysign(1.0, omega),
                                  lambda u: dynamics.tabulated(u)[..., 2] / speed,
                                  dynamics.table_size)
    if dynamics.flat:
        return _flat_closed_form(dynamics, u0, u_dot0, method)
    small = _small_libration(dynamics, u0, u_dot0)
    if small is not None:
        return small
    if u_dot0 == 0 and dynamics.is_equilibrium(u0):
        return RestSolution(u0)
    if method != 'table':
        return None
    f0 = dynamics.tabulated(u0)
    energy = 0.5 * f0[0] * u_dot0**2 + f0[1]
    margin = energy - dynamics.barrier
    centre = dynamics.well(u0)[0] if margin < 0 else None
    return _table_closed_form(dynamics, u0, u_dot0, energy, margin, centre)


def _ode(dynamics, mode, method, t_end, u0, u_dot0, tolerance):
    """DOP853 from (u0 (rad), u_dot0 (rad/s)) over [0, t_end] (s): (OdeSolution, nfev).

    For a motion without a closed form (:func:`_closed_form` gave None).
    """
    if mode == 'kinematic':
        omega = u_dot0 * float(dynamics.angular_speed_per_phase(u0))
        speed, direction = abs(omega), math.copysign(1.0, omega)

        def rate(u):
            return direction * speed / dynamics.angular_speed_per_phase(u)

        def rhs(t, y):
            return [float(rate(y[0]))]
        return _solve(rhs, t_end, [u0], tolerance, 1.0, rate=rate)
    if dynamics.flat:
        def rhs(t, y):
            m, dm = (float(x) for x in dynamics.effective_mass_jet(y[0]))
            return [y[1], -0.5 * dm * y[1] ** 2 / m]
        return _solve(rhs, t_end, [u0, u_dot0], tolerance, max(abs(u_dot0), 1.0))
    f0 = dynamics.tabulated(u0)
    energy = 0.5 * f0[0] * u_dot0**2 + f0[1]
    centre = dynamics.well(u0)[0] if _in_one_well(dynamics, u0, energy) else None
    if method == 'table' and centre is None:
        # The table method falls back on DOP853 only where no closed form is resolved: next
        # to the separatrix (docs/physics.md). Rolling over it, a thin body's m(u) spans
        # orders of magnitude, and so does u̇ = w/|ω_u|: stepping in t, DOP853 needs steps as
        # short as the fastest swing (a = 1 mm, b/a = 0.01, Δ/a = 0.001 from θ0 = 0 at
        # 3 rad/s: 171 560 right-hand sides for 0.05 s, energy drift 1.2e-7; a 0.5 s batch
        # took 356 s). The regular chart (u, w) in the Sundman time τ (the chart of every
        # other lamina, physics/motion/sundman.py) has no such swing: 2 117 for the same
        # 0.05 s, drift 4.4e-9. The state crosses in and out as (u, u̇). (An oscillation in
        # one well keeps the centred chart below: its displacement keeps relative precision.)
        rate0 = float(dynamics.angular_speed_per_phase(u0))
        return sundman(dynamics, mode, method, t_end, u0, u_dot0 * rate0, tolerance)
    if method == 'table':
        def rhs(t, y):
            u = y[0] if centre is None else centre + y[0]
            f = dynamics.tabulated(u)
            df = dynamics.tabulated(u, derivative=1)
            return [y[1], -(df[1] + 0.5 * df[0] * y[1] ** 2) / f[0]]
    else:
        def rhs(t, y):
            u = y[0] if centre is None else centre + y[0]
            m, dm = (float(x) for x in dynamics.effective_mass_jet(u))
            dv = float(dynamics.potential_slope(u))
            return [y[1], -(dv + 0.5 * dm * y[1] ** 2) / m]
    if centre is None:
        return _solve(rhs, t_end, [u0, u_dot0], tolerance, max(abs(u_dot0), 1.0))
    # an oscillation: integrate δ = u − u*, so that rtol and atol act on the displacement
    frequency = math.sqrt(dynamics.potential_curvature(centre) / float(f0[0]))
    delta0 = u0 - centre
    amplitude = math.hypot(delta0, u_dot0 / frequency)
    return _solve(rhs, t_end, [delta0, u_dot0], tolerance,
                  np.array([amplitude, amplitude * frequency]), centre=centre)


def _table_closed_form(dynamics, u0, u_dot0, energy, margin, centre):
    """The table method's closed-form solution for energy E, or None (then DOP853).

    Away from the barrier (margins in M g L) as before. Inside the band the closed form is
    taken only if it is resolved on its grid: 1/|u̇| resolved on half the table grid
    (:func:`_resolved`), or a libration whose tables in φ converge within
    BAND_NODES nodes. The band is in units of M g L, but what matters is E − max V against
    the variation of V: for a thin or nearly neutral body (b/a = 0.01, Δ/a → 1: max V − min V
    ~ 2e-8 M g L) every motion lies in the band, far from the separatrix in its own terms,
    and DOP853 through the sharp features of m(u) took ~50 000 steps per 10 s.
    """
    n, scale = dynamics.table_size, dynamics.energy_scale
    if u_dot0 != 0 and margin > 0:
        def inverse_speed(u):
            f = dynamics.tabulated(u)
            return np.sqrt(f[..., 0] / (2.0 * (energy - f[..., 1])))
        if margin > ROLLING_MARGIN * scale or _resolved(inverse_speed, n):
            return QuadratureSolution(u0, math.copysign(1.0, u_dot0), inverse_speed, n)
    if margin < 0:
        margin = energy - dynamics.well_rim(u0)    # the lower maximum bounding the well
        if margin >= 0:      # over it: an oscillation across several wells
            return span_closed_form(dynamics, u0, math.copysign(1.0, u_dot0) if u_dot0 else
                                    0.0, energy)
        well = dynamics.tabulated_well(centre)
        if margin < -LIBRATION_MARGIN * scale:
            return LibrationSolution(well, u0 - centre, u_dot0, n)
        try:
            libration = LibrationSolution(well, u0 - centre, u_dot0, min(n, BAND_NODES))
        except RuntimeError:     # dt/dφ not positive and finite on the grid: at the barrier
            return None
        if libration.resolved:
            return libration
    return None


def _in_one_well(dynamics, u0, energy):
    """True if a motion of energy E (J) from u0 (rad) stays in the well holding u0: E below
    the lower of the two maxima bounding it (:meth:`RollingDynamics.well_rim`)."""
    return energy < dynamics.barrier and energy < dynamics.well_rim(u0)


def span_closed_form(dynamics, u0, direction, energy):
    """The table method's oscillation of energy E (J) over several wells, between the
    turning points either side of u0 (rad) (physics/motion/turning.py), or None (then DOP853) if
    the turning points are not simple or dt/dφ is not resolved on the table's nodes."""
    n = dynamics.table_size

    def mass(u):
        return dynamics.tabulated(u)[..., 0]
    potential, slope = dynamics.tabulated_potential, partial(dynamics.tabulated_potential,
                                                              derivative=1)
    bounds = turning_points(potential, slope, energy, u0, direction, n)
    if bounds is None:
        return None
    try:
        solution = TurningPointSolution(potential, slope, mass, bounds, u0, direction, n)
    except RuntimeError:
        return None
    return solution if solution.resolved else None


def _resolved(function, n):
    """True if the periodic function, sampled on n nodes over a cycle, is finite, positive
    and resolved: already on every other node its spectral tail is below HALF_GRID_TAIL, so
    on all n it is converged far below (spectra of analytic functions shrink geometrically).
    The tail on the n nodes themselves would show the rounding of E − V instead (~1e-13 when
    E − V is 1 % of V).

    Or resolved down to that rounding: the tail on every other node is below ROLLING_NOISE
    and did not shrink by STALL from every fourth node. A geometric spectrum ρᵏ whose tail
    shrinks by less than STALL under a doubling has a tail above STALL² (its tail at N/4
    modes is the square of that ratio), so a small tail that stalls is noise: for a thin,
    nearly neutral body (b/a = 0.01, Δ/a → 1) at a = 1 mm and 3 rad/s, E − V is 1e-5 of V
    and its rounding puts a flat floor of ~5e-12 under the spectrum of 1/|u̇| from mode 100
    on (tails 1.6e-11, 1.2e-11 on 2¹⁵, 2¹⁶ nodes), and DOP853 ran > 5 min for its 10 s."""
    samples = function(TWO_PI * np.arange(n) / n)
    if not (np.all(np.isfinite(samples)) and np.all(samples > 0)):
        return False
    half = spectral_tail(samples[::2])
    if half < HALF_GRID_TAIL:
        return True
    return bool(half < ROLLING_NOISE and half > STALL * spectral_tail(samples[::4]))


def _small_libration(dynamics, u0, u_dot0):
    """The solution of a small oscillation (or rest) about a stable equilibrium, else None.

    Small: within LOCAL_FRACTION of the radius of the equilibrium's
    :class:`~twodisk_ros.physics.stability.wells.LocalWell`, for both methods.
    """
    if not dynamics.has_wells:
        return None
    centre = dynamics.well(u0)[0]
    delta0 = u0 - centre
    if delta0 == 0 and u_dot0 == 0:
        return RestSolution(u0)
    f0 = dynamics.tabulated(u0)
    if not _in_one_well(dynamics, u0, 0.5 * f0[0] * u_dot0**2 + f0[1]):
        return None
    local = dynamics.local_well(centre)
    if abs(delta0) > local.radius:
        return None
    amplitude = math.hypot(delta0, u_dot0 * math.sqrt(float(local.mass(delta0))
                                                      / local.stiffness))
    if amplitude > LOCAL_FRACTION * local.radius:
        return None
    return LibrationSolution(local, delta0, u_dot0, dynamics.table_size)


def _flat_closed_form(dynamics, u0, u_dot0, method):
    """V constant (g = 0 or z_G constant): ½ m(u) u̇² is conserved, the body rolls on."""
    if u_dot0 == 0:
        return RestSolution(u0)
    if method != 'table':
        return None
    m0 = float(dynamics.tabulated(u0)[0])

    def inverse_speed(u):
        return np.sqrt(dynamics.tabulated(u)[..., 0] / m0) / abs(u_dot0)
    return QuadratureSolution(u0, math.copysign(1.0, u_dot0), inverse_speed,
                              dynamics.table_size)


def _solve(rhs, t_end, y0, tolerance, scale, rate=None, centre=None):
    """DOP853 over [0, t_end] (s): (OdeSolution, right-hand-side evaluations)."""
    from scipy.integrate import solve_ivp
    t_end = float(t_end)
    if t_end == 0.0:
        return OdeSolution(None, y0, t_end, rate, centre), 0
    result = solve_ivp(rhs, (0.0, t_end), y0, method='DOP853', rtol=tolerance,
                       atol=tolerance * scale, dense_output=True)
    if not result.success:
        raise RuntimeError(f'integration failed: {result.message}')
    return OdeSolution(result.sol, y0, t_end, rate, centre), result.nfev


#: the closed forms of the ellipse path that general_closed_form reuses where u is regular
_REGULAR_FORMS = (_small_libration, _table_closed_form, span_closed_form)
