"""What a sweep computes: the grid, the options and how the grid is cut into tasks (numpy only).

The grid is exponent × b/a × Δ/a: the superellipse exponents n (2, the ellipse, by default; a
list of values or an inclusive linspace) are the first (slowest) axis, then b/a and Δ/a
(inclusive, as :func:`numpy.linspace`). Each exponent's plane is cut into rectangular
**blocks** of at most ``chunk_size`` bodies: whole rows of Δ/a when a row fits (several rows
per block), else pieces of one row of near-equal length; a block never spans two exponents, so
one task computes one path (batched for n = 2, per body otherwise) and a grid of n = 2 alone is
cut exactly as before the exponent axis existed. One block is one
Dask task and, in a Zarr store, one chunk of every variable, so that no two tasks ever write
the same chunk (what makes the workers' parallel writes safe). Every block has the same shape
except at the far edges of the grid (Zarr's regular chunk grid).

No Dask, no xarray, no physics here (numpy, and the names of the quantities): the command
line builds the spec and compares it with the manifest of an existing store before Dask is
started.
"""

from dataclasses import dataclass, field
import math

import numpy as np

from .. import __version__
from .variables import MASS_MODELS, VARIABLES
from .request import DEFAULT_CHUNK_SIZE, ELLIPSE_EXPONENT, SweepError, exponent_values

__all__ = ['SweepSpec', 'MANIFEST_FORMAT', 'block_shape']

#: Version of :meth:`SweepSpec.manifest` (4: whether the output has the exponent axis; 3: the
#: exponent axis; 2: rectangular blocks; 1 was runs of the flat grid).
MANIFEST_FORMAT = 4


def _ellipse_only():
    return np.array([ELLIPSE_EXPONENT])


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
    """What to compute: the grid (exponent, b/a, Δ/a), the mass model, μ's reference speed,
    chunking. ``exponent`` (the superellipse exponents n, 2 ≤ n ≤ 100, strictly increasing)
    comes last so that ``SweepSpec(b, d, ...)`` is the ellipse sweep (n = 2) whose output is
    2-D, as it was before the exponent axis existed; naming exponents (even ``[2.0]``) gives
    the 3-D output."""

    b_over_a: np.ndarray
    delta_over_a: np.ndarray
    mass_model: str = 'laminae'
    reference_speed: float = 0.5     #: kinematic |ω| for mu_required (units √(g/a))
    chunk_size: int = DEFAULT_CHUNK_SIZE   #: the most bodies of one task
    #: superellipse n (1); None: the ellipse alone, without an exponent axis in the output
    exponent: np.ndarray = None
    #: True when the request named exponents: the output has the dimension ``exponent``;
    #: False (no exponent given): the 2-D (b/a, Δ/a) output, ``exponent`` a scalar coordinate
    exponent_axis: bool = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, 'exponent_axis', self.exponent is not None)
        object.__setattr__(self, 'exponent', exponent_values('exponent', np.atleast_1d(
            np.asarray(_ellipse_only() if self.exponent is None else self.exponent,
                       dtype=float))))
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
        """(number of exponents, of b/a values, of Δ/a values)."""
        return (len(self.exponent), len(self.b_over_a), len(self.delta_over_a))

    @property
    def size(self):
        """Number of bodies."""
        return math.prod(self.shape)

    @property
    def general(self):
        """True when some exponent is not 2: the grid has bodies of the per-body path."""
        return bool(np.any(self.exponent != ELLIPSE_EXPONENT))

    @property
    def block(self):
        """(1, rows, columns) of one block (:func:`block_shape` in one exponent's plane)."""
        return (1, *block_shape(*self.shape[1:], self.chunk_size))

    def points(self):
        """(exponent, b/a, Δ/a) of every grid point, flat, C order (exponent major)."""
        n, b, d = np.meshgrid(self.exponent, self.b_over_a, self.delta_over_a, indexing='ij')
        return n.ravel(), b.ravel(), d.ravel()

    def blocks(self):
        """The blocks, each ``(exponent, rows, columns)`` as three slices of the grid (one
        exponent each), in C order of the grid."""
        (n_e, n_b, n_d), (_, rows, cols) = self.shape, self.block
        return [(slice(k, k + 1), slice(i, min(i + rows, n_b)), slice(j, min(j + cols, n_d)))
                for k in range(n_e) for i in range(0, n_b, rows) for j in range(0, n_d, cols)]

    def block_exponent(self, block):
        """The exponent n of a block (every block has one)."""
        return float(self.exponent[block[0]][0])

    def block_points(self, block):
        """(b/a, Δ/a) of the bodies of one block, flat, C order (as :meth:`points`); its
        exponent is :meth:`block_exponent`."""
        b, d = np.meshgrid(self.b_over_a[block[1]], self.delta_over_a[block[2]], indexing='ij')
        return b.ravel(), d.ravel()

    def chunks(self):
        """The blocks as flat indices into :meth:`points` (``b[chunk]`` is a block's b/a)."""
        flat = np.arange(self.size).reshape(self.shape)
        return [flat[block].ravel() for block in self.blocks()]

    def manifest(self):
        """JSON description of the sweep (floats as ``float.hex``: exact); two sweeps share
        resume state only under equal manifests."""
        return {'format': MANIFEST_FORMAT, 'package_version': __version__,
                'exponent': [float(x).hex() for x in self.exponent],
                'exponent_axis': self.exponent_axis,
                'b_over_a': [float(x).hex() for x in self.b_over_a],
                'delta_over_a': [float(x).hex() for x in self.delta_over_a],
                'mass_model': self.mass_model,
                'reference_speed': float(self.reference_speed).hex(),
                'chunk_size': int(self.chunk_size), 'block': list(self.block),
                'variables': list(VARIABLES)}

    def attrs(self):
        """Global attributes of the output."""
        b, d, n = self.b_over_a, self.delta_over_a, self.exponent
        title = ('Quantities of the rolling two-disk bodies over b/a and Delta/a'
                 if not self.general else
                 'Quantities of the rolling bodies of two superellipse laminae '
                 '|x/b|^n + |y/a|^n <= 1 over the exponent n, b/a and Delta/a')
        return {
            'title': title,
            'source': f'twodisk_ros {__version__} (twodisk_ros.sweep)',
            'package_version': __version__,
            'units_convention': 'a = 1, g = 1, M = 1: lengths in a, times in sqrt(a/g), '
                                'angular speeds in sqrt(g/a)',
            'mass_model': self.mass_model,
            'reference_speed': float(self.reference_speed),
            'reference_speed_units': 'sqrt(g/a)',
            'b_over_a_grid': f'linspace({float(b[0])!r}, {float(b[-1])!r}, {len(b)})',
            'delta_over_a_grid': f'linspace({float(d[0])!r}, {float(d[-1])!r}, {len(d)})',
            'exponent_values': ' '.join(repr(float(x)) for x in n),
            'chunk_size': int(self.chunk_size),
        }
