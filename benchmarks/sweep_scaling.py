"""Scaling of ``twodisk-sweep`` over worker processes, and its extrapolation to a cluster.

Not a unit test. Side by side in one run, on this machine:

1. the cost of a body, serially in this process (the current per-body code, whatever it is:
   every number below is derived from this measurement, not from a constant);
2. a real cluster — a ``dask scheduler`` process and ``dask worker --nworkers N`` (one thread
   each) on 127.0.0.1 — for N = 1, 2, 4, each running the same Zarr sweep with this process as
   the client: wall time, bodies/s, the CPU seconds of the scheduler process and of the
   client per task, the workers' time per chunk computing and writing, bytes and files per
   chunk, the peak memory (VmHWM) of scheduler, client and workers;
3. the scheduler's own overhead per task, on empty tasks;
4. the client's one-off costs for a 1000 × 1000 store (lay-out, the resume scan of its
   flags, the final count of masked points);
5. an extrapolation to 64 and 512 workers and a 1000 × 1000 map, naming the bottleneck.

The sweep's grid is ``ROWS`` rows of b/a × K values of Δ/a with K = the bodies of one
``TASK_SECONDS`` task at the measured cost, so each task is one row and every N runs the same
``ROWS`` tasks, whatever the per-body cost. On a 2-core machine, 4 workers oversubscribe the
cores (the rate cannot exceed the 2-worker one); the table says so.

Run: ``python benchmarks/sweep_scaling.py [--quick]`` (PYTHONPATH = the repository). Every
process it starts listens on 127.0.0.1 only and is stopped (by its PID) before it returns.
"""

import contextlib
import math
import os
from pathlib import Path
import pickle
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time


def _arguments():
    """The command line's options (``--help`` answers here, before the heavy imports)."""
    import argparse
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--quick', action='store_true', help='fewer tasks (a smoke run)')
    return parser.parse_args()


if __name__ == '__main__':
    _arguments()

import numpy as np  # noqa: E402

from twodisk_ros.sweep.chunks import timed_chunk  # noqa: E402
from twodisk_ros.sweep.request import BYTES_PER_TASK, DEFAULT_STORE_CHUNK_SIZE  # noqa: E402
from twodisk_ros.sweep.spec import SweepSpec  # noqa: E402

B_RANGE, D_RANGE = (0.2, 3.0), (0.05, 0.95)
TASK_SECONDS = 1.0         # the shortest task the sweep should have (docs/sweeps.md)
ROWS = 24                  # tasks of each scaling run (one row of Delta/a each)
WORKERS = (1, 2, 4)
EMPTY_TASKS = 2000
CLUSTER = (64, 512)        # workers of the extrapolation
MAP = (1000, 1000)         # the map of the extrapolation
ONE_OFF_CHUNKS = (1000, 100)   # bodies per chunk of the MAP stores timed for the one-offs
DASK = str(Path(sys.executable).with_name('dask'))
# the repository and this folder: the scheduler and the workers unpickle this module's task
# functions by reference when make bench (run_all.py) has imported it as ``sweep_scaling``
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(
    [str(Path(__file__).resolve().parents[1]), str(Path(__file__).resolve().parent),
     os.environ.get('PYTHONPATH', '')]))
ENV.pop('DASK_SCHEDULER_ADDRESS', None)


def per_body_cost(shape=(6, 8)):
    """(wall s, CPU s, result bytes) per body, serially in this process, on a sample of the
    map; result bytes: what a task of a NetCDF sweep sends to the client (pickled)."""
    b = np.linspace(*B_RANGE, shape[0])
    d = np.linspace(*D_RANGE, shape[1])
    bb, dd = (x.ravel() for x in np.meshgrid(b, d, indexing='ij'))
    timed_chunk(bb[:2], dd[:2])                 # imports and first-call caches apart
    start, cpu = time.perf_counter(), time.process_time()
    result = timed_chunk(bb, dd)[0]
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    return wall / bb.size, cpu / bb.size, len(pickle.dumps(result)) / bb.size


def _free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def _peak_rss(pid):
    """Peak resident memory of process ``pid`` (bytes; VmHWM), 0 if unknown."""
    try:
        with open(f'/proc/{pid}/status', encoding='ascii') as status:
            for line in status:
                if line.startswith('VmHWM:'):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _cpu(process):
    times = process.cpu_times()
    return times.user + times.system


