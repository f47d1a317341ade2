"""The physics objects the node's settings build, sampled in blocks (no rclpy here).

:class:`Simulation` takes the body, mass model, dynamics and motion stream that
:class:`~twodisk_ros.run.description.RunDescription` builds from
:class:`~twodisk_ros.run.parameters.RollerSettings`, adds the equilibria and the contact
forces, and samples everything the node publishes at a block of simulated times.
"""

from dataclasses import dataclass

import numpy as np

from ..model.frames import disk_rims
from ..physics.forces.contact import ContactForceModel
from ..physics.forces.validity import check_validity
from ..physics.motion.dynamics import PhaseState
from .description import RunDescription
from .scene_simulation import SceneMotion

__all__ = ['Sample', 'Simulation', 'continuous_quaternions']

#: Diagnostics turn to WARN when μ_required exceeds this share of μ, or N < this share of M g.
MARGIN_WARN = 0.1


def continuous_quaternions(quaternions, previous=None):
    """Flip signs so that consecutive quaternions satisfy q_k · q_{k+1} ≥ 0.

    Parameters
    ----------
    quaternions : ndarray, shape (n, 4)
        x, y, z, w, body → world (q and −q are the same rotation).
    previous : ndarray, shape (4,), optional
        The last quaternion published before this block (continuity across blocks).

    Returns
    -------
    ndarray, shape (n, 4)
    """
    q = np.array(quaternions, dtype=float)
    if q.shape[0] == 0:
        return q
    dots = np.einsum('ij,ij->i', q[1:], q[:-1])
    signs = np.concatenate([[1.0], np.cumprod(np.where(dots < 0, -1.0, 1.0))])
    if previous is not None and float(np.dot(q[0], previous)) < 0:
        signs = -signs
    return q * signs[:, None]


@dataclass
class Sample:
    """Published quantities at a block of simulated times (arrays over the block, SI units).

    Positions are in the world frame (m), quaternions x, y, z, w body → world (continuous
    across blocks), angles in rad and rates in rad/s.
    """

    t: np.ndarray
    phase: np.ndarray
    phase_rate: np.ndarray
    theta: np.ndarray
    psi: np.ndarray
    theta_rate: np.ndarray
    psi_rate: np.ndarray
    position_g: np.ndarray
    contact_a: np.ndarray
    contact_b: np.ndarray
    quaternion: np.ndarray
    forces: object = None      #: ContactForces of the block (None if not asked for)
    scene: object = None       #: SceneValues (energy balance, drive) of a scene's motion
    #: w = |ω_u| u̇ (rad/s, signed as u̇): the angular speed about AB, finite also where the
    #: body stops turning in u (u̇ infinite there: a contact on a flat vertex)
    angular_speed: np.ndarray = None
    #: contact_model hybrid: the block's HybridSamples (which model, engine state, energy)
    hybrid: object = None

    def __len__(self):
        return len(self.t)


