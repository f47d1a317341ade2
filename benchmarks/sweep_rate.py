"""Bodies per second of ``twodisk-sweep`` on Dask, and projections (not a unit test).

Measured on one representative map, b/a ∈ [0.2, 3], Δ/a ∈ [0.05, 0.95] (no masked point):

1. the cost per body split by quantity (stage), serial, in this process (no Dask);
2. the rate inside a Dask worker against the serial rate, and 2 workers against 1, side by
   side in one run, before (a bare worker, as Dask's nanny starts it) and after the sweep's
   worker set-up (:class:`~twodisk_ros.sweep.worker.SweepWorkerSetup`, which ``run_sweep``
   registers); ``REPEATS`` rounds, each measuring serial, 1 and 2 workers in turn, medians
   reported. "Inside a worker" is the tasks' own wall time (sum over chunks), so the
   scheduler is left out; "N workers" is the wall time from the first submission to the last
   result. CPU/wall below 1 means other jobs took the cores (contention, not Dask): the
   ratios are also given in CPU time per body, which contention disturbs far less;
3. the scheduling overhead per task (empty tasks on a 2-worker LocalCluster) and the client's
   cost per finished chunk (saving it to the resume cache);
4. an end-to-end ``run_sweep`` (resume cache, NetCDF file) on 2 workers, and the wall time of
   a 100 × 100 map extrapolated from it;
5. a projection for a 1000 × 1000 map on N workers (model printed with the numbers).

Run: ``python benchmarks/sweep_rate.py`` (PYTHONPATH = the repository). Every cluster
listens on 127.0.0.1 only and is closed before the script ends.
"""

import math
import os
import tempfile
import time

import numpy as np

from twodisk_ros.sweep.parts import PartsCache
from twodisk_ros.sweep.quantities import STAGES, body_quantities, chunk_quantities, timed_chunk
from twodisk_ros.sweep.run import DEFAULT_CHUNK_SIZE, SweepSpec, dask_client, run_sweep
from twodisk_ros.sweep.worker import SweepWorkerSetup

B_RANGE, D_RANGE = (0.2, 3.0), (0.05, 0.95)
STAGE_GRID = (16, 12)      # bodies timed serially by stage
RATE_GRID = (24, 16)       # bodies timed serially and on 1 and 2 workers: 24 chunks of 16,
                           # so the 2-worker run's tail (one worker idle while the other
                           # ends its last chunk) stays a few % of its wall time
EMPTY_TASKS = 400
REPEATS = 3                # rounds of serial / 1 worker / 2 workers (medians)


def _grid(shape):
    return np.linspace(*B_RANGE, shape[0]), np.linspace(*D_RANGE, shape[1])


def _import_physics():
    import twodisk_ros.sweep.quantities  # noqa: F401  (the workers' one-time imports)


def _noop(x):
    return x


def stage_costs():
    b, d = _grid(STAGE_GRID)
    timings = {}
    start, cpu = time.perf_counter(), time.process_time()
    for bi in b:
        for di in d:
            body_quantities(bi, di, timings=timings)
    total = time.perf_counter() - start
    n = b.size * d.size
    share = (time.process_time() - cpu) / total
    return n, total / n, share, {stage: timings.get(stage, 0.0) / n for stage in STAGES}


def task_overhead(client):
    client.gather(client.map(_noop, range(20), pure=False))       # warm up
    start = time.perf_counter()
    client.gather(client.map(_noop, range(EMPTY_TASKS), pure=False))
    return (time.perf_counter() - start) / EMPTY_TASKS


def client_cost_per_chunk():
    result = chunk_quantities([1.0] * DEFAULT_CHUNK_SIZE, [0.5] * DEFAULT_CHUNK_SIZE)
    with tempfile.TemporaryDirectory() as folder:
        cache = PartsCache(folder + '/x.parts', {'benchmark': 1})
        start = time.perf_counter()
        for k in range(50):
            cache.save(k, result)
        return (time.perf_counter() - start) / 50


def _timed_tasks(client, spec):
    """Submit every chunk of ``spec`` as a bare task; (wall, Σ task wall, Σ task CPU) in s."""
    b, d = spec.points()
    start = time.perf_counter()
    futures = [client.submit(timed_chunk, b[part], d[part], pure=False)
               for part in spec.chunks()]
    results = client.gather(futures)
    wall = time.perf_counter() - start
    return wall, sum(r[1] for r in results), sum(r[2] for r in results)


def serial_rate():
    """(wall, CPU) per body (s) of the chunks of the rate grid, in this process."""
    spec = SweepSpec(*_grid(RATE_GRID))
    b, d = spec.points()
    start, cpu = time.perf_counter(), time.process_time()
    for part in spec.chunks():
        chunk_quantities(b[part], d[part])
    return (time.perf_counter() - start) / spec.size, (time.process_time() - cpu) / spec.size


def worker_rates(workers):
    """{'before'|'after': (wall per body, task wall per body, task CPU per body)} (s).

    One LocalCluster: bare workers first (Dask's defaults), then the same tasks after
    registering the sweep's worker plugin, exactly as ``run_sweep`` does.
    """
    spec = SweepSpec(*_grid(RATE_GRID))
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


