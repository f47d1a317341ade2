"""Tests of the /tf and /clock encoders of twodisk_ros.recordings.cdr, byte for byte.

References: rosbags' Jazzy type store serializer (its own TFMessage and Clock definitions;
zero padding, exact length), ``rclpy.serialization.serialize_message`` of the equivalent rclpy
message at every data byte (and the scalar reference writer of ``test_cdr``), through
``test_cdr.check``, for Clock always and for TFMessage where tf2_msgs is built into the venv.
Decoders: rclpy, rosbags (strict about the size) and mcap-ros2-support, floats bit for bit.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '91')

import struct  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

pytest.importorskip('rclpy.serialization')
typesys = pytest.importorskip('rosbags.typesys')

from rosgraph_msgs.msg import Clock  # noqa: E402

from cdr_helpers import mcap_decode  # noqa: E402
from test_cdr import NS_MAX, NS_MIN, SETTINGS, check, frames, rows, stamps  # noqa: E402
from twodisk_ros.recordings import cdr, msgdefs  # noqa: E402
from twodisk_ros.node import messages  # noqa: E402

try:
    from tf2_msgs.msg import TFMessage
except ImportError:          # not built into this venv yet: rosbags is the byte reference
    TFMessage = None

TYPESTORE = typesys.get_typestore(typesys.Stores.ROS2_JAZZY)
TF = 'tf2_msgs/msg/TFMessage'
pytestmark = pytest.mark.ros
HAVE_TF_DEFINITION = msgdefs.find_share_file('tf2_msgs', 'msg', 'TFMessage.msg') is not None


def rosbags_tf(stamp, parent, child, position, quaternion):
    """The TFMessage of one transform as a rosbags object (its Jazzy type store)."""
    types = TYPESTORE.types
    sec, nanosec = divmod(int(stamp), 10**9)
    transform = types['geometry_msgs/msg/TransformStamped'](
        header=types['std_msgs/msg/Header'](
            stamp=types['builtin_interfaces/msg/Time'](sec=sec, nanosec=nanosec),
            frame_id=parent),
        child_frame_id=child,
        transform=types['geometry_msgs/msg/Transform'](
            translation=types['geometry_msgs/msg/Vector3'](*map(float, position)),
            rotation=types['geometry_msgs/msg/Quaternion'](*map(float, quaternion))))
    return types[TF](transforms=[transform])


def rclpy_tf(stamp, parent, child, position, quaternion):
    from geometry_msgs.msg import Quaternion, Transform, TransformStamped, Vector3
    x, y, z = map(float, position)
    qx, qy, qz, qw = map(float, quaternion)
    return TFMessage(transforms=[TransformStamped(
        header=messages.header(parent, stamp), child_frame_id=child,
        transform=Transform(translation=Vector3(x=x, y=y, z=z),
                            rotation=Quaternion(x=qx, y=qy, z=qz, w=qw)))])


def _bits(values):
    return struct.pack(f'<{len(values)}d', *values)


def check_tf(data, stamp, parent, child, position, quaternion):
    """Bytes equal rosbags' serializer's; every decoder gives the inputs back bit for bit."""
    assert data == bytes(TYPESTORE.serialize_cdr(
        rosbags_tf(stamp, parent, child, position, quaternion), TF))
    decoded = [TYPESTORE.deserialize_cdr(data, TF)]
    if HAVE_TF_DEFINITION:
        decoded.append(mcap_decode(data, TF))
    if TFMessage is not None:
        check(data, rclpy_tf(stamp, parent, child, position, quaternion))
    for msg in decoded:
        (t,) = msg.transforms
        assert divmod(int(stamp), 10**9) == (t.header.stamp.sec, t.header.stamp.nanosec)
        assert (t.header.frame_id, t.child_frame_id) == (parent, child)
        tr, rot = t.transform.translation, t.transform.rotation
        assert _bits([tr.x, tr.y, tr.z]) == _bits(position)
        assert _bits([rot.x, rot.y, rot.z, rot.w]) == _bits(quaternion)


@SETTINGS
@given(stamps=st.lists(stamps, min_size=4, max_size=4), parent=frames, child=frames,
       positions=rows(3), quaternions=rows(4))
def test_tf_message(stamps, parent, child, positions, quaternions):
    n = min(len(positions), len(quaternions))
    encoded = cdr.encode_tf_message(np.array(stamps[:n]), parent, child, positions[:n],
                                    quaternions[:n])
    assert len(encoded) == n
    for i in range(n):
        check_tf(encoded[i], stamps[i], parent, child, positions[i], quaternions[i])


@pytest.mark.parametrize('length', range(10))
def test_tf_every_frame_padding(length):
    """Parent and child frame ids of 0..9 bytes: every padding before the float64 block."""
    t = np.array([0, 1_700_000_000_123_456_789, NS_MAX, NS_MIN])
    xyz = np.array([[1.5, -0.0, 5e-324], [1e300, -2.0, 3.0], [0.0, 7.0, -1e-310],
                    [np.inf, -np.inf, np.nan]])
    quat = np.array([[0.0, 0.0, 0.0, 1.0], [0.5, -0.5, 0.5, -0.5], [1.0, 2.0, 3.0, 4.0],
                     [-0.0, 1e-300, 0.25, -1.0]])
    for parent, child in (('abcdefghi'[:length], 'twodisk_body'), ('world', 'xyz012345'[:length])):
        encoded = cdr.encode_tf_message(t, parent, child, xyz, quat)
        for i, data in enumerate(encoded):
            check_tf(data, t[i], parent, child, xyz[i], quat[i])


def test_tf_same_numbers_as_pose_stamped():
    """The transform's stamp, frame and numbers are the PoseStamped's bytes, shifted."""
    t = np.array([5, 10**9 + 7])
    xyz = np.array([[0.1, 0.2, 0.3], [-1.0, 2.0, -3.0]])
    quat = np.array([[0.0, 0.0, 0.0, 1.0], [0.5, 0.5, 0.5, 0.5]])
    tf = cdr.encode_tf_message(t, 'world', 'twodisk_body', xyz, quat)
    pose = cdr.encode_pose_stamped(t, 'world', xyz, quat)
    for a, b in zip(tf, pose):
        assert a[-56:] == b[-56:] and a[8:16] == b[4:12]


@SETTINGS
@given(times=st.lists(stamps, min_size=0, max_size=5))
def test_clock(times):
    encoded = cdr.encode_clock(np.array(times, np.int64))
    assert len(encoded) == len(times)
    for data, ns in zip(encoded, times):
        msg = Clock(clock=messages.stamp(ns))
        check(data, msg)
        assert data == bytes(TYPESTORE.serialize_cdr(
            TYPESTORE.deserialize_cdr(data, 'rosgraph_msgs/msg/Clock'), 'rosgraph_msgs/msg/Clock'))
        got = TYPESTORE.deserialize_cdr(data, 'rosgraph_msgs/msg/Clock').clock
        assert (got.sec, got.nanosec) == divmod(ns, 10**9)
        assert len(data) == 12


def test_invalid_input():
    zeros3, zeros4 = np.zeros((1, 3)), np.zeros((1, 4))
    with pytest.raises(ValueError, match='shape'):
        cdr.encode_tf_message([1], 'w', 'b', zeros4, zeros4)
    with pytest.raises(ValueError, match='NUL'):
        cdr.encode_tf_message([1], 'w', 'b\x00', zeros3, zeros4)
    with pytest.raises(ValueError, match='int32'):
        cdr.encode_clock([NS_MAX + 1])
    with pytest.raises(TypeError, match='integer'):
        cdr.encode_clock([0.5])
    assert cdr.encode_clock([]) == []
    assert cdr.encode_tf_message([], 'w', 'b', np.zeros((0, 3)), np.zeros((0, 4))) == []
