"""Is the whole run in the file? Recovered samples compared with what the run was meant to hold.

The ``roller`` node publishes sample k (k = 0, 1, ...) at simulated time k / rate and, with a
``duration`` d > 0, ends after tick ⌊d · rate⌋ (``Roller._end_tick``): a finished run holds
``⌊d · rate + 1e-9⌋ + 1`` samples, t = 0 … d.  The ``duration`` and ``rate`` are read-only
node parameters, recorded in the ``twodisk_ros`` metadata record, which the node writes when
the file is opened (so a cut file still has it) and again when it closes it.

A run is *complete* when

- the file is complete: the writer closed it (footer present, ``truncated`` False) and no
  part of it is damaged; and
- no sample is missing between the first and the last one recovered.

A complete file with fewer samples than the duration asks for is a run *stopped early*
(SIGINT or SIGTERM: the node then closes the file normally, ``rosbag2`` metadata with the
shorter duration); it is complete, its checks decide.  A run with duration 0 (until stopped)
has no expected count: only the completeness of the file matters.
"""

import math

__all__ = ['DIAGNOSTICS_RATE', 'expected_samples', 'run_completeness']

#: Hz of simulated time: the node's ``/diagnostics`` (one at t = 0, 1, 2, ... s).
DIAGNOSTICS_RATE = 1.0


def _positive(parameters, name, allow_zero=False):
    """A recorded parameter as a finite float (> 0, or ≥ 0 with ``allow_zero``), else None."""
    try:
        value = float(parameters.get(name))
    except (TypeError, ValueError):
        return None
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        return None
    return value


def expected_samples(duration, rate):
    """Samples a finished run of ``duration`` s at ``rate`` Hz holds (None if duration is 0).

    Ticks 0 … ⌊duration · rate⌋, both included, as the node counts them.
    """
    if duration is None or rate is None or duration <= 0:
        return None
    return int(math.floor(duration * rate + 1e-9)) + 1


def run_completeness(recording, parameters, sample_t, diagnostics_count):
    """What part of the run the recovered samples are (a JSON-ready dict).

    Parameters
    ----------
    recording : twodisk_ros.recordings.Recording
        The file read (``truncated``, ``damage``).
    parameters : dict of str to str
        The ``twodisk_ros`` metadata (``duration`` s, ``rate`` Hz).
    sample_t : numpy.ndarray or None
        Times of the recovered samples (s from the first stamp of the recording).
    diagnostics_count : int
        ``/diagnostics`` messages recovered.

    Returns
    -------
    dict
        ``complete`` (the run is all there), ``file_complete`` (closed by the writer, not
        damaged), ``truncated``, ``damaged``, ``duration_s`` and ``rate_hz`` (recorded; None
        if missing), ``expected_samples`` (None for duration 0 or unknown),
        ``recovered_samples``, ``share`` (recovered / expected, of the run), ``first_s``,
        ``last_s`` (s), ``missing_inside`` (samples missing between the first and the last
        recovered, from the rate; None without a rate), ``stopped_early`` (complete file
        ending before the duration), ``expected_diagnostics``, ``recovered_diagnostics``
        and ``reason`` (one phrase: why the run is not complete, else '').
    """
    duration = _positive(parameters, 'duration', allow_zero=True)
    rate = _positive(parameters, 'rate')
    expected = expected_samples(duration, rate)
    count = 0 if sample_t is None else int(len(sample_t))
    first = float(sample_t[0]) if count else None
    last = float(sample_t[-1]) if count else None
    missing_inside = None
    if rate is not None and count:
        missing_inside = max(0, int(round((last - first) * rate)) + 1 - count)
    file_complete = not recording.truncated and not recording.damage
    if not file_complete:
        reason = ('the file is damaged' if recording.damage and not recording.truncated
                  else 'the file is cut (no footer: the writer did not close it)'
                  if not recording.damage else 'the file is cut and damaged')
    elif missing_inside:
        reason = f'{missing_inside} samples missing inside the run'
    elif not count:
        reason = 'no sample recovered'
    else:
        reason = ''
    stopped_early = bool(file_complete and expected is not None and count
                         and count < expected and not missing_inside)
    expected_diagnostics = (None if duration is None or duration <= 0 else
                            int(math.floor(duration * DIAGNOSTICS_RATE + 1e-9)) + 1)
    return {
        'complete': not reason,
        'file_complete': file_complete,
        'truncated': bool(recording.truncated),
        'damaged': bool(recording.damage),
        'duration_s': duration,
        'rate_hz': rate,
        'expected_samples': expected,
        'recovered_samples': count,
        'share': None if expected is None else count / expected,
        'first_s': first,
        'last_s': last,
        'missing_inside': missing_inside,
        'stopped_early': stopped_early,
        'expected_diagnostics': expected_diagnostics,
        'recovered_diagnostics': int(diagnostics_count),
        'reason': reason,
    }
