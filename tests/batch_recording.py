"""A batch recording (``realtime:=false``) by the roller node, made in this process.

The same entry function, parameters and recorder as ``python -m twodisk_ros.roller --ros-args
[--params-file FILE] -p realtime:=false -p record:=PATH ...``, without a new interpreter
(each one pays ~1–2 s of imports): for tests whose claim is about the recording, not about the
process (the process is covered by test_roller, test_node_arguments, test_node_reliability).
It goes through :func:`roller_here.record_with_roller_main`, the one in-process path of the
suite, on ``domain`` with loopback discovery.
"""

import os

from roller_here import record_with_roller_main


def _value(value):
    """A ``-p name:=value`` text of a Python value, as the node's YAML parser reads it."""
    if isinstance(value, bool):
        return 'true' if value else 'false'
    return repr(value) if isinstance(value, float) else str(value)


def record(path, params_file=None, domain=None, **values):
    """Record the node's batch run with ``params_file`` then ``values`` (name -> value, the
    node's parameter types: float, int, str, bool) to ``path``; returns ``path``."""
    args = ['--params-file', str(params_file)] if params_file else []
    for name, value in {'realtime': False, 'record': str(path), **values}.items():
        args += ['-p', f'{name}:={_value(value)}']
    domain = int(domain if domain is not None else os.environ.get('ROS_DOMAIN_ID', '0'))
    code = record_with_roller_main(args, domain)
    assert code == 0, f'the roller refused {args} (exit {code})'
    return path
