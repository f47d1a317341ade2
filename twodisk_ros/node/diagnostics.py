"""The node's ``/diagnostics`` status at one sample: invariant, contacts, rate, scene.

Levels: ERROR once the motion has left the rolling model (lift-off, slip, or a slope the body
cannot stand on: from t = 0, with the reason), WARN when the invariant drifts beyond
``tolerance``, the rate is not held, or the contacts are close to their limits, else OK.
The invariant is the energy E (dynamic mode, flat free scene), the angular speed (kinematic
mode, flat; in the other modes it is a value too, ``angular_speed`` |w| = |ω_u| |u̇| about
AB: finite and exact also where a contact sits on a flat vertex) or the energy balance E + W − W_d (any other scene: W the work done against
damping and rolling resistance, W_d the drive's work, both from the run's start or its last
reset). With losses and no drive the body comes to rest on a stable pose: the values give the
energy above it and, once at rest, the time it came to rest (``at_rest_since``, s).
"""

import math

import numpy as np

from . import messages

__all__ = ['NAME', 'status']

NAME = 'twodisk_ros: roller'


def status(node, sample, i):
    """(level, message, values) of the diagnostics at sample i of a block (module doc)."""
    s, simulation = node.settings, node.simulation
    name, value, drift = simulation.invariant(sample, i)
    level, message = messages.OK, 'rolling'
    if drift > s.tolerance:
        level, message = messages.WARN, (f'{name} drift {drift:.2e} exceeds tolerance '
                                          f'{s.tolerance:.1e}')
    achieved = node.achieved_rate()
    dropped_lately = node.samples_dropped - node.dropped_reported
    node.dropped_reported = node.samples_dropped
    slow = achieved is not None and achieved < 0.95 * s.rate
    if s.realtime and (slow or dropped_lately) and level < messages.ERROR:
        level = messages.WARN
        rate_text = f'achieved {achieved:.4g} Hz, ' if achieved is not None else ''
        message = (f'cannot hold rate {s.rate:g} Hz: {rate_text}{dropped_lately} samples '
                   f'dropped since the last report ({node.samples_dropped} in all) to keep '
                   'real time')
    contact_level, contact_message, contact_values = simulation.contact_status(sample, i)
    if contact_level > level or contact_level == level == messages.OK:   # (OK: which model)
        level, message = contact_level, contact_message
    values = [(name, value), (f'{name}_drift', drift),
              ('energy', simulation.energy(sample, i)),
              ('tilt', float(simulation.dynamics.cycle.state(sample.phase[i]).tilt)),
              ('phase', float(sample.phase[i])), ('mode', s.mode), ('method', s.method),
              ('rate', s.rate), ('achieved_rate', achieved if achieved else s.rate),
              ('clock_lag', float(np.mean(node.lag)) if node.lag else 0.0),
              ('samples_dropped', node.samples_dropped)] + contact_values
    if name != 'energy':
        values = [v for v in values if v[0] != 'energy'] + [
            ('energy', simulation.energy(sample, i))]
    if name != 'angular_speed':     # |w| about AB: finite also on a flat vertex (u̇ is not)
        values.append(('angular_speed', abs(simulation.angular_speed(sample, i))))
    if sample.scene is not None:
        values += scene_values(node, sample, i)
    return level, message, values + simulation.equilibrium_values()


def scene_values(node, sample, i):
    """The scene's entries: slope, drive in force and command, the drive's torque and power,
    the works and the energy balance's constant E₀ (J)."""
    scene, v = node.simulation.scene.scene, sample.scene
    return [('slope', scene.slope), ('heading0', scene.heading0),
            ('drive', scene.drive), ('command', scene.command),
            ('drive_torque', float(v.drive_torque[i])), ('drive_power', float(v.power[i])),
            ('dissipated_work', float(v.dissipated[i])),
            ('drive_work', float(v.drive_work[i])),
            ('energy0', node.simulation.energy0)] + _rest_values(node, sample, i)


def _rest_values(node, sample, i):
    """With losses and no drive: the energy above the nearest stable rest pose (J) and, once
    the body is at rest (scene_simulation.REST_ENERGY), the time it came to rest (s)."""
    motion = node.simulation.scene
    if not motion.comes_to_rest:
        return []
    excess = float(motion.rest_excess(sample.phase[i], sample.scene.energy[i]))
    values = [('energy_above_rest', excess if math.isfinite(excess) else 'not near a rest pose')]
    if math.isfinite(motion.rested):
        values.append(('at_rest_since', motion.rested))
    return values
