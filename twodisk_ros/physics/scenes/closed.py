"""Closed-form motions of a conservative scene (a slope, no drive, no dissipation).

The energy E = ½ m(u) u̇² + V(u) is conserved, V(u) = V_p(u) + c u/2π with V_p periodic and c
the change of V over one cycle (the drift: c = −M g sin β × the downhill part of a cycle's
mean travel), both tabulated once by :class:`~twodisk_ros.physics.scenes.terms.SceneTerms`
(``energy_jet``). As on flat ground the table method needs no time stepping
(docs/physics.md#scenes):

* **rolling on** (:class:`DriftQuadrature`): while E − V > 0 ahead for good (the motion heads
  downhill on average, c u̇ ≤ 0, and clears the first cycle's maxima of V), u(t) inverts the
  quadrature t(u) = ∫ √(m / (2(E − V))) du. Its integrand is not periodic (E − V grows by |c|
  per cycle), so t is tabulated cycle by cycle as it is needed, on the nodes of the scene's
  tables, each panel integrated by the quintic Hermite rule from f, f′, f″ at its ends, and
  each sample time inverted in its panel by Newton's method on the quintic Hermite t(x);
* **rocking in a well** of the non-periodic V (e.g. aimed across the slope), E below both
  neighbouring maxima: :class:`~twodisk_ros.physics.motion.solvers.LibrationSolution` in the angle
  φ, with the well of :class:`SceneWell` (V′ is periodic, so the wells repeat every cycle;
  only their depths drift);
* **swinging over several wells** between two turning points (E below a maximum on each
  side but above the maxima between): :class:`OscillationSolution`, u = c − r cos φ;
* **rest** at an equilibrium (u̇ = 0, V′ = 0).

Every other conservative motion (a body that climbs, stops and falls back, or starts from
rest off an equilibrium, or runs at the separatrix) has None here and is integrated by
DOP853 (:class:`~twodisk_ros.physics.scenes.motion.SceneStream`).
"""

import math

import numpy as np

from ..bodies.cycle import TWO_PI
from .terms import STOPPED

from ..motion.solvers import LibrationSolution, PhaseSolution, QuadratureSolution, RestSolution
from ..numerics.spectral import spectral_tail
from ..numerics.tables import hermite_jet

__all__ = ['DriftQuadrature', 'OscillationSolution', 'SceneWell', 'conservative_solution']

#: a drift below this fraction of M g L per cycle is none (heading0 = ±π/2 to rounding)
DRIFT_FLOOR = 1e-13
#: cycles searched for a turning point on each side
SEARCH = 4


