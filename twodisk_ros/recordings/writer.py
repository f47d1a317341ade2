"""Writing MCAP recordings laid out as rosbag2 (ROS 2 Jazzy, mcap storage plugin) writes them.

No rosbag2 is needed: messages arrive as CDR bytes (``rclpy.serialization`` or
:mod:`twodisk_ros.recordings.cdr`) and are written with the ``mcap`` library. What makes the file a
rosbag2 file is copied from the Jazzy sources:

- header profile ``ros2``; one schema per type, named ``pkg/msg/Type``, encoding ``ros2msg``,
  holding the full definition text (see :mod:`twodisk_ros.recordings.msgdefs`);
- one channel per topic, message encoding ``cdr``, metadata ``offered_qos_profiles`` (the QoS
  list as YAML, metadata version 9) and ``topic_type_hash``;
- a metadata record ``rosbag2`` with key ``serialized_metadata`` (the YAML bag metadata,
  :mod:`twodisk_ros.recordings.rosbag2_metadata`), written when the file is opened and again, final,
  when it is closed;
- chunked data with chunk and message indexes, statistics and summary offsets.

Times are integer nanoseconds; a message's log time and publish time are both its stamp.
Each chunk is handed to the operating system as soon as it is complete, so a process that is
killed leaves every message before its last, unfinished chunk readable by
:func:`twodisk_ros.recordings.reader.read_recording`.

The file is written under a hidden temporary name beside it (``.run.1a2b3c4d.partial.mcap``)
and takes its own name when its first message is on disk (the chunk holding it is ended at
once), or at :meth:`McapRecorder.close` if it holds none. So an existing file is replaced
only by a recording that holds a message, a recorder that is :meth:`~McapRecorder.discard`-ed
before its first message leaves the old file byte for byte as it was, and a path that is not
a regular file (a directory, a device, a FIFO) is never opened, replaced or removed.
"""

import contextlib
import operator
import os
import stat
import threading
from dataclasses import dataclass
from importlib import metadata as _importlib_metadata
from typing import Mapping

from mcap.writer import CompressionType, Writer

from .. import __version__
from ..outputs import temporary_beside
from . import msgdefs
from .errors import (RecordingError, RecordingExistsError, io_errors, one_line,
                     os_error_reason)
from .rosbag2_metadata import ROS_DISTRO, bag_metadata, qos_profiles_yaml

__all__ = ['DEFAULT_CHUNK_SIZE', 'LIBRARY', 'McapRecorder']

#: Uncompressed bytes per chunk.  A chunk reaches the disk only when complete, so this bounds
#: what a killed process loses; 256 KiB keeps the per-chunk index overhead far below 1 % and
#: still compresses well (rosbag2's own default, from libmcap, is 768 KiB).
DEFAULT_CHUNK_SIZE = 256 * 1024

_UINT64_MAX = 2**64 - 1
_COMPRESSION = {
    'zstd': CompressionType.ZSTD,
    'lz4': CompressionType.LZ4,
    'none': CompressionType.NONE,
}


def _version(dist):
    """Return the installed version of a distribution, or ``None``."""
    try:
        return _importlib_metadata.version(dist)
    except _importlib_metadata.PackageNotFoundError:
        return None


LIBRARY = (f'twodisk_ros {__version__} rosbag2-compatible writer '
           f'(ros2 {ROS_DISTRO}; mcap-python {_version("mcap") or "unknown"})')


