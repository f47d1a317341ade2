"""Parameter sweeps on Dask (twodisk_ros.sweep): exact agreement, distributed, resume, input.

Every scheduler and worker listens on 127.0.0.1 only; every process a test starts is stopped
in a ``finally`` (terminate, wait, kill).
"""

import json
import math
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from dask_helpers import free_port
from harsh_start import harshly
from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import liftoff_speed, mu_required_kinematic
from twodisk_ros.physics.bodies.cycle import RollingCycle
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.stability.equilibria import equilibria, stability_map
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.physics.motion.simulate import simulate_phase
from twodisk_ros.sweep.cli import main
from twodisk_ros.sweep.dataset import read_netcdf
from twodisk_ros.sweep.chunks import timed_chunk
from twodisk_ros.sweep.quantities import VARIABLES
from twodisk_ros.sweep.run import SweepSpec, dask_client, parts_folder, run_sweep

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get('PYTHONPATH', ''))
ENV.pop('DASK_SCHEDULER_ADDRESS', None)
# b/a = 1, 1.5; Δ/a = 0.25, 0.5, 0.75, 1: both stable families (b/a = 1 has both), the oloid
# (1, 0.5) and the masked Δ/a = 1 points
B_GRID = ('1', '1.5', '2')
D_GRID = ('0.25', '1', '4')
CHUNK = 3


def _spec():
    return SweepSpec(np.linspace(1.0, 1.5, 2), np.linspace(0.25, 1.0, 4), chunk_size=CHUNK)


@pytest.fixture(scope='module')
def client():
    """dask_client's LocalCluster of worker processes (each with its nanny), one worker: every
    test here needs one, none two (each more costs two Python processes importing Dask and
    the physics)."""
    with dask_client(workers=1) as c:
        yield c


@pytest.fixture(scope='module')
def local(client):
    """The sweep of the ellipse alone (no exponent named): 2-D, ``exponent`` a scalar."""
    dataset = run_sweep(_spec(), client, progress=None).dataset
    assert dataset['cycle_advance'].dims == ('b_over_a', 'delta_over_a')
    assert dataset['exponent'].ndim == 0 and float(dataset['exponent']) == 2.0
    return dataset


def _user_code(dataset):
    """What a user of the 2-D output wrote before the exponent axis existed."""
    return float(dataset.sel(b_over_a=1.0, delta_over_a=0.5, method='nearest')['cycle_advance'])


def test_without_an_exponent_axis_the_output_is_2d_in_memory_and_netcdf(client, local,
                                                                        tmp_path):
    # (a Zarr store of the ellipse alone: tests/test_sweep_reliability.py, whose sweeps are it)
    import xarray as xr
    expected = float(local['cycle_advance'].sel(b_over_a=1.0, delta_over_a=0.5))
    assert _user_code(local) == expected
    run_sweep(_spec(), client, out=tmp_path / 'map.nc', progress=None, overwrite=False)
    with xr.open_dataset(tmp_path / 'map.nc') as opened:      # plain xarray, engine guessed
        assert dict(opened.sizes) == {'b_over_a': 2, 'delta_over_a': 4}
        assert float(opened['exponent']) == 2.0 and opened['exponent'].attrs['units']
        assert _user_code(opened) == expected


def test_named_exponents_give_the_exponent_axis(client, local):
    spec = SweepSpec(_spec().b_over_a, _spec().delta_over_a, chunk_size=CHUNK, exponent=[2.0])
    dataset = run_sweep(spec, client, progress=None).dataset
    assert dataset['cycle_advance'].dims == ('exponent', 'b_over_a', 'delta_over_a')
    np.testing.assert_array_equal(dataset['cycle_advance'].sel(exponent=2.0).values,
                                  local['cycle_advance'].values)     # the same bodies
    with pytest.raises(TypeError):       # the 3-D selection is not one number
        _user_code(dataset)


