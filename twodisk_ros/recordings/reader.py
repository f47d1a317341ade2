"""Reading MCAP recordings (rosbag2 layout), tolerant of cut and damaged files.

The records are found by :func:`twodisk_ros.recordings.mcap_scan.scan_mcap` (its docstring states the
recovery rule); here they become decoded messages, channels and metadata.  Messages are
decoded by :mod:`twodisk_ros.recordings.cdr_decode`: what ``mcap_ros2`` returns, faster.

Needs only ``mcap`` and ``mcap-ros2-support``: no rclpy, so recordings are read and checked
offline on any machine.
"""

import contextlib
import errno
from functools import lru_cache
import gc
import io
import os
import stat
import threading
from dataclasses import dataclass, field
from typing import Any

from mcap.records import Schema

from ..limits import describe_bytes, memory_limit
from .cdr_decode import DecoderFactory
from .errors import RecordingError, os_error_reason
from .mcap_scan import MAGIC, reason_of, scan_mcap

__all__ = ['RecordedMessage', 'Recording', 'TopicInfo', 'collector_paused', 'read_recording']


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
        The message as ``mcap_ros2`` decodes it (attribute access like the ROS class), or the raw
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
    damage : list of str
        One line per damaged part of the file that was skipped (a chunk that does not
        decompress or fails its CRC, a record whose fields do not fit, lost framing, CRC
        mismatches of the data section or summary; see :mod:`twodisk_ros.recordings.mcap_scan` for
        the recovery rule).  Empty for an intact (possibly truncated) file.
    undecodable : dict of str to tuple of (int, str)
        Messages that could not be decoded, by topic: their count and the first reason.
        They are not in ``messages``.
    orphans : int
        Messages whose channel is defined nowhere in the readable part (not in ``messages``).
    recovered_bytes : int
        Bytes of the file read as intact records (``== total_bytes`` unless truncated or
        damaged).
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
    damage: list = field(default_factory=list)
    undecodable: dict = field(default_factory=dict)
    orphans: int = 0
    recovered_bytes: int = 0
    total_bytes: int = 0
    profile: str = ''
    library: str = ''

    @property
    def damaged(self):
        """True if part of the file was damaged (not merely cut)."""
        return bool(self.damage)

    @property
    def empty(self):
        """True if nothing of a recording was recovered: no channel, message or metadata."""
        return not (self.topics or self.messages or self.metadata or self.undecodable)



def read_recording(path, *, decode=None) -> Recording:
    """Read a recording written by :class:`McapRecorder` (or rosbag2), tolerating damage.

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
        chunks; damaged parts are skipped and listed in ``damage`` (the recovery rule is
        that of :mod:`twodisk_ros.recordings.mcap_scan`); messages that do not decode are counted in
        ``undecodable``.  The file is read into memory, which suits recordings of simulation
        runs.

    Raises
    ------
    RecordingError
        If the file is missing, unreadable or not MCAP (no magic).
    """
    path = os.fspath(path)
    try:
        data = _read_regular_file(path)
    except OSError as error:
        reason = os_error_reason(path, error, writing=False)
        raise RecordingError(f'cannot read recording {path}: {reason}') from None
    if not data.startswith(MAGIC):
        reason = ('empty file' if not data else
                  f'not an MCAP file (only {len(data)} bytes)' if MAGIC.startswith(data) else
                  'not an MCAP file')
        raise RecordingError(f'cannot read recording {path}: {reason}')
    with collector_paused():
        return _read(path, data, decode)


def _read(path, data, decode):
    scan = scan_mcap(data)
    recording = Recording(path=path, truncated=scan.truncated, damage=list(scan.damage),
                          recovered_bytes=scan.recovered_bytes, total_bytes=len(data))
    if scan.header is not None:
        recording.profile, recording.library = scan.header.profile, scan.header.library
    for record in scan.metadata:
        recording.metadata[record.name] = dict(record.metadata)
    _decode(scan, recording, decode)
    return recording


_PAUSE_LOCK = threading.Lock()
_pauses = {'depth': 0, 'was_enabled': False}