class DriftQuadrature(PhaseSolution):
    """u(t) rolling on in one direction with V = V_p + c u/2π, E − V > 0 ahead for good.

    With x = σ (u − u₀) ≥ 0 the distance travelled and f(x) = √(m / (2(E − V))) = dt/dx, t(x)
    is tabulated on x_j = j h (h the scene tables' node spacing), one cycle of nodes at a
    time: t_{j+1} − t_j = h (f_j + f_{j+1})/2 + h² (f′_j − f′_{j+1})/10 + h³ (f″_j + f″_{j+1})/120
    (the integral of the quintic Hermite interpolant of f), f′ and f″ from m, V and their
    first two derivatives. A sample time is located among the t_j and x solved in its panel
    by Newton on the quintic Hermite of t(x) (data t, f, f′), to 1e-14 of the panel; then
    w = σ √(2(E − V(u))/J(u)) and u̇ = w/|ω_u|. f = |ω_u| √(J/(2(E − V))) is written with
    J = m/|ω_u|², so that it stays regular where the body stops turning in u (f = 0 there).

    Parameters
    ----------
    terms : SceneTerms
    u0, u_dot0 : float
        Initial phase (rad) and rate (rad/s), u̇0 ≠ 0.
    angular_speed : float, optional
        w0 = |ω_u(u0)| u̇0 (rad/s, ≠ 0) instead of u̇0: the start where |ω_u(u0)| = 0.
    """

    regular_chart = True
    name = 'quadrature'
    #: cycles of nodes kept before the earliest time of the latest call (older ones dropped)
    KEEP = 2
    #: the nodes of t(x) are every STRIDE-th node of the scene's tables (their spacing is
    #: that of the cycle's resolution: t(u) on the last node changed by < 1e-13 rad from
    #: STRIDE = 1 over 13 cycles of the oloid; 8 moved it by 1e-11)
    STRIDE = 4
    #: most cycles of nodes tabulated in one batch
    BATCH = 64

    def __init__(self, terms, u0, u_dot0, angular_speed=None):
        self._terms = terms
        jet = terms.energy_jet(float(u0))
        w0 = float(angular_speed) if angular_speed is not None else float(u_dot0) * float(
            jet[4])
        self._u0, self._s = float(u0), math.copysign(1.0, w0)
        self.energy = 0.5 * float(jet[7]) * w0 ** 2 + float(jet[1])
        self._n = terms.table_nodes // self.STRIDE
        self._h = TWO_PI / self._n
        self._first = 0                        # index of the first node kept
        self._x = np.zeros(0)
        self._t = np.zeros(0)
        self._data = np.zeros((0, 3))          # t, h f, h² f′ at the nodes
        self._extend()

    def _integrand(self, x):
        """f, f′, f″ (in x) at x (arrays): f = |ω_u| a, a = √(J / (2(E − V))), regular
        where the body stops turning in u (f = 0 there: u̇ is infinite for an instant)."""
        u = self._u0 + self._s * x
        _, v, _, dv, rate, _, ddv, j, dj, drate = np.moveaxis(
            self._terms.energy_jet(u), -1, 0)
        _, _, _, _, _, _, _, _, ddj, ddrate = np.moveaxis(
            self._terms.energy_jet(u, 1), -1, 0)
        room = self.energy - v
        if not np.all(room > 0):
            raise RuntimeError('E - V reached 0: the motion turns back (no quadrature)')
        a = np.sqrt(j / (2 * room))
        g1 = 0.5 * dj / j + 0.5 * dv / room                      # (ln a)′ in u
        g2 = 0.5 * ddj / j - 0.5 * (dj / j) ** 2 + 0.5 * ddv / room + 0.5 * (dv / room) ** 2
        da, dda = a * g1, a * (g2 + g1 * g1)
        f = rate * a
        return f, self._s * (drate * a + rate * da), ddrate * a + 2 * drate * da + rate * dda

    def _extend(self, cycles=1):
        """Tabulate ``cycles`` more cycles of nodes (in one batch: the cost per cycle is then
        that of the arithmetic, not of numpy's calls)."""
        start = self._first + len(self._x) - (1 if len(self._x) else 0)
        x = self._h * np.arange(start, start + cycles * self._n + 1)
        f, df, ddf = self._integrand(x)
        h = self._h
        panels = (0.5 * h * (f[:-1] + f[1:]) + h * h / 10 * (df[:-1] - df[1:])
                  + h ** 3 / 120 * (ddf[:-1] + ddf[1:]))
        t0 = self._t[-1] if len(self._t) else 0.0
        t = np.concatenate([[t0], t0 + np.cumsum(panels)])
        data = np.column_stack([t, h * f, h * h * df])
        keep = slice(0, -1) if len(self._x) else slice(None)
        self._x = np.concatenate([self._x[keep], x])
        self._t = np.concatenate([self._t[keep], t])
        self._data = np.concatenate([self._data[keep], data])

    def forget_before(self, t):
        """Drop the nodes more than KEEP cycles before time t (s)."""
        j = int(np.searchsorted(self._t, t, side='right')) - 1 - self.KEEP * self._n
        if j > self._n:
            self._x, self._t, self._data = self._x[j:], self._t[j:], self._data[j:]
            self._first += j

    def _evaluate(self, t):
        u, w, rate = self._state(t)
        with np.errstate(divide='ignore', invalid='ignore'):
            return u, w / rate

    def state(self, t, turn_rate=None):
        """(u, w) at times t (s): the phase and the angular speed about AB,
        w = σ √(2(E − V)/J) (rad/s, finite where the body stops turning in u)."""
        return self._state(t)[:2]

    def initial_energy(self, energy_turning=None, turn_rate=None):
        """E (J): the energy it was built from."""
        return float(self.energy)

    def _state(self, t):
        """(u, w, |ω_u|) at times t (s): one read of the energy table per call."""
        t = np.asarray(t, dtype=float)
        if t.size == 0:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        if float(np.min(t)) < self._t[0]:
            raise ValueError(f'time {float(np.min(t))!r} s is before the nodes kept '
                             f'(from {self._t[0]!r} s)')
        last = float(np.max(t))
        while self._t[-1] < last:
            # the cycles still needed if each took as long as the latest, a quarter more
            # (rolling on downhill the cycles get shorter: this too few, else more batches)
            took = self._t[-1] - self._t[-1 - self._n]
            self._extend(min(self.BATCH, math.ceil(1.25 * (last - self._t[-1]) / took)))
        j = np.clip(np.searchsorted(self._t, t, side='right') - 1, 0, len(self._t) - 2)
        start, end = self._data[j].T, self._data[j + 1].T
        s = (t - start[0]) / (end[0] - start[0])            # linear guess
        # converged when the steps reach the rounding of t over a panel's duration
        floor = max(1e-13, 8e-16 * float(np.max(t)) / float(np.min(end[0] - start[0])))
        for _ in range(30):
            value, slope, _ = hermite_jet(s, start, end)
            step = (value - t) / slope
            s = np.clip(s - step, 0.0, 1.0)
            if np.max(np.abs(step), initial=0.0) <= floor:
                break
        x = self._x[j] + s * self._h
        u = self._u0 + self._s * x
        jet = self._terms.energy_jet(u)
        return u, self._s * np.sqrt(2 * np.maximum(self.energy - jet[..., 1], 0.0)
                                    / jet[..., 7]), jet[..., 4]


