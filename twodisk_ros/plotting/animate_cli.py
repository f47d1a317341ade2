"""``twodisk-animate``: a run as an animated GIF (or MP4 with ffmpeg), 3D or from above.

A run of the library (the node's parameters: flags, or ``--params-file`` like
config/oloid.yaml) or of an MCAP recording of the node::

    twodisk-animate -o oloid.gif --params-file config/oloid.yaml --stop 4
    twodisk-animate run.mcap -o run.gif --start 2 --stop 8 --fps 15 --size 480x360
    twodisk-animate -o top.gif --a 0.2 --b 0.1 --delta 0.1 --view top --forces

Exit status: 0 written, 2 bad input (unreadable file, bad span, unwritable output; one line
on stderr), 1 an internal error.
"""

import argparse
import os
import re
import sys

from .runs import RunError, library_run, recorded_run, settings_from

__all__ = ['main']

PROG = 'twodisk-animate'


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise RunError(message)


def _size(text):
    match = re.fullmatch(r'\s*(\d+)\s*[xX×]\s*(\d+)\s*', text)
    if not match:
        raise argparse.ArgumentTypeError(f'size must be WIDTHxHEIGHT in pixels, got {text!r}')
    return int(match.group(1)), int(match.group(2))


def _parser():
    parser = _Parser(prog=PROG, description='Render a rolling run (library or MCAP '
                     'recording) as an animated GIF, or MP4 when ffmpeg is installed.',
                     epilog='Exit status: 0 written, 2 bad input (one line on stderr).')
    parser.add_argument('recording', nargs='?', help='an MCAP recording of the roller node '
                        '(omit to simulate with the parameters below)')
    parser.add_argument('-o', '--output', required=True,
                        help='the file to write: .gif, or .mp4 (needs ffmpeg)')
    parser.add_argument('--start', type=float, default=0.0, help='first time shown (s)')
    parser.add_argument('--stop', type=float, default=None,
                        help='last time shown (s); default: end of the recording, 6 s '
                             'for a simulated run')
    parser.add_argument('--fps', type=float, default=15.0, help='frames per second')
    parser.add_argument('--view', choices=('3d', 'top'), default='3d',
                        help='3d, or the ground seen from above (top)')
    parser.add_argument('--camera', choices=('auto', 'follow', 'fit'), default='auto',
                        help='follow G, or fit the whole span (auto: fit short runs)')
    parser.add_argument('--size', type=_size, default=(640, 480), metavar='WxH',
                        help='size in pixels (default 640x480)')
    parser.add_argument('--forces', action='store_true',
                        help='draw the ground forces at A and B (simulated runs: the contact '
                             'force model; recordings: /wrench_a, /wrench_b if recorded)')
    body = parser.add_argument_group('simulated run (the node\'s parameters; see README)')
    body.add_argument('--params-file', help='a parameter file of the node (YAML)')
    for name, kind in (('a', float), ('b', float), ('delta', float), ('theta0', float),
                       ('branch', int), ('omega0', float), ('mass', float),
                       ('gravity', float)):
        body.add_argument(f'--{name}', type=kind)
    body.add_argument('--mode', choices=('dynamic', 'kinematic'))
    body.add_argument('--mass-model', dest='mass_model', choices=('laminae', 'solid', 'custom'))
    return parser


def _run_of(args):
    if args.recording:
        given = [f'--{n.replace("_", "-")}' for n in ('params_file', 'a', 'b', 'delta',
                                                       'theta0', 'branch', 'omega0', 'mass',
                                                       'gravity', 'mode', 'mass_model')
                 if getattr(args, n) is not None]
        if given:
            raise RunError(f'{given[0]} applies to simulated runs, not to a recording')
        return recorded_run(args.recording)
    settings = settings_from(args.params_file, **{
        n: getattr(args, n) for n in ('a', 'b', 'delta', 'theta0', 'branch', 'omega0',
                                      'mass', 'gravity', 'mode', 'mass_model')})
    stop = 6.0 if args.stop is None else args.stop
    if not stop > 0:
        raise RunError(f'the span must satisfy 0 <= start < stop, got stop = {stop!r} s')
    return library_run(settings, stop=stop, forces=args.forces)


def main(argv=None):
    """Run ``twodisk-animate``; return the exit status (0, 1 or 2)."""
    from .animation import animate
    try:
        args = _parser().parse_args(argv)
        run = _run_of(args)
        count = animate(run, args.output, start=args.start, stop=args.stop, fps=args.fps,
                        view=args.view, size=args.size, forces=args.forces,
                        camera=args.camera)
    except RunError as error:
        print(f'{PROG}: {" ".join(str(error).split())}', file=sys.stderr)
        return 2
    except Exception as error:  # noqa: BLE001 - one line, not a traceback
        if os.environ.get('TWODISK_DEBUG'):
            raise
        print(f'{PROG}: internal error: {type(error).__name__}: {error}', file=sys.stderr)
        return 1
    if args.forces and run.force_a is None:
        print(f'{PROG}: note: the recording has no /wrench_a, /wrench_b: no forces drawn',
              file=sys.stderr)
    print(f'{args.output}: {count} frames')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
