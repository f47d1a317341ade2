"""``twodisk-animate``: a run as an animated GIF (or MP4 with ffmpeg), 3D or from above.

A run of the library (the node's parameters: flags, or ``--params-file`` like
config/oloid.yaml; any shape, through the run description) or of an MCAP recording of the
node (of any shape: the recording holds it)::

    twodisk-animate -o oloid.gif --params-file config/oloid.yaml --stop 4
    twodisk-animate run.mcap -o run.gif --start 2 --stop 8 --fps 15 --size 480x360
    twodisk-animate -o top.gif --a 0.2 --b 0.1 --delta 0.1 --view top --forces
    twodisk-animate -o square.png --params-file config/rounded_square.yaml --stop 3
    twodisk-animate -o slope.png --params-file config/slope.yaml --stop 3

A scene (slope, drive, dissipation; README "Scenes") is drawn with its ground: the plane
through the origin going down along +X at the slope. A simulated run is the node's batch
run, in which no command or service call acts; a recording of a real-time run shows them.

A ``.png`` output is one still: the body at ``--stop`` (default the run's end) with the
traces from ``--start``. Outputs follow :mod:`twodisk_ros.outputs`: ``-o`` must end in
``.gif`` or ``.png`` (``.mp4`` only when ffmpeg is installed); an existing file is refused unless ``--overwrite``; the file is written
through a hidden temporary name and renamed, so an interrupted or failed run leaves it as it
was. The request is sized before anything is simulated or drawn: at most :data:`MAX_FRAMES`
frames, a simulated run of at most :data:`MAX_SIMULATED_SECONDS`, and no more memory than
:func:`twodisk_ros.limits.memory_limit` allows (:func:`estimate_memory`).

Exit status: 0 written, 2 bad input (unreadable file, bad span, a request too large,
unwritable output; one line on stderr), 1 an internal error, 130 interrupted.
"""

import argparse
import math
import os
import re
import shutil
import sys

from ..limits import LimitError, check_memory, describe_bytes
from ..outputs import OutputError, check_output, replacing
from ..recordings.errors import one_line

__all__ = ['main', 'estimate_memory', 'MAX_FRAMES', 'MAX_SIMULATED_SECONDS']

PROG = 'twodisk-animate'
#: The node's shapes (twodisk_ros.run.shape.SHAPES; not imported: --help loads no physics).
SHAPES = ('ellipse', 'superellipse', 'egg', 'points')
#: The node's parameters a simulated run takes from options (after --params-file).
RUN_OPTIONS = ('a', 'b', 'delta', 'theta0', 'branch', 'omega0', 'mass', 'gravity', 'mode',
               'mass_model', 'shape', 'exponent', 'egg_asymmetry', 'shape_file',
               'arrangement', 'method', 'slope', 'heading0', 'drive', 'rolling_resistance',
               'damping')
#: At most this many frames (4 min at 15 fps; ~0.09 s of drawing each at 640x480 here).
MAX_FRAMES = 3600
#: A simulated run is computed from 0 s up to at most this time (s): 720 001 samples.
MAX_SIMULATED_SECONDS = 3600.0
#: Memory per sample of a run (B): measured 435-660 B (60 001 samples, with forces), rounded up.
BYTES_PER_SAMPLE = 1024
#: Memory per pixel of each frame (B): the GIF writer keeps every frame as RGBA until the end;
#: measured 5.7-9.7 B (100-200 frames at 320x240 and 640x480), rounded up.
BYTES_PER_FRAME_PIXEL = 10
#: Size limits of a frame (pixels), as :func:`~twodisk_ros.plotting.animation.animate`.
MIN_SIDE, MAX_SIDE = 64, 4096


