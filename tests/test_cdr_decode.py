"""The generated CDR decoders (twodisk_ros.recordings.cdr_decode) against mcap-ros2-support's decoder.

The claim checked (the module's equivalence guarantee): on any bytes, the generated function
either raises or returns what mcap_ros2's own ``DecoderFactory`` decoder returns, field by
field (class name, type name, slots, value types, floats bit for bit); where mcap_ros2 raises,
it raises too; and the decoder the reader uses (generated function, mcap_ros2 on any error)
returns mcap_ros2's value or raises its exception with its text.  Checked on

- every message of two recordings of the node (the oloid; an egg with a speed drive, damping
  and friction), every topic: /tf, /tf_static, joint states, wrenches, paths, markers,
  diagnostics, the URDF string;
- damaged copies of their payloads: every cut of the small messages, cuts of the large ones,
  bit flips, overwritten bytes (hypothesis);
- random definitions (every primitive, strings, bounded strings, fixed arrays, bounded and
  unbounded sequences, nested messages and arrays of them, empty messages, builtin time
  types), with payloads encoded by mcap_ros2's encoder (the generated function must then
  succeed) and with random bytes;
- hand-made payloads whose values and padding are written out here (an independent
  reference), little- and big-endian.
"""

import functools
import gc
import os
from pathlib import Path
import struct
import subprocess
import sys

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.records import Schema
from mcap_ros2._dynamic import serialize_dynamic
from mcap_ros2.decoder import DecoderFactory as McapDecoderFactory
import pytest

from twodisk_ros.recordings import read_recording
from twodisk_ros.recordings.cdr_decode import DecoderFactory, compile_decoder
from twodisk_ros.recordings.mcap_scan import reason_of, scan_mcap

pytestmark = pytest.mark.ros
REPO = Path(__file__).resolve().parents[1]
RUNS = {
    'oloid': ['--params-file', 'config/oloid.yaml'],
    'egg_driven': ['--params-file', 'config/egg.yaml', '-p', 'drive:=speed',
                   '-p', 'damping:=0.002', '-p', 'friction:=0.5'],
}
TYPES = {'tf2_msgs/msg/TFMessage', 'std_msgs/msg/String', 'geometry_msgs/msg/PoseStamped',
         'geometry_msgs/msg/PointStamped', 'sensor_msgs/msg/JointState',
         'geometry_msgs/msg/WrenchStamped', 'nav_msgs/msg/Path',
         'visualization_msgs/msg/MarkerArray', 'diagnostic_msgs/msg/DiagnosticArray'}


@pytest.fixture(scope='module')
def recordings(tmp_path_factory):
    """``{name: path}`` of short batch recordings of the node, made side by side."""
    folder = tmp_path_factory.mktemp('decode')
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='86',
               PYTHONPATH=str(REPO))
    runs = {}
    for name, args in RUNS.items():
        path = folder / f'{name}.mcap'
        runs[name] = (path, subprocess.Popen(
            [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', *args,
             '-p', 'realtime:=false', '-p', 'duration:=0.4', '-p', 'rate:=100.0',
             '-p', f'record:={path}'], cwd=REPO, env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE, text=True))
    for name, (path, process) in runs.items():
        _, err = process.communicate(timeout=120)
        assert process.returncode == 0, err[-2000:]
    return {name: path for name, (path, _) in runs.items()}


@pytest.fixture(scope='module')
def samples(recordings):
    """``[(schema, [payload, ...])]``: the payloads of every type in the recordings."""
    found = {}
    for path in recordings.values():
        scan = scan_mcap(path.read_bytes())
        channels = {**scan.summary_channels, **scan.channels}
        schemas = {**scan.summary_schemas, **scan.schemas}
        for raw in scan.messages:
            schema = schemas[channels[raw.channel_id].schema_id]
            found.setdefault(schema.name, (schema, []))[1].append(raw.data)
    return list(found.values())


