"""The result of a sweep as an xarray Dataset, its NetCDF file, and the layout of its Zarr store.

Coordinates ``exponent`` (the superellipse exponent n; 2 is the ellipse), ``b_over_a`` and
``delta_over_a`` (dimensionless, a = 1), the dimensions in that order when the request named
exponents; without them (the ellipse alone) the dimensions are ``b_over_a`` and
``delta_over_a`` and ``exponent`` is a scalar coordinate (2.0); one float64 variable per
name of :data:`~twodisk_ros.sweep.quantities.VARIABLES` with ``units`` and ``description``
attributes (and, when the grid has an exponent n != 2, ``general_path``: what the variable
means there, or why it is NaN), NaN where a body failed; ``failure`` (str, '' on success)
says why. The package version and the sweep's parameters are global attributes. NetCDF files
are NetCDF3 (scipy
backend), written to a hidden temporary name and renamed. A Zarr store
(:mod:`~twodisk_ros.sweep.store`) has the same variables, chunked, and ``computed``.
"""

from pathlib import Path

import numpy as np
import xarray as xr

from ..outputs import replacing
from .variables import FAMILIES, GENERAL_FAMILIES, GENERAL_MEANINGS, VARIABLES

__all__ = ['build_dataset', 'template_dataset', 'write_netcdf', 'read_netcdf', 'read_sweep',
           'COMPUTED']

#: The completion flags of a Zarr store (int8 per point; store.py).
COMPUTED = 'computed'
DIMS = ('exponent', 'b_over_a', 'delta_over_a')


def _variable_attrs(general=False):
    """name → attributes of every variable of the output (``failure`` included); with
    ``general`` (some exponent n != 2) each variable also says what it means on the per-body
    path (``general_path``) and ``stable_family`` has the flag of both families."""
    attrs = {name: {'units': units, 'description': description}
             for name, (units, description) in VARIABLES.items()}
    families = GENERAL_FAMILIES if general else FAMILIES
    attrs['stable_family'].update({
        'flag_values': np.array(sorted(families), dtype=np.int32),
        'flag_meanings': ' '.join(families[k].replace(' ', '_') for k in sorted(families))})
    if general:
        for name, meaning in GENERAL_MEANINGS.items():
            attrs[name]['general_path'] = meaning
    attrs['failure'] = {'units': '1', 'description': "why the point is masked (NaN); '' if "
                                                     "computed"}
    return attrs


def _coords(b, d, n):
    return {
        'exponent': ('exponent', n, {'units': '1', 'long_name': 'n',
                                     'description': 'superellipse exponent of both laminae, '
                                                    '|x/b|^n + |y/a|^n <= 1 (2: the ellipse)'}),
        'b_over_a': ('b_over_a', b, {'units': '1', 'long_name': 'b/a',
                                     'description': 'semi-axis b over the semi-axis a along '
                                                    'the common axis (a = 1)'}),
        'delta_over_a': ('delta_over_a', d, {'units': '1', 'long_name': 'Delta/a',
                                             'description': 'half the distance between the '
                                                            'disk centres over a'}),
    }


def _exponents(exponent):
    return np.atleast_1d(np.asarray(2.0 if exponent is None else exponent, dtype=float))


def _layout(b, d, n, axis):
    """(dims, shape, coordinates) of the output: 3-D with the exponent axis, else 2-D with
    ``exponent`` (one value) a scalar coordinate."""
    coords = _coords(b, d, n)
    if axis:
        return DIMS, (n.size, b.size, d.size), coords
    if n.size != 1:
        raise ValueError(f'{n.size} exponents need the exponent axis')
    coords['exponent'] = ((), n[0], coords['exponent'][2])
    return DIMS[1:], (b.size, d.size), coords


