"""A user's outline as a lamina: a smooth, strictly convex, symmetric fit of its points.

The fitted lamina is a :class:`~twodisk_ros.physics.laminae.support.SupportLamina` whose support
function is a cosine series h(φ) = Σ_{k=0..M} c_k cos kφ of the outward normal's angle φ
(measured from −y): even in φ, so symmetric about the common axis y, exactly. The fit
(docs/physics.md#laminae-other-than-ellipses), for points in order around the
outline (either direction), x along the lamina's other axis and y along the common axis:

1. checks: an (N, 2) array of finite numbers, N ≥ MIN_POINTS distinct consecutive points;
2. moves x so that the common axis (the vertical line through the polygon's area centroid)
   is x = 0 (``axis_offset`` keeps the shift; y is kept as given);
3. the points must go once around that centre with the polar angle strictly monotonic
   (else self-intersecting, unordered or not convex), lie within ``tolerance`` of their convex
   hull (else not convex: a dent) and their mirror images within ``tolerance`` of it (else
   not symmetric);
4. fits the points and their mirror images by least squares of their distances to the curve:
   for a point d whose foot on the curve has normal angle φ, the signed distance is
   h(φ) − d·n(φ), linear in the c_k; the feet are found by Newton on h′(φ) = d·t(φ), and the
   two steps alternate (Gauss–Newton with the feet projected out) until the feet settle;
5. tries M on a ladder and keeps the smallest M whose largest distance is within twice the
   best, among fits with radius of curvature h + h″ > 0 everywhere;
6. refuses a fit whose largest distance exceeds ``tolerance`` (noisy points) or whose radius
   of curvature leaves [RADIUS_RANGE[0], RADIUS_RANGE[1]] × size (a corner or a flat piece),
   saying where.

``tolerance`` is relative to the size (largest distance of a point from the origin after
step 2). Each refusal is a one-line ValueError.
"""

import math
from pathlib import Path

import numpy as np

from .shapes import normal_of_angle
from .support import SupportLamina

__all__ = ['MIN_POINTS', 'MAX_POINTS', 'RADIUS_RANGE', 'Outline', 'read_outline']

#: Fewest distinct points accepted (a cosine series with a few terms needs more data).
MIN_POINTS = 8
#: Most points accepted (memory: the hull distance checks hold N × hull-size arrays).
MAX_POINTS = 20000
#: Allowed radius of curvature of the fit, relative to the size: below, a corner; above, a
#: piece too flat for rolling (its contact point would jump).
RADIUS_RANGE = (1e-3, 1e3)
#: Harmonic counts tried by the fit.
LADDER = (2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128)
_FOOT_ITERATIONS = 40


def _where(p):
    return f'({p[0]:.6g}, {p[1]:.6g})'


