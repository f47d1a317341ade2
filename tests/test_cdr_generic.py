"""Tests of twodisk_ros.recordings.cdr.serialize, the field-by-field CDR writer for any rclpy message.

Each message is checked against: a scalar reference writer written here, which walks the type
*strings* of ``get_fields_and_field_types()`` (not the ``SLOT_TYPES`` that ``serialize`` walks)
and records where the padding is; ``rclpy.serialization.serialize_message`` at every data byte
(its padding is uninitialised memory), with its length checked to be Fast-CDR's size estimate;
the decoders of rclpy, rosbags (strict about the size; its re-serialisation must give our bytes
back) and mcap-ros2-support, field by field, floats bit for bit; and, for the four fixed-layout
messages, the vectorised encoders of the same module.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '91')

import re  # noqa: E402
import struct  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

rclpy_serialization = pytest.importorskip('rclpy.serialization')
typesys = pytest.importorskip('rosbags.typesys')

from builtin_interfaces.msg import Duration, Time  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue  # noqa: E402
from geometry_msgs.msg import (Point, Pose, PoseWithCovariance,  # noqa: E402
                               Quaternion, Twist, TwistWithCovariance, Vector3, Wrench,
                               WrenchStamped)
from nav_msgs.msg import Odometry  # noqa: E402
from rcl_interfaces.msg import ParameterValue  # noqa: E402
from sensor_msgs.msg import (CameraInfo, CompressedImage, Image, Imu, JointState,  # noqa: E402
                             PointCloud2, PointField, RegionOfInterest)
from shape_msgs.msg import SolidPrimitive  # noqa: E402
from std_msgs.msg import (Bool, Byte, ByteMultiArray, Char, ColorRGBA, Empty,  # noqa: E402
                          Float32MultiArray, Int8MultiArray, MultiArrayDimension,
                          MultiArrayLayout, String, UInt64)
from type_description_interfaces.msg import FieldType  # noqa: E402
from unique_identifier_msgs.msg import UUID  # noqa: E402
from visualization_msgs.msg import Marker, MarkerArray, MeshFile, UVCoordinate  # noqa: E402

from cdr_helpers import mcap_decode  # noqa: E402
from twodisk_ros.recordings import cdr, msgdefs  # noqa: E402
from twodisk_ros.node import messages  # noqa: E402

serialize_message = rclpy_serialization.serialize_message
deserialize_message = rclpy_serialization.deserialize_message
TYPESTORE = typesys.get_typestore(typesys.Stores.ROS2_JAZZY)
pytestmark = pytest.mark.ros


# -- the scalar reference writer, from the type strings -----------------------------------------
_FORMATS = {'boolean': '?', 'octet': 'B', 'char': 'B', 'int8': 'b', 'uint8': 'B', 'int16': 'h',
            'uint16': 'H', 'int32': 'i', 'uint32': 'I', 'int64': 'q', 'uint64': 'Q',
            'float': 'f', 'double': 'd'}
_SEQUENCE = re.compile(r'^sequence<([^,>]+)(?:, \d+)?>$')
_ARRAY = re.compile(r'^(.+)\[\d+\]$')
_STRING = re.compile(r'^string(?:<\d+>)?$')


def _octet(value):
    """An octet as 0..255: rclpy has ``bytes`` of length 1, rosbags decodes ``int8``."""
    return value[0] if isinstance(value, bytes) else int(value) % 256


class ReferenceWriter:
    """Plain CDR (XCDR1, little endian) one element at a time; padding zero, its positions kept.

    With ``fastcdr_size``, an empty sequence of a primitive is aligned for its elements all the
    same: that is Fast-CDR's size estimate, the length ``serialize_message`` returns.
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
        if kind in _FORMATS:
            self.align(struct.calcsize(_FORMATS[kind]))
            self.data += struct.pack('<' + _FORMATS[kind],
                                     _octet(value) if kind == 'octet' else value)
        elif _STRING.match(kind):
            text = value.encode('utf-8')
            self.write('uint32', len(text) + 1)
            self.data += text + b'\x00'
        elif _SEQUENCE.match(kind):
            item_kind = _SEQUENCE.match(kind).group(1)
            self.write('uint32', len(value))
            if self.fastcdr_size and not len(value) and item_kind in _FORMATS:
                self.align(struct.calcsize(_FORMATS[item_kind]))
            for item in value:
                self.write(item_kind, item)
        elif _ARRAY.match(kind):
            for item in value:
                self.write(_ARRAY.match(kind).group(1), item)
        else:
            fields = value.get_fields_and_field_types()
            if not fields:          # rosidl's structure_needs_at_least_one_member
                self.write('uint8', 0)
            for name, field_kind in fields.items():
                self.write(field_kind, getattr(value, name))
        return self


