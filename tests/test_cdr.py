"""Tests of twodisk_ros.recordings.cdr, byte for byte against independent encoders and decoders.

References: ``rclpy.serialization.serialize_message`` of the equivalent message object (built
with the node's own builders in ``twodisk_ros.node.messages``), a scalar CDR writer written here
that walks the rclpy message object and records where the alignment padding is, and rosbags'
serializer.  Decoders: rclpy, rosbags (strict about the message size) and mcap-ros2-support.

Fast-CDR (through ``serialize_message``) does not zero alignment padding: those bytes hold
whatever was in the buffer, and a JointState with an empty ``effort`` gets 4 more such bytes
after its last field.  So ``serialize_message`` is compared at the data bytes only, its extra
length is checked to be trailing padding, and our padding is checked to be zero.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '91')

import math  # noqa: E402
import struct  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

rclpy_serialization = pytest.importorskip('rclpy.serialization')
typesys = pytest.importorskip('rosbags.typesys')

from geometry_msgs.msg import Pose, PoseStamped, Quaternion  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

from twodisk_ros.recordings import msgdefs  # noqa: E402
from twodisk_ros.node import messages  # noqa: E402
from cdr_helpers import mcap_decode  # noqa: E402
from twodisk_ros.recordings import cdr  # noqa: E402

serialize_message = rclpy_serialization.serialize_message
deserialize_message = rclpy_serialization.deserialize_message
TYPESTORE = typesys.get_typestore(typesys.Stores.ROS2_JAZZY)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
pytestmark = pytest.mark.ros

SEC_MAX = 2**31 - 1
NS_MIN, NS_MAX = -2**31 * 10**9, SEC_MAX * 10**9 + 999_999_999
SPECIAL_FLOATS = [0.0, -0.0, 5e-324, -5e-324, 1e-310, 2.2250738585072014e-308, 1e-300, -1e300,
                  1.7976931348623157e308, -math.inf, math.inf, math.nan, 1.0, -1.0]
floats = st.one_of(st.sampled_from(SPECIAL_FLOATS), st.floats(allow_nan=False))
stamps = st.one_of(st.sampled_from([0, 1, 999_999_999, 10**9, NS_MAX, NS_MIN, -1]),
                   st.integers(NS_MIN, NS_MAX))
frames = st.one_of(st.text('abcxyz_/0', max_size=9),
                   st.text(st.characters(codec='utf-8', exclude_characters='\x00'), max_size=9))
SETTINGS = settings(max_examples=80, deadline=None)


def rows(width, max_rows=4):
    return st.lists(st.tuples(*[floats] * width), min_size=1, max_size=max_rows)


# -- the scalar reference writer ---------------------------------------------------------------
_PRIMITIVES = {'double': '<d', 'int32': '<i', 'uint32': '<I'}


class ReferenceWriter:
    """Plain CDR (XCDR1, little endian) of an rclpy message, one field at a time.

    Padding is written as zeros and its byte positions are kept in ``padding``.  With
    ``fastcdr_size``, an empty sequence of a primitive is aligned for its elements all the same:
    that gives the length ``serialize_message`` returns (Fast-CDR's size estimate, the buffer
    rmw_fastrtps hands back whole).
    """

    def __init__(self, fastcdr_size=False):
        self.data = bytearray(b'\x00\x01\x00\x00')
        self.padding = set()
        self.fastcdr_size = fastcdr_size

    def align(self, size):
        count = -(len(self.data) - 4) % size
        self.padding.update(range(len(self.data), len(self.data) + count))
        self.data += bytes(count)

    def write(self, kind, value):
        if kind in _PRIMITIVES:
            self.align(struct.calcsize(_PRIMITIVES[kind]))
            self.data += struct.pack(_PRIMITIVES[kind], value)
        elif kind == 'string':
            text = value.encode('utf-8')
            self.write('uint32', len(text) + 1)
            self.data += text + b'\x00'
        elif kind.startswith('sequence<'):
            self.write('uint32', len(value))
            item_kind = kind[len('sequence<'):-1]
            if self.fastcdr_size and not len(value) and item_kind in _PRIMITIVES:
                self.align(struct.calcsize(_PRIMITIVES[item_kind]))
            for item in value:
                self.write(item_kind, item)
        else:
            for name, field_kind in value.get_fields_and_field_types().items():
                self.write(field_kind, getattr(value, name))
        return self


def reference(msg):
    return ReferenceWriter().write('message', msg)


# -- field-by-field comparison of decoded messages (floats bit for bit) -----------------------
def _bits(value):
    return struct.pack('<d', value)


def assert_same(expected, got, kind='message', where='msg'):
    if kind == 'double':
        assert _bits(expected) == _bits(float(got)), where
    elif kind in _PRIMITIVES or kind == 'string':
        assert expected == got, where
    elif kind.startswith('sequence<'):
        assert len(expected) == len(got), where
        for i, (a, b) in enumerate(zip(expected, got)):
            assert_same(a, b, kind[len('sequence<'):-1], f'{where}[{i}]')
    else:
        for name, field_kind in expected.get_fields_and_field_types().items():
            assert_same(getattr(expected, name), getattr(got, name), field_kind,
                        f'{where}.{name}')




def check(ours, msg, extra=0):
    """All checks of one encoded message against the equivalent rclpy message object."""
    name = msgdefs.ros_type_name(type(msg))
    ref = reference(msg)
    assert ours == bytes(ref.data)                  # exact, padding included
    assert all(ours[i] == 0 for i in ref.padding)   # (so: every padding byte is zero)
    raw = serialize_message(msg)
    # serialize_message: the same bytes wherever they are data, all of them within our length;
    # its surplus (`extra`) is the padding its size estimate counts for empty sequences, left
    # unwritten after the last field.
    assert all(raw[i] == ours[i] for i in range(len(ours)) if i not in ref.padding)
    assert len(raw) - len(ours) == extra
    assert len(raw) == len(ReferenceWriter(fastcdr_size=True).write('message', msg).data)
    assert bytes(TYPESTORE.serialize_cdr(TYPESTORE.deserialize_cdr(ours, name), name)) == ours
    assert_same(msg, deserialize_message(ours, type(msg)))
    assert_same(msg, TYPESTORE.deserialize_cdr(ours, name))
    assert_same(msg, mcap_decode(ours, name))


# -- one test per message type -----------------------------------------------------------------
@SETTINGS
@given(stamps=st.lists(stamps, min_size=4, max_size=4), frame=frames, positions=rows(3),
       quaternions=rows(4))
def test_pose_stamped(stamps, frame, positions, quaternions):
    n = min(len(positions), len(quaternions))
    encoded = cdr.encode_pose_stamped(np.array(stamps[:n]), frame, positions[:n], quaternions[:n])
    assert len(encoded) == n
    for i in range(n):
        check(encoded[i], messages.pose_stamped(frame, stamps[i], positions[i], quaternions[i]))


@SETTINGS
@given(stamps=st.lists(stamps, min_size=4, max_size=4), frame=frames, points=rows(3))
def test_point_stamped(stamps, frame, points):
    n = len(points)
    encoded = cdr.encode_point_stamped(np.array(stamps[:n]), frame, np.array(points))
    assert len(encoded) == n
    for i in range(n):
        check(encoded[i], messages.point_stamped(frame, stamps[i], points[i]))


@SETTINGS
@given(stamps=st.lists(stamps, min_size=4, max_size=4), frame=frames, values=rows(6))
def test_joint_state(stamps, frame, values):
    n = len(values)
    values = np.array(values).reshape(n, 6)
    positions, velocities = values[:, :3], values[:, 3:]
    encoded = cdr.encode_joint_state(np.array(stamps[:n]), messages.JOINT_NAMES, positions,
                                     velocities, frame_id=frame)
    for i in range(n):
        msg = JointState(header=messages.header(frame, stamps[i]),
                         name=list(messages.JOINT_NAMES), position=positions[i].tolist(),
                         velocity=velocities[i].tolist())
        check(encoded[i], msg, extra=4)
        if frame == '':
            assert_same(msg, messages.rolling_state(stamps[i], positions[i], velocities[i]))


@SETTINGS
@given(stamp=stamps, frame=frames, count=st.integers(0, 5), quaternions=st.booleans(),
       data=st.data())
def test_path(stamp, frame, count, quaternions, data):
    positions = data.draw(st.lists(st.tuples(floats, floats, floats), min_size=count,
                                   max_size=count))
    pose_stamps = data.draw(st.lists(stamps, min_size=count, max_size=count))
    q = data.draw(st.lists(st.tuples(*[floats] * 4), min_size=count, max_size=count))
    if quaternions:
        poses = [PoseStamped(header=messages.header(frame, s),
                             pose=Pose(position=messages.point(p),
                                       orientation=Quaternion(x=r[0], y=r[1], z=r[2], w=r[3])))
                 for s, p, r in zip(pose_stamps, positions, q)]
        encoded = cdr.encode_path(stamp, frame, positions, q, np.array(pose_stamps, np.int64))
    else:
        poses = [messages.path_pose(frame, s, p) for s, p in zip(pose_stamps, positions)]
        encoded = cdr.encode_path(stamp, frame, positions, stamps_ns=pose_stamps)
    check(encoded, messages.path(frame, stamp, poses))


@pytest.mark.parametrize('length', range(10))
def test_every_frame_id_padding(length):
    """Frame ids of 0..9 bytes: every padding length after the string, in every message type."""
    frame = 'abcdefghi'[:length]
    t = np.array([0, 1_700_000_000_123_456_789, NS_MAX])
    xyz = np.array([[1.5, -0.0, 5e-324], [1e300, -2.0, 3.0], [0.0, 7.0, -1e-310]])
    quat = np.array([[0.0, 0.0, 0.0, 1.0], [0.5, -0.5, 0.5, -0.5], [1.0, 2.0, 3.0, 4.0]])
    for i, data in enumerate(cdr.encode_pose_stamped(t, frame, xyz, quat)):
        check(data, messages.pose_stamped(frame, t[i], xyz[i], quat[i]))
    for i, data in enumerate(cdr.encode_point_stamped(t, frame, xyz)):
        check(data, messages.point_stamped(frame, t[i], xyz[i]))
    for i, data in enumerate(cdr.encode_joint_state(t, messages.JOINT_NAMES, xyz, -xyz, frame)):
        check(data, JointState(header=messages.header(frame, t[i]), name=messages.JOINT_NAMES,
                               position=xyz[i].tolist(), velocity=(-xyz[i]).tolist()), extra=4)
    for m in range(4):
        check(cdr.encode_path(t[1], frame, xyz[:m], stamps_ns=t[:m]),
              messages.path(frame, t[1], [messages.path_pose(frame, t[k], xyz[k])
                                          for k in range(m)]))


def test_joint_state_variants():
    """Other joint names (every string padding), no velocities, one stamp for the batch."""
    names = ['', 'a', 'ab', 'abc', 'abcd', 'abcde']
    positions = np.arange(12.0).reshape(2, 6)
    encoded = cdr.encode_joint_state(5, names, positions, frame_id='map')
    for i in range(2):
        msg = JointState(header=messages.header('map', 5), name=names,
                         position=positions[i].tolist())
        check(encoded[i], msg, extra=8)   # 4 bytes for each empty float64 sequence
    assert cdr.encode_joint_state([], names, np.zeros((0, 6)), np.zeros((0, 6))) == []


def test_rosbags_rejects_serialize_message_joint_state_but_accepts_ours():
    msg = messages.rolling_state(123, (1.0, 2.0, 3.0), (4.0, 5.0, 6.0))
    raw = serialize_message(msg)
    ours = cdr.encode_joint_state([123], messages.JOINT_NAMES, [[1.0, 2.0, 3.0]],
                                  [[4.0, 5.0, 6.0]])[0]
    assert (len(raw), len(ours)) == (124, 120)
    with pytest.raises(Exception, match='size mismatch'):
        TYPESTORE.deserialize_cdr(raw, 'sensor_msgs/msg/JointState')
    got = TYPESTORE.deserialize_cdr(ours, 'sensor_msgs/msg/JointState')
    assert got.name == messages.JOINT_NAMES and got.effort.size == 0
    assert got.position.tolist() == [1.0, 2.0, 3.0]
    # rosbags accepts serialize_message's bytes once cut to the length of ours
    TYPESTORE.deserialize_cdr(raw[:len(ours)], 'sensor_msgs/msg/JointState')


def test_rosbags_accepts_serialize_message_of_the_other_types():
    for msg in (messages.pose_stamped('w', 1, (1, 2, 3), (0, 0, 0, 1)),
                messages.point_stamped('w', 1, (1, 2, 3)),
                messages.path('w', 1, [messages.path_pose('w', 1, (1, 2, 3))])):
        TYPESTORE.deserialize_cdr(serialize_message(msg), msgdefs.ros_type_name(type(msg)))


def test_stamp_conversion_is_floor_division():
    """sec = ns // 1e9 and nanosec = ns % 1e9 (so non-negative), as Time(sec=..., nanosec=...)."""
    t = np.array([-1, -10**9, -10**9 - 1, NS_MIN, NS_MAX, 0])
    for i, data in enumerate(cdr.encode_point_stamped(t, '', np.zeros((6, 3)))):
        sec, nanosec = struct.unpack_from('<iI', data, 4)
        assert (sec, nanosec) == (int(t[i]) // 10**9, int(t[i]) % 10**9)


def test_invalid_input():
    zeros = np.zeros((1, 3))
    with pytest.raises(ValueError, match='int32'):
        cdr.encode_point_stamped([NS_MAX + 1], '', zeros)
    with pytest.raises(ValueError, match='int32'):
        cdr.encode_point_stamped([NS_MIN - 1], '', zeros)
    with pytest.raises(TypeError, match='integer'):
        cdr.encode_point_stamped([1.5], '', zeros)
    with pytest.raises(ValueError, match='NUL'):
        cdr.encode_point_stamped([1], 'a\x00b', zeros)
    with pytest.raises(ValueError, match='shape'):
        cdr.encode_pose_stamped([1], '', zeros, zeros)
    with pytest.raises(ValueError, match='stamps'):
        cdr.encode_point_stamped([1, 2], '', zeros)
    with pytest.raises(ValueError, match='rows'):
        cdr.encode_joint_state([1], 'abc', zeros, np.zeros((2, 3)))


def test_batch_of_one_stamp_and_contiguous_input_not_required():
    xyz = np.arange(30.0).reshape(10, 3)[::2]      # a strided view
    encoded = cdr.encode_point_stamped(7, 'odom', xyz)
    for i in range(5):
        check(encoded[i], messages.point_stamped('odom', 7, xyz[i]))
    assert cdr.encode_point_stamped([], 'odom', np.zeros((0, 3))) == []


def test_imports_without_rclpy():
    code = ('import sys; import twodisk_ros.recordings.cdr; '
            'assert not [m for m in sys.modules if m.split(".")[0] == "rclpy"]')
    subprocess.run([sys.executable, '-c', code], cwd=ROOT, check=True)


def test_path_with_one_quaternion_for_all_poses():
    xyz = np.arange(9.0).reshape(3, 3)
    q = (0.5, -0.5, 0.5, -0.5)
    assert (cdr.encode_path(3, 'map', xyz, q, [1, 2, 3])
            == cdr.encode_path(3, 'map', xyz, np.tile(q, (3, 1)), [1, 2, 3]))
    assert (cdr.encode_path(3, 'map', xyz)
            == cdr.encode_path(3, 'map', xyz, stamps_ns=[3, 3, 3]))
