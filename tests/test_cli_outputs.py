"""Outputs, runaway requests and --help of ``twodisk-sweep`` and ``twodisk-animate``.

Every command runs as a real entry point in a subprocess (but the runs of the tests that
replace outputs: the command line in this process), most inside a wrapper that makes
importing Dask, distributed, xarray and zarr (and, for the early refusals of
``twodisk-animate``, scipy and matplotlib) raise: a refusal that still comes out as one line
with exit 2 was made before any of them was imported (not a timing claim). The runaway
requests run under an address-space limit (RLIMIT_AS) so that a regression fails with a
MemoryError instead of eating the machine. Sweeps that do run connect (``--scheduler``) to
one Dask scheduler of this module, on threads of the test process and listening on 127.0.0.1
only (each command starting a LocalCluster of worker processes cost seconds of CPU; the
LocalCluster itself is tested in tests/test_sweep.py); the test kills the command's process
group if it overruns.
"""

import os
from pathlib import Path
import shutil
import sys
import time

import pytest

from zygote import Zygote

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
           ROS_DOMAIN_ID='15', MPLBACKEND='Agg')
ENV.pop('DASK_SCHEDULER_ADDRESS', None)
ENV.pop('TWODISK_DEBUG', None)

SWEEP = 'twodisk_ros.sweep'
ANIMATE = 'twodisk_ros.plotting.animate_cli'      # twodisk-animate in setup.py
ANIMATION = 'twodisk_ros.plotting.animate_cli'
DASK_LIKE = ('dask', 'distributed', 'xarray', 'zarr')
HEAVY = DASK_LIKE + ('scipy', 'matplotlib')
#: The sweep's modules that compute bodies (the command-line checks import the node's
#: parameters, and so scipy and the physics, but never these before the grid passed).
SWEEP_WORK = ('twodisk_ros.sweep.spec', 'twodisk_ros.sweep.quantities',
              'twodisk_ros.sweep.batch', 'twodisk_ros.sweep.general')
#: The modules that compute bodies (scipy's optimizers and the physics' tables): a worker's,
#: never imported by the command's client, not even for a sweep it runs on a scheduler.
BODY_WORK = SWEEP_WORK[1:]
REFUSED = 'imported before the command line was checked'
#: Address space for the runaway requests (B): Python with numpy needs ~0.5 GiB here.
ADDRESS_SPACE = 2 * 2**30
# a valid 1-body sweep (the oloid)
ONE_BODY = ['--b-over-a', '1', '1', '1', '--delta-over-a', '0.5', '0.5', '1']

WRAPPER = '''
import runpy, sys
BLOCKED = {blocked!r}
class _Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in BLOCKED or name in BLOCKED:
            raise ImportError(name + ' {refused}')
sys.meta_path.insert(0, _Refuse())
sys.argv = [{module!r}, *sys.argv[1:]]
runpy.run_module({module!r}, run_name='__main__', alter_sys=True)
'''


@pytest.fixture(scope='module', autouse=True)
def zygote():
    """The module's command runs are children of one fork server (tests/zygote.py), each in
    a session of its own: the command as ``python`` runs it, without ~0.25 s of interpreter
    start and numpy import (numpy is not among the imports these tests refuse)."""
    global ZYGOTE
    with Zygote(ENV) as ZYGOTE:
        yield ZYGOTE


def _run(module, *args, cwd, blocked=(), address_space=False, timeout=60):
    """Run ``python -m module args`` (through the import-blocking wrapper if ``blocked``);
    returns (CompletedProcess, seconds)."""
    if blocked:
        command = ['-c', WRAPPER.format(blocked=tuple(blocked), module=module,
                                        refused=REFUSED), *args]
    else:
        command = ['-m', module, *args]
    start = time.monotonic()
    result = ZYGOTE.run(command, cwd=cwd, timeout=timeout, new_session=True,
                        address_space=ADDRESS_SPACE if address_space else None)
    return result, time.monotonic() - start


@pytest.fixture(scope='module')
def scheduler():
    """The address of a Dask scheduler on threads of this process (one worker thread),
    listening on 127.0.0.1 only, no dashboard."""
    import logging
    from distributed import LocalCluster
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                           protocol='tcp://', host='127.0.0.1', dashboard_address=None,
                           silence_logs=logging.CRITICAL,
                           scheduler_kwargs={'dashboard': False,
                                             'dashboard_address': '127.0.0.1:0'})
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def _one_line_exit_2(result, *words):
    assert result.returncode == 2, result.stderr[-3000:]
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr[-3000:]
    assert 'Traceback' not in result.stderr and REFUSED not in result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


