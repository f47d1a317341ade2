"""The stamp checks of ``twodisk-inspect``: ``timestamps`` and ``stamps`` (:mod:`.checks`).

``timestamps``
    stamps of pose, contacts and rolling state increase with no gaps: every interval within
    1 % of 1/rate (the recorded ``rate``; the median interval if it is missing).
``stamps``
    header stamp = log time = publish time, and pose, contacts and rolling state carry the same
    stamps (the tail cut off a truncated file excepted); tolerance 0 mismatches.
"""

import math

import numpy as np

from .results import Check, json_ready
from .series import SAMPLED, STAMP_TOLERANCE

__all__ = ['STAMP_TITLES', 'check_stamps', 'check_timestamps', 'nominal_step_ns']

#: What each check verifies, in words.
STAMP_TITLES = {
    'timestamps': 'stamps increasing with no gaps (pose, contacts, rolling_state)',
    'stamps': 'consistent stamps across messages and topics',
}


def _check(name, value, tolerance, unit='', detail=()):
    passed = value is not None and tolerance is not None and bool(value <= tolerance)
    return Check(name, STAMP_TITLES[name], passed, json_ready(value), json_ready(tolerance),
                 unit, list(detail))


def nominal_step_ns(series, model):
    """1/rate in ns from the recorded rate, else the median stamp interval; and its source."""
    if model is not None and model.rate:
        return 1e9 / model.rate, f'1/rate, rate = {model.rate:g} Hz'
    intervals = [np.diff(series[role].stamp_ns) for role in SAMPLED
                 if role in series and len(series[role]) > 1]
    if not intervals:
        return None, 'no intervals'
    return float(np.median(np.concatenate(intervals))), 'median interval (no valid rate)'


def check_timestamps(series, step_ns, source):
    """The ``timestamps`` :class:`Check`: intervals against ``step_ns`` (ns) of ``source``."""
    roles = [role for role in SAMPLED if role in series]
    if step_ns is None or not roles:
        return _check('timestamps', None, STAMP_TOLERANCE, '', ['too few messages'])
    detail, worst = [], 0.0
    for role in roles:
        stamps = series[role].stamp_ns
        if stamps.size < 2:
            detail.append(f'{series[role].topic}: {stamps.size} message(s), no interval')
            worst = math.inf
            continue
        intervals = np.diff(stamps)
        deviation = np.abs(intervals - step_ns) / step_ns
        bad = np.nonzero(deviation > STAMP_TOLERANCE)[0]
        worst = max(worst, float(np.max(deviation)))
        line = f'{series[role].topic}: {stamps.size} stamps'
        if bad.size:
            first = int(bad[0])
            line += (f', {bad.size} bad intervals, the first {intervals[first] * 1e-9:.6g} s '
                     f'after t = {stamps[first] * 1e-9:.6g} s')
            if np.any(intervals <= 0):
                line += f', {int(np.sum(intervals <= 0))} not increasing'
        detail.append(line)
    detail.append(f'nominal interval {step_ns * 1e-9:.6g} s ({source}); '
                  f'tolerance {STAMP_TOLERANCE:.0%} of it')
    return _check('timestamps', worst, STAMP_TOLERANCE, '', detail)


def check_stamps(series, truncated):
    """The ``stamps`` :class:`Check` (``truncated``: the file's cut tail is not compared)."""
    roles = [role for role in SAMPLED if role in series and len(series[role])]
    detail, mismatches = [], 0
    for role in roles:
        data = series[role]
        count = int(np.sum(data.stamp_ns != data.log_ns) + np.sum(data.log_ns != data.publish_ns))
        if count:
            detail.append(f'{data.topic}: {count} header stamp / log time / publish time '
                          'mismatches')
        mismatches += count
    if roles:
        sets = {role: np.unique(series[role].stamp_ns) for role in roles}
        union = np.unique(np.concatenate(list(sets.values())))
        if truncated:
            union = union[union <= min(stamps[-1] for stamps in sets.values())]
        for role, stamps in sets.items():
            lacking = union.size - np.intersect1d(union, stamps).size
            if lacking:
                detail.append(f'{series[role].topic}: lacks {lacking} stamps of the others')
            mismatches += lacking
    if not detail:
        detail.append('pose, contacts and rolling_state share their stamps; header stamp = '
                      'log time = publish time'
                      + (' (the tail cut by the truncation ignored)' if truncated else ''))
    return _check('stamps', mismatches, 0, 'mismatches', detail)
