"""A tolerant scan of an MCAP file: every intact record, and where and why the rest is damaged.

The recovery rule, modelled on ``mcap recover``:

- Top-level records are framed by an opcode and a length.  A record whose framing is intact
  but whose content is damaged (a chunk that does not decompress or fails its CRC, fields that
  do not fit the record's length, invalid UTF-8, ...) is skipped, described in
  :attr:`Scan.damage`, and reading goes on with the next record.  So a corrupt chunk in the
  middle of a file loses that chunk's messages only, with or without footer.
- When the framing is lost (an unknown opcode, a length past the end of the data section),
  reading resumes at the next chunk, found by its signature (opcode, a length that fits, a
  known compression name and a records length consistent with both), or at the next record
  the summary section indexes (chunk and metadata indexes, each checked to frame a record
  there), whichever comes first.  With neither, reading stops there and keeps everything
  before, as for a file whose writer was killed.
- A file that does not end with a footer and the magic is *truncated* (:attr:`Scan.truncated`):
  a record running past its end, or zero bytes after the last complete record, is the cut and
  not damage (unless a chunk follows it: then it was damage).
- CRCs are checked where the writer set them: a chunk's (the chunk is skipped), the data
  section's (``DataEnd``) and the summary's (``Footer``).  The summary's schemas and channels
  are used only when its CRC holds, and only for ids that the data section does not define
  (e.g. when the chunk that defined them is damaged).

Nothing here raises on damaged content; the caller decides what is too little to use.
"""

from dataclasses import dataclass, field
import io
import struct
import zlib

from mcap.records import Channel, Chunk, ChunkIndex, DataEnd, Header, Message, Metadata, \
    MetadataIndex, Schema

from .errors import one_line

__all__ = ['MAGIC', 'MAX_CHUNK_SIZE', 'RawMessage', 'Scan', 'reason_of', 'scan_mcap']

MAGIC = b'\x89MCAP0\r\n'
#: Largest uncompressed chunk accepted (a larger declared size is taken as damage).
MAX_CHUNK_SIZE = 1 << 30

_HEADER, _FOOTER, _SCHEMA, _CHANNEL, _MESSAGE, _CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
_CHUNK_INDEX, _METADATA, _METADATA_INDEX, _DATA_END = 0x08, 0x0C, 0x0D, 0x0F
_KNOWN_OPCODES = frozenset(range(0x01, 0x10))
_COMPRESSIONS = (b'', b'zstd', b'lz4')
_FOOTER_SIZE = 9 + 20           # opcode, length, summary_start, summary_offset_start, crc
_READ_STEP = 1 << 20           # decompressed bytes asked for at a time (no huge buffers)
_MESSAGE_FIXED = 22             # channel id, sequence, log time, publish time
_MESSAGE_HEAD = struct.Struct('<HIQQ')


class _Damaged(Exception):
    """A record's content does not fit its framing."""


def reason_of(error):
    """A one-line, never empty, description of an exception."""
    text = one_line(error)
    name = type(error).__name__
    if not text:
        return {'EndOfFile': 'record ends early'}.get(name, name)
    return text if isinstance(error, _Damaged) else f'{text} ({name})'


class _Body:
    """The reading interface of :class:`mcap.data_stream.ReadDataStream`, strict about length.

    ``ReadDataStream`` returns short reads silently; here reading past the record is damage.
    """

    def __init__(self, data):
        self._data = data
        self.count = 0

    def read(self, length):
        if length < 0 or self.count + length > len(self._data):
            raise _Damaged(f'a field of {length} bytes runs past the record end')
        start, self.count = self.count, self.count + length
        return bytes(self._data[start:self.count])

    def _unpack(self, fmt, size):
        return struct.unpack(fmt, self.read(size))[0]

    def read1(self):
        return self._unpack('<B', 1)

    def read2(self):
        return self._unpack('<H', 2)

    def read4(self):
        return self._unpack('<I', 4)

    def read8(self):
        return self._unpack('<Q', 8)

    def read_prefixed_string(self):
        return str(self.read(self.read4()), 'utf-8')


_PARSERS = {
    _HEADER: Header.read, _SCHEMA: Schema.read, _CHANNEL: Channel.read, _CHUNK: Chunk.read,
    _METADATA: Metadata.read, _DATA_END: DataEnd.read, _CHUNK_INDEX: ChunkIndex.read,
    _METADATA_INDEX: MetadataIndex.read,
}