@contextlib.contextmanager
def dask_cluster(workers, folder):
    """(address, scheduler psutil.Process, [worker psutil.Process]) of a scheduler and
    ``workers`` single-thread workers, each a process of its own group; all stopped on exit."""
    import psutil
    from distributed import Client
    port = _free_port()
    address = f'tcp://127.0.0.1:{port}'
    quiet = ['--no-dashboard', '--dashboard-address', '127.0.0.1:0']
    procs = []
    log = open(Path(folder) / 'cluster.log', 'w')
    try:
        procs.append(subprocess.Popen(
            [DASK, 'scheduler', '--host', '127.0.0.1', '--port', str(port), *quiet],
            stdout=log, stderr=subprocess.STDOUT, env=ENV, start_new_session=True))
        procs.append(subprocess.Popen(
            [DASK, 'worker', address, '--host', '127.0.0.1', '--nworkers', str(workers),
             '--nthreads', '1', *quiet],
            stdout=log, stderr=subprocess.STDOUT, env=ENV, start_new_session=True))
        deadline = time.monotonic() + 120
        while True:
            try:
                with Client(address, timeout='10s', set_as_default=False) as client:
                    client.wait_for_workers(workers, timeout=120)
                    pids = list(client.run(os.getpid).values())
                break
            except (OSError, TimeoutError):
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.5)
        yield address, psutil.Process(procs[0].pid), [psutil.Process(p) for p in pids]
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)     # the group started with it
                proc.wait(timeout=5)
        log.close()


def _noop(x):
    return x


def _warm_up():
    import twodisk_ros.sweep.store  # noqa: F401  (zarr, xarray, the physics: once per worker)


def empty_task_overhead(address, scheduler):
    """(wall s, scheduler CPU s) per empty task, EMPTY_TASKS of them submitted at once."""
    from distributed import Client
    with Client(address, set_as_default=False) as client:
        client.gather(client.map(_noop, range(50), pure=False))
        cpu, start = _cpu(scheduler), time.perf_counter()
        client.gather(client.map(_noop, range(EMPTY_TASKS), pure=False))
        wall = time.perf_counter() - start
        return wall / EMPTY_TASKS, (_cpu(scheduler) - cpu) / EMPTY_TASKS


def scaling_run(workers, spec, folder):
    """One Zarr sweep of ``spec`` on a fresh cluster of ``workers``; its measurements."""
    from distributed import Client
    from twodisk_ros.sweep.run import run_sweep
    from twodisk_ros.sweep.store import store_bytes
    store = Path(folder) / f'scaling-{workers}.zarr'
    with dask_cluster(workers, folder) as (address, scheduler, procs):
        out = {'workers': workers}
        if workers == 2:
            out['empty_wall'], out['empty_scheduler'] = empty_task_overhead(address, scheduler)
        marks = []      # (client CPU, scheduler CPU) after each finished chunk

        def mark(index, computed):
            marks.append((time.process_time(), _cpu(scheduler)))

        with Client(address, set_as_default=False) as client:
            client.run(_warm_up)
            scheduler_cpu = _cpu(scheduler)
            run = run_sweep(spec, client, out=store, progress=None, overwrite=False,
                            on_chunk=mark)
            out['scheduler_cpu'] = _cpu(scheduler) - scheduler_cpu
        # steady state, first to last finished chunk (the one-off lay-out and final count of
        # the client apart)
        out['client_cpu_per_task'] = (marks[-1][0] - marks[0][0]) / (len(marks) - 1)
        out['scheduler_rss'] = _peak_rss(scheduler.pid)
        out['worker_rss'] = max(_peak_rss(p.pid) for p in procs)
    tasks = run.computed
    out['result_bytes'] = len(pickle.dumps({'bodies': 1, 'masked': 0, 'seconds': 1.0,
                                            'cpu_seconds': 1.0, 'write_seconds': 1.0}))
    files = sum(1 for p in store.rglob('*') if p.is_file() and '/c/' in p.as_posix())
    out.update(wall=run.seconds, tasks=tasks, bodies=run.bodies, rate=run.bodies / run.seconds,
               compute=float(np.sum(run.chunk_seconds)),
               compute_cpu=float(np.sum(run.chunk_cpu_seconds)),
               write=float(np.sum(run.chunk_write_seconds)),
               write_median=float(np.median(run.chunk_write_seconds)),
               bytes=store_bytes(store), files_per_chunk=files / tasks)
    shutil.rmtree(store)
    return out


