"""Set-up of a Dask worker for sweep tasks: the C allocator tuned as in a plain process.

Why: Dask's nanny starts every worker process with ``MALLOC_TRIM_THRESHOLD_=65536``
(configuration ``distributed.nanny.pre-spawn-environ``, meant to hand freed memory back to the
OS at once). In glibc, setting that variable also switches off the dynamic mmap threshold, so
every numpy array above 128 KiB is a fresh ``mmap``/``munmap`` with its pages faulted in
again, and the heap is trimmed whenever 64 KiB lie free at its top. A sweep body allocates
many short-lived arrays of that size (cycle and contact-force tables), so inside a worker it
cost 1.7× the CPU time of the same body in a plain process, and a batched block 2.6×
(benchmarks/sweep_rate.py; numbers
in docs/sweeps.md). BLAS threads are not the cause: the nanny already sets
``OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=1``.

:func:`tune_allocator` restores what glibc's dynamic thresholds reach by themselves in a
long-running process (mmap threshold 32 MiB, the dynamic maximum on 64-bit; trim threshold
twice that), with ``mallopt`` at run time, so it works on workers started by anyone
(``LocalCluster`` or ``dask worker`` on a cluster). A worker then keeps at most ~64 MiB of
freed heap instead of returning it at once. Elsewhere than glibc it does nothing.

:class:`SweepWorkerSetup` is the ``distributed`` worker plugin that calls it on every worker,
including workers that join later; :func:`~twodisk_ros.sweep.run.run_sweep` registers it.
"""

import ctypes
import ctypes.util
import sys

from distributed.diagnostics.plugin import WorkerPlugin

__all__ = ['MMAP_THRESHOLD', 'TRIM_THRESHOLD', 'tune_allocator', 'SweepWorkerSetup']

#: glibc mallopt parameters (malloc.h).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Allocations above this many bytes get their own mmap (glibc's dynamic maximum on 64-bit).
MMAP_THRESHOLD = 32 * 1024 * 1024
#: Free bytes at the top of the heap before it is trimmed (twice the mmap threshold, as the
#: dynamic rule of glibc sets it).
TRIM_THRESHOLD = 2 * MMAP_THRESHOLD


def tune_allocator():
    """Set glibc's mmap and trim thresholds of this process (see the module docstring).

    Returns
    -------
    bool
        True if both thresholds were set; False where there is no glibc (macOS, Windows,
        musl) or ``mallopt`` refused (nothing changed then).
    """
    if not sys.platform.startswith('linux'):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library('c') or 'libc.so.6')
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)
                and mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))


class SweepWorkerSetup(WorkerPlugin):
    """Worker plugin: :func:`tune_allocator` once on each worker (present and future)."""

    name = 'twodisk-sweep-setup'
    idempotent = True      # registering it again (another sweep) is a no-op

    def setup(self, worker):
        worker.twodisk_allocator_tuned = tune_allocator()
