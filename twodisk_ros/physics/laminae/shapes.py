"""A planar lamina in its own plane: one protocol, and the ellipse, superellipse and egg.

The foundation of bodies of any two congruent symmetric laminae: :mod:`general_body` solves
their contact geometry from it and :mod:`lamina_body` makes them rolling bodies
(docs/physics.md#laminae-other-than-ellipses).

Lamina coordinates (metres), those of disk 1 in the body frame seen from its centre C1:
``x`` along e1 (the disk's other axis, semi-extent ``b``), ``y`` along e2 (the common axis,
semi-extent ``a``). Every lamina is convex and symmetric about the common axis (x → −x); it
need not be symmetric about the x axis (the egg is not).

The boundary is a closed curve r(s) of a 2π-periodic parameter ``s`` (rad), in the sense of
the package's θ: s = 0 is the far tip on −y (where θ = 0 touches), s = π the tip on +y, s
increases counterclockwise (towards +x first) and s → −s is the mirror x → −x. What s is
depends on the shape: the eccentric anomaly for the ellipse (as in body.py), its radial
projection for the superellipse, the outward normal's angle for the laminae defined by their
support function (egg, fitted outline). Everything is vectorised: ``s`` of any shape gives
results of shape ``s.shape`` (scalars) or ``s.shape + (2,)`` (vectors); a direction array of
shape ``(..., 2)`` gives ``(...)`` heights and ``(..., 2)`` points.

Protocol (:class:`Lamina`): ``point(s)``, ``tangent(s)`` (unit, s increasing), ``normal(s)``
(unit, outward), ``curvature(s)`` (1/m, ≥ 0), ``support(direction)`` (the support function
h(n) = max over the boundary of r·n, the point attaining it and its parameter), ``moments``
(area, centroid, second moments of area about the lamina's origin), ``extents``, ``size`` and
``vertex(axis)`` (extent, radius of curvature and order of contact where the normal is ±y, +x).
"""

import abc
from dataclasses import dataclass
import math

import numpy as np

__all__ = ['AreaMoments', 'Egg', 'Ellipse', 'Lamina', 'LENGTH_RANGE', 'SUPERELLIPSE_EXPONENT',
           'Superellipse', 'Support', 'SupportLamina', 'VERTEX_AXES', 'Vertex', 'check_length']

#: Allowed lengths (m), as for TwoDiskBody: the forms hold up to sixth powers of lengths.
LENGTH_RANGE = (1e-30, 1e30)
#: Allowed superellipse exponents n: from the ellipse (2) to a rounded rectangle whose corner
#: radius of curvature is a few per cent of its size (about 0.05 b at n = 100, b = a).
SUPERELLIPSE_EXPONENT = (2.0, 100.0)
#: Area moments of support-function laminae: the trapezoidal rule in φ (exponentially
#: convergent) doubles its nodes until two results agree to this, relative to the largest.
MOMENT_RTOL = 2e-15
_MAX_MOMENT_NODES = 1 << 17
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


def _direction_angle(direction):
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

    def support(self, direction):
        d = np.asarray(direction, dtype=float)
        _direction_angle(d)
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
        _direction_angle(d)
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

    def vertex(self, axis):
        """For n > 2 the four vertices are flat: h(d + t d⊥) = e + |r t|^q e^(1−q)/q + O(|t|^2q),
        e the extent (a or b) and r the other semi-axis (from the closed-form h)."""
        if self.n == 2.0 or axis not in VERTEX_AXES:
            return super().vertex(axis)
        direction = np.array(VERTEX_AXES[axis])
        extent, other = (self.b, self.a) if axis == '+x' else (self.a, self.b)
        return Vertex(axis, direction, extent * direction, extent, math.inf, self.q,
                      other**self.q * extent ** (1.0 - self.q) / self.q)


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
        phi, length = _direction_angle(direction)
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
                if np.max(np.abs(new - old)) <= MOMENT_RTOL * scale or nodes >= _MAX_MOMENT_NODES:
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