def _listing(folder):
    return sorted(p.name for p in Path(folder).iterdir())


# -- the wrapper itself ----------------------------------------------------------------------

def test_the_wrapper_blocks_dask(tmp_path):
    # a valid request passes the checks and then needs xarray: the wrapper must stop it
    result, _ = _run(SWEEP, *ONE_BODY, '--out', tmp_path / 'x.nc', cwd=tmp_path,
                     blocked=DASK_LIKE)
    assert result.returncode != 0 and REFUSED in result.stderr
    assert not (tmp_path / 'x.nc').exists()


# -- twodisk-sweep: argument errors before Dask --------------------------------------------

@pytest.mark.parametrize('args, words', [
    (['--b-over-a', '1', '2', 'x', '--delta-over-a', '0.1', '0.5', '3'], 'integer'),
    (['--b-over-a', '1', '2', '3', '--delta-over-a', '0.1', '0.5', '3', '--mass-model',
      'lamina'], 'invalid choice'),
    (['--b-over-a', '1', '2', '3', '--delta-over-a', '0.1', '0.5', '3', '--quite'],
     'unrecognized arguments'),
    (['--b-over-a', '1', '2', '3', '--delta-over-a', '0.1', '0.5', '3', '--workers', 'x'],
     'integer'),
    (['--b-over-a', '1', '2', '3', '--delta-over-a', '0.1', '0.5', '3',
      '--reference-speed', 'inf'], 'finite'),
    (['--b-over-a', '1', '2', '3', '--delta-over-a', '0.1', '0.5', '3', '--workers',
      '100000'], 'per core of this machine'),
])
def test_sweep_typo_exits_2_fast_without_dask(tmp_path, args, words):
    # refused before Dask or xarray was imported (the wrapper), let alone started
    result, _ = _run(SWEEP, *args, '--out', tmp_path / 'x.nc', cwd=tmp_path,
                     blocked=DASK_LIKE)
    _one_line_exit_2(result, words)
    assert _listing(tmp_path) == []


# -- twodisk-sweep: outputs -----------------------------------------------------------------

def test_sweep_refuses_an_existing_output(tmp_path):
    out = tmp_path / 'family.nc'
    out.write_bytes(b'an earlier result')
    result, _ = _run(SWEEP, *ONE_BODY, '--out', out, cwd=tmp_path,
                     blocked=DASK_LIKE + BODY_WORK)
    _one_line_exit_2(result, 'family.nc exists', '--overwrite')
    assert out.read_bytes() == b'an earlier result'
    assert _listing(tmp_path) == ['family.nc']        # no resume cache, no temporary file


def test_sweep_refuses_existing_maps(tmp_path):
    maps = tmp_path / 'maps'
    maps.mkdir()
    (maps / 'barrier.png').write_bytes(b'an earlier map')
    result, _ = _run(SWEEP, *ONE_BODY, '--out', tmp_path / 'x.nc', '--plot', maps,
                     cwd=tmp_path, blocked=DASK_LIKE)
    _one_line_exit_2(result, 'barrier.png exists', '--overwrite')
    assert (maps / 'barrier.png').read_bytes() == b'an earlier map'
    assert _listing(tmp_path) == ['maps'] and _listing(maps) == ['barrier.png']


def test_sweep_refuses_an_existing_zarr_store_before_dask(tmp_path):
    import numpy as np
    from twodisk_ros.sweep.spec import SweepSpec
    from twodisk_ros.sweep.store import create_store, finish_store
    store = tmp_path / 'family.zarr'
    finish_store(create_store(store, SweepSpec(np.array([1.0]), np.array([0.5]),
                                               chunk_size=1)))
    before = sorted((p, p.stat().st_mtime_ns) for p in store.rglob('*'))
    result, _ = _run(SWEEP, *ONE_BODY, '--out', store, cwd=tmp_path,
                     blocked=DASK_LIKE + BODY_WORK)
    _one_line_exit_2(result, 'family.zarr exists', '--overwrite')
    assert sorted((p, p.stat().st_mtime_ns) for p in store.rglob('*')) == before
    # a directory the sweep did not write is never replaced, not even with --overwrite
    (tmp_path / 'other.zarr').mkdir()
    (tmp_path / 'other.zarr' / 'zarr.json').write_text('{"zarr_format": 3}')
    result, _ = _run(SWEEP, *ONE_BODY, '--out', tmp_path / 'other.zarr', '--overwrite',
                     cwd=tmp_path, blocked=DASK_LIKE)
    _one_line_exit_2(result, 'not a twodisk-sweep Zarr store', 'even with --overwrite')
    assert _listing(tmp_path / 'other.zarr') == ['zarr.json']
    assert _listing(tmp_path) == ['family.zarr', 'other.zarr']


