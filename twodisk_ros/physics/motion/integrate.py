"""Motions stepped in time: DOP853 where no closed form holds, from the state (u, w).

w = |ω_u| u̇ is the body's angular speed about the contact line AB (rad/s), finite wherever
the body is. Two charts of that one state:

* a body that turns in u at every phase (``body.turns_everywhere``: |ω_u| > 0, e.g. the
  ellipse or the egg) is stepped in t in (u, u̇), inside a well in the displacement
  δ = u − u* (which keeps its relative precision however small the amplitude), except the
  table method's rolling over near the separatrix, which is stepped in τ as below;
* a body that stops turning in u at isolated phases (a contact crossing a superellipse's
  flat vertex: |ω_u| = 0, m(u) = 0, u̇ infinite for an instant, so m ü + ½ m′ u̇² + V′ = 0
  is singular) is stepped in the regularised time τ, dt/dτ = |ω_u|, where du/dτ = w and
  (u, w) stay finite (:class:`~twodisk_ros.physics.motion.solvers.SundmanSolution`,
  docs/physics.md#bodies-that-stop-turning-in-u), with closed forms (``direct``) or the
  periodic tables of m, V, |ω_u| and J (``table``).
"""

import math

import numpy as np

from .closed_forms import in_one_well
from .solvers import OdeSolution, SundmanSolution

__all__ = ['integrate', 'sundman', 'turning_state']


def integrate(dynamics, mode, method, t_end, u0, w0, u_dot0, tolerance):
    """DOP853 from (u0 (rad), w0 (rad/s)) over t ∈ [0, t_end] (s): (solution, nfev).

    ``u_dot0`` = w0/|ω_u(u0)| (rad/s) is the state of the chart in t (module docstring).
    """
    if dynamics.body.turns_everywhere:
        return _ode(dynamics, mode, method, t_end, u0, u_dot0, tolerance)
    return sundman(dynamics, mode, method, t_end, u0, w0, tolerance)


def _ode(dynamics, mode, method, t_end, u0, u_dot0, tolerance):
    """DOP853 from (u0 (rad), u_dot0 (rad/s)) over [0, t_end] (s): (OdeSolution, nfev).

    For a motion without a closed form (:func:`~twodisk_ros.physics.motion.closed_forms.closed_form` gave None).
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
    centre = dynamics.well(u0)[0] if in_one_well(dynamics, u0, energy) else None
    if method == 'table' and centre is None:
        # The table method falls back on DOP853 only where no closed form is resolved: next
        # to the separatrix (docs/physics.md). Rolling over it, a thin body's m(u) spans
        # orders of magnitude, and so does u̇ = w/|ω_u|: stepping in t, DOP853 needs steps as
        # short as the fastest swing (a = 1 mm, b/a = 0.01, Δ/a = 0.001 from θ0 = 0 at
        # 3 rad/s: 171 560 right-hand sides for 0.05 s, energy drift 1.2e-7; a 0.5 s batch
        # took 356 s). The regular chart (u, w) in the Sundman time τ (the chart of a body
        # that stops turning in u, :func:`sundman`) has no such swing: 2 117 for the same
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


def sundman(dynamics, mode, method, t_end, u0, w0, tolerance):
    """DOP853 in the regularised time τ over t ∈ [0, t_end] (s): (SundmanSolution, nfev)."""
    from scipy.integrate import solve_ivp
    if method == 'table':
        def terms(u):
            f = dynamics.tabulated(u)
            return (float(dynamics.tabulated_inertia(u)),
                    float(dynamics.tabulated_inertia(u, derivative=1)),
                    float(dynamics.tabulated_potential(u, derivative=1)), float(f[2]))
    else:
        def terms(u):
            j, dj = dynamics.contact_line_inertia_jet(u)
            return (float(j), float(dj), float(dynamics.potential_slope(u)),
                    float(dynamics.angular_speed_per_phase(u)))
    kinematic, flat = mode == 'kinematic', dynamics.flat

    def rhs(tau, y):
        j, dj, dv, rate = terms(y[0])
        if kinematic:
            return [y[1], 0.0, rate]
        return [y[1], -(0.5 * dj * y[1] ** 2 + (0.0 if flat else dv)) / j, rate]
    y0 = [float(u0), float(w0), 0.0]
    t_end = float(t_end)
    rate_of = dynamics.angular_speed_per_phase
    if t_end == 0.0:
        return SundmanSolution(None, y0, 0.0, rate_of), 0
    mean_rate = float(np.mean(dynamics.tabulated(np.linspace(0, 2 * math.pi, 64,
                                                              endpoint=False))[..., 2]))

    def reached(tau, y):
        return y[2] - t_end
    reached.terminal = True
    scale = np.array([1.0, max(abs(w0), 1.0), max(t_end, 1.0)])
    span, nfev = 4.0 * t_end / mean_rate + 1.0, 0
    while True:
        result = solve_ivp(rhs, (0.0, span), y0, method='DOP853', rtol=tolerance,
                           atol=tolerance * scale, dense_output=True, events=reached)
        nfev += result.nfev
        if not result.success:
            raise RuntimeError(f'integration failed: {result.message}')
        if result.t_events[0].size:
            return SundmanSolution(result.sol, y0, float(result.t_events[0][0]), rate_of), nfev
        span *= 4.0


def turning_state(dynamics, sol, t, mode, energy, speed):
    """(u, u̇, w) of a solution at times t (s, from its start): w = |ω_u| u̇ (rad/s, signed as
    u̇) in the regular chart, finite where the body stops turning in u.

    DOP853 in τ (:class:`SundmanSolution`) integrates w itself; u̇ = w/|ω_u| as it reports.
    A closed form gives (u, u̇); then w is |ω_u| u̇ for a body that turns everywhere
    (|ω_u| > 0) and, for any other body, what the solution conserves, evaluated where it is regular: |w| = Ω
    (``speed``, kinematic) or √(2(E − V(u))/J(u)) (``energy`` E, J the inertia about AB), with
    the sign of u̇. (At a flat vertex |ω_u| and m are rounding, ~1e-13 and ~1e-27, so |ω_u| u̇
    and ½ m u̇² are not: 2.17 rad/s and a 2e-5 error of E at the vertex of the n = 4
    square at 3 rad/s.)
    """
    if sol.regular_chart:
        u, w = sol.state(t)
        with np.errstate(divide='ignore', invalid='ignore'):
            return u, w / dynamics.angular_speed_per_phase(u), w
    u, u_dot = sol(t)
    if dynamics.body.turns_everywhere:
        return u, u_dot, dynamics.tabulated(u)[..., 2] * u_dot
    if mode == 'kinematic':
        return u, u_dot, np.sign(u_dot) * abs(speed)
    twice = np.maximum(2.0 * (energy - dynamics.tabulated(u)[..., 1]), 0.0)
    return u, u_dot, np.sign(u_dot) * np.sqrt(twice / dynamics.tabulated_inertia(u))


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
