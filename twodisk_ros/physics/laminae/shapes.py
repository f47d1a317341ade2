"""A planar lamina in its own plane: one protocol, the ellipse and the superellipse.

The foundation of bodies of any two congruent symmetric laminae: :mod:`~twodisk_ros.physics.bodies.contact_solver` solves
their contact geometry from it and :mod:`~twodisk_ros.physics.bodies.lamina_body` makes them rolling bodies
(docs/physics.md#laminae-other-than-ellipses).

Lamina coordinates (metres), those of disk 1 in the body frame seen from its centre C1:
``x`` along e1 (the disk's other axis, semi-extent ``b``), ``y`` along e2 (the common axis,
semi-extent ``a``). Every lamina is convex and symmetric about the common axis (x → −x); it
need not be symmetric about the x axis (the egg is not).

The boundary is a closed curve r(s) of a 2π-periodic parameter ``s`` (rad), in the sense of
the package's θ: s = 0 is the far tip on −y (where θ = 0 touches), s = π the tip on +y, s
increases counterclockwise (towards +x first) and s → −s is the mirror x → −x. What s is
depends on the shape: the eccentric anomaly for the ellipse (as in bodies/ellipse.py), its radial
projection for the superellipse, the outward normal's angle for the laminae defined by their
support function (egg, fitted outline). Everything is vectorised: ``s`` of any shape gives
results of shape ``s.shape`` (scalars) or ``s.shape + (2,)`` (vectors); a direction array of
shape ``(..., 2)`` gives ``(...)`` heights and ``(..., 2)`` points.

Protocol (:class:`Lamina`): ``point(s)``, ``tangent(s)`` (unit, s increasing), ``normal(s)``
(unit, outward), ``curvature(s)`` (1/m, ≥ 0), ``support(direction)`` (the support function
h(n) = max over the boundary of r·n, the point attaining it and its parameter), ``moments``
(area, centroid, second moments of area about the lamina's origin), ``extents``, ``size`` and
``vertex(axis)`` (extent, radius of curvature and order of contact where the normal is ±y, +x),
``rim_speed(s)`` (|dr/ds|), ``log_curvature(s)`` and ``phase_map()`` (how the body's regular
phase re-spaces s). Laminae given by their support function (the egg, a fitted outline) are
in :mod:`.support`.
"""

import abc
from dataclasses import dataclass
import math

import numpy as np

from .phase_map import PhaseMap, superellipse_phase_map

__all__ = ['AreaMoments', 'Ellipse', 'Lamina', 'LENGTH_RANGE', 'SUPERELLIPSE_EXPONENT',
           'Superellipse', 'Support', 'VERTEX_AXES', 'Vertex', 'check_length', 'direction_angle',
           'normal_of_angle']

#: Allowed lengths (m), as for EllipseBody: the forms hold up to sixth powers of lengths.
LENGTH_RANGE = (1e-30, 1e30)
#: Allowed superellipse exponents n: from the ellipse (2) to a rounded rectangle whose corner
#: radius of curvature is a few per cent of its size (about 0.05 b at n = 100, b = a).
SUPERELLIPSE_EXPONENT = (2.0, 100.0)
#: A vertex radius of curvature above this multiple of the size is a flat vertex (zero
#: curvature, up to rounding), whose order of contact the lamina must give itself.
FLAT_RADIUS = 1e12
#: The vertices of a lamina symmetric about its y axis: where the outward normal is ±y or +x.
VERTEX_AXES = {'-y': (0.0, -1.0), '+y': (0.0, 1.0), '+x': (1.0, 0.0)}


def check_length(name, value, rule='> 0 (metres)', low=0.0):
    """``value`` as a float when finite, > ``low`` and within LENGTH_RANGE, else ValueError."""
    if isinstance(value, (str, bytes, bool)) or value is None:
        raise ValueError(f'{name} must be a real number {rule}, got {value!r}')
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} must be a real number {rule}, got {value!r}') from None
    lo, hi = LENGTH_RANGE
    if not (math.isfinite(value) and value > low and lo <= value <= hi):
        raise ValueError(f'{name} must be finite, {rule} and in [{lo:g}, {hi:g}] m, '
                         f'got {value!r}')
    return value


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def direction_angle(direction):
    """Normal angle φ of a direction: n(φ) = (sin φ, −cos φ); also |direction|."""
    d = np.asarray(direction, dtype=float)
    if d.shape[-1:] != (2,):
        raise ValueError(f'a direction must have a last axis of length 2, got shape {d.shape}')
    return np.arctan2(d[..., 0], -d[..., 1]), np.hypot(d[..., 0], d[..., 1])


