"""Rounding bounds for the tests: n ulps of a computed magnitude.

A float64 result built from rounded terms (a sum, a product of sums, a table's interpolant,
an FFT) agrees with the same quantity computed another way only to a few ulps of the
magnitude of its terms, and how many depends on the machine's floating-point path: FMA
contraction, numpy's SIMD dispatch and pairwise sums, the BLAS kernel, libm's last bit. A
bound of a few ulps therefore proves nothing about the code and fails elsewhere. Where a
test's only error is rounding, its bound is :func:`ulps`: n ulps of the magnitude it applies
to, with n >= :data:`MIN_ULPS` (the project's rule), and each use says which magnitude and
why that n. Bit-identity (``==``, ``array_equal``) is asserted only where the same code runs
on the same data in one process, or where the value is exact by construction (a copy, a
zero written as zero, a product by ±1 or a power of 2, a correctly rounded decimal
round trip).
"""

import numpy as np

#: Machine epsilon of float64, 2.2e-16: eps·|x| bounds one ulp of any normal x.
EPS = float(np.finfo(float).eps)

#: The least n of a rounding bound of a result that is a sum of rounded terms.
MIN_ULPS = 16


def ulps(n, magnitude=1.0):
    """n ulps of ``magnitude`` (its units): n·eps·|magnitude|, elementwise for arrays.

    Raises ValueError for n < :data:`MIN_ULPS`, a bound that only this machine's rounding
    would meet.
    """
    if n < MIN_ULPS:
        raise ValueError(f'a rounding bound takes n >= {MIN_ULPS} ulps, got {n}')
    return n * EPS * np.abs(magnitude)
