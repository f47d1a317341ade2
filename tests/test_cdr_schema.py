"""Tests of twodisk_ros.recordings.cdr_schema: layouts derived from the .msg definitions.

For every message of ``test_cdr_generic`` (markers, diagnostics, and the other types: fixed
arrays, bounded and unbounded sequences of primitives, strings and messages, bool, octet,
char, empty messages), the fields of the rclpy object are split here, from its own type
strings (``get_fields_and_field_types``, not the definitions the builder reads), into batch
constants (strings), sequence counts and numeric columns; the layout filled with those columns
must give the bytes that ``test_cdr_generic.check`` verifies against rclpy's
``serialize_message`` (data bytes and length), a scalar reference writer, rosbags and
mcap-ros2-support.  Declared defaults (Quaternion's w = 1, NavSatStatus's status = -2) are
compared with rclpy's default-constructed objects.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '91')

import re  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

pytest.importorskip('rclpy.serialization')
pytest.importorskip('rosbags.typesys')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import Quaternion  # noqa: E402
from rcl_interfaces.msg import ParameterDescriptor  # noqa: E402
from sensor_msgs.msg import NavSatStatus  # noqa: E402
from visualization_msgs.msg import MarkerArray  # noqa: E402

from test_cdr_generic import (OTHER, SETTINGS, check, headers, markers,  # noqa: E402
                              small_lists, statuses)
from twodisk_ros.recordings import cdr_schema, msgdefs  # noqa: E402

pytestmark = pytest.mark.ros
_PRIMITIVE = {'boolean', 'octet', 'char', 'int8', 'uint8', 'int16', 'uint16', 'int32', 'uint32',
              'int64', 'uint64', 'float', 'double'}
_SEQUENCE = re.compile(r'^sequence<(.+?)(?:, \d+)?>$')
_ARRAY = re.compile(r'^(.+)\[(\d+)\]$')
_STRING = re.compile(r'^string(?:<\d+>)?$')


def _number(kind, value):
    if kind == 'octet' and isinstance(value, (bytes, bytearray)):
        return value[0]
    return value


def split(msg, prefix='', parts=None):
    """(constants, counts, columns) of an rclpy message, by the builder's dotted paths."""
    constants, counts, columns = parts if parts is not None else ({}, {}, {})
    for name, kind in msg.get_fields_and_field_types().items():
        path, value = prefix + name, getattr(msg, name)
        sequence, array = _SEQUENCE.match(kind), _ARRAY.match(kind)
        item = (sequence or array).group(1) if (sequence or array) else kind
        if sequence or array:
            if isinstance(value, (bytes, bytearray)):
                value = list(value)
            if _STRING.match(item):
                constants[path] = list(value)
            elif item in _PRIMITIVE:
                if sequence:
                    counts[path] = len(value)
                if len(value):
                    columns[path] = [_number(item, v) for v in value]
            else:
                if sequence:
                    counts[path] = len(value)
                for k, element in enumerate(value):
                    split(element, f'{path}[{k}].', (constants, counts, columns))
        elif _STRING.match(kind):
            constants[path] = value
        elif kind in _PRIMITIVE:
            columns[path] = _number(kind, value)
        else:
            split(value, path + '.', (constants, counts, columns))
    return constants, counts, columns


def built(msg):
    """The message through message_layout, from the parts of split()."""
    constants, counts, columns = split(msg)
    layout = cdr_schema.message_layout(msgdefs.ros_type_name(type(msg)), constants, counts)
    return layout.fill(1, **columns).tobytes()


@pytest.mark.parametrize('msg', OTHER, ids=lambda m: type(m).__name__)
def test_other_types(msg):
    assert built(msg) == check(msg)


@SETTINGS
@given(st.lists(markers, max_size=3))
def test_marker_array(marker_list):
    msg = MarkerArray(markers=marker_list)
    assert built(msg) == check(msg)


@SETTINGS
@given(st.builds(DiagnosticArray, header=headers, status=small_lists(statuses, 3)))
def test_diagnostic_array(msg):
    assert built(msg) == check(msg)


@pytest.mark.parametrize('msg_type', [Quaternion, NavSatStatus, ParameterDescriptor])
def test_declared_defaults_are_rclpys(msg_type):
    """A field not given has the default the definition declares (rclpy's default object)."""
    layout = cdr_schema.message_layout(msgdefs.ros_type_name(msg_type))
    assert layout.fill(1).tobytes() == check(msg_type())


def test_fields_from_the_definition():
    fields = cdr_schema.message_fields('sensor_msgs/msg/CameraInfo')
    assert [f.name for f in fields] == ['header', 'height', 'width', 'distortion_model', 'd',
                                        'k', 'r', 'p', 'binning_x', 'binning_y', 'roi']
    by_name = {f.name: f for f in fields}
    assert (by_name['d'].array, by_name['k'].array, by_name['p'].array) == (-1, 9, 12)
    assert by_name['roi'].type == 'sensor_msgs/msg/RegionOfInterest'
    assert by_name['header'].type == 'std_msgs/msg/Header'
    # constants (Marker.ARROW=0, ...) are not fields
    assert 'ARROW' not in {f.name for f in cdr_schema.message_fields(
        'visualization_msgs/msg/Marker')}