def assert_same(ours, theirs, where='msg'):
    """Equal field by field: classes by name and type, exact value types, floats by bits."""
    assert type(ours).__name__ == type(theirs).__name__, where
    if hasattr(type(theirs), '_type'):
        assert (ours._type, ours._full_text, ours.__slots__) == \
               (theirs._type, theirs._full_text, theirs.__slots__), where
        assert type(ours).__mro__[1:] == type(theirs).__mro__[1:], where
        for name in theirs.__slots__:
            assert_same(getattr(ours, name), getattr(theirs, name), f'{where}.{name}')
        return
    assert type(ours) is type(theirs), (where, ours, theirs)
    if isinstance(theirs, list):
        assert len(ours) == len(theirs), where
        for i, (a, b) in enumerate(zip(ours, theirs)):
            assert_same(a, b, f'{where}[{i}]')
    elif isinstance(theirs, float):
        assert struct.pack('<d', ours) == struct.pack('<d', theirs), (where, ours, theirs)
    else:
        assert ours == theirs, (where, ours, theirs)


def outcome(decode, data):
    """``('ok', value)`` or ``('error', reason)``."""
    try:
        return 'ok', decode(data)
    except Exception as error:  # noqa: BLE001 - any failure of a decoder is an outcome
        return 'error', reason_of(error)


@functools.lru_cache(maxsize=64)
def decoders(name, text):
    """``(generated, mcap_ros2's, the reader's)`` decoders of a schema."""
    schema = Schema(id=1, name=name, encoding='ros2msg', data=text)
    fast, _ = compile_decoder(name, text.decode())
    return (fast, McapDecoderFactory().decoder_for('cdr', schema),
            DecoderFactory().decoder_for('cdr', schema))


def check_equivalent(schema, data, must_decode=False):
    """The guarantee on one payload; returns True if the generated function decoded it."""
    fast, mcap_ros2, used_by_reader = decoders(schema.name, schema.data)
    assert fast is not None, schema.name
    theirs = outcome(mcap_ros2, data)
    ours = outcome(fast, data)
    if theirs[0] == 'error' or ours[0] == 'error':
        assert not must_decode or theirs[0] == 'error', (ours, theirs)
        assert theirs[0] == 'error' or ours[0] == 'error'    # never ours alone succeeding...
        assert ours[0] == 'error' or theirs[0] == 'ok'       # ...where mcap_ros2 fails
    else:
        assert_same(ours[1], theirs[1])
    used = outcome(used_by_reader, data)
    assert used[0] == theirs[0]
    if used[0] == 'ok':
        assert_same(used[1], theirs[1])
    else:
        assert used[1] == theirs[1]
    return ours[0] == 'ok'


def test_every_message_of_the_node_decodes_as_mcap_ros2_does(samples):
    names = set()
    for schema, payloads in samples:
        names.add(schema.name)
        fast, _ = compile_decoder(schema.name, schema.data.decode())
        theirs = McapDecoderFactory().decoder_for('cdr', schema)
        for data in payloads:
            assert_same(fast(data), theirs(data))
    assert names == TYPES


def test_the_reader_gives_mcap_ros2s_messages(recordings):
    for path in recordings.values():
        recording = read_recording(path)
        assert not recording.undecodable
        scan = scan_mcap(path.read_bytes())
        channels = {**scan.summary_channels, **scan.channels}
        schemas = {**scan.summary_schemas, **scan.schemas}
        factory = McapDecoderFactory()
        assert len(recording.messages) == len(scan.messages)
        for message, raw in zip(recording.messages, scan.messages):
            schema = schemas[channels[raw.channel_id].schema_id]
            assert_same(message.msg, factory.decoder_for('cdr', schema)(raw.data))
        # the values are those of the run: a pose stamp and a joint name as written
        poses = [m.msg for m in recording.messages if m.topic == '/pose']
        assert poses[0].header.frame_id == 'world' and len(poses) == 41
        joints = next(m.msg for m in recording.messages if m.topic == '/rolling_state')
        assert joints.name == ['theta', 'psi', 'phase'] and len(joints.position) == 3


