"""Mass models of the rigid body made of two congruent laminae (ellipses or any shape).

:func:`mass_properties_of` takes any rolling body (its ``lamina``, ``delta``, ``arrangement``);
:func:`mass_properties` and the functions below it are the closed-form path of two ellipses,
from a, b and Δ; :func:`mass_properties_of` takes the general path for every lamina, the
ellipse too (there within 1.6e-15 of the closed forms, tests/test_hull_general.py).

Ellipses. Body frame ``G e1 e2 e3`` (metres): G is the origin, the midpoint of the disk
centres and the centre of mass of every model here. Disk 1 lies in the plane ``x3 = 0`` with centre
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

The solid hull is computed in :mod:`twodisk_ros.physics.mass.hull`; docs/physics.md#mass-models.

Any lamina (bodies/contact_solver.py's frame): disk 1's lamina point (x, y) at (x, y − Δ, 0) from O,
the midpoint of the centres, disk 2's at (0, Δ + σ y, x); G, the body-frame origin, is the
laminae's centroid (1 + σ) ȳ/2 e2 (ȳ the lamina's centroid). ``laminae`` takes the lamina's
area moments (centre of mass G exactly); ``solid`` the convex hull of the two laminae from
:mod:`twodisk_ros.physics.mass.hull_laminae`, whose centre of mass is off G along e2 for an
asymmetric lamina (the egg) in the parallel arrangement. :func:`centred_on_mass` moves such
a body's origin to that centre of mass (LaminaBody.about), as the dynamics needs.
"""

import dataclasses
from functools import lru_cache
import math
import weakref

import numpy as np

from ..bodies.contact_solver import ARRANGEMENTS
from ..bodies.protocol import check_rolling_body
from .hull import unit_hull_moments
from .hull_laminae import general_hull_moments
from ..laminae.shapes import Lamina
from .record import MassProperties, check_rtol, one_line, positive, real_number

__all__ = ['MODELS', 'MassProperties', 'centred_on_mass', 'clear_hull_cache', 'custom',
           'laminae', 'laminae_of', 'mass_properties', 'mass_properties_of', 'solid_hull',
           'solid_of']

#: Model names accepted by :func:`mass_properties`.
MODELS = ('laminae', 'solid', 'custom')

# Relative slack of the triangle inequalities of custom moments (a flat plate is on the edge).
_TRIANGLE_SLACK = 1e-12


def _geometry(a, b, delta):
    """Validate the disk geometry (m) and return it as floats ``(a, b, delta)``."""
    a = positive('a', a, 'm')
    b = positive('b', b, 'm')
    what = f'finite with 0 < delta < a = {a!r} m'
    d = real_number('delta', delta, what)
    if not (math.isfinite(d) and 0.0 < d < a):
        raise ValueError(f'delta must be {what}, got {d!r}')
    return a, b, d


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
    m = positive('mass', mass, 'kg')
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
    m = positive('mass', mass, 'kg')
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
        raise ValueError(f'principal_moments must be {what}, got {one_line(principal_moments)}')
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
    """:func:`~twodisk_ros.physics.mass.hull.unit_hull_moments` remembered per (Δ/a, rtol): the
    quadrature depends on Δ/a only, so a sweep over b/a pays it once per Δ/a (arrays
    read-only, results identical to a fresh call)."""
    volume, first, second, error = unit_hull_moments(d, rtol)
    first.setflags(write=False)
    second.setflags(write=False)
    return volume, first, second, error


def clear_hull_cache():
    """Forget the quadratures :func:`solid_hull` and :func:`solid_of` remember (to time a
    first call)."""
    _unit_hull.cache_clear()
    _GENERAL_HULLS.clear()


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
    m = positive('mass', mass, 'kg')
    tol = check_rtol(rtol)
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
    _check_model(model)
    a, b, d = _geometry(a, b, delta)
    return _by_model(model, mass, principal_moments, lambda: laminae(a, b, d, mass),
                     lambda: solid_hull(a, b, d, mass, rtol=rtol))


