"""Outputs and reliability of ``twodisk-sweep``: Zarr and NetCDF, resume, killed workers, refusals.

The reference of every comparison is an undisturbed sweep of the same grid (the values
themselves are checked against the library in tests/test_sweep.py): a disturbed sweep must
give it bitwise. Interruptions happen at a deterministic point — the client raises SIGINT on
itself, or kills a busy worker, right after its k-th finished chunk (a wrapper around
``run_sweep`` used only here) — never after a sleep. Clusters listen on 127.0.0.1 only; every
process a test starts is stopped in a ``finally``.
"""

import contextlib
import fcntl
import os
from pathlib import Path
import pty
import signal
import struct
import sys
import termios
import time

import numpy as np
import pytest

from twodisk_ros.sweep.cli import main
from twodisk_ros.sweep.dataset import read_sweep
from twodisk_ros.sweep.run import SweepSpec, run_sweep
from twodisk_ros.sweep.spec import block_shape

# 6 x 8 = 48 bodies, both stable families, and Delta/a = 1 (masked) in the last column
B_GRID, D_GRID = ('0.5', '1.5', '6'), ('0.3', '1', '8')
TOTAL = 48


def _spec(chunk):
    return SweepSpec(np.linspace(0.5, 1.5, 6), np.linspace(0.3, 1.0, 8), chunk_size=chunk)


def _argv(out, *more):
    return ['--b-over-a', *B_GRID, '--delta-over-a', *D_GRID, '--out', str(out), *more]


@pytest.fixture(scope='module')
def client():
    """A cluster of two worker threads of this process, its scheduler on 127.0.0.1 (TCP: the
    commands a test starts connect to it); no worker processes to start (the LocalCluster
    of worker processes, dask_client's default, is tested in tests/test_sweep.py)."""
    import logging
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                           protocol='tcp://', host='127.0.0.1', dashboard_address=None,
                           silence_logs=logging.CRITICAL,
                           scheduler_kwargs={'dashboard': False,
                                             'dashboard_address': '127.0.0.1:0'})
    c = Client(cluster, set_as_default=False)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


@pytest.fixture(scope='module', autouse=True)
def bodies_computed_once():
    """Each block's bodies are computed once in this module (dask_helpers.blocks_computed_once):
    the claims here are about the outputs — which blocks are written, resumed, refused, their
    flags, their place in the grid — not about the values (tests/test_sweep.py and
    tests/test_sweep_batch.py check those against the library, and that a body's bits do not
    depend on its batch). Saves the ~1.4 s of CPU of each repeated 48-body sweep."""
    from dask_helpers import blocks_computed_once
    with blocks_computed_once():
        yield


@pytest.fixture
def shared(client, monkeypatch):
    """The command line (cli.main, in this process) runs on the module's cluster instead of
    starting a LocalCluster of its own: for tests about outputs and refusals, not about the
    cluster's life (each LocalCluster costs seconds of CPU in its worker processes)."""
    import contextlib
    import twodisk_ros.sweep.run as run

    @contextlib.contextmanager
    def on_the_module_cluster(scheduler=None, workers=None, **kwargs):
        assert scheduler is None
        yield client

    monkeypatch.setattr(run, 'dask_client', on_the_module_cluster)


@pytest.fixture(scope='module')
def netcdf_run(client, tmp_path_factory):
    """(file, SweepRun) of the undisturbed sweep written as NetCDF."""
    out = tmp_path_factory.mktemp('netcdf') / 'map.nc'
    return out, run_sweep(_spec(5), client, out=out, progress=None, overwrite=False)


@pytest.fixture(scope='module')
def reference(netcdf_run):
    """The undisturbed sweep, in memory (the Dataset its run built before writing the file)."""
    return netcdf_run[1].dataset


@pytest.fixture(scope='module')
def finished_store(client, tmp_path_factory):
    """(store, SweepRun) of the undisturbed sweep written as a Zarr store (a test that needs a
    finished store of the sweep copies it)."""
    store = tmp_path_factory.mktemp('finished') / 'map.zarr'
    return store, run_sweep(_spec(5), client, out=store, progress=None, overwrite=False)


