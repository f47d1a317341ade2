"""The Zarr store of a sweep: laid out by the client, filled chunk by chunk by the workers.

Layout (Zarr format 3, ``xarray.open_dataset(FILE.zarr)`` reads it): the coordinates and
variables of :func:`~twodisk_ros.sweep.dataset.build_dataset`, every variable chunked in the
sweep's blocks (:attr:`SweepSpec.block <twodisk_ros.sweep.spec.SweepSpec.block>`), so that
each task writes whole chunks that no other task touches, and one more variable,
``computed`` (int8): 1 where the point's block is complete, 0 (the fill value) where it is
not yet. The root attributes are the sweep's (:meth:`SweepSpec.attrs`) plus
``sweep_manifest`` (the grid and options, JSON) and ``sweep_state`` ('incomplete' until the
client has seen every block complete, then 'complete').

**Completion is the store's own state.** A task (:func:`write_block`, on a worker) computes
its block, writes the block's chunk of every variable (zarr region writes), and only then
its ``computed`` chunk. Zarr's local store writes each chunk object to a temporary name and
renames it, so an object is whole or absent; a worker killed before the flags are written
leaves them at 0, and the block counts as missing. To resume, the client reads ``computed`` (one byte per
point) and submits the blocks not complete (:func:`complete_blocks`); their chunks are
simply written again. A task run twice (a worker thought lost that was not) writes the same
bytes twice.

The store is created under a hidden temporary name beside the target and renamed into place
once its metadata is complete, so a store at the target path always has every variable.
"""

import contextlib
import json
import os
from pathlib import Path
import shutil
import tempfile
import time
import warnings

import numpy as np

from .dataset import COMPUTED, template_dataset
from .chunks import timed_chunk
from .variables import VARIABLES
from .request import STORE_MANIFEST, STORE_STATE

__all__ = ['create_store', 'remove_store', 'complete_blocks', 'write_block', 'finish_store',
           'open_store', 'masked_count', 'unseen_by_workers', 'store_bytes']


@contextlib.contextmanager
def _quiet_zarr():
    """Hide zarr's note that consolidated metadata is not part of the Zarr format 3
    specification (xarray and zarr-python read it; other readers list the store instead)."""
    with warnings.catch_warnings():
        warnings.filterwarnings('ignore', message='Consolidated metadata')
        yield


def create_store(path, spec):
    """Lay out the empty store of ``spec`` at ``path`` (which must not exist); returns the
    absolute Path. Written under a hidden name beside ``path``, renamed when complete."""
    path = Path(path).absolute()
    staging = Path(tempfile.mkdtemp(prefix=f'.{path.name}.', suffix='.partial',
                                    dir=path.parent))
    try:
        template, encoding = template_dataset(spec.b_over_a, spec.delta_over_a, spec.block,
                                              spec.attrs(), exponent=spec.exponent,
                                              exponent_axis=spec.exponent_axis)
        template.attrs.update({STORE_MANIFEST: json.dumps(spec.manifest()),
                               STORE_STATE: 'incomplete'})
        with _quiet_zarr():
            template.to_zarr(staging / 'store', mode='w-', compute=False, zarr_format=3,
                             consolidated=True, encoding=encoding)
        os.rename(staging / 'store', path)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return path


def remove_store(path):
    """Delete the store at ``path`` (the caller checked it is a sweep's store)."""
    shutil.rmtree(path)


def _block_minima(values, spec):
    """The smallest value of each block (flat, in the order of ``spec.blocks()``)."""
    for axis, step in enumerate(spec.block):
        values = np.minimum.reduceat(values, np.arange(0, values.shape[axis], step), axis=axis)
    return values.ravel()


