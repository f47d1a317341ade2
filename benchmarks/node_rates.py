"""The node's throughput: batch recording against the file format's floor, and real time.

Batch: a ``roller`` node in this process records ``duration`` simulated seconds with every
topic (``run_batch`` is timed, so start-up is excluded); in the same run and on the same
message sizes, the ``mcap`` writer's own ``add_message`` rate (the floor the node can reach)
and ``rclpy.serialization.serialize_message`` (the old per-message path) are measured.

Real time: the node runs as a process (as users run it) with recording on, while a
subscriber in this process takes every topic; at the subscriber, the inter-arrival times of
``/pose`` (p50, p99), the achieved rate and the lag of arrival behind the stamp; from the
node's last ``/diagnostics``, its own achieved rate and the samples it dropped.
"""

from dataclasses import asdict, dataclass
import io
import os
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOMAIN = os.environ.get('ROS_DOMAIN_ID', '77')


@dataclass
class BatchRate:
    rate_hz: float            #: samples per simulated second
    duration: float           #: simulated seconds
    messages: int             #: messages written, every topic
    wall: float               #: run_batch (s), start-up excluded
    floor_rate: float         #: mcap Writer.add_message alone, same sizes (messages/s)
    serialize_rate: float     #: rclpy serialize_message of pre-built messages (messages/s)

    @property
    def per_second(self):
        return self.messages / self.wall

    @property
    def hour_estimate(self):
        """Wall time (s) of an hour at this rate, extrapolated linearly from the run."""
        return self.wall * 3600.0 / self.duration

    def as_dict(self):
        return dict(asdict(self), per_second=self.per_second, hour_estimate=self.hour_estimate)


def _floor(payloads, repeats=2):
    """add_message rate (messages/s) of the mcap writer on these payloads, as the node writes."""
    from mcap.writer import CompressionType, Writer
    best = 0.0
    for _ in range(repeats):
        writer = Writer(io.BytesIO(), chunk_size=256 * 1024, compression=CompressionType.ZSTD)
        writer.start(profile='ros2', library='bench')
        schema = writer.register_schema('x/msg/X', 'ros2msg', b'')
        channel = writer.register_channel('/x', 'cdr', schema)
        start = time.perf_counter()
        for i, data in enumerate(payloads):
            writer.add_message(channel, log_time=i, data=data, publish_time=i)
        best = max(best, len(payloads) / (time.perf_counter() - start))
        writer.finish()
    return best


def _serialize_rate(count=20000):
    from rclpy.serialization import serialize_message
    from twodisk_ros.node import messages
    msgs = [messages.pose_stamped('world', i, (0.1, 0.2, 0.3), (0.0, 0.0, 0.0, 1.0))
            for i in range(count)]
    start = time.perf_counter()
    for msg in msgs:
        serialize_message(msg)
    return count / (time.perf_counter() - start)


def batch_rate(rate=1000.0, duration=300.0):
    """Record ``duration`` s at ``rate`` Hz in process; the floors in the same run."""
    import rclpy
    from rclpy.parameter import Parameter
    from twodisk_ros.io import read_recording
    from twodisk_ros.node.roller import Roller
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, 'run.mcap')
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=int(DOMAIN))
        try:
            node = Roller(context=context, parameter_overrides=[
                Parameter('realtime', value=False), Parameter('rate', value=float(rate)),
                Parameter('duration', value=float(duration)),
                Parameter('record', value=path)])
            start = time.perf_counter()
            node.run_batch()
            wall = time.perf_counter() - start
            node.close()
            node.destroy_node()
        finally:
            rclpy.try_shutdown(context=context)
        recording = read_recording(path, decode=lambda topic: False)
        payloads = [m.msg for m in recording.messages]
    sample = payloads[:min(len(payloads), 400_000)]
    return BatchRate(rate_hz=rate, duration=duration, messages=len(payloads), wall=wall,
                     floor_rate=_floor(sample), serialize_rate=_serialize_rate())


@dataclass
class RealtimeRate:
    rate_hz: float
    seconds: float            #: wall seconds measured (after a warm-up)
    received: int             #: /pose messages received
    achieved_hz: float        #: received / span of their arrival times
    p50_ms: float             #: inter-arrival times at the subscriber
    p99_ms: float
    lag_ms: float             #: mean (arrival time − stamp) at the subscriber
    node_lag_ms: float        #: the node's own: wall clock − time of the last sample published
    node_achieved_hz: float   #: from the node's last /diagnostics
    dropped: int              #: samples the node dropped to keep real time
    level: int                #: its diagnostics level (0 OK, 1 WARN, 2 ERROR)

    def as_dict(self):
        return asdict(self)


def realtime_rate(rate, seconds=8.0, warmup=3.0):
    """Run the node at ``rate`` Hz in real time, every topic subscribed and recording on."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.serialization import deserialize_message
    from twodisk_ros.node.roller import TOPIC_TYPES
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID=DOMAIN,
                   PYTHONPATH=ROOT + os.pathsep + os.environ.get('PYTHONPATH', ''))
        process = subprocess.Popen(
            [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
             os.path.join(ROOT, 'config', 'oloid.yaml'), '-p', f'rate:={float(rate)}',
             '-p', f'record:={os.path.join(folder, "rt.mcap")}'],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=int(DOMAIN))
        node = rclpy.create_node('bench_listener', context=context)
        arrivals, stamps, diagnostics = [], [], []

        def on_pose(data):
            arrivals.append(time.time())
            sec, nanosec = struct.unpack_from('<iI', data, 4)   # header stamp after CDR header
            stamps.append(sec + 1e-9 * nanosec)
        for topic, kind in TOPIC_TYPES.items():   # raw: the listener must not be the bottleneck
            callback = (on_pose if topic == 'pose' else diagnostics.append
                        if kind is DiagnosticArray else (lambda data: None))
            node.create_subscription(kind, topic, callback, 1000, raw=True)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        try:
            end = time.monotonic() + warmup
            while time.monotonic() < end or not arrivals:
                executor.spin_once(timeout_sec=0.01)
                if time.monotonic() > end + 30:
                    raise RuntimeError('no pose received')
            first = len(arrivals)
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                executor.spin_once(timeout_sec=0.001)
        finally:
            process.send_signal(2)
            try:
                process.wait(timeout=20)
            finally:
                if process.poll() is None:
                    process.kill()
            executor.shutdown()
            node.destroy_node()
            rclpy.try_shutdown(context=context)
    t = np.array(arrivals[first:])
    s = np.array(stamps[first:])
    gaps = np.diff(t) * 1e3
    last = deserialize_message(diagnostics[-1], DiagnosticArray) if diagnostics else None
    values = {kv.key: kv.value for kv in last.status[0].values} if last else {}
    level = ord(last.status[0].level) if last else -1
    return RealtimeRate(
        rate_hz=rate, seconds=seconds, received=len(t),
        achieved_hz=(len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 else 0.0,
        p50_ms=float(np.percentile(gaps, 50)), p99_ms=float(np.percentile(gaps, 99)),
        lag_ms=float(np.mean(t - s) * 1e3),
        node_lag_ms=float(values.get('clock_lag', 'nan')) * 1e3,
        node_achieved_hz=float(values.get('achieved_rate', 'nan')),
        dropped=int(float(values.get('samples_dropped', '0'))), level=level)


if __name__ == '__main__':
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0] + ' Real time at 100 Hz, 1 kHz '
                            'and 10 kHz (5 s each).').parse_args()
    for hz in (100.0, 1000.0, 10000.0):
        print(realtime_rate(hz, seconds=5.0, warmup=2.0))
