"""``twodisk-inspect`` on damaged copies of one real recording (issue 9).

One recording is made per session by the node itself (a 2 s batch run at 25 Hz: 51 samples in
three chunks, every record type the node writes, at a quarter of the decoding cost of 100 Hz
per case); hundreds of
mutated copies (bit flips, truncations at random points and at every record boundary, zeroed,
duplicated and removed ranges, wrong CRCs, tiny files) are inspected in-process, a few through
a subprocess.  Whatever the damage: exit 0/1/4 with a report, or exit 2 with exactly one
non-empty line ``twodisk-inspect: cannot read recording PATH: <reason>``; never a traceback,
never a hang.  The random generator is seeded: a failure names the seed and the case.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '92')

import collections  # noqa: E402
import contextlib  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
from pathlib import Path  # noqa: E402
import random  # noqa: E402
import struct  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402
from mcap.records import Channel, Metadata, Message, Schema  # noqa: E402
from mcap.stream_reader import StreamReader  # noqa: E402
from mcap.writer import CompressionType, Writer  # noqa: E402
import pytest  # noqa: E402

from twodisk_ros.inspector import cli as inspect_cli  # noqa: E402
from twodisk_ros.recordings import read_recording  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
SEED = 20240909
MAGIC = b'\x89MCAP0\r\n'
PREFIX = 'twodisk-inspect: '
CHUNK, MESSAGE, DATA_END, FOOTER = 0x06, 0x05, 0x0F, 0x02


def node_env():
    return dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get('PYTHONPATH', '').split(os.pathsep) if p]))


@pytest.fixture(scope='module')
def original(tmp_path_factory):
    """The bytes of a real recording: the node, 2 s of simulated time at 25 Hz, batch."""
    from batch_recording import record     # the roller's entry function, in this process
    path = tmp_path_factory.mktemp('fuzz') / 'run.mcap'
    record(path, rate=25.0, duration=2.0)
    return path.read_bytes()


def rewrite(data, compression=CompressionType.NONE, crcs=False, edit=None, chunk_size=16384,
            metadata=None):
    """The same records written again, e.g. uncompressed without CRCs (so that flips reach the
    CDR decoder); ``edit(topic, index, payload) -> payload`` may change a message,
    ``metadata`` {key: text} replaces entries of the metadata records."""
    out = io.BytesIO()
    writer = Writer(out, chunk_size=chunk_size, compression=compression, enable_crcs=crcs)
    writer.start('ros2', 'test rewrite')
    schemas, channels, seen = {}, {}, collections.Counter()
    for record in StreamReader(io.BytesIO(data)).records:
        if isinstance(record, Schema) and record.id not in schemas:
            schemas[record.id] = writer.register_schema(record.name, record.encoding,
                                                        record.data)
        elif isinstance(record, Channel) and record.id not in channels:
            channels[record.id] = (record.topic, writer.register_channel(
                record.topic, record.message_encoding, schemas[record.schema_id],
                record.metadata))
        elif isinstance(record, Message):
            topic, channel_id = channels[record.channel_id]
            payload = record.data if edit is None else edit(topic, seen[topic], record.data)
            seen[topic] += 1
            writer.add_message(channel_id, record.log_time, payload, record.publish_time,
                               record.sequence)
        elif isinstance(record, Metadata):
            writer.add_metadata(record.name, {**record.metadata, **(metadata or {})})
    writer.finish()
    return out.getvalue()


@pytest.fixture(scope='module')
def variants(original):
    return {'zstd': original, 'plain': rewrite(original),
            'lz4': rewrite(original, CompressionType.LZ4, crcs=True)}


def records(data):
    """``(opcode, start, end)`` of the top-level records of an intact file."""
    found, pos = [], len(MAGIC)
    while pos + 9 <= len(data):
        opcode, length = struct.unpack_from('<BQ', data, pos)
        found.append((opcode, pos, pos + 9 + length))
        pos += 9 + length
        if opcode == FOOTER:
            break
    return found


def inner_messages(data):
    """Starts of the message records inside the chunks of an uncompressed file."""
    starts = []
    for opcode, start, end in records(data):
        if opcode != CHUNK:
            continue
        body = start + 9 + 8 + 8 + 8 + 4
        (clen,) = struct.unpack_from('<I', data, body)
        pos = body + 4 + clen + 8
        while pos + 9 <= end:
            inner, length = struct.unpack_from('<BQ', data, pos)
            if inner == MESSAGE:
                starts.append(pos)
            pos += 9 + length
    return starts


def flip(data, rng, count, positions=None):
    out = bytearray(data)
    for _ in range(count):
        k = rng.choice(positions) if positions else rng.randrange(len(out))
        out[k] ^= 1 << rng.randrange(8)
    return bytes(out)


def span(rng, size, longest):
    start = rng.randrange(size)
    return start, min(size, start + rng.randint(1, longest))


def set_field(data, offset, fmt, value):
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, value)
    return bytes(out)


#: Of these random groups only the first half of the draws is inspected (the draws of the
#: others are still made, so the cases kept are those of the full list): a throw-away
#: arc-coverage run of the 582 cases of the full list over twodisk_ros (branch coverage,
#: 3672 arcs) found no arc that only their second halves reached; the groups left whole
#: (structure and plain flips) reach arcs in their second halves too.
HALVED = ('zstd flip', 'lz4 flip', 'random cut', 'plain cut', 'zero', 'copy', 'remove')


def mutations(variants, rng):
    """``(number, kind, name, bytes)`` of the cases (``number``: the case's place in the full
    list); the same list for the same seed."""
    for number, (kind, name, case, index, count) in enumerate(_drawn(variants, rng)):
        if index is None or not name.startswith(HALVED) or index < count // 2:
            yield number, kind, name, case


def _drawn(variants, rng):
    """``(kind, name, bytes, index, count)`` of every drawn case (``index`` of ``count`` in
    its random group, None for the deterministic ones); the same list for the same seed."""
    data = variants['zstd']
    size = len(data)
    recs = records(data)
    structure = sorted({k for _, start, end in recs
                        for k in range(start, min(end, start + 9 + 64))})
    chunks = [(start, end) for opcode, start, end in recs if opcode == CHUNK]
    for i in range(100):
        yield 'flip', f'zstd flip {i}', flip(data, rng, rng.randint(1, 50)), i, 100
    for i in range(40):
        yield ('flip', f'zstd structure flip {i}',
               flip(data, rng, rng.randint(1, 8), structure), i, 40)
    for i in range(80):
        yield 'flip', f'plain flip {i}', flip(variants['plain'], rng, rng.randint(1, 50)), i, 80
    for i in range(20):
        yield 'flip', f'lz4 flip {i}', flip(variants['lz4'], rng, rng.randint(1, 50)), i, 20
    for i in range(40):
        cut = rng.randrange(size)
        yield 'truncate', f'random cut at {cut}', data[:cut], i, 40
    for opcode, start, end in recs:
        for cut in (start, start + 9):
            yield ('truncate', f'cut at {cut} (record 0x{opcode:02x} at {start})', data[:cut],
                   None, None)
    plain = variants['plain']
    for i, start in enumerate(rng.sample(inner_messages(plain), 30)):
        yield ('truncate', f'plain cut at message {start}', plain[:start + rng.randrange(30)],
               i, 30)
    for i in range(40):
        a, b = span(rng, size, 4096)
        yield 'zero', f'zero {a}:{b}', data[:a] + bytes(b - a) + data[b:], i, 40
    for i in range(30):
        a, b = span(rng, size, 8192)
        at = rng.randrange(size)
        yield 'duplicate', f'copy {a}:{b} to {at}', data[:at] + data[a:b] + data[at:], i, 30
    for i in range(30):
        a, b = span(rng, size, 8192)
        yield 'remove', f'remove {a}:{b}', data[:a] + data[b:], i, 30
    for opcode, start, end in rng.sample(recs, 10):
        yield ('duplicate', f'record 0x{opcode:02x} at {start} twice', data[:end] + data[start:],
               None, None)
        yield ('remove', f'record 0x{opcode:02x} at {start} removed', data[:start] + data[end:],
               None, None)
    header_end = recs[0][2]
    garbage = bytes(rng.randrange(256) for _ in range(4096))
    for name, case in [
            ('empty', b''), ('8 garbage bytes', garbage[:8]), ('magic only', MAGIC),
            ('5 bytes of magic', MAGIC[:5]), ('header only', data[:header_end]),
            ('header and footer', data[:header_end] + data[-37:]),
            ('magic then garbage', MAGIC + garbage), ('header then garbage',
                                                      data[:header_end] + garbage),
            ('magic, zeros', MAGIC + bytes(4096)), ('footer only', MAGIC + data[-37:]),
            ('trailing garbage', data + garbage[:100]),
            ('garbage between magic and header', MAGIC + garbage[:50] + data[8:])]:
        yield 'tiny', name, case, None, None
    for start, end in chunks:   # wrong CRCs of the chunks (uncompressed records)
        yield ('crc', f'chunk crc at {start}',
               set_field(data, start + 9 + 24, '<I', 0xDEADBEEF), None, None)
    footer = size - 8 - 29
    yield 'crc', 'summary crc', set_field(data, footer + 9 + 16, '<I', 0x12345678), None, None
    data_end = next(start for opcode, start, _ in recs if opcode == DATA_END)
    yield ('crc', 'data section crc', set_field(data, data_end + 9, '<I', 0x12345678),
           None, None)
    for start, end in chunks:   # a declared uncompressed size far too large or small
        for value in (2**62, 1, 0):
            yield ('crc', f'chunk size {value} at {start}',
                   set_field(data, start + 9 + 16, '<Q', value), None, None)


def run_in_process(path, *extra):
    """``main`` in this process: exit status, stdout, stderr (warnings a user would see on
    stderr are added to it: pytest would otherwise swallow them)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
            warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('default')
        status = inspect_cli.main([str(path), *extra])
    shown = [f'{w.category.__name__}: {w.message}\n' for w in caught
             if not issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning))]
    return status, out.getvalue(), err.getvalue() + ''.join(shown)


