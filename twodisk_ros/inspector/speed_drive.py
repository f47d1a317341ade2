"""The speed drive's rule, from the recording alone (the ``speed_drive`` check).

Under the speed drive the signed rolling speed Ω = |ω| sgn(u̇) follows the command in force
by the documented first-order lag (README "Scenes", node/scene_control.py)

    dΩ/dt = (Ω_cmd − Ω)/T,   so   Ω(t) = Ω_cmd + (Ω(t_r) − Ω_cmd) e^{−(t − t_r)/T}

from any time t_r of a stretch on which the command does not change (the law is the same
from any of its points). The stretches are those of the node's events
(:func:`~twodisk_ros.inspector.balance.scene_timeline`): a stretch under the speed drive with
a command (``command speed <value>``) follows that value; before the first command (and
after a reset or a change of drive) the drive holds the speed it starts from, Ω_cmd = Ω(t_r);
mode kinematic holds it throughout. T is ``drive_lag`` of the recorded parameters, with the
``scene drive_lag <old> -> <new>`` events undone back to the start.

|ω| comes from the central differences of the recorded poses (:mod:`.differences`), u̇'s
sign from rolling_state; t_r is each stretch's first sample with a difference, so the
reference's own difference error enters once more. The claim checked: the recorded motion
obeys the lag rule to the accuracy the poses allow, i.e. the largest |Ω − Ω_rule| / Ω_s
(Ω_s = max(|Ω| over the stretches, 1 rad/s)) is within 2 × FD_MARGIN × the difference error
of |ω| (the model's poses at the recorded phases against the exact |ω_u(u)| |u̇|, as the
``angular_speed`` check) + round-off and the solver's allowance (as ``energy``), on the
samples whose own difference error keeps that within 1e-3 (:mod:`.resolution`; t_r is then
the first of them).
"""

import math
import re

import numpy as np

from .resolution import resolve
from .results import Check, json_ready

__all__ = ['TITLE', 'speed_drive_check', 'speed_stretches']

TITLE = ('speed drive: |ω| from the poses follows the first-order lag rule after each '
         'command (events)')
_LAG = re.compile(r'drive_lag (\S+) -> ([^,\s]+)')


def _lags(parameters, events):
    """[(start stamp or None, T (s))]: ``drive_lag`` over the run, from the scene events."""
    lag = float(parameters.get('drive_lag', 0.1))
    for _, text in reversed(events):
        if text.startswith('scene '):
            for old, _new in _LAG.findall(text):
                lag = float(old)
    lags = [(None, lag)]
    for stamp, text in events:
        for _old, new in _LAG.findall(text) if text.startswith('scene ') else ():
            lags.append((stamp, float(new)))
    return lags


def _lag_at(lags, stamp):
    lag = lags[0][1]
    for start, value in lags[1:]:
        if start <= stamp:
            lag = value
    return lag


def speed_stretches(samples, motion, model, timeline, lags, keep=None):
    """Residuals of the lag rule on every stretch under the speed drive.

    ``keep`` (bool over the rows of ``motion.index``, :mod:`.resolution`): the samples the
    differences resolve; the others are left out and t_r is each stretch's first sample kept
    (the rule holds from any of its points).

    Returns (rows, skipped): rows of (t (s), Ω recorded, Ω by the rule, |ω_fd − ω_exact| of
    the model's poses) arrays per stretch with at least two differenced samples; skipped:
    lines on the speed stretches too short to check.
    """
    k = motion.index
    stamps = samples.stamp_ns[k]
    signed, fd_errors = _speeds(samples, motion, model)
    keep = np.ones(k.size, dtype=bool) if keep is None else keep
    starts = [-math.inf if s is None else s for s, _ in timeline] + [math.inf]
    rows, skipped = [], []
    for (start, state), end in zip(zip(starts, (s for _, s in timeline)), starts[1:]):
        if state['active'] != 'speed':
            continue
        inside = np.nonzero((stamps >= start) & (stamps < end) & keep)[0]
        if inside.size < 2:
            if start != -math.inf or end != math.inf:
                skipped.append(f'{inside.size} differenced sample(s) in the stretch from '
                               f'stamp {start}')
            continue
        t = samples.t[k[inside]]
        lag = _lag_at(lags, int(stamps[inside[0]]))
        held = state['command'] is None or model.mode == 'kinematic'
        target = signed[inside[0]] if held else state['command']
        rule = target + (signed[inside[0]] - target) * np.exp(-(t - t[0]) / lag)
        rows.append((t, signed[inside], rule, fd_errors[inside]))
    return rows, skipped


