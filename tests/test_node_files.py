"""``roller``'s record file and its process, through the real entry point in a subprocess.

- a path that is not a regular file (FIFO, directory, symbolic link to a FIFO) or has another
  suffix than ``.mcap`` is refused at start-up, one line, exit 2, left as it was;
- ``overwrite:=true`` replaces the old file only with a recording that holds a sample: a stop
  before the first sample leaves it byte for byte, and no temporary file behind;
- a second SIGINT / SIGTERM during a long start-up ends the process at once, exit 0;
- one INFO line when the run starts and one when it ends.

Subprocess nodes use ROS domain 78; discovery is localhost-only.
"""

import os
from pathlib import Path
import queue
import re
import signal
import stat
import subprocess
import sys
import threading
import time

import pytest

from roller_here import run_roller_main
from twodisk_ros.recordings import RecordingError, read_recording

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[1]
OLD = b'an old recording the user wants to keep\n'
#: a body whose tables take many seconds to build (about 18 s on the development machine)
#: the costliest allowed body (b/a = 0.01, delta/a = 1e-3): its tables take 2-4 s, announced
#: by an INFO line 'building tables for an extreme body ...' before they are built
SLOW_BODY = ('-p', 'a:=0.1', '-p', 'b:=0.001', '-p', 'delta:=0.0001')


DOMAIN = 78


def node_env():
    return dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID=str(DOMAIN),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')


def roller(*params):
    return subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
         'config/oloid.yaml', *params], cwd=REPO, env=node_env(), stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True)


def finish(process, timeout=30.0):
    """(exit code, stderr); a process still running after ``timeout`` s fails the test."""
    try:
        _, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        pytest.fail(f'the node did not end within {timeout} s: {err[-2000:]}')
    return process.returncode, err


