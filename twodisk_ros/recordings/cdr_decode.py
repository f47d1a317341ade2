"""Fast decoding of CDR messages: one generated Python function per ``ros2msg`` schema.

``mcap_ros2`` decodes every message by walking the parsed definition field by field, with one
``struct`` call and two method calls per primitive; a 1 kHz recording spends most of its
reading time there.  Here the same definitions (parsed by ``mcap_ros2`` itself:
``_for_each_msgdef`` and its vendored ``rosidl_adapter`` parser, the ``builtin_interfaces``
overrides of ``generate_dynamic``) are compiled once per schema into the source of a decoding
function, with

- one precomputed ``struct.Struct`` per run of consecutive fixed-size primitives, nested
  messages flattened into it, the alignment padding written into the format as ``x`` bytes
  wherever the position is known modulo the alignment (CDR aligns a primitive of size ``s``
  to ``s`` relative to the payload, which starts at byte 4), and a string or sequence length
  prefix read as the run's last field;
- alignment computed at run time only after a string or a sequence, whose length is known at
  run time only (the known alignment of the position is tracked through the code);
- primitive sequences and fixed arrays read by one ``struct`` call, sequences and arrays of
  messages by a generated function per element type called in a loop.

**Equivalence guarantee.** The decoder returned by :meth:`DecoderFactory.decoder_for` returns
what ``mcap_ros2.decoder.DecoderFactory().decoder_for(...)`` returns for the same bytes, or
raises what it raises:

- the objects are instances of the classes ``mcap_ros2`` creates (``_message_class``, one
  class cache shared with the fallback below), with the same attributes, value types and
  values: ``int``, ``float`` (``float32`` widened as ``struct`` does), ``bool``, ``str``;
  ``bytes`` for ``uint8``/``byte`` arrays and sequences (sliced as ``mcap_ros2`` slices, so a
  cut one comes back short there as well), lists for every other array or sequence;
  ``char`` is a signed ``int8``; ``builtin_interfaces`` time types as ``mcap_ros2`` reads them;
- the generated function never succeeds where ``mcap_ros2`` raises: it reads every byte that
  ``mcap_ros2`` reads (a run's ``struct`` needs the same bytes as its last field), decodes
  strings as strict UTF-8, requires the 4-byte encapsulation header, and takes only
  little-endian ``bytes``;
- whenever it raises (damaged data, a big-endian payload, anything unexpected), the message is
  decoded again by ``mcap_ros2``'s own decoding function (``_read_message`` on the same
  definitions), whose value or exception stands, so error texts are ``mcap_ros2``'s;
- a schema using what is not compiled here (``wstring``, a field type with no definition, a
  field name that is a Python keyword, nesting deeper than 64, two definitions of one type
  name in use) is decoded by ``mcap_ros2`` only.  Schema errors raise exactly what ``mcap_ros2``'s factory raises.

``tests/test_cdr_decode.py`` checks the guarantee field by field (floats bit for bit) on
recordings of the node, on random definitions and bytes, and on damaged payloads.  Only the
standard library and ``mcap``/``mcap_ros2`` are imported.
"""

import functools
import keyword
import struct

from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap_ros2.decoder import DecoderFactory as McapDecoderFactory
from mcap_ros2.decoder import McapROS2DecodeError

try:   # the definitions and classes of mcap-ros2-support 0.6 (requirements.txt pins it)
    from mcap_ros2._dynamic import TimeDefinition, _for_each_msgdef, _message_class, \
        _read_message
except ImportError:   # pragma: no cover - another version: plain mcap_ros2 decoding
    TimeDefinition = None

__all__ = ['DecoderFactory', 'compile_decoder', 'parse_schema']

#: ``struct`` code and size of each primitive (``char`` is read as ``int8`` by mcap_ros2).
_PRIMITIVES = {
    'bool': ('?', 1), 'byte': ('B', 1), 'char': ('b', 1), 'int8': ('b', 1), 'uint8': ('B', 1),
    'int16': ('h', 2), 'uint16': ('H', 2), 'int32': ('i', 4), 'uint32': ('I', 4),
    'int64': ('q', 8), 'uint64': ('Q', 8), 'float32': ('f', 4), 'float64': ('d', 8),
}
_MAX_INLINE_DEPTH = 64
_CACHED_COUNTS = 256       # sequence lengths up to this get a cached Struct