def _parse(opcode, body):
    """The record of ``opcode`` read from ``body`` (a memoryview), or None if not used here."""
    if opcode == _MESSAGE:
        if len(body) < _MESSAGE_FIXED:
            raise _Damaged(f'message record of {len(body)} bytes, shorter than its fixed '
                           f'{_MESSAGE_FIXED}')
        return Message.read(_Body(body), len(body))
    parser = _PARSERS.get(opcode)
    if parser is None:
        return None
    stream = _Body(body)
    return parser(stream)


@dataclass(frozen=True)
class RawMessage:
    """A message record as found: channel id, times, serialized data."""

    channel_id: int
    log_time: int
    publish_time: int
    data: bytes


@dataclass
class Scan:
    """What :func:`scan_mcap` found.

    ``schemas``/``channels`` are from the data section, ``summary_schemas``/
    ``summary_channels`` from a summary whose CRC holds; ``metadata`` in file order;
    ``damage`` one line per damaged part; ``recovered_bytes`` the bytes read as intact records
    (with the magic), ``== len(data)`` for an intact file.
    """

    header: Header | None = None
    schemas: dict = field(default_factory=dict)
    channels: dict = field(default_factory=dict)
    summary_schemas: dict = field(default_factory=dict)
    summary_channels: dict = field(default_factory=dict)
    metadata: list = field(default_factory=list)
    messages: list = field(default_factory=list)
    damage: list = field(default_factory=list)
    truncated: bool = False
    recovered_bytes: int = 0


def _frame(data, pos, limit):
    """``(opcode, end)`` of the record at ``pos``, end None if it does not fit before limit."""
    if pos + 9 > limit:
        return None, None
    opcode, length = struct.unpack_from('<BQ', data, pos)
    end = pos + 9 + length
    return opcode, (end if end <= limit else None)


def _footer(data):
    """``(position, summary_start, summary_crc, end)`` of the last footer, or None.

    ``end`` is where its closing magic ends: the file's size unless bytes follow it.
    """
    size = len(data)
    magic = data.rfind(MAGIC, len(MAGIC) + _FOOTER_SIZE)
    while magic >= 0:
        pos = magic - _FOOTER_SIZE
        opcode, length, summary_start, _, crc = struct.unpack_from('<BQQQI', data, pos)
        if opcode == _FOOTER and length == _FOOTER_SIZE - 9:
            return pos, summary_start, crc, magic + len(MAGIC)
        if size - magic > 1 << 20:   # only a little garbage after the end is looked through
            return None
        magic = data.rfind(MAGIC, len(MAGIC) + _FOOTER_SIZE, magic)
    return None


def _decompress(chunk):
    """The uncompressed records of ``chunk``; raises :class:`_Damaged` with the reason."""
    size = chunk.uncompressed_size
    if size > MAX_CHUNK_SIZE:
        raise _Damaged(f'declared uncompressed size {size} bytes is implausible')
    try:
        if chunk.compression == 'zstd':
            import zstandard
            with zstandard.ZstdDecompressor().stream_reader(io.BytesIO(chunk.data)) as reader:
                parts, total = [], 0
                while total <= size:
                    part = reader.read(min(_READ_STEP, size + 1 - total))
                    if not part:
                        break
                    parts.append(part)
                    total += len(part)
                data = b''.join(parts)
        elif chunk.compression == 'lz4':
            import lz4.frame
            data = lz4.frame.LZ4FrameDecompressor().decompress(chunk.data, max_length=size + 1)
        elif chunk.compression == '':
            data = chunk.data
        else:
            raise _Damaged(f'unsupported compression {chunk.compression!r}')
    except _Damaged:
        raise
    except Exception as error:  # noqa: BLE001 - any failure of a decompressor is damage
        raise _Damaged(f'{chunk.compression} decompression failed: {reason_of(error)}') from None
    if len(data) != size:
        raise _Damaged(f'decompressed to {len(data)}{"+" if len(data) > size else ""} bytes, '
                       f'{size} declared')
    if chunk.uncompressed_crc != 0 and zlib.crc32(data) != chunk.uncompressed_crc:
        raise _Damaged(f'CRC mismatch of the uncompressed records (0x{zlib.crc32(data):08x}, '
                       f'0x{chunk.uncompressed_crc:08x} recorded)')
    return memoryview(data)


