"""A section of docs/benchmarks.md that a benchmark script owns, between its own markers,
and where and when it was measured (:func:`provenance`)."""

import os
import platform
import subprocess
import time


def replace_section(path, text, begin, end):
    """Write ``text`` (which starts with ``begin`` and ends with ``end`` and a newline) into
    the file at ``path`` in place of the section between those markers, or at its end if the
    file has none (a missing file is created)."""
    old = open(path, encoding='utf-8').read() if os.path.exists(path) else ''
    if begin in old and end in old:
        new = old[:old.index(begin)] + text + old[old.index(end) + len(end) + 1:]
    else:
        new = old.rstrip('\n') + '\n\n' + text
    with open(path, 'w', encoding='utf-8') as out:
        out.write(new)


def _output(command):
    """A command's standard output, stripped ('' if it cannot run or fails)."""
    try:
        return subprocess.run(command, capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ''


def provenance(root):
    """(machine, date, commit) of a measurement: the CPU model, CPU count and Python version;
    the UTC date; the commit checked out at ``root``."""
    cpu = next((line.split(':', 1)[1].strip() for line in _output(['lscpu']).splitlines()
                if line.startswith('Model name')), platform.processor() or 'unknown CPU')
    machine = f'{cpu}, {_output(["nproc"]) or os.cpu_count()} CPUs, Python ' \
        f'{platform.python_version()}'
    date = _output(['date', '-u']) or time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    commit = _output(['git', '-C', root, 'rev-parse', 'HEAD']) or 'unknown'
    return machine, date, commit
