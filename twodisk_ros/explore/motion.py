"""The motion ``twodisk-explore`` shows: the node's run from its settings, or a recording.

No viser and no rclpy here: the page (:mod:`~twodisk_ros.explore.page`) asks a motion for
the frames at simulated times and draws them. Both motions give :class:`Frame` s in the
world frame ``frame_id`` (Z up against gravity, SI units: m, N, s).

- :class:`LiveMotion`: the node's physics (:class:`twodisk_ros.run.simulation.Simulation`,
  the settings of ``roller``), sampled with the contact forces, so its lift-off, slip and
  flat-vertex reports are the node's (:attr:`Simulation.invalid`, a ValidityReport). A new
  value of a parameter restarts the motion at t = 0 from ``theta0``, ``omega0``; a value the
  node refuses is refused with the node's one-line reason and the motion goes on.
- :class:`RecordedMotion`: the samples of an MCAP recording of the node
  (:func:`twodisk_ros.runs.recorded_run`), the body and the settings from its metadata.
"""

from dataclasses import dataclass
import math

import numpy as np

from ..recordings.errors import one_line
from ..run.description import RunDescription
from ..run.parameters import BY_NAME
from ..run.scene_simulation import ground_normal
from ..run.simulation import Simulation
from ..runs import RunError, recorded_run

__all__ = ['CONTROLLED', 'CYCLE_POINTS', 'PHASE_GRID', 'Frame', 'LiveMotion', 'RecordedMotion',
           'cycle_curve']

#: The node's parameters the page controls (the physical ones), in the page's order.
CONTROLLED = ('shape', 'a', 'b', 'delta', 'exponent', 'egg_asymmetry', 'arrangement',
              'mass_model', 'mode', 'theta0', 'omega0', 'slope', 'heading0', 'damping',
              'rolling_resistance', 'friction', 'drive')
#: Phase samples of the z_G curve over one cycle.
CYCLE_POINTS = 361
#: Phases a replay's pose is matched against (a step of 0.1 degree).
PHASE_GRID = 3600


@dataclass
class Frame:
    """The samples of one step of the show (arrays over the step, world frame, SI units);
    the last sample is the pose drawn."""

    t: np.ndarray             #: (n,) simulated time (s)
    phase: np.ndarray | None  #: (n,) u (rad); a replay's from its attitude (RecordedMotion.phases)
    position_g: np.ndarray    #: (n, 3) m
    quaternion: np.ndarray    #: (n, 4) x, y, z, w body → world
    contact_a: np.ndarray     #: (n, 3) m
    contact_b: np.ndarray     #: (n, 3) m
    force_a: np.ndarray | None = None   #: (n, 3) N, the ground's force at A
    force_b: np.ndarray | None = None
    normal_a: np.ndarray | None = None  #: (n,) N_A (N)
    normal_b: np.ndarray | None = None
    mu_required: np.ndarray | None = None  #: (n,) least friction coefficient for rolling

    def __len__(self):
        return len(self.t)


def _in_body(quaternion, vector):
    """R^T v: a world vector (3,) in the body frames of unit quaternions (n, 4) x, y, z, w."""
    q = np.asarray(quaternion, dtype=float)
    u, w = -q[:, :3], q[:, 3:]                      # the inverse rotation
    v = np.broadcast_to(np.asarray(vector, dtype=float), u.shape)
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def cycle_curve(dynamics, points=CYCLE_POINTS):
    """(u, z_G) over one cycle on the flat ground: u in [0, 2π] (rad), z_G (m) the height of
    the centre of mass of the body's poses (``dynamics.cycle.poses``)."""
    u = np.linspace(0.0, 2.0 * math.pi, points)
    return u, np.asarray(dynamics.cycle.poses(u).position_g)[:, 2]