def complete_blocks(path, spec):
    """Indices (into ``spec.blocks()``) of the blocks whose ``computed`` flags are all 1."""
    import zarr
    flags = zarr.open_array(Path(path) / COMPUTED, mode='r')
    try:    # a store without the exponent axis: the same points, one exponent
        return set(np.flatnonzero(_block_minima(flags[...].reshape(spec.shape), spec)
                                  == 1).tolist())
    except Exception:  # noqa: BLE001 (a damaged chunk object: look at the blocks one by one)
        found = set()
        for k, block in enumerate(spec.blocks()):
            try:
                if np.all(flags[block[-flags.ndim:]] == 1):
                    found.add(k)
            except Exception:  # noqa: BLE001 (unreadable: the block is computed again)
                pass
        return found


def write_block(path, block, b_values, delta_values, mass_model, reference_speed,
                exponent=2.0):
    """Compute one block and write it into the store at ``path`` (a Dask task; see the module
    docstring for the order of the writes).

    Parameters
    ----------
    path : str
        Absolute path of the store, as every worker sees it.
    block : (slice, slice, slice)
        The block's exponent (one), rows (b/a) and columns (Δ/a) in the grid (a store without
        the exponent axis is written at the rows and columns).
    b_values, delta_values : 1-D arrays
        The grid values of those rows and columns.
    mass_model, reference_speed, exponent
        As :func:`~twodisk_ros.sweep.chunks.timed_chunk` (``exponent``: the block's n).

    Returns
    -------
    dict
        ``bodies``, ``masked`` (count), ``seconds`` and ``cpu_seconds`` of the computation,
        ``write_seconds`` of the writes (s): no results travel back to the client.
    """
    import zarr
    b, d = np.meshgrid(b_values, delta_values, indexing='ij')
    result, seconds, cpu = timed_chunk(b.ravel(), d.ravel(), mass_model, reference_speed,
                                       exponent)
    start = time.perf_counter()
    group = zarr.open_group(path, mode='r+')       # the layout, from the consolidated metadata
    # (exponent, rows, columns), or (rows, columns) in a store without the exponent axis
    block = tuple(block)[-group[COMPUTED].ndim:]
    shape = (1, *b.shape)[-len(block):]
    failure = np.asarray(result['failure'], dtype=object).reshape(shape)
    for name in VARIABLES:
        group[name][block] = np.asarray(result[name], dtype=float).reshape(shape)
    group['failure'][block] = failure.astype(np.dtypes.StringDType())
    group[COMPUTED][block] = np.ones(shape, dtype=np.int8)      # last: the block is complete
    return {'bodies': int(b.size), 'masked': int(np.count_nonzero(failure != '')),
            'seconds': seconds, 'cpu_seconds': cpu,
            'write_seconds': time.perf_counter() - start}


def finish_store(path):
    """Mark the store 'complete' (root attribute, consolidated metadata rewritten)."""
    import zarr
    with _quiet_zarr():
        group = zarr.open_group(path, mode='r+', use_consolidated=False)
        group.attrs[STORE_STATE] = 'complete'
        zarr.consolidate_metadata(path)


def open_store(path):
    """The sweep's Dataset from the store, read lazily (``xarray.open_dataset``)."""
    import xarray as xr
    return xr.open_dataset(path, engine='zarr', chunks=None)


def masked_count(path):
    """Points of the store whose ``failure`` is not '' (read by the client at the end)."""
    import zarr
    failure = zarr.open_array(Path(path) / 'failure', mode='r')[...]
    return int(np.count_nonzero(failure != ''))


def store_bytes(path):
    """Bytes of the store's files (data and metadata)."""
    return sum(entry.stat().st_size for entry in Path(path).rglob('*') if entry.is_file())


def _sees(path):
    return os.path.isfile(os.path.join(path, 'zarr.json'))


def unseen_by_workers(client, path):
    """Addresses of the workers that cannot see the store at ``path`` (a Zarr sweep needs a
    file system shared by the client and every worker, mounted at the same path)."""
    seen = client.run(_sees, os.fspath(path))
    return sorted(address for address, ok in seen.items() if not ok)