def _library(b, d, reference_speed=0.5):
    """One body through the library's scalar path, as a user calls it (a = g = M = 1).

    Returns (body, dynamics, values): ``values`` holds each sweep quantity that is one library
    call or attribute; the derived ones (barrier, rollover speed, cycle time, contact lengths)
    are checked against other library calls in :func:`_check_derived`, never by the sweep's
    own formulas.
    """
    body = EllipseBody(1.0, b, d)
    cycle = RollingCycle(body)
    dyn = RollingDynamics(body, mass_properties('laminae', 1.0, b, d, 1.0), 1.0, cycle=cycle)
    heights = [eq.height for eq in equilibria(body)]
    periods = dyn.small_oscillation_periods()
    model = ContactForceModel(dyn)
    return body, dyn, {
        'theta_max': body.theta_max, 'stability_margin': body.stability_margin,
        'stable_family': float(stability_map(b, d)),
        'height_min': min(heights), 'height_max': max(heights),
        'oscillation_period': periods[0][1] if periods else math.nan,
        'cycle_advance': abs(cycle.displacement.shift), 'cycle_heading': cycle.displacement.turn,
        'liftoff_speed': liftoff_speed(model)[0],
        'mu_required': float(mu_required_kinematic(model, reference_speed)),
    }


def _check_derived(point, body, dyn):
    """The sweep's derived quantities of one body against other library calls."""
    where = (body.b, body.delta)
    barrier, speed = float(point['barrier']), float(point['rollover_speed'])
    if dyn.flat:
        # neutral: z_G constant over the cycle, so no barrier and nothing to roll over
        assert barrier == 0.0 and speed == 0.0, where
        u = np.linspace(0.0, 2 * math.pi, 64)
        assert np.ptp(body.phase_height(u)) <= 1e-12, where   # claim: flat to rounding
    else:
        u_star = dyn.small_oscillation_periods()[0][0].phase
        floor = float(dyn.tabulated_potential(u_star))
        # claim: barrier = separatrix energy (library's RollingDynamics.barrier) above the
        # stable equilibrium, per unit weight; tables vs closed forms agree to ~1e-13 M g a
        assert barrier == pytest.approx(dyn.barrier - floor, rel=1e-10, abs=1e-12), where
        # claim: leaving u* at |omega| = rollover_speed the body has exactly the separatrix
        # energy (library's initial_phase_rate and energy, from the tables): 1e-12 relative
        energy = float(dyn.energy(u_star, dyn.initial_phase_rate(u_star, speed)))
        assert energy == pytest.approx(dyn.barrier, rel=1e-12, abs=1e-14), where
    # claim: driven at |omega| = 1 (library's kinematic ODE on the closed forms, DOP853 at
    # rtol 1e-11) the body completes one cycle, u: 0 -> 2 pi, in cycle_time: 1e-8 rad
    cycle_time = float(point['cycle_time'])
    motion = simulate_phase(dyn, [0.0, cycle_time], 0.0, dyn.initial_phase_rate(0.0, 1.0),
                            mode='kinematic', method='direct', tolerance=1e-11)
    assert abs(motion.phase[-1] - motion.phase[0]) == pytest.approx(2 * math.pi, abs=1e-8), where
    # claim: the contact-length extremes are those of |AB| over the cycle (library's
    # phase_geometry on 2^16 phases): no sample beyond them (1e-14 rounding), and none
    # farther than the sampling bound |L''| (h/2)^2 / 2 < 1e-8 a
    u = 2 * math.pi * np.arange(2**16) / 2**16
    geo = body.phase_geometry(u)
    length = np.linalg.norm(geo.contact_b - geo.contact_a, axis=-1)
    low, high = float(point['contact_length_min']), float(point['contact_length_max'])
    assert low <= length.min() + 1e-14 and length.min() - low <= 1e-8, where
    assert high >= length.max() - 1e-14 and high - length.max() <= 1e-8, where


def _plane(dataset):
    """The n = 2 plane of a sweep's Dataset (as the ``local`` fixture holds it)."""
    return dataset.sel(exponent=2.0) if 'exponent' in dataset.dims else dataset


def _same(x, y):
    """Bitwise-equal datasets (NaN equal to NaN), every variable and attribute (n = 2)."""
    x, y = _plane(x), _plane(y)
    assert list(x.data_vars) == list(y.data_vars)
    for name in x.data_vars:
        assert x[name].attrs.keys() == y[name].attrs.keys()
        np.testing.assert_array_equal(x[name].values, y[name].values, err_msg=name)
    for name in ('exponent', 'b_over_a', 'delta_over_a'):
        np.testing.assert_array_equal(x[name].values, y[name].values)


def _assert_library_path(point, b, d):
    body, dyn, values = _library(b, d)
    assert str(point['failure'].values) == ''
    for name, value in values.items():
        # claim: each sweep point agrees with the library's scalar call to 1e-10 relative
        # (the batched path of a sweep's tasks, docs/sweeps.md; 0, inf and NaN, the period of
        # a neutral body, exactly)
        got = float(point[name])
        assert got == pytest.approx(value, rel=1e-10, abs=0.0, nan_ok=True), (b, d, name)
    _check_derived(point, body, dyn)
    assert set(values) | DERIVED == set(VARIABLES)


