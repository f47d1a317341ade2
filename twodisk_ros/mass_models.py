"""Mass models of the rigid body made of two identical elliptical disks.

Body frame ``G e1 e2 e3`` (metres): G is the origin, the midpoint of the disk centres and the
centre of mass of every model here. Disk 1 lies in the plane ``x3 = 0`` with centre
``(0, -delta, 0)`` and boundary ``x1**2 / b**2 + (x2 + delta)**2 / a**2 = 1``; disk 2 lies in the
plane ``x1 = 0`` with centre ``(0, +delta, 0)`` and boundary
``(x2 - delta)**2 / a**2 + x3**2 / b**2 = 1``. Allowed parameters: ``a > 0``, ``b > 0`` (``b > a``
is allowed) and ``0 < delta < a``. The Oloid is ``a = b = r, delta = r / 2``, the
Two-Circle-Roller ``a = b = r, delta = r / sqrt(2)``.

Three models are offered:

``'laminae'``
    Two thin uniform elliptic laminae of mass ``M / 2`` each (closed form).
``'solid'``
    The uniform solid convex hull of the two disks (the real oloid toy), computed from the
    geometry with an exponentially convergent quadrature and a convergence check.
``'custom'``
    Principal moments given by the user, principal axes along ``e1, e2, e3``.

The solid hull
--------------
A boundary point of the hull lies on a segment ``P Q`` with ``P`` on ellipse 1, ``Q`` on
ellipse 2 and a common supporting plane through both (the rolling-contact condition of the
paper). No flat part of either disk is on the boundary: each disk plane cuts the other disk.
With the parametric angle ``t`` of ellipse 1, ``P(t) = (b sin t, -delta - a cos t, 0)``, the
contact point on ellipse 2 is, with ``D = a + 2 delta cos t``,

    ``Q(t) = (0, delta - a**2 cos t / D, +-b sqrt(D**2 - a**2 cos**2 t) / D)``,

for ``cos t > -a / (a + 2 delta)`` (the paper's range ``|theta| < theta_max``, written in ``t``).
The substitution ``t = t_max sin u`` with the sign of the square root taken as
``sign(cos u)`` turns both sheets of this ruled surface into one closed surface that is smooth
(analytic) and ``2 pi``-periodic in ``u``; the square root is evaluated in a factored form that
has no removable singularity at the turning points ``u = +-pi/2``. Volume, first and second
moments follow from the divergence theorem, ``int x_i x_j dV = 1/5 oint x_i x_j (x . n) dA``
(and ``1/3``, ``1/4`` for the volume and the first moments); the surface integrand is a
polynomial in the segment parameter (Gauss-Legendre, exact) and periodic-analytic in ``u``
(trapezoidal rule, exponential convergence). The grid is doubled until two successive results
agree to ``rtol``. The work is done for the normalised body ``a = b = 1`` and mapped by the
linear map ``diag(b, a, b)``, so the cost and the accuracy depend on ``delta / a`` only: the
analyticity strip narrows like ``sqrt(delta / a)`` (about 2 000 nodes for ``delta / a = 1e-3``).
"""

import math
from dataclasses import dataclass, fields

import numpy as np

__all__ = ['MODELS', 'MassProperties', 'custom', 'laminae', 'mass_properties', 'solid_hull']

#: Model names accepted by :func:`mass_properties`.
MODELS = ('laminae', 'solid', 'custom')

# Quadrature settings of the solid hull: first grid (nodes in u), last grid, and the level
# below which differences between successive grids are roundoff rather than truncation.
_N_START = 64
_N_MAX = 2 ** 18
_ROUNDOFF = 1e-12
# Relative slack of the triangle inequalities of custom moments (a flat plate is on the edge).
_TRIANGLE_SLACK = 1e-12
# Gauss-Legendre nodes and weights on [0, 1] along each segment P Q (exact up to degree 5;
# the integrands are of degree 3).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
_LAMBDA = 0.5 * (_GL_X + 1.0)
_LAMBDA_W = 0.5 * _GL_W
# Index pairs of the six independent second moments, in the order of the integrand columns.
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


