"""``twodisk-view``: a live 3D view in Foxglove without ROS (foxglove-sdk's WebSocket server).

Runs the library's motion in real time from the node's parameters (a params file of the
node, or options), or replays an MCAP recording of the node, and serves it on
``ws://127.0.0.1:8765`` to Foxglove or Lichtblick::

    twodisk-view --params-file config/oloid.yaml
    twodisk-view run.mcap --speed 0.5
    twodisk-view --a 0.2 --b 0.1 --delta 0.1 --mode kinematic --port 0

Exit status: 0 stopped by SIGINT/SIGTERM (or ``--help``), 2 bad input (one line on stderr:
options, parameters, a recording that cannot be read, a port that is taken), 1 an internal
error. The protocol, channels and the viewers that can connect: :data:`EPILOG`.
"""

import argparse
import ipaddress
import math
import os
import signal
import sys
import threading

from ..recordings.errors import one_line

__all__ = ['DEFAULT_PORT', 'EPILOG', 'MAX_RATE', 'MAX_SPEED', 'main']

PROG = 'twodisk-view'
DEFAULT_HOST, DEFAULT_PORT = '127.0.0.1', 8765
#: Samples per second the view sends at most (each one a message on /tf).
MAX_RATE = 1000.0
#: The fastest replay or simulation (× real time), and the slowest.
MAX_SPEED, MIN_SPEED = 100.0, 0.01
#: The body frame when the node's parameters do not name one.
DEFAULT_BODY_FRAME = 'twodisk_body'
#: Options of a simulated run: (name, type, unit); the node's parameters of these names.
SIMULATION_OPTIONS = (('a', float, 'm'), ('b', float, 'm'), ('delta', float, 'm'),
                      ('theta0', float, 'rad'), ('branch', int, '+1 or -1'),
                      ('omega0', float, 'rad/s'), ('mass', float, 'kg'),
                      ('gravity', float, 'm/s^2'), ('friction', float, 'mu; .inf: no limit'),
                      ('rate', float, 'Hz'), ('duration', float, 's; 0: until stopped'),
                      ('path_length', int, 'samples in each trace'),
                      ('exponent', float, 'superellipse exponent n >= 2'),
                      ('egg_asymmetry', float, 'egg: share of the largest convex asymmetry'),
                      ('shape_file', str, 'points: CSV or YAML outline (m)'))
CHOICE_OPTIONS = (('shape', ('ellipse', 'superellipse', 'egg', 'points')),
                  ('arrangement', ('parallel', 'swapped')),
                  ('mode', ('dynamic', 'kinematic')),
                  ('mass_model', ('laminae', 'solid', 'custom')),
                  ('method', ('direct', 'table')))

EPILOG = f"""\
Protocol: the Foxglove WebSocket protocol with subprotocol foxglove.sdk.v1 (foxglove-sdk
0.30.3), on ws://HOST:PORT. Viewers that connect: Foxglove (app.foxglove.dev or a current
desktop app: Open connection -> Foxglove WebSocket) and Lichtblick 1.22.0 or later. Older
clients speak only foxglove.websocket.v1 and are refused (HTTP 400): Lichtblick up to 1.21
and the open-source Foxglove Studio 1.x.
Channels: /tf (foxglove.FrameTransforms: frame_id -> body frame at every sample, body ->
{DEFAULT_BODY_FRAME}_disk_a/_disk_b), /body (the mesh and the disk rims, frame-locked),
/contact_segment, /contact_forces, /traces (foxglove.SceneUpdate), /parameters (JSON); the
server's time follows the samples' stamps; the parameters are also served read-only.
Serves on this machine only ({DEFAULT_HOST}) unless --allow-remote. Exit status: 0 stopped
by SIGINT/SIGTERM, 2 bad input or a port in use (one line on stderr), 1 internal error."""


class _Refusal(ValueError):
    """Bad input found before anything is served; one line."""