def _same(x, y):
    """Bitwise-equal variables (NaN equal to NaN), coordinates and variable attributes."""
    for name in y.data_vars:
        np.testing.assert_array_equal(x[name].values, y[name].values, err_msg=name)
        assert x[name].attrs.keys() == y[name].attrs.keys(), name
    for name in ('exponent', 'b_over_a', 'delta_over_a'):
        np.testing.assert_array_equal(x[name].values, y[name].values)


def _flags(store):
    """The store's completion flags, read with zarr (not with the sweep's code)."""
    import zarr
    return zarr.open_array(Path(store) / 'computed', mode='r')[...]


def _idle(dask_worker):
    return not dask_worker.state.executing


def _wait_until_idle(client, timeout=60):
    """Return once no worker runs a task: a task the client cancelled still finishes (and
    writes its block) on its worker."""
    deadline = time.monotonic() + timeout
    while not all(client.run(_idle).values()):
        assert time.monotonic() < deadline, 'the workers never went idle'
        time.sleep(0.05)


def _tree(folder):
    """path → (inode, size) of every file: a rewritten chunk gets a new inode (renamed)."""
    return {p: (p.stat().st_ino, p.stat().st_size) for p in Path(folder).rglob('*')
            if p.is_file()}


# -- the blocks ------------------------------------------------------------------------------

