"""Reading MCAP recordings (rosbag2 layout), tolerant of files whose writer was killed.

Needs only ``mcap`` and ``mcap-ros2-support``: no rclpy, so recordings are read and checked
offline on any machine.
"""

import io
import os
import struct
from dataclasses import dataclass, field
from typing import Any

from mcap.exceptions import McapError
from mcap.records import Channel, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory

from .errors import RecordingError, one_line, os_error_reason

__all__ = ['RecordedMessage', 'Recording', 'TopicInfo', 'read_recording']

_MAGIC = b'\x89MCAP0\r\n'
_OPCODE_FOOTER = 0x02


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
            f'cannot read recording {path}: {os_error_reason(path, error, writing=False)}') from None
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
        raise RecordingError(f'cannot read recording {path}: {one_line(error)}') from None
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
