"""Entry point of ``roller`` (``ros2 run twodisk_ros roller``, ``python -m twodisk_ros.roller``).

The signal handlers go in first, before the heavy imports; ``--help``, ``--version`` and
arguments outside ``--ros-args`` are answered next, without importing rclpy or numpy
(:mod:`twodisk_ros.node.usage`). The process is in :mod:`twodisk_ros.node.main` and the node
in :mod:`twodisk_ros.node.roller`.
"""

import sys

from .node.stop import StopRequest

_STOP = StopRequest()

from .node.usage import early_exit  # noqa: E402  (after the signal handlers; stdlib only)


def main(args=None):
    """Run the node with the signal handlers installed at import; returns the exit code."""
    argv = list(sys.argv if args is None else args)
    status = early_exit(argv)
    if status is not None:
        _STOP.ignore_from_now()
        return status
    from .node.main import main as run   # rclpy, numpy: only for a run
    return run(argv, stop=_STOP, answered=True)


if __name__ == '__main__':
    sys.exit(main())
