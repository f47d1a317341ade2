"""The energy balance of a recorded scene, from the recording alone (``energy_balance``).

With a drive or dissipation E = T + V is not conserved; instead

    E(t) + W(t) − W_d(t) = E(t₀)   on each stretch of the run,

E = ½ M |v_G|² + ½ ω·I ω + M g z_G from the central differences of the recorded poses (z along
gravity: ``frame_id`` is gravity-aligned on a slope too), W the work done against damping and
rolling resistance, W_d the drive's work, both integrated (trapezoid rule) over the recorded
samples from their powers:

* damping c: c |ω|² (ω from the poses);
* rolling resistance μ_r: μ_r (N_A + N_B) |v_G| (N from the recorded wrenches along the ground
  normal);
* torque drive τ: τ Ω, Ω = |ω| sgn(u̇) (u̇ from rolling_state), τ the command in force (from the
  ``events``: 0 until the first command, 0 again after a ``timeout``).

The stretches are those between the node's events
(:mod:`twodisk_ros.node.scene_control`), and the parameters of each come from the recorded
parameters with the ``scene`` events (``scene <name> <old> -> <new>``) undone back to the
start. The speed drive's work is whatever
its rule needs: stretches under it are not checked here (the node's own balance is in
/diagnostics). Tolerance: twice the FD error of the energy (as the ``energy`` check) plus the
trapezoid rule's error estimate (h/12 Σ|Δ²P| per stretch). Samples whose differences do not
resolve the motion (:mod:`.resolution`) cut a stretch: each piece is balanced on its own.
"""

import math
import re

import numpy as np

from .differences import kinetic_energy

__all__ = ['balance_stretches', 'scene_timeline']

_CHANGE = re.compile(r'(\w+) (\S+) -> ([^,\s]+)')
_SCENE = ('drive', 'damping', 'rolling_resistance')


def scene_timeline(parameters, events):
    """[(start stamp (ns) or None for the run's start, state)] of the recorded scene.

    ``state``: dict with ``drive`` (the parameter), ``active`` (the drive in force: 'none'
    after a time-out), ``command`` (float, None before the first: the drive's start),
    ``damping`` and ``rolling_resistance``.
    """
    values = {name: parameters.get(name, 'none' if name == 'drive' else '0')
              for name in _SCENE}
    for _, text in reversed(events):
        if text.startswith('scene '):
            for name, old, _new in _CHANGE.findall(text[6:]):
                if name in values:
                    values[name] = old
    state = {'drive': values['drive'], 'damping': float(values['damping']),
             'rolling_resistance': float(values['rolling_resistance']),
             'command': None}
    if parameters.get('mode') == 'kinematic':
        state['drive'] = 'speed'
    state['active'] = state['drive']
    timeline = [(None, dict(state))]
    for stamp, text in events:
        words = text.split()
        kind = words[0] if words else ''
        if kind in ('reset', 'restart'):
            state.update(command=None, active=state['drive'])
        elif kind == 'timeout':
            state['active'] = 'none'
        elif kind == 'command' and len(words) == 3:
            state.update(command=float(words[2]), active=state['drive'])
        elif kind == 'scene':
            for name, _old, new in _CHANGE.findall(text[6:]):
                if name == 'drive':
                    state.update(drive=new, active=new, command=None)
                elif name in state:
                    state[name] = float(new)
        timeline.append((stamp, dict(state)))
    return timeline


def balance_stretches(samples, motion, model, timeline, normal_force, keep=None):
    """The balance residual on each stretch whose drive's work is known.

    Parameters
    ----------
    samples, motion, model
        As the other checks (:mod:`.checks`).
    timeline : list
        :func:`scene_timeline`.
    normal_force : numpy.ndarray or None
        N_A + N_B (N) at every sample, or None (no wrenches: rolling resistance unknown).
    keep : numpy.ndarray of bool, optional
        Over the rows of ``motion.index``: the samples the differences resolve
        (:mod:`.resolution`). A stretch is cut at the samples left out and each piece is
        balanced from its own first sample (the work across a left-out sample is unknown).

    Returns
    -------
    (residuals, skipped, quadrature)
        residuals: list of (t, |E + W − W_d − E(t₀)|) arrays per checked stretch (J);
        skipped: lines on the stretches not checked; quadrature: the largest trapezoid
        error estimate (J).
    """
    k = motion.index
    mass, gravity = model.dynamics.mass, model.dynamics.gravity
    energy = (kinetic_energy(mass, motion.velocity, motion.angular_velocity,
                             samples.rotation[k]) + mass.mass * gravity * samples.position_g[k, 2])
    stamps = samples.stamp_ns[k]
    starts = [-math.inf if s is None else s for s, _ in timeline] + [math.inf]
    residuals, skipped, quadrature = [], [], 0.0
    omega = np.linalg.norm(motion.angular_velocity, axis=1)
    speed_g = np.linalg.norm(motion.velocity, axis=1)
    keep = np.ones(k.size, dtype=bool) if keep is None else np.asarray(keep, dtype=bool)
    pieces = np.cumsum(~keep)       # the rows between two left-out samples share a number
    for (start, state), end in zip(zip(starts, (s for _, s in timeline)), starts[1:]):
        stretch = (stamps >= start) & (stamps < end)
        if np.sum(stretch) < 3:
            continue
        t = samples.t[k[stretch]]
        where = f't = {t[0]:.6g} … {t[-1]:.6g} s'
        if state['active'] == 'speed':
            skipped.append(f'{where}: speed drive (its work is what its rule needs; '
                           'the rule is the speed_drive check)')
            continue
        if state['rolling_resistance'] > 0 and normal_force is None:
            skipped.append(f'{where}: rolling resistance without recorded wrenches')
            continue
        for piece in np.unique(pieces[stretch & keep]):
            inside = stretch & keep & (pieces == piece)
            if np.sum(inside) < 3:
                continue
            t = samples.t[k[inside]]
            power = -state['damping'] * omega[inside]**2
            if state['rolling_resistance'] > 0:
                power = power - state['rolling_resistance'] * normal_force[k[inside]] * \
                    speed_g[inside]
            if state['active'] == 'torque' and state['command']:
                signed = omega[inside] * np.sign(samples.rates[k[inside], 2])
                power = power + state['command'] * signed
            h = np.diff(t)
            work = np.concatenate([[0.0], np.cumsum(0.5 * h * (power[1:] + power[:-1]))])
            quadrature = max(quadrature, float(np.mean(h)) / 12 * float(np.sum(np.abs(
                np.diff(power, 2)))))
            total = energy[inside] - work
            residuals.append((t, np.abs(total - total[0])))
    return residuals, skipped, quadrature
