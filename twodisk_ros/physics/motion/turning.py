"""Oscillation between two turning points across several wells of V, in closed form.

A body whose two maxima of V bounding a well differ (a parallel egg: V(0) ≠ V(π/2)) has
energies above the lower maximum and below the highest: the motion crosses the lower maximum
and swings over several wells, between the turning points u₁ < u₂ where V(u) = E
(docs/physics.md#oscillations-over-several-wells). There is no single minimum to expand
about, so the angle φ of :class:`~twodisk_ros.physics.motion.solvers.LibrationSolution` does not
apply; instead

    u = c − R cos φ,   c = (u₁ + u₂)/2,   R = (u₂ − u₁)/2,

and with E − V(u) = (u − u₁)(u₂ − u) Q(u) = R² sin²φ Q(u), Q > 0 on [u₁, u₂] (simple turning
points),

    dt/dφ = R |sin φ| √(m / (2(E − V))) = √(m(u) / (2 Q(u))),

smooth, positive and 2π-periodic in φ (one period of the oscillation per turn of φ, u
running u₁ → u₂ → u₁). φ(t) comes from :class:`~twodisk_ros.physics.motion.solvers.
QuadratureSolution`; u̇ = R sin φ φ̇. Near a turning point E − V is a difference of nearly
equal numbers, so there it is computed as V(uᵢ) − V(u) = ∓(u − uᵢ) ∫₀¹ V′(uᵢ + τ(u − uᵢ)) dτ
(20-point Gauss) with u − u₁ = 2R sin²(φ/2), u₂ − u = 2R cos²(φ/2): Q keeps its relative
precision at the turning points themselves.
"""

import math

import numpy as np

from ..bodies.cycle import TWO_PI
from .solvers import PhaseSolution, QuadratureSolution
from ..numerics.spectral import STALL, refine_grid, spectral_tail, upsample

__all__ = ['TurningPointSolution', 'turning_points']

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(20)


def turning_points(potential, slope, energy, u0, direction, n):
    """(u₁, u₂), u₁ ≤ u0 ≤ u₂, the nearest phases either side of u0 where V = E, or None.

    Parameters
    ----------
    potential, slope : callable
        V(u) (J) and V′(u) (J/rad), 2π-periodic.
    energy : float
        E (J), with V(u0) ≤ E.
    u0 : float
        The start (rad).
    direction : float
        Sign of u̇0 (0 at rest: u0 is then a turning point, the other found downhill).
    n : int
        Nodes per cycle of the scan for a crossing; each crossing is then refined by
        bisection and Newton to the rounding of V. None if V < E over a whole cycle from u0.
    """
    h = TWO_PI / n
    if direction == 0:
        downhill = -math.copysign(1.0, float(slope(u0)))
        other = _crossing(potential, slope, energy, u0, downhill, h, n)
        if other is None:
            return None
        return (u0, other) if downhill > 0 else (other, u0)
    low = _crossing(potential, slope, energy, u0, -1.0, h, n)
    high = _crossing(potential, slope, energy, u0, 1.0, h, n)
    if low is None or high is None or high - low >= TWO_PI:
        return None
    return low, high


def _crossing(potential, slope, energy, u0, side, h, n):
    """The first u = u0 + side·x, x > 0, with V(u) = E (V(u0) < E), or None within a cycle."""
    x = h * np.arange(1, n + 1)
    above = np.nonzero(potential(u0 + side * x) >= energy)[0]
    if above.size == 0:
        return None
    k = int(above[0])
    inner, outer = (x[k - 1] if k else 0.0), x[k]
    for _ in range(200):          # bisection to a small bracket, then Newton within it
        if outer - inner <= 1e-6 * h:
            break
        mid = 0.5 * (inner + outer)
        if potential(u0 + side * mid) >= energy:
            outer = mid
        else:
            inner = mid
    y = outer
    for _ in range(20):
        g = float(potential(u0 + side * y)) - energy
        dg = side * float(slope(u0 + side * y))
        if g >= 0:
            outer = min(outer, y)
        else:
            inner = max(inner, y)
        step = g / dg if dg > 0 else math.inf
        new = y - step
        if not inner <= new <= outer:
            new = 0.5 * (inner + outer)
        if abs(new - y) <= 1e-16 * max(1.0, abs(u0)):
            y = new
            break
        y = new
    return u0 + side * y


