"""Fixed CDR layouts: a template row of constant bytes and numeric columns, filled from numpy.

Encoding (XCDR1 / plain CDR, little endian): the encapsulation header ``00 01 00 00``, then the
payload, in which every primitive is aligned to its own size (``float64`` to 8, ``int32`` and
``uint32`` to 4) relative to the start of the payload.  A string is a ``uint32`` length counting
the terminating NUL, the UTF-8 bytes, and the NUL; a sequence is a ``uint32`` count then its
elements.  A :class:`Layout` holds the constant bytes of a message whose strings and sequence
lengths are fixed (header, string lengths, zero padding) and where each numeric field sits;
:meth:`Layout.fill` writes a whole batch of messages as the rows of an ``(n, L)`` ``uint8``
array through ``float64``/``int32`` views.  Only numpy and the standard library are imported.
"""

import bisect
import struct

import numpy as np

__all__ = ['ENCAPSULATION', 'Layout', 'float_columns', 'split_rows', 'stamp_columns']

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
        self._blocks = {}         # name -> (offset, dtype, count) of a group of fields
        self._template = None
        self._names = None
        self._runs = {}           # path -> (element size, elements) of repeated elements

    def _align(self, size):
        self.raw += bytes(-(self.offset + len(self.raw)) % size)

    def constant(self, dtype, values):
        """Append constant primitive values (aligned to their size, as CDR aligns them)."""
        data = np.asarray(values, dtype=np.dtype(dtype)).reshape(-1)
        if data.size:
            self._align(data.itemsize)
        self.raw += data.tobytes()

    def u32(self, value):
        self._align(4)
        self.raw += struct.pack('<I', value)

    def string(self, text):
        data = text.encode('utf-8')
        if b'\x00' in data:
            raise ValueError(f'a CDR string cannot contain NUL: {text!r}')
        self.u32(len(data) + 1)
        self.raw += data + b'\x00'

    def field(self, name, dtype, count=1, initial=None):
        """A numeric column of ``count`` elements (aligned unless empty); zeros or ``initial``."""
        dtype = np.dtype(dtype)
        if count:
            self._align(dtype.itemsize)
        if name in self.fields:
            raise ValueError(f'field {name!r} defined twice')
        self.fields[name] = (len(self.raw), dtype, count)
        self.raw += (bytes(dtype.itemsize * count) if initial is None else
                     np.broadcast_to(np.asarray(initial, dtype), (count,)).tobytes())

    def repeat(self, begin, count, path):
        """Append ``count`` copies of the bytes from ``begin`` to the end.

        They are elements 2 … count + 1 of the sequence ``path``, whose element 1 starts at
        ``begin`` and ends at the end (the caller checks that all have one layout: the same
        start modulo 8, no element-specific constants).  Their fields get no names of their
        own: :meth:`block` finds ``path[k].…`` from element 1's, and ``path`` as a whole.
        """
        size = len(self.raw) - begin
        self._runs[path] = (size, count + 2)
        self.raw += bytes(self.raw[begin:]) * count

    def _element(self, name):
        """The block of a field of a repeated element (``path[k]…``, k ≥ 2), or None."""
        for path, (size, total) in self._runs.items():
            if not name.startswith(path + '['):
                continue
            close = name.index(']', len(path))
            k = int(name[len(path) + 1:close])
            if k < 2:
                return None
            if k >= total:
                raise KeyError(f'no field {name!r} in this layout ({total} elements)')
            offset, dtype, count = self.block(f'{path}[1]{name[close + 1:]}')
            return offset + (k - 1) * size, dtype, count
        return None

    def block(self, name):
        """``(offset, dtype, count)`` of a field, or of the fields named ``name.*``/``name[*``.

        A group (e.g. ``'pose'``: position x, y, z, orientation x, y, z, w) is one column if
        its fields follow each other without padding and have one size and kind (integers of
        one size count as one kind: a value written through the first field's dtype has the
        same bytes in the others, e.g. Time's int32 sec and uint32 nanosec < 2**31).
        """
        found = self.fields.get(name) or self._blocks.get(name) or self._element(name)
        if found is not None:
            return found
        if self._names is None or len(self._names) != len(self.fields):
            self._names = sorted(self.fields)      # the names under a prefix: one range
        members = []
        for prefix in (name + '.', name + '['):
            first = bisect.bisect_left(self._names, prefix)
            last = bisect.bisect_left(self._names, prefix[:-1] + chr(ord(prefix[-1]) + 1))
            members += [self.fields[key] for key in self._names[first:last]]
        members = sorted((spec for spec in members if spec[2]), key=lambda f: f[0])
        if not members:
            raise KeyError(f'no field {name!r} in this layout')
        offset, dtype, _ = members[0]
        kind = 'iu' if dtype.kind in 'iu' else dtype.kind
        end = offset
        for start, other, count in members:
            if start != end or other.itemsize != dtype.itemsize or other.kind not in kind:
                raise ValueError(f'the fields of {name!r} are not one contiguous column of '
                                 f'{dtype}')
            end = start + other.itemsize * count
        if name in self._runs:                    # the whole sequence: all elements packed?
            size, total = self._runs[name]
            if end - offset != 2 * size:
                raise ValueError(f'the elements of {name!r} are not one contiguous column')
            end += (total - 2) * size
        self._blocks[name] = (offset, dtype, (end - offset) // dtype.itemsize)
        return self._blocks[name]

    def fill(self, n, **columns):
        """``(n, len(raw))`` uint8 array: the template in every row, the named columns set.

        A column is a field or a group of fields (:meth:`block`), broadcast to
        ``(n, count)`` of its dtype.
        """
        if self._template is None or len(self._template) != len(self.raw):
            self._template = np.frombuffer(bytes(self.raw), np.uint8)
        rows = np.empty((n, len(self.raw)), np.uint8)
        rows[...] = self._template
        for name, values in columns.items():
            offset, dtype, count = self.block(name)
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


def float_columns(values, width, name):
    """``values`` as a float64 ``(n, width)`` array, or ValueError naming ``name``."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != width:
        raise ValueError(f'{name} must have shape (n, {width}), got {array.shape}')
    return array
