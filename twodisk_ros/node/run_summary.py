"""The two lines ``roller`` logs: what a run is about to do, and what it did (no rclpy here).

As ``ros2 bag record`` says what it records, the node logs one INFO line when it is ready
(the body, the motion, the rate, how it runs, the output file) and one when the run ends
(samples published, simulated and wall time, the file and its size, the first sample outside
the rolling model, samples dropped to keep real time); and one more at the start if that is
on a flat vertex of the laminae (:func:`start_note`).
"""

import math
import os

import numpy as np

__all__ = ['start_line', 'start_note', 'end_line', 'file_size']

#: rad: a start this close to a flat vertex's phase is on it (the phases are exact to rounding)
VERTEX_GAP = 1e-9


def start_line(settings):
    """One line (no newline) describing the run of checked ``settings`` (SI units)."""
    s = settings
    if s.realtime:
        timing = (f'in real time for {s.duration:g} s' if s.duration > 0
                  else 'in real time until stopped')
    else:
        timing = f'as a batch of {s.duration:g} s'
    output = f'recording to {s.record}' if s.record else 'not recording'
    return (f'rolling a={s.a:g} m, b={s.b:g} m, delta={s.delta:g} m ({s.mass_model} mass '
            f'model, {s.mode} mode, method {s.method}) at {s.rate:g} Hz {timing}; {output}')


def start_note(body, start):
    """One line if the start is a phase where the body does not turn in u (a contact on a flat
    vertex of its laminae), else None. ``start``: the run's
    :class:`~twodisk_ros.physics.motion.dynamics.PhaseState`."""
    vertices = np.asarray(body.flat_vertex_phases(), dtype=float)
    gap = np.abs(np.remainder(start.phase - vertices + math.pi, 2 * math.pi) - math.pi)
    if not vertices.size or float(np.min(gap)) > VERTEX_GAP:
        return None
    vertex = float(vertices[int(np.argmin(gap))])
    where = (f'the start is on a flat vertex (phase u0 = {vertex:.9g} rad), where the body '
             'does not turn in u')
    if start.angular_speed == 0:
        return f'{where}: it starts at rest there'
    return (f'{where} (u̇ is infinite there): it starts from the angular speed '
            f'{start.angular_speed:g} rad/s about the contact line AB, and the contact forces '
            'are unbounded at that instant')


def file_size(nbytes):
    """``nbytes`` for people: '812 B', '1.5 kB', '2.31 MB' (powers of 1000)."""
    for unit, scale in (('GB', 1e9), ('MB', 1e6), ('kB', 1e3)):
        if nbytes >= scale:
            return f'{nbytes / scale:.3g} {unit}'
    return f'{nbytes} B'


def end_line(samples, simulated, wall, recorded_path=None, invalid=None, dropped=0):
    """One line on a finished run.

    Parameters
    ----------
    samples : int
        Samples published.
    simulated : float
        Simulated time of the last sample (s).
    wall : float
        Wall-clock time of the run (s).
    recorded_path : str, optional
        The recording written (its size is read), or None.
    invalid : str, optional
        Why the motion left the rolling model (the first sample outside it), or None.
    dropped : int
        Samples dropped to keep real time.
    """
    parts = [f'published {samples} samples ({simulated:g} s of simulated time) in '
             f'{wall:.3g} s']
    if recorded_path is not None:
        try:
            size = file_size(os.path.getsize(recorded_path))
        except OSError:
            size = 'size unknown'
        parts.append(f'recorded {recorded_path} ({size})')
    else:
        parts.append('not recorded')
    if invalid:
        parts.append(f'outside the rolling model: {invalid}')
    if dropped:
        parts.append(f'{dropped} samples dropped to keep real time')
    return '; '.join(parts)