class _Unsupported(Exception):
    """The schema uses something not compiled here; mcap_ros2 decodes it."""


@functools.lru_cache(maxsize=1024)
def _small_sequence(code, count):
    return struct.Struct(f'<{count}{code}').unpack_from


def _sequence(code, count):
    """``unpack_from`` of ``count`` little-endian primitives ``code`` (cached when small)."""
    if count <= _CACHED_COUNTS:
        return _small_sequence(code, count)
    return struct.Struct(f'<{count}{code}').unpack_from


class _Function:
    """The source of one generated function, with the read position tracked statically.

    The position is ``o + delta``: ``o`` is a local variable of the generated code, ``delta``
    a number known here.  ``known`` is an alignment that ``o`` is known to have relative to
    the payload start (``(o - 4) % known == 0``; 1, 2, 4 or 8).  Fixed-size primitives are
    collected into a pending run (``fmt`` from ``start`` to ``end``, into ``targets``), read
    by one ``struct`` call when :meth:`flush` is called; the run never ends with padding.
    """

    def __init__(self, compiler, known):
        self.compiler = compiler
        self.lines = []
        self.indent = 1
        self.delta = 0
        self.known = known
        self.fmt, self.targets, self.start, self.end = '', [], 0, 0
        self.names = 0

    def emit(self, line):
        self.lines.append('    ' * self.indent + line)

    def local(self, prefix):
        self.names += 1
        return f'{prefix}{self.names}'

    def at(self, extra=0):
        """The source expression of the position ``o + delta + extra``."""
        offset = self.delta + extra
        return f'o + {offset}' if offset else 'o'

    def flush(self):
        """Read the pending run."""
        if self.fmt:
            reader = self.compiler.reader(self.fmt)
            call = f'{reader}(d, {self.at(self.start - self.delta)})'
            if self.targets:
                self.emit(f'{", ".join(self.targets)}, = {call}')
            else:
                self.emit(call)
            self.fmt, self.targets = '', []

    def sync(self):
        """Flush and move ``o`` to the position (``delta`` becomes 0)."""
        self.flush()
        if self.delta:
            self.emit(f'o += {self.delta}')
            self.known = min(self.known, self.delta & -self.delta)
            self.delta = 0

    def align(self, size):
        """Align the position to ``size`` (statically if the known alignment allows)."""
        if size <= 1:
            return
        if size <= self.known:
            self.delta += -self.delta % size
            return
        self.sync()
        self.emit(f'o += (4 - o) & {size - 1}')
        self.known = size

    def primitive(self, code, size, target):
        """A fixed-size primitive into ``target`` (None: read and dropped), in the run."""
        self.align(size)
        if not self.fmt:
            self.start = self.end = self.delta
        self.fmt += 'x' * (self.delta - self.end) + (code if target is not None else 'x')
        if target is not None:
            self.targets.append(target)
        self.delta += size
        self.end = self.delta

    def count(self):
        """A ``uint32`` length prefix; returns the local it is in, with ``o`` at its end."""
        name = self.local('n')
        self.primitive('I', 4, name)
        self.sync()
        return name