@dataclass(frozen=True, eq=False)
class MassProperties:
    """Mass properties of the two-disk body in the body frame ``G e1 e2 e3``.

    Parameters
    ----------
    model : str
        Name of the mass model: ``'laminae'``, ``'solid'`` or ``'custom'``.
    mass : float
        Total mass (kg).
    center_of_mass : numpy.ndarray, shape (3,)
        Centre of mass (m, body frame). It is G (the origin) for every model; for ``'solid'``
        it is the computed value, zero up to roundoff.
    inertia : numpy.ndarray, shape (3, 3)
        Inertia tensor about G (kg m**2, body frame), symmetric.
    volume : float or None
        Volume of the solid (m**3) for ``'solid'``, else None.
    relative_error : float
        Estimated relative error of the quadrature (``'solid'``; 0.0 for the closed-form
        models): the largest relative change of the volume, the centre of mass and each
        second moment between the last two grids. It bounds the error of the returned values,
        which come from the finer grid.

    Notes
    -----
    The arrays are stored as read-only float copies. ``==`` compares all fields by value.
    """

    model: str
    mass: float
    center_of_mass: np.ndarray
    inertia: np.ndarray
    volume: float | None = None
    relative_error: float = 0.0

    def __post_init__(self):
        com = np.array(self.center_of_mass, dtype=float)
        inertia = np.array(self.inertia, dtype=float)
        if com.shape != (3,):
            raise ValueError(f'center_of_mass must have shape (3,), got shape {com.shape}')
        if inertia.shape != (3, 3):
            raise ValueError(f'inertia must have shape (3, 3), got shape {inertia.shape}')
        com.setflags(write=False)
        inertia.setflags(write=False)
        object.__setattr__(self, 'center_of_mass', com)
        object.__setattr__(self, 'inertia', inertia)
        object.__setattr__(self, 'mass', float(self.mass))
        object.__setattr__(self, 'relative_error', float(self.relative_error))
        if self.volume is not None:
            object.__setattr__(self, 'volume', float(self.volume))

    def __eq__(self, other):
        if not isinstance(other, MassProperties):
            return NotImplemented
        return all(
            np.array_equal(getattr(self, f.name), getattr(other, f.name)) for f in fields(self)
        )

    __hash__ = None

    @property
    def principal_moments(self):
        """Diagonal of the inertia tensor about G (kg m**2), along ``e1, e2, e3``.

        Returns
        -------
        numpy.ndarray, shape (3,)
            ``(I11, I22, I33)``. These are the principal moments: the products of inertia of
            every model vanish by the symmetries of the body.
        """
        return np.diag(self.inertia).copy()


# --------------------------------------------------------------------------- validation


def _one_line(value, limit=80):
    """Short one-line representation of ``value`` for error messages."""
    text = ' '.join(repr(value).split())
    return text if len(text) <= limit else text[:limit - 3] + '...'


def _real(name, value, what):
    """Convert a real scalar to float, or raise a one-line ValueError.

    Parameters
    ----------
    name : str
        Parameter name used in the message.
    value : object
        The value to convert.
    what : str
        What is allowed, e.g. ``'finite and > 0 kg'``.

    Returns
    -------
    float
    """
    bad = isinstance(value, (bool, np.bool_, str, bytes))
    if not bad:
        try:
            arr = np.asarray(value)
            bad = arr.shape != () or arr.dtype.kind not in 'iuf'
        except Exception:  # noqa: BLE001 - anything that is not array-like is invalid
            bad = True
    if bad:
        raise ValueError(f'{name} must be a real number, {what}, got {_one_line(value)}')
    return float(arr)


def _positive(name, value, unit):
    """Return ``value`` as a finite float > 0, or raise a one-line ValueError."""
    what = f'finite and > 0 {unit}'
    x = _real(name, value, what)
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f'{name} must be {what}, got {x!r}')
    return x


