"""The roller's controls: ``cmd_speed``, ``cmd_torque``, ``reset``, ``pause`` and ``events``.

* ``cmd_speed`` / ``cmd_torque`` (std_msgs/Float64, rad/s and N m) command the drive of the
  ``drive`` parameter (speed: the signed angular speed Ω, the sign of ``omega0``, followed
  with the first-order lag dΩ/dt = (Ω_cmd − Ω)/``drive_lag``; torque: τ about the axis AB).
  A command NaN, ±inf, beyond the limit (|Ω| ≤ 1000 rad/s, |τ| ≤ 10 N m) or for the other
  drive is ignored with a WARN; the body keeps its command.
* A command that is not renewed within ``cmd_timeout`` s of simulated time (0: never)
  returns the body to free motion, as robots do with cmd_vel; the next command drives it
  again. Before the first command the drive holds its start (speed: the speed it starts
  from; torque: 0 N m) and never times out.
* ``reset`` (std_srvs/Empty): back to the initial state of the current parameters (from
  ``theta0``), paths cleared, the drive back to its start, the energy balance restarted.
* ``pause`` (std_srvs/SetBool, data true: pause, false: resume): the simulated clock stops;
  nothing is sampled or published (``/clock`` included) until it resumes, and the run goes
  on from the same sample. Stamps are simulated time: after a pause of p s a realtime run's
  stamps trail the system clock by p s.

Commands and service calls are queued like runtime parameter changes and take effect at the
next sample: a command or a time-out continues the motion from the state of the last
published sample (it does not restart it). Each change is published once on ``events``
(std_msgs/String, reliable, recorded), stamped with the first sample it applies to (the
tick it takes effect at): ``reset``, ``pause``, ``resume``, ``command speed <value>``,
``command torque <value>``, ``timeout``, ``scene <name> <old> -> <new>, ...``, ``restart``
(parameters that restart the motion). ``twodisk-inspect`` checks the stretches between
them on their own. Only realtime runs take commands and calls (a batch run is never idle).
"""

import math

from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64, String
from std_srvs.srv import Empty, SetBool

from ..recordings import cdr
from ..run.scene_simulation import SPEED_LIMIT, TORQUE_LIMIT
from ..physics.scenes.scene import command_error

__all__ = ['EVENTS_TOPIC', 'EVENTS_QOS', 'SceneControl']

EVENTS_TOPIC = 'events'
EVENTS_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
LIMITS = {'speed': SPEED_LIMIT, 'torque': TORQUE_LIMIT}


class SceneControl:
    """Commands, time-out, reset and pause of a :class:`~twodisk_ros.node.roller.Roller`.

    The node asks :meth:`apply` for the queued changes before it samples, and
    :meth:`limit` for the tick its blocks must stop at (a time-out due there).
    """

    def __init__(self, node):
        self.node = node
        self.queue = []             # ('command', drive, value), ('reset',), ('pause', bool)
        self.paused = False
        self.command = None         # the command in force (a float), None: the drive's start
        self.command_tick = None    # tick the command in force took effect at
        self.timed_out = False
        node.create_subscription(Float64, 'cmd_speed',
                                 lambda msg: self._on_command('speed', msg.data), 10)
        node.create_subscription(Float64, 'cmd_torque',
                                 lambda msg: self._on_command('torque', msg.data), 10)
        node.create_service(Empty, 'reset', self._on_reset)
        node.create_service(SetBool, 'pause', self._on_pause)
        self.publisher = node.create_publisher(String, EVENTS_TOPIC, EVENTS_QOS)

    # -- callbacks: queue ------------------------------------------------------------------
    def _on_command(self, drive, value):
        why = command_error(drive, value, LIMITS[drive])
        if not why and self.node.settings.drive != drive:
            why = (f'cmd_{drive} ignored: the drive is {self.node.settings.drive!r} (set the '
                   f'parameter drive to {drive!r} to take it)')
        if why:
            self.node.get_logger().warn(why, throttle_duration_sec=5.0)
            return
        self.queue.append(('command', drive, float(value)))

    def _on_reset(self, request, response):
        self.queue.append(('reset',))
        return response

    def _on_pause(self, request, response):
        self.queue.append(('pause', bool(request.data)))
        response.success = True
        response.message = 'pausing' if request.data else 'resuming'
        return response

    @property
    def pending(self):
        """True while changes wait for the next sample."""
        return bool(self.queue)

    # -- applying ----------------------------------------------------------------------------
    def forget_command(self):
        """The drive back to its start (a reset, or parameters that restart the motion)."""
        self.command = self.command_tick = None
        self.timed_out = False

    def apply(self, tick):
        """Apply the queued changes at ``tick`` (the next sample); returns the changes in
        the pause state as a list of (paused: bool)."""
        pauses = []
        queue, self.queue = self.queue, []
        for item in queue:
            if item[0] == 'reset':
                self.forget_command()
                self.node.restart_motion()
                self.event('reset', tick)
            elif item[0] == 'pause':
                if item[1] != self.paused:
                    self.paused = item[1]
                    pauses.append(self.paused)
                    self.event('pause' if self.paused else 'resume', tick)
            elif self.node.settings.drive == item[1]:    # (a command: the drive may have
                self.command, self.command_tick = item[2], tick    # changed since)
                self.timed_out = False
                self.node.continue_motion(drive=item[1], command=item[2])
                self.event(f'command {item[1]} {item[2]!r}', tick)
        # no time-out here: it is decided when the tick's sample is published (the roller's
        # loop), so a change that arrives before that sample comes first at the same tick
        return pauses

    def timeout_tick(self):
        """The tick at which the command in force times out, or None."""
        s = self.node.settings
        if self.command_tick is None or self.timed_out or s.cmd_timeout <= 0:
            return None
        return self.command_tick + max(1, math.ceil(s.cmd_timeout * s.rate - 1e-9))

    def check_timeout(self, tick):
        """Return to free motion if the command in force has timed out by ``tick``."""
        due = self.timeout_tick()
        if due is not None and tick >= due:
            self.timed_out = True
            self.node.continue_motion(drive='none')
            self.event('timeout', tick)

    def limit(self, tick, count):
        """``count`` cut so that a block from ``tick`` stops where a time-out is due."""
        due = self.timeout_tick()
        return count if due is None or due <= tick else min(count, due - tick)

    def drive_state(self):
        """(drive, command) in force: for a continued or rebuilt motion."""
        if self.timed_out:
            return 'none', None
        return self.node.settings.drive, self.command

    def event(self, text, tick):
        """Publish and record one event, stamped with ``tick``'s stamp."""
        node = self.node
        time_ns = node.stamp_of(tick)
        data = cdr.serialize(String(data=text))
        self.publisher.publish(data)
        if node.recorder is not None:
            node.recorder.write_serialized(self.publisher.topic_name, data, time_ns)
        node.get_logger().info(f'{text} at t = {tick / node.settings.rate:.6g} s')
