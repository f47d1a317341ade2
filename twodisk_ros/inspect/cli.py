"""``twodisk-inspect FILE.mcap [--json] [--plot PNG]``: summary and checks of a recording.

Exit status: 0 when every check passes, 1 when one fails, 2 when the file cannot be read or
the plot cannot be written (one line on stderr).
"""

import argparse
import json
import os
import sys
import warnings

import numpy as np

from ..io import RecordingError
from ..io.errors import one_line
from .inspection import inspect_recording
from .report import PROG, format_report

__all__ = ['main']


def _parser():
    parser = argparse.ArgumentParser(
        prog=PROG,
        description='Summarise a roller MCAP recording and check it offline against the '
                    'physics (contacts, no slip, energy, timestamps).',
        epilog='Exit status: 0 every check passes, 1 a check fails, 2 the file cannot be read '
               '(or the plot cannot be written).')
    parser.add_argument('file', help='the .mcap recording')
    parser.add_argument('--json', action='store_true',
                        help='print one JSON document (summary and checks) instead of text')
    parser.add_argument('--plot', metavar='PNG',
                        help='write a figure (a file name ending in .png): traces on the '
                             'ground, height of G, energy')
    return parser


def _plot_refusal(path):
    """Why the figure cannot go to ``path`` (None if it can be tried).

    The path must name a ``.png`` file: matplotlib would append ``.png`` to a path without
    suffix, and the report must name the file actually written.
    """
    if os.path.isdir(path):
        return 'it is a directory (give a file name ending in .png)'
    if not os.fspath(path).lower().endswith('.png'):
        return 'the file name must end in .png'
    return None


def _print(text):
    """Print to stdout; a reader that went away (``| head``) is not an error."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def main(argv=None):
    """Run ``twodisk-inspect``; return the exit status.

    0 when every check passes, 1 when a check fails, 2 when the file cannot be read or the
    plot cannot be written (one line on stderr, no traceback).

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; ``sys.argv[1:]`` if omitted.

    Returns
    -------
    int
    """
    args = _parser().parse_args(argv)
    # Values of a damaged file may overflow; the checks report non-finite results, so
    # numpy's floating-point warnings would only add lines to stderr.
    with warnings.catch_warnings(), np.errstate(all='ignore'):
        warnings.simplefilter('ignore', RuntimeWarning)
        return _run(args)


def _run(args):
    if args.plot:
        refusal = _plot_refusal(args.plot)
        if refusal:
            print(f'{PROG}: cannot write plot {args.plot}: {refusal}', file=sys.stderr)
            return 2
    try:
        inspection = inspect_recording(args.file)
    except RecordingError as error:
        print(f'{PROG}: {one_line(error) or "unreadable"}', file=sys.stderr)
        return 2
    except Exception as error:  # noqa: BLE001 - last resort: one line, never a traceback
        print(f'{PROG}: cannot read recording {args.file}: internal error: '
              f'{one_line(error) or "no message"} ({type(error).__name__})', file=sys.stderr)
        return 2
    if args.json:
        _print(json.dumps(inspection.as_dict(), indent=2, allow_nan=False, ensure_ascii=False))
    else:
        _print(format_report(inspection))
    if args.plot:
        try:
            from ..plotting.inspection import plot_inspection
            plot_inspection(inspection, args.plot)
        except Exception as error:  # noqa: BLE001 - any failure to plot is one line
            reason = one_line(error) or type(error).__name__
            if not isinstance(error, (OSError, ValueError)):
                reason = f'{reason} ({type(error).__name__})'
            print(f'{PROG}: cannot write plot {args.plot}: {reason}', file=sys.stderr)
            return 2
        if not args.json:
            _print(f'plot: {args.plot}')
    return 0 if inspection.passed else 1


if __name__ == '__main__':
    sys.exit(main())
