"""The regular phase u of a body of any two congruent laminae: its exact solution at nodes.

docs/physics.md#the-phase-of-a-general-body. Quarter-cycle u ∈ [0, π/2] (θ ≥ 0, branch +1)
is solved here; the rest of the cycle follows from the body's two mirror symmetries
(:func:`unfold`).

**The phase.** Along the cycle, A's lamina parameter s_A and B's parameter β_B measured from
disk 2's far tip (the tip B touches at the turning points) trace a closed curve. In the
normalised plane (p, q) = (s_A/s_max, β_B/β_0), β_0 being β_B at θ = 0 on branch +1, it
passes through (0, 1) at θ = 0 (branch +1), (1, 0) at the turning point +θ_max, (0, −1) at
θ = 0 on branch −1 and (−1, 0) at −θ_max, winding once around the origin like (sin u, cos u).
u is the polar angle in that plane: p cos u − q sin u = 0, p sin u + q cos u > 0. Both
parameters are smooth functions of the *points* (the eccentric anomaly, the superellipse's
projected anomaly for even n, the normal angle of a strictly convex support-function lamina),
and the curve G(s_A, s_B) = 0 of the common tangent plane (the triple product of the tangents
at A and B and A − B) is regular in them, also where a contact crosses a flat vertex. So
everything is smooth in u; in θ, ψ or the normal angles it is not (B moves like τ^(1/(n−1))
near a superellipse's flat tip).

**The solve.** Given u, the point on the ray is found by a bracketing root finder (scipy's
elementwise Chandrupatla) on the signed distance p cos u − q sin u from the ray, in the chart
that is well conditioned there: A's parameter for u ≤ π/4 (q from the convex elevation
equation of :meth:`~twodisk_ros.physics.general_body.GeneralTwoDiskBody.elevation_of_parameter`
and the support point of disk 2), B's parameter for u > π/4
(:meth:`~twodisk_ros.physics.general_body.GeneralTwoDiskBody.chart_from_b`, regular at the
turning points where ψ(θ) ~ √(θ_max − θ) is not).
"""

import math

import numpy as np
from scipy.optimize import elementwise

__all__ = ['BRANCH_FLIP', 'COLUMNS', 'PhaseSolver', 'THETA_FLIP', 'unfold']

#: The sampled functions of u, in table order (lengths in m, angles in rad): r1 = GA has no
#: e3 part and r2 = GB no e1 part; t1 lies in disk 1's plane.
COLUMNS = ('r1_x', 'r1_y', 'r2_y', 'r2_z', 'n_x', 'n_y', 'n_z', 't1_x', 't1_y', 'height',
           'theta', 'psi')
#: Sign of each column under the mirror x1 → −x1 (u → −u, θ → −θ; t1 → −M1 t1) ...
THETA_FLIP = np.array([-1, 1, 1, 1, -1, 1, 1, 1, -1, 1, -1, 1], dtype=float)
#: ... and under the mirror x3 → −x3 (u → π − u, the other branch).
BRANCH_FLIP = np.array([1, 1, 1, -1, 1, 1, -1, 1, 1, 1, 1, -1], dtype=float)
_TOLERANCES = {'xatol': 1e-300, 'xrtol': 4 * np.finfo(float).eps, 'fatol': 0.0, 'frtol': 0.0}


def _wrap(angle):
    """angle in (−π, π] (rad)."""
    return math.pi - np.remainder(math.pi - np.asarray(angle, dtype=float), 2 * math.pi)