#: The quantities checked by _check_derived (the others are one library call each).
DERIVED = {'barrier', 'rollover_speed', 'cycle_time', 'contact_length_min',
           'contact_length_max'}


def test_sweep_points_are_the_library_scalar_path(local):
    """Every valid point of the Dask sweep, body by body (both stable families)."""
    families = set()
    for b in local['b_over_a'].values:
        for d in local['delta_over_a'].values[:3]:
            point = local.sel(b_over_a=b, delta_over_a=d)
            _assert_library_path(point, float(b), float(d))
            families.add(float(point['stable_family']))
    assert families == {1.0, -1.0}


def test_chunk_of_a_neutral_body_is_the_library_scalar_path():
    """A body on the neutral line b^2 - 2 a^2 + 2 Delta^2 = 0 (and a stable one beside it)."""
    import xarray as xr
    b = [math.sqrt(2 - 2 * 0.5**2), 2.0]
    d = [0.5, 0.3]
    result = timed_chunk(b, d)[0]
    for k in range(2):
        point = xr.Dataset({name: ((), result[name][k]) for name in VARIABLES}
                           | {'failure': ((), result['failure'][k])})
        _assert_library_path(point, b[k], d[k])
    assert result['stable_family'][0] == 0 and math.isnan(result['oscillation_period'][0])


def test_sweep_closed_forms(local):
    # The paper's closed forms for the oloid (a = 1, b = 1, Delta = 1/2): independent of
    # the library, to ~rounding of the quadratures / minimisations (1e-14 relative)
    oloid = local.sel(b_over_a=1.0, delta_over_a=0.5)
    assert float(oloid['cycle_advance']) == pytest.approx(8 * math.sqrt(3) * math.pi / 9,
                                                          rel=1e-14)
    # the heights at the equilibria: closed forms, rounded (16 ulps)
    assert float(oloid['height_min']) == pytest.approx(1 / math.sqrt(2), rel=ulps(16))
    assert float(oloid['height_max']) == pytest.approx(0.75, rel=ulps(16))
    assert float(oloid['contact_length_min']) == pytest.approx(math.sqrt(3), rel=1e-14)
    assert float(oloid['contact_length_max']) == pytest.approx(math.sqrt(3), rel=1e-14)
    assert float(oloid['stable_family']) == -1
    # every point with Δ/a = 1 is masked, with a reason
    edge = local.sel(delta_over_a=1.0)
    for name in VARIABLES:
        assert np.all(np.isnan(edge[name].values)), name
    assert all('delta/a = 1.0 >= 1' in str(r) for r in edge['failure'].values)
    assert np.all(local['failure'].values[:, :3] == '')
    for name, (units, description) in VARIABLES.items():
        assert local[name].attrs['units'] == units and local[name].attrs['description']
    assert local.attrs['package_version'] and local.attrs['mass_model'] == 'laminae'


def _page_faults_of_reallocation(repeats=50, size=2**18):
    """Minor page faults of this process while a 2 MiB array is allocated, filled and freed
    ``repeats`` times (after one warm-up)."""
    import resource
    a = np.ones(size)
    del a
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(repeats):
        a = np.ones(size)
        del a
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='glibc malloc only')
def test_sweep_workers_reuse_freed_memory_like_a_plain_process(client, local):
    # The cause of the 1.7x slower bodies in Dask workers: the nanny's
    # MALLOC_TRIM_THRESHOLD_=65536 gives every array >= 128 KiB a fresh mmap, whose 512 pages
    # (2 MiB) fault in again on every allocation: 50 x 512 = 25600 faults (measured 25650
    # on a bare worker). After run_sweep (the `local` fixture) registered SweepWorkerSetup,
    # a worker reuses the heap as a plain process does (measured 0): claim checked with a
    # margin of 4x against the fresh-mmap count.
    faults = client.run(_page_faults_of_reallocation)
    assert len(faults) == 1
    assert all(count < 50 * 512 / 4 for count in faults.values()), faults


def _listening_hosts(procs):
    """The addresses every started process (and its children) listens on."""
    import psutil
    hosts = set()
    for proc in procs:
        parent = psutil.Process(proc.pid)
        for p in [parent, *parent.children(recursive=True)]:
            hosts |= {c.laddr.ip for c in p.net_connections('inet')
                      if c.status == psutil.CONN_LISTEN}
    return hosts


