"""The record of a body's mass properties, and the checks of the numbers that make one.

Shared by the mass models of ellipses and of any lamina (mass/models.py). Every check raises a
one-line ValueError naming the parameter, what is allowed and what it got.
"""

from dataclasses import dataclass, fields
import math

import numpy as np

__all__ = ['MassProperties', 'check_rtol', 'one_line', 'positive', 'real_number']


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
        Centre of mass (m, body frame, from G). It is G (zero) for the ellipse models and
        ``'laminae'``; for ``'solid'`` it is the computed value: zero up to roundoff by the
        symmetries, except for an asymmetric lamina in the parallel arrangement, where it
        lies on e2.
    inertia : numpy.ndarray, shape (3, 3)
        Inertia tensor about the centre of mass (kg m**2, body frame), symmetric (about G
        for the ellipse's ``'solid'``, which differs by roundoff squared).
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


# --------------------------------------------------------------------------- checks


def one_line(value, limit=80):
    """Short one-line representation of ``value`` for error messages."""
    text = ' '.join(repr(value).split())
    return text if len(text) <= limit else text[:limit - 3] + '...'


def real_number(name, value, what):
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
        raise ValueError(f'{name} must be a real number, {what}, got {one_line(value)}')
    return float(arr)


def positive(name, value, unit):
    """Return ``value`` as a finite float > 0, or raise a one-line ValueError."""
    what = f'finite and > 0 {unit}'
    x = real_number(name, value, what)
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f'{name} must be {what}, got {x!r}')
    return x


def check_rtol(rtol):
    """Validate the relative tolerance of the solid quadrature."""
    what = 'finite with 0 < rtol < 1'
    x = real_number('rtol', rtol, what)
    if not (math.isfinite(x) and 0.0 < x < 1.0):
        raise ValueError(f'rtol must be {what}, got {x!r}')
    return x
