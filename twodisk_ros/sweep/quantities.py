"""What a parameter sweep computes for one body: pure numpy/scipy, no Dask, no files.

Every body of the sweep has a = 1 and is named by its ratios (b/a, Δ/a); lengths are in units
of a, times in units of √(a/g), angular speeds in units of √(g/a) (a = 1 m, g = 1 m/s²,
M = 1 kg in the library calls). In :func:`body_quantities` each quantity is one call of the
physics library (:mod:`twodisk_ros.physics`): the scalar reference path, which agrees bitwise
with the same call made directly (docs/sweeps.md lists the variables and their definitions).
A sweep's tasks (:func:`~twodisk_ros.sweep.chunks.quantities`) compute the same
quantities for a whole chunk at once as arrays (:class:`~twodisk_ros.sweep.batch.Ellipses`),
to ≤ 1e-10 relative of the scalar path, which computes the bodies the batch cannot finish.

A body that cannot be built or whose computation fails is not an error of the sweep: its
quantities from the failing stage on are NaN and ``failure`` says why, in one line.

A chunk of exponent n != 2 (superellipse laminae) goes through the per-body general path
(:mod:`~twodisk_ros.sweep.general`), which runs the same stages (:func:`run_stages`).
"""

import math
import time

import numpy as np
from scipy.optimize import minimize_scalar

from ..physics.bodies.ellipse import EllipseBody
from ..physics.forces.contact import ContactForceModel
from ..physics.forces.validity import liftoff_speed, mu_required_kinematic
from ..physics.bodies.cycle import RollingCycle, TWO_PI
from ..physics.motion.dynamics import RollingDynamics
from ..physics.stability.equilibria import NEUTRAL, STABLE
from ..physics.mass.models import mass_properties
from .variables import VARIABLES

__all__ = ['VARIABLES', 'STAGES', 'body_quantities', 'run_stages', 'shape_failure',
           'contact_length_range', 'cycle_time', 'one_line']

#: Stages of one body, in order; a failing stage leaves its quantities and the later ones NaN.
STAGES = ('body', 'cycle', 'equilibria', 'cycle_time', 'contact_length', 'contact_tables',
          'liftoff_speed', 'mu_required')

def one_line(text, limit=200):
    """``text`` on one line, at most ``limit`` characters (a ``failure`` value)."""
    text = ' '.join(str(text).split())
    return text if len(text) <= limit else text[:limit - 3] + '...'


def cycle_time(dynamics):
    """∫ |ω_u| du over one cycle (rad of body rotation; s at |ω| = 1 rad/s).

    Trapezoidal rule on the dynamics' table nodes: |ω_u| is smooth and 2π-periodic, so the
    rule converges spectrally and the table's resolution (resolved to ~1e-13) suffices.
    """
    n = dynamics.table_size
    u = TWO_PI * np.arange(n) / n
    return float(np.sum(dynamics.angular_speed_per_phase(u)) * (TWO_PI / n))


def contact_length_range(body, nodes):
    """(min, max) of |AB| = |r2 − r1| (m) over one cycle.

    The extremes are located on ``nodes`` equally spaced phases and refined by bounded Brent
    on the closed form (to ~1e-12 rad in u; the values to rounding).
    """
    def length(u):
        geo = body.phase_geometry(u)
        return np.linalg.norm(geo.contact_b - geo.contact_a, axis=-1)

    u = TWO_PI * np.arange(nodes) / nodes
    values = length(u)
    step = TWO_PI / nodes
    found = []
    for sign, i in ((1.0, int(np.argmin(values))), (-1.0, int(np.argmax(values)))):
        res = minimize_scalar(lambda x: sign * float(length(x)),
                              bounds=(u[i] - step, u[i] + step), method='bounded',
                              options={'xatol': 1e-12})
        found.append(sign * min(sign * float(values[i]), float(res.fun)))
    return found[0], found[1]


def _stable_reference(dynamics):
    """(u*, period) of the first stable equilibrium in phase order, or (None, None)."""
    for eq, period in dynamics.equilibria_with_periods():
        if eq.stability == STABLE:
            return eq.phase, period
    return None, None


