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
    bracketed Newton, or for large calls by a table of its inverse checked against it (no time
    stepping, no drift); when it oscillates in a well (E < max V),
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
import math

import numpy as np

from .closed_forms import closed_form
from .dynamics import PhaseState, RollingDynamics
from .integrate import integrate, turning_state
from .solvers import LibrationSolution, OdeSolution, QuadratureSolution, RestSolution
from .turning import TurningPointSolution

__all__ = ['CLOSED_FORM_SOLVERS', 'METHODS', 'MODES', 'MotionStream', 'RollingMotion',
           'simulate', 'simulate_phase']

METHODS = ('direct', 'table')
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
    return simulate_phase(dynamics, t_eval, u0, None, mode=mode, method=method,
                          tolerance=tolerance, angular_speed=omega0)


def simulate_phase(dynamics, t_eval, u0, u_dot0, *, mode='dynamic', method='table',
                   tolerance=1e-10, angular_speed=None):
    """As :func:`simulate`, from the phase u0 (rad) and phase rate u_dot0 (rad/s).

    In kinematic mode the angular speed held is |w0| = |u_dot0|·|ω_u(u0)|. The start may instead
    (or as well) be given as ``angular_speed`` w0 = |ω_u(u0)| u̇0 (rad/s, signed; u_dot0 may
    then be None): the form that holds also where the body does not turn in u (|ω_u(u0)| = 0,
    u̇0 infinite).
    """
    _check_choice('mode', mode, MODES)
    _check_choice('method', method, METHODS)
    t_eval = np.asarray(t_eval, dtype=float)
    u0, u_dot0, w0 = _start(dynamics, u0, u_dot0, angular_speed)
    closed = closed_form(dynamics, mode, method, u0, w0, u_dot0)
    if closed is not None:
        return _motion(dynamics, mode, method, t_eval, closed)
    sol, nfev = integrate(dynamics, mode, method, float(t_eval[-1]), u0, w0, u_dot0, tolerance)
    return _motion(dynamics, mode, method, t_eval, sol, nfev)


def _start(dynamics, u0, u_dot0, angular_speed):
    """The :class:`~twodisk_ros.physics.motion.dynamics.PhaseState` (u0, u̇0, w0) of a start
    given by u̇0 (rad/s), by w0 = ``angular_speed`` (rad/s), or by both (one state of two
    charts: a finite u̇0 is kept as given, else u̇0 = w0/|ω_u(u0)|)."""
    if angular_speed is None:
        u0, u_dot0 = float(u0), float(u_dot0)
        return PhaseState(u0, u_dot0, u_dot0 * float(dynamics.angular_speed_per_phase(u0)))
    state = dynamics.initial_state(u0, angular_speed)
    if u_dot0 is not None and math.isfinite(u_dot0):
        return PhaseState(state.phase, float(u_dot0), state.angular_speed)
    return state


