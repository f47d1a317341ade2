"""Uniform-grid tables with quintic Hermite interpolation.

Used for the smooth functions of the cycle phase u: values, first and second derivatives
are stored at the nodes, so the interpolant is C² and its error is O(h⁶ f⁽⁶⁾/46080).
Large batches use :meth:`HermiteTable.weights` and :meth:`HermiteTable.combine`: the six
Hermite weights are computed once per sample (shared by tables on the same grid), and each
table contributes one gather of its node data and one small matrix product per sample.
"""

import math

import numpy as np

__all__ = ['HermiteTable', 'hermite_jet', 'power_coefficients', 'power_value']


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

    #: points evaluated at once by :meth:`__call__` (4096 measured fastest among 1024 …
    #: 65536 on the 2-core benchmark machine, for one and for three columns)
    BLOCK = 4096

    def __init__(self, start, step, values, first, second):
        self.start = float(start)
        self.step = float(step)
        values = np.asarray(values)
        first = np.asarray(first) * self.step
        second = np.asarray(second) * self.step**2
        dtype = np.result_type(values, first, second)
        # node data interleaved, (n + 1, 3, ...): rows i and i + 1 are one contiguous gather
        self._nodes = np.stack([values, first, second], axis=1).astype(dtype, copy=False)
        self.values, self.first, self.second = (self._nodes[:, k] for k in range(3))
        self._rows = self._nodes.reshape(len(self._nodes), -1)
        self.last_index = len(self.values) - 2
        self._power_rows = None          # the power basis' coefficients, built on first use

    def _locate(self, x):
        s = (np.asarray(x, dtype=float) - self.start) / self.step
        i = np.clip(np.floor(s).astype(np.intp), 0, self.last_index)
        t = s - i
        return i, t

    def __call__(self, x, derivative=0):
        """f(x) (``derivative=0``) or f′(x) (``derivative=1``); x inside the table's span.

        A finite scalar x (an ODE's right-hand side asks for one point at a time) takes the
        same arithmetic in Python floats, without the array set-up: the same result bit for
        bit, at a third of the cost. Arrays of more than :attr:`BLOCK` points are evaluated in
        blocks of that size (the same operations per point, so the same result bit for bit:
        the temporaries stay in cache, 3× faster for three columns on 65536 points)."""
        if np.ndim(x) and np.size(x) > self.BLOCK:
            return self._blocked(np.asarray(x, dtype=float), derivative)
        if isinstance(x, (float, np.floating)) and math.isfinite(x):
            position = (float(x) - self.start) / self.step
            i = min(max(math.floor(position), 0), self.last_index)
            t = position - i
        else:
            i, t = self._locate(x)
        y0, y1 = self.values[i], self.values[i + 1]
        d0, d1 = self.first[i], self.first[i + 1]
        s0, s1 = self.second[i], self.second[i + 1]
        if not isinstance(t, float):
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

    def _blocked(self, x, derivative):
        flat = x.reshape(-1)
        out = np.empty(flat.shape + self.values.shape[1:], dtype=self.values.dtype)
        for start in range(0, flat.size, self.BLOCK):
            part = slice(start, start + self.BLOCK)
            out[part] = self(flat[part], derivative)
        return out.reshape(x.shape + self.values.shape[1:])

    def jet(self, x):
        """(f, f′, f″) at points x inside the table's span: the interpolant and its first two
        derivatives (:func:`hermite_jet`; f″ is the quintic's, accurate to O(h⁴))."""
        i, t = self._locate(x)
        t = t.reshape(t.shape + (1,) * (self.values.ndim - 1))
        value, slope, curvature = hermite_jet(
            t, [x[i] for x in (self.values, self.first, self.second)],
            [x[i + 1] for x in (self.values, self.first, self.second)])
        return value, slope / self.step, curvature / self.step**2

    def weights(self, x, derivative=0):
        """Interval indices and Hermite weights at points x, for :meth:`combine`.

        Parameters
        ----------
        x : array_like
            Points inside the table's span (same unit as ``start`` and ``step``).
        derivative : {0, 1}
            Weights of f (0) or of f′ (1: :meth:`combine` then gives ``self(x, 1)``).

        Returns
        -------
        index : ndarray of intp, shape x.shape
            The interval [start + h·i, start + h·(i + 1)] of each point.
        weights : ndarray, shape x.shape + (6,)
            Weights of f_i, h f′_i, h² f″_i, f_{i+1}, h f′_{i+1}, h² f″_{i+1}; they depend on
            the grid only, so they serve every table with the same start, step and length.
        """
        i, t = self._locate(x)
        t2 = t * t
        t3 = t2 * t
        w = np.empty(t.shape + (6,))
        if derivative == 1:
            w[..., 0] = t2 * (-30 + t * (60 - 30 * t)) / self.step
            w[..., 1] = (1 + t2 * (-18 + t * (32 - 15 * t))) / self.step
            w[..., 2] = (t + t2 * (-4.5 + t * (6 - 2.5 * t))) / self.step
            w[..., 3] = -w[..., 0]
            w[..., 4] = t2 * (-12 + t * (28 - 15 * t)) / self.step
            w[..., 5] = t2 * (1.5 + t * (-4 + 2.5 * t)) / self.step
            return i, w
        if derivative != 0:
            raise ValueError(f'derivative must be 0 or 1, got {derivative!r}')
        w[..., 0] = 1 + t3 * (-10 + t * (15 - 6 * t))
        w[..., 1] = t + t3 * (-6 + t * (8 - 3 * t))
        w[..., 2] = 0.5 * (t2 + t3 * (-3 + t * (3 - t)))
        w[..., 3] = t3 * (10 + t * (-15 + 6 * t))
        w[..., 4] = t3 * (-4 + t * (7 - 3 * t))
        w[..., 5] = 0.5 * t3 * (1 + t * (-2 + t))
        return i, w

    def combine(self, index, weights):
        """f at the points of :meth:`weights` (same interpolant as ``self(x)``, vectorised).

        One gather of the node data of intervals ``index`` and a 1 × 6 by 6 × m product per
        point: about half the work of :meth:`__call__` for tables of several columns.

        Returns
        -------
        ndarray, shape index.shape + the table's trailing shape
        """
        index = np.asarray(index)
        flat = index.reshape(-1)
        pairs = np.stack([flat, flat + 1], axis=-1)
        data = self._rows.take(pairs, axis=0).reshape(flat.size, 6, -1)
        out = np.matmul(weights.reshape(flat.size, 1, 6), data)
        return out.reshape(index.shape + self.values.shape[1:])

    def powers(self, x):
        """Interval indices and the powers (1, t, t², t³, t⁴, t⁵) of points x, for :meth:`expand`.

        Cheaper than :meth:`weights` (four products per point instead of six polynomials);
        the powers depend on the grid only, so they serve every table on it.
        """
        i, t = self._locate(x)
        p = np.empty(t.shape + (6,))
        p[..., 0] = 1.0
        p[..., 1] = t
        np.multiply(t, t, out=p[..., 2])
        np.multiply(p[..., 2], t, out=p[..., 3])
        np.multiply(p[..., 2], p[..., 2], out=p[..., 4])
        np.multiply(p[..., 4], t, out=p[..., 5])
        return i, p

    def expand(self, index, powers):
        """f at the points of :meth:`powers`: the same interpolant in the power basis of t.

        The coefficients of every interval are computed once from the node data (c₀ = f_i,
        c₁ = h f′_i, c₂ = h² f″_i/2, and c₃ … c₅ from the differences to node i + 1: terms of
        order h³ and up, so their rounding stays far below an ulp of f); each point then takes
        one gather of its interval's row and a 1 × 6 by 6 × m product. Agrees with
        :meth:`__call__` to a few ulps of the node data; reproduces the nodes exactly.
        """
        index = np.asarray(index)
        flat = index.reshape(-1)
        data = self._coefficients().take(flat, axis=0).reshape(flat.size, 6, -1)
        out = np.matmul(powers.reshape(flat.size, 1, 6), data)
        return out.reshape(index.shape + self.values.shape[1:])

    def scratch(self, size):
        """Work arrays for :meth:`expand_into` on blocks of up to ``size`` points."""
        return _Scratch(size, self._coefficients().shape[1])

    def expand_into(self, x, scratch):
        """``expand(*powers(x))`` for a 1-d block x of at most ``scratch.size`` points, computed
        in the work arrays of :meth:`scratch` (no allocation, the temporaries stay in cache):
        the same operations, so the same result bit for bit.

        Returns
        -------
        ndarray, shape (x.size, columns)
            A view into ``scratch``, valid until its next use.
        """
        m = x.size
        s, floor, index = scratch.s[:m], scratch.floor[:m], scratch.index[:m]
        p, rows, f = scratch.powers[:m], scratch.rows[:m], scratch.values[:m]
        np.subtract(x, self.start, out=s)
        np.divide(s, self.step, out=s)
        np.floor(s, out=floor)
        np.maximum(floor, 0.0, out=floor)
        np.minimum(floor, self.last_index, out=floor)
        np.copyto(index, floor, casting='unsafe')
        t = p[:, 1]
        np.subtract(s, floor, out=t)
        np.multiply(t, t, out=p[:, 2])
        np.multiply(p[:, 2], t, out=p[:, 3])
        np.multiply(p[:, 2], p[:, 2], out=p[:, 4])
        np.multiply(p[:, 4], t, out=p[:, 5])
        # indices are in range: mode='clip' spares take the copy of `out` that 'raise' makes
        self._coefficients().take(index, axis=0, out=rows, mode='clip')
        np.matmul(p[:, None, :], rows.reshape(m, 6, -1), out=f[:, None, :])
        return f

    def _coefficients(self):
        if self._power_rows is None:
            c = power_coefficients(*(x[:-1] for x in (self.values, self.first, self.second)),
                                   *(x[1:] for x in (self.values, self.first, self.second)))
            self._power_rows = np.ascontiguousarray(c.reshape(len(c), -1))
        return self._power_rows

    @classmethod
    def periodic(cls, values, first, second):
        """A table over one cycle [0, 2π] from samples at u_j = 2πj/N of a periodic function.

        ``values``, ``first`` and ``second`` (shape (N, ...)) are f, f′ and f″ at the N nodes;
        the node u = 2π repeats u = 0.
        """
        closed = [np.concatenate([x, x[:1]]) for x in (values, first, second)]
        return cls(0.0, 2.0 * np.pi / len(values), *closed)


