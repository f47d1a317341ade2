"""``python -m twodisk_ros.view``: the same as ``twodisk-view``."""

from .cli import main

if __name__ == '__main__':
    raise SystemExit(main())
