"""A sweep over the family of bodies on Dask: tasks, results, progress and resume.

The grid is cut into blocks (:class:`~twodisk_ros.sweep.spec.SweepSpec`), each of one
exponent n; each block is one Dask task on a worker (:func:`~twodisk_ros.sweep.chunks.quantities`
of the block's batch: the batched ellipse for n = 2, body by body otherwise). Where the
results go depends on the output's suffix:

- ``FILE.nc`` (small maps): a task (:func:`~twodisk_ros.sweep.chunks.timed_chunk`) sends
  its block's values back to the client, which saves each finished block in the resume cache
  (:class:`~twodisk_ros.sweep.parts.PartsCache`, ``FILE.nc.parts/``) and writes the NetCDF
  file at the end. Workers need no shared file system; the client holds the whole map.
- ``FILE.zarr`` (large maps): the client lays out the store
  (:func:`~twodisk_ros.sweep.store.create_store`), and each task
  (:func:`~twodisk_ros.sweep.store.write_block`) writes its block into it and returns a few
  numbers; the client carries no data. The store's completion flags are the resume state.
  Workers and client must share the file system.

The default chunk holds 128 bodies for NetCDF, ~0.4 s of work on one core with the batched
path (:class:`~twodisk_ros.sweep.batch.Ellipses`), and 1024 for Zarr
(far fewer tasks, files and reads on large maps), against ~1 ms of scheduler CPU and a few ms
of client CPU per task (benchmarks/sweep_scaling.py; docs/sweeps.md "Scaling"). Every
worker gets the plugin :class:`~twodisk_ros.sweep.worker.SweepWorkerSetup` first, which
undoes the allocator setting of Dask's nanny that made a body 1.7× (per-body path) to 2.6×
(batched path, larger arrays) as costly on a worker as in a plain process.

Clusters (:func:`dask_client`): by default a ``LocalCluster`` of worker processes on every
core, listening on 127.0.0.1 only, without dashboard; or any running scheduler given by its
address (``tcp://host:port``) or by Dask's configuration (``DASK_SCHEDULER_ADDRESS``).
"""

from contextlib import contextmanager
from dataclasses import dataclass, field
import logging
import math
import os
from pathlib import Path
import sys
import time

import numpy as np

from ..outputs import OutputError, check_output
from .dataset import build_dataset, write_netcdf
from .parts import PartsCache, parts_folder
from .progress import SweepProgress
from .chunks import timed_chunk
from .variables import VARIABLES
from .request import DEFAULT_CHUNK_SIZE, SweepError, linspace_grid, output_format, store_plan
from .spec import SweepSpec

__all__ = ['SweepSpec', 'SweepRun', 'SweepError', 'linspace_grid', 'dask_client', 'run_sweep',
           'parts_folder', 'DEFAULT_CHUNK_SIZE', 'CONNECT_TIMEOUT']

#: Seconds to reach a scheduler before giving up (s).
CONNECT_TIMEOUT = 5.0


@dataclass
class SweepRun:
    """The outcome of :func:`run_sweep`."""

    dataset: object           #: xarray.Dataset (a Zarr store's: read lazily)
    computed: int             #: chunks computed by this run
    resumed: int              #: chunks taken from the resume state
    seconds: float            #: wall time (s)
    output: Path = None       #: the NetCDF file or Zarr store written, if any
    chunk_seconds: list = field(default_factory=list)   #: wall time per computed chunk (s)
    chunk_cpu_seconds: list = field(default_factory=list)   #: worker CPU time per chunk (s)
    chunk_write_seconds: list = field(default_factory=list)  #: Zarr: worker write time (s)
    bodies: int = 0           #: bodies of the grid
    bodies_computed: int = 0  #: bodies computed by this run
    masked: int = 0           #: points whose body could not be computed (failure != '')


def _check_address(address):
    """SweepError (one line) for an address Dask cannot parse, before a Client exists: a
    Client that fails on it leaves a half-built object whose finalizer waits 10 s and prints
    a traceback at exit."""
    from distributed.comm.addressing import get_address_host_port
    try:
        get_address_host_port(address)
    except ValueError as error:
        raise SweepError(f'scheduler address {address!r} is not valid ({error}); allowed: '
                         'tcp://HOST:PORT, tls://HOST:PORT or HOST:PORT') from None


