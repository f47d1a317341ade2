"""The ``twodisk-view`` process of the tests: rclpy made unimportable, its port read from its
first line, stopped by a signal and killed by its PID."""

import os
from pathlib import Path
import queue
import signal
import subprocess
import sys
import threading
import time

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='46',
           PYTHONPATH=str(REPO))
#: Start-up (imports, tables, server) on a loaded 2-core machine: ~2 s measured, bound far above.
READY_SECONDS = 90.0
#: A stop (signal → server stopped → exit) takes well under a second; bound far above.
STOP_SECONDS = 30.0

RUNNER = '''
import sys
class _Refuse:
    def find_spec(self, name, path=None, target=None):
        if name == 'rclpy' or name.startswith('rclpy.'):
            raise ImportError('rclpy refused by the test')
sys.meta_path.insert(0, _Refuse())
from twodisk_ros.view.cli import main
status = main(sys.argv[1:])
imported = [name for name in ('rclpy', 'matplotlib') if name in sys.modules]
if imported:
    print('imported', imported, file=sys.stderr)
    sys.exit(9)
sys.exit(status)
'''


class View:
    """A ``twodisk-view`` process; ``port`` once it serves."""

    def __init__(self, *args):
        self.process = subprocess.Popen([sys.executable, '-c', RUNNER, *map(str, args)],
                                        cwd=REPO, env=ENV, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True,
                                        stdin=subprocess.DEVNULL)
        self.lines = queue.Queue()
        self.stdout = []
        threading.Thread(target=self._read, daemon=True).start()
        self.port = None

    def _read(self):
        for line in self.process.stdout:
            self.stdout.append(line)
            self.lines.put(line)
        self.lines.put(None)

    def wait_serving(self):
        deadline = time.monotonic() + READY_SECONDS
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            if 'serving ws://127.0.0.1:' in line:
                self.port = int(line.split('ws://127.0.0.1:')[1].split()[0])
                return self.port
        raise AssertionError(f'not serving: {"".join(self.stdout)}'
                             f'{self.process.stderr.read() if self.process.poll() else ""}')

    def wait_line(self, text):
        deadline = time.monotonic() + READY_SECONDS
        while time.monotonic() < deadline:
            if any(text in line for line in self.stdout):
                return
            time.sleep(0.05)
        raise AssertionError(f'no line with {text!r}: {"".join(self.stdout)}')

    def stop(self, number=signal.SIGTERM):
        os.kill(self.process.pid, number)
        status = self.process.wait(timeout=STOP_SECONDS)
        return status, self.process.stderr.read()

    def kill(self):
        if self.process.poll() is None:
            os.kill(self.process.pid, signal.SIGKILL)
            self.process.wait(timeout=STOP_SECONDS)


def wait_for_handlers(pid, timeout=READY_SECONDS):
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
