"""``twodisk-inspect`` checks the speed drive's first-order lag rule from the recording alone.

A real-time roller under the speed drive is commanded from a second rclpy node (three
speeds, then silence until the time-out); the inspector's ``speed_drive`` check must pass
with |ω| from the recorded poses, and must fail when the recorded ``drive_lag`` is not the
one the motion followed (the reference: the documented rule Ω = Ω_cmd + (Ω_r − Ω_cmd)
e^{−(t − t_r)/T}, evaluated by the check on |ω| from finite differences of the poses, not
on the node's own rates). Old code had no such check (speed stretches were skipped).
"""

import math
import time

import pytest

rclpy = pytest.importorskip('rclpy')

DOMAIN = 75
LAG, RATE, COMMANDS = 0.2, 100.0, (4.0, 5.5, 2.5)


def _wait(executor, seconds, until=None):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.01)
        if until is not None and until():
            return True
    return False


@pytest.fixture(scope='module')
def recording(tmp_path_factory):
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import Float64, String
    from twodisk_ros.node.roller import Roller
    path = tmp_path_factory.mktemp('speed') / 'speed.mcap'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    try:
        node = Roller(context=context, parameter_overrides=[
            Parameter('drive', value='speed'), Parameter('drive_lag', value=LAG),
            Parameter('cmd_timeout', value=0.6), Parameter('rate', value=RATE),
            Parameter('friction', value=math.inf), Parameter('record', value=str(path))])
        driver = rclpy.create_node('speed_driver', context=context)
        publisher = driver.create_publisher(Float64, 'cmd_speed', 10)
        events = []
        driver.create_subscription(String, 'events', lambda m: events.append(m.data), 100)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(driver)
        try:
            assert _wait(executor, 10.0, lambda: node.samples_published >= 20)
            for value in COMMANDS:
                publisher.publish(Float64(data=value))
                assert _wait(executor, 10.0, lambda v=value: f'command speed {v!r}' in events)
                _wait(executor, 0.45)
            assert _wait(executor, 10.0, lambda: 'timeout' in events), events
            _wait(executor, 0.2)
        finally:
            executor.shutdown()
            node.close()
            node.destroy_node()
            driver.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    return path


def _speed_check(inspection):
    return {c.name: c for c in inspection.checks}['speed_drive']


def test_the_recorded_speed_follows_the_lag_rule(recording):
    from twodisk_ros.inspector import inspect_recording
    check = _speed_check(inspect_recording(recording))
    assert check.passed, check.detail
    # the stretches: the start (held), three commands; the time-out's is free motion
    assert 'over 4 stretch(es)' in check.detail[0], check.detail
    # the claim is FD-limited: the tolerance stays near the difference error of |ω| at
    # h = 10 ms (~(|ω| h)⁴ ≈ 1e-5 relative at ≤ 5.5 rad/s), far below a wrong lag's miss
    assert check.tolerance < 1e-4, check.tolerance


@pytest.mark.parametrize('lag', [0.25, 0.1])
def test_a_wrong_drive_lag_fails(recording, monkeypatch, lag):
    """The same poses checked against another T: the rule misses by ~|ΔΩ| (1/T − 1/T') t."""
    from twodisk_ros.inspector import inspect_recording, inspection
    original = inspection.read_recording

    def with_lag(*args, **kwargs):
        read = original(*args, **kwargs)
        read.metadata['twodisk_ros']['drive_lag'] = repr(lag)
        return read
    monkeypatch.setattr(inspection, 'read_recording', with_lag)
    check = _speed_check(inspect_recording(recording))
    assert not check.passed
    assert check.value > 100 * check.tolerance
