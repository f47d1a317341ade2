"""``roller``'s entry function run inside the test process, for refused starts.

A start refused for bad input builds nothing (no node runs, nothing is recorded), so the
code path is that of the real process minus the interpreter's start (about a second of
imports each). The test files that use it keep one or two real processes per kind of
refusal to prove the process path. The signal handlers the entry function sets are put
back, and its rclpy context (the default one, shut down at its end) is on ``domain``.
"""

import os
import signal


def run_roller_main(args, monkeypatch, capfd, domain, cwd=None):
    """(exit code, stderr) of ``roller --ros-args *args`` through
    :func:`twodisk_ros.node.main.main` in this process (``cwd``: its working directory)."""
    from twodisk_ros.node.main import main
    if cwd is not None:
        monkeypatch.chdir(cwd)
    monkeypatch.setenv('ROS_DOMAIN_ID', str(domain))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    handlers = {sig: signal.getsignal(sig)
                for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGXFSZ)}
    capfd.readouterr()
    try:
        code = main(['roller', '--ros-args', *map(str, args)])
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    assert os.environ['ROS_DOMAIN_ID'] == str(domain)
    return code, capfd.readouterr().err