def client_one_offs(folder):
    """The client's one-off costs on a MAP store, as (constant s, s per chunk) for its
    lay-out, the resume scan of its flags and the final count of masked points, fitted on
    blocks of ONE_OFF_CHUNKS bodies (read costs grow with the number of chunk objects)."""
    from twodisk_ros.sweep.store import complete_blocks, create_store, masked_count
    points = []
    for chunk in ONE_OFF_CHUNKS:
        spec = SweepSpec(np.linspace(*B_RANGE, MAP[0]), np.linspace(*D_RANGE, MAP[1]),
                         chunk_size=chunk)
        path = Path(folder) / 'layout.zarr'
        start = time.perf_counter()
        create_store(path, spec)
        complete_blocks(path, spec)
        masked_count(path)
        points.append((len(spec.blocks()), time.perf_counter() - start))
        shutil.rmtree(path)
    (n0, t0), (n1, t1) = points
    per_chunk = max(0.0, (t1 - t0) / (n1 - n0))
    return max(0.0, t0 - per_chunk * n0), per_chunk


def extrapolate(m, workers, chunk):
    """Wall time and bottleneck of a MAP sweep on ``workers`` workers in tasks of ``chunk``
    bodies, from the measurements ``m`` (see docs/sweeps.md "Scaling" for the model)."""
    bodies = MAP[0] * MAP[1]
    tasks = math.ceil(bodies / chunk)
    task = chunk * m['per_body_worker']
    compute = math.ceil(tasks / workers) * task                    # rounds of tasks
    # the scheduler's core: the tasks one after another, plus its upkeep while it runs
    scheduler = tasks * m['scheduler_per_task'] + compute * m['scheduler_upkeep']
    client = tasks * m['client_per_task']
    parts = {'workers': compute, 'scheduler': scheduler, 'client': client}
    bottleneck = max(parts, key=parts.get)
    one_off = m['one_off'][0] + m['one_off'][1] * tasks
    return {'workers': workers, 'chunk': chunk, 'tasks': tasks, 'task_seconds': task,
            'compute': compute, 'scheduler': scheduler, 'client': client,
            'one_off': one_off, 'wall': max(parts.values()) + one_off,
            'bottleneck': bottleneck,
            'scheduler_load': workers * m['scheduler_per_task'] / task + m['scheduler_upkeep'],
            'objects_per_second': workers * m['files_per_chunk'] / task,
            'megabytes_per_second': workers * m['bytes_per_body'] * chunk / task / 1e6,
            'client_memory': tasks * BYTES_PER_TASK + bodies * m['client_bytes_per_body'],
            'store_bytes': bodies * m['bytes_per_body']}