def assert_outcome(status, out, err, path, why):
    assert 'Traceback' not in out + err, why + err[-2000:]
    assert status in (0, 1, 2, 4), why     # PASS, FAIL, unreadable, INCOMPLETE
    if status == 2:
        lines = err.splitlines()
        assert len(lines) == 1 and err.endswith('\n'), why + repr(err)
        head = f'{PREFIX}cannot read recording {path}: '
        assert lines[0].startswith(head) and lines[0][len(head):].strip(), why + repr(err)
        assert 'internal error' not in err, why + err
        assert out == '', why
    else:
        assert err == '', why + err
        assert 'result: ' in out or out.lstrip().startswith('{'), why + out[-2000:]


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_inspector_survives_every_mutation(tmp_path, variants):
    rng = random.Random(SEED)
    outcomes = collections.defaultdict(collections.Counter)
    path = tmp_path / 'case.mcap'
    for number, kind, name, case in mutations(variants, rng):
        path.write_bytes(case)
        why = f'seed {SEED}, case {number} ({kind}: {name}, {len(case)} bytes): '
        as_json = number % 4 == 0
        status, out, err = run_in_process(path, *(['--json'] if as_json else []))
        assert_outcome(status, out, err, path, why)
        if status != 2 and as_json:
            summary = json.loads(out)['summary']
            assert 0 <= summary['recovered']['bytes'] <= len(case), why
            assert summary['damage'] or not summary['damaged'], why
        elif status != 2 and kind == 'truncate':
            assert 'TRUNCATED' in out or 'DAMAGED' in out, why + out[:600]
        outcomes[kind][status] += 1
    report = {kind: dict(sorted(c.items())) for kind, c in sorted(outcomes.items())}
    print(f'\nfuzz outcomes by kind (exit status: cases): {report}')
    assert sum(sum(c.values()) for c in outcomes.values()) > 400   # 437 of 582 drawn (HALVED)
    # the mutations reach every outcome: reports of what was recovered, and refusals
    assert outcomes['flip'][1] and outcomes['truncate'][4] and outcomes['tiny'][2]
    assert not outcomes['truncate'][0]      # a cut file is never a PASS


