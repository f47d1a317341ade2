"""Parameter YAML as rcl reads it, read safely: the one loader of ``--params-file`` and ``-p``.

rcl (``rcl_yaml_param_parser``, C) types a scalar by its text alone, and :func:`typed` does
the same, so the node's type checks agree with what rclpy hands the node (checked against
rclpy in ``tests/test_node_arguments.py``): unquoted ``true/yes/on/y`` and ``false/no/off/n``
(three spellings each) are bools; what C ``strtol(text, 0)`` reads whole is an integer
(``0x10`` is 16, ``010`` is 8); what ``strtod`` reads whole without a range error is a double
(``1e5``, ``.5``, ``inf``, ``.inf``; ``1e400`` and subnormals like ``5e-324`` are strings); quoted
scalars, ``!!str`` and everything else are strings. Lists hold one type.

Limits; a file beyond them is refused in one line before rclpy (or rcl) reads it:

- a regular file of at most :data:`MAX_BYTES` (1 MiB), UTF-8 text;
- no aliases (``*name``): rcl refuses them too ("Will not support aliasing"), so an alias
  bomb never expands (an anchor alone is harmless and allowed);
- mappings nested at most :data:`MAX_DEPTH` (32) deep; lists flat (rcl's arrays);
- at most :data:`MAX_ENTRIES` (10 000) entries: each key and each list element counts one.
  rcl looks every parameter name up linearly, so its own parse time grows with the square of
  the count: 10 000 parameters take it 0.1 s, 20 000 take 0.55 s (measured, rclpy Jazzy).

No rclpy and no numpy here.
"""

from dataclasses import dataclass
import math
import os
import re
import stat

import yaml

__all__ = ['ArgumentError', 'MAX_BYTES', 'MAX_DEPTH', 'MAX_ENTRIES', 'NODE_NAME', 'ParamsFile',
           'Value', 'at', 'flat', 'load_params_file', 'node_matches', 'params_file_values',
           'parse_value', 'typed']

#: The node's name: a parameter file's entries for ``/roller`` (or ``/**``) are the run's.
NODE_NAME = 'roller'

MAX_BYTES = 1 << 20          #: largest params file read (bytes)
MAX_DEPTH = 32               #: deepest nesting of mappings and lists
MAX_ENTRIES = 10_000         #: most keys plus list elements in a file (and on a command line)
PARAMS_KEY = 'ros__parameters'

_LOADER = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)   # only its event parser is used
_STR_TAG = 'tag:yaml.org,2002:str'
_TRUE = frozenset('Y y yes Yes YES true True TRUE on On ON'.split())
_FALSE = frozenset('N n no No NO false False FALSE off Off OFF'.split())
_SPECIAL = {s: float(s.replace('.', '')) for s in (
    '.nan .NaN .NAN .inf .Inf .INF +.inf +.Inf +.INF -.inf -.Inf -.INF'.split())}
_WS = r'[ \t\n\v\f\r]*'      # C isspace, skipped by strtol and strtod
_INT = re.compile(_WS + r'([+-]?)(?:0[xX]([0-9a-fA-F]+)|(0[0-7]*)|([1-9][0-9]*))')
_HEX_FLOAT = re.compile(_WS + r'([+-]?0[xX]([0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)'
                        r'(?:[pP][+-]?[0-9]+)?)')
_DEC_FLOAT = re.compile(_WS + r'([+-]?([0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)')
_SMALLEST_NORMAL = 2.2250738585072014e-308
_INF_NAN = re.compile(_WS + r'([+-]?)(inf|infinity|nan(?:\([0-9A-Za-z_]*\))?)', re.I)
_INT64 = (-(1 << 63), (1 << 63) - 1)
_NODE_PART = re.compile(r'[A-Za-z_][A-Za-z0-9_]*|\*\*?')
_TYPE_NAMES = {bool: 'bool', int: 'integer', float: 'double', str: 'string'}


class ArgumentError(ValueError):
    """A command-line argument or parameter file that is refused; the message is one line."""


@dataclass(frozen=True)
class Value:
    """A parameter value as rcl types it: bool, int, float, str or a list of one of them.

    ``text`` is what was written (a list: ``[a, b]`` of its elements' texts); ``line`` the
    1-based line in its file (0 on the command line).
    """

    value: object
    text: str
    line: int = 0

    @property
    def type_name(self):
        """'bool', 'integer', 'double', 'string', 'double array', ... or 'empty list'."""
        if isinstance(self.value, list):
            if not self.value:
                return 'empty list'
            return f'{_TYPE_NAMES[type(self.value[0])]} array'
        return _TYPE_NAMES[type(self.value)]


