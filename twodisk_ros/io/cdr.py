"""Vectorised CDR encoding of the node's fixed-layout ROS 2 messages, from numpy arrays.

Each function encodes a whole batch of messages at once and returns one ``bytes`` per
message, ready for ``publisher.publish(data)`` and ``mcap.Writer.add_message(data=...)``.
The bytes are what ``rclpy.serialization.serialize_message`` gives for the equivalent message
object (ROS 2 Jazzy, rmw_fastrtps_cpp, Fast-CDR), with two differences that strict readers such
as rosbags need: every alignment padding byte is zero (Fast-CDR leaves whatever the buffer held),
and the message ends after its last field (``serialize_message`` of a JointState with an empty
``effort`` appends 4 bytes of padding past it, which rosbags rejects as a size mismatch).

Encoding (XCDR1 / plain CDR, little endian): the encapsulation header ``00 01 00 00``, then the
payload, in which every primitive is aligned to its own size (``float64`` to 8, ``int32`` and
``uint32`` to 4) relative to the start of the payload.  A string is a ``uint32`` length counting
the terminating NUL, the UTF-8 bytes, and the NUL; a sequence is a ``uint32`` count then its
elements.  All messages of a batch share one frame id, hence one length and one layout: a
template row holds the constant bytes (header, string lengths, zero padding), and the numeric
columns of an ``(n, L)`` ``uint8`` array are filled through ``float64``/``int32`` views.

``serialize`` encodes any other rclpy message object (MarkerArray, DiagnosticArray, ...) one
field at a time, walking the generated class's introspection data, with the same guarantees.

Stamps are integer nanoseconds (``int64``), converted exactly as
``Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)``: floor division, so the
nanoseconds are always in ``[0, 1e9)``; ``sec`` must fit ``int32``.

Only numpy and the standard library are imported, so this module works without ROS (``serialize``
duck-types the message object and its ``rosidl_parser`` field types by class name).
"""

import struct

import numpy as np

__all__ = [
    'ENCAPSULATION',
    'encode_joint_state',
    'encode_path',
    'encode_point_stamped',
    'encode_pose_stamped',
    'encode_wrench_stamped',
    'serialize',
    'split_rows',
    'stamp_columns',
    'Layout',
]

#: CDR_LE encapsulation header (representation id 0x0001, options 0).
ENCAPSULATION = b'\x00\x01\x00\x00'

_NS = 1_000_000_000
_SEC_MIN, _SEC_MAX = -2**31, 2**31 - 1


class Layout:
    """Byte layout of one message (or a part of one) with fixed lengths.

    ``start`` is the payload offset (bytes after the encapsulation header) of the first byte;
    alignment is relative to the payload start, so only ``start % 8`` matters.
    """

    def __init__(self, start=0, prefix=b''):
        self.start = start
        self.raw = bytearray(prefix)
        self.fields = {}          # name -> (byte offset in raw, numpy dtype, element count)
        self.offset = start - len(prefix)

    def _align(self, size):
        self.raw += bytes(-(self.offset + len(self.raw)) % size)

    def u32(self, value):
        self._align(4)
        self.raw += struct.pack('<I', value)

    def string(self, text):
        data = text.encode('utf-8')
        if b'\x00' in data:
            raise ValueError(f'a CDR string cannot contain NUL: {text!r}')
        self.u32(len(data) + 1)
        self.raw += data + b'\x00'

    def field(self, name, dtype, count=1):
        dtype = np.dtype(dtype)
        if count:
            self._align(dtype.itemsize)
        self.fields[name] = (len(self.raw), dtype, count)
        self.raw += bytes(dtype.itemsize * count)

    def header(self, frame_id, name='stamp'):
        """std_msgs/Header: builtin_interfaces/Time (int32 sec, uint32 nanosec), frame_id."""
        self.field(name, '<i4', 2)
        self.string(frame_id)

    def float64_sequence(self, name, count):
        self.u32(count)
        self.field(name, '<f8', count)

    def pose(self, position='position', orientation='orientation'):
        """geometry_msgs/Pose: Point (x, y, z), Quaternion (x, y, z, w), all float64."""
        self.field(position, '<f8', 3)
        self.field(orientation, '<f8', 4)

    def fill(self, n, **columns):
        """``(n, len(raw))`` uint8 array: the template in every row, the named columns set.

        Each column is broadcast to ``(n, count)`` of the field's dtype.
        """
        rows = np.empty((n, len(self.raw)), np.uint8)
        rows[...] = np.frombuffer(bytes(self.raw), np.uint8)
        for name, values in columns.items():
            offset, dtype, count = self.fields[name]
            if count:
                view = rows[:, offset:offset + dtype.itemsize * count].view(dtype)
                view[...] = values          # broadcast to (n, count) by the assignment
        return rows


