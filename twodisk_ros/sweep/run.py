"""A sweep over the family of bodies on Dask: grid, chunks, progress and resume.

The grid (b/a × Δ/a, inclusive as :func:`numpy.linspace`) is flattened in C order (b/a major)
and cut into chunks of consecutive points; each chunk is one Dask task running
:func:`~twodisk_ros.sweep.quantities.timed_chunk` on a worker (which imports the physics
only, not xarray). Results come back to the
client, which saves each finished chunk in the resume cache
(:class:`~twodisk_ros.sweep.parts.PartsCache`, ``FILE.nc.parts/``) as it completes, so
workers need no shared file system and an interrupted sweep recomputes only the chunks it had
not finished. The default chunk holds 16 bodies, ~0.5 s of work on one core (benchmarks/
sweep_rate.py measures the per-task overhead of the scheduler at a few ms). Every worker
gets the plugin :class:`~twodisk_ros.sweep.worker.SweepWorkerSetup` first, which undoes the
allocator setting of Dask's nanny that made a body 1.7× as costly on a worker as in a plain
process.

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

from .. import __version__
from ..outputs import OutputError, check_output
from .dataset import build_dataset, write_netcdf
from .parts import PartsCache, parts_folder
from .quantities import MASS_MODELS, VARIABLES, timed_chunk
from .request import DEFAULT_CHUNK_SIZE, SweepError, linspace_grid

__all__ = ['SweepSpec', 'SweepRun', 'SweepError', 'linspace_grid', 'dask_client', 'run_sweep',
           'parts_folder', 'DEFAULT_CHUNK_SIZE', 'CONNECT_TIMEOUT']

#: Seconds to reach a scheduler before giving up (s).
CONNECT_TIMEOUT = 5.0


@dataclass(frozen=True)
class SweepSpec:
    """What to compute: the grid (b/a, Δ/a), the mass model, μ's reference speed, chunking."""

    b_over_a: np.ndarray
    delta_over_a: np.ndarray
    mass_model: str = 'laminae'
    reference_speed: float = 0.5     #: kinematic |ω| for mu_required (units √(g/a))
    chunk_size: int = DEFAULT_CHUNK_SIZE

    def __post_init__(self):
        if self.mass_model not in MASS_MODELS:
            raise SweepError(f'mass model must be one of {", ".join(MASS_MODELS)}, got '
                             f'{self.mass_model!r}')
        if not (math.isfinite(self.reference_speed) and self.reference_speed >= 0):
            raise SweepError(f'reference speed must be finite and >= 0, got '
                             f'{self.reference_speed!r}')
        if int(self.chunk_size) != self.chunk_size or self.chunk_size < 1:
            raise SweepError(f'chunk size must be an integer >= 1, got {self.chunk_size!r}')

    @property
    def shape(self):
        """(number of b/a values, number of Δ/a values)."""
        return (len(self.b_over_a), len(self.delta_over_a))

    @property
    def size(self):
        """Number of bodies."""
        return self.shape[0] * self.shape[1]

    def points(self):
        """(b/a, Δ/a) of every grid point, flat, C order (b/a major)."""
        b, d = np.meshgrid(self.b_over_a, self.delta_over_a, indexing='ij')
        return b.ravel(), d.ravel()

    def chunks(self):
        """The slices of the flat grid, one per task."""
        size, step = self.size, int(self.chunk_size)
        return [slice(start, min(start + step, size)) for start in range(0, size, step)]

    def manifest(self):
        """JSON description of the sweep (floats as ``float.hex``: exact)."""
        return {'format': 1, 'package_version': __version__,
                'b_over_a': [float(x).hex() for x in self.b_over_a],
                'delta_over_a': [float(x).hex() for x in self.delta_over_a],
                'mass_model': self.mass_model,
                'reference_speed': float(self.reference_speed).hex(),
                'chunk_size': int(self.chunk_size), 'variables': list(VARIABLES)}

    def attrs(self):
        """Global attributes of the output."""
        b, d = self.b_over_a, self.delta_over_a
        return {
            'title': 'Quantities of the rolling two-disk bodies over b/a and Delta/a',
            'source': f'twodisk_ros {__version__} (twodisk_ros.sweep)',
            'package_version': __version__,
            'units_convention': 'a = 1, g = 1, M = 1: lengths in a, times in sqrt(a/g), '
                                'angular speeds in sqrt(g/a)',
            'mass_model': self.mass_model,
            'reference_speed': float(self.reference_speed),
            'reference_speed_units': 'sqrt(g/a)',
            'b_over_a_grid': f'linspace({float(b[0])!r}, {float(b[-1])!r}, {len(b)})',
            'delta_over_a_grid': f'linspace({float(d[0])!r}, {float(d[-1])!r}, {len(d)})',
            'chunk_size': int(self.chunk_size),
        }


@dataclass
class SweepRun:
    """The outcome of :func:`run_sweep`."""

    dataset: object           #: xarray.Dataset
    computed: int             #: chunks computed by this run
    resumed: int              #: chunks taken from the resume cache
    seconds: float            #: wall time (s)
    output: Path = None       #: the NetCDF file written, if any
    chunk_seconds: list = field(default_factory=list)   #: wall time per computed chunk (s)
    chunk_cpu_seconds: list = field(default_factory=list)   #: worker CPU time per chunk (s)


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
        finally:
            client.close()
    finally:
        if cluster is not None:
            cluster.close()