class _Refusal(ValueError):
    """Bad input found before the run is read or simulated; one line."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _Refusal(message)


def _size(text):
    match = re.fullmatch(r'\s*(\d+)\s*[xX×]\s*(\d+)\s*', text)
    if not match:
        raise argparse.ArgumentTypeError(f'size must be WIDTHxHEIGHT in pixels, got {text!r}')
    return int(match.group(1)), int(match.group(2))


def _parser():
    parser = _Parser(prog=PROG, description='Render a rolling run (library or MCAP '
                     'recording) as an animated GIF, or MP4 when ffmpeg is installed.',
                     epilog=f'At most {MAX_FRAMES} frames and a simulated run of at most '
                            f'{MAX_SIMULATED_SECONDS:g} s. Exit status: 0 written, 2 bad input '
                            f'or a request too large (one line on stderr), 1 internal error, '
                            f'130 interrupted.')
    parser.add_argument('recording', nargs='?', help='an MCAP recording of the roller node '
                        '(omit to simulate with the parameters below)')
    parser.add_argument('-o', '--output', required=True,
                        help='the file to write: .gif, .png (one still at --stop) or .mp4 '
                             '(needs ffmpeg); an existing file is refused unless --overwrite')
    parser.add_argument('--overwrite', action='store_true',
                        help='replace an existing output (only once the new one is complete)')
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
    body.add_argument('--shape', choices=SHAPES, help='the laminae (default ellipse)')
    body.add_argument('--exponent', type=float, help='superellipse exponent n >= 2')
    body.add_argument('--egg-asymmetry', dest='egg_asymmetry', type=float,
                      help='egg: share of the largest convex asymmetry, |.| <= 0.95')
    body.add_argument('--shape-file', dest='shape_file',
                      help='points: a CSV or YAML outline (x, y in m, in order)')
    body.add_argument('--arrangement', choices=('parallel', 'swapped'))
    body.add_argument('--method', choices=('direct', 'table'))
    scene = parser.add_argument_group(
        'scene (the node\'s parameters; see README "Scenes")',
        'A simulated run is the node\'s batch run: no command or service call acts in it (a '
        'speed drive holds its starting speed, a torque drive gives 0 N m); commands, '
        'reset and pause act in real-time runs of the node, and a recording of one shows '
        'them. The ground is drawn through the origin, going down along +X.')
    scene.add_argument('--slope', type=float, help='inclination of the ground (rad)')
    scene.add_argument('--heading0', type=float,
                       help='heading of the mean travel from straight downhill (rad)')
    scene.add_argument('--drive', choices=('none', 'speed', 'torque'))
    scene.add_argument('--rolling-resistance', dest='rolling_resistance', type=float,
                       help='rolling-resistance coefficient (dimensionless, >= 0)')
    scene.add_argument('--damping', type=float, help='viscous damping (N m s, >= 0)')
    return parser


def _check_output(path, overwrite):
    """The output's suffix (.gif; .mp4 only with ffmpeg) and :func:`check_output`."""
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in ('.gif', '.mp4', '.png'):
        raise OutputError(f'cannot write {path}: the file name must end in .gif, .png (one '
                          f'still) or .mp4 (needs ffmpeg)')
    if suffix == '.mp4' and shutil.which('ffmpeg') is None:
        raise OutputError(f'cannot write {path}: MP4 needs ffmpeg, which is not installed '
                          '(write a .gif instead)')
    check_output(path, overwrite=overwrite, suffixes=('.gif', '.mp4', '.png'))


def _frame_count(start, stop, fps):
    """Frames of the span, as :func:`~twodisk_ros.plotting.animation.frame_times` counts
    them, without building the times."""
    return int(math.floor((stop - start) * fps + 1e-9)) + 1


def estimate_memory(frames, size, samples):
    """Bytes an animation of ``frames`` frames of ``size`` (w, h) pixels from a run of
    ``samples`` samples needs (see BYTES_PER_FRAME_PIXEL and BYTES_PER_SAMPLE)."""
    width, height = size
    return frames * width * height * BYTES_PER_FRAME_PIXEL + samples * BYTES_PER_SAMPLE


def _check_numbers(args):
    """The span, the frame rate and the size: finite, ordered, in range."""
    for name in ('start', 'stop', 'fps'):
        value = getattr(args, name)
        if value is not None and not math.isfinite(value):
            raise _Refusal(f'--{name} must be a finite number, got {value!r}')
    if not 0 < args.fps <= 120:
        raise _Refusal(f'fps must be in (0, 120], got {args.fps!r}')
    if args.start < 0 or (args.stop is not None and args.stop <= args.start):
        raise _Refusal(f'the span must satisfy 0 <= start < stop, got start = {args.start!r} '
                       f's, stop = {args.stop!r} s')
    width, height = args.size
    if not (MIN_SIDE <= width <= MAX_SIDE and MIN_SIDE <= height <= MAX_SIDE):
        raise _Refusal(f'size must be between {MIN_SIDE}x{MIN_SIDE} and {MAX_SIDE}x{MAX_SIDE} '
                       f'pixels, got {width}x{height}')