def _geometry(a, b, delta):
    """Validate the disk geometry (m) and return it as floats ``(a, b, delta)``."""
    a = _positive('a', a, 'm')
    b = _positive('b', b, 'm')
    what = f'finite with 0 < delta < a = {a!r} m'
    d = _real('delta', delta, what)
    if not (math.isfinite(d) and 0.0 < d < a):
        raise ValueError(f'delta must be {what}, got {d!r}')
    return a, b, d


def _rtol(rtol):
    """Validate the relative tolerance of the solid quadrature."""
    what = 'finite with 0 < rtol < 1'
    x = _real('rtol', rtol, what)
    if not (math.isfinite(x) and 0.0 < x < 1.0):
        raise ValueError(f'rtol must be {what}, got {x!r}')
    return x


# --------------------------------------------------------------------------- models


def laminae(a, b, delta, mass):
    """Two thin uniform elliptic laminae of mass ``mass / 2`` each.

    Parameters
    ----------
    a : float
        Semi-axis of both disks along the common axis e2 (m), ``a > 0``.
    b : float
        Other semi-axis (m): along e1 for disk 1, along e3 for disk 2, ``b > 0``.
    delta : float
        Half the distance between the disk centres (m), ``0 < delta < a``.
    mass : float
        Total mass (kg), ``> 0``.

    Returns
    -------
    MassProperties
        Centre of mass at G; inertia about G in the body frame (kg m**2):
        ``I11 = I33 = M (2 a**2 + b**2) / 8 + M delta**2``, ``I22 = M b**2 / 4``, no products.

    Raises
    ------
    ValueError
        If a parameter is not allowed (one-line message).
    """
    a, b, d = _geometry(a, b, delta)
    m = _positive('mass', mass, 'kg')
    i11 = m * (2.0 * a * a + b * b) / 8.0 + m * d * d
    i22 = m * b * b / 4.0
    return MassProperties('laminae', m, np.zeros(3), np.diag([i11, i22, i11]))


def custom(mass, principal_moments):
    """User-given principal moments of inertia about G along e1, e2, e3.

    Parameters
    ----------
    mass : float
        Total mass (kg), ``> 0``.
    principal_moments : sequence of 3 floats
        ``(I1, I2, I3)`` about G along e1, e2, e3 (kg m**2), each ``> 0``, satisfying the
        triangle inequalities ``I1 + I2 >= I3``, ``I2 + I3 >= I1``, ``I3 + I1 >= I2`` (up to a
        relative slack of 1e-12 of their sum). The body's symmetries give ``I1 = I3`` for a
        real two-disk body; this is not enforced.

    Returns
    -------
    MassProperties
        Centre of mass at G, inertia ``diag(I1, I2, I3)`` (kg m**2, body frame).

    Raises
    ------
    ValueError
        If a parameter is not allowed (one-line message).
    """
    m = _positive('mass', mass, 'kg')
    moments = _moments(principal_moments)
    return MassProperties('custom', m, np.zeros(3), np.diag(moments))


def _moments(principal_moments):
    """Validate custom principal moments (kg m**2) and return them as a float array."""
    what = 'a sequence of 3 finite numbers > 0 kg m**2 (I1, I2, I3)'
    try:
        arr = np.asarray(principal_moments)
        ok = arr.shape == (3,) and arr.dtype.kind in 'iuf'
    except Exception:  # noqa: BLE001 - anything that is not array-like is invalid
        ok = False
    if not ok:
        raise ValueError(f'principal_moments must be {what}, got {_one_line(principal_moments)}')
    moments = arr.astype(float)
    shown = '(' + ', '.join(repr(float(x)) for x in moments) + ')'
    if not (np.all(np.isfinite(moments)) and np.all(moments > 0.0)):
        raise ValueError(f'principal_moments must be {what}, got {shown}')
    slack = _TRIANGLE_SLACK * float(moments.sum())
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        if moments[i] + moments[j] < moments[k] - slack:
            raise ValueError(
                f'principal_moments must satisfy the triangle inequalities I1 + I2 >= I3, '
                f'I2 + I3 >= I1, I3 + I1 >= I2, got {shown}: '
                f'I{i + 1} + I{j + 1} = {float(moments[i] + moments[j])!r} '
                f'< I{k + 1} = {float(moments[k])!r}'
            )
    return moments