class SceneWell:
    """A well of the scene's V between two maxima, in the displacement δ = u − u*.

    The interface :class:`~twodisk_ros.physics.motion.solvers.LibrationSolution` needs (as
    :class:`~twodisk_ros.physics.stability.wells.TabulatedWell`): centre u* (rad), bounds ``low`` < 0 <
    ``high`` of δ at the maxima, ``stiffness`` V″(u*), ``ratio(δ)`` = V′(u* + δ)/δ and
    ``mass(δ)``, from the scene's tables. u* is refined by Newton on the tabulated V′.
    """

    def __init__(self, terms, centre, low, high):
        self._terms = terms
        for _ in range(3):
            dv, ddv = (float(x) for x in terms.energy_jet(centre, 1)[[1, 3]])
            centre -= dv / ddv
        self.centre = float(centre)
        self.low, self.high = low - self.centre, high - self.centre
        self.stiffness = float(terms.energy_jet(self.centre, 1)[3])
        self.radius = max(-self.low, self.high)

    def ratio(self, delta):
        """V′(u* + δ)/δ (J/rad²); V″(u*) at δ = 0."""
        delta = np.asarray(delta, dtype=float)
        zero = delta == 0
        slope = self._terms.energy_jet(self.centre + delta)[..., 3]
        return np.where(zero, self.stiffness, slope / np.where(zero, 1.0, delta))

    def mass(self, delta):
        """m(u* + δ) (kg m²/rad²)."""
        return self._terms.energy_jet(self.centre + np.asarray(delta, dtype=float))[..., 0]


