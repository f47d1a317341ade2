"""The node's throughput: batch recording against the file format's floor, and real time.

Batch: a ``roller`` node in this process records ``duration`` simulated seconds with every
topic (``run_batch`` is timed, so start-up is excluded); in the same run and on the same
message sizes, the ``mcap`` writer's own ``add_message`` rate (the floor the node can reach)
and ``rclpy.serialization.serialize_message`` (the old per-message path) are measured.

Real time: the node runs as a process (as users run it) with recording on, while a
subscriber in this process takes every topic (``/tf``, ``/clock`` and the latched
``/tf_static`` and ``robot_description`` too); at the subscriber, the inter-arrival times of
``/pose`` (p50, p99), the achieved rate and the lag of arrival behind the stamp; from the
node's last ``/diagnostics``, its own achieved rate and the samples it dropped; from
``/proc``, the node's CPU time per wall second.

The cost of ``/tf``: the node builds and publishes it only for a subscriber or a recording,
so the same run with and without a ``/tf`` subscriber (recording off) shows what it adds:
in real time as the node's CPU share (:func:`realtime_rate` with ``tf`` off and on), and in
a batch run as wall time per sample (:func:`batch_tf_cost`, in process, runs alternated).

Real time by shape: the same real-time run at 1 kHz for the ellipse (config/oloid.yaml) and
non-elliptic bodies (config/rounded_square.yaml, a superellipse n = 4; config/egg.yaml), side
by side (:func:`shape_rates`, :data:`SHAPE_SCENARIOS`).

Real time by scene: the same run at 1 kHz in every scene (slope, damping, rolling resistance,
the speed and the torque drive commanded at 10 Hz by the listener) beside the flat free
oloid (:func:`scene_rates`, :data:`SCENE_SCENARIOS`).
"""

from dataclasses import asdict, dataclass
import io
import math
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


def _listen(node, topics, callbacks=None):
    """Raw subscriptions of ``node`` to ``topics`` ({name: type}) with the publishers' QoS."""
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from twodisk_ros.node.frames_publisher import LATCHED_QOS, TYPES
    callbacks = callbacks or {}
    for topic, kind in topics.items():
        qos = (QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
               if topic == '/clock' else LATCHED_QOS if topic in TYPES else 1000)
        node.create_subscription(kind, topic, callbacks.get(topic, lambda data: None), qos,
                                 raw=True)


def every_topic(tf=True):
    """{topic: type} of everything the node publishes (``/tf`` left out if not ``tf``)."""
    from rosgraph_msgs.msg import Clock
    from twodisk_ros.node.frames_publisher import TYPES
    from twodisk_ros.node.roller import TOPIC_TYPES
    topics = dict(TOPIC_TYPES, **TYPES)
    topics['/clock'] = Clock
    if not tf:
        del topics['/tf']
    return topics


def batch_tf_cost(rate=1000.0, duration=20.0, repeats=5):
    """Time per sample (µs) of ``run_batch`` without and with a /tf subscriber.

    In process, no recording, a listener node in the same context subscribed to every other
    topic (never spun: the node's cost is publishing, not the listener's); best of
    ``repeats`` alternated runs each, as wall time and as CPU time of this process (all
    threads, DDS's included: less disturbed by other processes on a shared machine).
    Returns {'off': µs, 'on': µs, 'cpu_off': µs, 'cpu_on': µs, 'samples': n}.
    """
    import rclpy
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    best = {}
    for _ in range(repeats):
        for tf in (False, True):
            context = rclpy.Context()
            rclpy.init(context=context, domain_id=int(DOMAIN))
            try:
                listener = rclpy.create_node('bench_listener', context=context)
                topics = every_topic(tf)
                _listen(listener, topics)
                node = Roller(context=context, parameter_overrides=[
                    Parameter('realtime', value=False), Parameter('rate', value=float(rate)),
                    Parameter('duration', value=float(duration))])
                deadline = time.monotonic() + 30.0
                while not all(node.count_subscribers(t) for t in topics if t in (
                        '/tf', 'pose')) and time.monotonic() < deadline:
                    time.sleep(0.01)            # discovery in this process
                start, cpu = time.perf_counter(), time.process_time()
                node.run_batch()
                samples = node.samples_published
                per_sample = (time.perf_counter() - start) / samples * 1e6
                cpu_per_sample = (time.process_time() - cpu) / samples * 1e6
                node.destroy_node()
                listener.destroy_node()
            finally:
                rclpy.try_shutdown(context=context)
            for key, value in (('on' if tf else 'off', per_sample),
                               ('cpu_on' if tf else 'cpu_off', cpu_per_sample)):
                best[key] = min(best.get(key, math.inf), value)
    best['samples'] = samples
    return best


