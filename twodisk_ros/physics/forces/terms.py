"""The coefficients of the ground forces over one cycle, per unit of the body's turn γ.

docs/physics.md#contact-forces. The body turns about the contact line AB: ω = w ω̂, with
ω̂ = σ ê the unit vector along AB (ê from A to B, σ = ±1 the body's sense of rolling, fixed),
γ the angle turned (rad) and w = γ̇ the angular speed (rad/s). On the table coordinate y
(below), with s = dγ/dy ≥ 0 and c = −ω̂ × r1 = dG/dγ (body frame, m):

    a_G = w² (ω̂ × c + c_γ) + ẇ c,             c_γ = (dc/dy)/s
    L_G = w² (I ω̂_γ + ω̂ × I ω̂) + ẇ I ω̂,       ω̂_γ = (dω̂/dy)/s

so every determinate force is Q = Q_g + ẇ Q_a + w² P/s, with (force, moment) pairs
Q_g = (M g n, 0), Q_a = (M c, I ω̂) and P = (M(s ω̂ × c + dc/dy), I dω̂/dy + s ω̂ × I ω̂):
**no division in P**. s = 0 only where the body does not turn while its contacts move (a
flat vertex: dr1/dγ is infinite there); then P ≠ 0 and the force is infinite for an instant.

**Table coordinate y.** y = u where the pose moves at a rate bounded away from zero per unit u
(EllipseBody, LaminaBody: their contacts move at a finite rate per u even where the body does
not turn). A phase that stops the whole pose (the test double's u = g(v) with g′ = 0) would
make s and P vanish together (0/0); there y = x, the pose's arc length normalised to 2π per
cycle, dx/du ∝ √(s_u² + (|r1′|² + |r2′|²)/L²) (L the body size), in which the pose moves at a
positive rate and only flat vertices have s = 0.
"""

import math

import numpy as np

from ..numerics.analytic import complex_step
from ..numerics.spectral import real_spectral_derivative, spectral_antiderivative
from ..numerics.tables import HermiteTable

__all__ = ['ForceTerms', 'project', 'REGULAR_RATE']

TWO_PI = 2.0 * math.pi
#: the phase u is used as table coordinate if the pose's rate per unit u stays above this
#: fraction of its largest value over the cycle
REGULAR_RATE = 1e-3
#: below this fraction of max s the body is taken as not turning (V′/s → 0 there: a flat
#: vertex of the superellipses is an equilibrium, docs/physics.md#contact-forces)
STOPPED = 1e-9


def _dot(x, y):
    return np.sum(x * y, axis=-1)


def project(force, moment, r1, r2, normal):
    """(N_A, N_B, T_A, T_B, S, τ) of a total force and moment about G, shape (..., 6).

    Moments about A: d × F_B + τ ê = moment − r1 × force (d = r2 − r1 = |d| ê), so
    F_B⊥ = (L_A × d)/|d|², τ = ê·L_A; p = n × ê; vectors (..., 3) in the body frame.
    """
    d = r2 - r1
    length2 = _dot(d, d)
    e = d / np.sqrt(length2)[..., None]
    p = np.cross(normal, e)
    moment_a = moment - np.cross(r1, force)
    f_b = np.cross(moment_a, d) / length2[..., None]
    return np.stack([_dot(force, normal) - _dot(f_b, normal), _dot(f_b, normal),
                     _dot(force, p) - _dot(f_b, p), _dot(f_b, p), _dot(force, e),
                     _dot(moment_a, e)], axis=-1)


