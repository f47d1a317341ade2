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

The solid hull is computed in :mod:`twodisk_ros.physics.hull`; docs/physics.md#mass-models.
"""

from dataclasses import dataclass, fields
from functools import lru_cache
import math

import numpy as np

from .hull import unit_hull_moments

__all__ = ['MODELS', 'MassProperties', 'clear_hull_cache', 'custom', 'laminae', 'mass_properties',
           'solid_hull']

#: Model names accepted by :func:`mass_properties`.
MODELS = ('laminae', 'solid', 'custom')

# Relative slack of the triangle inequalities of custom moments (a flat plate is on the edge).
_TRIANGLE_SLACK = 1e-12


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


@lru_cache(maxsize=4096)
def _unit_hull(d, rtol):
    """:func:`~twodisk_ros.physics.hull.unit_hull_moments` remembered per (Δ/a, rtol): the
    quadrature depends on Δ/a only, so a sweep over b/a pays it once per Δ/a (arrays
    read-only, results identical to a fresh call)."""
    volume, first, second, error = unit_hull_moments(d, rtol)
    first.setflags(write=False)
    second.setflags(write=False)
    return volume, first, second, error


def clear_hull_cache():
    """Forget the quadratures :func:`solid_hull` remembers (to time a first call)."""
    _unit_hull.cache_clear()


def solid_hull(a, b, delta, mass, *, rtol=1e-9):
    """Uniform solid convex hull of the two disks (the real oloid toy).

    Parameters
    ----------
    a, b, delta : float
        The disks' geometry (m), as in :func:`laminae`.
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
    1 ms for the Oloid and 5 ms for ``delta / a = 1e-3`` at ``rtol = 1e-9``; the quadrature of
    each (``delta / a``, ``rtol``) is remembered (4096 of them), so the same ratio costs only
    the scaling after its first call.
    """
    a, b, d = _geometry(a, b, delta)
    m = _positive('mass', mass, 'kg')
    tol = _rtol(rtol)
    vol, first, second, err = _unit_hull(d / a, tol)
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
