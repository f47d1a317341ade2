"""The ``roller`` node: advances the two-disk body in time and publishes its state.

Topics (relative names, so namespaces work), frames per REP-103, SI units:
``pose`` (PoseStamped, body frame at G), ``contact_a`` / ``contact_b`` (PointStamped),
``rolling_state`` (JointState: theta, psi, phase), ``wrench_a`` / ``wrench_b``
(WrenchStamped: the ground's force on the body at A / B), ``path_a`` / ``path_b`` /
``path_g`` (Path, ≤ 2 Hz), ``markers`` (MarkerArray, ≤ 10 Hz), ``/diagnostics`` (1 Hz), the
body frame on ``/tf`` (at ``rate``, the values of ``pose``), the disk frames on ``/tf_static``
and the URDF on ``robot_description`` (latched: :mod:`~twodisk_ros.node.frames_publisher`), and
the simulated time on ``/clock`` (:mod:`~twodisk_ros.node.sim_clock`).
Run: ``ros2 run twodisk_ros roller --ros-args --params-file config/oloid.yaml``.

States are computed in blocks ahead of time and encoded to CDR in one vectorised step
(:mod:`twodisk_ros.recordings.cdr`); the per-sample work is handing bytes to DDS and to the recorder.
"""

from collections import deque
import math
import time

import numpy as np
from rclpy.node import Node
from rcl_interfaces.msg import SetParametersResult

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PointStamped, PoseStamped, WrenchStamped
from nav_msgs.msg import Path
from sensor_msgs.msg import JointState
from visualization_msgs.msg import MarkerArray

from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

from .. import __version__
from ..recordings import McapRecorder, cdr
from ..recordings.cdr_markers import encode_markers
from ..outputs import check_output
from ..physics.motion.startup import startup_estimate
from ..run import schedule
from ..run.description import RunDescription
from ..run.parameters import BY_NAME, DEFAULTS, PARAMETERS
from ..run.hybrid_simulation import simulation_of
from ..run.scene_simulation import frame_metadata
from . import diagnostics, encoding, messages, run_summary, sim_clock
from .descriptors import descriptor, ros_value
from .frames_publisher import LatchedTopics, TF_QOS, TF_TOPIC, TFMessage, describe
from .path_history import PathHistory
from .scene_control import EVENTS_QOS, SceneControl

__all__ = ['Roller']

MARKER_RATE = 10.0       # Hz of simulated time: markers at most this often
PATH_RATE = 2.0          # Hz of simulated time: paths (up to path_length poses each)
DIAGNOSTICS_RATE = 1.0   # Hz of simulated time
BATCH_SAMPLES = 2000     # samples computed and written at once in batch runs
AHEAD = 0.05             # s: realtime states are computed this far ahead, in one block
MAX_LAG = 0.5            # s: a realtime node further behind drops samples to catch up
QOS_DEPTH = 10
MIN_SAMPLES = 5          # a stopped run that began publishing ends with at least this many
TOPIC_TYPES = {
    'pose': PoseStamped, 'contact_a': PointStamped, 'contact_b': PointStamped,
    'rolling_state': JointState, 'wrench_a': WrenchStamped, 'wrench_b': WrenchStamped,
    'path_a': Path, 'path_b': Path, 'path_g': Path, 'markers': MarkerArray,
    '/diagnostics': DiagnosticArray, TF_TOPIC: TFMessage,
}
#: QoS other than keep last QOS_DEPTH (tf2's broadcaster QoS for /tf)
TOPIC_QOS = {TF_TOPIC: TF_QOS}
#: topics that need the contact forces of every sample
NEED_FORCES = ('wrench_a', 'wrench_b', 'markers', '/diagnostics')


