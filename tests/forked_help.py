"""Run many programs' ``--help`` in one interpreter: each in a child forked from this one.

Usage (by tests/test_entry_points.py): ``python forked_help.py JOBS.json`` where the file
holds ``[[label, kind, target, cwd, out_dir], ...]``, kind ``module`` (``python -m target
--help``) or ``script`` (``python target --help``). Each child changes to ``cwd``, writes
its stdout and stderr to ``out_dir/stdout`` and ``out_dir/stderr``, runs the program with
:mod:`runpy` as ``__main__`` with ``sys.argv = [target, '--help']`` (what ``python -m`` and
``python script`` do, with ``cwd`` or the script's folder first on ``sys.path`` as they
put it), and exits with
the program's status. Prints ``[[label, status], ...]`` as JSON. The children share the
interpreter's start-up and numpy's import (made here, once), the ~0.2 s each of them would
otherwise pay; everything of the program itself runs in the child as it would alone.
A child that runs past 60 s is killed (status -9).
"""

import json
import os
import runpy
import signal
import sys
import time

import numpy  # noqa: F401  (imported once, for every child)

TIMEOUT = 60.0


def _child(kind, target, cwd, out_dir):
    os.chdir(cwd)
    for fd, name in ((1, 'stdout'), (2, 'stderr')):
        handle = os.open(os.path.join(out_dir, name), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        os.dup2(handle, fd)
        os.close(handle)
    sys.argv = [target, '--help']
    status = 0
    try:
        # sys.path[0] is this file's folder (tests/): the program's own first entry instead
        if kind == 'module':
            sys.path[0] = cwd
            runpy.run_module(target, run_name='__main__', alter_sys=True)
        else:
            sys.path[0] = os.path.dirname(target)
            runpy.run_path(target, run_name='__main__')
    except SystemExit as stop:
        code = stop.code
        status = code if isinstance(code, int) else (0 if code is None else 1)
        if code is not None and not isinstance(code, int):
            print(code, file=sys.stderr)
    except BaseException:
        import traceback
        traceback.print_exc()
        status = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


def main():
    with open(sys.argv[1], encoding='utf-8') as handle:
        jobs = json.load(handle)
    results = []
    for label, kind, target, cwd, out_dir in jobs:
        sys.stdout.flush()
        pid = os.fork()
        if pid == 0:
            _child(kind, target, cwd, out_dir)
        deadline = time.monotonic() + TIMEOUT
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                break
            if time.monotonic() > deadline:
                os.kill(pid, signal.SIGKILL)
                _, status = os.waitpid(pid, 0)
                break
            time.sleep(0.002)
        results.append([label, os.waitstatus_to_exitcode(status)])
    print(json.dumps(results))


if __name__ == '__main__':
    main()
