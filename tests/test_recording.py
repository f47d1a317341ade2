"""Tests of the MCAP layer, checked against references independent of the writer.

Messages are decoded with mcap-ros2-support's decoder through mcap's own reader, schemas are
rebuilt here from the .msg files, and the file structure is read with mcap's readers.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '57')

import shutil  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import textwrap  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402
import yaml  # noqa: E402
from builtin_interfaces.msg import Duration as DurationMsg  # noqa: E402
from builtin_interfaces.msg import Time  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue  # noqa: E402
from geometry_msgs.msg import (Point, PointStamped, Pose, PoseStamped,  # noqa: E402
                               Quaternion, Vector3)
from hypothesis import example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from mcap.reader import make_reader  # noqa: E402
from mcap.records import MessageIndex, SummaryOffset  # noqa: E402
from mcap.stream_reader import StreamReader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from nav_msgs.msg import Path as PathMsg  # noqa: E402
from rclpy.duration import Duration, Infinite  # noqa: E402
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, LivelinessPolicy,  # noqa: E402
                       QoSProfile, ReliabilityPolicy)
from rclpy.serialization import serialize_message  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import ColorRGBA, Header  # noqa: E402
from visualization_msgs.msg import Marker, MarkerArray  # noqa: E402

from twodisk_ros.recordings import msgdefs, rosbag2_metadata, writer  # noqa: E402
from twodisk_ros.recordings import McapRecorder, RecordingError, read_recording  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
T0 = 1_700_000_000 * 10**9


# ------------------------------------------------------------------------------------------
# Sample messages with distinctive values.

def header(i, frame='map'):
    return Header(stamp=Time(sec=1_700_000_000 + i, nanosec=1000 * i), frame_id=frame)


def pose(i):
    return Pose(position=Point(x=0.5 * i, y=-1.25, z=3.0 + i),
                orientation=Quaternion(x=0.0, y=0.6, z=0.0, w=0.8))


def pose_stamped(i):
    return PoseStamped(header=header(i), pose=pose(i))


def point_stamped(i):
    return PointStamped(header=header(i, 'contact'),
                        point=Point(x=1.0 / (i + 1), y=2.0, z=-float(i)))


def joint_state(i):
    return JointState(header=header(i, ''), name=['phi', 'theta', 'psi'],
                      position=[0.1 * i, 1.5, -2.25], velocity=[1.0, 2.0, 3.0], effort=[])


def path_msg(i):
    return PathMsg(header=header(i, 'odom'), poses=[pose_stamped(i + k) for k in range(4)])


def marker_array(i):
    line = Marker(header=header(i), ns='trace', id=7, type=Marker.LINE_STRIP,
                  action=Marker.ADD, pose=pose(i), scale=Vector3(x=0.01, y=0.0, z=0.0),
                  color=ColorRGBA(r=1.0, g=0.5, b=0.25, a=1.0),
                  lifetime=DurationMsg(sec=2, nanosec=5), frame_locked=True,
                  points=[Point(x=float(k), y=float(k * k), z=0.0) for k in range(5)],
                  colors=[ColorRGBA(r=0.125, g=0.25, b=0.375, a=0.5)] * 5)
    text = Marker(header=header(i), ns='label', id=8, type=Marker.TEXT_VIEW_FACING,
                  text=f'G at step {i}', mesh_resource='package://twodisk_ros/oloid.stl')
    text.mesh_file.filename = 'oloid.stl'
    text.mesh_file.data = [0, 1, 2, 255]
    return MarkerArray(markers=[line, text])


def diagnostic_array(i):
    status = DiagnosticStatus(level=DiagnosticStatus.WARN, name='roller: energy',
                              message='drift 1e-9', hardware_id='sim',
                              values=[KeyValue(key='step', value=str(i)),
                                      KeyValue(key='energy', value='-0.125')])
    return DiagnosticArray(header=header(i), status=[status])


SAMPLES = {
    '/pose': (PoseStamped, pose_stamped),
    '/contact': (PointStamped, point_stamped),
    '/joint_states': (JointState, joint_state),
    '/trace': (PathMsg, path_msg),
    '/markers': (MarkerArray, marker_array),
    '/diagnostics': (DiagnosticArray, diagnostic_array),
}


def write_samples(path, count=5, **kwargs):
    """Record ``count`` messages per sample topic; return them in write order."""
    written = []
    with McapRecorder(path, metadata={'package_version': '0.1.0', 'mass': '1.5'},
                      **kwargs) as rec:
        for topic, (msg_type, _) in SAMPLES.items():
            rec.add_topic(topic, msg_type)
        for i in range(count):
            for k, (topic, (_, make)) in enumerate(SAMPLES.items()):
                msg = make(i)
                stamp = T0 + i * 10**7 + k * 1000
                rec.write(topic, msg, stamp)
                written.append((topic, stamp, msg))
        assert rec.message_count == len(written)
    return written


def assert_same(expected, decoded, where='msg'):
    """Compare an rclpy message with an mcap_ros2-decoded one, field by field."""
    if hasattr(expected, 'get_fields_and_field_types'):
        for name in expected.get_fields_and_field_types():
            assert_same(getattr(expected, name), getattr(decoded, name), f'{where}.{name}')
    elif isinstance(expected, (list, tuple)) or hasattr(expected, 'tolist'):
        expected = list(expected)
        decoded = list(decoded)
        assert len(expected) == len(decoded), where
        for k, (a, b) in enumerate(zip(expected, decoded)):
            assert_same(a, b, f'{where}[{k}]')
    elif isinstance(expected, bytes) and isinstance(decoded, int):
        assert expected == bytes([decoded]), where  # ROS 'byte' fields: b'\x01' vs 1
    else:
        assert expected == decoded, where


def independent_messages(path):
    """Decode a file with mcap's reader and mcap_ros2's decoder: (topic, log_time, msg)."""
    with open(path, 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        return [(channel.topic, message.log_time, message.publish_time, decoded)
                for _, channel, message, decoded in reader.iter_decoded_messages(
                    log_time_order=False)]


def summary_of(path):
    with open(path, 'rb') as stream:
        reader = make_reader(stream)
        return reader.get_header(), reader.get_summary(), list(reader.iter_metadata())


# ------------------------------------------------------------------------------------------
# Message content.

def test_messages_decode_with_independent_decoder(tmp_path):
    path = tmp_path / 'run.mcap'
    written = write_samples(path)
    decoded = independent_messages(path)
    assert len(decoded) == len(written) == 30
    for (topic, stamp, msg), (d_topic, log_time, publish_time, d_msg) in zip(written, decoded):
        assert (d_topic, log_time, publish_time) == (topic, stamp, stamp)
        assert_same(msg, d_msg, topic)


def test_read_recording_gives_the_same_messages(tmp_path):
    path = tmp_path / 'run.mcap'
    written = write_samples(path)
    rec = read_recording(path)
    assert not rec.truncated
    assert rec.recovered_bytes == rec.total_bytes == path.stat().st_size
    assert [(m.topic, m.log_time_ns) for m in rec.messages] == [(t, s) for t, s, _ in written]
    for (topic, _, msg), got in zip(written, rec.messages):
        assert got.type_name == msgdefs.ros_type_name(type(msg))
        assert_same(msg, got.msg, topic)
    assert rec.topics['/markers'].type_name == 'visualization_msgs/msg/MarkerArray'
    assert {t: i.message_count for t, i in rec.topics.items()} == {t: 5 for t in SAMPLES}
    assert rec.metadata['twodisk_ros'] == {'package_version': '0.1.0', 'mass': '1.5'}
    assert rec.profile == 'ros2' and 'twodisk_ros' in rec.library


def test_read_recording_decodes_only_the_selected_topics(tmp_path):
    path = tmp_path / 'run.mcap'
    written = write_samples(path, count=2)
    rec = read_recording(path, decode=lambda topic: topic == '/pose')
    assert [(m.topic, m.log_time_ns) for m in rec.messages] == [(t, s) for t, s, _ in written]
    with open(path, 'rb') as stream:
        raw = [message.data for _, _, message in make_reader(stream).iter_messages(
            log_time_order=False)]
    for (topic, _, msg), got, data in zip(written, rec.messages, raw):
        if topic == '/pose':
            assert_same(msg, got.msg, topic)
        else:
            assert got.msg == data
    assert rec.topics['/trace'].message_count == 2


@pytest.mark.parametrize('compression', ['zstd', 'lz4', 'none'])
def test_compressions_round_trip(tmp_path, compression):
    path = tmp_path / f'{compression}.mcap'
    written = write_samples(path, count=2, compression=compression, chunk_size=2048)
    _, summary, _ = summary_of(path)
    expected = '' if compression == 'none' else compression
    assert {c.compression for c in summary.chunk_indexes} == {expected}
    assert len(independent_messages(path)) == len(written)


def test_write_serialized_is_stored_verbatim(tmp_path):
    path = tmp_path / 'raw.mcap'
    data = serialize_message(pose_stamped(3))
    with McapRecorder(path) as rec:
        rec.add_topic('/pose', PoseStamped)
        rec.write_serialized('/pose', data, 42)
    with open(path, 'rb') as stream:
        (_, _, message), = make_reader(stream).iter_messages()
    assert message.data == data and message.log_time == message.publish_time == 42


# ------------------------------------------------------------------------------------------
# Schemas: the rosbag2 rule, rebuilt here from the .msg files line by line.

PRIMITIVES = {'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16',
              'int32', 'uint32', 'int64', 'uint64', 'string'}


def msg_text(type_name):
    package, *_, name = type_name.split('/')
    return (Path(sys.prefix, 'share', package, 'msg', name + '.msg')).read_text()


def field_types(text, package):
    found = set()
    for line in text.splitlines():
        words = line.split('#')[0].split()
        if len(words) < 2:
            continue
        base = words[0].split('[')[0].split('<')[0]
        if base not in PRIMITIVES:
            found.add(base if '/' in base else f'{package}/{base}')
    return sorted(found)


def expected_definition(type_name, seen):
    """rosbag2: own text, then each unseen dependency (sorted) after its MSG separator."""
    text = msg_text(type_name)
    for dep in field_types(text, type_name.split('/')[0]):
        if dep not in seen:
            seen.add(dep)
            text += '\n' + '=' * 80 + '\n' + f'MSG: {dep}\n' + expected_definition(dep, seen)
    return text


HEADER_SECTION = """
================================================================================
MSG: std_msgs/Header
# Standard metadata for higher-level stamped data types.
# This is generally used to communicate timestamped data
# in a particular coordinate frame.