def _check_model(model):
    if not isinstance(model, str) or model not in MODELS:
        allowed = ', '.join(repr(name) for name in MODELS)
        raise ValueError(f'model must be one of {allowed}, got {one_line(model)}')


def _by_model(model, mass, principal_moments, laminae_model, solid_model):
    """``model``'s MassProperties once ``principal_moments`` fits it (given for 'custom'
    only): :func:`custom`, or the call of ``laminae_model`` or ``solid_model``."""
    if model == 'custom':
        if principal_moments is None:
            raise ValueError("principal_moments must be given (I1, I2, I3) in kg m**2 for "
                             "model 'custom', got None")
        return custom(mass, principal_moments)
    if principal_moments is not None:
        raise ValueError(f"principal_moments must be None unless model is 'custom', got "
                         f'{one_line(principal_moments)} for model {model!r}')
    return laminae_model() if model == 'laminae' else solid_model()


# --------------------------------------------------------------------------- any lamina

# solid_of's quadratures per lamina object: {(delta, arrangement, rtol): moments}
_GENERAL_HULLS = weakref.WeakKeyDictionary()


def _shape(lamina, delta, arrangement):
    """Validate (lamina, delta, arrangement) of any body; return them with σ and G's y (m)."""
    if not isinstance(lamina, Lamina):
        raise ValueError(f'lamina must be a Lamina (Ellipse, Superellipse, Egg, Outline), got '
                         f'{type(lamina).__name__}')
    if arrangement not in ARRANGEMENTS:
        raise ValueError(f'arrangement must be one of {sorted(ARRANGEMENTS)}, got '
                         f'{one_line(arrangement)}')
    _, y_min, y_max = lamina.extents
    limit = 0.5 * (y_max - y_min)
    what = f'finite with 0 < delta < {limit:.6g} m (half the lamina\'s length along e2)'
    d = real_number('delta', delta, what)
    if not (math.isfinite(d) and 0.0 < d < limit):
        raise ValueError(f'delta must be {what}, got {d!r}')
    sigma = ARRANGEMENTS[arrangement]
    return d, sigma, 0.5 * (1.0 + sigma) * float(lamina.moments.centroid[1])


def laminae_of(lamina, delta, arrangement, mass):
    """Two thin uniform plates of mass ``mass / 2`` of any lamina, inertia about G.

    Parameters
    ----------
    lamina : Lamina
        The plates' shape (laminae/shapes.py), from its area moments (area A, centroid ȳ, ∫x², ∫y²).
    delta : float
        Half the distance between the centres (m), 0 < Δ < (y_max − y_min)/2.
    arrangement : str
        'parallel' or 'swapped' (σ = ±1, bodies/contact_solver.py).
    mass : float
        Total mass (kg), > 0.

    Returns
    -------
    MassProperties
        Centre of mass G (zero: G is the laminae's centroid); with k = M/(2A), the second
        moments about O are ∫x1² = ∫x3² = k ∫x² dA, ∫x2² = k (2 ∫y² dA + 2Δ² A
        + 2(σ − 1) Δ A ȳ), moved to G by −M g², g = (1 + σ) ȳ/2; I = tr(S) 1 − S.
    """
    d, sigma, g = _shape(lamina, delta, arrangement)
    m = positive('mass', mass, 'kg')
    moments = lamina.moments
    area, y_bar = moments.area, float(moments.centroid[1])
    k = 0.5 * m / area
    # plate 1 at (x, y − Δ, 0), plate 2 at (0, Δ + σ y, x); ∫x dA = 0 by symmetry
    s22 = k * (moments.second_yy - 2 * d * area * y_bar + d * d * area
               + moments.second_yy + 2 * sigma * d * area * y_bar + d * d * area) - m * g * g
    s11 = s33 = k * moments.second_xx
    s12, s23 = k * moments.second_xy, sigma * k * moments.second_xy
    second = np.array([[s11, s12, 0.0], [s12, s22, s23], [0.0, s23, s33]])
    return MassProperties('laminae', m, np.zeros(3), np.trace(second) * np.eye(3) - second)