@dataclass
class _TopicState:
    """What the recorder keeps per topic."""

    channel_id: int
    msg_type: type
    type_name: str
    qos: object   # rclpy.qos.QoSProfile
    type_hash: str
    message_count: int = 0


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
        The ``.mcap`` file to create.
    metadata : Mapping[str, str], optional
        Written as the metadata record ``twodisk_ros`` now and again at :meth:`close`
        (replace it with :meth:`set_metadata`), e.g. parameters and package version.
    chunk_size : int, optional
        Uncompressed bytes per chunk (:data:`DEFAULT_CHUNK_SIZE`); at most this much is lost
        if the process is killed.
    compression : {'zstd', 'lz4', 'none'}, optional
        Chunk compression.
    overwrite : bool, optional
        Replace an existing regular file (default) when the new one holds its first
        message; if False an existing file is refused with :class:`RecordingExistsError`,
        as ``ros2 bag record`` refuses an existing bag.

    Raises
    ------
    RecordingError
        If ``path`` cannot be written (missing directory, not a regular file such as a
        directory or a FIFO, no permission).

    Examples
    --------
    >>> with McapRecorder('run.mcap', metadata={'version': '0.1.0'}) as rec:  # doctest: +SKIP
    ...     rec.add_topic('/pose', PoseStamped)
    ...     rec.write('/pose', msg, stamp_ns)
    """

    def __init__(self, path, *, metadata: Mapping[str, str] | None = None,
                 chunk_size: int = DEFAULT_CHUNK_SIZE, compression: str = 'zstd',
                 overwrite: bool = True):
        self._path = os.fspath(path)
        self._metadata = _check_metadata(metadata or {})
        if isinstance(chunk_size, bool) or operator.index(chunk_size) <= 0:
            raise ValueError(f'chunk_size must be a positive integer, got {chunk_size!r}')
        if compression not in _COMPRESSION:
            raise ValueError(f'compression must be one of {sorted(_COMPRESSION)}, '
                             f'got {compression!r}')
        self._overwrite = bool(overwrite)
        self._check_target()
        self._published = False
        self._target = os.path.realpath(self._path)   # through a symbolic link, as open()
        self._temporary = None
        try:
            handle, self._temporary = temporary_beside(self._target)
            self._raw = os.fdopen(handle, 'wb', buffering=0)
        except OSError as error:
            raise RecordingError(
                f'cannot write recording {self._path}: '
                f'{os_error_reason(self._path, error, writing=True)}') from None
        except BaseException:          # a signal's exception right after the file appeared
            self._remove_temporary()
            raise
        self._closed = False
        try:
            self._lock = threading.Lock()
            self._topics: dict[str, _TopicState] = {}
            self._schemas: dict[str, int] = {}
            self._message_count = 0
            self._first_ns = None
            self._last_ns = None
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
            self._remove_temporary()
            raise

    @property
    def path(self) -> str:
        """The file written (its final name)."""
        return self._path

    @property
    def published(self) -> bool:
        """Whether the recording has taken its final name (:attr:`path`) yet."""
        return self._published

    @property
    def message_count(self) -> int:
        """Number of messages written so far."""
        return self._message_count

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has been called."""
        return self._closed

    def add_topic(self, topic: str, msg_type: type, qos=None) -> int:
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
        type_name = msgdefs.ros_type_name(msg_type)
        if qos is None:
            from rclpy.qos import QoSProfile   # only here: reading needs no rclpy
            qos = QoSProfile(depth=10)
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
                        text = msgdefs.full_text(type_name)
                    except msgdefs.DefinitionNotFoundError as error:
                        raise RecordingError(one_line(error)) from None
                    schema_id = self._writer.register_schema(type_name, 'ros2msg', text)
                    self._schemas[type_name] = schema_id
                type_hash = msgdefs.type_hash(type_name)
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
        from rclpy.serialization import serialize_message
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
            self._publish_first()

    def channel_id(self, topic: str) -> int:
        """The MCAP channel id of a registered topic (for :meth:`write_interleaved`)."""
        return self._topic(topic).channel_id

    def write_interleaved(self, topics, messages, stamps_ns) -> None:
        """Add a block of samples, each a message on every topic, sample by sample.

        The fast path of a batch run: one lock and no per-message checks beyond the block's.

        Parameters
        ----------
        topics : sequence of str
            Registered topics, k of them.
        messages : sequence of sequences of bytes
            ``messages[j][i]``: CDR bytes of sample i on ``topics[j]``.
        stamps_ns : sequence of int
            Log and publish time of each sample (ns, in [0, 2**64)).
        """
        states = [self._topic(topic) for topic in topics]
        stamps = [operator.index(s) for s in stamps_ns]
        if stamps and not (0 <= min(stamps) and max(stamps) <= _UINT64_MAX):
            raise ValueError('stamps_ns must be in [0, 2**64)')
        if any(len(column) != len(stamps) for column in messages):
            raise ValueError('every topic needs one message per stamp')
        if not stamps or not states:
            return
        channels = [state.channel_id for state in states]
        add = self._writer.add_message
        with self._lock:
            self._check_open()
            with self._io('write'):
                for stamp, row in zip(stamps, zip(*messages)):
                    for channel, data in zip(channels, row):
                        add(channel, stamp, data, stamp)
                    if not self._published:   # the first sample is on disk before the rest
                        self._publish_first()
            for state in states:
                state.message_count += len(stamps)
            self._message_count += len(stamps) * len(states)
            first, last = min(stamps), max(stamps)
            self._first_ns = first if self._first_ns is None else min(self._first_ns, first)
            self._last_ns = last if self._last_ns is None else max(self._last_ns, last)

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
            except BaseException:
                self._raw.close()
                self._remove_temporary()   # nothing readable of it took the final name
                raise
            self._raw.close()
            if not self._published:        # no message: an empty recording, as rosbag2's
                try:
                    self._publish()
                except BaseException:
                    self._remove_temporary()
                    raise

    def discard(self) -> bool:
        """Close without publishing if no message has been written: the path is untouched.

        The temporary file is removed and an existing file at :attr:`path` is left byte for
        byte as it was. A recording that already holds messages is closed as by
        :meth:`close`. Returns True if the recording was kept (it had messages).
        """
        with self._lock:
            if self._published or self._closed:
                kept = self._published
            else:
                self._closed = True
                self._raw.close()
                self._remove_temporary()
                return False
        self.close()
        return kept

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

    def _check_target(self):
        """Refuse a path that is not a regular file, or an existing one without overwrite."""
        try:
            info = os.stat(self._path)
        except FileNotFoundError:
            return
        except OSError as error:
            raise RecordingError(f'cannot write recording {self._path}: '
                                 f'{os_error_reason(self._path, error, writing=True)}') from None
        if not stat.S_ISREG(info.st_mode):
            kind = 'a directory' if stat.S_ISDIR(info.st_mode) else 'not a regular file'
            raise RecordingError(f'cannot write recording {self._path}: it is {kind} '
                                 '(a recording replaces regular files only)')
        if not self._overwrite:
            raise RecordingExistsError(f'cannot write recording {self._path}: the file exists '
                                       '(not replaced)')

    def _publish_first(self):
        """After the first message: end its chunk, give the file its name (lock held).

        From here on a killed process or a full disk leaves the recording readable under
        its name, the old file (if any) replaced by one that holds at least a message.
        """
        if not self._published:
            with self._io('write'):
                self._writer.flush()
            self._publish()

    def _publish(self):
        """Rename the temporary file to :attr:`path` (checked again: never over a non-file)."""
        with self._io('write'):
            self._check_target()
            os.replace(self._temporary, self._target)
        self._published = True

    def _remove_temporary(self):
        if not self._published and self._temporary is not None:
            with contextlib.suppress(OSError):
                os.remove(self._temporary)

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
        return io_errors(self._path, what)

    def _bag_metadata(self):
        """Return the ``rosbag2`` metadata record: ``{'serialized_metadata': yaml}``."""
        topics = [{'name': topic, 'type': state.type_name, 'qos': state.qos,
                   'type_hash': state.type_hash, 'message_count': state.message_count}
                  for topic, state in self._topics.items()]
        return bag_metadata(self._path, topics, self._message_count, self._first_ns,
                            self._last_ns)


def _check_metadata(metadata):
    """Return ``metadata`` as a ``dict[str, str]``, or raise ``TypeError``."""
    if not isinstance(metadata, Mapping):
        raise TypeError(f'metadata must be a mapping of str to str, got {type(metadata)}')
    checked = dict(metadata)
    for key, value in checked.items():
        if not isinstance(key, str) or not isinstance(value, str):
            raise TypeError(f'metadata must map str to str, got {key!r}: {value!r}')
    return checked
