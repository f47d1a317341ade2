"""The paced loop of ``twodisk-view``: samples of a source shown on the server when due.

Every sample is shown when the wall clock reaches its ``due`` time: its transforms on
``/tf`` and the server's time; the contact segment and the force arrows at most
:data:`SCENE_RATE` times per second of the show, the traces :data:`TRACE_RATE` times. When
the loop is more than :data:`MAX_LAG` behind (a stalled machine), the overdue samples are
skipped, counted in :attr:`Player.skipped`, and the traces still take them. After the last
sample the server keeps serving the last state (and the static content to new clients)
until told to stop. No rclpy here.
"""

import time

from . import scene

__all__ = ['MAX_LAG', 'SCENE_RATE', 'TRACE_RATE', 'Player']

#: Contact segment and force arrows: at most this many updates per second of the show.
SCENE_RATE = 60.0
#: Traces of A, B and G: updates per second of the show.
TRACE_RATE = 10.0
#: Samples due longer ago than this (s) are skipped rather than shown late.
MAX_LAG = 0.5
#: How often new subscriptions are served while waiting for a sample or idle (s).
IDLE_POLL = 0.05


class Player:
    """Shows a source's samples on a :class:`~twodisk_ros.view.server.ViewServer`.

    Parameters
    ----------
    source : LiveSource or ReplaySource
        The samples (with ``settings``, ``body``, ``weight``, ``has_forces``).
    server : ViewServer
    frames : (str, str)
        The world frame ``frame_id`` and the body frame.
    parts : dict of str to Mesh
        The body's mesh in parts (:func:`twodisk_ros.model.mesh.mesh_parts`), body frame (m).
    disks : pair of DiskFrame
        The disk frames relative to the body frame.
    run_info, parameters : dict
        What ``/parameters`` shows under ``run`` and under ``parameters``.
    stop : threading.Event
        Set to stop (by the signal handlers).
    """

    def __init__(self, source, server, frames, parts, disks, run_info, parameters, stop):
        self.source, self.server, self.stop = source, server, stop
        self.frame_id, self.body_frame = frames
        self.parts, self.disks = parts, disks
        self.document = {'parameters': parameters, 'run': run_info}
        self.size = source.body.size
        self.traces = scene.Traces(source.settings.path_length)
        self.shown = 0           #: samples shown
        self.skipped = 0         #: samples skipped to keep up with the clock
        self.last_stamp = None   #: stamp (ns) of the last sample shown
        self._next_scene = self._next_trace = 0.0

    # -- static content -------------------------------------------------------------------
    def _static(self, topics):
        stamp = self.last_stamp if self.last_stamp is not None else self.source.start_ns
        if '/body' in topics:
            self.server.log_scene('/body', scene.body_update(
                stamp, self.body_frame, self.source.body, self.parts, self.disks), stamp)
        if '/parameters' in topics:
            self.server.log_parameters(self.document, stamp)

    def serve_subscriptions(self):
        """Log the static content of the channels a client subscribed to since last time."""
        topics = self.server.newly_subscribed()
        if topics:
            self._static(topics)

    # -- samples --------------------------------------------------------------------------
    def _show(self, block, i, clock):
        stamp = int(block.stamp_ns[i])
        self.server.log_transforms(scene.frame_transforms(
            stamp, self.frame_id, self.body_frame, block.position_g[i], block.quaternion[i],
            self.disks), stamp)
        if clock >= self._next_scene:
            self._next_scene = clock + 1.0 / SCENE_RATE
            self.server.log_scene('/contact_segment', scene.contact_update(
                stamp, self.frame_id, block.contact_a[i], block.contact_b[i], self.size), stamp)
            if block.force_a is not None:
                self.server.log_scene('/contact_forces', scene.force_update(
                    stamp, self.frame_id, (block.contact_a[i], block.contact_b[i]),
                    (block.force_a[i], block.force_b[i]), self.source.weight, self.size),
                    stamp)
        self.server.broadcast_time(stamp)
        self.last_stamp = stamp
        self.shown += 1

    def _extend(self, block, start, stop=None):
        """Add samples [start, stop) of the block to the traces."""
        pick = slice(start, stop)
        self.traces.extend(block.contact_a[pick], block.contact_b[pick], block.position_g[pick])

    def _publish_traces(self, stamp):
        self.server.log_scene('/traces', scene.trace_update(
            stamp, self.frame_id, self.traces, self.size), stamp)

    def _wait(self, due):
        """Serve new subscriptions until the monotonic time ``due``; False if stopped."""
        while True:
            self.serve_subscriptions()
            left = due - time.monotonic()
            if left <= 0:
                return not self.stop.is_set()
            if self.stop.wait(min(left, IDLE_POLL)):
                return False

    def play(self):
        """Show every sample when due; return True if the source ran out, False if stopped.

        The static content goes to each client when it subscribes (:meth:`serve_subscriptions`).
        """
        self.source.start(time.time_ns())
        start = time.monotonic()
        self.document['run']['start_stamp_ns'] = self.source.start_ns
        for block in self.source.blocks():
            traced = 0
            for i in range(len(block)):
                if not self._wait(start + float(block.due[i])):
                    return False
                clock = time.monotonic() - start
                if clock - float(block.due[i]) > MAX_LAG and i + 1 < len(block):
                    self.skipped += 1
                    continue
                self._show(block, i, clock)
                if clock >= self._next_trace:
                    self._next_trace = clock + 1.0 / TRACE_RATE
                    self._extend(block, traced, i + 1)
                    traced = i + 1
                    self._publish_traces(self.last_stamp)
            self._extend(block, traced)
        return True

    def idle(self):
        """After the run: keep serving new subscriptions until stopped."""
        if self.last_stamp is not None:
            self._publish_traces(self.last_stamp)
        while not self.stop.wait(IDLE_POLL):
            self.serve_subscriptions()
