"""The samples ``twodisk-view`` shows: the library's motion computed as it goes, or a recording.

Both sources give :class:`Block` s of samples with their stamps (ns) and the wall-clock
times (s after the show started) at which each is due. No rclpy here.

- :class:`LiveSource`: the node's physics (:class:`twodisk_ros.run.simulation.Simulation`,
  the same settings as ``roller``) sampled at ``rate`` from t = 0, in blocks of
  :data:`BLOCK_SECONDS` of simulated time, for ``duration`` (0: until stopped). Sample k is
  at t = k / rate and stamped ``start_ns + round(k × 1e9 / rate)``, as the node stamps it
  (stamps follow the clock at ``speed`` 1); the contact forces of every sample are computed.
- :class:`ReplaySource`: the samples of an MCAP recording of the node (``pose``,
  ``contact_a``/``contact_b``, ``wrench_a``/``wrench_b`` when recorded), values and stamps
  exactly as recorded (:func:`twodisk_ros.runs.recorded_run`).
"""

from dataclasses import dataclass

import numpy as np

from ..run import schedule
from ..run.simulation import Simulation
from ..runs import recorded_run

__all__ = ['BLOCK_SECONDS', 'Block', 'LiveSource', 'ReplaySource']

#: Simulated seconds computed at a time by the live source (ahead of the clock).
BLOCK_SECONDS = 0.05


@dataclass
class Block:
    """Consecutive samples (arrays over the block; world frame, SI units).

    ``due`` is when each sample is shown, in wall-clock seconds after the show started;
    ``force_a``/``force_b`` (N) are None when the source has no forces.
    """

    stamp_ns: np.ndarray      #: (n,) int64
    due: np.ndarray           #: (n,) s
    position_g: np.ndarray    #: (n, 3) m
    quaternion: np.ndarray    #: (n, 4) x, y, z, w, body → world
    contact_a: np.ndarray     #: (n, 3) m
    contact_b: np.ndarray     #: (n, 3) m
    force_a: np.ndarray | None = None
    force_b: np.ndarray | None = None

    def __len__(self):
        return len(self.stamp_ns)


class LiveSource:
    """The library's motion from the node's settings, computed block by block.

    Parameters
    ----------
    settings : RollerSettings
        Checked settings (geometry, mass model, motion, ``rate``, ``duration``).
    speed : float
        Simulated seconds per wall-clock second (> 0).
    """

    description = 'the library (simulated as it goes)'

    def __init__(self, settings, *, speed=1.0):
        self.settings = settings
        self.simulation = Simulation(settings)
        self.body = self.simulation.body
        self.weight = self.simulation.weight
        self.speed = float(speed)
        #: the stamp of sample 0 (ns): the wall clock when the show starts (:meth:`start`)
        self.start_ns = None
        rate, duration = settings.rate, settings.duration
        #: ticks 0 … last (None: until stopped), as the node publishes them
        self.last_tick = schedule.last_tick(duration, rate)

    @property
    def has_forces(self):
        return True

    def start(self, now_ns):
        """The show starts: sample 0 is stamped ``now_ns`` (the wall clock, ns)."""
        self.start_ns = int(now_ns)

    def times(self, ticks):
        """Simulated times (s) of the ticks k: k / rate, as the node computes them."""
        return np.asarray(ticks) / self.settings.rate

    def stamps(self, ticks):
        """Stamps (ns) of the ticks k: start_ns + round(k × 1e9 / rate), as the node's."""
        return schedule.stamps(self.start_ns, ticks, self.settings.rate)

    def blocks(self):
        """The blocks of the run, in order (for ever when ``duration`` is 0)."""
        rate = self.settings.rate
        per_block = max(1, int(round(BLOCK_SECONDS * rate)))
        first = 0
        while self.last_tick is None or first <= self.last_tick:
            end = first + per_block if self.last_tick is None else min(
                first + per_block, self.last_tick + 1)
            ticks = np.arange(first, end)
            t = self.times(ticks)
            sample = self.simulation.sample(t, forces=True)
            yield Block(self.stamps(ticks), t / self.speed, sample.position_g,
                        sample.quaternion, sample.contact_a, sample.contact_b,
                        sample.forces.force_a, sample.forces.force_b)
            first = end


class ReplaySource:
    """The samples of a recording of the node, paced by their stamps.

    Parameters
    ----------
    path : str
        The ``.mcap`` file.
    speed : float
        Recorded seconds per wall-clock second (> 0).

    Raises
    ------
    twodisk_ros.runs.RunError
        If the file cannot be read or holds no run (one line).
    """

    def __init__(self, path, *, speed=1.0):
        run = recorded_run(path)
        self.description = f'the recording {path}'
        self.settings = run.settings
        self.body = run.body           # the recorded run's body, any shape (run description)
        self.weight = run.weight
        self.speed = float(speed)
        self.run = run

    @property
    def has_forces(self):
        return self.run.force_a is not None

    @property
    def start_ns(self):
        return int(self.run.stamp_ns[0])

    def start(self, now_ns):
        """The show starts (the recorded stamps are kept)."""

    def blocks(self, size=64):
        """The recording's samples in blocks of ``size``, due at (stamp − first) / speed."""
        run = self.run
        due = (run.stamp_ns - run.stamp_ns[0]) * 1e-9 / self.speed
        for first in range(0, len(run), size):
            pick = slice(first, first + size)
            yield Block(run.stamp_ns[pick], due[pick], run.position_g[pick],
                        run.quaternion[pick], run.contact_a[pick], run.contact_b[pick],
                        None if run.force_a is None else run.force_a[pick],
                        None if run.force_b is None else run.force_b[pick])
