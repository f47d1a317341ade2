"""The sweep's quantities for many bodies at once: arrays over a batch axis, no Dask, no files.

:class:`Ellipses`, the batch of a task of exponent n = 2, computes in
:meth:`Ellipses.batched` what :func:`~twodisk_ros.sweep.quantities.body_quantities` computes
(the reference, one body and one library call per quantity), for a whole chunk of bodies as
array operations (docs/sweeps.md, "The batched path"):

1. each body is checked and its mass model built one by one, as the scalar path does
   (microseconds each; a body the scalar path refuses at these stages goes through it, so
   its reason is the scalar path's own line);
2. the cycle resolution of every body, by the scalar construction's own test
   (:func:`~twodisk_ros.physics.bodies.cycle.required_resolutions`, batched);
3. bodies of one resolution are evaluated together in blocks of at most :data:`POINTS`
   nodes × bodies: the closed forms on the 4 × resolution nodes of the scalar path's tables
   (:meth:`~twodisk_ros.physics.bodies.ellipse_batch.EllipseBodies.cycle_samples`), then every
   quantity from these samples with numpy over the batch axis: the cycle's displacement
   (spectral integration), the eight equilibria, the cycle time (trapezoidal), the extremes
   of |AB| (nodes, then Newton on the closed form), the kinematic contact-force columns,
   the lift-off speed (nodes, then Newton on the tables' quintic interpolant) and
   μ_required (its 2048 phases are table nodes);
4. a body whose batched values are not all finite where the scalar path's are (or that has
   no stable equilibrium although not neutral), and every body of a block that raised, is
   left to :meth:`Ellipses.one`, the scalar path, which then gives its values or its
   one-line failure (:func:`~twodisk_ros.sweep.chunks.quantities` calls it).

Every quantity agrees with the scalar path to ≤ 1e-10 relative, except where the scalar
path itself is less accurate (the oscillation period within ~1e-3 a² of the neutral line
and at the extreme shapes; docs/sweeps.md states the measured agreement).
"""

from contextlib import contextmanager
import math
import time

import numpy as np

from ..physics.numerics.analytic import COMPLEX_STEP
from ..physics.bodies.ellipse import EllipseBody
from ..physics.bodies.ellipse_batch import EllipseBodies, dot
from ..physics.forces.contact import kinematic_coefficients
from ..physics.forces.validity import liftoff_speed_batch, mu_required_kinematic_batch
from ..physics.bodies.cycle import TWO_PI, displacement_from_rates, required_resolutions
from ..physics.stability.equilibria import equilibria_batch
from ..physics.mass.models import mass_properties
from ..physics.numerics.spectral import node_sum
from .quantities import body_quantities

__all__ = ['POINTS', 'BATCH_STAGES', 'Ellipses']

#: Nodes × bodies evaluated at once (a block): ~150 B of temporaries per point, so a block
#: stays within a few tens of MiB (benchmarks/sweep_batch.py measured 2^15 … 2^18 within
#: a few % of each other).
POINTS = 2**16
#: Stages of :class:`Ellipses`, the keys of its ``timings``.
BATCH_STAGES = ('bodies', 'resolution', 'samples', 'cycle', 'equilibria', 'cycle_time',
                'contact_length', 'contact_tables', 'liftoff_speed', 'mu_required', 'scalar')
#: Newton steps of the refinements of the extremes of |AB| (from a node, converged in ~4).
_NEWTON_STEPS = 6
#: Quantities that are finite for every body the scalar path computes.
_FINITE = ('theta_max', 'stability_margin', 'stable_family', 'height_min', 'height_max',
           'barrier', 'rollover_speed', 'cycle_advance', 'cycle_heading', 'cycle_time',
           'contact_length_min', 'contact_length_max')


class _Clock:
    """Adds the wall time of each stage to a ``timings`` dict (or does nothing)."""

    def __init__(self, timings):
        self.timings = timings

    @contextmanager
    def __call__(self, stage):
        start = time.perf_counter()
        try:
            yield
        finally:
            if self.timings is not None:
                self.timings[stage] = self.timings.get(stage, 0.0) + time.perf_counter() - start