def solid_hull(a, b, delta, mass, *, rtol=1e-9):
    """Uniform solid convex hull of the two disks (the real oloid toy).

    Parameters
    ----------
    a : float
        Semi-axis of both disks along the common axis e2 (m), ``a > 0``.
    b : float
        Other semi-axis (m): along e1 for disk 1, along e3 for disk 2, ``b > 0``.
    delta : float
        Half the distance between the disk centres (m), ``0 < delta < a``.
    mass : float
        Total mass (kg), ``> 0``; the density is ``mass / volume``.
    rtol : float, optional
        Requested relative accuracy of the volume, the centre of mass and each second moment,
        ``0 < rtol < 1``. About 1e-13 is the roundoff floor.

    Returns
    -------
    MassProperties
        ``volume`` (m**3), computed centre of mass (m, body frame; zero up to roundoff by the
        symmetries), inertia about G (kg m**2, body frame) and the estimated
        ``relative_error <= rtol``.

    Raises
    ------
    ValueError
        If a parameter is not allowed (one-line message).
    RuntimeError
        If the quadrature cannot reach ``rtol`` (below the roundoff floor, or ``delta / a``
        so small, below about 1e-8, that the finest grid is not enough).

    Notes
    -----
    See the module docstring for the method. The cost depends on ``delta / a`` only: about
    1 ms for the Oloid and 5 ms for ``delta / a = 1e-3`` at ``rtol = 1e-9``.
    """
    a, b, d = _geometry(a, b, delta)
    m = _positive('mass', mass, 'kg')
    tol = _rtol(rtol)
    vol, first, second, err = _unit_hull_moments(d / a, tol)
    # Map the normalised body (a = b = 1) by diag(b, a, b); the Jacobian is a b**2.
    scale = np.array([b, a, b])
    jac = a * b * b
    vol = jac * vol
    first = jac * scale * first
    second = jac * np.outer(scale, scale) * second
    density = m / vol
    inertia = density * (np.trace(second) * np.eye(3) - second)
    return MassProperties('solid', m, first / vol, inertia, volume=vol, relative_error=err)


def mass_properties(model, a, b, delta, mass, principal_moments=None, rtol=1e-9):
    """Mass properties of the two-disk body by model name.

    Parameters
    ----------
    model : str
        ``'laminae'``, ``'solid'`` or ``'custom'``.
    a, b, delta : float
        Geometry (m), validated for every model: ``a > 0``, ``b > 0``, ``0 < delta < a``.
    mass : float
        Total mass (kg), ``> 0``.
    principal_moments : sequence of 3 floats, optional
        ``(I1, I2, I3)`` (kg m**2) for ``'custom'`` (required there); must be None for the
        other models.
    rtol : float, optional
        Relative accuracy of ``'solid'``; validated and used only for ``'solid'``.

    Returns
    -------
    MassProperties

    Raises
    ------
    ValueError
        If a parameter is not allowed (one-line message).
    RuntimeError
        If ``'solid'`` cannot reach ``rtol``.
    """
    if not isinstance(model, str) or model not in MODELS:
        allowed = ', '.join(repr(name) for name in MODELS)
        raise ValueError(f'model must be one of {allowed}, got {_one_line(model)}')
    a, b, d = _geometry(a, b, delta)
    if model == 'custom':
        if principal_moments is None:
            raise ValueError(
                "principal_moments must be given (I1, I2, I3) in kg m**2 for model 'custom', "
                'got None'
            )
        return custom(mass, principal_moments)
    if principal_moments is not None:
        raise ValueError(
            f"principal_moments must be None unless model is 'custom', got "
            f'{_one_line(principal_moments)} for model {model!r}'
        )
    if model == 'laminae':
        return laminae(a, b, d, mass)
    return solid_hull(a, b, d, mass, rtol=rtol)