def batch_rate(rate=1000.0, duration=300.0):
    """Record ``duration`` s at ``rate`` Hz in process; the floors in the same run."""
    import rclpy
    from rclpy.parameter import Parameter
    from twodisk_ros.recordings import read_recording
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
    node_cpu: float = math.nan   #: the node's CPU seconds per wall second (1 = one core)
    tf: bool = True           #: /tf subscribed
    record: bool = True       #: recording on
    body: str = 'oloid'       #: the scenario's name (SHAPE_SCENARIOS), the body it runs

    def as_dict(self):
        return asdict(self)


def _cpu_seconds(pid):
    """User + system CPU time (s) of a process so far, all its threads (/proc/PID/stat)."""
    with open(f'/proc/{pid}/stat', encoding='ascii') as stat:
        fields = stat.read().rsplit(')', 1)[1].split()   # from field 3 (state) on
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


#: Bodies of the real-time runs at 1 kHz by shape: name → (params file in config/, extra
#: node parameters).
SHAPE_SCENARIOS = {
    'oloid': ('oloid.yaml', ()),
    'rounded_square': ('rounded_square.yaml', ()),
    'egg': ('egg.yaml', ()),
}


#: Scenes of the real-time runs at 1 kHz: name → (params file in config/, extra node
#: parameters, command published by the listener at 10 Hz as (topic, value) or None). The
#: drives are commanded throughout (cmd_timeout 1 s in config/driven.yaml): 6 rad/s, and
#: 0.01 N m against the damping of 0.002 N m s (|ω| → τ/c = 5 rad/s).
SCENE_SCENARIOS = {
    'flat free (oloid.yaml)': ('oloid.yaml', (), None),
    'slope 0.05 rad, damped (slope.yaml)': ('slope.yaml', (), None),
    'slope 0.05 rad across, conservative': (
        'slope.yaml', ('-p', 'heading0:=1.5708', '-p', 'damping:=0.0'), None),
    'damping 0.01 N m s': ('oloid.yaml', ('-p', 'damping:=0.01'), None),
    'rolling resistance 0.01': ('oloid.yaml', ('-p', 'rolling_resistance:=0.01'), None),
    'speed drive, cmd_speed 6 (driven.yaml)': ('driven.yaml', (), ('cmd_speed', 6.0)),
    'torque drive, cmd_torque 0.01': ('driven.yaml', ('-p', 'drive:=torque'),
                                      ('cmd_torque', 0.01)),
}


def _scenario(body):
    """(params file, extra parameters, command or None) of a SHAPE_ or SCENE_SCENARIOS name."""
    if body in SCENE_SCENARIOS:
        return SCENE_SCENARIOS[body]
    return SHAPE_SCENARIOS[body] + (None,)