class LiveMotion:
    """The node's run of ``settings``, restarted at every accepted change.

    Parameters
    ----------
    settings : RollerSettings
        Checked settings of the node.
    command : float
        The drive's command (rad/s for drive speed, N m for drive torque; 0 by default:
        the torque drive then gives 0 N m; the speed drive is commanded 0 rad/s only when
        a command is given, else it holds its starting speed).
    """

    live = True

    def __init__(self, settings, command=None):
        self.settings, self.command = settings, command
        self.simulation = Simulation(settings, drive=settings.drive, command=command)
        self.t = 0.0              #: simulated time of the last sample (s)
        self.restarts = 0         #: accepted changes (and resets) so far

    # -- what the page shows next to the body ----------------------------------------------
    @property
    def body(self):
        return self.simulation.body

    @property
    def weight(self):
        """M g (N)."""
        return self.simulation.weight

    @property
    def invalid(self):
        """The node's words for the first sample outside the rolling model, or None."""
        report = self.simulation.invalid
        return None if report is None else report.reason

    @property
    def ground_normal(self):
        return ground_normal(self.settings.slope)

    def cycle(self):
        """(u, z_G) over one cycle (:func:`cycle_curve`) of the body on the flat ground."""
        return cycle_curve(self.simulation.dynamics)

    def equilibria(self):
        """[(u (rad), z_G (m), stability)] of the flat ground (the node's list; stability
        'stable', 'unstable' or 'neutral')."""
        return [(float(eq.phase), float(eq.height), eq.stability)
                for eq, _ in self.simulation.dynamics.equilibria_with_periods()]

    # -- changes ---------------------------------------------------------------------------
    def _build(self, settings, command):
        """A Simulation of checked settings; reuses the dynamics (its tables and equilibria)
        when only the start or the scene changed (same body, mass model and gravity)."""
        old = self.simulation.run
        description = RunDescription(settings)
        if (description.body is old.body and description.mass is old.mass
                and settings.gravity == old.settings.gravity):
            description.__dict__['dynamics'] = old.dynamics
        return Simulation(settings, description, drive=settings.drive, command=command)

    def change(self, name, value):
        """Set parameter ``name`` (or ``'command'``) to ``value`` and restart at t = 0.

        Returns None if accepted, else the node's one-line reason (the motion goes on).
        """
        settings, command = self.settings, self.command
        try:
            if name == 'command':
                command = None if value is None else float(value)
            elif name not in BY_NAME:
                return f'unknown parameter {name!r}'
            else:
                settings = settings.with_values(**{name: value}).checked()
            simulation = self._build(settings, command)
        except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
            return one_line(error)
        self.settings, self.command, self.simulation = settings, command, simulation
        self.t = 0.0
        self.restarts += 1
        return None

    def reset(self):
        """Start the run again at t = 0 (same settings)."""
        self.simulation = self._build(self.settings, self.command)
        self.t = 0.0
        self.restarts += 1

    # -- samples ---------------------------------------------------------------------------
    def advance(self, dt, samples=1):
        """The :class:`Frame` of ``samples`` equal steps over the next ``dt`` simulated
        seconds (> 0): the last one at the new time."""
        t = self.t + dt * np.arange(1, samples + 1) / samples
        if self.t == 0.0:
            t = np.concatenate([[0.0], t])
        sample = self.simulation.sample(t, forces=True)
        self.t = float(t[-1])
        f = sample.forces
        return Frame(t, sample.phase, sample.position_g, sample.quaternion, sample.contact_a,
                     sample.contact_b, f.force_a, f.force_b, f.normal_a, f.normal_b,
                     f.mu_required)


