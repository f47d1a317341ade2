"""Parameter sweeps over the family of bodies, on Dask: ``twodisk-sweep`` and its library.

- :mod:`~twodisk_ros.sweep.chunks`: one task, :func:`~twodisk_ros.sweep.chunks.quantities` of
  a batch of bodies (no Dask), which batches what it can (the ellipse,
  :mod:`~twodisk_ros.sweep.batch`) and computes the rest one by one
  (:mod:`~twodisk_ros.sweep.quantities`, the ellipse's scalar reference;
  :mod:`~twodisk_ros.sweep.general`, any other lamina);
- :mod:`~twodisk_ros.sweep.spec`: the grid, the options and the blocks (one task each);
- :mod:`~twodisk_ros.sweep.run`: the Dask tasks, results, progress and resume;
- :mod:`~twodisk_ros.sweep.store`: the Zarr store, written by the workers, its own resume state;
- :mod:`~twodisk_ros.sweep.worker`: the set-up of each Dask worker (its C allocator);
- :mod:`~twodisk_ros.sweep.parts`: the resume cache ``FILE.nc.parts/`` of a NetCDF sweep;
- :mod:`~twodisk_ros.sweep.dataset`: the xarray Dataset, its NetCDF file and Zarr layout;
- :mod:`~twodisk_ros.sweep.progress`: the progress bar (tqdm) and the summary line;
- :mod:`~twodisk_ros.sweep.request`: the checks and size limits made before Dask starts;
- :mod:`~twodisk_ros.sweep.cli`: the command line (``python -m twodisk_ros.sweep``).

Units: a = 1, g = 1, M = 1, so lengths are in a, times in √(a/g) and angular speeds in √(g/a)
(docs/sweeps.md). Dask and xarray are imported only by the modules that need them.
"""

__all__ = ['chunks', 'quantities', 'batch', 'general', 'spec', 'run', 'store', 'worker', 'parts',
           'dataset', 'progress', 'request', 'cli']