# -- field-by-field comparison with decoded messages, floats bit for bit ------------------------
def assert_same(expected, got, kind='message', where='msg'):
    if kind in ('double', 'float'):
        fmt = '<d' if kind == 'double' else '<f'
        assert struct.pack(fmt, float(expected)) == struct.pack(fmt, float(got)), where
    elif kind == 'octet':
        assert _octet(expected) == _octet(got), where
    elif kind == 'boolean':
        assert bool(expected) is bool(got), where
    elif kind in _FORMATS:
        assert int(expected) == int(got), where
    elif _STRING.match(kind):
        assert expected == got, where
    elif _SEQUENCE.match(kind) or _ARRAY.match(kind):
        item_kind = (_SEQUENCE.match(kind) or _ARRAY.match(kind)).group(1)
        assert len(expected) == len(got), where
        for i, (a, b) in enumerate(zip(expected, got)):
            assert_same(a, b, item_kind, f'{where}[{i}]')
    else:
        for name, field_kind in expected.get_fields_and_field_types().items():
            assert_same(getattr(expected, name), getattr(got, name), field_kind,
                        f'{where}.{name}')




def check(msg):
    """Every check of ``cdr.serialize(msg)``; returns our bytes."""
    name = msgdefs.ros_type_name(type(msg))
    ours = cdr.serialize(msg)
    ref = ReferenceWriter().write('message', msg)
    assert ours == bytes(ref.data)                  # exact, padding and length included
    assert all(ours[i] == 0 for i in ref.padding)
    raw = serialize_message(msg)
    assert all(raw[i] == ours[i] for i in range(len(ours)) if i not in ref.padding)
    # Its length: Fast-CDR's estimate, and at least 4 payload bytes (Bool, Int16, Empty: 8 in
    # all); the surplus over ours is unwritten padding after the last field.
    estimate = len(ReferenceWriter(fastcdr_size=True).write('message', msg).data)
    assert len(raw) == max(estimate, 8) >= len(ours)
    assert_same(msg, deserialize_message(ours, type(msg)))
    decoded = TYPESTORE.deserialize_cdr(ours, name)
    assert_same(msg, decoded)
    assert bytes(TYPESTORE.serialize_cdr(decoded, name)) == ours
    assert_same(msg, mcap_decode(ours, name))
    return ours


# -- strategies ---------------------------------------------------------------------------------
SETTINGS = settings(max_examples=30, deadline=None)
SPECIAL = [0.0, -0.0, 5e-324, -1e-310, 1e300, -1.7976931348623157e308, float('inf'),
           float('-inf'), float('nan'), 1.0]
f64 = st.one_of(st.sampled_from(SPECIAL), st.floats())
f32 = st.floats(width=32, allow_nan=False)
int32 = st.integers(-2**31, 2**31 - 1)
uint32 = st.integers(0, 2**32 - 1)
texts = st.one_of(st.text('abc_/0', max_size=9),
                  st.text(st.characters(codec='utf-8', exclude_characters='\x00'), max_size=12))


def small_lists(elements, max_size=4):
    return st.lists(elements, max_size=max_size)


times = st.builds(Time, sec=int32, nanosec=st.integers(0, 999_999_999))
headers = st.builds(messages.Header, stamp=times, frame_id=texts)
points = st.builds(Point, x=f64, y=f64, z=f64)
vectors = st.builds(Vector3, x=f64, y=f64, z=f64)
poses = st.builds(Pose, position=points,
                  orientation=st.builds(Quaternion, x=f64, y=f64, z=f64, w=f64))
colors = st.builds(ColorRGBA, r=f32, g=f32, b=f32, a=f32)
uint8_lists = small_lists(st.integers(0, 255), 7)

