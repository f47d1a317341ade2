"""Fixed CDR layouts derived from the message definitions, as rosbags' type store derives them.

:func:`message_layout` reads a type's ``.msg`` file (and, recursively, those of its field
types) from the share directories of the installed ROS packages
(:func:`~twodisk_ros.recordings.msgdefs.definition_text`), and lays the message out in CDR (XCDR1,
little endian, the rules of :mod:`~twodisk_ros.recordings.cdr_layout`) with:

- ``constants``: fields whose value is the same for a whole batch, by dotted path
  (``'header.frame_id'``, ``'name'`` for JointState's joint names,
  ``'transforms[0].child_frame_id'``): every string, every sequence of strings, and any
  primitive or primitive array that is not a column;
- ``counts``: the length of each variable sequence by path (``'position': 3``,
  ``'transforms': 1``); a sequence not named has its constant's length, else 0;
- every other primitive field becomes a column, named by its path, zero (or its declared
  default) in the template.  :meth:`Layout.fill` writes a field or a contiguous group of
  fields as one column: ``'header.stamp'`` (sec, nanosec), ``'pose'`` (7 float64),
  ``'transforms[0].transform.translation'``.

Fields not given take the ROS defaults (0, ``''``, empty sequence) or the default the
definition declares.  Layouts are cached: a batch of one message costs a dictionary look-up,
not a walk of the definitions.  Only the standard library and numpy are imported.
"""

from collections import namedtuple
import functools
import re

import numpy as np

from . import msgdefs
from .cdr_layout import ENCAPSULATION, Layout

__all__ = ['Field', 'message_fields', 'message_layout']

#: numpy dtype of each ``.msg`` primitive (CDR size = alignment = itemsize).
PRIMITIVES = {
    'bool': '?', 'byte': 'u1', 'char': 'u1', 'int8': 'i1', 'uint8': 'u1', 'int16': '<i2',
    'uint16': '<u2', 'int32': '<i4', 'uint32': '<u4', 'int64': '<i8', 'uint64': '<u8',
    'float32': '<f4', 'float64': '<f8',
}
_STRINGS = ('string', 'wstring')

#: One field of a definition: ``type`` a primitive name, ``'string'`` or ``'pkg/msg/Type'``;
#: ``array`` None (a single value), N >= 0 (fixed array) or -1 (sequence, ``bound`` or None);
#: ``default`` the declared default text or None.
Field = namedtuple('Field', 'name type array bound default')

_TYPE = re.compile(r'^([A-Za-z][\w/]*)(?:<=(\d+))?(?:\[(<=)?(\d*)\])?$')
_CONSTANT = re.compile(r'^[A-Za-z]\w*\s*=')


def _qualified(base, package):
    if base in PRIMITIVES or base in _STRINGS:
        return base
    parts = base.split('/')
    if len(parts) == 1:
        return f'{package}/msg/{base}'
    if len(parts) == 2:
        return f'{parts[0]}/msg/{parts[1]}'
    return base


@functools.lru_cache(maxsize=None)
def message_fields(type_name):
    """The fields of a message type, in wire order, from its ``.msg`` file.

    Parameters
    ----------
    type_name : str
        ``pkg/msg/Type``.

    Returns
    -------
    tuple of Field
        Constants (``TYPE NAME=value``) and comments are left out: they are not on the wire.

    Raises
    ------
    DefinitionNotFoundError
        If the ``.msg`` file is not installed.
    """
    package = type_name.split('/')[0]
    fields = []
    for line in msgdefs.definition_text(type_name).decode('utf-8').splitlines():
        line = line.split('#', 1)[0].strip()
        if not line:
            continue
        kind, rest = (line.split(None, 1) + [''])[:2]
        if _CONSTANT.match(rest):
            continue
        name, _, default = rest.partition(' ')
        match = _TYPE.match(kind)
        if match is None or not name:
            raise ValueError(f'cannot parse the field {line!r} of {type_name}')
        base, _, bounded, size = match.groups()
        if match.group(0).endswith(']'):
            array = -1 if bounded or not size else int(size)
            bound = int(size) if bounded else None
        else:
            array, bound = None, None
        fields.append(Field(name, _qualified(base, package), array, bound,
                            default.strip() or None))
    if not fields:   # rosidl gives an empty message one uint8 member
        fields.append(Field('structure_needs_at_least_one_member', 'uint8', None, None, None))
    return tuple(fields)


def _default(field):
    """The declared default of a primitive field as numbers (a list for an array), or None."""
    if field.default is None:
        return None
    text = field.default.strip('[]')
    values = [v.strip() for v in text.split(',') if v.strip()]
    if field.type == 'bool':
        return [v.lower() in ('true', '1') for v in values]
    return [float(v) if field.type.startswith('float') else int(v, 0) for v in values]


