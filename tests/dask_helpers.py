"""A real Dask cluster for tests: ``dask scheduler`` and ``dask worker`` processes on 127.0.0.1.

Each process gets a session (process group) of its own, so a test can kill one worker with
everything it started, and :func:`stop` ends them all (terminate, wait, kill the group).
"""

import contextlib
import os
from pathlib import Path
import signal
import socket
import subprocess
import sys
import time

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get('PYTHONPATH', ''))
ENV.pop('DASK_SCHEDULER_ADDRESS', None)
DASK = str(Path(sys.executable).with_name('dask'))
NO_DASHBOARD = ['--no-dashboard', '--dashboard-address', '127.0.0.1:0']


def free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def stop(procs):
    """Terminate the processes in the reverse order of their start (the workers before
    their scheduler), each waited for before the next; kill the group of any that overran.

    One at a time: a ``dask worker`` terminated while its scheduler closes gets both closes
    at once and can hang in the second (its log ends in a CancelledError; measured: 2 of 3
    runs of a one-worker cluster waited the whole 15 s for it, then killed it)."""
    for proc in reversed(procs):
        if proc.poll() is None:
            proc.terminate()
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)   # the group this helper started with the proc
            proc.wait(timeout=5)


def wait_for_workers(address, count, timeout=60):
    """Return once the scheduler at ``address`` has ``count`` workers (polls while it starts)."""
    from distributed import Client
    deadline = time.monotonic() + timeout
    while True:
        try:
            with Client(address, timeout='20s', set_as_default=False) as client:
                client.wait_for_workers(count, timeout=timeout)
            return
        except (OSError, TimeoutError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)


def _start_workers(folder, address, count, procs, logs, first=0):
    """Append ``count`` single-thread ``dask worker --no-nanny`` commands of the scheduler at
    ``address`` to ``procs`` (their logs, ``folder/worker{k}.log``, to ``logs``)."""
    for k in range(first, first + count):
        log = open(Path(folder) / f'worker{k}.log', 'w')
        logs.append(log)
        procs.append(subprocess.Popen(
            [DASK, 'worker', address, '--host', '127.0.0.1', '--nworkers', '1',
             '--nthreads', '1', '--no-nanny', *NO_DASHBOARD],
            stdout=log, stderr=subprocess.STDOUT, env=ENV, cwd=folder,
            start_new_session=True))


@contextlib.contextmanager
def cluster(folder, workers=2):
    """(address, [scheduler, worker...] Popen) of a scheduler and ``workers`` single-thread
    worker processes (each its own ``dask worker --no-nanny`` command: one process per
    worker, no nanny process to start, and nothing restarts a killed worker), logs in
    ``folder``; everything stopped on exit."""
    port = free_port()
    address = f'tcp://127.0.0.1:{port}'
    procs, logs = [], []
    try:
        log = open(Path(folder) / 'scheduler.log', 'w')
        logs.append(log)
        procs.append(subprocess.Popen(
            [DASK, 'scheduler', '--host', '127.0.0.1', '--port', str(port), *NO_DASHBOARD],
            stdout=log, stderr=subprocess.STDOUT, env=ENV, cwd=folder, start_new_session=True))
        _start_workers(folder, address, workers, procs, logs)
        wait_for_workers(address, workers)
        yield address, procs
    finally:
        stop(procs)
        for log in logs:
            log.close()


@contextlib.contextmanager
def worker_processes(folder, client, count=1):
    """[Popen] of ``count`` single-thread ``dask worker --no-nanny`` commands (each in a
    session of its own, logs in ``folder``) joined to the scheduler of ``client`` (e.g. one on
    threads of the test process: no scheduler process to start); returns once the scheduler
    has them all; every one stopped on exit."""
    procs, logs = [], []
    try:
        before = len(client.scheduler_info(n_workers=-1)['workers'])
        _start_workers(folder, client.scheduler.address, count, procs, logs)
        client.wait_for_workers(before + count, timeout=60)
        yield procs
    finally:
        stop(procs)
        for log in logs:
            log.close()


@contextlib.contextmanager
def blocks_computed_once():
    """Within: each task's bodies are computed once (by the first task of this process that
    asks for them) and handed out again, as copies, to every later task of this process with
    the same bodies, settings, exponent and general-path factories (``timed_chunk`` as the
    sweep's client and ``write_block`` call it). For modules whose claims are about the
    outputs — which blocks are written, resumed, refused, and where — not about the values:
    a block written at the wrong place, twice, or not at all still differs from the
    reference, and a task with other bodies or settings is computed afresh. Processes
    started by :func:`worker_processes` compute their blocks themselves."""
    import copy
    import pytest
    import numpy as np
    import twodisk_ros.sweep.run as run
    from twodisk_ros.sweep import general, store
    real = run.timed_chunk
    assert store.timed_chunk is real
    computed = {}

    def once(b_values, delta_values, *settings):
        key = (np.asarray(b_values, dtype=float).tobytes(),
               np.asarray(delta_values, dtype=float).tobytes(), settings,
               general.superellipse_body, general.lamina_mass)
        if key not in computed:
            computed[key] = real(b_values, delta_values, *settings)
        return copy.deepcopy(computed[key])

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(run, 'timed_chunk', once)
        patch.setattr(store, 'timed_chunk', once)
        yield