def measure(quick=False, log=print):
    """Every measurement of this module (a dict; ``report_lines`` formats it)."""
    wall, cpu, result_bytes = per_body_cost((4, 4) if quick else (6, 8))
    chunk = max(1, math.ceil(TASK_SECONDS / wall))
    rows = 8 if quick else ROWS
    log(f'   sweep scaling: {1e3 * wall:.1f} ms per body serially, tasks of {chunk} bodies')
    spec = SweepSpec(np.linspace(*B_RANGE, rows), np.linspace(*D_RANGE, chunk),
                     chunk_size=chunk)
    m = {'per_body': wall, 'per_body_cpu': cpu, 'chunk': chunk, 'rows': rows,
         'netcdf_result_bytes_per_body': result_bytes,
         'cores': os.cpu_count(), 'load_before': os.getloadavg()[0], 'runs': []}
    with tempfile.TemporaryDirectory(prefix='sweep-scaling-') as folder:
        for workers in WORKERS:
            run = scaling_run(workers, spec, folder)
            m['runs'].append(run)
            log(f'   {workers} worker(s): {run["rate"]:.1f} bodies/s, {run["wall"]:.1f} s')
        m['one_off'] = client_one_offs(folder)
    m['load_after'] = os.getloadavg()[0]
    one = m['runs'][0]
    two = next(r for r in m['runs'] if r['workers'] == 2)
    # inside a worker: CPU time computing plus the wall time writing, per body (the least
    # contended run): what a dedicated core spends (the wall time computing is inflated by
    # other jobs on this shared machine)
    m['per_body_worker'] = min((r['compute_cpu'] + r['write']) / r['bodies']
                               for r in m['runs'])
    # the scheduler: CPU per task (empty tasks), and per second besides the tasks (its
    # periodic callbacks, heartbeats; from the sweeps: about the same for 1, 2 and 4 workers)
    m['scheduler_per_task'] = two['empty_scheduler']
    m['scheduler_upkeep'] = max(0.0, max(
        (r['scheduler_cpu'] - r['tasks'] * m['scheduler_per_task']) / r['wall']
        for r in m['runs']))
    m['client_per_task'] = max(r['client_cpu_per_task'] for r in m['runs'])
    m['bytes_per_body'] = two['bytes'] / two['bodies']
    m['files_per_chunk'] = two['files_per_chunk']
    # the client reads one flag (1 B) per point to resume and the failure strings at the end
    # (numpy StringDType: 16 B per point, longer strings on the heap)
    m['client_bytes_per_body'] = 17
    m['extrapolation'] = []
    bodies = MAP[0] * MAP[1]
    for workers in CLUSTER:
        # ~1 s tasks; the default of a .zarr output; 8 rounds of tasks per worker
        sizes = sorted({chunk, DEFAULT_STORE_CHUNK_SIZE,
                        max(chunk, math.ceil(bodies / (8 * workers)))})
        m['extrapolation'].extend(extrapolate(m, workers, k) for k in sizes)
    return m


def _mib(x):
    return f'{x / 2**20:.0f} MiB' if x < 2**30 else f'{x / 2**30:.1f} GiB'