def _checked_bodies(b_values, delta_values, mass_model, out):
    """(indices of the bodies the batch computes, their inertia (k, 3, 3)); theta_max and
    the stability margin filled in from the scalar body (exact)."""
    chosen, inertia = [], []
    for k, (b, d) in enumerate(zip(b_values, delta_values)):
        b, d = float(b), float(d)
        if not (math.isfinite(b) and math.isfinite(d)) or d >= 1.0:
            continue
        try:
            body = EllipseBody(1.0, b, d)
            props = mass_properties(mass_model, 1.0, b, d, 1.0)
        except Exception:  # noqa: BLE001 (the scalar path gives this body's reason)
            continue
        out['theta_max'][k] = body.theta_max
        out['stability_margin'][k] = body.stability_margin
        chosen.append(k)
        inertia.append(props.inertia)
    return np.array(chosen, dtype=int), np.array(inertia).reshape(-1, 3, 3)


def _length_jet(bodies, u):
    """|AB| and d|AB|/du at phases u (shape (k, B)), by complex step of the closed forms."""
    vectors = bodies.phase_vectors(u + 1j * COMPLEX_STEP)
    d = vectors[1] - vectors[0]
    length = np.sqrt(np.sum(d * d, axis=-1))
    return length.real, length.imag / COMPLEX_STEP


def _length_extremes(bodies, lengths):
    """(min, max) of |AB| over the cycle: the node extremes, refined by Newton's method on
    the closed form (slope by complex step, curvature by a central difference of it) within
    one node spacing, the best value found kept (the scalar path's bounded Brent on the same
    bracket reaches the same extreme to ~1e-12 rad, its value to rounding)."""
    n, count = lengths.shape
    h = TWO_PI / n
    columns = np.arange(count)
    node = np.stack([np.argmin(lengths, axis=0), np.argmax(lengths, axis=0)])      # (2, B)
    centre = TWO_PI * node / n
    best = lengths[node, columns]
    sign = np.array([1.0, -1.0])[:, None]
    x = centre.copy()
    delta = 1e-3 * h
    for step in range(_NEWTON_STEPS + 1):
        value, slope = _length_jet(bodies, np.concatenate([x, x - delta, x + delta]))
        best = sign * np.minimum(sign * best, sign * value[:2])
        if step == _NEWTON_STEPS:
            break
        curvature = (slope[4:] - slope[2:4]) / (2 * delta)
        with np.errstate(divide='ignore', invalid='ignore'):
            move = np.where(sign * curvature > 0, -slope[:2] / curvature, 0.0)
        x = np.clip(x + np.where(np.isfinite(move), move, 0.0), centre - h, centre + h)
    return best[0], best[1]


