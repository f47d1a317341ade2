"""Entry point of ``roller`` (``ros2 run twodisk_ros roller``, ``python -m twodisk_ros.roller``).

The signal handlers go in first, before the heavy imports; the process is in
:mod:`twodisk_ros.node.main` and the node in :mod:`twodisk_ros.node.roller`.
"""

import sys

from .node.stop import StopRequest

_STOP = StopRequest()

from .node.main import main as _main  # noqa: E402  (after the signal handlers)


def main(args=None):
    """Run the node with the signal handlers installed at import; returns the exit code."""
    return _main(args, stop=_STOP)


if __name__ == '__main__':
    sys.exit(main())
