"""Bodies per second of ``twodisk-sweep`` on Dask, batched against per-body, and projections.

Measured on one representative map, b/a ∈ [0.2, 3], Δ/a ∈ [0.05, 0.95] (no masked point), on
this machine, side by side in one run (not a unit test):

1. the cost per body of the two paths in this process (no Dask), on the same bodies: the
   per-body path (:func:`~twodisk_ros.sweep.quantities.body_quantities`, one library call
   per quantity, the sweep's path before the batched one; split by stage) and the batched
   path (:mod:`twodisk_ros.sweep.batch`, what a sweep's tasks run; split by stage) in chunks
   of 16 (the current default chunk size) and of :data:`BATCH_CHUNK`: the speed-up per body;
2. the rate inside a Dask worker against the serial rate, and 2 workers against 1 (batched
   path, chunks of :data:`RATE_CHUNK`), before (a bare worker, as Dask's nanny starts it)
   and after the sweep's worker set-up (:class:`~twodisk_ros.sweep.worker.SweepWorkerSetup`,
   which ``run_sweep`` registers); ``REPEATS`` rounds, medians. "Inside a worker" is the
   tasks' own wall time (sum over chunks), so the scheduler is left out; "N workers" is the
   wall time from the first submission to the last result. CPU/wall below 1 means other jobs
   took the cores (contention, not Dask): the ratios are also given in CPU time per body;
3. the scheduling overhead per task (empty tasks on a 2-worker LocalCluster) and the client's
   cost per finished chunk (saving it to the resume cache);
4. end to end, ``twodisk-sweep`` itself (a subprocess: start-up, imports, Dask, the NetCDF
   file) on a 100 × 100 map with 2 local workers and chunks of :data:`BATCH_CHUNK`, against
   the per-body path's 100 × 100 time extrapolated from its 2-worker rate measured here;
5. a projection for a 1000 × 1000 map on N workers (model printed with the numbers).

Run: ``python benchmarks/sweep_rate.py`` (PYTHONPATH = the repository). Every cluster
listens on 127.0.0.1 only and is closed before the script ends.
"""

import math
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time

if __name__ == '__main__':   # --help answers before the heavy imports below
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()

import numpy as np  # noqa: E402

from twodisk_ros.sweep.batch import BATCH_STAGES, Ellipses  # noqa: E402
from twodisk_ros.sweep.parts import PartsCache  # noqa: E402
from twodisk_ros.sweep.chunks import quantities, timed_chunk  # noqa: E402
from twodisk_ros.sweep.quantities import STAGES, body_quantities  # noqa: E402
from twodisk_ros.sweep.run import DEFAULT_CHUNK_SIZE, SweepSpec, dask_client  # noqa: E402
from twodisk_ros.sweep.worker import SweepWorkerSetup  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
B_RANGE, D_RANGE = (0.2, 3.0), (0.05, 0.95)
SIDE_GRID = (24, 16)       # bodies timed serially by both paths, side by side
BATCH_CHUNK = 128          # bodies per task of the batched path (docs/sweeps.md, "Cost")
RATE_GRID = (48, 32)       # bodies timed serially and on 1 and 2 workers (batched path)
RATE_CHUNK = 64            # 24 chunks: the 2-worker run's tail (one worker idle while the
                           # other ends its last chunk) stays a few % of its wall time
SCALAR_GRID = (24, 16)     # the per-body path on 2 workers, chunks of 16 (as it ran)
MAP = (100, 100)           # the end-to-end map
EMPTY_TASKS = 400
REPEATS = 3                # rounds of serial / 1 worker / 2 workers (medians)


def _grid(shape):
    return np.linspace(*B_RANGE, shape[0]), np.linspace(*D_RANGE, shape[1])


def _import_physics():
    import twodisk_ros.sweep.batch  # noqa: F401  (the workers' one-time imports)


def _noop(x):
    return x


