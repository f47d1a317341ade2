"""The per-body path of a sweep for an exponent n != 2: superellipse laminae, any RollingBody.

A body of exponent n is two congruent superellipse laminae |x/b|ⁿ + |y/a|ⁿ ≤ 1 (a = 1 along
the common axis, b = b/a across it) with centres at ∓Δ:
``LaminaBody(Superellipse(1.0, b, n), Δ)`` (:mod:`~twodisk_ros.physics.bodies.lamina_body`). It has
no closed forms, so it is computed one body at a time through the
:class:`~twodisk_ros.physics.bodies.protocol.RollingBody` protocol: its
:class:`~twodisk_ros.physics.bodies.cycle.RollingCycle`, :class:`~twodisk_ros.physics.motion.dynamics.
RollingDynamics` with the mass model of :func:`~twodisk_ros.physics.mass.models.
mass_properties_of`, the equilibria the dynamics finds (every root of dz_G/du over the cycle)
and :class:`~twodisk_ros.physics.forces.contact.ContactForceModel`. The stages and the failure
lines are those of :func:`~twodisk_ros.sweep.quantities.body_quantities`.

Quantities whose ellipse definition does not carry over (docs/sweeps.md "The exponent axis";
:data:`~twodisk_ros.sweep.variables.GENERAL_MEANINGS` is written into each variable's
``general_path`` attribute):

- ``stability_margin`` is NaN: b² − 2a² + 2Δ² is the ellipse's criterion; a superellipse with
  n > 2 has flat vertices (zero curvature) where no quadratic criterion exists;
- ``stable_family`` comes from the closed-form stability of the symmetric equilibria of any
  lamina (:func:`~twodisk_ros.physics.stability.symmetric.symmetric_equilibria`): +1 the tips
  (θ = 0 and the turning points), −1 the side vertices (θ = ±π/2), **2 both** (what flat
  vertices give: each symmetric pose is a shallow local minimum), 0 neutral, NaN neither;
- ``oscillation_period`` is the dynamics' period about the lowest stable equilibrium, NaN where
  it has none (on a flat vertex: no linear small-oscillation period);
- ``rollover_speed`` is √(2 M g barrier / I_AB), I_AB the moment of inertia about the contact
  line AB at the lowest stable equilibrium: the n = 2 value (½ m(u*) u̇² = M g barrier,
  |ω| = |ω_u| u̇) written without the phase, whose rate ω_u vanishes where a contact crosses
  a flat vertex.

:class:`Laminae` is the batch of a task (:func:`~twodisk_ros.sweep.chunks.quantities`): it
has nothing to batch, every body goes through :meth:`Laminae.one`. The body and
its mass model are made by two callables that a caller may replace (``body_factory(b, delta,
exponent)`` and ``mass_factory(model, body)``), so that this path is also tested with the
ellipse's closed forms standing in for the lamina body.
"""

import math

import numpy as np

from ..physics.motion.dynamics import RollingDynamics
from ..physics.stability.equilibria import NEUTRAL, STABLE
from .quantities import run_stages, shape_failure
from .variables import VARIABLES

__all__ = ['Laminae', 'superellipse_body', 'lamina_mass', 'axis_inertia', 'symmetric_family']


class Laminae:
    """A batch of bodies of exponent n (a = 1; module docstring), computed one by one.

    ``b_values``, ``delta_values``: b/a and Δ/a (paired, flattened); ``body_factory(b, Δ, n)``
    → RollingBody and ``mass_factory(model, body)`` → MassProperties with M = 1 (default
    :func:`superellipse_body` and :func:`lamina_mass`).
    """

    def __init__(self, b_values, delta_values, exponent, body_factory=None, mass_factory=None):
        self.b = np.asarray(b_values, dtype=float).ravel()
        self.delta = np.asarray(delta_values, dtype=float).ravel()
        self.exponent, self.factories = float(exponent), (body_factory, mass_factory)

    def __len__(self):
        return self.b.size

    def batched(self, out, mass_model, reference_speed, timings):
        """No closed forms to batch: every index is left to :meth:`one`."""
        return range(len(self))

    def one(self, k, mass_model, reference_speed, timings):
        """(values, failure) of body ``k`` (M = g = 1), as
        :func:`~twodisk_ros.sweep.quantities.body_quantities`: the same stages and failure
        lines (:func:`~twodisk_ros.sweep.quantities.run_stages`, wall times in ``timings``)."""
        body_factory = self.factories[0] or superellipse_body
        mass_factory = self.factories[1] or lamina_mass
        values = dict.fromkeys(VARIABLES, math.nan)
        b, d, n = float(self.b[k]), float(self.delta[k]), self.exponent
        failure = shape_failure(b, d)
        if failure:
            return values, failure

        def body_stage(state, values):
            state['body'] = body = body_factory(b, d, n)
            values['theta_max'] = float(body.theta_max)

        return run_stages(values, body_stage,
                          lambda state, values: _equilibria_stage(state, values, mass_model,
                                                                  mass_factory),
                          reference_speed, timings)


