"""/tf and /tf_static in a recording, as rosbag2 (Jazzy) records them, through every reader.

The recording is written by McapRecorder from the node's encoders (``cdr.encode_tf_message``
for /tf, ``cdr.serialize`` of one TFMessage with several transforms for /tf_static) with the
QoS that tf2_ros's broadcasters offer: /tf keep last 100, reliable, volatile; /tf_static keep
last 1, reliable, transient local (rosbag2 stores each publisher's offered QoS, and its player
republishes /tf_static transient local from that). References, none of them this package:
rosbags' Jazzy type store (the type hash, the CDR, the QoS parsed back from the bag metadata),
mcap-ros2-support's decoder, rclpy's deserializer, and Foxglove's own readers (@mcap/core,
@foxglove/rosmsg2-serialization in Node.js, installed by ``make foxglove-readers`` from
tests/foxglove/package-lock.json); every number comes back bit for bit.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '40')

import struct  # noqa: E402
import textwrap  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402

pytest.importorskip('rclpy')
tf2_msgs = pytest.importorskip('tf2_msgs.msg')

from geometry_msgs.msg import (PoseStamped, Quaternion, Transform,  # noqa: E402
                               TransformStamped, Vector3)
from mcap.reader import make_reader  # noqa: E402
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile,  # noqa: E402
                       ReliabilityPolicy)
from rclpy.serialization import deserialize_message  # noqa: E402
from rosbags.highlevel import AnyReader  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

from foxglove_helpers import foxglove_decode  # noqa: E402
from twodisk_ros.recordings import McapRecorder, cdr, msgdefs, read_recording  # noqa: E402
from twodisk_ros.node import messages  # noqa: E402

TFMessage = tf2_msgs.TFMessage
pytestmark = pytest.mark.ros
STORE = get_typestore(Stores.ROS2_JAZZY)
TF = 'tf2_msgs/msg/TFMessage'
T0 = 1_700_000_000 * 10**9
# tf2_ros DynamicBroadcasterQoS and StaticBroadcasterQoS (what robot_state_publisher offers)
TF_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                    reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
TF_STATIC_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                           reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)
N = 50


def samples():
    """Stamps, positions and quaternions with awkward floats (subnormals, -0, extremes)."""
    rng = np.random.default_rng(22)
    stamps = T0 + np.arange(N, dtype=np.int64) * 10_000_001
    positions = rng.normal(size=(N, 3)) * 10.0 ** rng.integers(-300, 300, size=(N, 3))
    positions[0] = (5e-324, -0.0, 1.7976931348623157e308)
    quaternions = rng.normal(size=(N, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    return stamps, positions, quaternions


def static_message(stamp):
    """Two disk frames in the body frame, as the node's /tf_static carries them."""
    def transform(child, xyz, q):
        return TransformStamped(
            header=messages.header('twodisk_body', stamp), child_frame_id=child,
            transform=Transform(translation=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                                rotation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3])))
    return TFMessage(transforms=[transform('twodisk_disk_1', (0.0, 0.0, -0.5), (0, 0, 0, 1.0)),
                                 transform('twodisk_disk_2', (0.0, 0.0, 0.5),
                                           (0.7071067811865476, 0.0, 0.0, 0.7071067811865476))])


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """The recording and a rosbag2 bag folder around it (metadata.yaml from its own record)."""
    folder = tmp_path_factory.mktemp('tfbag')
    path = folder / 'tf.mcap'
    stamps, positions, quaternions = samples()
    static = static_message(int(stamps[0]))
    with McapRecorder(path) as rec:
        rec.add_topic('/tf_static', TFMessage, TF_STATIC_QOS)
        rec.add_topic('/pose', PoseStamped)
        rec.add_topic('/tf', TFMessage, TF_QOS)
        rec.write_serialized('/tf_static', cdr.serialize(static), int(stamps[0]))
        rec.write_interleaved(
            ['/pose', '/tf'],
            [cdr.encode_pose_stamped(stamps, 'world', positions, quaternions),
             cdr.encode_tf_message(stamps, 'world', 'twodisk_body', positions, quaternions)],
            stamps)
    metadata = read_recording(path, decode=lambda t: False).metadata['rosbag2']
    (folder / 'metadata.yaml').write_text(
        'rosbag2_bagfile_information:\n'
        + textwrap.indent(metadata['serialized_metadata'], '  ') + '\n')
    return folder, path, static