@pytest.mark.slow
def test_distributed_cli_equals_local(local, tmp_path, capsys):
    # a `dask scheduler` and a `dask worker` command (one worker: the values travel through
    # a remote scheduler and worker all the same), the command line in this process
    from dask_helpers import cluster
    out = tmp_path / 'remote.nc'
    with cluster(tmp_path, workers=1) as (address, procs):
        assert _listening_hosts(procs) == {'127.0.0.1'}
        status = main(['--b-over-a', *B_GRID, '--delta-over-a', *D_GRID, '--out', str(out),
                       '--chunk-size', str(CHUNK), '--scheduler', address])
        err = capsys.readouterr().err
        assert status == 0, err
        assert 'Traceback' not in err
        remote = read_netcdf(out)
    assert all(p.returncode is not None for p in procs)
    _same(local, remote)
    assert not parts_folder(out).exists()


class _Stop(Exception):
    pass


def test_interrupted_sweep_resumes_without_recomputing(client, local, tmp_path, capsys):
    out = tmp_path / 'map.nc'
    spec = _spec()
    n_chunks = len(spec.chunks())

    def interrupt(index, computed):
        if computed == 2:
            raise _Stop

    with pytest.raises(_Stop):
        run_sweep(spec, client, out=out, progress=None, on_chunk=interrupt)
    parts = parts_folder(out)
    saved = sorted(parts.glob('chunk-*.npz'))
    assert len(saved) == 2 and not out.exists()
    manifest = json.loads((parts / 'manifest.json').read_text())
    assert manifest['chunk_size'] == CHUNK
    again = run_sweep(spec, client, out=out, progress=None)
    assert again.resumed == 2 and again.computed == n_chunks - 2
    _same(again.dataset, local)
    _same(read_netcdf(out), local)
    assert not parts.exists()
    # a different grid is never mixed in: the cache of another sweep is refused (exit 2)
    other = SweepSpec(np.linspace(0.5, 1.5, 2), np.linspace(0.25, 1.0, 4), chunk_size=CHUNK)
    with pytest.raises(_Stop):
        run_sweep(other, client, out=out, progress=None,
                  on_chunk=lambda i, c: (_ for _ in ()).throw(_Stop()))
    # (--overwrite: the output exists; the cache, not the output, is what is refused here)
    status = main(['--b-over-a', *B_GRID, '--delta-over-a', *D_GRID, '--out', str(out),
                   '--chunk-size', str(CHUNK), '--quiet', '--workers', '1', '--overwrite'])
    assert status == 2
    assert 'different sweep' in capsys.readouterr().err


@pytest.mark.parametrize('override, words', [
    ({'--b-over-a': ['1.5', '0.5', '3']}, 'reversed'),
    ({'--b-over-a': ['1', '1', '3']}, 'empty range'),
    ({'--delta-over-a': ['0.25', '0.75', '0']}, 'N must be an integer >= 1'),
    ({'--b-over-a': ['0.5', 'x', '3']}, 'must be a number'),
    ({'--b-over-a': ['0.5', '1.5', '2.5']}, 'integer'),
    ({'--b-over-a': ['0', '1.5', '3']}, 'START must be > 0'),
    ({'--b-over-a': ['0.5', '1.5']}, 'expected 3 arguments'),
    ({'--reference-speed': ['fast']}, 'must be a number'),
    ({'--chunk-size': ['0']}, 'integer >= 1'),
    ({'--mass-model': ['lead']}, 'invalid choice'),
    ({'--out': ['{tmp}/missing/map.nc']}, 'does not exist'),
    ({'--out': ['{tmp}']}, 'is a directory'),
    ({'--out': ['{tmp}/file.txt/map.nc']}, 'Not a directory'),
    ({'--out': ['{tmp}/x.csv']}, 'allowed: .nc'),
    ({'--delta-over-a': ['1', '2', '3']}, 'no body of the grid is valid'),
    ({'--b-over-a': ['0.2', '3', '10000000000']}, 'allowed: at most 10000000 bodies'),
    ({'--plot': ['{tmp}/file.txt']}, 'not a directory'),
])
def test_bad_input_one_line_exit_2(override, words, capsys, tmp_path):
    (tmp_path / 'file.txt').write_text('not a folder')
    options = {'--b-over-a': ['0.5', '1.5', '3'], '--delta-over-a': ['0.25', '0.75', '3'],
               '--out': [str(tmp_path / 'x.nc')], **override}
    argv = [x for key, values in options.items()
            for x in [key, *(v.replace('{tmp}', str(tmp_path)) for v in values)]]
    status = main(argv)
    err = capsys.readouterr().err
    assert status == 2
    assert len(err.strip().splitlines()) == 1, err
    assert words in err and 'Traceback' not in err
    assert not (tmp_path / 'x.nc.parts').exists()