class _Stopped(Exception):
    """A signal arrived before the server was up."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _Refusal(message)


def _parser():
    parser = _Parser(prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
                     description='Serve a rolling run (the library in real time, or an MCAP\n'
                     'recording) to Foxglove over its WebSocket protocol: the body, its frames,\n'
                     'the contact segment, the traces and the ground forces. No ROS needed.',
                     epilog=EPILOG)
    parser.add_argument('recording', nargs='?', help='an MCAP recording of the roller node '
                        'to replay (omit to simulate with the parameters below)')
    parser.add_argument('--speed', type=float, default=1.0,
                        help=f'simulated or recorded seconds per second, {MIN_SPEED:g} to '
                             f'{MAX_SPEED:g} (default 1: real time)')
    parser.add_argument('--host', default=DEFAULT_HOST,
                        help=f'address to serve on (default {DEFAULT_HOST}); a loopback '
                             'address unless --allow-remote')
    parser.add_argument('--port', type=int, default=DEFAULT_PORT,
                        help=f'TCP port (default {DEFAULT_PORT}; 0: any free port, printed)')
    parser.add_argument('--allow-remote', action='store_true',
                        help='serve on a non-loopback --host: anyone who reaches it can watch')
    group = parser.add_argument_group(
        'simulated run', "the roller node's parameters (README, Parameters): a --params-file\n"
        f"first, then these options; rate 100 Hz unless given (at most {MAX_RATE:g} here)")
    group.add_argument('--params-file', help='a parameter file of the roller node (YAML)')
    for name, kind, unit in SIMULATION_OPTIONS:
        group.add_argument('--' + name.replace('_', '-'), dest=name, type=kind,
                           metavar=name.upper(), help=unit)
    for name, choices in CHOICE_OPTIONS:
        group.add_argument('--' + name.replace('_', '-'), dest=name, choices=choices)
    return parser


def _check_host(host, allow_remote):
    if host == 'localhost':
        return
    try:
        address = ipaddress.ip_address(host)
    except ValueError:
        raise _Refusal(f'--host must be an IP address or localhost, got {host!r}') from None
    if not address.is_loopback and not allow_remote:
        raise _Refusal(f'--host {host} is not a loopback address: the view serves on this '
                       'machine only (127.0.0.1, ::1) unless --allow-remote is given')


def _check_args(args):
    _check_host(args.host, args.allow_remote)
    if not 0 <= args.port <= 65535:
        raise _Refusal(f'--port must be 0 (any free port) to 65535, got {args.port}')
    if not (math.isfinite(args.speed) and MIN_SPEED <= args.speed <= MAX_SPEED):
        raise _Refusal(f'--speed must be in [{MIN_SPEED:g}, {MAX_SPEED:g}], got {args.speed!r}')
    given = [name for name, *_ in SIMULATION_OPTIONS + CHOICE_OPTIONS
             if getattr(args, name) is not None]
    if args.params_file is not None:
        given.insert(0, 'params_file')
    if args.recording is not None and given:
        raise _Refusal(f'--{given[0].replace("_", "-")} applies to simulated runs, not to '
                       'a recording (the recording holds its parameters)')


def _settings(args):
    """The node's settings of a simulated run (the view is always paced by the clock)."""
    from ..runs import RunError, settings_from
    values = {name: getattr(args, name) for name, *_ in SIMULATION_OPTIONS + CHOICE_OPTIONS}
    settings = settings_from(args.params_file, realtime=True, **values)
    if settings.rate > MAX_RATE:
        raise RunError(f'rate must be <= {MAX_RATE:g} Hz for the view (every sample is a '
                       f'message), got {settings.rate:g} Hz: pass --rate')
    return settings


class _Signals:
    """SIGINT/SIGTERM: stop the show; before the server is up, end at once (exit 0)."""

    def __init__(self):
        self.stop = threading.Event()
        self.serving = False

    def install(self):
        for number in (signal.SIGINT, signal.SIGTERM):
            signal.signal(number, self._handle)

    def _handle(self, number, frame):
        self.stop.set()
        if not self.serving:
            raise _Stopped()


def _refuse(error):
    print(f'{PROG}: {one_line(error)}', file=sys.stderr)
    return 2


def _serve(args, signals):
    from ..model.frames import disk_frames
    from ..model.mesh import mesh_parts
    from .player import Player
    from .server import SUBPROTOCOL, ViewServer, parameter_values
    from .sources import LiveSource, ReplaySource
    if args.recording is not None:
        source = ReplaySource(args.recording, speed=args.speed)
    else:
        source = LiveSource(_settings(args), speed=args.speed)
    settings = source.settings
    body_frame = getattr(settings, 'body_frame', DEFAULT_BODY_FRAME)
    disks = disk_frames(source.body, body_frame)
    parts = mesh_parts(source.body, settings.mass_model)
    parameters = parameter_values(settings)
    signals.serving = True          # from here on a signal only sets the flag
    server = ViewServer(args.host, args.port, parameters)
    try:
        if signals.stop.is_set():
            return 0
        run_info = {'source': source.description, 'frame_id': settings.frame_id,
                    'body_frame': body_frame, 'disk_frames': [d.child_frame_id for d in disks],
                    'speed': args.speed, 'start_stamp_ns': None,
                    'rate': settings.rate, 'forces': source.has_forces,
                    'subprotocol': SUBPROTOCOL}
        player = Player(source, server, (settings.frame_id, body_frame), parts, disks,
                        run_info, parameters, signals.stop)
        host = f'[{args.host}]' if ':' in args.host else args.host
        print(f'{PROG}: serving ws://{host}:{server.port} (subprotocol {SUBPROTOCOL}): '
              f'{source.description}; stop with Ctrl-C', flush=True)
        if player.play():
            print(f'{PROG}: the run ended after {player.shown} samples; serving its last '
                  'state until stopped', flush=True)
            player.idle()
        skipped = f', {player.skipped} skipped to keep up' if player.skipped else ''
        print(f'{PROG}: stopped after {player.shown} samples{skipped}', flush=True)
    finally:
        server.stop()
    return 0


def main(argv=None):
    """Run ``twodisk-view``; return the exit status (0, 1 or 2)."""
    signals = _Signals()
    signals.install()
    try:
        args = _parser().parse_args(argv)
        _check_args(args)
        from ..runs import RunError
        from .server import ServeError
    except _Refusal as error:
        return _refuse(error)
    except _Stopped:
        return 0
    try:
        return _serve(args, signals)
    except _Stopped:
        return 0
    except (RunError, ServeError) as error:
        return _refuse(error)
    except Exception as error:  # noqa: BLE001 - one line, not a traceback
        if os.environ.get('TWODISK_DEBUG'):
            raise
        print(f'{PROG}: internal error: {type(error).__name__}: {one_line(error)}',
              file=sys.stderr)
        return 1


if __name__ == '__main__':
    raise SystemExit(main())
