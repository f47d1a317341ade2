"""Motions of a body other than the ellipse, also where it stops turning in u.

A :class:`~twodisk_ros.physics.bodies.lamina_body.LaminaBody` may not turn per unit of its phase at
isolated phases (|ω_u| = 0, m(u) = 0: a contact crossing a flat vertex). There u̇ is infinite
for an instant and the equation m ü + ½ m′ u̇² + V′ = 0 is singular, so the state is carried
as (u, w), w = |ω_u| u̇ the body's angular speed about the contact line AB (rad/s, finite),
and (docs/physics.md#bodies-that-stop-turning-in-u):

* the table method's quadratures stay as they are: t = ∫ √(m / (2(E − V))) du (rolling over)
  and t = ∫ |ω_u| du / Ω (kinematic) only see 1/|u̇| vanish at isolated phases;
* libration in the angle φ and the local well models need V″ > 0 and m > 0 at the centre:
  they are used only about equilibria where the body turns in u (``regular_centre``);
* everything else (the direct method, the band around the separatrix, wells about a
  degenerate equilibrium) is DOP853 in the regularised time τ of
  :class:`~twodisk_ros.physics.motion.solvers.SundmanSolution`, with closed forms (``direct``) or the
  periodic tables of m, V, |ω_u| and J (``table``).
"""

import math

import numpy as np

from .solvers import QuadratureSolution, RestSolution, SundmanSolution

__all__ = ['SundmanSolution', 'general_closed_form', 'sundman', 'turning_state']


def general_closed_form(dynamics, mode, method, u0, w0, regular_forms):
    """The closed-form solution from (u0 (rad), w0 (rad/s)), or None (then :func:`sundman`).

    ``regular_forms`` = (small_libration, table_closed_form, span_closed_form) of the
    ellipse path (physics/motion/simulate.py), the first two used where u is regular at the start and
    at the well's centre; an oscillation over several wells (E above the lower maximum
    bounding the well, below the highest) is the span's closed form wherever it starts.
    """
    small_libration, table_closed_form, span_closed_form = regular_forms
    n = dynamics.table_size
    if w0 == 0 and (mode == 'kinematic' or dynamics.flat or dynamics.is_equilibrium(u0)):
        return RestSolution(u0)
    direction = math.copysign(1.0, w0)
    if mode == 'kinematic':
        if method != 'table':
            return None
        speed = abs(w0)
        return QuadratureSolution(u0, direction, lambda u: dynamics.tabulated(u)[..., 2] / speed,
                                  n)
    if dynamics.flat:
        if method != 'table':
            return None
        twice_kinetic = float(dynamics.tabulated_inertia(u0)) * w0 * w0
        return QuadratureSolution(u0, direction, lambda u: np.sqrt(
            dynamics.tabulated(u)[..., 0] / twice_kinetic), n)
    rate0 = float(dynamics.angular_speed_per_phase(u0))
    centre = dynamics.well(u0)[0] if dynamics.has_wells else None
    energy = 0.5 * float(dynamics.tabulated_inertia(u0)) * w0 * w0 + float(
        dynamics.tabulated(u0)[1])
    margin = energy - dynamics.barrier
    if centre is not None and margin < 0 and energy >= dynamics.well_rim(u0):
        return (span_closed_form(dynamics, u0, direction if w0 else 0.0, energy)
                if method == 'table' else None)
    regular = rate0 > 0 and (centre is None or dynamics.regular_centre(centre))
    if regular:
        u_dot0 = w0 / rate0
        small = small_libration(dynamics, u0, u_dot0)
        if small is not None:
            return small
        if method != 'table':
            return None
        return table_closed_form(dynamics, u0, u_dot0, energy, margin,
                                 centre if margin < 0 else None)
    if method == 'table' and w0 != 0 and margin > 0:
        def inverse_speed(u):
            f = dynamics.tabulated(u)
            return np.sqrt(f[..., 0] / (2.0 * (energy - f[..., 1])))
        try:
            return QuadratureSolution(u0, direction, inverse_speed, n)
        except RuntimeError:            # E − V not positive on the grid: at the barrier
            return None
    return None


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
    A closed form gives (u, u̇); then w is |ω_u| u̇ for the ellipse (|ω_u| > 0 everywhere) and,
    for any other body, what the solution conserves, evaluated where it is regular: |w| = Ω
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
    if not dynamics.general:
        return u, u_dot, dynamics.tabulated(u)[..., 2] * u_dot
    if mode == 'kinematic':
        return u, u_dot, np.sign(u_dot) * abs(speed)
    twice = np.maximum(2.0 * (energy - dynamics.tabulated(u)[..., 1]), 0.0)
    return u, u_dot, np.sign(u_dot) * np.sqrt(twice / dynamics.tabulated_inertia(u))