class TurningPointSolution(PhaseSolution):
    """u(t) of an oscillation between the turning points u₁ < u₂, over any number of wells.

    Parameters
    ----------
    potential, slope, mass : callable
        V(u) (J), V′(u) (J/rad) and m(u) (kg m²/rad², ≥ 0; zero at isolated phases where the
        body does not turn in u), vectorised.
    bounds : (float, float)
        The turning points (rad), from :func:`turning_points`.
    u0, direction : float
        Start (rad) in [u₁, u₂] and the sign of u̇0 (0 at a turning point).
    max_nodes : int
        Largest number of nodes in φ; ``resolved`` tells whether dt/dφ converged.

    Raises
    ------
    RuntimeError
        If Q = (E − V)/((u − u₁)(u₂ − u)) is not positive on the grid (a turning point
        where V′ vanishes: the separatrix; or a crossing the scan missed).
    """

    name = 'oscillation'
    #: as LibrationSolution.TAIL and .NOISE
    TAIL, NOISE = 1e-11, 1e-8
    #: E − V from the integral of V′ within this fraction of u₂ − u₁ of a turning point
    NEAR = 0.02

    def __init__(self, potential, slope, mass, bounds, u0, direction, max_nodes):
        self._potential, self._slope, self._mass = potential, slope, mass
        self.turning_points = u1, u2 = tuple(float(b) for b in bounds)
        self._c, self._r = 0.5 * (u1 + u2), 0.5 * (u2 - u1)
        self._levels = (float(potential(u1)), float(potential(u2)))
        self.energy = 0.5 * sum(self._levels)
        tails = []

        def sample(n):
            rate = self._inverse_rate(TWO_PI * np.arange(n) / n)
            tails.append(spectral_tail(rate))
            return tails[-1], rate
        n, rate = refine_grid(sample, 128, max(128, max_nodes), tolerance=self.TAIL,
                              floor=self.NOISE)
        self.tail = tails[-1]
        self.resolved = self.tail < self.TAIL or (
            len(tails) > 1 and self.tail <= self.NOISE and self.tail > STALL * tails[-2])
        d1, d2 = float(u0) - u1, u2 - float(u0)
        sin0 = 2.0 * math.sqrt(max(d1, 0.0) * max(d2, 0.0))
        phi0 = math.atan2(sin0 if direction >= 0 else -sin0, d2 - d1)
        # as in LibrationSolution: the Hermite table in φ on a grid 4 times finer
        fine = upsample(rate, 4)
        self._phase = QuadratureSolution(phi0, 1.0, lambda _: fine, 4 * n)
        #: the period of the oscillation (s)
        self.period = self._phase.cycle_time

    def initial_energy(self, energy_turning=None, turn_rate=None):
        """E (J): the level the motion keeps between its turning points."""
        return float(self.energy)

    def _inverse_rate(self, phi):
        """dt/dφ = √(m / (2Q)) at φ (s/rad)."""
        r = self._r
        u1, u2 = self.turning_points
        d1, d2 = 2 * r * np.sin(0.5 * phi) ** 2, 2 * r * np.cos(0.5 * phi) ** 2
        u = np.where(d1 <= d2, u1 + d1, u2 - d2)
        tau = 0.5 * (1 + _NODES)

        def mean_slope(start, length):      # ∫₀¹ V′(start + τ length) dτ
            return np.sum(0.5 * _WEIGHTS * self._slope(start + length[..., None] * tau),
                          axis=-1)
        near = self.NEAR * (u2 - u1)
        with np.errstate(divide='ignore', invalid='ignore'):
            middle = (self.energy - self._potential(u)) / (d1 * d2)
            q = np.where(d1 <= near, -mean_slope(u1, np.minimum(d1, near)) / d2,
                         np.where(d2 <= near, mean_slope(u2, -np.minimum(d2, near)) / d1,
                                  middle))
        if not np.all(q > 0):
            raise RuntimeError('E − V does not vanish simply at the turning points: at a '
                               'separatrix, or a crossing between the scan nodes')
        return np.sqrt(np.maximum(self._mass(u), 0.0) / (2.0 * q))

    def _evaluate(self, t):
        phi, phi_dot = self._phase(t)
        with np.errstate(invalid='ignore'):
            return self._c - self._r * np.cos(phi), self._r * np.sin(phi) * phi_dot