# Two-integer timestamp that is expressed as seconds and nanoseconds.
builtin_interfaces/Time stamp
"""


def test_pose_stamped_schema_follows_rosbag2_rule(tmp_path):
    path = tmp_path / 'run.mcap'
    write_samples(path, count=1)
    _, summary, _ = summary_of(path)
    schemas = {s.name: s for s in summary.schemas.values()}
    schema = schemas['geometry_msgs/msg/PoseStamped']
    assert schema.encoding == 'ros2msg'
    text = schema.data.decode()
    assert text == expected_definition('geometry_msgs/msg/PoseStamped', set())
    assert text.startswith('# A Pose with reference coordinate frame and timestamp\n\n'
                           'std_msgs/Header header\nPose pose\n\n' + '=' * 80 + '\n'
                           'MSG: geometry_msgs/Pose\n')
    assert HEADER_SECTION in text
    sections = [line[5:] for line in text.splitlines() if line.startswith('MSG: ')]
    assert sections == ['geometry_msgs/Pose', 'geometry_msgs/Point', 'geometry_msgs/Quaternion',
                        'std_msgs/Header', 'builtin_interfaces/Time']


@pytest.mark.parametrize('msg_type', [t for t, _ in SAMPLES.values()])
def test_every_sample_schema_follows_rosbag2_rule(msg_type):
    name = msgdefs.ros_type_name(msg_type)
    assert msgdefs.full_text(name).decode() == expected_definition(name, set())


def test_one_schema_per_type(tmp_path):
    path = tmp_path / 'two.mcap'
    with McapRecorder(path) as rec:
        first = rec.add_topic('/a', PoseStamped)
        second = rec.add_topic('/b', PoseStamped)
        assert rec.add_topic('/a', PoseStamped) == first != second
        rec.write('/a', pose_stamped(0), 1)
        rec.write('/b', pose_stamped(1), 2)
    _, summary, _ = summary_of(path)
    assert len(summary.schemas) == 1 and len(summary.channels) == 2


def test_definitions_found_through_ament_prefix_path(tmp_path, monkeypatch):
    msg_dir = tmp_path / 'share' / 'std_msgs' / 'msg'
    msg_dir.mkdir(parents=True)
    (msg_dir / 'Header.msg').write_bytes(b'# overlay\nstring frame_id\n')
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.pathsep.join([str(tmp_path), '/nonexistent']))
    assert msgdefs.full_text('std_msgs/msg/Header') == b'# overlay\nstring frame_id\n'
    monkeypatch.delenv('AMENT_PREFIX_PATH')
    assert msgdefs.full_text('std_msgs/msg/Header').startswith(b'# Standard metadata')


# ------------------------------------------------------------------------------------------
# rosbag2 layout: profile, encodings, QoS, metadata, statistics, indexes.

DEFAULT_QOS_YAML = """\
- history: keep_last
  depth: 10
  reliability: reliable
  durability: volatile
  deadline:
    sec: 0
    nsec: 0
  lifespan:
    sec: 0
    nsec: 0
  liveliness: system_default
  liveliness_lease_duration:
    sec: 0
    nsec: 0
  avoid_ros_namespace_conventions: false"""


def test_profile_encodings_and_qos(tmp_path):
    path = tmp_path / 'qos.mcap'
    latched = QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=0,
                         reliability=ReliabilityPolicy.BEST_EFFORT,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL,
                         deadline=Duration(seconds=1, nanoseconds=500_000_000),
                         lifespan=Infinite, liveliness=LivelinessPolicy.AUTOMATIC,
                         liveliness_lease_duration=Duration(seconds=3))
    with McapRecorder(path) as rec:
        rec.add_topic('/pose', PoseStamped)
        rec.add_topic('/markers', MarkerArray, latched)
        rec.write('/pose', pose_stamped(0), T0)
        rec.write('/markers', marker_array(0), T0)
    head, summary, _ = summary_of(path)
    assert head.profile == 'ros2' and 'twodisk_ros' in head.library
    assert {s.encoding for s in summary.schemas.values()} == {'ros2msg'}
    channels = {c.topic: c for c in summary.channels.values()}
    assert {c.message_encoding for c in channels.values()} == {'cdr'}
    assert channels['/pose'].metadata['offered_qos_profiles'] == DEFAULT_QOS_YAML
    (qos,) = yaml.safe_load(channels['/markers'].metadata['offered_qos_profiles'])
    assert qos == {
        'history': 'keep_all', 'depth': 0, 'reliability': 'best_effort',
        'durability': 'transient_local', 'deadline': {'sec': 1, 'nsec': 500_000_000},
        'lifespan': {'sec': 9223372036, 'nsec': 854775807}, 'liveliness': 'automatic',
        'liveliness_lease_duration': {'sec': 3, 'nsec': 0},
        'avoid_ros_namespace_conventions': False}
    hash_file = Path(sys.prefix, 'share/geometry_msgs/msg/PoseStamped.json')
    assert channels['/pose'].metadata['topic_type_hash'] in hash_file.read_text()
    assert channels['/pose'].metadata['topic_type_hash'].startswith('RIHS01_')


def test_rosbag2_metadata_and_statistics(tmp_path):
    path = tmp_path / 'stats.mcap'
    written = write_samples(path, count=40, chunk_size=4096)
    _, summary, metadata = summary_of(path)
    stats = summary.statistics
    assert stats.message_count == len(written) == 240
    assert stats.message_start_time == T0 and stats.message_end_time == T0 + 39 * 10**7 + 5000
    by_topic = {summary.channels[c].topic: n for c, n in stats.channel_message_counts.items()}
    assert by_topic == {t: 40 for t in SAMPLES}
    assert stats.schema_count == stats.channel_count == 6
    assert stats.chunk_count == len(summary.chunk_indexes) > 1
    assert all(c.message_index_length > 0 for c in summary.chunk_indexes)

    names = [m.name for m in metadata]
    assert names == ['rosbag2', 'twodisk_ros', 'rosbag2', 'twodisk_ros']
    assert stats.metadata_count == 4
    first, last = (yaml.safe_load(m.metadata['serialized_metadata'])
                   for m in metadata if m.name == 'rosbag2')
    assert first['message_count'] == 0 and first['topics_with_message_count'] == []
    assert first['starting_time'] == {'nanoseconds_since_epoch': 2**63 - 1}
    assert last['message_count'] == stats.message_count
    assert last['version'] == 9 and last['storage_identifier'] == 'mcap'
    assert last['ros_distro'] == 'jazzy' and last['custom_data'] is None
    assert last['compression_format'] == last['compression_mode'] == ''
    assert last['starting_time'] == {'nanoseconds_since_epoch': T0}
    assert last['duration'] == {'nanoseconds': 39 * 10**7 + 5000}
    assert last['relative_file_paths'] == ['stats.mcap']
    assert last['files'] == [{'path': 'stats.mcap', 'starting_time': last['starting_time'],
                              'duration': last['duration'], 'message_count': 240}]
    topics = {t['topic_metadata']['name']: t for t in last['topics_with_message_count']}
    assert {name: t['message_count'] for name, t in topics.items()} == by_topic
    pose_meta = topics['/pose']['topic_metadata']
    assert pose_meta['type'] == 'geometry_msgs/msg/PoseStamped'
    assert pose_meta['serialization_format'] == 'cdr'
    assert pose_meta['offered_qos_profiles'] == yaml.safe_load(DEFAULT_QOS_YAML)

    with open(path, 'rb') as stream:
        records = list(StreamReader(stream, emit_chunks=True).records)
    assert sum(isinstance(r, SummaryOffset) for r in records) >= 5
    assert sum(isinstance(r, MessageIndex) for r in records) >= stats.chunk_count


def test_set_metadata_replaces_what_close_writes(tmp_path):
    path = tmp_path / 'meta.mcap'
    with McapRecorder(path) as rec:
        rec.set_metadata({'duration': '20.0', 'package_version': '0.1.0'})
        rec.set_metadata({'duration': '5.0'})
        with pytest.raises(TypeError):
            rec.set_metadata({'duration': 5.0})
    _, _, metadata = summary_of(path)
    assert [(m.name, m.metadata) for m in metadata if m.name == 'twodisk_ros'] == [
        ('twodisk_ros', {'duration': '5.0'})]
    assert read_recording(path).metadata['twodisk_ros'] == {'duration': '5.0'}


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=40))
@example('...')      # a document end marker, plain: the probe itself raised (found by hypothesis)
@example('---')
def test_metadata_yaml_reads_back_any_string(text):
    tree = {'name': text, 'list': [text, {'k': text}], 'empty': [], 'none': None}
    assert yaml.safe_load(rosbag2_metadata.dump_yaml(tree)) == tree


# ------------------------------------------------------------------------------------------
# Lifecycle and errors.

def test_close_is_idempotent_and_context_manager_finishes(tmp_path):
    path = tmp_path / 'life.mcap'
    rec = McapRecorder(path)
    rec.add_topic('/pose', PoseStamped)
    rec.write('/pose', pose_stamped(0), 5)
    rec.close()
    rec.close()
    assert rec.closed and not read_recording(path).truncated
    with pytest.raises(ValueError):
        rec.write('/pose', pose_stamped(1), 6)

    with pytest.raises(ZeroDivisionError):
        with McapRecorder(tmp_path / 'boom.mcap') as rec:
            rec.add_topic('/pose', PoseStamped)
            rec.write('/pose', pose_stamped(0), 5)
            1 / 0
    assert not read_recording(tmp_path / 'boom.mcap').truncated
    assert len(read_recording(tmp_path / 'boom.mcap').messages) == 1


def test_bad_writes_are_refused(tmp_path):
    with McapRecorder(tmp_path / 'bad.mcap') as rec:
        rec.add_topic('/pose', PoseStamped)
        with pytest.raises(ValueError, match='unknown topic'):
            rec.write('/nope', pose_stamped(0), 1)
        with pytest.raises(TypeError):
            rec.write('/pose', point_stamped(0), 1)
        with pytest.raises(ValueError):
            rec.write('/pose', pose_stamped(0), -1)
        with pytest.raises(TypeError):
            rec.write('/pose', pose_stamped(0), 1.5)
        with pytest.raises(ValueError):
            rec.add_topic('/pose', PointStamped)
        assert rec.message_count == 0


def assert_one_line_naming(error, path, reason):
    message = str(error.value)
    assert '\n' not in message and str(path) in message and reason in message.lower()


def test_unwritable_paths_raise_at_construction(tmp_path, monkeypatch):
    missing = tmp_path / 'no' / 'such' / 'dir' / 'run.mcap'
    with pytest.raises(RecordingError) as error:
        McapRecorder(missing)
    assert_one_line_naming(error, missing, 'does not exist')

    with pytest.raises(RecordingError) as error:
        McapRecorder(tmp_path)
    assert_one_line_naming(error, tmp_path, 'directory')

    denied = tmp_path / 'denied.mcap'

    def refuse(*args, **kwargs):
        raise PermissionError(13, 'Permission denied', str(denied))

    monkeypatch.setattr(writer, 'temporary_beside', refuse)   # where the file is created
    with pytest.raises(RecordingError) as error:
        McapRecorder(denied)
    assert_one_line_naming(error, denied, 'permission denied')


@pytest.mark.skipif(os.geteuid() == 0, reason='root can write to read-only directories')
def test_read_only_directory_raises(tmp_path):
    locked = tmp_path / 'locked'
    locked.mkdir(mode=0o500)
    with pytest.raises(RecordingError) as error:
        McapRecorder(locked / 'run.mcap')
    assert_one_line_naming(error, locked / 'run.mcap', 'permission denied')


def test_reading_something_else_raises(tmp_path):
    with pytest.raises(RecordingError) as error:
        read_recording(tmp_path / 'missing.mcap')
    assert_one_line_naming(error, tmp_path / 'missing.mcap', 'no such file')
    text = tmp_path / 'notes.mcap'
    text.write_text('not an mcap file at all\n')
    with pytest.raises(RecordingError) as error:
        read_recording(text)
    assert_one_line_naming(error, text, 'not an mcap file')


# ------------------------------------------------------------------------------------------
# Truncated files and a writer killed for real.

def test_truncated_files_keep_every_complete_chunk(tmp_path):
    full_path = tmp_path / 'full.mcap'
    written = write_samples(full_path, count=60, chunk_size=4096)
    data = full_path.read_bytes()
    _, summary, _ = summary_of(full_path)
    chunks = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    assert len(chunks) > 4
    middle = chunks[len(chunks) // 2]
    cuts = [middle.chunk_start_offset + middle.chunk_length // 2,  # inside a chunk
            middle.chunk_start_offset,  # at a record boundary
            chunks[0].chunk_start_offset - 1,  # before any chunk
            len(data) - 3,  # footer's magic cut
            8]  # the magic alone
    for cut in cuts:
        cut_path = tmp_path / f'cut_{cut}.mcap'
        cut_path.write_bytes(data[:cut])
        rec = read_recording(cut_path)
        complete = [c for c in chunks if c.chunk_start_offset + c.chunk_length <= cut]
        last_time = max((c.message_end_time for c in complete), default=-1)
        expected = [(t, s) for t, s, _ in written if s <= last_time]
        assert rec.truncated and rec.total_bytes == cut and rec.recovered_bytes <= cut
        assert [(m.topic, m.log_time_ns) for m in rec.messages] == expected, cut
        for (_, _, msg), got in zip(written, rec.messages):
            assert_same(msg, got.msg)
    (tmp_path / 'short.mcap').write_bytes(data[:5])
    with pytest.raises(RecordingError):
        read_recording(tmp_path / 'short.mcap')


KILLED_WRITER = textwrap.dedent("""
    import sys, time
    from geometry_msgs.msg import PoseStamped
    from twodisk_ros.recordings import McapRecorder

    path, count, flush = sys.argv[1], int(sys.argv[2]), sys.argv[3] == 'flush'
    rec = McapRecorder(path, chunk_size=8192, metadata={'run': 'killed'})
    rec.add_topic('/pose', PoseStamped)
    for i in range(count):
        msg = PoseStamped()
        msg.header.frame_id = 'map'
        msg.header.stamp.sec = i
        msg.pose.position.x = 0.5 * i
        rec.write('/pose', msg, 10**9 * i)
    if flush:
        rec.flush()
        for i in range(count, count + 10):
            rec.write('/pose', PoseStamped(), 10**9 * i)
    print('READY', flush=True)
    time.sleep(120)