def solid_of(lamina, delta, arrangement, mass, *, rtol=1e-9):
    """Uniform solid convex hull of two laminae of any shape (mass/hull_laminae.py).

    Parameters
    ----------
    lamina, delta, arrangement, mass
        As in :func:`laminae_of`.
    rtol : float
        Requested relative accuracy (0 < rtol < 1; roundoff floor about 1e-13).

    Returns
    -------
    MassProperties
        ``volume`` (m³), centre of mass from G (m, on e2), inertia about the centre of mass
        (kg m²) and the quadrature's ``relative_error``. Remembered per lamina object.

    Raises
    ------
    ValueError
        For a body ContactSolver refuses (one line).
    RuntimeError
        If the quadrature cannot reach ``rtol``.
    """
    d, _, g = _shape(lamina, delta, arrangement)
    m = positive('mass', mass, 'kg')
    tol = check_rtol(rtol)
    remembered = _GENERAL_HULLS.setdefault(lamina, {})
    key = (d, arrangement, tol)
    if key not in remembered:
        remembered[key] = general_hull_moments(lamina, d, arrangement, tol)
    vol, first, second, err = remembered[key]
    com = first / vol                                     # from O
    central = second - vol * np.outer(com, com)
    inertia = m / vol * (np.trace(central) * np.eye(3) - central)
    return MassProperties('solid', m, com - np.array([0.0, g, 0.0]), inertia, volume=vol,
                          relative_error=err)


def mass_properties_of(model, body, mass, principal_moments=None, rtol=1e-9):
    """Mass properties of any rolling body by model name.

    Parameters
    ----------
    model : str
        'laminae', 'solid' or 'custom'.
    body : RollingBody
        Anything with ``lamina``, ``delta`` and ``arrangement`` (EllipseBody, LaminaBody,
        ContactSolver). An ellipse's are those of :func:`mass_properties` (model, a, b,
        delta, ...) to rounding (measured ≤ 3.6e-16 relative for 'laminae', ≤ 1.6e-15 for
        'solid', whose quadrature costs ~50 ms here, ~2 ms there).
    mass, principal_moments, rtol
        As in :func:`mass_properties`.

    Returns
    -------
    MassProperties
        In the body frame with origin G, the laminae's centroid (the midpoint of the centres
        for symmetric laminae), or the body's reference point G + offset e2 for a body moved
        by :meth:`~twodisk_ros.physics.bodies.lamina_body.LaminaBody.about` (centre of mass from
        it; inertia about the centre of mass either way).
    """
    props = _properties_of(model, body, mass, principal_moments, rtol)
    offset = float(body.offset)
    if not offset:
        return props
    return dataclasses.replace(props, center_of_mass=props.center_of_mass
                               - np.array([0.0, offset, 0.0]))


def centred_on_mass(model, body, mass, principal_moments=None, rtol=1e-9):
    """(body, mass properties) whose body-frame origin is the centre of mass.

    The body decides (``body.centred_on``): a LaminaBody is moved onto it (``about``; its
    centre of mass is then exactly zero), an EllipseBody (G by symmetry) returned as it is.
    ``body``: a RollingBody; other arguments as in :func:`mass_properties_of`.

    Returns
    -------
    (RollingBody, MassProperties)
        Ready for :class:`~twodisk_ros.physics.motion.dynamics.RollingDynamics`.
    """
    props = mass_properties_of(model, body, mass, principal_moments, rtol)
    body, com = check_rolling_body(body).centred_on(props.center_of_mass)
    return body, dataclasses.replace(props, center_of_mass=com)


def _properties_of(model, body, mass, principal_moments, rtol):
    """:func:`mass_properties_of` about G."""
    _check_model(model)
    try:
        lamina, delta, arrangement = body.lamina, body.delta, body.arrangement
    except AttributeError:
        raise ValueError(f'body must be a rolling body with lamina, delta and arrangement '
                         f'(EllipseBody, LaminaBody), got {type(body).__name__}') from None
    _shape(lamina, delta, arrangement)
    return _by_model(model, mass, principal_moments,
                     lambda: laminae_of(lamina, delta, arrangement, mass),
                     lambda: solid_of(lamina, delta, arrangement, mass, rtol=rtol))
