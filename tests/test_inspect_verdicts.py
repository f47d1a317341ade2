"""The verdict of ``twodisk-inspect``: PASS (0), FAIL (1), INCOMPLETE (4), and the share of the
run a file holds.

A real recording of the node (batch, 1 s at 1 kHz: 1001 samples, t = 0 … 1 s) is cut at a
third and at two thirds of its bytes: the checks pass on what was recovered, but the run is
not all there, so the verdict is INCOMPLETE, exit 4, and the share is of the run (samples
recovered / (duration × rate + 1)), not of the cut file.  The recovered samples are counted
independently of the inspector, with ``mcap``'s own stream reader and ``mcap_ros2``'s
decoder.  A complete recording and a run stopped by SIGTERM (the node closes its file)
stay PASS, exit 0.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import io  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
from pathlib import Path  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

from mcap.records import Channel, Message  # noqa: E402
from mcap.stream_reader import StreamReader  # noqa: E402
import pytest  # noqa: E402

from cdr_helpers import mcap_decode  # noqa: E402
from roller_here import record_with_roller_main  # noqa: E402
from test_inspect import OLOID, simulate_run, write_run  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
DURATION, RATE = 1.0, 1000.0
EXPECTED = 1001           # the node publishes ticks 0 … duration × rate, both included
SAMPLED = ('pose', 'contact_a', 'contact_b', 'rolling_state')
TYPES = {'pose': 'geometry_msgs/msg/PoseStamped', 'contact_a': 'geometry_msgs/msg/PointStamped',
         'contact_b': 'geometry_msgs/msg/PointStamped',
         'rolling_state': 'sensor_msgs/msg/JointState'}


def env():
    return dict(os.environ, PYTHONPATH=str(ROOT), ROS_DOMAIN_ID=os.environ.get(
        'ROS_DOMAIN_ID', '13'), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')


def inspect(path, *extra):
    """The real entry point in a subprocess: (exit status, stdout, stderr)."""
    result = subprocess.run([sys.executable, '-m', 'twodisk_ros.inspect_mcap', str(path),
                             *extra], capture_output=True, text=True, cwd=ROOT, env=env(),
                            timeout=120)
    assert 'Traceback' not in result.stderr, result.stderr
    return result.returncode, result.stdout, result.stderr


@pytest.fixture
def inspect_here(capsys):
    """The entry point's function in this process: (exit status, stdout, stderr). The real
    entry point (a subprocess) gives each verdict once — PASS (the complete recording), FAIL
    (a failing check on a cut file), INCOMPLETE (the file cut at a third) —; every other
    reading goes through the same function here, without an interpreter start each."""
    from twodisk_ros.inspector.cli import main

    def run(path, *extra):
        capsys.readouterr()
        status = main([str(path), *extra])
        out, err = capsys.readouterr()
        assert 'Traceback' not in err, err
        return status, out, err
    return run


def independent_count(data):
    """(samples, diagnostics) in MCAP bytes, read with mcap's StreamReader (not the package's
    reader): stamps carried by pose, both contacts and rolling_state, decoded by mcap_ros2;
    a cut file is read up to the record the cut breaks."""
    topics, stamps, diagnostics = {}, {role: set() for role in SAMPLED}, 0
    try:
        for record in StreamReader(io.BytesIO(data)).records:
            if isinstance(record, Channel):
                topics[record.id] = record.topic.rsplit('/', 1)[-1]
            elif isinstance(record, Message):
                role = topics.get(record.channel_id)
                if role == 'diagnostics':
                    diagnostics += 1
                elif role in SAMPLED:
                    stamp = mcap_decode(record.data, TYPES[role]).header.stamp
                    stamps[role].add(stamp.sec * 10**9 + stamp.nanosec)
    except Exception:  # noqa: BLE001 - the cut: mcap's reader stops with an error there
        pass
    return len(set.intersection(*stamps.values())), diagnostics


@pytest.fixture(scope='module')
def node_recording(tmp_path_factory):
    """A real recording: the node in batch mode, 1 s at 1 kHz (about half a second to make), through
    its entry function in this process (the signal-stopped run below is a real process)."""
    path = tmp_path_factory.mktemp('verdicts') / 'run.mcap'
    assert record_with_roller_main(('-p', 'realtime:=false', '-p', f'rate:={RATE}',
                                    '-p', f'duration:={DURATION}', '-p', f'record:={path}'),
                                   domain=env()['ROS_DOMAIN_ID'], cwd=ROOT) == 0
    return path


def test_complete_recording_passes(node_recording, inspect_here):
    assert EXPECTED == math.floor(DURATION * RATE) + 1
    status, out, err = inspect(node_recording)
    assert status == 0 and err == '', out
    assert 'result: PASS (all ' in out
    assert 'recovered 1 001 of 1 001 samples of the run (100.0 %), t = 0 … 1 s of 1 s' in out
    assert independent_count(node_recording.read_bytes()) == (EXPECTED, 2)
    status, out, _ = inspect_here(node_recording, '--json')
    document = json.loads(out)
    assert status == 0 and document['verdict'] == 'PASS' and document['exit_status'] == 0
    run = document['summary']['run']
    assert run['complete'] and run['file_complete'] and not run['stopped_early']
    assert run['recovered_samples'] == run['expected_samples'] == EXPECTED
    assert run['share'] == 1.0 and run['recovered_diagnostics'] == 2


@pytest.mark.parametrize('fraction', [1 / 3, 2 / 3])
def test_cut_recording_is_incomplete_with_the_share_of_the_run(tmp_path, node_recording,
                                                                fraction, inspect_here):
    """The cut at a third through the real entry point, at two thirds in this process."""
    data = node_recording.read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[:int(fraction * len(data))])
    samples, diagnostics = independent_count(cut.read_bytes())
    assert 0 < samples < EXPECTED and diagnostics == 0      # the diagnostics went with the cut
    status, out, err = (inspect if fraction < 0.5 else inspect_here)(cut)
    assert status == 4 and err == '', out
    # one decimal, but a run short of a sample is never shown as 100.0 %
    share = f'{min(100 * samples / EXPECTED, 99.9):.1f} %'
    count = f'{samples:,}'.replace(',', ' ')
    phrase = (f'recovered {count} of 1 001 samples of the run ({share}), '
              f't = 0 … {(samples - 1) / RATE:.6g} s of 1 s')
    result = [line for line in out.splitlines() if line.startswith('result: ')]
    # 14 checks: the node records /tf, so the tf check (/tf against the poses) is one of them
    assert len(result) == 1 and result[0].startswith('result: INCOMPLETE (all 14 checks '
                                                     'passed on the recovered part'), result
    assert phrase in result[0] and 'the file is cut' in result[0]
    assert 'PASS (' not in out and 'FAIL' not in out
    assert '0 of 2 diagnostics' in ' '.join(out.split())      # (the run: line may wrap)
    status, out, _ = inspect_here(cut, '--json')
    document = json.loads(out)
    assert status == 4
    assert document['verdict'] == 'INCOMPLETE' and document['exit_status'] == 4
    assert document['passed'] is False and document['checks_passed'] is True
    assert len(document['checks']) == 14 and 'tf' in {c['name'] for c in document['checks']}
    run = document['summary']['run']
    assert run['recovered_samples'] == samples and run['expected_samples'] == EXPECTED
    assert run['share'] == samples / EXPECTED
    assert run['last_s'] == pytest.approx((samples - 1) / RATE, abs=1e-12)
    assert run['truncated'] and not run['complete'] and not run['file_complete']
    assert run['recovered_diagnostics'] == 0 and run['expected_diagnostics'] == 2
    # the share of the file's bytes is another number: that of the cut file
    assert document['summary']['recovered']['total_bytes'] == len(cut.read_bytes())


def test_signal_stopped_node_recording_passes(tmp_path, inspect_here):
    """SIGTERM during a long batch run: the node closes the file; fewer samples, still PASS."""
    path = tmp_path / 'stopped.mcap'
    process = subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '-p', 'realtime:=false',
         '-p', f'rate:={RATE}', '-p', 'duration:=10000.0', '-p', f'record:={path}'],
        cwd=ROOT, env=env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while (not path.exists() or path.stat().st_size < 300_000) and \
                time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.02)
        process.send_signal(signal.SIGTERM)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == 0, err
    samples, _ = independent_count(path.read_bytes())
    expected = 10_000_001
    assert 0 < samples < expected
    status, out, err = inspect_here(path, '--json')
    document = json.loads(out)
    assert status == 0 and err == '', [c for c in document['checks'] if not c['passed']]
    assert document['verdict'] == 'PASS'
    run = document['summary']['run']
    assert run['stopped_early'] and run['complete'] and run['file_complete']
    assert run['recovered_samples'] == samples and run['expected_samples'] == expected
    status, out, _ = inspect_here(path)
    assert status == 0 and 'result: PASS (all ' in out
    assert 'stopped early, the file is complete' in ' '.join(out.split())


# ------------------------------------------------------------------------------------------
# Recordings written with the recorder directly (test_inspect's helpers): short and exact.

SHORT = dict(OLOID, duration='1.0')       # 101 samples at 100 Hz


@pytest.fixture(scope='module')
def short_run():
    return simulate_run(SHORT)


def test_recorder_closed_early_is_a_pass(tmp_path, short_run, inspect_here):
    """A file closed by its writer after 60 of 101 samples: what a stopped run leaves."""
    path = write_run(tmp_path / 'early.mcap', short_run, SHORT, skip=set(range(60, 101)))
    status, out, _ = inspect_here(path, '--json')
    document = json.loads(out)
    assert status == 0 and document['verdict'] == 'PASS'
    run = document['summary']['run']
    assert run['recovered_samples'] == 60 and run['expected_samples'] == 101
    assert run['stopped_early'] and run['last_s'] == pytest.approx(0.59)


def test_samples_missing_inside_a_closed_file_are_not_a_pass(tmp_path, short_run, inspect_here):
    path = write_run(tmp_path / 'gap.mcap', short_run, SHORT, skip={50})
    status, out, _ = inspect_here(path, '--json')
    document = json.loads(out)
    assert status == 1 and document['verdict'] == 'FAIL'   # the timestamps check sees the gap
    run = document['summary']['run']
    assert not run['complete'] and run['missing_inside'] == 1 and not run['stopped_early']
    status, out, _ = inspect_here(path)
    assert 'the run is also INCOMPLETE: 1 samples missing inside the run' in out


@pytest.mark.parametrize('cut', [False, True])
def test_run_until_stopped_has_no_expected_count(tmp_path, short_run, cut, inspect_here):
    """duration 0 (realtime until stopped): only the completeness of the file counts."""
    params = dict(SHORT, duration='0.0', realtime='True')
    path = write_run(tmp_path / 'open.mcap', short_run, params, chunk_size=4096)
    if cut:
        data = path.read_bytes()
        path.write_bytes(data[:len(data) // 2])
    status, out, _ = inspect_here(path, '--json')
    document = json.loads(out)
    run = document['summary']['run']
    assert run['expected_samples'] is None and run['share'] is None
    assert (status, document['verdict']) == ((4, 'INCOMPLETE') if cut else (0, 'PASS'))
    assert 0 < run['recovered_samples'] <= 101
    status, out, _ = inspect_here(path)
    assert 'no count is expected' in ' '.join(out.split())


def test_failing_check_takes_precedence_over_a_cut(tmp_path, short_run):
    run = {key: value.copy() for key, value in short_run.items()}
    run['a'][10, 2] = 0.01                        # A above the ground early in the run
    path = write_run(tmp_path / 'lifted.mcap', run, SHORT, chunk_size=4096)
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])
    status, out, _ = inspect(path)
    assert status == 1
    result = [line for line in out.splitlines() if line.startswith('result: ')][0]
    assert result.startswith('result: FAIL (') and 'ground' in result
    assert 'the run is also INCOMPLETE: the file is cut' in result