def _per_body(b, d, timings=None):
    """The per-body path (the scalar reference) over paired b/a and Δ/a."""
    return [body_quantities(bk, dk, timings=timings) for bk, dk in zip(b, d)]


def _batched(b, d, timings=None):
    """The batched path, as a task of exponent 2 runs it."""
    return quantities(Ellipses(b, d), timings=timings)


def _cpu_clock():
    return time.perf_counter(), time.process_time()


def serial_costs(shape=SIDE_GRID):
    """{path: (wall per body, CPU per body, {stage: wall per body})} (s), same bodies."""
    spec = SweepSpec(*_grid(shape))
    _, b, d = spec.points()       # (exponent 2 alone: the ellipse)
    _batched(b[:8], d[:8])                                             # first calls apart
    found = {}
    for label, path, chunk in (('per-body', _per_body, DEFAULT_CHUNK_SIZE),
                               (f'batched, chunks of {DEFAULT_CHUNK_SIZE}', _batched,
                                DEFAULT_CHUNK_SIZE),
                               (f'batched, chunks of {BATCH_CHUNK}', _batched, BATCH_CHUNK)):
        timings = {}
        wall, cpu = _cpu_clock()
        for start in range(0, spec.size, chunk):
            part = slice(start, start + chunk)
            path(b[part], d[part], timings)
        wall, cpu = (x / spec.size for x in np.subtract(_cpu_clock(), (wall, cpu)))
        found[label] = (wall, cpu, {k: v / spec.size for k, v in timings.items()})
    return spec.size, found


def task_overhead(client):
    client.gather(client.map(_noop, range(20), pure=False))       # warm up
    start = time.perf_counter()
    client.gather(client.map(_noop, range(EMPTY_TASKS), pure=False))
    return (time.perf_counter() - start) / EMPTY_TASKS


def client_cost_per_chunk():
    result = _batched([1.0] * BATCH_CHUNK, [0.5] * BATCH_CHUNK)
    with tempfile.TemporaryDirectory() as folder:
        cache = PartsCache(folder + '/x.parts', {'benchmark': 1})
        start = time.perf_counter()
        for k in range(50):
            cache.save(k, result)
        return (time.perf_counter() - start) / 50


def _timed_tasks(client, spec):
    """Submit every chunk of ``spec`` as a bare task; (wall, Σ task wall, Σ task CPU) in s."""
    _, b, d = spec.points()       # (exponent 2 alone: the ellipse)
    start = time.perf_counter()
    futures = [client.submit(timed_chunk, b[part], d[part], pure=False)
               for part in spec.chunks()]
    results = client.gather(futures)
    wall = time.perf_counter() - start
    return wall, sum(r[1] for r in results), sum(r[2] for r in results)


def serial_rate():
    """(wall, CPU) per body (s) of the chunks of the rate grid, in this process."""
    spec = SweepSpec(*_grid(RATE_GRID), chunk_size=RATE_CHUNK)
    _, b, d = spec.points()       # (exponent 2 alone: the ellipse)
    wall, cpu = _cpu_clock()
    for part in spec.chunks():
        _batched(b[part], d[part])
    return tuple(x / spec.size for x in np.subtract(_cpu_clock(), (wall, cpu)))


def worker_rates(workers):
    """{'before'|'after': (wall per body, task wall per body, task CPU per body)} (s).

    One LocalCluster: bare workers first (Dask's defaults), then the same tasks after
    registering the sweep's worker plugin, exactly as ``run_sweep`` does.
    """
    spec = SweepSpec(*_grid(RATE_GRID), chunk_size=RATE_CHUNK)
    found = {}
    with dask_client(workers=workers) as client:
        client.wait_for_workers(workers)
        client.run(_import_physics)
        warm = SweepSpec(*_grid((1, 2 * workers)), chunk_size=1)
        for label in ('before', 'after'):
            if label == 'after':
                client.register_plugin(SweepWorkerSetup())
            _timed_tasks(client, warm)          # first calls (caches, lazy imports) apart
            found[label] = tuple(x / spec.size for x in _timed_tasks(client, spec))
    return found