""")


@pytest.mark.parametrize('mode', ['chunks', 'flush'])
def test_sigkilled_writer_leaves_a_readable_file(tmp_path, mode):
    path = tmp_path / 'killed.mcap'
    count = 1000
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get('PYTHONPATH', '').split(os.pathsep) if p]))
    proc = subprocess.Popen([sys.executable, '-c', KILLED_WRITER, str(path), str(count), mode],
                            stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout.readline().strip() == 'READY'
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL

    rec = read_recording(path)
    assert rec.truncated and rec.metadata['twodisk_ros'] == {'run': 'killed'}
    assert yaml.safe_load(rec.metadata['rosbag2']['serialized_metadata'])['version'] == 9
    if mode == 'flush':
        assert count <= len(rec.messages) <= count + 10
    else:
        # Only the unfinished chunk may be lost: at most chunk_size / smallest record.
        sample = PoseStamped()
        sample.header.frame_id = 'map'
        record_size = 1 + 8 + 2 + 4 + 8 + 8 + len(serialize_message(sample))
        assert count - 8192 // record_size - 1 <= len(rec.messages) < count
    for i, got in enumerate(rec.messages[:count]):
        assert got.log_time_ns == 10**9 * i
        assert got.msg.header.stamp.sec == i and got.msg.pose.position.x == 0.5 * i


def test_unclosed_recorder_file_is_readable_while_open(tmp_path):
    path = tmp_path / 'open.mcap'
    rec = McapRecorder(path, chunk_size=1024)
    rec.add_topic('/pose', PoseStamped)
    for i in range(100):
        rec.write('/pose', pose_stamped(i), T0 + i)
    snapshot = tmp_path / 'snapshot.mcap'
    shutil.copyfile(path, snapshot)
    rec.close()
    partial = read_recording(snapshot)
    assert partial.truncated and 0 < len(partial.messages) < 100
    assert [m.log_time_ns for m in partial.messages] == [T0 + i for i in
                                                         range(len(partial.messages))]
    assert len(read_recording(path).messages) == 100


@pytest.mark.parametrize('where', ['after-open', 'starting'])
def test_an_interrupt_while_the_recorder_opens_leaves_no_temporary_file(tmp_path, monkeypatch,
                                                                        where):
    """A signal's exception (KeyboardInterrupt here, StopNow in the node) that lands right
    after the hidden temporary file is created, or while the header is written, removes it:
    the directory holds only the old recording, byte for byte."""
    from twodisk_ros.recordings import writer as writer_module
    target = tmp_path / 'run.mcap'
    target.write_bytes(b'old recording')

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    if where == 'after-open':
        monkeypatch.setattr(writer_module.threading, 'Lock', interrupt)
    else:
        monkeypatch.setattr(writer_module, 'Writer', interrupt)
    with pytest.raises(KeyboardInterrupt):
        writer_module.McapRecorder(str(target), overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ['run.mcap']
    assert target.read_bytes() == b'old recording'