def _read_chunk(chunk, where, scan, schemas, channels):
    """Add the records of a chunk; a broken inner framing ends the chunk (damage noted).

    A message record is read here directly (the fields of ``mcap.records.Message.read``, one
    ``struct`` call): it is most of the records, and ``Message.read`` through :class:`_Body`
    took 2/3 of the scan of a 1 kHz recording.
    """
    data = _decompress(chunk)
    size = len(data)
    messages = scan.messages
    pos = 0
    while pos < size:
        opcode, end = _frame(data, pos, size)
        if end is None:
            scan.damage.append(f'{where}: inner record framing broken at offset {pos}; the '
                               f'rest of the chunk ({size - pos} bytes) skipped')
            return
        if opcode == _MESSAGE and end - pos - 9 >= _MESSAGE_FIXED:
            channel_id, _, log_time, publish_time = _MESSAGE_HEAD.unpack_from(data, pos + 9)
            messages.append(RawMessage(channel_id, log_time, publish_time,
                                       bytes(data[pos + 9 + _MESSAGE_FIXED:end])))
            pos = end
            continue
        try:
            record = _parse(opcode, data[pos + 9:end]) if opcode in (
                _SCHEMA, _CHANNEL, _MESSAGE) else None
        except Exception as error:  # noqa: BLE001 - third-party record parsers
            scan.damage.append(f'{where}: inner record at offset {pos} (opcode 0x{opcode:02x}) '
                               f'skipped: {reason_of(error)}')
            record = None
        _add(record, scan, schemas, channels)
        pos = end


def _add(record, scan, schemas, channels):
    if isinstance(record, Message):
        scan.messages.append(RawMessage(record.channel_id, record.log_time,
                                        record.publish_time, record.data))
    elif isinstance(record, Schema):
        schemas.setdefault(record.id, record)
    elif isinstance(record, Channel):
        channels.setdefault(record.id, record)


def _read_summary(data, start, end, scan, trusted):
    """Resync offsets of a summary section; its schemas and channels too if ``trusted``."""
    offsets = set()
    pos = start
    while pos < end:
        opcode, stop = _frame(data, pos, end)
        if stop is None or opcode not in _KNOWN_OPCODES:
            scan.damage.append(f'summary section: record framing broken at byte {pos}; the '
                               f'rest of the summary ignored')
            break
        try:
            record = _parse(opcode, data[pos + 9:stop])
        except Exception as error:  # noqa: BLE001 - third-party record parsers
            scan.damage.append(f'summary section: record at byte {pos} (opcode '
                               f'0x{opcode:02x}) skipped: {reason_of(error)}')
            record = None
        if isinstance(record, ChunkIndex):
            offsets.add(record.chunk_start_offset)
        elif isinstance(record, MetadataIndex):
            offsets.add(record.offset)
        elif trusted:
            _add(record, scan, scan.summary_schemas, scan.summary_channels)
        pos = stop
    return sorted(o for o in offsets if len(MAGIC) <= o < start)


def _summary(data, scan):
    """Find the footer; return ``(data_limit, resync offsets, summary bytes kept)``."""
    footer = _footer(data)
    scan.truncated = footer is None
    if footer is None:
        return len(data), [], 0
    footer_pos, summary_start, crc, end = footer
    trailer = end - footer_pos
    if end < len(data):
        scan.damage.append(f'bytes {end}-{len(data)}: {len(data) - end} bytes after the end of '
                           f'the MCAP file (footer and magic at byte {footer_pos}) ignored')
    if summary_start == 0:
        return footer_pos, [], trailer
    if not len(MAGIC) <= summary_start <= footer_pos:
        scan.damage.append(f'footer: summary start {summary_start} outside the file; summary '
                           f'ignored')
        return footer_pos, [], trailer
    computed = zlib.crc32(memoryview(data)[summary_start:footer_pos + 9 + 16])
    trusted = crc == 0 or computed == crc
    if not trusted:
        scan.damage.append(f'summary section (bytes {summary_start}-{footer_pos}): CRC '
                           f'mismatch (0x{computed:08x}, 0x{crc:08x} recorded); its schemas '
                           f'and channels ignored')
    offsets = _read_summary(data, summary_start, footer_pos, scan, trusted)
    return summary_start, offsets, trailer + (footer_pos - summary_start if trusted else 0)


