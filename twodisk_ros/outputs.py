"""One rule for every file a command writes (standard library only).

Every command of the package that writes a file (``roller record:=``, ``twodisk-inspect
--plot/--csv/--npz``, ``twodisk-animate -o``, ``twodisk-sweep --out/--plot``, the figure
commands) checks its outputs with :func:`check_output` *before* doing any work, and writes
them through :func:`replacing`:

- an existing file is refused unless the user said so (``--overwrite``, ``overwrite:=true``);
- a path that exists but is not a regular file (a directory, a device such as ``/dev/null``,
  a FIFO, a socket) is refused even then: the command never replaces or removes what it did
  not create;
- a suffix the command cannot write (``--out maps.csv`` for a NetCDF file) is refused;
- a missing parent directory is refused (nothing is created behind the user's back, except
  the output directories a command documents);
- the new content goes to a hidden temporary file beside the target and replaces it in one
  atomic rename only when complete, so an interrupted or failed command leaves the old file
  byte for byte as it was (and no half-written new one).

An output that is a directory of files (a Zarr store, ``twodisk-sweep --out FILE.zarr``) is
checked by :func:`check_output_store`: the same rules, except that the existing path must be
a directory *the command recognises as its own output* (a store it wrote) to be replaced with
``--overwrite``; any other directory, and any file, is refused even then.

Each refusal is an :class:`OutputError` whose message is one line naming the path, what is
wrong and what is allowed; the commands print it and exit 2.
"""

import contextlib
import os
import stat
import tempfile

__all__ = ['OutputError', 'check_output', 'check_output_dir', 'check_output_store', 'replacing',
           'temporary_beside']


class OutputError(ValueError):
    """An output path the command refuses; the message is one line."""


def _kind(mode):
    for test, name in ((stat.S_ISDIR, 'a directory'), (stat.S_ISCHR, 'a character device'),
                       (stat.S_ISBLK, 'a block device'), (stat.S_ISFIFO, 'a FIFO'),
                       (stat.S_ISSOCK, 'a socket')):
        if test(mode):
            return name
    return 'not a regular file'


def _check_suffix(text, suffixes):
    if suffixes:
        suffix = os.path.splitext(text.rstrip(os.sep))[1].lower()
        if suffix not in suffixes:
            allowed = ', '.join(suffixes)
            raise OutputError(f'{text}: cannot write a {suffix or "suffix-less"} file here '
                              f'(allowed: {allowed})')


def _check_parent(text):
    parent = os.path.dirname(os.path.abspath(text))
    if not os.path.isdir(parent):
        raise OutputError(f'{text}: directory {parent} does not exist')
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f'{text}: directory {parent} is not writable')


def check_output(path, *, overwrite=False, suffixes=None, option='--overwrite'):
    """Check that ``path`` may be written; return it as given, or raise :class:`OutputError`.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.
    overwrite : bool
        The user allowed replacing an existing regular file.
    suffixes : sequence of str, optional
        The suffixes the command can write (lower case, with the dot: ``('.png',)``).
    option : str
        How the user says "replace it", quoted in the refusal (``--overwrite``,
        ``-p overwrite:=true``).
    """
    text = os.fspath(path)
    if not text:
        raise OutputError('the output path is empty')
    _check_suffix(text, suffixes)
    try:
        info = os.stat(text)
    except FileNotFoundError:
        info = None
    except OSError as error:
        raise OutputError(f'{text}: cannot use it as an output: '
                          f'{error.strerror or error}') from None
    if info is not None:
        if not stat.S_ISREG(info.st_mode):
            raise OutputError(f'{text} is {_kind(info.st_mode)}: the output must be a '
                              'regular file (or a new name)')
        if not overwrite:
            raise OutputError(f'{text} exists: pass {option} to replace it')
    _check_parent(text)
    return path


def check_output_store(path, *, overwrite=False, suffixes=None, option='--overwrite',
                       recognised=lambda path: False, what='store'):
    """Check that the directory output ``path`` may be written; return it or raise
    :class:`OutputError`.

    As :func:`check_output`, for an output that is a directory (a Zarr store): an existing
    ``path`` is refused unless ``overwrite``, and even then unless it is a directory for
    which ``recognised(path)`` is true (a ``what`` the command wrote itself; anything else
    it never replaces or removes).
    """
    text = os.fspath(path)
    if not text:
        raise OutputError('the output path is empty')
    _check_suffix(text, suffixes)
    if os.path.lexists(text):
        if os.path.islink(text) or not os.path.isdir(text):
            raise OutputError(f'{text} exists and is not a directory: the output must be a '
                              f'{what} directory (or a new name)')
        if not recognised(text):
            raise OutputError(f'{text} exists and is not a {what} written by this command: '
                              f'refused even with {option} (choose a new name)')
        if not overwrite:
            raise OutputError(f'{text} exists: pass {option} to replace it')
    _check_parent(text)
    return path


def check_output_dir(path, *, overwrite=False, names=(), option='--overwrite'):
    """Check an output directory and the files ``names`` that will be written into it.

    The directory may exist or will be created (its parent must exist). Each name that
    exists in it is refused unless ``overwrite``; a name that is not a regular file always.
    """
    text = os.fspath(path)
    if not text:
        raise OutputError('the output directory is empty')
    if os.path.exists(text) and not os.path.isdir(text):
        raise OutputError(f'{text} exists and is not a directory')
    parent = os.path.dirname(os.path.abspath(text))
    if not os.path.isdir(parent):
        raise OutputError(f'{text}: directory {parent} does not exist')
    if os.path.isdir(text):
        for name in names:
            check_output(os.path.join(text, name), overwrite=overwrite, option=option)
    return path


def _umask():
    """The process's umask, read without changing it where Linux tells it (os.umask sets
    it, for a moment, for every thread)."""
    try:
        with open('/proc/self/status', encoding='ascii') as status:
            for line in status:
                if line.startswith('Umask:'):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    umask = os.umask(0)
    os.umask(umask)
    return umask


def temporary_beside(path):
    """(descriptor, name) of a new hidden file beside ``path``, open for writing:
    ``.run.1a2b3c4d.partial.mcap`` for ``run.mcap`` (the suffix kept: writers choose the
    format from it), with the mode a plain ``open()`` would give (not mkstemp's 0600)."""
    directory, name = os.path.split(os.path.abspath(os.fspath(path)))
    stem, suffix = os.path.splitext(name)
    handle, temporary = tempfile.mkstemp(prefix=f'.{stem}.', suffix=f'.partial{suffix}',
                                         dir=directory)
    try:
        os.fchmod(handle, 0o666 & ~_umask())
    except BaseException:
        os.close(handle)
        os.remove(temporary)
        raise
    return handle, temporary


@contextlib.contextmanager
def replacing(path):
    """Write ``path`` through a hidden temporary file beside it, renamed over it at the end.

    Yields the temporary file's path (for writers that open files by name, such as
    matplotlib's ``savefig`` or xarray's ``to_netcdf``). On success the temporary file
    replaces ``path`` atomically; on any exception (also KeyboardInterrupt) it is removed and
    ``path`` is left as it was. Call :func:`check_output` first.
    """
    handle, temporary = temporary_beside(path)
    os.close(handle)
    try:
        yield temporary
        os.replace(temporary, os.fspath(path))
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(temporary)
        raise
