"""Many two-disk bodies at once: the closed forms of :mod:`~twodisk_ros.physics.bodies.ellipse` on a
batch axis.

:class:`EllipseBodies` holds B bodies (a, b, Δ as arrays of shape (B,), metres) and inherits
every closed form in the cycle phase u from :class:`~twodisk_ros.physics.bodies.ellipse.EllipseForms`,
the same code as :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody`: a phase array of shape
(..., B) (one phase per body) or (..., 1) (the same phases for every body) broadcasts against
the parameters, and vectors get a trailing axis of 3 (body frame). Only the constants of the
constructor are computed with numpy instead of ``math``; results agree with the scalar body's
to rounding (~1e-16 relative).

:meth:`EllipseBodies.cycle_samples` evaluates on the nodes u_j = 2πj/N of one cycle
everything that the sweep's tables need (contact vectors, ground normal, height and its
slope, angular velocity per u̇, the rates of the contact trace), vectors component first.
"""

from dataclasses import dataclass
import math

import numpy as np

from .ellipse import LENGTH_RANGE, EllipseForms
from ..numerics.spectral import real_spectral_derivative

__all__ = ['EllipseBodies', 'CycleSamples', 'cross', 'dot']


@dataclass(frozen=True)
class CycleSamples:
    """Closed forms of B bodies at the N nodes u_j = 2πj/N of one cycle.

    Scalars have shape (N, B); vectors (3, N, B), component first (body frame, metres or
    unit), so that products of components are contiguous array operations.
    """

    contact_a: np.ndarray       #: r1 = GA (m)
    contact_b: np.ndarray       #: r2 = GB (m)
    ground_normal: np.ndarray   #: n, unit, up
    tangent_a: np.ndarray       #: t1, unit tangent of disk 1 at A
    height: np.ndarray          #: z_G (m)
    height_slope: np.ndarray    #: dz_G/du (m/rad), spectral
    angular_velocity: np.ndarray   #: ω_u (rad per unit u), as EllipseForms.phase_angular_velocity
    arc_rate: np.ndarray        #: ds/du of the trace of A (m/rad)
    turn_rate: np.ndarray       #: dα/du of the trace of A (rad/rad)


def cross(x, y):
    """x × y of component-first vectors (3, ...) (the arithmetic of :func:`numpy.cross`)."""
    out = np.empty(np.broadcast_shapes(x.shape, y.shape), dtype=np.result_type(x, y))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        np.multiply(x[j], y[k], out=out[i])
        out[i] -= x[k] * y[j]
    return out


def dot(x, y):
    """x · y of component-first vectors (3, ...), summed in the order 0, 1, 2."""
    out = x[0] * y[0]
    out += x[1] * y[1]
    out += x[2] * y[2]
    return out


