"""An independent reference for a free rolling motion on level ground: the energy integral.

With no losses, E = ½ m(u) u̇² + V(u) is constant, so u̇(u) = √(2 (E − V(u)) / m(u)) and the
time to reach u is t(u) = ∫ du / u̇(u). Here the integral is taken by adaptive quadrature
(scipy.integrate.quad, rtol 1e-13) from the dynamics' m(u) and V(u): it shares no code with
the solvers, tables or closed forms that produce u(t). For a motion that rolls over (u̇ never
0 on the stretch).
"""

import math

import numpy as np
from scipy.integrate import quad


def phase_rate(dynamics, energy, u):
    """u̇(u) (rad/s) of a motion of energy ``energy`` (J) at the phases ``u`` (rad)."""
    return np.array([math.sqrt(2.0 * (energy - float(dynamics.potential(x)))
                               / float(dynamics.effective_mass(x))) for x in np.ravel(u)])


def times_to(dynamics, energy, u0, u):
    """t(u_k) − t(u0) (s) for the increasing phases ``u`` (rad), by the energy integral."""
    def dt(x):
        return 1.0 / phase_rate(dynamics, energy, x)[0]
    bounds = np.r_[u0, np.asarray(u, dtype=float)]
    return np.cumsum([quad(dt, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]
                      for lo, hi in zip(bounds[:-1], bounds[1:])])
