"""``twodisk-inspect FILE.mcap [--json] [--plot PNG]``: summary and checks of a recording.

Exit status: 0 when every check passes, 1 when one fails, 2 when the file cannot be read or
the plot cannot be written (one line on stderr).
"""

import argparse
import json
import os
import sys

from ..io import RecordingError
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
                        help='write a figure: traces on the ground, height of G, energy')
    return parser


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
    try:
        inspection = inspect_recording(args.file)
    except RecordingError as error:
        print(f'{PROG}: {error}', file=sys.stderr)
        return 2
    if args.json:
        _print(json.dumps(inspection.as_dict(), indent=2, allow_nan=False, ensure_ascii=False))
    else:
        _print(format_report(inspection))
    if args.plot:
        try:
            from ..plotting.inspection import plot_inspection
            plot_inspection(inspection, args.plot)
        except (OSError, ValueError) as error:
            print(f'{PROG}: cannot write plot {args.plot}: {" ".join(str(error).split())}',
                  file=sys.stderr)
            return 2
        if not args.json:
            _print(f'plot: {args.plot}')
    return 0 if inspection.passed else 1


if __name__ == '__main__':
    sys.exit(main())
