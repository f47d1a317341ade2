"""The ``roller`` node: advances the two-disk body in time and publishes its state.

Topics (relative names, so namespaces work), frames per REP-103, SI units:
``pose`` (PoseStamped, body frame at G), ``contact_a`` / ``contact_b`` (PointStamped),
``rolling_state`` (JointState: theta, psi, phase), ``path_a`` / ``path_b`` / ``path_g``
(Path, ≤ 10 Hz), ``markers`` (MarkerArray, ≤ 10 Hz) and ``/diagnostics`` (1 Hz).
Run: ``ros2 run twodisk_ros roller --ros-args --params-file config/oloid.yaml``.
"""

from collections import deque
import signal
import sys

import numpy as np
import rclpy
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.serialization import serialize_message
from rclpy.signals import SignalHandlerOptions
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                SetParametersResult)

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Path
from sensor_msgs.msg import JointState
from visualization_msgs.msg import MarkerArray

from .. import __version__
from ..io import McapRecorder, RecordingError
from . import messages
from .simulation import DEFAULTS, RollerSettings, Simulation

MARKER_RATE = 10.0       # Hz: markers at most this often
PATH_RATE = 2.0          # Hz: paths (up to path_length poses each) at most this often
DIAGNOSTICS_RATE = 1.0   # Hz
BATCH = 500              # samples computed at once in batch runs
QOS_DEPTH = 10

_DESCRIPTIONS = {
    'a': ('semi-axis of each disk along the common axis (m)', (1e-9, 1e9)),
    'b': ('other semi-axis of each disk (m); b > a is allowed', (1e-9, 1e9)),
    'delta': ('half the distance between the disk centres (m), 0 < delta < a', (0.0, 1e9)),
    'mass': ('total mass (kg)', (1e-12, 1e12)),
    'gravity': ('gravitational acceleration (m/s^2)', (0.0, 1e3)),
    'mass_model': ('laminae (two thin disks), solid (convex hull), or custom', None),
    'principal_moments': ('custom mass model: I1, I2, I3 about G (kg m^2)', None),
    'mode': ('dynamic (gravity only) or kinematic (constant angular speed)', None),
    'theta0': ('initial contact angle theta on disk 1 (rad), |theta0| <= theta_max', None),
    'branch': ('+1: the paper branch (B below the plane of disk 1), -1: its mirror', (-1, 1)),
    'omega0': ('initial signed angular speed (rad/s); + means theta increasing on branch +1',
               None),
    'rate': ('publishing rate (Hz); read-only at run time', (1e-3, 1e5)),
    'duration': ('simulated time (s), 0 = until stopped; read-only at run time', None),
    'realtime': ('true: paced by the clock; false: as fast as possible, then exit', None),
    'method': ('table (fast, precomputed cycle tables) or direct (closed forms on the fly)',
               None),
    'tolerance': ('relative ODE tolerance; energy drift above it raises a WARN', (1e-15, 0.5)),
    'frame_id': ('world frame of poses, points, paths and markers', None),
    'path_length': ('poses kept in each Path', (1, 1000000)),
    'record': ('MCAP file to record every published message to, empty = off; read-only', None),
}
_READ_ONLY = ('rate', 'duration', 'realtime', 'record')


def _descriptor(name):
    text, bounds = _DESCRIPTIONS[name]
    descriptor = ParameterDescriptor(description=text, read_only=name in _READ_ONLY)
    if bounds is not None and isinstance(getattr(DEFAULTS, name), int) and not isinstance(
            getattr(DEFAULTS, name), bool):
        step = 2 if name == 'branch' else 1
        descriptor.integer_range = [IntegerRange(from_value=bounds[0], to_value=bounds[1],
                                                 step=step)]
    elif bounds is not None:
        descriptor.floating_point_range = [FloatingPointRange(from_value=float(bounds[0]),
                                                              to_value=float(bounds[1]))]
    return descriptor


def _default_value(name):
    value = getattr(DEFAULTS, name)
    return [float(x) for x in value] if isinstance(value, tuple) else value