markers = st.builds(
    Marker, header=headers, ns=texts, id=int32, type=st.integers(0, 11),
    action=st.integers(0, 3), pose=poses, scale=vectors, color=colors,
    lifetime=st.builds(Duration, sec=int32, nanosec=uint32), frame_locked=st.booleans(),
    points=small_lists(points), colors=small_lists(colors), texture_resource=texts,
    texture=st.builds(CompressedImage, header=headers, format=texts, data=uint8_lists),
    uv_coordinates=small_lists(st.builds(UVCoordinate, u=f32, v=f32)), text=texts,
    mesh_resource=st.one_of(texts, st.just('package://twodisk_ros/meshes/disk.dae')),
    mesh_file=st.builds(MeshFile, filename=texts, data=uint8_lists),
    mesh_use_embedded_materials=st.booleans())

statuses = st.builds(
    DiagnosticStatus, level=st.sampled_from([b'\x00', b'\x01', b'\x02', b'\x03']), name=texts,
    message=texts, hardware_id=texts,
    values=small_lists(st.builds(KeyValue, key=texts, value=texts)))


# -- the node's messages ------------------------------------------------------------------------
@SETTINGS
@given(st.lists(markers, max_size=3))
def test_marker_array(marker_list):
    check(MarkerArray(markers=marker_list))


@SETTINGS
@given(st.builds(DiagnosticArray, header=headers, status=small_lists(statuses, 3)))
def test_diagnostic_array(msg):
    check(msg)


@pytest.mark.parametrize('length', range(10))
def test_marker_array_every_frame_id_length(length):
    """All fields non-default; frame ids of 0..9 bytes (every padding after the strings)."""
    frame = 'abcdefghi'[:length]
    marker_list = messages.body_markers(frame, 1_700_000_000_123_456_789, np.eye(3),
                                        -np.eye(3)[:length % 3], (0, 0, 1), (1, 0, 0), 0.3).markers
    marker_list.append(Marker(
        header=messages.header(frame[::-1], -5), ns='ns' * length, id=-7,
        type=Marker.MESH_RESOURCE, action=Marker.MODIFY,
        pose=messages.pose_stamped('', 0, (1, 2, 3), (0.5, -0.5, 0.5, -0.5)).pose,
        scale=Vector3(x=1.5, y=2.5, z=-3.5), color=ColorRGBA(r=0.1, g=0.2, b=0.3, a=0.4),
        lifetime=Duration(sec=3, nanosec=4), frame_locked=True,
        points=[messages.point((k, -k, 1e-310)) for k in range(length)],
        colors=[ColorRGBA(r=float(k), a=1.0) for k in range(length % 4)],
        texture_resource='embedded://tex.png'[:length + 4],
        texture=CompressedImage(header=messages.header('cam', 9), format='png',
                                data=list(range(length))),
        uv_coordinates=[UVCoordinate(u=0.25, v=float(k)) for k in range(length % 3)],
        text='θ = 1.5 rad ✓'[:length], mesh_resource='package://twodisk_ros/meshes/disk.stl',
        mesh_file=MeshFile(filename='disk.stl'[:length], data=[1, 2, 3][:length]),
        mesh_use_embedded_materials=True))
    check(MarkerArray(markers=marker_list))
    check(messages.diagnostics(10**9 + length, 'twodisk/integrator' + 'é' * length, messages.WARN,
                               'step rejected ⚠', [('energy drift', 1.5e-9), ('steps', length),
                                                    ('ключ', 'значение'[:length])]))


# -- the fixed-layout messages, against the vectorised encoders ---------------------------------
NS_MIN, NS_MAX = -2**31 * 10**9, (2**31 - 1) * 10**9 + 999_999_999
stamps = st.integers(NS_MIN, NS_MAX)


@SETTINGS
@given(stamp=stamps, frame=texts, xyz=st.tuples(f64, f64, f64),
       q=st.tuples(f64, f64, f64, f64))
def test_pose_and_point_stamped_as_the_vectorised_encoders(stamp, frame, xyz, q):
    ours = check(messages.pose_stamped(frame, stamp, xyz, q))
    assert ours == cdr.encode_pose_stamped([stamp], frame, [xyz], [q])[0]
    ours = check(messages.point_stamped(frame, stamp, xyz))
    assert ours == cdr.encode_point_stamped([stamp], frame, [xyz])[0]