@contextlib.contextmanager
def collector_paused():
    """Pause Python's cyclic garbage collector while a recording is read.

    Reading makes a few objects per message (records, decoded messages, lists) and no reference
    cycles; with the collector on, its full collections walk all of them again and again: 2.1
    of the 2.9 s that decoding a 15 s, 1 kHz recording took (Python 3.11).  Paused, it walks
    the messages that outlive the pause a few times once it runs again (a read of that
    recording followed by a pass over its messages: 30 % less time than without the pause),
    and never those freed before (:func:`~twodisk_ros.inspector.inspection.inspect_recording`
    keeps it paused until it has dropped them).  Nested and concurrent pauses share one; the
    collector is enabled again, if it was, when the last one ends.
    """
    with _PAUSE_LOCK:
        if _pauses['depth'] == 0:
            _pauses['was_enabled'] = gc.isenabled()
            gc.disable()
        _pauses['depth'] += 1
    try:
        yield
    finally:
        with _PAUSE_LOCK:
            _pauses['depth'] -= 1
            if _pauses['depth'] == 0 and _pauses['was_enabled']:
                gc.enable()


def _read_regular_file(path):
    """The bytes of ``path``; RecordingError if it is not a regular file or cannot fit.

    Opened without blocking (a FIFO nobody writes to would block ``open`` forever) and
    checked on the open descriptor: a FIFO, a device (``/dev/zero`` never ends) or a socket
    is refused before anything is read, as is a file larger than the memory a command may
    use (:func:`twodisk_ros.limits.memory_limit`).
    """
    fd = os.open(path, os.O_RDONLY | getattr(os, 'O_NONBLOCK', 0))
    with open(fd, 'rb') as stream:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError(errno.EISDIR, 'it is a directory')
        if not stat.S_ISREG(info.st_mode):
            raise RecordingError(f'cannot read recording {path}: not a regular file (a FIFO, '
                                 'a device or a socket is not read)')
        limit, reason = memory_limit()
        if info.st_size > limit:
            raise RecordingError(f'cannot read recording {path}: {describe_bytes(info.st_size)}'
                                 f', more than the {describe_bytes(limit)} it may use ({reason})')
        os.set_blocking(fd, True)
        return stream.read()


@lru_cache(maxsize=32)
def _decoder(message_encoding, schema_name, schema_encoding, schema_data):
    """(decoder, None) or (None, reason) for a channel's encoding and schema record (name,
    encoding, bytes; None without a schema). Cached by those exact values: reading many
    recordings of the node in one process parses each schema text once (~1 ms apiece, a
    sixth of inspecting a short recording), and a damaged schema is another key."""
    schema = (None if schema_name is None else
              Schema(id=1, name=schema_name, encoding=schema_encoding, data=schema_data))
    printed = io.StringIO()   # the vendored msg parser prints its complaints
    try:
        with contextlib.redirect_stderr(printed), contextlib.redirect_stdout(printed):
            return DecoderFactory().decoder_for(message_encoding, schema), None
    except Exception as error:  # noqa: BLE001 - a damaged schema text
        return None, f'schema: {reason_of(error)}'


def _decode(scan, recording, decode):
    """Decode the scanned messages into ``recording``; failures are counted, not raised.

    What to do with a channel's messages (its topic, type, decoder or schema error) is
    settled once per channel, at its first message; ``decode(topic)`` is asked once per
    channel.
    """
    schemas = {**scan.summary_schemas, **scan.schemas}
    channels = {**scan.summary_channels, **scan.channels}
    counts = {channel.topic: 0 for channel in channels.values()}
    plans = {}

    def plan_of(channel_id):
        """``(topic, type name, decoder or None, schema error or None)``, or None: orphan."""
        channel = channels.get(channel_id)
        if channel is None:
            return None
        schema = schemas.get(channel.schema_id)
        decoder = reason = None
        if decode is None or decode(channel.topic):
            decoder, reason = _decoder(
                channel.message_encoding, *((None, None, None) if schema is None else
                                            (schema.name, schema.encoding, bytes(schema.data))))
        return channel.topic, schema.name if schema else '', decoder, reason

    messages = recording.messages
    undecodable = recording.undecodable
    for raw in scan.messages:
        channel_id = raw.channel_id
        if channel_id not in plans:
            plans[channel_id] = plan_of(channel_id)
        plan = plans[channel_id]
        if plan is None:
            recording.orphans += 1
            continue
        topic, type_name, decoder, reason = plan
        msg = raw.data
        if decoder is not None:
            try:
                msg = decoder(msg)
            except Exception as error:  # noqa: BLE001 - malformed CDR, any decoder failure
                reason = reason_of(error)
        if reason is not None:
            count, first = undecodable.get(topic, (0, reason))
            undecodable[topic] = (count + 1, first)
            continue
        messages.append(RecordedMessage(topic, type_name, raw.log_time, raw.publish_time,
                                        msg))
        counts[topic] += 1
    for channel in channels.values():
        schema = schemas.get(channel.schema_id)
        recording.topics[channel.topic] = TopicInfo(
            schema.name if schema else '', counts[channel.topic],
            channel.metadata.get('offered_qos_profiles', ''))