class _Progress:
    """A one-line progress report on a stream (redrawn on a terminal, else ~every 5 s)."""

    def __init__(self, stream, total_chunks, total_bodies, resumed_chunks, resumed_bodies):
        self.stream, self.total, self.bodies = stream, total_chunks, total_bodies
        self.done, self.done_bodies = resumed_chunks, resumed_bodies
        self.resumed = resumed_chunks
        self.start = self.last = time.monotonic()
        self.tty = bool(getattr(stream, 'isatty', lambda: False)())

    def update(self, bodies):
        self.done += 1
        self.done_bodies += bodies
        now = time.monotonic()
        if self.stream is None or (not self.tty and now - self.last < 5.0
                                   and self.done < self.total):
            return
        self.last = now
        elapsed = now - self.start
        rate = (self.done - self.resumed) / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else math.inf
        text = (f'twodisk-sweep: {self.done}/{self.total} chunks '
                f'({100 * self.done / self.total:.0f} %), {self.done_bodies}/{self.bodies} '
                f'bodies, {elapsed:.1f} s' + (f', ~{left:.0f} s left' if self.done < self.total
                                             else ''))
        self.stream.write(('\r' + text + ' ' * 4) if self.tty else text + '\n')
        if self.tty and self.done >= self.total:
            self.stream.write('\n')
        self.stream.flush()


def run_sweep(spec, client, out=None, progress=sys.stderr, on_chunk=None, fresh=False,
              keep_parts=False, overwrite=True):
    """Compute the sweep ``spec`` on the Dask ``client``; resume from ``out``'s cache.

    Parameters
    ----------
    spec : SweepSpec
    client : distributed.Client
    out : path-like, optional
        NetCDF file to write. Finished chunks are cached in ``out.parts/`` as they complete
        and reused by a later run of the same sweep; the cache is removed once ``out`` is
        written (unless ``keep_parts``). Without ``out`` nothing is written.
    progress : file, optional
        Stream for the progress line (None: silent).
    on_chunk : callable, optional
        ``on_chunk(index, computed)`` after each computed chunk is saved (``computed``
        counts this run's chunks); an exception raised there stops the sweep (saved chunks
        stay saved).
    fresh : bool
        Discard the cache of a different or earlier sweep instead of refusing / resuming.
    keep_parts : bool
        Keep ``out.parts/`` after writing ``out``.
    overwrite : bool
        Replace an existing ``out`` (checked again just before writing; the command line
        checks it before any work too). ``out`` is written through a hidden temporary file
        renamed over it (:func:`~twodisk_ros.outputs.replacing`): until the new file is
        complete the old one stays as it was.

    Returns
    -------
    SweepRun

    Raises
    ------
    SweepError
        If no body of the grid could be computed (every point masked): nothing is written
        and the resume cache is removed (unless ``keep_parts``); or if ``out`` cannot be
        written (the resume cache is kept: run again to write it).
    """
    from distributed import as_completed

    from .worker import SweepWorkerSetup

    started = time.perf_counter()
    # glibc's allocator as in a plain process: without it a body costs 1.7x the CPU time on a
    # worker (Dask's MALLOC_TRIM_THRESHOLD_; twodisk_ros.sweep.worker); idempotent per worker
    client.register_plugin(SweepWorkerSetup())
    cache = PartsCache(parts_folder(out), spec.manifest(), fresh=fresh) if out else None
    chunks = spec.chunks()
    b_flat, d_flat = spec.points()
    arrays = {name: np.full(spec.size, math.nan) for name in VARIABLES}
    arrays['failure'] = np.full(spec.size, '', dtype=object)
    done = set(cache.finished()) & set(range(len(chunks))) if cache else set()

    def store(index, result):
        part = chunks[index]
        for name in arrays:
            arrays[name][part] = result[name]

    for index in sorted(done):
        store(index, cache.load(index))
    bar = _Progress(progress, len(chunks), spec.size, len(done),
                    sum(chunks[i].stop - chunks[i].start for i in done))
    todo = [i for i in range(len(chunks)) if i not in done]
    futures = {}
    for index in todo:
        part = chunks[index]
        future = client.submit(timed_chunk, b_flat[part], d_flat[part], spec.mass_model,
                               spec.reference_speed, pure=False)
        futures[future] = index
    computed, chunk_seconds, chunk_cpu = 0, [], []
    try:
        for future in as_completed(futures, loop=client.loop):
            # dropping the last reference lets the worker forget the result (saved below)
            index = futures.pop(future)
            result, seconds, cpu = future.result()
            store(index, result)
            if cache is not None:
                cache.save(index, result)
            computed += 1
            chunk_seconds.append(seconds)
            chunk_cpu.append(cpu)
            bar.update(chunks[index].stop - chunks[index].start)
            if on_chunk is not None:
                on_chunk(index, computed)
    finally:
        pending = [f for f in futures if not f.done()]
        if pending:
            client.cancel(pending)
    arrays['failure'] = arrays['failure'].astype(str)
    if spec.size and np.all(arrays['failure'] != ''):
        if cache is not None and not keep_parts:
            cache.remove()      # nothing worth resuming: the same grid fails the same way
        first = (f'b/a = {float(b_flat[0])!r}, Delta/a = {float(d_flat[0])!r}: '
                 f'{arrays["failure"][0]}')
        raise SweepError(f'no body of the grid could be computed: all {spec.size} points are '
                         f'masked (e.g. {first}); nothing written')
    dataset = build_dataset(spec.b_over_a, spec.delta_over_a, arrays, spec.attrs())
    written = None
    if out:
        try:
            check_output(out, overwrite=overwrite)
            written = write_netcdf(dataset, out)
        except (OSError, OutputError) as error:
            raise SweepError(f'cannot write {out}: {getattr(error, "strerror", None) or error}'
                             f'; the finished chunks are kept in {parts_folder(out)}/, run '
                             f'again to write it') from None
        if not keep_parts:
            cache.remove()
    return SweepRun(dataset, computed, len(done), time.perf_counter() - started, written,
                    chunk_seconds, chunk_cpu)
