"""``twodisk-explore``: explore the family in a browser (a viser page; no ROS needed).

Serves a page on this machine from the same run description as the node (a params file of
the node, ``-p name:=value``), or replays an MCAP recording of the node, or writes a
single-file HTML lesson that plays a run with no server and no network::

    twodisk-explore --params-file config/oloid.yaml
    twodisk-explore -p a:=0.1 -p b:=0.1 -p delta:=0.07 --port 8080
    twodisk-explore --params-file config/egg.yaml --export lesson.html
    twodisk-explore run.mcap

Exit status: 0 stopped by SIGINT/SIGTERM, or an export written (or ``--help``); 2 bad input
(one line on stderr: options, parameters, a recording that cannot be read, a port in use, an
export path that exists without ``--overwrite``); 1 an internal error.
"""

import argparse
import ipaddress
import math
import os
import signal
import sys
import threading

from ..recordings.errors import one_line

__all__ = ['EXPORT_FPS', 'EXPORT_SECONDS', 'main']

PROG = 'twodisk-explore'
DEFAULT_HOST = '127.0.0.1'
#: Default length (s of the run) and frame rate (Hz) of an exported lesson.
EXPORT_SECONDS, EXPORT_FPS = 20.0, 30.0
#: The longest lesson (s): its size grows with the frames (docs/benchmarks.md).
MAX_EXPORT_SECONDS = 600.0

EPILOG = """\
The page: the body rolling on its ground in real time (traces of A, B and G, the contact
segment AB, the ground's forces at A and B), the physical parameters of the node as controls
(a change restarts the motion; a value the node refuses is refused with the node's reason),
play/pause, reset, speed x0.1 to x10; z_G over the cycle with the equilibria, N_A, N_B and
mu_required against the friction mu; lift-off, slip or a flat vertex in the node's words.
The page's client (viser 1.1.1, three.js) is served by this command: no network needed.
--export writes one HTML file (the client and the run) that plays in a browser from disk."""


class _Refusal(ValueError):
    """Bad input found before anything is served; one line."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _Refusal(message)


def _parser():
    parser = _Parser(prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
                     description='Explore a rolling two-disk body in a browser: the node\'s '
                     'physics\nin real time with its parameters as controls, or a recording.',
                     epilog=EPILOG)
    parser.add_argument('recording', nargs='?', help='an MCAP recording of the roller node '
                        'to replay (omit to simulate)')
    parser.add_argument('--params-file', help='a parameter file of the roller node (YAML)')
    parser.add_argument('-p', dest='values', action='append', default=[], metavar='NAME:=VALUE',
                        help="one parameter of the node, typed as ros2 types it "
                             "(doubles need a decimal point: a:=0.1); repeatable")
    parser.add_argument('--host', default=DEFAULT_HOST,
                        help=f'loopback address to serve on (default {DEFAULT_HOST})')
    parser.add_argument('--port', type=int, default=0,
                        help='TCP port (default 0: a free port; the URL is printed)')
    parser.add_argument('--speed', type=float, default=1.0,
                        help='simulated seconds per second at start, 0.1 to 10 (default 1)')
    parser.add_argument('--export', metavar='FILE.html',
                        help='write a single-file HTML lesson of the run and exit')
    parser.add_argument('--seconds', type=float, default=EXPORT_SECONDS,
                        help=f'--export: seconds of the run (default {EXPORT_SECONDS:g}; a '
                             'recording: its length up to this)')
    parser.add_argument('--overwrite', action='store_true',
                        help='--export: replace an existing file')
    return parser


def _check_args(args):
    if args.host != 'localhost':
        try:
            address = ipaddress.ip_address(args.host)
        except ValueError:
            raise _Refusal(f'--host must be an IP address or localhost, got {args.host!r}') \
                from None
        if not address.is_loopback:
            raise _Refusal(f'--host {args.host} is not a loopback address: the page is '
                           'served on this machine only (127.0.0.1, ::1)')
    if not 0 <= args.port <= 65535:
        raise _Refusal(f'--port must be 0 (any free port) to 65535, got {args.port}')
    if not (math.isfinite(args.speed) and 0.1 <= args.speed <= 10):
        raise _Refusal(f'--speed must be in [0.1, 10], got {args.speed!r}')
    if not (math.isfinite(args.seconds) and 0 < args.seconds <= MAX_EXPORT_SECONDS):
        raise _Refusal(f'--seconds must be in (0, {MAX_EXPORT_SECONDS:g}], got '
                       f'{args.seconds!r}')
    if args.recording is not None and (args.params_file or args.values):
        option = '--params-file' if args.params_file else '-p'
        raise _Refusal(f'{option} applies to simulated runs, not to a recording (the '
                       'recording holds its parameters)')
    if args.export is not None:
        from ..outputs import check_output
        check_output(args.export, overwrite=args.overwrite, suffixes=('.html',))


def _values(pairs):
    """{name: value} of ``-p name:=value`` items, typed as rcl types them."""
    from ..run.parameters import BY_NAME
    from ..run.params_yaml import parse_value
    values = {}
    for pair in pairs:
        name, sep, text = pair.partition(':=')
        if not sep or not name:
            raise _Refusal(f'-p {pair}: expected NAME:=VALUE (e.g. -p a:=0.1)')
        if name not in BY_NAME:
            raise _Refusal(f'-p {pair}: the node has no parameter {name!r}')
        if BY_NAME[name].read_only:
            raise _Refusal(f'-p {pair}: {name} is not used by the page')
        value = parse_value(text, name, f'-p {pair}')
        if BY_NAME[name].kind is float and type(value.value) is int:   # as the node says it
            raise _Refusal(f'-p {pair}: {name} is a double: write {float(value.value)!r}, not '
                           f'{value.text} (a double needs a decimal point)')
        values[name] = value.value
    return values


def _motion(args):
    from ..runs import settings_from
    from .motion import open_motion
    if args.recording is not None:
        return open_motion(recording=args.recording)
    settings = settings_from(args.params_file, realtime=True, **_values(args.values))
    return open_motion(settings=settings)


def _server(host, port):
    """A viser server on (host, port); ServeError (one line) if it cannot bind."""
    import socket
    from .client import viser_server
    with socket.socket(socket.AF_INET6 if ':' in host else socket.AF_INET) as probe:
        try:
            probe.bind((host, port))
            port = probe.getsockname()[1]
        except OSError as error:
            raise _ServeError(f'cannot serve on {host}:{port}: {one_line(error.strerror or error)}'
                              + (' (the port is in use: pick another --port, or 0 for a '
                                 'free one)' if error.errno == 98 else '')) from None
    with quiet():
        server = viser_server(host, port)
    if server.get_port() != port:       # viser moves to the next port when one is taken
        stop_server(server)
        raise _ServeError(f'cannot serve on {host}:{port}: the port is in use (pick another '
                          '--port, or 0 for a free one)')
    return server


class _ServeError(RuntimeError):
    pass


def quiet():
    """Silence viser's banners (printed on stdout when a server starts and stops)."""
    import contextlib
    import io
    return contextlib.redirect_stdout(io.StringIO())


