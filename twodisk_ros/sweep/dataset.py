"""The result of a sweep as an xarray Dataset, and its NetCDF file.

Coordinates ``b_over_a`` and ``delta_over_a`` (dimensionless, a = 1); one float64 variable per
name of :data:`~twodisk_ros.sweep.quantities.VARIABLES` with ``units`` and ``description``
attributes, NaN where a body failed; ``failure`` (str, '' on success) says why. The package
version and the sweep's parameters are global attributes. Files are NetCDF3 (scipy backend),
written to a hidden temporary name and renamed.
"""

from pathlib import Path

import numpy as np
import xarray as xr

from ..outputs import replacing
from .quantities import FAMILIES, VARIABLES

__all__ = ['build_dataset', 'write_netcdf', 'read_netcdf']


def build_dataset(b_over_a, delta_over_a, arrays, attrs):
    """The sweep's Dataset from flat per-point arrays.

    Parameters
    ----------
    b_over_a, delta_over_a : 1-D array_like
        Grid coordinates (dimensionless).
    arrays : dict
        name → flat array of ``len(b_over_a) * len(delta_over_a)`` values in C order (b/a
        major), for every name of ``VARIABLES`` and ``failure``.
    attrs : dict
        Global attributes (str, int or float values).

    Returns
    -------
    xarray.Dataset
    """
    b = np.asarray(b_over_a, dtype=float)
    d = np.asarray(delta_over_a, dtype=float)
    shape = (b.size, d.size)
    dims = ('b_over_a', 'delta_over_a')
    data = {}
    for name, (units, description) in VARIABLES.items():
        data[name] = (dims, np.asarray(arrays[name], dtype=float).reshape(shape),
                      {'units': units, 'description': description})
    data['stable_family'][2].update({
        'flag_values': np.array(sorted(FAMILIES), dtype=np.int32),
        'flag_meanings': ' '.join(FAMILIES[k].replace(' ', '_') for k in sorted(FAMILIES))})
    failure = np.asarray(arrays['failure'], dtype=str).reshape(shape)
    data['failure'] = (dims, failure, {'units': '1', 'description':
                                       "why the point is masked (NaN); '' if computed"})
    coords = {
        'b_over_a': ('b_over_a', b, {'units': '1', 'long_name': 'b/a',
                                     'description': 'semi-axis b over the semi-axis a along '
                                                    'the common axis (a = 1)'}),
        'delta_over_a': ('delta_over_a', d, {'units': '1', 'long_name': 'Delta/a',
                                             'description': 'half the distance between the '
                                                            'disk centres over a'}),
    }
    return xr.Dataset(data, coords=coords, attrs=dict(attrs))


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
    with xr.open_dataset(path, engine='scipy') as dataset:
        dataset = dataset.load()
    order = [name for name in (*VARIABLES, 'failure') if name in dataset.data_vars]
    dataset = dataset[order + [n for n in dataset.data_vars if n not in order]]
    if 'failure' in dataset:
        dataset['failure'] = dataset['failure'].astype(str)
    return dataset