class Roller(Node):
    """Publishes the rolling body; the physics lives in :class:`Simulation` (or HybridSimulation).

    Raises ValueError or RuntimeError (one line) if the parameters define no valid run,
    and :class:`~twodisk_ros.recordings.RecordingError` if the record file cannot be written.
    """

    def __init__(self, **kwargs):
        super().__init__('roller', **kwargs)
        for p in PARAMETERS:
            self.declare_parameter(p.name, ros_value(p), descriptor(p))
        values = {p.name: self.get_parameter(p.name).value for p in PARAMETERS}
        sim_clock.check_use_sim_time(self.get_parameter(sim_clock.USE_SIM_TIME).value)
        self.settings = DEFAULTS.with_values(**values).checked()
        if self.settings.record:   # before any work; never a file the node did not create
            check_output(self.settings.record, overwrite=self.settings.overwrite,
                         suffixes=('.mcap',), option='-p overwrite:=true')
        run = RunDescription(self.settings)
        if self.settings.shape != 'ellipse':
            self.get_logger().info(f'shape: {run.shape_line}')
        cost = startup_estimate(run.body)
        if cost.message:      # an extreme body: say what the tables cost while it is paid
            self.get_logger().info(cost.message)
        self.simulation = simulation_of(self.settings, run)
        note = run_summary.start_note(run.body, self.simulation.initial_state())
        if note:
            self.get_logger().info(note)
        if self.simulation.invalid is not None:    # a slope the body cannot stand on
            self.get_logger().error(self.simulation.invalid.reason)
        if (self.settings.method == 'table' and self.simulation.scene.level
                and self.simulation.stream.solver == 'DOP853'):
            self.get_logger().info(
                'no closed form of this motion is resolved (a start just below the barrier '
                'of a thin body): it is integrated numerically (DOP853), 0.5 s ahead at a '
                'time, at a higher cost per sample')
        self._recorder = None
        self._pubs = {topic: self.create_publisher(kind, topic, TOPIC_QOS.get(topic, QOS_DEPTH))
                      for topic, kind in TOPIC_TYPES.items()}
        self._pubs[sim_clock.CLOCK_TOPIC] = self.create_publisher(
            Clock, sim_clock.CLOCK_TOPIC, sim_clock.CLOCK_QOS)     # published, not recorded
        description = describe(self.settings, self.simulation.body,
                               self.simulation.dynamics.mass)
        if description.problem:
            self.get_logger().warn(description.problem)
        self._latched = LatchedTopics(self, description)
        self.control = SceneControl(self)
        try:
            if self.settings.record:
                self._open_recorder()
            self._init_run_state()
        except BaseException:   # (a signal's StopNow too): no hidden temporary file is left
            if self._recorder is not None:
                self._recorder.discard()
            raise

    def _init_run_state(self):
        """The counters, history, clocks and callbacks of a run (after the recorder)."""
        self.samples_published = 0      # samples since start (across motion restarts)
        self.samples_dropped = 0        # realtime samples skipped to catch up with the clock
        self.dropped_reported = 0      # samples_dropped at the last diagnostics
        self.messages_built = {topic: 0 for topic in self._pubs}
        self._history = PathHistory(self.settings.path_length)
        self._tick = 0                  # global sample index: simulated time tick / rate
        self._motion_tick = 0           # tick at which the motion (re)started
        self._next = {'path': 0.0, 'marker': 0.0, 'diagnostics': 0.0}
        self._pending = None
        self._block = None              # realtime: (first tick, Sample, encoded messages)
        self._last = None               # (Sample, index, tick) of the last sample published
        self._pause_wall = None         # wall time (monotonic, s) the pause began
        self._start_ns = self.get_clock().now().nanoseconds
        self._wall_start = time.monotonic()
        self._rate_window = deque(maxlen=64)   # (wall time, samples) for the achieved rate
        self.lag = deque(maxlen=1000)          # s: wall clock minus the last sample's time
        self.finished = False
        self.add_on_set_parameters_callback(self._on_set_parameters)
        if self.settings.realtime:
            self._timer = self.create_timer(1.0 / self.settings.rate, self._on_timer)
        self.get_logger().info(run_summary.start_line(self.settings))

    def _open_recorder(self):
        """The recorder of ``record``, under a temporary name until its first sample."""
        try:
            self._recorder = McapRecorder(self.settings.record, metadata=self._metadata(),
                                          overwrite=self.settings.overwrite)
            for topic, kind in TOPIC_TYPES.items():
                publisher = self._pubs[topic]
                self._recorder.add_topic(publisher.topic_name, kind, publisher.qos_profile)
            for topic, publisher in self._latched.publishers.items():
                self._recorder.add_topic(publisher.topic_name, publisher.msg_type,
                                         publisher.qos_profile)
            self._recorder.add_topic(self.control.publisher.topic_name, String, EVENTS_QOS)
        except BaseException:      # also a start-up cut short by a second signal
            if self._recorder is not None:
                self._recorder.discard()
            raise

    # -- parameters -------------------------------------------------------------------------
    @property
    def pending_changes(self):
        """True while accepted parameter changes wait for the next sample."""
        return self._pending is not None or self.control.pending

    @property
    def recorder(self):
        """The McapRecorder of ``record``, or None."""
        return self._recorder

    def stamp_of(self, tick):
        """The stamp (int ns) of global tick ``tick``."""
        return int(schedule.stamps(self._start_ns, [tick], self.settings.rate)[0])

    @property
    def motion_start_stamp(self):
        """The stamp (int ns) of the first sample of the current motion (its last restart)."""
        return self.stamp_of(self._motion_tick)

    def _metadata(self):
        """The recording's metadata: the run's (parameters, a points run's outline)."""
        metadata = self.simulation.run.metadata()
        metadata.update(self.settings.as_strings())   # (friction, frames: changed in place)
        metadata.update(frame_metadata(self.settings))
        metadata['version'] = __version__
        return metadata

    def _on_set_parameters(self, parameters):
        try:   # (called before rclpy's own use_sim_time callback, which it can stop)
            for p in parameters:
                if p.name == sim_clock.USE_SIM_TIME:
                    sim_clock.check_use_sim_time(p.value)
        except ValueError as error:
            return SetParametersResult(successful=False, reason=str(error))
        changes = {p.name: p.value for p in parameters if p.name in BY_NAME}
        read_only = [name for name in changes if BY_NAME[name].read_only]
        if read_only:
            return SetParametersResult(successful=False,
                                       reason=f'{read_only[0]} is read-only at run time')
        base = self._pending[0] if self._pending else self.settings
        try:
            candidate = base.with_values(**changes).checked()
            simulation = (simulation_of(candidate) if candidate.physics_differs(self.settings)
                          else None)
            if simulation is None:
                self.simulation.check_scene_change(candidate)
            built = simulation or self.simulation
            description = describe(candidate, built.body, built.dynamics.mass)
        except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
            return SetParametersResult(successful=False, reason=' '.join(str(error).split()))
        self._pending = (candidate, simulation, description)
        return SetParametersResult(successful=True)

    def _apply_pending(self):
        (candidate, simulation, description), self._pending = self._pending, None
        previous, self.settings = self.settings, candidate
        if description.problem:
            self.get_logger().warn(description.problem, throttle_duration_sec=60.0)
        self._latched.take(description)
        self._history.length = candidate.path_length
        if simulation is not None:
            self.control.forget_command()
            self._restart(simulation)
            self.control.event('restart', self._tick)
        elif candidate.scene_differs(previous):
            if candidate.drive != previous.drive:
                self.control.forget_command()
            self.continue_motion(*self.control.drive_state())
            changed = [p.name for p in PARAMETERS if p.scene
                       and getattr(candidate, p.name) != getattr(previous, p.name)]
            self.control.event('scene ' + ', '.join(
                f'{name} {getattr(previous, name)} -> {getattr(candidate, name)}'
                for name in changed), self._tick)
        else:   # the same motion; friction, frame or path length may have changed
            self.simulation.update(candidate)
            if self._block is not None:     # the prepared samples, encoded again
                first, sample, stamps, _ = self._block
                self._block = (first, sample, stamps, self._encode(first, sample, stamps))
        if self._recorder is not None:
            self._recorder.set_metadata(self._metadata())

    def _restart(self, simulation):
        self.simulation = simulation
        self._motion_tick = self._tick
        self._block = self._last = None
        self._history.clear()
        self._next['diagnostics'] = self._tick / self.settings.rate

    def restart_motion(self):
        """The motion from the initial state of the current parameters, at the next tick."""
        self._restart(self.simulation.restarted())

    def continue_motion(self, drive, command=None):
        """The motion continued from the last published sample under ``drive``/``command``
        and the current settings (from the start if no sample of this motion is out yet)."""
        if self._last is None:
            self.simulation = type(self.simulation)(
                self.settings, self.simulation.run if self.simulation.run.settings
                == self.settings else None, drive=drive, command=command)
            self._motion_tick = self._tick
        else:
            sample, i, tick = self._last
            self.simulation = self.simulation.continued(self.settings, sample, i,
                                                        drive=drive, command=command)
            self._motion_tick = tick
        self._block = None

    # -- computing and publishing -----------------------------------------------------------
    def _wanted(self, topic):
        return self._recorder is not None or self._pubs[topic].get_subscription_count() > 0

    def _prepare(self, first, count):
        """Sample and encode ``count`` samples from global tick ``first``."""
        rate = self.settings.rate
        ticks = np.arange(first, first + count)
        invalid_before = self.simulation.invalid
        sample = self.simulation.sample((ticks - self._motion_tick) / rate,
                                        forces=any(self._wanted(t) for t in NEED_FORCES),
                                        time_offset=self._motion_tick / rate)
        if invalid_before is None and self.simulation.invalid is not None:
            self.get_logger().error(f'outside the rolling model: '
                                    f'{self.simulation.invalid.reason}; the rolling solution '
                                    'is published on, marked invalid in /diagnostics')
        stamps = schedule.stamps(self._start_ns, ticks, rate)
        return sample, stamps, self._encode(first, sample, stamps)

    def _encode(self, first, sample, stamps):
        """CDR bytes of the per-sample topics somebody wants (:func:`encoding.encode_block`)."""
        encoded, built = encoding.encode_block(
            first, sample, stamps, self.settings, self._wanted,
            self._pubs[sim_clock.CLOCK_TOPIC].get_subscription_count() > 0)
        for topic, count in built.items():
            self.messages_built[topic] += count
        return encoded

    def _emit(self, sample, stamps, encoded, start, stop):
        """Publish and record samples [start, stop) of a prepared block, sample by sample; the
        latched topics first when they changed, stamped with the first sample's stamp; a
        switch of contact model as an event stamped with the new model's first sample."""
        for j, text in self.simulation.switches(sample, start, stop):
            if j > start:               # (the simulation's indices never go back)
                self._emit(sample, stamps, encoded, start, j)
                start = j
            self.control.event(text, self._tick)
        if self._latched.due:
            self._latched.send(int(stamps[start]), None if self._recorder is None
                               else self._recorder.write_serialized)
        subscribed = [(self._pubs[topic].publish, encoded[topic]) for topic in encoded
                      if self._pubs[topic].get_subscription_count() > 0]
        for i in range(start, stop):
            for publish, column in subscribed:
                data = column[i]
                if data is not None:      # (/clock skips samples above CLOCK_MAX_RATE)
                    publish(data)
        topics = [topic for topic in encoded if topic != sim_clock.CLOCK_TOPIC]
        if self._recorder is not None and topics:
            self._recorder.write_interleaved(
                [self._pubs[t].topic_name for t in topics],
                [encoded[t][start:stop] for t in topics], stamps[start:stop])
        self._low_rate_topics(sample, stamps, start, stop)
        self._history.extend(stamps[start:stop], sample.contact_a[start:stop],
                             sample.contact_b[start:stop], sample.position_g[start:stop])
        self._tick += stop - start
        self.samples_published += stop - start
        self._last = (sample, stop - 1, self._tick - 1)

    def _low_rate_topics(self, sample, stamps, start, stop):
        """Paths, markers and diagnostics of samples [start, stop), each at its own rate."""
        times = sample.t[start:stop] + self._motion_tick / self.settings.rate
        for kind, rate in (('path', PATH_RATE), ('marker', MARKER_RATE),
                           ('diagnostics', DIAGNOSTICS_RATE)):
            while True:
                j = int(np.searchsorted(times, self._next[kind] - 1e-12))
                if j >= len(times):
                    break
                self._next[kind] = times[j] + 1.0 / rate
                i = start + j
                if kind == 'path':
                    self._publish_paths(sample, stamps, start, i)
                elif kind == 'marker':
                    self._publish_markers(sample, i, int(stamps[i]))
                else:
                    self._publish_diagnostics(sample, i, int(stamps[i]))

    def _send(self, topic, data, time_ns):
        self.messages_built[topic] += 1
        if self._pubs[topic].get_subscription_count() > 0:
            self._pubs[topic].publish(data)
        if self._recorder is not None:
            self._recorder.write_serialized(self._pubs[topic].topic_name, data, time_ns)

    def _publish_paths(self, sample, stamps, start, i):
        """The three paths up to sample i of the block (the block's [start, i] and before)."""
        frame, time_ns = self.settings.frame_id, int(stamps[i])
        points = {'a': sample.contact_a, 'b': sample.contact_b, 'g': sample.position_g}
        for key in 'abg':
            topic = 'path_' + key
            if self._wanted(topic):
                past_stamps, past_points = self._history.tail(
                    key, stamps[start:i + 1], points[key][start:i + 1])
                self._send(topic, cdr.encode_path(time_ns, frame, past_points,
                                                  stamps_ns=past_stamps), time_ns)

    def _publish_markers(self, sample, i, time_ns):
        if not self._wanted('markers'):
            return
        rotation = self.simulation.rotation(sample, i)
        disk1, disk2 = self.simulation.disk_outlines(rotation, sample.position_g[i])
        hull = (self.simulation.hull_rims(rotation, sample.position_g[i])
                if self.settings.mass_model == 'solid' else None)
        specs = messages.body_marker_specs(disk1, disk2, sample.contact_a[i],
                                           sample.contact_b[i], self.simulation.body.size,
                                           hull=hull)
        if sample.forces is not None:
            specs += messages.force_arrow_specs(
                (sample.contact_a[i], sample.contact_b[i]),
                (sample.forces.force_a[i], sample.forces.force_b[i]), self.simulation.weight,
                self.simulation.body.size)
        if self.settings.slope != 0.0:
            specs.append(messages.ground_spec(sample.position_g[i], self.settings.slope,
                                              self.simulation.body.size))
        self._send('markers', encode_markers(time_ns, self.settings.frame_id, specs), time_ns)

    def achieved_rate(self):
        """Samples per wall-clock second over the last few ticks (realtime), or None."""
        if len(self._rate_window) < 2:
            return None
        (w0, k0), (w1, k1) = self._rate_window[0], self._rate_window[-1]
        return (k1 - k0) / (w1 - w0) if w1 > w0 else None

    def _publish_diagnostics(self, sample, i, time_ns):
        if self._wanted('/diagnostics'):
            level, message, values = diagnostics.status(self, sample, i)
            self._send('/diagnostics', cdr.serialize(messages.diagnostics(
                time_ns, diagnostics.NAME, level, message, values)), time_ns)

    # -- the two ways to run ----------------------------------------------------------------
    def _on_timer(self):
        """Realtime: publish every sample that is due by the wall clock (drop beyond MAX_LAG)."""
        if self.finished:
            return
        rate = self.settings.rate
        now = time.monotonic()
        if self._tick == 0 and not self.samples_published:
            # the clock starts with the first tick, not when the node was built (start-up,
            # discovery and the executor's first spin are not samples missed)
            self._wall_start = now
            self._start_ns = self.get_clock().now().nanoseconds
        due = int(math.floor((now - self._wall_start) * rate)) + 1   # ticks due so far
        limit = self._end_tick()
        if not self.control.paused:
            # before the queued changes: they are stamped with the tick they take effect at,
            # which must be a sample that is published, not one dropped
            self._drop_backlog(due if limit is None else min(due, limit))
        if self._pending is not None:
            self._apply_pending()
        for paused in self.control.apply(self._tick):
            if paused:
                self._pause_wall = now
            elif self._pause_wall is not None:     # the schedule moves on by the pause
                self._wall_start += now - self._pause_wall
                due = int(math.floor((now - self._wall_start) * rate)) + 1
        if self.control.paused:
            return
        if limit is not None:
            due = min(due, limit)
        self._drop_backlog(due)
        while self._tick < due:
            self.control.check_timeout(self._tick)
            block = self._block
            if block is None or not block[0] <= self._tick < block[0] + len(block[1]):
                count = max(1, int(AHEAD * rate), due - self._tick)
                if limit is not None:
                    count = min(count, limit - self._tick)
                count = self.control.limit(self._tick, count)
                self._block = block = (self._tick, *self._prepare(self._tick, count))
            first, sample, stamps, encoded = block
            start = self._tick - first
            stop = min(len(sample), due - first)
            self._emit(sample, stamps, encoded, start, stop)
        self._rate_window.append((now, self.samples_published))
        if self._tick:   # how far the newest published sample's time trails the wall clock
            self.lag.append(now - self._wall_start - (self._tick - 1) / rate)
        if limit is not None and self._tick >= limit:
            self.finished = True

    def _drop_backlog(self, due):
        """Skip the samples beyond MAX_LAG behind the wall clock (``due``: ticks due), counted
        in ``samples_dropped`` and said in a WARN."""
        rate = self.settings.rate
        backlog = due - self._tick
        allowed = max(1, int(MAX_LAG * rate))
        if backlog > allowed:
            self.samples_dropped += backlog - allowed
            self._tick = due - allowed
            self._block = None
            self.get_logger().warn(
                f'cannot hold rate {rate:g} Hz: dropped {backlog - allowed} samples '
                f'({self.samples_dropped} so far) to keep real time',
                throttle_duration_sec=5.0)

    def _end_tick(self):
        """One past the last tick of a run with a duration, or None."""
        last = schedule.last_tick(self.settings.duration, self.settings.rate)
        return None if last is None else last + 1

    def run_batch(self, keep_going=lambda: True):
        """realtime=false: compute ``duration`` as fast as possible, publishing every sample.

        ``keep_going()`` is asked between blocks (a signal ends the run at a block boundary,
        every topic on the same sample).
        """
        end = self._end_tick()
        while self._tick < end and keep_going():
            if self._pending is not None:
                self._apply_pending()
            count = min(BATCH_SAMPLES, end - self._tick)
            sample, stamps, encoded = self._prepare(self._tick, count)
            self._emit(sample, stamps, encoded, 0, count)
        self.finished = self._tick >= end

    def finish_samples(self):
        """Publish at once what a stopped run still needs to be checkable offline.

        A run stopped after its first sample ends with at least :data:`MIN_SAMPLES` samples
        (the fewest the inspector's central differences use); stamps stay on the schedule.
        """
        missing = MIN_SAMPLES - self.samples_published
        end = self._end_tick()
        if end is not None:
            missing = min(missing, end - self._tick)
        if self.samples_published > 0 and missing > 0:
            sample, stamps, encoded = self._prepare(self._tick, missing)
            self._emit(sample, stamps, encoded, 0, missing)

    def close(self):
        """Finish the recording (idempotent; RecordingError if it cannot be written); True if
        one was kept. One without a sample (stopped during start-up) is discarded: its temporary
        file removed, an existing file at ``record`` left as it was."""
        if self._recorder is None:
            return False
        return self._recorder.discard()   # closed as it is once it holds a sample

    def end_line(self):
        """One line on what the run did (samples, times, the file, warnings), for the log."""
        recorder, invalid = self._recorder, self.simulation.invalid
        return run_summary.end_line(
            self.samples_published, max(self._tick - 1, 0) / self.settings.rate,
            time.monotonic() - self._wall_start,
            recorder.path if recorder is not None and recorder.published else None,
            invalid.reason if invalid is not None else None, self.samples_dropped)

