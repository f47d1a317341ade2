"""Tests of the contact-force checks of ``twodisk-inspect`` (issue 14, inspector side).

Recordings are written directly with :class:`McapRecorder` from physics states, as in
tests/test_inspect.py, with the wrenches of :class:`ContactForceModel` (the node's source of
the forces). The inspector recomputes the forces from the poses alone (finite differences and
Newton–Euler), an independent method.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '58')

import json  # noqa: E402
import math  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from builtin_interfaces.msg import Time  # noqa: E402
from geometry_msgs.msg import (Point, PointStamped, Pose, PoseStamped, Quaternion,  # noqa: E402
                               Vector3, Wrench, WrenchStamped)
from scipy.optimize import brentq  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Header  # noqa: E402

from twodisk_ros.inspector import cli as inspect_cli  # noqa: E402
from twodisk_ros.inspector import inspect_recording  # noqa: E402
from twodisk_ros.inspector.differences import finite_differences, second_differences  # noqa
from twodisk_ros.recordings import McapRecorder  # noqa: E402
from twodisk_ros.physics import RollingDynamics, simulate  # noqa: E402
from twodisk_ros.physics.bodies.ellipse import EllipseBody  # noqa: E402
from twodisk_ros.physics.forces.contact import ContactForceModel  # noqa: E402
from twodisk_ros.physics.forces.validity import check_validity, liftoff_speed  # noqa: E402
from twodisk_ros.physics.mass.models import mass_properties  # noqa: E402

pytestmark = pytest.mark.ros

#: A small oloid (Ω_c = 8.28 rad/s) rolling over freely, as the node records it.
BASE = {
    'a': '0.1', 'b': '0.1', 'delta': '0.05', 'mass': '1.0', 'gravity': '9.81',
    'mass_model': 'laminae', 'principal_moments': '[0.0, 0.0, 0.0]', 'mode': 'dynamic',
    'theta0': '0.3', 'branch': '1', 'omega0': '5.0', 'rate': '100.0', 'duration': '2.0',
    'realtime': 'False', 'method': 'table', 'tolerance': '1e-10', 'frame_id': 'world',
    'path_length': '200', 'record': 'run.mcap', 'overwrite': 'False', 'friction': '0.5',
}
OTHER = ('inputs', 'ground', 'contact_points', 'tangent_plane', 'theta', 'psi', 'no_slip',
         'timestamps', 'stamps')
NEW = ('contact_forces', 'force_split', 'rolling_validity')


def dynamics_of(params):
    body = EllipseBody(float(params['a']), float(params['b']), float(params['delta']))
    mass = mass_properties(params['mass_model'], body.a, body.b, body.delta,
                           float(params['mass']))
    return RollingDynamics(body, mass, float(params['gravity']))


def simulate_run(params):
    """Stamps, poses, contacts, angles and the model's contact forces of the motion."""
    dynamics = dynamics_of(params)
    body = dynamics.body
    rate = float(params['rate'])
    count = int(round(float(params['duration']) * rate)) + 1
    stamps = np.array([round(i * 1e9 / rate) for i in range(count)], dtype=np.int64)
    motion = simulate(dynamics, stamps * 1e-9, mode=params['mode'],
                      theta0=float(params['theta0']), branch=int(params['branch']),
                      omega0=float(params['omega0']), method=params['method'],
                      tolerance=float(params['tolerance']))
    state = dynamics.cycle.state(motion.phase)
    step = 1e-6
    ahead, behind = (body.phase_geometry(motion.phase + s) for s in (step, -step))
    rates = np.stack([(ahead.theta - behind.theta) / (2 * step),
                      np.angle(np.exp(1j * (ahead.psi - behind.psi))) / (2 * step),
                      np.ones_like(motion.phase)], axis=1) * motion.phase_rate[:, None]
    model = ContactForceModel(dynamics)
    forces = model.along(motion)
    return {'stamp': stamps, 't': stamps * 1e-9, 'g': state.position_g.copy(),
            'quaternion': state.quaternion.copy(), 'a': state.contact_a.copy(),
            'b': state.contact_b.copy(),
            'angles': np.stack([state.theta, state.psi, motion.phase], axis=1),
            'rates': rates, 'force_a': forces.force_a.copy(), 'force_b': forces.force_b.copy(),
            'forces': forces, 'model': model, 'phase': motion.phase.copy()}