class OscillationSolution(PhaseSolution):
    """A bounded motion between turning points u_a < u_b (E = V there), over any number of
    wells, in the angle φ: u = c − r cos φ (c, r the centre and half-width of [u_a, u_b]).

    dt/dφ = r |sin φ| √(m / (2(E − V))) is smooth, positive and 2π-periodic (√(m r/|V′|) at
    the turning points φ = 0, π), so φ(t) is the periodic
    :class:`~twodisk_ros.physics.motion.solvers.QuadratureSolution` and u̇ = r sin φ φ̇. The table in
    φ is doubled from the scene's node count until its spectral tail is below ``TAIL``.
    """

    name = 'oscillation'
    TAIL = 1e-11
    MAX_NODES = 2 ** 16

    def __init__(self, terms, u0, u_dot0, energy, turning):
        low, high = turning
        self.centre_of_swing, self.half_width = 0.5 * (low + high), 0.5 * (high - low)
        c, r = self.centre_of_swing, self.half_width
        cos0 = min(1.0, max(-1.0, (c - u0) / r))
        sin0 = math.sqrt(1.0 - cos0 * cos0) * (1.0 if u_dot0 > 0 else -1.0)
        slopes = np.abs(terms.energy_jet(np.array([low, high]))[:, 3])
        n = terms.table_nodes
        while True:
            phi = TWO_PI * np.arange(n) / n
            m, v = np.moveaxis(terms.energy_jet(c - r * np.cos(phi))[..., :2], -1, 0)
            room = energy - v
            end = (phi == 0) | (phi == math.pi)
            with np.errstate(divide='ignore', invalid='ignore'):
                rate = np.where(end, np.sqrt(m * r / np.where(phi == 0, *slopes)),
                                r * np.abs(np.sin(phi)) * np.sqrt(m / (2 * room)))
            # dt/dφ vanishes at isolated phases where the body stops turning in u
            if not (np.all(np.isfinite(rate)) and np.all(rate >= 0) and np.mean(rate) > 0):
                raise RuntimeError('E - V is not positive between the turning points')
            if spectral_tail(rate) < self.TAIL:
                break
            if n >= self.MAX_NODES:
                raise RuntimeError('dt/dphi not resolved (at the separatrix?)')
            n *= 2
        self._phase = QuadratureSolution(math.atan2(sin0, cos0), 1.0, lambda _: rate, n)
        self.period = self._phase.cycle_time
        self.turning_points = (low, high)

    def _evaluate(self, t):
        phi, phi_dot = self._phase(t)
        r = self.half_width
        return self.centre_of_swing - r * np.cos(phi), r * np.sin(phi) * phi_dot


def _turning_point(terms, energy, u, side):
    """The first u′ beyond u on ``side`` with V(u′) = E, bracketed between the extremum
    before the first maximum above E and that maximum; None within ``SEARCH`` cycles."""
    from scipy.optimize import brentq
    maxima, minima = _extrema(terms)
    if not maxima:
        return None
    edge = u
    for _ in range(SEARCH * len(maxima)):
        top = _around(maxima, edge, side)
        if float(terms.potential(top)) > energy:
            bottom = _around(minima, top, -side) if minima else edge
            if side * (bottom - u) < 0:
                bottom = u
            return brentq(lambda x: float(terms.potential(x)) - energy, *sorted((bottom, top)),
                          xtol=1e-15, rtol=1e-15)
        edge = top
    return None


def _extrema(terms):
    """Phases (rad, in [0, 2π)) of the maxima and of the minima of V over one cycle."""
    found = terms.equilibria()
    return ([eq.phase for eq in found if not eq.stable], [eq.phase for eq in found if eq.stable])