def split_rows(rows):
    """One ``bytes`` per row of a 2-D ``uint8`` array (the messages of a batch)."""
    rows = np.ascontiguousarray(rows)
    size = rows.shape[1]
    data = rows.tobytes()
    return [data[i:i + size] for i in range(0, len(data), size)]


def stamp_columns(stamps_ns, n=None):
    """``(n, 2)`` int64 columns (sec, nanosec) from integer nanoseconds, range-checked."""
    ns = np.asarray(stamps_ns)
    if ns.dtype.kind not in 'iu' and ns.size:
        raise TypeError(f'stamps must be integer nanoseconds, got dtype {ns.dtype}')
    ns = ns.astype(np.int64).reshape(-1)
    if n is not None and ns.size != n:
        if ns.size != 1:
            raise ValueError(f'{ns.size} stamps for {n} messages')
        ns = np.repeat(ns, n)
    sec, nanosec = np.divmod(ns, _NS)
    if sec.size and (sec.min() < _SEC_MIN or sec.max() > _SEC_MAX):
        raise ValueError('stamp out of the int32 seconds range of builtin_interfaces/Time')
    return np.stack([sec, nanosec], axis=1)


def _float_array(values, width, name):
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != width:
        raise ValueError(f'{name} must have shape (n, {width}), got {array.shape}')
    return array


def _header_only(frame_id):
    layout = Layout(prefix=ENCAPSULATION)
    layout.header(frame_id)
    return layout


def encode_pose_stamped(stamps_ns, frame_id, positions, quaternions):
    """Encode a batch of ``geometry_msgs/msg/PoseStamped``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds (since the epoch or simulation start).
    frame_id : str
        Header frame id, the same for the whole batch.
    positions : array_like of float, shape (n, 3)
        Position x, y, z in metres, in ``frame_id``.
    quaternions : array_like of float, shape (n, 4)
        Orientation as x, y, z, w (body → ``frame_id``, the world frame).

    Returns
    -------
    list of bytes
        One CDR message (with encapsulation header) per sample.
    """
    positions = _float_array(positions, 3, 'positions')
    quaternions = _float_array(quaternions, 4, 'quaternions')
    n = len(positions)
    layout = _header_only(frame_id)
    layout.pose()
    return split_rows(layout.fill(n, stamp=stamp_columns(stamps_ns, n), position=positions,
                                  orientation=quaternions))


def encode_point_stamped(stamps_ns, frame_id, points):
    """Encode a batch of ``geometry_msgs/msg/PointStamped``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    frame_id : str
        Header frame id, the same for the whole batch.
    points : array_like of float, shape (n, 3)
        Point x, y, z in metres, in ``frame_id``.

    Returns
    -------
    list of bytes
        One CDR message per sample.
    """
    points = _float_array(points, 3, 'points')
    layout = _header_only(frame_id)
    layout.field('point', '<f8', 3)
    return split_rows(layout.fill(len(points), stamp=stamp_columns(stamps_ns, len(points)),
                                  point=points))


def encode_wrench_stamped(stamps_ns, frame_id, forces, torques=None):
    """Encode a batch of ``geometry_msgs/msg/WrenchStamped``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    frame_id : str
        Header frame id (the axes of force and torque), the same for the whole batch.
    forces : array_like of float, shape (n, 3)
        Force (N).
    torques : array_like of float, shape (n, 3), optional
        Torque (N m); zero if omitted.

    Returns
    -------
    list of bytes
        One CDR message (with encapsulation header) per sample.
    """
    forces = _float_array(forces, 3, 'forces')
    n = len(forces)
    torques = np.zeros((n, 3)) if torques is None else _float_array(torques, 3, 'torques')
    layout = _header_only(frame_id)
    layout.field('force', '<f8', 3)
    layout.field('torque', '<f8', 3)
    return split_rows(layout.fill(n, stamp=stamp_columns(stamps_ns, n), force=forces,
                                  torque=torques))


