"""Entry point ``python -m twodisk_ros.inspect_mcap`` (see :mod:`twodisk_ros.inspector`)."""

import sys

from .inspector.cli import main

if __name__ == '__main__':
    sys.exit(main())