@pytest.mark.parametrize('shape', [(1, 1), (1, 7), (7, 1), (6, 8), (13, 5), (3, 100)])
@pytest.mark.parametrize('chunk', [1, 2, 3, 5, 8, 9, 16, 40, 1000])
def test_blocks_cover_the_grid_once_within_the_chunk_size(shape, chunk):
    spec = SweepSpec(np.linspace(0.5, 1.5, shape[0]) if shape[0] > 1 else np.array([1.0]),
                     np.linspace(0.1, 0.9, shape[1]) if shape[1] > 1 else np.array([0.5]),
                     chunk_size=chunk)
    covered = np.zeros((1, *shape), dtype=int)       # one exponent (2): the ellipse's grid
    rows, cols = block_shape(*shape, chunk)
    assert spec.block == (1, rows, cols)
    n, b, d = spec.points()
    assert np.all(n == 2.0)
    for block, flat in zip(spec.blocks(), spec.chunks()):
        covered[block] += 1
        size = covered[block].size
        assert 1 <= size <= chunk
        # a regular chunk grid (Zarr): every block has the block shape, cut at the far edges
        assert block[0] == slice(0, 1) and spec.block_exponent(block) == 2.0
        assert block[1].start % rows == 0 and block[2].start % cols == 0
        assert block[1].stop - block[1].start == min(rows, shape[0] - block[1].start)
        assert block[2].stop - block[2].start == min(cols, shape[1] - block[2].start)
        # the flat indices are the block's points, in the order block_points gives them
        np.testing.assert_array_equal(b[flat], spec.block_points(block)[0])
        np.testing.assert_array_equal(d[flat], spec.block_points(block)[1])
    assert np.all(covered == 1)
    # not wastefully small: whole rows when a row fits, else pieces of >= half the chunk
    if chunk >= shape[1]:
        assert cols == shape[1] and rows > min(shape[0], chunk // shape[1]) / 2
    else:
        assert rows == 1 and cols > chunk / 2


# -- the two formats -------------------------------------------------------------------------

def test_zarr_and_netcdf_are_the_sweep_and_open_with_xarray(reference, netcdf_run,
                                                           finished_store):
    import xarray as xr
    (out, netcdf), (store, zarr_run) = netcdf_run, finished_store
    runs = {out: netcdf, store: zarr_run}
    for path, run in runs.items():
        assert run.computed == len(_spec(5).blocks()) and run.resumed == 0
        assert run.bodies == TOTAL and run.masked == 6 * 1     # the Delta/a = 1 column
        with xr.open_dataset(path) as opened:   # engine auto-detected
            for name in reference.data_vars:
                assert opened[name].attrs['units'] and opened[name].attrs['description']
            assert opened.attrs['package_version'] and opened.attrs['mass_model'] == 'laminae'
            # the ellipse alone: 2-D, exponent a scalar coordinate, as before the exponent axis
            assert dict(opened.sizes) == {'b_over_a': 6, 'delta_over_a': 8}, path
            assert float(opened['exponent']) == 2.0 and opened['exponent'].attrs['units']
            point = {'b_over_a': 1.0, 'delta_over_a': 0.5, 'method': 'nearest'}
            assert float(opened.sel(**point)['cycle_advance']) == float(
                reference.sel(**point)['cycle_advance'])
        _same(read_sweep(path), reference)
    assert np.all(_flags(store) == 1)
    assert sorted(p.name for p in out.parent.iterdir()) == ['map.nc']     # no .parts left
    assert sorted(p.name for p in store.parent.iterdir()) == ['map.zarr']


def test_a_block_killed_mid_write_is_computed_again(client, reference, tmp_path):
    """Whatever a killed worker left of a block — data without its flags, part of the data,
    a torn flag object — the block counts as missing and only such blocks are computed."""
    store, spec = tmp_path / 'map.zarr', _spec(5)
    total = len(spec.blocks())

    class Stop(Exception):
        pass

    def stop_at_the_end(index, computed):
        if computed == total:
            raise Stop        # every block written, the sweep never marked 'complete'

    with pytest.raises(Stop):
        run_sweep(spec, client, out=store, progress=None, on_chunk=stop_at_the_end)
    assert np.all(_flags(store) == 1)
    # block (0, 0): data written, flags not yet; block (1, 1): part of the data and no flags;
    # block (2, 0): a torn flag object (a store that does not write objects atomically);
    # chunk keys b/delta (the ellipse alone: a 2-D store, no exponent axis)
    (store / 'computed/c/0/0').unlink()
    (store / 'computed/c/1/1').unlink()
    for name in ('theta_max', 'mu_required', 'failure'):
        (store / name / 'c/1/1').unlink(missing_ok=True)
    flag = store / 'computed/c/2/0'
    flag.write_bytes(flag.read_bytes()[:5])
    kept = {p: v for p, v in _tree(store).items() if '/c/' in str(p)
            and not any(str(p).endswith(f'/c/{k}') for k in ('0/0', '1/1', '2/0'))}
    again = run_sweep(spec, client, out=store, progress=None, overwrite=False)
    assert (again.computed, again.resumed) == (3, total - 3)
    _same(read_sweep(store), reference)
    tree = _tree(store)
    assert all(tree[p] == v for p, v in kept.items())    # the other chunks were not rewritten


class _Killed(BaseException):
    pass


def test_the_flags_are_written_after_every_variable(tmp_path, monkeypatch):
    """A worker killed at any write of a block (the k-th of its chunk objects) leaves the
    block's flags at 0: the flags are the block's last write."""
    import shutil
    import zarr
    from twodisk_ros.sweep import store as zstore
    spec = SweepSpec(np.array([1.0]), np.array([0.5]), chunk_size=1)
    # the store as create_store lays it out, copied afresh for each write to kill at
    pristine = zstore.create_store(tmp_path / 'pristine.zarr', spec)
    path = tmp_path / 'one.zarr'
    shutil.copytree(pristine, path)
    real = zarr.Array.__setitem__
    writes = []     # the arrays written by write_block, in order
    kill_at = None  # kill at this write (0: watch only; None: neither)

    def write(array, selection, value):
        if kill_at is not None:
            writes.append(array.basename)
            if len(writes) == kill_at:
                raise _Killed
        real(array, selection, value)

    monkeypatch.setattr(zarr.Array, '__setitem__', write)
    variables = set(read_sweep(path).data_vars)
    kill_at = 0         # watch, never kill
    zstore.write_block(str(path), spec.blocks()[0], spec.b_over_a, spec.delta_over_a,
                       'laminae', 0.5)
    assert set(writes) == variables and writes[-1] == 'computed'
    for k in range(1, len(variables) + 1):
        kill_at = None
        shutil.rmtree(path)
        shutil.copytree(pristine, path)
        writes.clear()
        kill_at = k
        with pytest.raises(_Killed):
            zstore.write_block(str(path), spec.blocks()[0], spec.b_over_a, spec.delta_over_a,
                               'laminae', 0.5)
        kill_at = None
        assert _flags(path)[0, 0] == 0, writes       # a 2-D store (no exponent axis)
        assert zstore.complete_blocks(path, spec) == set()


# -- interrupted and resumed -----------------------------------------------------------------

@contextlib.contextmanager
def _sigint_raises_keyboardinterrupt():
    """Python's own SIGINT handler within (a suite started in the background or under nohup
    runs with SIGINT ignored, and the command line's script installs the handler the same
    way: tests/test_sweep.py runs it as a command); the handler and the levels of the loggers
    that an interrupted command line quiets for the rest of its process restored at exit."""
    import logging
    levels = {name: logging.getLogger(name).level for name in logging.root.manager.loggerDict}
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        for name, level in levels.items():
            logging.getLogger(name).setLevel(level)


@pytest.mark.slow
def test_interrupted_zarr_sweep_resumes_only_the_missing_chunks(client, reference, shared,
                                                                tmp_path, capsys,
                                                                monkeypatch):
    # the command line in this process, on the module's cluster: a real SIGINT (the process
    # signals itself right after the client's 5th finished chunk), then the rerun
    import twodisk_ros.sweep.run as run
    store = tmp_path / 'map.zarr'
    argv = _argv(store, '--chunk-size', '2')
    blocks = len(SweepSpec(np.linspace(0.5, 1.5, 6), np.linspace(0.3, 1.0, 8),
                           chunk_size=2).blocks())
    assert blocks == TOTAL // 2
    real = run.run_sweep

    def hooked(spec, sweep_client, *args, **kwargs):
        def on_chunk(index, computed):
            if computed == 5:
                signal.raise_signal(signal.SIGINT)
                raise AssertionError('SIGINT raised nothing')
        return real(spec, sweep_client, *args, on_chunk=on_chunk, **kwargs)

    capsys.readouterr()
    with monkeypatch.context() as patch, _sigint_raises_keyboardinterrupt():
        patch.setattr(run, 'run_sweep', hooked)
        status = main(argv)
    err = capsys.readouterr().err
    assert status == 130, err
    assert err.strip().splitlines() == [
        f'twodisk-sweep: interrupted; finished chunks are kept in {store} - run the same '
        'command again to resume']
    _wait_until_idle(client)    # a cancelled task still finishes on its worker
    flags = _flags(store)
    finished = int(flags.sum()) // 2   # 5, or a few more finished by the workers meanwhile
    assert 5 <= finished < blocks
    kept = {p: v for p, v in _tree(store).items() if '/computed/c/' in str(p)}
    assert len(kept) == finished
    assert main([*argv, '--quiet']) == 0
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert f'{blocks - finished} chunks computed, {finished} resumed' in last, last
    tree = _tree(store)
    assert all(tree[p] == v for p, v in kept.items())     # the finished chunks untouched
    _same(read_sweep(store), reference)
    assert np.all(_flags(store) == 1)


@pytest.mark.slow
def test_a_worker_killed_mid_sweep_changes_nothing(client, reference, tmp_path, capsys,
                                                  monkeypatch):
    # the command line runs in this process on the module's scheduler, joined by one
    # `dask worker` command; the hook kills that worker while it is busy (the module's two
    # worker threads finish the sweep)
    import twodisk_ros.sweep.run as run
    from dask_helpers import worker_processes
    store = tmp_path / 'map.zarr'
    real = run.run_sweep

    with worker_processes(tmp_path, client) as procs:
        (proc,) = procs

        def hooked(spec, sweep_client, *args, **kwargs):
            def on_chunk(index, computed):
                if computed != 3:
                    return
                address = next(a for a, pid in sweep_client.run(os.getpid).items()
                               if pid == proc.pid)
                # wait for the event (a task on the worker), never a sleep of a guessed length
                deadline = time.monotonic() + 60
                while not sweep_client.processing(workers=[address])[address]:
                    assert time.monotonic() < deadline, 'the worker command never got a task'
                    time.sleep(0.01)
                proc.kill()         # SIGKILL: one process (no nanny), nothing it started
                print('killed a busy worker after 3 chunks', file=sys.stderr)
            return real(spec, sweep_client, *args, on_chunk=on_chunk, **kwargs)

        monkeypatch.setattr(run, 'run_sweep', hooked)
        status = main(_argv(store, '--chunk-size', '5', '--scheduler',
                            client.scheduler.address))
        err = capsys.readouterr().err
        dead = proc.poll()
    assert status == 0, err
    lines = err.strip().splitlines()
    assert lines[0] == 'killed a busy worker after 3 chunks', lines
    assert dead == -9                                       # the `dask worker` is gone
    assert f'({TOTAL} bodies, 6 masked; ' in lines[-1] and 'Traceback' not in err
    _same(read_sweep(store), reference)
    assert np.all(_flags(store) == 1)


# -- existing outputs ------------------------------------------------------------------------

def _fails_in_one_line(argv, capsys, *words):
    status = main(argv)
    err = capsys.readouterr().err
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1 and 'Traceback' not in err, err
    for word in words:
        assert word in err, err
    return err


@pytest.mark.slow
def test_an_existing_zarr_store_is_refused_unless_overwrite(reference, finished_store, shared,
                                                           tmp_path, capsys):
    import shutil
    store = tmp_path / 'map.zarr'
    shutil.copytree(finished_store[0], store)       # the finished store of this sweep
    argv = _argv(store, '--chunk-size', '5', '--workers', '1', '--quiet')
    before = _tree(store)
    _fails_in_one_line(argv, capsys, 'map.zarr exists', '--overwrite')
    assert _tree(store) == before
    # another grid: refused the same way (the store is finished, whatever it holds)
    other = ['--b-over-a', '0.5', '1.5', '3', *argv[4:]]
    _fails_in_one_line(other, capsys, 'map.zarr exists', '--overwrite')
    assert _tree(store) == before
    assert main([*argv, '--overwrite']) == 0
    assert f'{len(_spec(5).blocks())} chunks computed, 0 resumed' in capsys.readouterr().err
    _same(read_sweep(store), reference)


def test_an_interrupted_store_of_another_sweep_is_refused(client, tmp_path, capsys):
    store = tmp_path / 'map.zarr'

    class Stop(Exception):
        pass

    with pytest.raises(Stop):
        run_sweep(_spec(5), client, out=store, progress=None,
                  on_chunk=lambda index, computed: (_ for _ in ()).throw(Stop()))
    _wait_until_idle(client)
    before = _tree(store)
    _fails_in_one_line(_argv(store, '--chunk-size', '4'), capsys, 'map.zarr holds an '
                       'interrupted sweep of a different grid or options', '--overwrite')
    assert _tree(store) == before


@pytest.mark.parametrize('make, words', [
    (lambda p: p.mkdir() or (p / 'notes.txt').write_text('mine'), 'is not a twodisk-sweep'),
    (lambda p: p.write_text('a file'), 'is not a directory'),
])
@pytest.mark.parametrize('overwrite', [[], ['--overwrite']])
def test_what_the_sweep_did_not_write_is_never_replaced(make, words, overwrite, tmp_path,
                                                        capsys):
    store = tmp_path / 'map.zarr'
    make(store)
    before = _tree(tmp_path)
    _fails_in_one_line(_argv(store, *overwrite), capsys, words)
    assert _tree(tmp_path) == before


# -- bad input -------------------------------------------------------------------------------

@pytest.mark.parametrize('override, words', [
    ({'--b-over-a': ['1.5', '0.5', '3']}, 'reversed'),
    ({'--delta-over-a': ['0.5', '0.5', '3']}, 'empty range'),
    ({'--delta-over-a': ['0.25', '0.75', '1']}, 'empty range'),   # one point, two values
    ({'--b-over-a': ['nan', '1.5', '3']}, 'finite'),
    ({'--delta-over-a': ['0.25', 'nan', '3']}, 'finite'),
    ({'--keep-parts': []}, '--keep-parts is for a .nc output only'),
    ({'--out': ['{tmp}/x.zip']}, 'allowed: .nc, .zarr'),
])
def test_bad_input_for_a_zarr_store_one_line_exit_2(override, words, tmp_path, capsys):
    options = {'--b-over-a': ['0.5', '1.5', '3'], '--delta-over-a': ['0.25', '0.75', '3'],
               '--out': [str(tmp_path / 'x.zarr')], **override}
    argv = [x for key, values in options.items()
            for x in [key, *(v.replace('{tmp}', str(tmp_path)) for v in values)]]
    _fails_in_one_line(argv, capsys, words)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_grid_without_any_computable_body_leaves_no_store(shared, tmp_path, capsys):
    # Delta/a = 1e-300 passes the command line, but the body refuses a length below its range
    _fails_in_one_line(['--b-over-a', '1', '1', '1', '--delta-over-a', '1e-300', '1e-300', '1',
                        '--out', str(tmp_path / 'x.zarr'), '--workers', '1', '--quiet'],
                       capsys, 'no body of the grid could be computed', 'nothing written')
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_unreachable_scheduler_creates_no_store(tmp_path, capsys):
    # the command line in this process (tests/test_sweep.py runs it as a command)
    from dask_helpers import free_port
    _fails_in_one_line([*_argv(tmp_path / 'x.zarr'), '--scheduler',
                        f'tcp://127.0.0.1:{free_port()}'], capsys, 'cannot reach the Dask scheduler')
    assert list(tmp_path.iterdir()) == []


# -- progress --------------------------------------------------------------------------------

def _stderr_on_a_terminal(argv, monkeypatch):
    """(exit status, text) of the command line (cli.main, in this process) with its stderr on
    a pseudo-terminal of 100 columns (a reader thread empties the terminal meanwhile)."""
    import threading
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack('HHHH', 24, 100, 0, 0))
    chunks = []

    def read():
        while True:
            try:
                data = os.read(leader, 65536)
            except OSError:          # EIO: the terminal's other side is closed
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    terminal = open(follower, 'w', encoding='utf-8')
    try:
        with monkeypatch.context() as patch:
            patch.setattr(sys, 'stderr', terminal)
            status = main(argv)
    finally:
        terminal.close()
        reader.join(timeout=60)
        os.close(leader)
    assert not reader.is_alive()
    return status, b''.join(chunks).decode('utf-8', 'replace')