class StderrLines:
    """The lines a running process writes to stderr, read by a thread."""

    def __init__(self, process):
        self.lines = queue.Queue()
        self.seen = []
        self._thread = threading.Thread(target=self._read, args=(process.stderr,), daemon=True)
        self._thread.start()

    def _read(self, stream):
        for line in stream:
            self.lines.put(line)

    def wait_for(self, text, timeout):
        """True once a line containing ``text`` was written, False after ``timeout`` s."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                line = self.lines.get(timeout=0.05)
            except queue.Empty:
                continue
            self.seen.append(line)
            if text in line:
                return True
        return False

    def rest(self):
        self._thread.join(timeout=10.0)
        while not self.lines.empty():
            self.seen.append(self.lines.get())
        return ''.join(self.seen)


def wait(process, timeout=30.0):
    """Exit code of a process whose stderr a :class:`StderrLines` reads."""
    try:
        return process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        pytest.fail(f'the node did not end within {timeout} s')


def left_over(folder, *expected):
    """Files in ``folder`` besides ``expected`` (a temporary file left behind would show)."""
    return sorted(set(os.listdir(folder)) - set(expected))


# -- files the node did not create -----------------------------------------------------------

def _fifo(folder):
    path = folder / 'pipe.mcap'
    os.mkfifo(path)
    return path, stat.S_ISFIFO


def _directory(folder):
    path = folder / 'folder.mcap'
    path.mkdir()
    return path, stat.S_ISDIR


def _link_to_fifo(folder):
    fifo = folder / 'target-pipe'
    os.mkfifo(fifo)
    path = folder / 'link.mcap'
    path.symlink_to(fifo)
    return path, stat.S_ISFIFO


@pytest.mark.parametrize('make', [_fifo, _directory, _link_to_fifo],
                         ids=['fifo', 'directory', 'symlink-to-fifo'])
def test_a_path_that_is_not_a_regular_file_is_refused_even_with_overwrite(tmp_path, make,
                                                                          monkeypatch, capfd):
    """Exit 2 with one line before any work; the FIFO or directory stays as it was.

    (Before: a FIFO was opened for writing, which blocks until a reader comes, and was
    removed by a stop before the first sample.) The FIFOs run in a real process, under a
    timeout: a regression would block; the directory through the entry function here.
    """
    path, is_kind = make(tmp_path)
    before = sorted(os.listdir(tmp_path))
    params = ('-p', 'realtime:=false', '-p', 'duration:=0.1', '-p', f'record:={path}',
              '-p', 'overwrite:=true')
    if make is _directory:
        code, err = run_roller_main(('--params-file', 'config/oloid.yaml', *params),
                                    monkeypatch, capfd, domain=DOMAIN, cwd=REPO)
    else:
        code, err = finish(roller(*params), timeout=20.0)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and 'Traceback' not in err, err
    assert str(path) in lines[0] and 'regular file' in lines[0], err
    assert is_kind(os.stat(path).st_mode)
    assert sorted(os.listdir(tmp_path)) == before


def test_a_record_file_must_end_in_mcap(tmp_path, monkeypatch, capfd):
    """Through the entry function in this process (the FIFO cases above are real processes
    refused at the same place)."""
    target = tmp_path / 'run.bag'
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', '-p', 'realtime:=false',
                                 '-p', 'duration:=0.1', '-p', f'record:={target}'),
                                monkeypatch, capfd, domain=DOMAIN, cwd=REPO)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and '.mcap' in lines[0], err
    assert os.listdir(tmp_path) == []


# -- overwrite: the old file goes only when the new one holds a sample -----------------------

def test_overwrite_and_a_stop_before_the_first_sample_keep_the_old_file(tmp_path):
    """A real-time run at 0.01 Hz has its first sample after 100 s; SIGINT before it.

    (Before: the old file was truncated when the node opened it, then removed.)
    """
    target = tmp_path / 'run.mcap'
    target.write_bytes(OLD)
    process = roller('-p', 'rate:=0.01', '-p', f'record:={target}', '-p', 'overwrite:=true')
    err = StderrLines(process)
    started = err.wait_for('recording to', timeout=20.0)
    time.sleep(0.3)                      # the node is built; its first tick is 100 s away
    process.send_signal(signal.SIGINT)
    code = wait(process)
    text = err.rest()
    assert started, text
    assert code == 0 and 'Traceback' not in text, text
    assert 'stopped before the first sample: no recording written' in text, text
    assert target.read_bytes() == OLD
    assert left_over(tmp_path, 'run.mcap') == []


def test_overwrite_replaces_the_old_file_once_a_sample_is_on_disk(tmp_path):
    """SIGKILL a real-time run: the file under its name is the new recording, readable."""
    target = tmp_path / 'run.mcap'
    target.write_bytes(OLD)
    process = roller('-p', 'rate:=200.0', '-p', f'record:={target}', '-p', 'overwrite:=true')
    err = StderrLines(process)
    try:
        assert err.wait_for('recording to', timeout=20.0), err.rest()
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline and target.read_bytes() == OLD:
            time.sleep(0.05)
        assert target.read_bytes() != OLD, 'the old file was not replaced within 10 s'
        while time.monotonic() < deadline and not _poses_on_disk(target):
            time.sleep(0.05)             # until a chunk of samples is on disk
    finally:
        process.kill()
        process.wait(timeout=10.0)
        err.rest()
    recording = read_recording(target, decode=lambda topic: False)
    assert recording.truncated                   # killed: no summary, but readable
    assert recording.topics['/pose'].message_count > 0
    assert left_over(tmp_path, 'run.mcap') == []


def _poses_on_disk(path):
    """True once the file being written holds a /pose message readable as a cut file."""
    try:
        recording = read_recording(path, decode=lambda topic: False)
    except RecordingError:               # (not expected: the new file starts with its header)
        return False
    return '/pose' in recording.topics and recording.topics['/pose'].message_count > 0


# -- a second signal during a long start-up --------------------------------------------------

#: (count, phase, signal): every pair of values of two of the three factors once (the
#: handler is the same for both signals, node/stop.py: what differs between the cases is
#: the phase and the count; each signal still meets each phase and each count)
START_UP_SIGNALS = [(1, 'during-imports', signal.SIGINT), (2, 'during-imports', signal.SIGTERM),
                    (1, 'during-tables', signal.SIGTERM), (2, 'during-tables', signal.SIGINT)]


@pytest.mark.slow
@pytest.mark.parametrize('count, phase, sig', START_UP_SIGNALS,
                         ids=[f'{("one-signal", "two-signals")[c - 1]}-{p}-{s.name}'
                              for c, p, s in START_UP_SIGNALS])
def test_a_signal_ends_a_long_start_up_at_once(tmp_path, sig, phase, count):
    """The tables of SLOW_BODY take seconds; one or two signals end the process within 1.5 s.

    0.3 s after the start the interpreter is still importing (one signal is acted on when
    the imports end, before any table); 0.3 s after the node announces the table build it
    is building them. (Before: the start-up went on to its end, which for some allowed
    bodies took minutes.)
    """
    target = tmp_path / 'run.mcap'
    target.write_bytes(OLD)
    process = roller(*SLOW_BODY, '-p', 'realtime:=false', '-p', 'duration:=1.0',
                     '-p', f'record:={target}', '-p', 'overwrite:=true')
    before = ''
    if phase == 'during-tables':
        before = _read_until(process, 'building tables for an extreme body', timeout=30.0)
    time.sleep(0.3)
    assert process.poll() is None, 'the start-up was not slow: choose a slower body'
    for index in range(count):
        time.sleep(0.05 * index)
        process.send_signal(sig)
    code, err = finish(process, timeout=5.0)   # a hang guard (measured 0.06-0.5 s)
    lines = err.strip().splitlines()
    assert code == 0 and 'Traceback' not in err, before + err
    # bounded work: the start-up stopped where it was. Had it gone on to its end (the old
    # behaviour), the node would have logged its start line and run, then its end line
    assert len(lines) == 1 and 'no recording written' in lines[0], before + err
    assert 'rolling a=' not in err and 'published' not in err, before + err
    assert target.read_bytes() == OLD
    assert left_over(tmp_path, 'run.mcap') == []


def _wait_for_handlers(pid, timeout=10.0):
    """Wait until the process catches SIGTERM (its handlers are in: /proc/PID/status)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        with open(f'/proc/{pid}/status', encoding='ascii') as status:
            caught = next(int(line.split()[1], 16) for line in status
                          if line.startswith('SigCgt:'))
        if caught & (1 << (signal.SIGTERM - 1)):
            return
        time.sleep(0.002)
    raise AssertionError(f'no SIGTERM handler within {timeout} s')