def scalar_on_two_workers():
    """Wall per body (s) of the per-body path on 2 workers (chunks of 16, as it ran)."""
    spec = SweepSpec(*_grid(SCALAR_GRID))
    _, b, d = spec.points()       # (exponent 2 alone: the ellipse)
    with dask_client(workers=2) as client:
        client.wait_for_workers(2)
        client.register_plugin(SweepWorkerSetup())
        client.run(_import_physics)
        start = time.perf_counter()
        futures = [client.submit(_per_body, b[part], d[part], pure=False)
                   for part in spec.chunks()]
        client.gather(futures)
        return (time.perf_counter() - start) / spec.size


def end_to_end(shape=MAP, workers=2, chunk=BATCH_CHUNK):
    """``twodisk-sweep`` as a user runs it (a subprocess): (wall s, its last stderr line)."""
    with tempfile.TemporaryDirectory() as folder:
        argv = [sys.executable, '-m', 'twodisk_ros.sweep',
                '--b-over-a', str(B_RANGE[0]), str(B_RANGE[1]), str(shape[0]),
                '--delta-over-a', str(D_RANGE[0]), str(D_RANGE[1]), str(shape[1]),
                '--out', str(Path(folder) / 'map.nc'), '--workers', str(workers),
                '--chunk-size', str(chunk)]
        env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep
                   + os.environ.get('PYTHONPATH', ''))
        env.pop('DASK_SCHEDULER_ADDRESS', None)
        start = time.perf_counter()
        done = subprocess.run(argv, env=env, cwd=folder, capture_output=True, text=True,
                              timeout=3600)
        wall = time.perf_counter() - start
    lines = done.stderr.strip().splitlines()
    if done.returncode != 0:
        raise RuntimeError(f'twodisk-sweep failed ({done.returncode}): {lines[-1:]}')
    return wall, lines[-1] if lines else ''


def _median(rows, index):
    return float(np.median([row[index] for row in rows]))


def rate_table():
    """Serial, 1 and 2 workers before/after the worker set-up, REPEATS rounds; prints medians.

    Returns the median per-body costs {key: (wall, task wall, task CPU)} (s), with key
    'serial' (wall, wall, CPU) and (workers, 'before'|'after').
    """
    rounds = {}
    loads = [os.getloadavg()[0]]
    for _ in range(REPEATS):
        wall, cpu = serial_rate()
        rounds.setdefault('serial', []).append((wall, wall, cpu))
        for workers in (1, 2):
            for label, costs in worker_rates(workers).items():
                rounds.setdefault((workers, label), []).append(costs)
        loads.append(os.getloadavg()[0])
    med = {key: tuple(_median(rows, i) for i in range(3)) for key, rows in rounds.items()}
    n = RATE_GRID[0] * RATE_GRID[1]
    print(f'rates of the batched path, {n} bodies in chunks of {RATE_CHUNK}, medians of '
          f'{REPEATS} rounds (load average {", ".join(f"{x:.2f}" for x in loads)} over the '
          f'rounds):')
    serial_wall, _, serial_cpu = med['serial']
    print(f'  serial (this process, no Dask): {1e3 * serial_wall:.2f} ms/body wall, '
          f'{1e3 * serial_cpu:.2f} ms/body CPU')
    for label, text in (('before', 'bare Dask workers (before)'),
                        ('after', 'with SweepWorkerSetup (after)')):
        one, two = med[(1, label)], med[(2, label)]
        print(f'  {text}:')
        for workers, (wall, task, cpu) in ((1, one), (2, two)):
            print(f'    {workers} worker(s): {1 / wall:6.1f} bodies/s; inside a worker '
                  f'{1e3 * task:.2f} ms/body wall, {1e3 * cpu:.2f} ms/body CPU '
                  f'(CPU/wall {cpu / task:.2f})')
        print(f'    rate inside a worker / serial rate: {serial_wall / one[1]:.2f} (wall), '
              f'{serial_cpu / one[2]:.2f} (CPU)   [target >= 0.90]')
        print(f'    2 workers / 1 worker: {one[0] / two[0]:.2f} (wall rate)   '
              f'[target >= 1.80; needs 2 idle cores]')
    return med


