"""Many two-disk bodies at once: the closed forms of :mod:`~twodisk_ros.physics.body` on a
batch axis.

:class:`TwoDiskBodies` holds B bodies (a, b, Δ as arrays of shape (B,), metres) and inherits
every closed form in the cycle phase u from :class:`~twodisk_ros.physics.body.TwoDiskForms`,
the same code as :class:`~twodisk_ros.physics.body.TwoDiskBody`: a phase array of shape
(..., B) (one phase per body) or (..., 1) (the same phases for every body) broadcasts against
the parameters, and vectors get a trailing axis of 3 (body frame). Only the constants of the
constructor are computed with numpy instead of ``math``; results agree with the scalar body's
to rounding (~1e-16 relative).

:meth:`TwoDiskBodies.cycle_samples` evaluates on the nodes u_j = 2πj/N of one cycle
everything that the sweep's tables need (contact vectors, ground normal, height and its
slope, angular velocity per u̇, the rates of the contact trace), vectors component first.
"""

from dataclasses import dataclass
import math

import numpy as np

from .analytic import COMPLEX_STEP
from .body import LENGTH_RANGE, TwoDiskForms
from .spectral import real_spectral_derivative

__all__ = ['TwoDiskBodies', 'CycleSamples', 'cross', 'dot']


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
    angular_velocity: np.ndarray   #: ω_u (rad per unit u), as TwoDiskForms.phase_angular_velocity
    arc_rate: np.ndarray        #: ds/du of the trace of A (m/rad)
    turn_rate: np.ndarray       #: dα/du of the trace of A (rad/rad)


def cross(x, y):
    """x × y of component-first vectors (3, ...)."""
    return np.stack([x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                     x[0] * y[1] - x[1] * y[0]])


def dot(x, y):
    """x · y of component-first vectors (3, ...)."""
    return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]


class TwoDiskBodies(TwoDiskForms):
    """B two-disk bodies (a, b, Δ) at once, for array evaluation of the closed forms in u.

    Parameters
    ----------
    a, b, delta : array_like
        Broadcast to one axis of B bodies (m): each finite, in ``LENGTH_RANGE``, b > 0 and
        0 < delta < a, as for :class:`~twodisk_ros.physics.body.TwoDiskBody` (whose
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
        # the constants of TwoDiskBody.__init__, element by element
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
        return f'TwoDiskBodies({len(self)} bodies)'

    def subset(self, index):
        """The bodies ``index`` (an integer array or a boolean mask) as a new batch."""
        return TwoDiskBodies(self.a[index], self.b[index], self.delta[index])

    @property
    def size(self):
        """:attr:`TwoDiskBody.size` of each body (m), shape (B,)."""
        a, b, d = self.a, self.b, self.delta
        with np.errstate(divide='ignore', invalid='ignore'):
            wide = np.sqrt(b * b + d * d + (a * d) ** 2 / (b * b - a * a))
        return np.where((a >= b) | (a * d >= b * b - a * a), a + d, wide)

    def cycle_samples(self, nodes):
        """:class:`CycleSamples` at u_j = 2πj/``nodes``, as the scalar body computes them.

        The values (contact vectors, normal, tangent, height, the trace's rates) are the
        real closed forms; ω_u is :meth:`TwoDiskForms.phase_angular_velocity`'s formula,
        with n, t1 and their u-derivatives from one complex step at u + ih (h = 1e-30, exact
        derivatives), so the samples equal the scalar body's to rounding (also for the
        extreme shapes, where the real parts of a complex-step evaluation differ from the
        real closed forms by up to ~1e-13; spectral derivatives of n and t1 instead would
        differ by ~1e-11). dz_G/du, which only the signs of the equilibria's curvatures at
        the turning points need, is the spectral derivative of z_G on the nodes.
        """
        u = (2.0 * math.pi * np.arange(nodes) / nodes)[:, None]
        theta, cos_t, sin_t, j = self.phase_angles(u)
        sq = self._phase_sqrt_q(u, cos_t, sin_t, j)
        r1, r2, normal, t1, height = self._geometry_components(cos_t, sin_t, sq)[:5]
        ds, dalpha = self._rates(u, cos_t, sin_t, sq)
        uc = u + 1j * COMPLEX_STEP
        _, cos_c, sin_c, j_c = self.phase_angles(uc)
        n_c, t_c = self._frame(cos_c, sin_c, self._phase_sqrt_q(uc, cos_c, sin_c, j_c))[:2]
        n_c, t_c = np.stack(n_c), np.stack(t_c + [np.zeros_like(t_c[0])])
        n_re, t1_re, dn, dt1 = n_c.real, t_c.real, n_c.imag / COMPLEX_STEP, t_c.imag / COMPLEX_STEP
        m_re = cross(n_re, t1_re)
        dm = cross(dn, t1_re) + cross(n_re, dt1)
        frame_rate = 0.5 * (cross(n_re, dn) + cross(t1_re, dt1) + cross(m_re, dm))
        return CycleSamples(contact_a=np.stack(r1), contact_b=np.stack(r2),
                            ground_normal=np.stack(normal), tangent_a=np.stack(t1),
                            height=height, height_slope=real_spectral_derivative(height),
                            angular_velocity=dalpha * n_re - frame_rate, arc_rate=ds,
                            turn_rate=dalpha)