def _probe(address, timeout):
    """SweepError (one line) at once when nothing accepts a TCP connection at ``address``
    (connection refused, unknown host): a Client retries a refused connection until its
    ``timeout`` (s) is over, so the user waited ``timeout`` seconds for nothing."""
    import socket
    from distributed.comm.addressing import get_address_host_port
    host, port = get_address_host_port(address)
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except OSError as error:
        reason = (f'no answer within {timeout:g} s' if isinstance(error, TimeoutError)
                  else type(error).__name__)
        raise SweepError(f'cannot reach the Dask scheduler at {address}: {reason}') from None


@contextmanager
def dask_client(scheduler=None, workers=None, timeout=CONNECT_TIMEOUT):
    """A ``distributed.Client``: to ``scheduler``, to Dask's configured address, or local.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running scheduler, e.g. ``tcp://127.0.0.1:8786``. Default: Dask's
        ``scheduler-address`` configuration (environment ``DASK_SCHEDULER_ADDRESS``), else a
        new ``LocalCluster``.
    workers : int, optional
        Worker processes of the LocalCluster (default: every core), one thread each.
    timeout : float
        Seconds to reach the scheduler (s).

    Raises
    ------
    SweepError
        If the scheduler cannot be reached within ``timeout``.
    """
    import dask
    from distributed import Client, LocalCluster

    address = scheduler or dask.config.get('scheduler-address', None)
    cluster = None
    try:
        if address:
            _check_address(address)
            _probe(address, timeout)
            try:
                client = Client(address, timeout=f'{timeout}s', set_as_default=False)
            except (OSError, TimeoutError, ValueError) as error:
                raise SweepError(f'cannot reach the Dask scheduler at {address} within '
                                 f'{timeout:g} s: {type(error).__name__}') from None
        else:
            cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                                   threads_per_worker=1, processes=True, host='127.0.0.1',
                                   dashboard_address=None, silence_logs=logging.CRITICAL,
                                   # no dashboard; the scheduler's health routes on a free
                                   # port of 127.0.0.1 (not 8787, which others may use)
                                   scheduler_kwargs={'dashboard': False,
                                                     'dashboard_address': '127.0.0.1:0'})
            client = Client(cluster, set_as_default=False)
        try:
            yield client
        except BaseException:
            # stopped (Ctrl-C, a failed task): the caller reports it in one line, so
            # Dask's own noise while the client closes early is not shown on top of it
            with quiet_dask_shutdown():
                client.close()
            raise
        client.close()
    finally:
        if cluster is not None:
            cluster.close()


#: Loggers through which Dask and asyncio report what goes wrong while a client closes
#: early (e.g. "Future exception was never retrieved ... TimeoutError" on a loaded machine).
SHUTDOWN_LOGGERS = ('asyncio', 'distributed', 'tornado')


def quiet_dask_loggers():
    """Let the :data:`SHUTDOWN_LOGGERS` and their children show only CRITICAL records; returns their previous
    levels ({name: level}). For a program whose sweep was stopped and said so in one line:
    futures its client left behind may still report when the interpreter exits."""
    names = set(SHUTDOWN_LOGGERS) | {
        name for name in logging.root.manager.loggerDict
        if name.startswith(tuple(f'{prefix}.' for prefix in SHUTDOWN_LOGGERS))}
    previous = {name: logging.getLogger(name).level for name in sorted(names)}
    for name in previous:          # their own levels too: Dask sets some (distributed.client)
        logging.getLogger(name).setLevel(logging.CRITICAL)
    return previous


@contextmanager
def quiet_dask_shutdown():
    """:func:`quiet_dask_loggers` within, their levels restored at exit: for the early close
    of a client whose sweep was stopped (the caller reports the stop)."""
    previous = quiet_dask_loggers()
    try:
        yield
    finally:
        for name, level in previous.items():
            logging.getLogger(name).setLevel(level)


