"""Bodies per second of ``twodisk-sweep`` on Dask, and projections (not a unit test).

Measured on one representative map, b/a ∈ [0.2, 3], Δ/a ∈ [0.05, 0.95] (no masked point):

1. the cost per body split by quantity (stage), serial, in this process (no Dask);
2. the scheduling overhead per task (empty tasks on a 2-worker LocalCluster) and the client's
   cost per finished chunk (saving it to the resume cache);
3. bodies per second with 1 and 2 worker processes (start-up excluded and reported apart:
   the cluster and the workers' first import of the physics), and the parallel efficiency rate(2) / (2 rate(1));
   (CPU/wall in the tasks below 1 means other jobs took the cores: contention, not Dask);
4. the wall time of a 100 × 100 map, extrapolated from the measured 2-worker rate;
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
from twodisk_ros.sweep.quantities import STAGES, body_quantities, chunk_quantities
from twodisk_ros.sweep.run import DEFAULT_CHUNK_SIZE, SweepSpec, dask_client, run_sweep

B_RANGE, D_RANGE = (0.2, 3.0), (0.05, 0.95)
RATE_GRID = (16, 12)       # bodies timed serially (by stage) and on 1 and 2 workers
EMPTY_TASKS = 400


def _grid(shape):
    return np.linspace(*B_RANGE, shape[0]), np.linspace(*D_RANGE, shape[1])


def _import_physics():
    import twodisk_ros.sweep.quantities  # noqa: F401  (the workers' one-time imports)


def _noop(x):
    return x


def stage_costs():
    b, d = _grid(RATE_GRID)
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


def rate(workers):
    b, d = _grid(RATE_GRID)
    spec = SweepSpec(b, d)
    start = time.perf_counter()
    with dask_client(workers=workers) as client:
        client.wait_for_workers(workers)
        client.run(_import_physics)
        startup = time.perf_counter() - start
        overhead = task_overhead(client) if workers == 2 else math.nan
        with tempfile.TemporaryDirectory() as folder:
            run = run_sweep(spec, client, out=folder + '/map.nc', progress=None)
    return spec.size / run.seconds, run.seconds, startup, overhead, run


def main():
    n, per_body, share, stages = stage_costs()
    print(f'load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores')
    print(f'cost per body, serial, {n} bodies of b/a in {B_RANGE}, delta/a in {D_RANGE}:')
    print(f'  total {1e3 * per_body:.1f} ms per body (wall; CPU/wall {share:.2f})')
    for stage, seconds in stages.items():
        print(f'  {stage:16s} {1e3 * seconds:7.2f} ms  ({100 * seconds / per_body:4.1f} %)')
    save = client_cost_per_chunk()
    print(f'client: saving one {DEFAULT_CHUNK_SIZE}-body chunk to the resume cache: '
          f'{1e3 * save:.2f} ms')
    results = {}
    for workers in (1, 2):
        results[workers] = rate(workers)
        r, seconds, startup, _, run = results[workers]
        print(f'{workers} worker(s): {r:.2f} bodies/s ({RATE_GRID[0]}x{RATE_GRID[1]} = '
              f'{RATE_GRID[0] * RATE_GRID[1]} bodies in {seconds:.2f} s, chunks of '
              f'{DEFAULT_CHUNK_SIZE}: median task {np.median(run.chunk_seconds):.2f} s, '
              f'CPU/wall in the tasks {sum(run.chunk_cpu_seconds) / sum(run.chunk_seconds):.2f}'
              f'); cluster start-up {startup:.2f} s')
    overhead = results[2][3]
    efficiency = results[2][0] / (2 * results[1][0])
    print(f'parallel efficiency with 2 workers: {efficiency:.2f} (rate(2) / (2 rate(1))); '
          f'1 worker against serial without Dask: {results[1][0] * per_body:.2f}')
    print(f'scheduler round trip of an empty task (2 workers): {1e3 * overhead:.2f} ms')
    map_100 = 100 * 100 / results[2][0]
    print(f'100 x 100 map on 2 workers: ~{map_100:.0f} s ({map_100 / 60:.1f} min), '
          f'extrapolated from the measured 2-worker rate (+ {results[2][2]:.1f} s start-up)')
    # Projection: each worker spends c per body (from the 1-worker run, which includes the
    # per-task overhead) on B / N bodies; the client handles every chunk serially (save +
    # round trip), which bounds the rate from below whatever N is.
    c = 1.0 / results[1][0]
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
