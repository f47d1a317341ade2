"""Hostile input through the real entry points (issue 19): one line on stderr, exit 2, no
traceback, no hang (subprocess timeouts), nothing of the user's destroyed."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from zygote import Zygote

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(REPO), MPLBACKEND='Agg',
           ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
ENV.setdefault('ROS_DOMAIN_ID', '21')
TIMEOUT = 20     # s: each command answers in about 1 s; a hang (a blocked open) never does


@pytest.fixture(scope='module', autouse=True)
def zygote():
    """The module's runs are children of one fork server (tests/zygote.py): each is the
    command as ``python`` runs it, without ~0.25 s of interpreter start and numpy import."""
    global ZYGOTE
    with Zygote(ENV) as ZYGOTE:
        yield ZYGOTE


def run(module, *args, cwd):
    """(exit code, stderr lines) of ``python -m module args``; fails on a hang."""
    result = ZYGOTE.run(['-m', module, *args], cwd=cwd, timeout=TIMEOUT)
    return result.returncode, result.stderr.splitlines()


def refused(module, *args, cwd, says):
    code, lines = run(module, *args, cwd=cwd)
    assert code == 2, lines
    assert len(lines) == 1 and 'Traceback' not in lines[0], lines
    assert says in lines[0], lines


@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / 'pipe.mcap'
    os.mkfifo(path)
    return path


# -- recordings that are not regular files: opened without blocking, never read -----------

@pytest.mark.parametrize('module', ['twodisk_ros.inspect_mcap',
                                    'twodisk_ros.plotting.animate_cli'])
def test_a_fifo_as_recording_is_refused_without_waiting_for_a_writer(module, fifo, tmp_path):
    extra = ['-o', tmp_path / 'out.gif'] if 'animate' in module else []
    refused(module, fifo, *extra, cwd=tmp_path, says='not a regular file')
    assert fifo.is_fifo() and not (tmp_path / 'out.gif').exists()


@pytest.mark.parametrize('module', ['twodisk_ros.inspect_mcap',
                                    'twodisk_ros.plotting.animate_cli'])
def test_dev_zero_as_recording_is_refused_before_reading(module, tmp_path):
    # /dev/zero never ends: read whole it was a MemoryError (exit 1 from twodisk-animate)
    extra = ['-o', tmp_path / 'out.gif'] if 'animate' in module else []
    refused(module, '/dev/zero', *extra, cwd=tmp_path, says='not a regular file')


def test_a_symlink_to_a_fifo_as_recording_is_refused(fifo, tmp_path):
    link = tmp_path / 'link.mcap'
    link.symlink_to(fifo)
    refused('twodisk_ros.inspect_mcap', link, cwd=tmp_path, says='not a regular file')
    assert link.is_symlink() and fifo.is_fifo()


def test_a_directory_as_recording_still_says_so(tmp_path):
    refused('twodisk_ros.inspect_mcap', tmp_path, cwd=tmp_path, says='it is a directory')


# -- twodisk-sweep: every number bounded before any work ----------------------------------

SWEEP = ['--b-over-a', '0.2', '3', '2', '--delta-over-a', '0.2', '0.5', '2', '--quiet']


def test_sweep_chunk_size_beyond_any_grid_is_refused(tmp_path):
    # was a failed task after the work (int32 cast in the NetCDF), exit 1, a stale cache left
    refused('twodisk_ros.sweep', *SWEEP, '--out', tmp_path / 'm.nc', '--chunk-size',
            '1000000000000', cwd=tmp_path, says='--chunk-size must be an integer from 1 to')
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize('speed', ['1e308', '1e200', '-1', 'nan', 'inf'])
def test_sweep_reference_speed_out_of_range_is_refused(speed, tmp_path):
    # 1e308 ran, printed 20 lines of overflow warnings and wrote a map of NaN, exit 0
    refused('twodisk_ros.sweep', *SWEEP, '--out', tmp_path / 'm.nc', '--reference-speed',
            speed, cwd=tmp_path, says='--reference-speed must be finite, 0 <= W <= 1000')
    assert list(tmp_path.iterdir()) == []


def test_sweep_malformed_scheduler_address_is_one_line(tmp_path):
    # was the refusal, then 10 s later "Exception ignored in Client.__del__" and a traceback
    # (at the process's exit: the real command, once)
    refused('twodisk_ros.sweep', *SWEEP, '--out', tmp_path / 'm.nc', '--scheduler', '!!!',
            cwd=tmp_path, says='is not valid')
    assert not (tmp_path / 'm.nc').exists()


@pytest.mark.parametrize('address', ['!!!', 'tcp://host', 'foo://127.0.0.1:5'])
def test_every_malformed_scheduler_address_is_one_line(address, tmp_path, capsys):
    # the command line in this process (the real command refuses in the test above); a
    # collection afterwards finds no half-made Client to complain about on stderr
    import gc
    from twodisk_ros.sweep.cli import main
    status = main([*SWEEP, '--out', str(tmp_path / 'm.nc'), '--scheduler', address])
    gc.collect()
    lines = capsys.readouterr().err.strip().splitlines()
    assert status == 2, lines
    assert len(lines) == 1 and 'Traceback' not in lines[0], lines
    assert 'is not valid' in lines[0], lines
    assert not (tmp_path / 'm.nc').exists()


def test_sweep_grid_of_ten_billion_says_what_it_would_need(tmp_path):
    refused('twodisk_ros.sweep', '--b-over-a', '0.2', '3', '10000000000', '--delta-over-a',
            '0.2', '0.5', '3', '--out', tmp_path / 'm.nc', cwd=tmp_path, says='would need ~')


# -- twodisk-animate ----------------------------------------------------------------------

@pytest.mark.parametrize('args, says', [
    (['--stop', '1e9'], 'frames'),
    (['--fps', '0'], 'fps must be in'),
    (['--fps', 'nan'], 'finite'),
    (['--size', '100000x100000'], 'size must be between'),
    (['--start', '3', '--stop', '1'], '0 <= start < stop'),
])
def test_animate_runaway_or_empty_requests_are_refused(args, says, tmp_path):
    refused('twodisk_ros.plotting.animate_cli', '-o', tmp_path / 'a.gif', *args, cwd=tmp_path,
            says=says)
    assert list(tmp_path.iterdir()) == []


# -- params files (the one loader of roller and twodisk-animate) --------------------------

LAUGHS = ('/**:\n  ros__parameters:\n    a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n'
          + ''.join(f'    a{i}: &a{i} {{x: *a{i - 1}, y: *a{i - 1}}}\n' for i in range(1, 39)))


@pytest.mark.parametrize('content, says', [
    (LAUGHS, 'aliases'),
    ('/**:\n  ros__parameters: &a\n    x: *a\n', 'aliases'),
    ('/**:\n  ros__parameters:\n    x: ' + '[' * 5000 + ']' * 5000 + '\n', 'a list may hold'),
    ('/**:\n  ros__parameters:\n    x: ' + '{a: ' * 5000 + '1' + '}' * 5000 + '\n', 'nested'),
    (b'\xf2\x00\xff binary', 'not UTF-8'),
])
def test_params_file_bombs_are_refused_by_twodisk_animate(content, says, tmp_path):
    path = tmp_path / 'p.yaml'
    (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
    refused('twodisk_ros.plotting.animate_cli', '-o', tmp_path / 'a.gif', '--params-file',
            path, cwd=tmp_path, says=says)


@pytest.mark.parametrize('special', ['fifo', '/dev/zero', 'directory'])
def test_params_file_that_is_not_a_file_is_refused_by_roller(special, tmp_path):
    path = {'fifo': tmp_path / 'p.yaml', '/dev/zero': '/dev/zero', 'directory': tmp_path}[special]
    if special == 'fifo':
        os.mkfifo(path)
    refused('twodisk_ros.roller', '--ros-args', '--params-file', path, cwd=tmp_path,
            says='--params-file')


# -- roller record:= that is not a regular file, with overwrite:=true ---------------------

def test_record_through_a_symlink_to_a_fifo_is_refused_and_kept(fifo, tmp_path):
    link = tmp_path / 'run.mcap'
    link.symlink_to(fifo)
    refused('twodisk_ros.roller', '--ros-args', '-p', 'realtime:=false', '-p',
            'duration:=0.05', '-p', f'record:={link}', '-p', 'overwrite:=true', cwd=tmp_path,
            says='is a FIFO')
    assert link.is_symlink() and fifo.is_fifo()


#: Modules whose import means that work beyond checking the command line began: Dask and
#: the sweep's modules that compute bodies.
HEAVY = ('dask', 'distributed', 'xarray', 'zarr', 'twodisk_ros.sweep.spec',
         'twodisk_ros.sweep.quantities', 'twodisk_ros.sweep.batch', 'twodisk_ros.sweep.general')


@pytest.mark.parametrize('b_range', [('0.001', '3'), ('0.2', '300')])
def test_sweep_refuses_shapes_outside_the_stated_range(tmp_path, b_range):
    """b/a beyond [0.01, 100] (the node's range) is refused before any work (9 such bodies
    took 100 s before)."""
    # the command, then the heavy modules it had imported when it exited: none, so no body
    # was computed
    probe = ('import atexit, runpy, sys\n'
             'atexit.register(lambda: print(sorted(m for m in HEAVY if m in sys.modules)))\n'
             f'HEAVY = {HEAVY!r}\n'
             "sys.argv = ['twodisk_ros.sweep', *sys.argv[1:]]\n"
             "runpy.run_module('twodisk_ros.sweep', run_name='__main__', alter_sys=True)\n")
    result = subprocess.run(
        [sys.executable, '-c', probe, '--b-over-a', *b_range, '3',
         '--delta-over-a', '0.5', '0.5', '1', '--out', str(tmp_path / 'x.nc')],
        env=dict(os.environ, PYTHONPATH=str(REPO)), capture_output=True, text=True,
        timeout=60)   # hang guard
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, result.stderr
    assert 'b/a must be within [0.01, 100]' in lines[0]
    assert result.stdout.strip() == '[]', result.stdout
    assert list(tmp_path.iterdir()) == []
