"""``twodisk-sweep``: maps of the whole family of bodies, computed on Dask.

Usage::

    twodisk-sweep --b-over-a START STOP N --delta-over-a START STOP N --out FILE.nc|FILE.zarr
                  [--exponent N1 [N2 ...] | --exponent-range START STOP N]
                  [--mass-model laminae|solid] [--reference-speed W] [--scheduler ADDRESS]
                  [--workers N] [--chunk-size K] [--plot DIR] [--overwrite] [--fresh]
                  [--keep-parts] [--quiet]

The whole command line is checked first (numbers, the size of the grid against the memory of
the machine, the outputs), before Dask or xarray is imported: a mistake costs a fraction of a
second. The third axis is the superellipse exponent n of both laminae (|x/b|^n + |y/a|^n
<= 1, 2 <= n <= 100; default 2 alone, the ellipse): n = 2 takes the batched closed forms, any
other n the per-body general path (docs/sweeps.md "The exponent axis"). Outputs follow
:mod:`twodisk_ros.outputs`: ``--out`` ends in ``.nc`` (a NetCDF file written by the client) or
``.zarr`` (a Zarr store written by the workers); an existing output
(``FILE.nc``, a finished ``FILE.zarr``, or a ``DIR/NAME.png`` of ``--plot``) is refused unless
``--overwrite``; files are written through hidden temporary names and renamed, so an
interrupted or failed sweep leaves them as they were. The resume state (``FILE.nc.parts/``,
or an interrupted ``FILE.zarr`` itself) is resumed with or without ``--overwrite``
(``--fresh`` discards it). docs/sweeps.md has the rules.

Exit status: 0 written; 1 a task failed (finished chunks are kept: run again to resume);
2 bad input, a grid too large for this machine, a grid without any valid body, unreachable
scheduler or unwritable output (one line on stderr); 130 interrupted (finished chunks are
kept: run the same command again to resume).
"""

import argparse
import os
from pathlib import Path
import shutil
import sys
import tempfile

import numpy as np

from ..outputs import OutputError, check_output, check_output_dir
from .request import (DEFAULT_CHUNK_SIZE, DEFAULT_STORE_CHUNK_SIZE, ELLIPSE_EXPONENT,
                      EXPONENT_RANGE, FORMATS, GENERAL_CHUNK_SIZE, MAX_BODIES, SweepError,
                      check_size, check_some_valid, default_chunk_size, exponent_values,
                      grid_range, linspace_grid, output_format, store_plan)

__all__ = ['main', 'PROG', 'MAX_WORKERS_PER_CORE']

PROG = 'twodisk-sweep'
#: A local cluster has at most this many worker processes per core of the machine.
MAX_WORKERS_PER_CORE = 4
#: Largest --reference-speed, in sqrt(g/a) (far beyond rolling speeds; its square stays finite
#: in every force of the map).
MAX_REFERENCE_SPEED = 1000.0


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _Usage(message)


class _Usage(Exception):
    pass


def _parser():
    parser = _Parser(
        prog=PROG,
        description='Compute maps of the rolling two-disk bodies over b/a and Delta/a '
                    '(a = g = M = 1), and over the superellipse exponent n of the laminae, on '
                    'Dask and save them as NetCDF (.nc) or Zarr (.zarr).',
        epilog='Exit status: 0 done, 1 a task failed, 2 bad input / grid too large or without '
               'a valid body / unreachable scheduler / unwritable output, 130 interrupted '
               '(run again to resume).')
    parser.add_argument('--b-over-a', nargs=3, required=True, metavar=('START', 'STOP', 'N'),
                        help='grid of b/a, inclusive: numpy.linspace(START, STOP, N)')
    parser.add_argument('--delta-over-a', nargs=3, required=True,
                        metavar=('START', 'STOP', 'N'),
                        help='grid of Delta/a, inclusive; points with Delta/a >= 1 are masked')
    low, high = EXPONENT_RANGE
    exponent = parser.add_mutually_exclusive_group()
    exponent.add_argument('--exponent', nargs='+', metavar='N',
                          help=f'superellipse exponents n of both laminae, |x/b|^n + |y/a|^n '
                               f'<= 1, strictly increasing, {low:g} <= n <= {high:g} (default '
                               f'2: the ellipse, batched; any other n: the per-body general '
                               f'path, far costlier per body)')
    exponent.add_argument('--exponent-range', nargs=3, metavar=('START', 'STOP', 'N'),
                          help='exponents numpy.linspace(START, STOP, N), inclusive, within '
                               f'[{low:g}, {high:g}]')
    parser.add_argument('--out', required=True, metavar='FILE.nc|FILE.zarr',
                        help='output: a NetCDF file (.nc, small maps) or a Zarr store (.zarr, '
                             'large maps, written by the workers, its own resume state); an '
                             'existing one is refused unless --overwrite (an interrupted '
                             '.zarr of the same sweep is resumed)')
    parser.add_argument('--mass-model', default='laminae', choices=('laminae', 'solid'),
                        help='laminae (two thin disks, default) or solid (convex hull)')
    parser.add_argument('--reference-speed', default='0.5', metavar='W',
                        help='kinematic angular speed for mu_required, in sqrt(g/a) '
                             '(default 0.5)')
    parser.add_argument('--scheduler', metavar='ADDRESS',
                        help='a running Dask scheduler, e.g. tcp://host:8786 (default: '
                             'DASK_SCHEDULER_ADDRESS, else a local cluster on every core)')
    parser.add_argument('--workers', metavar='N',
                        help='worker processes of the local cluster (default: every core)')
    parser.add_argument('--chunk-size', default=None, metavar='K',
                        help=f'the most bodies per task (default {DEFAULT_CHUNK_SIZE} for .nc, '
                             f'{DEFAULT_STORE_CHUNK_SIZE} for .zarr, {GENERAL_CHUNK_SIZE} with an '
                             f'exponent other than 2; fewer on small grids)')
    parser.add_argument('--plot', metavar='DIR',
                        help='write one PNG map per variable to DIR/NAME.png (DIR is created '
                             'if its parent exists)')
    parser.add_argument('--overwrite', action='store_true',
                        help='replace an existing FILE.nc, a finished FILE.zarr and existing '
                             'maps; the resume state is kept either way')
    parser.add_argument('--fresh', action='store_true',
                        help='discard the resume state of an earlier sweep (FILE.nc.parts/, '
                             'an interrupted FILE.zarr) and compute everything again')
    parser.add_argument('--keep-parts', action='store_true',
                        help='.nc: keep FILE.nc.parts/ after the output is written')
    parser.add_argument('--quiet', action='store_true',
                        help='no progress bar (there is none either when stderr is not a '
                             'terminal); the summary line is still printed')
    return parser