@pytest.mark.parametrize('name', ['family.csv', 'family', 'family.png'])
def test_sweep_refuses_a_suffix_it_cannot_write(tmp_path, name):
    result, _ = _run(SWEEP, *ONE_BODY, '--out', tmp_path / name, cwd=tmp_path,
                     blocked=DASK_LIKE)
    _one_line_exit_2(result, 'allowed: .nc')
    assert _listing(tmp_path) == []


def test_sweep_without_any_valid_body_is_refused_before_dask(tmp_path):
    # every Delta/a >= 1: no body of the grid can be built
    result, _ = _run(SWEEP, '--b-over-a', '0.5', '2', '4', '--delta-over-a', '1', '2', '3',
                     '--out', tmp_path / 'x.nc', cwd=tmp_path, blocked=DASK_LIKE)
    _one_line_exit_2(result, 'no body of the grid is valid')
    assert _listing(tmp_path) == []


# -- twodisk-sweep: runaway grids -----------------------------------------------------------

@pytest.mark.parametrize('grid, words', [
    # 5e11 bodies: the old code tried to allocate 74.5 GiB for one linspace
    (['--b-over-a', '0.2', '3', '10000000000', '--delta-over-a', '0.02', '0.98', '50'],
     ['500000000000 bodies', 'allowed: at most 10000000 bodies']),
    # 1e6 bodies: ~3 GiB estimated, above half of the 2 GiB address space
    (['--b-over-a', '0.2', '3', '1000', '--delta-over-a', '0.02', '0.98', '1000'],
     ['1000000 bodies', 'GiB of memory; allowed:']),
])
def test_sweep_runaway_grid_refused_with_what_it_needs(tmp_path, grid, words):
    # refused before any body: the sweep's computing modules and Dask never imported, and
    # nothing allocated beyond the address-space limit
    result, _ = _run(SWEEP, *grid, '--out', tmp_path / 'x.nc', cwd=tmp_path,
                     blocked=DASK_LIKE + SWEEP_WORK, address_space=True)
    _one_line_exit_2(result, *words)
    assert _listing(tmp_path) == []


# -- twodisk-sweep: runs (Dask) ---------------------------------------------------------------

@pytest.mark.slow
def test_sweep_without_any_computable_body_is_an_error(scheduler, tmp_path):
    # Delta/a = 1e-300 passes the command-line checks, but the body refuses a length below
    # its range (1e-30 m at a = 1): every point is masked. The bodies are computed by the
    # scheduler's worker (a thread of this process), never by the command's client, which
    # therefore runs without the modules that compute them
    result, _ = _run(SWEEP, '--b-over-a', '1', '1', '1', '--delta-over-a', '1e-300',
                     '1e-300', '1', '--out', tmp_path / 'x.nc', '--scheduler', scheduler,
                     '--quiet',
                     cwd=tmp_path, blocked=BODY_WORK, timeout=120)
    _one_line_exit_2(result, 'no body of the grid could be computed', 'nothing written')
    assert _listing(tmp_path) == []       # no file, no resume cache


@pytest.mark.slow
def test_sweep_overwrite_replaces_outputs_and_still_resumes(scheduler, tmp_path, capsys):
    from twodisk_ros.sweep.cli import main
    out, maps = tmp_path / 'family.nc', tmp_path / 'maps'
    command = [*ONE_BODY, '--out', out, '--scheduler', scheduler, '--quiet']
    # the sweeps by the command line in this process (Dask and the maps' matplotlib imported
    # once, not per command); the refusal, made before Dask, is the real command
    assert main([*map(str, command), '--keep-parts']) == 0, capsys.readouterr().err
    written = out.read_bytes()
    parts = sorted((tmp_path / 'family.nc.parts').iterdir())
    assert [p.name for p in parts] == ['chunk-000000.npz', 'manifest.json']
    out.write_bytes(b'an earlier result')
    maps.mkdir()
    (maps / 'barrier.png').write_bytes(b'an earlier map')
    # without --overwrite: refused before Dask, the output and the resume cache untouched
    refused, _ = _run(SWEEP, *command, '--plot', maps, cwd=tmp_path, blocked=DASK_LIKE)
    _one_line_exit_2(refused, 'family.nc exists')
    assert out.read_bytes() == b'an earlier result'
    assert sorted((tmp_path / 'family.nc.parts').iterdir()) == parts
    # with --overwrite: the cache is resumed (not discarded), the outputs are replaced
    capsys.readouterr()
    assert main([*map(str, command), '--plot', str(maps), '--overwrite']) == 0
    again = capsys.readouterr().err
    assert '0 chunks computed, 1 resumed' in again and f'wrote 15 maps to {maps}' in again, again
    assert out.read_bytes() == written          # the resumed result is bitwise the same
    assert (maps / 'barrier.png').read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert len(_listing(maps)) == 15 and not any(n.startswith('.') for n in _listing(maps))
    assert _listing(tmp_path) == ['family.nc', 'maps']   # cache removed, no temporary


