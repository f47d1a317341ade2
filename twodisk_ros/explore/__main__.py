"""``python -m twodisk_ros.explore``: the same as ``twodisk-explore``."""

from .cli import main

if __name__ == '__main__':
    raise SystemExit(main())