def _collect(client, futures, bar, on_chunk, handle):
    """Wait for ``futures`` (future → chunk index) as they finish; ``handle(index, result)``
    returns the bodies of a chunk; cancels the rest on any exception (Ctrl-C included)."""
    from distributed import as_completed
    computed = 0
    try:
        for future in as_completed(futures, loop=client.loop):
            # dropping the last reference lets the scheduler forget the result
            index = futures.pop(future)
            bar.update(handle(index, future.result()))
            computed += 1
            if on_chunk is not None:
                on_chunk(index, computed)
    finally:
        pending = [f for f in futures if not f.done()]
        if pending:
            client.cancel(pending)
        bar.close()
    return computed


def _all_masked(spec, first_failure):
    b, d, n = spec.b_over_a[0], spec.delta_over_a[0], spec.exponent[0]
    where = f'b/a = {float(b)!r}, Delta/a = {float(d)!r}'
    if spec.general:
        where = f'n = {float(n)!r}, {where}'
    return SweepError(f'no body of the grid could be computed: all {spec.size} points are '
                      f'masked (e.g. {where}: {first_failure}); nothing written')


def run_sweep(spec, client, out=None, progress=sys.stderr, on_chunk=None, fresh=False,
              keep_parts=False, overwrite=True):
    """Compute the sweep ``spec`` on the Dask ``client``; resume from ``out``'s state.

    Parameters
    ----------
    spec : SweepSpec
    client : distributed.Client
    out : path-like, optional
        ``FILE.nc``: finished chunks are cached in ``FILE.nc.parts/`` as they complete and
        reused by a later run of the same sweep; the cache is removed once the file is
        written (unless ``keep_parts``). ``FILE.zarr``: the workers write each chunk into the
        store; an interrupted store of the same sweep is resumed (docs/sweeps.md). Without
        ``out`` nothing is written.
    progress : file, optional
        Stream for the progress bar (None, or not a terminal: none).
    on_chunk : callable, optional
        ``on_chunk(index, computed)`` after each computed chunk is saved (``computed``
        counts this run's chunks); an exception raised there stops the sweep (saved chunks
        stay saved).
    fresh : bool
        Discard the resume state of a different or earlier sweep instead of refusing /
        resuming.
    keep_parts : bool
        ``FILE.nc``: keep ``FILE.nc.parts/`` after writing the file.
    overwrite : bool
        Replace an existing output (a NetCDF file through a hidden temporary file renamed
        over it when complete; a finished Zarr store of this command is removed first).

    Returns
    -------
    SweepRun

    Raises
    ------
    SweepError
        If no body of the grid could be computed (every point masked): nothing is written
        and the resume state is removed (unless ``keep_parts``); a Zarr store that holds
        another sweep or that some worker cannot see; or if a NetCDF ``out`` cannot be
        written (the resume cache is kept: run again to write it).
    OutputError
        If ``out`` may not be written (see :mod:`twodisk_ros.outputs`).
    """
    from .worker import SweepWorkerSetup

    started = time.perf_counter()
    # glibc's allocator as in a plain process: without it a body costs 1.7x the CPU time on a
    # worker (Dask's MALLOC_TRIM_THRESHOLD_; twodisk_ros.sweep.worker); idempotent per worker
    client.register_plugin(SweepWorkerSetup())
    if out is not None and output_format(out) == 'zarr':
        run = _run_zarr(spec, client, Path(out), progress, on_chunk, fresh, overwrite)
    else:
        run = _run_in_memory(spec, client, out, progress, on_chunk, fresh, keep_parts,
                             overwrite)
    run.seconds = time.perf_counter() - started
    return run