class Roller(Node):
    """Publishes the rolling body; the physics lives in :class:`Simulation`."""

    def __init__(self, **kwargs):
        super().__init__('roller', **kwargs)
        for name in _DESCRIPTIONS:
            self.declare_parameter(name, _default_value(name), _descriptor(name))
        values = {name: self.get_parameter(name).value for name in _DESCRIPTIONS}
        self.settings = DEFAULTS.with_values(**values).checked()
        self.simulation = Simulation(self.settings)
        self._recorder = None
        if self.settings.record:
            self._recorder = McapRecorder(self.settings.record, metadata=self._metadata())
        self._pubs = {}  # topic → publisher
        for topic, kind in (('pose', PoseStamped), ('contact_a', PointStamped),
                            ('contact_b', PointStamped), ('rolling_state', JointState),
                            ('path_a', Path), ('path_b', Path), ('path_g', Path),
                            ('markers', MarkerArray), ('/diagnostics', DiagnosticArray)):
            publisher = self.create_publisher(kind, topic, QOS_DEPTH)
            self._pubs[topic] = publisher
            if self._recorder is not None:
                self._recorder.add_topic(publisher.topic_name, kind, publisher.qos_profile)
        self._paths = {key: deque(maxlen=self.settings.path_length) for key in 'abg'}
        self._tick = 0            # samples published since the motion (re)started
        self._t_offset = 0.0      # simulated time (s) at which the motion (re)started
        self._next_path = 0.0
        self._next_marker = 0.0
        self._next_diagnostics = 0.0
        self._pending = None
        self._start_ns = self.get_clock().now().nanoseconds
        self.finished = False
        self.add_on_set_parameters_callback(self._on_set_parameters)
        if self.settings.realtime:
            self._timer = self.create_timer(1.0 / self.settings.rate, self._on_timer)

    # -- parameters -------------------------------------------------------------------------
    def _metadata(self):
        metadata = self.settings.as_strings()
        metadata['version'] = __version__
        return metadata

    def _on_set_parameters(self, parameters):
        changes = {p.name: p.value for p in parameters if p.name in _DESCRIPTIONS}
        base = self._pending or self.settings   # changes not yet applied still count
        try:
            candidate = base.with_values(**changes).checked()
        except (ValueError, TypeError) as error:
            return SetParametersResult(successful=False, reason=str(error))
        self._pending = candidate
        return SetParametersResult(successful=True)

    def _apply_pending(self, now):
        candidate, self._pending = self._pending, None
        physics_changed = any(getattr(candidate, k) != getattr(self.settings, k)
                              for k in RollerSettings.PHYSICS)
        self.settings = candidate
        for key in 'abg':
            self._paths[key] = deque(self._paths[key], maxlen=candidate.path_length)
        if physics_changed:
            self.simulation = Simulation(candidate)
            self._t_offset, self._tick = now, 0
            for path in self._paths.values():
                path.clear()
            self._next_diagnostics = now
        if self._recorder is not None:
            self._recorder.set_metadata(self._metadata())

    # -- publishing -------------------------------------------------------------------------
    def _wanted(self, topic):
        return self._recorder is not None or self._pubs[topic].get_subscription_count() > 0

    def _publish(self, topic, message, time_ns):
        data = serialize_message(message)   # once, for the wire and the file
        self._pubs[topic].publish(data)
        if self._recorder is not None:
            self._recorder.write_serialized(self._pubs[topic].topic_name, data, time_ns)

    def _sim_time(self, tick):
        return self._t_offset + tick / self.settings.rate

    def _on_timer(self):
        now = self._sim_time(self._tick)
        if self._pending is not None:
            self._apply_pending(now)
        duration = self.settings.duration
        if duration > 0 and now > duration + 1e-9:
            self.finished = True
            return
        self.publish_samples(np.array([now]))

    def publish_samples(self, times):
        """Compute and publish the state at simulated times (s, increasing array)."""
        sample = self.simulation.sample(times - self._t_offset)
        frame = self.settings.frame_id
        state = sample.state
        quaternions = state.quaternion if self._wanted('pose') else None
        for i, t in enumerate(times):
            time_ns = self._start_ns + int(round(t * 1e9))
            if quaternions is not None:
                self._publish('pose', messages.pose_stamped(
                    frame, time_ns, state.position_g[i], quaternions[i]), time_ns)
            for key, points in (('contact_a', state.contact_a), ('contact_b', state.contact_b)):
                if self._wanted(key):
                    self._publish(key, messages.point_stamped(frame, time_ns, points[i]),
                                  time_ns)
            if self._wanted('rolling_state'):
                self._publish('rolling_state', messages.rolling_state(
                    time_ns, (state.theta[i], state.psi[i], sample.phase[i]),
                    (sample.theta_rate[i], sample.psi_rate[i], sample.phase_rate[i])), time_ns)
            for key, points in (('a', state.contact_a), ('b', state.contact_b),
                                ('g', state.position_g)):
                if self._wanted('path_' + key):
                    self._paths[key].append(messages.path_pose(frame, time_ns, points[i]))
            if t + 1e-12 >= self._next_path:
                self._next_path = t + 1.0 / PATH_RATE
                self._publish_paths(time_ns)
            if t + 1e-12 >= self._next_marker:
                self._next_marker = t + 1.0 / MARKER_RATE
                self._publish_markers(sample, i, time_ns)
            if t + 1e-12 >= self._next_diagnostics:
                self._next_diagnostics = t + 1.0 / DIAGNOSTICS_RATE
                self._publish_diagnostics(sample, i, time_ns)
        self._tick += len(times)

    def _publish_paths(self, time_ns):
        for key in 'abg':
            topic = 'path_' + key
            if self._wanted(topic):
                self._publish(topic, messages.path(self.settings.frame_id, time_ns,
                                                   self._paths[key]), time_ns)

    def _publish_markers(self, sample, i, time_ns):
        frame = self.settings.frame_id
        if self._wanted('markers'):
            state = sample.state
            disk1, disk2 = self.simulation.disk_outlines(state.rotation[i], state.position_g[i])
            self._publish('markers', messages.body_markers(
                frame, time_ns, disk1, disk2, state.contact_a[i], state.contact_b[i],
                self.simulation.body.size), time_ns)

    def _publish_diagnostics(self, sample, i, time_ns):
        if not self._wanted('/diagnostics'):
            return
        drift = self.simulation.energy_drift(sample.energy[i])
        dynamic = self.settings.mode == 'dynamic'
        warn = dynamic and drift > self.settings.tolerance
        values = [('energy', float(sample.energy[i])), ('energy_drift', drift),
                  ('tilt', float(sample.state.tilt[i])), ('phase', float(sample.phase[i])),
                  ('mode', self.settings.mode), ('method', self.settings.method)]
        for k, (eq, period) in enumerate(self.simulation.equilibria):
            values.append((f'equilibrium {k}', (
                f'{eq.name}: theta={eq.theta:.9g} rad, psi={eq.psi:.9g} rad, '
                f'height={eq.height:.9g} m, d2z/d{eq.coordinate}2={eq.curvature:.6g} m, '
                f'{eq.stability}' + (f', period={period:.9g} s' if period else ''))))
        message = (f'energy drift {drift:.2e} exceeds tolerance {self.settings.tolerance:.1e}'
                   if warn else 'rolling')
        level = messages.WARN if warn else messages.OK
        self._publish('/diagnostics', messages.diagnostics(
            time_ns, 'twodisk_ros: roller', level, message, values), time_ns)

    def run_batch(self):
        """realtime=false: compute ``duration`` as fast as possible, publishing every sample."""
        count = int(np.floor(self.settings.duration * self.settings.rate + 1e-9)) + 1
        for start in range(0, count, BATCH):
            if not rclpy.ok():
                break
            ticks = np.arange(start, min(count, start + BATCH))
            self.publish_samples(ticks / self.settings.rate)
        self.finished = True

    def close(self):
        """Finish the recording (idempotent)."""
        if self._recorder is not None:
            self._recorder.close()


def _interrupt(signum, frame):
    raise KeyboardInterrupt(signal.Signals(signum).name)


def main(args=None):
    """Entry point of ``ros2 run twodisk_ros roller``; exit 2 on invalid start-up values.

    SIGINT and SIGTERM both end the node cleanly (recording finished) with exit code 0.
    """
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.SIGINT)
    signal.signal(signal.SIGTERM, _interrupt)
    node = None
    try:
        try:
            node = Roller()
        except (ValueError, TypeError, RecordingError,
                ParameterException) as error:
            print(f'roller: {_one_line(error)}', file=sys.stderr)
            return 2
        if not node.settings.realtime:
            node.run_batch()
        else:
            while rclpy.ok() and not node.finished:
                rclpy.spin_once(node, timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.close()
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


def _one_line(error):
    text = ' '.join(str(error).split())
    return text if len(text) < 400 else text[:397] + '...'


if __name__ == '__main__':
    sys.exit(main())
