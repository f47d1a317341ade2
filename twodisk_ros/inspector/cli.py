"""``twodisk-inspect FILE.mcap [--json] [--plot PNG] [--csv CSV] [--npz NPZ] [--overwrite]``.

Summary and checks of a recording, and its states as a table.

Exit status (:mod:`twodisk_ros.inspector.status`): 0 PASS (every check passes and the run is
all there), 1 FAIL (a check fails), 4 INCOMPLETE (every check passes on the recovered part,
but the file is cut or damaged), 2 the file cannot be read, an output is refused (an existing
file without ``--overwrite``, a wrong suffix, a missing directory) or cannot be written (one
line on stderr).
"""

import argparse
import json
import os
import sys
import warnings

from ..recordings.errors import RecordingError, one_line
from ..outputs import OutputError, check_output, replacing
from .status import EXIT_UNUSABLE, PROG

# Light imports only up to here: ``--help`` and bad arguments answer without numpy, the
# reader or the physics, which ``main`` imports once the arguments are parsed.

__all__ = ['main']

#: (option, suffix, what) of every file the command may write.
_OUTPUTS = (('plot', '.png', 'plot'), ('csv', '.csv', 'CSV'), ('npz', '.npz', 'NPZ'))


def _parser():
    parser = argparse.ArgumentParser(
        prog=PROG,
        description='Summarise a roller MCAP recording, check it offline against the '
                    'physics (contacts, no slip, energy, timestamps) and against the run it '
                    'was meant to hold (duration x rate), and export its states.',
        epilog='Exit status: 0 PASS (every check passes and the whole run is there), 1 FAIL '
               '(a check fails), 4 INCOMPLETE (the checks pass on what was recovered, but '
               'the file is cut or damaged), 2 the file cannot be read or an output is '
               'refused or cannot be written.')
    parser.add_argument('file', help='the .mcap recording')
    parser.add_argument('--json', action='store_true',
                        help='print one JSON document (summary, checks, verdict) instead of '
                             'text')
    parser.add_argument('--plot', metavar='PNG',
                        help='write a figure (a file name ending in .png): traces on the '
                             'ground, height of G, energy')
    parser.add_argument('--csv', metavar='CSV',
                        help='write the states, one row per sample, as CSV (.csv; header '
                             '"name [unit]", floats that read back exactly)')
    parser.add_argument('--npz', metavar='NPZ',
                        help='write the same columns as a NumPy .npz (one array per column, '
                             'with "columns" and "units")')
    parser.add_argument('--overwrite', action='store_true',
                        help='replace existing --plot/--csv/--npz files (refused otherwise)')
    return parser


def _print(text):
    """Print to stdout; a reader that went away (``| head``) is not an error."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def main(argv=None):
    """Run ``twodisk-inspect``; return the exit status (module doc: 0, 1, 2 or 4).

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; ``sys.argv[1:]`` if omitted.

    Returns
    -------
    int
    """
    args = _parser().parse_args(argv)
    import numpy as np
    # Values of a damaged file may overflow; the checks report non-finite results, so
    # numpy's floating-point warnings would only add lines to stderr.
    with warnings.catch_warnings(), np.errstate(all='ignore'):
        warnings.simplefilter('ignore', RuntimeWarning)
        return _run(args)


def _refused_output(args):
    """One line saying why an output cannot be written, or None (checked before any work)."""
    chosen = {}
    for option, suffix, what in _OUTPUTS:
        path = getattr(args, option)
        if path is None:
            continue
        if os.path.isdir(path):
            return f'cannot write {what} {path}: it is a directory (give a file name ending ' \
                   f'in {suffix})'
        try:
            check_output(path, overwrite=args.overwrite, suffixes=(suffix,))
        except OutputError as error:
            return f'cannot write {what} {path}: {_without_path(str(error), path)}'
        real = os.path.realpath(path)
        if real in chosen:
            return f'cannot write {what} {path}: it is also the --{chosen[real]} output'
        chosen[real] = option
    return None


def _without_path(message, path):
    """An :class:`OutputError` message without the path it starts with (named already)."""
    text = os.fspath(path)
    if not message.startswith(text):
        return message
    rest = message[len(text):]
    return rest[2:] if rest.startswith(': ') else 'it' + rest


def _run(args):
    refusal = _refused_output(args)
    if refusal:
        print(f'{PROG}: {one_line(refusal)}', file=sys.stderr)
        return EXIT_UNUSABLE
    from .inspection import inspect_recording
    from .report import format_report
    try:
        inspection = inspect_recording(args.file)
    except RecordingError as error:
        print(f'{PROG}: {one_line(error) or "unreadable"}', file=sys.stderr)
        return EXIT_UNUSABLE
    except Exception as error:  # noqa: BLE001 - last resort: one line, never a traceback
        print(f'{PROG}: cannot read recording {args.file}: internal error: '
              f'{one_line(error) or "no message"} ({type(error).__name__})', file=sys.stderr)
        return EXIT_UNUSABLE
    if args.json:
        _print(json.dumps(inspection.as_dict(), indent=2, allow_nan=False, ensure_ascii=False))
    else:
        _print(format_report(inspection))
    for option, _, what in _OUTPUTS:
        path = getattr(args, option)
        if path is None:
            continue
        try:
            _write(option, inspection, path)
        except Exception as error:  # noqa: BLE001 - any failure to write is one line
            reason = one_line(error) or type(error).__name__
            if not isinstance(error, (OSError, ValueError)):
                reason = f'{reason} ({type(error).__name__})'
            print(f'{PROG}: cannot write {what} {path}: {reason}', file=sys.stderr)
            return EXIT_UNUSABLE
        if not args.json:
            _print(f'{option}: {path}')
    return inspection.exit_status


def _write(option, inspection, path):
    """Write one output through a temporary file renamed over ``path`` when complete."""
    if option == 'plot':
        from .figure import plot_inspection
        with replacing(path) as temporary:
            plot_inspection(inspection, temporary)
    else:
        from .export import write_outputs
        write_outputs(inspection, **{option: path})


if __name__ == '__main__':
    sys.exit(main())