def _around(phases, u, side):
    """The nearest of the 2π-periodic ``phases`` strictly beyond u on ``side`` (±1)."""
    phases = np.asarray(phases, dtype=float)
    base = math.floor(u / TWO_PI) * TWO_PI
    candidates = np.concatenate([phases + base + k * TWO_PI for k in (-1, 0, 1)])
    ahead = candidates[side * (candidates - u) > 0]
    return float(ahead[np.argmin(np.abs(ahead - u))])


def _within(phases, u, side):
    """The 2π-periodic ``phases`` in the cycle of travel (u, u + 2π·side] (array)."""
    phases = np.asarray(phases, dtype=float)
    base = math.floor(u / TWO_PI) * TWO_PI
    candidates = np.concatenate([phases + base + k * TWO_PI for k in (-1, 0, 1, 2)])
    travel = side * (candidates - u)
    return candidates[(travel > 0) & (travel <= TWO_PI)]


def conservative_solution(terms, u0, u_dot0, angular_speed=None):
    """The closed-form solution of a conservative scene from (u0 (rad), u̇0 (rad/s)), or None.

    Module docstring: rest, rolling on (DriftQuadrature) or rocking (LibrationSolution).
    ``angular_speed`` w0 = |ω_u(u0)| u̇0 (rad/s) replaces u̇0 if given (the one form that
    holds where the body stops turning in u). Wells whose centre is such a stop, and starts
    from rest at one, have no closed form here (None: DOP853 in τ).
    """
    if not terms.scene.conservative:
        raise ValueError('closed forms are for conservative scenes (no drive, no dissipation)')
    if not terms.periodic_potential and terms.sin_b != 0:
        return None            # V is not periodic plus a drift: a curving path (DOP853)
    u0 = float(u0)
    jet = terms.energy_jet(u0)
    w0 = float(angular_speed) if angular_speed is not None else float(u_dot0) * float(jet[4])
    energy = 0.5 * float(jet[7]) * w0 ** 2 + float(jet[1])
    u_dot0 = w0                                    # only its sign is used below
    scale = terms.dynamics.energy_scale
    maxima, minima = _extrema(terms)
    stopped = float(jet[4]) <= STOPPED * terms.turn_scale
    if w0 == 0 and not stopped and (
            abs(float(terms.potential_turn_slope(u0))) <= 1e-13 * scale or any(
            abs(math.remainder(u0 - p, TWO_PI)) < 1e-9 for p in maxima + minima)):
        return RestSolution(u0)
    if w0 == 0 and stopped:
        return RestSolution(u0) if abs(float(terms.potential_turn_slope(u0))) <= \
            1e-13 * scale else None
    if u_dot0 != 0:
        sigma = math.copysign(1.0, u_dot0)
        if sigma * terms.drift <= DRIFT_FLOOR * scale:      # level or downhill on average
            ahead = _within(maxima, u0, sigma)
            tops = terms.potential(ahead) if ahead.size else np.zeros(0)
            if np.all(tops < energy):
                try:
                    return DriftQuadrature(terms, u0, None, angular_speed=w0)
                except RuntimeError:           # E − V not positive on the first cycle's nodes
                    pass
    if not (minima and maxima):
        return None
    low, high = _around(maxima, u0, -1.0), _around(maxima, u0, 1.0)
    if energy < float(np.min(terms.potential(np.array([low, high])))):
        centre = _around(minima, low, 1.0)
        regular = float(terms.energy_jet(centre)[4]) > 1e-3 * terms.turn_scale
        if centre < high and regular and float(jet[4]) > 0:    # one well: libration in φ
            well = SceneWell(terms, centre, low, high)
            try:
                libration = LibrationSolution(well, u0 - well.centre, w0 / float(jet[4]),
                                              terms.table_nodes)
                if libration.resolved:
                    return libration
            except RuntimeError:
                pass
    turning = [_turning_point(terms, energy, u0, side) for side in (-1.0, 1.0)]
    if None in turning:
        return None
    try:
        return OscillationSolution(terms, u0, u_dot0, energy, turning)
    except RuntimeError:
        return None
