"""The motions known at every time without stepping: the closed forms of u(t).

From a state (u0, w0) (rad, rad/s; w = |ω_u| u̇ the body's angular speed about the contact
line AB), :func:`closed_form` gives the solution that holds for ever, or None (then
:func:`~twodisk_ros.physics.motion.integrate.integrate` steps it). One function for every body:

* kinematic mode (|w| = Ω held): rest if Ω = 0, else t = ∫ |ω_u| du / Ω (table method);
* V flat (g = 0 or z_G constant): rest, or t = ∫ du/|u̇| with ½ m u̇² = ½ J w² conserved;
* where u is a regular chart at the start and at the centre of its well (|ω_u| > 0 there,
  z_G quadratic at the centre): a small libration in the local well model (both methods),
  rest at an equilibrium, and with the table method the quadrature of rolling over, the
  libration in the angle φ or the oscillation over several wells
  (docs/physics.md#the-two-methods-direct-and-table);
* elsewhere (the body does not turn in u at the start or at the well's centre: a contact on
  a superellipse's flat vertex): rest, the oscillation over several wells, or the quadrature
  of rolling over, whose 1/|u̇| = √(m / (2(E − V))) only vanishes at isolated phases
  (docs/physics.md#bodies-that-stop-turning-in-u).

The ellipse takes these closed forms as any body does; only its functions of u are closed
forms of their own.
"""

from functools import partial
import math

import numpy as np

from ..bodies.cycle import TWO_PI
from ..numerics.spectral import STALL, spectral_tail
from .solvers import LibrationSolution, QuadratureSolution, RestSolution
from .turning import TurningPointSolution, turning_points

__all__ = ['BAND_NODES', 'HALF_GRID_TAIL', 'LIBRATION_MARGIN', 'LOCAL_FRACTION',
           'REGULAR_RATE', 'ROLLING_MARGIN', 'ROLLING_NOISE', 'closed_form', 'in_one_well', 'span_closed_form']

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
#: u is a regular chart at a phase where |ω_u| exceeds this fraction of its peak over the
#: cycle: at a flat vertex |ω_u| is rounding (~1e-11 of the peak), u̇ = w/|ω_u| and ½ m u̇² are
#: then noise; an ellipse stays above 2e-5 of its peak (b/a ≤ 100, Δ/a ≥ 0.001)
REGULAR_RATE = 1e-7


def closed_form(dynamics, mode, method, u0, w0, u_dot0):
    """The solution of the motion from (u0 (rad), w0 (rad/s)) known at any time, or None.

    ``u_dot0`` (rad/s) is u̇0 = w0/|ω_u(u0)|, infinite where the body does not turn at u0
    (used only where it does). See the module docstring for which solution is taken.
    """
    n = dynamics.table_size
    if mode == 'kinematic':
        if w0 == 0:
            return RestSolution(u0)
        if method != 'table':
            return None
        speed = abs(w0)
        return QuadratureSolution(u0, math.copysign(1.0, w0),
                                  lambda u: dynamics.tabulated(u)[..., 2] / speed, n)
    turns = float(dynamics.angular_speed_per_phase(u0)) > REGULAR_RATE * dynamics.peak_turn_rate
    if dynamics.flat:
        if turns:
            return _flat_closed_form(dynamics, u0, u_dot0, method)
        if w0 == 0:
            return RestSolution(u0)
        if method != 'table':
            return None
        twice_kinetic = float(dynamics.tabulated_inertia(u0)) * w0 * w0
        return QuadratureSolution(u0, math.copysign(1.0, w0), lambda u: np.sqrt(
            dynamics.tabulated(u)[..., 0] / twice_kinetic), n)
    centre = dynamics.well(u0)[0] if dynamics.has_wells else None
    if turns and (centre is None or dynamics.regular_centre(centre)):
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
        return _table_closed_form(dynamics, u0, u_dot0, energy, margin,
                                  dynamics.well(u0)[0] if margin < 0 else None)
    # the body does not turn in u at the start or at the well's centre: the state is w
    if w0 == 0 and dynamics.is_equilibrium(u0):
        return RestSolution(u0)
    energy = 0.5 * float(dynamics.tabulated_inertia(u0)) * w0 * w0 + float(
        dynamics.tabulated(u0)[1])
    margin = energy - dynamics.barrier
    if centre is not None and margin < 0 and energy >= dynamics.well_rim(u0):
        return (span_closed_form(dynamics, u0, math.copysign(1.0, w0) if w0 else 0.0, energy)
                if method == 'table' else None)
    if method == 'table' and w0 != 0 and margin > 0:
        def inverse_speed(u):
            f = dynamics.tabulated(u)
            return np.sqrt(f[..., 0] / (2.0 * (energy - f[..., 1])))
        try:
            return QuadratureSolution(u0, math.copysign(1.0, w0), inverse_speed, n)
        except RuntimeError:            # E − V not positive on the grid: at the barrier
            return None
    return None


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


def in_one_well(dynamics, u0, energy):
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
    if not in_one_well(dynamics, u0, 0.5 * f0[0] * u_dot0**2 + f0[1]):
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