def _string_default(field):
    if field.default is None:
        return ''
    return field.default.strip().strip('\'"')


class _Walk:
    """Lays out one message, keeping track of which constants and counts were used."""

    def __init__(self, layout, constants, counts):
        self.layout = layout
        self.constants = constants
        self.counts = counts
        self.used = set()

    def _get(self, table, path, default):
        if path in table:
            self.used.add(path)
            return table[path]
        return default

    def message(self, type_name, prefix):
        for field in message_fields(type_name):
            path = prefix + field.name
            if field.array is None:
                self.single(field, path)
            else:
                self.array(field, path)

    def single(self, field, path):
        if field.type in PRIMITIVES:
            if path in self.constants:
                self.layout.constant(PRIMITIVES[field.type], self._get(self.constants, path, 0))
            else:
                self.layout.field(path, PRIMITIVES[field.type], 1, _default(field))
        elif field.type in _STRINGS:
            self.string(field, self._get(self.constants, path, _string_default(field)))
        else:
            self.message(field.type, path + '.')

    def string(self, field, text):
        if field.type == 'wstring':
            raise TypeError(f'wstring fields are not supported ({field.name})')
        self.layout.string(text)

    def array(self, field, path):
        constant = self._get(self.constants, path, None)
        default = _default(field) if field.type in PRIMITIVES else None
        if field.array >= 0:
            count = field.array
        else:
            known = constant if constant is not None else default
            count = self._get(self.counts, path, None if known is None else len(known))
            count = 0 if count is None else int(count)
            if default is not None and len(default) != count:
                default = None          # a count given for a sequence with a default: zeros
            if field.bound is not None and count > field.bound:
                raise ValueError(f'{path}: {count} elements exceed the bound {field.bound}')
            self.layout.u32(count)
        if constant is not None and len(constant) != count:
            raise ValueError(f'{path}: {len(constant)} values for {count} elements')
        if field.type in PRIMITIVES:
            if constant is not None:
                self.layout.constant(PRIMITIVES[field.type], constant)
            else:
                self.layout.field(path, PRIMITIVES[field.type], count, default)
        elif field.type in _STRINGS:
            for k in range(count):
                self.string(field, constant[k] if constant is not None else '')
        else:
            self.messages(field.type, path, count)

    def messages(self, type_name, path, count):
        """A sequence or array of messages. From the third element on, if the second one's
        size is a multiple of 8 (so every later element starts at the same offset modulo 8)
        and no constant or count names an element, the elements repeat the second one's
        bytes: a Marker's thousand points cost one walk of geometry_msgs/Point, not 1000."""
        specific = any(key.startswith(path + '[') for key in (*self.constants, *self.counts))
        layout = self.layout
        for k in range(min(count, 2)):
            begin = len(layout.raw)
            self.message(type_name, f'{path}[{k}].')
        if count <= 2:
            return
        if specific or (len(layout.raw) - begin) % 8:
            for k in range(2, count):
                self.message(type_name, f'{path}[{k}].')
        else:
            layout.repeat(begin, count - 2, path)


def _frozen(table):
    """A mapping as a hashable key (lists become tuples)."""
    return tuple(sorted(
        (key, tuple(value.tolist()) if isinstance(value, np.ndarray) else
         tuple(value) if isinstance(value, (list, tuple)) else value)
        for key, value in (table or {}).items()))


def message_layout(type_name, constants=None, counts=None, start=None):
    """The :class:`~twodisk_ros.recordings.cdr_layout.Layout` of a message type (cached).

    Parameters
    ----------
    type_name : str
        ``pkg/msg/Type``, e.g. ``'geometry_msgs/msg/PoseStamped'``.
    constants : dict, optional
        Path → value of the fields that are the same in the whole batch (see the module doc).
    counts : dict, optional
        Path → length of variable sequences that are columns or hold messages.
    start : int, optional
        Payload offset where the message starts, for a message inside another (only
        ``start % 8`` matters); default: a whole message, with its encapsulation header.

    Returns
    -------
    Layout
        Shared between callers: do not append to it.

    Raises
    ------
    KeyError
        For a constant or count whose path is not a field of the type.
    ValueError
        For a string containing NUL or a bound exceeded.
    """
    return _cached_layout(type_name, _frozen(constants), _frozen(counts),
                          None if start is None else start % 8)


@functools.lru_cache(maxsize=256)
def _cached_layout(type_name, constants, counts, start):
    layout = Layout(prefix=ENCAPSULATION) if start is None else Layout(start)
    walk = _Walk(layout, dict(constants), dict(counts))
    walk.message(type_name, '')
    unknown = (set(walk.constants) | set(walk.counts)) - walk.used
    if unknown:
        raise KeyError(f'not fields of {type_name} (or not constants/counts there): '
                       f'{sorted(unknown)}')
    return layout
