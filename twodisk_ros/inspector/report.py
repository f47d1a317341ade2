"""The human-readable report of ``twodisk-inspect``."""

import textwrap

from .status import FAIL, INCOMPLETE, PROG
from .series import METADATA_NAME

__all__ = ['PROG', 'format_report', 'run_phrase']

_DAMAGE_SHOWN = 10


def _size(nbytes):
    for unit in ('B', 'KiB', 'MiB', 'GiB'):
        if nbytes < 1024 or unit == 'GiB':
            return f'{nbytes:.0f} {unit}' if unit == 'B' else f'{nbytes:.1f} {unit}'
        nbytes /= 1024
    return f'{nbytes} B'


def _value(value, unit):
    if value is None:
        return 'n/a'
    text = f'{value:.3g}'
    return f'{text} {unit}' if unit else text


def _count(number):
    """An integer with its thousands apart: 10001 → '10 001'."""
    return f'{number:,}'.replace(',', ' ')


def _percent(part, whole):
    """part / whole in %, one decimal; never 100.0 for a part short of the whole, nor 0.0."""
    share = 100.0 * part / whole
    text = f'{share:.1f}'
    if part < whole and text in ('100.0', '100'):
        text = '99.9'
    elif 0 < part and text == '0.0':
        text = '0.1'
    return f'{text} %'


def run_phrase(run):
    """The share of the run recovered, in words (``summary['run']``; '' without it).

    E.g. ``recovered 6 667 of 10 001 samples of the run (66.7 %), t = 0 … 6.66 s of 10 s``.
    """
    if not run:
        return ''
    count, expected = run['recovered_samples'], run['expected_samples']
    span = (f't = {run["first_s"]:.6g} … {run["last_s"]:.6g} s' if count else 'no sample')
    if expected is not None:
        return (f'recovered {_count(count)} of {_count(expected)} samples of the run '
                f'({_percent(count, expected)}), {span} of {run["duration_s"]:.6g} s')
    why = ('duration 0: the run was to go on until stopped, so no count is expected'
           if run['duration_s'] == 0 else 'no recorded duration and rate: no expected count')
    return f'recovered {_count(count)} samples, {span} ({why})'


def _run_lines(run):
    """The ``run:`` line: the share of the run, completeness of the file, diagnostics."""
    if not run:
        return []
    text = run_phrase(run)
    if run['stopped_early']:
        text += ('; stopped early, the file is complete (closed by the node, as after '
                 'SIGINT or SIGTERM)')
    elif run['complete']:
        text += '; the file is complete'
    else:
        text += f'; INCOMPLETE: {run["reason"]}'
    diagnostics = run['recovered_diagnostics']
    if run['expected_diagnostics'] is not None and not run['stopped_early']:
        text += f'; {diagnostics} of {run["expected_diagnostics"]} diagnostics'
    else:
        text += f'; {diagnostics} diagnostics'
    return textwrap.wrap(f'run: {text}', 99, initial_indent='  ', subsequent_indent='    ')


def _result_line(inspection):
    """``result: PASS|FAIL|INCOMPLETE (...)``."""
    checks, run = inspection.checks, inspection.summary.get('run') or {}
    failed = [check.name for check in checks if not check.passed]
    verdict = inspection.verdict
    if verdict == FAIL:
        text = (f'result: FAIL ({len(failed)} of {len(checks)} checks failed: '
                f'{", ".join(failed)})')
        if not inspection.complete:
            text += f'; the run is also INCOMPLETE: {run["reason"]}, {run_phrase(run)}'
        return text
    if verdict == INCOMPLETE:
        return (f'result: INCOMPLETE (all {len(checks)} checks passed on the recovered part, '
                f'but {run["reason"]}: {run_phrase(run)})')
    text = f'result: PASS (all {len(checks)} checks passed)'
    if run.get('stopped_early'):
        text += f'; the run was stopped early, at t = {run["last_s"]:.6g} s of ' \
                f'{run["duration_s"]:.6g} s, and its file is complete'
    return text


def _extremes(info):
    friction = info.get('friction')
    mu = 'inf' if friction is None else f'{friction:g}'
    return (f'min N_A = {_value(info["min_normal_a"], "N")}, min N_B = '
            f'{_value(info["min_normal_b"], "N")}, max mu_required = '
            f'{_value(info["max_mu_required"], "")} (mu = {mu}), {len(info["stretches"])} '
            f'invalid stretch(es)')


def _force_lines(info):
    """The ``contact forces:`` section (nothing for a report without that summary)."""
    if not info:
        return []
    if not info.get('recorded'):
        lines = ['contact forces: not recorded']
        lines.extend(textwrap.wrap(info.get('note', ''), 99, initial_indent='  ',
                                   subsequent_indent='    '))
        poses = info.get('from_poses')
        if poses:
            lines.extend(textwrap.wrap(f'from the poses (information): {_extremes(poses)}', 99,
                                       initial_indent='  ', subsequent_indent='    '))
            for stretch in poses['stretches'][:_DAMAGE_SHOWN]:
                lines.append(f'    - t = {stretch["start_s"]:.6g} … {stretch["end_s"]:.6g} s: '
                             f'{stretch["reason"]}')
        return lines
    if 'stretches' not in info:
        return ['contact forces: recorded (not evaluated, see the checks)']
    return [f'contact forces: from {info["source"]}, {info["samples"]} samples',
            f'  {_extremes(info)}']


