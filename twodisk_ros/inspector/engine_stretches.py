"""Engine stretches of a ``contact_model:=hybrid`` recording (issue 31), checked on their own.

The node publishes an event ``contact_model engine: <reason>`` stamped with the first sample
MuJoCo's free body gives, and ``contact_model rolling: <reason>`` with the first sample of
exact rolling again. The samples between are not the rolling model's: the rolling checks
leave them out (:func:`split_series`), and :func:`engine_check` checks what the free body
with unilateral contacts and Coulomb friction must satisfy, from the recorded wrenches and
contact points:

* unilateral: the ground only pushes, N = F·n ≥ 0 at each disk (n the ground's normal: e_z,
  on a slope β the recorded ``ground_normal`` (sin β, 0, cos β); the forces and points are
  taken to the slope frame, R_y(β)ᵀ p, the tangential part is the rest);
* Coulomb: |F_tangential| ≤ μ N (μ the recorded ``friction``), to 1e-6 of M g (MuJoCo's
  solver meets its elliptic cone to its tolerance; a disk's total of several contact forces
  inside the cone is inside it too);
* no contact point below the ground by more than 1e-2 of the body's size: the engine's soft
  contact gives under an impact by about the impact speed × its time constant (5 ms: 1.1 mm
  measured for the rounded square landing at 15 rad/s, 5.5e-3 of its size), and sinks
  1.4e-5 m at rest.
"""

from dataclasses import replace
import math

import numpy as np

from .results import Check

__all__ = ['ENGINE_EVENT', 'RESTART_EVENTS', 'ROLLING_EVENT', 'engine_check',
           'engine_intervals', 'rolling_starts', 'split_series', 'starts_anew']

ENGINE_EVENT = 'contact_model engine:'
ROLLING_EVENT = 'contact_model rolling:'
#: events after which the motion starts anew from a rolling state (the node's texts)
RESTART_EVENTS = ('reset', 'restart')
#: roles sampled at the node's rate (the rest, e.g. diagnostics and paths, are kept whole)
_PER_SAMPLE = ('pose', 'contact_a', 'contact_b', 'rolling_state', 'wrench_a', 'wrench_b')
CONE_TOLERANCE = 1e-6      #: of M g: the engine's friction cone
DEPTH_TOLERANCE = 1e-2     #: of the body's size: contact points below the ground


def starts_anew(text):
    """Whether the event ``text`` starts the motion anew from a rolling state: ``reset``
    (scene_control) or ``restart`` (a parameter change that rebuilds the motion, the node's
    roller.py); neither announces its first rolling stretch."""
    return text.split(' ', 1)[0] in RESTART_EVENTS


def rolling_starts(events):
    """Stamps (int ns) where exact rolling starts from a new state: a ``contact_model
    rolling`` event (the engine's state mapped back), ``reset`` or ``restart``: the energy
    check's E0 is taken again there."""
    return [int(stamp) for stamp, text in events
            if text.startswith(ROLLING_EVENT) or starts_anew(text)]


def engine_intervals(events):
    """[(first stamp, end stamp or None)] (int ns) of the engine stretches: from a
    ``contact_model engine`` event to the next ``contact_model rolling``, ``reset`` or
    ``restart`` event (excluded)."""
    intervals, start = [], None
    for stamp, text in events:
        if text.startswith(ENGINE_EVENT) and start is None:
            start = int(stamp)
        elif (text.startswith(ROLLING_EVENT) or starts_anew(text)) and start is not None:
            intervals.append((start, int(stamp)))
            start = None
    if start is not None:
        intervals.append((start, None))
    return intervals


def _inside(stamps, intervals):
    inside = np.zeros(len(stamps), dtype=bool)
    for start, end in intervals:
        inside |= (stamps >= start) & (True if end is None else stamps < end)
    return inside


def _masked(series, keep):
    values = {key: np.asarray(value)[keep] for key, value in series.values.items()}
    return replace(series, stamp_ns=series.stamp_ns[keep], log_ns=series.log_ns[keep],
                   publish_ns=series.publish_ns[keep], values=values)


def split_series(series, intervals):
    """(rolling series, engine series): the per-sample roles' messages outside and inside
    the engine stretches (the other roles whole in the first, absent in the second)."""
    rolling, engine = dict(series), {}
    for role in _PER_SAMPLE:
        if role in series and len(series[role]):
            inside = _inside(series[role].stamp_ns, intervals)
            rolling[role] = _masked(series[role], ~inside)
            engine[role] = _masked(series[role], inside)
    return rolling, engine


def engine_check(engine, intervals, parameters, weight, size):
    """The ``engine_stretches`` check (module docstring): the worst violation / M g or
    / size; None if there are no engine stretches."""
    if not intervals:
        return None
    mu = float(parameters.get('friction', 'inf'))
    slope = float(parameters.get('slope', 0.0))
    c, s = math.cos(slope), math.sin(slope)
    to_slope = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])    # R_y(β)ᵀ

    def ground(values):
        values = np.asarray(values, dtype=float)
        return values @ to_slope.T if slope else values

    worst, where, count = 0.0, '', 0
    for disk in 'ab':
        wrench, point = engine.get('wrench_' + disk), engine.get('contact_' + disk)
        if wrench is not None and len(wrench):
            force = ground(wrench.values['force'])
            normal = force[:, 2]
            tangential = np.linalg.norm(force[:, :2], axis=1)
            cone = tangential - (mu * np.maximum(normal, 0) if math.isfinite(mu) else np.inf)
            for name, excess in ((f'N_{disk.upper()} < 0', -normal / weight),
                                 (f'|F_t| > mu N at {disk.upper()}',
                                  cone / weight - CONE_TOLERANCE)):
                i = int(np.argmax(excess))
                count = max(count, len(excess))
                if excess[i] > worst:
                    worst, where = float(excess[i]), f'{name} at stamp {wrench.stamp_ns[i]}'
        if point is not None and len(point):
            depth = -ground(point.values['point'])[:, 2] / size - DEPTH_TOLERANCE
            i = int(np.argmax(depth))
            if depth[i] > worst:
                worst, where = float(depth[i]), f'contact {disk.upper()} below the ground ' \
                                                f'at stamp {point.stamp_ns[i]}'
    spans = ', '.join(f'{start} … {"end" if end is None else end}' for start, end in intervals)
    detail = [f'{len(intervals)} engine stretch(es) (stamps, ns: {spans}), {count} samples, '
              f'left out of the rolling checks',
              f'unilateral N >= 0, Coulomb |F_t| <= mu N (mu = {mu:g}) to {CONE_TOLERANCE:g} '
              f'M g, contact points no deeper than {DEPTH_TOLERANCE:g} of the size']
    if where:
        detail.append(f'worst: {where}')
    return Check('engine_stretches', 'MuJoCo stretches: unilateral contacts, Coulomb '
                 'friction, nothing through the ground', worst <= 0.0, max(worst, 0.0), 0.0,
                 '', detail)
