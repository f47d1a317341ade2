"""Checks of the node's ``--ros-args`` before rclpy parses them (no rclpy here).

rclpy answers a malformed ``--ros-args`` section (``-p a:=``, a missing or broken
``--params-file``) with a multi-line ``RCLError`` traceback, silently ignores a parameter name
the node does not declare, and refuses a value of the wrong type (``rate:=50``, an integer)
only after rcl has parsed everything. :func:`check_arguments` reads the same arguments first,
with the one loader of :mod:`~twodisk_ros.run.params_yaml` (rcl's typing, bounded), and
returns one-line errors and warnings instead.

Every value given for a declared parameter must have its declared type, wherever it appears
(each ``-p``, each section of each file that applies), not only the last one: when two values
of one name differ in type, rcl keeps neither the first nor the last but the first of bool,
integer, double, string (measured, rclpy Jazzy: ``-p duration:=0.05 -p duration:=abc`` runs
with 0.05). With the types checked, every value of a name has the same type and the last one
given counts, as in rcl.
"""

import difflib
import re

from ..run.parameters import BY_NAME, ROS_OWN, SHAPE_ONLY
from .usage import split_ros_args
from ..run.params_yaml import (ArgumentError, MAX_ENTRIES, NODE_NAME, at, flat, load_params_file,
                               parse_value)

__all__ = ['ArgumentError', 'check_arguments', 'node_fqn',
           'rclpy_type_hint', 'type_problem']

UNKNOWN_SHOWN = 5            #: unknown names warned about one by one; the rest are counted
_PARAM_FLAGS = ('-p', '--param')
_FILE_FLAGS = ('--params-file',)
_REMAP_FLAGS = ('-r', '--remap')
_VALUE_FLAGS = _REMAP_FLAGS + ('--log-level', '--log-config-file', '--log-file-name', '-e',
                               '--enclave')
_KIND_WORDS = {float: 'a double', int: 'an integer', bool: 'a bool (true or false)',
               str: 'a string', tuple: 'a list of doubles'}


def _ros_sections(argv):
    """The arguments inside every ``--ros-args ... [--]`` section."""
    return split_ros_args(argv)[0]


def node_fqn(section):
    """The node's fully qualified name after ``-r __node:=`` / ``-r __ns:=`` remaps."""
    name, namespace = NODE_NAME, '/'
    for flag, rule in zip(section, section[1:]):
        if flag not in _REMAP_FLAGS or ':=' not in rule:
            continue
        target, value = rule.split(':=', 1)
        node, _, target = target.rpartition(':')
        if node not in ('', NODE_NAME):
            continue
        if target in ('__node', '__name') and value:
            name = value
        elif target == '__ns' and value:
            namespace = '/' + value.strip('/')
    return (namespace.rstrip('/') or '') + '/' + name


def _parse_override(text):
    """(name or None if for another node, Value) of ``name:=value`` / ``node:name:=value``."""
    where = f'-p {flat(text, 200)}'
    if ':=' not in text:
        raise ArgumentError(f'{where}: expected NAME:=VALUE')
    name, value = text.split(':=', 1)
    node, _, name = name.rpartition(':')
    if not name:
        raise ArgumentError(f'{where}: the parameter name is empty')
    if value.strip() == '':
        raise ArgumentError(f'{where}: no value after ":=" (write e.g. {name}:=1.0; an '
                            f"empty string is {name}:='')")
    parsed = parse_value(value, name, where)
    return (name if node in ('', NODE_NAME) else None), parsed


def type_problem(parameter, value):
    """Why ``value`` (a :class:`~.params_yaml.Value`) does not have the parameter's declared
    type, in words quoting what was written; None if it does."""
    p, v, text = parameter, value.value, value.text
    kind = type(v)
    if kind is str:
        text = f"'{text}'"
    if p.kind is tuple:
        if isinstance(v, list) and v and all(type(x) is float for x in v):
            return None
        if isinstance(v, list) and v and all(type(x) is int for x in v):
            better = '[' + ', '.join(repr(float(x)) for x in v) + ']'
            return f'{p.name} is a list of doubles: write {better}, not {text}'
        return (f'{p.name} is a list of 3 doubles (e.g. [0.1, 0.2, 0.1]), got the '
                f'{value.type_name} {text}')
    if kind is p.kind:
        return None
    if p.kind is float and kind is int:
        return (f'{p.name} is a double: write {float(v)!r}, not {text} (a double needs a '
                'decimal point)')
    if p.kind is int and kind is float and v == v and abs(v) < 1e18 and v == int(v):
        return f'{p.name} is an integer: write {int(v)}, not {text}'
    if p.kind is str and kind is not list:
        return (f'{p.name} is a string, got the {value.type_name} {text}: quote it to make it '
                f"one: '{text}'")
    return f'{p.name} is {_KIND_WORDS[p.kind]}, got the {value.type_name} {text}'