class ForceTerms:
    """Q_g, Q_a, P, s and what converts the phase u at the nodes of the table coordinate.

    Parameters
    ----------
    body : RollingBody
    inertia : ndarray (3, 3)
        I_G (kg m², body frame).
    mass, gravity : float
        M (kg), g (m/s²).
    n : int
        Nodes per cycle (y_k = 2πk/n).
    phase_only : bool
        Use y = u whatever the body (for coefficients per u̇², ü, smooth in u).

    Attributes (arrays over the nodes)
    ----------------------------------
    y, u : the nodes and their phases (rad); ``regular`` True if y = u.
    q_g, q_a, p : (n, 6) coefficients (N, N m per unit of w², ẇ; see the module docstring).
    s : dγ/dy; s_u, ds_u : dγ/du and d²γ/du² at u (|ω_u| and its slope).
    ratio : s_u²/s (dγ/du · dx/du; s_u where y = u).
    inertia_line, inertia_slope : J = ω̂ I ω̂ + M |c|² (kg m²), dJ/dy.
    potential_slope : dV/dy (J per unit y), V = M g z_G.
    e, t1, normal : ê, disk 1's tangent at A and n (body frame).
    """

    def __init__(self, body, inertia, mass, gravity, n, phase_only=False):
        u = TWO_PI * np.arange(n) / n
        geo = body.phase_geometry(u)
        w_u = body.phase_angular_velocity(u)
        e = self._unit(geo.contact_b - geo.contact_a)
        along = _dot(w_u, e)
        self.sense = 1.0 if np.sum(along) >= 0 else -1.0
        s_u = self.sense * along
        drift = real_spectral_derivative(np.concatenate([geo.contact_a, geo.contact_b], -1))
        rate = np.sqrt(s_u**2 + _dot(drift, drift) / body.size**2)
        self.regular = phase_only or bool(rate.min() > REGULAR_RATE * rate.max())
        self.n = n
        # u-table: [x(u) − u, γ(u) − mean·u (periodic), s_u]: the maps u → y, γ and |ω_u|
        mean_rate, x_part = spectral_antiderivative(rate)
        self.turn_rate, gamma_part = spectral_antiderivative(s_u)
        ds_u = real_spectral_derivative(s_u)
        if self.regular:
            x_part, x_rate, x_slope = np.zeros(n), np.zeros(n), np.zeros(n)
        else:
            x_part, x_rate = x_part / mean_rate, rate / mean_rate - 1.0
            x_slope = real_spectral_derivative(rate) / mean_rate
        self._phase_table = HermiteTable.periodic(
            np.column_stack([x_part, gamma_part, s_u]),
            np.column_stack([x_rate, s_u - self.turn_rate, ds_u]),
            np.column_stack([x_slope, ds_u, real_spectral_derivative(ds_u)]))
        self.y = u
        if self.regular:
            self.u = u
            self.s_u, self.ds_u, self.s, self.ratio = s_u, ds_u, s_u, s_u
            dz = complex_step(body.phase_height, u)
        else:
            self.u = self.phase_of(u)
            geo = body.phase_geometry(self.u)
            rest = np.mod(self.u, TWO_PI)
            table, jet = self._phase_table(rest), self._phase_table(rest, derivative=1)
            self.s_u, self.ds_u = table[..., 2], jet[..., 2]
            gamma = self.turn_rate * (self.u - u) + table[..., 1]   # γ(u(y)) − mean·y
            self.s = self.turn_rate + real_spectral_derivative(gamma)
            self.ratio = self.s_u * (1.0 + jet[..., 0])
            e = self._unit(geo.contact_b - geo.contact_a)
            dz = real_spectral_derivative(geo.height)
        # rounding of a stop (|ω_u| ~ 1e-13) is a stop: s = 0 exactly there
        self.s = np.where(self.s <= STOPPED * np.max(self.s), 0.0, self.s)
        r1, r2, normal = geo.contact_a, geo.contact_b, geo.ground_normal
        self.e, self.t1, self.normal, self.height = e, geo.tangent_a, normal, geo.height
        axis = self.sense * e                                    # ω̂
        inertia = np.asarray(inertia, dtype=float)
        c = -np.cross(axis, r1)
        dc, daxis = np.split(real_spectral_derivative(np.concatenate([c, axis], -1)), 2, -1)
        i_axis = axis @ inertia
        s = self.s[:, None]
        zero = np.zeros_like(c)
        self.q_g = project(mass * gravity * normal, zero, r1, r2, normal)
        self.q_a = project(mass * c, i_axis, r1, r2, normal)
        self.p = project(mass * (s * np.cross(axis, c) + dc),
                         daxis @ inertia + s * np.cross(axis, i_axis), r1, r2, normal)
        self.inertia_line = _dot(axis, i_axis) + mass * _dot(c, c)
        self.inertia_slope = real_spectral_derivative(self.inertia_line)
        self.potential_slope = mass * gravity * dz

    @staticmethod
    def _unit(d):
        return d / np.linalg.norm(d, axis=-1)[..., None]

    def coordinate(self, u):
        """y(u) (rad, any real u): u itself if ``regular``, else the pose's arc length x."""
        u = np.asarray(u, dtype=float)
        if self.regular:
            return u
        return u + self._phase_table(np.mod(u, TWO_PI))[..., 0]

    def turn_rates(self, u):
        """(dγ/du, d²γ/du²) at phase(s) u (rad): |ω_u| and its slope, from the u-table."""
        u = np.mod(np.asarray(u, dtype=float), TWO_PI)
        return self._phase_table(u)[..., 2], self._phase_table(u, derivative=1)[..., 2]

    def phase_of(self, y):
        """u with y(u) = y (rad), by bisection (y(u) − u is periodic and increasing in u)."""
        y = np.asarray(y, dtype=float)
        if self.regular:
            return y
        reach = float(np.max(np.abs(self._phase_table.values[:, 0]))) + 1e-9
        low, high = y - reach, y + reach
        for _ in range(64):
            mid = 0.5 * (low + high)
            above = self.coordinate(mid) > y
            low, high = np.where(above, low, mid), np.where(above, mid, high)
        return 0.5 * (low + high)

    def potential_turn_slope(self):
        """dV/dγ = (dV/dy)/s at the nodes (J/rad); 0 where the body does not turn (s below
        :data:`STOPPED` of its largest value: a flat vertex, an equilibrium)."""
        stopped = self.s <= STOPPED * np.max(self.s)
        return np.where(stopped, 0.0, self.potential_slope / np.where(stopped, 1.0, self.s))