def _is_chunk(data, pos, limit):
    """True if a chunk record's framing and fixed fields are consistent at ``pos``."""
    fixed = 8 + 8 + 8 + 4 + 4
    if pos + 9 + fixed > limit or data[pos] != _CHUNK:
        return False
    (length,) = struct.unpack_from('<Q', data, pos + 1)
    (name_length,) = struct.unpack_from('<I', data, pos + 9 + fixed - 4)
    start = pos + 9 + fixed
    if pos + 9 + length > limit or name_length > 8 or start + name_length + 8 > limit:
        return False
    if bytes(data[start:start + name_length]) not in _COMPRESSIONS:
        return False
    (records,) = struct.unpack_from('<Q', data, start + name_length)
    return records == length - fixed - name_length - 8


def _resync(data, pos, limit, offsets):
    """Where reading can resume after lost framing at ``pos`` (None: nowhere)."""
    indexed = None
    for offset in offsets:
        opcode, end = _frame(data, offset, limit)
        if offset > pos and end is not None and opcode in _KNOWN_OPCODES:
            indexed = offset
            break
    k = pos
    while True:
        k = data.find(b'\x06', k + 1, indexed or limit)
        if k < 0:
            return indexed
        if _is_chunk(data, k, limit):
            return k


def _record(opcode, data, pos, end, scan, in_summary):
    """Read one top-level record into ``scan``; False (damage noted) if it is damaged."""
    where = f'record at byte {pos} (opcode 0x{opcode:02x}, {end - pos} bytes)'
    try:
        record = _parse(opcode, data[pos + 9:end])
        if isinstance(record, Chunk):
            where = f'chunk at byte {pos} ({end - pos} bytes)'
            _read_chunk(record, where, scan, scan.schemas, scan.channels)
        elif isinstance(record, Header):
            scan.header = scan.header or record
        elif isinstance(record, Metadata):
            scan.metadata.append(record)
        elif isinstance(record, DataEnd):
            computed = zlib.crc32(memoryview(data)[:pos])
            if record.data_section_crc not in (0, computed):
                scan.damage.append(f'data section (bytes 0-{pos}): CRC mismatch '
                                   f'(0x{computed:08x}, 0x{record.data_section_crc:08x} '
                                   f'recorded): damage outside the chunks\' records')
        elif in_summary:
            _add(record, scan, scan.summary_schemas, scan.summary_channels)
        else:
            _add(record, scan, scan.schemas, scan.channels)
    except Exception as error:  # noqa: BLE001 - third-party record parsers and decompressors
        scan.damage.append(f'{where} skipped: {reason_of(error)}')
        return False
    return True


def scan_mcap(data):
    """Scan ``data`` (the bytes of a file that starts with :data:`MAGIC`).

    Returns
    -------
    Scan
    """
    scan = Scan()
    limit, resync, summary_kept = _summary(data, scan)
    pos, intact, in_summary = len(MAGIC), len(MAGIC), False
    while pos < limit:
        opcode, end = _frame(data, pos, limit)
        if end is None or opcode not in _KNOWN_OPCODES:
            target = _resync(data, pos, limit, resync)
            if target is None and scan.truncated and (
                    opcode in _KNOWN_OPCODES or opcode is None or not any(data[pos:])):
                break   # the cut of a killed writer
            what = ('too short for a record header' if opcode is None
                    else f'opcode 0x{opcode:02x}' + (', length past the end' if end is None
                                                     and opcode in _KNOWN_OPCODES else ''))
            scan.damage.append(
                f'bytes {pos}-{target or limit}: record framing lost ({what}); '
                + (f'resumed at the {"chunk" if data[target] == _CHUNK else "record"} at '
                   f'byte {target}' if target else 'the rest of the data section is '
                                                     'unreadable'))
            if target is None:
                break
            pos = target
            continue
        if opcode == _FOOTER:
            break
        if _record(opcode, data, pos, end, scan, in_summary):
            intact += end - pos
        in_summary = in_summary or opcode == _DATA_END
        pos = end
    scan.recovered_bytes = intact + summary_kept
    return scan