def stop_server(server):
    with quiet():
        server.stop()


def export(motion, path, seconds=EXPORT_SECONDS, fps=EXPORT_FPS):
    """Write the lesson: ``seconds`` of ``motion`` at ``fps`` frames a second, one HTML file
    that plays in a browser with no server and no network, with its plots (z_G over the cycle
    and the phase, N_A, N_B, mu_required: :mod:`~twodisk_ros.explore.lesson`); return its
    size (bytes)."""
    from ..outputs import replacing
    from .client import with_settings
    from .lesson import LessonPlots, with_plots
    from .page import PLOT_RATE
    from .scene3d import Scene3D, camera_for
    server = _server(DEFAULT_HOST, 0)
    try:
        server.scene.set_up_direction('+z')
        serializer = server.get_scene_serializer()
        scene = Scene3D(server, motion)
        position, look_at = camera_for(scene.size)
        server.initial_camera.position = tuple(position)
        server.initial_camera.look_at = tuple(look_at)
        frames = int(round(seconds * fps))
        if not motion.live:
            frames = min(frames, int(motion.duration * fps) + 1)
        every = max(1, int(round(fps / PLOT_RATE)))
        plots = LessonPlots(motion, fps)
        for k in range(frames):
            frame = motion.advance(1.0 / fps, samples=4)
            scene.show(frame, traces=k % every == 0 or k == frames - 1)
            plots.add(frame)
            serializer.insert_sleep(1.0 / fps)
        html = with_plots(with_settings(serializer.as_html()), plots)
    finally:
        stop_server(server)
    with replacing(path) as temporary:
        with open(temporary, 'w', encoding='utf-8') as out:
            out.write(html)
    return len(html.encode())


class _Signals:
    def __init__(self):
        self.stop = threading.Event()

    def install(self):
        for number in (signal.SIGINT, signal.SIGTERM):
            signal.signal(number, lambda *_: self.stop.set())


def _serve(args, signals):
    from .page import Explorer
    motion = _motion(args)
    if args.export is not None:
        size = export(motion, args.export, args.seconds)
        print(f'{PROG}: wrote {args.export} ({size / 1e6:.2f} MB, {args.seconds:g} s of the '
              'run): open it in a browser, no server needed', flush=True)
        return 0
    server = _server(args.host, args.port)
    explorer = Explorer(server, motion, speed=args.speed).start()
    try:
        host = f'[{args.host}]' if ':' in args.host else args.host
        print(f'{PROG}: serving http://{host}:{server.get_port()}/ ; stop with Ctrl-C',
              flush=True)
        signals.stop.wait()
    finally:
        explorer.stop()
        stop_server(server)
    return 0


def main(argv=None):
    """Run ``twodisk-explore``; return the exit status (0, 1 or 2)."""
    signals = _Signals()
    signals.install()
    try:
        args = _parser().parse_args(argv)
        _check_args(args)
    except _Refusal as error:
        return _refuse(error)
    except ValueError as error:          # OutputError
        return _refuse(error)
    from ..run.params_yaml import ArgumentError
    from ..runs import RunError
    try:
        return _serve(args, signals)
    except (_Refusal, _ServeError, RunError, ArgumentError) as error:
        return _refuse(error)
    except Exception as error:  # noqa: BLE001 - one line, not a traceback
        if os.environ.get('TWODISK_DEBUG'):
            raise
        print(f'{PROG}: internal error: {type(error).__name__}: {one_line(error)}',
              file=sys.stderr)
        return 1


def _refuse(error):
    print(f'{PROG}: {one_line(error)}', file=sys.stderr)
    return 2


if __name__ == '__main__':
    raise SystemExit(main())
