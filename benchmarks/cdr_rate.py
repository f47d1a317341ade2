"""Messages per second of CDR encoding, and of MCAP's add_message with these message sizes.

For each of the node's fixed-layout types (PoseStamped, PointStamped, WrenchStamped, JointState,
TFMessage of one transform, Clock, and a Path of ``path_length`` poses), compares:

* ``vectorised``: :mod:`twodisk_ros.recordings.cdr`, a whole batch from numpy arrays to ``list[bytes]``;
* ``serialize``: ``rclpy.serialization.serialize_message`` of message objects built beforehand;
* ``build+serialize``: building each object with :mod:`twodisk_ros.node.messages` then serializing
  it, what the node did until now;
* ``add_message``: ``mcap.writer.Writer.add_message`` alone, the encoded messages of that type
  into an in-memory stream written as the project writes (chunks of 256 KiB, zstd).

``recording_share`` is the rate of encoding (smallest batch) plus add_message relative to
add_message alone: the fraction of the bare writer rate a recording loop built on the encoder
can reach (the goal is at least 0.6; publishing is not included).  The Path is sent at 2 Hz,
so its share matters little.

Run ``python benchmarks/cdr_rate.py [--quick]``; prints JSON.
"""

import argparse
import io
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

from twodisk_ros.recordings import cdr  # noqa: E402

FRAME = 'world'
NAMES = ['theta', 'psi', 'phase']
TYPES = {'pose': 'geometry_msgs/msg/PoseStamped', 'point': 'geometry_msgs/msg/PointStamped',
         'wrench': 'geometry_msgs/msg/WrenchStamped', 'joint_state': 'sensor_msgs/msg/JointState',
         'tf': 'tf2_msgs/msg/TFMessage', 'clock': 'rosgraph_msgs/msg/Clock',
         'path': 'nav_msgs/msg/Path'}


def _best(function, repeat):
    """Shortest wall time (s) of ``repeat`` calls, after one untimed warm-up call."""
    function()
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def _samples(n, seed=0):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    return {'stamps': 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000,
            'xyz': rng.normal(size=(n, 3)), 'q': q / np.linalg.norm(q, axis=1, keepdims=True),
            'joints': rng.normal(size=(n, 3)), 'rates': rng.normal(size=(n, 3))}


def _encoders(s, path_length):
    """type -> (function encoding the batch, messages it makes)."""
    n = len(s['stamps'])
    m = min(path_length, n)
    return {
        'pose': (lambda: cdr.encode_pose_stamped(s['stamps'], FRAME, s['xyz'], s['q']), n),
        'point': (lambda: cdr.encode_point_stamped(s['stamps'], FRAME, s['xyz']), n),
        'wrench': (lambda: cdr.encode_wrench_stamped(s['stamps'], FRAME, s['xyz'],
                                                     s['joints']), n),
        'tf': (lambda: cdr.encode_tf_message(s['stamps'], FRAME, 'twodisk_body', s['xyz'],
                                             s['q']), n),
        'clock': (lambda: cdr.encode_clock(s['stamps']), n),
        'joint_state': (lambda: cdr.encode_joint_state(s['stamps'], NAMES, s['joints'],
                                                       s['rates']), n),
        'path': (lambda: [cdr.encode_path(s['stamps'][-1], FRAME, s['xyz'][:m],
                                          stamps_ns=s['stamps'][:m])], 1),
    }