class PhaseSolver:
    """Exact resting poses at phases u ∈ [0, π/2] of a :class:`GeneralTwoDiskBody`.

    Raises ValueError (one line) when the cycle's curve in the (p, q) plane is not
    star-shaped about the origin (u would not be one-to-one).
    """

    def __init__(self, general):
        self.general = general
        self.s_max = general.s_max
        self.tip = general.far_tip
        tau0 = general.elevation_of_parameter(0.0)
        self.beta0 = float(_wrap(self._parameter_b(np.array(0.0), tau0) - self.tip))
        if not abs(self.beta0) > 0:
            raise ValueError(f'{general!r}: B sits at disk 2\'s far tip at theta = 0; no '
                             'regular phase')
        # star-shapedness: the polar angle must increase along the chart-A samples
        s = self.s_max * np.linspace(0.0, 1.0, 1025)
        p, q = self.chart_a(s)
        if not (np.all(np.diff(np.arctan2(p, q)) > 0) and np.all(q[:-1] > 0)):
            raise ValueError(f'{general!r}: the contact parameters do not wind once around '
                             'the cycle (no regular phase); choose another delta')

    def _parameter_b(self, s_a, tau_abs):
        """B's lamina parameter on branch +1 from A's parameter and |τ|."""
        g = self.general
        nu = g.lamina.normal(s_a)
        return g.lamina.support(np.stack([-tau_abs, g.sigma * nu[..., 1]], axis=-1)).parameter

    def chart_a(self, s_a):
        """(p, q) from A's parameter s_a ∈ [0, s_max] (branch +1)."""
        tau = self.general.elevation_of_parameter(s_a)
        beta = _wrap(self._parameter_b(s_a, tau) - self.tip)
        return s_a / self.s_max, beta / self.beta0

    def _chart_b(self, q):
        """(p, q, s_A, |τ|) from q = β/β_0 ∈ [0, 1] (branch +1)."""
        s_a, tau = self.general.chart_from_b(_wrap(self.tip + q * self.beta0))
        return s_a / self.s_max, q, s_a, tau

    def solve(self, u):
        """(s_A, |τ|) at phases u ∈ [0, π/2] (rad, 1-D array), to the last bits."""
        u = np.asarray(u, dtype=float)
        s_a = np.empty_like(u)
        tau = np.empty_like(u)
        first = u <= 0.0
        turn = u >= 0.5 * math.pi
        s_a[first], s_a[turn] = 0.0, self.s_max
        tau[turn] = 0.0
        near_a = ~first & ~turn & (u <= 0.25 * math.pi)
        near_b = ~first & ~turn & ~near_a
        if np.any(near_a):
            c, s = np.cos(u[near_a]), np.sin(u[near_a])

            def distance_a(x, c, s):
                p, q = self.chart_a(x)
                return p * c - q * s
            found = elementwise.find_root(distance_a, (np.zeros_like(c), np.full_like(c, self.s_max)),
                                          args=(c, s), tolerances=_TOLERANCES)
            s_a[near_a] = found.x
        if np.any(near_b):
            c, s = np.cos(u[near_b]), np.sin(u[near_b])

            def distance_b(x, c, s):
                p, q, _, _ = self._chart_b(x)
                return q * s - p * c
            found = elementwise.find_root(distance_b, (np.zeros_like(c), np.ones_like(c)),
                                          args=(c, s), tolerances=_TOLERANCES)
            _, _, s_a[near_b], tau[near_b] = self._chart_b(found.x)
        done_a = first | near_a
        tau[done_a] = self.general.elevation_of_parameter(s_a[done_a])
        return s_a, tau

    def samples(self, u):
        """The :data:`COLUMNS` at phases u ∈ [0, π/2], shape u.shape + (12,)."""
        s_a, tau = self.solve(u)
        geo = self.general.geometry_at_parameter(s_a, tau, 1)
        r1, r2, n, t1 = geo.contact_a, geo.contact_b, geo.ground_normal, geo.tangent_a
        return np.stack([r1[..., 0], r1[..., 1], r2[..., 1], r2[..., 2], n[..., 0], n[..., 1],
                         n[..., 2], t1[..., 0], t1[..., 1], geo.height, geo.theta, geo.psi],
                        axis=-1)


def unfold(quarter):
    """The whole cycle's samples at u_j = 2πj/N from the quarter u ∈ [0, π/2].

    ``quarter`` has N/4 + 1 rows (u = 2πj/N, j = 0 … N/4); returns N rows. u → −u is the
    mirror x1 → −x1 (θ → −θ) and u → π − u the mirror x3 → −x3 (the other branch).
    """
    m = quarter.shape[0] - 1
    first = quarter[:m + 1]                                   # [0, π/2]
    second = (quarter[m - 1::-1] * BRANCH_FLIP)              # (π/2, π]
    third = (quarter[1:m + 1] * BRANCH_FLIP * THETA_FLIP)   # (π, 3π/2]
    fourth = (quarter[m - 1:0:-1] * THETA_FLIP)              # (3π/2, 2π)
    return np.concatenate([first, second, third, fourth])