def encode_joint_state(stamps_ns, names, positions, velocities=None, frame_id=''):
    """Encode a batch of ``sensor_msgs/msg/JointState`` with fixed joint names, no effort.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    names : sequence of str, length k
        Joint names, the same for every message (the node uses ``['theta', 'psi', 'phase']``).
    positions : array_like of float, shape (n, k)
        Joint positions (rad for revolute joints, m for prismatic ones).
    velocities : array_like of float, shape (n, k), optional
        Joint velocities (rad/s or m/s); None gives an empty ``velocity``.
    frame_id : str, default ''
        Header frame id.

    Returns
    -------
    list of bytes
        One CDR message per sample, ending right after the (empty) ``effort`` count.
    """
    names = list(names)
    positions = _float_array(positions, len(names), 'positions')
    n = len(positions)
    columns = {'stamp': stamp_columns(stamps_ns, n), 'position': positions}
    layout = _header_only(frame_id)
    layout.u32(len(names))
    for name in names:
        layout.string(name)
    layout.float64_sequence('position', len(names))
    if velocities is None:
        layout.u32(0)
    else:
        columns['velocity'] = _float_array(velocities, len(names), 'velocities')
        if len(columns['velocity']) != n:
            raise ValueError('positions and velocities must have the same number of rows')
        layout.float64_sequence('velocity', len(names))
    layout.u32(0)   # effort: empty, and nothing after it (no alignment for an empty sequence)
    return split_rows(layout.fill(n, **columns))


def encode_path(stamp_ns, frame_id, positions, quaternions=None, stamps_ns=None):
    """Encode one ``nav_msgs/msg/Path`` whose poses all have the header frame id.

    Parameters
    ----------
    stamp_ns : int
        Stamp of the Path header, integer nanoseconds.
    frame_id : str
        Frame id of the Path header and of every pose's header.
    positions : array_like of float, shape (m, 3)
        Pose positions x, y, z in metres, in ``frame_id``; m may be 0.
    quaternions : array_like of float, shape (m, 4) or (4,), optional
        Pose orientations x, y, z, w (body → ``frame_id``); default identity (0, 0, 0, 1).
    stamps_ns : array_like of int, shape (m,), optional
        Per-pose stamps, integer nanoseconds; default ``stamp_ns`` for every pose.

    Returns
    -------
    bytes
        The CDR message.
    """
    positions = _float_array(np.reshape(positions, (-1, 3)), 3, 'positions')
    m = len(positions)
    if quaternions is None:
        quaternions = (0.0, 0.0, 0.0, 1.0)
    quaternions = np.asarray(quaternions, np.float64)
    if quaternions.shape != (4,):
        quaternions = _float_array(quaternions.reshape(-1, 4), 4, 'quaternions')
    quaternions = np.broadcast_to(quaternions, (m, 4))
    stamps = stamp_columns(stamp_ns if stamps_ns is None else stamps_ns, m)
    layout = _header_only(frame_id)
    layout.u32(m)
    parts = [layout.fill(1, stamp=stamp_columns(stamp_ns, 1))]
    # Alignment is relative to the payload start: the first pose starts at a multiple of 4, and
    # every pose ends with a float64, so all later poses start at a multiple of 8 and share one
    # layout; the first one may have 4 bytes more padding.
    start = len(layout.raw) - len(ENCAPSULATION)
    for rows in (slice(0, 1), slice(1, m)):
        if rows.start >= m:
            break
        pose = Layout(start)
        pose.header(frame_id)
        pose.pose()
        parts.append(pose.fill(len(positions[rows]), stamp=stamps[rows],
                               position=positions[rows], orientation=quaternions[rows]))
        start += len(pose.raw)
    return b''.join(part.tobytes() for part in parts)


# -- any message, field by field ---------------------------------------------------------------
#: ``struct`` format of each rosidl ``BasicType``; its size is the CDR size and alignment.
#: ``octet`` values are ``bytes`` of length 1 in rclpy (a sequence may be one ``bytes``), an IDL
#: ``char`` is a ``str`` of length 1 (a ``.msg`` ``char`` is ``uint8``); see ``_byte``.
_BASIC_FORMATS = {
    'boolean': '?', 'octet': 'B', 'char': 'B', 'int8': 'b', 'uint8': 'B', 'int16': 'h',
    'uint16': 'H', 'int32': 'i', 'uint32': 'I', 'int64': 'q', 'uint64': 'Q', 'float': 'f',
    'double': 'd',
}


