"""Which samples an FD-limited check can judge, from the check's own error estimate.

The checks that differentiate the recorded poses (``no_slip``, ``energy``,
``angular_speed``, ``energy_balance``, ``speed_drive``, ``contact_forces``) take their
tolerance from the error the same differences show on a perfect recording: the model's poses
at the recorded phases, against the model's exact values (:mod:`.checks`). That error is
known sample by sample. Where the samples resolve the motion it is small: over the runs of
every ``config/`` body at its rate (3 s and 20 s) the FD part of a tolerance is at most
1.8e-4 of its scale (the egg's ``no_slip``; the Oloid's are ≤ 7.5e-6), except on the slope,
whose forces take the reference acceleration from second differences of the recorded u̇:
8.4e-4 over 20 s. Where they do not it is of order one: a contact crossing a flat vertex
of a superellipse makes the body stop turning in u for an instant, its acceleration is
unbounded there (an integrable spike, docs/physics.md "Any body: the forces per unit of the
turn, and flat vertices"), and no five-point stencil across that instant is accurate (0.03
to 12 of the scale at 100 Hz, tests/test_inspect_resolution.py). A tolerance taken from such
samples makes a check that cannot fail.

So each such check first sets aside the samples at which the FD part of its tolerance,
computed from that sample alone, would exceed :data:`CAP` = 1e-3 of its scale, evaluates the
rest with the tolerance they give, and names the stretches it left out. 1e-3 is where an
FD-limited check stops saying anything the docs promise: it is the error of the plain
three-point differences at 100 Hz, (ω h)² for ω = 3 rad/s, that the five-point stencils are
there to avoid (:mod:`.checks`: it would hide millimetre errors of the contacts); it is six
orders above the motion's own accuracy (docs/physics.md "Accuracy and its limits") and 1.2
times the largest of a resolved run above. Where no sample is left the check is not
evaluated (the samples do not resolve the motion): a failed check, like every check that
cannot be evaluated, never a PASS.
"""

from dataclasses import dataclass
import math

import numpy as np

__all__ = ['CAP', 'Resolution', 'resolve', 'UNRESOLVED']

#: The largest FD part of a tolerance, relative to the check's scale, at which an FD-limited
#: check still says something (module docstring).
CAP = 1e-3
#: The stencils reach two samples either side (differences.py).
_REACH = 2
_LISTED = 5                 # left-out stretches named; the rest are counted
_PHASE_SLACK = 1e-9         # rad: the flat vertices' phases are exact to rounding
UNRESOLVED = 'the samples do not resolve the motion here'


@dataclass
class Resolution:
    """The samples a check keeps and the detail line on those it left out.

    Attributes
    ----------
    keep : numpy.ndarray of bool
        Over the rows given to :func:`resolve`.
    note : str or None
        ``'left out ...'`` (None when nothing was left out); for a check with no sample left,
        the reason it is not evaluated.
    """

    keep: np.ndarray
    note: str | None

    @property
    def count(self):
        """Samples kept."""
        return int(np.sum(self.keep))

    @property
    def reason(self):
        """:attr:`note` without its leading ``'not evaluated: '``."""
        prefix = 'not evaluated: '
        return self.note[len(prefix):] if self.note.startswith(prefix) else self.note


