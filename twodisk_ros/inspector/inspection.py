"""``inspect_recording``: read a recording, join its samples, run the checks, summarise.

``twodisk-inspect FILE.mcap [--json] [--plot PNG]`` (or ``python -m twodisk_ros.inspect_mcap``)
reads an MCAP file written by the node (:mod:`twodisk_ros.recordings`), summarises it (topics,
types, counts, duration, rates, recorded parameters) and runs the checks of
:mod:`twodisk_ros.inspector.checks`. A truncated file (writer killed, no footer) is checked
on the part that was recovered; the report says how many messages and bytes that is.  A
damaged file (corrupt chunks, CRC mismatches, lost framing: see
:mod:`twodisk_ros.recordings.mcap_scan` for what is skipped) is checked on what could be read, and
the damage, with messages that do not decode, are problems of the ``inputs`` check.  A file
from which no channel, message or metadata can be read is not a recording
(:class:`RecordingError`).  How much of the *run* was recovered (samples against ``duration``
× ``rate``) is ``summary['run']`` (:mod:`twodisk_ros.inspector.completeness`); with it the
checks give the verdict PASS, FAIL or INCOMPLETE (:mod:`twodisk_ros.inspector.results`).
The body frame on ``/tf`` is checked against the poses by :mod:`twodisk_ros.inspector.tf_check`
(not applicable to recordings without /tf).
"""

import numpy as np

from ..recordings import RecordingError, read_recording
from ..recordings.reader import collector_paused
from .checks import run_checks
from .completeness import run_completeness
from .differences import kinetic_energy
from .engine_stretches import engine_check, engine_intervals, split_series
from .force_checks import FORCE_TITLES, force_checks
from .model import build_model
from .results import Check, Inspection, json_ready
from .series import (METADATA_NAME, TOPIC_TYPES, WRENCHES, extract_series, join_samples,
                     select_topics, topic_role)
from .tf_check import reads_topic, tf_check

__all__ = ['inspect_recording']

_DECODED = frozenset(TOPIC_TYPES)
#: the node's events (reset, pause, commands: node/scene_control.py); each begins a stretch
EVENTS = 'events'
_DAMAGE_LISTED = 5      # damaged parts named in the inputs check; the rest are counted


def _nothing_recovered(recording):
    """Why a recording from which nothing could be read is not a recording (one line)."""
    if recording.damage:
        more = len(recording.damage) - 1
        return (f'no recording recovered: {recording.damage[0]}'
                + (f' (and {more} more damaged parts)' if more else ''))
    if recording.total_bytes <= 8:
        return 'not a recording: the file ends after the MCAP magic'
    where = (f'in {recording.recovered_bytes} readable of {recording.total_bytes} bytes'
             if recording.truncated else f'in {recording.total_bytes} bytes')
    return f'not a recording: no channel, message or metadata record {where}'


def _input_problems(recording):
    """The damage and the undecodable messages of a recording, as problems of ``inputs``."""
    problems = [f'damaged: {line}' for line in recording.damage[:_DAMAGE_LISTED]]
    if len(recording.damage) > _DAMAGE_LISTED:
        problems.append(f'damaged: {len(recording.damage) - _DAMAGE_LISTED} more damaged '
                        f'parts (see the summary)')
    for topic, (count, reason) in sorted(recording.undecodable.items()):
        problems.append(f'{count} messages of {topic} could not be decoded (first: {reason})')
    if recording.orphans:
        problems.append(f'{recording.orphans} messages on channels defined nowhere readable')
    return problems