# -- twodisk-animate ------------------------------------------------------------------------

def test_animate_refuses_an_existing_output(tmp_path):
    out = tmp_path / 'run.gif'
    out.write_bytes(b'an earlier animation')
    result, _ = _run(ANIMATE, '-o', out, '--stop', '0.2', cwd=tmp_path, blocked=HEAVY)
    _one_line_exit_2(result, 'run.gif exists', '--overwrite')
    assert out.read_bytes() == b'an earlier animation'
    assert _listing(tmp_path) == ['run.gif']


def test_animate_overwrite_replaces_the_output(tmp_path, monkeypatch, capsys):
    # the command line in this process (its refusals above are the real command)
    from PIL import Image
    from twodisk_ros.plotting.animate_cli import main
    monkeypatch.chdir(tmp_path)
    out = tmp_path / 'run.gif'
    out.write_bytes(b'an earlier animation')
    status = main(['-o', str(out), '--stop', '0.2', '--fps', '10', '--size', '160x120',
                   '--overwrite'])
    assert status == 0, capsys.readouterr().err
    with Image.open(out) as image:
        assert image.format == 'GIF' and image.n_frames == 3 and image.size == (160, 120)
    assert _listing(tmp_path) == ['run.gif']    # no temporary file left


@pytest.mark.parametrize('name, words', [
    ('run.jpg', '.gif, .png (one still) or .mp4'),
    ('run', '.gif, .png (one still) or .mp4'),
    pytest.param('run.mp4', 'ffmpeg', marks=pytest.mark.skipif(
        shutil.which('ffmpeg') is not None, reason='ffmpeg is installed: .mp4 is writable')),
])
def test_animate_refuses_a_suffix_it_cannot_write(tmp_path, name, words):
    result, _ = _run(ANIMATE, '-o', tmp_path / name, '--stop', '0.2', cwd=tmp_path,
                     blocked=HEAVY)
    _one_line_exit_2(result, words)
    assert _listing(tmp_path) == []


@pytest.mark.parametrize('args, words', [
    # the old code simulated 2e11 samples: 'internal error: MemoryError ... 1.46 TiB'
    (['--stop', '1e9'], ['15000000001 frames', 'allowed: at most 3600 frames']),
    (['--fps', '120', '--stop', '100'], ['12001 frames', 'allowed: at most 3600 frames']),
    (['--start', '5000', '--stop', '5001'], ['allowed: --stop <= 3600 s']),
    # 91 frames of 4096x4096: ~15 GiB, above half of the 2 GiB address space
    (['--stop', '6', '--size', '4096x4096'], ['91 frames of 4096x4096', 'GiB of memory',
                                             'allowed:']),
])
def test_animate_runaway_request_refused_with_what_it_needs(tmp_path, args, words):
    # refused before any frame: scipy, matplotlib and Dask never imported (the wrapper)
    result, _ = _run(ANIMATE, '-o', tmp_path / 'run.gif', *args, cwd=tmp_path,
                     blocked=HEAVY, address_space=True)
    _one_line_exit_2(result, *words)
    assert _listing(tmp_path) == []


# -- --help --------------------------------------------------------------------------------

@pytest.mark.parametrize('module, flag, blocked', [
    (SWEEP, '--help', HEAVY), (SWEEP, '-h', HEAVY), (ANIMATE, '--help', HEAVY),
    (ANIMATE, '-h', HEAVY),
    # the module of the drawing code imports the physics (scipy), not matplotlib
    (ANIMATION, '--help', DASK_LIKE + ('matplotlib',))])
def test_help_exits_0_and_writes_nothing(tmp_path, module, flag, blocked):
    cwd = tmp_path / 'empty'
    cwd.mkdir()
    result, _ = _run(module, flag, cwd=cwd, blocked=blocked)   # the heavy modules blocked
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith('usage:') and '--overwrite' in result.stdout
    assert result.stderr == ''
    assert _listing(cwd) == []
