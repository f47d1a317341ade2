"""Laminae given by their support function h(φ) of the outward normal's angle: the egg.

A strictly convex lamina is its support function: r(φ) = h n + h′ t and the radius of
curvature h + h″ follow from h alone, and the area moments by Green's theorem in φ
(docs/physics.md#laminae-other-than-ellipses). :class:`SupportLamina` is the protocol of
:mod:`.shapes` in those terms; :class:`Egg` (the ellipse's support function plus a third
harmonic) and the fitted outline of :mod:`.fit` are laminae of this kind.
"""

import abc
import math

import numpy as np

from .shapes import (AreaMoments, Lamina, Support, check_length, direction_angle,
                     normal_of_angle)

__all__ = ['Egg', 'MOMENT_RTOL', 'SupportLamina']

#: Area moments of support-function laminae: the trapezoidal rule in φ (exponentially
#: convergent) doubles its nodes until two results agree to this, relative to the largest.
MOMENT_RTOL = 2e-15
MAX_MOMENT_NODES = 1 << 17


class SupportLamina(Lamina):
    """A lamina given by its support function h(φ) of the normal angle, n(φ) = (sin φ, −cos φ).

    The parameter s is φ itself. With t(φ) = (cos φ, sin φ): r(φ) = h n + h′ t,
    dr/dφ = (h + h″) t, curvature 1/(h + h″); the lamina is strictly convex where the radius
    of curvature h + h″ > 0 everywhere. Symmetric about the common axis: h(−φ) = h(φ).
    Subclasses give :meth:`support_jet`; the area moments follow by Green's theorem in φ.
    """

    @abc.abstractmethod
    def support_jet(self, phi):
        """(h, h′, h″) at normal angles φ (m)."""

    def radius_of_curvature(self, phi):
        """h + h″ at φ (m)."""
        h, _, h2 = self.support_jet(phi)
        return h + h2

    def _vertex_radius(self, s):
        return float(self.radius_of_curvature(s))

    def rim_speed(self, s):
        """|dr/dφ| = h + h″ (m per rad): the parameter is the normal's angle."""
        return self.radius_of_curvature(np.asarray(s, dtype=float))

    def point(self, s):
        s = np.asarray(s, dtype=float)
        h, h1, _ = self.support_jet(s)
        n = normal_of_angle(s)
        return h[..., None] * n + h1[..., None] * np.stack([-n[..., 1], n[..., 0]], axis=-1)

    def normal(self, s):
        return normal_of_angle(s)

    def curvature(self, s):
        return 1.0 / self.radius_of_curvature(np.asarray(s, dtype=float))

    def support(self, direction):
        phi, length = direction_angle(direction)
        h, _, _ = self.support_jet(phi)
        return Support(h * length, self.point(phi), phi)

    def _moments_on(self, nodes):
        phi = 2 * np.pi * np.arange(nodes) / nodes
        x, y = np.moveaxis(self.point(phi), -1, 0)
        rho = self.radius_of_curvature(phi)
        dx, dy = rho * np.cos(phi), rho * np.sin(phi)   # dr/dφ = ρ t
        step = 2 * np.pi / nodes
        # Green: ∮ x dy = A, ∮ −y²/2 dx = ∫y, ∮ x³/3 dy = ∫x², ∮ −y³/3 dx = ∫y², ∮ x²y/2 dy = ∫xy
        return step * np.array([np.sum(x * dy), np.sum(-y * y * dx) / 2,
                                np.sum(x**3 * dy) / 3, np.sum(-y**3 * dx) / 3,
                                np.sum(x * x * y * dy) / 2])

    @property
    def moments(self):
        cached = self.__dict__.get('_moments')
        if cached is None:
            nodes = 64
            old = self._moments_on(nodes)
            while True:
                nodes *= 2
                new = self._moments_on(nodes)
                scale = self.size ** 4
                if np.max(np.abs(new - old)) <= MOMENT_RTOL * scale or nodes >= MAX_MOMENT_NODES:
                    break
                old = new
            area, first_y, xx, yy, xy = (float(v) for v in new)
            cached = AreaMoments(area, np.array([0.0, first_y / area]), xx, yy, xy)
            self.__dict__['_moments'] = cached
        return cached


