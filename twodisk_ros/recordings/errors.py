"""Errors of the recording layer, and one-line reasons for operating-system errors."""

import os

__all__ = ['RecordingError', 'RecordingExistsError', 'io_errors', 'one_line',
           'os_error_reason']


class RecordingError(Exception):
    """A recording file cannot be written or read; the message is one line naming the path."""


class RecordingExistsError(RecordingError):
    """The recording file exists and the writer was not asked to replace it."""


def one_line(text):
    """Collapse whitespace so that an error message is a single line."""
    return ' '.join(str(text).split())


def os_error_reason(path, error, writing):
    """Explain an ``OSError`` raised while opening ``path``, in a few words."""
    parent = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        return 'it is a directory'
    if writing and not os.path.isdir(parent):
        return f'directory {parent} does not exist'
    return one_line(error.strerror or error)


class io_errors:  # noqa: N801 - used as a context manager, like contextlib's helpers
    """Context manager re-raising ``OSError`` as a one-line :class:`RecordingError`.

    ``with io_errors(path, 'write'):`` turns e.g. ENOSPC into
    ``RecordingError('cannot write recording run.mcap: No space left on device')``.
    """

    def __init__(self, path, what):
        self._path = path
        self._what = what

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, traceback):
        if exc_type is not None and issubclass(exc_type, OSError):
            raise RecordingError(f'cannot {self._what} recording {self._path}: '
                                 f'{one_line(exc.strerror or exc)}') from exc
        return False