def realtime_rate(rate, seconds=8.0, warmup=3.0, tf=True, record=True, body='oloid'):
    """Run the node at ``rate`` Hz in real time, every topic subscribed and recording on.

    ``tf=False`` leaves /tf unsubscribed and ``record=False`` the recording off: with both,
    the node builds no /tf (the "off" side of the cost of /tf). ``body``: a name of
    :data:`SHAPE_SCENARIOS` or :data:`SCENE_SCENARIOS` (its params file and parameters; a
    scene's command is published at 10 Hz from the listener, warm-up included).
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.serialization import deserialize_message
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID=DOMAIN,
                   PYTHONPATH=ROOT + os.pathsep + os.environ.get('PYTHONPATH', ''))
        recording = ['-p', f'record:={os.path.join(folder, "rt.mcap")}'] if record else []
        params_file, extra, command = _scenario(body)
        process = subprocess.Popen(
            [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
             os.path.join(ROOT, 'config', params_file), '-p', f'rate:={float(rate)}',
             *extra, *recording], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=int(DOMAIN))
        node = rclpy.create_node('bench_listener', context=context)
        arrivals, stamps, diagnostics = [], [], []

        def on_pose(data):
            arrivals.append(time.time())
            sec, nanosec = struct.unpack_from('<iI', data, 4)   # header stamp after CDR header
            stamps.append(sec + 1e-9 * nanosec)
        # raw: the listener must not be the bottleneck
        _listen(node, every_topic(tf), {'pose': on_pose, '/diagnostics': diagnostics.append})
        if command is not None:
            from std_msgs.msg import Float64
            publisher = node.create_publisher(Float64, command[0], 10)
            node.create_timer(0.1, lambda: publisher.publish(Float64(data=command[1])))
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        try:
            end = time.monotonic() + warmup
            while time.monotonic() < end or not arrivals:
                executor.spin_once(timeout_sec=0.01)
                if process.poll() is not None:
                    raise RuntimeError('the node exited before its first pose: ' + ' '.join(
                        process.communicate()[1].decode(errors='replace').split()[-40:]))
                if time.monotonic() > end + 60:
                    raise RuntimeError(f'no pose received in {warmup + 60:g} s')
            first = len(arrivals)
            cpu0, wall0 = _cpu_seconds(process.pid), time.monotonic()
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                executor.spin_once(timeout_sec=0.001)
            node_cpu = (_cpu_seconds(process.pid) - cpu0) / (time.monotonic() - wall0)
        finally:
            process.send_signal(2)
            try:
                err = process.communicate(timeout=20)[1].decode(errors='replace')
            finally:
                if process.poll() is None:
                    process.kill()
            executor.shutdown()
            node.destroy_node()
            rclpy.try_shutdown(context=context)
    if len(arrivals) - first < 2:
        raise RuntimeError(f'no pose while measuring; the node said: {err[-2000:]}')
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
        dropped=int(float(values.get('samples_dropped', '0'))), level=level,
        node_cpu=node_cpu, tf=tf, record=record, body=body)


def shape_rates(rate=1000.0, seconds=8.0, warmup=3.0):
    """:func:`realtime_rate` of every body of :data:`SHAPE_SCENARIOS` at ``rate`` Hz."""
    return [realtime_rate(rate, seconds=seconds, warmup=warmup, body=name)
            for name in SHAPE_SCENARIOS]


def scene_rates(rate=1000.0, seconds=8.0, warmup=3.0):
    """:func:`realtime_rate` of every scene of :data:`SCENE_SCENARIOS` at ``rate`` Hz."""
    return [realtime_rate(rate, seconds=seconds, warmup=warmup, body=name)
            for name in SCENE_SCENARIOS]


if __name__ == '__main__':
    import argparse
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] + ' Real time at '
                                     '100 Hz, 1 kHz and 10 kHz (5 s each), then the cost of '
                                     '/tf (1 kHz, off and on), then 1 kHz by shape.')
    parser.add_argument('--seconds', type=float, default=5.0,
                        help='wall seconds measured per real-time run (default 5)')
    parser.add_argument('--only-tf', action='store_true', help='only the cost of /tf')
    parser.add_argument('--only-shapes', action='store_true',
                        help='only real time at 1 kHz by shape (SHAPE_SCENARIOS)')
    parser.add_argument('--only-scenes', action='store_true',
                        help='only real time at 1 kHz by scene (SCENE_SCENARIOS)')
    options = parser.parse_args()
    if options.only_scenes:
        for result in scene_rates(seconds=options.seconds, warmup=2.0):
            print(result)
        raise SystemExit(0)
    if options.only_shapes:
        for result in shape_rates(seconds=options.seconds, warmup=2.0):
            print(result)
        raise SystemExit(0)
    if not options.only_tf:
        for hz in (100.0, 1000.0, 10000.0):
            print(realtime_rate(hz, seconds=options.seconds, warmup=2.0))
    for tf in (False, True):
        print(realtime_rate(1000.0, seconds=options.seconds, warmup=2.0, tf=tf, record=False))
    if not options.only_tf:
        for result in shape_rates(seconds=options.seconds, warmup=2.0):
            print(result)
    print('batch, µs per sample without and with /tf:',
          batch_tf_cost(duration=max(2.0, 4 * options.seconds)))