def bits(values):
    return struct.pack(f'<{len(values)}d', *map(float, values))


def transform_values(t):
    """(stamp ns, parent, child, translation bits, rotation bits) of a decoded transform."""
    tr, rot = t.transform.translation, t.transform.rotation
    return (t.header.stamp.sec * 10**9 + t.header.stamp.nanosec, t.header.frame_id,
            t.child_frame_id, bits([tr.x, tr.y, tr.z]), bits([rot.x, rot.y, rot.z, rot.w]))


def expected_tf():
    stamps, positions, quaternions = samples()
    return [(int(s), 'world', 'twodisk_body', bits(p), bits(q))
            for s, p, q in zip(stamps, positions, quaternions)]


def test_type_hash_and_schema_are_jazzys(bag):
    _, path, _ = bag
    assert msgdefs.type_hash(TF) == STORE.hash_rihs01(TF)
    with open(path, 'rb') as stream:
        summary = make_reader(stream).get_summary()
    channels = {c.topic: c for c in summary.channels.values()}
    for topic in ('/tf', '/tf_static'):
        channel = channels[topic]
        assert channel.metadata['topic_type_hash'] == STORE.hash_rihs01(TF)
        schema = summary.schemas[channel.schema_id]
        assert (schema.name, schema.encoding) == (TF, 'ros2msg')
        assert schema.data.startswith(b'geometry_msgs/TransformStamped[] transforms\n')
        for dep in ('geometry_msgs/TransformStamped', 'std_msgs/Header',
                    'builtin_interfaces/Time', 'geometry_msgs/Transform',
                    'geometry_msgs/Vector3', 'geometry_msgs/Quaternion'):
            assert schema.data.count(f'\nMSG: {dep}\n'.encode()) == 1
    assert channels['/tf'].schema_id == channels['/tf_static'].schema_id


def test_qos_as_rosbag2_records_it(bag):
    """The QoS in the channel metadata and the bag metadata, parsed back by rosbags."""
    folder, path, _ = bag
    with open(path, 'rb') as stream:
        summary = make_reader(stream).get_summary()
    channels = {c.topic: c for c in summary.channels.values()}
    (static,) = yaml.safe_load(channels['/tf_static'].metadata['offered_qos_profiles'])
    (dynamic,) = yaml.safe_load(channels['/tf'].metadata['offered_qos_profiles'])
    assert (static['durability'], static['reliability'], static['history'], static['depth']) \
        == ('transient_local', 'reliable', 'keep_last', 1)
    assert (dynamic['durability'], dynamic['reliability'], dynamic['history'],
            dynamic['depth']) == ('volatile', 'reliable', 'keep_last', 100)
    with AnyReader([folder], default_typestore=STORE) as reader:
        by_topic = {c.topic: c for c in reader.connections}
        assert by_topic['/tf'].msgtype == by_topic['/tf_static'].msgtype == TF
        assert by_topic['/tf'].digest == STORE.hash_rihs01(TF)
        (offered,) = by_topic['/tf_static'].ext.offered_qos_profiles
        assert offered.durability.name.lower() == 'transient_local'
        assert offered.depth == 1
        (offered,) = by_topic['/tf'].ext.offered_qos_profiles
        assert offered.durability.name.lower() == 'volatile'
        assert (by_topic['/tf'].msgcount, by_topic['/tf_static'].msgcount) == (N, 1)


def test_rosbags_decodes_tf_bit_for_bit(bag):
    folder, _, static = bag
    got = {'/tf': [], '/tf_static': []}
    with AnyReader([folder], default_typestore=STORE) as reader:
        wanted = [c for c in reader.connections if c.topic in got]
        for connection, stamp, data in reader.messages(connections=wanted):
            msg = reader.deserialize(data, connection.msgtype)   # strict about the length
            assert STORE.serialize_cdr(msg, TF) == bytes(data)   # zero padding, exact end
            got[connection.topic].append((stamp, [transform_values(t) for t in msg.transforms]))
    assert [values for _, (values,) in got['/tf']] == expected_tf()
    assert [stamp for stamp, _ in got['/tf']] == [e[0] for e in expected_tf()]
    ((_, transforms),) = got['/tf_static']
    assert transforms == [transform_values(t) for t in static.transforms]


