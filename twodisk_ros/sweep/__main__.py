"""``python -m twodisk_ros.sweep``: the same as ``twodisk-sweep``."""

import sys

from .cli import main

sys.exit(main())
