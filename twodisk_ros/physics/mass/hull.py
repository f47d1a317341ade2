"""The convex hull of the two disks: a closed ruled surface, and its volume and moments.

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

import numpy as np

__all__ = ['PAIRS', 'hull_surface_area', 'relative_change', 'unit_hull_moments']

# Quadrature settings of the solid hull: first grid (nodes in u), last grid, and the level
# below which differences between successive grids are roundoff rather than truncation.
_N_START = 64
_N_MAX = 2 ** 18
_ROUNDOFF = 1e-12
# Gauss-Legendre nodes and weights on [0, 1] along each segment P Q (exact up to degree 5;
# the integrands are of degree 3).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
_LAMBDA = 0.5 * (_GL_X + 1.0)
_LAMBDA_W = 0.5 * _GL_W
#: Index pairs of the six independent second moments, in the order of the integrand columns.
PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


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
        (order of ``PAIRS``); the integral over ``u`` in ``[0, 2 pi)`` gives the moments.
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
        for col, (i, j) in enumerate(PAIRS, start=4):
            out[:, col] += x[:, i] * x[:, j] * xn / 5.0
    return out


def _unpack(sums):
    """Split the 10 integrals into volume, first moments (3,) and second moments (3, 3)."""
    second = np.empty((3, 3))
    for col, (i, j) in enumerate(PAIRS, start=4):
        second[i, j] = second[j, i] = sums[col]
    return sums[0], sums[1:4].copy(), second


def relative_change(coarse, fine):
    """Relative change between two quadratures of the 10 integrals (volume, first moments,
    second moments in the order of ``PAIRS``), scale invariant under diagonal maps: of the
    volume, of each first moment to sqrt(vol S_ii), of each S_ij to sqrt(S_ii S_jj)."""
    v0, m0, s0 = _unpack(coarse)
    v1, m1, s1 = _unpack(fine)
    diag = np.diag(s1)
    errors = [abs(v1 - v0) / v1]
    errors.extend(np.abs(m1 - m0) / np.sqrt(v1 * diag))
    for i, j in PAIRS:
        errors.append(abs(s1[i, j] - s0[i, j]) / math.sqrt(diag[i] * diag[j]))
    return float(max(errors))


def unit_hull_moments(d, rtol):
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
        error = relative_change(coarse, fine)
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


def hull_surface_area(a, b, delta, n=256):
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
    a, b, d = float(a), float(b), float(delta)
    u = 2.0 * math.pi * np.arange(n) / n
    p, p_u, q, q_u = _hull_surface(u, d / a)
    scale = np.array([b, a, b])
    p, p_u, q, q_u = (scale * v for v in (p, p_u, q, q_u))
    w, w_u = q - p, q_u - p_u
    area = 0.0
    for lam, weight in zip(_LAMBDA, _LAMBDA_W):
        area += weight * np.linalg.norm(np.cross(p_u + lam * w_u, w), axis=1).sum()
    return float(area * 2.0 * math.pi / n)
