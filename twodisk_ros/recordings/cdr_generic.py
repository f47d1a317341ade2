"""CDR of any rclpy message object, field by field (the messages without a fast path).

Walks the generated class's introspection data (``SLOT_TYPES``, ``rosidl_parser`` definitions
matched by class name, so rclpy itself is not imported) with the guarantees of
:mod:`twodisk_ros.recordings.cdr`: zero padding, nothing after the last field.
"""

import struct

import numpy as np

from .cdr_layout import ENCAPSULATION

__all__ = ['serialize']

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