def _run_in_memory(spec, client, out, progress, on_chunk, fresh, keep_parts, overwrite):
    """Results to the client, resume cache FILE.nc.parts/, NetCDF written at the end."""
    if out is not None and output_format(out) != 'netcdf':
        raise OutputError(f'{out}: cannot write this suffix (allowed: .nc, .zarr)')
    cache = PartsCache(parts_folder(out), spec.manifest(), fresh=fresh) if out else None
    blocks = spec.blocks()
    arrays = {name: np.full(spec.shape, math.nan) for name in VARIABLES}
    arrays['failure'] = np.full(spec.shape, '', dtype=object)
    done = set(cache.finished()) & set(range(len(blocks))) if cache else set()
    run = SweepRun(None, 0, len(done), 0.0, bodies=spec.size)

    def store(index, result):
        block = blocks[index]
        shape = arrays['failure'][block].shape
        for name in arrays:
            arrays[name][block] = np.asarray(result[name]).reshape(shape)
        return arrays['failure'][block].size

    for index in sorted(done):
        store(index, cache.load(index))

    def handle(index, finished):
        result, seconds, cpu = finished
        bodies = store(index, result)
        if cache is not None:
            cache.save(index, result)
        run.chunk_seconds.append(seconds)
        run.chunk_cpu_seconds.append(cpu)
        run.bodies_computed += bodies
        return bodies

    futures = {client.submit(timed_chunk, *spec.block_points(blocks[index]), spec.mass_model,
                             spec.reference_speed, spec.block_exponent(blocks[index]),
                             pure=False): index
               for index in range(len(blocks)) if index not in done}
    bar = SweepProgress(progress, spec.size, sum(arrays['failure'][blocks[i]].size
                                                 for i in done))
    run.computed = _collect(client, futures, bar, on_chunk, handle)
    failure = arrays['failure'].astype(str)
    arrays['failure'] = failure
    run.masked = int(np.count_nonzero(failure != ''))
    if spec.size and run.masked == spec.size:
        if cache is not None and not keep_parts:
            cache.remove()      # nothing worth resuming: the same grid fails the same way
        raise _all_masked(spec, failure.flat[0])
    run.dataset = build_dataset(spec.b_over_a, spec.delta_over_a, arrays, spec.attrs(),
                                exponent=spec.exponent, exponent_axis=spec.exponent_axis)
    if out:
        try:
            check_output(out, overwrite=overwrite)
            run.output = write_netcdf(run.dataset, out)
        except (OSError, OutputError) as error:
            raise SweepError(f'cannot write {out}: {getattr(error, "strerror", None) or error}'
                             f'; the finished chunks are kept in {parts_folder(out)}/, run '
                             f'again to write it') from None
        if not keep_parts:
            cache.remove()
    return run


def _run_zarr(spec, client, path, progress, on_chunk, fresh, overwrite):
    """The workers write the store; the client submits blocks and counts."""
    from . import store as zstore
    path = path.absolute()
    plan = store_plan(path, spec.manifest(), overwrite=overwrite, fresh=fresh)
    if plan == 'replace':
        zstore.remove_store(path)
    if plan != 'resume':
        zstore.create_store(path, spec)
    unseen = zstore.unseen_by_workers(client, path)
    if unseen:
        raise SweepError(f'{len(unseen)} Dask worker(s) cannot see {path} (e.g. {unseen[0]}): '
                         f'a .zarr output needs a file system shared by the client and every '
                         f'worker at the same path; use a .nc output otherwise')
    blocks = spec.blocks()
    done = zstore.complete_blocks(path, spec) if plan == 'resume' else set()
    run = SweepRun(None, 0, len(done), 0.0, output=path, bodies=spec.size)

    def handle(index, result):
        run.chunk_seconds.append(result['seconds'])
        run.chunk_cpu_seconds.append(result['cpu_seconds'])
        run.chunk_write_seconds.append(result['write_seconds'])
        run.bodies_computed += result['bodies']
        return result['bodies']

    def size(block):
        return math.prod(part.stop - part.start for part in block)

    futures = {client.submit(zstore.write_block, os.fspath(path), blocks[index],
                             spec.b_over_a[blocks[index][1]],
                             spec.delta_over_a[blocks[index][2]], spec.mass_model,
                             spec.reference_speed, spec.block_exponent(blocks[index]),
                             pure=False): index
               for index in range(len(blocks)) if index not in done}
    bar = SweepProgress(progress, spec.size, sum(size(blocks[i]) for i in done))
    run.computed = _collect(client, futures, bar, on_chunk, handle)
    run.masked = zstore.masked_count(path)
    if spec.size and run.masked == spec.size:
        first = str(zstore.open_store(path)['failure'].values.flat[0])
        zstore.remove_store(path)   # nothing worth resuming: the same grid fails the same way
        raise _all_masked(spec, first)
    zstore.finish_store(path)
    run.dataset = zstore.open_store(path)
    return run
