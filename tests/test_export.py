"""``twodisk-inspect --csv/--npz``: the recorded states as a table, and the rule for outputs.

The table of a real node recording is read back with pandas, numpy.genfromtxt and numpy.load
and compared, exactly, with the messages decoded independently: mcap's StreamReader and
mcap_ros2's decoder (tests/cdr_helpers.py), not the package's reader.  Floats are written so
that they read back to the same float64, so the comparison is equality, NaN included.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import io  # noqa: E402
from pathlib import Path  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

from mcap.records import Channel, Message  # noqa: E402
from mcap.stream_reader import StreamReader  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from cdr_helpers import mcap_decode  # noqa: E402
from roller_here import record_with_roller_main  # noqa: E402
from test_inspect import OLOID, simulate_run, write_run  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
NAMES = ['t', 'stamp', 'G_x', 'G_y', 'G_z', 'q_x', 'q_y', 'q_z', 'q_w', 'A_x', 'A_y', 'A_z',
         'B_x', 'B_y', 'B_z', 'theta', 'psi', 'u', 'theta_rate', 'psi_rate', 'u_rate',
         'F_A_x', 'F_A_y', 'F_A_z', 'F_B_x', 'F_B_y', 'F_B_z']
UNITS = ['s', 'ns', 'm', 'm', 'm', '1', '1', '1', '1', 'm', 'm', 'm', 'm', 'm', 'm', 'rad',
         'rad', 'rad', 'rad/s', 'rad/s', 'rad/s', 'N', 'N', 'N', 'N', 'N', 'N']
TYPES = {'pose': 'geometry_msgs/msg/PoseStamped', 'contact_a': 'geometry_msgs/msg/PointStamped',
         'contact_b': 'geometry_msgs/msg/PointStamped',
         'rolling_state': 'sensor_msgs/msg/JointState',
         'wrench_a': 'geometry_msgs/msg/WrenchStamped',
         'wrench_b': 'geometry_msgs/msg/WrenchStamped'}


def env():
    return dict(os.environ, PYTHONPATH=str(ROOT), ROS_DOMAIN_ID=os.environ.get(
        'ROS_DOMAIN_ID', '13'), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')


def inspect(*args):
    """The real entry point in a subprocess: (exit status, stdout, stderr)."""
    result = subprocess.run([sys.executable, '-m', 'twodisk_ros.inspect_mcap',
                             *map(str, args)], capture_output=True, text=True, cwd=ROOT,
                            env=env(), timeout=120)
    assert 'Traceback' not in result.stderr, result.stderr
    return result.returncode, result.stdout, result.stderr


@pytest.fixture
def inspect_here(capsys):
    """The entry point's function in this process: (exit status, stdout, stderr). The real
    entry point (a subprocess) writes the module's tables (``exported``) and gives each kind
    of refusal once (an existing output, a wrong suffix) and ``--help``; the other calls go
    through the same function here, without an interpreter start each."""
    from twodisk_ros.inspector.cli import main

    def run(*args):
        capsys.readouterr()
        status = main([str(arg) for arg in args])
        out, err = capsys.readouterr()
        assert 'Traceback' not in err, err
        return status, out, err
    return run


def decoded_table(path):
    """The expected columns, from the messages decoded with mcap and mcap_ros2 alone."""
    topics, rows = {}, {role: {} for role in TYPES}
    try:
        for record in StreamReader(io.BytesIO(Path(path).read_bytes())).records:
            if isinstance(record, Channel):
                topics[record.id] = record.topic.rsplit('/', 1)[-1]
            elif isinstance(record, Message) and topics.get(record.channel_id) in TYPES:
                role = topics[record.channel_id]
                msg = mcap_decode(record.data, TYPES[role])
                stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
                rows[role].setdefault(stamp, msg)          # the first message of a stamp
    except Exception:  # noqa: BLE001 - a cut file: mcap's reader stops at the cut
        pass
    stamps = sorted(set(rows['pose']).intersection(
        rows['contact_a'], rows['contact_b'], rows['rolling_state']))
    nan = float('nan')
    table = {name: [] for name in NAMES}
    for stamp in stamps:
        pose, state = rows['pose'][stamp], rows['rolling_state'][stamp]
        p, q = pose.pose.position, pose.pose.orientation
        values = [stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w]
        for role in ('contact_a', 'contact_b'):
            point = rows[role][stamp].point
            values += [point.x, point.y, point.z]
        index = [list(state.name).index(name) for name in ('theta', 'psi', 'phase')]
        values += [state.position[k] for k in index] + [state.velocity[k] for k in index]
        for role in ('wrench_a', 'wrench_b'):
            wrench = rows[role].get(stamp)
            force = wrench.wrench.force if wrench is not None else None
            values += [force.x, force.y, force.z] if force is not None else [nan] * 3
        for name, value in zip(NAMES[1:], values):
            table[name].append(value)
    table['stamp'] = np.array(table['stamp'], dtype=np.int64)
    table['t'] = (table['stamp'] - table['stamp'][0]) * 1e-9
    return {name: np.asarray(value) for name, value in table.items()}


@pytest.fixture(scope='module')
def node_recording(tmp_path_factory):
    """A real recording: the node in batch mode, 2 s at 100 Hz, with the contact forces,
    through its entry function in this process."""
    path = tmp_path_factory.mktemp('export') / 'run.mcap'
    assert record_with_roller_main(('-p', 'realtime:=false', '-p', 'rate:=100.0',
                                    '-p', 'duration:=2.0', '-p', f'record:={path}'),
                                   domain=env()['ROS_DOMAIN_ID'], cwd=ROOT) == 0
    return path


@pytest.fixture(scope='module')
def exported(node_recording, tmp_path_factory):
    out = tmp_path_factory.mktemp('tables')
    csv, npz = out / 'states.csv', out / 'states.npz'
    status, stdout, err = inspect(node_recording, '--csv', csv, '--npz', npz)
    assert status == 0 and err == '', stdout
    assert f'csv: {csv}' in stdout and f'npz: {npz}' in stdout
    assert sorted(p.name for p in out.iterdir()) == ['states.csv', 'states.npz']   # no temps
    return csv, npz, decoded_table(node_recording)


def assert_same(actual, expected, name):
    assert actual.shape == expected.shape, name
    assert np.array_equal(actual, expected, equal_nan=True), (
        name, np.max(np.abs(actual - expected)))


def test_csv_reads_back_exactly_with_pandas(exported):
    csv, _, expected = exported
    frame = pd.read_csv(csv)
    assert list(frame.columns) == [f'{n} [{u}]' for n, u in zip(NAMES, UNITS)]
    assert len(frame) == 201 and frame['stamp [ns]'].dtype == np.int64
    for name, unit in zip(NAMES, UNITS):
        assert_same(frame[f'{name} [{unit}]'].to_numpy(), expected[name], name)
    assert np.all(np.isfinite(frame.to_numpy(dtype=float)))     # forces recorded: no NaN
    assert frame['t [s]'].iloc[-1] == pytest.approx(2.0, abs=1e-12)


def test_csv_reads_with_numpy_genfromtxt(exported):
    csv, _, expected = exported
    data = np.genfromtxt(csv, delimiter=',', names=True)
    assert data.shape == (201,) and len(data.dtype.names) == 27
    assert data.dtype.names[0] == 't_s' and 'theta_rate_rads' in data.dtype.names
    for field, name in zip(data.dtype.names, NAMES):
        if name != 'stamp':      # stamps near 1.8e18 ns do not fit a float64's 53 bits
            assert_same(data[field], expected[name], name)
    loaded = np.loadtxt(csv, delimiter=',', skiprows=1)
    assert loaded.shape == (201, 27)


def test_npz_one_array_per_column_with_units(exported):
    _, npz, expected = exported
    with np.load(npz) as data:            # allow_pickle=False: plain arrays only
        assert list(data['columns']) == NAMES and list(data['units']) == UNITS
        assert set(data.files) == set(NAMES) | {'columns', 'units'}
        assert data['stamp'].dtype == np.int64
        for name in NAMES:
            assert_same(data[name], expected[name], name)


def test_recording_without_wrenches_has_nan_forces(tmp_path, inspect_here):
    params = dict(OLOID, duration='0.5')
    path = write_run(tmp_path / 'old.mcap', simulate_run(params), params)
    csv, npz = tmp_path / 'old.csv', tmp_path / 'old.npz'
    status, out, err = inspect_here(path, '--npz', npz, '--csv', csv, '--json')
    assert status == 0 and err == ''
    assert out.lstrip().startswith('{')   # --json: stdout is the JSON document only
    frame = pd.read_csv(csv)
    expected = decoded_table(path)
    assert len(frame) == 51
    for name, unit in zip(NAMES, UNITS):
        assert_same(frame[f'{name} [{unit}]'].to_numpy(), expected[name], name)
    forces = frame[[c for c in frame.columns if c.startswith('F_')]].to_numpy()
    assert forces.shape == (51, 6) and np.all(np.isnan(forces))
    with np.load(npz) as data:
        assert np.all(np.isnan(data['F_B_z'])) and data['t'].size == 51


def test_cut_recording_exports_what_was_recovered(tmp_path, node_recording, inspect_here):
    data = node_recording.read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[:len(data) // 3])
    csv = tmp_path / 'cut.csv'
    status, _, err = inspect_here(cut, '--csv', csv)
    assert status == 4 and err == ''      # INCOMPLETE, the table written all the same
    frame = pd.read_csv(csv)
    expected = decoded_table(cut)
    assert 0 < len(frame) == expected['stamp'].size <= 201
    for name, unit in zip(NAMES, UNITS):
        assert_same(frame[f'{name} [{unit}]'].to_numpy(), expected[name], name)


# ------------------------------------------------------------------------------------------
# Outputs: refused before any work unless --overwrite; the old file kept byte for byte.

@pytest.mark.parametrize('option, suffix', [('--csv', '.csv'), ('--npz', '.npz'),
                                            ('--plot', '.png')])
def test_existing_output_is_refused_without_overwrite(tmp_path, node_recording, option,
                                                      suffix, inspect_here):
    """--csv through the real entry point, the others in this process."""
    target = tmp_path / f'out{suffix}'
    target.write_bytes(b'precious\x00bytes')
    status, out, err = (inspect if option == '--csv' else inspect_here)(node_recording, option,
                                                                         target)
    assert status == 2 and out == ''
    lines = err.splitlines()
    assert len(lines) == 1 and str(target) in lines[0] and '--overwrite' in lines[0], err
    assert target.read_bytes() == b'precious\x00bytes'
    # refused before the recording is read: the same line for a recording that is not there
    status, _, err = inspect_here(tmp_path / 'missing.mcap', option, target)
    assert status == 2 and '--overwrite' in err and 'cannot read recording' not in err
    status, out, err = inspect_here(node_recording, option, target, '--overwrite')
    assert status == 0 and err == '', err
    assert target.read_bytes() != b'precious\x00bytes' and target.stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]     # no temp files


@pytest.mark.parametrize('option, name', [('--plot', 'figure.pdf'), ('--plot', 'figure'),
                                          ('--csv', 'states.txt'), ('--npz', 'states.npy'),
                                          ('--csv', 'states.npz')])
def test_wrong_suffix_is_refused(tmp_path, node_recording, option, name, inspect_here):
    """The first case through the real entry point, the others in this process."""
    run = inspect if name == 'figure.pdf' else inspect_here
    status, out, err = run(node_recording, option, tmp_path / name)
    assert status == 2 and out == '' and len(err.splitlines()) == 1, err
    assert 'allowed: .' in err and list(tmp_path.iterdir()) == []


def test_three_outputs_at_once(tmp_path, node_recording, inspect_here):
    status, _, err = inspect_here(node_recording, '--csv', tmp_path / 'a.csv', '--npz',
                                  tmp_path / 'a.npz', '--plot', tmp_path / 'a.png')
    assert status == 0 and err == ''
    assert sorted(p.name for p in tmp_path.iterdir()) == ['a.csv', 'a.npz', 'a.png']


def test_help_has_no_side_effects(tmp_path):
    result = subprocess.run([sys.executable, '-m', 'twodisk_ros.inspect_mcap', '--help'],
                            capture_output=True, text=True, cwd=tmp_path, env=env(),
                            timeout=60)
    assert result.returncode == 0 and '--csv' in result.stdout and '--overwrite' in result.stdout
    assert 'INCOMPLETE' in result.stdout and list(tmp_path.iterdir()) == []
