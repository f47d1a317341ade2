"""The resume cache of a sweep: finished chunks saved beside the output as they complete.

``FILE.nc.parts/`` holds ``manifest.json`` (the grid, the options and the chunking, so parts of
a different sweep are never mixed in) and one ``chunk-NNNNNN.npz`` per finished chunk, each
written to a temporary name and renamed (a chunk file is whole or absent, also after a kill).
Floats are kept bitwise (the manifest stores them as ``float.hex``), so a resumed sweep gives
the identical result.
"""

import json
import os
from pathlib import Path
import shutil

import numpy as np

__all__ = ['PartsCache', 'PartsMismatch', 'parts_folder']

MANIFEST = 'manifest.json'


def parts_folder(out):
    """The resume cache of output ``out``: ``out`` + '.parts' (beside it, never the output)."""
    return Path(str(out) + '.parts')


class PartsMismatch(ValueError):
    """The cache folder holds the parts of a different sweep."""


class PartsCache:
    """Finished chunks of one sweep in a folder (see the module docstring).

    Parameters
    ----------
    folder : path-like
        The cache folder (created if missing).
    manifest : dict
        JSON-serialisable description of the sweep; chunks are reused only under an equal
        manifest.
    fresh : bool
        Discard the chunks of a different (or the same) sweep instead of refusing.

    Raises
    ------
    PartsMismatch
        If the folder holds another sweep's parts and ``fresh`` is false.
    OSError
        If the folder cannot be created or written.
    """

    def __init__(self, folder, manifest, fresh=False):
        self.folder = Path(folder)
        self.manifest = json.loads(json.dumps(manifest))
        self.folder.mkdir(parents=False, exist_ok=True)
        path = self.folder / MANIFEST
        old = None
        if path.exists():
            try:
                old = json.loads(path.read_text(encoding='utf-8'))
            except (OSError, ValueError):
                old = None
        if old is not None and old != self.manifest and not fresh:
            raise PartsMismatch(f'{self.folder} holds the parts of a different sweep (grid or '
                                f'options differ); pass --fresh to discard them or choose '
                                f'another output')
        if fresh or old != self.manifest:
            for stale in self.folder.glob('chunk-*.npz'):
                stale.unlink()
            self._write_bytes(path, json.dumps(self.manifest, indent=1).encode('utf-8'))

    def _chunk_path(self, index):
        return self.folder / f'chunk-{int(index):06d}.npz'

    @staticmethod
    def _write_bytes(path, data):
        tmp = path.with_name(path.name + f'.tmp{os.getpid()}')
        with open(tmp, 'wb') as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)

    def finished(self):
        """Indices of the chunks saved (sorted)."""
        found = []
        for path in self.folder.glob('chunk-*.npz'):
            try:
                found.append(int(path.stem.split('-')[1]))
            except (IndexError, ValueError):
                continue
        return sorted(found)

    def save(self, index, arrays):
        """Save one chunk's arrays (name → array or list of str), atomically."""
        path = self._chunk_path(index)
        # the temporary name does not match chunk-*.npz: a half-written chunk is never listed
        tmp = path.with_name(f'.{path.stem}.tmp{os.getpid()}.npz')
        np.savez(tmp, **{name: np.asarray(value) for name, value in arrays.items()})
        os.replace(tmp, path)

    def load(self, index):
        """The arrays of a saved chunk (name → ndarray; strings as a unicode array)."""
        with np.load(self._chunk_path(index), allow_pickle=False) as data:
            return {name: data[name] for name in data.files}

    def remove(self):
        """Delete the folder and everything in it."""
        shutil.rmtree(self.folder, ignore_errors=True)