class Simulation:
    """Physics objects built from settings; the node samples them in blocks.

    Parameters
    ----------
    settings : RollerSettings
        Checked settings.
    run : RunDescription, optional
        The description of these settings if already built (else built here).
    drive, command, start, carry, terms
        A scene's motion (:class:`~twodisk_ros.run.scene_simulation.SceneMotion`): the drive
        in force and its command, the state at t = 0 (a
        :class:`~twodisk_ros.physics.motion.dynamics.PhaseState` (u, u̇, w); None: ``theta0``,
        ``omega0``), the work
        done before and the balance's E₀, reused tables. Where the settings are flat, free
        and conservative and ``start`` is None the scene takes the level ground's fast solver
        (``run_start`` of :class:`~twodisk_ros.run.scene_simulation.SceneMotion`).
    orientation : array (4,), optional
        The last quaternion published before (the signs stay continuous).

    Raises
    ------
    ValueError, RuntimeError
        If the settings define no motion that can be simulated (one-line message).
    """

    def __init__(self, settings, run=None, *, drive=None, command=None, start=None,
                 carry=None, terms=None, orientation=None):
        if run is None or run.settings != settings:
            run = RunDescription(settings)
        self.run = run
        s = self.settings = run.settings
        self.body = run.body
        self.dynamics = run.dynamics
        self.forces = ContactForceModel(self.dynamics)
        self.weight = self.dynamics.mass.mass * self.dynamics.gravity   # M g (N)
        self.invalid = None        # ValidityReport of the first sample outside the model
        self._last_quaternion = orientation
        self.angular_speed0 = abs(s.omega0)
        #: the :class:`~twodisk_ros.run.scene_simulation.SceneMotion` of this stretch
        self.start = run.start() if start is None else start
        self.motion = self.scene = SceneMotion(
            self.dynamics, s, self.forces, drive=drive, command=command, start=self.start,
            carry=carry, terms=terms, run_start=start is None)
        self.invalid = self.scene.standing_report()
        self.stream = self.motion.stream
        self.energy0 = self.motion.energy0
        if start is None:
            self.equilibria     # (computed before the first sample, not during it)

    @property
    def equilibria(self):
        """[(Equilibrium, period or None)] of the flat ground (empty in a scene on a slope:
        :meth:`equilibrium_values` gives the rest poses there)."""
        if self.settings.slope != 0.0:
            return []
        if '_equilibria' not in self.__dict__:
            self.__dict__['_equilibria'] = self.dynamics.equilibria_with_periods()
        return self.__dict__['_equilibria']

    def equilibrium_values(self):
        """[(key, text)] of the rest poses, for the diagnostics."""
        if self.settings.slope != 0.0:
            return self.scene.equilibrium_values()
        return [(f'equilibrium {k}', (
            f'{eq.name}: theta={eq.theta:.9g} rad, psi={eq.psi:.9g} rad, '
            f'height={eq.height:.9g} m, d2z/d{eq.coordinate}2={eq.curvature:.6g} m, '
            f'{eq.stability}' + (f', period={period:.9g} s' if period else '')))
            for k, (eq, period) in enumerate(self.equilibria)]

    def restarted(self):
        """The motion of these settings from their start again (a reset)."""
        return type(self)(self.settings, self.run)

    def continued(self, settings, sample, i, *, drive=None, command=None):
        """A Simulation of ``settings`` (same motion parameters) continuing from sample i.

        Its t = 0 is sample i's time; the energy balance, the first failure found and the
        orientation's sign carry over. ``drive``/``command``: the drive in force from now.
        """
        if settings.physics_differs(self.settings):
            raise ValueError('these settings change the motion: build a new Simulation')
        values = sample.scene
        if values is not None:
            carry = (values.dissipated[i], values.drive_work[i], self.energy0)
        else:
            carry = (0.0, 0.0, self.energy0)
        nxt = Simulation(settings, self.run if self.run.settings == settings else None,
                         drive=drive, command=command,
                         start=PhaseState(float(sample.phase[i]), float(sample.phase_rate[i]),
                                          self.angular_speed(sample, i)), carry=carry,
                         terms=self.scene.known_terms,
                         orientation=sample.quaternion[i])
        if self.invalid is not None and settings.friction == self.settings.friction:
            nxt.invalid = self.invalid
        if '_equilibria' in self.__dict__:
            nxt.__dict__['_equilibria'] = self.__dict__['_equilibria']
        return nxt

    def initial_state(self):
        """The :class:`~twodisk_ros.physics.motion.dynamics.PhaseState` (u0, u̇0, w0) this stretch
        starts from: w0 the angular speed about AB, finite also at a flat vertex."""
        return self.start

    def sample(self, t, forces=False, time_offset=0.0):
        """Everything published at simulated times t (s, increasing array, after earlier ones).

        With ``forces`` the contact forces are computed too and the first sample outside the
        rolling model (lift-off, or μ_required > friction) is kept in :attr:`invalid`, its
        time reported as ``t + time_offset`` (s, the node's simulated time).
        """
        t = np.asarray(t, dtype=float)
        u, u_dot, u_ddot, speed, values, (g, a, b, q) = self.motion.sample(t)
        self.motion.track_rest(t + time_offset, u, u_dot, u_ddot, values)
        quaternion = continuous_quaternions(q, self._last_quaternion)
        if len(quaternion):
            self._last_quaternion = quaternion[-1]
        theta, psi, dtheta, dpsi = self.body.phase_angles_with_rates(u)
        contact = None
        if forces:
            contact = self.motion.forces(u, u_dot, u_ddot, speed)
            if self.invalid is None and len(t):
                report = check_validity(t + time_offset, contact, self.settings.friction)
                if not report.valid:
                    self.invalid = report
        return Sample(t=t, phase=u, phase_rate=u_dot, theta=theta, psi=psi,
                      theta_rate=dtheta * u_dot, psi_rate=dpsi * u_dot, position_g=g,
                      contact_a=a, contact_b=b, quaternion=quaternion, forces=contact,
                      scene=values, angular_speed=speed)

    def update(self, settings):
        """Take settings that leave the motion unchanged (e.g. friction, frame_id).

        A new friction coefficient is judged from now on: a slip found under the old one
        is forgotten (a lift-off does not depend on it and is found again at once).
        """
        if settings.physics_differs(self.settings):
            raise ValueError('these settings change the motion: build a new Simulation')
        if settings.friction != self.settings.friction:
            self.invalid = None
        self.settings = settings

    def check_scene_change(self, settings):
        """Raise ValueError (one line) if this motion cannot continue under ``settings``'
        scene (a runtime change of drive, damping or rolling resistance); rolling can."""

    def switches(self, sample, start, stop):
        """[(index, event text)] of the switches of contact model among samples [start, stop)
        of a block (none: exact rolling only; :mod:`~twodisk_ros.run.hybrid_simulation`)."""
        return []

    def contact_status(self, sample, i):
        """(level, message, values) of the contact forces at sample i, for the diagnostics.

        level: 0 OK, 1 WARN (margin to slip or lift-off below :data:`MARGIN_WARN`), 2 ERROR
        (the motion has left the rolling model: it is published on, marked as invalid).
        """
        f, mu = sample.forces, self.settings.friction
        normal_a, normal_b = float(f.normal_a[i]), float(f.normal_b[i])
        required = float(f.mu_required[i])
        lift = min(normal_a, normal_b) / self.weight if self.weight > 0 else float('inf')
        values = [('normal_a', normal_a), ('normal_b', normal_b), ('mu_required', required),
                  ('friction', mu), ('slip_margin', mu - required), ('lift_off_margin', lift)]
        if self.invalid is not None:
            return 2, f'outside the rolling model: {self.invalid.reason}', values
        if required > (1 - MARGIN_WARN) * mu or lift < MARGIN_WARN:
            return 1, (f'close to the limits of the rolling model: mu_required {required:.3g} '
                       f'of friction {mu:.3g}, min N / (M g) = {lift:.3g}'), values
        return 0, 'rolling', values

    def invariant(self, sample, i):
        """(name, value, relative drift) of the conserved quantity at sample i.

        Dynamic mode: the energy E (J), drift |E − E₀| / (M g L). Kinematic mode: the
        angular speed |ω| (rad/s), drift ||ω| − |omega0|| / |omega0| (|ω| itself if
        omega0 = 0). Energy is not conserved there: the motor does work.
        """
        if sample.scene is not None:
            balance = float(sample.scene.balance[i])
            return ('energy_balance', balance,
                    abs(balance - self.energy0) / self.dynamics.energy_scale)
        if self.settings.mode == 'kinematic':
            speed = abs(self.angular_speed(sample, i))
            scale = self.angular_speed0 if self.angular_speed0 > 0 else 1.0
            return 'angular_speed', speed, abs(speed - self.angular_speed0) / scale
        energy = self.energy(sample, i)
        return 'energy', energy, abs(energy - self.energy0) / self.dynamics.energy_scale

    def angular_speed(self, sample, i):
        """w (rad/s, signed as u̇) at sample i: the angular speed about AB."""
        return float(sample.angular_speed[i])

    def energy(self, sample, i):
        """E (J) at sample i: ½ J w² + V (the regular chart: finite and exact also where the
        body stops turning in u)."""
        if sample.scene is not None:
            return float(sample.scene.energy[i])
        return float(self.dynamics.energy_turning(sample.phase[i], sample.angular_speed[i]))

    def rotation(self, sample, i):
        """R body → world (3 × 3) at sample i, from its quaternion."""
        x, y, z, w = sample.quaternion[i]
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])

    def disk_outlines(self, rotation, position_g):
        """World points (m) of both disk outlines for one pose: two closed arrays (N + 1, 3),
        the real outline of the body's lamina to a polygon error of 2e-3 of its size
        (:func:`~twodisk_ros.model.frames.disk_rims`, sampled once per body)."""
        rims = self.__dict__.get('_outline_rims')
        if rims is None:
            rims = self.__dict__['_outline_rims'] = disk_rims(self.body)
        return tuple(rim @ rotation.T + position_g for rim in rims)

    def hull_rims(self, rotation, position_g, points=64):
        """World end points A, B of the hull's rulings over one cycle: two arrays (points + 1, 3).

        The convex hull of the disks is ruled by the contact segments AB of the rolling
        cycle (:mod:`~twodisk_ros.physics.mass.hull`); for the hull marker of ``body_markers``.
        """
        u = np.linspace(0.0, 2 * np.pi, points + 1)
        r1, r2 = self.body.phase_vectors(u)[:2]
        return r1 @ rotation.T + position_g, r2 @ rotation.T + position_g
