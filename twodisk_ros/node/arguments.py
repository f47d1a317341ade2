"""Checks of the node's command line before rclpy parses it (no rclpy here).

rclpy answers a malformed ``--ros-args`` section (``-p a:=``, a missing or broken
``--params-file``) with a multi-line ``RCLError`` traceback, and silently ignores a parameter
name the node does not declare. :func:`check_arguments` reads the same arguments first and
returns one-line errors and warnings instead.
"""

import difflib

import yaml

from .parameters import BY_NAME, ROS_OWN

__all__ = ['ArgumentError', 'check_arguments', 'params_file_values']

NODE_NAME = 'roller'
_PARAM_FLAGS = ('-p', '--param')
_FILE_FLAGS = ('--params-file',)
_VALUE_FLAGS = ('-r', '--remap', '--log-level', '--log-config-file', '-e', '--enclave')


class ArgumentError(ValueError):
    """A command-line argument that rclpy would reject; the message is one line."""


def _ros_sections(argv):
    """The arguments inside every ``--ros-args ... [--]`` section."""
    inside, section = False, []
    for arg in argv:
        if arg == '--ros-args':
            inside = True
        elif arg == '--' and inside:
            inside = False
        elif inside:
            section.append(arg)
    return section


def _parse_override(text):
    """(name, value) of ``name:=value`` (or ``node:name:=value``), or ArgumentError."""
    if ':=' not in text:
        raise ArgumentError(f'-p {text}: expected NAME:=VALUE')
    name, value = text.split(':=', 1)
    node, _, name = name.rpartition(':')
    if not name:
        raise ArgumentError(f'-p {text}: the parameter name is empty')
    if value.strip() == '':
        raise ArgumentError(f'-p {text}: no value after ":=" (write e.g. {name}:=1.0; an '
                            f"empty string is {name}:='')")
    try:
        parsed = yaml.safe_load(value)
    except yaml.YAMLError as error:
        raise ArgumentError(f'-p {text}: the value is not valid YAML '
                            f'({" ".join(str(error).split())[:120]})') from None
    return (name if node in ('', NODE_NAME) else None), parsed


def _node_key_matches(key):
    key = str(key).lstrip('/')
    last = key.rsplit('/', 1)[-1]
    return last in (NODE_NAME, '*', '**') or key in ('*', '**')


def params_file_values(path):
    """{name: value} that a params file (rclpy's format) sets for this node, or ArgumentError.

    Nested mappings are flattened to dotted names, as rclpy does.
    """
    try:
        with open(path, encoding='utf-8') as stream:
            tree = yaml.safe_load(stream)
    except OSError as error:
        raise ArgumentError(f'--params-file {path}: cannot read it: '
                            f'{error.strerror or error}') from None
    except yaml.YAMLError as error:
        raise ArgumentError(f'--params-file {path}: not valid YAML '
                            f'({" ".join(str(error).split())[:160]})') from None
    if not isinstance(tree, dict):
        raise ArgumentError(f'--params-file {path}: expected a mapping of node names to '
                            '{ros__parameters: {...}}')
    values = {}
    for key, entry in tree.items():
        if not isinstance(entry, dict) or not isinstance(entry.get('ros__parameters'), dict):
            raise ArgumentError(f'--params-file {path}: node {key!r} has no '
                                'ros__parameters mapping')
        if _node_key_matches(key):
            values.update(_flatten(entry['ros__parameters']))
    return values


def _flatten(mapping, prefix=''):
    for key, value in mapping.items():
        name = f'{prefix}{key}'
        if isinstance(value, dict):
            yield from _flatten(value, name + '.')
        else:
            yield name, value


def check_arguments(argv):
    """Check the ``--ros-args`` of ``argv``; return warnings (list of str).

    Raises
    ------
    ArgumentError
        One line naming the argument and what is allowed, for what rclpy would reject.
    """
    section = _ros_sections(argv or [])
    names = []
    i = 0
    while i < len(section):
        flag = section[i]
        needs_value = flag in _PARAM_FLAGS + _FILE_FLAGS + _VALUE_FLAGS
        if needs_value and i + 1 >= len(section):
            raise ArgumentError(f'{flag} needs a value')
        if flag in _PARAM_FLAGS:
            name, _ = _parse_override(section[i + 1])
            if name is not None:
                names.append(name)
        elif flag in _FILE_FLAGS:
            names.extend(params_file_values(section[i + 1]))
        i += 2 if needs_value else 1
    warnings = []
    for name in dict.fromkeys(names):
        if name in BY_NAME or name in ROS_OWN or name.startswith('qos_overrides.'):
            continue
        close = difflib.get_close_matches(name, list(BY_NAME), n=1)
        hint = f'; did you mean {close[0]!r}?' if close else ''
        warnings.append(f'unknown parameter {name!r} is ignored{hint} '
                        f'(known: {", ".join(BY_NAME)})')
    return warnings