def test_groups_of_fields_are_one_column():
    layout = cdr_schema.message_layout('geometry_msgs/msg/PoseStamped',
                                       {'header.frame_id': 'world'})
    offset, dtype, count = layout.block('pose')
    assert (dtype, count) == (np.dtype('<f8'), 7)
    assert layout.block('header.stamp')[1:] == (np.dtype('<i4'), 2)
    with pytest.raises(ValueError, match='contiguous'):
        cdr_schema.message_layout('sensor_msgs/msg/CameraInfo').block('roi')   # u32 + bool
    with pytest.raises(KeyError):
        layout.block('pose.nothing')


def test_bad_constants_and_counts():
    with pytest.raises(KeyError, match='frame'):
        cdr_schema.message_layout('geometry_msgs/msg/PoseStamped', {'header.frame': 'w'})
    with pytest.raises(KeyError, match='transform'):
        cdr_schema.message_layout('tf2_msgs/msg/TFMessage', counts={'transform': 1})
    with pytest.raises(ValueError, match='NUL'):
        cdr_schema.message_layout('geometry_msgs/msg/PoseStamped', {'header.frame_id': 'a\0'})
    with pytest.raises(ValueError, match='bound'):
        cdr_schema.message_layout('shape_msgs/msg/SolidPrimitive', counts={'dimensions': 4})
    with pytest.raises(msgdefs.DefinitionNotFoundError):
        cdr_schema.message_layout('no_such_msgs/msg/Nothing')


def test_layouts_are_cached():
    a = cdr_schema.message_layout('sensor_msgs/msg/JointState', {'name': ['a', 'b']},
                                  {'position': 2})
    b = cdr_schema.message_layout('sensor_msgs/msg/JointState', {'name': ('a', 'b')},
                                  {'position': 2})
    assert a is b


def test_long_sequences_repeat_one_element_layout():
    """1000 points, colours and uv coordinates: the repeated elements are addressable one by
    one and as one column, and give rclpy's bytes."""
    from geometry_msgs.msg import Point
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker, UVCoordinate
    rng = np.random.default_rng(3)
    xyz = rng.normal(size=(1000, 3))
    rgba = rng.random((1000, 4)).astype(np.float32)
    marker = Marker(ns='n', id=7, points=[Point(x=a, y=b, z=c) for a, b, c in xyz.tolist()],
                    colors=[ColorRGBA(r=float(r), g=float(g), b=float(b), a=float(a))
                            for r, g, b, a in rgba],
                    uv_coordinates=[UVCoordinate(u=float(u), v=float(v)) for u, v in rgba[:, :2]])
    msg = MarkerArray(markers=[marker])
    expected = check(msg)
    assert built(msg) == expected           # element by element, names like points[637].y
    layout = cdr_schema.message_layout(
        'visualization_msgs/msg/MarkerArray', {'markers[0].ns': 'n'},
        {'markers': 1, 'markers[0].points': 1000, 'markers[0].colors': 1000,
         'markers[0].uv_coordinates': 1000})
    whole = layout.fill(1, **{'markers[0].id': 7, 'markers[0].points': xyz.ravel(),
                              'markers[0].colors': rgba.ravel(),
                              'markers[0].uv_coordinates': rgba[:, :2].ravel()})
    assert whole.tobytes() == expected
    assert layout.block('markers[0].points')[2] == 3000
    with pytest.raises(KeyError):
        layout.block('markers[0].points[1000].x')


def test_declared_defaults_of_every_kind(tmp_path, monkeypatch):
    """A definition with constants, comments and defaults of each kind, laid out by hand."""
    import struct
    folder = tmp_path / 'share' / 'twodisk_test_msgs' / 'msg'
    folder.mkdir(parents=True)
    (folder / 'Defaults.msg').write_text(
        '# a comment line\n'
        'int32 CONSTANT=5\n'
        'string NAME="x # y"\n'
        'float64[] seq [1.5, -2.0]   # a sequence default\n'
        'int16[3] fixed [1, 2, -3]\n'
        'bool flag true\n'
        'string text "hello"\n'
        'uint8 last\n')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path))
    expected = (b'\x00\x01\x00\x00' + struct.pack('<I', 2) + bytes(4)
                + struct.pack('<2d3h?', 1.5, -2.0, 1, 2, -3, True) + bytes(1)
                + struct.pack('<I', 6) + b'hello\x00' + b'\x00')
    layout = cdr_schema.message_layout('twodisk_test_msgs/msg/Defaults')
    assert layout.fill(1).tobytes() == expected
    assert [f.name for f in cdr_schema.message_fields('twodisk_test_msgs/msg/Defaults')] == [
        'seq', 'fixed', 'flag', 'text', 'last']
    three = cdr_schema.message_layout('twodisk_test_msgs/msg/Defaults', {'text': ''},
                                      {'seq': 3})
    data = three.fill(1, seq=[1.0, 2.0, 3.0], last=7).tobytes()
    assert data[4:8] == struct.pack('<I', 3) and data[12:36] == struct.pack('<3d', 1, 2, 3)
    assert data.endswith(struct.pack('<I', 1) + b'\x00' + b'\x07')