def test_cached_models_give_the_results_of_fresh_ones(tmp_path, original):
    """Inspecting two bodies alternately (the models cached by their parameters) reports
    exactly what inspecting each with nothing cached reports: the shared models are not
    changed by an inspection; and the second inspection of a body reuses its model."""
    from twodisk_ros.inspector import model as model_module
    other = rewrite(original, metadata={'b': '0.08', 'mass': '2.0'})
    paths = []
    for name, data in (('a.mcap', original), ('b.mcap', other)):
        paths.append(tmp_path / name)
        paths[-1].write_bytes(data)
    fresh = []
    for path in paths:
        model_module.clear_model_cache()
        fresh.append(run_in_process(path, '--json'))
    assert fresh[0] != fresh[1]           # the two bodies are told apart
    model_module.clear_model_cache()
    for path, expected in zip(paths * 2, fresh * 2):
        assert run_in_process(path, '--json') == expected, path.name
    info = model_module._cached.cache_info()
    assert (info.misses, info.hits) == (2, 2), info


#: Cases of test_damaged_files_through_a_subprocess run by the real entry point: one for each
#: way a damaged file ends (refused with one line: exit 2; a report: the cut file); the others
#: through its function in this process.
AS_A_PROCESS = ('garbage', 'cut')


def test_damaged_files_through_a_subprocess(tmp_path, variants):
    data = variants['zstd']
    rng = random.Random(SEED + 1)
    first_chunk = next(start for opcode, start, _ in records(data) if opcode == CHUNK)
    cases = {'empty': b'', 'magic': MAGIC, 'flips': flip(data, rng, 30),
             'cut': data[:len(data) // 2], 'chunk': flip(data, rng, 1, [first_chunk + 5000]),
             'garbage': MAGIC + bytes(rng.randrange(256) for _ in range(300))}
    statuses = {}
    for name, case in cases.items():
        path = tmp_path / f'{name}.mcap'
        path.write_bytes(case)
        if name in AS_A_PROCESS:
            result = subprocess.run(
                [sys.executable, '-m', 'twodisk_ros.inspect_mcap', str(path)],
                capture_output=True, text=True, cwd=ROOT, env=node_env(), timeout=120)
            status, out, err = result.returncode, result.stdout, result.stderr
        else:
            status, out, err = run_in_process(path)
        assert_outcome(status, out, err, path, f'seed {SEED + 1}, case {name}: ')
        statuses[name] = status
    assert statuses['garbage'] == 2 and statuses['cut'] != 2, statuses


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture,
                                 HealthCheck.too_slow, HealthCheck.data_too_large])