def resolve(fd_tolerance, index, samples, body=None, minimum=1):
    """The rows whose own FD tolerance is within :data:`CAP`, and the note on the others.

    Parameters
    ----------
    fd_tolerance : numpy.ndarray
        Per row: the FD part of the check's tolerance (its margin × the FD error of a perfect
        recording) at that sample alone, relative to the check's scale; NaN where it cannot
        be estimated (the row is left out).
    index : numpy.ndarray of int
        The sample of each row (``samples.t[index]``), increasing.
    samples : Samples
        For the times and the recorded phases of the stretches left out.
    body : RollingBody, optional
        For the flat vertices of its laminae (``flat_vertex_phases``), named in the note.
    minimum : int
        Fewest rows a meaningful evaluation needs (2 for a drift against a reference).

    Returns
    -------
    Resolution
        ``note`` is the reason "not evaluated: ..." if fewer than ``minimum`` rows are kept.
    """
    fd_tolerance = np.asarray(fd_tolerance, dtype=float)
    keep = np.isfinite(fd_tolerance) & (fd_tolerance <= CAP)
    dropped = np.nonzero(~keep)[0]
    if dropped.size == 0:
        count = int(np.sum(keep))
        return Resolution(keep, None if count >= minimum else (
            f'not evaluated: {count} sample(s) with central differences, {minimum} needed '
            f'(the stencils reach {_REACH} samples either side): the recording is too short'))
    stretches = np.split(dropped, np.nonzero(np.diff(index[dropped]) > 1)[0] + 1)
    spans = [_span(samples.t, index[rows]) for rows in stretches]
    shown = ', '.join(spans[:_LISTED]) + (f' and {len(spans) - _LISTED} more'
                                           if len(spans) > _LISTED else '')
    vertices = _vertex_stretches(samples, index, stretches, body)
    finite = fd_tolerance[np.isfinite(fd_tolerance)]
    largest = f'{float(np.max(finite)):.3g}' if finite.size else 'not finite'
    if int(np.sum(keep)) < minimum:
        count = int(np.sum(keep))
        left = ('no sample left to judge' if count == 0 else
                f'{count} sample(s) left, {minimum} needed')
        hint = ''
        if not vertices and finite.size:    # smooth motion: the error falls as h⁴
            hint = (f'; the error falls as h⁴: a rate about '
                    f'{(float(np.max(finite)) / CAP) ** 0.25:.2g} × higher would resolve it')
        return Resolution(keep, (
            f'not evaluated: {UNRESOLVED}: at {dropped.size} of {fd_tolerance.size} samples '
            f'a perfect recording\'s FD error alone gives a tolerance above {CAP:g} of the '
            f'scale (up to {largest}){vertices}; {left}{hint}'))
    return Resolution(keep, (
        f'left out {dropped.size} of {fd_tolerance.size} samples in {len(spans)} '
        f'stretch(es) where the samples do not resolve the motion (a perfect recording\'s FD '
        f'error alone gives a tolerance above {CAP:g} of the scale, up to {largest})'
        f'{vertices}: t = {shown}'))


def _span(t, samples):
    first, last = float(t[samples[0]]), float(t[samples[-1]])
    return f'{first:.6g} s' if samples.size == 1 else f'{first:.6g} … {last:.6g} s'


def _vertex_stretches(samples, index, stretches, body):
    """', each around a flat vertex ...' if the stretches' stencils cross flat vertices."""
    vertices = np.asarray(body.flat_vertex_phases(), dtype=float)
    if vertices.size == 0:
        return ''
    phase = np.unwrap(samples.angles[:, 2])
    last = phase.size - 1
    crossing = 0
    for rows in stretches:
        low = phase[max(int(index[rows[0]]) - _REACH, 0):min(int(index[rows[-1]]) + _REACH,
                                                             last) + 1]
        lo, hi = float(np.min(low)) - _PHASE_SLACK, float(np.max(low)) + _PHASE_SLACK
        turns = np.arange(math.floor((lo - vertices.max()) / (2 * math.pi)),
                          math.floor((hi - vertices.min()) / (2 * math.pi)) + 1)
        images = (vertices[None, :] + 2 * math.pi * turns[:, None]).ravel()
        crossing += bool(np.any((images >= lo) & (images <= hi)))
    if crossing == 0:
        return ''
    which = ('it spans' if len(stretches) == 1 else 'each spans'
             if crossing == len(stretches) else f'{crossing} of them span')
    return (f'; {which} a flat-vertex crossing, where the body stops turning in u and its '
            'acceleration spikes')