# --------------------------------------------------------------------------- the solid hull


def _hull_surface(u, d):
    """Points and u-derivatives of the generators of the normalised hull (a = b = 1).

    Parameters
    ----------
    u : numpy.ndarray, shape (n,)
        Cycle parameter (rad); ``t = t_max sin u`` is the parametric angle on ellipse 1 and
        the sheet (sign of ``x3`` of Q) is ``sign(cos u)``.
    d : float
        ``delta / a``, in (0, 1).

    Returns
    -------
    p, p_u, q, q_u : numpy.ndarray, shape (n, 3)
        End points ``P`` (on disk 1) and ``Q`` (on disk 2) of the segment for each ``u`` and
        their derivatives with respect to ``u`` (normalised body frame).
    """
    t_max = math.acos(-1.0 / (1.0 + 2.0 * d))
    sin_u, cos_u = np.sin(u), np.cos(u)
    t = t_max * sin_u
    cos_t, sin_t = np.cos(t), np.sin(t)
    # D**2 - cos**2 t = f1 * g with f1 = 1 + (2d - 1) cos t > 0 and
    # g = (1 + 2d) (cos t - cos t_max) = 2 (1 + 2d) sin(k A+) sin(k A-), k = t_max / 2,
    # A+- = 1 +- sin u, A+ A- = cos**2 u. So sign(cos u) sqrt(f1 g) = cos u * r with
    # r = sqrt(2 (1 + 2d) f1 S(A+) S(A-)) > 0, S(A) = sin(k A) / A: no 0/0 anywhere.
    big = 1.0 + np.abs(sin_u)
    small = cos_u * cos_u / big
    a_plus = np.where(sin_u >= 0.0, big, small)
    a_minus = np.where(sin_u >= 0.0, small, big)
    k = 0.5 * t_max
    s_plus = k * np.sinc(k * a_plus / math.pi)
    s_minus = k * np.sinc(k * a_minus / math.pi)
    f1 = 1.0 + (2.0 * d - 1.0) * cos_t
    r = np.sqrt(2.0 * (1.0 + 2.0 * d) * f1 * s_plus * s_minus)
    dd = 1.0 + 2.0 * d * cos_t
    zero = np.zeros_like(u)
    dt_du = t_max * cos_u
    p = np.stack([sin_t, -d - cos_t, zero], axis=-1)
    p_u = np.stack([dt_du * cos_t, dt_du * sin_t, zero], axis=-1)
    q = np.stack([zero, d - cos_t / dd, cos_u * r / dd], axis=-1)
    # dQ2/dt = sin t / D**2; dQ3/du follows from the ellipse-2 angle psi with
    # d psi / du = -t_max sin t / (D r) (regular because r > 0).
    q_u = np.stack([zero, dt_du * sin_t / dd ** 2, t_max * sin_t * cos_t / (dd ** 2 * r)], axis=-1)
    return p, p_u, q, q_u


def _hull_integrand(u, d):
    """Surface integrands of the normalised hull, integrated exactly along each segment.

    Parameters
    ----------
    u : numpy.ndarray, shape (n,)
        Cycle parameter (rad).
    d : float
        ``delta / a``.

    Returns
    -------
    numpy.ndarray, shape (n, 10)
        Per unit ``u``: volume, the three first moments and the six second moments
        (order of ``_PAIRS``); the integral over ``u`` in ``[0, 2 pi)`` gives the moments.
    """
    p, p_u, q, q_u = _hull_surface(u, d)
    w, w_u = q - p, q_u - p_u
    out = np.zeros((u.size, 10))
    for lam, weight in zip(_LAMBDA, _LAMBDA_W):
        x = p + lam * w
        normal = np.cross(p_u + lam * w_u, w)  # x_u cross x_lambda, outward (checked: V > 0)
        xn = weight * np.einsum('ij,ij->i', x, normal)
        out[:, 0] += xn / 3.0
        out[:, 1:4] += x * (xn / 4.0)[:, None]
        for col, (i, j) in enumerate(_PAIRS, start=4):
            out[:, col] += x[:, i] * x[:, j] * xn / 5.0
    return out