@SETTINGS
@given(stamp=stamps, frame=texts, names=small_lists(texts, 5), data=st.data())
def test_joint_state_as_the_vectorised_encoder(stamp, frame, names, data):
    k = len(names)
    values = [data.draw(st.lists(f64, min_size=k, max_size=k)) for _ in range(3)]
    header = messages.header(frame, stamp)
    ours = check(JointState(header=header, name=names, position=values[0], velocity=values[1]))
    assert ours == cdr.encode_joint_state([stamp], names, [values[0]], [values[1]], frame)[0]
    ours = check(JointState(header=header, name=names, position=values[0]))
    assert ours == cdr.encode_joint_state([stamp], names, [values[0]], frame_id=frame)[0]
    check(JointState(header=header, name=names, position=values[0], velocity=values[1],
                     effort=values[2]))     # non-empty effort (empty if k == 0)


@SETTINGS
@given(stamp=stamps, frame=texts, data=st.data())
def test_path_as_the_vectorised_encoder(stamp, frame, data):
    xyz = data.draw(small_lists(st.tuples(f64, f64, f64)))
    q = data.draw(st.lists(st.tuples(f64, f64, f64, f64), min_size=len(xyz), max_size=len(xyz)))
    pose_stamps = data.draw(st.lists(stamps, min_size=len(xyz), max_size=len(xyz)))
    path = messages.path(frame, stamp, [messages.pose_stamped(frame, *args)
                                        for args in zip(pose_stamps, xyz, q)])
    assert check(path) == cdr.encode_path(stamp, frame, xyz, q or None, pose_stamps)


# -- other common types -------------------------------------------------------------------------
@SETTINGS
@given(st.builds(WrenchStamped, header=headers,
                 wrench=st.builds(Wrench, force=vectors, torque=vectors)))
def test_wrench_stamped(msg):
    ours = check(msg)
    stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
    f, t = msg.wrench.force, msg.wrench.torque
    assert ours == cdr.encode_wrench_stamped([stamp], msg.header.frame_id, [[f.x, f.y, f.z]],
                                             [[t.x, t.y, t.z]])[0]


def _covariance(n):
    return np.linspace(-1.0, 1.0, n) * 1e-3


OTHER = [
    Imu(header=messages.header('imu_link', 12_345), orientation=Quaternion(x=0.1, w=0.9),
        orientation_covariance=_covariance(9), angular_velocity=Vector3(x=1.0, y=-2.0, z=3.0),
        angular_velocity_covariance=-_covariance(9), linear_acceleration=Vector3(z=9.81),
        linear_acceleration_covariance=_covariance(9) + 1),
    Odometry(header=messages.header('odom', 7), child_frame_id='base_link',
             pose=PoseWithCovariance(pose=messages.pose_stamped('', 0, (1, 2, 3),
                                                                (0, 0, 0.6, 0.8)).pose,
                                     covariance=_covariance(36)),
             twist=TwistWithCovariance(twist=Twist(linear=Vector3(x=0.5)),
                                       covariance=-_covariance(36))),
    String(data='hello, wörld ✓'), String(), Time(sec=-3, nanosec=999_999_999),
    Duration(sec=2**31 - 1, nanosec=1), Empty(), Bool(data=True), Byte(data=b'\xfe'),
    Char(data=65), UInt64(data=2**64 - 1),
    ParameterValue(type=9, bool_value=True, integer_value=-2**63, double_value=-0.0,
                   string_value='x', byte_array_value=[b'\x00', b'\xff', b'a'],
                   bool_array_value=[True, False, True], integer_array_value=[1, -2, 2**62],
                   double_array_value=[1.5], string_array_value=['', 'a', 'ab', 'abc', 'abcd']),
    ParameterValue(byte_array_value=b'xyz'),
    UUID(uuid=list(range(16))),
    FieldType(type_id=17, capacity=3, string_capacity=2**64 - 1, nested_type_name='pkg/msg/T'),
    SolidPrimitive(type=SolidPrimitive.CYLINDER, dimensions=[0.5, 0.25]),
    SolidPrimitive(type=SolidPrimitive.BOX, dimensions=[1.0, 2.0, 3.0]),
    Image(header=messages.header('cam', 1), height=2, width=3, encoding='mono8',
          is_bigendian=1, step=3, data=list(range(6))),
    PointCloud2(header=messages.header('lidar', 2), height=1, width=2,
                fields=[PointField(name=c, offset=4 * i, datatype=PointField.FLOAT32, count=1)
                        for i, c in enumerate('xyz')],
                is_bigendian=False, point_step=12, row_step=24,
                data=np.arange(24, dtype=np.uint8).tolist(), is_dense=True),
    CameraInfo(header=messages.header('cam', 3), height=480, width=640,
               distortion_model='plumb_bob', d=[0.1, -0.2, 0.0, 0.0, 0.05],
               k=_covariance(9), r=np.eye(3).ravel(), p=_covariance(12), binning_x=2,
               roi=RegionOfInterest(x_offset=1, y_offset=2, height=3, width=4, do_rectify=True)),
    CameraInfo(),
    ByteMultiArray(layout=MultiArrayLayout(dim=[MultiArrayDimension(label='a', size=3,
                                                                    stride=3)],
                                           data_offset=1), data=[b'\x01', b'\x02', b'\x03']),
    Int8MultiArray(data=[-128, 0, 127]), Float32MultiArray(data=[1.5, -2.25, 3.0e38]),
    Float32MultiArray(),
]


