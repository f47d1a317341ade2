"""Shared by the reader tests: decoding a recording with Foxglove's own readers (Node.js).

``tests/foxglove/decode.mjs`` reads the file with ``@mcap/core`` (and ``@mcap/support``'s
decompressors) and decodes each message with ``@foxglove/rosmsg2-serialization`` from the
``ros2msg`` schema stored in the file, as the Foxglove app does.  ``make foxglove-readers``
installs them (``npm ci`` from the lock file); without them the tests skip, except under CI.
"""

import json
import os
from pathlib import Path
import shutil
import struct
import subprocess

import pytest

FOXGLOVE = Path(__file__).resolve().parent / 'foxglove'


def _from_node(value):
    """Undo decode.mjs's JSON encoding: "f:<float64 bits>" and "i:<bigint>" back to numbers."""
    if isinstance(value, dict):
        return {k: _from_node(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_from_node(v) for v in value]
    if isinstance(value, str) and value[:2] == 'f:':
        return struct.unpack('<d', bytes.fromhex(value[2:]))[0]
    if isinstance(value, str) and value[:2] == 'i:':
        return int(value[2:])
    return value


def foxglove_decode(path, *topics):
    """Every message (of ``topics``, or all) as Foxglove's readers decode it.

    Returns
    -------
    list of dict
        ``topic``, ``schema``, ``logTime`` (int ns), ``trailing`` (bytes left after the
        last field) and ``message`` (nested dicts and lists; every number a Python float
        with the decoded float64's bits, 64-bit integers as int).
    """
    installed = (FOXGLOVE / 'node_modules' / '@foxglove' / 'rosmsg2-serialization').is_dir()
    if shutil.which('node') is None or not installed:
        if os.environ.get('CI', '').lower() in ('1', 'true', 'yes'):
            pytest.fail('Foxglove readers missing: make foxglove-readers')
        pytest.skip('Foxglove readers not installed (make foxglove-readers)')
    result = subprocess.run(['node', str(FOXGLOVE / 'decode.mjs'), str(path), *topics],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    return [_from_node(json.loads(line)) for line in result.stdout.splitlines()]