class _Compiler:
    """Generates the functions of one schema into one namespace."""

    def __init__(self, msgdefs, class_cache):
        self.msgdefs = msgdefs
        self.class_cache = class_cache
        self.namespace = {'_sequence': _sequence}
        self.values = {}
        self.readers = {}
        self.class_defs = {}
        self.elements = {}
        self.sources = []

    def reader(self, fmt):
        """Name of the ``unpack_from`` of the little-endian struct format ``fmt``."""
        if fmt not in self.readers:
            self.readers[fmt] = self.constant('S', struct.Struct('<' + fmt).unpack_from)
        return self.readers[fmt]

    def constant(self, prefix, value):
        """A name in the generated namespace bound to ``value``."""
        key = (prefix, id(value))
        if key not in self.values:
            name = f'{prefix}{len(self.values)}'
            self.namespace[name] = value
            self.values[key] = (name, value)
        return self.values[key][0]

    def definition(self, ftype):
        msgdef = self.msgdefs.get(f'{ftype.pkg_name}/{ftype.type}')
        if msgdef is None:
            raise _Unsupported(f'no definition of {ftype.pkg_name}/{ftype.type}')
        return msgdef

    def top(self, msgdef):
        """Source of ``decode(d)`` for the top-level message."""
        fn = _Function(self, known=8)
        fn.emit("if d.__class__ is not bytes or len(d) < 4 or not d[1] & 1:")
        fn.emit("    raise ValueError('not a little-endian CDR payload')")
        fn.emit('o = 4')
        result = self.message(fn, msgdef, None, 0)
        fn.flush()
        fn.emit(f'return {result}')
        self.sources.append('def decode(d):\n' + '\n'.join(fn.lines))

    def element(self, msgdef):
        """Name of the generated ``(d, o) -> (message, o)`` of a message type."""
        key = str(msgdef.base_type)
        if key not in self.elements:
            name = self.elements[key] = f'element{len(self.elements)}'
            fn = _Function(self, known=1)
            result = self.message(fn, msgdef, None, 0)
            fn.flush()
            fn.emit(f'return {result}, {fn.at()}')
            self.sources.append(f'def {name}(d, o):\n' + '\n'.join(fn.lines))
        return self.elements[key]

    def message(self, fn, msgdef, target, depth):
        """Code reading a message inline; returns the local holding it."""
        if depth > _MAX_INLINE_DEPTH:
            raise _Unsupported('nesting too deep')
        key = str(msgdef.base_type)
        if self.class_defs.setdefault(key, msgdef) is not msgdef:
            # two definitions share a class (builtin_interfaces Time and Duration, one from
            # the schema, one mcap_ros2's): which one makes it depends on the messages
            raise _Unsupported(f'two definitions of {key}')
        cls = self.constant('C', _message_class(msgdef, self.class_cache))
        var = fn.local('m')
        fn.emit(f'{var} = {cls}()' if target is None else f'{target} = {var} = {cls}()')
        if not msgdef.fields:
            fn.primitive('B', 1, None)    # the uint8 ROS 2 adds to an empty structure
        for field in msgdef.fields:
            if not field.name.isidentifier() or keyword.iskeyword(field.name):
                raise _Unsupported(f'field name {field.name!r}')
            self.field(fn, field.type, f'{var}.{field.name}', depth)
        return var

    def field(self, fn, ftype, target, depth):
        fixed = ftype.array_size if ftype.is_fixed_size_array() and \
            ftype.array_size is not None else None
        if not ftype.is_primitive_type():
            msgdef = self.definition(ftype)
            if not ftype.is_array:
                self.message(fn, msgdef, target, depth + 1)
                return
            element = self.element(msgdef)
            count = fn.count() if fixed is None else fixed
            if fixed is not None:
                fn.sync()
            else:   # each element reads at least one byte: a larger count cannot be whole
                fn.emit(f'if {count} > len(d): raise ValueError("sequence too long")')
            items = fn.local('q')
            fn.emit(f'{target} = {items} = []')
            fn.emit(f'for _ in range({count}):')
            fn.emit(f'    x, o = {element}(d, o)')
            fn.emit(f'    {items}.append(x)')
            fn.known = 1
            return
        if ftype.type == 'string':
            if not ftype.is_array:
                self.string(fn, target)
                return
            count = fn.count() if fixed is None else fixed
            fn.sync()
            items = fn.local('q')
            fn.emit(f'{target} = {items} = []')
            fn.emit(f'for _ in range({count}):')
            fn.indent += 1
            fn.known = 1
            self.string(fn, items, into_list=True)
            fn.indent -= 1
            return
        if ftype.type not in _PRIMITIVES:
            raise _Unsupported(f'type {ftype.type}')
        code, size = _PRIMITIVES[ftype.type]
        if not ftype.is_array:
            fn.primitive(code, size, target)
        elif fixed is not None:
            self.fixed_array(fn, code, size, fixed, target)
        else:
            self.sequence(fn, code, size, target)

    @staticmethod
    def string(fn, target, into_list=False):
        """A string into ``target`` (appended to it if ``into_list``)."""
        length = fn.count()
        text = f'd[o:o + {length} - 1].decode() if {length} > 1 else ""'
        fn.emit(f'{target}.append({text})' if into_list else f'{target} = {text}')
        fn.emit(f'o += {length}')
        fn.known = 1

    @staticmethod
    def fixed_array(fn, code, size, count, target):
        if code == 'B':     # mcap_ros2 slices uint8 arrays (a cut one comes back short)
            fn.emit(f'{target} = d[{fn.at()}:{fn.at(count)}]')
            fn.delta += count
            return
        fn.align(size)
        reader = fn.compiler.reader(f'{count}{code}')
        fn.emit(f'{target} = list({reader}(d, {fn.at()}))')
        fn.delta += count * size

    @staticmethod
    def sequence(fn, code, size, target):
        count = fn.count()
        known = fn.known
        if code == 'B':
            fn.emit(f'{target} = d[o:o + {count}]')
            fn.emit(f'o += {count}')
            fn.known = 1
            return
        fn.emit(f'if {count}:')
        if size > known:
            fn.emit(f'    o += (4 - o) & {size - 1}')
        fn.emit(f"    {target} = list(_sequence('{code}', {count})(d, o))")
        fn.emit(f'    o += {size} * {count}' if size > 1 else f'    o += {count}')
        fn.emit('else:')
        fn.emit(f'    {target} = []')
        fn.known = min(known, size)