def body_quantities(b_over_a, delta_over_a, mass_model='laminae', reference_speed=0.5,
                    timings=None):
    """All sweep quantities of the body (a, b, Δ) = (1, b/a, Δ/a) with M = g = 1.

    Parameters
    ----------
    b_over_a, delta_over_a : float
        Shape of the body; 0 < Δ/a < 1 and b/a > 0 are needed, else the point fails.
    mass_model : str
        'laminae' (two thin disks) or 'solid' (uniform convex hull).
    reference_speed : float
        Kinematic angular speed |ω| (units √(g/a)) at which ``mu_required`` is evaluated.
    timings : dict, optional
        If given, the wall time of each stage (s) is added to ``timings[stage]``.

    Returns
    -------
    values : dict
        name → float for every name of :data:`VARIABLES` (NaN where not computed).
    failure : str
        '' on success, else one line: the failing stage and why.
    """
    values = dict.fromkeys(VARIABLES, math.nan)
    b, d = float(b_over_a), float(delta_over_a)
    failure = shape_failure(b, d)
    if failure:
        return values, failure

    def body_stage(state, values):
        state['body'] = body = EllipseBody(1.0, b, d)
        values['theta_max'] = body.theta_max
        values['stability_margin'] = body.stability_margin

    return run_stages(values, body_stage,
                      lambda state, values: _equilibria_stage(state, values, mass_model, b, d),
                      reference_speed, timings)


def shape_failure(b, d):
    """The failure line of a body (1, b/a, Δ/a) that cannot be built, else ''."""
    if not (math.isfinite(b) and math.isfinite(d)):
        return f'body: b/a = {b!r} and delta/a = {d!r} must be finite'
    if d >= 1.0:
        return (f'body: delta/a = {d!r} >= 1, the disks do not interlock '
                f'(needs 0 < delta/a < 1)')
    return ''


def run_stages(values, body_stage, equilibria_stage, reference_speed, timings):
    """Run :data:`STAGES` in order, filling ``values``; (values, failure line or '').

    ``body_stage(state, values)`` puts the body in ``state['body']``; ``equilibria_stage(state,
    values)`` the dynamics in ``state['dynamics']``; the other stages are the same for every
    body. A stage that raises ends the run: the body's failure is data, not a crash.
    """
    state = {}

    def run(stage):
        if stage == 'body':
            body_stage(state, values)
        elif stage == 'cycle':
            state['cycle'] = cycle = RollingCycle(state['body'])
            values['cycle_advance'] = abs(cycle.displacement.shift)
            values['cycle_heading'] = cycle.displacement.turn
        elif stage == 'equilibria':
            equilibria_stage(state, values)
        elif stage == 'cycle_time':
            values['cycle_time'] = cycle_time(state['dynamics'])
        elif stage == 'contact_length':
            low, high = contact_length_range(state['body'], state['dynamics'].table_size)
            values['contact_length_min'], values['contact_length_max'] = low, high
        elif stage == 'contact_tables':
            state['model'] = ContactForceModel(state['dynamics'])
        elif stage == 'liftoff_speed':
            values['liftoff_speed'] = liftoff_speed(state['model'])[0]
        else:
            values['mu_required'] = float(mu_required_kinematic(state['model'],
                                                                reference_speed))

    for stage in STAGES:
        start = time.perf_counter()
        try:
            run(stage)
        except Exception as error:  # noqa: BLE001 (a failing body is data, not a crash)
            return values, one_line(f'{stage}: {type(error).__name__}: {error}')
        finally:
            if timings is not None:
                timings[stage] = timings.get(stage, 0.0) + time.perf_counter() - start
    return values, ''


def _equilibria_stage(state, values, mass_model, b, d):
    """Dynamics (M = g = 1), the stable family, the height range, barrier and period."""
    body = state['body']
    props = mass_properties(mass_model, 1.0, b, d, 1.0)
    state['dynamics'] = dynamics = RollingDynamics(body, props, 1.0, cycle=state['cycle'])
    found = dynamics.equilibria_with_periods()
    heights = [eq.height for eq, _ in found]
    values['height_min'], values['height_max'] = min(heights), max(heights)
    u_star, period = _stable_reference(dynamics)
    if all(eq.stability == NEUTRAL for eq, _ in found):
        values['stable_family'] = 0.0
        values['barrier'] = 0.0
        values['rollover_speed'] = 0.0
        return
    values['stable_family'] = 1.0 if body.stability_margin > 0 else -1.0
    barrier = values['height_max'] - values['height_min']
    values['barrier'] = barrier
    if u_star is None:
        raise RuntimeError('no stable equilibrium found although the body is not neutral')
    values['oscillation_period'] = period
    m_star = float(dynamics.effective_mass(u_star))
    omega_u = float(dynamics.angular_speed_per_phase(u_star))
    # ½ m(u*) u̇² = M g ΔH with M = g = 1, then |ω| = |ω_u(u*)| u̇
    values['rollover_speed'] = omega_u * math.sqrt(2.0 * barrier / m_star)
