"""One task of a sweep: :func:`quantities` of a batch of bodies. Pure numpy/scipy, no Dask.

A batch holds the b/a and Δ/a of its bodies and says itself what it computes at once:
``batched()`` fills what it can as arrays and leaves the other bodies' indices to
``one()``, body by body. The ellipse (n = 2, :class:`~twodisk_ros.sweep.batch.Ellipses`)
batches its closed forms (≤ 1e-10 relative from its scalar path) and leaves to
:func:`~twodisk_ros.sweep.quantities.body_quantities` the bodies it cannot finish; any other
lamina (:class:`~twodisk_ros.sweep.general.Laminae`) has nothing to batch and goes one by one.
"""

import math
import time

import numpy as np

from .request import ELLIPSE_EXPONENT
from .variables import VARIABLES

__all__ = ['quantities', 'chunk_bodies', 'timed_chunk']


def quantities(bodies, mass_model='laminae', reference_speed=0.5, timings=None):
    """Every sweep quantity of every body of the batch ``bodies`` (a = M = g = 1).

    Parameters
    ----------
    bodies : Ellipses or Laminae
        The batch (:func:`chunk_bodies`).
    mass_model : str
        'laminae' (two thin disks) or 'solid' (uniform convex hull).
    reference_speed : float
        Kinematic angular speed |ω| (units √(g/a)) at which ``mu_required`` is evaluated.
    timings : dict, optional
        Wall time (s) added per stage of the batch's paths (n = 2:
        :data:`~twodisk_ros.sweep.batch.BATCH_STAGES`; else
        :data:`~twodisk_ros.sweep.quantities.STAGES`).

    Returns
    -------
    dict
        name → float64 array for every name of
        :data:`~twodisk_ros.sweep.quantities.VARIABLES`, and ``failure`` → list of str ('' or
        the failing stage and why, in one line), all of the length of the batch.
    """
    out = {name: np.full(len(bodies), math.nan) for name in VARIABLES}
    out['failure'] = [''] * len(bodies)
    for k in bodies.batched(out, mass_model, reference_speed, timings):
        values, out['failure'][k] = bodies.one(k, mass_model, reference_speed, timings)
        for name, value in values.items():
            out[name][k] = value
    return out


def chunk_bodies(b_values, delta_values, exponent=ELLIPSE_EXPONENT):
    """The batch of a task: paired b/a and Δ/a of superellipse laminae of exponent n, the
    ellipse's closed forms for n = 2. (The paths, scipy and the physics, are imported here:
    on the workers, never by a client that only submits :func:`timed_chunk`.)"""
    if exponent == ELLIPSE_EXPONENT:
        from .batch import Ellipses
        return Ellipses(b_values, delta_values)
    from .general import Laminae
    return Laminae(b_values, delta_values, exponent)


def timed_chunk(b_values, delta_values, mass_model='laminae', reference_speed=0.5,
                exponent=ELLIPSE_EXPONENT):
    """(:func:`quantities` (...), wall time, CPU time of the process in s): one task (one
    exponent n)."""
    start, cpu = time.perf_counter(), time.process_time()
    result = quantities(chunk_bodies(b_values, delta_values, exponent), mass_model,
                        reference_speed)
    return result, time.perf_counter() - start, time.process_time() - cpu
