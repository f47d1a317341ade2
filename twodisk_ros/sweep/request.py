"""A sweep's request checked before anything is allocated or Dask is imported.

numpy only (no Dask, no xarray, no physics): ``twodisk-sweep`` validates its whole command
line here, so a typo costs the start of Python, not the start of Dask.

- :func:`grid_range` checks START, STOP, N of a grid (without building it) and
  :func:`linspace_grid` builds it;
- :func:`check_size` estimates the memory and work of a grid and refuses a runaway one;
- :func:`check_some_valid` refuses a grid in which no body can be valid (every Δ/a ≥ 1);
- :func:`exponent_values` checks the superellipse exponents of the third axis (2 ≤ n ≤ 100);
- :func:`output_format` tells the output's format by its suffix, :func:`store_info` what an
  existing Zarr store holds (its JSON metadata only, without zarr).

Memory estimate (bytes, measured on this machine with ``benchmarks``-style scripts, peak RSS
of the client process, rounded up): :data:`BYTES_PER_BODY` for the result arrays, the
xarray Dataset and its NetCDF encoding (0.3 KiB with empty ``failure`` strings, 0.9 KiB with
~100-character ones; a failure is at most 200 characters); for a Zarr store the client holds
no results, only :data:`BYTES_PER_BODY_ZARR` (the completion flags read to resume, the
``failure`` strings read to count the masked points); :data:`BYTES_PER_TASK` per Dask task
(future, task state and its graph in the client and the local scheduler: 18 KiB peak per task
for 20 000 tasks); :data:`BYTES_PER_AXIS_VALUE` for the manifest of the resume state.
"""

import json
import math
import os

import numpy as np

from ..limits import LimitError, check_memory, describe_bytes

__all__ = ['SweepError', 'linspace_grid', 'grid_range', 'estimate', 'check_size',
           'check_some_valid', 'default_chunk_size', 'output_format', 'store_info',
           'StoreInfo', 'FORMATS', 'DEFAULT_CHUNK_SIZE', 'DEFAULT_STORE_CHUNK_SIZE',
           'MIN_CHUNKS', 'MAX_BODIES', 'ELLIPSE_EXPONENT', 'EXPONENT_RANGE',
           'GENERAL_CHUNK_SIZE', 'GENERAL_CORE_SECONDS_PER_BODY', 'exponent_values',
           'BYTES_PER_BODY', 'BYTES_PER_BODY_ZARR', 'BYTES_PER_TASK', 'BYTES_PER_AXIS_VALUE',
           'CORE_SECONDS_PER_BODY', 'STORE_MANIFEST', 'STORE_STATE']

#: Bodies per task of a NetCDF sweep (the default of the library too): ~0.4 s of work on one
#: core with the batched path (~3 ms a body, benchmarks/sweep_rate.py), so the scheduler's
#: ~1 ms per task stays below 1 % (16-body tasks spent ~5 % on it: 100 x 100 in 16.8 s, not
#: 13.6 s).
DEFAULT_CHUNK_SIZE = 128
#: Bodies per task of a Zarr sweep: one chunk of every variable, 17 files of a few kB; far
#: fewer files, tasks and client reads (~0.3 ms per chunk) than 16-body chunks on the large
#: maps Zarr is for (docs/sweeps.md "Scaling"; benchmarks/sweep_scaling.py).
DEFAULT_STORE_CHUNK_SIZE = 1024
#: Bodies per task when the grid has an exponent n != 2 (the per-body general path, seconds
#: to minutes a body: GENERAL_CORE_SECONDS_PER_BODY), so that a task stays short enough to
#: resume from and a small map still spreads over the cores. Blocks have one shape over the whole grid (Zarr's regular
#: chunks), so the n = 2 plane of a mixed grid is cut as finely.
GENERAL_CHUNK_SIZE = 8
#: Without --chunk-size a grid is cut into at least this many tasks (smaller chunks on small
#: grids), so that a small map still spreads over the cores.
MIN_CHUNKS = 16
#: Output suffix → format.
FORMATS = {'.nc': 'netcdf', '.zarr': 'zarr'}
#: Attributes of a sweep's Zarr store: the manifest (JSON) and 'complete' / 'incomplete'.
STORE_MANIFEST, STORE_STATE = 'sweep_manifest', 'sweep_state'
#: At most this many bodies in one sweep (~10 core-hours at CORE_SECONDS_PER_BODY).
MAX_BODIES = 10_000_000
#: Client memory per body (B): result arrays, Dataset, NetCDF encoding (see the docstring).
BYTES_PER_BODY = 2048
#: Client memory per body with a Zarr output (B; see the docstring).
BYTES_PER_BODY_ZARR = 64
#: Client and local-scheduler memory per task (B).
BYTES_PER_TASK = 20 * 1024
#: Memory per grid value of the resume cache's manifest (float.hex strings) (B).
BYTES_PER_AXIS_VALUE = 256
#: Work per body in a Dask worker (core-seconds; docs/sweeps.md "Cost"): the batched path
#: measured ~3 ms on the benchmark's map; thin bodies need finer tables, hence the margin.
CORE_SECONDS_PER_BODY = 0.004
#: Work per body of the general path (exponent n != 2: LaminaBody, its cycle, dynamics and
#: contact-force tables; core-seconds). Measured on main of 26 Nov (b/a = 1, Δ/a = 0.5, load
#: average 2-3 on 2 cores): 0.56 s at n = 4, 4.2 s at n = 10, 165 s at n = 2.5 (and ~340 s
#: at n = 2.0001 on an earlier build), 75-97 % in the certified equilibrium search
#: (docs/sweeps.md "The exponent axis"); benchmarks/sweep_exponent.py measures it in make bench.
GENERAL_CORE_SECONDS_PER_BODY = 10.0
#: The exponent of the ellipse: its batched closed forms (:mod:`~twodisk_ros.sweep.batch`).
ELLIPSE_EXPONENT = 2.0
#: Allowed superellipse exponents n (|x/b|^n + |y/a|^n <= 1), inclusive.
EXPONENT_RANGE = (2.0, 100.0)


