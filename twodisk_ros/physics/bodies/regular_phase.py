"""The regular phase u of a body of any two congruent laminae: its exact solution at nodes.

docs/physics.md#the-phase-of-a-general-body. Quarter-cycle u ∈ [0, π/2] (θ ≥ 0, branch +1)
is solved here; the rest of the cycle follows from the body's two mirror symmetries
(:func:`unfold`).

**The phase.** Along the cycle, A's phase parameter t_A and B's phase parameter β_B measured
from disk 2's far tip (the tip B touches at the turning points) trace a closed curve. The
phase parameter t of a lamina is its boundary parameter s re-spaced, s = w(t)
(:mod:`~twodisk_ros.physics.laminae.phase_map`; t = s but for superellipses, whose vertices and
corners it smooths). In the normalised plane (p, q) = (t_A/t_max, β_B/β_0), β_0 being β_B
at θ = 0 on branch +1, the curve passes through (0, 1) at θ = 0 (branch +1), (1, 0) at the
turning point +θ_max, (0, −1) at θ = 0 on branch −1 and (−1, 0) at −θ_max, winding once
around the origin like (sin u, cos u). u is the polar angle in that plane:
p cos u − q sin u = 0, p sin u + q cos u > 0. The lamina parameters are smooth functions of
the *points* (the eccentric anomaly, the superellipse's projected anomaly away from its
vertices, the normal angle of a strictly convex support-function lamina), and the curve
G(s_A, s_B) = 0 of the common tangent plane (the triple product of the tangents at A and B
and A − B) is regular in them, also where a contact crosses a flat vertex. So everything is
as smooth in u as the points are in t; in θ, ψ or the normal angles it is not (B moves like
τ^(1/(n−1)) near a superellipse's flat tip).

**The solve.** Given u, the point on the ray is found by a bracketing root finder (scipy's
elementwise Chandrupatla) on the signed distance p cos u − q sin u from the ray, in the chart
that is well conditioned there: A's phase parameter for u ≤ π/4 (q from the convex elevation
equation of :meth:`~twodisk_ros.physics.bodies.contact_solver.ContactSolver.elevation_of_parameter`
and the support point of disk 2), B's phase parameter for u > π/4
(:meth:`~twodisk_ros.physics.bodies.contact_solver.ContactSolver.chart_from_b`, regular at the
turning points where ψ(θ) ~ √(θ_max − θ) is not).
"""

import math

import numpy as np

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
    """Exact resting poses at phases u ∈ [0, π/2] of a :class:`ContactSolver`.

    Raises ValueError (one line) when the cycle's curve in the (p, q) plane is not
    star-shaped about the origin (u would not be one-to-one).
    """

    def __init__(self, general):
        self.general = general
        self.map = general.lamina.phase_map()
        self.s_max = general.s_max
        self.t_max = float(self.map.inverse(self.s_max))
        self.tip = general.far_tip
        self.tip_t = float(self.map.inverse(self.tip))
        tau0 = general.elevation_of_parameter(0.0)
        self.beta0 = 1.0
        self.beta0 = float(self._beta(self._parameter_b(np.array(0.0), tau0)))
        if not abs(self.beta0) > 0:
            raise ValueError(f'{general!r}: B sits at disk 2\'s far tip at theta = 0; no '
                             'regular phase')
        # star-shapedness: the polar angle must increase along the chart-A samples
        p, q = self.chart_t(self.t_max * np.linspace(0.0, 1.0, 1025))
        if not (np.all(np.diff(np.arctan2(p, q)) > 0) and np.all(q[:-1] > 0)):
            raise ValueError(f'{general!r}: the contact parameters do not wind once around '
                             'the cycle (no regular phase); choose another delta')

    def _parameter_b(self, s_a, tau_abs):
        """B's lamina parameter on branch +1 from A's parameter and |τ|."""
        g = self.general
        nu = g.lamina.normal(s_a)
        return g.lamina.support(np.stack([-tau_abs, g.sigma * nu[..., 1]], axis=-1)).parameter

    def _beta(self, s_b):
        """q = β/β_0 of B's lamina parameter s_b: β its phase parameter from the far tip."""
        return _wrap(self.map.inverse(_wrap(s_b)) - self.tip_t) / self.beta0

    def chart_t(self, t_a):
        """(p, q) from A's phase parameter t_a ∈ [0, t_max] (branch +1)."""
        s_a = self.map(t_a)
        tau = self.general.elevation_of_parameter(s_a)
        return t_a / self.t_max, self._beta(self._parameter_b(s_a, tau))

    def chart_a(self, s_a):
        """(p, q) from A's lamina parameter s_a ∈ [0, s_max] (branch +1)."""
        return self.chart_t(self.map.inverse(s_a))

    def _chart_b(self, q):
        """(p, q, s_A, |τ|) from q = β/β_0 ∈ [0, 1] (branch +1)."""
        s_a, tau = self.general.chart_from_b(_wrap(self.map(self.tip_t + q * self.beta0)))
        return self.map.inverse(s_a) / self.t_max, q, s_a, tau

    def solve(self, u):
        """(s_A, |τ|) at phases u ∈ [0, π/2] (rad, 1-D array), to the last bits."""
        from scipy.optimize import elementwise
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
                p, q = self.chart_t(x)
                return p * c - q * s
            bracket = (np.zeros_like(c), np.full_like(c, self.t_max))
            found = elementwise.find_root(distance_a, bracket, args=(c, s),
                                          tolerances=_TOLERANCES)
            s_a[near_a] = self.map(found.x)
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

    def quarter_phases(self, a_parameters=(), b_parameters=()):
        """The phases u ∈ [0, π/2] where A sits at one of the lamina parameters
        ``a_parameters`` (of disk 1) or B at one of ``b_parameters`` (of disk 2), from the
        charts at those exact parameters (no root finding in u); parameters not met in the
        quarter (|s_A| > s_max, |β| > |β_0|) are left out. Sorted, without repeats.
        """
        found = []
        for s_a in a_parameters:
            p = float(self.map.inverse(abs(float(_wrap(s_a))))) / self.t_max
            if p <= 1.0:
                q = self.chart_t(p * self.t_max)[1] if 0.0 < p < 1.0 else 1.0 - p
                found.append(math.atan2(p, float(q)))
        for s_b in b_parameters:
            q = abs(float(self._beta(s_b)))
            if q <= 1.0:
                p = self._chart_b(q)[0] if 0.0 < q < 1.0 else 1.0 - q
                found.append(math.atan2(float(p), q))
        return np.unique(np.clip(found, 0.0, 0.5 * math.pi))

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
