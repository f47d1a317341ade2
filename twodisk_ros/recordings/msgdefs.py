"""Message definition texts as rosbag2 (Jazzy) stores them in MCAP schemas.

rosbag2 builds the ``ros2msg`` schema of a type in ``rosbag2_cpp``
(``message_definitions/local_message_definition_source.cpp``): the root ``.msg`` file as is
(comments included), then for every dependency, depth first, each once, a line ``\\n``, a line of
80 ``=``, a line ``MSG: pkg/Type`` and that type's own full text.  Dependencies of a file are the
non-primitive field types found by a regular expression, qualified with the file's package when
they have no ``/`` and visited in sorted order (they sit in a ``std::set``).  This module mirrors
that rule byte for byte; it works on ``bytes`` so that the text stays exactly the file content.
"""

import json
import os
import re
import sys
from pathlib import Path

__all__ = [
    'DefinitionNotFoundError',
    'definition_text',
    'find_share_file',
    'full_text',
    'ros_type_name',
    'type_hash',
]

# The regular expressions and the primitive set of local_message_definition_source.cpp.
_MSG_FIELD_TYPE = re.compile(rb'(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+')
_PRIMITIVES = frozenset(
    b'bool byte char float32 float64 int8 uint8 int16 uint16 int32 uint32 int64 uint64 '
    b'string'.split()
)
_NAME = '[a-zA-Z][a-zA-Z0-9_]*'
_TYPE_NAME = re.compile(rf'^({_NAME})/(?:({_NAME})/)?({_NAME})$')
_SEPARATOR = b'=' * 80 + b'\n'
# ROSBAG2_CPP_LOCAL_MESSAGE_DEFINITION_SOURCE_MAX_RECURSION_DEPTH
_MAX_DEPTH = 50


class DefinitionNotFoundError(LookupError):
    """A ``.msg`` file for a type name is in none of the share directories searched."""


def ros_type_name(msg_type):
    """Return the ROS name ``pkg/msg/Type`` of a generated Python message class.

    Parameters
    ----------
    msg_type : type
        A message class such as ``geometry_msgs.msg.PoseStamped``.

    Returns
    -------
    str
        ``'geometry_msgs/msg/PoseStamped'`` for that example.
    """
    parts = getattr(msg_type, '__module__', '').split('.')
    if len(parts) < 2 or not isinstance(msg_type, type) or not parts[0]:
        raise TypeError(f'not a ROS message class: {msg_type!r}')
    return f'{parts[0]}/{parts[1]}/{msg_type.__name__}'


def _prefixes():
    """Install prefixes searched for ``share/<pkg>``: AMENT_PREFIX_PATH, then ``sys.prefix``."""
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    prefixes.append(sys.prefix)
    return prefixes


def find_share_file(package, *parts):
    """Return the first existing ``<prefix>/share/<package>/<parts...>``, or ``None``.

    Parameters
    ----------
    package : str
        ROS package name.
    *parts : str
        Path components below the package's share directory.

    Returns
    -------
    pathlib.Path or None
        The file found, searching AMENT_PREFIX_PATH first (as ``ament_index`` does) and
        ``sys.prefix`` last (where the ROS 2 wheels of the venv put their share files).
    """
    for prefix in _prefixes():
        candidate = Path(prefix, 'share', package, *parts)
        if candidate.is_file():
            return candidate
    return None


def _split(type_name):
    """Split ``pkg/Type`` or ``pkg/ns/Type`` into ``(pkg, ns, Type)``, ``ns`` defaulting to msg."""
    match = _TYPE_NAME.match(type_name)
    if match is None:
        raise ValueError(f'invalid ROS type name: {type_name!r}')
    package, namespace, name = match.groups()
    return package, namespace or 'msg', name


def _dependencies(text, package):
    """Return the sorted dependency names of one ``.msg`` text, as rosbag2 parses them."""
    deps = set()
    for match in _MSG_FIELD_TYPE.finditer(text):
        name = match.group(1)
        if name in _PRIMITIVES:
            continue
        deps.add(name.decode() if b'/' in name else f'{package}/{name.decode()}')
    return sorted(deps)


def _load(type_name, cache):
    """Return ``(text, dependencies)`` of one type, reading its ``.msg`` file once."""
    if type_name not in cache:
        package, namespace, name = _split(type_name)
        path = find_share_file(package, namespace, f'{name}.msg')
        if path is None:
            raise DefinitionNotFoundError(
                f'no {namespace}/{name}.msg for {type_name} under share/{package} in '
                f'AMENT_PREFIX_PATH or {sys.prefix}')
        text = path.read_bytes()
        cache[type_name] = (text, _dependencies(text, package))
    return cache[type_name]


def definition_text(type_name):
    """Return the ``.msg`` file of one type as is (``bytes``), without its dependencies.

    Raises
    ------
    DefinitionNotFoundError
        If the file is in none of the share directories searched (:func:`find_share_file`).
    """
    return _load(type_name, {})[0]


def full_text(type_name):
    """Return the full ``ros2msg`` definition of a type as rosbag2 Jazzy writes it.

    Parameters
    ----------
    type_name : str
        ``pkg/msg/Type`` (or ``pkg/Type``).

    Returns
    -------
    bytes
        The schema data: root text, then each dependency once after its ``MSG:`` separator.

    Raises
    ------
    DefinitionNotFoundError
        If the ``.msg`` file of the type or of one of its dependencies cannot be found.
    """
    cache = {}
    seen = set()

    def append(name, depth):
        if depth <= 0:
            raise RecursionError(f'max recursion depth resolving definition of {type_name}')
        text, deps = _load(name, cache)
        parts = [text]
        for dep in deps:
            if dep not in seen:
                seen.add(dep)
                parts += [b'\n', _SEPARATOR, f'MSG: {dep}\n'.encode(), append(dep, depth - 1)]
        return b''.join(parts)

    return append(type_name, _MAX_DEPTH)


def type_hash(type_name):
    """Return the ``RIHS01_...`` type description hash of a type, or ``''`` if unknown.

    The hash is read from the ``<Type>.json`` type description that rosidl installs next to the
    ``.msg`` file; rosbag2 stores the same string as channel metadata ``topic_type_hash``.
    """
    package, namespace, name = _split(type_name)
    path = find_share_file(package, namespace, f'{name}.json')
    if path is None:
        return ''
    try:
        hashes = json.loads(path.read_text(encoding='utf-8'))['type_hashes']
    except (OSError, ValueError, KeyError):
        return ''
    wanted = f'{package}/{namespace}/{name}'
    return next((h['hash_string'] for h in hashes if h.get('type_name') == wanted), '')
