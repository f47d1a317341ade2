"""Models of a well of V(u) around a stable equilibrium u*, in the displacement δ = u − u*.

An oscillation in a well is solved in δ, not in u (docs/physics.md#the-two-methods-direct-and-
table): near u* the absolute value of V′(u) carries a rounding floor (~1e-16 M g L per rad for
the closed forms, ~1e-13 for the tables), which is the whole signal when δ is tiny. A well
model therefore gives, as functions of δ,

* ``ratio(δ)`` = V′(u* + δ) / δ (J/rad²), smooth and → V″(u*) as δ → 0, so V′ = δ·ratio(δ)
  keeps full relative precision however small δ is;
* ``mass(δ)`` = m(u* + δ) (kg m²/rad²).

:class:`LocalWell` holds both as Chebyshev interpolants on |δ| ≤ r, built once from the closed
forms; it is exact to ~1e-13 relative at every δ in its range, including δ → 0, and is used by
both methods for small amplitudes. :class:`TabulatedWell` reads the periodic tables (the
``table`` method at larger amplitudes).
"""

import math

import numpy as np
from numpy.polynomial import chebyshev

__all__ = ['LocalWell', 'TabulatedWell']


class LocalWell:
    """Chebyshev model of V′(u* + δ)/δ and m(u* + δ) on |δ| ≤ ``radius``, from closed forms.

    Parameters
    ----------
    dynamics : RollingDynamics
        Supplies ``potential_slope`` and ``effective_mass`` (closed forms) and ``well``.
    centre : float
        The stable equilibrium u* (rad): V′(u*) is taken as exactly 0 there.
    nodes : int
        Chebyshev points of the first kind (even: none at δ = 0).

    The radius starts at min(0.2, ¼ of the distance from u* to the nearer maximum of V) rad
    and is halved until the last four Chebyshev coefficients are below 1e-12 of the first.
    V′ is sampled at u_j = u* + r x_j and divided by the exact δ_j = u_j − u*: its absolute
    rounding (~1e-16) becomes a relative error ≲ 1e-13 of the ratio at the node nearest to 0.
    """

    def __init__(self, dynamics, centre, nodes=32):
        self.centre = float(centre)
        _, low, high = dynamics.well(self.centre)
        radius = min(0.2, 0.25 * min(self.centre - low, high - self.centre))
        x = np.cos((2 * np.arange(nodes) + 1) * math.pi / (2 * nodes))
        for _ in range(6):
            u = self.centre + radius * x
            delta = u - self.centre
            ratio = np.asarray(dynamics.potential_slope(u)) / delta
            mass = np.asarray(dynamics.effective_mass(u))
            self._ratio = chebyshev.chebfit(delta / radius, ratio, nodes - 1)
            self._mass = chebyshev.chebfit(delta / radius, mass, nodes - 1)
            tail = max(np.max(np.abs(self._ratio[-4:])) / abs(self._ratio[0]),
                       np.max(np.abs(self._mass[-4:])) / abs(self._mass[0]))
            if tail < 1e-12:
                break
            radius *= 0.5
        self.radius = radius
        self.low, self.high = -radius, radius     # the model's range
        #: V″(u*) (J/rad²) of the model
        self.stiffness = float(self.ratio(0.0))

    def ratio(self, delta):
        """V′(u* + δ)/δ (J/rad²), |δ| ≤ radius."""
        return chebyshev.chebval(np.asarray(delta, dtype=float) / self.radius, self._ratio)

    def mass(self, delta):
        """m(u* + δ) (kg m²/rad²), |δ| ≤ radius."""
        return chebyshev.chebval(np.asarray(delta, dtype=float) / self.radius, self._mass)


class TabulatedWell:
    """The well of V holding u* from the periodic tables (the ``table`` method).

    ``ratio(δ)`` = V′(u* + δ)/δ from the tabulated V′: use it for amplitudes well above the
    tables' absolute error of V′ over V″ (~1e-13 rad), i.e. where :class:`LocalWell` ends.
    """

    def __init__(self, dynamics, centre, stiffness):
        self._dynamics = dynamics
        self.centre = float(centre)
        _, low, high = dynamics.well(self.centre)
        self.low, self.high = low - self.centre, high - self.centre
        self.stiffness = float(stiffness)
        self.radius = max(-self.low, self.high)

    def ratio(self, delta):
        """V′(u* + δ)/δ (J/rad²); V″(u*) at δ = 0."""
        delta = np.asarray(delta, dtype=float)
        zero = delta == 0
        safe = np.where(zero, 1.0, delta)
        slope = self._dynamics.tabulated_potential(self.centre + delta, derivative=1)
        return np.where(zero, self.stiffness, slope / safe)

    def mass(self, delta):
        """m(u* + δ) (kg m²/rad²) from the tables."""
        return self._dynamics.tabulated(self.centre + np.asarray(delta, dtype=float))[..., 0]