def test_unreachable_scheduler_exit_2_fast(tmp_path, capsys):
    # the command line in this process (the real command refusing a scheduler address, and
    # exiting without noise: tests/test_hostile_input.py)
    port = free_port()   # nothing listens there
    status = main(['--b-over-a', '1', '1', '1', '--delta-over-a', '0.5', '0.5', '1', '--out',
                   str(tmp_path / 'x.nc'), '--scheduler', f'tcp://127.0.0.1:{port}'])
    err = capsys.readouterr().err
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1, err
    assert 'cannot reach the Dask scheduler' in err and 'ConnectionRefusedError' in err
    assert list(tmp_path.iterdir()) == []        # no output, no resume cache


def test_a_refused_connection_is_final_without_a_client(monkeypatch):
    # "fast": nothing accepts the connection, so no Client is built at all (a Client retried
    # the refused connection until its 5 s timeout was over: a wait for nothing)
    import distributed
    from twodisk_ros.sweep.request import SweepError

    def no_client(*args, **kwargs):
        raise AssertionError('a Client was built for a port that refuses connections')

    monkeypatch.setattr(distributed, 'Client', no_client)
    with pytest.raises(SweepError, match='cannot reach the Dask scheduler at .*: '
                                         'ConnectionRefusedError'):
        with dask_client(f'tcp://127.0.0.1:{free_port()}'):
            pass


#: The sweep's command line (cli.main, as ``python -m twodisk_ros.sweep`` runs it) with its
#: client paused for good after saving chunk K (argv[1]): the test's SIGINT then always
#: arrives mid-sweep, however fast the chunks are (no race with the sweep's end).
_PAUSED_CLI = """
import signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)  # also when started with it ignored
import twodisk_ros.sweep.run as run
real, pause_after = run.run_sweep, int(sys.argv[1])
def paused(*args, **kwargs):
    def on_chunk(index, computed):
        if computed == pause_after:
            time.sleep(120)          # the SIGINT arrives here; 120 s: the test times out first
    return real(*args, on_chunk=on_chunk, **kwargs)
run.run_sweep = paused
from twodisk_ros.sweep.cli import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.slow
def test_sigint_keeps_finished_chunks_and_the_rerun_resumes(client, local, tmp_path, capsys,
                                                            monkeypatch):
    # the interrupted command runs on the module's cluster (no LocalCluster of its own to
    # start); the rerun is the command line in this process, on the same cluster
    out = tmp_path / 'map.nc'
    args = ['--b-over-a', *B_GRID, '--delta-over-a', *D_GRID, '--out', str(out),
            '--chunk-size', '1', '--quiet']
    saved_before_signal = 2
    parts = parts_folder(out)
    proc = subprocess.Popen(harshly([sys.executable, '-c', _PAUSED_CLI, str(saved_before_signal),
                                     *args, '--scheduler', client.scheduler.address]),
                            env=ENV, cwd=tmp_path, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 60    # hang guard
        while len(list(parts.glob('chunk-*.npz'))) < saved_before_signal:
            assert proc.poll() is None, proc.communicate()[1]
            assert time.monotonic() < deadline, 'the first chunks never appeared'
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        err = proc.communicate(timeout=60)[1]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(timeout=10)
    assert proc.returncode == 130, err
    assert 'interrupted' in err and 'Traceback' not in err
    assert len(err.strip().splitlines()) == 1, err
    # the client was paused after saving exactly that many chunks: no more, no fewer
    assert len(list(parts.glob('chunk-*.npz'))) == saved_before_signal and not out.exists()
    import contextlib
    import twodisk_ros.sweep.run as run

    @contextlib.contextmanager
    def on_the_module_cluster(scheduler=None, workers=None, **kwargs):
        yield client

    monkeypatch.setattr(run, 'dask_client', on_the_module_cluster)
    capsys.readouterr()
    assert main(args) == 0
    again = capsys.readouterr().err
    total = len(_spec().b_over_a) * len(_spec().delta_over_a)
    assert (f'{total - saved_before_signal} chunks computed, {saved_before_signal} resumed'
            in again), again
    _same(read_netcdf(out), local)
