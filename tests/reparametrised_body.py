"""A test double of the RollingBody protocol: a EllipseBody seen through another phase.

``ReparametrisedBody(body, kind)`` is the ellipse body ``body`` with its phase u replaced by
u = g(v) (v the double's phase):

* ``'smooth'``: g(v) = v + ε sin 2v (|ε| < ½): a regular phase, different from the ellipse's;
* ``'degenerate'``: g(v) = v − ½ sin 2v, g′(v) = 2 sin² v = 0 at v = 0 and π: there the body
  does not turn per unit of v (ω_v = 0 and m(v) = 0), as in LaminaBody's phase where a contact
  crosses a flat vertex of a superellipse.

g(v + 2π) = g(v) + 2π and g keeps the landmarks (0, π/2, π, 3π/2), so the double is a valid
RollingBody. Its phase functions are the ellipse's composed with g; g is analytic, so the
complex-step contract holds by composition (f(g(v + ih)) = f(g(v)) + ih f′(g(v)) g′(v)).
Everything physical (equilibria's θ, heights, stability, periods; motions in time; poses;
forces) is the ellipse's: the double is an independent reference for the general paths of
equilibria, dynamics, motion and contact forces, which must not use anything of the ellipse.
"""

import math

import numpy as np

from twodisk_ros.physics.bodies.ellipse import PhaseGeometry
from twodisk_ros.physics.bodies.protocol import RollingBody

__all__ = ['ReparametrisedBody']


class ReparametrisedBody(RollingBody):
    """``base`` (a EllipseBody) with phase u = g(v); see the module docstring."""

    def __init__(self, base, kind='smooth', epsilon=0.3):
        if kind not in ('smooth', 'degenerate'):
            raise ValueError(f'kind must be smooth or degenerate, got {kind!r}')
        self.base, self.kind = base, kind
        self.epsilon = float(epsilon) if kind == 'smooth' else -0.5
        self.theta_max, self.psi_max = base.theta_max, base.psi_max
        self.delta, self.size = base.delta, base.size
        self.lamina, self.arrangement = base.lamina, base.arrangement
        # g′ = 1 + 2ε cos 2v: features narrower by 1 − 2|ε| (0 for the degenerate phase;
        # cube-root behaviour near v = 0, π: width ~ a tenth)
        self.feature_width = base.feature_width * (0.1 if kind == 'degenerate'
                                                   else 1 - 2 * abs(self.epsilon))

    def __repr__(self):
        return f'ReparametrisedBody({self.base!r}, {self.kind!r}, epsilon={self.epsilon!r})'

    def describe(self):
        return f'{self.base.describe()} in a {self.kind} phase'

    # -- the map and its inverse -----------------------------------------------------------
    def g(self, v):
        """u = g(v) (complex-safe)."""
        return v + self.epsilon * np.sin(2 * v)

    def g_prime(self, v):
        """g′(v) (complex-safe)."""
        return 1 + 2 * self.epsilon * np.cos(2 * v)

    def g_inverse(self, u):
        """v with g(v) = u (bisection: g is increasing, |g(v) − v| ≤ ½)."""
        u = np.asarray(u, dtype=float)
        low, high = u - 0.6, u + 0.6
        for _ in range(80):
            mid = 0.5 * (low + high)
            above = self.g(mid) > u
            low, high = np.where(above, low, mid), np.where(above, mid, high)
        return 0.5 * (low + high)

    # -- the protocol ----------------------------------------------------------------------
    def phase_geometry(self, u):
        u = np.asarray(u, dtype=float)
        geo = self.base.phase_geometry(self.g(u))
        return PhaseGeometry(phase=u, theta=geo.theta, psi=geo.psi, branch=geo.branch,
                             signed_sqrt_q=np.full_like(geo.theta, np.nan),
                             contact_a=geo.contact_a, contact_b=geo.contact_b,
                             ground_normal=geo.ground_normal, tangent_a=geo.tangent_a,
                             height=geo.height, tilt=geo.tilt)

    def phase_vectors(self, u):
        return self.base.phase_vectors(self.g(u))[:5]

    def phase_height(self, u):
        return self.base.phase_height(self.g(u))

    def phase_rates(self, u):
        ds, dalpha = self.base.phase_rates(self.g(u))
        scale = self.g_prime(u)
        return ds * scale, dalpha * scale

    def phase_angular_velocity(self, u):
        u = np.asarray(u, dtype=float)
        return self.base.phase_angular_velocity(self.g(u)) * self.g_prime(u)[..., None]

    def phase_angles_with_rates(self, u):
        u = np.asarray(u, dtype=float)
        theta, psi, dtheta, dpsi = self.base.phase_angles_with_rates(self.g(u))
        scale = self.g_prime(u)
        return theta, psi, dtheta * scale, dpsi * scale

    def phase_from_theta(self, theta, branch=1):
        u = self.base.phase_from_theta(theta, branch)
        v = self.g_inverse(u)
        return v if np.ndim(v) else float(v)

    def contact_angle_psi(self, theta, branch=1):
        return self.base.contact_angle_psi(theta, branch)


def degenerate_phases():
    """The phases v (rad) where the degenerate double does not turn: 0 and π."""
    return (0.0, math.pi)