def _unpack(sums):
    """Split the 10 integrals into volume, first moments (3,) and second moments (3, 3)."""
    second = np.empty((3, 3))
    for col, (i, j) in enumerate(_PAIRS, start=4):
        second[i, j] = second[j, i] = sums[col]
    return sums[0], sums[1:4].copy(), second


def _difference(coarse, fine):
    """Relative change between two quadratures (scale invariant under diagonal maps)."""
    v0, m0, s0 = _unpack(coarse)
    v1, m1, s1 = _unpack(fine)
    diag = np.diag(s1)
    errors = [abs(v1 - v0) / v1]
    errors.extend(np.abs(m1 - m0) / np.sqrt(v1 * diag))
    for i, j in _PAIRS:
        errors.append(abs(s1[i, j] - s0[i, j]) / math.sqrt(diag[i] * diag[j]))
    return float(max(errors))


def _unit_hull_moments(d, rtol):
    """Volume and moments of the normalised hull (a = b = 1, delta = d) to ``rtol``.

    Trapezoidal rule in the periodic parameter u, the grid doubled (old nodes reused) until
    two successive results differ by at most ``rtol``.

    Returns
    -------
    volume : float
    first : numpy.ndarray, shape (3,)
        ``int x dV``.
    second : numpy.ndarray, shape (3, 3)
        ``int x x^T dV``.
    error : float
        Relative change between the last two grids.
    """
    n = _N_START
    total = _hull_integrand(2.0 * math.pi * np.arange(n) / n, d).sum(axis=0)
    coarse = 2.0 * math.pi / n * total
    previous = math.inf
    while True:
        midpoints = 2.0 * math.pi * (np.arange(n) + 0.5) / n
        total = total + _hull_integrand(midpoints, d).sum(axis=0)
        n *= 2
        fine = 2.0 * math.pi / n * total
        if not fine[0] > 0.0:
            raise RuntimeError(f'solid hull quadrature failed for delta/a = {d!r}: volume '
                               f'{fine[0]!r} is not positive')
        error = _difference(coarse, fine)
        if error <= rtol:
            volume, first, second = _unpack(fine)
            return volume, first, second, error
        if n >= _N_MAX or (error < _ROUNDOFF and previous < _ROUNDOFF):
            raise RuntimeError(
                f'solid hull quadrature cannot reach rtol = {rtol!r} for delta/a = {d!r}: '
                f'relative change {error:.3g} with {n} nodes (roundoff floor about 1e-13)'
            )
        previous = error
        coarse = fine


def _hull_surface_area(a, b, delta, n=256):
    """Surface area of the hull (m**2) with ``n`` nodes in u (a check of the ruled surface).

    Parameters
    ----------
    a, b, delta : float
        Geometry (m).
    n : int
        Number of trapezoidal nodes in the cycle parameter u.

    Returns
    -------
    float
        Area of the ruled surface; ``4 pi r**2`` for the Oloid.
    """
    a, b, d = _geometry(a, b, delta)
    u = 2.0 * math.pi * np.arange(n) / n
    p, p_u, q, q_u = _hull_surface(u, d / a)
    scale = np.array([b, a, b])
    p, p_u, q, q_u = (scale * v for v in (p, p_u, q, q_u))
    w, w_u = q - p, q_u - p_u
    area = 0.0
    for lam, weight in zip(_LAMBDA, _LAMBDA_W):
        area += weight * np.linalg.norm(np.cross(p_u + lam * w_u, w), axis=1).sum()
    return float(area * 2.0 * math.pi / n)