def end_to_end(workers=2):
    """run_sweep with a NetCDF file on a fresh cluster: (SweepRun, start-up s, overhead s)."""
    import twodisk_ros.sweep.dataset  # noqa: F401  (xarray's import is not the sweep's work)
    spec = SweepSpec(*_grid(RATE_GRID))
    start = time.perf_counter()
    with dask_client(workers=workers) as client:
        client.wait_for_workers(workers)
        client.run(_import_physics)
        startup = time.perf_counter() - start
        overhead = task_overhead(client)
        with tempfile.TemporaryDirectory() as folder:
            run = run_sweep(spec, client, out=folder + '/map.nc', progress=None)
    return run, startup, overhead


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
    print(f'rates, {n} bodies in chunks of {DEFAULT_CHUNK_SIZE}, medians of {REPEATS} rounds '
          f'(load average {", ".join(f"{x:.2f}" for x in loads)} over the rounds):')
    serial_wall, _, serial_cpu = med['serial']
    print(f'  serial (this process, no Dask): {1e3 * serial_wall:.1f} ms/body wall, '
          f'{1e3 * serial_cpu:.1f} ms/body CPU')
    for label, text in (('before', 'bare Dask workers (before)'),
                        ('after', 'with SweepWorkerSetup (after)')):
        one, two = med[(1, label)], med[(2, label)]
        print(f'  {text}:')
        for workers, (wall, task, cpu) in ((1, one), (2, two)):
            print(f'    {workers} worker(s): {1 / wall:6.2f} bodies/s; inside a worker '
                  f'{1e3 * task:.1f} ms/body wall, {1e3 * cpu:.1f} ms/body CPU '
                  f'(CPU/wall {cpu / task:.2f})')
        print(f'    rate inside a worker / serial rate: {serial_wall / one[1]:.2f} (wall), '
              f'{serial_cpu / one[2]:.2f} (CPU)   [target >= 0.90]')
        print(f'    2 workers / 1 worker: {one[0] / two[0]:.2f} (wall rate)   '
              f'[target >= 1.80; needs 2 idle cores]')
    return med


def main():
    n, per_body, share, stages = stage_costs()
    print(f'load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores')
    print(f'cost per body, serial, {n} bodies of b/a in {B_RANGE}, delta/a in {D_RANGE}:')
    print(f'  total {1e3 * per_body:.1f} ms per body (wall; CPU/wall {share:.2f})')
    for stage, seconds in stages.items():
        print(f'  {stage:16s} {1e3 * seconds:7.2f} ms  ({100 * seconds / per_body:4.1f} %)')
    med = rate_table()
    save = client_cost_per_chunk()
    print(f'client: saving one {DEFAULT_CHUNK_SIZE}-body chunk to the resume cache: '
          f'{1e3 * save:.2f} ms')
    run, startup, overhead = end_to_end(2)
    rate2 = run.dataset['b_over_a'].size * run.dataset['delta_over_a'].size / run.seconds
    print(f'end to end, run_sweep on 2 workers with the resume cache and the NetCDF file: '
          f'{rate2:.2f} bodies/s ({run.seconds:.2f} s; median task '
          f'{np.median(run.chunk_seconds):.2f} s, CPU/wall in the tasks '
          f'{sum(run.chunk_cpu_seconds) / sum(run.chunk_seconds):.2f}); cluster start-up '
          f'{startup:.2f} s')
    print(f'scheduler round trip of an empty task (2 workers): {1e3 * overhead:.2f} ms')
    map_100 = 100 * 100 / rate2
    print(f'100 x 100 map on 2 workers: ~{map_100:.0f} s ({map_100 / 60:.1f} min), '
          f'extrapolated from the end-to-end 2-worker rate (+ {startup:.1f} s start-up)')
    # Projection: each worker spends c per body (the 1-worker wall cost with the worker
    # set-up, which includes the per-task overhead) on B / N bodies; the client handles every
    # chunk serially (save + round trip), which bounds the rate from below whatever N is.
    c = med[(1, 'after')][0]
    bodies = 1000 * 1000
    chunks = math.ceil(bodies / DEFAULT_CHUNK_SIZE)
    client_floor = chunks * (save + overhead)
    print(f'1000 x 1000 map ({bodies} bodies, {chunks} chunks of {DEFAULT_CHUNK_SIZE}); '
          f'T(N) = max(B c / N, chunks (s + o)) with c = {1e3 * c:.1f} ms/body (1-worker '
          f'run), s = {1e3 * save:.2f} ms (save), o = {1e3 * overhead:.2f} ms (round trip); '
          f'N dedicated cores like this one, ideal scaling (divide by the efficiency '
          f'measured on your cluster):')
    for workers in (1, 2, 8, 32, 128, 512):
        compute = bodies * c / workers
        total = max(compute, client_floor)
        print(f'  N = {workers:4d}: {total / 3600:7.2f} h'
              + ('   (client-bound)' if client_floor > compute else ''))
    print(f'load average after: {os.getloadavg()[0]:.2f} (other jobs on the machine lower the '
          f'2-worker rate)')


if __name__ == '__main__':
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    main()
