"""Helpers for functions that are analytic in their argument (the closed forms of u).

Every closed form of the body is analytic in the phase u, so its derivatives are taken by
complex step: f′(u) = Im f(u + i h) / h with h = 1e-30 has no subtractive cancellation and is
exact to rounding (docs/physics.md#the-regular-phase-u).
"""

import numpy as np

__all__ = ['COMPLEX_STEP', 'complex_step', 'complex_step_jet', 'sinc']

#: The imaginary step h of :func:`complex_step` (dimensionless, far below any scale of u).
COMPLEX_STEP = 1e-30


def complex_step(function, u):
    """Derivative of an analytic real function at real ``u`` by complex step (exact to rounding).

    Parameters
    ----------
    function : callable
        Accepts complex arrays and is analytic in its argument.
    u : array_like
        Points where the derivative is taken.
    """
    u = np.asarray(u, dtype=float)
    return np.imag(function(u + 1j * COMPLEX_STEP)) / COMPLEX_STEP


def complex_step_jet(values):
    """(value, derivative) of an analytic function from its value at u + i h.

    Parameters
    ----------
    values : ndarray or tuple of ndarray
        f(u + i·:data:`COMPLEX_STEP`), complex; a tuple is handled element by element.

    Returns
    -------
    (ndarray, ndarray) or tuple of such pairs
        Re f (the value at u, exact to O(h²)) and Im f / h (the derivative).
    """
    if isinstance(values, tuple):
        return tuple(complex_step_jet(v) for v in values)
    return np.real(values), np.imag(values) / COMPLEX_STEP


def sinc(x):
    """sin(x)/x, analytic (complex-step safe), exact at x = 0 (series below |x| = 1e-3)."""
    x = np.asarray(x)
    small = np.abs(x) < 1e-3
    if not small.any():     # the usual case: the arithmetic of the last line, without the rest
        return np.asarray(np.sin(x) / x)
    x_safe = np.where(small, 1.0, x)
    x2 = x * x
    series = 1.0 - x2 / 6.0 + x2 * x2 / 120.0 - x2 * x2 * x2 / 5040.0
    return np.where(small, series, np.sin(x_safe) / x_safe)
