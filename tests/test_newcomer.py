"""A newcomer's first hour: the README's shell commands, as written, work from any directory.

The Quick start promises that, with the venv active, the commands run "from any directory";
the blocks after it must not silently depend on the checkout (``config/…``, ``out/…``,
``.venv/bin/…``), and one block must not write the same output twice (the second command is
refused: outputs are never replaced without ``--overwrite``). Static checks of README.md; the
Quick start block itself runs for real in tests/test_entry_points.py.
"""

import re
import shlex
from pathlib import Path

from package_helpers import console_scripts

REPO = Path(__file__).resolve().parents[1]
README = (REPO / 'README.md').read_text(encoding='utf-8')
#: the checkout-relative prefixes that exist only when the shell is in the checkout
CHECKOUT_ONLY = ('config/', 'out/', '.venv/', './')
#: options naming an output file
OUTPUT_OPTIONS = ('-o', '--out', '--plot', '--csv', '--npz')


def _console_scripts():
    return set(console_scripts())


def _commands():
    """(block index, words) of every command line of the README's ```sh blocks that runs a
    console script or ``python`` (continuation lines joined, comments dropped)."""
    scripts = _console_scripts() | {'python'}
    blocks = re.findall(r'^```sh[ \t]*\n(.*?)^```', README, re.MULTILINE | re.DOTALL)
    found = []
    for index, block in enumerate(blocks):
        for line in block.replace('\\\n', ' ').splitlines():
            words = shlex.split(line, comments=True)
            if words and Path(words[0]).name in scripts:
                found.append((index, words))
    return found


def test_readme_commands_do_not_need_the_checkout_as_working_directory():
    commands = _commands()
    assert len(commands) >= 8         # the Quick start, animation and sweep blocks
    bad = [' '.join(words) for _, words in commands
           if any(word.startswith(CHECKOUT_ONLY) for word in words)]
    # before: 'twodisk-animate out/oloid.mcap …', '… --params-file config/oloid.yaml …',
    # '.venv/bin/twodisk-sweep …' (no such file outside the checkout)
    assert bad == []


def test_readme_blocks_do_not_write_one_output_twice():
    written = {}
    for index, words in _commands():
        if '--overwrite' in words or any('overwrite:=true' in word for word in words):
            continue
        for option, value in zip(words, words[1:]):
            if option in OUTPUT_OPTIONS:
                # before: two twodisk-animate lines of one block both wrote oloid.gif
                assert (index, value) not in written, (
                    f'{value} written by {written[(index, value)]!r} and {" ".join(words)!r}')
                written[(index, value)] = ' '.join(words)


def test_parameter_table_into_a_closed_pipe_has_no_traceback():
    """``python -m twodisk_ros.run.parameters | head -3`` printed a BrokenPipeError
    traceback (the reader closes the pipe before the table is written)."""
    import os
    import subprocess
    import sys
    read, write = os.pipe()
    os.close(read)                # the reader is gone before the table is written
    try:
        result = subprocess.run([sys.executable, '-m', 'twodisk_ros.run.parameters'],
                                stdout=write, stderr=subprocess.PIPE, text=True, timeout=60,
                                env=dict(os.environ, PYTHONPATH=str(REPO)))
    finally:
        os.close(write)
    assert 'Traceback' not in result.stderr and result.stderr == ''
    assert result.returncode == 0