def _integer(name, text, low=1):
    try:
        value = int(text)
    except (TypeError, ValueError):
        raise _Usage(f'{name} must be an integer >= {low}, got {text!r}') from None
    if value < low:
        raise _Usage(f'{name} must be an integer >= {low}, got {text!r}')
    return value


def _number(name, text):
    try:
        return float(text)
    except (TypeError, ValueError):
        raise _Usage(f'{name} must be a number, got {text!r}') from None


def _grid_range(name, values):
    start, stop = (_number(f'{name} START/STOP', v) for v in values[:2])
    return grid_range(name, start, stop, _integer(f'{name} N', values[2]))


def _exponents(args):
    """The exponent axis of the command line (SweepError or _Usage, one line)."""
    if args.exponent_range is not None:
        start, stop, n = _grid_range('--exponent-range', args.exponent_range)
        exponent_values('--exponent-range', sorted({start, stop}))    # the ends named
        return exponent_values('--exponent-range', np.linspace(start, stop, n))
    if args.exponent is None:
        return None          # the ellipse alone, without an exponent axis (a 2-D output)
    return exponent_values('--exponent', [_number('--exponent', v) for v in args.exponent])


def _plot_names():
    """The files ``--plot DIR`` writes: one PNG per float variable of the Dataset."""
    from .variables import VARIABLES    # plain data
    return [f'{name}.png' for name in VARIABLES]


def _checked(args):
    """Everything of the command line checked, nothing allocated or imported beyond numpy and
    the names of the quantities (the spec is built only once the grid's size passed);
    returns (SweepSpec, format, workers).

    Raises _Usage, SweepError or OutputError (one line each)."""
    workers = None
    if args.workers is not None:
        workers = _integer('--workers', args.workers)
        most = MAX_WORKERS_PER_CORE * (os.cpu_count() or 1)
        if workers > most:
            raise _Usage(f'--workers {workers}: at most {most} worker processes '
                         f'({MAX_WORKERS_PER_CORE} per core of this machine)')
    from ..run.parameters import B_OVER_A     # (numpy: not needed for --help)
    b = _grid_range('--b-over-a', args.b_over_a)
    if not B_OVER_A[0] <= b[0] <= b[1] <= B_OVER_A[1]:
        # the node's range: beyond it the tables of one body grow past 65 536 nodes a cycle
        raise _Usage(f'--b-over-a {b[0]:g} {b[1]:g}: b/a must be within [{B_OVER_A[0]:g}, '
                     f'{B_OVER_A[1]:g}] (the range the physics is stated for)')
    d = _grid_range('--delta-over-a', args.delta_over_a)
    exponents = _exponents(args)
    counted = np.array([ELLIPSE_EXPONENT]) if exponents is None else exponents
    general = int(np.count_nonzero(counted != ELLIPSE_EXPONENT))
    speed = _number('--reference-speed', args.reference_speed)
    if not 0 <= speed <= MAX_REFERENCE_SPEED:
        raise _Usage(f'--reference-speed must be finite, 0 <= W <= {MAX_REFERENCE_SPEED:g}, '
                     f'got {args.reference_speed!r}')
    fmt = output_format(args.out)
    chunk = (default_chunk_size(b[2] * d[2], fmt, general > 0) if args.chunk_size is None
             else _integer('--chunk-size', args.chunk_size))
    if chunk > MAX_BODIES:
        raise _Usage(f'--chunk-size must be an integer from 1 to {MAX_BODIES} (the most '
                     f'bodies of a sweep), got {args.chunk_size!r}')
    if os.path.isdir(args.out) and fmt != 'zarr':    # said first: the suffix is not the problem
        raise OutputError(f'{args.out} is a directory: --out must name a .nc file or a .zarr '
                          f'store')
    if fmt is None:
        check_output(args.out, suffixes=tuple(FORMATS))    # the refusal of the suffix
    check_size(b[2], d[2], chunk, fmt, counted.size, general)
    check_some_valid(d[0])
    if fmt == 'zarr' and args.keep_parts:
        raise _Usage('--keep-parts is for a .nc output only (a .zarr store is its own resume '
                     'state)')
    from .spec import SweepSpec     # (numpy and the names of the quantities, no Dask)
    spec = SweepSpec(linspace_grid('--b-over-a', *b), linspace_grid('--delta-over-a', *d),
                     args.mass_model, speed, chunk, exponents)
    if fmt == 'zarr':
        store_plan(args.out, spec.manifest(), overwrite=args.overwrite, fresh=args.fresh)
    else:
        check_output(args.out, overwrite=args.overwrite, suffixes=tuple(FORMATS))
        parts = f'{args.out}.parts'
        if os.path.lexists(parts) and not os.path.isdir(parts):
            raise SweepError(f'{parts} (the resume cache of {args.out}) exists and is not a '
                             f'directory')
    if args.plot:
        check_output_dir(args.plot, overwrite=args.overwrite, names=_plot_names())
    return spec, fmt, workers