def _check_size(args, stop, samples):
    """Refuse more than MAX_FRAMES frames or more memory than the machine allows (the run's
    ``samples`` included)."""
    frames = 1 if _is_still(args) else _frame_count(args.start, stop, args.fps)
    width, height = args.size
    what = (f'--start {args.start:g} --stop {stop:g} at --fps {args.fps:g} is {frames} frames '
            f'of {width}x{height}')
    if frames > MAX_FRAMES:
        need = estimate_memory(frames, args.size, samples)
        raise LimitError(f'{what} (~{describe_bytes(need)} of memory); allowed: at most '
                         f'{MAX_FRAMES} frames (shorten the span or lower --fps)')
    check_memory(estimate_memory(frames, args.size, samples), what)


def _is_still(args):
    return os.fspath(args.output).lower().endswith('.png')


def _check_request(args):
    """What can be sized before the run is read or simulated (no physics imported)."""
    if args.recording is None:
        stop = 6.0 if args.stop is None else args.stop
        _check_size(args, stop, 0)
        if stop > MAX_SIMULATED_SECONDS:
            raise LimitError(f'a simulated run is computed from 0 s, --stop {stop:g} s is too '
                             f'long; allowed: --stop <= {MAX_SIMULATED_SECONDS:g} s')
    elif args.stop is not None:
        _check_size(args, args.stop, 0)


def _run_of(args):
    from ..runs import LIBRARY_RATE, RunError, library_run, recorded_run, settings_from
    if args.recording:
        given = [f'--{n.replace("_", "-")}' for n in ('params_file',) + RUN_OPTIONS
                 if getattr(args, n) is not None]
        if given:
            raise RunError(f'{given[0]} applies to simulated runs, not to a recording')
        run = recorded_run(args.recording)
        _check_size(args, float(run.t[-1]) if args.stop is None else args.stop, len(run))
        return run
    stop = 6.0 if args.stop is None else args.stop
    _check_size(args, stop, max(2, int(math.ceil(stop * LIBRARY_RATE)) + 1))
    settings = settings_from(args.params_file, **{n: getattr(args, n) for n in RUN_OPTIONS})
    return library_run(settings, stop=stop, forces=args.forces)


def _refuse(error):
    print(f'{PROG}: {one_line(error)}', file=sys.stderr)
    return 2


def main(argv=None):
    """Run ``twodisk-animate``; return the exit status (0, 1, 2 or 130)."""
    try:
        args = _parser().parse_args(argv)
        _check_output(args.output, args.overwrite)
        _check_numbers(args)
        _check_request(args)
    except (_Refusal, OutputError, LimitError) as error:
        return _refuse(error)      # before numpy, scipy and matplotlib are imported
    from ..runs import RunError
    try:
        run = _run_of(args)
        from .animation import animate, still
        with replacing(args.output) as temporary:
            if _is_still(args):
                still(run, temporary, at=args.stop, start=args.start, view=args.view,
                      size=args.size, forces=args.forces,
                      camera='fit' if args.camera == 'auto' else args.camera)
                count = 1
            else:
                count = animate(run, temporary, start=args.start, stop=args.stop,
                                fps=args.fps, view=args.view, size=args.size,
                                forces=args.forces, camera=args.camera)
    except (RunError, OutputError, LimitError) as error:
        return _refuse(error)
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted; nothing written', file=sys.stderr)
        return 130
    except Exception as error:  # noqa: BLE001 - one line, not a traceback
        if os.environ.get('TWODISK_DEBUG'):
            raise
        print(f'{PROG}: internal error: {type(error).__name__}: {one_line(error)}',
              file=sys.stderr)
        return 1
    if args.forces and run.force_a is None:
        print(f'{PROG}: note: the recording has no /wrench_a, /wrench_b: no forces drawn',
              file=sys.stderr)
    print(f'{args.output}: {count} frame{"s" if count != 1 else ""}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
