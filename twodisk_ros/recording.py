"""MCAP recordings laid out as rosbag2 (ROS 2 Jazzy, mcap storage plugin) writes them.

No rosbag2 is needed: messages are serialized to CDR with ``rclpy.serialization`` and written
with the ``mcap`` library.  What makes the file a rosbag2 file is copied from the Jazzy sources:

- header profile ``ros2``; one schema per type, named ``pkg/msg/Type``, encoding ``ros2msg``,
  holding the full definition text (see :mod:`twodisk_ros._msgdefs`);
- one channel per topic, message encoding ``cdr``, metadata ``offered_qos_profiles`` (the QoS
  list as YAML, metadata version 9) and ``topic_type_hash``;
- a metadata record ``rosbag2`` with key ``serialized_metadata`` (the YAML bag metadata), written
  when the file is opened and again, final, when it is closed;
- chunked data with chunk and message indexes, statistics and summary offsets.

Times are integer nanoseconds; a message's log time and publish time are both its stamp.
Each chunk is handed to the operating system as soon as it is complete, so a process that is
killed leaves every message before its last, unfinished chunk readable by
:func:`read_recording`.
"""

import io
import operator
import os
import re
import struct
import threading
from dataclasses import dataclass, field
from importlib import metadata as _importlib_metadata
from typing import Any, Mapping

import yaml
from mcap.exceptions import McapError
from mcap.records import Channel, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer
from mcap_ros2.decoder import DecoderFactory
from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message

from twodisk_ros import _msgdefs

__all__ = [
    'DEFAULT_CHUNK_SIZE',
    'McapRecorder',
    'RecordedMessage',
    'Recording',
    'RecordingError',
    'TopicInfo',
    'qos_profiles_yaml',
    'read_recording',
]

#: Uncompressed bytes per chunk.  A chunk reaches the disk only when complete, so this bounds
#: what a killed process loses; 256 KiB keeps the per-chunk index overhead far below 1 % and
#: still compresses well (rosbag2's own default, from libmcap, is 768 KiB).
DEFAULT_CHUNK_SIZE = 256 * 1024

_MAGIC = b'\x89MCAP0\r\n'
_OPCODE_FOOTER = 0x02
_INT64_MAX = 2**63 - 1
_UINT64_MAX = 2**64 - 1
_BAG_METADATA_VERSION = 9  # rosbag2_storage BagMetadata::version in Jazzy
_ROS_DISTRO = 'jazzy'
_COMPRESSION = {
    'zstd': CompressionType.ZSTD,
    'lz4': CompressionType.LZ4,
    'none': CompressionType.NONE,
}


class RecordingError(Exception):
    """A recording file cannot be written or read; the message is one line naming the path."""


def _version(dist):
    """Return the installed version of a distribution, or ``None``."""
    try:
        return _importlib_metadata.version(dist)
    except _importlib_metadata.PackageNotFoundError:
        return None


def _package_version():
    """Return the twodisk_ros version: installed metadata, else the source tree's package.xml."""
    version = _version('twodisk_ros')
    if version:
        return version
    package_xml = os.path.join(os.path.dirname(os.path.dirname(__file__)), 'package.xml')
    try:
        with open(package_xml, encoding='utf-8') as stream:
            match = re.search(r'<version>\s*([^<\s]+)\s*</version>', stream.read())
    except OSError:
        match = None
    return match.group(1) if match else 'unknown'


LIBRARY = (f'twodisk_ros {_package_version()} rosbag2-compatible writer '
           f'(ros2 {_ROS_DISTRO}; mcap-python {_version("mcap") or "unknown"})')


def _one_line(text):
    """Collapse whitespace so that an error message is a single line."""
    return ' '.join(str(text).split())


def _reason(path, error, writing):
    """Explain an ``OSError`` raised while opening ``path``, in a few words."""
    parent = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        return 'it is a directory'
    if writing and not os.path.isdir(parent):
        return f'directory {parent} does not exist'
    return _one_line(error.strerror or error)


# --------------------------------------------------------------------------------------------
# YAML as yaml-cpp's YAML::Dump emits it (block style, sequences indented under their key).