class Egg(SupportLamina):
    """An egg: the ellipse's support function plus a third harmonic.

    h(φ) = √(a² cos²φ + b² sin²φ) + ε cos 3φ, φ the outward normal's angle from −y. The
    harmonic keeps the symmetry about the common axis (h even in φ) and breaks the one about
    the x axis (cos 3(π − φ) = −cos 3φ): for ε > 0 the end at −y is sharper and reaches
    y = −(a + ε), the end at +y is blunter and reaches a − ε; the half width stays b. Radius of
    curvature a²b²/h_E³ − 8ε cos 3φ; convex iff |ε| < ε_max(a, b) (:meth:`epsilon_max`), and
    Egg(a, b, −ε) is the mirror image of Egg(a, b, ε) in the x axis. Area πab − 4πε² (the
    cross terms integrate to zero); second moments by Green's theorem. The origin is the
    ellipse's centre, so the centroid lies off it along the common axis.

    Parameters
    ----------
    a, b : float
        Semi-axes of the underlying ellipse along y (common axis) and x (m), finite, > 0.
    epsilon : float
        Amplitude of the third harmonic (m), |epsilon| < epsilon_max(a, b).
    """

    def __init__(self, a, b, epsilon):
        self.a = check_length('a', a)
        self.b = check_length('b', b)
        limit = self.epsilon_max(self.a, self.b)
        rule = (f'|epsilon| < {limit:.6g} m for a = {self.a:g} m, b = {self.b:g} m '
                '(radius of curvature h + h\'\' > 0: a strictly convex egg)')
        if isinstance(epsilon, (str, bytes, bool)) or epsilon is None:
            raise ValueError(f'epsilon must be a real number with {rule}, got {epsilon!r}')
        try:
            eps = float(epsilon)
        except (TypeError, ValueError):
            raise ValueError(f'epsilon must be a real number with {rule}, '
                             f'got {epsilon!r}') from None
        if not (math.isfinite(eps) and abs(eps) < limit):
            raise ValueError(f'epsilon must be finite with {rule}, got {epsilon!r}')
        self.epsilon = eps
        grid = np.linspace(0.0, np.pi, 4097)
        if float(np.min(self.radius_of_curvature(grid))) <= 1e-9 * max(self.a, self.b):
            raise ValueError(f'epsilon must be finite with {rule}, got {epsilon!r}')

    def __repr__(self):
        return f'Egg(a={self.a!r}, b={self.b!r}, epsilon={self.epsilon!r})'

    def describe(self):
        return f'egg a = {self.a:.4g} m, b = {self.b:.4g} m, ε = {self.epsilon:.3g} m'

    @staticmethod
    def epsilon_max(a, b):
        """Largest |ε| (m) keeping h + h″ > 0: min over cos 3φ > 0 of (a²b²/h_E³)/(8 cos 3φ)."""
        from scipy.optimize import minimize_scalar
        def ratio(phi):
            he = math.hypot(a * math.cos(phi), b * math.sin(phi))
            return a * a * b * b / he**3 / (8 * math.cos(3 * phi))
        best = math.inf
        for low, high in ((0.0, np.pi / 6), (np.pi / 2, 5 * np.pi / 6)):
            grid = np.linspace(low, high, 402)[1:-1] if low else np.linspace(low, high, 401)[:-1]
            values = [ratio(p) for p in grid]
            j = int(np.argmin(values))
            step = grid[1] - grid[0]
            found = minimize_scalar(ratio, bounds=(max(grid[j] - step, low),
                                                   min(grid[j] + step, high - 1e-12)),
                                    method='bounded', options={'xatol': 1e-13})
            best = min(best, values[j], float(found.fun))
        return best

    def support_jet(self, phi):
        phi = np.asarray(phi, dtype=float)
        a, b, eps = self.a, self.b, self.epsilon
        sin, cos = np.sin(phi), np.cos(phi)
        he = np.hypot(a * cos, b * sin)
        he1 = (b * b - a * a) * sin * cos / he
        he2 = a * a * b * b / he**3 - he
        c3, s3 = np.cos(3 * phi), np.sin(3 * phi)
        return he + eps * c3, he1 - 3 * eps * s3, he2 - 9 * eps * c3
