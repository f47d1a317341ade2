"""Messages per second recorded to MCAP by a batch run of the roller node (issue: recording).

The node runs as a process, exactly as a user runs it (``python -m twodisk_ros.roller``),
with ``realtime:=false`` and ``record:=FILE``; the count comes from reading the file back.
The start-up cost (imports, node and table build) is measured by a run of one sample and
subtracted, so the rate is that of the recording loop itself.
"""

from dataclasses import asdict, dataclass
import os
import subprocess
import sys
import tempfile
import time

from twodisk_ros.io import read_recording

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@dataclass
class RecordingRate:
    rate_hz: float          #: the node's publishing rate (samples per simulated second)
    duration: float         #: simulated seconds
    messages: int           #: messages in the file, all topics
    file_bytes: int
    wall: float             #: whole process (s)
    startup: float          #: the same process recording one sample (s)

    @property
    def per_second(self):
        """Messages recorded per wall second, start-up excluded."""
        return self.messages / max(self.wall - self.startup, 1e-9)

    def as_dict(self):
        return dict(asdict(self), per_second=self.per_second)


def _run_node(path, rate, duration):
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS_DOMAIN_ID=os.environ.get('ROS_DOMAIN_ID', '77'),
               PYTHONPATH=ROOT + os.pathsep + os.environ.get('PYTHONPATH', ''))
    command = [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
               os.path.join(ROOT, 'config', 'oloid.yaml'), '-p', 'realtime:=false',
               '-p', f'rate:={float(rate)}', '-p', f'duration:={float(duration)}',
               '-p', f'record:={path}']
    start = time.perf_counter()
    subprocess.run(command, env=env, check=True, capture_output=True)
    return time.perf_counter() - start


def recording_throughput(rate=1000.0, duration=20.0):
    """Record ``duration`` simulated seconds of the oloid at ``rate`` Hz; best of two runs."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, 'run.mcap')
        startup = min(_run_node(path, rate, 0.0005) for _ in range(2))
        wall = min(_run_node(path, rate, duration) for _ in range(2))
        recording = read_recording(path, decode=lambda topic: False)
        return RecordingRate(rate_hz=rate, duration=duration,
                             messages=len(recording.messages),
                             file_bytes=os.path.getsize(path), wall=wall, startup=startup)
