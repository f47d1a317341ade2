"""What a sweep computes: the grid, the options and how the grid is cut into tasks (numpy only).

The grid is b/a × Δ/a (inclusive, as :func:`numpy.linspace`), b/a the first (slow) axis. It is
cut into rectangular **blocks** of at most ``chunk_size`` bodies: whole rows of Δ/a when a row
fits (several rows per block), else pieces of one row of near-equal length. One block is one
Dask task and, in a Zarr store, one chunk of every variable, so that no two tasks ever write
the same chunk (what makes the workers' parallel writes safe). Every block has the same shape
except at the far edges of the grid (Zarr's regular chunk grid).

No Dask, no xarray here (numpy, and the names of the quantities): the command line builds the
spec and compares it with the manifest of an existing store before Dask is started.
"""

from dataclasses import dataclass
import math

import numpy as np

from .. import __version__
from .quantities import MASS_MODELS, VARIABLES
from .request import DEFAULT_CHUNK_SIZE, SweepError

__all__ = ['SweepSpec', 'MANIFEST_FORMAT', 'block_shape']

#: Version of :meth:`SweepSpec.manifest` (2: rectangular blocks; 1 was runs of the flat grid).
MANIFEST_FORMAT = 2


def block_shape(n_b, n_delta, chunk_size):
    """(rows, columns) of the blocks of an ``n_b`` × ``n_delta`` grid, each ≤ ``chunk_size``
    bodies: whole rows when one fits, else near-equal pieces of a row (see the module
    docstring)."""
    k = int(chunk_size)
    if k >= n_delta:
        rows = min(n_b, k // n_delta)
        return math.ceil(n_b / math.ceil(n_b / rows)), n_delta
    return 1, math.ceil(n_delta / math.ceil(n_delta / k))


@dataclass(frozen=True)
class SweepSpec:
    """What to compute: the grid (b/a, Δ/a), the mass model, μ's reference speed, chunking."""

    b_over_a: np.ndarray
    delta_over_a: np.ndarray
    mass_model: str = 'laminae'
    reference_speed: float = 0.5     #: kinematic |ω| for mu_required (units √(g/a))
    chunk_size: int = DEFAULT_CHUNK_SIZE   #: the most bodies of one task

    def __post_init__(self):
        if self.mass_model not in MASS_MODELS:
            raise SweepError(f'mass model must be one of {", ".join(MASS_MODELS)}, got '
                             f'{self.mass_model!r}')
        if not (math.isfinite(self.reference_speed) and self.reference_speed >= 0):
            raise SweepError(f'reference speed must be finite and >= 0, got '
                             f'{self.reference_speed!r}')
        if int(self.chunk_size) != self.chunk_size or self.chunk_size < 1:
            raise SweepError(f'chunk size must be an integer >= 1, got {self.chunk_size!r}')

    @property
    def shape(self):
        """(number of b/a values, number of Δ/a values)."""
        return (len(self.b_over_a), len(self.delta_over_a))

    @property
    def size(self):
        """Number of bodies."""
        return self.shape[0] * self.shape[1]

    @property
    def block(self):
        """(rows, columns) of one block (:func:`block_shape`)."""
        return block_shape(*self.shape, self.chunk_size)

    def points(self):
        """(b/a, Δ/a) of every grid point, flat, C order (b/a major)."""
        b, d = np.meshgrid(self.b_over_a, self.delta_over_a, indexing='ij')
        return b.ravel(), d.ravel()

    def blocks(self):
        """The blocks, each ``(rows, columns)`` as two slices of the grid, b/a-major order."""
        (n_b, n_d), (rows, cols) = self.shape, self.block
        return [(slice(i, min(i + rows, n_b)), slice(j, min(j + cols, n_d)))
                for i in range(0, n_b, rows) for j in range(0, n_d, cols)]

    def block_points(self, block):
        """(b/a, Δ/a) of the bodies of one block, flat, C order (as :meth:`points`)."""
        b, d = np.meshgrid(self.b_over_a[block[0]], self.delta_over_a[block[1]], indexing='ij')
        return b.ravel(), d.ravel()

    def chunks(self):
        """The blocks as flat indices into :meth:`points` (``b[chunk]`` is a block's b/a)."""
        flat = np.arange(self.size).reshape(self.shape)
        return [flat[block].ravel() for block in self.blocks()]

    def manifest(self):
        """JSON description of the sweep (floats as ``float.hex``: exact); two sweeps share
        resume state only under equal manifests."""
        return {'format': MANIFEST_FORMAT, 'package_version': __version__,
                'b_over_a': [float(x).hex() for x in self.b_over_a],
                'delta_over_a': [float(x).hex() for x in self.delta_over_a],
                'mass_model': self.mass_model,
                'reference_speed': float(self.reference_speed).hex(),
                'chunk_size': int(self.chunk_size), 'block': list(self.block),
                'variables': list(VARIABLES)}

    def attrs(self):
        """Global attributes of the output."""
        b, d = self.b_over_a, self.delta_over_a
        return {
            'title': 'Quantities of the rolling two-disk bodies over b/a and Delta/a',
            'source': f'twodisk_ros {__version__} (twodisk_ros.sweep)',
            'package_version': __version__,
            'units_convention': 'a = 1, g = 1, M = 1: lengths in a, times in sqrt(a/g), '
                                'angular speeds in sqrt(g/a)',
            'mass_model': self.mass_model,
            'reference_speed': float(self.reference_speed),
            'reference_speed_units': 'sqrt(g/a)',
            'b_over_a_grid': f'linspace({float(b[0])!r}, {float(b[-1])!r}, {len(b)})',
            'delta_over_a_grid': f'linspace({float(d[0])!r}, {float(d[-1])!r}, {len(d)})',
            'chunk_size': int(self.chunk_size),
        }