class _Scratch:
    """Work arrays of :meth:`HermiteTable.expand_into` for up to ``size`` points of a table of
    ``width`` = 6 × columns coefficients per interval (~8 × (width + columns + 10) bytes per
    point)."""

    def __init__(self, size, width):
        self.size = int(size)
        self.s, self.floor = np.empty(self.size), np.empty(self.size)
        self.index = np.empty(self.size, dtype=np.intp)
        self.powers = np.empty((self.size, 6))
        self.powers[:, 0] = 1.0
        self.rows = np.empty((self.size, width))
        self.values = np.empty((self.size, width // 6))


def power_coefficients(y0, d0, s0, y1, d1, s1):
    """The quintic Hermite interpolant of :class:`HermiteTable` on intervals, in powers of t.

    Parameters
    ----------
    y0, d0, s0, y1, d1, s1 : ndarray, shape (n, ...)
        f, h f′ and h² f″ at the start and at the end of each interval (h its width).

    Returns
    -------
    ndarray, shape (n, 6, ...)
        c₀ … c₅ with f = Σ c_k t^k, t ∈ [0, 1] across the interval.
    """
    jump = y1 - y0
    return np.stack([y0, d0, 0.5 * s0,
                     10.0 * jump - 6.0 * d0 - 4.0 * d1 - 1.5 * s0 + 0.5 * s1,
                     -15.0 * jump + 8.0 * d0 + 7.0 * d1 + 1.5 * s0 - s1,
                     6.0 * jump - 3.0 * d0 - 3.0 * d1 - 0.5 * s0 + 0.5 * s1], axis=1)


def power_value(coefficients, t):
    """Σ c_k t^k (Horner) for rows of :func:`power_coefficients` of one column, shape (N, 6),
    at t, shape (N,)."""
    value = coefficients[:, 5] * t
    for k in (4, 3, 2, 1):
        value += coefficients[:, k]
        value *= t
    value += coefficients[:, 0]
    return value


def hermite_jet(t, start, end):
    """The quintic Hermite interpolant of :class:`HermiteTable` on one interval, and its slope
    and curvature, at t ∈ [0, 1] (arrays broadcast together).

    Parameters
    ----------
    t : array_like
        Position in the interval, (x − x_i)/h.
    start, end : sequence of three arrays
        (f, h f′, h² f″) at the interval's two nodes (the table's scaled node data).

    Returns
    -------
    f, df, d2f : ndarray
        The interpolant and its first and second derivatives in t (divide by h and h² for
        derivatives in x).
    """
    (y0, d0, s0), (y1, d1, s1) = start, end
    t = np.asarray(t, dtype=float)
    t2 = t * t
    t3 = t2 * t
    value = ((1 + t3 * (-10 + t * (15 - 6 * t))) * y0 + (t + t3 * (-6 + t * (8 - 3 * t))) * d0
             + 0.5 * (t2 + t3 * (-3 + t * (3 - t))) * s0 + 0.5 * t3 * (1 + t * (-2 + t)) * s1
             + t3 * (-4 + t * (7 - 3 * t)) * d1 + t3 * (10 + t * (-15 + 6 * t)) * y1)
    slope = (t2 * (-30 + t * (60 - 30 * t)) * (y0 - y1) + (1 + t2 * (-18 + t * (32 - 15 * t))) * d0
             + (t + t2 * (-4.5 + t * (6 - 2.5 * t))) * s0 + t2 * (1.5 + t * (-4 + 2.5 * t)) * s1
             + t2 * (-12 + t * (28 - 15 * t)) * d1)
    curvature = (t * (-60 + t * (180 - 120 * t)) * (y0 - y1) + t * (-36 + t * (96 - 60 * t)) * d0
                 + (1 + t * (-9 + t * (18 - 10 * t))) * s0 + t * (3 + t * (-12 + 10 * t)) * s1
                 + t * (-24 + t * (84 - 60 * t)) * d1)
    return value, slope, curvature