_PLAIN = re.compile(r'[A-Za-z0-9_./][A-Za-z0-9_./ -]*')
_ESCAPES = {'"': '\\"', '\\': '\\\\'}


def _quoted(text):
    """Return a double-quoted YAML scalar, escaping all but printable ASCII."""
    out = []
    for char in text:
        code = ord(char)
        if char in _ESCAPES:
            out.append(_ESCAPES[char])
        elif 0x20 <= code < 0x7f:
            out.append(char)
        elif code <= 0xffff:
            out.append(f'\\u{code:04x}')
        else:
            out.append(f'\\U{code:08x}')
    return '"' + ''.join(out) + '"'


def _scalar(value):
    """Format one YAML scalar: plain where that reads back as the same string, else quoted."""
    if value is None:
        return '~'
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, int):
        return str(value)
    text = str(value)
    if _PLAIN.fullmatch(text) and not text.endswith(' ') and yaml.safe_load(text) == text:
        return text
    return _quoted(text)


def _lines(value, indent):
    """Return the block YAML lines of a dict or a list at ``indent`` spaces."""
    pad = ' ' * indent
    out = []
    if isinstance(value, dict):
        for key, item in value.items():
            if isinstance(item, (dict, list)) and item:
                out.append(f'{pad}{key}:')
                out += _lines(item, indent + 2)
            else:
                out.append(f'{pad}{key}: {_empty(item)}')
    else:
        for item in value:
            if isinstance(item, (dict, list)) and item:
                sub = _lines(item, indent + 2)
                sub[0] = f'{pad}- {sub[0][indent + 2:]}'
                out += sub
            else:
                out.append(f'{pad}- {_empty(item)}')
    return out


def _empty(value):
    """Format a scalar, or an empty container as yaml-cpp does (``[]`` / ``{}``)."""
    if isinstance(value, list):
        return '[]'
    if isinstance(value, dict):
        return '{}'
    return _scalar(value)


def _dump(value):
    """Dump a dict or list like ``YAML::Dump`` (no trailing newline)."""
    return '\n'.join(_lines(value, 0))


# --------------------------------------------------------------------------------------------
# QoS and bag metadata as rosbag2_storage (qos.cpp, yaml.hpp) encodes them in Jazzy.

def _rmw_time(duration):
    """Return an ``rmw_time_t``-like ``{sec, nsec}`` mapping of an rclpy ``Duration``."""
    sec, nsec = divmod(int(duration.nanoseconds), 10**9)
    return {'sec': sec, 'nsec': nsec}


def _qos_node(qos):
    """Return the YAML node of one QoS profile (version 9: policies as rmw strings)."""
    return {
        'history': qos.history.name.lower(),
        'depth': int(qos.depth),
        'reliability': qos.reliability.name.lower(),
        'durability': qos.durability.name.lower(),
        'deadline': _rmw_time(qos.deadline),
        'lifespan': _rmw_time(qos.lifespan),
        'liveliness': qos.liveliness.name.lower(),
        'liveliness_lease_duration': _rmw_time(qos.liveliness_lease_duration),
        'avoid_ros_namespace_conventions': bool(qos.avoid_ros_namespace_conventions),
    }


def qos_profiles_yaml(profiles):
    """Return ``offered_qos_profiles`` channel metadata as rosbag2 Jazzy writes it.

    Parameters
    ----------
    profiles : sequence of rclpy.qos.QoSProfile
        The offered profiles of the topic's publishers.

    Returns
    -------
    str
        The YAML sequence, e.g. ``'- history: keep_last\\n  depth: 10\\n  ...'``.
    """
    return _dump([_qos_node(qos) for qos in profiles])


@dataclass
class _TopicState:
    """What the recorder keeps per topic."""

    channel_id: int
    msg_type: type
    type_name: str
    qos: QoSProfile
    type_hash: str
    message_count: int = 0


# --------------------------------------------------------------------------------------------
# Writing.