@pytest.mark.slow
def test_progress_bar_on_a_terminal_only(shared, tmp_path, monkeypatch):
    status, text = _stderr_on_a_terminal(_argv(tmp_path / 'a.nc', '--chunk-size', '8'),
                                         monkeypatch)
    assert status == 0, text
    # tqdm's bar, ending at 100 % of the bodies, then the summary line
    assert '100%' in text and f'{TOTAL}/{TOTAL}' in text and 'body/s' in text, text
    last = text.replace('\r', '\n').strip().splitlines()[-1]
    assert last.startswith(f'twodisk-sweep: wrote {tmp_path / "a.nc"} ({TOTAL} bodies, '
                           f'6 masked; 6 chunks computed, 0 resumed; '), last
    assert last.endswith(' bodies/s)'), last
    status, text = _stderr_on_a_terminal(_argv(tmp_path / 'b.nc', '--chunk-size', '8',
                                               '--quiet'), monkeypatch)
    assert status == 0 and '%' not in text and len(text.strip().splitlines()) == 1, text


def test_a_stopped_clients_close_reports_nothing_on_top_of_the_one_line(client, monkeypatch,
                                                                         caplog):
    """What asyncio and Dask log while a stopped sweep's client closes (seen on a loaded
    machine: "Future exception was never retrieved ... TimeoutError: Timeout" after the
    interrupted line) is not shown; a client closed after a finished sweep still shows it,
    and the loggers' levels are what they were."""
    import logging
    import distributed
    import twodisk_ros.sweep.run as run

    class NoisyClient:
        def __init__(self, *args, **kwargs):
            pass

        def close(self):
            logging.getLogger('asyncio').error('Future exception was never retrieved')
            logging.getLogger('distributed.client').error('closing failed')

    monkeypatch.setattr(distributed, 'Client', NoisyClient)
    address = client.scheduler.address
    names = (*run.SHUTDOWN_LOGGERS, 'distributed.client', 'distributed.scheduler')
    levels = {name: logging.getLogger(name).level for name in names}
    caplog.set_level(logging.INFO)
    with pytest.raises(KeyboardInterrupt):
        with run.dask_client(address):
            raise KeyboardInterrupt
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR] == []
    assert {name: logging.getLogger(name).level for name in names} == levels
    with run.dask_client(address):
        pass
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR] == [
        'Future exception was never retrieved', 'closing failed']