@dataclass(frozen=True)
class ParamsFile:
    """What a params file holds for one node: its sections and the values that apply.

    ``sections`` are the node keys with a ``ros__parameters`` mapping, in file order
    (``'/**'``, ``'roller'``, ``'ns/roller'``); ``applied`` those that select the node;
    ``values`` maps dotted parameter names to :class:`Value` (a later section wins);
    ``entries`` counts keys and list elements (the size rcl will parse).
    """

    path: str
    sections: tuple
    applied: tuple
    values: dict
    entries: int


def flat(text, limit=80):
    """Text for a one-line message: no line breaks, at most ``limit`` characters."""
    text = repr(str(text))[1:-1]
    return text if len(text) <= limit else text[:limit - 3] + '...'


def at(where, line):
    """``where`` and, for a file, the line: ``--params-file x.yaml, line 4``."""
    return f'{where}, line {line}' if line else where


def _int(text):
    match = _INT.fullmatch(text)
    if not match:
        return None
    sign, hexa, octal, decimal = match.groups()
    digits, base = (hexa, 16) if hexa else (octal, 8) if octal else (decimal, 10)
    if len(digits.lstrip('0')) > 22:     # beyond int64 in any base: strtol's ERANGE
        return None
    value = int(sign + digits, base)
    return value if _INT64[0] <= value <= _INT64[1] else None


def _double(text):
    if text in _SPECIAL:
        return _SPECIAL[text]
    match = _INF_NAN.fullmatch(text)
    if match:
        return float(match.group(1) + ('nan' if match.group(2)[:3].lower() == 'nan' else 'inf'))
    match = _HEX_FLOAT.fullmatch(text)
    if match:
        try:
            value = float.fromhex(match.group(1))
        except OverflowError:
            return None
        digits = match.group(2)
    else:
        match = _DEC_FLOAT.fullmatch(text)
        if not match:
            return None
        value = float(match.group(1))
        digits = match.group(2)
    # strtod's ERANGE (rcl then keeps the text as a string): overflow, or underflow to a
    # subnormal number or to zero from non-zero digits.
    if math.isinf(value) or (abs(value) < _SMALLEST_NORMAL
                             and (value != 0 or digits.strip('0.') != '')):
        return None
    return value


def typed(text, style=None, tag=None):
    """The value rcl gives a scalar: bool, int, float or str (see the module doc).

    ``style`` is the YAML scalar style (None or '' plain, ``'`` or ``"`` quoted, ``|``/``>``
    block); ``tag`` its explicit tag if any.
    """
    if style in ("'", '"') or tag == _STR_TAG:
        return text
    if text in _TRUE or text in _FALSE:
        return text in _TRUE
    for convert in (_int, _double):
        value = convert(text)
        if value is not None:
            return value
    return text


def _events(text, where):
    try:
        loader = _LOADER(text)
        try:
            while loader.check_event():
                yield loader.get_event()
        finally:
            loader.dispose()
    except yaml.YAMLError as error:
        raise ArgumentError(f'{where}: not valid YAML ({flat(" ".join(str(error).split()), 160)})'
                            ) from None
    except UnicodeError:     # an argument that is not valid text (undecodable bytes)
        raise ArgumentError(f'{where}: not valid UTF-8 text') from None


def _scalar(event, where):
    line = event.start_mark.line + 1
    if event.value == '' and event.style in (None, '') and event.tag != _STR_TAG:
        raise ArgumentError(f'{where}, line {line}: an empty value (write e.g. name: 1.0; an '
                            "empty string is name: '')")
    return Value(typed(event.value, event.style, event.tag), flat(event.value), line)