class _WriteThrough:
    """Output stream for :class:`mcap.writer.Writer` that hands every write to the OS at once.

    The Writer calls ``write`` once per completed chunk (and per index and metadata group), so
    writing through an unbuffered file makes completed chunks survive a killed process.
    """

    def __init__(self, raw):
        self._raw = raw
        self._position = 0

    def write(self, data):
        view = memoryview(data)
        while view:
            written = self._raw.write(view)
            view = view[written:]
        self._position += len(data)
        return len(data)

    def tell(self):
        return self._position

    def flush(self):
        pass


class McapRecorder:
    """Write ROS 2 messages to an MCAP file in the layout of rosbag2 Jazzy.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.mcap`` file to create (an existing file is replaced).
    metadata : Mapping[str, str], optional
        Written as the metadata record ``twodisk_ros`` now and again at :meth:`close`
        (replace it with :meth:`set_metadata`), e.g. parameters and package version.
    chunk_size : int, optional
        Uncompressed bytes per chunk (:data:`DEFAULT_CHUNK_SIZE`); at most this much is lost
        if the process is killed.
    compression : {'zstd', 'lz4', 'none'}, optional
        Chunk compression.

    Raises
    ------
    RecordingError
        If ``path`` cannot be written (missing directory, a directory, no permission).

    Examples
    --------
    >>> with McapRecorder('run.mcap', metadata={'version': '0.1.0'}) as rec:  # doctest: +SKIP
    ...     rec.add_topic('/pose', PoseStamped)
    ...     rec.write('/pose', msg, stamp_ns)
    """

    def __init__(self, path, *, metadata: Mapping[str, str] | None = None,
                 chunk_size: int = DEFAULT_CHUNK_SIZE, compression: str = 'zstd'):
        self._path = os.fspath(path)
        self._metadata = _check_metadata(metadata or {})
        if isinstance(chunk_size, bool) or operator.index(chunk_size) <= 0:
            raise ValueError(f'chunk_size must be a positive integer, got {chunk_size!r}')
        if compression not in _COMPRESSION:
            raise ValueError(f'compression must be one of {sorted(_COMPRESSION)}, '
                             f'got {compression!r}')
        try:
            self._raw = open(self._path, 'wb', buffering=0)
        except OSError as error:
            raise RecordingError(
                f'cannot write recording {self._path}: '
                f'{_reason(self._path, error, writing=True)}') from None
        self._lock = threading.Lock()
        self._closed = False
        self._topics: dict[str, _TopicState] = {}
        self._schemas: dict[str, int] = {}
        self._message_count = 0
        self._first_ns = None
        self._last_ns = None
        try:
            self._writer = Writer(_WriteThrough(self._raw),
                                  chunk_size=operator.index(chunk_size),
                                  compression=_COMPRESSION[compression])
            with self._io('start'):
                self._writer.start(profile='ros2', library=LIBRARY)
                self._writer.add_metadata('rosbag2', self._bag_metadata())
                if self._metadata:
                    self._writer.add_metadata('twodisk_ros', dict(self._metadata))
        except BaseException:
            self._closed = True
            self._raw.close()
            raise

    @property
    def path(self) -> str:
        """The file written."""
        return self._path

    @property
    def message_count(self) -> int:
        """Number of messages written so far."""
        return self._message_count

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has been called."""
        return self._closed

    def add_topic(self, topic: str, msg_type: type, qos: QoSProfile | None = None) -> int:
        """Register a topic; its type's schema is written once, on first use.

        Parameters
        ----------
        topic : str
            Topic name, e.g. ``'/pose'``.
        msg_type : type
            Generated message class, e.g. ``geometry_msgs.msg.PoseStamped``.
        qos : rclpy.qos.QoSProfile, optional
            Offered QoS stored in the channel metadata; reliable, volatile, keep last 10 if
            omitted.

        Returns
        -------
        int
            The MCAP channel id.  Adding a topic again with the same type returns its id.
        """
        type_name = _msgdefs.ros_type_name(msg_type)
        qos = qos if qos is not None else QoSProfile(depth=10)
        with self._lock:
            self._check_open()
            known = self._topics.get(topic)
            if known is not None:
                if known.msg_type is not msg_type:
                    raise ValueError(f'topic {topic} already has type {known.type_name}, '
                                     f'not {type_name}')
                return known.channel_id
            with self._io('add topic'):
                schema_id = self._schemas.get(type_name)
                if schema_id is None:
                    try:
                        text = _msgdefs.full_text(type_name)
                    except _msgdefs.DefinitionNotFoundError as error:
                        raise RecordingError(_one_line(error)) from None
                    schema_id = self._writer.register_schema(type_name, 'ros2msg', text)
                    self._schemas[type_name] = schema_id
                type_hash = _msgdefs.type_hash(type_name)
                channel_id = self._writer.register_channel(
                    topic, 'cdr', schema_id,
                    {'offered_qos_profiles': qos_profiles_yaml([qos]),
                     'topic_type_hash': type_hash})
            self._topics[topic] = _TopicState(channel_id, msg_type, type_name, qos, type_hash)
            return channel_id

    def write(self, topic: str, msg, stamp_ns: int) -> None:
        """Serialize a message to CDR and add it.

        Parameters
        ----------
        topic : str
            A topic registered with :meth:`add_topic`.
        msg : object
            A message of the topic's type.
        stamp_ns : int
            Log and publish time, integer nanoseconds (usually the header stamp).
        """
        state = self._topic(topic)
        if type(msg) is not state.msg_type:
            raise TypeError(f'topic {topic} records {state.type_name}, '
                            f'got {type(msg).__module__}.{type(msg).__name__}')
        self.write_serialized(topic, serialize_message(msg), stamp_ns)

    def write_serialized(self, topic: str, data: bytes, stamp_ns: int) -> None:
        """Add an already CDR-serialized message.

        Parameters
        ----------
        topic : str
            A topic registered with :meth:`add_topic`.
        data : bytes
            The CDR bytes (as ``rclpy.serialization.serialize_message`` returns them).
        stamp_ns : int
            Log and publish time, integer nanoseconds.
        """
        if isinstance(stamp_ns, bool):
            raise TypeError('stamp_ns must be an integer number of nanoseconds')
        stamp = operator.index(stamp_ns)
        if not 0 <= stamp <= _UINT64_MAX:
            raise ValueError(f'stamp_ns must be in [0, 2**64), got {stamp}')
        data = bytes(data)
        with self._lock:
            self._check_open()
            state = self._topic(topic)
            with self._io('write'):
                self._writer.add_message(state.channel_id, log_time=stamp, data=data,
                                         publish_time=stamp)
            state.message_count += 1
            self._message_count += 1
            self._first_ns = stamp if self._first_ns is None else min(self._first_ns, stamp)
            self._last_ns = stamp if self._last_ns is None else max(self._last_ns, stamp)

    def flush(self) -> None:
        """End the chunk in progress now, so that everything written so far is on disk."""
        with self._lock:
            self._check_open()
            with self._io('flush'):
                self._writer.flush()

    def set_metadata(self, metadata: Mapping[str, str]) -> None:
        """Replace the key-value pairs written under ``twodisk_ros`` at :meth:`close`."""
        checked = _check_metadata(metadata)
        with self._lock:
            self._check_open()
            self._metadata = checked

    def close(self) -> None:
        """Write the final metadata, the summary and the footer, and close the file.

        Calling it again does nothing.
        """
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                with self._io('close'):
                    self._writer.flush()
                    self._writer.add_metadata('rosbag2', self._bag_metadata())
                    self._writer.add_metadata('twodisk_ros', dict(self._metadata))
                    self._writer.finish()
            finally:
                self._raw.close()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, traceback):
        self.close()
        return False

    def __repr__(self):
        state = 'closed' if self._closed else 'open'
        return (f'<McapRecorder {self._path!r} {state}, {len(self._topics)} topics, '
                f'{self._message_count} messages>')

    # -- internals -------------------------------------------------------------------------

    def _check_open(self):
        if self._closed:
            raise ValueError(f'recording {self._path} is closed')

    def _topic(self, topic):
        try:
            return self._topics[topic]
        except KeyError:
            raise ValueError(f'unknown topic {topic!r}; call add_topic() first') from None

    def _io(self, what):
        """Context turning an ``OSError`` of the file into a one-line :class:`RecordingError`."""
        return _IoErrors(self._path, what)

    def _bag_metadata(self):
        """Return the ``rosbag2`` metadata record: ``{'serialized_metadata': yaml}``."""
        if self._first_ns is None:
            start, duration = _INT64_MAX, 0  # std::chrono::nanoseconds::max(), as rosbag2
        else:
            start, duration = self._first_ns, self._last_ns - self._first_ns
        name = os.path.basename(self._path)
        topics = [
            {
                'topic_metadata': {
                    'name': topic,
                    'type': state.type_name,
                    'serialization_format': 'cdr',
                    'offered_qos_profiles': [_qos_node(state.qos)],
                    'type_description_hash': state.type_hash,
                },
                'message_count': state.message_count,
            }
            for topic, state in self._topics.items()
        ]
        bag = {
            'version': _BAG_METADATA_VERSION,
            'storage_identifier': 'mcap',
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start},
            'message_count': self._message_count,
            'topics_with_message_count': topics,
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [name],
            'files': [{
                'path': name,
                'starting_time': {'nanoseconds_since_epoch': start},
                'duration': {'nanoseconds': duration},
                'message_count': self._message_count,
            }],
            'custom_data': None,
            'ros_distro': _ROS_DISTRO,
        }
        return {'serialized_metadata': _dump(bag)}


class _IoErrors:
    """Context manager re-raising ``OSError`` as :class:`RecordingError`."""

    def __init__(self, path, what):
        self._path = path
        self._what = what

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, traceback):
        if exc_type is not None and issubclass(exc_type, OSError):
            raise RecordingError(f'cannot {self._what} recording {self._path}: '
                                 f'{_one_line(exc.strerror or exc)}') from exc
        return False


def _check_metadata(metadata):
    """Return ``metadata`` as a ``dict[str, str]``, or raise ``TypeError``."""
    if not isinstance(metadata, Mapping):
        raise TypeError(f'metadata must be a mapping of str to str, got {type(metadata)}')
    checked = dict(metadata)
    for key, value in checked.items():
        if not isinstance(key, str) or not isinstance(value, str):
            raise TypeError(f'metadata must map str to str, got {key!r}: {value!r}')
    return checked


# --------------------------------------------------------------------------------------------
# Reading.

@dataclass(frozen=True)
class RecordedMessage:
    """One message read back from a recording.

    Attributes
    ----------
    topic : str
        Topic name.
    type_name : str
        ``pkg/msg/Type``.
    log_time_ns : int
        Log time (the stamp given to :meth:`McapRecorder.write`).
    publish_time_ns : int
        Publish time.
    msg : object
        The message decoded by ``mcap_ros2`` (attribute access like the ROS class), or the raw
        bytes if the channel is not CDR with a ``ros2msg`` schema or its topic was not selected
        for decoding (``read_recording(..., decode=...)``).
    """

    topic: str
    type_name: str
    log_time_ns: int
    publish_time_ns: int
    msg: Any


@dataclass(frozen=True)
class TopicInfo:
    """A channel of a recording: its type, the messages read and the offered QoS YAML."""

    type_name: str
    message_count: int
    offered_qos_profiles: str


@dataclass
class Recording:
    """Everything :func:`read_recording` could read from a file.

    Attributes
    ----------
    path : str
        The file read.
    messages : list of RecordedMessage
        In file order.
    metadata : dict of str to dict of str to str
        Metadata records by name; for a name written more than once the last record wins (as
        rosbag2 reads its ``rosbag2`` record).
    topics : dict of str to TopicInfo
        Channels by topic.
    truncated : bool
        True if the file has no footer (the writer did not close it); every complete record
        before the cut has been read.
    recovered_bytes : int
        Bytes of the file read as complete records (``== total_bytes`` unless truncated).
    total_bytes : int
        Size of the file.
    profile : str
        MCAP profile from the header (``'ros2'``).
    library : str
        Writer library from the header.
    """

    path: str
    messages: list = field(default_factory=list)
    metadata: dict = field(default_factory=dict)
    topics: dict = field(default_factory=dict)
    truncated: bool = False
    recovered_bytes: int = 0
    total_bytes: int = 0
    profile: str = ''
    library: str = ''


def _complete_prefix(stream, size):
    """Return ``(end, has_footer)``: where the last complete top-level record ends."""
    position = len(_MAGIC)
    while position + 9 <= size:
        stream.seek(position)
        opcode, length = struct.unpack('<BQ', stream.read(9))
        end = position + 9 + length
        if end > size:
            break
        position = end
        if opcode == _OPCODE_FOOTER:
            stream.seek(position)
            if stream.read(len(_MAGIC)) == _MAGIC:
                return position + len(_MAGIC), True
            break
    return position, False


def read_recording(path, *, decode=None) -> Recording:
    """Read a recording written by :class:`McapRecorder` (or rosbag2), tolerating a cut file.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.mcap`` file.
    decode : callable, optional
        ``decode(topic) -> bool``: which topics' messages to decode; the others keep their
        raw CDR bytes as ``msg`` (decoding is the slow part of reading, e.g. long paths).
        All topics are decoded if omitted.

    Returns
    -------
    Recording
        Messages decoded with ``mcap_ros2``, metadata records and channels.  A file without
        footer (writer killed) gives ``truncated=True`` and every message of its complete
        chunks.  The file is read into memory, which suits recordings of simulation runs.

    Raises
    ------
    RecordingError
        If the file is missing, unreadable, not MCAP, or damaged before its end.
    """
    path = os.fspath(path)
    try:
        with open(path, 'rb') as stream:
            size = os.fstat(stream.fileno()).st_size
            if stream.read(len(_MAGIC)) != _MAGIC:
                raise RecordingError(f'cannot read recording {path}: not an MCAP file')
            end, complete = _complete_prefix(stream, size)
            stream.seek(0)
            data = stream.read(end)
    except OSError as error:
        raise RecordingError(
            f'cannot read recording {path}: {_reason(path, error, writing=False)}') from None
    recording = Recording(path=path, truncated=not complete, recovered_bytes=end,
                          total_bytes=size)
    if complete:
        reader = StreamReader(io.BytesIO(data), validate_crcs=True)
    else:
        reader = StreamReader(io.BytesIO(data[len(_MAGIC):]), skip_magic=True,
                              validate_crcs=True)
    try:
        _collect(_records(reader, complete), recording, decode)
    except (McapError, ValueError, KeyError, IndexError, struct.error) as error:
        raise RecordingError(f'cannot read recording {path}: {_one_line(error)}') from None
    return recording


def _records(reader, complete):
    """Yield the records of ``reader``; for a cut file, stop quietly where reading fails."""
    records = reader.records
    while True:
        try:
            record = next(records)
        except StopIteration:
            return
        except (McapError, ValueError, struct.error):
            if complete:
                raise
            return  # EndOfFile at the cut, or a damaged last record of a killed writer
        yield record


def _collect(records, recording, decode=None):
    """Fill ``recording`` from a stream of MCAP records; ``decode(topic)`` selects topics."""
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    decoders = DecoderFactory()
    counts: dict[str, int] = {}
    for record in records:
        if isinstance(record, Message):
            channel = channels[record.channel_id]
            schema = schemas.get(channel.schema_id)
            decoder = None
            if decode is None or decode(channel.topic):
                decoder = decoders.decoder_for(channel.message_encoding, schema)
            msg = decoder(record.data) if decoder is not None else bytes(record.data)
            recording.messages.append(RecordedMessage(
                channel.topic, schema.name if schema else '', record.log_time,
                record.publish_time, msg))
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
        elif isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            channels[record.id] = record
        elif isinstance(record, Metadata):
            recording.metadata[record.name] = dict(record.metadata)
        elif isinstance(record, Header):
            recording.profile, recording.library = record.profile, record.library
    for channel in channels.values():
        schema = schemas.get(channel.schema_id)
        recording.topics[channel.topic] = TopicInfo(
            schema.name if schema else '', counts.get(channel.topic, 0),
            channel.metadata.get('offered_qos_profiles', ''))
