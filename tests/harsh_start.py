"""Start a test's child process the harsh way: with SIGINT and SIGHUP ignored.

A shell without job control starts ``cmd &`` with SIGINT ignored, ``nohup`` ignores SIGHUP,
and some CI runners do both; every process of such a run inherits the dispositions, and
Python then installs no KeyboardInterrupt handler. A test whose child must react to SIGINT
starts it through :func:`harshly`, so the child begins in that state however the suite itself
was started, and the child's own code must restore its handler (as a real user's program
would have to). The child also runs in a session of its own: whatever it signals as a group
is never the test run's.
"""

import sys

_EXEC_IGNORING = (
    'import os, signal, sys\n'
    'signal.signal(signal.SIGINT, signal.SIG_IGN)\n'
    'signal.signal(signal.SIGHUP, signal.SIG_IGN)\n'
    'os.execv(sys.executable, [sys.executable, *sys.argv[1:]])\n')


def harshly(argv):
    """``argv`` (a Python command: ``[sys.executable, ...]``) run with SIGINT and SIGHUP
    ignored at its start (an ``exec`` keeps ignored dispositions)."""
    if argv[0] != sys.executable:
        raise ValueError('harshly() starts Python commands: argv[0] must be sys.executable')
    return [sys.executable, '-c', _EXEC_IGNORING, *argv[1:]]
