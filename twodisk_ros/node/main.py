"""``roller``'s process: arguments, signals, exit codes (the node itself is in roller.py).

Exit codes: 0 a run that ended (duration reached, SIGINT or SIGTERM: the recording is
complete); 2 invalid input (arguments, parameters, an existing or unwritable record file),
one line on stderr; 3 the recording could not be written during the run (disk full, I/O
error), one line on stderr, everything written before stays readable; 1 an internal error,
one line (``TWODISK_DEBUG=1`` prints the traceback).
"""

import os
import sys
import traceback

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions

from ..recordings import RecordingError, RecordingExistsError
from ..recordings.errors import one_line
from .arguments import ArgumentError, check_arguments, rclpy_type_hint
from .stop import StopNow, StopRequest
from .usage import early_exit

__all__ = ['main', 'EXIT_OK', 'EXIT_INPUT', 'EXIT_IO', 'EXIT_INTERNAL']

EXIT_OK, EXIT_INTERNAL, EXIT_INPUT, EXIT_IO = 0, 1, 2, 3
PROG = 'roller'


def _say(text):
    print(f'{PROG}: {one_line(text)}', file=sys.stderr, flush=True)


def _internal(error):
    if os.environ.get('TWODISK_DEBUG'):
        traceback.print_exc()
    _say(f'internal error: {type(error).__name__}: {error} (TWODISK_DEBUG=1 shows the '
         'traceback)')
    return EXIT_INTERNAL


def _start(argv, stop):
    """rclpy and the node, or (None, exit code) after one line on stderr."""
    try:
        from .roller import Roller   # after the arguments are known to be well formed
    except ImportError as error:     # a message package missing from this environment
        _say(f'cannot load the node: {error} (the set-up installs every message package '
             'the node publishes, tf2_msgs included: see README.md, Quick start)')
        return None, EXIT_INTERNAL
    try:
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
        stop.install()
    except Exception as error:  # noqa: BLE001 - rclpy's argument errors are RCLError
        _say(f'invalid ROS arguments: {error}')
        return None, EXIT_INPUT
    try:
        return Roller(), EXIT_OK
    except RecordingExistsError as error:
        _say(f'{error}; pass -p overwrite:=true to replace it')
    except RecordingError as error:
        _say(error)
    except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
        _say(error)
    except Exception as error:  # noqa: BLE001 - rclpy's parameter exceptions, one line
        name = type(error).__name__
        if 'Parameter' not in name and 'RCL' not in name:
            raise
        _say(f'invalid parameter: {error}{rclpy_type_hint(error)}')
    return None, EXIT_INPUT


def _run(node, stop):
    stop.forbid_abort()    # samples are being recorded: a signal ends the run at a sample
    if not node.settings.realtime:
        node.run_batch(keep_going=lambda: not stop)
    else:
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        try:
            while not stop and not node.finished:
                executor.spin_once(timeout_sec=0.05)
        finally:
            executor.shutdown(timeout_sec=1.0)
    if stop:
        node.finish_samples()


def main(args=None, stop=None, answered=False):
    """Run the node; returns the exit code (module doc).

    ``stop`` is the :class:`StopRequest` installed by the entry point before the heavy
    imports (one is installed here if not given); ``answered``: the entry point has already
    run :func:`~.usage.early_exit` on these arguments.
    """
    argv = list(sys.argv if args is None else args)
    stop = stop if stop is not None else StopRequest()
    try:
        stop.allow_abort()   # start-up: a signal ends the process at once
        # --help, --version, arguments outside --ros-args (the entry point answered them)
        status = None if answered else early_exit(argv)
        return status if status is not None else _main(argv, stop)
    except StopNow:
        _say(f'stopped by {stop.requested} during start-up: no recording written')
        return EXIT_OK
    finally:
        stop.ignore_from_now()


def _main(argv, stop):
    try:
        for warning in check_arguments(argv):
            _say(f'warning: {warning}')
    except ArgumentError as error:
        _say(error)
        return EXIT_INPUT
    if stop:
        _say(f'stopped by {stop.requested} during start-up: no recording written')
        return EXIT_OK
    node, status = None, EXIT_OK
    try:
        node, status = _start(argv, stop)
        if node is not None and not stop:
            _run(node, stop)
    except StopNow:
        if node is None:
            raise                                 # main says it: nothing was built
    except RecordingError as error:
        _say(error)
        status = EXIT_IO
    except Exception as error:  # noqa: BLE001 - one line, never a traceback
        status = _internal(error)
    finally:
        stop.forbid_abort()   # the clean-up is never cut short
        if node is not None:
            status = _close(node, status)
            node.destroy_node()
        rclpy.try_shutdown()
        stop.install()   # rclpy's shutdown restored the default handlers: a late signal is ours
    return status


def _close(node, status):
    """Finish the recording and log the run's last line (or why nothing was recorded).

    Returns the exit code: EXIT_IO if the recording could not be finished.
    """
    try:
        kept = node.close()
    except RecordingError as error:
        if status == EXIT_OK:
            _say(error)
            return EXIT_IO
        return status
    if node.samples_published:
        node.get_logger().info(node.end_line())
    elif not kept:
        record = node.settings.record
        where = f': no recording written to {record}' if record else ''
        _say(f'stopped before the first sample{where}')
    return status


if __name__ == '__main__':
    sys.exit(main())
