"""Uniform-grid tables with quintic Hermite interpolation, and spectral integration.

Used for the smooth functions of the cycle phase u: values, first and second derivatives
are stored at the nodes, so the interpolant is C² and its error is O(h⁶ f⁽⁶⁾/46080).
"""

import numpy as np

__all__ = ['HermiteTable', 'spectral_antiderivative', 'spectral_tail']


class HermiteTable:
    """Quintic Hermite interpolation of f on the nodes ``start + h·i``, i = 0 … n.

    Parameters
    ----------
    start : float
        First node.
    step : float
        Node spacing h (> 0).
    values, first, second : ndarray, shape (n + 1, ...)
        f, f′ and f″ at the nodes (real or complex; trailing axes are carried along).
    """

    def __init__(self, start, step, values, first, second):
        self.start = float(start)
        self.step = float(step)
        self.values = np.asarray(values)
        self.first = np.asarray(first) * self.step
        self.second = np.asarray(second) * self.step**2
        self.last_index = len(self.values) - 2

    def _locate(self, x):
        s = (np.asarray(x, dtype=float) - self.start) / self.step
        i = np.clip(np.floor(s).astype(np.intp), 0, self.last_index)
        t = s - i
        return i, t

    def __call__(self, x, derivative=0):
        """f(x) (``derivative=0``) or f′(x) (``derivative=1``); x inside the table's span."""
        i, t = self._locate(x)
        y0, y1 = self.values[i], self.values[i + 1]
        d0, d1 = self.first[i], self.first[i + 1]
        s0, s1 = self.second[i], self.second[i + 1]
        t = t.reshape(t.shape + (1,) * (y0.ndim - t.ndim))
        t2 = t * t
        t3 = t2 * t
        if derivative == 0:
            h0 = 1 + t3 * (-10 + t * (15 - 6 * t))
            h1 = t + t3 * (-6 + t * (8 - 3 * t))
            h2 = 0.5 * (t2 + t3 * (-3 + t * (3 - t)))
            h3 = 0.5 * t3 * (1 + t * (-2 + t))
            h4 = t3 * (-4 + t * (7 - 3 * t))
            h5 = t3 * (10 + t * (-15 + 6 * t))
            return h0 * y0 + h1 * d0 + h2 * s0 + h3 * s1 + h4 * d1 + h5 * y1
        if derivative == 1:
            g0 = t2 * (-30 + t * (60 - 30 * t))
            g1 = 1 + t2 * (-18 + t * (32 - 15 * t))
            g2 = t + t2 * (-4.5 + t * (6 - 2.5 * t))
            g3 = t2 * (1.5 + t * (-4 + 2.5 * t))
            g4 = t2 * (-12 + t * (28 - 15 * t))
            return (g0 * (y0 - y1) + g1 * d0 + g2 * s0 + g3 * s1 + g4 * d1) / self.step
        raise ValueError(f'derivative must be 0 or 1, got {derivative!r}')


def spectral_tail(samples):
    """Relative size of the upper half of the spectrum of periodic samples (|k| > N/4).

    A resolution check: ~1e-16 for a resolved smooth function, larger when not.
    """
    coeffs = np.abs(np.fft.fft(samples, axis=0))
    n = coeffs.shape[0]
    k = np.abs(np.fft.fftfreq(n, d=1.0 / n))
    scale = max(float(np.max(coeffs)), np.finfo(float).tiny)
    return float(np.max(coeffs[k > n // 4])) / scale


def spectral_antiderivative(rate):
    """Antiderivative of a smooth 2π-periodic function sampled at u_j = 2πj/N.

    Returns ``(mean, periodic)``: the integral is ``mean·u + periodic(u)`` with
    ``periodic(0) = 0``, given at the same nodes.
    """
    rate = np.asarray(rate)
    n = rate.shape[0]
    coeffs = np.fft.fft(rate, axis=0)
    mean = coeffs[0] / n
    k = np.fft.fftfreq(n, d=1.0 / n)
    k_shape = (n,) + (1,) * (rate.ndim - 1)
    k = k.reshape(k_shape)
    safe_k = np.where(k == 0, 1.0, k)
    integ = np.where(k == 0, 0.0, coeffs / (1j * safe_k))
    if n % 2 == 0:
        integ[n // 2] = 0.0
    periodic = np.fft.ifft(integ, axis=0)
    periodic = periodic - periodic[0]
    if not np.iscomplexobj(rate):
        return float(np.real(mean)), periodic.real
    return mean, periodic