def _documents(text, where):
    """The YAML documents of ``text`` as dicts (str keys) and lists of :class:`Value`.

    Built from the parser's events, never composed: an alias is refused when it is met, the
    depth and the number of entries are counted as the events arrive.
    """
    documents, stack, entries = [], [], 0   # stack: [container, pending key] per open level
    for event in _events(text, where):
        kind = type(event)
        if kind is yaml.AliasEvent:
            raise ArgumentError(f'{where}, line {event.start_mark.line + 1}: YAML aliases '
                                f'(*{flat(event.anchor, 40)}) are not allowed (rcl refuses '
                                'them too): write the values out')
        if kind in (yaml.MappingEndEvent, yaml.SequenceEndEvent):
            stack.pop()
            continue
        if kind not in (yaml.ScalarEvent, yaml.MappingStartEvent, yaml.SequenceStartEvent):
            continue                    # stream and document boundaries
        line = event.start_mark.line + 1
        node = ({} if kind is yaml.MappingStartEvent else [] if kind is yaml.SequenceStartEvent
                else None)
        if not stack:
            entries += 1
            documents.append(node if node is not None else
                             Value(typed(event.value, event.style, event.tag), flat(event.value),
                                   line))
        else:
            top = stack[-1]
            container = top[0]
            if isinstance(container, list):
                if node is not None:
                    raise ArgumentError(f'{where}, line {line}: a list may hold only numbers, '
                                        'bools or strings (no nested lists or mappings)')
                entries += 1
                container.append(_scalar(event, where))
            elif top[1] is None:
                if node is not None:
                    raise ArgumentError(f'{where}, line {line}: a key must be a name, not a '
                                        f'{"list" if isinstance(node, list) else "mapping"}')
                if event.value == '':
                    raise ArgumentError(f'{where}, line {line}: an empty key')
                entries += 1
                top[1] = event.value
            else:
                container[top[1]] = node if node is not None else _scalar(event, where)
                top[1] = None
        if entries > MAX_ENTRIES:
            raise ArgumentError(f'{where}: more than {MAX_ENTRIES} entries (keys and list '
                                'elements); split the parameters or remove unused ones')
        if node is not None:
            stack.append([node, None])
            if len(stack) > MAX_DEPTH:
                raise ArgumentError(f'{where}, line {line}: nested more than {MAX_DEPTH} '
                                    'levels deep')
    return documents, entries


def _list_value(items, name, where):
    kinds = {type(item.value) for item in items}
    if len(kinds) > 1:
        found = ', '.join(sorted(_TYPE_NAMES[k] for k in kinds))
        raise ArgumentError(f'{at(where, items[0].line)}: {flat(name)} is a list that mixes '
                            f'{found} (rcl needs one type: e.g. [1.0, 2.0, 3.0])')
    text = flat('[' + ', '.join(item.text for item in items) + ']')
    return Value([item.value for item in items], text, items[0].line if items else 0)


def _parameters(mapping, where, prefix=''):
    """{dotted name: Value} of a ``ros__parameters`` mapping (nested mappings: dotted names)."""
    values = {}
    for key, value in mapping.items():
        name = prefix + key
        if isinstance(value, dict):
            if not value:
                raise ArgumentError(f'{where}: {flat(name)} is an empty mapping, not a '
                                    'value (rcl refuses it)')
            values.update(_parameters(value, where, name + '.'))
        elif isinstance(value, list):
            values[name] = _list_value(value, name, where)
        else:
            values[name] = value
    return values


def _sections(mapping, where, path=()):
    """(node key, {name: Value}) for each ``ros__parameters`` mapping, as rcl walks them."""
    for key, value in mapping.items():
        if key == PARAMS_KEY:
            if not path:
                raise ArgumentError(f'{where}: {PARAMS_KEY} must be under a node name (e.g. '
                                    f'/**: {{{PARAMS_KEY}: {{...}}}})')
            node = '/'.join(path)
            if not isinstance(value, dict):
                raise ArgumentError(f'{where}: node {flat(node)!r}: {PARAMS_KEY} must be a '
                                    'mapping of parameter names to values')
            _check_node_key(node, where)
            yield node, _parameters(value, where)
        elif isinstance(value, dict):
            yield from _sections(value, where, path + (key,))
        else:
            line = f', line {value.line}' if isinstance(value, Value) else ''
            raise ArgumentError(f'{where}{line}: {flat("/".join(path + (key,)))!r} has a value '
                                f'but no node name and {PARAMS_KEY} above it (expected NODE: '
                                f'{{{PARAMS_KEY}: {{name: value}}}})')


def _check_node_key(node, where):
    parts = node.lstrip('/').split('/') if node != '/**' else ['**']
    if not all(_NODE_PART.fullmatch(part) for part in parts):
        raise ArgumentError(f'{where}: {flat(node)!r} is not a node name (letters, digits and '
                            '_, not starting with a digit, separated by /; wildcards * and **)')