def _summary(recording, chosen, parameters, samples, model, t0_ns, t1_ns):
    truncated = recording.truncated
    topics = []
    times = {}
    for message in recording.messages:
        first, last = times.get(message.topic, (message.log_time_ns, message.log_time_ns))
        times[message.topic] = (min(first, message.log_time_ns), max(last, message.log_time_ns))
    for name in sorted(recording.topics):
        info = recording.topics[name]
        first, last = times.get(name, (None, None))
        rate = None
        if info.message_count > 1 and last > first:
            rate = (info.message_count - 1) / ((last - first) * 1e-9)
        topics.append({'topic': name, 'type': info.type_name, 'count': info.message_count,
                       'first_s': None if first is None else (first - t0_ns) * 1e-9,
                       'last_s': None if last is None else (last - t0_ns) * 1e-9,
                       'rate_hz': rate, 'role': next((r for r, t in chosen.items()
                                                      if t == name), None)})
    size = recording.total_bytes
    summary = {
        'file': recording.path,
        'size_bytes': size,
        'profile': recording.profile,
        'library': recording.library,
        'truncated': truncated,
        'damaged': recording.damaged,
        'damage': list(recording.damage),
        'undecodable': {topic: {'count': count, 'reason': reason}
                        for topic, (count, reason) in sorted(recording.undecodable.items())},
        'recovered': {'messages': len(recording.messages), 'bytes': recording.recovered_bytes,
                      'total_bytes': size,
                      'fraction': recording.recovered_bytes / size if size else None},
        'message_count': len(recording.messages),
        'start_ns': t0_ns,
        'end_ns': t1_ns,
        'duration_s': None if t0_ns is None else (t1_ns - t0_ns) * 1e-9,
        'topics': topics,
        'parameters': dict(parameters),
        'samples': 0 if samples is None else int(samples.stamp_ns.size),
        'mode': None if model is None else model.mode,
    }
    return json_ready(summary)


def inspect_recording(path):
    """Read a recording and run every check.

    Parameters
    ----------
    path : str or os.PathLike
        An MCAP file written by the ``roller`` node (or a truncated copy).

    Returns
    -------
    Inspection

    Raises
    ------
    RecordingError
        If the file cannot be read at all (missing, a directory, not MCAP, damaged).

    The cyclic garbage collector is paused meanwhile
    (:func:`~twodisk_ros.recordings.reader.collector_paused`): the messages make no cycles, they are
    freed when this returns, and with the collector on its full collections walked them all
    repeatedly (2 of 6 s for a 15 s, 1 kHz recording).
    """
    with collector_paused():
        return _inspect(path)


def _inspect(path):
    recording = read_recording(
        path, decode=lambda topic: topic_role(topic) in _DECODED or reads_topic(topic)
        or topic.rsplit('/', 1)[-1] == EVENTS)
    if recording.empty:
        raise RecordingError(f'cannot read recording {recording.path}: '
                             f'{_nothing_recovered(recording)}')
    problems = _input_problems(recording)
    chosen = select_topics(recording.topics, problems)
    series = extract_series(recording, chosen, problems)
    parameters = recording.metadata.get(METADATA_NAME)
    if parameters is None:
        problems.append(f'no metadata record {METADATA_NAME!r} (node parameters)')
        parameters = {}
    model = build_model(parameters, problems) if METADATA_NAME in recording.metadata else None
    log_times = [message.log_time_ns for message in recording.messages]
    t0_ns = min(log_times) if log_times else None
    t1_ns = max(log_times) if log_times else None
    stamp0 = min([int(s.stamp_ns.min()) for s in series.values() if len(s)] or [0])
    events = [(message.log_time_ns, str(getattr(message.msg, 'data', '')))
              for message in recording.messages if message.topic.rsplit('/', 1)[-1] == EVENTS]
    intervals = engine_intervals(events)     # contact_model hybrid: checked on their own
    whole, (series, engine) = series, split_series(series, intervals)
    samples = None
    try:
        samples = join_samples(series, stamp0)
    except ValueError as error:  # e.g. a zero quaternion
        problems.append(f'cannot use the poses: {" ".join(str(error).split())}')
    checks, motion = run_checks(recording, problems, chosen, series, samples, model,
                                parameters, events, whole)
    more, forces, force_series = _force_checks(series, samples, motion, model, parameters,
                                               recording.truncated)
    checks.extend(more)
    if intervals and model is not None:
        checks.append(engine_check(engine, intervals, parameters, model.dynamics.mass.mass
                                   * model.dynamics.gravity, model.body.size, model))
    more, tf_summary = tf_check(recording, whole, parameters, stamp0)
    checks.extend(more)
    summary = _summary(recording, chosen, parameters, samples, model, t0_ns, t1_ns)
    summary['tf'] = tf_summary
    summary['diagnostics'] = _diagnostics_summary(series)
    summary['contact_forces'] = forces
    summary['events'] = [{'t_s': (stamp - stamp0) * 1e-9, 'event': text}
                         for stamp, text in events]
    diagnostics = series.get('diagnostics')
    every = samples if not intervals else _joined(whole, stamp0)    # (engine samples too)
    summary['run'] = json_ready(run_completeness(
        recording, parameters, None if every is None else every.t,
        0 if diagnostics is None else len(diagnostics)))
    plot = _plot_series(series, samples, motion, model, stamp0)
    plot.update(force_series)
    return Inspection(summary, checks, plot, samples=samples, sources=series)


