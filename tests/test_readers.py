"""Every message of a node recording, every topic, through the common readers.

- rosbags (the pure-Python rosbag2 library) opens the file as a rosbag2 bag, with the
  ``metadata.yaml`` that rosbag2 would write beside it, taken from the file's own ``rosbag2``
  record; its strict CDR decoder accepts every message, and its encoder gives back exactly
  the recorded bytes: exact lengths and zero padding, no process memory in the file;
- mcap-ros2-support decodes every message with the schemas stored in the file;
- the two agree with each other and with rclpy's ``deserialize_message`` of the same bytes
  (the bytes that went out over DDS), field by field;
- Foxglove's own readers (``@mcap/core``, ``@foxglove/rosmsg2-serialization``, in Node.js:
  tests/foxglove) decode every message, with no bytes left after its last field, field for
  field as mcap-ros2-support does.
"""

import math
import struct
import os
from pathlib import Path
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from twodisk_ros.recordings import read_recording

pytestmark = pytest.mark.ros
REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """A 3 s recording with every topic, laid out as a rosbag2 bag directory."""
    folder = tmp_path_factory.mktemp('bag')
    path = folder / 'run.mcap'
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='95',
               PYTHONPATH=str(REPO))
    subprocess.run([sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
                    'config/oloid.yaml', '-p', 'realtime:=false', '-p', 'duration:=3.0',
                    '-p', 'rate:=100.0', '-p', f'record:={path}'],
                   cwd=REPO, env=env, check=True, capture_output=True, timeout=120)
    metadata = read_recording(path, decode=lambda t: False).metadata['rosbag2']
    (folder / 'metadata.yaml').write_text(
        'rosbag2_bagfile_information:\n'
        + textwrap.indent(metadata['serialized_metadata'], '  ') + '\n')
    return folder, path


def _same(a, b, where):
    """Field-by-field equality of two decoded messages (any two libraries' objects)."""
    if isinstance(a, (bool, np.bool_)):
        assert bool(a) == bool(b), (where, a, b)
    elif isinstance(a, (bytes, bytearray)) or isinstance(b, (bytes, bytearray)):
        as_bytes = [bytes([x % 256]) if isinstance(x, (int, np.integer)) else bytes(x)
                    for x in (a, b)]   # a byte field: bytes in rclpy, an int in rosbags
        assert as_bytes[0] == as_bytes[1], (where, a, b)
    elif isinstance(a, (int, float, np.integer, np.floating)) and not isinstance(a, bool):
        if isinstance(b, (bytes, bytearray)):
            b = b[0]
        assert (math.isnan(a) and math.isnan(b)) or a == b or int(a) % 256 == int(b) % 256, \
            (where, a, b)
    elif isinstance(a, str):
        assert a == b, (where, a, b)
    elif isinstance(a, (list, tuple, np.ndarray)) or hasattr(a, '__len__') and not hasattr(
            a, '__slots__') and not hasattr(a, '__dataclass_fields__'):
        a, b = list(a), list(b)
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f'{where}[{k}]')
    else:
        names = [n for n in getattr(type(a), '__dataclass_fields__', {})
                 if n != '__msgtype__' and not n.isupper()]   # constants are UPPER_CASE
        if not names:
            names = [n.lstrip('_') for n in a.__slots__ if n != '_check_fields']
        for name in names:
            _same(getattr(a, name), getattr(b, name), f'{where}.{name}')


def test_every_message_through_rosbags_mcap_ros2_and_rclpy(bag):
    from rclpy.serialization import deserialize_message
    import importlib
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    folder, path = bag
    ours = read_recording(path)                         # decoded with mcap-ros2-support
    raw = read_recording(path, decode=lambda topic: False)
    assert not ours.damaged and not ours.undecodable
    store = get_typestore(Stores.ROS2_JAZZY)
    with AnyReader([folder], default_typestore=store) as reader:
        count = sum(1 for _ in reader.messages())
    assert count == len(ours.messages) == len(raw.messages) > 1800
    topics = {m.topic for m in ours.messages}
    assert {'/pose', '/contact_a', '/contact_b', '/rolling_state', '/wrench_a', '/wrench_b',
            '/path_a', '/path_b', '/path_g', '/markers', '/diagnostics'} <= topics
    by_file = [(m.topic, m.log_time_ns, m.msg, r.msg, m.type_name)
               for m, r in zip(ours.messages, raw.messages)]
    classes = {}
    with AnyReader([folder], default_typestore=store) as reader:
        for connection, stamp, data in reader.messages():
            decoded = reader.deserialize(data, connection.msgtype)   # strict: exact length
            assert store.serialize_cdr(decoded, connection.msgtype) == bytes(data), \
                f'{connection.topic} at {stamp}: padding not zero or bytes after the end'
    for topic, stamp, mcap_msg, data, type_name in by_file:
        package, _, name = type_name.split('/')
        kind = classes.setdefault(type_name, getattr(
            importlib.import_module(f'{package}.msg'), name))
        rclpy_msg = deserialize_message(bytes(data), kind)
        rosbags_msg = store.deserialize_cdr(bytes(data), type_name)
        _same(rclpy_msg, rosbags_msg, f'{topic}@{stamp} rclpy/rosbags')
        _same(rosbags_msg, mcap_msg, f'{topic}@{stamp} rosbags/mcap-ros2')


def _same_as_foxglove(py, js, where):
    """A message decoded by mcap-ros2-support against Foxglove's decoding of the same bytes
    (JSON from tests/foxglove/decode.mjs: numbers as float64 bits, 64-bit integers as int)."""
    if isinstance(js, dict):
        for key, value in js.items():
            _same_as_foxglove(getattr(py, key), value, f'{where}.{key}')
    elif isinstance(js, list):
        items = list(py)
        assert len(items) == len(js), where
        for k, (a, b) in enumerate(zip(items, js)):
            _same_as_foxglove(a, b, f'{where}[{k}]')
    elif isinstance(js, bool):
        assert bool(py) is js, (where, py, js)
    elif isinstance(js, float):
        if isinstance(py, (bytes, bytearray)):
            (py,) = py
        if isinstance(py, float):
            assert (math.isnan(py) and math.isnan(js)) or \
                struct.pack('<d', py) == struct.pack('<d', js), (where, py, js)
        else:
            assert float(py) == js, (where, py, js)
    else:
        assert py == js, (where, py, js)


def test_every_message_through_foxglove_readers(bag):
    """Foxglove's @mcap/core and @foxglove/rosmsg2-serialization read every message of the
    node's recording, with nothing left after its last field, field for field as
    mcap-ros2-support decodes it."""
    from foxglove_helpers import foxglove_decode
    _, path = bag
    ours = read_recording(path)
    decoded = foxglove_decode(path)
    assert len(decoded) == len(ours.messages) > 1800
    assert not [m['topic'] for m in decoded if m['trailing']]
    by_key = {}
    for m in decoded:
        by_key.setdefault((m['topic'], m['logTime']), []).append(m)
    for message in ours.messages:
        js = by_key[(message.topic, message.log_time_ns)].pop(0)
        assert js['schema'] == message.type_name
        _same_as_foxglove(message.msg, js['message'], f'{message.topic}@{message.log_time_ns}')
