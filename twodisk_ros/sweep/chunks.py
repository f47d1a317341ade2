"""One task of a sweep: the quantities of a chunk of bodies, on the path that fits it.

The ellipse (exponent n = 2) takes the batched closed forms (:mod:`~twodisk_ros.sweep.batch`,
all bodies of the chunk at once as arrays, ≤ 1e-10 relative from the scalar path) or, with
``method='scalar'``, :func:`~twodisk_ros.sweep.quantities.body_quantities` body by body (the
reference); any other exponent, or a body factory of the caller, the per-body general path
(:mod:`~twodisk_ros.sweep.general`). Pure numpy/scipy, no Dask, no files.
"""

import math
import time

import numpy as np

from .request import ELLIPSE_EXPONENT
from .variables import VARIABLES

__all__ = ['chunk_quantities', 'timed_chunk']


def chunk_quantities(b_values, delta_values, mass_model='laminae', reference_speed=0.5,
                     timings=None, method='batch', exponent=ELLIPSE_EXPONENT,
                     body_factory=None, mass_factory=None):
    """:func:`~twodisk_ros.sweep.quantities.body_quantities` over paired 1-D arrays of b/a and Δ/a (one task of a sweep).

    Parameters
    ----------
    method : str
        'batch' (default): all bodies at once as arrays (:mod:`~twodisk_ros.sweep.batch`,
        ≤ 1e-10 relative from the scalar path, docs/sweeps.md); 'scalar':
        :func:`~twodisk_ros.sweep.quantities.body_quantities` body by body (the reference). ``timings`` gets the stages of
        the chosen path (:data:`~twodisk_ros.sweep.batch.BATCH_STAGES` or :data:`~twodisk_ros.sweep.quantities.STAGES`).
        Ignored for an exponent other than 2 or with a ``body_factory``.
    exponent : float
        Superellipse exponent n of every body of the chunk: 2 (the ellipse, default) takes
        ``method``; any other n, or a ``body_factory``, the per-body general path
        (:func:`~twodisk_ros.sweep.general.general_body_quantities`, its stages in
        ``timings``).
    body_factory, mass_factory : callable, optional
        ``body_factory(b, delta, n)`` → RollingBody and ``mass_factory(model, body)`` →
        MassProperties (M = 1) of the general path (default: superellipse laminae,
        ``LaminaBody``; tests pass their own).

    Returns
    -------
    dict
        name → float64 array for every name of
        :data:`~twodisk_ros.sweep.quantities.VARIABLES`, and ``failure`` → list of
        str, all of the length of the inputs.
    """
    # the paths (scipy and the physics) imported here: on the workers, never by a client that
    # only submits timed_chunk
    if exponent != ELLIPSE_EXPONENT or body_factory is not None:
        from .general import general_body_quantities
        return _body_by_body(b_values, delta_values, lambda b, d: general_body_quantities(
            b, d, exponent, mass_model, reference_speed, timings, body_factory, mass_factory))
    if method == 'batch':
        from .batch import batch_quantities
        return batch_quantities(b_values, delta_values, mass_model, reference_speed, timings)
    if method != 'scalar':
        raise ValueError(f"method must be 'batch' or 'scalar', got {method!r}")
    from .quantities import body_quantities
    return _body_by_body(b_values, delta_values, lambda b, d: body_quantities(
        b, d, mass_model, reference_speed, timings))


def _body_by_body(b_values, delta_values, quantities):
    """:func:`chunk_quantities` one body after the other: ``quantities(b, d)`` → (values,
    failure) of each pair of the flattened inputs, gathered into arrays and a list."""
    b_values = np.asarray(b_values, dtype=float).ravel()
    delta_values = np.asarray(delta_values, dtype=float).ravel()
    out = {name: np.full(b_values.size, math.nan) for name in VARIABLES}
    failures = []
    for k, (b, d) in enumerate(zip(b_values, delta_values)):
        values, failure = quantities(b, d)
        for name, value in values.items():
            out[name][k] = value
        failures.append(failure)
    out['failure'] = failures
    return out


def timed_chunk(b_values, delta_values, mass_model='laminae', reference_speed=0.5,
                exponent=ELLIPSE_EXPONENT):
    """(:func:`chunk_quantities` (...), wall time, CPU time of the process in s): one task
    (one exponent n)."""
    start, cpu = time.perf_counter(), time.process_time()
    result = chunk_quantities(b_values, delta_values, mass_model, reference_speed,
                              exponent=exponent)
    return result, time.perf_counter() - start, time.process_time() - cpu
