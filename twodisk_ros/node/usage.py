"""``roller``'s own command line: ``--help``, ``--version``; nothing else outside ``--ros-args``.

No rclpy, no numpy, so that the help is instant and writes nothing, and a refusal comes
before any heavy import. rcl ignores every argument outside a ``--ros-args ... [--]``
section; a node that took ``roller -p duration:=1.0`` would run the defaults for ever, so
such an argument is refused. Each ``--params-file`` is read once here, within the limits of
:mod:`~twodisk_ros.run.params_yaml` (PyYAML only), so that a hostile file is refused in a
fraction of a second and never reaches rcl.
"""

import shlex
import sys

from .. import __version__

__all__ = ['USAGE', 'early_exit', 'outside_ros_args']

PROG = 'roller'
USAGE = f"""\
usage: {PROG} [-h] [--version] [--ros-args [-p NAME:=VALUE ...] [--params-file FILE ...] ...]

The twodisk_ros node: a rigid body of two congruent disks in perpendicular planes (the oloid
among them) rolling on a plane. It simulates the motion and publishes the pose, the body frame
on /tf, the contact points, paths, markers, /diagnostics and /clock at `rate`, the disk frames
on /tf_static and the URDF on robot_description, optionally recording every message to an MCAP
file (`record`). It runs until `duration` of simulated time (0: until SIGINT or SIGTERM).

The disks' shape (`shape`): ellipse (semi-axes a along the common axis, b across), superellipse
(a, b and `exponent` n: |x/b|^n + |y/a|^n <= 1), egg (a, b and `egg_asymmetry`) or points (the
outline of `shape_file`, a CSV or YAML list of x, y points in metres around it: a and b are
then the outline's, and the parameters a and b are not used). `arrangement` turns the second
disk end for end (swapped) or not (parallel). A recording keeps a points outline as fitted.

Scenes (README "Scenes"): `slope` and `heading0` tilt the ground, `drive` (speed, torque)
follows cmd_speed / cmd_torque, `damping` and `rolling_resistance` dissipate; the services
reset and pause restart or hold the run. Commands and service calls act only in a real-time
run (realtime:=true, the default): a batch run (realtime:=false) never waits for them, so it
is the motion of its parameters alone (a speed drive holds the speed it starts from, a torque
drive gives 0 N m).

Parameters are ROS 2 parameters and go after --ros-args:
  -p NAME:=VALUE        one parameter; doubles need a decimal point (rate:=50.0)
  --params-file FILE    a YAML file: /**: {{ros__parameters: {{NAME: VALUE, ...}}}}
                        (UTF-8, at most 1 MiB, 32 levels, 10 000 entries, no aliases)
Every parameter with its type, default, unit and allowed values:
  python -m twodisk_ros.run.parameters    (the table of README.md, "Parameters")

examples:
  ros2 run twodisk_ros roller --ros-args --params-file config/oloid.yaml -p rate:=50.0
  {PROG} --ros-args -p realtime:=false -p duration:=2.0 -p record:=run.mcap
  {PROG} --ros-args -p shape:=superellipse -p exponent:=4.0 -p delta:=0.05
  {PROG} --ros-args -p shape:=points -p shape_file:=outline.csv -p delta:=0.03
  {PROG} --ros-args --params-file config/driven.yaml    (then publish on /cmd_speed)

exit status: 0 the run ended (duration reached, SIGINT, SIGTERM); 1 internal error;
2 invalid input (one line on stderr); 3 the recording could not be written.
"""

_ROS_FLAGS = ('-p', '--param', '--params-file', '-r', '--remap', '--log-level',
              '--log-config-file', '--log-file-name', '-e', '--enclave')


def split_ros_args(args):
    """(inside, outside): the arguments inside every ``--ros-args ... [--]`` section, and the
    others, each in order (the markers themselves dropped)."""
    inside, outside, within = [], [], False
    for arg in args:
        if arg == '--ros-args':
            within = True
        elif arg == '--' and within:
            within = False
        else:
            (inside if within else outside).append(arg)
    return inside, outside


def outside_ros_args(args):
    """The arguments (program name excluded) outside every ``--ros-args ... [--]`` section."""
    return split_ros_args(args)[1]


def _inside(args):
    return split_ros_args(args)[0]


def _shown(text, limit=160):
    text = repr(text)[1:-1]
    return text if len(text) <= limit else text[:limit - 3] + '...'


def _refusal(args, outside):
    given = _shown(' '.join(outside))
    rosish = [a for a in outside if a in _ROS_FLAGS or (':=' in a and not a.startswith('-'))]
    if not rosish:
        return (f"unexpected argument '{given}': {PROG} takes no arguments of its own; ROS "
                f'arguments go after --ros-args (see {PROG} --help)')
    # a bare NAME:=VALUE (ROS 1 style) is a parameter: -p NAME:=VALUE
    fixed = []
    for arg in outside:
        bare = ':=' in arg and not arg.startswith('-') and not (fixed and fixed[-1] in _ROS_FLAGS)
        fixed += ['-p', arg] if bare else [arg]
    suggestion = shlex.join([PROG, '--ros-args', *fixed, *_inside(args)])
    return f"'{given}' is outside --ros-args: write {_shown(suggestion, 240)}"


def early_exit(argv, out=None, err=None):
    """The exit status if ``argv`` asks for no run, else None.

    ``-h``/``--help`` print the usage and ``--version`` the version (exit 0); any other
    argument outside ``--ros-args``, and a ``--params-file`` beyond the loader's limits, get
    one line on stderr (exit 2). ``argv[0]`` is the program.
    """
    out = out or sys.stdout
    err = err or sys.stderr
    outside = outside_ros_args(list(argv)[1:])
    if '-h' in outside or '--help' in outside:
        out.write(USAGE)
        return 0
    if '--version' in outside:
        out.write(f'{PROG} (twodisk_ros) {__version__}\n')
        return 0
    if outside:
        err.write(f'{PROG}: {_refusal(list(argv)[1:], outside)}\n')
        return 2
    files = _inside(list(argv)[1:])
    files = [value for flag, value in zip(files, files[1:]) if flag == '--params-file']
    if files:
        from ..run.params_yaml import ArgumentError, load_params_file
        try:
            for path in files:
                load_params_file(path)
        except ArgumentError as error:
            err.write(f'{PROG}: {error}\n')
            return 2
    return None
