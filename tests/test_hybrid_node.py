"""The roller under contact_model:=hybrid (issue 31): events, diagnostics, a disk in the air.

One batch run of config/rounded_square.yaml's body over 1 s, in process (ROS domain 81):
rolling needs more friction than μ = 0.5 at 0.499 s, the engine runs, rolling resumes.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402

from twodisk_ros.recordings import read_recording  # noqa: E402

pytestmark = pytest.mark.ros
DOMAIN = 81
RATE = 100.0
CONFIG = Path(__file__).resolve().parents[1] / 'config' / 'rounded_square.yaml'


@pytest.fixture(scope='module')
def recording(tmp_path_factory):
    pytest.importorskip('mujoco')
    import rclpy
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    path = tmp_path_factory.mktemp('hybrid') / 'hybrid.mcap'
    values = yaml.safe_load(CONFIG.read_text())['/**']['ros__parameters']
    values.update(contact_model='hybrid', realtime=False, duration=1.0, record=str(path))
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=DOMAIN)
    try:
        node = Roller(context=ctx, parameter_overrides=[Parameter(k, value=v)
                                                        for k, v in values.items()])
        try:
            node.run_batch()
            stretches = list(node.simulation.hybrid.stretches)
            (refused,) = node.set_parameters([Parameter('damping', value=0.01)])
        finally:
            node.close()
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)
    return read_recording(path), stretches, path, refused


def _topic(recording, name):
    return [m for m in recording.messages if m.topic.rsplit('/', 1)[-1] == name]


def _stamp(msg):
    return msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec


def test_each_switch_is_an_event_at_the_new_models_first_sample(recording):
    rec, stretches, _, _ = recording
    assert [s.model for s in stretches] == ['rolling', 'engine', 'rolling']
    events = [(m.log_time_ns, m.msg.data) for m in _topic(rec, 'events')]
    assert [text for _, text in events] == [f'contact_model {s.model}: {s.reason}'
                                            for s in stretches[1:]]
    stamps = np.array([_stamp(m.msg) for m in _topic(rec, 'pose')])
    t = (stamps - stamps[0]) * 1e-9
    engine_first = int(np.argmax(t > stretches[1].t_start))
    rolling_first = int(np.argmax(t >= stretches[2].t_start - 1e-9))
    assert [stamp for stamp, _ in events] == [stamps[engine_first], stamps[rolling_first]]
    assert events[0][1].startswith('contact_model engine: slip at t = 0.4993')


def test_diagnostics_say_which_model_runs(recording):
    rec, stretches, _, _ = recording
    last = _topic(rec, 'diagnostics')[-1].msg.status[0]
    values = {kv.key: kv.value for kv in last.values}
    assert values['contact_model'] == 'hybrid' and values['model'] == 'rolling'
    assert values['switches'] == '2'
    assert float(values['model_since']) == stretches[2].t_start
    assert last.level == 0 and 'rolling again since t = 0.5405' in last.message


def test_a_disk_in_the_air_has_no_force_and_its_lowest_point(recording):
    """Samples where the engine's disk 1 (A) is in the air (wrench_a zero): contact_a lies in
    disk 1's plane (x3 = 0 of the pose), above the ground and below G."""
    rec, _, _, _ = recording
    wrench = np.array([[m.msg.wrench.force.x, m.msg.wrench.force.y, m.msg.wrench.force.z]
                       for m in _topic(rec, 'wrench_a')])
    point = np.array([[m.msg.point.x, m.msg.point.y, m.msg.point.z]
                      for m in _topic(rec, 'contact_a')])
    poses = [m.msg.pose for m in _topic(rec, 'pose')]
    air = [i for i in range(len(poses)) if not wrench[i].any()]   # no contact: no force
    assert air
    for i in air:
        p = poses[i]
        g = np.array([p.position.x, p.position.y, p.position.z])
        x, y, z, w = p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w
        e3 = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
        assert abs((point[i] - g) @ e3) <= 1e-3 * 0.2     # the rim polygon's tolerance
        assert 0 < point[i, 2] < g[2]


def test_the_inspector_checks_engine_stretches_on_their_own(recording):
    """twodisk-inspect leaves the engine's samples out of the rolling checks (which then
    pass, energy from each return on) and checks them by the free body's own rules."""
    from twodisk_ros.inspector import inspect_recording
    inspection = inspect_recording(recording[2])
    checks = {c.name: c for c in inspection.checks}
    assert checks['engine_stretches'].passed, checks['engine_stretches'].detail
    assert all(c.passed for c in inspection.checks), [
        (c.name, c.detail) for c in inspection.checks if not c.passed]
    assert inspection.summary['run']['recovered_samples'] == 101
    # the engine's contact parameters are in the metadata (the landing depth bound's)
    meta = recording[0].metadata['twodisk_ros']
    assert (meta['engine_time_constant'], meta['engine_damping_ratio']) == ('0.005', '1.0')
    assert 'tau = 0.005 s, zeta = 1, recorded' in checks['engine_stretches'].detail[1]


def test_a_scene_change_at_run_time_is_refused_in_one_line(recording):
    """damping is taken at the start (tests/test_hybrid_damping.py) but not changed at run
    time: the hybrid motion cannot continue a new scene; refused, the run keeps its own."""
    refused = recording[3]
    assert not refused.successful
    assert refused.reason == ('contact_model hybrid takes no scene changes at run time (set '
                              'slope, damping and drive at the start; commands, friction, '
                              'reset and pause work)')


def test_the_engine_check_fails_outside_the_cone_and_through_the_ground():
    from twodisk_ros.inspector.engine_stretches import engine_check
    from twodisk_ros.inspector.series import Series
    stamps = np.arange(3, dtype=np.int64)

    def series(key, rows):
        return Series('x', stamps, stamps, stamps, {key: np.array(rows, dtype=float)})
    good = {'wrench_a': series('force', [[0.0, 0.0, 5.0], [2.0, 0.0, 5.0], [0, 0, 0]]),
            'contact_a': series('point', [[0, 0, 0.0], [0, 0, -1e-5], [0, 0, 0.01]])}
    assert engine_check(good, [(0, None)], {'friction': '0.5'}, 9.81, 0.2).passed
    for key, rows in (('wrench_a', [[0, 0, 5.0], [2.6, 0, 5.0], [0, 0, 0]]),    # |F_t| > mu N
                      ('wrench_a', [[0, 0, 5.0], [0, 0, -0.1], [0, 0, 0]]),     # pulls
                      ('contact_a', [[0, 0, 0.0], [0, 0, -3e-3], [0, 0, 0]])):  # 1.5e-2 L deep
        bad = dict(good, **{key: series('force' if key == 'wrench_a' else 'point', rows)})
        assert not engine_check(bad, [(0, None)], {'friction': '0.5'}, 9.81, 0.2).passed