def parse_schema(schema_name, schema_text):
    """The definitions ``mcap_ros2.generate_dynamic`` builds: ``{name: MessageSpecification}``.

    Raises what ``mcap_ros2``'s ``DecoderFactory.decoder_for`` raises for a bad schema.
    """
    msgdefs = {'builtin_interfaces/Time': TimeDefinition,
               'builtin_interfaces/Duration': TimeDefinition}
    names = set()

    def handle(name, short_name, msgdef):
        msgdefs[name] = msgdefs[short_name] = msgdef
        names.update((name, short_name))

    _for_each_msgdef(schema_name, schema_text, handle)
    if schema_name not in names:
        raise McapROS2DecodeError(f'schema parsing failed for "{schema_name}"')
    return msgdefs


def compile_decoder(schema_name, schema_text):
    """``(fast, reference)`` decoders of one schema, sharing their message classes.

    ``reference(data)`` is ``mcap_ros2``'s decoding; ``fast(data)`` the generated function
    (None if the schema is not supported), which returns the same value or raises (see the
    module docstring).  Schema errors raise as in ``mcap_ros2``.
    """
    msgdefs = parse_schema(schema_name, schema_text)
    class_cache = {}
    reference = functools.partial(_read_message, schema_name, msgdefs, class_cache=class_cache)
    compiler = _Compiler(msgdefs, class_cache)
    try:
        compiler.top(msgdefs[schema_name])
        source = '\n\n'.join(compiler.sources) + '\n'
        exec(compile(source, f'<cdr_decode {schema_name}>', 'exec'), compiler.namespace)
    except Exception:  # noqa: BLE001 - _Unsupported, or anything not foreseen here
        class_cache.clear()     # mcap_ros2 makes its classes as it meets them
        return None, reference
    fast = compiler.namespace['decode']
    fast.source = source
    return fast, reference


def _with_fallback(fast, reference):
    def decode(data):
        try:
            return fast(data)
        except Exception:  # noqa: BLE001 - mcap_ros2 decodes it again: its value or error
            return reference(data)
    return decode


class DecoderFactory(McapDecoderFactory):
    """``mcap_ros2.decoder.DecoderFactory`` with the generated decoders (same results)."""

    def __init__(self):
        super().__init__()
        self._fast = {}

    def decoder_for(self, message_encoding, schema):
        if TimeDefinition is None:   # pragma: no cover - not the pinned mcap-ros2-support
            return super().decoder_for(message_encoding, schema)
        if (message_encoding != MessageEncoding.CDR or schema is None
                or schema.encoding != SchemaEncoding.ROS2):
            return None
        decoder = self._fast.get(schema.id)
        if decoder is None:
            fast, reference = compile_decoder(schema.name, schema.data.decode())
            decoder = reference if fast is None else _with_fallback(fast, reference)
            self._fast[schema.id] = decoder
        return decoder