def _read_until(process, text, timeout):
    """The stderr lines of ``process`` up to and including the first holding ``text``."""
    import select
    seen, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([process.stderr], [], [], 0.1)
        if ready:
            line = process.stderr.readline()
            assert line, 'stderr closed before: ' + ''.join(seen)
            seen.append(line)
            if text in line:
                return ''.join(seen)
    process.kill()
    raise AssertionError(f'no {text!r} within {timeout} s: ' + ''.join(seen))


def test_one_signal_during_start_up_still_writes_nothing(tmp_path):
    """The first signal only sets the flag: start-up ends, the node stops, nothing written."""
    target = tmp_path / 'run.mcap'
    process = roller('-p', 'realtime:=false', '-p', 'duration:=1.0', '-p', f'record:={target}')
    _wait_for_handlers(process.pid)       # (before: Python's default action, exit -15)
    process.send_signal(signal.SIGTERM)
    code, err = finish(process)
    assert code == 0 and 'Traceback' not in err and 'no recording written' in err, err
    assert os.listdir(tmp_path) == []


# -- what the node says ----------------------------------------------------------------------

def _size(text):
    number, unit = text.split()
    return float(number) * {'B': 1, 'kB': 1e3, 'MB': 1e6, 'GB': 1e9}[unit]


def test_one_line_at_start_and_one_at_the_end(tmp_path):
    target = tmp_path / 'run.mcap'
    code, err = finish(roller('-p', 'realtime:=false', '-p', 'duration:=2.0',
                              '-p', 'friction:=0.01', '-p', f'record:={target}'))
    lines = [line for line in err.strip().splitlines() if not line.startswith('[ERROR] ')]
    assert code == 0 and len(lines) == 2, err   # (the ERROR line of the first slip besides)
    start, end = lines
    assert start.startswith('[INFO] ') and '[roller]: ' in start, err
    for words in ('a=0.1 m', 'b=0.1 m', 'delta=0.05 m', 'laminae mass model', 'dynamic mode',
                  'at 100 Hz', 'batch of 2 s', f'recording to {target}'):
        assert words in start, (words, start)
    assert end.startswith('[INFO] ') and '[roller]: ' in end, err
    recording = read_recording(target, decode=lambda topic: False)
    samples = recording.topics['/pose'].message_count
    assert samples == 201
    assert f'published {samples} samples (2 s of simulated time)' in end, end
    match = re.search(rf'recorded {re.escape(str(target))} \(([^)]+)\)', end)
    assert match, end
    # the size is printed to 3 significant digits: within 0.5 % of the file's
    assert abs(_size(match.group(1)) - target.stat().st_size) <= 0.005 * target.stat().st_size
    # friction 0.01 is far below what rolling needs: the first slip is named
    assert 'outside the rolling model' in end and 'slip' in end, end


def test_without_recording_the_lines_say_so(monkeypatch, capfd):
    """Through the entry function in this process (the run above is the real process)."""
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', '-p', 'realtime:=false',
                                 '-p', 'duration:=0.5'), monkeypatch, capfd, domain=DOMAIN,
                                cwd=REPO)
    lines = err.strip().splitlines()
    assert code == 0 and len(lines) == 2, err
    assert 'not recording' in lines[0] and 'not recorded' in lines[1], err
    assert 'published 51 samples' in lines[1], err
