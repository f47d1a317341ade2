"""Parameter sweeps over the family of bodies, on Dask: ``twodisk-sweep`` and its library.

- :mod:`~twodisk_ros.sweep.quantities`: what is computed for one body (pure numpy/scipy);
- :mod:`~twodisk_ros.sweep.run`: the grid, chunks as Dask tasks, progress and resume;
- :mod:`~twodisk_ros.sweep.worker`: the set-up of each Dask worker (its C allocator);
- :mod:`~twodisk_ros.sweep.parts`: the resume cache ``FILE.nc.parts/``;
- :mod:`~twodisk_ros.sweep.dataset`: the xarray Dataset and its NetCDF file;
- :mod:`~twodisk_ros.sweep.request`: the checks and size limits made before Dask starts;
- :mod:`~twodisk_ros.sweep.cli`: the command line (``python -m twodisk_ros.sweep``).

Units: a = 1, g = 1, M = 1, so lengths are in a, times in √(a/g) and angular speeds in √(g/a)
(docs/sweeps.md). Dask and xarray are imported only by the modules that need them.
"""

__all__ = ['quantities', 'run', 'worker', 'parts', 'dataset', 'request', 'cli']