def build_dataset(b_over_a, delta_over_a, arrays, attrs, exponent=None, exponent_axis=None):
    """The sweep's Dataset from flat per-point arrays.

    Parameters
    ----------
    b_over_a, delta_over_a : 1-D array_like
        Grid coordinates (dimensionless).
    arrays : dict
        name → array of ``len(exponent) * len(b_over_a) * len(delta_over_a)`` values, flat in
        C order (exponent major) or of the grid's shape, for every name of ``VARIABLES`` and
        ``failure``.
    attrs : dict
        Global attributes (str, int or float values).
    exponent : 1-D array_like, optional
        The exponents n (default: 2 alone, the ellipse).
    exponent_axis : bool, optional
        Whether the output has the dimension ``exponent`` (default: when ``exponent`` is
        given); without it the Dataset is 2-D (b_over_a, delta_over_a) and ``exponent`` is a
        scalar coordinate.

    Returns
    -------
    xarray.Dataset
    """
    b = np.asarray(b_over_a, dtype=float)
    d = np.asarray(delta_over_a, dtype=float)
    n = _exponents(exponent)
    dims, shape, coords = _layout(b, d, n, exponent is not None if exponent_axis is None
                                  else exponent_axis)
    attrs_of = _variable_attrs(bool(np.any(n != 2.0)))
    data = {name: (dims, np.asarray(arrays[name], dtype=float).reshape(shape), attrs_of[name])
            for name in VARIABLES}
    failure = np.asarray(arrays['failure'], dtype=str).reshape(shape)
    data['failure'] = (dims, failure, attrs_of['failure'])
    return xr.Dataset(data, coords=coords, attrs=dict(attrs))


def template_dataset(b_over_a, delta_over_a, block, attrs, exponent=None, exponent_axis=None):
    """The sweep's Dataset with lazy (Dask) variables, and the encoding that chunks them in
    ``block`` = (1, rows, columns) (exponents ``exponent``, default 2 alone; without the
    exponent axis, as :func:`build_dataset`, the chunks are (rows, columns)): what
    ``to_zarr(compute=False, encoding=...)`` lays out as an empty store. Floats NaN,
    ``failure`` '' (variable-length UTF-8 strings), ``computed`` 0
    (int8; 1 once a block is complete). Returns (Dataset, encoding).

    Each variable is one Dask chunk (a graph of one task per variable, however many blocks:
    nothing of it is computed); the store's chunks come from the encoding."""
    import dask.array as da
    b = np.asarray(b_over_a, dtype=float)
    d = np.asarray(delta_over_a, dtype=float)
    n = _exponents(exponent)
    dims, shape, coords = _layout(b, d, n, exponent is not None if exponent_axis is None
                                  else exponent_axis)
    chunks = tuple(int(x) for x in block)[-len(dims):]
    attrs_of = _variable_attrs(bool(np.any(n != 2.0)))
    data = {name: (dims, da.full(shape, np.nan, chunks=-1), attrs_of[name])
            for name in VARIABLES}
    data['failure'] = (dims, da.full(shape, '', dtype=np.dtypes.StringDType(), chunks=-1),
                       attrs_of['failure'])
    data[COMPUTED] = (dims, da.zeros(shape, dtype=np.int8, chunks=-1), {
        'units': '1', 'description': '1 where the point was computed and written (its chunk '
                                     'complete), 0 where not yet (an interrupted sweep)'})
    dataset = xr.Dataset(data, coords=coords, attrs=dict(attrs))
    return dataset, {name: {'chunks': chunks} for name in dataset.data_vars}


def write_netcdf(dataset, path):
    """Write ``dataset`` to ``path`` (NetCDF3, scipy backend) through a hidden temporary file
    renamed over it when complete (:func:`~twodisk_ros.outputs.replacing`); returns the Path.

    Whether ``path`` may be replaced is the caller's check (``check_output``)."""
    path = Path(path)
    with replacing(path) as tmp:
        dataset.to_netcdf(tmp, engine='scipy')
    return path


def read_netcdf(path):
    """The Dataset of a sweep file, in memory, variables in the order written (file closed)."""
    return read_sweep(path)


def read_sweep(path):
    """The Dataset of a sweep's output, NetCDF file or Zarr store (the engine is chosen by
    xarray), in memory, variables in the order written, ``failure`` as ``str``."""
    with xr.open_dataset(path) as dataset:
        dataset = dataset.load()
    order = [name for name in (*VARIABLES, 'failure') if name in dataset.data_vars]
    dataset = dataset[order + [n for n in dataset.data_vars if n not in order]]
    if 'failure' in dataset:     # (numpy's StringDType from Zarr: str through object)
        dataset['failure'] = dataset['failure'].astype(object).astype(str)
    return dataset
