#!/usr/bin/env python3
"""The test suite's time on a fresh clone, as CI runs it (not a test).

Part of ``make bench`` (docs/benchmarks.md, section "The test suite"). The committed HEAD of
this checkout is cloned into a temporary directory and ``.ci/run`` is started there, as CI
starts it (``CI=true``, SIGINT and SIGHUP ignored by ``.ci/run`` itself), with
``PYTEST_ARGS=--durations=20`` so that pytest lists its 20 slowest tests. Reported: the set-up
(the clone's ``.venv``, tf2_msgs and Foxglove's readers, from the package caches), the tests
alone (pytest's own ``in N s``), the outcome counts, the 20 slowest tests, the machine's load
before and after (the figure is only meaningful on a quiet machine). The clone is removed at the
end; nothing in this checkout is touched.

Run: ``python benchmarks/suite_time.py [--quick]`` (``--quick``: the suite's collection only,
a smoke run of this script whose times are not the reported ones).
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: the README's promise for ``make test`` (tests alone, 2 cores, a quiet machine), in seconds
TARGET_SECONDS = 360.0

_SUMMARY = re.compile(r'^=+ (?P<counts>.*?) in (?P<seconds>[0-9.]+)s')
_DURATION = re.compile(r'^(?P<seconds>[0-9.]+)s (?P<phase>call|setup|teardown)\s+(?P<test>\S+)')


def _load():
    return ' '.join(f'{x:.2f}' for x in os.getloadavg())


def parse(output):
    """(tests-alone seconds, outcome counts text, [(seconds, phase, test)]) of pytest's output."""
    seconds, counts, slowest = None, '', []
    for line in output.splitlines():
        match = _SUMMARY.match(line)
        if match:
            seconds, counts = float(match['seconds']), match['counts']
        match = _DURATION.match(line)
        if match:
            slowest.append((float(match['seconds']), match['phase'], match['test']))
    return seconds, counts, slowest


def measure(quick=False, log=print):
    """Clone HEAD, run ``.ci/run`` there, return what :func:`report_lines` shows."""
    commit = subprocess.run(['git', '-C', ROOT, 'rev-parse', 'HEAD'], capture_output=True,
                            text=True, check=True).stdout.strip()
    folder = tempfile.mkdtemp(prefix='twodisk-suite-')
    try:
        clone = os.path.join(folder, 'twodisk_ros')
        subprocess.run(['git', 'clone', '--quiet', ROOT, clone], check=True)
        env = dict(os.environ, CI='true',
                   PYTEST_ARGS='--collect-only -q' if quick else '--durations=20')
        for name in ('PYTHONPATH', 'VIRTUAL_ENV', 'MAKEFLAGS', 'MFLAGS', 'MAKELEVEL'):
            env.pop(name, None)
        load_before = _load()
        log(f'suite: {commit[:7]} cloned into {clone}; .ci/run (load {load_before})')
        start = time.monotonic()
        result = subprocess.run(['bash', '.ci/run'], cwd=clone, env=env, capture_output=True,
                                text=True, stdin=subprocess.DEVNULL)
        total = time.monotonic() - start
        output = result.stdout + result.stderr
        seconds, counts, slowest = parse(output)
        log(f'suite: exit {result.returncode}, {counts or "no summary"}, tests '
            f'{seconds if seconds is not None else float("nan"):.0f} s of {total:.0f} s')
        return dict(commit=commit, quick=quick, exit=result.returncode, total=total,
                    tests=seconds, counts=counts, slowest=slowest[:20],
                    load_before=load_before, load_after=_load(), cores=os.cpu_count(),
                    tail='' if result.returncode == 0 else output[-3000:])
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def report_lines(data):
    """Markdown of the section "The test suite"."""
    if not data:
        return []
    out = ['## The test suite (`make test` on a fresh clone)\n']
    if data['quick']:
        out.append('A `--quick` run: the suite was only collected; no time is reported.\n')
        return out
    tests = data['tests']
    verdict = ('within' if tests is not None and tests <= TARGET_SECONDS else 'OVER')
    out.append(
        f'`.ci/run` (CI=true, SIGINT and SIGHUP ignored) in a fresh clone of '
        f'{data["commit"][:7]} on {data["cores"]} cores, exit {data["exit"]}: '
        f'{data["counts"] or "no summary line"}. Tests alone (pytest\'s own time): '
        f'**{tests:.0f} s** ({verdict} the {TARGET_SECONDS / 60:.0f}-minute target); all of '
        f'`make test` with the set-up of `.venv` from the package caches: {data["total"]:.0f} s. '
        f'Load average before {data["load_before"]}, after {data["load_after"]}.\n'
        if tests is not None else
        f'`.ci/run` in a fresh clone of {data["commit"][:7]} exited {data["exit"]} without '
        f'a pytest summary after {data["total"]:.0f} s.\n')
    if data['slowest']:
        out.append('The 20 slowest test phases:\n')
        out.append('| seconds | phase | test |')
        out.append('|---:|---|---|')
        out.extend(f'| {s:.1f} | {phase} | `{test}` |' for s, phase, test in data['slowest'])
        out.append('')
    if data['tail']:
        out.append('The end of its output:\n\n```\n' + data['tail'] + '\n```\n')
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--quick', action='store_true', help='collect only (a smoke run)')
    args = parser.parse_args(argv)
    print('\n'.join(report_lines(measure(quick=args.quick))))
    return 0


if __name__ == '__main__':
    sys.exit(main())
