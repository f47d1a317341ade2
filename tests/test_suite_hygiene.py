"""The suite's own manners: it signals only what it started, however it was started.

A suite run with SIGINT ignored (``make test &`` from a script, ``nohup``, some CI runners)
once SIGKILLed itself: a child that raised SIGINT on itself saw nothing happen and fell
through to killing its process group, which was pytest's. These checks read the tests' source:
every group kill names a group that the same file started in a session of its own, and no
test reaches for its own group or for every process (pid 0 or negative pids).
"""

from pathlib import Path
import re

TESTS = Path(__file__).resolve().parent
SOURCES = sorted(p for p in TESTS.glob('*.py') if p.name != Path(__file__).name)


def test_a_group_is_signalled_only_where_the_file_made_it_a_session():
    for path in SOURCES:
        text = path.read_text(encoding='utf-8')
        kills = re.findall(r'os\.killpg\(([^,]+),', text)
        if kills:
            assert 'start_new_session=True' in text or 'os.setsid' in text, (
                f'{path.name} kills process groups but starts none in a session of its own')
        for target in kills:
            assert 'getpgrp' not in target and target.strip() not in ('0', 'os.getpgid(0)'), (
                f'{path.name}: os.killpg({target}, ...) signals the test run itself')


def test_no_signal_goes_to_every_process_or_to_the_callers_group():
    for path in SOURCES:
        for target in re.findall(r'os\.kill\(([^,]+),', path.read_text(encoding='utf-8')):
            assert target.strip() not in ('0', '-1') and not target.strip().startswith('-'), (
                f'{path.name}: os.kill({target}, ...) reaches processes it did not start')


def test_a_child_that_raises_sigint_on_itself_installs_the_handler_first():
    """Started with SIGINT ignored, Python installs no KeyboardInterrupt handler: a script
    that relies on one must install it before it raises the signal."""
    for path in SOURCES:
        for script in re.findall(r'"""(.*?)"""', path.read_text(encoding='utf-8'), re.DOTALL):
            if 'raise_signal(signal.SIGINT)' in script:
                assert 'signal.signal(signal.SIGINT, signal.default_int_handler)' in script, (
                    f'{path.name}: a child script raises SIGINT without installing its handler')
