"""Entry point ``python -m twodisk_ros.roller`` (the node lives in :mod:`twodisk_ros.node`)."""

import sys

from .node.roller import main

if __name__ == '__main__':
    sys.exit(main())