def serialize(msg):
    """CDR of any rclpy message object, with zero padding and no bytes after the last field.

    The bytes are those of ``rclpy.serialization.serialize_message`` (Jazzy, Fast-CDR, XCDR1
    little endian) at every data byte; where that leaves alignment padding uninitialised, these
    are zero, and where its buffer goes on past the last field (the size estimate counts
    alignment for empty primitive sequences, and a payload is at least 4 bytes), these stop.  The message is walked through its class's ``SLOT_TYPES`` (``rosidl_parser``
    definitions, matched by class name) and ``get_fields_and_field_types()``: primitives,
    strings, nested messages, and bounded/unbounded sequences and fixed arrays of those.

    Parameters
    ----------
    msg : rclpy message object
        An instance of a generated message class, e.g. ``visualization_msgs.msg.MarkerArray``.

    Returns
    -------
    bytes
        Encapsulation header ``00 01 00 00`` and the payload.

    Raises
    ------
    TypeError
        For a field type not supported (``wstring``, ``wchar``, ``long double``).
    ValueError
        For a string containing NUL, a fixed array of the wrong length, or a bound exceeded.
    """
    out = bytearray(ENCAPSULATION)
    _write_message(out, msg)
    return bytes(out)


def _align(out, size):
    out += bytes(-(len(out) - len(ENCAPSULATION)) % size)


def _write_message(out, msg):
    kinds = type(msg).SLOT_TYPES
    if not kinds:   # an empty message has rosidl's one uint8 `structure_needs_at_least_one_member`
        out += b'\x00'
    for name, kind in zip(msg.get_fields_and_field_types(), kinds):
        _write_value(out, kind, getattr(msg, name))


def _write_value(out, kind, value):
    kind_name = type(kind).__name__
    if kind_name == 'BasicType':
        fmt = _basic_format(kind)
        _align(out, struct.calcsize(fmt))
        out += struct.pack('<' + fmt, _byte(value))
    elif kind_name == 'NamespacedType':
        _write_message(out, value)
    elif kind_name in ('UnboundedString', 'BoundedString'):
        data = value.encode('utf-8')
        if b'\x00' in data:
            raise ValueError(f'a CDR string cannot contain NUL: {value!r}')
        _check_bound(kind, value)
        _write_uint32(out, len(data) + 1)
        out += data + b'\x00'
    elif kind_name in ('Array', 'UnboundedSequence', 'BoundedSequence'):
        if kind_name == 'Array':
            if len(value) != kind.size:
                raise ValueError(f'fixed array of {kind.size} elements given {len(value)}')
        else:
            _check_bound(kind, value)
            _write_uint32(out, len(value))
        item = kind.value_type
        if type(item).__name__ != 'BasicType':
            packed = _pack_uniform(value) if type(item).__name__ == 'NamespacedType' else None
            if packed is not None:      # e.g. geometry_msgs/Point: one block of float64
                _align(out, packed.dtype.itemsize)
                out += packed.tobytes()
                return
            for element in value:
                _write_value(out, item, element)
        elif len(value):     # Fast-CDR aligns an array of primitives only if it is not empty
            fmt = _basic_format(item)
            _align(out, struct.calcsize(fmt))
            if isinstance(value, (bytes, bytearray, memoryview)):
                out += bytes(value)
            else:
                if item.typename in ('octet', 'char'):
                    value = [_byte(v) for v in value]
                out += np.asarray(value, np.dtype('<' + fmt)).tobytes()
    else:
        raise TypeError(f'unsupported field type {kind_name}')


def _pack_uniform(elements):
    """Messages whose fields are all float64 (or all float32) as one array, else None.

    Such elements follow each other without padding (every field has the element's
    alignment), so the sequence is the array's bytes: one call instead of one per field.
    """
    if not len(elements):
        return None
    kinds = type(elements[0]).SLOT_TYPES
    names = {getattr(k, 'typename', None) for k in kinds}
    if not kinds or len(names) != 1 or not {'double', 'float'} >= names \
            or any(type(k).__name__ != 'BasicType' for k in kinds):
        return None
    fields = list(elements[0].get_fields_and_field_types())
    dtype = '<f8' if names == {'double'} else '<f4'
    return np.array([[getattr(e, f) for f in fields] for e in elements], dtype=dtype)


def _write_uint32(out, count):
    """A string length or sequence count."""
    _align(out, 4)
    out += struct.pack('<I', count)


def _byte(value):
    """An octet (``bytes`` of length 1) or char (``str``) as an int; any other value as is."""
    if isinstance(value, (bytes, bytearray)):
        (value,) = value
    return ord(value) if isinstance(value, str) else value


def _basic_format(kind):
    fmt = _BASIC_FORMATS.get(kind.typename)
    if fmt is None:
        raise TypeError(f'unsupported primitive type {kind.typename!r}')
    return fmt


def _check_bound(kind, value):
    bound = getattr(kind, 'maximum_size', None)
    if bound is not None and len(value) > bound:
        raise ValueError(f'{len(value)} elements exceed the bound {bound}')
