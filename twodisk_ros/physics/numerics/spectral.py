"""Spectral tools for smooth 2π-periodic functions sampled at u_j = 2πj/N.

Every function of the cycle phase u is smooth and periodic, so one cycle is represented by N
equispaced samples and differentiated, integrated and refined with the FFT; the grid is
doubled until the spectrum's upper half is below :data:`TAIL_TOLERANCE` of its peak
(docs/physics.md#spectral-integration-over-one-cycle).
"""

import numpy as np

__all__ = ['STALL', 'TAIL_TOLERANCE', 'refine_grid', 'spectral_antiderivative',
           'spectral_derivative', 'spectral_derivative_at', 'spectral_tail', 'spectral_tails',
           'real_spectral_derivative', 'node_sum', 'upsample']

#: A periodic function counts as resolved when :func:`spectral_tail` is below this.
TAIL_TOLERANCE = 1e-13
#: refine_grid's noise test: a doubling that shrinks the tail by less than this has reached
#: the noise floor of the samples
STALL = 0.5


def _wavenumbers(n, ndim=1):
    """Integer wavenumbers of an N-point FFT, shaped (N, 1, ...) to broadcast over ndim axes."""
    return np.fft.fftfreq(n, d=1.0 / n).reshape((n,) + (1,) * (ndim - 1))


def spectral_tail(samples):
    """Relative size of the upper half of the spectrum of periodic samples (|k| > N/4).

    A resolution check: ~1e-16 for a resolved smooth function, larger when not.
    """
    coeffs = np.abs(np.fft.fft(samples, axis=0))
    n = coeffs.shape[0]
    k = np.abs(np.fft.fftfreq(n, d=1.0 / n))
    scale = max(float(np.max(coeffs)), np.finfo(float).tiny)
    return float(np.max(coeffs[k > n // 4])) / scale


def spectral_tails(samples):
    """:func:`spectral_tail` of each column: samples (N, ...) along axis 0, one tail per column.

    Returns
    -------
    ndarray, shape samples.shape[1:]
        The relative size of the upper half of each column's spectrum (|k| > N/4).
    """
    coeffs = np.abs(np.fft.fft(samples, axis=0))
    n = coeffs.shape[0]
    k = np.abs(np.fft.fftfreq(n, d=1.0 / n))
    scale = np.maximum(np.max(coeffs, axis=0), np.finfo(float).tiny)
    return np.max(coeffs[k > n // 4], axis=0) / scale


def refine_grid(sample, start, maximum, tolerance=TAIL_TOLERANCE, floor=None):
    """Double the number of nodes until a periodic function is resolved.

    Parameters
    ----------
    sample : callable
        ``sample(n) -> (tail, data)``: the spectral tail of the function on n nodes (0 when
        there is nothing to resolve) and whatever the caller wants to keep of that grid.
    start, maximum : int
        First and largest node count (powers of two).
    tolerance : float
        Stop once ``tail < tolerance``.
    floor : float, optional
        Also stop when the tail is below ``floor`` and a doubling shrank it by less than
        :data:`STALL`: the function is resolved down to the noise of its samples (a spectrum
        that still converges shrinks geometrically, much faster; noise spread over twice the
        modes only by about √2). Without it, samples noisier than ``tolerance`` are refined
        up to ``maximum`` for nothing.

    Returns
    -------
    (int, object)
        The node count used and its ``data``.
    """
    n = int(start)
    previous = np.inf
    while True:
        tail, data = sample(n)
        if tail < tolerance or n >= maximum:
            return n, data
        if floor is not None and tail <= floor and tail > STALL * previous:
            return n, data
        previous = tail
        n *= 2


def spectral_derivative(samples):
    """d/du of periodic samples along axis 0 (the Nyquist term set to zero)."""
    samples = np.asarray(samples)
    n = samples.shape[0]
    coeffs = np.fft.fft(samples, axis=0)
    if n % 2 == 0:
        coeffs[n // 2] = 0.0
    derivative = np.fft.ifft(1j * _wavenumbers(n, samples.ndim) * coeffs, axis=0)
    return derivative if np.iscomplexobj(samples) else np.real(derivative)


def node_sum(samples):
    """Σ over axis 0 (the nodes) for each column, summed row by row of the transposed array
    (numpy's pairwise sum): a column's sum depends on that column only, not on how many
    columns are summed with it (bodies of a batch give the same bits in any batch)."""
    samples = np.asarray(samples)
    return np.ascontiguousarray(np.moveaxis(samples, 0, -1)).sum(axis=-1)


def real_spectral_derivative(samples, axis=0):
    """d/du of real periodic samples along ``axis`` (real FFT; the Nyquist term set to zero).

    The same derivative as :func:`spectral_derivative` (to rounding) at about a third of its
    cost for real data, along any axis (e.g. (3, N, B) vectors of B bodies, axis=1).
    """
    samples = np.asarray(samples, dtype=float)
    n = samples.shape[axis]
    coeffs = np.fft.rfft(samples, axis=axis)
    shape = [1] * samples.ndim
    shape[axis] = n // 2 + 1
    k = np.arange(n // 2 + 1, dtype=float)
    if n % 2 == 0:
        k[-1] = 0.0
    return np.fft.irfft(coeffs * (1j * k).reshape(shape), n, axis=axis)


def spectral_derivative_at(samples, points):
    """d/du of a periodic real function, from its N samples, at arbitrary phases (rad)."""
    n = len(samples)
    coeffs = np.fft.fft(samples) / n
    k = np.fft.fftfreq(n, d=1.0 / n)
    if n % 2 == 0:
        coeffs[n // 2] = 0.0
    return [float(np.real(np.sum(1j * k * coeffs * np.exp(1j * k * p)))) for p in points]


def upsample(samples, factor):
    """Samples of a periodic function on a grid ``factor`` times finer (zero-padded FFT)."""
    n = samples.shape[0]
    coeffs = np.fft.rfft(samples)
    padded = np.zeros(n * factor // 2 + 1, dtype=complex)
    padded[:n // 2] = coeffs[:n // 2]
    padded[n // 2] = 0.5 * coeffs[n // 2]    # split the Nyquist term symmetrically
    return np.fft.irfft(padded, n * factor) * factor


def spectral_antiderivative(rate):
    """Antiderivative of a smooth 2π-periodic function sampled at u_j = 2πj/N.

    Returns ``(mean, periodic)``: the integral is ``mean·u + periodic(u)`` with
    ``periodic(0) = 0``, given at the same nodes. Samples of shape (N, ...) hold one function
    per column (axis 0 is u); ``mean`` then has shape (...) (a float for one real function).
    """
    rate = np.asarray(rate)
    n = rate.shape[0]
    coeffs = np.fft.fft(rate, axis=0)
    mean = coeffs[0] / n
    k = _wavenumbers(n, rate.ndim)
    safe_k = np.where(k == 0, 1.0, k)
    integ = np.where(k == 0, 0.0, coeffs / (1j * safe_k))
    if n % 2 == 0:
        integ[n // 2] = 0.0
    periodic = np.fft.ifft(integ, axis=0)
    periodic = periodic - periodic[0]
    if not np.iscomplexobj(rate):
        mean = np.real(mean)
        return (float(mean) if mean.ndim == 0 else mean), periodic.real
    return mean, periodic
