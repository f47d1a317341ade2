"""``roller``'s entry function run inside the test process.

A start refused for bad input builds nothing (no node runs, nothing is recorded), and a
batch run that is not about the process (its signals, its exit) records the same file, so
the code path is that of the real process minus the interpreter's start (about a second of
imports each). The test files that use it keep real processes for each kind of refusal
and for everything about the process itself. The signal handlers the entry function sets
are put back, and its rclpy context (the default one, shut down at its end) is on
``domain``.
"""

import os
import signal


def run_roller_main(args, monkeypatch, capfd, domain, cwd=None):
    """(exit code, stderr) of ``roller --ros-args *args`` through
    :func:`twodisk_ros.node.main.main` in this process (``cwd``: its working directory;
    ``capfd`` None: stderr is left to pytest's capture and None returned for it)."""
    from twodisk_ros.node.main import main
    if cwd is not None:
        monkeypatch.chdir(cwd)
    monkeypatch.setenv('ROS_DOMAIN_ID', str(domain))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    handlers = {sig: signal.getsignal(sig)
                for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGXFSZ)}
    if capfd is not None:
        capfd.readouterr()
    try:
        code = main(['roller', '--ros-args', *map(str, args)])
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    assert os.environ['ROS_DOMAIN_ID'] == str(domain)
    return code, (capfd.readouterr().err if capfd is not None else None)


def record_with_roller_main(args, domain, cwd=None):
    """Exit code of ``roller --ros-args *args`` through the entry function in this process,
    for module-scoped fixtures (no function-scoped monkeypatch or capfd there)."""
    import pytest
    with pytest.MonkeyPatch.context() as monkeypatch:
        code, _ = run_roller_main(args, monkeypatch, None, domain, cwd=cwd)
    return code
