"""/clock: a node with ``use_sim_time:=true`` takes the roller's stamps as its own time.

A batch run (``realtime:=false``) is followed by an rclpy node in this process whose clock is
ROS time: every ``now()`` it reads is a stamp of the run (the stamps of the recording made in
the same run), its time advances faster than the wall clock, and after the run its ``now()``
is the last sample's stamp. The batch is long and stopped by SIGINT once the follower has
watched it for a while: discovery can take longer on a loaded machine than a short batch
runs. Subprocess nodes use ROS domain 33, localhost only.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

from pathlib import Path  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import rclpy  # noqa: E402
from rclpy.clock import ClockType  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

from rosgraph_msgs.msg import Clock  # noqa: E402

from twodisk_ros.recordings import read_recording  # noqa: E402
from twodisk_ros.node.sim_clock import CLOCK_MAX_RATE, clock_step, encode_clock_column  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
DOMAIN = 33
STARTED = 30.0        # s: a node answers within this on a loaded 2-core machine
RATE = 1000.0         # Hz: /clock at every sample (CLOCK_MAX_RATE)
PERIOD_NS = 1_000_000
WATCH = 1.0           # s of wall time the follower watches the batch after discovery (at
                      # 1 kHz that is thousands of /clock stamps, far more than the 20 needed)
SETTLED = 0.5         # s without a new /clock after the run: the follower's time has settled


def node_env():
    return dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID=str(DOMAIN),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')


def spin_until(executor, predicate, timeout=STARTED):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.01)
        if predicate():
            return True
    return False


def stamp_ns(header):
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


@pytest.mark.ros
def test_a_sim_time_node_follows_a_batch_run_faster_than_real_time(tmp_path):
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=DOMAIN)
    follower = rclpy.create_node('sim_time_follower', context=ctx, parameter_overrides=[
        Parameter('use_sim_time', value=True)])
    clock = follower.get_clock()
    assert clock.clock_type == ClockType.ROS_TIME and clock.ros_time_is_active
    seen = []          # (wall s, the follower's now() in ns) whenever its time moved

    def watch(predicate):
        """``predicate``, after noting the follower's now() if it moved (read between spins:
        a subscription to the run's topics would flood this process and make it drop the
        best-effort /clock)."""
        def noted():
            now = clock.now().nanoseconds
            if not seen or now != seen[-1][1]:
                seen.append((time.monotonic(), now))
            return predicate()
        return noted
    executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(follower)
    target = tmp_path / 'batch.mcap'
    # A batch long enough never to end by itself (an unsubscribed 60 s batch at 1 kHz takes
    # about 2 s, less than discovery on a loaded machine): wait until the follower's time has
    # moved (discovery done, however long it took), watch it for a while, then stop the run.
    process = subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
         'config/oloid.yaml', '-p', 'realtime:=false', '-p', f'rate:={RATE}',
         '-p', 'duration:=3600.0', '-p', f'record:={target}'], cwd=REPO, env=node_env(),
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        assert clock.now().nanoseconds == 0        # no /clock yet: ROS time starts at 0
        assert spin_until(executor, watch(lambda: any(now > 0 for _, now in seen))), \
            'the follower never received the clock'
        watched = time.monotonic() + WATCH
        spin_until(executor, watch(lambda: process.poll() is not None
                                   or time.monotonic() > watched), timeout=WATCH + STARTED)
        assert process.poll() is None, 'the batch run ended by itself'
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=STARTED)
        last = read_recording(target, decode=lambda topic: False)
        stamps = np.array(sorted({m.log_time_ns for m in last.messages
                                  if m.topic == '/pose'}))
        assert np.all(np.diff(stamps) == PERIOD_NS)
        # /clock is best effort: on a loaded machine the follower may lose the very last ones,
        # so it must settle on a stamp of the run in its second half, not on the last one
        settled = {'now': None, 'since': time.monotonic()}

        def still():
            now = clock.now().nanoseconds
            if now != settled['now']:
                settled['now'], settled['since'] = now, time.monotonic()
            return time.monotonic() - settled['since'] > SETTLED
        spin_until(executor, still, 10.0)
        final = clock.now().nanoseconds
        assert final in set(stamps.tolist()) and final >= stamps[len(stamps) // 2], \
            (final, stamps[-1], len(seen), seen[:3])
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
        executor.shutdown()
        follower.destroy_node()
        rclpy.try_shutdown(context=ctx)
    assert process.returncode == 0, err
    seen = [(w, n) for w, n in seen if n > 0]   # (0 until the first /clock)
    wall, now = np.array([s[0] for s in seen]), np.array([s[1] for s in seen])
    assert len(now) >= 20, 'the follower saw its time move too rarely'
    assert np.all(np.isin(now, stamps)), 'a now() that is not a stamp of the run'
    assert np.all(np.diff(now) > 0)             # the follower's time only moves forward
    simulated = (now[-1] - now[0]) * 1e-9
    assert simulated > 2.0 * (wall[-1] - wall[0]), (simulated, wall[-1] - wall[0])


def test_clock_every_sample_up_to_the_cap_and_every_kth_tick_above():
    assert [clock_step(r) for r in (1.0, 100.0, CLOCK_MAX_RATE, 1000.1, 2500.0, 1e5)] == [
        1, 1, 1, 2, 3, 100]
    stamps = 1_000 + 400_000 * np.arange(7, 19, dtype=np.int64)   # 2.5 kHz, ticks 7 ... 18
    column = encode_clock_column(7, stamps, 3)
    sent = [i + 7 for i, data in enumerate(column) if data is not None]
    assert sent == [9, 12, 15, 18]
    from rclpy.serialization import deserialize_message
    for i, data in enumerate(column):
        if data is not None:
            message = deserialize_message(data, Clock)
            assert message.clock.sec * 10**9 + message.clock.nanosec == stamps[i]