def _joined(series, stamp0):
    try:
        return join_samples(series, stamp0)
    except ValueError:      # (said of the rolling samples already)
        return None


def _force_checks(series, samples, motion, model, parameters, truncated):
    """:func:`force_checks`; an error inside makes ``contact_forces`` fail, never raises."""
    try:
        return force_checks(series, samples, motion, model, parameters, truncated)
    except Exception as error:  # noqa: BLE001 - reported as a failed check
        if not (any(role in series for role in WRENCHES) or 'friction' in parameters):
            return [], {'recorded': False}, {}
        reason = f'cannot be evaluated: {type(error).__name__}: {" ".join(str(error).split())}'
        return [Check('contact_forces', FORCE_TITLES['contact_forces'], False, None, None, '',
                      [reason])], {'recorded': True, 'error': reason}, {}


def _diagnostics_summary(series):
    diagnostics = series.get('diagnostics')
    if diagnostics is None or not len(diagnostics):
        return None
    energy = diagnostics.values['energy']
    drift = diagnostics.values['energy_drift']
    return json_ready({
        'topic': diagnostics.topic,
        'count': len(diagnostics),
        'energy_first': energy[0] if energy.size else None,
        'energy_last': energy[-1] if energy.size else None,
        'max_energy_drift': float(np.nanmax(np.abs(drift))) if np.any(np.isfinite(drift))
        else None,
    })


def _plot_series(series, samples, motion, model, stamp0):
    out = {}
    for role, key in (('contact_a', 'point'), ('contact_b', 'point'), ('pose', 'position')):
        if role in series and len(series[role]):
            out[role] = series[role].values[key]
            out[f't_{role}'] = (series[role].stamp_ns - stamp0) * 1e-9
    if 'diagnostics' in series and len(series['diagnostics']):
        out['t_diagnostics'] = (series['diagnostics'].stamp_ns - stamp0) * 1e-9
        out['energy_diagnostics'] = series['diagnostics'].values['energy']
    if motion is not None and motion.index.size:
        k = motion.index
        mass, gravity = model.dynamics.mass, model.dynamics.gravity
        kinetic = kinetic_energy(mass, motion.velocity, motion.angular_velocity,
                                  samples.rotation[k])
        out['t_fd'] = samples.t[k]
        out['kinetic_fd'] = kinetic
        out['potential_fd'] = mass.mass * gravity * samples.position_g[k, 2]
        out['energy_scale'] = np.array(model.dynamics.energy_scale)
        if np.all(np.isfinite(samples.rates[:, 2])):
            phase = np.unwrap(samples.angles[:, 2])
            out['t_model'] = samples.t
            out['energy_model'] = model.dynamics.energy(phase, samples.rates[:, 2])
    return out