def _builders(s, path_length):
    """type -> function building the message objects of the batch (rclpy imported here)."""
    from geometry_msgs.msg import (Quaternion, Transform, TransformStamped, Vector3, Wrench,
                                   WrenchStamped)
    from rosgraph_msgs.msg import Clock
    from tf2_msgs.msg import TFMessage
    from twodisk_ros.node import messages
    n = len(s['stamps'])

    def vector(xyz):
        return Vector3(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))

    def tf(i):
        q = s['q'][i]
        return TFMessage(transforms=[TransformStamped(
            header=messages.header(FRAME, int(s['stamps'][i])), child_frame_id='twodisk_body',
            transform=Transform(translation=vector(s['xyz'][i]), rotation=Quaternion(
                x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))))])
    m = min(path_length, n)

    def path():
        poses = [messages.path_pose(FRAME, int(s['stamps'][k]), s['xyz'][k]) for k in range(m)]
        return [messages.path(FRAME, int(s['stamps'][-1]), poses)]

    return {
        'pose': lambda: [messages.pose_stamped(FRAME, int(s['stamps'][i]), s['xyz'][i], s['q'][i])
                         for i in range(n)],
        'point': lambda: [messages.point_stamped(FRAME, int(s['stamps'][i]), s['xyz'][i])
                          for i in range(n)],
        'wrench': lambda: [WrenchStamped(header=messages.header(FRAME, int(s['stamps'][i])),
                                         wrench=Wrench(force=vector(s['xyz'][i]),
                                                       torque=vector(s['joints'][i])))
                           for i in range(n)],
        'tf': lambda: [tf(i) for i in range(n)],
        'clock': lambda: [Clock(clock=messages.stamp(int(s['stamps'][i]))) for i in range(n)],
        'joint_state': lambda: [messages.rolling_state(int(s['stamps'][i]), s['joints'][i],
                                                       s['rates'][i]) for i in range(n)],
        'path': path,
    }


def add_message_rate(datas, repeat=3, chunk_size=256 * 1024):
    """Messages/s of ``Writer.add_message`` alone, zstd chunks, into a BytesIO."""
    from mcap.writer import CompressionType, Writer

    def run():
        writer = Writer(io.BytesIO(), chunk_size=chunk_size, compression=CompressionType.ZSTD)
        writer.start(profile='ros2', library='cdr_rate')
        schema = writer.register_schema(name='t', encoding='ros2msg', data=b'')
        channel = writer.register_channel(topic='/t', message_encoding='cdr', schema_id=schema)
        for i, data in enumerate(datas):
            writer.add_message(channel, log_time=i, data=data, publish_time=i)
        writer.finish()

    return len(datas) / _best(run, repeat)


def cdr_rates(batches=(1_000, 100_000), baseline_batch=1_000, path_length=1_000, repeat=5,
              types=tuple(TYPES)):
    """Messages per second, per message type, of each way of encoding and of add_message.

    Parameters
    ----------
    batches : tuple of int
        Batch sizes for the vectorised encoder (the Path is always one message of
        ``path_length`` poses, timed once per batch size only for the first).
    baseline_batch : int
        Messages per timed run of the rclpy baselines and of add_message.
    path_length : int
        Poses in each Path (the node's default is 1000).
    repeat : int
        Timed runs; the best one counts.

    Returns
    -------
    dict
        ``{type: {'bytes': message size, 'vectorised': {batch: msg/s}, 'serialize': msg/s,
        'build+serialize': msg/s, 'add_message': msg/s, 'recording_share': fraction}}``.
    """
    from rclpy.serialization import serialize_message
    results = {}
    for kind in types:
        row = {'vectorised': {}}
        for n in batches:
            s = _samples(max(n, path_length))
            if kind != 'path':
                s = {key: value[:n] for key, value in s.items()}
            encode, count = _encoders(s, path_length)[kind]
            row['vectorised'][n] = count / _best(encode, repeat)
            if kind == 'path':
                break
        s = _samples(max(baseline_batch, path_length))
        s = {key: value[:max(baseline_batch, path_length if kind == 'path' else 0)]
             for key, value in s.items()}
        build = _builders(s, path_length)[kind]
        objects = build()
        row['serialize'] = len(objects) / _best(lambda: [serialize_message(o) for o in objects],
                                                repeat)
        row['build+serialize'] = len(objects) / _best(
            lambda: [serialize_message(o) for o in build()], repeat)
        encode, _ = _encoders(s, path_length)[kind]
        datas = encode()
        if kind == 'path':
            datas = datas * 200
        row['bytes'] = len(datas[0])
        row['add_message'] = add_message_rate(datas[:max(baseline_batch, 200)], repeat)
        smallest = row['vectorised'][batches[0]]   # the node encodes batches of ~500 samples
        row['recording_share'] = 1 / (1 + row['add_message'] / smallest)
        results[kind] = row
    return results


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--quick', action='store_true', help='small batches, one run each')
    args = parser.parse_args(argv)
    if args.quick:
        results = cdr_rates(batches=(1_000,), baseline_batch=200, path_length=100, repeat=1)
    else:
        results = cdr_rates()
    print(json.dumps(results, indent=2))


if __name__ == '__main__':
    main()