class Outline(SupportLamina):
    """Lamina with support function h(φ) = Σ c_k cos kφ (m); see the module docstring.

    Parameters
    ----------
    coefficients : array_like, shape (M + 1,)
        c_0 … c_M (m), finite, with h + h″ > 0 everywhere (strictly convex).

    Attributes (set by :meth:`from_points`, else None/0): ``fit_error`` (m, largest distance
    of the given points to the curve), ``axis_offset`` (m, x of the common axis in the
    given coordinates), ``point_count``.
    """

    def __init__(self, coefficients):
        c = np.asarray(coefficients, dtype=float)
        if c.ndim != 1 or c.size < 1 or not np.all(np.isfinite(c)):
            raise ValueError('coefficients must be a non-empty 1-D array of finite numbers '
                             f'(metres), got shape {c.shape}')
        self.coefficients = c
        self.k = np.arange(c.size, dtype=float)
        grid = np.linspace(0.0, np.pi, 16 * c.size + 257)
        rho = self.radius_of_curvature(grid)
        scale = float(np.max(np.abs(c)))
        if not (scale > 0 and float(np.min(rho)) > 1e-12 * scale):
            j = int(np.argmin(rho))
            raise ValueError('coefficients must give h + h\'\' > 0 everywhere (a strictly '
                             f'convex outline), got {float(rho[j]):.3g} m at normal angle '
                             f'{grid[j]:.4f} rad')
        self.fit_error = None
        self.axis_offset = 0.0
        self.point_count = 0

    def __repr__(self):
        return f'Outline({self.coefficients.size - 1} harmonics, size={self.size:.6g} m)'

    def support_jet(self, phi):
        phi = np.asarray(phi, dtype=float)
        kphi = phi[..., None] * self.k
        cos, sin = np.cos(kphi), np.sin(kphi)
        c = self.coefficients
        return cos @ c, -(sin @ (self.k * c)), -(cos @ (self.k**2 * c))

    # -- the fit -----------------------------------------------------------------------------
    @classmethod
    def from_points(cls, points, tolerance=1e-3):
        """Fit a smooth, strictly convex, symmetric outline to ordered points (m).

        ``tolerance``: largest allowed distance of a point to the fit, to the convex hull and
        of a mirrored point to the outline, relative to the size (default 1e-3).
        Raises ValueError (one line) for points that cannot be fitted.
        """
        if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) \
                or not 1e-12 <= tolerance <= 0.1:
            raise ValueError('tolerance must be a number with 1e-12 <= tolerance <= 0.1 '
                             f'(relative to the size), got {tolerance!r}')
        p, offset = _checked_points(points)
        size = float(np.max(np.hypot(p[:, 0], p[:, 1])))
        tol = tolerance * size
        _check_shape(p, tol)
        data = np.concatenate([p, p * [-1.0, 1.0]])
        ahead, behind = np.roll(p, -1, axis=0), np.roll(p, 1, axis=0)
        chord = ahead - behind                      # counterclockwise: outward = chord turned −90°
        phi0 = np.arctan2(chord[:, 1], chord[:, 0])
        start = np.concatenate([phi0, -phi0])
        fits, loose, stalled, lowest = [], None, 0, np.inf
        for m in LADDER:
            if m + 1 > p.shape[0] // 2:
                break
            fit = _fit(data, start, m, size)
            if fit[4] > 0:
                fits.append(fit)
            elif loose is None or fit[1] < loose[1]:
                loose = fit
            if fit[4] > 0 and fit[1] <= 1e-13 * size:
                break
            stalled = stalled + 1 if m >= 8 and fit[1] > lowest / 2 else 0
            lowest = min(lowest, fit[1])
            if stalled >= 2:
                break                                 # the error stopped falling
        least = min((f[1] for f in fits), default=np.inf)
        if least > tol and loose is not None and (loose[1] <= tol or loose[1] < least / 2):
            j = int(np.argmin(loose[5]))
            raise ValueError(f'points are not strictly convex: the best convex fit misses them by '
                             f'{least:.3g} m (tolerance {tol:.3g} m), a closer one has '
                             'h + h\'\' <= 0 '
                             f'near {_where(loose[6][j])} (axis at x = 0): a flat piece or '
                             'a corner')
        if not fits:
            raise ValueError('points are not strictly convex: no smooth convex outline fits them '
                             '(every fit has a negative radius of curvature)')
        best = next(f for f in fits if f[1] <= 2 * least)
        outline = cls(best[0])
        distance = best[2][:p.shape[0]]
        if best[1] > tol:
            j = int(np.argmax(distance))
            raise ValueError(f'points are too noisy for a smooth convex outline: the fit misses '
                             f'point {j} at {_where(p[j] + [offset, 0])} by {distance[j]:.3g} m, '
                             f'more than the tolerance {tol:.3g} m')
        _check_radius(outline, size)
        outline.fit_error = float(np.max(distance))
        outline.axis_offset = offset
        outline.point_count = int(p.shape[0])
        return outline


