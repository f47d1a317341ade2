"""A fork server for the tests' short command-line runs (``python -m MODULE ARGS``,
``python -c CODE ARGS`` or ``python SCRIPT ARGS``): each run is a child forked from one interpreter that has already
started and imported numpy, instead of a new interpreter that starts and imports it again
(~0.25 s of CPU a run here).

What a child does is what ``python`` does with those arguments: ``sys.argv`` and
``sys.path[0]`` as ``python`` sets them, stdin ``/dev/null``, stdout and stderr to files, the
program run as ``__main__`` by :mod:`runpy` (``-m``) or ``exec`` (``-c``), and then the
interpreter's own exit: an uncaught exception prints its traceback and gives status 1,
``SystemExit`` its code, ``atexit`` handlers and thread joins as usual. Optionally the child
starts a session of its own (``new_session``) and limits its address space (``address_space``,
bytes). A run past its ``timeout`` is killed (its session, if it has one) and
:class:`subprocess.TimeoutExpired` raised, as :func:`subprocess.run` does.

The server is single-threaded (forking it is safe) and reads one JSON job a line on stdin,
answering one JSON line on stdout. Tests use it through :class:`Zygote` (a context manager).
"""

import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time


class Zygote:
    """A fork server started with environment ``env`` (the runs' environment)."""

    def __init__(self, env):
        self._folder = tempfile.mkdtemp(prefix='zygote-')
        self._server = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__)], env=env, stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, text=True, bufsize=1)
        self._count = 0

    def run(self, args, *, cwd, timeout=60.0, new_session=False, address_space=None):
        """:class:`subprocess.CompletedProcess` of ``python *args`` run in ``cwd``."""
        self._count += 1
        out = os.path.join(self._folder, f'{self._count}')
        job = {'args': [str(a) for a in args], 'cwd': str(cwd), 'out': out,
               'timeout': timeout, 'new_session': new_session, 'address_space': address_space}
        self._server.stdin.write(json.dumps(job) + '\n')
        answer = json.loads(self._server.stdout.readline())
        streams = []
        for name in ('stdout', 'stderr'):
            with open(f'{out}.{name}', encoding='utf-8', errors='replace') as handle:
                streams.append(handle.read())
            os.unlink(f'{out}.{name}')
        command = [sys.executable, *job['args']]
        if answer['timed_out']:
            raise subprocess.TimeoutExpired(command, timeout, *streams)
        return subprocess.CompletedProcess(command, answer['status'], *streams)

    def close(self):
        self._server.stdin.close()
        self._server.wait(timeout=30)
        self._server.stdout.close()
        os.rmdir(self._folder)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _child(job):
    """In the forked child: become ``python *job['args']`` (never returns normally: the
    program's end unwinds to the interpreter's exit)."""
    if job['new_session']:
        os.setsid()
    if job['address_space']:
        limit = int(job['address_space'])
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    os.chdir(job['cwd'])
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.close(null)
    for fd, name in ((1, 'stdout'), (2, 'stderr')):
        handle = os.open(f"{job['out']}.{name}", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(handle, fd)
        os.close(handle)
    import runpy
    first, *rest = job['args']
    if first == '-m':
        target, *rest = rest
        sys.argv = [target, *rest]
        sys.path[0] = os.getcwd()
        runpy.run_module(target, run_name='__main__', alter_sys=True)
    elif first == '-c':
        target, *rest = rest
        sys.argv = ['-c', *rest]
        sys.path[0] = ''
        exec(compile(target, '<string>', 'exec'), {'__name__': '__main__'})
    else:                                   # a script: python SCRIPT ARGS
        sys.argv = [first, *rest]
        sys.path[0] = os.path.dirname(os.path.abspath(first))
        runpy.run_path(first, run_name='__main__')
    raise SystemExit(0)


def _serve():
    import numpy  # noqa: F401  (the import every run shares)
    for line in sys.stdin:
        job = json.loads(line)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            _child(job)           # raises SystemExit through this frame in the child
        deadline = time.monotonic() + float(job['timeout'])
        timed_out = False
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                break
            if time.monotonic() > deadline:
                timed_out = True
                try:
                    (os.killpg if job['new_session'] else os.kill)(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                _, status = os.waitpid(pid, 0)
                break
            time.sleep(0.001)
        print(json.dumps({'status': os.waitstatus_to_exitcode(status),
                          'timed_out': timed_out}), flush=True)


if __name__ == '__main__':
    _serve()