def normal_of_angle(phi):
    """Outward unit normal (sin φ, −cos φ) of normal angle φ (rad)."""
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.sin(phi), -np.cos(phi)], axis=-1)


@dataclass(frozen=True)
class Support:
    """The support function at some directions and where it is attained."""

    height: np.ndarray      #: h(n) = max over the boundary of r·n (m; homogeneous in n)
    point: np.ndarray       #: the boundary point attaining it, shape (..., 2) (m)
    parameter: np.ndarray   #: its boundary parameter s (rad, in (−π, π])


@dataclass(frozen=True)
class AreaMoments:
    """Area moments of a lamina in its coordinates (about its origin unless said otherwise)."""

    area: float             #: A = ∫ dA (m²)
    centroid: np.ndarray    #: (∫x dA, ∫y dA) / A (m); x is 0 by symmetry
    second_xx: float        #: ∫ x² dA (m⁴), x along e1
    second_yy: float        #: ∫ y² dA (m⁴), y along the common axis e2
    second_xy: float        #: ∫ x y dA (m⁴), 0 by symmetry

    @property
    def polar(self):
        """∫ (x² + y²) dA about the origin (m⁴)."""
        return self.second_xx + self.second_yy

    @property
    def central_yy(self):
        """∫ (y − ȳ)² dA about the centroid (m⁴)."""
        return self.second_yy - self.area * float(self.centroid[1]) ** 2

    @property
    def central_polar(self):
        """Polar moment about the centroid (m⁴)."""
        return self.second_xx + self.central_yy


@dataclass(frozen=True)
class Vertex:
    """A vertex: the boundary point whose outward normal d lies along an axis.

    Near d the support function is h(d + t d⊥) = extent + (point·d⊥) t + coefficient·|t|^order
    + o(t²), with d⊥ = d turned by +90° (point·d⊥ = 0 at the ±y vertices). A rounded vertex
    has order 2 and coefficient radius/2; a flat one (radius = inf, the superellipse's for
    n > 2) has 1 < order < 2 and no t² term.
    """

    axis: str               #: '-y' (the far tip, s = 0), '+y' or '+x' (the side)
    direction: np.ndarray   #: d, the unit outward normal there
    point: np.ndarray       #: the vertex (m)
    extent: float           #: h(d) = point·d (m)
    radius: float           #: radius of curvature (m), inf where the curvature vanishes
    order: float            #: q in (1, 2]
    coefficient: float      #: c of c·|t|^q (m)