class SweepError(Exception):
    """A sweep cannot start or go on (bad input, unreachable scheduler, unwritable output)."""


def grid_range(name, start, stop, n):
    """Checked ``(start, stop, n)`` of the grid ``numpy.linspace(start, stop, n)``.

    Raises
    ------
    SweepError
        Non-finite or non-positive ends, n < 1, a reversed range, or an empty one (n > 1 with
        start == stop, or n = 1 with start != stop).
    """
    try:
        start, stop = float(start), float(stop)
    except (TypeError, ValueError):
        raise SweepError(f'{name}: START and STOP must be numbers, got {start!r} {stop!r}') \
            from None
    if isinstance(n, float) and not n.is_integer():
        raise SweepError(f'{name}: N must be an integer >= 1, got {n!r}')
    try:
        n = int(n)
    except (TypeError, ValueError, OverflowError):
        raise SweepError(f'{name}: N must be an integer >= 1, got {n!r}') from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise SweepError(f'{name}: START and STOP must be finite, got {start!r} {stop!r}')
    if n < 1:
        raise SweepError(f'{name}: N must be >= 1, got {n}')
    if start <= 0:
        raise SweepError(f'{name}: START must be > 0, got {start!r}')
    if stop < start:
        raise SweepError(f'{name}: reversed range, STOP {stop!r} < START {start!r}')
    if (n > 1) == (stop == start):
        raise SweepError(f'{name}: empty range: N = {n} points from {start!r} to {stop!r} '
                         f'(N = 1 needs START = STOP, N > 1 needs START < STOP)')
    return start, stop, n


def linspace_grid(name, start, stop, n):
    """The inclusive grid ``numpy.linspace(start, stop, n)`` of a ratio, validated
    (:func:`grid_range`; n is not checked against memory here, see :func:`check_size`)."""
    start, stop, n = grid_range(name, start, stop, n)
    return np.linspace(start, stop, n)


def exponent_values(name, values):
    """The exponents of the third axis as a float array: each finite, within
    :data:`EXPONENT_RANGE`, strictly increasing (so each is one plane of the grid).

    Raises
    ------
    SweepError
        One line naming the bad value and what is allowed.
    """
    low, high = EXPONENT_RANGE
    out = []
    for value in values:
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise SweepError(f'{name}: exponents must be numbers, got {value!r}') from None
        if not (math.isfinite(number) and low <= number <= high):
            raise SweepError(f'{name}: the superellipse exponent must be finite and within '
                             f'[{low:g}, {high:g}] (2 is the ellipse), got {number!r}')
        out.append(number)
    if not out:
        raise SweepError(f'{name}: give at least one exponent')
    if any(later <= earlier for earlier, later in zip(out, out[1:])):
        raise SweepError(f'{name}: exponents must be strictly increasing, got '
                         f'{" ".join(repr(float(x)) for x in out)}')
    return np.array(out, dtype=float)


def default_chunk_size(bodies, fmt='netcdf', general=False):
    """Bodies per task when --chunk-size is not given: :data:`DEFAULT_CHUNK_SIZE` (NetCDF) or
    :data:`DEFAULT_STORE_CHUNK_SIZE` (Zarr), :data:`GENERAL_CHUNK_SIZE` when the grid has an
    exponent n != 2 (``general``), smaller on a small grid so that it has at least
    :data:`MIN_CHUNKS` tasks. Depends on the grid only, so the same command resumes."""
    base = DEFAULT_STORE_CHUNK_SIZE if fmt == 'zarr' else DEFAULT_CHUNK_SIZE
    if general:
        base = GENERAL_CHUNK_SIZE
    return max(1, min(base, math.ceil(bodies / MIN_CHUNKS)))