def header(stamp):
    sec, nanosec = divmod(int(stamp), 10**9)
    return Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='world')


def point(xyz):
    return Point(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def vector(xyz):
    return Vector3(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def write_run(path, run, params, *, wrenches=True, chunk_size=None):
    """Record ``run`` as the node does, with the wrenches at A and B if ``wrenches``."""
    options = {} if chunk_size is None else {'chunk_size': chunk_size}
    with McapRecorder(path, metadata=params, **options) as rec:
        topics = {'pose': PoseStamped, 'contact_a': PointStamped, 'contact_b': PointStamped,
                  'rolling_state': JointState}
        if wrenches:
            topics.update(wrench_a=WrenchStamped, wrench_b=WrenchStamped)
        for name, msg_type in topics.items():
            rec.add_topic(f'/roller/{name}', msg_type)
        for i, stamp in enumerate(run['stamp']):
            q = run['quaternion'][i]
            messages = {
                'pose': PoseStamped(header=header(stamp), pose=Pose(
                    position=point(run['g'][i]),
                    orientation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))),
                'contact_a': PointStamped(header=header(stamp), point=point(run['a'][i])),
                'contact_b': PointStamped(header=header(stamp), point=point(run['b'][i])),
                'rolling_state': JointState(
                    header=header(stamp), name=['theta', 'psi', 'phase'],
                    position=[float(x) for x in run['angles'][i]],
                    velocity=[float(x) for x in run['rates'][i]]),
            }
            if wrenches:
                for name, key in (('wrench_a', 'force_a'), ('wrench_b', 'force_b')):
                    messages[name] = WrenchStamped(header=header(stamp), wrench=Wrench(
                        force=vector(run[key][i]), torque=vector((0.0, 0.0, 0.0))))
            for name, msg in messages.items():
                rec.write(f'/roller/{name}', msg, int(stamp))
    return path


def checks_of(path):
    return {check.name: check for check in inspect_recording(path).checks}


def copy_run(run):
    return {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in run.items()}


@pytest.fixture(scope='module')
def dynamic_run():
    return simulate_run(BASE)


KINEMATIC = dict(BASE, mode='kinematic', omega0='-5.0', rate='150.0', duration='1.5')


@pytest.fixture(scope='module')
def kinematic_run():
    return simulate_run(KINEMATIC)


@pytest.fixture(scope='module')
def dynamic_file(tmp_path_factory, dynamic_run):
    return write_run(tmp_path_factory.mktemp('forces') / 'dynamic.mcap', dynamic_run, BASE)


# ------------------------------------------------------------------------------------------
# Second differences.

def euler_motion(t):
    """R = Rz(α) Ry(β) Rx(γ) with its world ω and ω̇ in closed form."""
    a = np.stack([0.7 * t**2 + t, 1.3 * np.sin(2 * t), 0.5 * np.cos(3 * t) + t], axis=1)
    da = np.stack([1.4 * t + 1, 2.6 * np.cos(2 * t), 1 - 1.5 * np.sin(3 * t)], axis=1)
    dda = np.stack([np.full_like(t, 1.4), -5.2 * np.sin(2 * t), -4.5 * np.cos(3 * t)], axis=1)
    rz, ry, rx = (Rotation.from_rotvec(np.outer(a[:, j], axis))
                  for j, axis in enumerate(np.eye(3)[::-1]))
    ez, ey, ex = np.array([0.0, 0.0, 1.0]), rz.apply([0, 1, 0]), (rz * ry).apply([1, 0, 0])
    w1 = da[:, :1] * ez
    w2 = w1 + da[:, 1:2] * ey
    omega = w2 + da[:, 2:3] * ex
    omega_dot = (dda[:, :1] * ez + np.cross(w1, da[:, 1:2] * ey) + dda[:, 1:2] * ey
                 + np.cross(w2, da[:, 2:3] * ex) + dda[:, 2:3] * ex)
    return rz * ry * rx, omega, omega_dot


def test_second_differences_are_fourth_order_against_a_known_rotation():
    def errors(step):
        t = np.arange(0.0, 2.0, step)
        rotation, omega, omega_dot = euler_motion(t)
        position = np.stack([np.sin(3 * t), t**3, np.cos(t)], axis=1)
        exact_a = np.stack([-9 * np.sin(3 * t), 6 * t, -np.cos(t)], axis=1)
        index, acceleration, angular_acceleration = second_differences(t, position, rotation,
                                                                       step)
        first, _, angular_velocity = finite_differences(t, position, rotation, step)
        assert np.array_equal(index, first) and index[0] == 2 and index[-1] == t.size - 3
        return (np.max(np.abs(acceleration - exact_a[index])),
                np.max(np.abs(angular_acceleration - omega_dot[index])),
                np.max(np.abs(angular_velocity - omega[index])))
    coarse, fine = errors(0.02), errors(0.01)
    for c, f in zip(coarse, fine):
        assert 12 < c / f < 20      # 2⁴ = 16
    assert fine[0] < 1e-7 and fine[1] < 2e-6


# ------------------------------------------------------------------------------------------
# Correct recordings.

def test_clean_dynamic_recording_passes(capsys, dynamic_file, dynamic_run):
    inspection = inspect_recording(dynamic_file)
    checks = {check.name: check for check in inspection.checks}
    assert inspection.passed, [c for c in inspection.checks if not c.passed]
    assert set(NEW) <= set(checks) and checks['energy'].passed
    force = checks['contact_forces']
    # FD-limited at 100 Hz: (ω h)⁴ ~ 1e-6 of the accelerations
    assert 1e-9 < force.tolerance < 1e-3 and force.value > 0.05 * force.tolerance
    assert checks['force_split'].value < 1e-12
    assert checks['rolling_validity'].value == 0
    summary = inspection.summary['contact_forces']
    assert summary['recorded'] and summary['stretches'] == [] and summary['friction'] == 0.5
    assert summary['max_mu_required'] == pytest.approx(
        float(np.max(dynamic_run['forces'].mu_required)), rel=1e-9)
    assert summary['min_normal_a'] == pytest.approx(
        float(np.min(dynamic_run['forces'].normal_a)), rel=1e-9)
    status = inspect_cli.main([str(dynamic_file)])
    out = capsys.readouterr().out
    assert status == 0 and 'PASS  contact_forces' in out and 'PASS  rolling_validity' in out
    assert 'contact forces:' in out
    status = inspect_cli.main([str(dynamic_file), '--json'])
    document = json.loads(capsys.readouterr().out)
    assert {c['name'] for c in document['checks']} >= set(NEW)
    assert document['summary']['contact_forces']['stretches'] == []


def test_clean_kinematic_run_below_lift_off_passes(tmp_path, kinematic_run):
    assert 5.0 < liftoff_speed(kinematic_run['model'])[0]
    checks = checks_of(write_run(tmp_path / 'kinematic.mcap', kinematic_run, KINEMATIC))
    assert all(check.passed for check in checks.values()), checks
    assert checks['contact_forces'].tolerance < 1e-3
    assert 'energy' not in checks and checks['angular_speed'].passed


# ------------------------------------------------------------------------------------------
# Wrong wrenches.

def test_scaled_wrench_fails_contact_forces(tmp_path, dynamic_run):
    run = copy_run(dynamic_run)
    run['force_a'] *= 1.01
    checks = checks_of(write_run(tmp_path / 'scaled.mcap', run, BASE))
    force = checks['contact_forces']
    assert not force.passed and force.value > 100 * force.tolerance
    weight = 9.81
    expected = 0.01 * np.max(np.linalg.norm(dynamic_run['force_a'], axis=1)) / weight
    assert force.value == pytest.approx(expected, rel=0.05)
    for name in OTHER + ('energy',):
        assert checks[name].passed, checks[name]


def test_swapped_normal_forces_fail_contact_forces(tmp_path, dynamic_run):
    run = copy_run(dynamic_run)
    run['force_a'][:, 2], run['force_b'][:, 2] = (dynamic_run['force_b'][:, 2],
                                                  dynamic_run['force_a'][:, 2])
    checks = checks_of(write_run(tmp_path / 'swapped.mcap', run, BASE))
    force = checks['contact_forces']
    assert not force.passed and force.value > 100 * force.tolerance
    assert 'N_A' in force.detail[0]
    difference = np.abs(dynamic_run['force_a'][:, 2] - dynamic_run['force_b'][:, 2]) / 9.81
    assert force.value == pytest.approx(np.max(difference[2:-2]), rel=0.01)


def test_split_not_following_the_rule_fails_force_split(tmp_path, dynamic_run):
    run = copy_run(dynamic_run)
    squeeze = 0.05 * 9.81 * run['forces'].direction_ab      # +s ê at A, −s ê at B
    run['force_a'] += squeeze
    run['force_b'] -= squeeze
    checks = checks_of(write_run(tmp_path / 'squeeze.mcap', run, BASE))
    assert checks['contact_forces'].passed       # the squeeze is invisible to Newton–Euler
    assert not checks['force_split'].passed
    assert checks['force_split'].value == pytest.approx(0.05, rel=1e-6)


# ------------------------------------------------------------------------------------------
# Motions outside the rolling model.

def test_kinematic_run_above_lift_off_fails_validity_at_the_right_times(tmp_path):
    model = ContactForceModel(dynamics_of(BASE))
    critical, phase_c, contact_c = liftoff_speed(model)
    params = dict(BASE, mode='kinematic', omega0=repr(1.015 * critical), duration='1.0',
                  friction='inf')     # no slip limit: lift-off alone
    run = simulate_run(params)
    inspection = inspect_recording(write_run(tmp_path / 'fast.mcap', run, params))
    checks = {check.name: check for check in inspection.checks}
    assert checks['contact_forces'].passed and checks['force_split'].passed
    validity = checks['rolling_validity']
    assert not validity.passed and validity.value >= 3
    assert 'not physics' in ' '.join(validity.detail)
    assert 'follows the rolling model' in ' '.join(validity.detail)
    stretches = inspection.summary['contact_forces']['stretches']
    assert len(stretches) == validity.value
    forces, t = run['forces'], run['t']
    report = check_validity(t, forces)
    assert not report.valid and stretches[0]['start_s'] == pytest.approx(report.time, abs=1e-9)
    assert stretches[0]['reason'] == report.reason
    omega = 1.015 * critical
    for stretch in stretches:
        i = int(round(stretch['start_s'] * 100))
        j = int(round(stretch['end_s'] * 100))
        contact = stretch['kinds'][0][-1]
        normal = forces.normal_a if contact == 'A' else forces.normal_b
        assert np.all(normal[i:j + 1] < 0)
        if i > 0:   # N crosses 0 between the phase before the stretch and its first phase
            assert normal[i - 1] >= 0 and normal[j + 1] >= 0

            def n(u, column=0 if contact == 'A' else 1):
                return (model.kinematic(u, omega).normal_a if column == 0
                        else model.kinematic(u, omega).normal_b)
            crossing = brentq(n, run['phase'][i - 1], run['phase'][i])
            assert run['phase'][i - 1] <= crossing <= run['phase'][i]
        # the worst sample is where N(u; Ω) is least, to within a sampling step
        k = int(round(stretch['worst'][f'N_{contact}']['t'] * 100))
        low, high = run['phase'][max(i - 1, 0)], run['phase'][min(j + 1, t.size - 1)]
        fine = np.linspace(min(low, high), max(low, high), 2001)
        fine_forces = model.kinematic(fine, omega)
        fine_normal = fine_forces.normal_a if contact == 'A' else fine_forces.normal_b
        step = abs(run['phase'][1] - run['phase'][0])
        assert abs(run['phase'][k] - fine[np.argmin(fine_normal)]) < 1.5 * step
        assert stretch['worst'][f'N_{contact}']['value'] >= np.min(fine_normal) - 1e-12
    assert contact_c in ('A', 'B') and 0 <= phase_c < 2 * math.pi


def test_friction_below_the_required_fails_with_slip(tmp_path, kinematic_run):
    peak = float(np.max(kinematic_run['forces'].mu_required))
    mu = 0.9 * peak
    params = dict(KINEMATIC, friction=repr(mu))
    inspection = inspect_recording(write_run(tmp_path / 'slip.mcap', kinematic_run, params))
    checks = {check.name: check for check in inspection.checks}
    validity = checks['rolling_validity']
    assert not validity.passed and checks['contact_forces'].passed
    stretches = inspection.summary['contact_forces']['stretches']
    assert stretches and all(s['kinds'] == ['slip'] for s in stretches)
    report = check_validity(kinematic_run['t'], kinematic_run['forces'], mu)
    assert report.kind == 'slip' and stretches[0]['start_s'] == pytest.approx(report.time)
    assert max(s['worst']['mu_required']['value'] for s in stretches) == pytest.approx(
        peak, rel=1e-6)
    assert any('would slip' in line for line in validity.detail)


def test_missing_friction_assumes_no_slip_limit(tmp_path, kinematic_run):
    params = {k: v for k, v in KINEMATIC.items() if k != 'friction'}
    checks = checks_of(write_run(tmp_path / 'nofriction.mcap', kinematic_run, params))
    assert checks['rolling_validity'].passed
    assert 'mu = inf assumed' in checks['rolling_validity'].detail[0]


# ------------------------------------------------------------------------------------------
# Recordings without the wrenches.

def test_recording_without_wrenches_skips_the_force_checks(capsys, tmp_path, dynamic_run):
    older = {k: v for k, v in BASE.items() if k != 'friction'}
    path = write_run(tmp_path / 'older.mcap', dynamic_run, older, wrenches=False)
    inspection = inspect_recording(path)
    checks = {check.name: check for check in inspection.checks}
    assert inspection.passed and not set(NEW) & set(checks)
    assert set(OTHER) <= set(checks)
    summary = inspection.summary['contact_forces']
    assert summary['recorded'] is False and 'skipped' in summary['note']
    assert summary['from_poses']['stretches'] == []
    assert inspect_cli.main([str(path)]) == 0
    out = capsys.readouterr().out
    assert 'skipped' in out and 'FAIL' not in out


def test_friction_without_wrenches_fails_contact_forces(tmp_path, dynamic_run):
    checks = checks_of(write_run(tmp_path / 'lost.mcap', dynamic_run, BASE, wrenches=False))
    assert not checks['contact_forces'].passed
    assert 'no wrench_a/wrench_b' in checks['contact_forces'].detail[0]
    assert checks['rolling_validity'].passed      # from the forces of the poses
    assert 'recomputed from the poses' in checks['rolling_validity'].detail[0]
    for name in OTHER:
        assert checks[name].passed


def test_plot_shows_the_forces(capsys, tmp_path, dynamic_file):
    png = tmp_path / 'forces.png'
    assert inspect_cli.main([str(dynamic_file), '--plot', str(png)]) == 0
    capsys.readouterr()
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and png.stat().st_size > 20_000


def test_truncated_recording_with_wrenches_checks_the_rest(tmp_path, dynamic_run):
    path = write_run(tmp_path / 'whole.mcap', dynamic_run, BASE, chunk_size=8 * 1024)
    data = path.read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[:int(0.6 * len(data))])
    inspection = inspect_recording(cut)
    assert inspection.summary['truncated'] and 50 < inspection.summary['samples'] < 201
    checks = {check.name: check for check in inspection.checks}
    for name in NEW:
        assert checks[name].passed, checks[name]