def _write_maps(dataset, folder, overwrite):
    """The maps of ``write_maps`` into ``folder``, each renamed into place only when all are
    drawn (a failure leaves the old maps as they were); returns the paths written."""
    from ..plotting.sweep_maps import write_maps
    folder = Path(folder)
    created = not folder.exists()
    folder.mkdir(exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix='.maps.', suffix='.partial', dir=folder))
    try:
        drawn = write_maps(dataset, staging)
        targets = [folder / path.name for path in drawn]
        for target in targets:          # a map that appeared meanwhile is refused too
            check_output(target, overwrite=overwrite)
        for path, target in zip(drawn, targets):
            os.replace(path, target)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        if created:
            shutil.rmtree(folder, ignore_errors=True)
        raise
    shutil.rmtree(staging, ignore_errors=True)
    return targets


def _fail(message, status=2):
    print(f'{PROG}: error: {" ".join(str(message).split())}', file=sys.stderr)
    return status


def main(argv=None):
    """Run the command line; returns the exit status (see the module docstring)."""
    try:
        args = _parser().parse_args(argv)
        spec, fmt, workers = _checked(args)
    except (_Usage, SweepError, OutputError) as error:
        return _fail(error)
    # checked: from here on xarray (run, dataset) and, in dask_client, Dask
    from .parts import PartsCache, PartsMismatch, parts_folder
    from .progress import summary_line
    from .run import dask_client, quiet_dask_loggers, run_sweep
    progress = None if args.quiet else sys.stderr
    cache = None
    kept = f'{args.out}.parts/' if fmt == 'netcdf' else args.out
    if fmt == 'netcdf':
        try:
            cache = PartsCache(parts_folder(args.out), spec.manifest(), fresh=args.fresh)
        except PartsMismatch as error:
            return _fail(error)
        except OSError as error:
            return _fail(f'cannot write {args.out}.parts/: {error.strerror or error}')
    try:
        with dask_client(args.scheduler, workers) as client:
            run = run_sweep(spec, client, out=args.out, progress=progress, fresh=args.fresh,
                            keep_parts=args.keep_parts, overwrite=args.overwrite)
    except (SweepError, PartsMismatch, OutputError) as error:
        if cache is not None and not cache.finished():
            cache.remove()    # nothing to resume: leave no empty cache behind
        return _fail(error)
    except OSError as error:
        return _fail(f'cannot write {args.out}: {error}')
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted; finished chunks are kept in {kept} - run the same '
              f'command again to resume', file=sys.stderr)
        # futures the stopped client left behind may report at the interpreter's exit
        quiet_dask_loggers()
        return 130
    except Exception as error:  # noqa: BLE001 (a task died: keep the state, one line)
        return _fail(f'a task failed ({type(error).__name__}: {error}); finished chunks are '
                     f'kept in {kept}, run again to resume', status=1)
    print(f'{PROG}: {summary_line(run)}', file=sys.stderr)
    if args.plot:
        try:
            written = _write_maps(run.dataset, args.plot, args.overwrite)
        except (OSError, ValueError) as error:
            return _fail(f'cannot write plots to {args.plot}: {error}')
        except KeyboardInterrupt:
            print(f'{PROG}: interrupted while drawing the maps; {run.output} is written',
                  file=sys.stderr)
            return 130
        print(f'{PROG}: wrote {len(written)} maps to {args.plot}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