def _tf_lines(info):
    """The ``tf:`` line (nothing for a report without that summary)."""
    if not info:
        return []
    if not info.get('recorded'):
        return ['tf: not recorded, check not applicable (a recording made before /tf)']
    if 'transforms' not in info:
        return [f'tf: recorded on {info["topic"]} (not evaluated, see the checks)']
    parents = ' then '.join(info.get('parents') or [info['parent']])
    children = ' then '.join(info.get('children') or [info['child']])
    return [f'tf: {info["transforms"]} transforms {parents} → {children} on '
            f'{info["topic"]}, {info["pose_stamps"]} pose stamps']


def format_report(inspection):
    """The human-readable report of an :class:`Inspection` (several lines, no final newline)."""
    s = inspection.summary
    lines = [f'{PROG}: {s["file"]}',
             f'  file: {_size(s["size_bytes"])}, MCAP profile {s["profile"]!r}, '
             f'written by {s["library"] or "?"}']
    rec = s['recovered']
    fraction = rec['fraction'] if rec['fraction'] is not None else 0.0
    recovered = (f'read {rec["messages"]} messages from {_count(rec["bytes"])} of the '
                 f'{_count(rec["total_bytes"])} bytes in the file ({100 * fraction:.1f} % '
                 f'of this file, not of the run); the checks below are of that part')
    if s.get('damaged'):
        cut = ', and TRUNCATED (no footer)' if s['truncated'] else ''
        parts = f'{len(s["damage"])} damaged part' + ('s' if len(s['damage']) > 1 else '')
        lines.append(f'  DAMAGED ({parts} skipped{cut}): {recovered}')
        for line in s['damage'][:_DAMAGE_SHOWN]:
            lines.extend(textwrap.wrap(line, 99, initial_indent='    - ',
                                       subsequent_indent=' ' * 6))
        if len(s['damage']) > _DAMAGE_SHOWN:
            lines.append(f'    ... and {len(s["damage"]) - _DAMAGE_SHOWN} more (--json lists '
                         f'them all)')
    elif s['truncated']:
        lines.append(f'  TRUNCATED (no footer: the writer did not close it): {recovered}')
    for topic, bad in (s.get('undecodable') or {}).items():
        lines.append(f'  UNDECODABLE: {bad["count"]} messages of {topic} ({bad["reason"]})')
    if s['duration_s'] is not None:
        lines.append(f'  duration: {s["duration_s"]:.3f} s, {s["message_count"]} messages on '
                     f'{len(s["topics"])} topics')
    else:
        lines.append('  no messages')
    lines.extend(_run_lines(s.get('run')))
    lines.append('topics:')
    width = max([len(t['topic']) for t in s['topics']] + [5])
    type_width = max([len(t['type']) for t in s['topics']] + [4])
    for topic in s['topics']:
        rate = f'{topic["rate_hz"]:9.3f} Hz' if topic['rate_hz'] is not None else '        -'
        lines.append(f'  {topic["topic"]:<{width}}  {topic["type"]:<{type_width}}  '
                     f'{topic["count"]:7d}  {rate}')
    lines.append(f'parameters (metadata {METADATA_NAME!r}):')
    if s['parameters']:
        items = [f'{key} = {value}' for key, value in s['parameters'].items()]
        row = '  '
        for item in items:
            if len(row) + len(item) > 96 and row.strip():
                lines.append(row.rstrip())
                row = '  '
            row += item + '; '
        lines.append(row.rstrip().rstrip(';'))
    else:
        lines.append('  (none)')
    if s.get('diagnostics'):
        d = s['diagnostics']
        lines.append(f'diagnostics: {d["count"]} messages, energy {_value(d["energy_first"], "J")}'
                     f' → {_value(d["energy_last"], "J")}, max recorded energy_drift '
                     f'{_value(d["max_energy_drift"], "")}')
    else:
        lines.append('diagnostics: none recorded')
    lines.append(f'samples: {s["samples"]} stamps shared by pose, contacts and rolling_state'
                 + (f' ({s["mode"]} mode)' if s['mode'] else ''))
    lines.extend(_force_lines(s.get('contact_forces')))
    lines.extend(_tf_lines(s.get('tf')))
    lines.append('checks:')
    for check in inspection.checks:
        lines.append(f'  {check.status}  {check.name:<14} {_value(check.value, check.unit)} '
                     f'(tolerance {_value(check.tolerance, check.unit)})  {check.title}')
        for line in check.detail:
            lines.extend(textwrap.wrap(line, 99, initial_indent=' ' * 8,
                                       subsequent_indent=' ' * 10))
    lines.append(_result_line(inspection))
    return '\n'.join(lines)