def _speeds(samples, motion, model):
    """(Ω = |ω| sgn(u̇) from the recorded poses, |ω_fd − ω_exact| of the model's poses) at
    the rows of ``motion.index`` (rad/s)."""
    k = motion.index
    omega = np.linalg.norm(motion.angular_velocity, axis=1)
    model_omega = np.linalg.norm(motion.model_angular_velocity, axis=1)
    phase = np.unwrap(samples.angles[:, 2])[k]
    rate = samples.rates[k, 2]
    with np.errstate(invalid='ignore'):
        exact = np.abs(np.asarray(model.dynamics.angular_speed_per_phase(phase)) * rate)
    return omega * np.where(rate < 0, -1.0, 1.0), np.abs(model_omega - exact)


def _resolution(samples, motion, model, timeline, margin):
    """The samples whose own FD error is within the cap (:func:`.resolution.resolve`):
    2 × margin × |ω_fd − ω_exact| / Ω_s, Ω_s = max(|Ω| under the speed drive, 1 rad/s)."""
    k = motion.index
    signed, fd_errors = _speeds(samples, motion, model)
    stamps = samples.stamp_ns[k]
    starts = [-math.inf if s is None else s for s, _ in timeline] + [math.inf]
    driven = np.zeros(k.size, dtype=bool)
    for (start, state), end in zip(zip(starts, (s for _, s in timeline)), starts[1:]):
        if state['active'] == 'speed':
            driven |= (stamps >= start) & (stamps < end)
    scale = max(1.0, float(np.max(np.abs(signed[driven]))) if np.any(driven) else 1.0)
    return resolve(2 * margin * fd_errors / scale, k, samples, model.body, minimum=2)


def speed_drive_check(samples, motion, model, timeline, parameters, events, margin,
                      roundoff):
    """The ``speed_drive`` :class:`Check`, or None if no stretch runs under the speed drive.

    ``margin``: the tolerance's multiple of the FD error (checks.FD_MARGIN); ``roundoff``:
    the relative error always allowed (the differences' round-off and the solver's).
    """
    if not any(state['active'] == 'speed' for _, state in timeline):
        return None
    kept = _resolution(samples, motion, model, timeline, margin)
    if kept.count < 2:
        return Check('speed_drive', TITLE, False, None, None, '', [kept.note])
    rows, skipped = speed_stretches(samples, motion, model, timeline,
                                    _lags(parameters, events), kept.keep)
    if not rows:
        return Check('speed_drive', TITLE, False, None, None, '', [
            'not evaluated: no stretch under the speed drive with two differenced samples'] +
            skipped[:3] + ([] if kept.note is None else [kept.note]))
    scale = max(1.0, max(float(np.max(np.abs(r[1]))) for r in rows))
    errors = [np.abs(r[1] - r[2]) / scale for r in rows]
    worst_row = int(np.argmax([float(np.max(e)) for e in errors]))
    worst = int(np.argmax(errors[worst_row]))
    value = float(errors[worst_row][worst])
    fd_error = max(float(np.max(r[3])) for r in rows) / scale
    tolerance = 2 * margin * fd_error + roundoff
    t = rows[worst_row][0]
    passed = bool(value <= tolerance)
    return Check('speed_drive', TITLE, passed, json_ready(value), json_ready(tolerance), '', [
        f'max |Ω − Ω_rule| / Ω_s over {len(rows)} stretch(es) under the speed drive '
        f'(Ω_s = {scale:.4g} rad/s; Ω_rule = Ω_cmd + (Ω(t_r) − Ω_cmd) e^(−(t − t_r)/T), t_r '
        f'the stretch\'s first differenced sample, T = drive_lag); worst at t = '
        f'{t[worst]:.6g} s in the stretch from t = {t[0]:.6g} s',
        f'FD-limited: |ω| of the model\'s poses at the recorded phases is within '
        f'{fd_error:.3g} of the exact |ω_u(u)| |u̇|; tolerance 2 × {margin:g} × that (the '
        f'sample and the reference) + {roundoff:.3g} (round-off and solver)'] + [
        f'not checked: {line}' for line in skipped[:5]] + (
        [] if kept.note is None else [kept.note]))