def estimate(n_b, n_delta, chunk_size, fmt='netcdf', n_exponent=1, n_general=0):
    """(bytes of client memory, core-seconds of work) of a sweep of ``n_exponent`` ×
    ``n_b`` × ``n_delta`` bodies (``n_general`` of the exponents not 2: the per-body path)
    written as ``fmt`` ('netcdf' or 'zarr'); tasks counted as if the grid were cut into runs
    of ``chunk_size`` (rectangular blocks give at most twice as many)."""
    plane = n_b * n_delta
    bodies = n_exponent * plane
    tasks = 2 * n_exponent * -(-plane // max(1, int(chunk_size)))
    per_body = BYTES_PER_BODY_ZARR if fmt == 'zarr' else BYTES_PER_BODY
    memory = (bodies * per_body + tasks * BYTES_PER_TASK
              + (n_b + n_delta + n_exponent) * BYTES_PER_AXIS_VALUE)
    work = ((n_exponent - n_general) * plane * CORE_SECONDS_PER_BODY
            + n_general * plane * GENERAL_CORE_SECONDS_PER_BODY)
    return memory, work


def _hours(seconds):
    hours = seconds / 3600
    return f'{hours:.3g} core-hours' if hours >= 0.1 else f'{seconds:.3g} core-seconds'


def check_size(n_b, n_delta, chunk_size, fmt='netcdf', n_exponent=1, n_general=0):
    """Refuse a sweep that needs more than :data:`MAX_BODIES` bodies or more memory than
    :func:`~twodisk_ros.limits.memory_limit` allows (SweepError, one line); the arguments
    are those of :func:`estimate`."""
    bodies = n_exponent * n_b * n_delta
    memory, work = estimate(n_b, n_delta, chunk_size, fmt, n_exponent, n_general)
    grid = f'{n_b} x {n_delta}' if n_exponent == 1 else f'{n_exponent} x {n_b} x {n_delta}'
    what = (f'the grid of {grid} = {bodies} bodies in tasks of {chunk_size} '
            f'(~{_hours(work)} of work)')
    if bodies > MAX_BODIES:
        raise SweepError(f'{what} would need ~{describe_bytes(memory)} of memory; allowed: '
                         f'at most {MAX_BODIES} bodies')
    try:
        check_memory(memory, what)
    except LimitError as error:
        hint = '' if fmt == 'zarr' else ', a .zarr output far less'
        raise SweepError(f'{error} (a larger --chunk-size needs less{hint})') from None
    return memory, work


def check_some_valid(delta_start):
    """Refuse a Δ/a grid whose every point has Δ/a ≥ 1: no body of it can be built (the disks
    of such a body do not interlock), so the sweep would compute nothing."""
    if delta_start >= 1.0:
        raise SweepError(f'--delta-over-a: every point has Delta/a >= 1 (START = '
                         f'{delta_start!r}): no body of the grid is valid (needs 0 < Delta/a '
                         f'< 1)')


def output_format(path):
    """'netcdf' or 'zarr' by the suffix of ``path`` (lower case), None for another one."""
    return FORMATS.get(os.path.splitext(os.fspath(path).rstrip('/'))[1].lower())


class StoreInfo:
    """What an existing Zarr store of a sweep holds: its ``manifest`` (dict) and whether the
    sweep finished (``complete``)."""

    def __init__(self, manifest, complete):
        self.manifest, self.complete = manifest, complete


def store_info(path):
    """The :class:`StoreInfo` of the sweep store at ``path``, or None if it is not one (no
    such directory, or a directory that is not a store written by ``twodisk-sweep``).

    Reads the store's root metadata (``zarr.json``) with :mod:`json` only."""
    try:
        with open(os.path.join(os.fspath(path), 'zarr.json'), encoding='utf-8') as handle:
            attrs = json.load(handle).get('attributes', {})
        manifest = json.loads(attrs[STORE_MANIFEST])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return StoreInfo(manifest, attrs.get(STORE_STATE) == 'complete')


def store_plan(path, manifest, *, overwrite=False, fresh=False):
    """What a sweep with ``manifest`` does with the Zarr output ``path``: 'create' (no such
    path), 'resume' (an interrupted store of the same sweep), or 'replace' (a store of this
    command that ``--overwrite`` or ``--fresh`` may discard); json only, no zarr.

    Rules (docs/sweeps.md "Outputs and --overwrite"): an interrupted store of the same sweep
    is resumed, with or without ``overwrite`` (``fresh`` discards it); a finished store is
    replaced only with ``overwrite``; an interrupted store of another grid or options only
    with ``overwrite`` or ``fresh``; anything else at ``path`` (a file, a foreign directory)
    never. Refusals raise :class:`~twodisk_ros.outputs.OutputError` or
    :class:`SweepError`, one line each.
    """
    from ..outputs import check_output_store
    text = os.fspath(path)
    info = store_info(text) if os.path.isdir(text) and not os.path.islink(text) else None
    if info is not None and not info.complete:
        if info.manifest == manifest and not fresh:
            return 'resume'
        if info.manifest != manifest and not (overwrite or fresh):
            raise SweepError(f'{text} holds an interrupted sweep of a different grid or '
                             f'options (or package version): pass --overwrite to replace '
                             f'it, or choose another name')
        overwrite = True
    check_output_store(text, overwrite=overwrite, suffixes=('.zarr',),
                       recognised=lambda p: info is not None, what='twodisk-sweep Zarr store')
    return 'create' if info is None else 'replace'
