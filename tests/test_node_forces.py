"""The node's contact forces: wrench topics, force arrows, and /diagnostics at the model's limits.

The forces themselves are tested against Newton–Euler references in test_contact_forces.py;
here the node's wiring: what is recorded is the library's force at the recorded state, the
ERROR appears at the first sample outside the rolling model, and never below the limits.
Batch runs in process (ROS domain 87) with a recording read back.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import math  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from twodisk_ros.recordings import read_recording  # noqa: E402
from twodisk_ros.physics import RollingDynamics, EllipseBody  # noqa: E402
from twodisk_ros.physics.forces.contact import ContactForceModel  # noqa: E402
from twodisk_ros.physics.forces.validity import liftoff_speed  # noqa: E402
from twodisk_ros.physics.mass.models import laminae  # noqa: E402

pytestmark = pytest.mark.ros
WEIGHT = 9.81   # M g of the default 1 kg body (N)


@pytest.fixture(scope='module')
def context():
    import rclpy
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=87)
    yield ctx
    rclpy.try_shutdown(context=ctx)


def record(context, path, **values):
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    overrides = [Parameter('realtime', value=False), Parameter('record', value=str(path))]
    overrides += [Parameter(k, value=v) for k, v in values.items()]
    node = Roller(context=context, parameter_overrides=overrides)
    try:
        node.run_batch()
    finally:
        node.close()
        node.destroy_node()
    return read_recording(path, decode=lambda t: t.rsplit('/', 1)[-1] in (
        'wrench_a', 'wrench_b', 'rolling_state', 'diagnostics', 'markers'))


def by_topic(recording, name):
    return [m.msg for m in recording.messages if m.topic.rsplit('/', 1)[-1] == name]


def stamp(msg):
    return msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec


def diagnostics_values(msg):
    (status,) = msg.status
    return status.level, status.message, {kv.key: kv.value for kv in status.values}


def model():
    dynamics = RollingDynamics(EllipseBody(0.1, 0.1, 0.05), laminae(0.1, 0.1, 0.05, 1.0))
    return ContactForceModel(dynamics)


def test_wrenches_are_the_forces_at_the_recorded_state(context, tmp_path):
    recording = record(context, tmp_path / 'w.mcap', duration=2.0, rate=50.0)
    states = by_topic(recording, 'rolling_state')
    wrench_a, wrench_b = by_topic(recording, 'wrench_a'), by_topic(recording, 'wrench_b')
    assert len(states) == len(wrench_a) == len(wrench_b) == 101
    assert [stamp(m) for m in wrench_a] == [stamp(m) for m in states]
    u = np.array([m.position[2] for m in states])
    u_dot = np.array([m.velocity[2] for m in states])
    expected = model().dynamic(u, u_dot)
    for msgs, force in ((wrench_a, expected.force_a), (wrench_b, expected.force_b)):
        got = np.array([[m.wrench.force.x, m.wrench.force.y, m.wrench.force.z] for m in msgs])
        np.testing.assert_allclose(got, force, rtol=0, atol=1e-9 * WEIGHT)
        torque = np.array([[m.wrench.torque.x, m.wrench.torque.y, m.wrench.torque.z]
                           for m in msgs])
        assert np.all(torque == 0)
        assert all(m.header.frame_id == 'world' for m in msgs)
    level, message, values = diagnostics_values(by_topic(recording, 'diagnostics')[0])
    assert level == 0 and message == 'rolling'
    assert float(values['normal_a']) + float(values['normal_b']) > 0
    assert float(values['friction']) == 0.5
    assert float(values['slip_margin']) == pytest.approx(0.5 - float(values['mu_required']))


def test_force_arrows_in_the_markers(context, tmp_path):
    recording = record(context, tmp_path / 'm.mcap', duration=0.5, rate=50.0)
    arrays = by_topic(recording, 'markers')
    assert arrays
    for array in arrays:
        arrows = [m for m in array.markers if m.ns == 'twodisk_forces']
        assert [m.id for m in arrows] == [100, 101] and all(m.type == 0 for m in arrows)
        for arrow in arrows:     # pushing up: the arrow points up from the ground
            start, end = arrow.points
            assert start.z == pytest.approx(0.0, abs=1e-12) and end.z > 0


@pytest.mark.parametrize('factor', [0.98, 1.02])
def test_error_from_the_first_sample_above_the_lift_off_speed(context, tmp_path, factor):
    omega_c, _, _ = liftoff_speed(model())
    omega = factor * omega_c
    rate = 200.0
    recording = record(context, tmp_path / 'k.mcap', mode='kinematic', omega0=omega,
                       theta0=0.0, duration=2.0, rate=rate, friction=math.inf)
    states = by_topic(recording, 'rolling_state')
    u = np.array([m.position[2] for m in states])
    normal = model().kinematic(u, omega)
    below = np.nonzero(np.minimum(normal.normal_a, normal.normal_b) < 0)[0]
    diagnostics = by_topic(recording, 'diagnostics')
    levels = [diagnostics_values(d)[0] for d in diagnostics]
    if factor < 1:
        assert below.size == 0 and set(levels) <= {0, 1}
        return
    assert below.size > 0, 'the run never reaches the lift-off phase'
    first = below[0] / rate
    errors = [diagnostics_values(d) for d in diagnostics if diagnostics_values(d)[0] == 2]
    assert errors, levels
    message = errors[0][1]
    assert message.startswith('outside the rolling model: contact') and 'lift off' in message
    reported = float(message.split('t = ')[1].split(' s')[0])
    assert reported == pytest.approx(first, abs=1e-6)
    # once outside, every later diagnostics message says so
    first_error = levels.index(2)
    assert all(level == 2 for level in levels[first_error:])


def test_slip_when_friction_is_below_the_requirement(context, tmp_path):
    recording = record(context, tmp_path / 's.mcap', duration=1.0, rate=100.0, friction=1e-4)
    level, message, values = diagnostics_values(by_topic(recording, 'diagnostics')[-1])
    assert level == 2 and 'slip' in message
    assert float(values['slip_margin']) < 0


def test_friction_changed_at_run_time_is_judged_from_then_on(context, tmp_path):
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    node = Roller(context=context, parameter_overrides=[
        Parameter('realtime', value=False), Parameter('duration', value=4.0),
        Parameter('rate', value=1000.0), Parameter('friction', value=1e-4),
        Parameter('record', value=str(tmp_path / 'f.mcap'))])
    try:
        node.run_batch(keep_going=lambda: node.samples_published < 1)   # one block: 2 s
        assert node.simulation.invalid is not None and 'slip' in node.simulation.invalid.kind
        (result,) = node.set_parameters([Parameter('friction', value=0.5)])
        assert result.successful
        node.run_batch()
        assert node.settings.friction == 0.5 and node.simulation.settings.friction == 0.5
        assert node.simulation.invalid is None          # 0.5 is ample for this motion
    finally:
        node.close()
        node.destroy_node()