def _block(bodies, inertia, nodes, reference_speed, clock):
    """Every quantity after the body stage for bodies of one resolution: name → array."""
    values = {}
    with clock('samples'):
        samples = bodies.cycle_samples(nodes)
    with clock('cycle'):
        turn, shift = displacement_from_rates(samples.arc_rate, samples.turn_rate)
        values['cycle_advance'], values['cycle_heading'] = np.abs(shift), turn
    with clock('equilibria'):
        found = equilibria_batch(bodies, samples.height_slope)
        low, high = found.height.min(axis=0), found.height.max(axis=0)
        neutral = found.neutral
        values['height_min'], values['height_max'] = low, high
        values['stable_family'] = np.where(neutral, 0.0, np.where(
            bodies.stability_margin > 0, 1.0, -1.0))
        barrier = np.where(neutral, 0.0, high - low)
        values['barrier'] = barrier
        # u*: the first stable equilibrium in phase order (none when neutral)
        row = np.argmax(found.stable, axis=0)
        columns = np.arange(len(bodies))
        has_stable = found.stable[row, columns]
        u_star = found.phase[row, columns]
        stiffness = found.phase_curvature[row, columns]            # V''(u*), M = g = 1
        omega = bodies.phase_angular_velocity(u_star[None])[0]        # (B, 3)
        r1 = bodies.phase_geometry(u_star[None]).contact_a[0]
        v = np.cross(omega, r1)
        m_star = np.einsum('bi,bij,bj->b', omega, inertia, omega) + np.sum(v * v, axis=-1)
        with np.errstate(divide='ignore', invalid='ignore'):
            period = TWO_PI * np.sqrt(m_star / stiffness)
            speed = np.linalg.norm(omega, axis=-1) * np.sqrt(2.0 * barrier / m_star)
        values['oscillation_period'] = np.where(has_stable & (stiffness > 0), period, np.nan)
        values['rollover_speed'] = np.where(neutral, 0.0, speed)
    with clock('cycle_time'):
        w = samples.angular_velocity
        values['cycle_time'] = node_sum(np.sqrt(dot(w, w))) * (TWO_PI / nodes)
    with clock('contact_length'):
        d = samples.contact_b - samples.contact_a
        lengths = np.sqrt(dot(d, d))
        values['contact_length_min'], values['contact_length_max'] = _length_extremes(
            bodies, lengths)
    with clock('contact_tables'):
        q0, q2 = kinematic_coefficients(samples, inertia, 1.0, 1.0)
    with clock('liftoff_speed'):
        values['liftoff_speed'] = liftoff_speed_batch(q0[:2], q2[:2])
    with clock('mu_required'):
        values['mu_required'] = mu_required_kinematic_batch(q0, q2, reference_speed)
    good = (neutral | has_stable) & ~np.isnan(values['liftoff_speed']) & ~np.isnan(
        values['mu_required'])
    for name in _FINITE:
        if name in values:
            good &= np.isfinite(values[name])
    return values, good


class Ellipses:
    """The ellipse bodies (a, b, Δ) = (1, b/a, Δ/a) of a task of exponent n = 2, as arrays.

    Parameters
    ----------
    b_values, delta_values : array_like
        b/a and Δ/a of the bodies (paired, flattened), a = 1.
    """

    def __init__(self, b_values, delta_values):
        self.b = np.asarray(b_values, dtype=float).ravel()
        self.delta = np.asarray(delta_values, dtype=float).ravel()

    def __len__(self):
        return self.b.size

    def batched(self, out, mass_model, reference_speed, timings):
        """Fill ``out`` (name → array, :func:`~twodisk_ros.sweep.chunks.quantities`) with
        the bodies the closed forms compute as arrays (module docstring); the indices of the
        bodies left to :meth:`one`. ``timings``: wall time per stage of :data:`BATCH_STAGES`
        (s), added to ``timings[stage]``."""
        clock = _Clock(timings)
        with clock('bodies'):
            chosen, inertia = _checked_bodies(self.b, self.delta, mass_model, out)
        left = sorted(set(range(len(self))) - set(chosen.tolist()))
        if not chosen.size:
            return left
        with clock('resolution'):
            everyone = EllipseBodies(1.0, self.b[chosen], self.delta[chosen])
            resolution = required_resolutions(everyone, POINTS)
        for r in np.unique(resolution):
            group = np.flatnonzero(resolution == r)
            nodes = 4 * int(r)
            step = max(1, POINTS // nodes)
            for start in range(0, group.size, step):
                part = group[start:start + step]
                try:
                    # non-finite values are masks here (checked in _block), not warnings
                    with np.errstate(divide='ignore', invalid='ignore', over='ignore'):
                        values, good = _block(everyone.subset(part), inertia[part], nodes,
                                              reference_speed, clock)
                except Exception:  # noqa: BLE001 (never lose a chunk: the scalar path)
                    left.extend(chosen[part].tolist())
                    continue
                for name, array in values.items():
                    out[name][chosen[part]] = array
                left.extend(chosen[part[~good]].tolist())
        return sorted(left)

    def one(self, k, mass_model, reference_speed, timings):
        """(values, failure) of body ``k`` by the scalar reference
        :func:`~twodisk_ros.sweep.quantities.body_quantities`, timed as the stage 'scalar'."""
        with _Clock(timings)('scalar'):
            return body_quantities(self.b[k], self.delta[k], mass_model, reference_speed)
