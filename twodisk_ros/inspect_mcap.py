"""Entry point ``python -m twodisk_ros.inspect_mcap`` (see :mod:`twodisk_ros.inspect`)."""

import sys

from .inspect.cli import main

if __name__ == '__main__':
    sys.exit(main())