def node_matches(key, fqn):
    """True if the section key (``/**``, ``roller``, ``/ns/*``...) selects the node ``fqn``.

    rclcpp's rule, which rclpy follows: a relative key gets a leading ``/``; ``/**`` stands
    for any number of namespace levels and ``/*`` for exactly one; the whole name must match.
    """
    parts = key.lstrip('/').split('/')
    pattern = ''.join(r'(?:/\w+)*' if part == '**' else r'/\w+' if part == '*'
                      else '/' + re.escape(part) for part in parts)
    return re.fullmatch(pattern, fqn, re.ASCII) is not None


def _read_text(path, where):
    try:
        info = os.stat(path)
        if stat.S_ISDIR(info.st_mode):
            raise ArgumentError(f'{where}: is a directory, not a YAML file')
        if not stat.S_ISREG(info.st_mode):
            raise ArgumentError(f'{where}: not a regular file (a pipe or a device is not read)')
        if info.st_size > MAX_BYTES:
            raise ArgumentError(f'{where}: {info.st_size} bytes, more than the {MAX_BYTES} '
                                'bytes (1 MiB) a params file may have')
        with open(path, 'rb') as stream:
            data = stream.read(MAX_BYTES + 1)
    except OSError as error:
        raise ArgumentError(f'{where}: cannot read it: {error.strerror or error}') from None
    if len(data) > MAX_BYTES:
        raise ArgumentError(f'{where}: more than the {MAX_BYTES} bytes (1 MiB) a params file '
                            'may have')
    try:
        return data.decode('utf-8')
    except UnicodeDecodeError as error:
        raise ArgumentError(f'{where}: not UTF-8 text (byte {error.start} is '
                            f'0x{data[error.start]:02x}); a params file is YAML text') from None


def load_params_file(path, fqn='/' + NODE_NAME):
    """The :class:`ParamsFile` of ``path`` for the node named ``fqn``, or ArgumentError.

    Bounded: at most :data:`MAX_BYTES` read, :data:`MAX_ENTRIES` entries and :data:`MAX_DEPTH`
    levels, aliases refused before anything expands; time and memory linear in the file.
    """
    where = f'--params-file {flat(path, 400)}'
    documents, entries = _documents(_read_text(path, where), where)
    sections, applied, values = [], [], {}
    for document in documents:
        if isinstance(document, Value) and document.text == '':
            continue                    # an empty document
        if not isinstance(document, dict):
            found = ('a list' if isinstance(document, list)
                     else f'the {document.type_name} {flat(document.text, 40)!r}')
            raise ArgumentError(f'{where}: expected a mapping of node names to '
                                f'{{{PARAMS_KEY}: {{...}}}}, got {found}')
        for node, parameters in _sections(document, where):
            sections.append(node)
            if node_matches(node, fqn):
                applied.append(node)
                values.update(parameters)
    return ParamsFile(str(path), tuple(sections), tuple(applied), values, entries)


def parse_value(text, name, where):
    """The :class:`Value` of the VALUE of ``-p name:=VALUE`` (a scalar or a flat list), as rcl
    types it; ``where`` starts the message of an ArgumentError."""
    documents, _ = _documents(text, where)
    if len(documents) != 1 or isinstance(documents[0], dict):
        raise ArgumentError(f'{where}: a value must be a number, a bool, a string or a list of '
                            'one of them')
    value = documents[0]
    if isinstance(value, list):
        return _list_value(value, name, where)
    if value.value == '' and not any(isinstance(event, yaml.ScalarEvent) and event.style
                                     for event in _events(text, where)):
        # an empty plain scalar (``---``): rcl finds no value there; '' is the empty string
        raise ArgumentError(f"{where}: no value (write '' for an empty string)")
    return Value(value.value, flat(text.strip()), 0)


def params_file_values(path, fqn='/' + NODE_NAME):
    """{name: value} that a params file (rclpy's format) sets for this node, or ArgumentError.

    Nested mappings are flattened to dotted names, as rclpy does; values are typed as rcl
    types them (a list stays a list). The file is bounded (this module's limits).
    """
    loaded = load_params_file(path, fqn)
    return {name: value.value for name, value in loaded.values.items()}