class Lamina(abc.ABC):
    """A convex planar lamina symmetric about the common axis (see the module docstring)."""

    @abc.abstractmethod
    def point(self, s):
        """Boundary point r(s), shape ``s.shape + (2,)`` (m)."""

    @abc.abstractmethod
    def normal(self, s):
        """Outward unit normal at r(s), shape ``s.shape + (2,)``."""

    @abc.abstractmethod
    def curvature(self, s):
        """Curvature κ(s) ≥ 0 of the boundary (1/m)."""

    @abc.abstractmethod
    def support(self, direction):
        """:class:`Support` for directions of shape (..., 2) (unit or not; h is homogeneous)."""

    @property
    @abc.abstractmethod
    def moments(self):
        """:class:`AreaMoments` of the lamina."""

    def tangent(self, s):
        """Unit tangent at r(s), direction of increasing s: the normal turned by +90°."""
        n = self.normal(s)
        return np.stack([-n[..., 1], n[..., 0]], axis=-1)

    def rim_speed(self, s):
        """|dr/ds| (m per rad) of the boundary parameter: here an eighth-order central
        difference of :meth:`point` (about 1e-12 relative); the shipped laminae give it in
        closed form."""
        s = np.asarray(s, dtype=float)
        step = 1e-2
        coefficients = (4 / 5, -1 / 5, 4 / 105, -1 / 280)
        derivative = sum(c * (self.point(s + k * step) - self.point(s - k * step))
                         for k, c in enumerate(coefficients, start=1)) / step
        return np.linalg.norm(derivative, axis=-1)

    def log_curvature(self, s):
        """log κ(s) (κ in 1/m); a lamina whose curvature underflows overrides it."""
        return np.log(self.curvature(np.asarray(s, dtype=float)))

    def phase_map(self):
        """The :class:`~twodisk_ros.physics.laminae.phase_map.PhaseMap` of the regular phase:
        the identity unless the lamina has vertices the phase must dwell at."""
        return PhaseMap()

    def describe(self):
        """One line naming the lamina by its parameters (m), for titles and logs; here by its
        extents (the shipped laminae name their own parameters)."""
        x_max, y_min, y_max = self.extents
        return (f'{type(self).__name__.lower()} x_max = {x_max:.4g} m, y from {y_min:.4g} '
                f'to {y_max:.4g} m')

    def _vertex_radius(self, s):
        curvature = float(self.curvature(s))
        return 1.0 / curvature if curvature > 0 else math.inf

    def vertex(self, axis):
        """:class:`Vertex` at ``axis`` '-y', '+y' or '+x' (where the normal is along it)."""
        if axis not in VERTEX_AXES:
            raise ValueError(f'axis must be one of {sorted(VERTEX_AXES)}, got {axis!r}')
        direction = np.array(VERTEX_AXES[axis])
        found = self.support(direction)
        radius = self._vertex_radius(found.parameter)
        if not radius < FLAT_RADIUS * self.size:
            raise ValueError(f'{self!r} is flat at its {axis} vertex (radius of curvature '
                             f'{radius:.3g} m) and does not give its order of contact')
        return Vertex(axis, direction, np.asarray(found.point, dtype=float),
                      float(found.height), radius, 2.0, 0.5 * radius)

    @property
    def extents(self):
        """(x_max, y_min, y_max) (m): the half width and the ends along the common axis."""
        h = self.support(np.array([[1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])).height
        return float(h[0]), -float(h[1]), float(h[2])

    @property
    def size(self):
        """Largest distance of a boundary point from the origin (m) = max of h over n."""
        from scipy.optimize import minimize_scalar
        cached = self.__dict__.get('_size')
        if cached is None:
            grid = np.linspace(0.0, np.pi, 2049)
            radius = np.linalg.norm(self.point(grid), axis=-1)
            j = int(np.argmax(radius))
            step = grid[1]
            found = minimize_scalar(lambda s: -float(np.linalg.norm(self.point(s))),
                                    bounds=(max(grid[j] - step, 0.0), min(grid[j] + step, np.pi)),
                                    method='bounded', options={'xatol': 1e-12})
            cached = max(float(radius[j]), -float(found.fun))
            self.__dict__['_size'] = cached
        return cached


class Ellipse(Lamina):
    """|x/b|² + |y/a|² ≤ 1: closed forms, with s the eccentric anomaly: r = (b sin s, −a cos s).

    Parameters
    ----------
    a : float
        Semi-axis along the common axis, y (m), finite and > 0.
    b : float
        The other semi-axis, x (m), finite and > 0.
    """

    def __init__(self, a, b):
        self.a = check_length('a', a)
        self.b = check_length('b', b)

    def __repr__(self):
        return f'{type(self).__name__}(a={self.a!r}, b={self.b!r})'

    def describe(self):
        return f'ellipse a = {self.a:.4g} m, b = {self.b:.4g} m'

    def point(self, s):
        s = np.asarray(s, dtype=float)
        return np.stack([self.b * np.sin(s), -self.a * np.cos(s)], axis=-1)

    def normal(self, s):
        s = np.asarray(s, dtype=float)
        return _unit(np.stack([self.a * np.sin(s), -self.b * np.cos(s)], axis=-1))

    def curvature(self, s):
        s = np.asarray(s, dtype=float)
        a, b = self.a, self.b
        return a * b / np.hypot(b * np.cos(s), a * np.sin(s)) ** 3

    def rim_speed(self, s):
        """|dr/ds| = √(b² cos² s + a² sin² s) (m per rad of the eccentric anomaly)."""
        s = np.asarray(s, dtype=float)
        return np.hypot(self.b * np.cos(s), self.a * np.sin(s))

    def support(self, direction):
        d = np.asarray(direction, dtype=float)
        direction_angle(d)
        a, b = self.a, self.b
        h = np.hypot(b * d[..., 0], a * d[..., 1])
        point = np.stack([b * b * d[..., 0] / h, a * a * d[..., 1] / h], axis=-1)
        return Support(h, point, np.arctan2(point[..., 0] / b, -point[..., 1] / a))

    @property
    def moments(self):
        a, b = self.a, self.b
        return AreaMoments(math.pi * a * b, np.zeros(2), math.pi * a * b**3 / 4,
                           math.pi * a**3 * b / 4, 0.0)

    @property
    def size(self):
        return max(self.a, self.b)


class Superellipse(Lamina):
    """|x/b|ⁿ + |y/a|ⁿ ≤ 1 with 2 ≤ n ≤ 100 (n = 2: the ellipse; large n: a rounded rectangle).

    The parameter s is the eccentric anomaly projected radially onto the curve:
    r(s) = (b sin s, −a cos s) / N(s), N = (|sin s|ⁿ + |cos s|ⁿ)^(1/n), with nonzero speed
    everywhere. Support function in closed form, h(n) = (|b n_x|^q + |a n_y|^q)^(1/q) with
    q = n/(n − 1), and the support point is its gradient, exact also at the four vertices
    where the curvature vanishes (n > 2). Curvature from the implicit form F = |x/b|ⁿ + |y/a|ⁿ:
    κ = (F_y² F_xx + F_x² F_yy) / (F_x² + F_y²)^(3/2). Area 4ab Γ(1+1/n)²/Γ(1+2/n),
    ∫x² dA = 4ab³ Γ(3/n)Γ(1/n) / (n² Γ(1+4/n)), ∫y² dA the same with a³b.

    Parameters
    ----------
    a, b : float
        Semi-axes along y (the common axis) and x (m), finite and > 0.
    n : float
        Exponent, 2 ≤ n ≤ 100.
    """

    def __init__(self, a, b, n):
        self.a = check_length('a', a)
        self.b = check_length('b', b)
        low, high = SUPERELLIPSE_EXPONENT
        rule = f'{low:g} <= n <= {high:g} (2: the ellipse; larger: towards a rectangle)'
        if isinstance(n, (str, bytes, bool)) or n is None:
            raise ValueError(f'n must be a real number with {rule}, got {n!r}')
        try:
            n_value = float(n)
        except (TypeError, ValueError):
            raise ValueError(f'n must be a real number with {rule}, got {n!r}') from None
        if not (math.isfinite(n_value) and low <= n_value <= high):
            raise ValueError(f'n must be finite with {rule}, got {n!r}')
        self.n = n_value
        self.q = n_value / (n_value - 1.0)

    def __repr__(self):
        return f'Superellipse(a={self.a!r}, b={self.b!r}, n={self.n!r})'

    def describe(self):
        return f'superellipse a = {self.a:.4g} m, b = {self.b:.4g} m, n = {self.n:g}'

    def _sin_cos(self, s):
        s = np.asarray(s, dtype=float)
        sin, cos = np.sin(s), np.cos(s)
        norm = (np.abs(sin) ** self.n + np.abs(cos) ** self.n) ** (1.0 / self.n)
        return sin, cos, norm

    def point(self, s):
        sin, cos, norm = self._sin_cos(s)
        return np.stack([self.b * sin / norm, -self.a * cos / norm], axis=-1)

    def normal(self, s):
        sin, cos, _ = self._sin_cos(s)
        m = self.n - 1.0
        grad = np.stack([np.sign(sin) * np.abs(sin) ** m / self.b,
                         -np.sign(cos) * np.abs(cos) ** m / self.a], axis=-1)
        return _unit(grad)

    def curvature(self, s):
        sin, cos, norm = self._sin_cos(s)
        n, a, b = self.n, self.a, self.b
        gx, gy = np.abs(sin) ** (n - 1) / b, np.abs(cos) ** (n - 1) / a
        hx, hy = (n - 1) * np.abs(sin) ** (n - 2) / b**2, (n - 1) * np.abs(cos) ** (n - 2) / a**2
        return norm * (gy * gy * hx + gx * gx * hy) / np.hypot(gx, gy) ** 3

    def support(self, direction):
        d = np.asarray(direction, dtype=float)
        direction_angle(d)
        q, a, b = self.q, self.a, self.b
        bx, ay = np.abs(b * d[..., 0]), np.abs(a * d[..., 1])
        h = (bx**q + ay**q) ** (1.0 / q)
        scale = h ** (1.0 - q)
        point = np.stack([b * np.sign(d[..., 0]) * bx ** (q - 1) * scale,
                          a * np.sign(d[..., 1]) * ay ** (q - 1) * scale], axis=-1)
        return Support(h, point, np.arctan2(point[..., 0] / b, -point[..., 1] / a))

    @property
    def moments(self):
        a, b, n = self.a, self.b, self.n
        area = 4 * a * b * math.gamma(1 + 1 / n) ** 2 / math.gamma(1 + 2 / n)
        factor = 4 * math.gamma(3 / n) * math.gamma(1 / n) / (n * n * math.gamma(1 + 4 / n))
        return AreaMoments(area, np.zeros(2), factor * a * b**3, factor * a**3 * b, 0.0)

    def rim_speed(self, s):
        """|dr/ds| (m per rad) from r = (b sin s, −a cos s)/N(s), N = (|sin s|ⁿ + |cos s|ⁿ)^(1/n)."""
        s = np.asarray(s, dtype=float)
        n, sin, cos = self.n, np.sin(s), np.cos(s)
        norm = (np.abs(sin) ** n + np.abs(cos) ** n) ** (1.0 / n)
        dnorm = (np.sign(sin) * np.abs(sin) ** (n - 1) * cos
                 - np.sign(cos) * np.abs(cos) ** (n - 1) * sin) / norm ** (n - 1)
        dx = self.b * (cos * norm - sin * dnorm) / norm ** 2
        dy = self.a * (sin * norm + cos * dnorm) / norm ** 2
        return np.hypot(dx, dy)

    def log_curvature(self, s):
        """log κ(s), without underflow where the curvature vanishes: for large n,
        κ ~ |cos s|^(n−2) near the side vertices underflows to 0 within about 1e-3 rad of them
        (n = 100), while the ratio of two rims' curvatures stays finite."""
        s = np.asarray(s, dtype=float)
        n, a, b = self.n, self.a, self.b
        with np.errstate(divide='ignore'):
            log_sin, log_cos = np.log(np.abs(np.sin(s))), np.log(np.abs(np.cos(s)))
        log_norm = np.logaddexp(n * log_sin, n * log_cos) / n
        log_gx, log_gy = (n - 1) * log_sin - math.log(b), (n - 1) * log_cos - math.log(a)
        log_hx = math.log(n - 1) + (n - 2) * log_sin - 2 * math.log(b)
        log_hy = math.log(n - 1) + (n - 2) * log_cos - 2 * math.log(a)
        return (log_norm + np.logaddexp(2 * log_gy + log_hx, 2 * log_gx + log_hy)
                - 1.5 * np.logaddexp(2 * log_gx, 2 * log_gy))

    def phase_map(self):
        """Vertex maps for a non-even n, a corner map for large n (module phase_map)."""
        return superellipse_phase_map(self.n, self.b / self.a)

    def vertex(self, axis):
        """For n > 2 the four vertices are flat: h(d + t d⊥) = e + |r t|^q e^(1−q)/q + O(|t|^2q),
        e the extent (a or b) and r the other semi-axis (from the closed-form h)."""
        if self.n == 2.0 or axis not in VERTEX_AXES:
            return super().vertex(axis)
        direction = np.array(VERTEX_AXES[axis])
        extent, other = (self.b, self.a) if axis == '+x' else (self.a, self.b)
        return Vertex(axis, direction, extent * direction, extent, math.inf, self.q,
                      other**self.q * extent ** (1.0 - self.q) / self.q)