def _checked_points(points):
    """Points as an (N, 2) counterclockwise array with the common axis at x = 0, and the shift."""
    try:
        p = np.array(points, dtype=float)
    except (TypeError, ValueError):
        raise ValueError('points must be an (N, 2) array of numbers (metres)') from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f'points must be an (N, 2) array of (x, y) (metres), got shape {p.shape}')
    if not np.all(np.isfinite(p)):
        j = int(np.argwhere(~np.all(np.isfinite(p), axis=1))[0, 0])
        raise ValueError(f'points must be finite, point {j} is {p[j].tolist()}')
    if p.shape[0] > 1 and np.array_equal(p[0], p[-1]):
        p = p[:-1]
    if p.shape[0] < MIN_POINTS or p.shape[0] > MAX_POINTS:
        raise ValueError(f'an outline needs {MIN_POINTS} to {MAX_POINTS} distinct points in '
                         f'order around it, got {p.shape[0]}')
    repeated = np.all(p == np.roll(p, 1, axis=0), axis=1)
    if np.any(repeated):
        j = int(np.argmax(repeated))
        raise ValueError(f'point {j} at {_where(p[j])} repeats the one before it: give '
                         'distinct points in order around the outline')
    # polygon area centroid (shoelace): on the symmetry axis for a symmetric outline
    x, y = p[:, 0], p[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    area = cross.sum() / 2
    if not abs(area) > 0:
        raise ValueError('points enclose no area: give the outline of a lamina')
    cx = float(np.sum((x + np.roll(x, -1)) * cross) / (6 * area))
    cy = float(np.sum((y + np.roll(y, -1)) * cross) / (6 * area))
    # go once around the centroid, the polar angle strictly monotonic
    angle = np.arctan2(y - cy, x - cx)
    step = np.angle(np.exp(1j * (np.roll(angle, -1) - angle)))
    sense = 1.0 if area > 0 else -1.0
    if np.any(step * sense <= 0):
        j = int(np.argmax(step * sense <= 0))
        raise ValueError(f'points do not go once around the outline: at point {j + 1} '
                         f'{_where(p[(j + 1) % len(p)])} they turn back around the centre '
                         f'{_where((cx, cy))} (self-intersecting, out of order or not convex)')
    turns = round(float(step.sum()) / (2 * math.pi))
    if abs(turns) != 1:
        raise ValueError(f'points go {abs(turns)} times around the outline: it is '
                         'self-intersecting (give one turn, in order)')
    if sense < 0:
        p = p[::-1].copy()
    p[:, 0] -= cx
    return p, cx


def _hull_distance(hull, q):
    """Signed distance-like measure of points q to the hull boundary (> 0 outside, m)."""
    return np.max(q @ hull.equations[:, :2].T + hull.equations[:, 2], axis=1)


def _check_shape(p, tol):
    from scipy.spatial import ConvexHull, QhullError
    try:
        hull = ConvexHull(p)
    except QhullError:
        raise ValueError('points must enclose an area (they are collinear)') from None
    depth = -_hull_distance(hull, p)
    j = int(np.argmax(depth))
    if depth[j] > tol:
        raise ValueError(f'points are not convex: point {j} at {_where(p[j])} (axis at x = 0) '
                         f'lies {depth[j]:.3g} m inside their convex hull, more than the '
                         f'tolerance {tol:.3g} m')
    mirror = p * [-1.0, 1.0]
    gap = np.abs(_hull_distance(hull, mirror))
    j = int(np.argmax(gap))
    if gap[j] > tol:
        raise ValueError(f'points are not symmetric about the common axis: the mirror image of '
                         f'point {j} at {_where(p[j])} (axis at x = 0) is {gap[j]:.3g} m from the '
                         f'outline, more than the tolerance {tol:.3g} m')


def _feet(coefficients, data, phi):
    """Newton on h′(φ) − d·t(φ) = 0: the normal angles of the feet of the data points."""
    k = np.arange(coefficients.size, dtype=float)
    for _ in range(3):
        kphi = phi[:, None] * k
        cos, sin = np.cos(kphi), np.sin(kphi)
        h1 = -(sin @ (k * coefficients))
        h2 = -(cos @ (k * k * coefficients))
        t = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        n = normal_of_angle(phi)
        g = h1 - np.sum(data * t, axis=1)
        dg = h2 + np.sum(data * n, axis=1)
        step = np.where(dg > 0, g / np.where(dg > 0, dg, 1.0), 0.0)
        phi = phi - np.clip(step, -0.2, 0.2)
    return phi


def _fit(data, phi, m, size):
    """The M = m fit: (coefficients, largest distance, distances, feet' angles, smallest
    radius of curvature h + h″ (m), its grid, the points of that grid)."""
    k = np.arange(m + 1, dtype=float)
    for _ in range(_FOOT_ITERATIONS):
        basis = np.cos(phi[:, None] * k)
        target = np.sum(data * normal_of_angle(phi), axis=1)
        coefficients, *_ = np.linalg.lstsq(basis, target, rcond=None)
        moved = phi
        phi = _feet(coefficients, data, phi)
        if np.max(np.abs(phi - moved)) <= 1e-11:
            break
    grid = np.linspace(0.0, np.pi, 16 * (m + 1) + 257)
    cos = np.cos(grid[:, None] * k)
    rho = cos @ (coefficients * (1 - k * k))
    distance = np.abs(np.cos(phi[:, None] * k) @ coefficients
                      - np.sum(data * normal_of_angle(phi), axis=1))
    smallest = float(np.min(rho))
    points = None
    if smallest <= 1e-12 * size:
        h, h1 = cos @ coefficients, -(np.sin(grid[:, None] * k) @ (k * coefficients))
        n = normal_of_angle(grid)
        points = h[:, None] * n + h1[:, None] * np.stack([-n[:, 1], n[:, 0]], axis=-1)
        smallest = -1.0
    return coefficients, float(np.max(distance)), distance, phi, smallest, rho, points


def _check_radius(outline, size):
    grid = np.linspace(0.0, np.pi, 16 * outline.coefficients.size + 1025)
    rho = outline.radius_of_curvature(grid)
    low, high = RADIUS_RANGE
    j = int(np.argmin(rho))
    if rho[j] < low * size:
        raise ValueError(f'the outline has a corner near {_where(outline.point(grid[j]))} '
                         f'(axis at x = 0): radius of curvature {rho[j]:.3g} m below '
                         f'{low:g} of its size {size:.3g} m; round it off')
    j = int(np.argmax(rho))
    if rho[j] > high * size:
        raise ValueError(f'the outline has a flat piece near {_where(outline.point(grid[j]))} '
                         f'(axis at x = 0): radius of curvature {rho[j]:.3g} m above '
                         f'{high:g} times its size {size:.3g} m; it must be strictly convex')


def read_outline(path):
    """Points (N, 2) (m) from a CSV file (x, y per line; '#' comments, one header line
    allowed) or a YAML file (a list of [x, y] pairs, or a mapping with key ``points``).

    Raises ValueError with one line naming the file for anything unreadable.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f'outline file {path}: cannot be read ({error.__class__.__name__}: '
                         f'{error.strerror if isinstance(error, OSError) else "not UTF-8"})') \
            from None
    if path.suffix.lower() in ('.yaml', '.yml'):
        import yaml
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as error:
            line = getattr(getattr(error, 'problem_mark', None), 'line', None)
            where = f' at line {line + 1}' if line is not None else ''
            raise ValueError(f'outline file {path}: not valid YAML{where}') from None
        if isinstance(data, dict):
            data = data.get('points')
        rows = data if isinstance(data, list) else None
        if rows is None:
            raise ValueError(f'outline file {path}: expected a list of [x, y] pairs or a '
                             'mapping with key "points"')
        numbers = []
        for i, row in enumerate(rows):
            ok = isinstance(row, (list, tuple)) and len(row) == 2 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in row)
            if not ok:
                raise ValueError(f'outline file {path}: point {i} must be [x, y] numbers, '
                                 f'got {str(row)[:40]}')
            numbers.append([float(v) for v in row])
        return np.array(numbers, dtype=float).reshape(-1, 2)
    numbers = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.split('#', 1)[0].strip()
        if not line:
            continue
        fields = [f.strip() for f in line.replace(';', ',').split(',')] if ',' in line or ';' \
            in line else line.split()
        try:
            if len(fields) != 2:
                raise ValueError
            numbers.append([float(fields[0]), float(fields[1])])
        except ValueError:
            if not numbers and all(not _is_number(f) for f in fields):
                continue                                  # a header line
            raise ValueError(f'outline file {path}: line {number} must be two numbers x, y, '
                             f'got {line[:40]!r}') from None
    return np.array(numbers, dtype=float).reshape(-1, 2)


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True
