"""``twodisk-sweep``: maps of the whole family of bodies, computed on Dask.

Usage::

    twodisk-sweep --b-over-a START STOP N --delta-over-a START STOP N --out FILE.nc
                  [--mass-model laminae|solid] [--reference-speed W] [--scheduler ADDRESS]
                  [--workers N] [--chunk-size K] [--plot DIR] [--fresh] [--keep-parts]
                  [--quiet]

Exit status: 0 written; 1 a task failed (finished chunks are kept: run again to resume);
2 bad input, unreachable scheduler or unwritable output (one line on stderr); 130
interrupted (finished chunks are kept: run the same command again to resume).
"""

import argparse
import os
from pathlib import Path
import sys

__all__ = ['main', 'PROG']

PROG = 'twodisk-sweep'


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _Usage(message)


class _Usage(Exception):
    pass


def _parser():
    parser = _Parser(
        prog=PROG,
        description='Compute maps of the rolling two-disk bodies over b/a and Delta/a '
                    '(a = g = M = 1) on Dask and save them as NetCDF.',
        epilog='Exit status: 0 done, 1 a task failed, 2 bad input / unreachable scheduler / '
               'unwritable output, 130 interrupted (run again to resume).')
    parser.add_argument('--b-over-a', nargs=3, required=True, metavar=('START', 'STOP', 'N'),
                        help='grid of b/a, inclusive: numpy.linspace(START, STOP, N)')
    parser.add_argument('--delta-over-a', nargs=3, required=True,
                        metavar=('START', 'STOP', 'N'),
                        help='grid of Delta/a, inclusive; points with Delta/a >= 1 are masked')
    parser.add_argument('--out', required=True, metavar='FILE.nc', help='NetCDF output file')
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
                        help='bodies per task (default 16, ~1 s of work)')
    parser.add_argument('--plot', metavar='DIR', help='write one PNG map per variable to DIR')
    parser.add_argument('--fresh', action='store_true',
                        help='discard the resume cache FILE.nc.parts/ of an earlier sweep')
    parser.add_argument('--keep-parts', action='store_true',
                        help='keep FILE.nc.parts/ after the output is written')
    parser.add_argument('--quiet', action='store_true', help='no progress line')
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


def _grid(name, values):
    from .run import linspace_grid
    start, stop = (_number(f'{name} START/STOP', v) for v in values[:2])
    return linspace_grid(name, start, stop, _integer(f'{name} N', values[2]))


def _output_refusal(out):
    """Why the output cannot be written (None if it can be tried)."""
    path = Path(out)
    if path.is_dir():
        return f'{out} is a directory'
    parent = path.parent if str(path.parent) else Path('.')
    if not parent.is_dir():
        return f'its folder {parent} does not exist'
    if not os.access(parent, os.W_OK | os.X_OK) or (path.exists()
                                                      and not os.access(path, os.W_OK)):
        return f'{parent} is not writable'
    return None


def _plot_refusal(folder):
    path = Path(folder)
    if path.exists() and not path.is_dir():
        return f'{folder} is not a directory'
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        return f'{folder}: {error.strerror or error}'
    if not os.access(path, os.W_OK | os.X_OK):
        return f'{folder} is not writable'
    return None


def _spec(args):
    from .run import DEFAULT_CHUNK_SIZE, SweepSpec
    b = _grid('--b-over-a', args.b_over_a)
    d = _grid('--delta-over-a', args.delta_over_a)
    speed = _number('--reference-speed', args.reference_speed)
    chunk = (DEFAULT_CHUNK_SIZE if args.chunk_size is None
             else _integer('--chunk-size', args.chunk_size))
    return SweepSpec(b, d, args.mass_model, speed, chunk)


def _fail(message, status=2):
    print(f'{PROG}: error: {" ".join(str(message).split())}', file=sys.stderr)
    return status


def main(argv=None):
    """Run the command line; returns the exit status (see the module docstring)."""
    try:
        args = _parser().parse_args(argv)
        workers = None if args.workers is None else _integer('--workers', args.workers)
        from .parts import PartsCache, PartsMismatch
        from .run import SweepError, dask_client, parts_folder, run_sweep
        try:
            spec = _spec(args)
        except SweepError as error:
            raise _Usage(str(error)) from None
    except _Usage as error:
        return _fail(error)
    refusal = _output_refusal(args.out)
    if refusal:
        return _fail(f'cannot write {args.out}: {refusal}')
    if args.plot and (refusal := _plot_refusal(args.plot)):
        return _fail(f'cannot write plots: {refusal}')
    progress = None if args.quiet else sys.stderr
    try:
        cache = PartsCache(parts_folder(args.out), spec.manifest(), fresh=args.fresh)
    except PartsMismatch as error:
        return _fail(error)
    except OSError as error:
        return _fail(f'cannot write {args.out}.parts/: {error.strerror or error}')
    try:
        with dask_client(args.scheduler, workers) as client:
            run = run_sweep(spec, client, out=args.out, progress=progress,
                            keep_parts=args.keep_parts)
    except (SweepError, PartsMismatch) as error:
        if not cache.finished():
            cache.remove()    # nothing to resume: leave no empty cache behind
        return _fail(error)
    except OSError as error:
        return _fail(f'cannot write {args.out}: {error}')
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted; finished chunks are kept in {args.out}.parts/ - run the '
              f'same command again to resume', file=sys.stderr)
        return 130
    except Exception as error:  # noqa: BLE001 (a task died: keep the cache, one line)
        return _fail(f'a task failed ({type(error).__name__}: {error}); finished chunks are '
                     f'kept in {args.out}.parts/, run again to resume', status=1)
    masked = int((run.dataset['failure'] != '').sum())
    print(f'{PROG}: wrote {run.output} ({spec.size} bodies, {masked} masked; '
          f'{run.computed} chunks computed, {run.resumed} resumed, {run.seconds:.1f} s)',
          file=sys.stderr)
    if args.plot:
        from ..plotting.sweep_maps import write_maps
        try:
            written = write_maps(run.dataset, args.plot)
        except (OSError, ValueError) as error:
            return _fail(f'cannot write plots to {args.plot}: {error}')
        print(f'{PROG}: wrote {len(written)} maps to {args.plot}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