def report_lines(m):
    """The report's section (Markdown lines)."""
    lines = []
    w = lines.append
    one = m['runs'][0]
    w('## Scaling of the sweep to a cluster\n')
    w(f'`benchmarks/sweep_scaling.py`: a `dask scheduler` process and `dask worker --nworkers '
      f'N --nthreads 1` on 127.0.0.1, this process the client, each N running the same Zarr '
      f'sweep of {m["rows"]} × {m["chunk"]} bodies (b/a ∈ {list(B_RANGE)}, Δ/a ∈ '
      f'{list(D_RANGE)}) in {m["rows"]} tasks of {m["chunk"]} bodies, sized to '
      f'~{TASK_SECONDS:g} s from the measured serial cost of **{1e3 * m["per_body"]:.1f} ms '
      f'per body** (CPU {1e3 * m["per_body_cpu"]:.1f} ms). {m["cores"]} cores: **4 workers '
      f'oversubscribe them** (two processes per core), so their rate cannot pass the '
      f'2-worker one. Load average {m["load_before"]:.2f} before, {m["load_after"]:.2f} '
      'after (a shared machine).\n')
    w('| workers | wall (s) | bodies/s | × 1 worker | scheduler CPU per task, all in (ms) | '
      'client CPU per task (ms) | compute per chunk: wall, CPU (s) | write per chunk (ms, '
      'median) | bytes per chunk | peak memory: worker / scheduler |')
    w('|---|---|---|---|---|---|---|---|---|---|')
    for r in m['runs']:
        w(f'| {r["workers"]} | {r["wall"]:.1f} | {r["rate"]:.1f} | '
          f'{r["rate"] / one["rate"]:.2f} | {1e3 * r["scheduler_cpu"] / r["tasks"]:.1f} | '
          f'{1e3 * r["client_cpu_per_task"]:.1f} | {r["compute"] / r["tasks"]:.2f}, '
          f'{r["compute_cpu"] / r["tasks"]:.2f} | '
          f'{1e3 * r["write_median"]:.0f} | {r["bytes"] / r["tasks"] / 1e3:.0f} kB in '
          f'{r["files_per_chunk"]:.0f} files | {_mib(r["worker_rss"])} / '
          f'{_mib(r["scheduler_rss"])} |')
    constant, per_chunk = m['one_off']
    w(f'\nScheduler overhead on {EMPTY_TASKS} empty tasks (2 workers): '
      f'**{1e3 * m["scheduler_per_task"]:.2f} ms of scheduler CPU per task**; besides the '
      f'tasks it spends {1e3 * m["scheduler_upkeep"]:.0f} ms of CPU per second (periodic '
      f'callbacks, heartbeats; from the sweeps, about the same for 1, 2 and 4 workers). '
      f'Inside a worker a body costs {1e3 * m["per_body_worker"]:.1f} ms (CPU time '
      f'computing, what a dedicated core spends, plus the wall time writing; the least '
      f'contended run). The client receives {one["result_bytes"]} bytes '
      f'per task, whatever its size (counts and times; the workers write the data: a task of '
      f'a NetCDF sweep would send {m["netcdf_result_bytes_per_body"]:.0f} bytes per body) '
      f'and spends **{1e3 * m["client_per_task"]:.1f} ms of CPU per task**; its one-off '
      f'costs on a {MAP[0]} × {MAP[1]} store (lay-out, resume scan of the flags, final '
      f'count of the masked points) are {constant:.2f} s + '
      f'{1e3 * per_chunk:.2f} ms per chunk object read (timed on blocks of '
      f'{" and ".join(map(str, ONE_OFF_CHUNKS))} bodies). On disk: '
      f'**{m["bytes_per_body"]:.0f} bytes per body**, {m["files_per_chunk"]:.0f} files per '
      f'chunk.\n')
    w(f'Extrapolation to a {MAP[0]} × {MAP[1]} map (10⁶ bodies) on N workers like these. '
      'Model: the tasks run in rounds of N on dedicated cores, each costing the measured '
      'CPU + write per body inside a worker; the scheduler handles the tasks one after '
      'another at its CPU per task, plus its upkeep; the client likewise at its CPU per task; the wall time is '
      'the largest of the three plus the client\'s one-off costs. Rows: tasks of ~1 s, the '
      f'default chunk of a .zarr output ({DEFAULT_STORE_CHUNK_SIZE} bodies), and 8 rounds of '
      'tasks per worker.\n')
    w('| N | bodies per task | tasks | task (s) | workers (s) | scheduler (s) | client (s) | '
      'one-off (s) | wall | bottleneck | scheduler load | shared FS: objects/s, MB/s | '
      'client memory | store |')
    w('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
    for e in m['extrapolation']:
        w(f'| {e["workers"]} | {e["chunk"]} | {e["tasks"]} | {e["task_seconds"]:.1f} | '
          f'{e["compute"]:.0f} | {e["scheduler"]:.0f} | {e["client"]:.0f} | '
          f'{e["one_off"]:.0f} | {e["wall"] / 60:.1f} min | {e["bottleneck"]} | '
          f'{e["scheduler_load"]:.2f} | {e["objects_per_second"]:.0f}, '
          f'{e["megabytes_per_second"]:.1f} | {_mib(e["client_memory"])} | '
          f'{_mib(e["store_bytes"])} |')
    e64 = next(e for e in m['extrapolation']
               if e['workers'] == 64 and e['chunk'] == DEFAULT_STORE_CHUNK_SIZE)
    w(f'\n**A {MAP[0]} × {MAP[1]} map on 64 workers (default .zarr chunks): '
      f'~{e64["wall"] / 60:.0f} min**, {e64["tasks"]} tasks of {e64["chunk"]} bodies; '
      f'memory: the client ~{_mib(e64["client_memory"])}, each worker '
      f'~{_mib(one["worker_rss"])} at its peak (measured), the scheduler '
      f'~{_mib(one["scheduler_rss"])} + ~{BYTES_PER_TASK // 1024} kB per task; the store '
      f'~{_mib(e64["store_bytes"])} on disk. "scheduler load" is the share of the '
      'scheduler\'s core the run needs (N × CPU per task / task duration + upkeep): above '
      '~0.5 its queue starts to delay the workers, above 1 it is the bottleneck. docs/'
      'sweeps.md "Scaling" has the reasoning.\n')
    return lines


def main():
    args = _arguments()
    print('\n'.join(report_lines(measure(args.quick))))


if __name__ == '__main__':
    main()