@given(edits=st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)),
                      min_size=1, max_size=20),
       cut=st.one_of(st.none(), st.floats(0, 1)))
def test_hypothesis_edits_of_an_uncompressed_recording(tmp_path, variants, edits, cut):
    data = bytearray(variants['plain'])
    for where, value in edits:
        data[int(where * len(data))] = value
    if cut is not None:
        data = data[:int(cut * len(data))]
    path = tmp_path / 'hyp.mcap'
    path.write_bytes(bytes(data))
    status, out, err = run_in_process(path)
    assert_outcome(status, out, err, path, f'edits {edits}, cut {cut}: ')


# ------------------------------------------------------------------------------------------
# Regressions: the bugs measured on main.

def test_clean_recording_passes(tmp_path, original):
    path = tmp_path / 'run.mcap'
    path.write_bytes(original)
    status, out, err = run_in_process(path)
    assert status == 0 and err == '', out
    assert 'DAMAGED' not in out and 'TRUNCATED' not in out


@pytest.mark.parametrize('footer', [True, False])
def test_corrupt_chunk_is_skipped_and_reported(tmp_path, original, footer):
    first = next((start, end) for opcode, start, end in records(original) if opcode == CHUNK)
    data = flip(original, random.Random(SEED), 1, [(first[0] + first[1]) // 2])
    if not footer:
        data = data[:len(data) - 40]
    path = tmp_path / 'chunk.mcap'
    path.write_bytes(data)
    status, out, err = run_in_process(path)
    assert status == 1 and err == '', err
    assert 'DAMAGED' in out and f'chunk at byte {first[0]}' in out
    assert ('TRUNCATED' in out) != footer
    recording = read_recording(path)
    assert len(recording.damage) == 1 and f'chunk at byte {first[0]}' in recording.damage[0]
    # the chunks after the damaged one are kept (channels from the summary or their chunk)
    assert recording.messages
    assert recording.recovered_bytes <= len(data) - (first[1] - first[0])


def test_lost_framing_resumes_at_the_next_chunk(tmp_path, original):
    """A record length destroyed early in the file: the records after it are still read."""
    opcode, start, _ = records(original)[1]
    data = set_field(original, start + 1, '<Q', 2**40)
    path = tmp_path / 'framing.mcap'
    path.write_bytes(data)
    recording = read_recording(path)
    assert len(recording.damage) == 1 and 'record framing lost' in recording.damage[0]
    assert 'resumed at the record at byte' in recording.damage[0]  # the metadata index
    assert len(recording.messages) == len(read_recording_bytes(tmp_path, original).messages)
    status, out, err = run_in_process(path)
    assert status == 1 and err == '' and 'DAMAGED' in out and 'FAIL  inputs' in out


def test_garbage_after_the_end_is_damage(tmp_path, original):
    path = tmp_path / 'tail.mcap'
    path.write_bytes(original + b'tail garbage')
    recording = read_recording(path)
    intact = read_recording_bytes(tmp_path, original)
    # every message of the intact file (51 samples on every sampled topic and the rest)
    assert len(intact.messages) > 300 and not intact.damage
    assert not recording.truncated and len(recording.messages) == len(intact.messages)
    assert recording.damage == [f'bytes {len(original)}-{len(original) + 12}: 12 bytes after '
                                f'the end of the MCAP file (footer and magic at byte '
                                f'{len(original) - 37}) ignored']


def read_recording_bytes(tmp_path, data):
    path = tmp_path / 'intact.mcap'
    path.write_bytes(data)
    return read_recording(path)


def test_zero_length_message_is_counted_not_fatal(tmp_path, original):
    def empty_pose(topic, index, payload):
        return b'' if topic.endswith('/pose') and index == 10 else payload

    path = tmp_path / 'empty_message.mcap'
    path.write_bytes(rewrite(original, CompressionType.ZSTD, crcs=True, edit=empty_pose))
    recording = read_recording(path)
    (topic, (count, reason)), = recording.undecodable.items()
    assert topic.endswith('/pose') and count == 1 and reason.strip()
    status, out, err = run_in_process(path)
    assert status == 1 and err == ''
    assert 'UNDECODABLE' in out and '1 messages of /pose could not be decoded' in out
    assert 'FAIL  inputs' in out


@pytest.mark.parametrize('content, reason', [
    (MAGIC, 'not a recording: the file ends after the MCAP magic'),
    (b'12345678', 'not an MCAP file'),
    (b'', 'empty file'),
    (MAGIC[:5], 'not an MCAP file (only 5 bytes)')])
def test_tiny_files_are_not_recordings(tmp_path, content, reason):
    path = tmp_path / 'tiny.mcap'
    path.write_bytes(content)
    status, out, err = run_in_process(path)
    assert status == 2 and out == ''
    assert err == f'{PREFIX}cannot read recording {path}: {reason}\n'


def test_header_only_file_is_not_a_recording(tmp_path, original):
    path = tmp_path / 'header.mcap'
    path.write_bytes(original[:records(original)[0][2]])
    status, _, err = run_in_process(path)
    assert status == 2 and 'not a recording: no channel, message or metadata' in err


@pytest.mark.parametrize('target', ['directory', 'no_suffix', 'pdf'])
def test_plot_path_must_be_a_png_file(tmp_path, original, target):
    path = tmp_path / 'run.mcap'
    path.write_bytes(original)
    plot = {'directory': tmp_path, 'no_suffix': tmp_path / 'figure',
            'pdf': tmp_path / 'figure.pdf'}[target]
    status, out, err = run_in_process(path, '--plot', str(plot))
    assert status == 2 and out == ''
    assert len(err.splitlines()) == 1 and err.startswith(f'{PREFIX}cannot write plot {plot}: ')
    assert not Path(f'{plot}.png').exists() and not (tmp_path / 'figure.pdf').exists()


def test_plot_of_a_damaged_recording_names_the_file_written(tmp_path, original):
    path = tmp_path / 'cut.mcap'
    path.write_bytes(original[:len(original) * 2 // 3])
    png = tmp_path / 'cut.png'
    status, out, err = run_in_process(path, '--plot', str(png))
    assert status == 4 and err == ''     # INCOMPLETE: the checks pass on the cut file
    assert f'plot: {png}' in out and png.stat().st_size > 0