def check_arguments(argv):
    """Check the ``--ros-args`` of ``argv``; return warnings (list of str, one line each).

    Raises
    ------
    ArgumentError
        One line naming the argument and what is allowed, for what rclpy would reject or
        silently replace (a value of the wrong type), and for a params file beyond the
        loader's limits.
    """
    section = _ros_sections(argv or [])
    fqn = node_fqn(section)
    given, warnings, entries = [], [], 0      # given: (where, name, Value) in argument order
    i = 0
    while i < len(section):
        flag = section[i]
        needs_value = flag in _PARAM_FLAGS + _FILE_FLAGS + _VALUE_FLAGS
        if needs_value and i + 1 >= len(section):
            raise ArgumentError(f'{flag} needs a value')
        if flag in _PARAM_FLAGS:
            name, value = _parse_override(section[i + 1])
            entries += 1
            if name is not None:
                given.append((f'-p {flat(section[i + 1], 200)}', name, value))
        elif flag in _FILE_FLAGS:
            loaded = load_params_file(section[i + 1], fqn)
            entries += loaded.entries
            if not loaded.applied:
                warnings.append(_nothing_applied(loaded, fqn))
            where = f'--params-file {flat(section[i + 1], 200)}'
            given.extend((at(where, value.line), name, value)
                         for name, value in loaded.values.items())
        if entries > MAX_ENTRIES:
            raise ArgumentError(f'more than {MAX_ENTRIES} parameter entries in all -p and '
                                '--params-file arguments together')
        i += 2 if needs_value else 1
    for where, name, value in given:
        parameter = BY_NAME.get(name)
        problem = parameter and type_problem(parameter, value)
        if problem:
            raise ArgumentError(f'{where}: {problem}')
    return (warnings + _unknown_warnings([name for _, name, _ in given])
            + _unused_warnings({name: value.value for _, name, value in given}))


def _unused_warnings(last):
    """Warnings for shape parameters given but not read by the shape the run will have.

    ``last``: the last value given of each name (the one rcl keeps, the types being checked).
    """
    shape = last.get('shape', BY_NAME['shape'].default)
    warnings = [f'{name} is set but not used: it is read only with shape {only} (shape is '
                f'{shape})' for name, only in SHAPE_ONLY.items()
                if name in last and shape != only and shape in BY_NAME['shape'].choices]
    given = [name for name in ('a', 'b') if name in last]
    if shape == 'points' and given:
        warnings.append(f'{" and ".join(given)} {"is" if len(given) == 1 else "are"} set but '
                        'not used with shape points: the outline in shape_file gives the '
                        "disk's size")
    return warnings


def _nothing_applied(loaded, fqn):
    found = ', '.join(repr(flat(s, 60)) for s in loaded.sections[:5])
    more = f' and {len(loaded.sections) - 5} more' if len(loaded.sections) > 5 else ''
    found = f'its sections are {found}{more}' if found else 'it has no ros__parameters section'
    name = fqn.rsplit('/', 1)[-1]
    return (f'nothing from --params-file {flat(loaded.path, 200)} was applied: {found}; node '
            f"{fqn} reads the sections '/**', '{fqn.lstrip('/')}' or '{fqn}' (or wildcards "
            f"such as '/**/{name}')")


def _unknown_warnings(names):
    unknown = [name for name in dict.fromkeys(names)
               if not (name in BY_NAME or name in ROS_OWN or name.startswith('qos_overrides.'))]
    warnings = []
    for name in unknown[:UNKNOWN_SHOWN]:   # close matches only for the names shown
        close = difflib.get_close_matches(name, list(BY_NAME), n=1)
        hint = f'; did you mean {close[0]!r}?' if close else ''
        shown = name if len(name) <= 60 else name[:57] + '...'
        warnings.append(f'unknown parameter {shown!r} is ignored{hint} '
                        f'(known: {", ".join(BY_NAME)})')
    if len(unknown) > UNKNOWN_SHOWN:
        warnings.append(f'and {len(unknown) - UNKNOWN_SHOWN} more unknown parameter names are '
                        'ignored')
    return warnings


_RCLPY_TYPE = re.compile(r"parameter '([^']*)' to '(.*)' of type '(\w+)', expecting type "
                         r"'(\w+)'")


def rclpy_type_hint(message):
    """A hint for rclpy's "Trying to set parameter 'rate' to '50' of type 'INTEGER', expecting
    type 'DOUBLE'" quoting the value: ' (rate is a double: write 50.0, not 50)'; or ''."""
    match = _RCLPY_TYPE.search(str(message))
    if not match:
        return ''
    name, text, given, expected = match.groups()
    if given == 'INTEGER' and expected == 'DOUBLE':
        return f' ({name} is a double: write {text}.0, not {text})'
    if given == 'DOUBLE' and expected == 'INTEGER':
        try:
            number = float(text)
        except ValueError:
            return ''
        if number.is_integer():
            return f' ({name} is an integer: write {int(number)}, not {text})'
    return ''