def main():
    print(f'load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores')
    n, costs = serial_costs()
    print(f'cost per body, serial, the same {n} bodies of b/a in {B_RANGE}, delta/a in '
          f'{D_RANGE}, side by side:')
    per_body = costs['per-body'][0]
    for label, (wall, cpu, stages) in costs.items():
        print(f'  {label}: {1e3 * wall:.2f} ms/body wall ({1e3 * cpu:.2f} CPU), speed-up per '
              f'body {per_body / wall:.1f}x')
        order = STAGES if label == 'per-body' else BATCH_STAGES
        print('    ' + ', '.join(f'{stage} {1e3 * stages.get(stage, 0.0):.2f}'
                                 for stage in order if stage in stages) + ' (ms/body)')
    med = rate_table()
    save = client_cost_per_chunk()
    print(f'client: saving one {BATCH_CHUNK}-body chunk to the resume cache: '
          f'{1e3 * save:.2f} ms')
    scalar_two = scalar_on_two_workers()
    print(f'per-body path on 2 workers (chunks of {DEFAULT_CHUNK_SIZE}): '
          f'{1 / scalar_two:.1f} bodies/s')
    with dask_client(workers=2) as client:
        client.wait_for_workers(2)
        overhead = task_overhead(client)
    print(f'scheduler round trip of an empty task (2 workers): {1e3 * overhead:.2f} ms')
    bodies = MAP[0] * MAP[1]
    wall, last = end_to_end()
    print(f'end to end, twodisk-sweep {MAP[0]} x {MAP[1]} with 2 local workers, chunks of '
          f'{BATCH_CHUNK} (start-up, Dask, the NetCDF file): {wall:.1f} s wall '
          f'({bodies / wall:.0f} bodies/s) [target <= 60 s]')
    print(f'  its summary: {last}')
    print(f'  the per-body path, extrapolated from its 2-worker rate: ~{bodies * scalar_two:.0f} '
          f's for the same map; speed-up end to end {bodies * scalar_two / wall:.1f}x')
    # Projection: each worker spends c per body (the 1-worker wall cost with the worker
    # set-up, which includes the per-task overhead) on B / N bodies; the client handles every
    # chunk serially (save + round trip), which bounds the rate from below whatever N is.
    c = med[(1, 'after')][0]
    big = 1000 * 1000
    chunks = math.ceil(big / BATCH_CHUNK)
    client_floor = chunks * (save + overhead)
    print(f'1000 x 1000 map ({big} bodies, {chunks} chunks of {BATCH_CHUNK}); '
          f'T(N) = max(B c / N, chunks (s + o)) with c = {1e3 * c:.2f} ms/body (1-worker '
          f'run), s = {1e3 * save:.2f} ms (save), o = {1e3 * overhead:.2f} ms (round trip); '
          f'N dedicated cores like this one, ideal scaling (divide by the efficiency '
          f'measured on your cluster):')
    for workers in (1, 2, 8, 32, 64, 128, 512):
        compute = big * c / workers
        total = max(compute, client_floor)
        print(f'  N = {workers:4d}: {total / 60:8.1f} min'
              + ('   (client-bound)' if client_floor > compute else ''))
    print(f'load average after: {os.getloadavg()[0]:.2f} (other jobs on the machine lower the '
          f'2-worker rate)')


if __name__ == '__main__':
    main()