class EllipseBodies(EllipseForms):
    """B two-disk bodies (a, b, Δ) at once, for array evaluation of the closed forms in u.

    Parameters
    ----------
    a, b, delta : array_like
        Broadcast to one axis of B bodies (m): each finite, in ``LENGTH_RANGE``, b > 0 and
        0 < delta < a, as for :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` (whose
        constructor gives the per-body message).

    Raises
    ------
    ValueError
        If any body is not allowed (one line naming the first one).
    """

    def __init__(self, a, b, delta):
        a, b, delta = (np.atleast_1d(np.asarray(x, dtype=float)) for x in (a, b, delta))
        a, b, delta = (np.ascontiguousarray(x) for x in np.broadcast_arrays(a, b, delta))
        if a.ndim != 1:
            raise ValueError(f'a, b and delta must broadcast to one axis, got shape {a.shape}')
        low, high = LENGTH_RANGE
        with np.errstate(invalid='ignore'):
            good = ((a >= low) & (a <= high) & (b >= low) & (b <= high) & (delta >= low)
                    & (delta < a))
        if not np.all(good):
            i = int(np.argmin(good))
            raise ValueError(f'body {i} (a = {a[i]!r}, b = {b[i]!r}, delta = {delta[i]!r}) is '
                             f'not allowed: lengths must be finite in [{low:g}, {high:g}] m '
                             f'with 0 < delta < a')
        self.a, self.b, self.delta = a, b, delta
        # the constants of EllipseBody.__init__, element by element
        root = np.sqrt(a**4 + 4 * a * delta * b * b + 4 * delta * delta * b * b)
        self._cos_theta_max = -a * a / root
        self.theta_max = np.arctan2(2 * b * np.sqrt(delta * (a + delta)), -a * a)
        self._sin_theta_max = np.sin(self.theta_max)
        self._d_max = np.hypot(a * self._sin_theta_max, b * self._cos_theta_max)
        self._eta_max = np.arctan2(a * self._sin_theta_max, b * self._cos_theta_max)
        self._cos_eta_max = np.cos(self._eta_max)
        self._sin_eta_max = np.sin(self._eta_max)
        self._e_max = np.hypot(a * self._cos_eta_max, b * self._sin_eta_max)

    def __len__(self):
        return self.a.size

    def __repr__(self):
        return f'EllipseBodies({len(self)} bodies)'

    def subset(self, index):
        """The bodies ``index`` (an integer array or a boolean mask) as a new batch."""
        return EllipseBodies(self.a[index], self.b[index], self.delta[index])

    @property
    def size(self):
        """:attr:`EllipseBody.size` of each body (m), shape (B,)."""
        a, b, d = self.a, self.b, self.delta
        with np.errstate(divide='ignore', invalid='ignore'):
            wide = np.sqrt(b * b + d * d + (a * d) ** 2 / (b * b - a * a))
        return np.where((a >= b) | (a * d >= b * b - a * a), a + d, wide)

    def cycle_samples(self, nodes):
        """:class:`CycleSamples` at u_j = 2πj/``nodes``, from the closed forms.

        The values (contact vectors, normal, tangent, height, the trace's rates) are the
        scalar body's closed forms. ω_u is :meth:`EllipseForms.phase_angular_velocity`'s
        formula, ω_u = α′ n − ½ Σ b × b′ over the frame b = t1, n × t1, n, with the
        u-derivatives of n and t1 in closed form (:meth:`frame_rates`) instead of a complex
        step: the same values to ~1e-15 relative (measured over b/a ∈ [0.01, 100],
        Δ/a ∈ [1e-3, 1 − 1e-6]), without the complex evaluation that costs twice the real
        one. dz_G/du, which only the signs of the equilibria's curvatures at the turning
        points need, is the spectral derivative of z_G on the nodes.
        """
        u = (2.0 * math.pi * np.arange(nodes) / nodes)[:, None]
        theta, cos_t, sin_t, j = self.phase_angles(u)
        d = self._ellipse_terms(cos_t, sin_t)
        root = np.sqrt(j * self._q_cofactor(cos_t, d))
        sq = np.cos(u) * root               # σ√Q, as EllipseForms._phase_sqrt_q
        r1, r2, normal, t1, height, planar, norm_n = self._geometry_components(cos_t, sin_t,
                                                                                sq)
        ds, dalpha = self._rates(u, cos_t, sin_t, sq)
        normal, t1 = np.stack(normal), np.stack(t1)
        dn, dt1 = self.frame_rates(u, cos_t, sin_t, d, root, normal, t1, planar, norm_n)
        m = cross(normal, t1)
        dm = cross(dn, t1) + cross(normal, dt1)
        frame_rate = 0.5 * (cross(normal, dn) + cross(t1, dt1) + cross(m, dm))
        return CycleSamples(contact_a=np.stack(r1), contact_b=np.stack(r2),
                            ground_normal=normal, tangent_a=t1, height=height,
                            height_slope=real_spectral_derivative(height),
                            angular_velocity=dalpha * normal - frame_rate, arc_rate=ds,
                            turn_rate=dalpha)

    def frame_rates(self, u, cos_t, sin_t, d, root, normal, tangent, planar, norm_n):
        """dn/du and dt1/du (component first) in closed form, at phases u.

        n = N/|N| with N = (−a² sin θ, b² cos θ, σ√Q) and t1 = T/|T| with
        T = (b² cos θ, a² sin θ, 0), so n′ = (N′ − n (n·N′))/|N|, likewise t1′, with
        θ′ = dθ/dη · dη/du = (D²/ab) η_max cos u (tan θ = (b/a) tan η, D = √(a² sin²θ +
        b² cos²θ) = ab/E(η)) and (σ√Q)′ = Q_θ θ′ / (2 σ√Q) = Q_θ (D²/ab) η_max / (2 r), where
        σ√Q = r cos u (r > 0, :meth:`EllipseForms.phase_signed_sqrt_q`): regular at the
        turning points. Q_θ = 2 sin θ (a⁴ cos θ − 2abΔ D + 2abΔ (a² − b²) cos²θ / D
        − 4b²Δ² cos θ), from Q = a⁴ sin²θ + 4abΔ cos θ D + 4b²Δ² cos²θ.

        Parameters: u, the angles (cos θ, sin θ), D, r, n, t1 (3, ...), |T| and |N| as
        evaluated by :meth:`cycle_samples`.
        """
        a, b, delta = self.a, self.b, self.delta
        scale = d * d * self._eta_max / (a * b)
        theta_u = scale * np.cos(u)
        q_theta = 2 * sin_t * (a**4 * cos_t - 2 * a * b * delta * d
                               + 2 * a * b * delta * (a * a - b * b) * cos_t * cos_t / d
                               - 4 * b * b * delta * delta * cos_t)
        big_n = np.stack([-a * a * cos_t * theta_u, -b * b * sin_t * theta_u,
                          q_theta * scale / (2 * root)])
        big_t = np.stack([-b * b * sin_t * theta_u, a * a * cos_t * theta_u,
                          np.zeros_like(theta_u)])
        return ((big_n - normal * dot(normal, big_n)) / norm_n,
                (big_t - tangent * dot(tangent, big_t)) / planar)