def superellipse_body(b_over_a, delta_over_a, exponent):
    """``LaminaBody(Superellipse(1.0, b/a, n), Δ/a)``: the body of one grid point."""
    from ..physics.laminae.shapes import Superellipse
    from ..physics.bodies.lamina_body import LaminaBody
    return LaminaBody(Superellipse(1.0, b_over_a, exponent), delta_over_a)


def lamina_mass(mass_model, body):
    """The mass model ``mass_model`` of ``body`` with M = 1 (``mass_properties_of``)."""
    from ..physics.mass.models import mass_properties_of     # (issue 20: any RollingBody)
    return mass_properties_of(mass_model, body, 1.0)


def axis_inertia(body, props, u):
    """I_AB (kg m² with M = 1): the moment of inertia about the line through the contacts A
    and B at phase ``u``, about which a rolling body turns (both contacts at rest).

    ê = (r2 − r1)/|r2 − r1|, I_AB = êᵀ I_c ê + M |ê × (c − r1)|², I_c the inertia about the
    centre of mass c (``props.center_of_mass``, body frame)."""
    geo = body.phase_geometry(np.asarray(float(u)))
    r1 = np.asarray(geo.contact_a, dtype=float).reshape(3)
    r2 = np.asarray(geo.contact_b, dtype=float).reshape(3)
    axis = (r2 - r1) / np.linalg.norm(r2 - r1)
    arm = np.cross(axis, np.asarray(props.center_of_mass, dtype=float) - r1)
    return float(axis @ np.asarray(props.inertia, dtype=float) @ axis
                 + props.mass * float(arm @ arm))


def symmetric_family(body):
    """stable_family of ``body`` from its symmetric equilibria
    (:data:`~twodisk_ros.sweep.variables.GENERAL_FAMILIES`):
    +1 a tip (θ = 0 or the turning point) stable, −1 the side vertices, 2 both, NaN neither."""
    from ..physics.stability.symmetric import symmetric_equilibria
    first, turning, side = symmetric_equilibria(body.lamina, body.delta, body.arrangement)
    tips = STABLE in (first.stability, turning.stability)
    sides = side.stability == STABLE
    if tips and sides:
        return 2.0
    return 1.0 if tips else -1.0 if sides else math.nan


def _equilibria_stage(state, values, mass_model, mass_factory):
    """Dynamics (M = g = 1), the stable family, heights, barrier, period, roll-over speed."""
    body = state['body']
    props = mass_factory(mass_model, body)
    state['dynamics'] = dynamics = RollingDynamics(body, props, 1.0, cycle=state['cycle'])
    found = dynamics.equilibria_with_periods()
    heights = [float(eq.height) for eq, _ in found]
    values['height_min'], values['height_max'] = min(heights), max(heights)
    if all(eq.stability == NEUTRAL for eq, _ in found):
        values['stable_family'], values['barrier'], values['rollover_speed'] = 0.0, 0.0, 0.0
        return
    values['stable_family'] = symmetric_family(body)
    barrier = values['height_max'] - values['height_min']
    values['barrier'] = barrier
    stable = [(eq, period) for eq, period in found if eq.stability == STABLE]
    if not stable:
        raise RuntimeError('no stable equilibrium found although the body is not neutral')
    eq, period = min(stable, key=lambda pair: float(pair[0].height))   # first of the lowest
    values['oscillation_period'] = (float(period) if period is not None
                                    and math.isfinite(float(period)) else math.nan)
    values['rollover_speed'] = math.sqrt(2.0 * barrier / axis_inertia(body, props, eq.phase))