@pytest.mark.parametrize('msg', OTHER, ids=lambda m: type(m).__name__)
def test_other_types(msg):
    check(msg)


# -- errors, duck typing ------------------------------------------------------------------------
def test_invalid_values():
    with pytest.raises(ValueError, match='NUL'):
        cdr.serialize(String(data='a\x00b'))
    msg = Imu()
    msg._orientation_covariance = np.zeros(8)      # bypassing the property's own check
    with pytest.raises(ValueError, match='fixed array'):
        cdr.serialize(msg)
    msg = SolidPrimitive()
    msg._dimensions = [1.0, 2.0, 3.0, 4.0]
    with pytest.raises(ValueError, match='bound'):
        cdr.serialize(msg)


def test_duck_typed_message_and_unsupported_types():
    """Any object with SLOT_TYPES and get_fields_and_field_types(); wstring is not supported."""
    definition = pytest.importorskip('rosidl_parser.definition')

    class Fake:
        SLOT_TYPES = (definition.BasicType('char'), definition.BasicType('double'),
                      definition.Array(definition.BasicType('char'), 2))

        def __init__(self, **values):
            self.__dict__.update(values)

        @classmethod
        def get_fields_and_field_types(cls):
            return {'c': 'char', 'x': 'double', 'cs': 'char[2]'}

    assert (cdr.serialize(Fake(c='A', x=1.0, cs=['B', 'C']))
            == b'\x00\x01\x00\x00A' + bytes(7) + struct.pack('<d', 1.0) + b'BC')
    Fake.SLOT_TYPES = (definition.UnboundedWString(),)
    with pytest.raises(TypeError, match='UnboundedWString'):
        cdr.serialize(Fake(c='x'))
    Fake.SLOT_TYPES = (definition.BasicType('wchar'),)
    with pytest.raises(TypeError, match='wchar'):
        cdr.serialize(Fake(c='x'))


@pytest.mark.parametrize('length', range(10))
def test_node_markers_encoded_from_arrays_as_the_generic_serializer(length):
    """io/cdr_markers (the node's fast path) against serialize() of the same rclpy markers."""
    from twodisk_ros.recordings.cdr_markers import encode_markers
    frame = 'abcdefghi'[:length]
    s = np.linspace(0.0, 2 * np.pi, 5 + 7 * length)
    disk1 = np.stack([np.sin(s), -0.5 - np.cos(s), 0 * s], -1)
    disk2 = np.stack([0 * s, 0.5 + np.cos(s), np.sin(s)], -1)
    hull = (disk1, disk2) if length % 2 else None
    specs = messages.body_marker_specs(disk1, disk2, (0, 0, 0), (1, 2, 0), 0.3, hull=hull)
    specs += messages.force_arrow_specs(((0, 0, 0), (1, 2, 0)), ((0.1, 0.2, 4.0),
                                                                 (0.0, -0.1, -0.5)), 9.81, 0.3)
    stamp = 1_700_000_000_123_456_789 + length
    expected = cdr.serialize(MarkerArray(markers=[messages.marker(frame, stamp, spec)
                                                  for spec in specs]))
    assert encode_markers(stamp, frame, specs) == expected
    assert check(MarkerArray(markers=[messages.marker(frame, stamp, spec) for spec in specs]))