def test_every_cut_and_some_bit_flips_of_every_payload(samples):
    decoded = 0
    for schema, payloads in samples:
        data = max(payloads, key=len)
        step = 1 if len(data) <= 256 else len(data) // 40   # every cut of the small ones
        for cut in range(0, len(data), step):
            check_equivalent(schema, data[:cut])
        for bit in range(0, 8 * len(data), max(1, len(data) // 5)):     # 40 flips
            flipped = bytearray(data)
            flipped[bit // 8] ^= 1 << bit % 8
            decoded += check_equivalent(schema, bytes(flipped))
    assert decoded > 100        # the flips of float bits decode: the comparison is exercised


@settings(max_examples=200, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                 HealthCheck.data_too_large])
@given(data=st.data())
def test_hypothesis_damaged_payloads(samples, data):
    schema, payloads = data.draw(st.sampled_from(samples))
    payload = bytearray(data.draw(st.sampled_from(payloads)))
    for _ in range(data.draw(st.integers(1, 4))):
        where = data.draw(st.integers(0, len(payload) - 1))
        kind = data.draw(st.sampled_from(['byte', 'word', 'flip']))
        if kind == 'byte':
            payload[where] = data.draw(st.integers(0, 255))
        elif kind == 'word':   # a length or count: small, huge, or just past the end
            value = data.draw(st.sampled_from([0, 1, 2, 3, 7, 255, 2**31, 2**32 - 1,
                                               len(payload), len(payload) - where]))
            payload[where:where + 4] = struct.pack('<I', value % 2**32)
        else:
            payload[where] ^= 1 << data.draw(st.integers(0, 7))
    cut = data.draw(st.one_of(st.none(), st.integers(0, len(payload))))
    check_equivalent(schema, bytes(payload if cut is None else payload[:cut]))


# -- random definitions ----------------------------------------------------------------------
PRIMITIVES = {
    'bool': st.booleans(), 'byte': st.integers(0, 255), 'char': st.integers(-128, 127),
    'int8': st.integers(-128, 127), 'uint8': st.integers(0, 255),
    'int16': st.integers(-2**15, 2**15 - 1), 'uint16': st.integers(0, 2**16 - 1),
    'int32': st.integers(-2**31, 2**31 - 1), 'uint32': st.integers(0, 2**32 - 1),
    'int64': st.integers(-2**63, 2**63 - 1), 'uint64': st.integers(0, 2**64 - 1),
    'float32': st.floats(width=32), 'float64': st.floats(),
    'string': st.text(st.characters(blacklist_categories=('Cs',)), max_size=6),
    'string<=5': st.text(st.characters(blacklist_categories=('Cs',)), max_size=5),
}
SUFFIXES = ['', '', '', '[]', '[3]', '[1]', '[<=2]']


@st.composite
def definitions(draw):
    """``(schema, [field lists])``: up to 3 types, each may use the types after it."""
    count = draw(st.integers(1, 3))
    names = ['test_pkg/msg/Top'] + [f'test_pkg/T{i}' for i in range(1, count)]
    types = []
    for index in range(count):
        usable = list(PRIMITIVES) + [n.replace('/msg/', '/') for n in names[index + 1:]] \
            + ['builtin_interfaces/Time']
        fields = draw(st.lists(st.tuples(st.sampled_from(usable), st.sampled_from(SUFFIXES)),
                               max_size=6))
        types.append(fields)
    parts = []
    for index, fields in enumerate(types):
        text = ''.join(f'{kind}{suffix} f{i}\n' for i, (kind, suffix) in enumerate(fields))
        if index:
            text = '=' * 80 + f'\nMSG: {names[index].replace("/msg/", "/")}\n' + text
        parts.append(text)
    schema = Schema(id=1, name=names[0], encoding='ros2msg', data='\n'.join(parts).encode())
    return schema, dict(zip([n.replace('/msg/', '/') for n in names], types))


def values(draw, types, name):
    """A random message of type ``name`` as the dict mcap_ros2's encoder takes."""
    if name == 'builtin_interfaces/Time':
        return {'sec': draw(st.integers(0, 2**31 - 1)), 'nanosec': draw(st.integers(0, 10**9))}
    message = {}
    for i, (kind, suffix) in enumerate(types[name.replace('/msg/', '/')]):
        one = (lambda k=kind: draw(PRIMITIVES[k])) if kind in PRIMITIVES else \
            (lambda k=kind: values(draw, types, k))
        if not suffix:
            message[f'f{i}'] = one()
        else:
            size = int(suffix.strip('[]<=')) if suffix.strip('[]') else None
            length = size if size and '<=' not in suffix else draw(st.integers(0, size or 3))
            message[f'f{i}'] = [one() for _ in range(length)]
    return message


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(definition=definitions(), data=st.data())
def test_hypothesis_random_definitions_and_payloads(definition, data):
    schema, types = definition
    encode = serialize_dynamic(schema.name, schema.data.decode())[schema.name]
    payload = encode(values(data.draw, types, 'test_pkg/Top'))
    assert check_equivalent(schema, payload, must_decode=True)
    # damaged: cut, and random bytes after the header
    check_equivalent(schema, payload[:data.draw(st.integers(0, len(payload)))])
    noise = data.draw(st.lists(st.one_of(
        st.integers(0, 3).map(lambda n: struct.pack('<I', n)), st.binary(max_size=9)),
        max_size=12))
    check_equivalent(schema, payload[:4] + b''.join(noise))


# -- hand-made payloads ----------------------------------------------------------------------
LAYOUT = Schema(id=7, name='test_pkg/msg/Layout', encoding='ros2msg', data=(
    b'uint8 a\nfloat64 b\nstring s\nint16[] c\nfloat64 d\nbool[2] e\nbyte[] f\nchar g\n'
    b'Inner[] inner\nEmpty empty\nint32 z\n'
    + b'=' * 80 + b'\nMSG: test_pkg/Inner\nstring name\nfloat32 v\n'
    + b'=' * 80 + b'\nMSG: test_pkg/Empty\n'))


def layout_payload():
    """The payload of LAYOUT with its padding written out (offsets after the 4-byte header)."""
    body = (b'\x07' + b'\0' * 7                       # a at 0, b aligned to 8
            + struct.pack('<d', 1.5)                  # b at 8
            + struct.pack('<I', 3) + b'hi\0'          # s at 16: 'hi'
            + b'\0'                                   # c's count aligned to 4 (23 -> 24)
            + struct.pack('<I', 2) + struct.pack('<hh', -2, 5)    # c at 24: [-2, 5]
            + struct.pack('<d', -0.25)                # d at 32 (already aligned)
            + b'\x00\x09'                             # e at 40: [False, True]
            + b'\0\0' + struct.pack('<I', 2) + b'\xff\x01'        # f at 44: b'\xff\x01'
            + b'\xfe'                                 # g at 50: -2 (char is int8)
            + b'\0' + struct.pack('<I', 1)            # inner count at 52
            + struct.pack('<I', 1) + b'\0'            # inner[0].name at 56: '' (length 1)
            + b'\0\0\0' + struct.pack('<f', 0.5)      # inner[0].v at 64
            + b'\x2a'                                 # empty's byte at 68
            + b'\0\0\0' + struct.pack('<i', -9))      # z at 72
    return b'\x00\x01\x00\x00' + body


def test_a_hand_made_payload_decodes_to_the_values_written():
    fast, reference = compile_decoder(LAYOUT.name, LAYOUT.data.decode())
    for decode in (fast, reference, DecoderFactory().decoder_for('cdr', LAYOUT)):
        msg = decode(layout_payload())
        assert (msg.a, msg.b, msg.s, msg.c, msg.d, msg.e, msg.f, msg.g, msg.z) == \
               (7, 1.5, 'hi', [-2, 5], -0.25, [False, True], b'\xff\x01', -2, -9)
        assert [(i.name, i.v) for i in msg.inner] == [('', 0.5)]
        assert type(msg.empty).__slots__ == [] and type(msg).__name__ == 'Layout'
    check_equivalent(LAYOUT, layout_payload(), must_decode=True)


def test_big_endian_and_foreign_buffers_go_to_mcap_ros2():
    schema = Schema(id=3, name='test_pkg/msg/P', encoding='ros2msg',
                    data=b'uint16 a\nfloat64 b\nstring s\n')
    fast, _ = compile_decoder(schema.name, schema.data.decode())
    big = b'\x00\x00\x00\x00' + struct.pack('>H', 513) + b'\0' * 6 + struct.pack('>d', 2.0) \
        + struct.pack('>I', 2) + b'x\0'
    with pytest.raises(ValueError):
        fast(big)
    decode = DecoderFactory().decoder_for('cdr', schema)
    assert (decode(big).a, decode(big).b, decode(big).s) == (513, 2.0, 'x')
    little = b'\x00\x01\x00\x00' + struct.pack('<H', 513) + b'\0' * 6 + struct.pack('<d', 2.0) \
        + struct.pack('<I', 2) + b'x\0'
    with pytest.raises(ValueError):
        fast(bytearray(little))
    assert decode(bytearray(little)).a == decode(little).a == 513


def test_a_payload_shorter_than_its_header_fails_even_where_only_slices_are_read():
    schema = Schema(id=4, name='test_pkg/msg/Bytes', encoding='ros2msg', data=b'uint8[2] u\n')
    for cut in range(4):    # mcap_ros2 refuses a payload without its 4-byte header
        assert not check_equivalent(schema, b'\x00\x01\x00\x00'[:cut])
    # past the header, a cut uint8 array comes back short, as mcap_ros2 slices it
    assert check_equivalent(schema, b'\x00\x01\x00\x00\x05', must_decode=True)
    assert decoders(schema.name, schema.data)[0](b'\x00\x01\x00\x00\x05').u == b'\x05'


@pytest.mark.parametrize('text, unsupported', [
    ('wstring w\n', True), ('float64 x\nwstring[] w\n', True), ('int32 lambda\n', True),
    ('string<=3 s\nfloat64[<=2] v\nuint8[4] u\nint8 K=3\nint8 k\n', False),
])
def test_what_is_not_compiled_is_decoded_by_mcap_ros2(text, unsupported):
    schema = Schema(id=5, name='test_pkg/msg/U', encoding='ros2msg', data=text.encode())
    fast, reference = compile_decoder(schema.name, text)
    assert (fast is None) == unsupported
    payload = b'\x00\x01\x00\x00' + struct.pack('<I', 2) + b'a\0' + b'\0' * 16
    theirs = outcome(McapDecoderFactory().decoder_for('cdr', schema), payload)
    ours = outcome(DecoderFactory().decoder_for('cdr', schema), payload)
    assert ours[0] == theirs[0]
    if ours[0] == 'ok':
        assert_same(ours[1], theirs[1])
    else:
        assert ours[1] == theirs[1]


def test_a_class_made_from_one_of_two_definitions_is_the_one_mcap_ros2_makes():
    # Duration has no section: mcap_ros2 reads it with its own Time definition (uint32 sec),
    # whose class is keyed 'builtin_interfaces/Time' like the schema's Time (int32 sec); with
    # no Duration in the message, mcap_ros2 makes that class from the schema's Time
    text = ('builtin_interfaces/Duration[] ds\nbuiltin_interfaces/Time t\n' + '=' * 80
            + '\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n')
    schema = Schema(id=6, name='test_pkg/msg/Two', encoding='ros2msg', data=text.encode())
    payload = b'\x00\x01\x00\x00' + struct.pack('<IiI', 0, -1, 5)
    msg = DecoderFactory().decoder_for('cdr', schema)(payload)
    assert (msg.ds, msg.t.sec, msg.t.nanosec) == ([], -1, 5)
    assert type(msg.t)._full_text.endswith('\nint32 sec\nuint32 nanosec')
    assert_same(msg, McapDecoderFactory().decoder_for('cdr', schema)(payload))


@pytest.mark.parametrize('name, text', [
    ('test_pkg/msg/Bad', 'floa64 x\n'), ('test_pkg/msg/Bad', 'float64 x y z\n'),
    ('test_pkg/msg/Bad', 'float64[-1] x\n'), ('', 'float64 x\n'),
])
def test_schema_errors_are_mcap_ros2s(name, text):
    schema = Schema(id=9, name=name, encoding='ros2msg', data=text.encode())
    theirs = outcome(lambda s: McapDecoderFactory().decoder_for('cdr', s), schema)
    ours = outcome(lambda s: DecoderFactory().decoder_for('cdr', s), schema)
    assert ours[0] == theirs[0]
    assert ours[0] == 'ok' or ours[1] == theirs[1]


@pytest.mark.parametrize('enabled', [True, False])
def test_reading_leaves_the_garbage_collector_as_it_was(recordings, enabled):
    was = gc.isenabled()
    try:
        (gc.enable if enabled else gc.disable)()
        read_recording(recordings['oloid'])
        assert gc.isenabled() == enabled
    finally:
        (gc.enable if was else gc.disable)()
