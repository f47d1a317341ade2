"""Tests of ``twodisk-inspect`` on recordings built here from simulated physics states.

The recordings follow the node's contract (topics under a namespace, stamps = simulated time,
metadata ``twodisk_ros``) but are written directly with :class:`McapRecorder`, so every
corruption is under the test's control.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '57')

import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from builtin_interfaces.msg import Time  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue  # noqa: E402
from geometry_msgs.msg import Point, PointStamped, Pose, PoseStamped, Quaternion  # noqa: E402
from nav_msgs.msg import Path as PathMsg  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Header  # noqa: E402

from twodisk_ros.inspector import cli as inspect_cli  # noqa: E402
from twodisk_ros.inspector import finite_differences, inspect_recording  # noqa: E402
from twodisk_ros.physics.bodies.ellipse import EllipseBody  # noqa: E402
from twodisk_ros.physics import RollingDynamics, simulate  # noqa: E402
from twodisk_ros.physics.mass.models import mass_properties  # noqa: E402
from twodisk_ros.recordings import McapRecorder, read_recording  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]

#: The node's parameters for a 3 s oloid run in dynamic mode at 100 Hz.
OLOID = {
    'a': '1.0', 'b': '1.0', 'delta': '0.5', 'mass': '2.0', 'gravity': '9.81',
    'mass_model': 'laminae', 'principal_moments': '[0.1, 0.2, 0.1]', 'mode': 'dynamic',
    'theta0': '0.3', 'branch': '1', 'omega0': '3.0', 'rate': '100.0', 'duration': '3.0',
    'realtime': 'False', 'method': 'table', 'tolerance': '1e-10', 'frame_id': 'world',
    'path_length': '200', 'record': 'run.mcap', 'version': '0.1.0',
}


# ------------------------------------------------------------------------------------------
# Recordings from physics states.

def simulate_run(params):
    """Sample the motion the parameters describe: stamps, poses, contacts, angles, energy."""
    body = EllipseBody(float(params['a']), float(params['b']), float(params['delta']))
    mass = mass_properties(params['mass_model'], body.a, body.b, body.delta,
                           float(params['mass']))
    dynamics = RollingDynamics(body, mass, float(params['gravity']))
    rate = float(params['rate'])
    count = int(round(float(params['duration']) * rate)) + 1
    stamps = np.array([round(i * 1e9 / rate) for i in range(count)], dtype=np.int64)
    motion = simulate(dynamics, stamps * 1e-9, mode=params['mode'],
                      theta0=float(params['theta0']), branch=int(params['branch']),
                      omega0=float(params['omega0']), method=params['method'],
                      tolerance=float(params['tolerance']))
    state = dynamics.cycle.state(motion.phase)
    step = 1e-6   # rad of u: dθ/du and dψ/du by central differences (only recorded)
    ahead, behind = body.phase_geometry(motion.phase + step), body.phase_geometry(
        motion.phase - step)
    angle_rates = np.stack([(ahead.theta - behind.theta) / (2 * step),
                            np.angle(np.exp(1j * (ahead.psi - behind.psi))) / (2 * step),
                            np.ones_like(motion.phase)], axis=1) * motion.phase_rate[:, None]
    return {
        'stamp': stamps,
        'g': state.position_g.copy(),
        'quaternion': state.quaternion.copy(),
        'a': state.contact_a.copy(),
        'b': state.contact_b.copy(),
        'angles': np.stack([state.theta, state.psi, motion.phase], axis=1),
        'rates': angle_rates,
        'energy': motion.energy.copy(),
    }


@pytest.fixture(scope='module')
def oloid_run():
    return simulate_run(OLOID)


def copy_run(run):
    return {key: value.copy() for key, value in run.items()}


def header(stamp, frame='world'):
    sec, nanosec = divmod(int(stamp), 10**9)
    return Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=frame)


def point(xyz):
    return Point(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def write_run(path, run, params, *, namespace='/roller', skip=(), late=None,
              chunk_size=64 * 1024):
    """Record ``run`` as the node does.

    Samples whose index is in ``skip`` are left out; ``late`` maps topics (``'contact_b'``)
    to a delay of their stamps (ns).
    """
    late = late or {}
    rate = float(params['rate'])
    energy0 = run['energy'][0]
    with McapRecorder(path, metadata=params, chunk_size=chunk_size) as rec:
        topics = {
            'pose': PoseStamped, 'contact_a': PointStamped, 'contact_b': PointStamped,
            'rolling_state': JointState, 'path_g': PathMsg,
        }
        for name, msg_type in topics.items():
            rec.add_topic(f'{namespace}/{name}', msg_type)
        rec.add_topic('/diagnostics', DiagnosticArray)
        trail = []
        for i, stamp in enumerate(run['stamp']):
            if i in skip:
                continue
            q = run['quaternion'][i]
            pose = PoseStamped(header=header(stamp), pose=Pose(
                position=point(run['g'][i]),
                orientation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3])))
            messages = {
                'pose': pose,
                'contact_a': PointStamped(header=header(stamp), point=point(run['a'][i])),
                'contact_b': PointStamped(header=header(stamp), point=point(run['b'][i])),
                'rolling_state': JointState(
                    header=header(stamp), name=['theta', 'psi', 'phase'],
                    position=[float(x) for x in run['angles'][i]],
                    velocity=[float(x) for x in run['rates'][i]]),
            }
            for name, msg in messages.items():
                if name in late:
                    msg.header = header(stamp + late[name])
                rec.write(f'{namespace}/{name}', msg, int(stamp) + late.get(name, 0))
            trail.append(pose)
            if i % max(1, round(rate / 10)) == 0:
                rec.write(f'{namespace}/path_g', PathMsg(header=header(stamp),
                                                         poses=trail[-200:]), int(stamp))
            if i % round(rate) == 0:
                energy = run['energy'][i]
                status = DiagnosticStatus(name='roller', message='ok', values=[
                    KeyValue(key='energy', value=repr(float(energy))),
                    KeyValue(key='energy_drift',
                             value=repr(float(abs(energy - energy0) / abs(energy0))))])
                rec.write('/diagnostics', DiagnosticArray(header=header(stamp),
                                                          status=[status]), int(stamp))
    return path


def run_main(capsys, *argv):
    status = inspect_cli.main([str(arg) for arg in argv])
    out = capsys.readouterr()
    return status, out.out, out.err


def checks_of(path):
    return {check.name: check for check in inspect_recording(path).checks}


@pytest.fixture(scope='module')
def clean_file(tmp_path_factory, oloid_run):
    return write_run(tmp_path_factory.mktemp('clean') / 'oloid.mcap', oloid_run, OLOID)


# ------------------------------------------------------------------------------------------
# A correct recording.

def test_clean_recording_passes_every_check(capsys, clean_file):
    status, out, err = run_main(capsys, clean_file)
    assert status == 0, out
    assert err == ''
    for name in ('inputs', 'ground', 'contact_points', 'tangent_plane', 'theta', 'psi',
                 'no_slip', 'energy', 'timestamps', 'stamps'):
        assert f'PASS  {name} ' in out
    assert 'FAIL' not in out
    assert '/roller/pose' in out and 'geometry_msgs/msg/PoseStamped' in out
    assert 'result: PASS' in out and 'duration: 3.000 s' in out


def test_tolerances_are_tight_but_met(clean_file):
    checks = checks_of(clean_file)
    for check in checks.values():
        assert check.passed and check.value <= check.tolerance, check
    # FD-limited checks: the tolerance is set by the FD error at 100 Hz, ~ (ω h)⁴ ~ 1e-6
    assert 1e-8 < checks['no_slip'].tolerance < 1e-5
    assert 1e-8 < checks['energy'].tolerance < 1e-5
    assert checks['no_slip'].value > 0.1 * checks['no_slip'].tolerance
    assert checks['contact_points'].value < 1e-12


def test_json_document(capsys, clean_file):
    status, out, _ = run_main(capsys, clean_file, '--json')
    assert status == 0
    document = json.loads(out)
    assert document['passed'] is True and document['exit_status'] == 0
    summary = document['summary']
    assert summary['parameters'] == OLOID
    assert summary['truncated'] is False and summary['samples'] == 301
    assert summary['duration_s'] == pytest.approx(3.0)
    topics = {t['topic']: t for t in summary['topics']}
    assert topics['/roller/pose']['count'] == 301
    assert topics['/roller/pose']['rate_hz'] == pytest.approx(100.0)
    assert topics['/roller/rolling_state']['type'] == 'sensor_msgs/msg/JointState'
    assert topics['/diagnostics']['count'] == 4
    assert all(c['status'] == 'PASS' for c in document['checks'])
    assert {c['name'] for c in document['checks']} >= {'ground', 'no_slip', 'energy'}


def test_plot_writes_a_png(capsys, clean_file, tmp_path):
    png = tmp_path / 'oloid.png'
    status, out, _ = run_main(capsys, clean_file, '--plot', png)
    assert status == 0
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and png.stat().st_size > 20_000
    assert f'plot: {png}' in out
    status, _, err = run_main(capsys, clean_file, '--plot', tmp_path / 'no' / 'such.png')
    assert status == 2 and len(err.splitlines()) == 1 and 'cannot write plot' in err


def test_kinematic_recording_checks_angular_speed(tmp_path):
    params = dict(OLOID, mode='kinematic', omega0='-2.0', rate='150.0', duration='2.0')
    path = write_run(tmp_path / 'kinematic.mcap', simulate_run(params), params, namespace='')
    checks = checks_of(path)
    assert 'energy' not in checks
    assert all(check.passed for check in checks.values()), checks
    assert checks['angular_speed'].tolerance < 1e-3


def spin(t):
    """A rotation vector that turns and changes axis (rad)."""
    return np.stack([0.3 * t, 0.5 * t**2 - t, 2.0 * np.sin(t)], axis=-1)


def test_finite_differences_are_fourth_order():
    def errors(step):
        t = np.arange(0.0, 1.0, step)
        t = t + 1e-3 * step * np.sin(7 * t)   # stamps within 1 % of the step, not uniform
        position = np.stack([np.sin(3 * t), t**3, np.cos(t)], axis=1)
        index, velocity, omega = finite_differences(
            t, position, Rotation.from_rotvec(spin(t)), step)
        assert index[0] == 2 and index[-1] == t.size - 3
        exact_v = np.stack([3 * np.cos(3 * t), 3 * t**2, -np.sin(t)], axis=1)[index]
        tau = 1e-6   # reference ω: rotation vector of R(t + τ) R(t − τ)ᵀ over 2τ
        turn = Rotation.from_rotvec(spin(t + tau)) * Rotation.from_rotvec(spin(t - tau)).inv()
        exact_w = turn.as_rotvec()[index] / (2 * tau)
        return np.max(np.abs(velocity - exact_v)), np.max(np.abs(omega - exact_w))
    coarse, fine = errors(0.02), errors(0.01)
    assert coarse[0] / fine[0] > 12 and coarse[1] / fine[1] > 12   # 2⁴ = 16
    assert fine[0] < 1e-6 and fine[1] < 1e-6


def test_recording_without_parameters_fails_inputs(capsys, tmp_path, oloid_run):
    path = write_run(tmp_path / 'bare.mcap', oloid_run, {'rate': '100.0'})
    status, out, err = run_main(capsys, path)
    assert status == 1 and err == ''
    checks = checks_of(path)
    assert not checks['inputs'].passed and checks['inputs'].value >= 5
    assert any('parameter a is missing' in line for line in checks['inputs'].detail)
    assert checks['ground'].passed and checks['timestamps'].passed
    assert checks['no_slip'].value is None and not checks['no_slip'].passed


# ------------------------------------------------------------------------------------------
# Corrupted recordings.

def test_contact_above_the_ground_fails(capsys, tmp_path, oloid_run):
    run = copy_run(oloid_run)
    run['a'][120, 2] = 0.01
    path = write_run(tmp_path / 'lifted.mcap', run, OLOID)
    status, out, _ = run_main(capsys, path)
    assert status == 1
    assert 'FAIL  ground ' in out and 'result: FAIL' in out
    checks = checks_of(path)
    assert checks['ground'].value == pytest.approx(0.01)
    assert checks['timestamps'].passed and checks['energy'].passed


def test_shifted_contact_fails_geometry_and_slip(tmp_path, oloid_run):
    run = copy_run(oloid_run)
    run['a'][150, :2] += [1e-3, -1e-3]
    checks = checks_of(write_run(tmp_path / 'shifted.mcap', run, OLOID))
    assert checks['ground'].passed
    assert not checks['contact_points'].passed
    assert checks['contact_points'].value == pytest.approx(np.sqrt(2) * 1e-3)
    assert not checks['no_slip'].passed
    assert checks['energy'].passed and checks['timestamps'].passed


def test_wrong_branch_of_psi_fails(tmp_path, oloid_run):
    run = copy_run(oloid_run)
    run['angles'][200, 1] *= -1
    checks = checks_of(write_run(tmp_path / 'psi.mcap', run, OLOID))
    assert not checks['psi'].passed
    assert checks['theta'].passed and checks['contact_points'].passed


def test_energy_of_another_mass_model_fails(tmp_path, oloid_run):
    # poses of the laminae, recorded as if the body were the solid hull
    path = write_run(tmp_path / 'solid.mcap', oloid_run, dict(OLOID, mass_model='solid'))
    checks = checks_of(path)
    assert not checks['energy'].passed
    assert checks['energy'].value > 10 * checks['energy'].tolerance
    assert checks['no_slip'].passed and checks['contact_points'].passed


def test_gap_in_timestamps_fails(capsys, tmp_path, oloid_run):
    path = write_run(tmp_path / 'gap.mcap', oloid_run, OLOID, skip={100, 101, 102})
    status, out, _ = run_main(capsys, path)
    assert status == 1
    assert 'FAIL  timestamps ' in out
    checks = checks_of(path)
    assert checks['timestamps'].value == pytest.approx(3.0)
    # the samples next to the gap are left out of the differences, the rest still pass
    for name in ('no_slip', 'energy', 'contact_points', 'stamps'):
        assert checks[name].passed, checks[name]


def test_contacts_at_other_stamps_fail(tmp_path, oloid_run):
    path = write_run(tmp_path / 'late.mcap', oloid_run, OLOID, late={'contact_b': 10**6})
    checks = checks_of(path)
    assert not checks['stamps'].passed and checks['stamps'].value > 0
    assert checks['ground'].passed


# ------------------------------------------------------------------------------------------
# Files that cannot be read, truncated files.

@pytest.mark.parametrize('kind', ['missing', 'directory', 'not_mcap'])
def test_unreadable_file_exits_2_with_one_line(tmp_path, kind):
    target = {'missing': tmp_path / 'nothing.mcap', 'directory': tmp_path,
              'not_mcap': tmp_path / 'text.mcap'}[kind]
    if kind == 'not_mcap':
        target.write_text('this is not a recording\n')
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    result = subprocess.run([sys.executable, '-m', 'twodisk_ros.inspect_mcap', str(target)],
                            capture_output=True, text=True, env=env, cwd=ROOT, timeout=60)
    assert result.returncode == 2
    assert result.stdout == ''
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and 'Traceback' not in result.stderr
    assert lines[0].startswith('twodisk-inspect: cannot read recording')
    assert str(target) in lines[0]


def test_truncated_file_reports_recovery_and_checks_the_rest(capsys, tmp_path, clean_file):
    """A cut file is checked on what was recovered; the verdict is INCOMPLETE (exit 4)."""
    data = clean_file.read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[:int(0.6 * len(data))])
    status, out, _ = run_main(capsys, cut)
    assert status == 4, out
    assert 'TRUNCATED' in out and f'of the {int(0.6 * len(data)):,} bytes'.replace(',', ' ') in out
    assert 'result: INCOMPLETE (all ' in out and 'FAIL' not in out
    status, out, _ = run_main(capsys, cut, '--json')
    document = json.loads(out)
    recovered = document['summary']['recovered']
    assert document['summary']['truncated'] is True and status == 4
    assert document['verdict'] == 'INCOMPLETE' and document['exit_status'] == 4
    assert document['checks_passed'] is True and document['passed'] is False
    assert 0 < recovered['bytes'] < recovered['total_bytes'] == int(0.6 * len(data))
    assert 100 < document['summary']['samples'] < 301
    run = document['summary']['run']
    # the share of the run: samples recovered of the 3 s × 100 Hz + 1 the run holds
    assert run['expected_samples'] == 301
    assert run['recovered_samples'] == document['summary']['samples']
    assert run['share'] == run['recovered_samples'] / 301
    assert 0 < recovered['messages'] < len(read_recording(clean_file).messages)
