"""DOP853's dense output read at many times in one pass.

scipy's ``OdeSolution`` evaluates an array of times segment by segment: it sorts the times,
groups them by integration step and calls each step's interpolant on its group, a Python call
per step touched. The readers here (the Newton and bisection inversions of t(τ) in
:mod:`~twodisk_ros.physics.scenes.samples` and :mod:`~twodisk_ros.physics.motion.solvers`)
touch thousands of steps per call, dozens of times. :func:`dense_reader` gathers every step's
interpolant coefficients once and evaluates all times together, with the very operations of
scipy's ``Dop853DenseOutput`` applied to each time (the same Horner recursion in x = (t −
t_old)/h, the same segment rule): the values are scipy's, bit for bit.
"""

import numpy as np

__all__ = ['dense_reader']


class _Dop853Reader:
    """An ``OdeSolution`` of DOP853 steps, evaluated for all times at once."""

    def __init__(self, solution):
        self._solution = solution
        self._stacked = None

    def _stack(self):
        steps = self._solution.interpolants
        self._stacked = (np.array([step.t_old for step in steps], dtype=float),
                         np.array([step.h for step in steps], dtype=float),
                         np.stack([step.F[::-1] for step in steps]),   # (m, stages, n)
                         np.stack([step.y_old for step in steps]))     # (m, n)
        return self._stacked

    def __call__(self, t):
        """y at times ``t``: shape (n,) for a scalar, (n, len(t)) for a 1-D array."""
        t = np.asarray(t)
        if t.ndim != 1:
            return self._solution(t)
        solution = self._solution
        t_old, h, stages, y_old = self._stacked or self._stack()
        last = solution.n_segments - 1
        # scipy's rule: the step whose [t_i, t_i+1) holds t (side as scipy), clipped
        segment = np.searchsorted(solution.ts_sorted, t, side=solution.side) - 1
        segment = np.clip(segment, 0, last)
        if not solution.ascending:
            segment = last - segment
        x = ((t - t_old[segment]) / h[segment])[:, None]
        gathered = stages[segment]
        y = np.zeros((len(t), y_old.shape[1]), dtype=y_old.dtype)
        for i in range(gathered.shape[1]):
            y += gathered[:, i]
            if i % 2 == 0:
                y *= x
            else:
                y *= 1 - x
        y += y_old[segment]
        return y.T


def dense_reader(scipy_solution):
    """A callable y(t) equal to ``scipy_solution(t)`` (scipy's ``OdeSolution``), bit for bit,
    faster for arrays of times; ``scipy_solution`` itself if it is not made of DOP853 steps."""
    try:
        from scipy.integrate._ivp.rk import Dop853DenseOutput
    except ImportError:    # another scipy layout: its own evaluation
        return scipy_solution
    steps = getattr(scipy_solution, 'interpolants', None)
    if not steps or not all(type(step) is Dop853DenseOutput for step in steps):
        return scipy_solution
    return _Dop853Reader(scipy_solution)