def test_mcap_ros2_and_rclpy_decode_tf_bit_for_bit(bag):
    _, path, static = bag
    decoded = read_recording(path)                       # mcap-ros2-support
    raw = read_recording(path, decode=lambda topic: False)
    assert not decoded.damaged and not decoded.undecodable
    tf = [m for m in decoded.messages if m.topic == '/tf']
    assert [transform_values(m.msg.transforms[0]) for m in tf] == expected_tf()
    assert all(len(m.msg.transforms) == 1 for m in tf)
    (tf_static,) = [m for m in decoded.messages if m.topic == '/tf_static']
    assert [transform_values(t) for t in tf_static.msg.transforms] \
        == [transform_values(t) for t in static.transforms]
    for message in raw.messages:
        if message.topic in ('/tf', '/tf_static'):
            again = deserialize_message(bytes(message.msg), TFMessage)
            assert [transform_values(t) for t in again.transforms] == [
                transform_values(t) for t in STORE.deserialize_cdr(bytes(message.msg),
                                                                   TF).transforms]


def test_tf_equals_pose_sample_for_sample(bag):
    """Each /tf transform carries the stamp and numbers of the /pose sample logged with it."""
    _, path, _ = bag
    decoded = read_recording(path)
    poses = {m.log_time_ns: m.msg for m in decoded.messages if m.topic == '/pose'}
    tfs = {m.log_time_ns: m.msg.transforms[0] for m in decoded.messages if m.topic == '/tf'}
    assert poses.keys() == tfs.keys() and len(poses) == N
    for stamp, pose in poses.items():
        p, q = pose.pose.position, pose.pose.orientation
        assert transform_values(tfs[stamp]) == (
            pose.header.stamp.sec * 10**9 + pose.header.stamp.nanosec, pose.header.frame_id,
            'twodisk_body', bits([p.x, p.y, p.z]), bits([q.x, q.y, q.z, q.w]))


def _foxglove_transform(t):
    tr, rot = t['transform']['translation'], t['transform']['rotation']
    stamp = t['header']['stamp']
    return (int(stamp['sec']) * 10**9 + int(stamp['nanosec']), t['header']['frame_id'],
            t['child_frame_id'], bits([tr['x'], tr['y'], tr['z']]),
            bits([rot['x'], rot['y'], rot['z'], rot['w']]))


def test_foxglove_readers_decode_tf_bit_for_bit(bag):
    _, path, static = bag
    decoded = foxglove_decode(path, '/tf', '/tf_static')
    assert {m['schema'] for m in decoded} == {TF}
    assert not any(m['trailing'] for m in decoded)      # each message ends at its last field
    tf = [m for m in decoded if m['topic'] == '/tf']
    assert [m['logTime'] for m in tf] == [e[0] for e in expected_tf()]
    assert [[_foxglove_transform(t) for t in m['message']['transforms']] for m in tf] \
        == [[e] for e in expected_tf()]
    (tf_static,) = [m for m in decoded if m['topic'] == '/tf_static']
    assert [_foxglove_transform(t) for t in tf_static['message']['transforms']] \
        == [transform_values(t) for t in static.transforms]


@pytest.mark.parametrize('type_name', [
    TF, 'rosgraph_msgs/msg/Clock', 'std_msgs/msg/String', 'geometry_msgs/msg/PoseStamped',
    'geometry_msgs/msg/PointStamped', 'geometry_msgs/msg/WrenchStamped',
    'sensor_msgs/msg/JointState', 'nav_msgs/msg/Path', 'visualization_msgs/msg/MarkerArray',
    'diagnostic_msgs/msg/DiagnosticArray'])
def test_type_hashes_are_jazzys(type_name):
    """The hash each channel carries (``topic_type_hash``) is the one rosbags' Jazzy store
    computes from its own definitions: RViz, tf2 and ``ros2 bag`` accept the recording."""
    assert msgdefs.type_hash(type_name) == STORE.hash_rihs01(type_name)