class MotionStream:
    """Samples of one motion at increasing times, for as long as asked (the node's source).

    A closed-form solution is evaluated at any time. Otherwise DOP853 is run lazily, in
    segments that cover the times asked for and at least ``lookahead`` seconds beyond the
    last segment, at most ``chunk`` seconds each, each continued from the end state of the
    one before: the first samples cost only the integration up to them (a 10 s segment
    through the sharp features of a thin body cost ~30 s of CPU), and the choice between
    closed form and ODE is made once. The start is u_dot0 (rad/s) or ``angular_speed`` w0
    (rad/s, as :func:`simulate_phase`).
    """

    def __init__(self, dynamics, u0, u_dot0, *, mode='dynamic', method='table',
                 tolerance=1e-10, chunk=10.0, lookahead=0.5, angular_speed=None):
        _check_choice('mode', mode, MODES)
        _check_choice('method', method, METHODS)
        self.dynamics, self.mode, self.method, self.tolerance = dynamics, mode, method, tolerance
        self._chunk, self._lookahead = float(chunk), min(float(lookahead), float(chunk))
        self._start = 0.0
        u0, u_dot0, w0 = self._end_state = _start(dynamics, u0, u_dot0, angular_speed)
        self._speed = abs(w0)
        #: E (J): from u̇ where the body turns everywhere, else in the regular chart (u, w)
        self.initial_energy = float(
            dynamics.energy(u0, u_dot0) if dynamics.body.turns_everywhere
            else 0.5 * dynamics.tabulated_inertia(u0) * w0**2 + dynamics.tabulated(u0)[1])
        closed = closed_form(dynamics, mode, method, u0, w0, u_dot0)
        #: the solution from ``_start`` on: closed form, or the ODE's segment so far
        self._sol = closed if closed is not None else OdeSolution(None, [u0, u_dot0], 0.0)
        #: right-hand-side evaluations of the ODE segments so far (0 for a closed form)
        self.nfev = 0
        #: [(start s, solution)]: the pieces the latest call reached (:meth:`state_at`)
        self._window = [(self._start, self._sol)]

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
        turning in u (:func:`~twodisk_ros.physics.motion.integrate.turning_state`)."""
        return self._sample(t, True)

    @property
    def segment(self):
        """(start, end) (s) of the solution piece the last call ended in (end inf for a
        closed form)."""
        return self._start, self._start + self._sol.t_end

    @property
    def window(self):
        """(start, end) (s): :meth:`state_at`'s span, every solution piece the last call
        reached (a call past a segment's end integrates the next ones)."""
        start, sol = self._window[-1]
        return self._window[0][0], start + sol.t_end

    def state_at(self, t):
        """(u, u̇, w) at times t (s, 1-d, any order) within :attr:`window`, from the same
        dense solutions as :meth:`sample_with_speed` (a time on the boundary of two pieces
        from the earlier one, as there) and without moving on: the root finding between
        samples of :mod:`~twodisk_ros.run.hybrid`. ValueError outside the window."""
        t = np.asarray(t, dtype=float)
        start, end = self.window
        if np.any(t < start) or np.any(t > end):
            raise ValueError(f'state_at: times must lie in [{start:g}, {end:g}] s')
        ends = np.array([s + sol.t_end for s, sol in self._window])
        piece = np.minimum(np.searchsorted(ends, t, 'left'), len(ends) - 1)
        out = np.empty((3, t.size))
        for k in np.unique(piece):
            mine = piece == k
            s, sol = self._window[k]
            out[:, mine] = np.stack(turning_state(self.dynamics, sol, t[mine] - s, self.mode,
                                                  self.initial_energy, self._speed))
        return tuple(out)

    def _sample(self, t, with_speed):
        t = np.asarray(t, dtype=float)
        pieces, window = [], []
        while True:
            end = self._start + self._sol.t_end
            window.append((self._start, self._sol))
            inside = t <= end
            local = t[inside] - self._start
            pieces.append(np.stack(turning_state(self.dynamics, self._sol, local, self.mode,
                                                 self.initial_energy, self._speed)
                                   if with_speed else self._sol(local)))
            t = t[~inside]
            if not t.size:
                break
            if self._sol.t_end > 0:
                self._end_state = _end_state(self.dynamics, self._sol)
            self._start = end
            span = min(self._chunk, max(float(t[-1]) - end, self._lookahead))
            u0, u_dot0, w0 = self._end_state
            self._sol, nfev = integrate(self.dynamics, self.mode, self.method, span, u0, w0,
                                        u_dot0, self.tolerance)
            self.nfev += nfev
        self._window = [piece for piece in window if piece[1].t_end > 0] or window
        joined = np.concatenate(pieces, axis=1)
        return tuple(joined)


def _end_state(dynamics, sol):
    """(u, u̇, w) at the end of a stepped segment: (u, w) of the regular chart if the segment
    holds it (u̇ = w/|ω_u|, infinite where the body stops turning), else (u, u̇) of the
    chart in t (a body that turns everywhere: w = |ω_u| u̇)."""
    if sol.regular_chart:          # one search of t(τ): u̇ as the solution reports it
        u, w = (float(np.ravel(x)[0]) for x in sol.state(sol.t_end))
        with np.errstate(divide='ignore'):
            return u, float(w / dynamics.angular_speed_per_phase(u)), w
    u, u_dot = (float(np.ravel(x)[0]) for x in sol(sol.t_end))
    return u, u_dot, u_dot * float(dynamics.angular_speed_per_phase(u))


def _motion(dynamics, mode, method, t, sol, nfev=0):
    u, u_dot = sol(t)
    return RollingMotion(dynamics=dynamics, mode=mode, method=method, t=t, phase=u,
                         phase_rate=u_dot, energy=dynamics.energy(u, u_dot), nfev=nfev,
                         solver=sol.name, sol=sol)