class RecordedMotion:
    """An MCAP recording of the node, replayed by its stamps (raises RunError, one line)."""

    live = False

    def __init__(self, path):
        self.path = str(path)
        self.run = run = recorded_run(path)
        self.settings = run.settings
        self.command = None
        self.t = 0.0
        self.restarts = 0
        self.description = RunDescription(run.settings)

    @property
    def body(self):
        return self.run.body

    @property
    def weight(self):
        return self.run.weight

    @property
    def ground_normal(self):
        return ground_normal(self.settings.slope)

    @property
    def duration(self):
        """The recording's length (s)."""
        return float(self.run.t[-1])

    @property
    def invalid(self):
        """Lift-off or slip judged from the recorded forces up to now, or None."""
        return self._invalid

    _invalid = None

    def cycle(self):
        return cycle_curve(self.description.dynamics)

    def equilibria(self):
        return [(float(eq.phase), float(eq.height), eq.stability)
                for eq, _ in self.description.dynamics.equilibria_with_periods()]

    def phases(self, quaternion):
        """u (rad, in [0, 2π)) of recorded orientations (n, 4): the cycle's phase (to
        2π / :data:`PHASE_GRID`) whose attitude on the ground, the ground's normal in the
        body frame, is nearest the recorded one (heading and position play no part)."""
        if self._attitudes is None:
            u = np.linspace(0.0, 2.0 * math.pi, PHASE_GRID, endpoint=False)
            poses = self.description.dynamics.cycle.poses(u)     # on the flat ground, Z up
            self._attitudes = u, _in_body(poses.quaternion, (0.0, 0.0, 1.0))
        u, table = self._attitudes
        seen = _in_body(quaternion, self.ground_normal)
        return u[np.argmax(seen @ table.T, axis=1)]

    _attitudes = None

    def change(self, name, value):
        return (f'{name} is recorded in {self.path}: a replay shows the recorded run '
                '(simulate it with --params-file to change it)')

    def reset(self):
        self.t = 0.0
        self._invalid = None
        self.restarts += 1

    def advance(self, dt, samples=1):
        """The recorded samples in (t, t + dt] (at least the one nearest t + dt); the replay
        starts again at its end."""
        run = self.run
        if self.t >= run.t[-1]:
            self.reset()                 # the replay starts again (its traces too)
        stop = min(self.t + dt, float(run.t[-1]))
        first = int(np.searchsorted(run.t, self.t, side='right'))
        last = max(first + 1, int(np.searchsorted(run.t, stop, side='right')))
        pick = slice(first - 1 if first else 0, last)
        self.t = stop
        frame = Frame(run.t[pick], self.phases(run.quaternion[pick]), run.position_g[pick],
                      run.quaternion[pick], run.contact_a[pick], run.contact_b[pick])
        if run.force_a is not None:
            self._forces(frame, run.force_a[pick], run.force_b[pick])
        return frame

    def _forces(self, frame, force_a, force_b):
        """N and the friction ratio of the recorded forces (the chosen split)."""
        n = self.ground_normal
        frame.force_a, frame.force_b = force_a, force_b
        ratios = []
        for key, force in (('a', force_a), ('b', force_b)):
            normal = force @ n
            tangential = np.linalg.norm(force - normal[:, None] * n, axis=1)
            setattr(frame, 'normal_' + key, normal)
            with np.errstate(divide='ignore', invalid='ignore'):
                ratios.append(np.where(normal > 0, tangential / normal, np.inf))
        frame.mu_required = np.maximum(*ratios)
        if self._invalid is None:
            low = np.minimum(frame.normal_a, frame.normal_b)
            mu = self.settings.friction
            bad = np.flatnonzero((low < 0) | (frame.mu_required > mu))
            if len(bad):
                k = bad[0]
                what = ('a contact would lift off' if low[k] < 0 else
                        f'the body would slip: mu_required = {frame.mu_required[k]:.4g} > '
                        f'mu = {mu:.4g}')
                self._invalid = f'{what} at t = {frame.t[k]:.4g} s (recorded forces)'


def open_motion(recording=None, settings=None, command=None):
    """A :class:`RecordedMotion` of ``recording`` or a :class:`LiveMotion` of ``settings``;
    RunError (one line) if it cannot be built."""
    if recording is not None:
        return RecordedMotion(recording)
    try:
        return LiveMotion(settings, command)
    except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
        raise RunError(f'the parameters define no run: {one_line(error)}') from None
